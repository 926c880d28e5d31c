"""What defines a closed-loop run, as data: :class:`RunConfig`.

A RunConfig holds what a run is given; constructing or ``replace``-ing one checks its values and reads no file
and imports no module. A field may hold a reference (a cart's name or file, a plug-in's ``FILE.py:Class``, a
route file, a sensing or signals file): :func:`wmr_mj.sim.coerce.coerce` reads it once and types it, called by
:meth:`RunConfig.from_inputs` (the commands) and by :func:`wmr_mj.sim.parts.resolve_run` (a run).

Usage::

    from wmr_mj.sim.run_config import RunConfig
    config = RunConfig(model="nonholonomic", kp=100.0, kd=20.0, m1=700.0)   # data: nothing read
    config = RunConfig.from_inputs(cart="c80-magmotor")                     # the cart file read here, once
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from controllers.registry import PluginSource
from wmr_mj.params import PAPER_KD, PAPER_KP
from wmr_mj.sim.coerce import check_fields, coerce, is_coerced, m1_of_overrides, record_of

__all__ = ["RunConfig"]


def _deprecated_alias(old: str, new: str) -> Callable[..., Any]:
    """A method named ``old`` that warns (DeprecationWarning) and calls the method ``new``."""
    def alias(self: Any, *args: Any, **kwargs: Any) -> Any:
        warnings.warn(f"{type(self).__name__}.{old}() is deprecated and goes in the next release; use {new}() (the "
                      "same dict)", DeprecationWarning, stacklevel=2)
        return getattr(self, new)(*args, **kwargs)

    alias.__name__ = old
    alias.__doc__ = f"Deprecated: :meth:`{new}` (this name warns)."
    return alias


@dataclass(frozen=True, kw_only=True)
class RunConfig:
    """Everything that defines a closed-loop run (JSON-able via ``to_dict``)."""

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
    # None: the cart's own (wmr_mj.reference.named.default_path: its file's [paths] default, else the paper circle where
    # its stops steer it, else a loop derived from them; the paper circle without a cart), resolved where the config
    # is coerced, so that RunConfig(cart=...), a sweep's or a search's base on it, and the commands agree
    path: str = None  # type: ignore[assignment]
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
    # form, a mapping or a .json file); None: none (to_dict then has no "signals" key)
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
    # None: ideal, today's plant (to_dict then has none of these keys)
    sensing: Any = None
    actuation: Any = None
    transmission: Any = None
    # the cart the run is on (wmr_mj.carts): a shipped cart's name, a .toml cart file, a CartFile, or the record
    # to_dict writes ({"name", "version", "path", "text"}); it gives the base parameter set (geometry, masses,
    # motor, supply, stops), the m1 box and the default sensing, actuation and play. None, or a cart whose
    # numbers are the C80's: the C80 (to_dict then has no "cart" key). Kept as that record (the file's text).
    cart: Any = None
    # where each plug-in came from (controllers.registry.PluginSource: its name, import path and the SHA-256 of its
    # source), filled by coerce for a law or tracker that is not built from the config's fields; None until then
    controller_plugin: PluginSource | None = None
    tracker_plugin: PluginSource | None = None

    def __post_init__(self) -> None:
        m1, overrides = m1_of_overrides(self.m1, self.plant_overrides)
        if overrides is not self.plant_overrides:  # an override of m1 is the field m1 (one mass per run)
            object.__setattr__(self, "m1", m1)
            object.__setattr__(self, "plant_overrides", overrides)
        check_fields(self)  # the values as given: no file read, no module imported (coerce reads the references)

    @classmethod
    def from_inputs(cls, **user_input: Any) -> RunConfig:
        """A RunConfig from what a user gives, every field typed: the one way a config reads a file or imports
        user code (:func:`wmr_mj.sim.coerce.coerce`).

        A plug-in given by name (``FILE.py:Class``, ``module:Class``, an entry point) is imported and its source
        hashed once (``controller_plugin``), its ``default_model`` read; a cart (a shipped name, a .toml file) is
        read into its record, m1 and the m1 box the cart's where not given; a route (a packaged name, a .toml/.json
        file, a Path or Route object), a signals .json file or JSON text, a cart part's .json/.toml file are read
        and checked. ``RunConfig(...)`` keeps such input as given (nothing read) until ``resolve_run`` coerces it;
        the commands, the config builders of compare and the reports, and ``config_from_dict`` call this.

        A config that names no path (``path`` None) takes the cart's own (its ``[paths] default``, else one it can
        steer: :func:`wmr_mj.reference.named.default_path`; the paper circle without a cart), here as wherever the
        config is coerced: ``RunConfig(cart=...)`` keeps None as plain data until then.

        Raises:
            ParameterError, UnknownNameError: what cannot be coerced or is refused, in one line.
        """
        return coerce(cls(**user_input))

    # the name of earlier versions, documented in the api reference: one release, with a warning (issue 41)
    as_dict = _deprecated_alias("as_dict", "to_dict")  # deprecated alias: keep

    def to_dict(self) -> dict[str, Any]:
        """The config as JSON-able data (its record in a log and every command's output); a config given a
        reference (a cart's name, a plug-in by name, ...) is coerced first (:func:`wmr_mj.sim.coerce.coerce`)."""
        return record_of(self if is_coerced(self) else coerce(self))

    def replace(self, **changes: Any) -> RunConfig:
        """The config with ``changes`` (field name -> value), nothing else touched, nothing read.

        A field a coercion filled from the cart (the path, m1, the m1 box, the cart's default sensing, actuation
        and play) is a plain value by then: ``RunConfig.from_inputs(cart=A).replace(cart=B)`` keeps A's. To move
        a config to another cart, build it from the inputs again (``RunConfig.from_inputs(cart=B, ...)``) or
        replace on the config as built (``RunConfig(cart=A).replace(cart=B)``, whose fields left None are B's).
        """
        return dataclasses.replace(self, **changes)

