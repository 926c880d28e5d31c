"""``wmr-mj falsify``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli._common import CLAIM_BROKEN_EXIT
from wmr_mj.cli.command_options import add_command_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = ("worst-case search over the uncertainty box (its vertices, then CMA-ES; or a local polish, or "
        "differential evolution) on mujoco.batch, beside the same budget spent at random")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("falsify", help=HELP,
                       epilog=f"exit status: 0 nothing falsified; {CLAIM_BROKEN_EXIT} falsified: a run of the search "
                              "or of the random sample is certified-outside (it breaks the law's claim), or the "
                              "--require is falsified; 1 the serial re-run of the worst run did not reproduce it; "
                              "2 bad input")
    add_command_options(p, "falsify")
