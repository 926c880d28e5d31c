"""``wmr-mj robustness``'s parser, and the parser of the run options read after ``--certificate``."""

from __future__ import annotations

import argparse

from wmr_mj.cli.command_options import add_command_options
from wmr_mj.cli.options import OneLineParser

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "robustness condition (4.23) and error bounds of the computed-torque controller"


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "robustness",
        help=HELP,
        description=(
            "Evaluate the robustness analysis of section 4: operator gains gamma1, gamma2 (4.14), "
            "delta1 (4.18), the coefficients of ||E|| and ||E'|| in (4.19), condition (4.23) and the "
            "bounds on ||E||, ||E'||. Default: the paper's (5.1) example."
        ),
    )
    add_command_options(p, "robustness")


def certificate_parser() -> argparse.ArgumentParser:
    """The options read after ``--certificate``: those of ``wmr-mj run`` plus the box's ranges."""
    p = OneLineParser(
        prog="wmr-mj robustness --certificate",
        description="The certificate (wmr_mj.analysis.certificate) for the controller `wmr-mj run` would run with "
        "these options, on the plant it would simulate: region, terms and every assumption with its number.",
    )
    add_command_options(p, "robustness --certificate")
    return p
