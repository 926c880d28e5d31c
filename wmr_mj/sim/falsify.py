"""Worst-case search: the plant in the uncertainty box that the controller tracks worst.

A robustness claim is only as credible as the worst case anyone looked for. Sweeps
sample the box; ``falsify`` searches it, as falsification tools (S-TaLiRo, Breach) do,
maximising an objective of the closed-loop run over the ranged plant parameters, and the
same number of simulations is spent on a seeded Latin-hypercube sample beside it, so the
search can be judged against chance (``bench/bench_falsify.py`` does so over seeds).

Methods (:data:`METHODS`):

- ``portfolio`` (the default, of ``falsify`` and of ``validate``'s searches): the box's vertices
  first, as one batch: all 2^d where they fit half the budget (:data:`PORTFOLIO_VERTEX_SHARE`) and
  number at most 32 (:data:`PORTFOLIO_MAX_VERTICES`), so that a monotone worst case (a vertex) is
  found exactly (the full box, d = 5: its worst vertex, 0.3927 of E_max, within the first 32 runs of
  any budget >= 64), else a seeded fractional-factorial covering of at most an eighth of the budget
  (:data:`PORTFOLIO_COVER_SHARE`); then CMA-ES (``cmaes``) from the box's centre, moved a quarter of
  a range towards the worse side of each parameter whose main effect over the vertices is
  significant (:func:`screened_start`: the two-level screening of a designed experiment), a
  generation per batch, restarted with twice the population when it stops (IPOP), in whole
  generations up to the local phase; from 200 runs on, that global phase is two independent CMA-ES
  runs from the same start, equal in generations (:func:`portfolio_global_runs`); then a local
  CMA-ES from the worst point found (:func:`portfolio_local_phase`): the last fifth of the budget,
  step 0.05 of each range, below 200 runs, the last three tenths, step 0.02, from 200 on, where the
  second half of it (:func:`portfolio_coordinate_runs`) is coordinate moves of the worst point found
  instead: each parameter moved with probability 1/d (at least one), by a normal step of 0.05 of its
  range (:data:`PORTFOLIO_COORDINATE_STEP`), a generation's worth per batch, the worst found taken
  anew before each batch. Over C's path the high values lie on thin ridges (two adjacent curvature
  knots about 0.075 1/m apart), which a move of the coordinates off a ridge's normal stays on.
  How each part was measured and chosen, on synthetic objectives with known worst cases and on C's
  path with tuning seeds other than the bench's, and what else was tried: the benchmarks guide
  (``docs/guides/benchmarks.md``, "How the portfolio was chosen").
- ``cma``: CMA-ES alone, from the box's centre (the portfolio without the vertices).
- ``vertices-polish``: the box's 2^d vertices first, as one batch, where the budget allows them
  (else a fractional-factorial covering of them, :func:`covering_design`), then scipy's
  Nelder-Mead with bounds from the worst point found, restarted from the next-worst while budget
  is left. At a budget of 48 on the full box, differential evolution was beaten by random sampling
  in 3 of 6 seeds and never reached the worst vertex (0.3927 of E_max), which this finds in 27 runs.
- ``lhs-polish``: a seeded Latin hypercube of half the budget, then the same polish. Over C's path
  (3 knots, the hold, m1; budget 48) the vertices' worst was 0.68 of E_max and random sampling beat
  vertices-polish in 6 of 10 seeds, lhs-polish in 5 of 10.
- ``de``: scipy's differential evolution, a generation per batch (``vectorized=True``).

Each batch of points runs as one batch of simulations (``wmr_mj.sim.sweep.run_configs``:
``mujoco.batch``, or Dask chunks); the polish asks for one point at a time. A budget below one
generation (differential evolution's or CMA-ES's population) is refused before any run.

Where the objective is the certificate's ratio, :attr:`FalsifyResult.tightness` sets the worst
found (a lower bound on the worst case) beside the certificate's E_max (an upper bound): "the worst
found is X of the certificate's bound: the certificate is 1/X times the worst case found"; where X
exceeds 1, "the worst run is X times the claimed bound: the claim is exceeded".

Whatever the objective, a run of either phase that is ``certified-outside`` breaks the law's claim:
:attr:`FalsifyResult.claim_broken` names the one that breaks it most (its parameters), and
:attr:`FalsifyResult.falsified` is then True (``wmr-mj falsify`` prints the banner ``run`` prints and
exits with :data:`wmr_mj.cli._common.CLAIM_BROKEN_EXIT`).

Objectives (:data:`OBJECTIVES`), read from a run's summary by :func:`objective_value`:

- ``certificate``: sup|E| / E_max of the run's certificate (the default);
- ``paper``: sup|E| / E_max of the paper's region;
- ``sup-E``: sup|E| itself, rad;
- ``requirement``: minus the robustness of an STL requirement (``FalsifySpec.requirement``,
  :mod:`wmr_mj.analysis.requirements`): > 0 falsified. These runs go one by one on the engine,
  ``nthread`` at a time (the batch keeps no per-step signals to monitor).

The box (``FalsifySpec.box``) ranges plant parameters and, where the base config has signals
(:mod:`wmr_mj.sim.signals`), their parameters: ``disturbance.amplitude``, ``disturbance.t1``,
``load0.m1``, ... (:mod:`wmr_mj.sim.search_space`). A ranged disturbance amplitude with no
declared ``d_max`` declares the box's largest |amplitude|, one certificate for the whole search.
Runs with signals do not share a batch: they run one by one, ``nthread`` at a time.

Usage::

    from wmr_mj.sim.falsify import FalsifySpec, falsify
    from wmr_mj.params import uncertainty_ranges
    from wmr_mj.sim.closed_loop import RunConfig
    box = uncertainty_ranges("full")  # the certificate covers the declared box: give the base the same ranges
    base = RunConfig.from_inputs(model="nonholonomic", box_ranges={k: v for k, v in box.items() if k != "m1"})
    spec = FalsifySpec(base=base, box=box, budget=256)
    result = falsify(spec)
    print(result.worst.params, result.worst.objective, result.random_worst.objective)

Every evaluation is a run that ``run_closed_loop`` reproduces bit for bit, so the worst
run's parameters (kept at full precision) given back to ``wmr-mj run --m1 X --param
NAME=VALUE ...`` give the same sup|E|; the same seed gives the same search.
"""

from __future__ import annotations

import contextlib
import dataclasses
import itertools
import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE, VERDICTS
from wmr_mj.errors import ParameterError, UnknownNameError, WmrMjError
from wmr_mj.params import parameter_names
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.records import BrokenRun, Record, UnmetAssumption

__all__ = [
    "OBJECTIVES",
    "METHODS",
    "METHOD_LABELS",
    "covering_design",
    "OBJECTIVE_LABELS",
    "FalsifySpec",
    "FalsifyResult",
    "FalsifyReport",
    "WorstRun",
    "RandomWorst",
    "Tightness",
    "BrokenRun",
    "Evaluation",
    "Trace",
    "objective_value",
    "objective_source",
    "population_size",
    "cma_population",
    "portfolio_vertices",
    "portfolio_global_runs",
    "portfolio_coordinate_runs",
    "search_worst",
    "random_worst",
    "falsify",
    "check_runnable",
    "worst_config",
]

OBJECTIVES = ("certificate", "paper", "sup-E", "requirement")
#: Search methods (module docstring): the portfolio (default: vertices, CMA-ES, a local CMA-ES), CMA-ES alone,
#: vertices or a Latin hypercube then a Nelder-Mead polish, differential evolution.
METHODS = ("portfolio", "cma", "vertices-polish", "lhs-polish", "de")
#: What each method does, in a few words (the legend of the search's history plot); a test keeps each
#: label true to the search :func:`search_worst` dispatches the method to.
METHOD_LABELS = {"portfolio": "vertices, then CMA-ES", "cma": "CMA-ES", "vertices-polish": "vertices, then Nelder-Mead",
                 "lhs-polish": "Latin hypercube, then Nelder-Mead", "de": "differential evolution"}
OBJECTIVE_LABELS = {"certificate": "sup|E|/E_max of the certificate", "paper": "sup|E|/E_max of the paper's region",
                    "sup-E": "sup|E| [rad]", "requirement": "-robustness of the requirement (> 0: falsified)"}
MIN_POPULATION = 5  # scipy's differential evolution needs at least 5 members
_POPULATION_OF = {"de": "differential evolution", "cma": "CMA-ES", "portfolio": "CMA-ES"}  # methods with generations


# -- the objective, read from a run's summary ----------------------------------------------

def _ratio(sup: float, bound: Any) -> float | None:
    if bound is None:
        return None
    bound = float(bound)
    return sup / bound if math.isfinite(bound) and bound > 0 else None


def objective_value(summary: Mapping[str, Any], objective: str) -> float | None:
    """The number falsify maximises for one run's summary (None where it is undefined,
    e.g. a region that does not exist). The one place that reads it; see objective_source."""
    if objective not in OBJECTIVES:
        raise UnknownNameError("objective", objective, OBJECTIVES)
    if objective == "sup-E":
        return float(summary["sup_E"])
    if objective == "requirement":
        (req,) = summary["requirements"]
        return None if req["robustness"] is None else -float(req["robustness"])
    if objective == "paper":
        region = summary.get("paper_region")
        if isinstance(region, Mapping) and region.get("E_max") is not None:
            return _ratio(float(summary["sup_E"]), region["E_max"])
        return summary.get("E_ratio")
    certificate = summary.get("certificate")
    if isinstance(certificate, Mapping) and "E_ratio" in certificate:
        return certificate["E_ratio"]
    return summary.get("E_ratio")


def check_objective_applies(law: Any, objective: str) -> None:
    """Refuse, before any run, an objective that says nothing of the run's controller (``law``, the resolved
    run's: :attr:`wmr_mj.sim.parts.RunParts.controller`): the certificate's ratio for a law that states no
    claim, the paper's for a law that is not the paper's.

    Raises:
        ParameterError: naming the controller and the objectives that apply.
    """
    from controllers import SteeringController
    from wmr_mj.sim.config import estimate_of

    if objective not in ("certificate", "paper"):
        return
    if objective == "certificate" and type(law).claim is SteeringController.claim:
        raise ParameterError(f"controller {law.name!r} states no claim, so there is no certificate to search "
                             "against: falsify a requirement (--require STL) or maximise sup|E| (--objective sup-E)")
    if objective == "paper" and estimate_of(law) is None:
        raise ParameterError(f"the paper's region is for its computed-torque law, not controller {law.name!r}: "
                             "falsify a requirement (--require STL) or maximise sup|E| (--objective sup-E)")


def shares_the_base_certificate(base: RunConfig, names: Sequence[str]) -> bool:
    """Whether every run of ``base`` searched over ``names`` is judged by the base's certificate: m1 and plant
    parameters only (the certificate is over the config's box, whatever the run's plant in it), none of
    which reaches the certificate otherwise: the plant's limits (voltage_limit, steering_range), the gear
    ratio i2 where the sensing is not ideal and R_a where the actuation is not (their coverage reads them:
    :func:`wmr_mj.sim.certify.measurement_errors_of`). The cart's, the signals' and the path's axes give
    each run its own."""
    from wmr_mj.sim.search_space import hardware_axis, path_axis, signal_axis

    base = coerced(base)  # a base given directly: its parts typed (wmr_mj.sim.coerce)
    reaching = {"voltage_limit", "steering_range"}
    if not base.sensing.is_ideal or not base.transmission.is_ideal:
        reaching.add("i2")
    if not base.actuation.is_ideal:
        reaching.add("R_a")
    return not any(hardware_axis(n) or signal_axis(n) or path_axis(n) or n in reaching for n in names)


def check_objective_defined(parts: Any, spec: FalsifySpec) -> None:
    """Refuse, before any step, a search whose objective is undefined for every run: the certificate's
    ratio where the base's certificate has no finite bound and every run shares it
    (:func:`shares_the_base_certificate`); ``run`` knows this before it steps, and so does falsify.

    Args:
        parts: ``spec.base`` resolved (:func:`check_runnable`).

    Raises:
        ParameterError: one line naming why there is no bound and what to search instead.
    """
    claim = parts.claim
    if spec.objective != "certificate" or claim is None or not shares_the_base_certificate(spec.base, spec.names):
        return
    if claim.valid and 0.0 < claim.E_max < math.inf and 0.0 < claim.Edot_max:
        return
    why = getattr(claim, "reason", None) or ", ".join(claim.unmet) or "no finite bound"
    raise ParameterError(f"the objective sup|E|/E_max of the certificate is undefined for every run: controller "
                         f"{parts.controller.name!r} has no certificate over this box ({why}; see wmr-mj robustness "
                         "--certificate): search --objective sup-E or a requirement (--require STL) instead")


def undefined_objective_warning(result: FalsifyResult) -> str | None:
    """The warning of a search some of whose runs have no objective (left blank, never the worst): how many
    of each phase, which objective, and what to search where no certificate exists; None when every run
    has one."""
    blank = {phase: sum(e.objective is None for e in evals)
             for phase, evals in (("search", result.search), ("random", result.random))}
    if not any(blank.values()):
        return None
    counts = ", ".join(f"{blank[p]} of {len(evals)} {p} runs" for p, evals in
                       (("search", result.search), ("random", result.random)) if evals)
    objective = result.spec.objective
    text = (f"WARNING: {counts} have no {OBJECTIVE_LABELS[objective]} (left blank: the worst is over the "
            "others only)")
    if objective in ("certificate", "paper"):
        region = "certificate" if objective == "certificate" else "paper's region"
        text += (f"; a run without a {region} (its bound does not exist for that run) may be the worst: "
                 "--objective sup-E searches sup|E| on every run")
    return text


def objective_source(summary: Mapping[str, Any], objective: str) -> str:
    """Which field of the summary :func:`objective_value` read, in words (for the report)."""
    if objective == "sup-E":
        return "sup_E"
    if objective == "requirement":
        return f"-robustness of {summary['requirements'][0]['formula']} (rtamt, runs one by one)"
    if objective == "paper":
        region = summary.get("paper_region")
        if isinstance(region, Mapping) and region.get("E_max") is not None:
            return "sup_E / paper_region.E_max"
        return "E_ratio (the run's analysis region; the summary has no paper_region)"
    certificate = summary.get("certificate")
    if isinstance(certificate, Mapping) and "E_ratio" in certificate:
        return "certificate.E_ratio"
    return ("E_ratio of the run's analysis region: the run summary carries no certificate yet, so the "
            "objective falls back to the region the run is judged by today")


def _verdict(summary: Mapping[str, Any]) -> str:
    verdict = summary.get("verdict")
    if verdict is not None:
        return str(verdict)
    return "inside" if summary.get("inside") else "outside"


# -- the search itself: any evaluate(points) -> values ----------------------------------------

@dataclass(frozen=True)
class Trace:
    """Every point a search evaluated, in order: points (E, d), values (E,) (NaN: undefined),
    generation (E,) (0: the initial population; the random sample is all 0)."""

    points: np.ndarray
    values: np.ndarray
    generation: np.ndarray

    @property
    def best(self) -> int:
        """Index of the largest value (the first of equals); -1 if none is defined."""
        finite = np.where(np.isnan(self.values), -np.inf, self.values)
        return int(np.argmax(finite)) if finite.size and np.isfinite(finite).any() else -1


class _Recorder:
    """Calls evaluate(points (S, d)) -> values (S,), checks the shape, and keeps every batch in order
    (a batch is a generation) for the search's :class:`Trace`."""

    def __init__(self, evaluate: Callable[[np.ndarray], np.ndarray]) -> None:
        self._evaluate = evaluate
        self._points: list[np.ndarray] = []
        self._values: list[np.ndarray] = []
        self._generation: list[np.ndarray] = []
        self.spent = 0  # points evaluated so far

    def __call__(self, batch: np.ndarray) -> np.ndarray:
        v = np.asarray(self._evaluate(batch), dtype=float).reshape(-1)
        if v.shape != (len(batch),):
            raise ValueError(f"evaluate returned {v.shape} values for {len(batch)} points")
        self._generation.append(np.full(len(batch), len(self._points)))
        self._points.append(batch)
        self._values.append(v)
        self.spent += len(batch)
        return v

    def trace(self) -> Trace:
        return Trace(np.concatenate(self._points), np.concatenate(self._values), np.concatenate(self._generation))


def population_size(budget: int, d: int) -> int:
    """Members per generation: 10 per parameter, but at most an eighth of the budget (so
    that at least 8 generations run), and never below scipy's minimum of 5."""
    return max(MIN_POPULATION, min(10 * d, budget // 8))


def _check_budget(budget: int, population: int, what: str = "differential evolution") -> None:
    if isinstance(budget, bool) or not isinstance(budget, int) or budget < 1:
        raise ParameterError(f"budget = {budget!r} is not accepted; give the number of simulations, an integer >= 1")
    if isinstance(population, bool) or not isinstance(population, int) or population < MIN_POPULATION:
        raise ParameterError(f"population = {population!r} is not accepted; {what} needs an "
                             f"integer >= {MIN_POPULATION}")
    if budget < population:
        raise ParameterError(f"budget = {budget} simulations is below one population of {population} ({what} "
                             f"evaluates a whole population per generation); give a budget >= {population}")


def _unit_to_box(unit: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    return bounds[:, 0] + unit * (bounds[:, 1] - bounds[:, 0])


def _streams(seed: int) -> list[np.random.Generator]:
    """Independent generators for the initial population, the evolution and the random sample."""
    return [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(3)]


@contextlib.contextmanager
def _user_errors_unwrapped():
    """scipy wraps what the objective raises in a RuntimeError; give back a WmrMjError (bad input,
    one line at the CLI) as itself."""
    try:
        yield
    except RuntimeError as exc:
        cause = exc.__cause__ or exc.__context__
        if isinstance(cause, WmrMjError):
            raise cause from None
        raise


def search_worst(evaluate: Callable[[np.ndarray], np.ndarray], bounds: np.ndarray, *, budget: int, seed: int = 0,
                 population: int | None = None, method: str = "portfolio") -> Trace:
    """Maximise ``evaluate`` over the box ``bounds`` (d, 2) with ``method`` (:data:`METHODS`).

    evaluate(points (S, d)) -> values (S,), NaN where undefined, is called with a batch of
    points at a time. At most ``budget`` points are evaluated. Seeded: the same seed gives
    the same points. population: members per generation of differential evolution or CMA-ES.
    """
    if method not in METHODS:
        raise UnknownNameError("search method", method, METHODS)
    if method == "de":
        return _search_de(evaluate, bounds, budget=budget, seed=seed, population=population)
    if method in ("portfolio", "cma"):
        return _search_cma(evaluate, bounds, budget=budget, seed=seed, population=population,
                           vertices=method == "portfolio")
    return _search_vertices_polish(evaluate, bounds, budget=budget, seed=seed, first=method.split("-")[0])


def covering_design(d: int, runs: int, rng: np.random.Generator | None = None) -> np.ndarray:
    """Vertices of the unit box (runs, d) in {0, 1}: all 2^d when runs >= 2^d, else a two-level
    fractional factorial 2^(d-p) of 2^k <= runs points (k base factors in full factorial, every
    other factor the product of a subset of them, the largest subsets first: the highest
    resolution this simple construction gives). rng: random sign flips of the columns (a
    fold-over of the design), so that seeds cover different corners."""
    if runs < 1:
        raise ParameterError(f"runs = {runs!r}: a covering design needs at least one point")
    k = min(d, int(math.floor(math.log2(runs))))
    base = np.array(list(itertools.product((-1.0, 1.0), repeat=k))).reshape(2 ** k, k)
    columns = [base[:, j] for j in range(k)]
    subsets = [c for size in range(k, 1, -1) for c in itertools.combinations(range(k), size)]
    for j in range(d - k):
        if subsets:
            sub = subsets[j % len(subsets)]
            col = np.prod(base[:, list(sub)], axis=1) * (-1.0 if j >= len(subsets) else 1.0)
        else:  # k <= 1: alternate the single base column
            col = (base[:, 0] if k else np.ones(1)) * (-1.0 if j % 2 else 1.0)
        columns.append(col)
    design = np.column_stack(columns) if columns else np.zeros((1, 0))
    if rng is not None and 2 ** d > runs:
        design = design * rng.choice((-1.0, 1.0), size=d)
    return (design + 1.0) / 2.0


class _BudgetSpent(Exception):
    """The local optimiser asked for more runs than the budget has left."""


def _search_vertices_polish(evaluate: Callable[[np.ndarray], np.ndarray], bounds: np.ndarray, *, budget: int,
                            seed: int = 0, first: str = "vertices") -> Trace:
    """The box's vertices first, then a bounded local search from the worst found.

    first='lhs' (``--method lhs-polish``): a seeded Latin hypercube of half the budget instead of
    the vertices (its stream is not the random sample's), for spaces whose worst case is interior
    (C's path: knots between the bounds), then the same polish.

    1. Vertices, one batch: all 2^d corners where the budget allows them (2^d <= budget), else a
       fractional-factorial covering design of at most half the budget (:func:`covering_design`,
       seeded sign flips).
    2. Polish: scipy's Nelder-Mead with bounds, in the unit box, from the worst point so far,
       its initial simplex stepping inward from it by a seeded 5-20% of each range (evaluated
       as one batch), then one run per call; when it converges with budget left it restarts from
       the next-worst evaluated point. A point evaluated before is not run again.

    Robust-control worst cases sit at vertices more often than not (the objective is monotone
    in most parameters), which is why they come first; the polish finds an interior maximum
    near the worst vertex, or confirms the vertex. Deterministic for a seed.
    """
    from scipy.optimize import minimize

    bounds = np.asarray(bounds, dtype=float)
    d = len(bounds)
    _check_budget(budget, MIN_POPULATION)
    rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(4)[3])
    lo, span = bounds[:, 0], bounds[:, 1] - bounds[:, 0]
    rec = _Recorder(evaluate)
    seen: dict[tuple[float, ...], float] = {}

    def run(unit: np.ndarray) -> np.ndarray:
        """Evaluate unit-box points (rows) not seen before, within the budget; values of all."""
        unit = np.clip(np.atleast_2d(np.asarray(unit, dtype=float)), 0.0, 1.0)
        keys = [tuple(u.tolist()) for u in unit]
        new = list(dict.fromkeys(k for k in keys if k not in seen))
        if rec.spent + len(new) > budget:
            raise _BudgetSpent
        if new:
            v = rec(lo + np.array(new) * span)
            seen.update(zip(new, v.tolist()))
        return np.array([seen[k] for k in keys])

    def spent() -> int:
        return rec.spent

    if first == "lhs":
        from wmr_mj.sim.sweep import latin_hypercube

        run(latin_hypercube(max(1, budget // 2), d, rng))
    else:
        run(covering_design(d, budget if 2 ** d <= budget else max(1, budget // 2), rng))
    starts_used: list[np.ndarray] = []

    def energy(x: np.ndarray) -> float:  # Nelder-Mead minimises
        v = float(run(x)[0])
        return 1e300 if math.isnan(v) else -v

    while spent() < budget:
        keys = sorted(seen, key=lambda k: -math.inf if math.isnan(seen[k]) else seen[k], reverse=True)
        start = next((np.array(k) for k in keys
                      if all(np.max(np.abs(np.array(k) - s)) > 1e-3 for s in starts_used)), None)
        if start is None:
            break
        starts_used.append(start)
        inward = np.where(start > 0.5, -1.0, 1.0)
        steps = rng.uniform(0.05, 0.2, size=d) * inward
        simplex = np.vstack([start, start + np.diag(steps)])
        try:
            run(simplex[1:][: budget - spent()])  # the initial simplex as one batch
            if spent() >= budget:
                break
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                minimize(energy, start, method="Nelder-Mead", bounds=[(0.0, 1.0)] * d,
                         options={"initial_simplex": simplex, "maxfev": budget, "xatol": 1e-4, "fatol": 1e-7})
        except _BudgetSpent:
            break
    return rec.trace()


#: CMA-ES's starting step, in units of each range (the search runs in the unit box).
CMA_SIGMA0 = 0.3
#: The portfolio evaluates all 2^d vertices where they fit this share of the budget and number at most
#: PORTFOLIO_MAX_VERTICES (a monotone worst case is then found exactly: the full box, d = 5, at any budget >= 64) ...
PORTFOLIO_VERTEX_SHARE = 0.5
PORTFOLIO_MAX_VERTICES = 32
#: ... else a covering of at most this share of the budget (measured: the benchmarks guide). C's path (d = 6)
#: at a budget of 300: 32 of its 64 vertices, not all 64.
PORTFOLIO_COVER_SHARE = 0.125
#: The last share of the budget is a local CMA-ES around the worst point found, its step a share of each range
#: (measured: the benchmarks guide): (share of the budget, step) below PORTFOLIO_LONG_BUDGET runs ...
PORTFOLIO_LOCAL_SHORT = (0.2, 0.05)
#: ... and from there on, where the global phase has had its runs: a longer, finer local phase.
PORTFOLIO_LOCAL_LONG = (0.3, 0.02)
PORTFOLIO_LONG_BUDGET = 200
#: CMA-ES starts from the box's centre, moved by PORTFOLIO_SCREEN_SHIFT of a range towards the worse side of every
#: parameter whose main effect over the vertices is significant, |t| > PORTFOLIO_SCREEN_T (a two-level screening).
PORTFOLIO_SCREEN_T = 3.0
PORTFOLIO_SCREEN_SHIFT = 0.25
#: From PORTFOLIO_LONG_BUDGET runs on, the global phase is this many independent CMA-ES runs from the same start,
#: equal in whole generations (below it, one): on a rough objective one run's mean can wander off to a poorer region.
PORTFOLIO_GLOBAL_RUNS_LONG = 2
#: From PORTFOLIO_LONG_BUDGET runs on, this share of the local phase (its end) is coordinate moves of the worst point
#: found: each member moves each coordinate with probability 1/d (at least one) by a normal step of
#: PORTFOLIO_COORDINATE_STEP of its range. On C's path the high values lie on thin ridges (two adjacent knots a set
#: step apart): a move of the coordinates off a ridge's normal stays on it, an isotropic step seldom does.
PORTFOLIO_COORDINATE_SHARE = 0.5
PORTFOLIO_COORDINATE_STEP = 0.05


def portfolio_local_phase(budget: int) -> tuple[float, float]:
    """(share of the budget, step as a share of each range) of the portfolio's local phase:
    :data:`PORTFOLIO_LOCAL_SHORT` below :data:`PORTFOLIO_LONG_BUDGET` runs, else :data:`PORTFOLIO_LOCAL_LONG`."""
    return PORTFOLIO_LOCAL_LONG if budget >= PORTFOLIO_LONG_BUDGET else PORTFOLIO_LOCAL_SHORT


def portfolio_global_runs(d: int, budget: int, population: int | None = None) -> int:
    """How many independent CMA-ES runs, from the same start, share the portfolio's global phase in d parameters
    at ``budget``, as :func:`search_worst` spends them: one below :data:`PORTFOLIO_LONG_BUDGET` runs,
    :data:`PORTFOLIO_GLOBAL_RUNS_LONG` from there on, at most one per whole generation of ``population``
    (default :func:`cma_population`) in :func:`portfolio_phases`' global phase."""
    lam = cma_population(d) if population is None else population
    runs = PORTFOLIO_GLOBAL_RUNS_LONG if budget >= PORTFOLIO_LONG_BUDGET else 1
    return max(1, min(runs, portfolio_phases(d, budget, lam)[1] // lam))


def portfolio_coordinate_runs(d: int, budget: int, population: int | None = None) -> int:
    """How many of the portfolio's local runs (:func:`portfolio_phases`' last) are coordinate moves of the worst
    point found, at the end: none below :data:`PORTFOLIO_LONG_BUDGET` runs, else what is left after the local
    CMA-ES has :data:`PORTFOLIO_COORDINATE_SHARE`'s complement of them in whole generations of ``population``
    (default :func:`cma_population`)."""
    if budget < PORTFOLIO_LONG_BUDGET or PORTFOLIO_COORDINATE_SHARE <= 0.0:
        return 0
    lam = cma_population(d) if population is None else population
    local = portfolio_phases(d, budget, lam)[2]
    return local - int((1.0 - PORTFOLIO_COORDINATE_SHARE) * local) // lam * lam


def portfolio_phases(d: int, budget: int, population: int | None = None) -> tuple[int, int, int]:
    """The portfolio's runs in d parameters at ``budget``: (vertices, global CMA-ES, local CMA-ES), as
    :func:`search_worst` spends them (the global phase in whole generations of ``population``, default
    :func:`cma_population`; no local phase where the global one would have no whole generation)."""
    lam = cma_population(d) if population is None else population
    nv = min(portfolio_vertices(d, budget), budget)
    local = int(portfolio_local_phase(budget)[0] * budget)
    global_end = nv + (budget - nv - local) // lam * lam if local else budget
    if global_end <= nv:
        global_end = budget
    return nv, global_end - nv, budget - global_end


def screened_start(corners: np.ndarray, values: np.ndarray) -> np.ndarray:
    """CMA-ES's first mean (d,) in the unit box, from the vertices' values: the two-level screening of a
    designed experiment. The main effects are fitted by least squares on the corners (n, d) in {0, 1}
    (orthogonal columns for :func:`covering_design`'s designs); a parameter whose effect b_i exceeds
    :data:`PORTFOLIO_SCREEN_T` standard errors (s / sqrt(n), s from the residuals) starts
    :data:`PORTFOLIO_SCREEN_SHIFT` from the centre on its worse side, every other at the centre. Undefined
    (NaN) values are left out; with no residual degree of freedom every parameter starts at the centre."""
    ok = np.isfinite(values)
    X, y = 2.0 * np.asarray(corners, dtype=float)[ok] - 1.0, np.asarray(values, dtype=float)[ok]
    start = np.full(np.shape(corners)[1], 0.5)
    dof = len(y) - X.shape[1] - 1
    if dof < 1:
        return start
    A = np.column_stack([np.ones(len(y)), X])
    coef = np.linalg.lstsq(A, y, rcond=None)[0]
    resid = y - A @ coef
    se = math.sqrt(float(resid @ resid) / dof / len(y))
    for i, b in enumerate(coef[1:]):
        if abs(b) > PORTFOLIO_SCREEN_T * se and b != 0.0:
            start[i] = 0.5 + PORTFOLIO_SCREEN_SHIFT * math.copysign(1.0, b)
    return start


def cma_population(d: int) -> int:
    """CMA-ES's members per generation: its default 4 + floor(3 ln d), at least :data:`MIN_POPULATION`
    (5 in 1-D, 6 in 2-D, 8 in 4-5-D, 9 in 6-D)."""
    return max(MIN_POPULATION, 4 + int(math.floor(3 * math.log(max(d, 1)))))


def portfolio_vertices(d: int, budget: int) -> int:
    """How many vertices the portfolio evaluates first: all 2^d where they fit
    :data:`PORTFOLIO_VERTEX_SHARE` of the budget and number at most :data:`PORTFOLIO_MAX_VERTICES`,
    else the largest power of two within :data:`PORTFOLIO_COVER_SHARE` of it (a fractional-factorial
    covering), at least 2."""
    if 2 ** d <= min(int(PORTFOLIO_VERTEX_SHARE * budget), PORTFOLIO_MAX_VERTICES):
        return 2 ** d
    share = int(PORTFOLIO_COVER_SHARE * budget)
    return max(2, 2 ** int(math.floor(math.log2(max(share, 2)))))


def _search_cma(evaluate: Callable[[np.ndarray], np.ndarray], bounds: np.ndarray, *, budget: int, seed: int = 0,
                population: int | None = None, vertices: bool = True) -> Trace:
    """CMA-ES (the ``cmaes`` package), a generation per batch, in the unit box with its bounds;
    with ``vertices`` (the ``portfolio``) the box's vertices first, as one batch, and a last local
    CMA-ES around the worst point found.

    1. (portfolio) :func:`portfolio_vertices` vertices, one batch: all 2^d where they fit
       :data:`PORTFOLIO_VERTEX_SHARE` of the budget and number at most :data:`PORTFOLIO_MAX_VERTICES`,
       else a seeded fractional-factorial covering.
    2. CMA-ES: mean at the box's centre (not at the worst vertex: measured worse on interior maxima),
       (portfolio) moved towards the worse side of each parameter whose main effect over the vertices
       is significant (:func:`screened_start`), step :data:`CMA_SIGMA0` of each range, ``population``
       (default :func:`cma_population`) members per generation, evaluated as one batch; the package
       resamples a member outside the box (up to 100 times, then clips it). An undefined value (NaN)
       ranks below every defined one. When CMA-ES stops (converged, flat) with budget left it
       restarts from a seeded uniform point with twice the population (IPOP). (portfolio) This global
       phase runs whole generations of the first population up to the budget less the local phase's
       share of it (:func:`portfolio_local_phase`), from 200 runs on as :func:`portfolio_global_runs`
       independent runs from the same start (step CMA_SIGMA0, the first population), equal in whole
       generations; a run that stops early restarts within its share as above.
    3. (portfolio) The local phase: CMA-ES from the worst point found, its step
       (:func:`portfolio_local_phase`) of each range, the first population (restarted there when it
       stops), to the budget; none where the global phase would have no whole generation before it
       (tiny budgets). From 200 runs on the local CMA-ES ends early, in whole generations, and the
       rest (:func:`portfolio_coordinate_runs`) is coordinate moves: batches of ``population`` copies
       of the worst point found so far, each with every coordinate moved with probability 1/d (at
       least one) by a normal step of :data:`PORTFOLIO_COORDINATE_STEP`, clipped to the box. The last
       generation of each phase is cut to the budget.

    In one dimension (which ``cmaes`` does not take) it searches a square whose second coordinate
    is ignored. Deterministic for a seed (``cmaes`` keeps its own generator, seeded from it).
    """
    from cmaes import CMA

    bounds = np.asarray(bounds, dtype=float)
    d = len(bounds)
    lam0 = cma_population(d) if population is None else population
    _check_budget(budget, lam0, what="CMA-ES")
    seeds = np.random.SeedSequence(seed).spawn(5)[4]
    rng = np.random.default_rng(seeds)
    lo, span = bounds[:, 0], bounds[:, 1] - bounds[:, 0]
    rec = _Recorder(evaluate)
    n = max(d, 2)
    unit_points: list[np.ndarray] = []  # what CMA-ES asked, in the unit box (the recorder keeps the box's)

    def run(unit: np.ndarray) -> np.ndarray:  # a coordinate at 1 is the upper bound itself, not lo + span
        unit_points.append(unit)
        return rec(np.where(unit[:, :d] >= 1.0, bounds[:, 1], lo + unit[:, :d] * span))

    def incumbent() -> np.ndarray:
        """The worst point found so far, in the unit box (the first of equals; NaN ranks last)."""
        v = rec.trace().values
        return np.concatenate(unit_points)[int(np.argmax(np.where(np.isnan(v), -np.inf, v)))]

    start = np.full(n, 0.5)
    if vertices:
        corners = covering_design(d, portfolio_vertices(d, budget), rng)
        corner_values = run(np.hstack([corners, np.full((len(corners), n - d), 0.5)]))
        start[:d] = screened_start(corners, corner_values)
    local_sigma = portfolio_local_phase(budget)[1]
    # the global phase in whole generations of the first population, the local phase the rest; a budget
    # that leaves the global phase no whole generation has no local phase (CMA-ES from the centre, as before)
    global_end = rec.spent + portfolio_phases(d, budget, lam0)[1] if vertices else budget
    generations = (global_end - rec.spent) // lam0
    runs = portfolio_global_runs(d, budget, lam0) if vertices else 1
    run_ends = [rec.spent + generations * (i + 1) // runs * lam0 for i in range(runs - 1)] + [global_end]
    local_end = budget - (portfolio_coordinate_runs(d, budget, lam0) if vertices else 0)
    mean, lam, sigma = start, lam0, CMA_SIGMA0
    while rec.spent < local_end:
        if rec.spent >= global_end:  # the local phase (and its restarts): around the worst point found
            mean, lam, sigma = np.clip(incumbent(), 0.0, 1.0), lam0, local_sigma
        elif rec.spent >= run_ends[0]:  # the global phase's next independent run, from the same start
            run_ends.pop(0)
            mean, lam, sigma = start, lam0, CMA_SIGMA0
        opt = CMA(mean=mean, sigma=sigma, bounds=np.array([[0.0, 1.0]] * n), population_size=lam,
                  seed=int(rng.integers(2 ** 31 - 1)))
        end = run_ends[0] if rec.spent < global_end else local_end
        while rec.spent < end:
            xs = np.array([opt.ask() for _ in range(opt.population_size)])
            k = min(len(xs), end - rec.spent)
            v = run(xs[:k])
            if k < len(xs):
                break
            opt.tell([(x, 1e300 if math.isnan(e) else -e) for x, e in zip(xs, v)])  # cmaes minimises
            if opt.should_stop():
                break
        mean, lam = rng.uniform(0.0, 1.0, n), 2 * lam  # IPOP restart (of the global phase)
    while rec.spent < budget:  # coordinate moves of the worst point found, a generation's worth per batch
        k = min(lam0, budget - rec.spent)
        moved = rng.random((k, d)) < 1.0 / d
        unmoved = ~moved.any(axis=1)
        moved[unmoved, rng.integers(d, size=int(unmoved.sum()))] = True  # at least one coordinate each
        xs = np.repeat(incumbent()[None, :], k, axis=0)
        xs[:, :d] += np.where(moved, PORTFOLIO_COORDINATE_STEP * rng.standard_normal((k, d)), 0.0)
        run(np.clip(xs, 0.0, 1.0))
    return rec.trace()


def _search_de(evaluate: Callable[[np.ndarray], np.ndarray], bounds: np.ndarray, *, budget: int, seed: int = 0,
                 population: int | None = None) -> Trace:
    """Maximise ``evaluate`` over the box ``bounds`` (d, 2) with scipy's differential evolution.

    evaluate(points (S, d)) -> values (S,), NaN where undefined, is called once per
    generation with the whole population. At most ``budget`` points are evaluated:
    ``population`` (default :func:`population_size`) per generation, for
    budget // population generations, the first a Latin hypercube. Seeded: the same
    seed gives the same points.
    """
    from scipy.optimize import differential_evolution

    from wmr_mj.sim.sweep import latin_hypercube

    bounds = np.asarray(bounds, dtype=float)
    d = len(bounds)
    population = population_size(budget, d) if population is None else population
    _check_budget(budget, population)
    init_rng, evolve_rng, _ = _streams(seed)
    init = _unit_to_box(latin_hypercube(population, d, init_rng), bounds)
    rec = _Recorder(evaluate)

    def energies(x: np.ndarray) -> np.ndarray:  # x: (d, S); DE minimises
        v = rec(np.array(x.T, dtype=float))
        return np.where(np.isnan(v), np.inf, -v)

    with warnings.catch_warnings(), _user_errors_unwrapped():
        warnings.simplefilter("ignore", RuntimeWarning)  # inf energies of undefined points
        differential_evolution(energies, bounds, maxiter=budget // population - 1, init=init, polish=False,
                               tol=0.0, atol=0.0, updating="deferred", vectorized=True, rng=evolve_rng)
    return rec.trace()


def random_worst(evaluate: Callable[[np.ndarray], np.ndarray], bounds: np.ndarray, *, n: int,
                 seed: int = 0) -> Trace:
    """The same budget spent at random: ``n`` Latin-hypercube points of the box, one call."""
    from wmr_mj.sim.sweep import latin_hypercube

    bounds = np.asarray(bounds, dtype=float)
    points = _unit_to_box(latin_hypercube(n, len(bounds), _streams(seed)[2]), bounds)
    values = np.asarray(evaluate(points), dtype=float).reshape(-1)
    return Trace(points, values, np.zeros(n, dtype=int))


# -- falsify: the search on closed-loop runs ------------------------------------------------

@dataclass(frozen=True, kw_only=True)
class FalsifySpec:
    """Search ``box`` (parameter name -> (lo, hi), m1 included or fixed at base.m1) for the
    run of ``base`` that maximises ``objective``, spending ``budget`` simulations (and as
    many on the random sample)."""

    base: RunConfig = field(default_factory=RunConfig)
    box: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    objective: str = "certificate"
    budget: int = 256
    seed: int = 0
    population: int | None = None  # members per generation of differential evolution or CMA-ES
    method: str = "portfolio"  # one of METHODS
    requirement: str | None = None  # objective 'requirement': an STL formula (wmr_mj.analysis.requirements)

    def __post_init__(self) -> None:
        from wmr_mj._util.checks import positive_range as _check_range

        if self.objective not in OBJECTIVES:
            raise UnknownNameError("objective", self.objective, OBJECTIVES)
        if self.method not in METHODS:
            raise UnknownNameError("search method", self.method, METHODS)
        if (self.objective == "requirement") != (self.requirement is not None):
            raise ParameterError("the objective 'requirement' goes with a requirement (an STL formula), and only it")
        if self.requirement is not None:
            self.parsed_requirement  # noqa: B018  (refused here, before any run, when malformed)
        from wmr_mj.sim.search_space import check_hardware_range, config_for, hardware_axis, path_axis, signal_axis

        if not self.box:
            raise ParameterError("the box is empty; give at least one ranged parameter (e.g. --uncertainty m1)")
        names = parameter_names()
        for name, (lo, hi) in self.box.items():
            if hardware_axis(name):  # the cart's: searched, each run's claim covering its own cart
                check_hardware_range(self.base, name, lo, hi)
                continue
            if signal_axis(name) or path_axis(name):
                if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
                    raise ParameterError(f"range of {name} = {lo!r}:{hi!r} is not accepted: finite LO <= HI")
                continue
            if name not in names:
                raise UnknownNameError("parameter", name, names)
            _check_range(name, lo, hi)
        amplitude = self.box.get("disturbance.amplitude")
        signals = self.base.signals
        if amplitude is not None and signals is not None and signals.d_max is None:
            # the certificate declares one bound for the whole search: the largest amplitude of the box
            declared = dataclasses.replace(signals, d_max=max(abs(float(amplitude[0])), abs(float(amplitude[1]))))
            object.__setattr__(self, "base", self.base.replace(signals=declared))
        config_for(self.base, self.names, [lo for lo, _ in self.box.values()])  # a bad axis fails before any run
        if isinstance(self.seed, bool) or not isinstance(self.seed, int):
            raise ParameterError(f"seed = {self.seed!r} is not accepted; give an integer")
        _check_budget(self.budget, self.population_size if self.population_size is not None else MIN_POPULATION,
                      what=_POPULATION_OF.get(self.method, "the search"))

    @property
    def parsed_requirement(self):
        from wmr_mj.analysis.requirements import parse_requirement
        from wmr_mj.plant.mjcf import TIMESTEP

        period = TIMESTEP if self.base.control_period is None else self.base.control_period
        return parse_requirement(self.requirement, period=period)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.box)

    @property
    def bounds(self) -> np.ndarray:
        return np.array([self.box[n] for n in self.names], dtype=float)

    @property
    def population_size(self) -> int | None:
        """Members per generation: differential evolution's or CMA-ES's (its first; None for the polish methods)."""
        if self.method not in _POPULATION_OF:
            return None
        if self.population is not None:
            return self.population
        d = len(self.box)
        return population_size(self.budget, d) if self.method == "de" else cma_population(d)

    def recorded_values(self, point: Sequence[float]) -> dict[str, float]:
        """Each ranged parameter -> the value its run used (what the search's tables record): as proposed, but a
        hardware axis rounded as the run has it (:func:`wmr_mj.sim.search_space.hardware_values`)."""
        from wmr_mj.sim.search_space import hardware_axis, hardware_values

        out = {n: float(v) for n, v in zip(self.names, point)}
        out.update(hardware_values(self.base, {n: v for n, v in out.items() if hardware_axis(n)}))
        return out

    def config(self, point: Sequence[float]) -> RunConfig:
        """The run at ``point`` (values in ``names`` order): m1, the plant overrides and the signals'
        parameters set (:func:`wmr_mj.sim.search_space.config_for`)."""
        from wmr_mj.sim.search_space import config_for

        return config_for(self.base, self.names, point)


@dataclass(frozen=True)
class Evaluation:
    """One simulated run of the search or the random sample."""

    phase: str  # "search" or "random"
    index: int  # in its phase, in evaluation order
    generation: int
    # every ranged parameter, full precision, as the run used it: a hardware axis rounded as its run had it
    # (sensing.encoder_bits = 12.0 where the search proposed 11.533: the run had 4096 ticks)
    params: dict[str, float]
    objective: float | None
    summary: dict[str, Any]  # the run's report
    point: tuple[float, ...] = ()  # the point the search proposed (FalsifySpec.names order); () where unknown

    @property
    def sup_E(self) -> float:
        return float(self.summary["sup_E"])

    @property
    def sup_Edot(self) -> float:
        return float(self.summary["sup_Edot"])

    @property
    def verdict(self) -> str:
        return _verdict(self.summary)


@dataclass(frozen=True, kw_only=True)
class Tightness(Record):
    """How tight the certificate is (:attr:`FalsifyResult.tightness`).

    Attributes:
        ratio: the worst objective found, sup|E|/E_max of the certificate [-] (a lower bound on the worst case).
        factor: 1/ratio, how many times the worst case found the certificate is (inf where ratio <= 0).
        found_sup_E: the worst run's sup|E| [rad].
        E_max: the certificate's E_max [rad] (an upper bound); None where the run has none.
        text: the sentence ``wmr-mj falsify`` prints.
    """

    ratio: float | None
    factor: float
    found_sup_E: float
    E_max: float | None
    text: str


@dataclass(frozen=True, kw_only=True)
class WorstRun(Record):
    """The search's worst run (``falsify --json``'s ``worst``): its parameters, objective, sup|E| [rad],
    sup|E'| [rad/s], verdict, generation and index (0-based in the search), and the claim's assumptions it
    does not meet."""

    _records = {"unmet": UnmetAssumption}

    params: Mapping[str, float]
    objective: float | None
    sup_E: float
    sup_Edot: float
    verdict: str
    generation: int
    index: int
    unmet: tuple[UnmetAssumption, ...]


@dataclass(frozen=True, kw_only=True)
class RandomWorst(Record):
    """The random sample's worst run (``falsify --json``'s ``random``): its objective and parameters, the
    sample's size, the run's sup|E| [rad] and verdict."""

    worst_objective: float | None
    worst_params: Mapping[str, float]
    evaluations: int
    sup_E: float
    verdict: str


@dataclass(frozen=True, kw_only=True)
class FalsifyReport(Record):
    """What a search found, read by attribute: ``wmr-mj falsify --json``'s object (:meth:`to_dict`, before the
    command adds its files, cart and reproduce line), from :meth:`FalsifyResult.report`.

    Attributes:
        objective: one of :data:`OBJECTIVES`.
        objective_label: its words (:data:`OBJECTIVE_LABELS`).
        objective_source: where the objective's bound comes from (:func:`objective_source`).
        budget: the search's simulations asked.
        evaluations: the search's simulations run.
        seed: the search's seed.
        method: one of :data:`METHODS`.
        population: members per generation; None for the polish methods.
        generations: the search's generations.
        requirement: the STL requirement of the objective 'requirement'; None otherwise.
        falsified: :attr:`FalsifyResult.falsified`.
        claim_broken: the run that breaks the claim most; None when none does.
        box: each ranged parameter -> (lo, hi).
        worst: the search's worst run.
        tightness: how tight the certificate is, where the objective is its ratio; else None.
        random: the random sample's worst run.
        log: the MCAP log of the worst run's re-run; None where not written.
    """

    _records = {"claim_broken": BrokenRun, "worst": WorstRun, "tightness": Tightness, "random": RandomWorst}

    objective: str
    objective_label: str
    objective_source: str
    budget: int
    evaluations: int
    seed: int
    method: str
    population: int | None
    generations: int
    requirement: str | None
    falsified: bool | None
    claim_broken: BrokenRun | None
    box: Mapping[str, tuple[float, float]]
    worst: WorstRun
    tightness: Tightness | None
    random: RandomWorst
    log: str | None = None

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> FalsifyReport:
        report = super().from_dict(d)
        return dataclasses.replace(report, box={k: (float(lo), float(hi)) for k, (lo, hi) in report.box.items()})


@dataclass(frozen=True)
class FalsifyResult:
    """Every run of a search and of its random sample (:func:`falsify`); :meth:`report` is what they add up to."""

    spec: FalsifySpec
    search: list[Evaluation]
    random: list[Evaluation]
    objective_source: str

    @staticmethod
    def _worst(evals: list[Evaluation]) -> Evaluation:
        best, value = None, -math.inf
        for e in evals:  # the first of equals
            if e.objective is not None and e.objective > value:
                best, value = e, e.objective
        if best is None:
            raise ParameterError("the objective is undefined for every run: the design has no certificate over "
                                 "this box (an assumption fails: see wmr-mj robustness --certificate) or the "
                                 "region does not exist; search --objective sup-E or --against paper instead")
        return best

    @property
    def worst(self) -> Evaluation:
        return self._worst(self.search)

    @property
    def random_worst(self) -> Evaluation:
        """The random sample's run of the largest objective; where none of its runs has the objective (each
        left blank: :func:`undefined_objective_warning` says so), its run of the largest sup|E|, whose
        objective is None: the search's worst is still the answer, not an error."""
        if self.random and all(e.objective is None for e in self.random):
            return max(self.random, key=lambda e: e.sup_E)  # max keeps the first of equals
        return self._worst(self.random)

    @property
    def generations(self) -> int:
        return 1 + max((e.generation for e in self.search), default=-1)

    @property
    def method_label(self) -> str:
        """The search's method in words (:data:`METHOD_LABELS`: ``vertices, then CMA-ES``), as its figure says it."""
        return METHOD_LABELS[self.spec.method]

    @property
    def objective_label(self) -> str:
        """The objective in words (:data:`OBJECTIVE_LABELS`: ``sup|E|/E_max of the certificate``)."""
        return OBJECTIVE_LABELS[self.spec.objective]

    @property
    def tightness(self) -> Tightness | None:
        """How tight the certificate is, where the objective is its ratio sup|E|/E_max: the worst
        found (a lower bound on the worst case: a run reached it) beside the certificate's E_max (an
        upper bound), their ratio X and 1/X, and the sentence falsify prints. None for other objectives."""
        if self.spec.objective != "certificate":
            return None
        w = self.worst
        certificate = w.summary.get("certificate")
        e_max = certificate.get("E_max") if isinstance(certificate, Mapping) else None
        x = w.objective
        factor = 1.0 / x if x is not None and x > 0 else math.inf
        bound = "n/a" if e_max is None else f"{float(e_max):.4g}"
        if x is not None and x > 1.0:  # exceeded: said as such, never as a fraction of the worst case
            text = (f"the worst run is {x:.3g} times the claimed bound (sup|E| = {w.sup_E:.4g} rad found, <= "
                    f"{bound} rad claimed): the claim is exceeded"
                    + (" and its assumptions hold: CERTIFIED-OUTSIDE" if w.verdict == CERTIFIED_OUTSIDE else
                       f" where its assumptions are not all met ({w.verdict}): not a broken claim"))
        else:
            text = (f"the worst found is {x:.4g} of the certificate's bound: the certificate is {factor:.3g} times "
                    f"the worst case found (sup|E| >= {w.sup_E:.4g} rad found, <= {bound} rad certified)")
        return Tightness(ratio=x, factor=factor, found_sup_E=w.sup_E, E_max=None if e_max is None else float(e_max),
                         text=text)

    @property
    def claim_broken(self) -> BrokenRun | None:
        """The run (of the search or the random sample) that breaks the law's claim most, whatever the
        objective: the ``certified-outside`` run of the largest sup|E|/E_max (the first of equals, the
        search's first); None when no run breaks it."""
        broken = [e for e in (*self.search, *self.random) if e.verdict == CERTIFIED_OUTSIDE]
        if not broken:
            return None

        def ratio(e: Evaluation) -> float:
            value = (e.summary.get("certificate") or {}).get("E_ratio")
            return -math.inf if value is None else float(value)

        e = max(broken, key=ratio)  # max keeps the first of equals
        e_max = (e.summary.get("certificate") or {}).get("E_max")
        return BrokenRun(phase=e.phase, run=e.index + 1, params=dict(e.params), sup_E=e.sup_E, sup_Edot=e.sup_Edot,
                         E_max=None if e_max is None else float(e_max),
                         ratio=None if ratio(e) == -math.inf else ratio(e), count=len(broken))

    @property
    def falsified(self) -> bool | None:
        """True when a run breaks the law's claim (:attr:`claim_broken`) or, for the objective
        'requirement', when the worst run falsifies it; False when neither, where there is a claim or a
        requirement to falsify; None when there is neither (every run without a claim)."""
        if self.claim_broken is not None:
            return True
        if self.spec.objective == "requirement":
            w = self.worst
            return w.objective is not None and w.objective > 0.0
        judged = any(e.verdict in VERDICTS for e in (*self.search, *self.random))
        return False if judged else None

    def report(self, *, log: str | None = None) -> FalsifyReport:
        """What the search found, typed (``log``: the worst run's MCAP log, where written)."""
        from wmr_mj.analysis.verdicts import unmet_assumptions

        w, r = self.worst, self.random_worst
        return FalsifyReport(
            objective=self.spec.objective, objective_label=OBJECTIVE_LABELS[self.spec.objective],
            objective_source=self.objective_source, budget=self.spec.budget, evaluations=len(self.search),
            seed=self.spec.seed, method=self.spec.method, population=self.spec.population_size,
            generations=self.generations, requirement=self.spec.requirement, falsified=self.falsified,
            claim_broken=self.claim_broken,
            box={k: (float(lo), float(hi)) for k, (lo, hi) in self.spec.box.items()},
            worst=WorstRun(params=dict(w.params), objective=w.objective, sup_E=w.sup_E, sup_Edot=w.sup_Edot,
                           verdict=w.verdict, generation=w.generation, index=w.index,
                           unmet=tuple(UnmetAssumption.from_dict(a)
                                       for a in unmet_assumptions(w.summary.get("certificate")))),
            tightness=self.tightness,
            random=RandomWorst(worst_objective=r.objective, worst_params=dict(r.params), evaluations=len(self.random),
                               sup_E=r.sup_E, verdict=r.verdict),
            log=log)

    def to_dict(self, *, log: str | None = None) -> dict[str, Any]:
        """The ``wmr-mj falsify --json`` object (:meth:`report`'s JSON)."""
        return self.report(log=log).to_dict()

    # -- in a notebook (wmr_mj.sim.notebook): every run as a table, the search beside random, a few lines
    def to_pandas(self) -> Any:
        """One row per run, the search's then the random sample's: ``phase``, ``index``, ``generation``, the
        values the run used (each ranged parameter, with units), ``objective``, then the run's verdict, sup|E|,
        the certificate's bounds (``certificate_E_max [rad]``) and the paper's claim as a sweep's table.

        Raises:
            WmrMjError: pandas is not installed (``pip install 'wmr-mj[notebook]'``).
        """
        from wmr_mj.sim import notebook
        from wmr_mj.sim.sweep import flat_row
        from wmr_mj.sim.sweep_result import parameter_units

        names = self.spec.names
        rows = [{"phase": e.phase, "index": e.index, "generation": e.generation, **e.params,
                 "objective": e.objective, **{k: v for k, v in flat_row(e.summary).items() if k not in e.params}}
                for e in (*self.search, *self.random)]
        return notebook.runs_frame(rows, parameters=names, units=parameter_units(names),
                                   first=("phase", "index", "generation", "objective"))

    def plot(self, **options: Any) -> Any:
        """The search beside random: each run's objective and the running worst of each
        (a :class:`wmr_mj.figures.results.ResultPlot`)."""
        from wmr_mj.figures.results import plot_falsify

        return plot_falsify(self, **options)

    def _repr_html_(self) -> str:
        from wmr_mj.sim import notebook

        return notebook.falsify_html(self.report())

    as_dict = to_dict  # the name of earlier versions (tests and scripts call it)


def falsify(spec: FalsifySpec, *, chunk: int = 128, nthread: int = 0, scheduler: str | None = None,
            progress: Callable[[int, int], None] | None = None,
            checkpoint: Callable[[FalsifyResult], object] | None = None, parts: Any = None) -> FalsifyResult:
    """Search ``spec.box`` for the worst run, then spend as many runs on a random sample.

    ``parts``: ``spec.base`` already resolved (:func:`check_runnable`); None: resolved here.

    Each generation runs as one batch (locally in chunks of ``chunk`` on ``nthread``
    threads, or on the Dask ``scheduler``). progress(done, total) counts finished runs of
    both phases. checkpoint(partial result) is called after every generation (and the
    random batch), so an interrupted search can leave what it evaluated on disk.
    """
    from wmr_mj.sim.sweep import connect, run_configs

    parts = check_runnable(spec.base) if parts is None else parts  # a bad duration or path: one line, here
    check_objective_applies(parts.controller, spec.objective)
    check_objective_defined(parts, spec)  # undefined for every run: refused before any step
    client = connect(scheduler) if scheduler is not None else None
    evaluations: dict[str, list[Evaluation]] = {"search": [], "random": []}
    total = 2 * spec.budget  # refined once the search has run
    done = 0

    def evaluator(phase: str, generation_of: Callable[[], int]) -> Callable[[np.ndarray], np.ndarray]:
        def evaluate(points: np.ndarray) -> np.ndarray:
            nonlocal done
            configs = [spec.config(p) for p in points]
            base_done = done

            def chunk_progress(k: int, n: int) -> None:
                if progress is not None:
                    progress(base_done + k, total)

            requirements = () if spec.requirement is None else (spec.requirement,)
            reports = [s.to_dict() for s in  # the summaries' JSON, what a search writes and reads back
                       run_configs(configs, chunk=chunk, nthread=nthread, client=client, progress=chunk_progress,
                                   requirements=requirements)]
            done += len(reports)
            out = np.full(len(points), np.nan)
            generation = generation_of()
            for i, (p, r) in enumerate(zip(points, reports)):
                value = objective_value(r, spec.objective)
                out[i] = np.nan if value is None else value
                evaluations[phase].append(Evaluation(
                    phase=phase, index=len(evaluations[phase]), generation=generation,
                    params=spec.recorded_values(p), point=tuple(float(v) for v in p),
                    objective=None if value is None else float(value), summary=r))
            if checkpoint is not None:
                checkpoint(FalsifyResult(spec=spec, search=list(evaluations["search"]),
                                         random=list(evaluations["random"]),
                                         objective_source=objective_source(reports[0], spec.objective)))
            return out

        return evaluate

    generations = 0

    def next_generation() -> int:
        nonlocal generations
        generations += 1
        return generations - 1

    try:
        search_worst(evaluator("search", next_generation), spec.bounds, budget=spec.budget, seed=spec.seed,
                     population=spec.population_size, method=spec.method)
        total = 2 * len(evaluations["search"])
        random_worst(evaluator("random", lambda: 0), spec.bounds, n=len(evaluations["search"]), seed=spec.seed)
    finally:
        if client is not None:
            client.close()
    first = evaluations["search"][0].summary
    return FalsifyResult(spec=spec, search=evaluations["search"], random=evaluations["random"],
                         objective_source=objective_source(first, spec.objective))


def check_runnable(base: RunConfig) -> Any:
    """Raise what the first batch would raise for ``base`` (a duration too short for the path,
    a control period that does not fit), before any search starts: the reference every
    evaluation shares depends on the base configuration only (path, duration, period), and a law's
    claim() that raises or returns what is not a claim (:func:`wmr_mj.sim.certify.certificate_of`).

    Returns:
        RunParts: ``base`` resolved (:func:`wmr_mj.sim.parts.resolve_run`), for :func:`falsify`'s ``parts``.
    """
    from wmr_mj.sim.parts import resolve_run

    return resolve_run(base)


def worst_config(result: FalsifyResult) -> RunConfig:
    """The worst run's config, rebuilt from its reported parameters."""
    w = result.worst
    return result.spec.config(w.point or [w.params[n] for n in result.spec.names])
