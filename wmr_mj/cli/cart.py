"""``wmr-mj cart check FILE|NAME``: is a cart file sound? The answer in the first line, the certified design's
certificate on the cart in the second. ``wmr-mj cart card FILE|NAME [--out PATH]``: the cart's model card.

It reads and checks the file against its schema (a wrong file: one line naming the key, the value, its unit
and what is accepted, exit status 2), builds its default sensing, actuation and play, compiles the generated
model and steps it for 1 s with random controls (no MuJoCo warning accepted, as Menagerie's test), and
identifies the reduced model (P, C_V, F, K, gyro) from a simulated excitation against what the file implies
(:mod:`wmr_mj.plant.cartcheck`). Exit status 0 when every check passes, 1 when one fails.

It also reports the certified design on the cart: the rule of :mod:`wmr_mj.sim.designs` run on the cart's
parameter set and m1 box (its omega_r, never the C80's), and that design's certificate on the paper circle with the
cart's default sensing, actuation and play: E_max, the voltage bound against the supply, the assumptions met and
unmet. This is a report, not a check: a cart whose design cannot be certified still passes ``cart check``.

Its third line answers whether ``wmr-mj design`` can certify the cart on its default sensing: the design search
(:func:`wmr_mj.searches.design_search.search_design`, CMA-ES seeded with ``--seed``, design's default budget
(:data:`wmr_mj.searches.design_search.DEFAULT_BUDGET`) of certificates, the paper circle, the cart's m1 box, a 1 ms
period) run on the cart, as ``wmr-mj design --cart FILE --seed S`` runs it: "design certifies it: E_max ... rad
(K_P ..., K_D ...)" or "no gains in the box certify this cart: ... binds". Also a report: it does not change the
exit status. It adds about 4 s (2026-11-28, 2 cores: 1206 certificates in 3.9 s, the default objective's two
searches of 603; the whole ``cart check c80`` in 5.4 s wall).
"""

from __future__ import annotations

import argparse
from typing import Any

from wmr_mj._util.files import check_output_path, write_text_atomic
from wmr_mj.carts import load_cart
from wmr_mj.cli._common import print_json
from wmr_mj.experiments.cart_check import cart_check, default_parts
from wmr_mj.params import parameters_of_cart
from wmr_mj.plant.cartcheck import COEFFICIENT_UNITS
from wmr_mj.plant.modelcard import render_model_card
from wmr_mj.reference.route import path_name


def _design_line(d: dict[str, Any], wall: float) -> str:
    """The third line: can ``design`` certify the cart on its default sensing."""
    how = f"{d['command']}: {d['evaluations']} certificates in {wall:.1f} s"
    if not d["certified"]:
        return f"no gains in the box certify this cart: {d['binding']} binds ({how})"
    return (f"design certifies it: E_max {d['E_max']:.4g} rad (K_P {d['kp']:.6g}, K_D {d['kd']:.6g}, sign width "
            f"{d['friction_width']:.4g} rad/s, |u| <= {d['voltage_max']:.4g} V) on the cart's default sensing ({how})")


def _certified_line(c: dict[str, Any]) -> str:
    """The second line: the certified design's certificate on the cart."""
    if c["omega_r"] is None:
        return f"certified design: none on this cart ({c['reason']})"
    head = (f"certified design on this cart: omega_r = {c['omega_r']:g} rad/s (K_P = {c['kp']:g}, K_D = {c['kd']:g}, "
            "the rule of wmr_mj/sim/designs.py run on the cart): ")
    numbers = (f"E_max = {c['E_max']:.4g} rad, |E'| <= {c['Edot_max']:.4g} rad/s, |u| <= {c['voltage_max']:.4g} V "
               f"of the {c['voltage_limit']:g} V supply, on the cart's default sensing, path "
               f"{path_name(c['path'])}")
    if c["certified"]:
        return head + f"CERTIFIED, all {len(c['met'])} assumptions met; " + numbers
    return head + f"NOT certified: {', '.join(c['unmet']) or 'no valid bound'} not met; " + numbers


def _print_text(check: Any) -> None:
    """``cart check``'s report as text (``--json`` prints ``check.to_dict()``)."""
    parts, steps, ident = check.defaults, check.steps, check.identification
    print(check.answer)
    if check.path_note is not None:
        print(check.path_note)
    print(_certified_line(check.certified_design))
    print(_design_line(check.design, check.design_wall_s))
    print(f"defaults: sensing {parts['sensing']}; actuation {parts['actuation']}; play {parts['backlash']}")
    print(f"steps: {steps.steps} steps ({steps.duration:g} s) of uniform random controls, seed {steps.seed}: "
          f"{sum(steps.warnings.values())} MuJoCo warnings, state {'finite' if steps.finite else 'NOT finite'}")
    if ident is None:
        return
    diag = ident.result.diagnostics
    print(f"identification: {ident.result.duration:g} s excitation, seed {ident.result.seed}, {diag['samples']} "
          f"samples, residual {diag['residual_rms_V']:.3g} V rms, {ident.warnings} MuJoCo warnings; implied: the "
          "non-holonomic model (K = 0, gyro = P/l1), the paper's (2.13) beside")
    print(f"{'coef':5s} {'identified':>12s} {'implied':>10s} {'allowed':>9s} {'paper':>10s}  unit")
    for row in ident.rows:
        print(f"{row.name:5s} {row.identified:12.5g} {row.implied:10.5g} {'+-' + format(row.allowed, '.2g'):>9s} "
              f"{row.paper:10.5g}  {COEFFICIENT_UNITS[row.name]:10s} {'ok' if row.passed else 'FAILS'}")


def run(args: argparse.Namespace) -> int:
    cart = load_cart(args.cart)
    if args.action == "card":  # a parameter set or default part that cannot be built: one line, before the card
        parameters_of_cart(cart)
        default_parts(cart)
        return _write_card(cart, args.out)
    check = cart_check(cart, seed=args.seed, duration=args.duration, path=args.path)
    if args.json:
        print_json(check.to_dict())
    else:
        _print_text(check)
    return 0 if check.passed else 1


def _write_card(cart: Any, out: str | None) -> int:
    """Write the cart's model card (:func:`wmr_mj.plant.modelcard.render_model_card`) to ``out``."""
    path = check_output_path(out or f"logs/{cart.path.stem}-card.md", kind="file", option="--out")
    print(f"wrote {write_text_atomic(path, render_model_card(cart=cart))}")
    return 0
