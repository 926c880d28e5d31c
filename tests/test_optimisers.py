"""The ask/tell optimiser layer (:mod:`wmr_mj.searches.optimisers`): each optimiser driven by the one loop gives what
its library gives when called directly (the same points, in the same order, the same answer, bit for bit), as
MuJoCo's rollout tests compare against a plain loop; an error of the objective comes back as itself and leaves
no worker thread behind; the loop's record is every point evaluated, in order."""

from __future__ import annotations

import threading

import numpy as np
import pytest
from cmaes import CMA
from scipy.optimize import differential_evolution, minimize

from wmr_mj.errors import ParameterError
from wmr_mj.searches.optimisers import CMAES, Chain, DifferentialEvolution, NelderMead, Points, drive

BOX = np.array([[-1.0, 2.0], [0.0, 3.0], [-2.0, 0.5]])


def rosen(points: np.ndarray) -> np.ndarray:
    """Rosenbrock's function of each row (its minimum 0 at (1, 1, 1), inside BOX)."""
    x = np.atleast_2d(points)
    return np.sum(100.0 * (x[:, 1:] - x[:, :-1] ** 2) ** 2 + (1.0 - x[:, :-1]) ** 2, axis=1)


def _workers() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name == "optimiser"]


def test_cmaes_through_the_loop_is_the_package_in_a_plain_loop():
    opt = CMAES(mean=BOX.mean(axis=1), sigma=0.5, bounds=BOX, seed=3)
    trace = drive(opt, rosen, budget=70)
    direct, asked = CMA(mean=BOX.mean(axis=1), sigma=0.5, bounds=BOX, seed=3), []
    while len(asked) < 70:
        xs = [direct.ask() for _ in range(direct.population_size)]
        asked += xs
        direct.tell([(x, float(rosen(x)[0])) for x in xs])
    assert np.array_equal(trace.points, np.array(asked))
    assert direct.population_size == 7 and trace.generation.tolist() == [g for g in range(10) for _ in range(7)]


@pytest.mark.parametrize("vectorized", [True, False])
def test_differential_evolution_through_the_loop_is_scipys_call(vectorized):
    options = dict(maxiter=6, popsize=5, polish=False, tol=0.0, seed=1, vectorized=vectorized,
                   updating="deferred" if vectorized else "immediate")
    seen: list[np.ndarray] = []

    def energy(x):
        seen.append(np.array(x.T if vectorized else x[None, :], dtype=float))
        return rosen(x.T) if vectorized else float(rosen(x)[0])

    direct = differential_evolution(energy, BOX, **options)
    opt = DifferentialEvolution(BOX, **options)
    trace = drive(opt, rosen)
    assert np.array_equal(trace.points, np.concatenate(seen))
    assert opt.result.fun == direct.fun and np.array_equal(opt.result.x, direct.x)
    assert not _workers()


def test_nelder_mead_through_the_loop_is_scipys_call():
    options = {"maxfev": 80, "xatol": 1e-6}
    seen: list[np.ndarray] = []
    direct = minimize(lambda x: seen.append(x.copy()) or float(rosen(x)[0]), np.zeros(3), method="Nelder-Mead",
                      bounds=BOX, options=options)
    opt = NelderMead(np.zeros(3), bounds=BOX, options=options)
    trace = drive(opt, rosen)
    assert np.array_equal(trace.points, np.array(seen)) and len(trace.values) == direct.nfev
    assert opt.result.fun == direct.fun


def test_an_error_of_the_objective_comes_back_as_itself_and_the_worker_ends():
    def refuse(points):
        raise ParameterError("a bad run")

    with pytest.raises(ParameterError, match="a bad run"):
        drive(DifferentialEvolution(BOX, maxiter=3, popsize=5, seed=0, vectorized=True, updating="deferred"), refuse)
    assert not _workers()


def test_a_search_stopped_by_its_budget_leaves_no_worker_behind():
    trace = drive(NelderMead(np.zeros(3), bounds=BOX, options={"maxfev": 500}), rosen, budget=7)
    assert len(trace.values) == 7 and not _workers()


def test_the_loop_records_every_batch_and_the_best_in_either_sense():
    chain = Chain(Points([[0.0, 0.0, 0.0]]), Points([[1.0, 1.0, 1.0], [2.0, 0.0, 0.0]]))
    trace = drive(chain, rosen)
    assert trace.generation.tolist() == [0, 1, 1]
    assert not trace.maximise and trace.points[trace.best].tolist() == [1.0, 1.0, 1.0]  # Rosenbrock's minimum
    assert drive(Points(trace.points), rosen, maximise=True).best == 2  # maximised: the largest, 1602
    told: list[np.ndarray] = []

    class Recorder(Points):
        def tell(self, values):
            told.append(values)
            super().tell(values)

    drive(Recorder([[0.0, 0.0, 0.0]]), rosen, maximise=True)
    assert told[0].tolist() == [-2.0]  # Rosenbrock at 0 is 2: the optimisers minimise, a maximum is told negated


def test_an_evaluate_that_returns_the_wrong_number_of_values_is_refused():
    with pytest.raises(ValueError, match="2 points"):
        drive(Points(np.zeros((2, 3))), lambda p: np.zeros(3))
