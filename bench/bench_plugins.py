"""Plug-in law speed: a law of one's own compiled by numba, in Python, and the built-in compiled laws, in one process.

    .venv/bin/python bench/bench_plugins.py [--repeats 7] [--seconds 35] [--batch 32] [--batch-seconds 10]
                                            [--batch-repeats 5] [--nthread 2]

The plug-in is examples/fast_pd.py:FastPD (a PD with the reference's feedforward, stateless,
offering ``law(p, ...)``), named by file as ``wmr-mj run --controller`` names it. Variants are
alternated within every repeat (a slow spell of a shared machine hits all of them); medians of
the repeats, and ratios as the median of the repeat-by-repeat ratios (paired):

(a) one --seconds run of the paper's circle at 1 kHz control, one thread, unlogged; the block
    loop's wall time (``summary.wall_s``: stepping, recording, rows; models, the reference and
    numba's compilation outside the timing, as in bench/bench_run.py):
    - built-in PD and built-in computed torque, compiled in the callback;
    - the plug-in compiled by numba into the same callback (``law`` kind 2);
    - the plug-in on the Python path (``law="numpy"``: its ``voltage_scalar``, i.e. ``law`` run in
      Python, one call and one mj_step per control step);
    - bare ``mujoco.rollout`` of the same model, open loop, with the voltages the plug-in applied
      (it ends where the plug-in's run ended, to the bit: checked).
(b) a batch of --batch runs (m1 550-750 kg, --batch-seconds each) through ``run_batch`` on
    --nthread threads: the same laws (the plug-in compiled by numba, and its NumPy ``batch_law``
    path, ``law="numpy"``), against open-loop ``mujoco.rollout`` of the same models (steps/s);
    beside them the same in CPU seconds: one thread's share (--batch / --nthread runs) on one
    thread each side, which the load of other processes does not blur as it blurs wall time
    (as in bench/bench_sweep.py); likewise the single run's CPU seconds of its thread.

Targets: the plug-in compiled / the built-in compiled law >= 0.9 on a single run; the plug-in
compiled in a batch of 32 / rollout >= 0.8. The machine may be shared: compare ratios.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

import numpy as np  # noqa: E402
from bench_run import Bare  # noqa: E402
from bench_sweep import OpenLoop, applied_voltages  # noqa: E402
from mujoco import rollout  # noqa: E402

from wmr_mj.sim.batch import run_batch  # noqa: E402
from wmr_mj.sim.closed_loop import run_closed_loop  # noqa: E402
from wmr_mj.sim.config import RunConfig  # noqa: E402

PLUGIN = f"{ROOT / 'examples' / 'fast_pd.py'}:FastPD"
# name -> (controller, law backend)
LAWS = {"built-in PD": ("pd", "auto"), "built-in CT": ("computed-torque", "auto"),
        "plug-in, numba": (PLUGIN, "auto"), "plug-in, Python": (PLUGIN, "numpy")}
REFERENCE = "built-in PD"


def _med(xs: list[float]) -> float:
    return statistics.median(xs)


def single(args: argparse.Namespace) -> None:
    configs = {name: RunConfig(model=args.model, duration=args.seconds, controller=c) for name, (c, _) in LAWS.items()}
    warm = {name: run_closed_loop(configs[name], progress=False, law=law) for name, (_, law) in LAWS.items()}
    for name, (_, law) in LAWS.items():  # each took the path it is named for
        assert warm[name].law == ("python" if law == "numpy" else "compiled"), (name, warm[name].law_note)
    plugin = warm["plug-in, numba"]
    same_bits = all(np.array_equal(plugin.rows[k], warm["plug-in, Python"].rows[k]) for k in plugin.rows)
    bare = Bare(configs["plug-in, numba"], plugin.rows["voltage"])
    n = plugin.summary.steps
    wall: dict[str, list[float]] = {name: [] for name in [*LAWS, "bare rollout"]}
    cpu: dict[str, list[float]] = {name: [] for name in wall}  # CPU seconds of the stepping thread
    with rollout.Rollout(nthread=0) as pool:  # steps on the calling thread
        bare.seconds(pool)
        for _ in range(args.repeats):
            for name, (_, law) in LAWS.items():
                run = run_closed_loop(configs[name], progress=False, law=law)
                wall[name].append(run.summary.wall_s)
                cpu[name].append(run.cpu_s)
            w, c = bare.seconds(pool)
            wall["bare rollout"].append(w)
            cpu["bare rollout"].append(c)
    same = bool(bare.state[0, -2, 1 + bare.m.jnt_qposadr[bare.m.joint("steer").id]] == plugin.rows["alpha"][-1])
    print(f"(a) one {args.seconds:g} s run, {n} control steps of 1 ms, model {args.model}, {args.repeats} alternated "
          "repeats; the block loop's wall time, medians; speed ratios paired repeat by repeat")
    print(f"{'':24s} {'median s':>9s} {'us/step':>8s} {'x real time':>12s} {'vs ' + REFERENCE:>16s} "
          f"{'vs rollout':>11s}   in CPU s of the thread: {'vs ' + REFERENCE:>16s} {'vs rollout':>11s}")
    for name, xs in wall.items():
        vs_ref = _med([r / x for r, x in zip(wall[REFERENCE], xs)])
        vs_bare = _med([b / x for b, x in zip(wall["bare rollout"], xs)])
        cpu_ref = _med([r / x for r, x in zip(cpu[REFERENCE], cpu[name])])
        cpu_bare = _med([b / x for b, x in zip(cpu["bare rollout"], cpu[name])])
        print(f"{name:24s} {_med(xs):9.3f} {1e6 * _med(xs) / n:8.2f} {args.seconds / _med(xs):12.0f} "
              f"{vs_ref:16.3f} {vs_bare:11.3f}   {'':24s} {cpu_ref:16.3f} {cpu_bare:11.3f}")
    print(f"plug-in: numba and Python rows bit-identical: {same_bits}; rollout ends where the plug-in's run "
          f"ended, to the bit: {same}. Target: plug-in, numba vs {REFERENCE} >= 0.9")


def batch(args: argparse.Namespace) -> None:
    masses = np.linspace(550.0, 750.0, args.batch)
    configs = {name: [RunConfig(model=args.model, duration=args.batch_seconds, controller=c, m1=float(m))
                      for m in masses] for name, (c, _) in LAWS.items()}
    plugin = configs["plug-in, numba"]
    open_loop = OpenLoop(plugin, applied_voltages(plugin), args.nthread)
    share = max(1, args.batch // max(args.nthread, 1))  # one thread's share, for the CPU-time ratios
    one = OpenLoop(plugin[:share], applied_voltages(plugin[:share]), 0)
    rate: dict[str, list[float]] = {name: [] for name in ["rollout (open loop)", *LAWS]}
    cpu: dict[str, list[float]] = {name: [] for name in rate}  # steps per CPU second of one thread, its share
    same: dict[str, bool] = {}
    for name, (_, law) in LAWS.items():  # warm: imports, numba's compilation
        reports = run_batch(configs[name], nthread=args.nthread, law=law)
        assert {r.batch.law for r in reports} == {"numpy" if law == "numpy" else "compiled"}, name
    with rollout.Rollout(nthread=args.nthread) as pool, rollout.Rollout(nthread=0) as caller:
        open_loop.steps_per_s(pool)
        for _ in range(args.batch_repeats):
            rate["rollout (open loop)"].append(open_loop.steps_per_s(pool))
            for name, (_, law) in LAWS.items():
                reports = run_batch(configs[name], nthread=args.nthread, law=law)
                rate[name].append(reports[0].batch.steps_per_s)
                if name.startswith("plug-in"):
                    same[name] = open_loop.same_as(reports)
            if not args.no_cpu:  # one thread's share on one thread, in its CPU seconds: load does not blur it
                cpu["rollout (open loop)"].append(one.steps_per_s(caller, clock=time.thread_time))
                for name, (_, law) in LAWS.items():
                    cpu_s = run_batch(configs[name][:share], nthread=1, law=law)[0].batch.cpu_s
                    cpu[name].append(share * one.nstep / cpu_s)
    print(f"\n(b) a batch of {args.batch} runs of {args.batch_seconds:g} s (m1 550-750 kg), run_batch on "
          f"{args.nthread} threads, {args.batch_repeats} alternated repeats; physics steps/s, medians; "
          "ratios paired repeat by repeat")
    print(f"{'':24s} {'steps/s':>10s} {'vs ' + REFERENCE:>16s} {'vs rollout':>11s}   "
          f"{share} runs on 1 thread, steps per CPU s: {'':>10s} {'vs ' + REFERENCE:>16s} {'vs rollout':>11s}")
    for name, xs in rate.items():
        vs_ref = _med([x / r for x, r in zip(xs, rate[REFERENCE])])
        vs_bare = _med([x / b for x, b in zip(xs, rate["rollout (open loop)"])])
        line = f"{name:24s} {_med(xs):10.0f} {vs_ref:16.3f} {vs_bare:11.3f}"
        if cpu[name]:
            c_ref = _med([x / r for x, r in zip(cpu[name], cpu[REFERENCE])])
            c_bare = _med([x / b for x, b in zip(cpu[name], cpu["rollout (open loop)"])])
            line += f"   {'':37s}{_med(cpu[name]):10.0f} {c_ref:16.3f} {c_bare:11.3f}"
        print(line)
    print(f"the plug-in's batches end where open-loop rollout of their voltages ends, to the bit: "
          f"{', '.join(f'{k}: {v}' for k, v in same.items())}. Target: plug-in, numba vs rollout >= 0.8")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--seconds", type=float, default=35.0)
    ap.add_argument("--batch", type=int, default=32, help="runs in the batch (0: skip the batch)")
    ap.add_argument("--batch-seconds", type=float, default=10.0)
    ap.add_argument("--batch-repeats", type=int, default=5)
    ap.add_argument("--nthread", type=int, default=2)
    ap.add_argument("--model", default="nonholonomic")
    ap.add_argument("--no-cpu", action="store_true", help="skip the batch's one-thread CPU-time ratios")
    args = ap.parse_args()
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    single(args)
    if args.batch:
        batch(args)
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())} at the end")


if __name__ == "__main__":
    main()
