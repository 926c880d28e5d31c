"""``wmr-mj falsify``: search the uncertainty box for the plant the controller tracks worst."""

from __future__ import annotations

import argparse
import csv
import io
import json
import sys
import time
from typing import TYPE_CHECKING, Any

from wmr_mj._util.files import check_output_path, write_json_atomic, write_text_atomic
from wmr_mj._util.progress import counter_callback, progress_bar
from wmr_mj.analysis.verdicts import certified_outside_banner, format_unmet
from wmr_mj.cli._common import CLAIM_BROKEN_EXIT, print_json
from wmr_mj.cli.ranges import box_ranges_from_args, command_ranges
from wmr_mj.cli.run import config_from_args, with_design_file
from wmr_mj.cli.run_options import Replay, run_options
from wmr_mj.cli.sweep import fixed_m1_from_args
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.figures.plots import falsify_history, save_figure
from wmr_mj.hardware import cart_dict, cart_line, is_ideal_cart
from wmr_mj.logs.writer import run_logged
from wmr_mj.reference.knots import KnotSpace
from wmr_mj.searches.falsify import (
    PORTFOLIO_COORDINATE_STEP,
    FalsifySpec,
    check_objective_applies,
    check_objective_defined,
    check_runnable,
    falsify,
    portfolio_coordinate_runs,
    portfolio_global_runs,
    portfolio_local_phase,
    portfolio_phases,
    portfolio_start,
    undefined_objective_warning,
    worst_config,
)
from wmr_mj.searches.search_space import hardware_axis, path_axis
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.config import base_for, controller_and_settings, estimate_parameters
from wmr_mj.sim.many_runs import csv_number
from wmr_mj.sim.run_report import add_controller_source

if TYPE_CHECKING:
    from wmr_mj.searches.falsify import FalsifyResult

_AGAINST = ("certificate", "paper")
_OBJECTIVE_KINDS = ("ratio", "sup-E")


def _objective(args: argparse.Namespace) -> str:
    if args.objective not in _OBJECTIVE_KINDS:
        raise UnknownNameError("objective", args.objective, _OBJECTIVE_KINDS)
    if args.against not in _AGAINST:
        raise UnknownNameError("region", args.against, _AGAINST)
    if args.require is not None:
        return "requirement"
    return "sup-E" if args.objective == "sup-E" else args.against


def reproduce_command(config, params: dict[str, float], args: argparse.Namespace, *,
                      signals_file: str | None = None, path_file: str | None = None,
                      law_settings: frozenset[str] | None = None) -> str:
    """A ``wmr-mj run`` line that repeats the worst run ``config``, written by the table of run options
    (:func:`command_line`: each option writes back the field it sets, parameters at full
    precision; its signals, when it has some, from ``signals_file``, and its searched path from ``path_file``,
    where they were written exactly). ``params``: the worst run's searched values (already in ``config``)."""
    read = law_settings  # only the settings the law reads: the resolved run's (RunParts.law_settings)
    if read is None:
        read = controller_and_settings(config, estimate_parameters())[1]
    require = getattr(args, "require", None) or ()
    return command_line(config, Replay(preset=args.preset, law_settings=frozenset(read), path_file=path_file,
                                       signals_file=signals_file,
                                       require=(require,) if isinstance(require, str) else tuple(require)))


def command_line(config: Any, replay: Replay, *, command: str = "wmr-mj run") -> str:
    """The ``wmr-mj run`` line that builds ``config`` again: each row of the table writes its own field.

    Args:
        config: the run's RunConfig (a direct one is coerced first: its defaults resolved, as the run resolves them).
        replay: what the config does not record (:class:`Replay`).
    """
    config = coerced(config)
    return " ".join([command, *(w for row in run_options() for w in row.write(config, replay))])


def _portfolio_phases_text(spec, first, population: int) -> str:
    """What the portfolio did after its vertices: where CMA-ES started (the screening), its global and local
    phases, and (from 200 runs) the coordinate moves that end it."""
    start = portfolio_start(spec, first)
    moved = [f"{'up' if u > 0.5 else 'down'} in {n}" for n, u in zip(spec.names, start) if u != 0.5]
    _, global_runs, local_runs = portfolio_phases(len(spec.names), spec.budget, population)
    where = "the box's centre" + (f" moved {', '.join(moved)} (the vertices' main effects)" if moved else "")
    runs = portfolio_global_runs(len(spec.names), spec.budget, population)
    split = f" in {runs} independent runs" if runs > 1 else ""
    text = f"CMA-ES from {where} ({global_runs} runs{split}, {population} per generation)"
    coordinate_runs = portfolio_coordinate_runs(len(spec.names), spec.budget, population)
    if local_runs > coordinate_runs:
        text += (f", then a local CMA-ES around the worst found ({local_runs - coordinate_runs} runs, step "
                 f"{portfolio_local_phase(spec.budget)[1]:g} of each range)")
    if coordinate_runs:
        text += (f", then coordinate moves of the worst found ({coordinate_runs} runs, each parameter moved with "
                 f"probability 1/{len(spec.names)}, step {PORTFOLIO_COORDINATE_STEP:g} of its range)")
    return text


def _base_and_box(args: argparse.Namespace):
    """(base RunConfig, search box) of falsify's options. The signals', the path's and the cart's axes are
    searched, not certified over: the certificate's box is the plant's (each run's claim covers its own cart).

    Raises:
        ParameterError: a bad --path-knots or range (one line).
    """
    searched = command_ranges(args, "falsify").searched  # the one rule of --range; the plant's go to the box
    if args.path_knots < 0:
        raise ParameterError(f"--path-knots {args.path_knots} is not accepted: a number of knots >= 0")
    if (args.path_knots or any(path_axis(n) for n in searched)) and args.reference_bounds is None:
        args.reference_bounds = "paper"  # every searched path within the bounds its certificate declares

    fixed_m1 = fixed_m1_from_args(args)  # --m1 or a zero-width --m1-range: m1 not searched
    base = config_from_args(args) if fixed_m1 is None else config_from_args(args, m1=fixed_m1)
    if args.path_knots:
        space = KnotSpace(args.path_knots, hold_range=(0.0, 3.0))

        searched = {**space.ranges(base.reference_bounds, base_for(base)), **searched}  # the cart's l1 and stops
    box = {**({"m1": tuple(args.m1_range)} if fixed_m1 is None else {}), **box_ranges_from_args(args), **searched}
    return base, box


def run(args: argparse.Namespace) -> int:
    objective = _objective(args)
    if args.design is not None:  # the design's box before falsify's own default (the full box)
        with_design_file(args)
    args.uncertainty = args.uncertainty or "full"
    base, box = _base_and_box(args)
    spec = FalsifySpec(base=base, box=box, objective=objective, budget=args.budget, seed=args.seed,
                       population=args.population, method=args.method, requirement=args.require)
    parts = check_runnable(base)  # a duration too short for the path: one line, before any output or search
    check_objective_applies(parts.controller, spec.objective)  # before the output folder is made
    check_objective_defined(parts, spec)
    out = check_output_path(args.out or f"logs/falsify-{time.strftime('%Y%m%d-%H%M%S')}", kind="dir", option="--out")
    with progress_bar(2 * spec.budget, desc="falsify", unit="runs") as bar:
        result = falsify(spec, chunk=args.chunk, nthread=args.nthread, scheduler=args.scheduler,
                         progress=counter_callback(bar),  # evaluations.csv after every generation: Ctrl-C keeps them
                         checkpoint=lambda partial: write_text_atomic(out / "evaluations.csv", _table(partial)),
                         parts=parts)
    warning = undefined_objective_warning(result)  # runs left blank by the objective: said, on stderr
    if warning is not None:
        print(warning, file=sys.stderr, flush=True)
    summary, logged_sup_E = _write_outputs(result, base, args, out, law_settings=parts.law_settings)
    if args.json:
        print_json(summary)
    else:
        _print_text(result, base, summary, args, logged_sup_E)
    return exit_status(summary)


def _write_outputs(result, base, args: argparse.Namespace, out, *, law_settings) -> tuple[dict, float]:
    """Re-run the worst run serially with its MCAP log, write the search's files (falsify.json, evaluations.csv,
    the history plot, the worst run's signals and searched path where it has them): (the JSON, the re-run's
    sup|E| [rad]). ``base``: the command's base run (its controller, cart, path and reference bounds)."""
    worst, log_path = result.worst, out / "worst.mcap"
    config = worst_config(result)
    logged = run_logged(config, str(log_path))
    summary = result.to_dict(log=str(log_path), runs=False)  # the JSON, with the files and the cart added below
    add_controller_source(summary, base)
    summary.update(cart_dict(base))  # the base's cart where not ideal; the worst run's beside its parameters
    summary["worst"].update(cart_dict(config))
    signals_file = path_file = None
    if config.signals is not None:  # the worst run's signals, every parameter: --signals takes them back
        signals_file = str(out / "worst-signals.json")
        write_json_atomic(signals_file, config.signals.to_dict())
        summary["worst"]["signals"] = config.signals.to_dict()
        summary["signals_file"] = signals_file
    if config.path != base.path:  # a searched path: its canonical route, which --path takes back exactly
        path_file = str(out / "worst-path.json")
        write_text_atomic(path_file, config.path + "\n")
        summary["path_file"] = path_file
    summary.update({
        "reproduced": logged.sup_E == worst.sup_E,  # the serial re-run gives the batch's bits
        "reproduce": reproduce_command(config, worst.params, args, signals_file=signals_file, path_file=path_file,
                                       law_settings=law_settings),
        "reference_bounds": None if base.reference_bounds is None else base.reference_bounds.to_dict(),
        "uncertainty": args.uncertainty,
        "folder": str(out),
        "table": str(out / "evaluations.csv"),
        "plot": [str(p) for p in save_figure(falsify_history(result), out / "history")],
    })
    write_text_atomic(out / "evaluations.csv", _table(result))
    write_json_atomic(out / "falsify.json", summary)
    return summary, logged.sup_E


def _print_text(result, base, summary: dict, args: argparse.Namespace, logged_sup_E: float) -> None:
    """falsify's printout: how the search ran, the worst of the search and of the random sample, the claim,
    the worst run's certificate (E_max, the largest term of delta1) and tightness, its parameters and files."""
    spec, worst = result.spec, result.worst
    names, how = ", ".join(spec.names), _how_text(spec, result)
    print(f"worst-case search over {len(spec.names)} parameter(s) ({names}; box {args.uncertainty}): {how}, "
          f"seed {spec.seed}")
    print(f"objective: {result.objective_label}  [{result.objective_source}]")
    fmt = lambda x: "n/a" if x is None else f"{x:.6g}"  # noqa: E731
    print(f"search : worst objective {fmt(worst.objective)} in {len(result.search)} runs "
          f"(sup|E| = {worst.sup_E:.6g} rad, sup|E'| = {worst.sup_Edot:.6g} rad/s, {worst.verdict})")
    rw = result.random_worst
    print(f"random : worst objective {fmt(rw.objective)} in {len(result.random)} runs (Latin hypercube, same seed)")
    print("".join(f"{line}\n" for line in claim_lines(result)), end="")
    certificate = certificate_line(result)
    if certificate is not None:
        print(certificate)
    tightness = result.tightness
    if tightness is not None:
        print(f"tightness: {tightness.text}")
    if spec.objective == "requirement":
        first_s = next((e.index + 1 for e in result.search if e.objective is not None and e.objective > 0), None)
        first_r = next((e.index + 1 for e in result.random if e.objective is not None and e.objective > 0), None)
        print(f"requirement {spec.requirement}: "
              + (f"FALSIFIED, first at run {first_s} of the search" if first_s else "not falsified by the search")
              + (f"; random: first at run {first_r}" if first_r else "; random: not falsified"))
    print("worst parameters: " + ", ".join(f"{k} = {v!r}" for k, v in worst.params.items()))
    _print_cart(base, worst_config(result), spec.names)
    if "signals_file" in summary:
        print(f"worst signals: {json.dumps(summary['worst']['signals'], separators=(',', ':'))}")
    if "path_file" in summary:
        print(f"worst path: {summary['path_file']} (a knot path within the declared reference bounds)")
    if base.reference_bounds is not None:
        print(_bounds_line(base.reference_bounds))
    print(f"reproduce: {summary['reproduce']}")
    if not summary["reproduced"]:
        print(f"WARNING: the serial re-run gave sup|E| = {logged_sup_E!r}, the search {worst.sup_E!r}", flush=True)
    print(f"log:   {summary['log']}\nplot:  {summary['plot'][0]}\ntable: {summary['table']}")


def certificate_line(result: FalsifyResult) -> str | None:
    """The worst run's certificate, whatever the objective: its E_max and the largest term of its delta1; None
    where the run has neither."""
    w = result.worst
    if w.E_max is None and w.binding_term is None:
        return None
    line = "worst run's certificate: " + ("no E_max" if w.E_max is None else f"E_max = {w.E_max:.6g} rad")
    if w.binding_term is not None:
        line += f", its largest term of delta1 {w.binding_term.name} = {w.binding_term.value:.4g} rad/s^2"
    return line


def _print_cart(base, worst, names) -> None:
    """The cart's line where it is not ideal or is searched: the base's, and the worst run's (its hardware axes
    rounded as the run had them)."""
    searched = [n for n in names if hardware_axis(n)]
    if not is_ideal_cart(base) and not searched:
        print(cart_line(base))
    elif searched:
        print(f"worst {cart_line(worst)} (searched: {', '.join(searched)})")


def _bounds_line(b) -> str:
    """The declared reference bounds ``b`` (a ReferenceBounds), as falsify prints them."""
    return (f"reference bounds declared: |alpha0'| <= {b.alpha_dot_max:g} rad/s, |alpha0''| <= "
            f"{b.alpha_ddot_max:g} rad/s^2, |alpha0| <= {b.angle_max:.6g} rad (the certificate holds for every "
            "reference within them)")


def _how_text(spec, result: FalsifyResult) -> str:
    """How the search spent its runs, for falsify's first line."""
    if spec.method == "de":
        how = f"differential evolution, {result.population} per generation x {result.generations} generations"
    elif spec.method in ("portfolio", "cma"):
        first = [e for e in result.search if e.generation == 0] if spec.method == "portfolio" else []
        kind = ("all vertices" if len(first) == 2 ** len(spec.names) else
                "a fractional-factorial covering of the vertices")
        cma = (f"CMA-ES from the box's centre ({len(result.search) - len(first)} runs, {result.population} per "
               "generation)")
        if first:
            cma = _portfolio_phases_text(spec, first, int(result.population or 0))  # CMA-ES: always set
        how = f"{kind} ({len(first)} runs), then {cma}" if first else cma
    else:
        first = [e for e in result.search if e.generation == 0]
        kind = ("a Latin hypercube" if spec.method == "lhs-polish" else "all vertices"
                if len(first) == 2 ** len(spec.names) else "a fractional-factorial covering of the vertices")
        how = (f"{kind} ({len(first)} runs), then Nelder-Mead from the worst ({len(result.search) - len(first)} runs)")
    return how


def exit_status(summary: dict) -> int:
    """falsify's exit status from its JSON: 1 when the serial re-run did not reproduce the worst run (its
    numbers cannot be trusted), else CLAIM_BROKEN_EXIT when it falsified (a claim broken or the
    requirement falsified), else 0."""
    if not summary["reproduced"]:
        return 1
    return CLAIM_BROKEN_EXIT if summary["falsified"] else 0


def claim_lines(result: FalsifyResult) -> list[str]:
    """Beside the verdict: the banner and the run that broke the claim (where one did), and the worst
    run's unmet assumptions (name, value vs limit)."""
    lines = []
    broken = result.claim_broken
    if broken is not None:
        where = (f"{broken.count} run(s) break the claim; the worst, {broken.phase} run {broken.run} "
                 f"(sup|E| = {broken.sup_E:.6g} rad, {broken.ratio:.3g} times E_max = {broken.E_max:.4g} rad)")
        lines += [certified_outside_banner(where),
                  "broken by: " + ", ".join(f"{k} = {v!r}" for k, v in broken.params.items())]
    unmet = result.worst.unmet
    if unmet:
        lines.append(f"worst run {result.worst.verdict}: assumptions not met: "
                     f"{format_unmet(a.to_dict() for a in unmet)}")
    return lines


def _table(result) -> str:
    """evaluations.csv: every run of both phases, each parameter as its run used it (a hardware axis rounded as
    the run had it), numbers to 12 significant digits (falsify.json keeps every bit)."""
    names = list(result.spec.names)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["phase", "index", "generation", *names, "objective", "sup_E", "sup_Edot", "verdict"])
    for e in (*result.search, *result.random):
        w.writerow([e.phase, e.index, e.generation, *(csv_number(e.params[n]) for n in names),
                    "" if e.objective is None else csv_number(e.objective), csv_number(e.sup_E),
                    csv_number(e.sup_Edot), e.verdict])
    return buf.getvalue()
