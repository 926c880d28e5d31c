"""``wmr-mj excite``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli.options import add_seed, positive_float

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "write an excitation plan (target angle + voltage dither) for identify --data"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("excite", help=HELP)
    p.add_argument("--cart", default="c80", help="the cart file (or a shipped cart's name), default c80")
    p.add_argument("--duration", type=positive_float, default=60.0, help="plan length, s (default 60)")
    p.add_argument("--out", required=True, metavar="PLAN.csv", help="the plan: t_s,alpha0_rad,u_dither_V")
    add_seed(p, help="seed of the multisines (default 0)")
