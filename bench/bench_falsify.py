"""Worst-case search against random sampling at equal budget, ARCH-COMP style (falsification).

    .venv/bin/python bench/bench_falsify.py [--space box|paths|signals] [--trials 10] [--budgets 48,96]
                                            [--duration 20] [--method vertices-polish] [--threshold 0.05]
                                            [--nthread 2]

The certified design, objective sup|E|/E_max of its certificate (``wmr-mj falsify``'s default),
over one of three search spaces (``--space``):

  box:     the full uncertainty box (m1, mu, ground_friction, R_a, V_A) on the paper circle;
  paths:   m1 and C's path: 3 curvature knots and the hold time (``falsify --path-knots 3``),
           the certificate for the paper's declared reference bounds (5.1);
  signals: m1, R_a and a 1 s steering-torque pulse: amplitude -1.5..1.5 N m (d_max 1.5) and its
           start 2..15 s (``falsify --disturbance kind=pulse,... --range disturbance.amplitude=...``).

For each budget and each of ``--trials`` seeds, side by side:

  search: ``wmr_mj.sim.falsify.search_worst`` with ``--method`` (default: the box's vertices,
          then Nelder-Mead from the worst);
  random: the same number of runs as a seeded Latin hypercube (``random_worst``, as falsify does).

Printed: the worst objective each found per seed, the search's wins (worst >= random's), the
runs the search needed to come within 1% of the vertices' worst (the 32 corners of the box:
``wmr-mj sweep --preset certified --uncertainty full --sampling grid --n 32``), and, for the
requirement always(abs(E) <= --threshold) over the whole run, each method's falsification rate
and median number of runs to the first falsifying run (in evaluation order). Its robustness is
``threshold - sup|E|``, which the bench reads off the batch (the batch keeps sup|E|, not the
signals); a serial run of the worst case checks it against rtamt's monitor (printed).

Runs are deterministic (bit-identical for the same plant), so the bench keeps one result per
plant point and reuses it across seeds and budgets (the vertices are the same for every seed);
each method is still charged every run it asks for.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402

from wmr_mj.params import M1_RANGE, uncertainty_ranges  # noqa: E402
from wmr_mj.sim.config import RunConfig  # noqa: E402
from wmr_mj.sim.designs import CERTIFIED  # noqa: E402
from wmr_mj.sim.falsify import FalsifySpec, covering_design, objective_value, random_worst, search_worst  # noqa: E402
from wmr_mj.sim.sweep import run_configs  # noqa: E402


class CachedEvaluator:
    """evaluate(points) -> objective, running only the points not run before (one batch)."""

    def __init__(self, spec: FalsifySpec, nthread: int):
        self.spec, self.nthread = spec, nthread
        self.cache: dict[tuple[float, ...], tuple[float, float]] = {}  # point -> (objective, sup|E|)
        self.simulated = 0

    def __call__(self, points: np.ndarray) -> np.ndarray:
        new = list(dict.fromkeys(tuple(p.tolist()) for p in points if tuple(p.tolist()) not in self.cache))
        if new:
            reports = run_configs([self.spec.config(p) for p in new], nthread=self.nthread)
            self.simulated += len(new)
            for p, r in zip(new, reports):
                v = objective_value(r.to_dict(), self.spec.objective)
                self.cache[p] = (np.nan if v is None else float(v), float(r.sup_E))
        return np.array([self.cache[tuple(p.tolist())][0] for p in points])

    def sup_E(self, points: np.ndarray) -> np.ndarray:
        return np.array([self.cache[tuple(p.tolist())][1] for p in points])


def first_at_least(values: np.ndarray, level: float) -> int | None:
    """1-based index of the first value >= level (None: never)."""
    hit = np.nonzero(values >= level)[0]
    return int(hit[0]) + 1 if hit.size else None


def fmt_runs(x: int | None) -> str:
    return "-" if x is None else str(x)


def median_or_dash(xs: list[int | None]) -> str:
    got = [x for x in xs if x is not None]
    return f"{statistics.median(got):g}" if got else "-"


def make_spec(space: str, duration: float, budget: int, method: str) -> FalsifySpec:
    """The search of ``--space`` (module docstring)."""
    if space == "box":
        ranges = {k: v for k, v in uncertainty_ranges("full").items() if k != "m1"}
        base = RunConfig(**CERTIFIED.config_changes(), duration=duration, box_ranges=ranges)
        return FalsifySpec(base=base, box={"m1": M1_RANGE, **ranges}, objective="certificate", budget=budget,
                           method=method)
    if space == "paths":
        from wmr_mj.reference.bounds import reference_bounds_from
        from wmr_mj.reference.knots import KnotSpace

        bounds = reference_bounds_from("paper")
        base = RunConfig(**CERTIFIED.config_changes(), duration=duration, reference_bounds=bounds)
        return FalsifySpec(base=base, box={"m1": M1_RANGE, **KnotSpace(3, hold_range=(0.0, 3.0)).ranges(bounds)},
                           objective="certificate", budget=budget, method=method)
    ranges = {"R_a": uncertainty_ranges("full")["R_a"]}
    signals = {"disturbance": {"kind": "pulse", "amplitude": 1.0, "t1": 5.0, "t2": 6.0}, "d_max": 1.5}
    base = RunConfig(**CERTIFIED.config_changes(), duration=duration, box_ranges=ranges, signals=signals)
    return FalsifySpec(base=base, box={"m1": M1_RANGE, **ranges, "disturbance.amplitude": (-1.5, 1.5),
                                       "disturbance.t1": (2.0, 15.0)},
                       objective="certificate", budget=budget, method=method)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=10, help="seeds per budget (default 10)")
    ap.add_argument("--budgets", default="48,96", help="comma-separated budgets (default 48,96)")
    ap.add_argument("--duration", type=float, default=20.0, help="simulated seconds per run (default 20)")
    ap.add_argument("--method", default="vertices-polish", help="search method (default vertices-polish)")
    ap.add_argument("--threshold", type=float, default=0.05,
                    help="the requirement always(abs(E) <= THRESHOLD) rad to falsify (default 0.05)")
    ap.add_argument("--nthread", type=int, default=2, help="threads of each batch (default 2)")
    ap.add_argument("--space", default="box", choices=("box", "paths", "signals"),
                    help="what is searched (default box: the full uncertainty box)")
    args = ap.parse_args()
    budgets = [int(b) for b in args.budgets.split(",")]
    spec = make_spec(args.space, args.duration, max(budgets), args.method)
    bounds = spec.bounds
    evaluate = CachedEvaluator(spec, args.nthread)
    t0 = time.perf_counter()
    corners = bounds[:, 0] + covering_design(len(bounds), 2 ** len(bounds)) * (bounds[:, 1] - bounds[:, 0])
    corner_values = evaluate(corners)
    corner_worst = float(np.nanmax(corner_values))
    corner_at = corners[int(np.nanargmax(corner_values))]
    print(f"bench_falsify: certified design, space {args.space} ({', '.join(spec.names)}), "
          f"{args.duration:g} s per run, "
          f"objective sup|E|/E_max of the certificate; search = {args.method}, random = Latin hypercube; "
          f"{args.trials} seeds per budget")
    print(f"the box's {len(corners)} vertices: worst objective {corner_worst:.6g} at "
          + ", ".join(f"{n} = {v:g}" for n, v in zip(spec.names, corner_at))
          + f" (sup|E| = {float(evaluate.sup_E(corner_at[None])[0]):.6g} rad)")
    print(f"requirement: always(abs(E) <= {args.threshold:g}) over the whole run; robustness = "
          f"{args.threshold:g} - sup|E|; falsified when < 0")

    for budget in budgets:
        rows = []
        for seed in range(args.trials):
            search = search_worst(evaluate, bounds, budget=budget, seed=seed, method=args.method)
            random = random_worst(evaluate, bounds, n=len(search.values), seed=seed)
            s_sup, r_sup = evaluate.sup_E(search.points), evaluate.sup_E(random.points)
            rows.append({
                "seed": seed, "runs": len(search.values),
                "search": float(np.nanmax(search.values)), "random": float(np.nanmax(random.values)),
                "to_corner": first_at_least(search.values, 0.99 * corner_worst),
                "s_fals": first_at_least(s_sup, np.nextafter(args.threshold, np.inf)),
                "r_fals": first_at_least(r_sup, np.nextafter(args.threshold, np.inf)),
            })
        wins = sum(r["search"] >= r["random"] for r in rows)
        print(f"\nbudget {budget}:")
        print(f"{'seed':>4}  {'runs':>4}  {'search worst':>12}  {'random worst':>12}  {'winner':>6}  "
              f"{'runs to 99% of vertex worst':>27}  {'search falsified at':>19}  {'random falsified at':>19}")
        for r in rows:
            print(f"{r['seed']:>4}  {r['runs']:>4}  {r['search']:>12.6f}  {r['random']:>12.6f}  "
                  f"{'search' if r['search'] >= r['random'] else 'random':>6}  {fmt_runs(r['to_corner']):>27}  "
                  f"{fmt_runs(r['s_fals']):>19}  {fmt_runs(r['r_fals']):>19}")
        n = len(rows)
        print(f"median worst: search {statistics.median(r['search'] for r in rows):.6f}, random "
              f"{statistics.median(r['random'] for r in rows):.6f}; search >= random in {wins}/{n} seeds")
        near = sum(r["to_corner"] is not None for r in rows)
        print(f"within 1% of the vertices' worst {corner_worst:.4f}: search {near}/{n} (median "
              f"{median_or_dash([r['to_corner'] for r in rows])} runs), random "
              f"{sum(r['random'] >= 0.99 * corner_worst for r in rows)}/{n}")
        s_n, r_n = (sum(r[k] is not None for r in rows) for k in ("s_fals", "r_fals"))
        print(f"falsification of always(abs(E) <= {args.threshold:g}): search {s_n}/{n} (median "
              f"{median_or_dash([r['s_fals'] for r in rows])} runs to falsify), random {r_n}/{n} (median "
              f"{median_or_dash([r['r_fals'] for r in rows])})")

    # the requirement's robustness off the batch against rtamt's monitor on a serial run of the worst corner
    from wmr_mj.analysis.requirements import evaluate_run, parse_requirement
    from wmr_mj.plant.mjcf import TIMESTEP
    from wmr_mj.sim.closed_loop import run_closed_loop

    result = run_closed_loop(spec.config(corner_at), progress=False)
    req = parse_requirement(f"always(abs(E) <= {args.threshold!r})", period=TIMESTEP)
    (judged,) = evaluate_run([req], result.rows, result.summary.to_dict(), period=TIMESTEP)
    batch_rob = args.threshold - float(evaluate.sup_E(corner_at[None])[0])
    print(f"\ncheck: at the worst vertex rtamt's robustness {judged.robustness:.9g}, threshold - sup|E| of the batch "
          f"{batch_rob:.9g} ({'equal' if judged.robustness == batch_rob else 'DIFFERENT'})")
    print(f"{evaluate.simulated} distinct runs simulated in {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
