"""``wmr-mj robustness``: the paper's section-4 robustness condition (4.23) and error bounds.

Default: the paper's (5.1) example (box (5.1), K_D = 9, K_P = 6), corrected
reading of (4.19)-(4.20), exact operator gains. See :mod:`wmr_mj.robustness`.
"""

from __future__ import annotations

import argparse
import math

from ._common import parse_assignments, parse_range, positive_float


def _nonneg_float(text: str) -> float:
    """argparse type: a finite number >= 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number; a finite number >= 0 is accepted") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not accepted; a finite number >= 0 is required")
    return value


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "robustness",
        help="robustness condition (4.23) and error bounds of the computed-torque controller",
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
    p.add_argument(
        "--box",
        choices=("paper", "derived"),
        default="paper",
        help="uncertainty box: the paper's (5.1) intervals, or derived from the C80 parameter set",
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
    p.add_argument(
        "--model",
        choices=("paper", "nonholonomic"),
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
    p.add_argument(
        "--reading",
        choices=("corrected", "printed", "printed-literal"),
        default="corrected",
        help="reading of (4.19)-(4.20): corrected from (4.10) (default), printed labels, or (4.20) verbatim",
    )
    p.add_argument(
        "--gammas",
        choices=("exact", "paper"),
        default="exact",
        help="operator gains: exact integrals (default) or the paper's (4.16) 1/K_P, 4/(e K_D)",
    )
    p.add_argument("--alpha-ddot", type=_nonneg_float, default=0.4, help="||alpha0''|| [rad/s^2] (default 0.4)")
    p.add_argument("--alpha-dot", type=_nonneg_float, default=0.23, help="||alpha0'|| [rad/s] (default 0.23)")
    p.add_argument("--sin-cos3", type=_nonneg_float, default=1.24, help="||sin/cos^3|| (default 1.24)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..errors import ParameterError
    from ..robustness import (
        PAPER_CONDITION,
        ParameterBox,
        ReferenceBounds,
        analyse,
        exact_gammas,
        gains_from_omega_r,
        paper_gammas,
    )
    from ._common import print_json

    if args.omega_r is not None:
        if args.kp is not None or args.kd is not None:
            raise ParameterError("--omega-r sets both gains by (3.6); it cannot be combined with --kp/--kd")
        kp, kd = gains_from_omega_r(args.omega_r)
    else:
        kp = 6.0 if args.kp is None else args.kp
        kd = 9.0 if args.kd is None else args.kd

    if args.box == "paper":
        used = [opt for opt, v in (("--m1-range", args.m1_range), ("--range", args.range), ("--model", args.model)) if v]
        if used:
            raise ParameterError(f"{', '.join(used)} only apply to --box derived (got --box paper)")
        box = ParameterBox.paper()
        box_label = "paper (5.1)"
    else:
        from ..params import C80

        ranges: dict[str, tuple[float, float]] = {}
        for item in args.range or []:
            name, span = parse_range(item)
            if name in ranges:
                raise ParameterError(f"--range {name} given twice; give each parameter once")
            ranges[name] = span
        if "m1" in ranges and args.m1_range is not None:
            raise ParameterError("m1 given by both --m1-range and --range m1=LO:HI; give it once")
        m1_range = tuple(args.m1_range) if args.m1_range is not None else (550.0, 750.0)
        if "m1" in ranges:
            m1_range = ranges.pop("m1")
        model = args.model or "paper"
        box = ParameterBox.from_parameters(C80, m1_range=m1_range, ranges=ranges, model=model)
        spans = [f"m1 {m1_range[0]:g}-{m1_range[1]:g} kg"] + [f"{n} {lo:g}-{hi:g}" for n, (lo, hi) in ranges.items()]
        box_label = f"derived from C80 ({model} model; {', '.join(spans)})"

    bounds = ReferenceBounds(alpha_ddot_max=args.alpha_ddot, alpha_dot_max=args.alpha_dot, sin_cos3_max=args.sin_cos3)
    estimate = parse_assignments(args.estimate, option="--estimate", example="P=0.385") if args.estimate else None
    result = analyse(box, kp=kp, kd=kd, bounds=bounds, reading=args.reading, gammas=args.gammas, estimate=estimate)

    if args.json:
        print_json(result.as_dict())
        return 0

    g1e, g2e = exact_gammas(kp, kd)
    g1p, g2p = paper_gammas(kp, kd)
    rel = (result.condition - PAPER_CONDITION) / PAPER_CONDITION
    paper_example = (
        args.box == "paper" and kp == 6.0 and kd == 9.0 and estimate is None and bounds == ReferenceBounds()
    )
    if paper_example:
        paper_note = f"paper reports {PAPER_CONDITION} (rel. diff {rel:+.2%})"
    else:
        paper_note = f"(the paper's (5.1) example gives {PAPER_CONDITION}; not this case)"

    def fmt(x: float) -> str:
        return f"{x:.5g}" if math.isfinite(x) else "unbounded"

    rows = [
        ("gains K_P, K_D", f"{kp:g}, {kd:g} ({result.regime})"),
        ("box", box_label),
        ("box P [V s^2/rad]", "({:.4g}, {:.4g})".format(*box.P)),
        ("box C_V [V s/rad]", "({:.4g}, {:.4g})".format(*box.C_V)),
        ("box F [V]", "({:.4g}, {:.4g})".format(*box.F)),
        ("box K [V]", "({:.4g}, {:.4g})".format(*box.K)),
        ("estimate", ", ".join(f"{k}^={v:g}" for k, v in (estimate or {}).items()) or "anywhere in the box (4.2)"),
        ("reading / gammas", f"{args.reading} / {args.gammas}"),
        ("gamma1 (4.14)", f"{fmt(result.gamma1)}   [exact {g1e:.5g}, paper (4.16) {g1p:.5g}]"),
        ("gamma2 (4.14)", f"{fmt(result.gamma2)}   [exact {g2e:.5g}, paper (4.16) {g2p:.5g}]"),
        ("delta1 (4.18)", fmt(result.delta1)),
        ("delta2: coef of ||E||", fmt(result.delta_E)),
        ("delta3: coef of ||E'||", fmt(result.delta_Edot)),
        ("condition (4.23)", f"{fmt(result.condition)}   {paper_note}"),
        ("stable (< 1)", "yes" if result.stable else "no"),
        ("||E|| max [rad]", fmt(result.E_max)),
        ("||E'|| max [rad/s]", fmt(result.Edot_max)),
    ]
    width = max(len(k) for k, _ in rows)
    print("Robustness of computed-torque steering control (paper section 4)")
    for key, value in rows:
        print(f"  {key:<{width}}  {value}")
    return 0
