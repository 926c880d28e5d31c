"""The axes a worst-case search may range: plant parameters, signal parameters and C's path.

:func:`config_for` maps a point (one value per axis name) to a :class:`wmr_mj.sim.config.RunConfig`.
Each name is

- ``m1`` or a plant parameter (:func:`wmr_mj.params.parameter_names`): the plant;
- ``d_max``, ``disturbance.<field>`` (amplitude, t1, t2, bandwidth, seed) or ``load<i>.<field>``
  (t, t1, t2, m1, every of the i-th load change): the signals of the template (the base
  config's ``signals``, :mod:`wmr_mj.sim.signals`);

- ``path.k<i>`` (curvature of knot i [1/m]) and ``path.hold`` (s): C's path, a knot path
  (:mod:`wmr_mj.reference.knots`) feasible for the base's declared reference bounds
  (``RunConfig.reference_bounds``, which a path axis requires); knots not ranged are 0 (straight),
  the hold not ranged is :data:`DEFAULT_HOLD_S`;
- ``sensing.<field>``, ``actuation.<field>``, ``transmission.backlash`` (:data:`HARDWARE_AXES`): the cart as
  it is built (:mod:`wmr_mj.hardware`), each a field of the base's part changed; a delay is rounded to the
  grid it runs on (the sensing's to whole control periods, the actuation's to whole 1 ms physics steps) and
  the encoder's resolution to whole ticks (``sensing.encoder_ticks``) or to whole bits
  (``sensing.encoder_bits``: 2**round(bits) ticks), so every drawn value is one a run can have
  (:func:`hardware_values` gives the value a run used);

so a search over plants, signals, paths and the cart at once is a box over these names (``wmr-mj falsify
--range disturbance.amplitude=-1.5:1.5 --path-knots 3``). The config of a point carries its signals with every
parameter, so its ``to_dict()["signals"]`` is the ``--signals`` that reproduces the run::

    from wmr_mj.searches.search_space import config_for
    from wmr_mj.sim.signals import Signals, Disturbance
    template = Signals(disturbance=Disturbance("pulse", 1.0, t1=10.0, t2=11.0), d_max=1.0)
    cfg = config_for(base.replace(signals=template), ["m1", "disturbance.t1"], [700.0, 12.5])
    cfg.to_dict()["signals"]   # {"disturbance": {"kind": "pulse", "amplitude": 1.0, "t1": 12.5, "t2": 13.5}, ...}
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import Any

from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.params import parameter_names
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.reference.knots import knot_path
from wmr_mj.reference.route import route_from_path
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.config import RunConfig, base_for, estimate_parameters
from wmr_mj.sim.signals import Signals

__all__ = ["config_for", "signal_axis", "path_axis", "DISTURBANCE_FIELDS", "LOAD_FIELDS", "DEFAULT_HOLD_S",
           "HARDWARE_AXES", "hardware_axis", "hardware_values", "with_hardware", "check_hardware_range",
           "axis_names_text", "parameter_units"]

#: The fields of a disturbance and of a load change that a search may range.
DISTURBANCE_FIELDS = ("amplitude", "t1", "t2", "bandwidth", "seed")
LOAD_FIELDS = ("t", "t1", "t2", "m1", "every")


#: The hold time [s] of a knot path whose ``path.hold`` is not ranged.
DEFAULT_HOLD_S = 2.0


#: The cart's axes (:mod:`wmr_mj.hardware`): name -> what a drawn value becomes (units, rounding).
HARDWARE_AXES = {
    "sensing.delay": "s, rounded to the nearest whole number of control periods",
    "sensing.encoder_ticks": "ticks per revolution, rounded to the nearest integer (ties to even), >= 1",
    "sensing.encoder_bits": "bits: 2**round(bits) ticks per revolution (a draw over 10:14 gives 10, ..., 14 bits)",
    "sensing.noise": "rad, the noise on alpha: the base's kind (uniform where it has none), this bound or sigma",
    "sensing.velocity_noise": "rad/s, the noise on alpha': the base's kind (uniform where none)",
    "sensing.filter_tau": "s, the low-pass time constant (the base's velocity must be filtered)",
    "actuation.delay": "s, rounded to the nearest whole number of 1 ms physics steps",
    "actuation.inductance": "H, the armature inductance",
    "actuation.current_limit": "A, the current limit (> 0)",
    "transmission.backlash": "rad at the steering axis, the gear's half-width of play",
}
_CART_PREFIXES = ("sensing.", "actuation.", "transmission.")


def parameter_units(names: tuple[str, ...]) -> dict[str, str]:
    """Each ranged parameter -> its unit (m1 in kg, a cart axis as ``HARDWARE_AXES`` says); others none."""
    units = {"m1": "kg"}
    for name in names:
        text = HARDWARE_AXES.get(name)
        if text:
            units[name] = text.split(",")[0].split(":")[0].strip()
    return units


def hardware_axis(name: str) -> bool:
    """Whether ``name`` names a part of the cart (sensing.*, actuation.*, transmission.*); an unknown field of
    one is refused by :func:`with_hardware`, naming :data:`HARDWARE_AXES`."""
    return name.startswith(_CART_PREFIXES)


def _grid_delay(value: float, period: float) -> float:
    return round(value / period) * period  # n * period: whole_periods accepts it exactly


def hardware_values(base: RunConfig, values: Mapping[str, float]) -> dict[str, float]:
    """The value each hardware axis of ``values`` takes in a run of ``base`` (rounded as
    :data:`HARDWARE_AXES` says): what runs.csv and a search record as the run's.

    Raises:
        UnknownNameError: a name that is not in :data:`HARDWARE_AXES`.
        ParameterError: a negative number of bits.
    """
    out: dict[str, float] = {}
    for name, value in values.items():
        if name not in HARDWARE_AXES:
            raise UnknownNameError("hardware axis name", name, HARDWARE_AXES)
        v = float(value)
        if name == "sensing.delay":
            v = _grid_delay(v, TIMESTEP if base.control_period is None else base.control_period)
        elif name == "actuation.delay":
            v = _grid_delay(v, TIMESTEP)
        elif name == "sensing.encoder_ticks":
            v = float(max(1, round(v)))
        elif name == "sensing.encoder_bits":
            if round(v) < 0:
                raise ParameterError(f"sensing.encoder_bits = {value!r} is not accepted; a number of bits >= 0")
            v = float(round(v))
        out[name] = v
    return out


def with_hardware(base: RunConfig, values: Mapping[str, float]) -> RunConfig:
    """``base`` with each hardware axis of ``values`` set in its part (sensing, actuation, transmission), the
    values rounded by :func:`hardware_values`; the part checks the rest (one line naming the culprit).

    Raises:
        UnknownNameError: a name that is not in :data:`HARDWARE_AXES`.
        ParameterError: a value its part refuses (a negative delay, a filter time constant without
            velocity=filtered, a current limit of 0).
    """
    if not values:
        return base
    base = coerced(base)  # a base given directly: its parts typed (wmr_mj.sim.coerce)
    changes: dict[str, dict[str, Any]] = {"sensing": {}, "actuation": {}, "transmission": {}}
    for name, v in hardware_values(base, values).items():
        part, _, key = name.partition(".")
        if name == "sensing.encoder_ticks":
            changes[part]["encoder_ticks"] = int(v)
        elif name == "sensing.encoder_bits":
            changes[part]["encoder_ticks"] = 2 ** int(v)
        elif name in ("sensing.noise", "sensing.velocity_noise"):
            kind = "noise_kind" if key == "noise" else "velocity_noise_kind"
            changes[part][kind] = "uniform" if getattr(base.sensing, kind) == "none" else getattr(base.sensing, kind)
            changes[part][key] = v
        else:
            changes[part][key] = v
    return base.replace(**{part: dataclasses.replace(getattr(base, part), **fields)
                           for part, fields in changes.items() if fields})


def check_hardware_range(base: RunConfig, name: str, lo: float, hi: float) -> None:
    """A hardware axis's range: finite, 0 <= LO <= HI, and both ends a cart its part accepts.

    Raises:
        UnknownNameError, ParameterError: one line naming the axis and what is accepted.
    """
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 <= lo <= hi):
        raise ParameterError(f"range of {name} = {lo!r}:{hi!r} is not accepted: finite 0 <= LO <= HI "
                             f"({HARDWARE_AXES.get(name, 'a hardware axis')})")
    for end in (lo, hi):
        try:
            with_hardware(base, {name: end})
        except ParameterError as exc:  # the part's refusal, named by the range's end that drew it
            raise ParameterError(f"range of {name} = {lo!r}:{hi!r}: at {end!r}, {exc}") from None


def axis_names_text() -> str:
    """The axes a search may range, for a message: m1, the plant's parameters, the signals', the cart's."""
    return (f"m1, a plant parameter ({', '.join(sorted(parameter_names()))}), d_max, disturbance.<field> "
            "(amplitude, t1, t2, bandwidth, seed), load<i>.<field> (t, t1, t2, m1, every), path.k<i>, path.hold, "
            f"or a hardware axis ({', '.join(HARDWARE_AXES)})")


def path_axis(name: str) -> bool:
    """Whether ``name`` is a path axis (path.k<i>, path.hold)."""
    return name == "path.hold" or (name.startswith("path.k") and name[6:].isdigit() and int(name[6:]) >= 1)


def signal_axis(name: str) -> bool:
    """Whether ``name`` is a signal axis (d_max, disturbance.<field>, load<i>.<field>)."""
    return name == "d_max" or name.startswith("disturbance.") or (name.startswith("load") and "." in name)


def config_for(base: RunConfig, names: Sequence[str], x: Sequence[float]) -> RunConfig:
    """``base`` with each named value of ``x`` set: m1, plant parameters, the parameters of
    base's signals (seeds rounded to integers; a pulse's t2 is kept after its t1 by its template
    width when t1 moves alone), C's knot path, and the cart's hardware axes (:func:`with_hardware`).

    Raises:
        ParameterError: a name that is no axis, or a signal axis the base's signals do not have.
    """
    if len(names) != len(x):
        raise ParameterError(f"{len(names)} names for {len(x)} values")
    base = coerced(base)  # a base given directly: its signals, bounds and parts typed (wmr_mj.sim.coerce)
    template = base.signals if base.signals is not None else Signals()
    dist = template.disturbance
    d_changes: dict[str, Any] = {}
    loads = [dict() for _ in template.loads]  # type: list[dict[str, Any]]
    m1, overrides, d_max = base.m1, dict(base.plant_overrides), template.d_max
    knots: dict[str, float] = {}
    hardware: dict[str, float] = {}
    for name, value in zip(names, x):
        v = float(value)
        if path_axis(name):
            knots[name] = v
        elif hardware_axis(name):
            hardware[name] = v
        elif name == "m1":
            m1 = v
        elif name == "d_max":
            d_max = v
        elif name.startswith("disturbance."):
            if dist is None:
                raise ParameterError(f"{name}: the run has no disturbance to vary; give one (e.g. --disturbance "
                                     "kind=pulse,amplitude=1,t1=5,t2=6) and range its fields")
            field = name.split(".", 1)[1]
            if field not in DISTURBANCE_FIELDS:
                raise ParameterError(f"{name!r}: a disturbance has no field {field!r}; accepted: "
                                     f"{', '.join(DISTURBANCE_FIELDS)}")
            d_changes[field] = int(round(v)) if field == "seed" else v
        elif name.startswith("load") and "." in name:
            index, field = name[4:].split(".", 1)
            if not index.isdigit() or int(index) >= len(loads):
                raise ParameterError(f"{name}: the run has {len(loads)} load change(s) (--load), numbered from 0")
            if field not in LOAD_FIELDS:
                raise ParameterError(f"{name!r}: a load change has no field {field!r}; accepted: "
                                     f"{', '.join(LOAD_FIELDS)}")
            loads[int(index)][field] = v
        elif name in parameter_names():
            overrides[name] = v
        else:
            raise ParameterError(f"{name!r} is not a search axis; accepted: {axis_names_text()}")
    if dist is not None and d_changes:
        if dist.t2 is not None and "t1" in d_changes and "t2" not in d_changes:
            d_changes["t2"] = d_changes["t1"] + (dist.t2 - dist.t1)
        dist = dataclasses.replace(dist, **d_changes)
    new_loads = tuple(dataclasses.replace(ld, **ch) for ld, ch in zip(template.loads, loads))
    signals = Signals(disturbance=dist, loads=new_loads, d_max=d_max)
    changes: dict[str, Any] = {}
    if knots:
        changes["path"] = _knot_route(base, knots)
    config = base.replace(m1=m1, plant_overrides=overrides, signals=None if signals.empty else signals, **changes)
    return with_hardware(config, hardware)


def _knot_route(base: RunConfig, values: dict[str, float]) -> str:
    """The canonical route text of the knot path at ``values`` (path.k<i>, path.hold)."""
    if base.reference_bounds is None:
        raise ParameterError("searching C's path (path.k<i>, path.hold) needs declared reference bounds, for which "
                             "the certificate holds and within which every searched path stays: give "
                             "--reference-bounds paper (or alpha_dot_max=..,alpha_ddot_max=..,alpha_max=..)")
    count = max((int(n[6:]) for n in values if n != "path.hold"), default=0)
    curvatures = [values.get(f"path.k{i + 1}", 0.0) for i in range(count)]
    path = knot_path(curvatures, hold_s=values.get("path.hold", DEFAULT_HOLD_S), bounds=base.reference_bounds,
                     params=estimate_parameters(base_for(base)), duration=base.duration)  # the cart's l1 and stops
    return route_from_path(path, name="knots").text
