"""``wmr-mj falsify``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli._common import CLAIM_BROKEN_EXIT
from wmr_mj.cli.options import add_json, add_out, add_seed, add_threads, positive_int
from wmr_mj.cli.parsers.run import add_run_options, add_signal_options
from wmr_mj.cli.parsers.sweep import add_fixed_m1_option

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = ("worst-case search over the uncertainty box (its vertices, then CMA-ES; or a local polish, or "
        "differential evolution) on mujoco.batch, beside the same budget spent at random")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("falsify", help=HELP,
                       epilog=f"exit status: 0 nothing falsified; {CLAIM_BROKEN_EXIT} falsified: a run of the search "
                              "or of the random sample is certified-outside (it breaks the law's claim), or the "
                              "--require is falsified; 1 the serial re-run of the worst run did not reproduce it; "
                              "2 bad input")
    add_run_options(p)
    add_fixed_m1_option(p)
    p.add_argument("--range", action="append", metavar="NAME=LO:HI",
                   help="add a plant parameter to the box or replace its range (repeatable); with --disturbance "
                        "or --load, also their parameters: disturbance.amplitude, disturbance.t1, ..., load0.m1, "
                        "load0.t, ..., d_max (a ranged amplitude without --d-max declares the box's largest); "
                        "and the cart's axes, searched but not in the certificate's box (each run's claim covers its "
                        "own cart): sensing.delay (whole control periods), sensing.encoder_ticks (whole ticks), "
                        "sensing.encoder_bits (2**round(bits) ticks), sensing.noise, "
                        "sensing.velocity_noise, sensing.filter_tau, actuation.delay (whole 1 ms steps), "
                        "actuation.inductance, actuation.current_limit, transmission.backlash")
    p.add_argument("--path-knots", type=int, default=0, metavar="N",
                   help="search C's path too: N curvature knots (path.k1..path.kN, each within +-kappa_max of the "
                        "declared reference bounds) and the hold time at each (path.hold, 0-3 s), every path "
                        "feasible for those bounds (wmr_mj/reference/knots.py); declares --reference-bounds paper "
                        "unless given (default 0: the --path given)")
    p.add_argument("--against", default="certificate",
                   help="the region of the ratio sup|E|/E_max: certificate (default) or paper (the paper's region)")
    p.add_argument("--objective", default="ratio", help="what is maximised: ratio (default, see --against) or sup-E")
    p.add_argument("--method", default="portfolio",
                   help="search: portfolio (default: the box's 2^d vertices where they fit half the budget, else a "
                        "fractional-factorial covering of at most an eighth of it, then CMA-ES from the box's centre "
                        "moved to the worse side of significant main effects, a generation per batch, then a local "
                        "CMA-ES around the worst found), cma (CMA-ES alone), vertices-polish (the vertices, then "
                        "scipy's Nelder-Mead from the worst), lhs-polish (a Latin hypercube of half the budget, then "
                        "the same polish) or de (differential evolution)")
    p.add_argument("--require", metavar="STL",
                   help="falsify an STL requirement (e.g. 'always(abs(E) <= 0.05)', signals as for wmr-mj run "
                        "--require): maximise minus its robustness (> 0: falsified); runs one by one, the batch "
                        "keeps no per-step signals")
    p.add_argument("--budget", type=positive_int, default=256,
                   help="simulations of the search (default 256); the random sample gets as many")
    p.add_argument("--population", type=int, default=None,
                   help="members per generation: CMA-ES's (default 4 + 3 ln d) or differential evolution's "
                        "(default: 10 per parameter, at most budget/8, at least 5)")
    add_seed(p, help="seed of the search and of the random sample (default 0)")
    p.add_argument("--chunk", type=positive_int, default=128, help="simulations per batch (default 128)")
    add_threads(p, help="threads of the batch (default 0: all cores)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run the batches on a Dask cluster (e.g. tcp://127.0.0.1:8786)")
    add_out(p, help="output folder (default logs/falsify-<time>)")
    add_json(p, help="print one JSON object")
    add_signal_options(p)
