"""Closed-loop sweep throughput against MuJoCo's open-loop rollout, same models, threads, steps.

    .venv/bin/python bench/bench_sweep.py [--nsim 128] [--seconds 10] [--nthread 2] [--repeats 3]

Prints physics steps per second (medians over repeats) of
  rollout:    mujoco.rollout stepping the nsim models open loop (C, no Python per step)
  closed:     wmr_mj.sweep.run_batch: mujoco.batch + the vectorised computed-torque law every 1 ms step
and their ratio (target >= 0.90). Compilation and reference generation are outside both timings.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from mujoco import rollout  # noqa: E402

from wmr_mj.plant import compile_model  # noqa: E402
from wmr_mj.simulate import RunConfig, plant_parameters  # noqa: E402
from wmr_mj.sweep import run_batch  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nsim", type=int, default=128)
    ap.add_argument("--seconds", type=float, default=12.0, help="simulated time per run (>= 10 for the circle)")
    ap.add_argument("--nthread", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--model", default="nonholonomic")
    args = ap.parse_args()

    m1 = np.linspace(550.0, 750.0, args.nsim)
    configs = [RunConfig(model=args.model, duration=args.seconds, m1=float(m)) for m in m1]
    models = [compile_model(plant_parameters(c))[0] for c in configs]
    nstep = int(round(args.seconds / models[0].opt.timestep))
    nstate = mujoco.mj_stateSize(models[0], mujoco.mjtState.mjSTATE_FULLPHYSICS)
    initial = np.empty((args.nsim, nstate))
    for i, m in enumerate(models):
        d = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, d, m.key("home").id)
        mujoco.mj_getState(m, d, initial[i], mujoco.mjtState.mjSTATE_FULLPHYSICS)
    control = np.tile(models[0].key("home").ctrl, (args.nsim, nstep, 1))
    control[:, :, 0] = 3.0  # a steering voltage, so the steering moves as in the closed loop
    datas = [mujoco.MjData(models[0]) for _ in range(args.nthread)]

    open_loop, closed_loop = [], []
    with rollout.Rollout(nthread=args.nthread) as r:
        for _ in range(args.repeats):
            t = time.perf_counter()
            r.rollout(models, datas, initial, control)
            open_loop.append(args.nsim * nstep / (time.perf_counter() - t))
            reports = run_batch(configs, nthread=args.nthread)
            closed_loop.append(reports[0]["batch_steps_per_s"])
    ro, cl = statistics.median(open_loop), statistics.median(closed_loop)
    print(f"models: {args.nsim} (m1 550-750 kg), {nstep} steps each, {args.nthread} threads, {args.repeats} repeats")
    print(f"rollout (open loop)      : {ro:12.0f} steps/s  (median; runs: {', '.join(f'{x:.0f}' for x in open_loop)})")
    print(f"closed loop (run_batch)  : {cl:12.0f} steps/s  (median; runs: {', '.join(f'{x:.0f}' for x in closed_loop)})")
    print(f"ratio closed/open        : {cl / ro:.3f}   (target >= 0.90)")


if __name__ == "__main__":
    main()
