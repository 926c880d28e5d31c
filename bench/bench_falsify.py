"""Worst-case search against random sampling at equal budget, ARCH-COMP style (falsification).

    .venv/bin/python bench/bench_falsify.py [--spaces box,paths,signals] [--seeds 10] [--budgets 100,300]
                                            [--duration 20] [--method portfolio] [--path-knots 4]
                                            [--threshold RAD] [--nthread 2] [--first-seed 0]
                                            [--cache logs/falsify-cache.json]

The certified design, objective sup|E|/E_max of its certificate (``wmr-mj falsify``'s default),
over each of three search spaces (``--spaces``, comma-separated; default all three):

  box:     the full uncertainty box (m1, mu, ground_friction, R_a, V_A) on the paper circle;
  paths:   m1 and C's path: ``--path-knots`` (default 4) curvature knots and the hold time
           (``falsify --path-knots 4``), the certificate for the paper's declared reference bounds (5.1);
  signals: m1, R_a and a 1 s steering-torque pulse: amplitude -1.5..1.5 N m (d_max 1.5) and its
           start 2..15 s (``falsify --disturbance kind=pulse,... --range disturbance.amplitude=...``).

For each space, each budget and each of ``--seeds`` seeds, side by side:

  search: ``wmr_mj.searches.falsify.search_worst`` with ``--method`` (default ``portfolio``: the box's
          vertices, then CMA-ES);
  random: the same number of runs as a seeded Latin hypercube (``random_worst``, as falsify does).

Printed per space and budget: the worst objective each found per seed; then, search / random
side by side, the median worst, the best over the seeds, the seeds where the search's worst is
>= random's, the runs the search needed to come within 1% of the vertices' worst (all 2^d
corners), and, for the requirement always(abs(E) <= THRESHOLD) over the whole run, the
falsification rate and the median number of runs to the first falsifying run (in evaluation
order). THRESHOLD defaults per space to a level the space can exceed (box 0.05 rad, paths 0.038,
signals 0.045: its 16 vertices reach 0.0431 rad, the worst found 0.0519). Its robustness is
``threshold - sup|E|``, which the bench reads off the batch (the batch keeps sup|E|, not the
signals); a serial run of the worst vertex checks it against rtamt's monitor (printed). A
summary table of every space and budget closes the output.

Runs are deterministic (bit-identical for the same plant), so the bench keeps one result per
plant point and reuses it across seeds and budgets (the vertices are the same for every seed);
each method is still charged every run it asks for. ``--cache PATH`` keeps those results on disk
(a JSON file, one entry per search space: the base run's configuration, the ranged names and
their bounds, the objective and the MuJoCo version, hashed), so that a later bench over the same
space reuses every run it has already simulated; the printed figures are the same with or
without it. ``--first-seed N`` (default 0) runs seeds N .. N + seeds - 1, so that a search can be
tuned on seeds the bench's figures do not use.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402

from wmr_mj._util.files import write_text_atomic  # noqa: E402
from wmr_mj.params import M1_RANGE, uncertainty_ranges  # noqa: E402
from wmr_mj.searches.falsify import METHODS, FalsifySpec, covering_design, objective_value, random_worst, search_worst  # noqa: E402
from wmr_mj.sim.config import RunConfig  # noqa: E402
from wmr_mj.sim.designs import CERTIFIED  # noqa: E402
from wmr_mj.sim.many_runs import run_configs  # noqa: E402

THRESHOLDS = {"box": 0.05, "paths": 0.038, "signals": 0.045}  # rad: always(abs(E) <= T), one each space can fail


def cache_key(spec: FalsifySpec) -> str:
    """What a run's result depends on besides its point: the base run (duration, path, reference
    bounds, design, ...), the ranged names and bounds, the objective and the simulator's version."""
    import mujoco

    what = {"base": repr(spec.base), "names": list(spec.names), "bounds": spec.bounds.tolist(),
            "objective": spec.objective, "requirement": spec.requirement, "mujoco": mujoco.__version__}
    return hashlib.sha256(json.dumps(what, sort_keys=True).encode()).hexdigest()[:16]


class CachedEvaluator:
    """evaluate(points) -> objective, running only the points not run before (one batch); with
    ``path``, the results of earlier benches over the same space (:func:`cache_key`) are read from
    and written back to that JSON file."""

    def __init__(self, spec: FalsifySpec, nthread: int, path: str | None = None):
        self.spec, self.nthread, self.path = spec, nthread, path
        self.key = cache_key(spec)
        self.cache: dict[tuple[float, ...], tuple[float, float]] = {}  # point -> (objective, sup|E|)
        self.simulated = 0
        self._saved = 0
        if path is not None and Path(path).exists():
            entry = json.loads(Path(path).read_text()).get(self.key, {})
            for point, (v, sup) in zip(entry.get("points", []), entry.get("values", [])):
                self.cache[tuple(float(x) for x in point)] = (float(v), float(sup))
        self.loaded = len(self.cache)

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

    def save(self) -> None:
        """Write the results to ``path`` (nothing without one, or when nothing was simulated since);
        other spaces' entries in the file are kept. Floats go through JSON exactly (repr)."""
        if self.path is None or self.simulated == self._saved:
            return
        path = Path(self.path)
        data = json.loads(path.read_text()) if path.exists() else {}
        points = list(self.cache)
        data[self.key] = {"space": list(self.spec.names), "duration": self.spec.base.duration,
                          "points": [list(p) for p in points], "values": [list(self.cache[p]) for p in points]}
        write_text_atomic(path, json.dumps(data))
        self._saved = self.simulated


def first_at_least(values: np.ndarray, level: float) -> int | None:
    """1-based index of the first value >= level (None: never)."""
    hit = np.nonzero(values >= level)[0]
    return int(hit[0]) + 1 if hit.size else None


def fmt_runs(x: int | None) -> str:
    return "-" if x is None else str(x)


def median_or_dash(xs: list[int | None]) -> str:
    got = [x for x in xs if x is not None]
    return f"{statistics.median(got):g}" if got else "-"


def make_spec(space: str, duration: float, budget: int, method: str, knots: int = 4) -> FalsifySpec:
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
        return FalsifySpec(base=base, box={"m1": M1_RANGE, **KnotSpace(knots, hold_range=(0.0, 3.0)).ranges(bounds)},
                           objective="certificate", budget=budget, method=method)
    ranges = {"R_a": uncertainty_ranges("full")["R_a"]}
    signals = {"disturbance": {"kind": "pulse", "amplitude": 1.0, "t1": 5.0, "t2": 6.0}, "d_max": 1.5}
    base = RunConfig(**CERTIFIED.config_changes(), duration=duration, box_ranges=ranges, signals=signals)
    return FalsifySpec(base=base, box={"m1": M1_RANGE, **ranges, "disturbance.amplitude": (-1.5, 1.5),
                                       "disturbance.t1": (2.0, 15.0)},
                       objective="certificate", budget=budget, method=method)


def bench_space(space: str, args: argparse.Namespace, budgets: list[int]) -> list[dict]:
    """Every budget and seed of one space; the summary row of each budget."""
    threshold = THRESHOLDS[space] if args.threshold is None else args.threshold
    spec = make_spec(space, args.duration, max(budgets), args.method, args.path_knots)
    bounds = spec.bounds
    evaluate = CachedEvaluator(spec, args.nthread, args.cache)
    t0 = time.perf_counter()
    unit = covering_design(len(bounds), 2 ** len(bounds))
    corners = np.where(unit >= 1.0, bounds[:, 1], bounds[:, 0] + unit * (bounds[:, 1] - bounds[:, 0]))  # as searched
    corner_values = evaluate(corners)
    corner_worst = float(np.nanmax(corner_values))
    corner_at = corners[int(np.nanargmax(corner_values))]
    print(f"\n== space {space} ({', '.join(spec.names)}), {args.duration:g} s per run, objective sup|E|/E_max of the "
          f"certificate; search = {args.method}, random = Latin hypercube; {args.seeds} seeds per budget")
    print(f"the box's {len(corners)} vertices: worst objective {corner_worst:.6g} at "
          + ", ".join(f"{n} = {v:g}" for n, v in zip(spec.names, corner_at))
          + f" (sup|E| = {float(evaluate.sup_E(corner_at[None])[0]):.6g} rad)")
    print(f"requirement: always(abs(E) <= {threshold:g}) over the whole run; robustness = "
          f"{threshold:g} - sup|E|; falsified when < 0")
    level = np.nextafter(threshold, np.inf)
    summary = []
    for budget in budgets:
        rows = []
        for seed in range(args.first_seed, args.first_seed + args.seeds):
            search = search_worst(evaluate, bounds, budget=budget, seed=seed, method=args.method)
            random = random_worst(evaluate, bounds, n=len(search.values), seed=seed)
            s_sup, r_sup = evaluate.sup_E(search.points), evaluate.sup_E(random.points)
            rows.append({
                "seed": seed, "runs": len(search.values),
                "search": float(np.nanmax(search.values)), "random": float(np.nanmax(random.values)),
                "to_corner": first_at_least(search.values, 0.99 * corner_worst),
                "s_fals": first_at_least(s_sup, level), "r_fals": first_at_least(r_sup, level),
            })
            evaluate.save()
        wins = sum(r["search"] >= r["random"] for r in rows)
        print(f"\n{space}, budget {budget}:")
        print(f"{'seed':>4}  {'runs':>4}  {'search worst':>12}  {'random worst':>12}  {'winner':>6}  "
              f"{'runs to 99% of vertex worst':>27}  {'search falsified at':>19}  {'random falsified at':>19}")
        for r in rows:
            print(f"{r['seed']:>4}  {r['runs']:>4}  {r['search']:>12.6f}  {r['random']:>12.6f}  "
                  f"{'search' if r['search'] >= r['random'] else 'random':>6}  {fmt_runs(r['to_corner']):>27}  "
                  f"{fmt_runs(r['s_fals']):>19}  {fmt_runs(r['r_fals']):>19}")
        n = len(rows)
        row = {
            "space": space, "budget": budget, "n": n, "wins": wins,
            "median": (statistics.median(r["search"] for r in rows), statistics.median(r["random"] for r in rows)),
            "best": (max(r["search"] for r in rows), max(r["random"] for r in rows)),
            "corner": (sum(r["to_corner"] is not None for r in rows), median_or_dash([r["to_corner"] for r in rows]),
                       sum(r["random"] >= 0.99 * corner_worst for r in rows)),
            "falsified": (sum(r["s_fals"] is not None for r in rows), sum(r["r_fals"] is not None for r in rows)),
            "to_falsify": (median_or_dash([r["s_fals"] for r in rows]), median_or_dash([r["r_fals"] for r in rows])),
            "threshold": threshold,
        }
        summary.append(row)
        print(f"median worst: search {row['median'][0]:.6f}, random {row['median'][1]:.6f}; best: search "
              f"{row['best'][0]:.6f}, random {row['best'][1]:.6f}; search >= random in {wins}/{n} seeds")
        print(f"within 1% of the vertices' worst {corner_worst:.4f}: search {row['corner'][0]}/{n} (median "
              f"{row['corner'][1]} runs), random {row['corner'][2]}/{n}")
        print(f"falsification of always(abs(E) <= {threshold:g}): search {row['falsified'][0]}/{n} (median "
              f"{row['to_falsify'][0]} runs to falsify), random {row['falsified'][1]}/{n} (median "
              f"{row['to_falsify'][1]})")

    # the requirement's robustness off the batch against rtamt's monitor on a serial run of the worst corner
    from wmr_mj.analysis.requirements import evaluate_run, parse_requirement
    from wmr_mj.plant.mjcf import TIMESTEP
    from wmr_mj.sim.closed_loop import run_closed_loop

    result = run_closed_loop(spec.config(corner_at), progress=False)
    req = parse_requirement(f"always(abs(E) <= {threshold!r})", period=TIMESTEP)
    (judged,) = evaluate_run([req], result.rows, result.summary.to_dict(), period=TIMESTEP)
    batch_rob = threshold - float(evaluate.sup_E(corner_at[None])[0])
    print(f"check: at the worst vertex rtamt's robustness {judged.robustness:.9g}, threshold - sup|E| of the batch "
          f"{batch_rob:.9g} ({'equal' if judged.robustness == batch_rob else 'DIFFERENT'})")
    evaluate.save()
    print(f"{evaluate.simulated} distinct runs simulated in {time.perf_counter() - t0:.0f} s"
          + (f" ({evaluate.loaded} read from the cache {args.cache})" if args.cache is not None else ""))
    return summary


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", "--trials", dest="seeds", type=int, default=10, help="seeds per budget (default 10)")
    ap.add_argument("--budgets", default="100,300", help="comma-separated budgets (default 100,300)")
    ap.add_argument("--duration", type=float, default=20.0, help="simulated seconds per run (default 20)")
    ap.add_argument("--method", default="portfolio", choices=METHODS, help="search method (default portfolio)")
    ap.add_argument("--threshold", type=float, default=None,
                    help="the requirement always(abs(E) <= THRESHOLD) rad to falsify (default per space: "
                         + ", ".join(f"{k} {v:g}" for k, v in THRESHOLDS.items()) + ")")
    ap.add_argument("--nthread", type=int, default=2, help="threads of each batch (default 2)")
    ap.add_argument("--spaces", "--space", dest="spaces", default="box,paths,signals",
                    help="comma-separated spaces to search: box, paths, signals (default all three)")
    ap.add_argument("--path-knots", type=int, default=4, help="curvature knots of the paths space (default 4)")
    ap.add_argument("--first-seed", type=int, default=0, help="the first seed (default 0): seeds FIRST .. FIRST + "
                    "SEEDS - 1")
    ap.add_argument("--cache", default=None, metavar="PATH",
                    help="a JSON file of earlier runs (point -> objective, sup|E|) per search space, read and "
                         "updated: the runs are deterministic, so a repeated bench reuses them (default: none)")
    args = ap.parse_args()
    budgets = [int(b) for b in args.budgets.split(",")]
    spaces = [s.strip() for s in args.spaces.split(",") if s.strip()]
    bad = [s for s in spaces if s not in THRESHOLDS]
    if bad or not spaces or any(b < 1 for b in budgets) or args.seeds < 1:
        ap.error(f"--spaces takes box, paths, signals (got {args.spaces!r}); budgets and seeds >= 1")
    if args.cache is not None and Path(args.cache).exists():
        try:
            readable = isinstance(json.loads(Path(args.cache).read_text()), dict)
        except (OSError, ValueError):
            readable = False
        if not readable:
            ap.error(f"--cache {args.cache!r} is not a cache this bench wrote (a JSON object of runs per space); "
                     "give another path or remove the file")
    summary = [row for space in spaces for row in bench_space(space, args, budgets)]
    seeds = f"seeds {args.first_seed}-{args.first_seed + args.seeds - 1}" if args.first_seed else f"{args.seeds} seeds"
    print(f"\nsummary ({args.method} against random, {seeds}, {args.duration:g} s runs):")
    print("| space | budget | median worst: search / random | best: search / random | search >= random | "
          "within 1% of the vertex worst: search (median runs) / random | falsified: search / random "
          "| median runs to falsify: search / random |")
    print("|---|---|---|---|---|---|---|---|")
    for r in summary:
        n = r["n"]
        print(f"| {r['space']} | {r['budget']} | {r['median'][0]:.6f} / {r['median'][1]:.6f} | {r['best'][0]:.6f} / "
              f"{r['best'][1]:.6f} | {r['wins']}/{n} | {r['corner'][0]}/{n} ({r['corner'][1]}) / {r['corner'][2]}/{n} "
              f"| {r['falsified'][0]}/{n} / {r['falsified'][1]}/{n} (|E| > {r['threshold']:g}) "
              f"| {r['to_falsify'][0]} / {r['to_falsify'][1]} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
