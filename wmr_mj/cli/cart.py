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
(:func:`wmr_mj.sim.design_search.search_design`, CMA-ES seeded with ``--seed``, design's default budget
(:data:`wmr_mj.sim.design_search.DEFAULT_BUDGET`) of certificates, the paper circle, the cart's m1 box, a 1 ms
period) run on the cart, as ``wmr-mj design --cart FILE --seed S`` runs it: "design certifies it: E_max ... rad
(K_P ..., K_D ...)" or "no gains in the box certify this cart: ... binds". Also a report: it does not change the
exit status. It adds about 2 s (2026-11-27, 2 cores under a shared load of 4-5: 603 certificates in 2.0 s, the
whole ``cart check c80`` in 5.3 s wall).
"""

from __future__ import annotations

import argparse
from typing import Any

from wmr_mj.cli._common import positive_float

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "check a cart file (TOML): schema, compile and step, identification"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("cart", help=HELP)
    p.add_argument("action", choices=("check", "card"),
                   help="check: read the file against its schema, compile and step the generated model for 1 s "
                        "with random controls (no MuJoCo warning), identify P, C_V, F, K, gyro from a simulated "
                        "excitation and compare them with what the file implies, and report the certified design's "
                        "certificate on the cart; exit 1 if a check fails. card: write the cart's model card "
                        "(Markdown, as models/README.md is the C80's; about a minute of measurements)")
    p.add_argument("cart", metavar="FILE|NAME", help="a cart file (.toml, see wmr_mj/carts/c80.toml) or a shipped "
                                                     "cart's name (c80)")
    p.add_argument("--duration", type=positive_float, default=20.0,
                   help="length of the identification's excitation, s (default 20)")
    p.add_argument("--seed", type=int, default=0, help="seed of the random controls and the excitation (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--path", metavar="NAME|FILE", default=None,
                   help="check: the path the certified design and the design search answer for (a path name, a "
                        "packaged route or a route file; default: the cart's own, [paths] default in its file, "
                        "else paper-circle)")
    p.add_argument("--out", metavar="PATH", default=None,
                   help="card: the Markdown file to write (default: logs/<cart file's stem>-card.md)")
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


def certified_on_cart(cart: Any, path: str = "paper-circle") -> dict[str, Any]:
    """The certified design on ``cart`` (a checked CartFile) and its certificate on ``path`` with the cart's
    default sensing, actuation and play: omega_r [rad/s], kp, kd, certified, E_max [rad], Edot_max [rad/s],
    voltage_max [V], voltage_limit [V], met, unmet (assumption names); or omega_r None and 'reason' where the rule
    finds no omega_r on its grid."""
    from wmr_mj.errors import InfeasiblePathError, ParameterError
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import certified_design
    from wmr_mj.sim.parts import resolve_run

    try:  # a paper circle the cart's supply or stops cannot follow: the cart's answer, not the user's input
        design = certified_design(cart, path=path)
        claim = resolve_run(RunConfig(**design.config_changes(), cart=cart, path=path)).claim
    except (ParameterError, InfeasiblePathError) as exc:
        return {"omega_r": None, "reason": str(exc), "path": path}
    assert claim is not None  # the computed-torque law always states its certificate
    return {"omega_r": design.kd, "kp": design.kp, "kd": design.kd, "certified": claim.certified,
            "E_max": claim.E_max, "Edot_max": claim.Edot_max, "voltage_max": claim.voltage_max,
            "voltage_limit": float(cart.parameters["voltage_limit"]),
            "met": [a.name for a in claim.assumptions if a.met], "unmet": list(claim.unmet), "path": path}


def design_on_cart(cart: Any, *, seed: int | None = None, budget: int | None = None,
                   path: str = "paper-circle") -> dict[str, Any]:
    """Can ``wmr-mj design`` certify ``cart`` (a checked CartFile) on its default sensing, actuation and play? The
    design search on ``path`` over the cart's m1 box, computed-torque law, 1 ms period, E_max minimised.

    Returns:
        certified; where certified: E_max [rad], voltage_max [V], kp [1/s^2], kd [1/s], friction_width [rad/s];
        else binding (the assumption, or why no certificate covers the cart's sensing); budget, seed, evaluations,
        and the ``wmr-mj design`` command that runs the same search. seed, budget: None, design's defaults
        (:data:`~wmr_mj.sim.design_search.DEFAULT_SEED`, :data:`~wmr_mj.sim.design_search.DEFAULT_BUDGET`).
    """
    from wmr_mj.errors import InfeasiblePathError
    from wmr_mj.sim.coerce import default_path
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.design_search import (
        DEFAULT_BUDGET,
        DEFAULT_SEED,
        DesignProblem,
        law_changes,
        search_design,
        uncovered,
    )

    seed = DEFAULT_SEED if seed is None else seed
    budget = DEFAULT_BUDGET if budget is None else budget
    command = (f"wmr-mj design --cart {cart.path} --seed {seed}"
               + ("" if budget == DEFAULT_BUDGET else f" --budget {budget}")
               + ("" if path == default_path(cart) else f" --path {path}"))
    out: dict[str, Any] = {"budget": budget, "seed": seed, "command": command, "path": path}
    base = RunConfig.from_inputs(**law_changes("computed-torque"), cart=cart)
    why_not = uncovered(base)
    if why_not:  # design refuses such a cart's sensing (no certificate can cover it)
        return {**out, "certified": False, "evaluations": 0,
                "binding": f"the default sensing ({why_not}: no certificate covers it)"}
    try:
        result = search_design(DesignProblem(base=base, seed=seed, budget=budget, paths=(path,)))
    except InfeasiblePathError as exc:  # the cart cannot follow the path: no gains certify it
        return {**out, "certified": False, "evaluations": 0, "binding": f"the path {path}'s feasibility ({exc})"}
    out.update(certified=result.certified, evaluations=result.evaluations)
    if not result.certified:
        return {**out, "binding": result.binding}
    s = result.settings
    return {**out, "E_max": result.E_max, "voltage_max": result.certificates[path].voltage_max,
            "kp": s["kp"], "kd": s["kd"], "friction_width": s["friction_width"]}


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
               f"of the {c['voltage_limit']:g} V supply, on the cart's default sensing, path {c['path']}")
    if c["certified"]:
        return head + f"CERTIFIED, all {len(c['met'])} assumptions met; " + numbers
    return head + f"NOT certified: {', '.join(c['unmet']) or 'no valid bound'} not met; " + numbers


def _print_text(cart: Any, parts: dict[str, str], steps: Any, ident: Any, ident_error: str | None,
                certified: dict[str, Any], design: tuple[dict[str, Any], float]) -> None:
    from wmr_mj.plant.cartcheck import COEFFICIENT_UNITS

    print(_answer(cart, steps, ident, ident_error))
    print(_certified_line(certified))
    print(_design_line(*design))
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
    import time

    from wmr_mj.carts import load_cart
    from wmr_mj.cli._common import print_json
    from wmr_mj.errors import InfeasiblePathError, ParameterError, StiffReferenceError
    from wmr_mj.params import parameters_of_cart
    from wmr_mj.plant.cartcheck import check_identification, step_with_random_controls
    from wmr_mj.sim.coerce import default_path
    from wmr_mj.sim.config import build_reference

    cart = load_cart(args.cart)
    params = parameters_of_cart(cart)
    parts = _default_parts(cart)
    if args.action == "card":
        return _write_card(cart, args.out)
    path = default_path(cart) if args.path is None else args.path  # the cart's own, named in the answer
    try:  # a reference that cannot be built in bounded time is an absurd cart: refused before any step
        build_reference(path, params, dt=1e-3, duration=35.0)
    except StiffReferenceError as exc:
        raise ParameterError(f"cart file {str(cart.path)!r}: {exc}") from None
    except InfeasiblePathError:  # a circle the cart cannot steer: the cart's answer, reported below
        pass
    certified = certified_on_cart(cart, path)
    t0 = time.perf_counter()
    design = design_on_cart(cart, seed=args.seed, path=path)
    design_wall = time.perf_counter() - t0
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
                    "identification": None if ident is None else ident.as_dict(), "identification_error": ident_error,
                    "certified_design": certified, "design": design})
    else:
        _print_text(cart, parts, steps, ident, ident_error, certified, (design, design_wall))
    return 0 if passed else 1


def _write_card(cart: Any, out: str | None) -> int:
    """Write the cart's model card (:func:`wmr_mj.plant.modelcard.render_model_card`) to ``out``."""
    from wmr_mj._util.files import check_output_path, write_text_atomic
    from wmr_mj.plant.modelcard import render_model_card

    path = check_output_path(out or f"logs/{cart.path.stem}-card.md", kind="file", option="--out")
    print(f"wrote {write_text_atomic(path, render_model_card(cart=cart))}")
    return 0
