"""The whole ``wmr-mj compare`` against MuJoCo's open-loop rollout of the same models: steps per second.

    .venv/bin/python bench/bench_compare.py [--designs certified,pd] [--scenarios '*'] [--budgets 0,16]
                                            [--nthread 2] [--repeats 3]

Side by side in one process, interleaved repeat by repeat (medians over ``--repeats``):

  rollout: ``mujoco.rollout`` of every scenario run's model (each design on each selected scenario of
           ``standard-v1``), open loop, driven by the voltages its closed loop applied (serial runs
           before the timings; the suite's disturbance and payload signals are not replayed: they
           change the forces, not the cost of a step), on ``--nthread`` threads;
  compare: ``wmr_mj.experiments.compare.compare`` then ``wmr_mj.report.compare.write_report``, as the command
           runs them (every scenario run and judged by the suite's four requirements, the adversary's
           search and random sample at each budget of ``--budgets``, the Markdown, CSV, HTML and figure
           written; the command's imports excluded), on the same threads. Its physics steps
           (``CompareResult.steps``): every scenario run's and every adversary run's (those are drawn by
           the search, so they are counted, not replayed).

Printed: steps per second of each and their ratio, compare / rollout (target >= 0.85), and the
paired ratio (the median of the repeat-by-repeat ratios); then (unless ``--no-cpu``) the same ratio in
CPU seconds with one thread each side (``compare(nthread=1)`` timed by the process's CPU clock, rollout
by the thread's), which other processes on the machine do not blur as they blur wall time. The
machine may be shared: compare ratios, not absolute figures.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_sweep import OpenLoop, applied_voltages  # noqa: E402
from mujoco import rollout  # noqa: E402

from wmr_mj.experiments.compare import compare, design_from_token  # noqa: E402
from wmr_mj.experiments.suite import load_suite  # noqa: E402
from wmr_mj.report.compare import write_report  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", default="certified,pd", help="designs, comma-separated (compare's DESIGN tokens)")
    ap.add_argument("--scenarios", default="*", help="shell pattern of the scenario ids (default: all 30)")
    ap.add_argument("--budgets", default="0,16", help="the adversary's budgets, comma-separated (0: none)")
    ap.add_argument("--nthread", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-cpu", action="store_true", help="skip the one-thread CPU-time ratios")
    args = ap.parse_args()
    budgets = [int(b) for b in args.budgets.split(",") if b.strip()]

    suite = load_suite("standard-v1")
    designs = [design_from_token(t.strip(), suite) for t in args.designs.split(",") if t.strip()]
    chosen = suite.select([args.scenarios])
    configs = [s.config(d.config) for d in designs for s in chosen]
    voltages = applied_voltages(configs)
    open_loop = OpenLoop(configs, voltages, args.nthread)
    one_thread = OpenLoop(configs, voltages, 0)  # 0: rollout on the calling thread

    rollout_rates: list[float] = []
    compare_rates: dict[int, list[float]] = {b: [] for b in budgets}
    cpu_rollout: list[float] = []
    cpu_compare: dict[int, list[float]] = {b: [] for b in budgets}
    with (rollout.Rollout(nthread=args.nthread) as pool, rollout.Rollout(nthread=0) as caller,
          tempfile.TemporaryDirectory() as tmp):
        for rep in range(args.repeats):
            rollout_rates.append(open_loop.steps_per_s(pool))
            for budget in budgets:
                t = time.perf_counter()
                result = compare(designs, suite, scenarios=[args.scenarios], budget=budget, seed=0,
                                 nthread=args.nthread)
                write_report(result, Path(tmp) / f"compare-{budget}-{rep}")
                wall = time.perf_counter() - t
                compare_rates[budget].append(result.steps / wall)
            if not args.no_cpu:  # CPU seconds, one thread each side
                cpu_rollout.append(one_thread.steps_per_s(caller, clock=time.thread_time))
                for budget in budgets:
                    c = time.process_time()
                    result = compare(designs, suite, scenarios=[args.scenarios], budget=budget, seed=0, nthread=1)
                    write_report(result, Path(tmp) / f"compare-cpu-{budget}-{rep}")
                    cpu_compare[budget].append(result.steps / (time.process_time() - c))

    ro = statistics.median(rollout_rates)
    print(f"compare of {len(designs)} designs ({args.designs}) x {len(chosen)} scenarios of {suite.name} "
          f"({suite.duration:g} s each), {args.nthread} threads, {args.repeats} repeats (medians)")
    print(f"rollout of the scenarios' models: {ro:.0f} steps/s")
    for budget in budgets:
        rates = compare_rates[budget]
        cl = statistics.median(rates)
        paired = statistics.median(c / o for c, o in zip(rates, rollout_rates))
        runs = len(configs) + 2 * budget * len(designs)
        print(f"whole compare, adversary budget {budget} ({runs} runs): {cl:.0f} steps/s, ratio {cl / ro:.3f}, "
              f"paired {paired:.3f} (target >= 0.85)")
    if cpu_rollout:
        rc = statistics.median(cpu_rollout)
        print(f"CPU seconds, one thread each side: rollout {rc:.0f} steps per CPU second")
        for budget in budgets:
            cc = statistics.median(cpu_compare[budget])
            print(f"whole compare, adversary budget {budget}: {cc:.0f} steps per CPU second, ratio {cc / rc:.3f}")


if __name__ == "__main__":
    main()
