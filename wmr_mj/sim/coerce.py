"""The coercer: what a user gives a run (names, files, plug-ins) as a :class:`~wmr_mj.sim.config.RunConfig`'s
typed fields -- the one place a config reads a file or imports user code.

A ``RunConfig`` is data: constructing or ``replace``-ing one checks its values and reads nothing. A field may
hold a reference that needs a file or an import to become its typed value (a cart's name or file, a plug-in's
``FILE.py:Class``, a route file, a signals or sensing file); :func:`coerce` reads each once and returns the
config with every field typed: the cart as its record (name, version, path, text), m1 and the m1 box the cart's
where not given, each plug-in's :class:`~controllers.registry.PluginSource` (name, import path, SHA-256 of its
source), the law's default model, the sensing, actuation and play as their parts, the signals and the reference
bounds. ``RunConfig.from_inputs`` and :func:`wmr_mj.sim.parts.resolve_run` call it; on a config already coerced
it reads nothing again (a route file is kept by its modification time and size).

This module sits below ``sim.config`` (which calls it): it takes a config as ``Any`` and never imports it.

Usage::

    from wmr_mj.sim.coerce import coerce
    config = coerce(RunConfig(cart="c80-magmotor", controller="examples/my_pid.py:MyPID"))
    config.cart["name"], config.m1, config.controller_plugin.source_sha256
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

from controllers import SteeringController
from controllers.computed_torque import CONTROLLER_NAMES, FRICTION_SIGNS, MODEL_SOURCES
from controllers.registry import PluginSource, default_model, plugin_fresh, plugin_of
from controllers.tracking import PathTracker
from wmr_mj.carts import CartFile, cart_of, cart_of_text
from wmr_mj.carts.provenance import delay_split_unknown
from wmr_mj.errors import DurationError, ParameterError, UnknownNameError
from wmr_mj.hardware import Actuation, Sensing, Transmission, check_cart, is_ideal_cart
from wmr_mj.hardware.assembly import CART_PARTS, cart_dict
from wmr_mj.params import (
    C80,
    C80_CART,
    M1_NOMINAL,
    M1_RANGE,
    C80Parameters,
    check_motor_constant,
    parameter_names,
    parameters_of_cart_text,
    with_params,
)
from wmr_mj.plant.mjcf import STEERING_FRICTION_MODELS, TIMESTEP, TYRE_CONTACT_MODELS
from wmr_mj.reference.bounds import ReferenceBounds, reference_bounds_from
from wmr_mj.reference.named import PATH_NAMES, default_path
from wmr_mj.reference.route import Route, route_of, route_spec_of
from wmr_mj.sim.signals import Signals, signals_from

__all__ = ["PATH_NAMES", "cart_file_of_record", "coerce", "m1_of_overrides",
           "coerce_with_classes", "Coerced", "is_coerced", "check_fields", "route_of", "cart_file", "base_for",
           "plant_parameters", "base_of_record", "plugin_source", "controller_source", "controller_name", "law_name",
           "default_model", "check_motor_constant", "coerced", "record_of", "delay_split_of"]

#: the cart's parts: field name -> its typed class
_PARTS: tuple[tuple[str, Any], ...] = (("sensing", Sensing), ("actuation", Actuation),
                                        ("transmission", Transmission))


# --------------------------------------------------------------------------- the checks of construction (no I/O)
def check_fields(config: Any) -> None:
    """The config's values checked as they are, with no file read and no module imported (``__post_init__``).

    A value still a reference (a cart's name, m1 or the law's model left to the cart or the law, a part's spec)
    is checked where :func:`coerce` types it.

    Raises:
        ParameterError, UnknownNameError: an unknown name or a value out of range, in one line.
    """
    if config.model is not None and config.model not in MODEL_SOURCES:
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
        if name == "m1" and value is None:
            continue  # the cart's, filled by coerce
        if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
            error = DurationError if name == "duration" else ParameterError
            raise error(f"{name} = {value!r} is not accepted; a finite number > 0 is required")
    if config.control_period is not None and (not math.isfinite(config.control_period) or config.control_period <= 0):
        raise ParameterError(f"control_period = {config.control_period!r} s must be finite and > 0")
    check_period_fits(config.control_period, config.duration)
    if config.m1_range is not None:
        lo, hi = config.m1_range
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
            raise ParameterError(f"m1_range = {config.m1_range!r} must be (lo, hi) with 0 < lo < hi")
    names = parameter_names()
    for name in config.plant_overrides:
        if name not in names:
            raise UnknownNameError("parameter", name, names)
    for kind in ("controller", "tracker"):
        params = getattr(config, f"{kind}_params")
        if not isinstance(params, Mapping):
            raise ParameterError(f"{kind}_params = {params!r} is not accepted: a mapping NAME -> value")
    _check_plugin_form(config, "controller")
    _check_plugin_form(config, "tracker")
    if _is_inline(config.signals):
        signals_from(config.signals)  # a mapping or JSON text: refused here (a file is read where it is coerced)
    reference_bounds_from(config.reference_bounds)  # 'paper', a mapping or a spec: no file
    parts = {name: _part_without_io(getattr(config, name), cls) for name, cls in _PARTS}
    if config.cart is None and all(part is not None for part in parts.values()):
        # parts that need no file (typed, a KEY=VALUE spec, a preset, None: ideal) on the C80: their limits are
        # refused here, as coerce would (the typed parts are not kept: coerce types them)
        typed = SimpleNamespace(**parts, duration=config.duration, control_period=config.control_period,
                                plant_overrides=config.plant_overrides)
        m1 = M1_NOMINAL if config.m1 is None else config.m1
        _check_parts(typed, C80, with_params(C80, m1_inertia=config.m1_inertia, m1=m1, **dict(config.plant_overrides)))


def m1_of_overrides(m1: Any, overrides: Any) -> tuple[Any, Any]:
    """(m1, the other overrides): a plant override of m1 (``plant_overrides={"m1": 700}``, ``--param m1=700``) is the
    config's m1 (the one mass of the run: ``with_params`` takes m1 once); ``overrides`` unchanged where it names no m1.

    Raises:
        ParameterError: m1 given as a field and as an override with different values (one line).
    """
    if not isinstance(overrides, Mapping) or "m1" not in overrides:
        return m1, overrides
    try:
        mass = float(overrides["m1"])
    except (TypeError, ValueError):
        raise ParameterError(f"plant_overrides m1 = {overrides['m1']!r} is not accepted; a number of kg") from None
    if m1 is not None and m1 != mass:
        raise ParameterError(f"m1 = {m1!r} kg and plant_overrides m1 = {mass!r} kg (--m1 and --param m1=) give two "
                             "masses; give one of them")
    return mass, {k: v for k, v in overrides.items() if k != "m1"}


def _is_inline(signals: Any) -> bool:
    """Whether signals are given inline (a Signals, a mapping, JSON text), not as a file to read."""
    return (signals is None or isinstance(signals, (Signals, Mapping))
            or (isinstance(signals, str) and signals.lstrip().startswith("{")))


def _part_without_io(given: Any, cls: Any) -> Any:
    """A cart part as its typed value where that reads no file (a part, None: ideal, a number, a mapping, a spec or
    preset that names no .json/.toml file); None where it would read one."""
    if given is None:
        return cls()
    if isinstance(given, cls):
        return given
    if isinstance(given, str) and (".json" in given.lower() or ".toml" in given.lower()):
        return None
    if not isinstance(given, (str, int, float, Mapping)):
        return None  # a path object: a file
    return cls.from_spec(given)


def _check_plugin_form(config: Any, kind: str) -> None:
    """A controller (or tracker) of an accepted form, parameters only where a plug-in takes them (no import)."""
    given, params = getattr(config, kind), getattr(config, f"{kind}_params")
    base = SteeringController if kind == "controller" else PathTracker
    if kind == "tracker" and given is None:
        if params:
            raise ParameterError("tracker_params given without a tracker")
        return
    if kind == "tracker" and config.correction and given != "stanley-at-C":
        raise ParameterError(f"correction=True is the tracker stanley-at-C; it cannot run beside tracker {given!r}")
    if isinstance(given, str):
        if kind == "controller" and given in CONTROLLER_NAMES and params:
            raise ParameterError(f"controller {given!r} takes its settings as RunConfig fields (kp, kd, model, "
                                 f"friction_sign, friction_width), not controller_params {sorted(params)}")
        return
    if isinstance(given, base):
        if params:
            raise ParameterError(f"{kind}_params are for a {kind} given by name; this {kind} is an object")
        return
    if callable(given):
        return  # a factory: called (and checked) where the run builds its parts
    raise ParameterError(f"{kind} = {given!r} is not accepted: a name, FILE.py:Class, module:Class, a "
                         f"{base.__name__} or a factory of one")


def check_period_fits(control_period: float | None, duration: float) -> None:
    """A control period the run holds a whole number of times (at least once), else ParameterError.

    A longer period would run one control step for the whole duration (sup|E| = 0: judged
    inside), and one that does not divide it would silently change the run's length.
    control_period None: the physics step.
    """
    period = TIMESTEP if control_period is None else control_period
    what = (f"control_period = {period:g} s" if control_period is not None
            else f"the physics step ({period:g} s, the default control period)")
    if period > duration:
        raise DurationError(f"{what} is longer than the run (duration = {duration:g} s); give --control-period "
                             f"<= --duration and a whole fraction of it (e.g. 0.001-0.1 s)")
    n = round(duration / period)
    if abs(n * period - duration) > 1e-9 * max(1.0, duration):
        fix = f"give --duration {n * period:g}" + (" or a --control-period that divides it"
                                                   if control_period is not None else "")
        raise DurationError(f"the run's duration = {duration:g} s is not a whole multiple of {what} "
                             f"({duration / period:.6g} periods); {fix}")


# --------------------------------------------------------------------------- the coercer
def coerce(config: Any) -> Any:
    """``config`` with every field typed (the module docstring): each reference read once, here.

    Raises:
        ParameterError, UnknownNameError: a cart, plug-in, route, signals or part that cannot be read or is
            refused, in one line.
    """
    return coerce_with_classes(config, classes=False).config


@dataclass(frozen=True)
class Coerced:
    """What :func:`coerce_with_classes` read: the typed config, and what it found on the way that a run builds on.

    Attributes:
        config: the config with every field typed.
        classes: the class of each plug-in given by name (kind -> class): the run builds its law from it without
            importing it again.
        route: the route C's path names (:class:`wmr_mj.reference.route.Route`), None for a named path.
        base: the run's base parameter set: the cart's (the C80's without one), or the one the caller gave.
        plant: the plant's parameter set: ``base`` with m1 and the overrides.
        record: the config's record (:func:`record_of`: ``RunConfig.to_dict()``), as a run's log keeps it.
        delay_split: how the cart divides its delay between sensing and actuation (:func:`delay_split_of` its
            record): 'unknown' where recordings fixed only the sum, else 'known'.
    """

    config: Any
    classes: Mapping[str, type]
    route: Route | None
    base: C80Parameters
    plant: C80Parameters
    record: Mapping[str, Any]
    delay_split: str


def coerce_with_classes(config: Any, *, classes: bool = True, base: C80Parameters = C80) -> Coerced:
    """:func:`coerce`, with the class of each plug-in given by name and the route, found in the same pass
    (:class:`Coerced`): a run builds its law from them without importing or reading again
    (:func:`wmr_mj.sim.parts.resolve_run`). ``classes`` False: a plug-in whose source the config already holds is
    not looked up again (none returned). ``base``: the base parameter set of the run; where it is the default (the
    C80), the cart's (:func:`base_for`).

    Each reference goes down once to the package that types it, which does its whole job: the signals
    (:mod:`wmr_mj.sim.signals`), each plug-in and the law's default model (:mod:`controllers.registry`), the
    reference bounds (:mod:`wmr_mj.reference.bounds`), the cart (:mod:`wmr_mj.carts`, its parameters checked by
    :mod:`wmr_mj.params`), C's path (:mod:`wmr_mj.reference.route`), the cart's parts (:mod:`wmr_mj.hardware`).
    """
    changes: dict[str, Any] = {"signals": signals_from(config.signals)}
    found: dict[str, type] = {}
    for kind in ("controller", "tracker"):
        params = getattr(config, f"{kind}_params")
        changes[f"{kind}_params"] = dict(params)
        source, cls = plugin_of(getattr(config, kind), params, kind=kind, recorded=getattr(config, f"{kind}_plugin"),
                                look_up=classes)
        changes[f"{kind}_plugin"] = source
        if cls is not None:
            found[kind] = cls
    if config.model is None:
        changes["model"] = default_model(config.controller, config.controller_params, cls=found.get("controller"))
    changes["reference_bounds"] = reference_bounds_from(config.reference_bounds)
    cart = cart_of(config.cart)
    if cart is not None and cart.numbers() == C80_CART.numbers():
        cart = None  # the C80's numbers: the C80, and its record unchanged
    changes["cart"] = None if cart is None else {"name": cart.name, "version": cart.version, "path": str(cart.path),
                                                 "text": cart.text}
    if config.m1 is None:
        changes["m1"] = M1_NOMINAL if cart is None else cart.parameters["m1"]
    if config.m1_range is None:
        changes["m1_range"] = M1_RANGE if cart is None else cart.uncertainty["m1"]["m1"]
    path = default_path(cart) if config.path is None else config.path
    path, route = route_spec_of(path, named=PATH_NAMES)
    changes["path"] = path
    for name, cls_ in _PARTS:
        given = getattr(config, name)
        if given is None and cart is not None:  # the cart's default sensing, actuation and play
            default = cart.defaults["backlash" if name == "transmission" else name]
            given = Transmission(backlash=default) if name == "transmission" else default
        changes[name] = given if isinstance(given, cls_) else cls_.from_spec(given)
    typed = dataclasses.replace(config, **changes)
    # the parameter sets the cart's parts are checked against (the cart's, checked here: a value the parameter set
    # refuses, one line), and the run's: the same where the run's base is the default
    checked_base = base_of_record(typed.cart, C80)
    checked_plant = with_params(checked_base, m1_inertia=typed.m1_inertia, m1=typed.m1, **dict(typed.plant_overrides))
    _check_parts(typed, checked_base, checked_plant)
    plant = checked_plant if base is C80 else with_params(base, m1_inertia=typed.m1_inertia, m1=typed.m1,
                                                          **dict(typed.plant_overrides))
    return Coerced(config=typed, classes=found, route=route, base=checked_base if base is C80 else base, plant=plant,
                   record=record_of(typed), delay_split=delay_split_of(typed.cart))


def record_of(config: Any) -> dict[str, Any]:
    """:meth:`RunConfig.to_dict` of a typed config (:func:`coerce`): its fields as JSON-able data,
    read with nothing coerced (:func:`coerce_with_classes` takes a run's record here, once)."""
    d = dataclasses.asdict(config)
    del d["controller_plugin"], d["tracker_plugin"]
    if config.signals is None:
        del d["signals"]  # a run without signals keeps the keys it always had
    else:
        d["signals"] = config.signals.to_dict()
    if not config.correction:
        del d["correction"]  # the configs written before the correction existed, unchanged
    # likewise the plug-in keys, only where a plug-in runs
    for kind in ("controller", "tracker"):
        given = getattr(config, kind)
        if not getattr(config, f"{kind}_params"):
            del d[f"{kind}_params"]
        else:
            d[f"{kind}_params"] = dict(getattr(config, f"{kind}_params"))
        source = getattr(config, f"{kind}_plugin")
        if source is not None:
            d[f"{kind}_plugin"] = source.to_dict()
            if not isinstance(given, str):
                d[kind] = source.name  # an object: its name (the plugin record says where it came from)
    if config.tracker is None:
        del d["tracker"]
    for name in CART_PARTS:  # likewise: only the parts of the cart that are not ideal
        del d[name]
    d.update(cart_dict(config))
    if config.cart is None:
        del d["cart"]  # likewise: a C80 run's record as it always was
    if config.reference_bounds is None:
        del d["reference_bounds"]  # likewise
    else:
        d["reference_bounds"] = config.reference_bounds.to_dict()
    d["plant_overrides"] = dict(config.plant_overrides)
    d["m1_range"] = list(config.m1_range)
    d["box_ranges"] = {k: list(v) for k, v in config.box_ranges.items()}
    if config.identified is not None and not isinstance(config.identified, (str, bytes)):
        d["identified"] = dict(config.identified.get("identified", config.identified))
    return d


def is_coerced(config: Any) -> bool:
    """Whether every field of ``config`` is typed (no reference left for :func:`coerce` to read)."""
    return (config.m1 is not None and config.m1_range is not None and config.model is not None
            and (config.cart is None or (isinstance(config.cart, Mapping) and isinstance(config.cart.get("text"), str)
                                         and "version" in config.cart))
            and all(isinstance(getattr(config, name), cls) for name, cls in _PARTS)
            and (config.signals is None or isinstance(config.signals, Signals))
            and (config.reference_bounds is None or isinstance(config.reference_bounds, ReferenceBounds))
            and isinstance(config.path, str)
            and all(plugin_fresh(getattr(config, kind), getattr(config, f"{kind}_params"),
                                 getattr(config, f"{kind}_plugin"), kind=kind) for kind in ("controller", "tracker")))


def coerced(config: Any) -> Any:
    """``config`` itself where it is typed, else :func:`coerce`'d (a convenience for a config built directly)."""
    return config if is_coerced(config) else coerce(config)


def _check_parts(config: Any, base: C80Parameters, plant: C80Parameters) -> None:
    """The cart's parts against their grids and the plant (``hardware.assembly.check_cart``), and k_b = k_i after the
    overrides of ``base``."""
    config.sensing.delay_steps(TIMESTEP if config.control_period is None else config.control_period)
    config.actuation.delay_steps(TIMESTEP)
    if not is_ideal_cart(config):  # the limits that need the plant and the duration (hardware.assembly.check_cart)
        check_cart(config, plant)
    overrides = config.plant_overrides
    if "k_i" in overrides or "k_b" in overrides:
        check_motor_constant(overrides.get("k_i", base.k_i), overrides.get("k_b", base.k_b))


# --------------------------------------------------------------------------- the cart
_cart_of_text = cart_of_text  # a cart record's CartFile, the last few kept (wmr_mj.carts.cart_of_text)


def cart_file_of_record(record: Mapping[str, str] | None) -> CartFile | None:
    """The cart (:class:`wmr_mj.carts.CartFile`) of a typed config's cart record; None for the C80."""
    return None if record is None else _cart_of_text(record["text"], record["path"])


def delay_split_of(cart: Mapping[str, str] | None) -> str:
    """How the run's cart divides its delay (its ``[defaults.delay_split]``): 'unknown' for a cart identified from
    recordings at the controller, which fix only the sum of the sensing and actuation delays; 'known' for any other
    cart and the C80. ``cart``: a typed config's cart record (``RunConfig.cart``; None: the C80)."""
    return "unknown" if cart is not None and delay_split_unknown(cart["text"]) else "known"


def cart_file(config: Any) -> Any:
    """The config's cart (:class:`wmr_mj.carts.CartFile`), read from its record; None for the C80."""
    record = coerced(config).cart
    return None if record is None else _cart_of_text(record["text"], record["path"])


def base_for(config: Any, base: C80Parameters = C80) -> C80Parameters:
    """The base parameter set of a run: the config's cart's where ``base`` is the default (the C80) and the
    config names a cart; else ``base``."""
    return base_of_record(coerced(config).cart, base)


def base_of_record(record: Mapping[str, str] | None, base: C80Parameters = C80) -> C80Parameters:
    """:func:`base_for` of a typed config's cart record (``config.cart``): read, nothing coerced."""
    if record is None or base is not C80:
        return base
    return parameters_of_cart_text(record["text"], record["path"])


def plant_parameters(config: Any, base: C80Parameters = C80) -> C80Parameters:
    """The plant's parameter set: base (the config's cart's where it is the C80, :func:`base_for`) with m1 and the
    overrides (mass and inertia consistent)."""
    config = coerced(config)
    base = base_for(config, base)
    return with_params(base, m1_inertia=config.m1_inertia, m1=config.m1, **dict(config.plant_overrides))


# --------------------------------------------------------------------------- the path
# --------------------------------------------------------------------------- plug-ins
def plugin_source(config: Any, kind: str = "controller") -> PluginSource | None:
    """Where the run's controller (or tracker) comes from (:class:`controllers.registry.PluginSource`),
    as its log records it; None for the computed-torque and PD laws built from the config's fields and
    for no tracker. Held by the coerced config (``controller_plugin``, ``tracker_plugin``)."""
    return getattr(coerced(config), f"{kind}_plugin")


def controller_source(config: Any) -> dict[str, Any] | None:
    """Where the run's law comes from as JSON (:func:`plugin_source`'s record, as the MCAP log keeps it: spec,
    name, origin, import path, parameters, the SHA-256 of its source); None for computed-torque and pd, built
    from the config's fields. The ``controller_source`` of every command's JSON."""
    source = plugin_source(config, "controller")
    return None if source is None else source.to_dict()


def controller_name(config: Any) -> str:
    """What every output calls the run's steering law: a built-in's name, a plug-in's ``name``."""
    return law_name(coerced(config))


def law_name(config: Any) -> str:
    """:func:`controller_name` of a typed config (its ``controller_plugin`` found): read, nothing coerced."""
    source = config.controller_plugin
    return str(config.controller) if source is None else source.name
