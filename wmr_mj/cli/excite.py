"""``wmr-mj excite``: an excitation plan to play on a real cart, with the intervals identification would give."""

from __future__ import annotations

import argparse
from pathlib import Path

from wmr_mj._util.files import check_output_path
from wmr_mj.carts import load_cart
from wmr_mj.hardware.sensing import Sensing
from wmr_mj.params import parameters_of_cart
from wmr_mj.plant.excite import excitation_plan, plan_csv, preview
from wmr_mj.plant.output_error import POORLY_DETERMINED


def run(args: argparse.Namespace) -> int:
    out = check_output_path(args.out, kind="file", option="--out")
    cart = load_cart(args.cart)
    params = parameters_of_cart(cart)
    plan = excitation_plan(params, duration=args.duration, seed=args.seed)
    Path(out).write_text(plan_csv(plan), encoding="utf-8")
    fit = preview(plan, params, Sensing.from_spec(cart.defaults["sensing"]), seed=args.seed)
    print(f"wrote {out}: {args.duration:g} s; play alpha0_rad as your servo's target and add u_dither_V to its "
          f"output, record t_s,u_V (applied),alpha_rad (read), then: wmr-mj identify --cart {args.cart} --data ...")
    print("intervals identification would give (the plan played on the cart's reduced model, its default sensing):")
    for name, iv in fit.physical.items():
        print(f"  {name:16s} {iv.value:10.5g} [{iv.lo:.5g}, {iv.hi:.5g}]  +-{100 * iv.relative_half_width:.2g} %")
    wide = [n for n, iv in fit.physical.items() if iv.relative_half_width > POORLY_DETERMINED]
    if wide:
        print(f"  poorly determined (half-width above {100 * POORLY_DETERMINED:g} %): {', '.join(wide)}: the plan "
              "moves the steering too little against them; a longer plan (--duration) narrows the data's part")
    else:
        print(f"  every identified parameter within +-{100 * POORLY_DETERMINED:g} %")
    print("  gyro and K are not identified: gyro = P/l1 moves with C_V at a constant speed, K = 0 (the "
          "non-holonomic model); the 2 % model-error floor bounds every interval from below")
    return 0
