"""Single-run speed: the closed loop (one engine, compiled law) against bare stepping, in one process.

    .venv/bin/python bench/bench_run.py [--repeats 7] [--seconds 35] [--model nonholonomic] [--no-command]

A --seconds run of the paper's circle at 1 kHz control, one thread. Variants alternated within
every repeat (a slow spell of a shared machine hits all of them); min / median / max printed:

- closed loop: ``run_closed_loop`` unlogged, its block loop (stepping, recording, the rows);
  model compilation and the reference are outside the timing, as in bench/bench_sweep.py;
- bare stepping: ``mujoco.rollout`` of the same model (the plant without the law), one thread,
  driven open loop by the voltages the closed loop applied; outputs allocated once; it ends
  where the closed loop ended, to the bit (checked);
- Python law: the same engine with ``law="numpy"`` (``voltage_scalar`` and one mj_step a time);
- the old serial loop (tests/reference_loop.py), for the before/after ratio;
- the whole ``wmr-mj run --no-log`` command (a subprocess: interpreter start, imports, models,
  reference, run, report), beside them.

Target: closed loop / bare stepping >= 0.95 (as a speed: bare time / closed-loop time).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))  # the serial reference loop

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from mujoco import rollout  # noqa: E402

from wmr_mj.sim.closed_loop import run_closed_loop  # noqa: E402
from wmr_mj.sim.config import RunConfig, plant_parameters  # noqa: E402
from wmr_mj.sim.engine import batch_model, plant_options  # noqa: E402

TARGET = 0.95


class Bare:
    """mujoco.rollout of the run's model, open loop, with the applied voltages, on the calling thread."""

    def __init__(self, config: RunConfig, voltage: np.ndarray) -> None:
        self.m = m = batch_model(plant_parameters(config), **plant_options(config))
        spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
        d = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, d, m.key("home").id)
        self.initial = np.empty((1, mujoco.mj_stateSize(m, spec)))
        mujoco.mj_getState(m, d, self.initial[0], spec)
        self.control = np.tile(m.key("home").ctrl, (1, len(voltage), 1))
        self.control[0, :, m.actuator("steering_motor").id] = voltage
        self.data = mujoco.MjData(m)
        self.state = np.zeros((1, len(voltage), mujoco.mj_stateSize(m, spec)))  # pages touched outside the timing
        self.sensordata = np.zeros((1, len(voltage), m.nsensordata))

    def seconds(self, pool: rollout.Rollout) -> tuple[float, float]:
        """(wall, CPU of this thread) seconds of one rollout."""
        t, c = time.perf_counter(), time.thread_time()
        pool.rollout(self.m, self.data, self.initial, self.control, state=self.state, sensordata=self.sensordata)
        return time.perf_counter() - t, time.thread_time() - c


def _stats(xs: list[float]) -> str:
    return f"min {min(xs):.3f}  median {statistics.median(xs):.3f}  max {max(xs):.3f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--seconds", type=float, default=35.0)
    ap.add_argument("--model", default="nonholonomic")
    ap.add_argument("--no-command", action="store_true", help="skip the whole wmr-mj run command")
    ap.add_argument("--no-reference", action="store_true", help="skip the old serial loop and the Python law")
    args = ap.parse_args()
    config = RunConfig(model=args.model, duration=args.seconds)

    warm = run_closed_loop(config, progress=False)  # imports, caches; the voltages of the bare run
    assert warm.law == "compiled", warm.law_note
    bare = Bare(config, warm.rows["voltage"])
    n = warm.summary.steps
    command = [str(ROOT / ".venv/bin/wmr-mj"), "run", "--no-log", "--json", "--model", args.model,
               "--duration", repr(args.seconds)]
    times: dict[str, list[float]] = {"closed": [], "bare": [], "ratio": [], "closed_cpu": [], "bare_cpu": [],
                                     "ratio_cpu": []}
    if not args.no_reference:
        from reference_loop import reference_run

        times.update(python=[], serial=[])
    if not args.no_command:
        times["command"] = []
    with rollout.Rollout(nthread=0) as pool:  # steps on the calling thread
        bare.seconds(pool)
        for _ in range(args.repeats):
            run = run_closed_loop(config, progress=False)
            closed, closed_cpu = run.summary.wall_s, run.cpu_s
            b, b_cpu = bare.seconds(pool)
            times["closed"].append(closed)
            times["bare"].append(b)
            times["ratio"].append(b / closed)
            times["closed_cpu"].append(closed_cpu)
            times["bare_cpu"].append(b_cpu)
            times["ratio_cpu"].append(b_cpu / closed_cpu)
            if not args.no_reference:
                times["python"].append(run_closed_loop(config, progress=False, law="numpy").summary.wall_s)
                times["serial"].append(reference_run(config, progress=False).summary.wall_s)
            if not args.no_command:
                t = time.perf_counter()
                subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
                times["command"].append(time.perf_counter() - t)
    # the bare run ends where the closed loop ended (same model, same voltages): the same physics
    final_alpha = float(warm.rows["alpha"][-1])
    same = bool(bare.state[0, -2, 1 + bare.m.jnt_qposadr[bare.m.joint("steer").id]] == final_alpha)  # time, qpos

    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"{args.seconds:g} s run, {n} steps of 1 ms, model {args.model}, {args.repeats} alternated repeats; "
          "seconds: min / median / max")
    print(f"closed loop (engine, compiled law)  {_stats(times['closed'])}   {1e6 * med['closed'] / n:.2f} us/step, "
          f"{args.seconds / med['closed']:.0f}x real time")
    print(f"bare stepping (mujoco.rollout)       {_stats(times['bare'])}   {1e6 * med['bare'] / n:.2f} us/step"
          f"   (same trajectory: {same})")
    r = times["ratio"]
    print(f"closed loop / bare stepping speed   per repeat: min {min(r):.3f}  median {statistics.median(r):.3f}  "
          f"max {max(r):.3f};  of medians {med['bare'] / med['closed']:.3f}   target >= {TARGET}")
    r = times["ratio_cpu"]
    print(f"  the same in CPU time of the thread: closed {_stats(times['closed_cpu'])}, bare "
          f"{_stats(times['bare_cpu'])}; speed per repeat: min {min(r):.3f}  median {statistics.median(r):.3f}  "
          f"max {max(r):.3f}")
    if not args.no_reference:
        print(f"same engine, Python law              {_stats(times['python'])}   "
              f"{1e6 * med['python'] / n:.2f} us/step = {med['bare'] / med['python']:.3f} of bare")
        print(f"old serial loop (tests/)             {_stats(times['serial'])}   "
              f"{1e6 * med['serial'] / n:.2f} us/step = {med['bare'] / med['serial']:.3f} of bare;  "
              f"engine is {med['serial'] / med['closed']:.2f}x faster")
    if not args.no_command:
        print(f"whole `wmr-mj run --no-log` command  {_stats(times['command'])}   "
              "(interpreter, imports, models, reference, run, report)")


if __name__ == "__main__":
    main()
