"""Atomic file output: write to a temporary file beside the target, then rename."""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from wmr_mj.errors import OutputPathError

__all__ = [
    "write_bytes_atomic",
    "write_text_atomic",
    "write_json_atomic",
    "check_output_path",
    "json_safe",
    "software_versions",
]


def check_output_path(path: str | os.PathLike, *, kind: str = "file", option: str | None = None) -> Path:
    """Make sure ``path`` can be written before a job starts; return it as a Path.

    kind="file": ``path`` is a file whose folder must take a new file; kind="dir": ``path``
    is a folder. Missing folders are created and probed with a temporary file, then
    removed again, so the check leaves nothing behind whatever follows (the writers
    create their folders). Raises :class:`~wmr_mj.errors.OutputPathError` naming the path
    (and the ``option`` it came from, e.g. "--out") and why it cannot be written.
    """
    if kind not in ("file", "dir"):
        raise ValueError(f"kind = {kind!r}; 'file' or 'dir' is accepted")
    path = Path(path)
    name = f"{option} {str(path)!r}" if option else repr(str(path))

    def refuse(why: str) -> OutputPathError:
        return OutputPathError(f"{name} cannot be written: {why}; give a path in a writable folder")

    folder = path if kind == "dir" else path.parent
    if kind == "file" and path.is_dir():
        raise OutputPathError(f"{name} is a folder; give a file path")
    missing: list[Path] = []
    ancestor = folder.absolute()
    while not ancestor.exists() and not ancestor.is_symlink():
        missing.append(ancestor)
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise refuse(f"{ancestor} is {'a broken link' if ancestor.is_symlink() else 'a file'}, not a folder")
    created: list[Path] = []
    doing = ""
    try:
        for d in reversed(missing):
            doing = f"cannot create the folder {d}"
            d.mkdir()
            created.append(d)
        doing = f"cannot create a file in {folder.absolute()}"
        fd, probe = tempfile.mkstemp(dir=folder, prefix=".wmr-mj-probe-")
        os.close(fd)
        os.unlink(probe)
        if kind == "file" and path.exists() and not os.access(path, os.W_OK):
            doing = "the existing file is read-only"
            raise PermissionError(13, "Permission denied", str(path))
    except OSError as exc:
        raise refuse(f"{doing} ({exc.strerror or exc})") from None
    finally:
        for d in reversed(created):
            try:
                d.rmdir()
            except OSError:  # something else wrote there meanwhile: keep it
                pass
    return path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_bytes_atomic(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` so that readers see the old file or the whole new one."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file ordinary permissions
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    return write_bytes_atomic(path, text.encode())


def json_safe(obj: Any) -> Any:
    """``obj`` as plain JSON values: NumPy scalars and arrays made Python numbers and lists,
    NaN/inf replaced by None (standard JSON), paths as strings, dataclasses and objects with
    ``to_dict()`` as dicts, anything else as ``str(obj)``. The one sanitizer of the package."""
    if isinstance(obj, Mapping):
        return {str(k): json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, set, frozenset)):
        return [json_safe(v) for v in obj]
    if obj is None or isinstance(obj, (str, bool)):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        return float(obj) if math.isfinite(obj) else None
    if hasattr(obj, "tolist") and callable(obj.tolist):  # NumPy arrays and scalars
        return json_safe(obj.tolist())
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    if hasattr(obj, "to_dict") and callable(obj.to_dict):
        return json_safe(obj.to_dict())
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return json_safe(dataclasses.asdict(obj))
    return str(obj)


@functools.lru_cache(maxsize=1)
def _versions() -> tuple[tuple[str, str], ...]:
    import platform
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version(), "platform": platform.platform()}
    for dist in ("wmr-mj", "mujoco", "numpy", "scipy", "matplotlib", "mcap", "zstandard", "lz4"):
        try:
            out[dist.replace("-", "_")] = version(dist)
        except PackageNotFoundError:
            out[dist.replace("-", "_")] = "not installed"
    root = Path(__file__).resolve().parent.parent
    if (root / ".git").exists():  # a source checkout: record its commit
        import subprocess

        try:
            rev = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True,
                                 text=True, timeout=5)
            if rev.returncode == 0 and rev.stdout.strip():
                out["git_commit"] = rev.stdout.strip()
        except (OSError, subprocess.SubprocessError):  # no git: no commit recorded
            pass
    return tuple(out.items())


def software_versions() -> dict[str, str]:
    """Versions of python, the platform, wmr_mj, mujoco, numpy, scipy, matplotlib, mcap, zstandard
    and lz4 (from the installed distributions, nothing imported), plus ``git_commit`` in a source
    checkout. Computed once per process."""
    return dict(_versions())


def write_json_atomic(path: str | os.PathLike, obj: Any) -> Path:
    return write_text_atomic(path, json.dumps(json_safe(obj), indent=2, sort_keys=True, allow_nan=False) + "\n")
