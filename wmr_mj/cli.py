"""The ``wmr-mj`` command line.

Each subcommand lives in ``wmr_mj.commands.<name>`` and provides
``register(subparsers)``, which adds its parser and sets ``func(args) -> int``.
Command modules import heavy libraries inside ``func`` so that ``--help`` and
argument errors stay fast.

Bad input raises a :class:`wmr_mj.errors.WmrMjError`; it is printed here as one
line ``wmr-mj: error: ...`` and the exit status is 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from .errors import WmrMjError

COMMANDS = ("identify", "robustness", "run", "replay", "sweep", "falsify", "validate", "figures", "model")


class _OneLineParser(argparse.ArgumentParser):
    """Argument errors as one line (no usage dump), exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _OneLineParser(
        prog="wmr-mj",
        description="MuJoCo validation testbed for computed-torque steering control of the C80 cart.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"wmr_mj.commands.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"wmr_mj.commands.{name}":
                raise
            continue  # command not built yet
        module.register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except WmrMjError as exc:
        print(f"wmr-mj: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("wmr-mj: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head` and friends
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
