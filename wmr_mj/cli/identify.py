"""``wmr-mj identify``: fit the steering model to the driving MuJoCo plant."""

from __future__ import annotations

import argparse

from wmr_mj.cli._common import parse_assignments, positive_float
from wmr_mj.cli.options import add_json, add_out, add_seed
from wmr_mj.params import M1_NOMINAL

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "excite the plant's steering and fit P, C_V, F, K, gyro by least squares"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("identify", help=HELP)
    p.add_argument("--m1", type=positive_float, default=M1_NOMINAL,
                   help="chassis mass of the plant, kg (default: the cart's, 650 on the C80)")
    p.add_argument("--duration", type=positive_float, default=60.0, help="excitation length, s (default 60)")
    add_seed(p, help="seed of the excitation signal (default 0)")
    p.add_argument("--param", action="append", metavar="NAME=VALUE", help="override a plant parameter (repeatable)")
    add_out(p, metavar="PATH", help="also write the result as JSON (used by --model identified)")
    add_json(p, help="print one JSON object")
    from wmr_mj.cli.run_options import add_option

    add_option(p, "--cart")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from wmr_mj._util.files import check_output_path, write_json_atomic
    from wmr_mj.cli._common import print_json
    from wmr_mj.cli.options import cart_parameters
    from wmr_mj.params import COEFFICIENT_MODELS, COEFFICIENT_NAMES, with_params
    from wmr_mj.plant.identify import identify_plant

    if args.out:  # before the identification, which takes a while
        check_output_path(args.out, kind="file", option="--out")
    base = cart_parameters(args)
    m1 = base.m1 if args.m1 is M1_NOMINAL else args.m1  # --m1 not given: the cart's
    overrides = parse_assignments(args.param)
    params = with_params(base, m1=m1, **overrides)
    if "k_i" in overrides or "k_b" in overrides:
        from wmr_mj.sim.config import check_motor_constant

        check_motor_constant(params.k_i, params.k_b)
    result = identify_plant(params, duration=args.duration, seed=args.seed)
    obj = result.as_dict()
    if args.out:
        write_json_atomic(args.out, obj)
    if args.json:
        print_json(obj)
        return 0
    units = {"P": "V s^2/rad", "C_V": "V s/rad", "F": "V", "K": "V", "gyro": "V s/m"}
    se = result.diagnostics["std_error"]
    print(f"Steering identification of the MuJoCo plant: m1 = {params.m1:g} kg, {args.duration:g} s, seed {args.seed}, "
          f"{result.diagnostics['samples']} samples, residual {result.diagnostics['residual_rms_V']:.3g} V rms")
    print(f"{'coef':5s} {'identified':>12s} {'+-':>8s} {'paper':>10s} {'diff':>8s} {'nonholon.':>10s} "
          f"{'diff':>8s}  unit")
    rel = {name: result.relative_difference(name) for name in COEFFICIENT_MODELS}
    for k in COEFFICIENT_NAMES:
        cells = []
        for name in COEFFICIENT_MODELS:
            r = rel[name][k]
            diff = "   n/a" if r is None else f"{100 * r:+7.1f}%"
            cells.append(f"{getattr(result.predicted[name], k):10.4g} {diff:>8s}")
        print(f"{k:5s} {getattr(result.identified, k):12.5g} {se[k]:8.2g} {cells[0]} {cells[1]}  {units[k]}")
    print(result.verdict())
    if args.out:
        print(f"wrote {args.out}")
    return 0
