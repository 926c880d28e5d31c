"""``wmr-mj sweep``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli._common import CLAIM_BROKEN_EXIT
from wmr_mj.cli.command_options import add_command_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "Monte-Carlo over m1 (and --uncertainty/--range) on mujoco.batch: per-run verdicts, table and plot"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sweep",
                       help=HELP,
                       epilog=f"exit status: 0; {CLAIM_BROKEN_EXIT} when a run is certified-outside: it breaks the "
                              "law's claim (a banner names the run; summary.json's claim_broken); 2 bad input")
    add_command_options(p, "sweep")
