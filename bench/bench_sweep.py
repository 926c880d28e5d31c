"""Closed-loop sweep throughput against MuJoCo's open-loop rollout: same models, threads and steps.

    .venv/bin/python bench/bench_sweep.py [--sizes 16,32,64,128,256] [--seconds 10] [--nthread 2]
                                          [--repeats 3] [--sweep-n 32] [--sweep-seconds 35] [--no-cpu]
                                          [--projections C,NumPy]

For each batch size, side by side in one process and interleaved repeat by repeat, prints the
physics steps per second (medians over repeats) of

  rollout:  ``mujoco.rollout`` stepping the models open loop (C, no Python per step), each
            driven by the voltages its own closed-loop run applied (from a serial run before
            the timings), so that both loops do the same physics step for step (checked: the
            open loop ends where the closed loop did, to the bit); rollout records every
            step into output arrays allocated once;
  compiled: ``wmr_mj.sim.batch.run_batch`` as it runs by default: the law in C as MuJoCo's control
            callback (``wmr_mj.sim.compiled_law``), ``Batch.rollout`` a block of 1000 closed-loop
            steps per call, statistics folded per block (compilation and reference outside
            the timing);
  numpy:    ``run_batch(law="numpy")``: ``mujoco.batch.Batch.step`` every 1 ms step with the
            vectorised NumPy law in between (the library-only path, shown beside ours);

and their ratios to rollout (target >= 0.90); beside them the same ratios in CPU seconds of one
thread's share (nsim/nthread runs on one thread each side), which other processes on the
machine do not blur as they blur wall time. Then the whole sweep as ``wmr-mj sweep --n 32``
runs it (``run_sweep`` with its output folder: drawing, compilation, reference, statistics and
the CSV included; the command's imports and plot excluded) against rollout of the same models
(target >= 0.85), with either law and, with ``--projections C,NumPy``, with C's projection on its
path in C (``wmr_mj/analysis/_nearest_chord.c``, the default where it is built) and in NumPy side by
side. The machine may be shared: compare ratios, not absolute figures.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from mujoco import rollout  # noqa: E402

from wmr_mj.experiments.sweep import SweepSpec, run_sweep  # noqa: E402
from wmr_mj.sim.batch import batch_model, run_batch  # noqa: E402
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig, plant_parameters


def applied_voltages(configs: list[RunConfig]) -> np.ndarray:
    """(nsim, nstep) steering voltage each config's closed loop applies (serial runs)."""
    return np.stack([run_closed_loop(c, progress=False).rows["voltage"] for c in configs])


class OpenLoop:
    """Rollout of the models of ``configs``, open loop, on ``nthread`` threads."""

    def __init__(self, configs: list[RunConfig], voltage: np.ndarray, nthread: int):
        self.models = [batch_model(plant_parameters(c)) for c in configs]
        m = self.models[0]
        self.nstep = voltage.shape[1]
        spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
        self.initial = np.empty((len(configs), mujoco.mj_stateSize(m, spec)))
        for i, model in enumerate(self.models):
            d = mujoco.MjData(model)
            mujoco.mj_resetDataKeyframe(model, d, model.key("home").id)
            mujoco.mj_getState(model, d, self.initial[i], spec)
        self.control = np.tile(m.key("home").ctrl, (len(configs), self.nstep, 1))
        self.control[:, :, m.actuator("steering_motor").id] = voltage
        self.datas = [mujoco.MjData(m) for _ in range(max(nthread, 1))]
        self.nthread = nthread
        # rollout records every step; its outputs are allocated (and their pages touched) once,
        # outside the timings, so that they time the stepping and not the page faults
        self.state = np.zeros((len(configs), self.nstep, mujoco.mj_stateSize(m, spec)))
        self.sensordata = np.zeros((len(configs), self.nstep, m.nsensordata))

    def steps_per_s(self, pool: rollout.Rollout, *, clock=time.perf_counter) -> float:
        t = clock()
        state, _ = pool.rollout(self.models, self.datas, self.initial, self.control, state=self.state,
                                sensordata=self.sensordata)
        rate = len(self.models) * self.nstep / (clock() - t)
        m = self.models[0]
        self.final_alpha = state[:, -1, 1 + m.jnt_qposadr[m.joint("steer").id]]  # state: time, qpos, ...
        return rate

    def same_as(self, reports: list[dict]) -> bool:
        """Whether the open loop ended where the closed loop did, to the bit (the same physics)."""
        return bool(np.array_equal(self.final_alpha, [r.batch.final_alpha_after_step for r in reports]))


def _median_ratio(num: list[float], den: list[float]) -> str:
    return f"{statistics.median(num) / statistics.median(den):7.3f}" if num and den else f"{'-':>7s}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="16,32,64,128,256", help="batch sizes, comma-separated")
    ap.add_argument("--seconds", type=float, default=10.0,
                    help="simulated time per run in the batch comparison (>= 10 for the circle)")
    ap.add_argument("--nthread", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--model", default="nonholonomic")
    ap.add_argument("--laws", default="compiled,numpy", help="closed-loop laws to time, comma-separated")
    ap.add_argument("--sweep-n", type=int, default=32, help="runs of the whole-sweep comparison (0: skip it)")
    ap.add_argument("--sweep-seconds", type=float, default=35.0, help="simulated time per run of the whole sweep")
    ap.add_argument("--no-cpu", action="store_true", help="skip the one-thread CPU-time ratios")
    ap.add_argument("--projections", default="C", help="how the whole sweep projects C on its path, comma-separated: "
                    "C (the compiled loop, where built), NumPy (WMR_MJ_COMPILED_PROJECTION=0); both: side by side")
    args = ap.parse_args()
    sizes = [int(x) for x in args.sizes.split(",") if x.strip()]
    laws = [x.strip() for x in args.laws.split(",") if x.strip()]
    projections = [x.strip() for x in args.projections.split(",") if x.strip()]
    if not projections or set(projections) - {"C", "NumPy"}:
        ap.error(f"--projections takes C, NumPy or both (got {args.projections!r})")
    from wmr_mj.analysis import path_error

    os.environ.pop("WMR_MJ_COMPILED_PROJECTION", None)  # each case sets it below
    if "C" in projections and path_error.projection_backend() != "C":
        ap.error("--projections C: the C projection is not built here (wmr_mj.analysis._nearest_chord); give NumPy")

    cases = {}
    for nsim in sizes:
        configs = [RunConfig(model=args.model, duration=args.seconds, m1=float(m))
                   for m in np.linspace(550.0, 750.0, nsim)]
        voltages = applied_voltages(configs)
        per_thread = max(1, nsim // max(args.nthread, 1))  # one thread's share, for the CPU-time ratio
        cases[nsim] = (configs, OpenLoop(configs, voltages, args.nthread),
                       OpenLoop(configs[:per_thread], voltages[:per_thread], 0))
    open_loop: dict[int, list[float]] = {n: [] for n in sizes}
    closed = {law: {n: [] for n in sizes} for law in laws}
    cpu = {law: {n: [] for n in sizes} for law in laws}
    same: dict[tuple[str, int], bool] = {}
    sweep_open: list[float] = []
    sweep_closed: dict[tuple[str, str], list[float]] = {(law, p): [] for law in laws for p in projections}
    spec = (SweepSpec(n=args.sweep_n, seed=0, base=RunConfig(model=args.model, duration=args.sweep_seconds))
            if args.sweep_n else None)
    with (rollout.Rollout(nthread=args.nthread) as pool, rollout.Rollout(nthread=0) as caller,
          tempfile.TemporaryDirectory() as tmp):
        sweep_ol = None
        if spec is not None:
            from wmr_mj.experiments.sweep import _run_configs, draw_samples

            sweep_configs = _run_configs(spec, draw_samples(spec))
            sweep_ol = OpenLoop(sweep_configs, applied_voltages(sweep_configs), args.nthread)
        for rep in range(args.repeats):
            for nsim in sizes:
                configs, ol, one = cases[nsim]
                open_loop[nsim].append(ol.steps_per_s(pool))
                for law in laws:
                    reports = run_batch(configs, nthread=args.nthread, law=law)
                    closed[law][nsim].append(reports[0].batch.steps_per_s)
                    same[law, nsim] = ol.same_as(reports)
                if not args.no_cpu:  # CPU seconds of one thread's share: what a shared machine cannot blur
                    rollout_rate = one.steps_per_s(caller, clock=time.thread_time)
                    for law in laws:
                        closed_cpu = run_batch(configs[:len(one.models)], nthread=1, law=law)[0].batch.cpu_s
                        cpu[law][nsim].append(len(one.models) * one.nstep / closed_cpu / rollout_rate)
            if sweep_ol is not None:
                sweep_open.append(sweep_ol.steps_per_s(pool))
                for law in laws:
                    for projection in projections:
                        # run_sweep takes the compiled law and projection where they can run: switches turn them off
                        os.environ["WMR_MJ_COMPILED_LAW"] = "0" if law == "numpy" else "1"
                        os.environ["WMR_MJ_COMPILED_PROJECTION"] = "0" if projection == "NumPy" else "1"
                        t = time.perf_counter()
                        results = run_sweep(spec, out_dir=Path(tmp) / f"sweep-{law}-{projection}-{rep}", chunk=128,
                                            nthread=args.nthread)
                        sweep_closed[law, projection].append(sum(r["steps"] for r in results)
                                                             / (time.perf_counter() - t))
                        assert {r["batch_law"] for r in results} == {law}, "the sweep ran another law"
                os.environ.pop("WMR_MJ_COMPILED_LAW")
                os.environ.pop("WMR_MJ_COMPILED_PROJECTION")

    print(f"{args.model} model, m1 550-750 kg, {args.seconds:g} s per run, {args.nthread} threads, "
          f"{args.repeats} repeats (medians; ratio = median closed / median rollout, "
          "paired = median of the repeat-by-repeat ratios)")
    header = f"{'nsim':>6s} {'rollout steps/s':>16s}"
    for law in laws:
        header += f" {law + ' steps/s':>17s} {'ratio':>7s} {'paired':>7s} {'cpu':>7s}"
    print(header + "  same physics")
    for nsim in sizes:
        line = f"{nsim:6d} {statistics.median(open_loop[nsim]):16.0f}"
        for law in laws:
            paired = statistics.median(c / o for c, o in zip(closed[law][nsim], open_loop[nsim]))
            cpu_ratio = f"{statistics.median(cpu[law][nsim]):7.3f}" if cpu[law][nsim] else f"{'-':>7s}"
            ratio = _median_ratio(closed[law][nsim], open_loop[nsim])
            line += f" {statistics.median(closed[law][nsim]):17.0f} {ratio} {paired:7.3f} {cpu_ratio}"
        print(line + "  " + " ".join(f"{law}:{'yes' if same[law, nsim] else 'NO'}" for law in laws))
    print("target: ratio >= 0.90 for every size. cpu: the same ratio in CPU seconds of one thread's share "
          "(nsim/nthread runs, one thread each side), which load from other processes does not blur. "
          "same physics: the open loop ends where the closed loop did, to the bit")
    if sweep_open:
        ro = statistics.median(sweep_open)
        for (law, projection), rates in sweep_closed.items():
            cl = statistics.median(rates)
            paired = statistics.median(c / o for c, o in zip(rates, sweep_open))
            print(f"whole sweep --n {args.sweep_n} ({args.sweep_seconds:g} s per run; run_sweep with drawing, "
                  f"compilation, reference, statistics, CSV), {law} law, {projection} projection: rollout {ro:.0f}, "
                  f"sweep {cl:.0f} steps/s, ratio {cl / ro:.3f}, paired {paired:.3f} (target >= 0.85)")


if __name__ == "__main__":
    main()
