"""``wmr-mj run``'s parser, and the option groups it shares with sweep, falsify, robustness --certificate,
compare, validate and design (the rows of the table of run options, :mod:`wmr_mj.cli.run_options`)."""

from __future__ import annotations

import argparse

from wmr_mj.cli._common import CLAIM_BROKEN_EXIT
from wmr_mj.cli.options import add_json, add_out, positive_float, positive_int
from wmr_mj.cli.run_options import add_options
from wmr_mj.params import M1_NOMINAL

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
    add_run_options(p)
    p.add_argument("--m1", type=positive_float, default=M1_NOMINAL,
                   help="plant chassis mass, kg (default: the cart's, 650 on the C80)")
    p.add_argument("--range", action="append", metavar="NAME=LO:HI",
                   help="another ranged plant parameter of the analysis box (repeatable; it adds the parameter to "
                        "the --uncertainty box or replaces its range, e.g. R_a=1.0:1.3); a run draws nothing")
    add_out(p, metavar="PATH", help="MCAP log path (default logs/run-<time>-<model>-m<m1>.mcap)")
    p.add_argument("--no-log", action="store_true", help="do not write an MCAP log")
    p.add_argument("--log-every", type=positive_int, default=1, help="log signals every k-th control step (default 1)")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar (default: only on a terminal)")
    add_require_option(p)
    add_json(p)
    add_signal_options(p)


def add_run_options(p: argparse.ArgumentParser) -> None:
    """Options shared by ``run``, ``sweep``, ``falsify`` and ``robustness --certificate`` (the closed-loop
    configuration): the 'run' rows of the table of run options (:func:`wmr_mj.cli.run_options.run_options`,
    which also writes a config back as its ``wmr-mj run`` line), then the cart's (:func:`add_hardware_options`)."""
    add_options(p, "run")
    add_hardware_options(p)


def add_hardware_options(p: argparse.ArgumentParser) -> None:
    """--sensing, --actuation, --backlash: the cart as it is built (wmr_mj.hardware), RunConfig's sensing,
    actuation and transmission (``run``, ``sweep``, ``falsify``, ``robustness --certificate``, ``compare``,
    ``validate``): the 'cart' rows of the table of run options. Each is parsed by its part: bad values raise
    one line (exit status 2)."""
    g = p.add_argument_group("the cart as it is built (wmr_mj/hardware; default ideal: the exact alpha and alpha', "
                             "no delay, no inductance, no play); shown in every summary and JSON where not ideal")
    add_options(g, "cart")


def add_signal_options(p: argparse.ArgumentParser) -> None:
    """--signals, --disturbance, --load, --d-max (``run``, ``sweep``, ``falsify``; see
    :func:`wmr_mj.cli.run.signals_from_args`): the 'signals' rows of the table of run options."""
    g = p.add_argument_group("signals on the plant during the run (wmr_mj/sim/signals.py); reported under "
                             "'signals' in --json, which --signals takes back to reproduce the run to the bit")
    add_options(g, "signals")


def add_require_option(p: argparse.ArgumentParser) -> None:
    """--require STL (repeatable; ``run``, ``sweep``): the 'require' row of the table of run options."""
    add_options(p, "require")
