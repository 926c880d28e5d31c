"""One evaluation of the sampled loop's l1 gains: how long the design search of issue 35 item 4 waits per point.

    .venv/bin/python bench/bench_sampled_data.py [--repeats 21] [--threads 1]

One evaluation is :func:`wmr_mj.analysis.sampled_data.sampled_loop` (the augmented A, B, C, D) and
:func:`~wmr_mj.analysis.sampled_data.peak_gains` (every source into E, E' and u, summed until the tail is
within 1e-6 of each sum), for the certified gains (K_P = 100, K_D = 20) at T = 1 ms on carts of the hardware
guide: a 12-bit axis encoder with a differenced or filtered alpha', and exact alpha' with 5, 20 and 50 ms of
sensing delay. Prints min / median / max wall milliseconds over --repeats, and the gain q -> E. The BLAS
threads are set to --threads before numpy loads (a design search runs one evaluation per core).
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

CARTS: dict[str, dict[str, object]] = {
    "12-bit axis, difference": {"velocity": "difference"},
    "12-bit axis, filtered 5 ms": {"velocity": "filtered", "filter_tau": 0.005},
    "exact, 5 ms delay": {"sensing_delay": 5},
    "exact, 20 ms delay": {"sensing_delay": 20},
    "difference, 20 ms delay": {"velocity": "difference", "sensing_delay": 20},
    "exact, 50 ms delay": {"sensing_delay": 50},
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=21)
    ap.add_argument("--threads", type=int, default=1, help="BLAS threads (set before numpy loads)")
    args = ap.parse_args()
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[name] = str(args.threads)
    from wmr_mj.analysis.sampled_data import peak_gains, sampled_loop

    print(f"{'cart (K_P 100, K_D 20, T 1 ms)':32s} {'n':>4s} {'N':>6s}   min    median  max [ms]   q -> E")
    for name, options in CARTS.items():
        times, gains, n = [], None, 0
        for _ in range(args.repeats):
            t = time.perf_counter()
            loop = sampled_loop(kp=100.0, kd=20.0, control_period=1e-3, **options)  # type: ignore[arg-type]
            gains = peak_gains(loop)
            times.append(1e3 * (time.perf_counter() - t))
            n = loop.n_states
        assert gains is not None
        print(f"{name:32s} {n:4d} {gains.n_terms:6d}  {min(times):6.2f} {statistics.median(times):6.2f} "
              f"{max(times):6.2f}      {gains.gain('E', 'quantisation'):.4f}")


if __name__ == "__main__":
    main()
