"""``wmr-mj design``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli.options import add_json, positive_float, positive_int
from wmr_mj.cli.parsers.run import add_hardware_options
from wmr_mj.params import M1_RANGE
from wmr_mj.searches.design_options import DEFAULT_BUDGET, DEFAULT_OBJECTIVE, DEFAULT_SEED, METHODS, OBJECTIVE_WORDS

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "the computed-torque (or sliding-mode) gains, sign width, filter and period a given cart certifies"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "design", help=HELP,
        description="A seeded search (CMA-ES or scipy's differential evolution) over omega_n and zeta "
                    "(K_P = omega_n^2, K_D = 2 zeta omega_n; with --controller sliding-mode: lam, phi, k and eta), the "
                    "Coulomb sign's smoothing width, the velocity filter's tau_f "
                    "(where --sensing has velocity=filtered) and the control period (--periods), minimising the "
                    "certificate a run computes (the worst over --path) subject to every one of its assumptions "
                    "over the plant box, on the cart (--cart FILE|NAME: its parameters, box, supply and stops; its "
                    "default sensing, actuation and play unless given). Writes a design file that `wmr-mj run --design "
                    "FILE` (and sweep, falsify, robustness --certificate; compare FILE.json, validate --design "
                    "FILE.json) read back as the same design, on the cart it was found on.",
        epilog="exit status: 0 a certified design found; 1 none certifies (the binding assumption is named); "
               "2 bad input")
    add_hardware_options(p)
    p.add_argument("--controller", default="computed-torque", metavar="LAW",
                   help="the law searched: computed-torque (default: omega_n, zeta) or sliding-mode (lam, phi, k, eta "
                        "on the non-holonomic model); both with the sign's width, tau_f and the period")
    p.add_argument("--path", action="append", metavar="NAME|FILE",
                   help="a path every certificate must hold on (repeatable; default: the cart's own, [paths] default "
                        "in its file, else paper-circle)")
    p.add_argument("--uncertainty", default=None, help="the plant box: m1 (default) or full (wmr_mj/params.py)")
    p.add_argument("--m1-range", nargs=2, type=float, metavar=("LO", "HI"), default=M1_RANGE,
                   help="m1 range of the box, kg (default: the cart's m1 box, 550 750 on the C80)")
    p.add_argument("--range", action="append", metavar="NAME=LO:HI", help="another ranged parameter of the box")
    p.add_argument("--reference-bounds", metavar="paper|KEY=VALUE,...", default=None,
                   help="declared reference bounds the certificates cover (default: each path's own)")
    p.add_argument("--duration", type=positive_float, default=35.0, help="the run's length, s (default 35, run's)")
    p.add_argument("--periods", default="0.001", metavar="T1,T2,...",
                   help="control periods to try, s, each a whole number of 1 ms physics steps dividing the run "
                        "(default 0.001)")
    p.add_argument("--objective", default=DEFAULT_OBJECTIVE,
                   help=f"what is minimised (default {DEFAULT_OBJECTIVE}): " + "; ".join(
                       f"{name}: {words}" for name, words in OBJECTIVE_WORDS.items()).replace("%", "%%"))
    p.add_argument("--method", default="cma", choices=METHODS,
                   help="the optimiser: cma (CMA-ES, the default: the better of the two in bench/bench_design.py) "
                        "or de (scipy's differential evolution)")
    p.add_argument("--seed", type=int, default=DEFAULT_SEED,
                   help=f"the optimiser's seed (same seed, same design; default {DEFAULT_SEED})")
    p.add_argument("--budget", type=positive_int, default=DEFAULT_BUDGET,
                   help=f"certificate evaluations per period and path, about (default {DEFAULT_BUDGET})")
    p.add_argument("--check", type=int, default=0, metavar="N",
                   help="then sweep N runs over the box at the design and count the verdicts (default 0: none)")
    p.add_argument("--out", default="design.json", metavar="FILE", help="the design file (default design.json)")
    add_json(p)
