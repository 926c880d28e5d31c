"""falsify's search methods (:data:`METHODS`), each an ask/tell optimiser of :mod:`wmr_mj.searches.optimisers` that
:func:`search_worst` drives with the one loop (:func:`wmr_mj.searches.optimisers.drive`), maximising.

- ``portfolio`` (the default): the box's vertices, then CMA-ES from the screened start (:func:`screened_start`)
  in one or two independent runs, then a local CMA-ES around the worst point found, from 200 runs ending in
  coordinate moves (:func:`portfolio_phases`, :func:`portfolio_global_runs`, :func:`portfolio_coordinate_runs`);
- ``cma``: CMA-ES alone from the box's centre;
- ``vertices-polish`` / ``lhs-polish``: the vertices (a covering of them) or a Latin hypercube, then scipy's
  Nelder-Mead from the worst point found, restarted from the next-worst;
- ``de``: scipy's differential evolution, a generation per batch.

How each was chosen, and what each costs: :mod:`wmr_mj.searches.falsify`'s docstring and the benchmarks guide.
Every method is seeded: the same seed gives the same points, in the same order.

Usage::

    import numpy as np
    from wmr_mj.searches.search_methods import search_worst
    box = np.array([[550.0, 750.0], [0.01, 0.03]])
    trace = search_worst(lambda p: -np.sum((p - box[:, 0]) ** 2, axis=1), box, budget=64, seed=0)
    trace.points[trace.best]   # the worst case found (the largest value)
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Generator

import numpy as np

from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.searches.optimisers import (
    CMAES,
    DifferentialEvolution,
    NelderMead,
    Optimiser,
    Points,
    Steps,
    StepsGenerator,
    Trace,
    drive,
)
from wmr_mj.sim.many_runs import latin_hypercube

__all__ = [
    "METHODS",
    "METHOD_LABELS",
    "MIN_POPULATION",
    "Trace",
    "covering_design",
    "population_size",
    "cma_population",
    "check_budget",
    "portfolio_vertices",
    "portfolio_phases",
    "portfolio_local_phase",
    "portfolio_global_runs",
    "portfolio_coordinate_runs",
    "screened_start",
    "search_optimiser",
    "search_worst",
    "random_worst",
]

#: Search methods (module docstring): the portfolio (default: vertices, CMA-ES, a local CMA-ES), CMA-ES alone,
#: vertices or a Latin hypercube then a Nelder-Mead polish, differential evolution.
METHODS = ("portfolio", "cma", "vertices-polish", "lhs-polish", "de")
#: What each method does, in a few words (the legend of the search's history plot); a test keeps each
#: label true to the search :func:`search_worst` dispatches the method to.
METHOD_LABELS = {"portfolio": "vertices, then CMA-ES", "cma": "CMA-ES", "vertices-polish": "vertices, then Nelder-Mead",
                 "lhs-polish": "Latin hypercube, then Nelder-Mead", "de": "differential evolution"}
MIN_POPULATION = 5  # scipy's differential evolution needs at least 5 members


def population_size(budget: int, d: int) -> int:
    """Members per generation: 10 per parameter, but at most an eighth of the budget (so
    that at least 8 generations run), and never below scipy's minimum of 5."""
    return max(MIN_POPULATION, min(10 * d, budget // 8))


def check_budget(budget: int, population: int, what: str = "differential evolution") -> None:
    """Refuse, before any run, a budget that is not a whole number >= 1, a population below
    :data:`MIN_POPULATION`, or a budget below one generation of ``population`` (``what``: the method, in words).

    Raises:
        ParameterError: one line naming the value and what is accepted.
    """
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



def search_optimiser(bounds: np.ndarray, *, budget: int, seed: int = 0, population: int | None = None,
                     method: str = "portfolio") -> Optimiser:
    """The optimiser of ``method`` (:data:`METHODS`) over the box ``bounds`` (d, 2), for at most ``budget``
    points, minimising what it is told (:func:`search_worst` tells minus the values: it maximises).
    population: members per generation of differential evolution or CMA-ES.

    Raises:
        UnknownNameError: a method not in :data:`METHODS`.
        ParameterError: a budget below one generation (before any point is asked).
    """
    if method not in METHODS:
        raise UnknownNameError("search method", method, METHODS)
    if method == "de":
        return _search_de(bounds, budget=budget, seed=seed, population=population)
    if method in ("portfolio", "cma"):
        return _search_cma(bounds, budget=budget, seed=seed, population=population, vertices=method == "portfolio")
    return _search_vertices_polish(bounds, budget=budget, seed=seed, first=method.split("-")[0])


def search_worst(evaluate: Callable[[np.ndarray], np.ndarray], bounds: np.ndarray, *, budget: int, seed: int = 0,
                 population: int | None = None, method: str = "portfolio") -> Trace:
    """Maximise ``evaluate`` over the box ``bounds`` (d, 2) with ``method`` (:data:`METHODS`).

    evaluate(points (S, d)) -> values (S,), NaN where undefined, is called with a batch of
    points at a time. At most ``budget`` points are evaluated. Seeded: the same seed gives
    the same points. population: members per generation of differential evolution or CMA-ES.
    """
    optimiser = search_optimiser(bounds, budget=budget, seed=seed, population=population, method=method)
    return drive(optimiser, evaluate, maximise=True)


def random_worst(evaluate: Callable[[np.ndarray], np.ndarray], bounds: np.ndarray, *, n: int,
                 seed: int = 0) -> Trace:
    """The same budget spent at random: ``n`` Latin-hypercube points of the box, one call."""
    bounds = np.asarray(bounds, dtype=float)
    points = _unit_to_box(latin_hypercube(n, len(bounds), _streams(seed)[2]), bounds)
    return drive(Points(points), evaluate, maximise=True)


#: a strategy's sub-step: yields one batch, receives its told values, returns the values (maximised)
_Evaluated = Generator[np.ndarray, np.ndarray, np.ndarray]


class _BudgetSpent(Exception):
    """The local optimiser asked for more runs than the budget has left."""


def _search_vertices_polish(bounds: np.ndarray, *, budget: int, seed: int = 0, first: str = "vertices") -> Steps:
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
    bounds = np.asarray(bounds, dtype=float)
    d = len(bounds)
    check_budget(budget, MIN_POPULATION)

    def strategy() -> StepsGenerator:
        rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(4)[3])
        lo, span = bounds[:, 0], bounds[:, 1] - bounds[:, 0]
        seen: dict[tuple[float, ...], float] = {}  # unit-box point -> its value (maximised)
        spent = 0

        def run(unit: np.ndarray) -> _Evaluated:
            """Evaluate unit-box points (rows) not seen before, within the budget; values of all."""
            nonlocal spent
            unit = np.clip(np.atleast_2d(np.asarray(unit, dtype=float)), 0.0, 1.0)
            keys = [tuple(u.tolist()) for u in unit]
            new = list(dict.fromkeys(k for k in keys if k not in seen))
            if spent + len(new) > budget:
                raise _BudgetSpent
            if new:
                v = -(yield lo + np.array(new) * span)  # told minus the values
                spent += len(new)
                seen.update(zip(new, v.tolist()))
            return np.array([seen[k] for k in keys])

        if first == "lhs":
            yield from run(latin_hypercube(max(1, budget // 2), d, rng))
        else:
            yield from run(covering_design(d, budget if 2 ** d <= budget else max(1, budget // 2), rng))
        starts_used: list[np.ndarray] = []
        while spent < budget:
            keys = sorted(seen, key=lambda k: -math.inf if math.isnan(seen[k]) else seen[k], reverse=True)
            start = next((np.array(k) for k in keys
                          if all(np.max(np.abs(np.array(k) - s)) > 1e-3 for s in starts_used)), None)
            if start is None:
                break
            starts_used.append(start)
            inward = np.where(start > 0.5, -1.0, 1.0)
            steps = rng.uniform(0.05, 0.2, size=d) * inward
            simplex = np.vstack([start, start + np.diag(steps)])
            polish = NelderMead(start, bounds=[(0.0, 1.0)] * d,
                                options={"initial_simplex": simplex, "maxfev": budget, "xatol": 1e-4, "fatol": 1e-7})
            try:
                yield from run(simplex[1:][: budget - spent])  # the initial simplex as one batch
                if spent >= budget:
                    break
                while (x := polish.ask()) is not None:
                    polish.tell(-(yield from run(x)))  # Nelder-Mead minimises
            except _BudgetSpent:
                break
            finally:
                polish.close()

    return Steps(strategy)


def _search_cma(bounds: np.ndarray, *, budget: int, seed: int = 0, population: int | None = None,
                vertices: bool = True) -> Steps:
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
    bounds = np.asarray(bounds, dtype=float)
    d = len(bounds)
    lam0 = cma_population(d) if population is None else population
    check_budget(budget, lam0, what="CMA-ES")

    def strategy() -> StepsGenerator:
        rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(5)[4])
        lo, span = bounds[:, 0], bounds[:, 1] - bounds[:, 0]
        n = max(d, 2)
        unit_points: list[np.ndarray] = []  # what CMA-ES asked, in the unit box (the trace keeps the box's)
        values: list[np.ndarray] = []  # their values (maximised)
        spent = 0

        def run(unit: np.ndarray) -> _Evaluated:  # a coordinate at 1 is the upper bound itself, not lo + span
            nonlocal spent
            unit_points.append(unit)
            v = -(yield np.where(unit[:, :d] >= 1.0, bounds[:, 1], lo + unit[:, :d] * span))  # told minus them
            values.append(v)
            spent += len(unit)
            return v

        def incumbent() -> np.ndarray:
            """The worst point found so far, in the unit box (the first of equals; NaN ranks last)."""
            v = np.concatenate(values)
            return np.concatenate(unit_points)[int(np.argmax(np.where(np.isnan(v), -np.inf, v)))]

        start = np.full(n, 0.5)
        if vertices:
            corners = covering_design(d, portfolio_vertices(d, budget), rng)
            corner_values = yield from run(np.hstack([corners, np.full((len(corners), n - d), 0.5)]))
            start[:d] = screened_start(corners, corner_values)
        local_sigma = portfolio_local_phase(budget)[1]
        # the global phase in whole generations of the first population, the local phase the rest; a budget
        # that leaves the global phase no whole generation has no local phase (CMA-ES from the centre, as before)
        global_end = spent + portfolio_phases(d, budget, lam0)[1] if vertices else budget
        generations = (global_end - spent) // lam0
        runs = portfolio_global_runs(d, budget, lam0) if vertices else 1
        run_ends = [spent + generations * (i + 1) // runs * lam0 for i in range(runs - 1)] + [global_end]
        local_end = budget - (portfolio_coordinate_runs(d, budget, lam0) if vertices else 0)
        mean, lam, sigma = start, lam0, CMA_SIGMA0
        while spent < local_end:
            if spent >= global_end:  # the local phase (and its restarts): around the worst point found
                mean, lam, sigma = np.clip(incumbent(), 0.0, 1.0), lam0, local_sigma
            elif spent >= run_ends[0]:  # the global phase's next independent run, from the same start
                run_ends.pop(0)
                mean, lam, sigma = start, lam0, CMA_SIGMA0
            opt = CMAES(mean=mean, sigma=sigma, bounds=np.array([[0.0, 1.0]] * n), population=lam,
                        seed=int(rng.integers(2 ** 31 - 1)))
            end = run_ends[0] if spent < global_end else local_end
            while spent < end:
                xs = opt.ask()
                k = min(len(xs), end - spent)
                v = yield from run(xs[:k])
                if k < len(xs):
                    break
                opt.tell(-v)  # CMA-ES minimises
                if opt.converged:
                    break
            mean, lam = rng.uniform(0.0, 1.0, n), 2 * lam  # IPOP restart (of the global phase)
        while spent < budget:  # coordinate moves of the worst point found, a generation's worth per batch
            k = min(lam0, budget - spent)
            moved = rng.random((k, d)) < 1.0 / d
            unmoved = ~moved.any(axis=1)
            moved[unmoved, rng.integers(d, size=int(unmoved.sum()))] = True  # at least one coordinate each
            xs = np.repeat(incumbent()[None, :], k, axis=0)
            xs[:, :d] += np.where(moved, PORTFOLIO_COORDINATE_STEP * rng.standard_normal((k, d)), 0.0)
            yield from run(np.clip(xs, 0.0, 1.0))

    return Steps(strategy)


def _search_de(bounds: np.ndarray, *, budget: int, seed: int = 0, population: int | None = None) -> Optimiser:
    """scipy's differential evolution over the box ``bounds`` (d, 2), a generation per batch.

    At most ``budget`` points are evaluated: ``population`` (default :func:`population_size`) per
    generation, for budget // population generations, the first a Latin hypercube. Seeded: the same
    seed gives the same points.
    """
    bounds = np.asarray(bounds, dtype=float)
    d = len(bounds)
    population = population_size(budget, d) if population is None else population
    check_budget(budget, population)
    init_rng, evolve_rng, _ = _streams(seed)
    init = _unit_to_box(latin_hypercube(population, d, init_rng), bounds)
    return DifferentialEvolution(bounds, ignore=(RuntimeWarning,),  # inf energies of undefined points
                                 maxiter=budget // population - 1, init=init, polish=False, tol=0.0, atol=0.0,
                                 updating="deferred", vectorized=True, rng=evolve_rng)
