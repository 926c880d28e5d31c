"""``wmr-mj design``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli.command_options import add_command_options

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
    add_command_options(p, "design")
