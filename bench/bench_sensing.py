"""The sensing chain's cost: a compiled run with an encoder, a differenced velocity and a delay beside ideal sensing.

    .venv/bin/python bench/bench_sensing.py [--repeats 9] [--seconds 35] [--python-repeats 3]
                                            [--sensing encoder_ticks=4096,velocity=difference,delay=0.005]

The certified design (``RunConfig(model="nonholonomic", kp=100, kd=20, friction_width=0.01)``) on the
paper's circle, --seconds at 1 kHz control, one thread, unlogged; the same run twice:

- ideal sensing (the law reads the simulator's alpha and alpha');
- --sensing (default: a 4096-tick encoder on the steering axis, alpha' a backward difference of the measured
  angle, a 5 ms sensing delay): the chain (:class:`wmr_mj.hardware.SensingChain`) runs in MuJoCo's control
  callback, in C, its state in userdata, and the engine records the measured rows besides.

Both run on the compiled law, alternated A/B within every repeat (a slow spell of a shared machine hits
both), timed two ways: the engine's block loop (``summary.wall_s``: stepping, recording, the rows; models
and the reference outside it, as in bench/bench_run.py) and the whole ``run_closed_loop`` call (resolving
the run, compiling the model with the law and the sensor's numeric, the reference from its cache, the loop,
the summary and the verdicts). Medians of the repeats; the speed ratio sensed / ideal (ideal time over
sensed time) of the medians and paired, the median of the repeat-by-repeat ratios; the same in CPU
seconds of the stepping thread. For reference, the sensed run on the Python path (``law="numpy"``: the
chain's Python ``step`` and the law in Python, one mj_step per control step), --python-repeats times,
and a check that it gives the compiled run's rows to the bit.

Target: the sensed compiled run keeps >= 0.95 of the ideal run's speed (block loop, paired).

``--one ideal|sensed`` runs one side once and nothing else, for an instruction count that the load of a
shared machine does not blur (the callback's own cost, ``wmr_mj_control``, inclusive)::

    valgrind --tool=callgrind --callgrind-out-file=cg.sensed python bench/bench_sensing.py --one sensed --seconds 10
    callgrind_annotate --inclusive=yes cg.sensed | grep -E "wmr_mj_control|mjb_rollout"
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from wmr_mj.sim.closed_loop import RunResult, run_closed_loop  # noqa: E402
from wmr_mj.sim.config import RunConfig  # noqa: E402

TARGET = 0.95
CERTIFIED = {"model": "nonholonomic", "kp": 100.0, "kd": 20.0, "friction_width": 0.01}
SENSING = "encoder_ticks=4096,velocity=difference,delay=0.005"


def _timed(config: RunConfig, law: str = "auto") -> tuple[RunResult, float]:
    """(the run, wall seconds of the whole run_closed_loop call)."""
    t = time.perf_counter()
    run = run_closed_loop(config, progress=False, law=law)
    return run, time.perf_counter() - t


def _line(name: str, xs: list[float], n: int, seconds: float) -> str:
    med = statistics.median(xs)
    return (f"{name:34s} {min(xs):7.3f} {med:7.3f} {max(xs):7.3f}   {1e6 * med / n:6.2f} us/step  "
            f"{seconds / med:5.0f}x real time")


def _ratios(name: str, ideal: list[float], sensed: list[float]) -> str:
    paired = [i / s for i, s in zip(ideal, sensed)]
    return (f"{name:34s} of the medians {statistics.median(ideal) / statistics.median(sensed):.3f}; paired: "
            f"min {min(paired):.3f}  median {statistics.median(paired):.3f}  max {max(paired):.3f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=9)
    ap.add_argument("--seconds", type=float, default=35.0)
    ap.add_argument("--python-repeats", type=int, default=3, help="repeats of the Python path (0: skip it)")
    ap.add_argument("--sensing", default=SENSING, help=f"the sensed run's sensing (default {SENSING})")
    ap.add_argument("--one", choices=("ideal", "sensed"),
                    help="run that side once and nothing else, for a profiler that counts instructions "
                         "(valgrind --tool=callgrind), which the load of a shared machine does not blur")
    args = ap.parse_args()
    ideal_config = RunConfig(duration=args.seconds, **CERTIFIED)
    sensed_config = RunConfig(duration=args.seconds, sensing=args.sensing, **CERTIFIED)
    if args.one:
        run = run_closed_loop(sensed_config if args.one == "sensed" else ideal_config, progress=False)
        print(f"{args.one}: {run.summary.steps} control steps, law {run.law}, block loop {run.summary.wall_s:.3f} s")
        return

    warm_ideal, _ = _timed(ideal_config)  # imports, caches (the reference, the compiled law's library)
    warm_sensed, _ = _timed(sensed_config)
    for run in (warm_ideal, warm_sensed):
        assert run.law == "compiled", run.law_note
    assert "alpha_measured" in warm_sensed.rows and "alpha_measured" not in warm_ideal.rows
    n = warm_sensed.summary.steps
    keys = ("loop", "whole", "cpu")
    times: dict[str, dict[str, list[float]]] = {side: {k: [] for k in keys} for side in ("ideal", "sensed")}
    configs = {"ideal": ideal_config, "sensed": sensed_config}
    for r in range(args.repeats):
        order = ("ideal", "sensed") if r % 2 == 0 else ("sensed", "ideal")  # A/B, then B/A
        for side in order:
            run, whole = _timed(configs[side])
            times[side]["loop"].append(run.summary.wall_s)
            times[side]["whole"].append(whole)
            times[side]["cpu"].append(float(run.cpu_s or 0.0))
    python: list[float] = []
    same_bits = None
    for _ in range(args.python_repeats):
        py, _ = _timed(sensed_config, law="numpy")
        assert py.law == "python", py.law
        python.append(py.summary.wall_s)
        same_bits = all(np.array_equal(py.rows[k], warm_sensed.rows[k]) for k in warm_sensed.rows)

    print(f"certified design, paper circle, {args.seconds:g} s = {n} control steps of 1 ms, compiled law, "
          f"{args.repeats} alternated repeats; sensed: {warm_sensed.config.sensing.label()}")
    print(f"{'seconds':34s} {'min':>7s} {'median':>7s} {'max':>7s}")
    for what, label in (("loop", "block loop"), ("whole", "whole run_closed_loop")):
        for side in ("ideal", "sensed"):
            print(_line(f"{label}, {side}", times[side][what], n, args.seconds))
    print("speed, sensed / ideal (ideal time over sensed time):")
    print(_ratios("  block loop, wall", times["ideal"]["loop"], times["sensed"]["loop"]))
    print(_ratios("  block loop, CPU of the thread", times["ideal"]["cpu"], times["sensed"]["cpu"]))
    print(_ratios("  whole run, wall", times["ideal"]["whole"], times["sensed"]["whole"]))
    paired = statistics.median(i / s for i, s in zip(times["ideal"]["loop"], times["sensed"]["loop"]))
    print(f"target: block loop, paired >= {TARGET}: {'met' if paired >= TARGET else 'NOT met'} ({paired:.3f})")
    if python:
        sensed_loop = statistics.median(times["sensed"]["loop"])
        print(_line("sensed, Python path (law=numpy)", python, n, args.seconds)
              + f"   {sensed_loop / statistics.median(python):.3f} of the compiled sensed run's speed;"
              f" rows the same to the bit: {same_bits}")


if __name__ == "__main__":
    main()
