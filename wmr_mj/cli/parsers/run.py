"""``wmr-mj run``'s parser (its options: the table of each command's options, :mod:`wmr_mj.cli.command_options`)."""

from __future__ import annotations

import argparse

from wmr_mj.cli._common import CLAIM_BROKEN_EXIT
from wmr_mj.cli.command_options import add_command_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "simulate the circle headless with a controller and report the errors"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run", help=HELP,
        epilog=f"exit status: 0; {CLAIM_BROKEN_EXIT} when the run is certified-outside: it breaks the law's claim "
               "(the banner above the verdict); 1 the law failed mid-run; 2 bad input; 130 interrupted",
        description="One closed-loop run on the MuJoCo plant, reported against the regions. The run is a "
                    "batch of one: the steering law runs compiled in MuJoCo's control callback and "
                    "mujoco.batch steps a simulated second per call, recording every control step as "
                    "arrays (the rows and the MCAP log, flushed every simulated second). Where the "
                    "compiled law cannot run (no C compiler at install, WMR_MJ_COMPILED_LAW=0) the same "
                    "engine evaluates the Python law, with the same numbers, and says so on stderr.")
    add_command_options(p, "run")
