"""Single headless run speed: real-time factor and the controller's share of each step.

    .venv/bin/python bench/bench_run.py [--repeats 5] [--model nonholonomic]

A 35 s run of the paper's circle, MuJoCo plant plus the Python computed-torque law at
every 1 ms step, on one core (MuJoCo's own threads are not used). Prints medians of:
  run:        wall time and real-time factor of run_closed_loop (target >= 50x)
  physics:    the same number of mj_step calls alone, same state trajectory replayed
  controller: the law's cost per call, measured on the run's own states, and its share of a step
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import mujoco  # noqa: E402

from controllers import make_controller, model_from_source  # noqa: E402
from wmr_mj import C80
from wmr_mj.plant.mjcf import Plant  # noqa: E402
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--model", default="nonholonomic")
    args = ap.parse_args()
    config = RunConfig(model=args.model, duration=35.0)

    run_wall, physics_wall, law_wall = [], [], []
    for _ in range(args.repeats):
        result = run_closed_loop(config, progress=False)
        run_wall.append(result.summary["wall_s"])
        rows = result.rows
        # physics alone: replay the applied voltages open loop
        plant = Plant(C80)
        m, d = plant.model, plant.data
        u = rows["voltage"]
        act = plant.steer_actuator
        t = time.perf_counter()
        for k in range(len(u)):
            d.ctrl[act] = u[k]
            mujoco.mj_step(m, d)
        physics_wall.append(time.perf_counter() - t)
        # the law alone, on the run's states
        law = make_controller(config.controller, model_from_source(config.model, params=C80)).voltage_scalar
        a, ad, a0, a0d, a0dd = (rows[key].tolist()
                                for key in ("alpha", "alpha_dot", "alpha0", "alpha0_dot", "alpha0_ddot"))
        t = time.perf_counter()
        for k in range(len(a)):
            law(a[k], ad[k], a0[k], a0d[k], a0dd[k])
        law_wall.append(time.perf_counter() - t)
    n = result.summary["steps"]
    run_s, phys_s, law_s = (statistics.median(x) for x in (run_wall, physics_wall, law_wall))
    print(f"35 s run, {n} steps of 1 ms, model {args.model}, {args.repeats} repeats (medians)")
    print(f"closed-loop run     : {run_s:.3f} s wall, {35.0 / run_s:6.1f}x real time (target >= 50x), "
          f"{1e6 * run_s / n:.2f} us/step")
    print(f"mj_step alone       : {phys_s:.3f} s wall, {35.0 / phys_s:6.1f}x real time, {1e6 * phys_s / n:.2f} us/step")
    print(f"controller law      : {1e6 * law_s / n:.2f} us/call = {100 * law_s / run_s:.1f}% of each closed-loop step")
    print(f"rest of the loop    : {1e6 * (run_s - phys_s - law_s) / n:.2f} us/step "
          "(state reads, voltage limit, recording)")


if __name__ == "__main__":
    main()
