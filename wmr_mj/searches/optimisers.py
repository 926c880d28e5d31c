"""One ask/tell optimiser layer for every search of the package: falsify's worst case and design's gains.

An optimiser proposes points and is told their values; it never calls the objective itself. The caller
runs one loop, :func:`drive`: ask a batch of points (S, d), evaluate them (a batch of simulations, or
certificates one by one), tell the values, until the optimiser asks for nothing more. As with the
``cmaes`` package's ``ask``/``tell`` and MuJoCo's ``minimize.py``, one loop serves every caller, and the
record of what was evaluated (:class:`Trace`) is the loop's, the same for every optimiser.

Every optimiser here minimises what it is told (as scipy, ``cmaes`` and MuJoCo do); :func:`drive` with
``maximise=True`` tells minus the values. An undefined value (NaN) ranks below every defined one: each
optimiser gives its library the worst number it takes (``cmaes`` 1e300, scipy's differential evolution
inf, Nelder-Mead 1e300).

The optimisers:

- :class:`Points`: a given batch of points (a Latin hypercube, the box's vertices), once.
- :class:`CMAES`: the ``cmaes`` package's CMA-ES, a generation per batch (its own seeded generator).
- :class:`DifferentialEvolution`: scipy's ``differential_evolution``, a generation per batch where it
  is vectorised, else one point per batch.
- :class:`NelderMead`: scipy's ``minimize(method="Nelder-Mead")``, one point per batch.
- :class:`Chain`: optimisers one after the other, up to a budget.
- :class:`Steps`: a strategy written as a generator that yields batches and receives their values
  (falsify's portfolio: the vertices, CMA-ES, a local CMA-ES, coordinate moves:
  :mod:`wmr_mj.searches.search_methods`).

scipy's optimisers call their objective; :class:`DifferentialEvolution` and :class:`NelderMead` run the
library on a worker thread whose objective hands each call to :meth:`Optimiser.ask` and waits for
:meth:`Optimiser.tell` (one thread runs at a time: the same numbers as a direct call). The library is
wrapped, not rewritten.

Usage::

    import numpy as np
    from wmr_mj.searches.optimisers import CMAES, drive
    box = np.array([[-1.0, 1.0], [0.0, 2.0]])
    opt = CMAES(mean=box.mean(axis=1), sigma=0.3, bounds=box, seed=0)
    trace = drive(opt, lambda x: np.sum(x**2, axis=1), budget=60)   # minimises
    trace.points[trace.best], trace.values[trace.best]
"""

from __future__ import annotations

import math
import queue
import threading
import warnings
from collections.abc import Callable, Generator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from cmaes import CMA

__all__ = ["Optimiser", "Trace", "drive", "Points", "CMAES", "DifferentialEvolution", "NelderMead", "Chain", "Steps"]


@dataclass(frozen=True)
class Trace:
    """Every point a search evaluated, in order: points (E, d), values (E,) as evaluated (NaN: undefined),
    generation (E,): the batch each was asked in (0: the first). ``maximise``: whether the best value is the
    largest (falsify's worst case) or the smallest (design's)."""

    points: np.ndarray
    values: np.ndarray
    generation: np.ndarray
    maximise: bool = True

    @property
    def best(self) -> int:
        """Index of the best value (the first of equals); -1 if none is defined."""
        sign = 1.0 if self.maximise else -1.0
        finite = np.where(np.isnan(self.values), -np.inf, sign * self.values)
        return int(np.argmax(finite)) if finite.size and np.isfinite(finite).any() else -1


class Optimiser:
    """The ask/tell interface: :meth:`ask` the next batch of points (S, d), :meth:`tell` their values (S,),
    minimised; :meth:`ask` gives None when the optimiser is done. :meth:`close` ends it early (a worker
    thread, a generator); :func:`drive` closes every optimiser it drives."""

    def ask(self) -> np.ndarray | None:
        raise NotImplementedError

    def tell(self, values: np.ndarray) -> None:
        raise NotImplementedError

    def close(self) -> None:
        """End the optimiser where it stands (nothing more is asked)."""


def drive(optimiser: Optimiser, evaluate: Callable[[np.ndarray], Any], *, maximise: bool = False,
          budget: int | None = None) -> Trace:
    """The one search loop: ask, evaluate, tell, until ``optimiser`` asks for nothing more (or, with
    ``budget``, until that many points are evaluated: a batch is asked only while fewer are).

    Args:
        optimiser: what proposes the points.
        evaluate: points (S, d) -> values (S,), NaN where undefined.
        maximise: tell minus the values (the optimisers minimise).
        budget: the most points to start a batch below; None: the optimiser's own end.

    Returns:
        Trace: every point and value, in evaluation order.

    Raises:
        ValueError: ``evaluate`` returned another number of values than it was given points.
    """
    points: list[np.ndarray] = []
    values: list[np.ndarray] = []
    generation: list[np.ndarray] = []
    spent = 0
    try:
        while budget is None or spent < budget:
            batch = optimiser.ask()
            if batch is None:
                break
            v = np.asarray(evaluate(batch), dtype=float).reshape(-1)
            if v.shape != (len(batch),):
                raise ValueError(f"evaluate returned {v.shape} values for {len(batch)} points")
            generation.append(np.full(len(batch), len(points)))
            points.append(batch)
            values.append(v)
            spent += len(batch)
            optimiser.tell(-v if maximise else v)
    finally:
        optimiser.close()
    if not points:
        return Trace(np.zeros((0, 0)), np.zeros(0), np.zeros(0, dtype=int), maximise)
    return Trace(np.concatenate(points), np.concatenate(values), np.concatenate(generation), maximise)


class Points(Optimiser):
    """A given batch of points (S, d), asked once: a Latin hypercube, the box's vertices, a start."""

    def __init__(self, points: np.ndarray) -> None:
        self._points: np.ndarray | None = np.atleast_2d(np.asarray(points, dtype=float))

    def ask(self) -> np.ndarray | None:
        return self._points

    def tell(self, values: np.ndarray) -> None:
        self._points = None


class CMAES(Optimiser):
    """The ``cmaes`` package's CMA-ES: each :meth:`ask` is one generation (``population_size`` points, each
    kept in ``bounds`` by the package's resampling), each :meth:`tell` its values (NaN told as 1e300). It never
    ends by itself: :attr:`converged` says when the package would stop (a caller restarts or goes on).

    Args:
        mean: the first mean (n,); sigma: the first step; bounds: (n, 2); population: members per generation
            (None: the package's 4 + floor(3 ln n)); seed: the package's own generator's.
    """

    def __init__(self, *, mean: np.ndarray, sigma: float, bounds: np.ndarray, population: int | None = None,
                 seed: int | None = None) -> None:
        self._cma = CMA(mean=mean, sigma=sigma, bounds=bounds, population_size=population, seed=seed)
        self._asked: np.ndarray | None = None
        self.converged = False

    @property
    def population_size(self) -> int:
        return int(self._cma.population_size)

    def ask(self) -> np.ndarray:
        if self._asked is None:
            self._asked = np.array([self._cma.ask() for _ in range(self._cma.population_size)])
        return self._asked

    def tell(self, values: np.ndarray) -> None:
        assert self._asked is not None, "tell before ask"
        self._cma.tell([(x, 1e300 if math.isnan(e) else e) for x, e in zip(self._asked, values)])
        self._asked = None
        self.converged = bool(self._cma.should_stop())


class _Cancelled(BaseException):
    """Raised in a library's objective on its worker thread when its optimiser is closed (a BaseException, so
    that no library's ``except Exception`` takes it for the objective's own error)."""


_DONE = object()


class _Inverted(Optimiser):
    """A library that calls its objective (scipy's optimisers) turned into ask/tell: ``solve(objective)`` runs
    on a worker thread, from the first :meth:`ask`; each call of ``objective(points (S, d)) -> values (S,)`` is
    handed to :meth:`ask` and answered by :meth:`tell`, one thread running at a time. :attr:`result` is what
    ``solve`` returned, once it has (None before, or where it was closed early)."""

    def __init__(self, solve: Callable[[Callable[[np.ndarray], np.ndarray]], Any]) -> None:
        self._solve = solve
        self._asked: queue.Queue[Any] = queue.Queue()
        self._told: queue.Queue[Any] = queue.Queue()
        self._thread: threading.Thread | None = None
        self._done = False
        self.result: Any = None

    def _objective(self, points: np.ndarray) -> np.ndarray:
        self._asked.put(points)
        values = self._told.get()
        if values is _DONE:
            raise _Cancelled
        return values

    def _work(self) -> None:
        try:
            self.result = self._solve(self._objective)
            self._asked.put(_DONE)
        except _Cancelled:
            pass
        except BaseException as exc:  # handed to the asking thread, raised there
            self._asked.put(exc)

    def ask(self) -> np.ndarray | None:
        if self._done:
            return None
        if self._thread is None:
            self._thread = threading.Thread(target=self._work, name="optimiser", daemon=True)
            self._thread.start()
        item = self._asked.get()
        if item is _DONE or isinstance(item, BaseException):
            self._done = True
            self._thread.join()
            if isinstance(item, BaseException):
                raise item
            return None
        return item

    def tell(self, values: np.ndarray) -> None:
        self._told.put(values)

    def close(self) -> None:
        if self._thread is not None and not self._done:
            self._done = True
            self._told.put(_DONE)  # the objective waiting (or the next to wait) raises _Cancelled
            self._thread.join()


class DifferentialEvolution(_Inverted):
    """scipy's ``differential_evolution`` over ``bounds`` (d, 2) with ``options`` passed as they are
    (``vectorized=True``: a generation per batch; else one point per batch). NaN is told as inf.
    :attr:`result`: scipy's ``OptimizeResult`` once it has finished. ``ignore``: warning classes silenced
    while it runs (a generation of inf energies warns)."""

    def __init__(self, bounds: Any, *, ignore: Sequence[type[Warning]] = (), **options: Any) -> None:
        from scipy.optimize import differential_evolution  # scipy.optimize: 0.3 s to import, only where used

        vectorized = bool(options.get("vectorized", False))

        def energies(objective: Callable[[np.ndarray], np.ndarray]) -> Callable[[np.ndarray], Any]:
            def energy(x: np.ndarray) -> Any:  # vectorised: x (d, S); else x (d,)
                told = objective(np.array(x.T, dtype=float) if vectorized else np.array(x, dtype=float)[None, :])
                e = np.where(np.isnan(told), np.inf, told)
                return e if vectorized else e[0]
            return energy

        def solve(objective: Callable[[np.ndarray], np.ndarray]) -> Any:
            with warnings.catch_warnings():
                for category in ignore:
                    warnings.simplefilter("ignore", category)
                return differential_evolution(energies(objective), bounds, **options)

        super().__init__(solve)


class NelderMead(_Inverted):
    """scipy's ``minimize(method="Nelder-Mead")`` from ``start`` with ``bounds`` and ``options`` as they are,
    one point per batch (NaN told as 1e300), its warnings silenced. :attr:`result`: scipy's result."""

    def __init__(self, start: np.ndarray, *, bounds: Any, options: dict[str, Any]) -> None:
        from scipy.optimize import minimize  # scipy.optimize: 0.3 s to import, only where used

        def solve(objective: Callable[[np.ndarray], np.ndarray]) -> Any:
            def energy(x: np.ndarray) -> float:
                e = float(objective(np.atleast_2d(np.asarray(x, dtype=float)))[0])
                return 1e300 if math.isnan(e) else e

            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                return minimize(energy, start, method="Nelder-Mead", bounds=bounds, options=options)

        super().__init__(solve)


class Chain(Optimiser):
    """``optimisers`` one after the other: each asked until it ends, then the next."""

    def __init__(self, *optimisers: Optimiser) -> None:
        self._rest = list(optimisers)

    def ask(self) -> np.ndarray | None:
        while self._rest:
            batch = self._rest[0].ask()
            if batch is not None:
                return batch
            self._rest.pop(0).close()
        return None

    def tell(self, values: np.ndarray) -> None:
        self._rest[0].tell(values)

    def close(self) -> None:
        for opt in self._rest:
            opt.close()
        self._rest = []


#: a strategy's steps: yields a batch of points, receives their told values; returns when done
StepsGenerator = Generator[np.ndarray, np.ndarray, None]


class Steps(Optimiser):
    """A strategy written as a generator (``steps()``: ``values = yield points``), as ask/tell: the strategy
    reads like a loop and keeps its state in its locals, and drives other optimisers inside it (falsify's
    portfolio drives :class:`CMAES`, its polish :class:`NelderMead`)."""

    def __init__(self, steps: Callable[[], StepsGenerator]) -> None:
        self._steps_of = steps
        self._steps: StepsGenerator | None = None
        self._pending: np.ndarray | None = None
        self._done = False

    def ask(self) -> np.ndarray | None:
        if self._done:
            return None
        if self._steps is None:
            self._steps = self._steps_of()
            self._advance(None)
        return self._pending

    def tell(self, values: np.ndarray) -> None:
        self._advance(values)

    def _advance(self, values: np.ndarray | None) -> None:
        assert self._steps is not None
        try:
            self._pending = next(self._steps) if values is None else self._steps.send(values)
        except StopIteration:
            self._done, self._pending = True, None

    def close(self) -> None:
        if self._steps is not None:
            self._steps.close()
        self._done = True
