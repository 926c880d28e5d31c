"""``wmr-mj robustness``'s parser, and the parser of the run options read after ``--certificate``."""

from __future__ import annotations

import argparse
import math

from wmr_mj.cli.options import OneLineParser, add_json, positive_float
from wmr_mj.cli.parsers.run import add_run_options
from wmr_mj.params import COEFFICIENT_MODELS, M1_NOMINAL, UNCERTAINTY_NAMES


def _nonneg_float(text: str) -> float:
    """argparse type: a finite number >= 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number; a finite number >= 0 is accepted") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not accepted; a finite number >= 0 is required")
    return value


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
    p.add_argument("--kp", type=positive_float, default=None, help="K_P [1/s^2] (default 6)")
    p.add_argument("--kd", type=positive_float, default=None, help="K_D [1/s] (default 9)")
    p.add_argument(
        "--omega-r",
        type=positive_float,
        default=None,
        help="critical damping (3.6): K_P = omega_r^2/4, K_D = omega_r (not with --kp/--kd)",
    )
    _add_box_options(p)
    _add_reading_options(p)
    p.add_argument("--alpha-ddot", type=_nonneg_float, default=None, help="||alpha0''|| [rad/s^2] (default 0.4)")
    p.add_argument("--alpha-dot", type=_nonneg_float, default=None, help="||alpha0'|| [rad/s] (default 0.23)")
    p.add_argument("--sin-cos3", type=_nonneg_float, default=None, help="||sin/cos^3|| (default 1.24)")
    add_json(p, help="print one JSON object")
    p.add_argument(
        "--certificate",
        nargs=argparse.REMAINDER,
        default=None,
        metavar="RUN-OPTIONS",
        help="print the certificate for a controller as `wmr-mj run` would run it; every option after "
        "--certificate is one of run's (--model, --controller, --kp/--kd/--omega-r, --friction-sign, "
        "--friction-width, --control-period, --m1, --box, --m1-range, --param) or --range NAME=LO:HI, "
        "--uncertainty m1|full, --json (see: wmr-mj robustness --certificate --help)",
    )


def _add_box_options(p: argparse.ArgumentParser) -> None:
    """The box of the analysis: the paper's, or derived from a cart over ranges, by a reduced model."""
    p.add_argument(
        "--box",
        choices=("paper", "derived"),
        default=None,
        help="uncertainty box: the paper's (5.1) intervals (default), or derived from the C80 parameter set",
    )
    p.add_argument(
        "--m1-range",
        nargs=2,
        type=positive_float,
        metavar=("LO", "HI"),
        default=None,
        help="chassis mass range [kg] for --box derived (default 550 750)",
    )
    p.add_argument(
        "--range",
        action="append",
        default=None,
        metavar="NAME=LO:HI",
        help="extra C80 parameter range for --box derived (repeatable), e.g. mu=0.015:0.02",
    )
    p.add_argument("--cart", default=None, metavar="FILE|NAME",
                   help="for --box derived: the cart whose parameter set and m1 box span it (a cart file or a "
                        "shipped cart's name; default the C80)")
    p.add_argument(
        "--model",
        choices=COEFFICIENT_MODELS,
        default=None,
        help="reduced model whose coefficients span --box derived (default paper)",
    )
    p.add_argument(
        "--estimate",
        action="append",
        default=None,
        metavar="NAME=VALUE",
        help="fixed estimate of P, C_V, F or K (repeatable); others are anywhere in the box (4.2)",
    )


def _add_reading_options(p: argparse.ArgumentParser) -> None:
    """The estimate, the reading of (4.19)-(4.20) and the operator gains."""
    p.add_argument(
        "--reading",
        choices=("corrected", "printed", "printed-literal"),
        default=None,
        help="reading of (4.19)-(4.20): corrected from (4.10) (default), printed labels, or (4.20) verbatim",
    )
    p.add_argument(
        "--gammas",
        choices=("exact", "paper"),
        default=None,
        help="operator gains: exact integrals (default) or the paper's (4.16) 1/K_P, 4/(e K_D)",
    )


def certificate_parser() -> argparse.ArgumentParser:
    """The options read after ``--certificate``: those of ``wmr-mj run`` plus the box's ranges."""
    p = OneLineParser(
        prog="wmr-mj robustness --certificate",
        description="The certificate (wmr_mj.analysis.certificate) for the controller `wmr-mj run` would run with "
        "these options, on the plant it would simulate: region, terms and every assumption with its number.",
    )
    add_run_options(p)
    taken = set(p._option_string_actions)
    if "--m1" not in taken:
        p.add_argument("--m1", type=positive_float, default=M1_NOMINAL,
                       help="plant chassis mass, kg (default 650); the certificate's box includes it")
    if "--range" not in taken:
        p.add_argument("--range", action="append", metavar="NAME=LO:HI",
                       help="another ranged plant parameter of the box (repeatable), e.g. R_a=1.0:1.3")
    if "--d-max" not in taken:
        p.add_argument("--d-max", type=float, default=None, metavar="NM",
                       help="a steering disturbance torque bound, N m: its term R_a d_max/(k_i i2)/P enters delta1 "
                       "(wmr-mj run --disturbance)")
    if "--uncertainty" not in taken:
        p.add_argument("--uncertainty", choices=UNCERTAINTY_NAMES, default=None,
                       help="a named uncertainty box of wmr_mj.params: m1 (the paper's 550-750 kg) or full "
                       "(m1, mu, ground_friction, R_a, V_A); --m1-range and --range override its entries")
    if "--json" not in taken:
        add_json(p, help="print one JSON object")
    return p
