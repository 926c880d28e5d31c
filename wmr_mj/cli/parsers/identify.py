"""``wmr-mj identify``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli.command_options import add_command_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = ("fit the steering model: the simulated plant excited (P, C_V, F, K, gyro by least squares), or a cart's "
        "recordings (--data) into a cart file with intervals")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("identify", help=HELP)
    add_command_options(p, "identify")
