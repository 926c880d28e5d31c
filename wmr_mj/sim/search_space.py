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

so a search over plants, signals and paths at once is a box over these names (``wmr-mj falsify
--range disturbance.amplitude=-1.5:1.5 --path-knots 3``). The config of a point carries its signals with every
parameter, so its ``as_dict()["signals"]`` is the ``--signals`` that reproduces the run::

    from wmr_mj.sim.search_space import config_for
    from wmr_mj.sim.signals import Signals, Disturbance
    template = Signals(disturbance=Disturbance("pulse", 1.0, t1=10.0, t2=11.0), d_max=1.0)
    cfg = config_for(base.replace(signals=template), ["m1", "disturbance.t1"], [700.0, 12.5])
    cfg.as_dict()["signals"]   # {"disturbance": {"kind": "pulse", "amplitude": 1.0, "t1": 12.5, "t2": 13.5}, ...}
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from wmr_mj.errors import ParameterError
from wmr_mj.params import parameter_names
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.signals import Signals

__all__ = ["config_for", "signal_axis", "path_axis", "DISTURBANCE_FIELDS", "LOAD_FIELDS", "DEFAULT_HOLD_S"]

#: The fields of a disturbance and of a load change that a search may range.
DISTURBANCE_FIELDS = ("amplitude", "t1", "t2", "bandwidth", "seed")
LOAD_FIELDS = ("t", "t1", "t2", "m1", "every")


#: The hold time [s] of a knot path whose ``path.hold`` is not ranged.
DEFAULT_HOLD_S = 2.0


def path_axis(name: str) -> bool:
    """Whether ``name`` is a path axis (path.k<i>, path.hold)."""
    return name == "path.hold" or (name.startswith("path.k") and name[6:].isdigit() and int(name[6:]) >= 1)


def signal_axis(name: str) -> bool:
    """Whether ``name`` is a signal axis (d_max, disturbance.<field>, load<i>.<field>)."""
    return name == "d_max" or name.startswith("disturbance.") or (name.startswith("load") and "." in name)


def config_for(base: RunConfig, names: Sequence[str], x: Sequence[float]) -> RunConfig:
    """``base`` with each named value of ``x`` set: m1, plant parameters, and the parameters of
    base's signals (seeds rounded to integers; a pulse's t2 is kept after its t1 by its template
    width when t1 moves alone).

    Raises:
        ParameterError: a name that is no axis, or a signal axis the base's signals do not have.
    """
    if len(names) != len(x):
        raise ParameterError(f"{len(names)} names for {len(x)} values")
    template = base.signals if base.signals is not None else Signals()
    dist = template.disturbance
    d_changes: dict[str, Any] = {}
    loads = [dict() for _ in template.loads]  # type: list[dict[str, Any]]
    m1, overrides, d_max = base.m1, dict(base.plant_overrides), template.d_max
    knots: dict[str, float] = {}
    for name, value in zip(names, x):
        v = float(value)
        if path_axis(name):
            knots[name] = v
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
            raise ParameterError(f"{name!r} is not a search axis; accepted: m1, a plant parameter "
                                 f"({', '.join(sorted(parameter_names()))}), d_max, disturbance.<field> "
                                 "(amplitude, t1, t2, bandwidth, seed) or load<i>.<field> (t, t1, t2, m1, every)")
    if dist is not None and d_changes:
        if dist.t2 is not None and "t1" in d_changes and "t2" not in d_changes:
            d_changes["t2"] = d_changes["t1"] + (dist.t2 - dist.t1)
        dist = dataclasses.replace(dist, **d_changes)
    new_loads = tuple(dataclasses.replace(ld, **ch) for ld, ch in zip(template.loads, loads))
    signals = Signals(disturbance=dist, loads=new_loads, d_max=d_max)
    changes: dict[str, Any] = {}
    if knots:
        changes["path"] = _knot_route(base, knots)
    return base.replace(m1=m1, plant_overrides=overrides, signals=None if signals.empty else signals, **changes)


def _knot_route(base: RunConfig, values: dict[str, float]) -> str:
    """The canonical route text of the knot path at ``values`` (path.k<i>, path.hold)."""
    from wmr_mj.reference.knots import knot_path
    from wmr_mj.reference.route import route_from_path
    from wmr_mj.sim.config import estimate_parameters

    if base.reference_bounds is None:
        raise ParameterError("searching C's path (path.k<i>, path.hold) needs declared reference bounds, for which "
                             "the certificate holds and within which every searched path stays: give "
                             "--reference-bounds paper (or alpha_dot_max=..,alpha_ddot_max=..,alpha_max=..)")
    count = max((int(n[6:]) for n in values if n != "path.hold"), default=0)
    curvatures = [values.get(f"path.k{i + 1}", 0.0) for i in range(count)]
    path = knot_path(curvatures, hold_s=values.get("path.hold", DEFAULT_HOLD_S), bounds=base.reference_bounds,
                     params=estimate_parameters(), duration=base.duration)
    return route_from_path(path, name="knots").text
