"""``wmr-mj sweep``'s parser, and the fixed --m1 it shares with falsify."""

from __future__ import annotations

import argparse

from wmr_mj.cli._common import CLAIM_BROKEN_EXIT
from wmr_mj.cli.options import add_json, add_out, add_seed, add_threads, positive_float, positive_int
from wmr_mj.cli.parsers.run import add_require_option, add_run_options, add_signal_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "Monte-Carlo over m1 (and --uncertainty/--range) on mujoco.batch: per-run verdicts, table and plot"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sweep",
                       help=HELP,
                       epilog=f"exit status: 0; {CLAIM_BROKEN_EXIT} when a run is certified-outside: it breaks the "
                              "law's claim (a banner names the run; summary.json's claim_broken); 2 bad input")
    add_run_options(p)
    add_fixed_m1_option(p)
    p.add_argument("--n", type=int, default=200, help="number of runs (default 200)")
    add_seed(p, help="seed of the draw (default 0)")
    p.add_argument("--sampling", default="lhs", help="uniform, lhs (Latin hypercube, default) or grid")
    p.add_argument("--range", action="append", metavar="NAME=LO:HI",
                   help="draw another plant parameter over a range too (repeatable); the box includes it. Or a "
                        "hardware axis of the cart, drawn per run but not in the certificate's box (each run's claim "
                        "covers its own cart): sensing.delay (rounded to whole control periods), "
                        "sensing.encoder_ticks (rounded to whole ticks), sensing.encoder_bits (2**round(bits) "
                        "ticks), sensing.noise, sensing.velocity_noise, sensing.filter_tau, "
                        "actuation.delay (whole 1 ms steps), actuation.inductance, actuation.current_limit, "
                        "transmission.backlash; runs.csv records the value each run used")
    add_out(p, help="output folder (default logs/sweep-<time>); rerun to resume")
    p.add_argument("--chunk", type=positive_int, default=128, help="simulations per batch (default 128)")
    add_threads(p, help="threads of the batch (default 0: all cores)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run the chunks on a Dask cluster (e.g. tcp://127.0.0.1:8786)")
    p.add_argument("--log", action="store_true",
                   help="also write an MCAP log per run (re-run one by one; bit-identical)")
    add_json(p, help="print one summary JSON object")
    add_require_option(p)
    add_signal_options(p)


def add_fixed_m1_option(p: argparse.ArgumentParser) -> None:
    """sweep's and falsify's --m1: a fixed m1, so that the other axes are swept or searched alone."""
    p.add_argument("--m1", type=positive_float, default=None, metavar="KG",
                   help="fix every run's m1 at KG (the other ranges swept alone; the certificate's box stays "
                        "--m1-range); a zero-width --m1-range KG KG is the same, the box then the default 550-750 kg")
