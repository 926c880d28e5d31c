"""What defines a closed-loop run, and what follows from it before any step: the plant's
parameters, the controller's belief, the controller, the reference, the paper's analysis.

Usage::

    from wmr_mj.sim.config import RunConfig, build_reference, controller_for, estimate_parameters
    config = RunConfig(model="nonholonomic", kp=100.0, kd=20.0, m1=700.0)
    controller = controller_for(config, estimate_parameters())
    reference, settle_s = build_reference(config.path, estimate_parameters(), dt=1e-3, duration=35.0)
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from controllers import SteeringController, make_controller, model_from_source
from controllers.computed_torque import CONTROLLER_NAMES, FRICTION_SIGNS, MODEL_SOURCES
from controllers.registry import BUILTIN_CONTROLLERS, BUILTIN_TRACKERS, is_builtin
from wmr_mj._util.checks import as_pair
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware.cart import CART_PARTS, cart_dict
from wmr_mj.params import (
    C80,
    C80_CART,
    M1_NOMINAL,
    M1_RANGE,
    PAPER_KD,
    PAPER_KP,
    C80Parameters,
    parameter_names,
    parameters_of_cart,
    with_params,
)
from wmr_mj.plant.mjcf import STEERING_FRICTION_MODELS, TIMESTEP, TYRE_CONTACT_MODELS
from wmr_mj.sim.signals import signals_from

__all__ = [
    "PATH_NAMES",
    "RunConfig",
    "plant_parameters",
    "estimate_parameters",
    "controller_for",
    "controller_and_settings",
    "declared_parameters",
    "LAW_SETTINGS",
    "tracker_for",
    "has_tracker",
    "plugin_source",
    "controller_name",
    "controller_source",
    "default_model",
    "config_from_dict",
    "estimate_of",
    "build_reference",
    "analysis_box",
    "analysis_for",
    "reference_bounds_of",
    "base_for",
    "cart_file",
]

PATH_NAMES = ("paper-circle", "lane-change", "figure-eight")


@dataclass(frozen=True, kw_only=True)
class RunConfig:
    """Everything that defines a closed-loop run (JSON-able via ``as_dict``)."""

    # the steering law: a name (controllers.registry.controller_names(): computed-torque, pd, sliding-mode,
    # adaptive-computed-torque, an installed entry point), "FILE.py:Class" or "module:Class" (a plug-in, built
    # with controller_params), or a SteeringController object or a factory of one (a library user's own)
    controller: Any = "computed-torque"
    controller_params: Mapping[str, Any] = field(default_factory=dict)  # NAME: value for a plug-in's constructor
    # model source of the controller's estimate (MODEL_SOURCES); None: the law's own default, resolved here
    # once (SteeringController.default_model: 'paper' for computed-torque, pd and a plug-in that names none,
    # 'nonholonomic' for sliding-mode and adaptive-computed-torque)
    model: str | None = None
    # plant chassis mass, kg; None: the cart's nominal m1 (the C80's 650 kg), resolved when the config is checked
    m1: float = None  # type: ignore[assignment]
    duration: float = 35.0  # s
    control_period: float | None = None  # s; None: every physics step
    kp: float = PAPER_KP
    kd: float = PAPER_KD
    friction_sign: str = "measured"
    friction_width: float = 0.0  # rad/s, tanh smoothing of the Coulomb sign (0: exact sign)
    # C's path: one of PATH_NAMES, a packaged route name (wmr_mj.reference.route.route_names()), a
    # .toml/.json route file, or canonical route JSON; a Path or Route object is stored as its canonical JSON
    path: str = "paper-circle"
    plant_overrides: Mapping[str, float] = field(default_factory=dict)  # other plant parameters
    m1_inertia: str = "payload"
    identified: Any = None  # path or mapping from `wmr-mj identify` for model='identified'
    coefficients: Mapping[str, float] | None = None  # for model='explicit'
    box: str = "derived"  # 'derived' from the parameter set over m1_range, or 'paper' (5.1)
    # m1 range of the analysis box, kg; None: the cart's m1 box (the C80's 550-750 kg, (5.1)), resolved likewise
    m1_range: tuple[float, float] = None  # type: ignore[assignment]
    box_ranges: Mapping[str, tuple[float, float]] = field(default_factory=dict)  # other ranged parameters
    seed: int = 0  # recorded; a single run draws nothing at random
    steering_friction: str = "stiction"  # plant's steering friction law: one of STEERING_FRICTION_MODELS
    tyre_contact: str = "stiff"  # plant's tyre-floor contact law: one of TYRE_CONTACT_MODELS
    # a steering disturbance torque and chassis load changes (wmr_mj.sim.signals.Signals, or its JSON
    # form, a mapping or a .json file); None: none (as_dict then has no "signals" key)
    signals: Any = None
    # the Cartesian correction at C (controllers.tracking.StanleyAtC): an outer loop that corrects alpha0;
    # the same as tracker="stanley-at-C"
    correction: bool = False
    # a path tracker (the outer loop on C that writes alpha0): a name (controllers.registry.tracker_names()),
    # "FILE.py:Class", "module:Class", or a PathTracker object or factory; None: the path's own alpha0
    tracker: Any = None
    tracker_params: Mapping[str, Any] = field(default_factory=dict)
    # declared bounds on the reference alpha0 (wmr_mj.reference.bounds.ReferenceBounds, 'paper', a
    # mapping or 'key=value,...'): the certificate and the paper's region are computed for every
    # reference within them, and the run's own is checked against them; None: the run's own bounds
    reference_bounds: Any = None
    # the cart as it is built (wmr_mj.hardware): the steering sensor between the plant and the law (a Sensing,
    # its 'KEY=VALUE,...' form, a mapping, a .json/.toml file or a preset name), the motor's actuation (delay,
    # inductance, current limit) and the gear's play (a Transmission, or its backlash half-width in rad);
    # None: ideal, today's plant (as_dict then has none of these keys)
    sensing: Any = None
    actuation: Any = None
    transmission: Any = None
    # the cart the run is on (wmr_mj.carts): a shipped cart's name, a .toml cart file, a CartFile, or the record
    # as_dict writes ({"name", "version", "path", "text"}); it gives the base parameter set (geometry, masses,
    # motor, supply, stops), the m1 box and the default sensing, actuation and play. None, or a cart whose
    # numbers are the C80's: the C80 (as_dict then has no "cart" key). Kept as that record (the file's text).
    cart: Any = None
    # the plug-ins found once (kind -> PluginSource, kind + "_class" -> the class): imported and hashed when the
    # config is checked or first asked, never again for as_dict, controller_name or the run's build
    _plugins: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state["_plugins"] = {}  # a plug-in's class is found again where the copy is used (a file's module by path)
        return state

    def __post_init__(self) -> None:
        _coerce_inputs(self)  # the convenience path: what from_inputs does (nothing read where nothing needs it)
        _check_fields(self)  # the rest: no file read, no module imported

    @classmethod
    def from_inputs(cls, **user_input: Any) -> RunConfig:
        """The coercer: a RunConfig from what a user gives, the one way a config reads a file or imports user code.

        A built-in law or tracker name, a path of :data:`PATH_NAMES`, typed parts (a ``Sensing``, a
        ``Signals``, ...), spec strings and mappings are checked as they are, with no file read and no module
        imported. What needs either is coerced here (:func:`_coerce_inputs`): a plug-in given by name
        (``FILE.py:Class``, ``module:Class``, an entry point: imported and its source hashed once, its
        ``default_model`` read), a route (a packaged name, a .toml/.json file, a Path or Route object), a
        signals .json file or JSON text, a cart part's .json/.toml file. ``RunConfig(...)`` given such input
        coerces it the same way, through the same function (the convenience path); the commands, the config
        builders of compare and the reports, and :func:`config_from_dict` call this.

        Raises:
            ParameterError, UnknownNameError: what cannot be coerced or is refused, in one line.
        """
        return cls(**user_input)


    def as_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        del d["_plugins"]
        if self.signals is None:
            del d["signals"]  # a run without signals keeps the keys it always had
        else:
            d["signals"] = self.signals.as_dict()
        if not self.correction:
            del d["correction"]  # the configs written before the correction existed, unchanged
        # likewise the plug-in keys, only where a plug-in runs
        for kind in ("controller", "tracker"):
            given = getattr(self, kind)
            if not getattr(self, f"{kind}_params"):
                del d[f"{kind}_params"]
            else:
                d[f"{kind}_params"] = dict(getattr(self, f"{kind}_params"))
            source = plugin_source(self, kind)
            if source is not None:
                d[f"{kind}_plugin"] = source.as_dict()
                if not isinstance(given, str):
                    d[kind] = source.name  # an object: its name (the plugin record says where it came from)
        if self.tracker is None:
            del d["tracker"]
        for name in CART_PARTS:  # likewise: only the parts of the cart that are not ideal
            del d[name]
        d.update(cart_dict(self))
        if self.cart is None:
            del d["cart"]  # likewise: a C80 run's record as it always was
        if self.reference_bounds is None:
            del d["reference_bounds"]  # likewise
        else:
            d["reference_bounds"] = self.reference_bounds.as_dict()
        d["plant_overrides"] = dict(self.plant_overrides)
        d["m1_range"] = list(self.m1_range)
        d["box_ranges"] = {k: list(v) for k, v in self.box_ranges.items()}
        if self.identified is not None and not isinstance(self.identified, (str, bytes)):
            d["identified"] = dict(self.identified.get("identified", self.identified))
        return d

    def replace(self, **changes: Any) -> RunConfig:
        return dataclasses.replace(self, **changes)


def _check_cart(config: RunConfig) -> None:
    """The config's cart as its record (None for the C80), and m1 and m1_range where not given: the cart's.

    Raises:
        ParameterError: a missing file, an unknown name, a file its schema or rules refuse (one line).
    """
    from wmr_mj.carts import CartFile, load_cart

    given = config.cart
    cart: CartFile | None
    if given is None:
        cart = None
    elif isinstance(given, CartFile):
        cart = given
    elif isinstance(given, Mapping):
        if not isinstance(given.get("text"), str):
            raise ParameterError(f"cart = {dict(given)!r} is not accepted: a cart record holds the file's 'text'")
        cart = _cart_of_text(given["text"], str(given.get("path", "<text>")))
    elif isinstance(given, (str, os.PathLike)):
        cart = load_cart(given)
    else:
        raise ParameterError(f"cart = {given!r} is not accepted: a shipped cart's name, a .toml cart file or a "
                             "wmr_mj.carts.CartFile")
    if cart is not None and _numbers_of(cart) == _numbers_of(C80_CART):
        cart = None  # the C80's numbers: the C80, and its record unchanged
    if cart is not None:
        parameters_of_cart(cart)  # a value the parameter set refuses: one line now
    record = None if cart is None else {"name": cart.name, "version": cart.version, "path": str(cart.path),
                                        "text": cart.text}
    object.__setattr__(config, "cart", record)
    if config.m1 is None:
        object.__setattr__(config, "m1", M1_NOMINAL if cart is None else cart.parameters["m1"])
    if config.m1_range is None:
        object.__setattr__(config, "m1_range", M1_RANGE if cart is None else cart.uncertainty["m1"]["m1"])


def _numbers_of(cart: Any) -> tuple[dict, dict, dict]:
    """What a run reads of a cart: its parameters, its boxes and its defaults."""
    return (dict(cart.parameters), {k: dict(v) for k, v in cart.uncertainty.items()}, dict(cart.defaults))


@functools.lru_cache(maxsize=8)
def _cart_of_text(text: str, path: str):
    from wmr_mj.carts import load_cart_text

    return load_cart_text(text, path=path)


def cart_file(config: RunConfig):
    """The config's cart (:class:`wmr_mj.carts.CartFile`), read from its record; None for the C80."""
    if config.cart is None:
        return None
    return _cart_of_text(config.cart["text"], config.cart["path"])


def base_for(config: RunConfig, base: C80Parameters = C80) -> C80Parameters:
    """The base parameter set of a run: the config's cart's where ``base`` is the default (the C80) and the
    config names a cart; else ``base``."""
    cart = cart_file(config)
    if cart is None or base is not C80:
        return base
    return _parameters_of_text(config.cart["text"], config.cart["path"])


@functools.lru_cache(maxsize=8)
def _parameters_of_text(text: str, path: str) -> C80Parameters:
    return parameters_of_cart(_cart_of_text(text, path))


def _coerce_inputs(config: RunConfig) -> None:
    """The config's user inputs as its typed fields (:meth:`RunConfig.from_inputs`): the plug-ins found (a name
    that is not built in imported here, once), the model a law runs with where none is named, the path, the
    signals, the cart's parts and the reference bounds. A built-in name, a named path, a typed part and a spec
    string read no file and import no module.

    Raises:
        ParameterError, UnknownNameError: a plug-in, route, signals or part that cannot be read or is refused.
    """
    _check_cart(config)
    _check_plugin(config, "controller")
    _check_plugin(config, "tracker")
    if config.model is None:
        object.__setattr__(config, "model", default_model(config.controller, config.controller_params,
                                                          cls=config._plugins.get("controller_class")))
    _check_path(config)
    object.__setattr__(config, "signals", signals_from(config.signals))
    _typed_hardware(config)
    from wmr_mj.reference.bounds import reference_bounds_from

    object.__setattr__(config, "reference_bounds", reference_bounds_from(config.reference_bounds))


def _check_fields(config: RunConfig) -> None:
    """The config's typed fields checked, with no file read and no module imported.

    Raises:
        ParameterError, UnknownNameError: an unknown name or a value out of range, in one line.
    """
    if config.model not in MODEL_SOURCES:
        raise UnknownNameError("model source", str(config.model), MODEL_SOURCES)
    if config.friction_sign not in FRICTION_SIGNS:
        raise UnknownNameError("friction sign", config.friction_sign, FRICTION_SIGNS)
    if not isinstance(config.correction, bool):
        raise ParameterError(f"correction = {config.correction!r} is not accepted: True or False")
    if config.box not in ("derived", "paper"):
        raise UnknownNameError("box", config.box, ("derived", "paper"))
    if config.steering_friction not in STEERING_FRICTION_MODELS:
        raise UnknownNameError("steering friction model", config.steering_friction, STEERING_FRICTION_MODELS)
    if config.tyre_contact not in TYRE_CONTACT_MODELS:
        raise UnknownNameError("tyre contact model", config.tyre_contact, TYRE_CONTACT_MODELS)
    for name in ("m1", "duration", "kp", "kd"):
        value = getattr(config, name)
        if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
            raise ParameterError(f"{name} = {value!r} is not accepted; a finite number > 0 is required")
    if config.control_period is not None and (not math.isfinite(config.control_period) or config.control_period <= 0):
        raise ParameterError(f"control_period = {config.control_period!r} s must be finite and > 0")
    _check_period_fits(config.control_period, config.duration)
    lo, hi = config.m1_range
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
        raise ParameterError(f"m1_range = {config.m1_range!r} must be (lo, hi) with 0 < lo < hi")
    _check_hardware(config)
    names = parameter_names()
    for name in config.plant_overrides:
        if name not in names:
            raise UnknownNameError("parameter", name, names)
    _check_motor_constant(config)


def _check_motor_constant(config: RunConfig) -> None:
    """k_b equal to k_i after the overrides (:func:`check_motor_constant`)."""
    overrides = config.plant_overrides
    if "k_i" not in overrides and "k_b" not in overrides:
        return
    base = base_for(config)
    check_motor_constant(overrides.get("k_i", base.k_i), overrides.get("k_b", base.k_b))


def check_motor_constant(k_i: float, k_b: float) -> None:
    """k_b equal to k_i, as a cart file must have them (:mod:`wmr_mj.carts.cartfile`): one flux in SI units, and
    MuJoCo's dcmotor has one constant (it would silently use their geometric mean). Every command that takes
    ``--param`` checks it after its overrides.

    Args:
        k_i: the torque constant, N m/A. k_b: the back-EMF constant, V s/rad.

    Raises:
        ParameterError: they differ by more than a rounding (one line naming both and what is accepted).
    """
    from wmr_mj.carts.cartfile import MOTOR_CONSTANT_RTOL

    if abs(k_b - k_i) > MOTOR_CONSTANT_RTOL * abs(k_i):
        raise ParameterError(f"--param: k_b = {k_b!r} V s/rad and k_i = {k_i!r} N m/A differ; accepted: k_b equal to "
                             "k_i (one flux in SI units; MuJoCo's dcmotor has one constant), e.g. --param "
                             f"k_i={k_i!r} --param k_b={k_i!r}")


def _check_hardware(config: RunConfig) -> None:
    """The config's sensing, actuation and transmission (typed by :func:`_typed_hardware`), each delay checked
    against the grid it runs on: the sensing's against the control period, the actuation's against the physics
    step (MuJoCo's actuator delay).

    Raises:
        ParameterError, UnknownNameError: a malformed spec, a bad value, a delay the grid cannot represent.
    """
    from wmr_mj.hardware import check_cart, is_ideal_cart

    config.sensing.delay_steps(TIMESTEP if config.control_period is None else config.control_period)
    config.actuation.delay_steps(TIMESTEP)
    if not is_ideal_cart(config):  # the limits that need the plant and the duration (hardware.cart.check_cart)
        check_cart(config, plant_parameters(config))


def _typed_hardware(config: RunConfig) -> None:
    """The config's sensing, actuation and transmission as their typed parts (None: ideal); a spec naming a
    .json/.toml file is read here."""
    from wmr_mj.hardware import Actuation, Sensing, Transmission

    cart = cart_file(config)
    for name, cls in (("sensing", Sensing), ("actuation", Actuation), ("transmission", Transmission)):
        given = getattr(config, name)
        if given is None and cart is not None:  # the cart's default sensing, actuation and play
            default = cart.defaults["backlash" if name == "transmission" else name]
            given = Transmission(backlash=default) if name == "transmission" else default
        object.__setattr__(config, name, given if isinstance(given, cls) else cls.from_spec(given))


def _check_plugin(config: RunConfig, kind: str) -> None:
    """A controller (or tracker) that can be built: a name resolves (a plug-in's file and class are found,
    else one line naming them), an object is a law (or tracker), parameters only where a plug-in takes them."""
    from controllers.base import SteeringController
    from controllers.tracking import PathTracker

    given, params = getattr(config, kind), getattr(config, f"{kind}_params")
    if not isinstance(params, Mapping):
        raise ParameterError(f"{kind}_params = {params!r} is not accepted: a mapping NAME -> value")
    object.__setattr__(config, f"{kind}_params", dict(params))
    base = SteeringController if kind == "controller" else PathTracker
    if kind == "tracker" and given is None:
        if params:
            raise ParameterError("tracker_params given without a tracker")
        return
    if kind == "tracker" and config.correction and given != "stanley-at-C":
        raise ParameterError(f"correction=True is the tracker stanley-at-C; it cannot run beside tracker {given!r}")
    if isinstance(given, str):
        if kind == "controller" and given in CONTROLLER_NAMES:
            if params:
                raise ParameterError(f"controller {given!r} takes its settings as RunConfig fields (kp, kd, model, "
                                     f"friction_sign, friction_width), not controller_params {sorted(params)}")
            return
        if is_builtin(given, kind):
            return  # a built-in law or tracker: its class is the registry's (_builtin_class), nothing to import
        _resolved(config, kind)  # a missing file, class or method: one line, before any run
        return
    if isinstance(given, base):
        if params:
            raise ParameterError(f"{kind}_params are for a {kind} given by name; this {kind} is an object")
        return
    if callable(given):
        return  # a factory: called (and checked) where the run builds its parts
    raise ParameterError(f"{kind} = {given!r} is not accepted: a name, FILE.py:Class, module:Class, a "
                         f"{base.__name__} or a factory of one")


def plugin_source(config: RunConfig, kind: str = "controller"):
    """Where the run's controller (or tracker) comes from (:class:`controllers.registry.PluginSource`),
    as its log records it; None for the computed-torque and PD laws built from the config's fields and
    for no tracker. Found once per config (a plug-in imported and its source hashed once)."""
    given = getattr(config, kind)
    if given is None or (kind == "controller" and isinstance(given, str) and given in CONTROLLER_NAMES):
        return None
    if isinstance(given, str):
        return _resolved(config, kind)[1]
    if kind not in config._plugins:
        config._plugins[kind] = _instance_source(given, kind)
    return config._plugins[kind]


def _resolved(config: RunConfig, kind: str) -> tuple[type, Any]:
    """(class, PluginSource) of the config's plug-in given by name, resolved (imported, its source hashed) on
    the first call and kept in the config."""
    from controllers.registry import resolve

    if f"{kind}_class" not in config._plugins:
        cls, source = resolve(getattr(config, kind), getattr(config, f"{kind}_params"), kind=kind)
        config._plugins[f"{kind}_class"], config._plugins[kind] = cls, source
    return config._plugins[f"{kind}_class"], config._plugins[kind]


def _instance_source(given: Any, kind: str):
    """The PluginSource of a law (or tracker) given as an object or a factory."""
    from controllers.base import describe_params
    from controllers.registry import PluginSource, source_hash

    if callable(given) and not hasattr(given, "describe"):
        given = given()  # a factory (a class or a function): what it builds names the plug-in
    cls = type(given)
    describe = getattr(given, "describe", None)
    params = {}
    if callable(describe):
        params = {k: v for k, v in describe().items() if k not in (kind, "law")}
    return PluginSource(spec=f"{cls.__module__}:{cls.__qualname__}", name=str(getattr(given, "name", cls.__name__)),
                        origin="instance", import_path=f"{cls.__module__}:{cls.__qualname__}",
                        params=describe_params(params), source_sha256=source_hash(cls))


def _builtin_class(name: str, kind: str) -> type:
    """The class of a built-in law or tracker (``controllers.registry.BUILTIN_CONTROLLERS``/``BUILTIN_TRACKERS``),
    read from its module, which the ``controllers`` package imports: nothing is imported here."""
    import sys

    builtins = BUILTIN_CONTROLLERS if kind == "controller" else BUILTIN_TRACKERS
    module_name, _, class_name = builtins[name].partition(":")
    return getattr(sys.modules[module_name], class_name)


def default_model(controller: Any, params: Mapping[str, Any] | None = None, *, cls: type | None = None) -> str:
    """The model source a law runs with where the run names none: its class's ``default_model``
    (:attr:`controllers.base.SteeringController.default_model`); 'paper' for computed-torque, pd and a
    factory (its class is known only once built). ``cls``: the plug-in's class, already found."""
    from controllers.base import SteeringController
    from controllers.registry import resolve

    if cls is None and isinstance(controller, str) and is_builtin(controller):
        cls = _builtin_class(controller, "controller")
    elif cls is None and isinstance(controller, str) and controller not in CONTROLLER_NAMES:
        cls = resolve(controller, params, kind="controller")[0]
    elif cls is None and isinstance(controller, SteeringController):
        cls = type(controller)
    model = getattr(cls, "default_model", "paper")
    if model not in MODEL_SOURCES:
        raise UnknownNameError(f"default_model of controller {getattr(cls, 'name', controller)!r}", str(model),
                               MODEL_SOURCES)
    return str(model)


def controller_source(config: RunConfig) -> dict[str, Any] | None:
    """Where the run's law comes from as JSON (:func:`plugin_source`'s record, as the MCAP log keeps it: spec,
    name, origin, import path, parameters, the SHA-256 of its source); None for computed-torque and pd, built
    from the config's fields. The ``controller_source`` of every command's JSON."""
    source = plugin_source(config, "controller")
    return None if source is None else source.as_dict()


def controller_name(config: RunConfig) -> str:
    """What every output calls the run's steering law: a built-in's name, a plug-in's ``name``."""
    source = plugin_source(config, "controller")
    return str(config.controller) if source is None else source.name


def _check_path(config: RunConfig) -> None:
    """Accept a path name, a route (name, file, canonical JSON) or a Path/Route object (stored as its
    canonical JSON, so the config stays hashable and JSON-able); a malformed route raises here."""
    p = config.path
    if isinstance(p, str) and p in PATH_NAMES:
        return  # a named path: nothing to read
    from wmr_mj.reference.paths import Path
    from wmr_mj.reference.route import Route, is_route_spec, load_route, route_from_path, route_names

    if isinstance(p, Path):
        object.__setattr__(config, "path", route_from_path(p).text)
    elif isinstance(p, Route):
        object.__setattr__(config, "path", p.text if p.source == "<text>" or not os.path.isfile(p.source)
                           else p.source)
    elif not isinstance(p, str):
        raise ParameterError(f"path = {p!r} is not accepted: a path name, a route file or a Path")
    elif p not in PATH_NAMES:
        if not is_route_spec(p):
            raise UnknownNameError("path", p, PATH_NAMES + route_names() + ("<route file .toml/.json>",))
        load_route(p)  # malformed: ParameterError naming the file and the segment


def _check_period_fits(control_period: float | None, duration: float) -> None:
    """A control period the run holds a whole number of times (at least once), else ParameterError.

    A longer period would run one control step for the whole duration (sup|E| = 0: judged
    inside), and one that does not divide it would silently change the run's length.
    control_period None: the physics step.
    """
    period = TIMESTEP if control_period is None else control_period
    what = (f"control_period = {period:g} s" if control_period is not None
            else f"the physics step ({period:g} s, the default control period)")
    if period > duration:
        raise ParameterError(f"{what} is longer than the run (duration = {duration:g} s); give --control-period "
                             f"<= --duration and a whole fraction of it (e.g. 0.001-0.1 s)")
    n = round(duration / period)
    if abs(n * period - duration) > 1e-9 * max(1.0, duration):
        fix = f"give --duration {n * period:g}" + (" or a --control-period that divides it"
                                                   if control_period is not None else "")
        raise ParameterError(f"the run's duration = {duration:g} s is not a whole multiple of {what} "
                             f"({duration / period:.6g} periods); {fix}")


def plant_parameters(config: RunConfig, base: C80Parameters = C80) -> C80Parameters:
    """The plant's parameter set: base (the config's cart's where it is the C80, :func:`base_for`) with m1 and the
    overrides (mass and inertia consistent)."""
    base = base_for(config, base)
    return with_params(base, m1_inertia=config.m1_inertia, m1=config.m1, **dict(config.plant_overrides))


def estimate_parameters(base: C80Parameters = C80) -> C80Parameters:
    """The controller's belief: the nominal parameter set (m1 = 650 kg)."""
    return base


def build_reference(path: str, params: C80Parameters, *, dt: float, duration: float):
    """(reference, settle_s) for a path of C on a grid of step dt: a named path (PATH_NAMES) or
    a route (a packaged route name, a route file, canonical route JSON; a closed route is
    repeated lap after lap to fill the duration).

    settle_s is when the entry transient ends: for the paper's circle, the
    time C enters the circle; 0 for the other paths.

    The last :data:`REFERENCE_CACHE_SIZE` references are kept (a Reference's arrays are read-only):
    runs that share a path, as a comparison's scenarios on one path or a sweep's chunks do, build it
    once (it costs about a quarter of a 35 s run's physics). A route file is keyed by its
    modification time and size as well as its name, so an edited file is read again.
    """
    file_key = None
    if path not in PATH_NAMES and not path.lstrip().startswith("{") and os.path.isfile(path):
        st = os.stat(path)
        file_key = (os.path.abspath(path), st.st_mtime_ns, st.st_size)
    return _cached_reference(path, file_key, params, float(dt), float(duration))


#: references kept by :func:`build_reference`
REFERENCE_CACHE_SIZE = 16


@functools.lru_cache(maxsize=REFERENCE_CACHE_SIZE)
def _cached_reference(path: str, file_key: tuple | None, params: C80Parameters, dt: float, duration: float):
    return _build_reference(path, params, dt=dt, duration=duration)


#: the named path lane-change: a lead-in line, the lane change (lateral offset over a length), then a line that
#: fills the duration [m]
LANE_CHANGE_LEAD_IN_M, LANE_CHANGE_OFFSET_M, LANE_CHANGE_LENGTH_M = 0.5, 0.5, 4.0


def manoeuvre_length(path: str) -> float | None:
    """The length [m] of C's reference a run of the named ``path`` must drive for its verdict to judge the whole
    manoeuvre: lane-change's lead-in and lane change (the line after it only fills the duration); None for a
    path that refuses a duration too short for it (paper-circle), a closed one (figure-eight) or a route (whose
    own length :func:`wmr_mj.reference.route.route_length` gives)."""
    if path == "lane-change":
        return LANE_CHANGE_LEAD_IN_M + LANE_CHANGE_LENGTH_M
    return None


def _build_reference(path: str, params: C80Parameters, *, dt: float, duration: float):
    """:func:`build_reference` without the cache."""
    from wmr_mj.reference import paths as ref

    if path not in PATH_NAMES:
        from wmr_mj.reference.route import is_route_spec, load_route, route_names, route_reference

        if not is_route_spec(path):
            raise UnknownNameError("path", path, PATH_NAMES + route_names() + ("<route file .toml/.json>",))
        return route_reference(load_route(path), params, dt=dt, duration=duration), 0.0
    if path == "paper-circle":
        p = ref.paper_circle(params, duration=duration)
    elif path == "lane-change":
        p = (ref.line(LANE_CHANGE_LEAD_IN_M) + ref.lane_change(LANE_CHANGE_OFFSET_M, LANE_CHANGE_LENGTH_M)
             + ref.line(max(duration * params.V_A, 1.0)))
    elif path == "figure-eight":
        p = ref.line(0.5) + ref.figure_eight(1.5, laps=max(1, int(duration * params.V_A / 20.0) + 1))
    else:
        raise UnknownNameError("path", path, PATH_NAMES)
    reference = ref.make_reference(p, params, dt=dt, duration=duration)
    settle_s = 0.0
    if path == "paper-circle":
        circle_start = float(p.starts[-2])  # starts ends with the total length
        reached = np.nonzero(np.asarray(reference.s) >= circle_start)[0]
        settle_s = float(reference.t[reached[0]]) if reached.size else float(reference.t[-1])
    return reference, settle_s


def analysis_box(config: RunConfig, params: C80Parameters = C80):
    """The parameter box of the analysis: the paper's (5.1), or derived from ``params`` over
    the config's m1 range (and box ranges) with the model the controller's source stands on
    ('nonholonomic' for nonholonomic and identified, 'paper' otherwise)."""
    from wmr_mj.analysis.plant_box import derived_box
    from wmr_mj.analysis.robustness import ParameterBox

    if config.box == "paper":
        return ParameterBox.paper()
    box_model = "nonholonomic" if config.model in ("nonholonomic", "identified") else "paper"
    return derived_box(params, as_pair(config.m1_range), config.m1_inertia,
                       tuple((k, as_pair(v)) for k, v in config.box_ranges.items()), model=box_model)


def analysis_for(config: RunConfig, reference, params: C80Parameters = C80, *, estimate=None):
    """The robustness analysis (4.17)-(4.23) for the run's box, gains and reference bounds.

    estimate: the controller's coefficients (P^, C_V^, F^, K^); the parameter
    errors are then truth-anywhere-in-the-box minus this estimate. None: the
    estimate is anywhere in the box too, as in the paper's (4.2).
    """
    from wmr_mj.analysis.robustness import analyse
    from wmr_mj.reference.bounds import ReferenceBounds

    box = analysis_box(config, params)
    b = reference_bounds_of(config, reference)
    bounds = ReferenceBounds(alpha_ddot_max=max(b.alpha_ddot_max, 1e-12), alpha_dot_max=max(b.alpha_dot_max, 1e-12),
                             sin_cos3_max=max(b.sin_cos3_max, 1e-12))
    return analyse(box, kp=config.kp, kd=config.kd, bounds=bounds, estimate=estimate)



def reference_bounds_of(config: RunConfig, reference):
    """The reference bounds the run's analyses are computed for: the declared ones
    (``config.reference_bounds``), else the run's own reference's (``reference.bounds()``)."""
    return reference.bounds() if config.reference_bounds is None else config.reference_bounds


def controller_for(config: RunConfig, params: C80Parameters) -> SteeringController:
    """A fresh instance of the controller ``config`` runs, built on ``params`` (the controller's belief,
    see :func:`estimate_parameters`): the computed-torque and PD laws from the config's fields, a plug-in
    from its name and ``controller_params`` (``from_context``), an object as a deep copy (a run never
    shares a law's state with another), a factory by calling it.

    Raises:
        UnknownNameError: an unknown controller or model source.
        ParameterError: a plug-in that cannot be built (a parameter it does not take, a factory that
            returns no SteeringController).
    """
    return controller_and_settings(config, params)[0]


#: The RunConfig fields that configure a steering law beside its own parameters (``--model``, ``--kp``,
#: ``--kd``, ``--friction-sign``, ``--friction-width``): the computed-torque law reads them all.
LAW_SETTINGS = ("model", "kp", "kd", "friction_sign", "friction_width")
#: The ones the PD law reads (it has no Coulomb compensation).
_PD_SETTINGS = ("model", "kp", "kd")


def controller_and_settings(config: RunConfig, params: C80Parameters) -> tuple[SteeringController, frozenset[str]]:
    """:func:`controller_for`, and the names of :data:`LAW_SETTINGS` the law reads: all of them for the
    computed-torque law, model, kp and kd for PD; for a law built by name, those of its build context
    (``controllers.base.BuildContext``) its ``from_context`` read; none for an object or a factory.
    Only these describe the law in its outputs (the others' values were never used)."""
    given = config.controller
    model = model_from_source(str(config.model), params=params, identified=config.identified,
                              coefficients=config.coefficients)
    if isinstance(given, str) and given in CONTROLLER_NAMES:
        law = make_controller(given, model, kp=config.kp, kd=config.kd,
                              friction_sign=config.friction_sign, friction_width=config.friction_width)
        return law, frozenset(_PD_SETTINGS if given == "pd" else LAW_SETTINGS)
    read: set[str] = set()
    law = _plugin_for(config, params, "controller", given, config.controller_params, SteeringController, model,
                      read=read)
    return law, frozenset(read)


def declared_parameters(spec: str) -> frozenset[str]:
    """The keyword parameters the law named ``spec`` (a built-in name, FILE.py:Class, module:Class) declares
    in its constructor or its ``from_context`` (which a run's ``controller_params`` may set)."""
    import inspect

    from controllers.registry import resolve

    cls, _ = resolve(spec, kind="controller")
    names: set[str] = set()
    for fn in (cls, getattr(cls, "from_context", cls)):
        try:
            sig = inspect.signature(fn)
        except (TypeError, ValueError):
            continue
        names.update(n for n, p in sig.parameters.items()
                     if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and n not in ("self", "cls", "context"))
    return frozenset(names)


def tracker_for(config: RunConfig, params: C80Parameters):
    """A fresh instance of the run's path tracker (:class:`controllers.tracking.PathTracker`), None without one;
    built as :func:`controller_for` builds a plug-in."""
    from controllers.tracking import PathTracker

    given = "stanley-at-C" if config.tracker is None and config.correction else config.tracker
    if given is None:
        return None
    return _plugin_for(config, params, "tracker", given, config.tracker_params, PathTracker)


def _plugin_for(config: RunConfig, params: C80Parameters, kind: str, given: Any, plugin_params: Mapping[str, Any],
                base: type, model: Any = None, read: set[str] | None = None) -> Any:
    """A fresh instance of a plug-in (law or tracker): an object deep-copied, a name resolved and built with its
    parameters on the run's context (``model``: the run's reduced model, built here where None), a factory
    called; checked to be a ``base``. ``read``: a set given here receives the context's settings the build
    read (``BuildContext.read``)."""
    import copy

    from controllers.base import BuildContext
    from controllers.registry import build, resolve

    if isinstance(given, base):
        return copy.deepcopy(given)
    if isinstance(given, str):
        cls = _resolved(config, kind)[0] if given == getattr(config, kind) else resolve(given, plugin_params,
                                                                                         kind=kind)[0]
        if model is None:
            model = model_from_source(str(config.model), params=params, identified=config.identified,
                                      coefficients=config.coefficients)
        context = BuildContext(model=model, estimate=params, voltage_limit=params.voltage_limit, kp=config.kp,
                               kd=config.kd)
        built = build(cls, plugin_params, context, spec=given, kind=kind)
        if read is not None:
            read.update(context.read)
    else:
        built = given()
    if not isinstance(built, base):
        raise ParameterError(f"{kind} {given!r} built {type(built).__name__}, not a controllers.{base.__name__}")
    return built


def has_tracker(config: RunConfig) -> bool:
    """Whether the run has an outer loop on C (a tracker, or the correction)."""
    return config.tracker is not None or bool(config.correction)


def estimate_of(controller: SteeringController) -> dict[str, float] | None:
    """The coefficients the paper's analysis takes as the law's estimate (P^, C_V^, F^, K^), where the law
    is the paper's family (:meth:`~controllers.computed_torque.ComputedTorque.paper_estimate`); None: the
    paper's (4.2), the estimate anywhere in the box."""
    method = getattr(controller, "paper_estimate", None)
    return method() if callable(method) else None


def config_from_dict(obj: Mapping[str, Any]) -> RunConfig:
    """The RunConfig of ``RunConfig.as_dict()`` (after a JSON round trip: lists back to tuples).

    A plug-in (``controller_plugin``, ``tracker_plugin``) is found again by its name, else by the
    absolute import path the record holds (a file named relative to another folder), and its source
    must be the one recorded.

    Raises:
        ParameterError: a plug-in given as an object (it cannot be rebuilt from JSON), one whose file
            or module is gone, or whose source has changed since the record was written (its SHA-256).
    """
    d = dict(obj)
    d["m1_range"] = tuple(d["m1_range"])  # a record always holds m1 and m1_range, the cart's where not given
    d["box_ranges"] = {k: tuple(v) for k, v in d.get("box_ranges", {}).items()}
    for kind in ("controller", "tracker"):
        record = d.pop(f"{kind}_plugin", None)
        if record is not None:
            d[kind] = _plugin_again(kind, record)
    return RunConfig.from_inputs(**d)


def _plugin_again(kind: str, record: Mapping[str, Any]) -> str:
    """The name a recorded plug-in is found by now, its source checked against the record."""
    from controllers.registry import resolve

    if record.get("origin") == "instance":
        raise ParameterError(f"the {kind} {record.get('name')!r} was given as an object "
                             f"({record.get('import_path')}); it cannot be rebuilt from the record: give it by "
                             "name, FILE.py:Class or module:Class to make runs that can be replayed and resumed")
    spec = str(record.get("spec"))
    if record.get("origin") == "file":
        where = spec.rpartition(":")[0]
        if not os.path.isfile(where):
            spec = str(record.get("import_path"))  # the absolute path it was imported from
    params = record.get("params") or {}
    _, now = resolve(spec, params, kind=kind)
    if record.get("source_sha256") and now.source_sha256 != record["source_sha256"]:
        raise ParameterError(f"the {kind} {record.get('name')!r} ({now.import_path}) has changed since it ran: its "
                             f"source's SHA-256 is {str(now.source_sha256)[:12]}..., the record's "
                             f"{str(record['source_sha256'])[:12]}...; restore that source to reproduce the run")
    return spec
