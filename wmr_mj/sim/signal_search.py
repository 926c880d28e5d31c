"""Worst-case search over signal parameters combined with the parameter box (the hook for falsify).

:func:`config_for` maps a parameter vector to a :class:`wmr_mj.sim.config.RunConfig` with signals:
each name is ``m1``, a plant parameter (``--param``), ``d_max``, ``disturbance.<field>``
(amplitude, t1, t2, bandwidth, seed) or ``load<i>.<field>`` (t, t1, t2, m1, every of the i-th
load change of the template). :func:`search_signals` searches such a space with scipy's
differential evolution, one run at a time (batches do not apply signals), and returns the worst
run with its config, whose ``as_dict()["signals"]`` is the ``--signals`` that reproduces it::

    from wmr_mj.sim.signal_search import search_signals
    from wmr_mj.sim.signals import Signals, Disturbance
    template = Signals(disturbance=Disturbance("pulse", 1.0, t1=10.0, t2=11.0), d_max=1.0)
    found = search_signals(base, template, {"m1": (550, 750), "disturbance.amplitude": (-1, 1),
                                            "disturbance.t1": (5, 20)}, budget=20)
    found.worst_config.as_dict()["signals"], found.worst.sup_E
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from wmr_mj.errors import ParameterError
from wmr_mj.params import parameter_names
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.signals import Signals

__all__ = ["config_for", "search_signals", "SignalSearch"]


def config_for(base: RunConfig, template: Signals, names: Sequence[str], x: Sequence[float]) -> RunConfig:
    """``base`` with ``template``'s signals, each named value of ``x`` set (seeds rounded to integers;
    a pulse's t2 is kept after its t1 by its template width when t1 moves alone)."""
    if len(names) != len(x):
        raise ParameterError(f"{len(names)} names for {len(x)} values")
    dist = template.disturbance
    d_changes: dict[str, Any] = {}
    loads = [dict() for _ in template.loads]  # type: list[dict[str, Any]]
    m1, overrides, d_max = base.m1, dict(base.plant_overrides), template.d_max
    for name, value in zip(names, x):
        v = float(value)
        if name == "m1":
            m1 = v
        elif name == "d_max":
            d_max = v
        elif name.startswith("disturbance."):
            if dist is None:
                raise ParameterError(f"{name}: the template has no disturbance")
            field = name.split(".", 1)[1]
            d_changes[field] = int(round(v)) if field == "seed" else v
        elif name.startswith("load") and "." in name:
            index, field = name[4:].split(".", 1)
            if not index.isdigit() or int(index) >= len(loads):
                raise ParameterError(f"{name}: the template has {len(loads)} load change(s), numbered from 0")
            loads[int(index)][field] = v
        elif name in parameter_names():
            overrides[name] = v
        else:
            raise ParameterError(f"{name!r} is not a search axis: m1, d_max, a plant parameter, "
                                 "disturbance.<field> or load<i>.<field>")
    if dist is not None and d_changes:
        if dist.t2 is not None and "t1" in d_changes and "t2" not in d_changes:
            d_changes["t2"] = d_changes["t1"] + (dist.t2 - dist.t1)
        dist = dataclasses.replace(dist, **d_changes)
    new_loads = tuple(dataclasses.replace(ld, **ch) for ld, ch in zip(template.loads, loads))
    signals = Signals(disturbance=dist, loads=new_loads, d_max=d_max)
    return base.replace(m1=m1, plant_overrides=overrides, signals=signals)


@dataclass(frozen=True)
class SignalSearch:
    """The search's evaluations (names, x, objective, verdict) and its worst run."""

    names: tuple[str, ...]
    evaluations: tuple[tuple[tuple[float, ...], float, str], ...]
    worst_x: tuple[float, ...]
    worst_objective: float
    worst_config: RunConfig
    worst: Any  # the worst run's RunSummary


def _objective(summary: Any, objective: str) -> float:
    if objective == "sup-E":
        return float(summary.sup_E)
    ratio = summary.certificate.E_ratio if summary.certificate is not None else None
    return math.inf if ratio is None else float(ratio)


def search_signals(base: RunConfig, template: Signals, ranges: Mapping[str, tuple[float, float]], *, budget: int,
                   seed: int = 0, objective: str = "E-ratio") -> SignalSearch:
    """The worst run over ``ranges`` (differential evolution, about ``budget`` runs, from ``seed``).

    objective: 'E-ratio' (sup|E|/E_max of the run's certificate, the default) or 'sup-E' [rad].
    """
    from scipy.optimize import differential_evolution

    from wmr_mj.sim.closed_loop import run_closed_loop

    if objective not in ("E-ratio", "sup-E"):
        raise ParameterError(f"objective {objective!r}: one of E-ratio, sup-E")
    names = tuple(ranges)
    if not names or budget < 2:
        raise ParameterError("a search needs at least one range and a budget of 2 runs")
    bounds = [tuple(float(v) for v in ranges[n]) for n in names]
    for n, (lo, hi) in zip(names, bounds):
        if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
            raise ParameterError(f"range of {n} = ({lo}, {hi}): finite lo <= hi required")
    config_for(base, template, names, [lo for lo, _ in bounds])  # a bad axis fails before any run
    pop = max(2, min(5, budget // 2))
    popsize = max(1, math.ceil(pop / len(names)))
    per_generation = popsize * len(names)
    maxiter = max(0, budget // per_generation - 1)
    evaluations: list[tuple[tuple[float, ...], float, str]] = []
    best: dict[str, Any] = {"value": -math.inf}

    def minus_objective(x: Any) -> float:
        cfg = config_for(base, template, names, x)
        s = run_closed_loop(cfg).summary
        value = _objective(s, objective)
        evaluations.append((tuple(float(v) for v in x), value, str(s.verdict)))
        if value > best["value"]:
            best.update(value=value, x=tuple(float(v) for v in x), config=cfg, summary=s)
        return -value if math.isfinite(value) else -1e300

    differential_evolution(minus_objective, bounds, popsize=popsize, maxiter=maxiter, seed=seed, polish=False,
                           init="latinhypercube", tol=0.0, updating="deferred")
    return SignalSearch(names=names, evaluations=tuple(evaluations), worst_x=best["x"],
                        worst_objective=best["value"], worst_config=best["config"], worst=best["summary"])
