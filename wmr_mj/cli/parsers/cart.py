"""``wmr-mj cart``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli.command_options import add_command_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "check a cart file (TOML): schema, compile and step, identification"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("cart", help=HELP)
    add_command_options(p, "cart")
