"""MCAP logging cost: write time per logged row and read throughput (samples/s).

    .venv/bin/python bench/bench_logging.py [--seconds 35] [--repeats 5] [--end-to-end] [--json]

- write: wmr_mj.mcaplog.RunLogger on the C80 model (wmr_mj.plant), blocks of one
  simulated second (1000 rows at 1 kHz) built beforehand from a smooth synthetic
  motion; the time of write_block + close, all channels (/steering, /motor, /pose,
  /sim/state, /tf) at every row, divided by the rows. Target: <= ~10 us/row, so
  that a 35 s run at 1 kHz (~1 s unlogged) takes at most 1.5x with logging.
- read: wmr_mj.logs.load_log + .signals + .state of that file; samples = scalar
  values returned (signal fields incl. A_pos/C_pos columns, and t/qpos/qvel/ctrl of
  /sim/state); target >= 1e6 samples/s.
- --end-to-end: the closed-loop runner (wmr_mj.simulate.run_closed_loop, paper
  circle, --seconds long) without and with logging, via
  wmr_mj.mcaplog.measure_logging_overhead; target ratio <= 1.5.

All figures are medians over --repeats.
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

from wmr_mj.logs import load_log  # noqa: E402
from wmr_mj.mcaplog import RunLogger, measure_logging_overhead  # noqa: E402


def _model() -> tuple[mujoco.MjModel, str]:
    try:
        from wmr_mj.plant import compile_model

        return compile_model()
    except ImportError:  # before the plant existed: the tests' stand-in model
        sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
        from test_mcaplog import TEST_MJCF

        return mujoco.MjModel.from_xml_string(TEST_MJCF), TEST_MJCF


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


def bench_write(m, xml, blocks, path: Path, repeats: int) -> dict[str, float]:
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    s0 = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, mujoco.MjData(m), s0, spec)
    rows = sum(len(b["t"]) for b in blocks)
    times = []
    for _ in range(repeats):
        log = RunLogger(path, mjcf_xml=xml, config={"bench": True, "seed": 0}, parameters={}, initial_state=s0,
                        timestep=m.opt.timestep, control_substeps=1, model=m,
                        reference_path=np.column_stack([np.cos(np.linspace(0, 7, 2000)), np.sin(np.linspace(0, 7, 2000))]))  # fmt: skip
        t0 = time.perf_counter()
        for b in blocks:
            log.write_block(b)
        log.close({"bench": True})
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    return {"rows": rows, "write_s": med, "write_us_per_row": 1e6 * med / rows, "file_mb": path.stat().st_size / 1e6}


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


def bench_end_to_end(seconds: float, path: Path, repeats: int) -> dict[str, float]:
    from wmr_mj.simulate import RunConfig, run_closed_loop

    cfg = RunConfig(duration=seconds)

    def run(log_path):
        factory = None if log_path is None else (lambda **kw: RunLogger(log_path, **kw))
        run_closed_loop(cfg, logger_factory=factory, progress=False)

    return measure_logging_overhead(run, path, repeats=repeats)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=35.0, help="simulated seconds (1 kHz rows)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--end-to-end", action="store_true", help="also time the closed-loop runner with and without the log")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    m, xml = _model()
    blocks = synthetic_blocks(m, args.seconds)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.mcap"
        res = {"nq": m.nq, "nv": m.nv, "nu": m.nu, **bench_write(m, xml, blocks, path, args.repeats)}
        res.update(bench_read(path, args.repeats))
        if args.end_to_end:
            res.update(bench_end_to_end(args.seconds, Path(tmp) / "e2e.mcap", max(1, args.repeats // 2)))
    if args.json:
        print(json.dumps(res, indent=2))
        return
    print(f"model nq={res['nq']} nv={res['nv']} nu={res['nu']}; {res['rows']} rows (1 kHz, {args.seconds:g} s), all channels every row")
    print(f"write   {res['write_us_per_row']:.2f} us/row  ({res['write_s'] * 1e3:.0f} ms total, file {res['file_mb']:.1f} MB)  target <= ~10 us/row")
    print(f"read    {res['samples_per_s'] / 1e6:.1f} M samples/s  ({res['samples']} samples in {res['read_s'] * 1e3:.0f} ms)  target >= 1 M samples/s")
    if args.end_to_end:
        print(f"run     unlogged {res['unlogged_s']:.3f} s, logged {res['logged_s']:.3f} s: ratio {res['ratio']:.2f}  target <= 1.5")
    print(f"(medians over {args.repeats} repeats)")


if __name__ == "__main__":
    main()
