"""The package installed the ordinary way: build the wheel, install it in a fresh virtualenv, run it.

The wheel is built from a copy of the working tree (so no stale build/ folder can
hide a missing file) without network (--no-build-isolation, with the setuptools of
the test extra) and installed without its dependencies into a virtualenv that does
not see the system's packages; a .pth file lends it this environment's
site-packages for the dependencies (a .pth in a *path* entry is not executed, so
the editable install of the checkout stays invisible). Commands run from a folder
outside the repository.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import site
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from wmr_mj.cli.app import COMMANDS

pytestmark = pytest.mark.wheel  # builds the wheel: `make test-fast` leaves it out

REPO = Path(__file__).resolve().parents[1]
# what a build must not see: environments, build outputs, caches, run outputs
_IGNORE_ANYWHERE = shutil.ignore_patterns(".git", ".venv", "build", "dist", "*.egg-info", "__pycache__",
                                          ".pytest_cache", ".ruff_cache", ".gl", "node_modules", "MUJOCO_LOG.TXT",
                                          "*.so")  # the editable install's compiled law: the wheel builds its own


def _IGNORE(folder: str, names: list[str]) -> set[str]:
    """What the copy of the source leaves out; the run-output folder logs/ only at the project's root
    (wmr_mj/logs/ is a subpackage)."""
    ignored = set(_IGNORE_ANYWHERE(folder, names))
    if "pyproject.toml" in names and "logs" in names:
        ignored.add("logs")
    return ignored
# files of the source that are package data (everything else in a package folder is a module or a cache)
_DATA_GLOBS = ("wmr_mj/schemas/*", "wmr_mj/data/*", "wmr_mj/data/routes/*", "wmr_mj/data/suites/*", "wmr_mj/py.typed",
               "controllers/py.typed")
_MODEL_FILES = ("c80.xml", "scene.xml", "README.md", "c80.png", "CHANGELOG.md")


def _run(cmd: list[str], *, cwd: Path, env: dict[str, str] | None = None, timeout: float = 120) -> str:
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert proc.returncode == 0, f"{' '.join(map(str, cmd))} exited {proc.returncode}:\n{proc.stdout}\n{proc.stderr}"
    return proc.stdout


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(venv bin folder, wheel path, source copy, outside folder, environment) of a fresh install."""
    try:
        from importlib.metadata import version

        setuptools_major = int(version("setuptools").split(".")[0])
    except Exception:  # noqa: BLE001  no setuptools at all
        setuptools_major = 0
    if setuptools_major < 77:
        pytest.fail("the wheel test builds offline with this environment's setuptools >= 77 "
                    "(the 'test' extra of pyproject.toml); run `make venv`")
    root = tmp_path_factory.mktemp("wheel")
    src, wheels, venv, outside = root / "src", root / "wheels", root / "venv", root / "elsewhere"
    shutil.copytree(REPO, src, ignore=_IGNORE)
    outside.mkdir()
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--no-index", "-q",
          "-w", str(wheels), str(src)], cwd=root)
    (wheel,) = wheels.glob("wmr_mj-*.whl")
    _run([sys.executable, "-m", "venv", "--without-pip", str(venv)], cwd=root)
    python = venv / "bin" / "python"
    _run([sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps", "--no-index", "-q",
          str(wheel)], cwd=root)
    purelib = _run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], cwd=outside)
    (Path(purelib.strip()) / "zz_wmr_mj_test_deps.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env["MPLBACKEND"] = "Agg"
    return venv / "bin", wheel, src, outside, env


def test_wheel_carries_every_module_and_data_file(installed):
    _, wheel, src, _, _ = installed
    names = set(zipfile.ZipFile(wheel).namelist())
    expected = {p.relative_to(src).as_posix() for pkg in ("wmr_mj", "controllers") for p in (src / pkg).rglob("*.py")}
    expected |= {p.relative_to(src).as_posix() for g in _DATA_GLOBS for p in src.glob(g)
                 if p.is_file() and not p.name.startswith(".")}  # hidden: an atomic write's temporary file
    expected |= {f"wmr_mj/models/{name}" for name in _MODEL_FILES}
    assert "wmr_mj/cli/run.py" in expected and "wmr_mj/schemas/wmr_mj.channels.json" in expected
    assert sorted(expected - names) == []
    for name in _MODEL_FILES:  # the shipped model files are the checkout's, byte for byte
        assert zipfile.ZipFile(wheel).read(f"wmr_mj/models/{name}") == (src / "models" / name).read_bytes()


def test_installed_package_is_the_wheel_not_the_checkout(installed):
    bin_dir, _, _, outside, env = installed
    out = _run([str(bin_dir / "python"), "-c", "import wmr_mj, controllers; print(wmr_mj.__file__); "
                "print(controllers.__file__)"], cwd=outside, env=env)
    for line in out.split():
        assert Path(line).is_relative_to(bin_dir.parent), line
        assert not Path(line).is_relative_to(REPO), line


def test_the_wheel_builds_the_compiled_law_and_it_runs(installed):
    bin_dir, wheel, _, outside, env = installed
    names = zipfile.ZipFile(wheel).namelist()
    assert any(n.startswith("wmr_mj/sim/_compiled_law.") and n.endswith(".so") for n in names)
    out = _run([str(bin_dir / "python"), "-c", "from wmr_mj.sim import compiled_law, _compiled_law; "
                "print(compiled_law.unavailable_reason()); print(_compiled_law.__file__)"], cwd=outside, env=env)
    reason, path = out.split("\n")[:2]
    assert reason == "None" and Path(path).is_relative_to(bin_dir.parent), out


def test_without_a_c_compiler_the_wheel_builds_without_the_compiled_law(installed, tmp_path):
    _, _, src, _, env = installed
    source = tmp_path / "src"
    shutil.copytree(src, source, ignore=_IGNORE)
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--no-index", "-q",
          "-w", str(tmp_path / "wheels"), str(source)], cwd=tmp_path, env={**env, "CC": "/bin/false"})
    (wheel,) = (tmp_path / "wheels").glob("wmr_mj-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert "wmr_mj/sim/compiled_law.py" in names and not [n for n in names if n.endswith(".so")]


def test_help_lists_every_command(installed):
    bin_dir, _, _, outside, env = installed
    out = _run([str(bin_dir / "wmr-mj"), "--help"], cwd=outside, env=env)
    listed = [name for name in COMMANDS if f"    {name} " in out or f"    {name}\n" in out]
    assert listed == list(COMMANDS), out


def test_run_from_outside_the_repository(installed):
    bin_dir, _, _, outside, env = installed
    out = _run([str(bin_dir / "wmr-mj"), "run", "--duration", "10", "--no-log", "--json"], cwd=outside, env=env)
    summary = json.loads(out)
    assert summary["steps"] == 10_000
    assert summary["status"] == "completed"
    assert summary["log"] is None
    assert math.isfinite(summary["sup_E"]) and summary["sup_E"] >= 0.0
    assert list(outside.iterdir()) == []  # --no-log writes nothing


def test_model_check_compares_the_installed_copy(installed):
    """From a wheel, `model check` names the shipped copy and judges it as the checkout's check judges
    the same files (exit 0: they match the parameter set, 1: out of date)."""
    bin_dir, _, src, outside, env = installed
    proc = subprocess.run([str(bin_dir / "wmr-mj"), "model", "check"], cwd=outside, env=env, capture_output=True,
                          text=True, timeout=120)
    assert "copy installed with the package" in proc.stdout, proc.stdout + proc.stderr
    assert str(bin_dir.parent) in proc.stdout  # it names the folder it compared
    checkout = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "model", "check"], cwd=src, capture_output=True,
                              text=True, timeout=120)
    assert "(checkout)" in checkout.stdout, checkout.stdout + checkout.stderr
    assert (proc.returncode, checkout.returncode) in ((0, 0), (1, 1)), (proc.stdout, checkout.stdout)


def test_the_installed_package_runs_a_built_in_plug_in_and_the_packaged_suite(installed):
    """The built-in laws are found by name and the suite file ships in the wheel (package data)."""
    bin_dir, _, _, outside, env = installed
    out = _run([str(bin_dir / "wmr-mj"), "run", "--controller", "sliding-mode", "--model", "nonholonomic",
                "--path", "lane-change", "--duration", "10", "--no-log", "--json"], cwd=outside, env=env)
    summary = json.loads(out)
    assert summary["controller"] == "sliding-mode" and summary["verdict"].endswith(("inside", "outside"))
    code = ("from wmr_mj.experiments.suite import load_suite; s = load_suite('standard-v1'); "
            "print(s.name, len(s.scenarios), s.source)")
    printed = _run([str(bin_dir / "python"), "-c", code], cwd=outside, env=env)
    assert printed.startswith("standard-v1 30 ") and str(bin_dir.parent) in printed
