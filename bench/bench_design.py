"""``wmr-mj design``'s cost: one certificate evaluation, and a whole design.

    .venv/bin/python bench/bench_design.py [--sensing magnetic-12bit-axis] [--repeats 50] [--budget 600]
                                           [--designs 1] [--seeds 2] [--controller computed-torque|sliding-mode]

Printed:

  evaluation: the median wall time (and the quartiles) of one point's score as the search computes it
              (``wmr_mj.searches.design_search._Scorer``: the law built from the point's gains and
              ``wmr_mj.sim.certify.certificate_of`` on the parts ``resolve_run`` gave once), over ``--repeats``
              points drawn uniformly in the law's search space (``_Scorer.bounds``, seeded);
  design:     for each optimiser (:data:`wmr_mj.searches.design_search.METHODS`) and seed (0 .. ``--seeds`` - 1),
              the median wall time of ``search_design`` (the paper circle, the 1 ms period, ``--budget``
              points) over ``--designs`` repeats, with its certified E_max (the same every repeat: the search
              is seeded): which optimiser finds the smaller certificate at the same budget;
  random:     beside them, ``--budget`` points drawn uniformly in the same box per seed, the best certified
              E_max kept (the objective is E_max, so the score is it): what the optimisers add over sampling.

The machine may be shared: the quartiles say how much the load blurs the medians.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time


def main() -> None:
    import dataclasses

    import numpy as np

    from wmr_mj.hardware import Sensing
    from wmr_mj.searches.design_search import (
        LAWS,
        METHODS,
        PENALTY,
        DesignProblem,
        _Scorer,
        law_changes,
        search_design,
    )
    from wmr_mj.sim.config import RunConfig

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sensing", default="magnetic-12bit-axis")
    ap.add_argument("--repeats", type=int, default=50)
    ap.add_argument("--budget", type=int, default=600)
    ap.add_argument("--designs", type=int, default=1)
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--controller", default="computed-torque", choices=LAWS)
    args = ap.parse_args()

    base = RunConfig(**law_changes(args.controller), sensing=Sensing.from_spec(args.sensing))
    problem = DesignProblem(base=base, budget=args.budget, objective="E_max")  # the optimisers on E_max alone
    scorer = _Scorer(problem, 0.001)
    rng = np.random.default_rng(0)
    lows, highs = (list(side) for side in zip(*scorer.bounds(0.001)))
    times = []
    for _ in range(args.repeats):
        x = rng.uniform(lows, highs)
        t0 = time.perf_counter()
        scorer(x)
        times.append(time.perf_counter() - t0)
    q1, med, q3 = statistics.quantiles(times, n=4)
    print(f"evaluation ({args.controller}, {args.sensing}, {args.repeats} points): median {med * 1e3:.1f} ms "
          f"(quartiles {q1 * 1e3:.1f}-{q3 * 1e3:.1f} ms)")
    for method in METHODS:
        for seed in range(args.seeds):
            walls, e_max, evaluations = [], math.nan, 0
            for _ in range(args.designs):
                t0 = time.perf_counter()
                result = search_design(dataclasses.replace(problem, method=method, seed=seed))
                walls.append(time.perf_counter() - t0)
                e_max, evaluations = result.E_max, result.evaluations
            print(f"design {method} seed {seed} (budget {args.budget}, {evaluations} evaluations, {args.designs} "
                  f"repeats): median {statistics.median(walls):.1f} s (min {min(walls):.1f}, max "
                  f"{max(walls):.1f}); certified E_max {e_max:.6g} rad")
    for seed in range(args.seeds):  # the baseline: as many points drawn uniformly in the same box, the best kept
        rng = np.random.default_rng(seed)
        t0 = time.perf_counter()
        best = min(scorer(rng.uniform(lows, highs)) for _ in range(args.budget))
        wall = time.perf_counter() - t0
        found = f"certified E_max {best:.6g} rad" if best < PENALTY else "none certified"
        print(f"design random seed {seed} (budget {args.budget}, {args.budget} evaluations, uniform in the search's "
              f"box): {wall:.1f} s; {found}")


if __name__ == "__main__":
    main()
