"""``wmr-mj model``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli.command_options import add_command_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "write/check the MJCF files generated from the C80 parameter set"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("model", help=HELP)
    add_command_options(p, "model")
