"""``wmr-mj replay``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli.command_options import add_command_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "summarise, plot, verify (bit for bit) or render a run log"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "replay",
        help=HELP,
        description="summarise, plot, verify (bit for bit) or render a wmr-mj run log (MCAP)",
    )
    add_command_options(p, "replay")
