"""``wmr-mj cart check FILE|NAME``: is a cart file sound? The answer in the first line.

It reads and checks the file against its schema (a wrong file: one line naming the key, the value, its unit
and what is accepted, exit status 2), builds its default sensing, actuation and play, compiles the generated
model and steps it for 1 s with random controls (no MuJoCo warning accepted, as Menagerie's test), and
identifies the reduced model (P, C_V, F, K, gyro) from a simulated excitation against what the file implies
(:mod:`wmr_mj.plant.cartcheck`). Exit status 0 when every check passes, 1 when one fails.
"""

from __future__ import annotations

import argparse
from typing import Any

from wmr_mj.cli._common import positive_float


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("cart", help="check a cart file (TOML): schema, compile and step, identification")
    p.add_argument("action", choices=("check",),
                   help="check: read the file against its schema, compile and step the generated model for 1 s "
                        "with random controls (no MuJoCo warning), identify P, C_V, F, K, gyro from a simulated "
                        "excitation and compare them with what the file implies; exit 1 if a check fails")
    p.add_argument("cart", metavar="FILE|NAME", help="a cart file (.toml, see wmr_mj/carts/c80.toml) or a shipped "
                                                     "cart's name (c80)")
    p.add_argument("--duration", type=positive_float, default=20.0,
                   help="length of the identification's excitation, s (default 20)")
    p.add_argument("--seed", type=int, default=0, help="seed of the random controls and the excitation (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def _default_parts(cart: Any) -> dict[str, str]:
    """The cart's default sensing, actuation and play built as their parts (a bad spec raises one line)."""
    from wmr_mj.errors import ParameterError, WmrMjError
    from wmr_mj.hardware import Actuation, Sensing, Transmission

    built = {}
    for key, cls in (("sensing", Sensing), ("actuation", Actuation), ("backlash", Transmission)):
        value = cart.defaults[key]
        try:
            part = cls(backlash=value) if cls is Transmission else cls.from_spec(value)
        except WmrMjError as exc:
            raise ParameterError(f"cart file {str(cart.path)!r}: defaults.{key}.value = {value!r}: {exc}") from None
        built[key] = part.label()
    return built


def _answer(cart: Any, steps: Any, ident: Any, ident_error: str | None) -> str:
    """The first line: passes, or what failed (``ident`` None: the fit was impossible, ``ident_error`` says why)."""
    where = f"cart {cart.name} {cart.version} ({cart.path})"
    failed = []
    if not steps.passed:
        what = ", ".join(f"{name} x{n}" for name, n in steps.warnings.items()) or "no warning"
        failed.append(f"1 s of random controls: {what}" + ("" if steps.finite else ", a non-finite state"))
    if ident is None:
        failed.append(f"no identification: {ident_error}")
    elif ident.warnings:
        failed.append(f"{ident.warnings} MuJoCo warnings in the excitation")
    if ident is not None:
        failed += [f"{row.name} identified {row.identified:.4g}, implied {row.implied:.4g} +- {row.allowed:.2g}"
                   for row in ident.rows if not row.passed]
    if failed:
        return f"{where}: FAILS: " + "; ".join(failed)
    return (f"{where}: passes: compiles and steps 1 s of random controls with no MuJoCo warning; the identified "
            "P, C_V, F, K, gyro are those the file implies")


def _print_text(cart: Any, parts: dict[str, str], steps: Any, ident: Any, ident_error: str | None) -> None:
    from wmr_mj.plant.cartcheck import COEFFICIENT_UNITS

    print(_answer(cart, steps, ident, ident_error))
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
    from wmr_mj.carts import load_cart
    from wmr_mj.cli._common import print_json
    from wmr_mj.errors import ParameterError
    from wmr_mj.params import parameters_of_cart
    from wmr_mj.plant.cartcheck import check_identification, step_with_random_controls

    cart = load_cart(args.cart)
    params = parameters_of_cart(cart)
    parts = _default_parts(cart)
    steps = step_with_random_controls(params, seed=args.seed)
    ident, ident_error = None, None
    try:
        ident = check_identification(params, duration=args.duration, seed=args.seed)
    except ParameterError as exc:  # too few sliding samples: the cart's answer, not the user's input
        ident_error = str(exc)
    passed = steps.passed and ident is not None and ident.passed
    answer = _answer(cart, steps, ident, ident_error)
    if args.json:
        print_json({"answer": answer, "passed": passed, "cart": cart.name, "version": cart.version,
                    "path": str(cart.path), "defaults": parts, "steps": steps.as_dict(),
                    "identification": None if ident is None else ident.as_dict(), "identification_error": ident_error})
    else:
        _print_text(cart, parts, steps, ident, ident_error)
    return 0 if passed else 1
