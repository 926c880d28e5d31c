"""``wmr-mj design``: the computed-torque (or sliding-mode) gains a given cart can certify
(:mod:`wmr_mj.searches.design_search`)."""

from __future__ import annotations

import argparse
import dataclasses
import math
import shlex
import time
from typing import Any

from wmr_mj.analysis.delay_split import covered_split
from wmr_mj.carts.provenance import identified_from_line
from wmr_mj.cli._common import print_json
from wmr_mj.cli.ranges import box_ranges_from_args
from wmr_mj.cli.run import hardware_from_args
from wmr_mj.errors import ParameterError
from wmr_mj.experiments.sweep import sweep_over_box
from wmr_mj.params import M1_RANGE
from wmr_mj.reference.named import default_path, default_path_note
from wmr_mj.reference.route import path_name
from wmr_mj.searches.design_search import (
    DESIGN_FIELDS,
    OBJECTIVES,
    DesignProblem,
    check_periods,
    law_changes,
    search_design,
    uncovered,
    write_design,
)
from wmr_mj.sim.certify import certificate_name
from wmr_mj.sim.coerce import cart_file_of_record
from wmr_mj.sim.config import RunConfig


def problem_from_args(args: argparse.Namespace) -> Any:
    """The :class:`~wmr_mj.searches.design_search.DesignProblem` of the options, every input checked first.

    Raises:
        ParameterError: an empty box, an unknown objective, a period list that is not accepted, a cart no claim
            covers (one line naming the culprit).
    """
    law = law_changes(args.controller)
    if args.objective not in OBJECTIVES:
        raise ParameterError(f"--objective {args.objective!r} is not accepted; one of {', '.join(OBJECTIVES)}")
    lo, hi = (float(v) for v in args.m1_range)
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
        raise ParameterError(f"--m1-range {lo:g} {hi:g} is an empty box; LO <= HI, both > 0 kg, is accepted")
    # --cart: the cart's parameter set, supply and stops, its default sensing, actuation and play (the parts not
    # given stay None) and, where --m1-range is not given (its default, the very object), its m1 box
    m1_range: Any = None if args.m1_range is M1_RANGE else (lo, hi)
    ranges = box_ranges_from_args(args)
    for name, (a, b) in ranges.items():
        if not a <= b:
            raise ParameterError(f"--range {name}={a:g}:{b:g} is an empty box; LO <= HI is accepted")
    periods_text = [t for t in str(args.periods).split(",") if t.strip()]
    try:
        periods = tuple(float(t) for t in periods_text)
    except ValueError:
        raise ParameterError(f"--periods {args.periods!r} is not a list of numbers (s), e.g. 0.001,0.002") from None
    check_periods(periods, args.duration)
    base = RunConfig.from_inputs(**law, m1_range=m1_range, box_ranges=ranges, duration=args.duration,
                     reference_bounds=args.reference_bounds, cart=getattr(args, "cart", None),
                     **hardware_from_args(args))
    why_not = uncovered(base)
    if why_not:
        raise ParameterError(f"{why_not}: no certificate can cover it (--sensing, --actuation, --backlash); a "
                             "bounded error is accepted")

    paths = tuple(args.path or (default_path(cart_file_of_record(base.cart)),))  # none given: the cart's own
    return DesignProblem(base=base, paths=paths, periods=periods,
                         objective=args.objective, method=args.method, seed=args.seed,
                         budget=args.budget)


def run(args: argparse.Namespace) -> int:
    if args.check < 0:
        raise ParameterError(f"--check {args.check} is not accepted; a number of runs >= 0")
    problem = problem_from_args(args)
    t0 = time.perf_counter()
    result = search_design(problem)
    wall = time.perf_counter() - t0
    write_design(result, args.out)
    out = result.to_dict()  # the design file's content (design_dict), then what the command adds
    out.update(file=str(args.out), wall_s=wall, run=run_line(args))
    note = _path_note(args, problem)
    if note is not None:  # the default path derived from the cart's stops, named
        out["path_note"] = note
    if result.certified and args.check > 0:
        out["check"] = check_design(problem, result, args.check)
    if args.json:
        print_json(out)
    else:
        _print(result, args, out, wall)
    return 0 if result.certified else 1


def check_design(problem: Any, result: Any, n: int) -> dict[str, Any]:
    """A sweep of ``n`` runs over the box (m1 and the --range parameters) at the design, on the first path, with
    the search's seed: its verdict counts."""
    base = dataclasses.replace(problem.base, path=problem.paths[0], **{k: result.settings[k] for k in DESIGN_FIELDS})
    runs = sweep_over_box(base, n, seed=problem.seed)
    return {"n": runs.n, "verdicts": dict(runs.verdicts), "path": base.path}


def _path_note(args: argparse.Namespace, problem: Any) -> str | None:
    """The line naming the default path derived from the cart's stops where no --path is given
    (:func:`wmr_mj.reference.named.default_path_note`); None otherwise."""
    return None if args.path else default_path_note(cart_file_of_record(problem.base.cart))


def _print(result: Any, args: argparse.Namespace, out: dict[str, Any], wall: float) -> None:
    s = result.settings
    paths = ", ".join(path_name(p) for p in result.paths)
    if "path_note" in out:
        print(out["path_note"])
    if not result.certified:
        print(f"no gains in the box certify this cart: {result.binding} binds (the best point found, over "
              f"{paths}; {result.evaluations} certificates in {wall:.1f} s)")
        return
    tau = s["sensing"].filter_tau
    if result.law_parameters:  # the law's own parameters (controllers.base.DesignParameter), not the run's gains
        c = s["controller_params"]
        law = (s["controller"].replace("-", " ") + " "
               + ", ".join(f"{p.name} = {c[p.name]:{p.format}} {p.unit}" for p in result.law_parameters)
               + f", sign width {c['friction_width']:.4g} rad/s")
    else:
        law = (f"K_P = {s['kp']:.6g} 1/s^2, K_D = {s['kd']:.6g} 1/s (omega_n {math.sqrt(s['kp']):.4g} rad/s, zeta "
               f"{s['kd'] / (2 * math.sqrt(s['kp'])):.3g}), sign width {s['friction_width']:.4g} rad/s")
    print(f"design ({result.objective}, {args.method}, seed {result.seed}, {result.evaluations} certificates in "
          f"{wall:.1f} s): {law}, period {s['control_period'] * 1e3:g} ms"
          + (f", tau_f {tau * 1e3:.4g} ms" if tau is not None else ""))
    for path, cert in result.certificates.items():
        split = covered_split(cert.assumptions)  # a delay known as its sum: every split certified
        print(f"  {path_name(path)}: certified, E_max {cert.E_max:.6g} rad, voltage {cert.voltage_max:.4g} V "
              f"({certificate_name(cert)}; {len(cert.assumptions)} assumptions met"
              + ("" if split is None else f"; {split}") + ")")
    if "check" in out:
        c = out["check"]
        print(f"check: {c['n']} runs over the box on {path_name(c['path'])}: "
              + ", ".join(f"{v} {n}" for v, n in c["verdicts"].items()))
    if result.cart is not None:  # a cart identified from recordings: the data the design rests on
        rests_on = identified_from_line(str(result.cart.get("text", "")), str(result.cart.get("path", "")))
        if rests_on is not None:
            print(rests_on)
    print(f"wrote {args.out}: {run_line(args)}")


def run_line(args: argparse.Namespace) -> str:
    """The ``wmr-mj run`` line of the design on its first path: the file, and the box and run options the
    design was certified for where they are not run's defaults (the file holds the law and the cart only)."""
    words = ["wmr-mj", "run", "--design", shlex.quote(str(args.out))]
    if getattr(args, "cart", None) is not None:
        words += ["--cart", shlex.quote(str(args.cart))]
    if args.path:
        words += ["--path", shlex.quote(args.path[0])]
    if args.uncertainty is not None:
        words += ["--uncertainty", args.uncertainty]
    if tuple(args.m1_range) != tuple(M1_RANGE) or (getattr(args, "cart", None) is not None
                                                   and args.m1_range is not M1_RANGE):  # given on a cart: its own
        words += ["--m1-range", *(repr(float(v)) for v in args.m1_range)]
    words += [w for item in args.range or [] for w in ("--range", shlex.quote(item))]
    if args.reference_bounds is not None:
        words += ["--reference-bounds", shlex.quote(args.reference_bounds)]
    if args.duration != 35.0:
        words += ["--duration", repr(args.duration)]
    return " ".join(words)
