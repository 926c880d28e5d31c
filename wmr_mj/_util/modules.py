"""Where a module's file is, found the way ``import`` finds it, but without running any of it.

``importlib.util.find_spec("pkg.mod")`` imports ``pkg`` first, and so runs ``pkg/__init__.py``, to
read the package's ``__path__``. :func:`find_module_file` walks the dotted name one level at a time
instead: a level already imported is read from ``sys.modules`` (import would not run it again); any
other is asked of the finders on ``sys.meta_path`` (the path finder lists folders, an editable
install's finder reads its table), with the parent's search locations as the finder reads them from
its spec, so no module's code runs. Before a plug-in's source is checked against its record and
then imported (``wmr-mj replay --verify``), this is how its file is found.

A package whose ``__init__`` changes its own ``__path__`` when it runs (``pkgutil.extend_path``)
may put a submodule where this walk does not look; it then says the module is not found, rather
than run that ``__init__``.

Usage::

    from wmr_mj._util.modules import find_module_file
    found = find_module_file("my_package.laws")   # ModuleFile(path=..., runs_first=(.../__init__.py,))
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass
from importlib.machinery import ModuleSpec
from pathlib import Path

__all__ = ["ModuleFile", "ModuleNotLocated", "find_module_file"]


class ModuleNotLocated(LookupError):
    """The module's file cannot be found without running code (the message says why)."""


@dataclass(frozen=True)
class ModuleFile:
    """A module's file, as ``import`` would execute it.

    Attributes:
        name: the dotted module name.
        path: the file import executes for it (a package's ``__init__.py``).
        imported: True where the module is in ``sys.modules`` already (import runs nothing again).
        runs_first: the ``__init__.py`` of each enclosing package not imported yet: import runs them,
            outermost first, before ``path``.
    """

    name: str
    path: Path
    imported: bool = False
    runs_first: tuple[Path, ...] = ()


def _spec_from_finders(name: str, search: Sequence[str] | None) -> ModuleSpec | None:
    """The first spec a ``sys.meta_path`` finder gives for ``name`` (search: the parent package's
    locations; None for a top-level name), as the import system asks them; nothing is executed."""
    for finder in sys.meta_path:
        find_spec = getattr(finder, "find_spec", None)
        if find_spec is None:
            continue
        spec = find_spec(name, search)
        if spec is not None:
            return spec
    return None


def _file_of(spec: ModuleSpec | None) -> Path | None:
    origin = getattr(spec, "origin", None)
    if spec is None or not spec.has_location or not origin or not Path(origin).is_file():
        return None
    return Path(origin)


def _level(name: str, search: Sequence[str] | None) -> tuple[Path | None, Sequence[str] | None, bool, str]:
    """(its file, its search locations where it is a package, whether it is imported, its origin) of one
    level of a dotted name, read from ``sys.modules`` or else from the finders."""
    loaded = sys.modules.get(name)
    if loaded is not None:  # import returns it as it is
        file = getattr(loaded, "__file__", None)
        return (Path(file) if file else None, getattr(loaded, "__path__", None), True,
                str(getattr(getattr(loaded, "__spec__", None), "origin", None)))
    spec = _spec_from_finders(name, search)
    if spec is None:
        raise ModuleNotLocated(f"module {name!r} is not found on sys.path")
    return _file_of(spec), spec.submodule_search_locations, False, str(spec.origin)


def find_module_file(name: str) -> ModuleFile:
    """The file that ``import name`` would execute, found without executing any module.

    Args:
        name: a dotted module name, e.g. ``"my_package.laws"``.

    Returns:
        A :class:`ModuleFile`: the module's file and the package ``__init__`` files import would run first.

    Raises:
        ModuleNotLocated: a level of the name that no finder knows, a parent that is not a package, or a
            module without a source file of its own (built in, frozen, a namespace package).
    """
    parts = name.split(".")
    if not all(p.isidentifier() for p in parts):
        raise ModuleNotLocated(f"{name!r} is not a dotted module name")
    search: Sequence[str] | None = None  # sys.path, for the top level
    runs_first: list[Path] = []
    for depth in range(1, len(parts)):
        package = ".".join(parts[:depth])
        init, below, imported, _ = _level(package, search)
        if below is None:
            raise ModuleNotLocated(f"{package!r} is not a package, so it holds no module {name!r}")
        search = list(below)
        if not imported and init is not None:  # a namespace package has no __init__ to run
            runs_first.append(init)
    path, _, imported, origin = _level(name, search)
    if path is None or not path.is_file():
        raise ModuleNotLocated(f"module {name!r} has no source file of its own (origin {origin})")
    return ModuleFile(name=name, path=path, imported=imported, runs_first=tuple(runs_first))
