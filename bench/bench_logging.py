"""MCAP logging cost: the closed-loop run with and without its log, and the read-back rate.

    .venv/bin/python bench/bench_logging.py [--seconds 35] [--repeats 5] [--json]

All in one process, variants alternated within each repeat (so that a slow spell of a shared
machine hits all of them), medians over --repeats:

- run: wmr_mj.sim.closed_loop.run_closed_loop (paper circle, --seconds long, 1 kHz control) without a
  log; with a null logger (the runner's own logging path: the recorded state and the blocks,
  nothing written); and with wmr_mj.logs.writer.RunLogger for each compression. Target: logged /
  unlogged <= 1.15 for the default compression; min / median / max of the per-repeat ratio beside
  the ratio of the medians.
- write: RunLogger alone on synthetic blocks of the same shape (us per logged row).
- read: wmr_mj.logs.reader.load_log + .signals + .state of the run's log; samples = scalar values
  returned (signal fields incl. A_pos/C_pos columns, t/qpos/qvel/ctrl of /sim/state).
  Target >= 20 M samples/s.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from wmr_mj.logs.reader import load_log  # noqa: E402
from wmr_mj.logs.writer import COMPRESSIONS, LogHeader, LogOptions, RunLogger  # noqa: E402
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig

RATIO_TARGET = 1.15
READ_TARGET = 20e6
DEFAULT_COMPRESSION = "lz4"


class NullLogger:
    """Takes the runner's blocks and drops them: what the runner's logging path costs alone."""

    def __init__(self, header: object) -> None:
        pass

    def write_block(self, block: dict) -> None:
        pass

    def close(self, summary: dict, *, status: str = "completed") -> None:
        pass


def bench_run(seconds: float, folder: Path, repeats: int, compressions: list[str]) -> dict[str, float]:
    cfg = RunConfig(duration=seconds)
    variants: dict[str, object] = {"unlogged": None, "null": NullLogger}
    for c in compressions:
        # as `wmr-mj run` writes: a writer thread compresses and writes each second while the next steps
        variants[c] = lambda header, c=c: RunLogger(folder / f"run-{c}.mcap", header,
                                                    options=LogOptions(compression=c, background=True))

    def library_writer(header: object) -> RunLogger:
        # the same log written with the official mcap Writer.add_message for every message, beside the
        # writer's NumPy bulk path (which builds the same records from mcap's internals)
        log = RunLogger(folder / "run-lz4-library.mcap", header, options=LogOptions(compression="lz4", background=True))
        log._bulk = None
        return log

    variants["lz4-library"] = library_writer
    run_closed_loop(cfg, progress=False)  # warm up (imports, caches)
    wall: dict[str, list[float]] = {k: [] for k in variants}
    cpu: dict[str, list[float]] = {k: [] for k in variants}
    for _ in range(repeats):
        for name, factory in variants.items():
            t0, c0 = time.perf_counter(), time.process_time()
            run_closed_loop(cfg, logger_factory=factory, progress=False)
            wall[name].append(time.perf_counter() - t0)
            cpu[name].append(time.process_time() - c0)
    out: dict[str, float] = {}
    for kind, times in (("", wall), ("cpu_", cpu)):  # wall clock, and this process's CPU time
        med = {k: statistics.median(v) for k, v in times.items()}
        for name in variants:
            out[f"{kind}{name}_min_s"], out[f"{kind}{name}_max_s"] = min(times[name]), max(times[name])
            if name != "unlogged":  # side by side in each repeat
                per = [x / u for x, u in zip(times[name], times["unlogged"])]
                out[f"{kind}{name}_ratio_min"] = min(per)
                out[f"{kind}{name}_ratio_median"] = statistics.median(per)
                out[f"{kind}{name}_ratio_max"] = max(per)
        out[f"{kind}unlogged_s"] = med["unlogged"]
        for name in variants:
            if name != "unlogged":
                out[f"{kind}{name}_s"] = med[name]
                out[f"{kind}{name}_ratio"] = med[name] / med["unlogged"]
    for c in [*compressions, "lz4-library"]:
        out[f"{c}_file_mb"] = (folder / f"run-{c}.mcap").stat().st_size / 1e6
    return out


def synthetic_blocks(m: mujoco.MjModel, seconds: float, rate_hz: float = 1000.0) -> list[dict[str, np.ndarray]]:
    """One block per simulated second: a cart driving a circle with a swinging steer angle."""
    n_block = int(round(rate_hz))
    blocks = []
    for b in range(int(round(seconds))):
        t = (np.arange(n_block) + b * n_block) / rate_hz
        a = 0.6 * np.sin(0.5 * t)
        ad = 0.3 * np.cos(0.5 * t)
        psi = 0.2 * t
        x, y = np.cos(psi), np.sin(psi)
        blk = {
            "t": t, "alpha": a, "alpha_dot": ad, "alpha0": a + 1e-3 * np.sin(7 * t), "alpha0_dot": ad,
            "alpha0_ddot": -0.15 * np.sin(0.5 * t), "E": 1e-3 * np.sin(7 * t), "E_dot": 7e-3 * np.cos(7 * t),
            "voltage_cmd": 5 * np.sin(t), "voltage": 5 * np.sin(t), "current": 0.5 * np.sin(t),
            "steer_torque": 2 * np.sin(t), "A_pos": np.column_stack([x, y]), "C_pos": np.column_stack([x + 0.6, y]),
            "heading": psi,
        }  # fmt: skip
        q = np.tile(m.qpos0, (n_block, 1))
        q[:, 0], q[:, 1] = x, y
        q[:, 3], q[:, 6] = np.cos(psi / 2), np.sin(psi / 2)
        q[:, 7:] = (t[:, None] * np.linspace(1, 2, m.nq - 7)) % (2 * np.pi)
        blk["qpos"] = q
        blk["qvel"] = np.tile(np.linspace(-1, 1, m.nv), (n_block, 1)) * np.cos(t)[:, None]
        blk["ctrl"] = np.tile(np.linspace(0, 1, m.nu), (n_block, 1)) * np.sin(t)[:, None]
        blocks.append(blk)
    return blocks


def bench_write(seconds: float, path: Path, repeats: int, compression: str) -> dict[str, float]:
    from wmr_mj.params import C80
    from wmr_mj.plant.mjcf import Plant

    plant = Plant(C80)
    m, xml = plant.model, plant.xml
    blocks = synthetic_blocks(m, seconds)
    s0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(m, mujoco.MjData(m), s0, mujoco.mjtState.mjSTATE_INTEGRATION)
    rows = sum(len(b["t"]) for b in blocks)
    times = []
    for _ in range(repeats):
        header = LogHeader(mjcf_xml=xml, config={"bench": True, "seed": 0}, parameters={"voltage_limit": 24.0},
                           initial_state=s0, timestep=m.opt.timestep, control_substeps=1, model=m,
                           bounds={"E_max": 0.1, "Edot_max": 0.2})
        log = RunLogger(path, header, options=LogOptions(compression=compression))
        t0 = time.perf_counter()
        for b in blocks:
            log.write_block(b)
        log.close({"bench": True})
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    return {"rows": rows, "write_s": med, "write_us_per_row": 1e6 * med / rows}


def bench_read(path: Path, repeats: int) -> dict[str, float]:
    times = []
    samples = 0
    for _ in range(repeats):
        t0 = time.perf_counter()
        log = load_log(path)
        sig, st = log.signals, log.state
        times.append(time.perf_counter() - t0)
        samples = sum(v.size for v in sig.values()) + sum(v.size for v in st.values())
    med = statistics.median(times)
    return {"read_s": med, "samples": samples, "samples_per_s": samples / med}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=35.0, help="simulated seconds (1 kHz control)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--end-to-end", action="store_true", help="(always on; kept for old command lines)")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    compressions = [DEFAULT_COMPRESSION] + [c for c in COMPRESSIONS if c != DEFAULT_COMPRESSION]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        res = bench_run(args.seconds, folder, args.repeats, compressions)
        res.update(bench_write(args.seconds, folder / "write.mcap", args.repeats, DEFAULT_COMPRESSION))
        res.update(bench_read(folder / f"run-{DEFAULT_COMPRESSION}.mcap", args.repeats))
    if args.json:
        print(json.dumps(res, indent=2))
        return
    d = DEFAULT_COMPRESSION
    print(f"closed-loop run, paper circle, {args.seconds:g} s at 1 kHz; medians over {args.repeats} alternated repeats")
    print("                       wall clock                 CPU time of this process")
    print(f"run     unlogged       {res['unlogged_s']:.3f} s                    {res['cpu_unlogged_s']:.3f} s")
    for name in ["null", *compressions, "lz4-library"]:
        what = {"null": "null logger", "lz4-library": "lz4, mcap's"}.get(name, f"logged {name}")
        print(f"run     {what:14s} {res[f'{name}_s']:.3f} s = {res[f'{name}_ratio']:.2f}x"
              f"             {res[f'cpu_{name}_s']:.3f} s = {res[f'cpu_{name}_ratio']:.2f}x"
              + (f"   file {res[f'{name}_file_mb']:.1f} MB" if name != "null" else "   (the runner's copies only)")
              + ("   (Writer.add_message per message)" if name == "lz4-library" else ""))
    print(f"logged/unlogged ({d}) = {res[f'{d}_ratio']:.2f} wall, {res[f'cpu_{d}_ratio']:.2f} CPU (medians);"
          f"  target <= {RATIO_TARGET}")
    for kind, what in (("", "wall"), ("cpu_", "CPU ")):
        print(f"  {what} unlogged min {res[f'{kind}unlogged_min_s']:.3f}  median {res[f'{kind}unlogged_s']:.3f}  "
              f"max {res[f'{kind}unlogged_max_s']:.3f} s; logged {d} min {res[f'{kind}{d}_min_s']:.3f}  "
              f"median {res[f'{kind}{d}_s']:.3f}  max {res[f'{kind}{d}_max_s']:.3f} s; per-repeat ratio min "
              f"{res[f'{kind}{d}_ratio_min']:.2f}  median {res[f'{kind}{d}_ratio_median']:.2f}  "
              f"max {res[f'{kind}{d}_ratio_max']:.2f}")
    print(f"write   {res['write_us_per_row']:.2f} us per row ({d}; {res['rows']} rows in "
          f"{res['write_s'] * 1e3:.0f} ms)")
    print(f"read    {res['samples_per_s'] / 1e6:.1f} M samples/s ({res['samples']} samples in "
          f"{res['read_s'] * 1e3:.1f} ms)  target >= {READ_TARGET / 1e6:.0f} M samples/s")


if __name__ == "__main__":
    main()
