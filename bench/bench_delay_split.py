"""The sampled-data bound for each split of a measured delay (issue 43): does the verdict depend on the split?

    .venv/bin/python bench/bench_delay_split.py [--sensing-ms 5 --actuation-ms 0] [--out DIR]

The walk of docs/guides/identify.md: the true cart (tests/data/identify_truth.toml, a 12-bit axis encoder, the
delays given, 5 ms in all by default) recorded 20 s on the lane change and 20 s on the figure-eight under the
dithered PD of tests/data/identify_dithered_pd.py; ``identify --data`` from tests/data/identify_start.toml;
``design --uncertainty full --objective E_max --budget 12`` over the identified box. Then the design's certificate
on the identified cart (paper circle, the identified box), whose [defaults.delay_split] is 'unknown': one
sampled-data certificate per split d_s + d_a of the identified delay, read from ``inputs['delay_split']``, each
printed with its E_max, E'_max and voltage bound, and the worst (claimed).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
import tempfile
import time
from pathlib import Path

from wmr_mj.cli.app import main as wmr_mj
from wmr_mj.plant.recordings import write_csv
from wmr_mj.searches.design_search import design_file_box, design_file_settings
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.parts import resolve_run
from wmr_mj.sim.run_config import RunConfig

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"


def _record(out: Path, path: str, seed: int, sensing: str, actuation: str) -> Path:
    cfg = RunConfig.from_inputs(cart=str(DATA / "identify_truth.toml"), sensing=sensing, actuation=actuation,
                                path=path, duration=20.0, controller=f"{DATA / 'identify_dithered_pd.py'}:DitheredPD",
                                controller_params={"seed": seed})
    rows = run_closed_loop(cfg, progress=False).rows
    return write_csv(out, {"t_s": rows["t"], "u_V": rows["voltage"], "alpha_rad": rows["alpha_measured"]})


def _quiet(argv: list[str]) -> None:
    with contextlib.redirect_stdout(io.StringIO()):
        code = wmr_mj(argv)
    if code != 0:
        raise SystemExit(f"wmr-mj {' '.join(argv)}: exit {code}")


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sensing-ms", type=float, default=5.0, help="the true cart's sensing delay, ms (default 5)")
    ap.add_argument("--actuation-ms", type=float, default=0.0, help="its actuation delay, ms (default 0)")
    ap.add_argument("--out", help="a folder for the recordings, new.toml and design.json (default: a temporary one)")
    args = ap.parse_args()
    folder = Path(args.out or tempfile.mkdtemp(prefix="delay-split-"))
    folder.mkdir(parents=True, exist_ok=True)
    sensing = f"encoder_ticks=4096,velocity=difference,delay={args.sensing_ms / 1e3!r}"
    actuation = f"delay={args.actuation_ms / 1e3!r}"
    t0 = time.perf_counter()
    lane = _record(folder / "lane.csv", "lane-change", 0, sensing, actuation)
    eight = _record(folder / "eight.csv", "figure-eight", 1, sensing, actuation)
    new, design = folder / "new.toml", folder / "design.json"
    _quiet(["identify", "--cart", str(DATA / "identify_start.toml"), "--data", f"{lane}:m1=100",
            "--data", f"{eight}:m1=100", "--out", str(new)])
    _quiet(["design", "--cart", str(new), "--uncertainty", "full", "--objective", "E_max", "--budget", "12",
            "--out", str(design)])
    walk_s = time.perf_counter() - t0
    s, box = design_file_settings(design), design_file_box(design)
    cfg = RunConfig.from_inputs(cart=str(new), controller=s["controller"], model=s["model"], kp=s["kp"], kd=s["kd"],
                                friction_sign=s["friction_sign"], friction_width=s["friction_width"],
                                control_period=s["control_period"], sensing=s["sensing"], actuation=s["actuation"],
                                m1_range=box["m1_range"], box_ranges=box["box_ranges"], path="paper-circle")
    t0 = time.perf_counter()
    claim = resolve_run(cfg).claim
    claim_s = time.perf_counter() - t0
    record = claim.inputs["delay_split"]
    print(f"true cart: sensing {args.sensing_ms:g} ms + actuation {args.actuation_ms:g} ms; recorded, identified and "
          f"designed in {walk_s:.1f} s (folder {folder})")
    print(f"design: K_P = {s['kp']:.6g} 1/s^2, K_D = {s['kd']:.6g} 1/s, sign width {s['friction_width']:.4g} rad/s; "
          f"identified delay {record['total_periods']} periods of {record['control_period_s'] * 1e3:g} ms")
    print(f"{'d_s':>4s} {'d_a':>4s} {'E_max rad':>11s} {'voltage V':>10s} certified")
    for split in record["splits"]:
        print(f"{split['sensing_periods']:4d} {split['actuation_periods']:4d} {split['E_max']:11.6g} "
              f"{split['voltage_max']:10.4g} {split['certified']}")
    values = [split["E_max"] for split in record["splits"]]
    print(f"worst {record['worst'][0]}+{record['worst'][1]} (claimed): E_max {claim.E_max:.6g} rad, voltage "
          f"{claim.voltage_max:.4g} V, certified {claim.certified}; spread over the splits "
          f"{100 * (max(values) - min(values)) / max(values):.1f} % of the worst; the run simulates "
          f"{record['simulated'][0]}+{record['simulated'][1]}; {len(values)} certificates in {claim_s:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
