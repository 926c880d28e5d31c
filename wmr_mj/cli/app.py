"""The ``wmr-mj`` command line.

Each command has two modules:

* its parser, ``wmr_mj.cli.parsers.<name>``: ``HELP`` (its line in ``wmr-mj --help``) and ``register(subparsers)``,
  which adds its parser and its options, its rows of the options table (:mod:`wmr_mj.cli.command_options`, with the
  table of run options, :mod:`wmr_mj.cli.run_options`); argparse and the light modules of the CLI only, a help
  that names what a heavy module holds being computed for ``--help`` alone
  (:func:`wmr_mj.cli.options.add_argument_with_help_of`, :func:`~wmr_mj.cli.options.names_in`);
* its implementation, ``wmr_mj.cli.<name>``: ``run(args) -> int``, with every import at its top (the
  simulation, MuJoCo, scipy).

A command line registers only its own command (the others are listed by name and ``HELP``), and :func:`main`
imports the implementation of the command given, by name, once its options are parsed: the one place where the
CLI defers an import. So ``wmr-mj --help`` and a bad option answer without importing the simulation
(``bench/bench_cli_help.py``; tests/test_cli_help.py checks what building a parser imports).

Bad input raises a :class:`wmr_mj.errors.WmrMjError`; it is printed here as one
line ``wmr-mj: error: ...`` and the exit status is 2.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Collection, Sequence

from wmr_mj.cli._common import m1_of_param
from wmr_mj.cli.options import OneLineParser
from wmr_mj.cli.parsers import (
    cart,
    compare,
    design,
    excite,
    falsify,
    figures,
    identify,
    model,
    replay,
    robustness,
    run,
    sweep,
    validate,
)
from wmr_mj.errors import DurationError, WmrMjError

#: each command's parser module (:mod:`wmr_mj.cli.parsers`), in the order ``wmr-mj --help`` lists them
PARSERS = {"identify": identify, "robustness": robustness, "run": run, "replay": replay, "sweep": sweep,
           "falsify": falsify, "compare": compare, "validate": validate, "figures": figures, "model": model,
           "cart": cart, "design": design, "excite": excite}
COMMANDS = tuple(PARSERS)


def build_parser(commands: Collection[str] = COMMANDS) -> argparse.ArgumentParser:
    """The ``wmr-mj`` parser: the commands named in ``commands`` (default: all) with all their options; the
    others by name and one-line help alone (as ``wmr-mj --help`` lists them), not registered, so a command line
    builds only its own command's options."""
    parser = OneLineParser(
        prog="wmr-mj",
        description="MuJoCo validation testbed for computed-torque steering control of the C80 cart.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, module in PARSERS.items():
        if name in commands:
            module.register(sub)
        else:
            sub.add_parser(name, help=module.HELP)
    return parser


def _commands_of(argv: Sequence[str]) -> tuple[str, ...]:
    """The command a command line gives (its first word), or none (``wmr-mj --help``, a bad command)."""
    return (argv[0],) if argv and argv[0] in COMMANDS else ()


def _mujoco_importable() -> str | None:
    """None when MuJoCo imports; else one line naming the cause (a MUJOCO_GL backend that is not installed
    makes ``import mujoco`` fail inside PyOpenGL, before any command runs)."""
    try:
        import mujoco  # noqa: F401  (the check itself: whether MuJoCo imports here, before any command runs)
    except Exception as exc:  # noqa: BLE001  (any failure here ends in one line, not a traceback)
        gl = os.environ.get("MUJOCO_GL")
        hint = (f"MUJOCO_GL={gl!r} names a GL backend that cannot be loaded here; unset it or use egl, glfw or "
                "osmesa with its library installed" if gl else "reinstall it: pip install mujoco")
        return f"MuJoCo cannot be imported ({type(exc).__name__}: {exc}); {hint}"
    return None


def _implementation(command: str):
    """The ``run(args) -> int`` of ``command``: its implementation module ``wmr_mj.cli.<command>``."""
    # imported by name, here and only here, once the command line is parsed: an implementation imports the
    # simulation (MuJoCo, scipy, the laws), which --help and a bad option must not wait for (tests/test_cli_help.py)
    return importlib.import_module(f"wmr_mj.cli.{command}").run


def main(argv: Sequence[str] | None = None) -> int:
    problem = _mujoco_importable()
    if problem is not None:
        print(f"wmr-mj: error: {problem}", file=sys.stderr)
        return 2
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(_commands_of(argv)).parse_args(argv)
    try:
        m1_of_param(args)  # --param m1=KG is --m1 KG wherever --m1 is an option
        return int(_implementation(args.command)(args) or 0)
    except WmrMjError as exc:
        print(f"wmr-mj: error: {_with_where_duration_came_from(exc, args, argv)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("wmr-mj: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head` and friends
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


def _with_where_duration_came_from(exc: WmrMjError, args: argparse.Namespace, argv: Sequence[str]) -> str:
    """``exc``'s message, and, for a run's refused duration (:class:`~wmr_mj.errors.DurationError`), where it came
    from when the user gave none: the command's default --duration (run's, design's, validate's, ...), or, for
    ``cart check`` (whose --duration is the identification's excitation), the length of its runs on the cart's
    path."""
    message = str(exc)
    if not isinstance(exc, DurationError) or any(a == "--duration" or a.startswith("--duration=") for a in argv):
        return message
    if getattr(args, "command", None) == "cart":
        return (f"{message} (the duration of cart check's runs on the path, run's default, as no --duration of a run "
                "is given here; cart check's --duration is the identification's excitation: give --path, or declare "
                "[paths] default in the cart file, for a path the cart drives within it)")
    duration = getattr(args, "duration", None)
    if not isinstance(duration, (int, float)):
        return message
    return (f"{message} (the duration is --duration's default, {duration:g} s, as none was given; "
            "give --duration)")


if __name__ == "__main__":
    sys.exit(main())
