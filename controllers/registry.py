"""Finding a steering law or a path tracker by name: built-ins, files, modules and installed plug-ins.

A controller (or tracker) is named by one string:

- a built-in name (:data:`BUILTIN_CONTROLLERS`, :data:`BUILTIN_TRACKERS`);
- ``FILE.py:Class``: a class in a Python file of one's own (relative to the working folder);
- ``module:Class`` or ``package.module:Class``: a class of an importable module;
- the name of an entry point that an installed package registers in the group
  ``wmr_mj.controllers`` (or ``wmr_mj.trackers``)::

      [project.entry-points."wmr_mj.controllers"]
      my-smc = "my_package.smc:SlidingMode"

with its parameters as NAME=VALUE strings (``--controller-param``): a value is read as JSON where
it parses (numbers, true/false, lists), else kept as a string. :func:`resolve` returns the class
and a :class:`PluginSource`: what the log records to find it again (the import path, the
parameters, the SHA-256 of the file that defines it). :func:`check_recorded_source` finds that file
again without running any code (:func:`locate_source`) and compares its SHA-256 with the record's, so
that ``replay --verify`` refuses a source that has changed, or is gone, before importing it.

Usage::

    from controllers.registry import resolve, parse_params
    cls, source = resolve("examples/my_law.py:MyPD", parse_params(["kp=40"]), kind="controller")
"""

from __future__ import annotations

import copy
import hashlib
import importlib
import importlib.util
import inspect
import json
import sys
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any

from controllers.base import BuildContext, SteeringController, describe_params, law_methods_missing
from controllers.computed_torque import CONTROLLER_NAMES, MODEL_SOURCES, model_from_source
from controllers.tracking import PathTracker
from wmr_mj._util.modules import ModuleNotLocated, find_module_file
from wmr_mj.errors import ParameterError, UnknownNameError

__all__ = ["PluginSource", "LocatedSource", "resolve", "parse_params", "locate_source", "check_recorded_source",
           "recorded_spec", "BUILTIN_CONTROLLERS", "BUILTIN_TRACKERS", "ENTRY_POINT_GROUPS",
           "controller_names", "tracker_names", "source_hash", "is_builtin", "refuse_builtin_name",
           "plugin_of", "plugin_fresh", "build_plugin", "builtin_class", "default_model"]

#: built-in steering laws: name -> "module:Class"
BUILTIN_CONTROLLERS: dict[str, str] = {
    "computed-torque": "controllers.computed_torque:ComputedTorque",
    "pd": "controllers.computed_torque:PDController",
    "sliding-mode": "controllers.sliding_mode:SlidingMode",
    "adaptive-computed-torque": "controllers.adaptive:AdaptiveComputedTorque",
}
#: built-in path trackers: name -> "module:Class"
BUILTIN_TRACKERS: dict[str, str] = {
    "stanley-at-C": "controllers.tracking:StanleyAtC",
    "pure-pursuit": "controllers.pure_pursuit:PurePursuit",
}
ENTRY_POINT_GROUPS = {"controller": "wmr_mj.controllers", "tracker": "wmr_mj.trackers"}


@dataclass(frozen=True)
class PluginSource:
    """Where a law or tracker came from, as its log records it.

    Attributes:
        spec: the name as given (a built-in name, ``FILE.py:Class``, ``module:Class``, an entry point).
        name: the class's ``name`` (what every output calls it).
        origin: 'builtin', 'file', 'module', 'entry-point' or 'instance' (given as an object).
        import_path: ``module:Class``, or ``/absolute/file.py:Class`` for a file.
        params: the parameters it was built with (JSON-able).
        source_sha256: SHA-256 of the file that defines the class (None where there is no file).
    """

    spec: str
    name: str
    origin: str
    import_path: str
    params: Mapping[str, Any] = field(default_factory=dict)
    source_sha256: str | None = None

    def __post_init__(self) -> None:
        refuse_builtin_name(self.name, self.import_path, origin=self.origin)

    def to_dict(self) -> dict[str, Any]:
        return {"spec": self.spec, "name": self.name, "origin": self.origin, "import_path": self.import_path,
                "params": dict(self.params), "source_sha256": self.source_sha256}


def refuse_builtin_name(name: str, import_path: str, *, origin: str) -> None:
    """Refuse a plug-in that takes a built-in's name: every output would call it the built-in (its claim, its
    record, its log). A built-in's own class, given by name or as an object, keeps its name.

    Raises:
        ParameterError: ``name`` is a built-in law's or tracker's and ``import_path`` is not that built-in's class.
    """
    builtin = BUILTIN_CONTROLLERS.get(name, BUILTIN_TRACKERS.get(name))
    if origin != "builtin" and builtin is not None and import_path != builtin:
        raise ParameterError(f"{import_path} takes the built-in name {name!r} (of {builtin}): a plug-in names "
                             "itself, set name = '...' in its class")


def controller_names() -> tuple[str, ...]:
    """Every steering law reachable by name: the built-ins, then installed entry points."""
    return tuple(BUILTIN_CONTROLLERS) + _entry_point_names("controller")


def tracker_names() -> tuple[str, ...]:
    """Every path tracker reachable by name: the built-ins, then installed entry points."""
    return tuple(BUILTIN_TRACKERS) + _entry_point_names("tracker")


def is_builtin(spec: Any, kind: str = "controller") -> bool:
    return isinstance(spec, str) and spec in (BUILTIN_CONTROLLERS if kind == "controller" else BUILTIN_TRACKERS)


def _entry_point_names(kind: str) -> tuple[str, ...]:
    return tuple(sorted(ep.name for ep in entry_points(group=ENTRY_POINT_GROUPS[kind])))


def parse_params(items: Iterable[str] | Mapping[str, Any] | None, *, option: str = "--controller-param"
                 ) -> dict[str, Any]:
    """NAME=VALUE strings as a mapping (a value that parses as JSON is read as JSON, else kept as text).

    Raises:
        ParameterError: an item without '=' or with an empty name, or a name given twice.
    """
    if items is None:
        return {}
    if isinstance(items, Mapping):
        return dict(items)
    out: dict[str, Any] = {}
    for item in items:
        name, sep, text = str(item).partition("=")
        name = name.strip()
        if not sep or not name or not name.isidentifier():
            raise ParameterError(f"{option} {item!r} is not accepted: NAME=VALUE with NAME a Python identifier, "
                                 "e.g. k=2.5")
        if name in out:
            raise ParameterError(f"{option}: {name!r} is given twice")
        try:
            out[name] = json.loads(text)
        except ValueError:
            out[name] = text
    return out


def source_hash(cls: type) -> str | None:
    """SHA-256 of the file that defines ``cls``; None where it has none (built in C, made in a REPL)."""
    try:
        path = inspect.getsourcefile(cls)
    except (TypeError, OSError):  # built in C; a class of a __main__ without a file (a REPL, python -c)
        return None
    if path is None or not Path(path).is_file():
        return None
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _from_file(path_text: str, class_name: str, kind: str) -> tuple[type, str]:
    path = Path(path_text).expanduser()
    if not path.is_file():
        raise ParameterError(f"{kind} file {path_text!r} does not exist; give FILE.py:Class with FILE.py a Python file")
    path = path.resolve()
    module_name = "wmr_mj_plugin_" + hashlib.sha256(str(path).encode()).hexdigest()[:12]
    module = sys.modules.get(module_name)
    if module is None or getattr(module, "__file__", None) != str(path):
        spec = importlib.util.spec_from_file_location(module_name, path)
        if spec is None or spec.loader is None:
            raise ParameterError(f"{kind} file {path_text!r} cannot be imported as Python")
        module = importlib.util.module_from_spec(spec)
        sys.modules[module_name] = module  # dataclasses and pickling look the module up by name
        try:
            spec.loader.exec_module(module)
        except Exception as exc:  # noqa: BLE001  (any error of the user's file: one line, naming it)
            del sys.modules[module_name]
            raise ParameterError(f"{kind} file {path_text!r} fails to import: {type(exc).__name__}: {exc}") from None
    cls = getattr(module, class_name, None)
    if cls is None:
        found = sorted(n for n, v in vars(module).items() if isinstance(v, type) and v.__module__ == module_name)
        raise ParameterError(f"{kind} file {path_text!r} has no class {class_name!r}; classes there: "
                             f"{', '.join(found) or 'none'}")
    return cls, f"{path}:{class_name}"


def _from_module(module_name: str, class_name: str, kind: str) -> tuple[type, str]:
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise ParameterError(f"{kind} module {module_name!r} cannot be imported ({exc}); give module:Class of an "
                             "installed module, or FILE.py:Class") from None
    except Exception as exc:  # noqa: BLE001
        raise ParameterError(f"{kind} module {module_name!r} fails to import: {type(exc).__name__}: {exc}") from None
    obj: Any = module
    for part in class_name.split("."):
        obj = getattr(obj, part, None)
        if obj is None:
            raise ParameterError(f"{kind} module {module_name!r} has no {class_name!r}")
    return obj, f"{module_name}:{class_name}"


def _form_of(spec: str, kind: str) -> tuple[str, str, str]:
    """How a name is found, without finding it: (form, where, class name).

    form: 'builtin' (where: its module), 'file' (where: the path as given), 'module' (where: the module
    name) or 'entry-point' (where: the name; class name empty). :func:`resolve` imports by this form and
    :func:`locate_source` finds the same file without importing, so both read it here.

    Raises:
        ParameterError: ``where:Class`` with an empty ``where`` or a class name that is not an identifier.
    """
    builtins = BUILTIN_CONTROLLERS if kind == "controller" else BUILTIN_TRACKERS
    if spec in builtins:
        module_name, class_name = builtins[spec].split(":")
        return "builtin", module_name, class_name
    if ":" in spec:
        where, _, class_name = spec.rpartition(":")
        if not class_name.replace(".", "_").isidentifier() or not where:
            raise ParameterError(f"{kind} {spec!r} is not accepted: FILE.py:Class or module:Class")
        if where.endswith(".py") or "/" in where or "\\" in where:
            return "file", where, class_name
        return "module", where, class_name
    return "entry-point", spec, ""


def _entry_point(name: str, kind: str) -> Any:
    """The installed entry point called ``name`` in the kind's group (read from metadata: nothing loaded);
    None where there is none."""
    for ep in entry_points(group=ENTRY_POINT_GROUPS[kind]):
        if ep.name == name:
            return ep
    return None


def _class_of(spec: str, kind: str) -> tuple[type, str, str]:
    """(class, origin, import path) of a name."""
    form, where, class_name = _form_of(spec, kind)
    if form == "file":
        cls, path = _from_file(where, class_name, kind)
        return cls, "file", path
    if form in ("builtin", "module"):
        cls, path = _from_module(where, class_name, kind)
        return cls, form, path
    ep = _entry_point(spec, kind)
    if ep is not None:
        try:
            cls = ep.load()
        except Exception as exc:  # noqa: BLE001
            raise ParameterError(f"{kind} entry point {spec!r} ({ep.value}) fails to load: {exc}") from None
        return cls, "entry-point", ep.value
    names = controller_names() if kind == "controller" else tracker_names()
    if spec.endswith(".py"):
        raise ParameterError(f"{kind} {spec!r} is not accepted: name the class too, FILE.py:Class")
    raise UnknownNameError(kind, spec, names + ("FILE.py:Class", "module:Class"))


def resolve(spec: str, params: Mapping[str, Any] | None = None, *, kind: str = "controller"
            ) -> tuple[type, PluginSource]:
    """The class named by ``spec`` and where it came from (the module docstring lists the forms).

    kind: 'controller' (a :class:`controllers.base.SteeringController`) or 'tracker' (a
    :class:`controllers.tracking.PathTracker`); the class is checked to be one, with the method a
    law needs (:func:`controllers.base.law_methods_missing`).

    Raises:
        UnknownNameError: a name that is neither built in, nor a file or module path, nor an entry point.
        ParameterError: a missing file, a file or module that fails to import, a missing class, a
            class that is not a law (or tracker).
    """
    if not isinstance(spec, str) or not spec.strip():
        raise ParameterError(f"{kind} {spec!r} is not accepted: a name, FILE.py:Class or module:Class")
    cls, origin, import_path = _class_of(spec.strip(), kind)
    if kind == "controller":
        why = law_methods_missing(cls)
    else:
        why = (None if isinstance(cls, type) and issubclass(cls, PathTracker) else
               f"{getattr(cls, '__name__', cls)!r} is not a path tracker: subclass controllers.PathTracker")
    if why is not None:
        raise ParameterError(f"{kind} {spec!r}: {why}")

    source = PluginSource(spec=spec.strip(), name=str(getattr(cls, "name", cls.__name__)), origin=origin,
                          import_path=import_path, params=describe_params(params or {}),
                          source_sha256=source_hash(cls))
    return cls, source


def build(cls: type, params: Mapping[str, Any], context: Any, *, spec: str, kind: str = "controller") -> Any:
    """``cls.from_context(context, **params)``, a bad parameter named in one line.

    Raises:
        ParameterError: a parameter the class does not take, or a value it refuses.
    """
    try:
        return cls.from_context(context, **dict(params))  # type: ignore[attr-defined]
    except TypeError as exc:
        accepted = _accepted(cls)
        raise ParameterError(f"{kind} {spec!r} does not take these parameters ({exc}); accepted: "
                             f"{', '.join(accepted) or 'none'}") from None
    except (ValueError, ArithmeticError) as exc:
        raise ParameterError(f"{kind} {spec!r}: a parameter is refused: {exc}") from None


# --------------------------------------------------------------------------- a run's law and tracker, as given
def plugin_of(given: Any, params: Mapping[str, Any], *, kind: str, recorded: PluginSource | None = None,
              look_up: bool = True) -> tuple[PluginSource | None, type | None]:
    """(source, class) of a run's law (or tracker) as its config gives it, in one call
    (:func:`wmr_mj.sim.coerce.coerce`): (None, None) for a law built from the config's fields
    (:data:`controllers.computed_torque.CONTROLLER_NAMES`) and for no tracker; a name resolved (imported, its
    source hashed: :func:`resolve`); an object's or factory's source from its class (no class returned).

    ``recorded``: the source the config already holds; with ``look_up`` False it is kept where it is still the
    one of ``given`` (:func:`plugin_fresh`), and no class is returned.
    """
    if not look_up and plugin_fresh(given, params, recorded, kind=kind):
        return recorded, None
    if kind == "tracker" and given is None:
        return None, None
    if isinstance(given, str):
        if kind == "controller" and given in CONTROLLER_NAMES:
            return None, None
        cls, source = resolve(given, params, kind=kind)
        return source, cls
    return _instance_source(given, kind), None


def plugin_fresh(given: Any, params: Mapping[str, Any], recorded: PluginSource | None, *, kind: str) -> bool:
    """Whether ``recorded`` is the source of the law (or tracker) ``given`` with ``params``, as given now."""
    if given is None or (kind == "controller" and isinstance(given, str) and given in CONTROLLER_NAMES):
        return recorded is None
    if recorded is None:
        return False
    if isinstance(given, str):
        return recorded.spec == given.strip() and dict(recorded.params) == describe_params(params)
    if not isinstance(given, SteeringController if kind == "controller" else PathTracker):
        return recorded.origin == "instance"  # a factory: its record, made by calling it once when coerced
    cls = type(given)
    return (recorded.origin == "instance" and recorded.import_path == f"{cls.__module__}:{cls.__qualname__}"
            and dict(recorded.params) == _described(given, kind))


def _described(given: Any, kind: str) -> dict[str, Any]:
    """The parameters an object's ``describe()`` gives, as its PluginSource records them."""
    describe = getattr(given, "describe", None)
    params = {}
    if callable(describe):
        params = {k: v for k, v in describe().items() if k not in (kind, "law")}
    return describe_params(params)


def _instance_source(given: Any, kind: str) -> PluginSource:
    """The PluginSource of a law (or tracker) given as an object or a factory."""
    if callable(given) and not hasattr(given, "describe"):
        given = given()  # a factory (a class or a function): what it builds names the plug-in
    cls = type(given)
    return PluginSource(spec=f"{cls.__module__}:{cls.__qualname__}", name=str(getattr(given, "name", cls.__name__)),
                        origin="instance", import_path=f"{cls.__module__}:{cls.__qualname__}",
                        params=_described(given, kind), source_sha256=source_hash(cls))


def build_plugin(given: Any, params: Mapping[str, Any], *, kind: str, estimate: Any, kp: float, kd: float,
                 model: Any = None, model_source: str = "paper", identified: Any = None,
                 coefficients: Mapping[str, float] | None = None, cls: type | None = None
                 ) -> tuple[Any, frozenset[str]]:
    """(instance, settings read): a fresh instance of a run's law (or tracker) that is not built from the config's
    fields, on the run's build context, in one call. None for no tracker; an object deep-copied (a run never shares
    a law's state); a name built with its parameters on a :class:`controllers.base.BuildContext` of the belief
    ``estimate`` (its voltage limit), the gains kp [1/s^2], kd [1/s] and the reduced model ``model`` (else
    :func:`controllers.computed_torque.model_from_source` of ``model_source``, ``identified``, ``coefficients``),
    ``cls`` its class already found (else resolved here); a factory called. The settings read: the names of the
    context's settings its ``from_context`` read (none for an object or a factory).

    Raises:
        ParameterError: a parameter it does not take, or what was built is not a law (or tracker).
    """
    if given is None:
        return None, frozenset()
    base = SteeringController if kind == "controller" else PathTracker
    if isinstance(given, base):
        return copy.deepcopy(given), frozenset()
    read: frozenset[str] = frozenset()
    if isinstance(given, str):
        found = cls if cls is not None else resolve(given, params, kind=kind)[0]
        if model is None:
            model = model_from_source(model_source, params=estimate, identified=identified, coefficients=coefficients)
        context = BuildContext(model=model, estimate=estimate, voltage_limit=estimate.voltage_limit, kp=kp, kd=kd)
        built = build(found, params, context, spec=given, kind=kind)
        read = frozenset(context.read)
    else:
        built = given()
    if not isinstance(built, base):
        raise ParameterError(f"{kind} {given!r} built {type(built).__name__}, not a controllers.{base.__name__}")
    return built, read


def builtin_class(name: str, kind: str) -> type:
    """The class of a built-in law or tracker (:data:`BUILTIN_CONTROLLERS`, :data:`BUILTIN_TRACKERS`), read from
    its module, which the ``controllers`` package imports: nothing is imported here."""
    builtins = BUILTIN_CONTROLLERS if kind == "controller" else BUILTIN_TRACKERS
    module_name, _, class_name = builtins[name].partition(":")
    return getattr(sys.modules[module_name], class_name)


def default_model(controller: Any, params: Mapping[str, Any] | None = None, *, cls: type | None = None) -> str:
    """The model source a law runs with where the run names none: its class's ``default_model``
    (:attr:`controllers.base.SteeringController.default_model`); 'paper' for computed-torque, pd and a
    factory (its class is known only once built). ``cls``: the plug-in's class, already found."""
    if cls is None and isinstance(controller, str) and is_builtin(controller):
        cls = builtin_class(controller, "controller")
    elif cls is None and isinstance(controller, str) and controller not in CONTROLLER_NAMES:
        cls = resolve(controller, params, kind="controller")[0]
    elif cls is None and isinstance(controller, SteeringController):
        cls = type(controller)
    model = getattr(cls, "default_model", "paper")
    if model not in MODEL_SOURCES:
        raise UnknownNameError(f"default_model of controller {getattr(cls, 'name', controller)!r}", str(model),
                               MODEL_SOURCES)
    return str(model)


def _accepted(cls: type) -> list[str]:
    try:
        sig = inspect.signature(cls)
    except (TypeError, ValueError):
        return []
    return [n for n, p in sig.parameters.items() if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


# --------------------------------------------------------------------------- a recorded plug-in, checked before import


@dataclass(frozen=True)
class LocatedSource:
    """A plug-in's file, found without running any code (:func:`locate_source`).

    Attributes:
        spec: the name it is imported by (a built-in name, ``FILE.py:Class``, ``module:Class``, an entry point).
        form: 'builtin', 'file', 'module' or 'entry-point' (how :func:`resolve` reads ``spec``).
        path: the file import executes for it (a module's own file, a package's ``__init__.py``).
        module: the module it is imported as; None for a file.
        runs_first: the enclosing packages' ``__init__.py`` that import runs before ``path`` (not checked:
            the record hashes one file).
        sha256: the SHA-256 of ``path`` as found now.
    """

    spec: str
    form: str
    path: Path
    module: str | None = None
    runs_first: tuple[Path, ...] = ()
    sha256: str = ""

    def describe(self) -> str:
        """One line: the file, the module it is imported as, what import runs before it."""
        text = str(self.path) if self.module is None else f"{self.path} (module {self.module})"
        if self.runs_first:
            text += "; import runs first " + ", ".join(map(str, self.runs_first))
        return text


def recorded_spec(record: Mapping[str, Any]) -> str:
    """The name a log's plug-in record is found again by: its ``spec``; for a file that is not where the
    spec says (relative to another folder), the absolute path the record holds. This is the name
    :func:`wmr_mj.sim.config.config_from_dict` resolves, so it is the name to check before that import."""
    spec = str(record.get("spec"))
    if record.get("origin") == "file" and not Path(spec.rpartition(":")[0]).is_file():
        spec = str(record.get("import_path"))
    return spec


def locate_source(spec: str, *, kind: str = "controller") -> LocatedSource:
    """The file that :func:`resolve` would import for ``spec``, found without importing or running anything.

    A file is read as given (relative to the working folder); a module is found level by level
    (:func:`wmr_mj._util.modules.find_module_file`: no enclosing package's ``__init__`` runs on the
    way, as it would under ``importlib.util.find_spec``); an entry point is read from the installed
    packages' metadata, not loaded, and its module found likewise.

    Raises:
        ParameterError: a file that is gone, a module or entry point that cannot be found without running
            code, a malformed name.
    """
    form, where, _ = _form_of(spec.strip(), kind)
    if form == "file":
        path = Path(where).expanduser()
        if not path.is_file():
            raise ParameterError(f"{kind} plug-in file {where} is gone")
        path = path.resolve()
        return LocatedSource(spec=spec, form=form, path=path, sha256=_file_hash(path))
    if form == "entry-point":
        ep = _entry_point(where, kind)
        if ep is None:
            raise ParameterError(f"{kind} entry point {where!r} is not installed (group "
                                 f"{ENTRY_POINT_GROUPS[kind]})")
        where = ep.module
    try:
        found = find_module_file(where)
    except ModuleNotLocated as exc:
        raise ParameterError(f"{kind} plug-in {spec!r}: {exc}, by a search that runs no code (a module that is "
                             "gone, or one whose package extends its __path__ when imported)") from None
    return LocatedSource(spec=spec, form=form, path=found.path, module=found.name,
                         runs_first=found.runs_first, sha256=_file_hash(found.path))


def check_recorded_source(record: Mapping[str, Any], *, kind: str = "controller") -> LocatedSource:
    """A log's plug-in record (``controller_plugin``, ``tracker_plugin``) checked against the file it names,
    before anything is imported: the file is found (:func:`locate_source`) and hashed, and must have the
    SHA-256 the record holds.

    Returns:
        The file, to be imported (by :func:`wmr_mj.sim.config.config_from_dict`).

    Raises:
        ParameterError: the file is gone or cannot be found without running code, the record holds no
            SHA-256, or the file's SHA-256 differs from the record's (one line: the file, both prefixes).
    """
    name = record.get("name")
    recorded = str(record.get("source_sha256") or "")
    try:
        located = locate_source(recorded_spec(record), kind=kind)
    except ParameterError as exc:
        raise ParameterError(f"{exc}: the {kind} {name!r} of the log is not imported (the record's SHA-256 "
                             f"{_prefix(recorded)}, found: no file)") from None
    if not recorded:
        raise ParameterError(f"the {kind} plug-in {name!r} ({located.path}) has no SHA-256 in the log's record, so "
                             "its source cannot be checked: not imported")
    if located.sha256 != recorded:
        elsewhere = ("; or the class is defined in another file than its module's, which cannot be found without "
                     "running code" if located.module is not None else "")
        raise ParameterError(f"the {kind} plug-in {name!r} ({located.path}) has changed since it ran: its file's "
                             f"SHA-256 is {_prefix(located.sha256)}, the record's {_prefix(recorded)}; not imported "
                             f"(restore that source to reproduce the run{elsewhere})")
    return located


def _file_hash(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _prefix(sha256: str) -> str:
    """A SHA-256 as a message shows it: its first 12 hex digits."""
    return f"{sha256[:12]}..." if sha256 else "none"
