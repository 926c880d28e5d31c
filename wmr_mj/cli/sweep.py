"""``wmr-mj sweep``: N closed-loop runs with m1 (and other parameters) drawn over their ranges."""

from __future__ import annotations

import argparse
import functools
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from wmr_mj._util.files import check_output_path, write_json_atomic
from wmr_mj._util.progress import counter_callback, progress_bar
from wmr_mj.analysis.verdicts import (
    PAPER_CLAIM_NOT_APPLICABLE,
    certified_outside_banner,
    format_unmet,
)
from wmr_mj.cli._common import CLAIM_BROKEN_EXIT, print_json
from wmr_mj.cli.ranges import box_ranges_from_args, hardware_ranges_from_args
from wmr_mj.cli.run import config_from_args, requirements_from_args
from wmr_mj.errors import ParameterError
from wmr_mj.experiments.sweep import SweepSpec
from wmr_mj.experiments.sweep_result import sweep
from wmr_mj.figures.plots import save_figure
from wmr_mj.figures.results import figure_sweep_region
from wmr_mj.hardware import cart_line, is_ideal_cart
from wmr_mj.logs.writer import RunLogger
from wmr_mj.params import M1_RANGE
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.config import estimate_of
from wmr_mj.sim.engine import law_path
from wmr_mj.sim.parts import resolve_run

if TYPE_CHECKING:
    from wmr_mj.experiments.sweep import SweepSummary


def fixed_m1_from_args(args: argparse.Namespace) -> float | None:
    """The fixed m1 [kg] of sweep's or falsify's options, None where m1 is drawn or searched: --m1 KG, or a
    zero-width --m1-range KG KG, which then gives the certificate's box back its default range (a box of one
    mass is no box: :class:`wmr_mj.sim.config.RunConfig` refuses it), rewriting ``args.m1_range``.

    Raises:
        ParameterError: a zero-width range outside the default box, or one that differs from --m1.
    """
    fixed = getattr(args, "m1", None)
    lo, hi = (float(v) for v in args.m1_range)
    if lo != hi:
        return fixed
    if fixed is not None and fixed != lo:
        raise ParameterError(f"--m1 {fixed:g} and --m1-range {lo:g} {hi:g} fix two masses; give one")
    if not M1_RANGE[0] <= lo <= M1_RANGE[1]:
        raise ParameterError(f"--m1-range {lo:g} {hi:g} fixes m1 at {lo:g} kg, outside the certificate's default "
                             f"box {M1_RANGE[0]:g}-{M1_RANGE[1]:g} kg: give --m1 {lo:g} with --m1-range LO HI "
                             "around it")
    args.m1_range = list(M1_RANGE)
    return lo


def _spec_from_args(args: argparse.Namespace) -> tuple[Any, Any]:
    """The sweep of the options, and its base's resolved parts (what the runs would raise, a law's claim() that
    raises, is one line here, before any output)."""
    if args.n < 1:
        raise ParameterError(f"--n {args.n} is not accepted; the number of runs must be >= 1")
    fixed_m1 = fixed_m1_from_args(args)  # --m1 or a zero-width --m1-range: m1 not drawn
    # --uncertainty (default m1), then --range: the plant's, then the cart's axes (drawn, not in the box)
    ranges = {**box_ranges_from_args(args), **hardware_ranges_from_args(args)}
    base = config_from_args(args)
    base_parts = resolve_run(base)
    requirements = tuple(r.text for r in requirements_from_args(args, args.control_period or TIMESTEP))
    spec = SweepSpec(n=args.n, seed=args.seed, sampling=args.sampling, m1_range=tuple(args.m1_range),
                     ranges=ranges, base=base, requirements=requirements, m1=fixed_m1)
    return spec, base_parts


def _log_runs(spec: Any, rows: Any, logs_dir: Path) -> None:
    """--log: each run again with its MCAP log, ``run-NNNNN.mcap`` in ``logs_dir``."""
    for r in rows:
        cfg = spec.config_at([r[k] for k in spec.names])
        run_closed_loop(cfg, logger_factory=functools.partial(RunLogger, logs_dir / f"run-{r['run']:05d}.mcap"),
                        progress=False)


def run(args: argparse.Namespace) -> int:
    out = check_output_path(args.out or f"logs/sweep-{time.strftime('%Y%m%d-%H%M%S')}", kind="dir", option="--out")
    spec, base_parts = _spec_from_args(args)
    with progress_bar(spec.n, desc="sweep", unit="runs", fractional=True) as bar:
        result = sweep(spec, out_dir=out, chunk=args.chunk, nthread=args.nthread, scheduler=args.scheduler,
                       progress=counter_callback(bar))
    runs = result.summary  # the one aggregator of sweep and validate
    summary = result.to_dict(runs=False)  # and the keys the command adds: its figure, its logs
    plot_path = _plot(result, out / "region")
    summary["plot"] = str(plot_path)
    if args.log:
        _log_runs(spec, result.rows, out / "mcap")
        summary["mcap_dir"] = str(out / "mcap")
    write_json_atomic(out / "summary.json", summary)
    status = CLAIM_BROKEN_EXIT if runs.claim_broken is not None else 0
    if args.json:
        print_json(summary)
    else:
        _print_text(spec, runs, base_parts.controller, summary, result.wall_s)
        print(f"table: {out / 'runs.csv'}\nplot:  {plot_path}")
    return status


def _print_text(spec: Any, runs: SweepSummary, law: Any, summary: dict[str, Any], wall: float) -> None:
    """The sweep's report as text (``--json`` prints ``summary`` instead)."""
    fmt = lambda x: "n/a" if x is None else f"{x:.3f}"  # noqa: E731
    base = spec.base
    m1_text = (f"m1 fixed at {spec.m1:g} kg" if spec.m1 is not None
               else f"m1 over {spec.m1_range[0]:g}-{spec.m1_range[1]:g} kg")
    print(f"{runs.n} runs ({law.label()}, {m1_text}, {spec.sampling}, seed {spec.seed}):")
    if not is_ideal_cart(base) or spec.hardware_names:
        drawn = f" (drawn per run: {', '.join(spec.hardware_names)})" if spec.hardware_names else ""
        print(cart_line(base) + drawn)
    print("verdicts: " + ", ".join(f"{v} {c}" for v, c in runs.verdicts.items()))
    print("\n".join(claim_lines(runs)))
    print(f"certificate: worst sup|E|/E_max = {fmt(runs.certificate_E_ratio.value)}, "
          f"worst sup|E'|/Edot_max = {fmt(runs.certificate_Edot_ratio.value)}; "
          f"{runs.growing} runs with |E| still growing at the end")
    if base.cart is not None:
        pass  # the paper's claim is made for its C80 only: not printed on another cart (--json keeps its numbers)
    elif estimate_of(law) is None or runs.paper_inside is None:
        print(f"paper's claim: {PAPER_CLAIM_NOT_APPLICABLE}")
    else:
        print(f"paper's claim: {runs.paper_inside} inside, {runs.n - runs.paper_inside} outside its region; "
              f"worst sup|E|/E_max = {fmt(runs.paper_E_ratio.value)}, "
              f"worst sup|E'|/Edot_max = {fmt(runs.paper_Edot_ratio.value)}")
    print(f"{runs.hit_stop} runs hit the steering stop")
    print("\n".join(effort_lines(runs)))
    if runs.path_verdicts is not None:
        print(f"path of C: worst sup|cross-track| = {runs.path_cross_track.value:.4g} m "
              f"(m1 = {runs.path_cross_track.m1:g} kg); path verdicts: "
              + ", ".join(f"{v} {c}" for v, c in runs.path_verdicts.items()))
    for req in runs.requirements:
        least = ("n/a" if req.min_robustness is None
                 else f"{req.min_robustness:+.5g} (run {req.run}, m1 = {req.m1:g} kg)")
        print(f"requirement {req.requirement}: {req.satisfied} hold, {req.violated} violated"
              + (f", {req.undefined} without a region" if req.undefined else "") + f"; least robustness {least}")
    backend = f"; the law ran {' and '.join(law_path(b) for b in runs.batch_law)}" if runs.batch_law else ""
    print(f"{runs.steps} steps in {wall:.1f} s ({summary['steps_per_s']:.3g} steps/s{backend})")


def effort_lines(runs: SweepSummary) -> list[str]:
    """What the runs asked of the motor: saturation, peak voltage and voltage activity, overall and per level
    of each ranged axis that has levels; nothing where the rows have no effort (a runs.csv written before)."""
    e = runs.effort
    if e is None:
        return []

    def text(x) -> str:
        return (f"saturated {100 * x.mean_saturated_fraction:.3g}% of the time "
                f"(at most {100 * x.max_saturated_fraction:.3g}%), "
                f"peak |u| {x.peak_voltage:.4g} V, RMS u {x.mean_rms_voltage:.4g} V, activity "
                f"{x.mean_tv_voltage:.4g} V/s (at most {x.max_tv_voltage:.4g})")

    lines = [f"effort: {text(e)}"]
    for axis in runs.effort_by_level:
        lines += [f"  {axis.axis} = {lv.value:g} ({lv.effort.runs} runs): {text(lv.effort)}" for lv in axis.levels]
    return lines


def claim_lines(runs: SweepSummary) -> list[str]:
    """Beside the verdicts: the banner and the run that broke the claim (where one did), and the claim's
    unmet assumptions (name, value vs limit, in how many runs)."""
    lines = []
    b = runs.claim_broken
    if b is not None:
        lines += [certified_outside_banner(
            f"{b.count} of {runs.n} run(s) break the claim; the worst, run {b.run} (sup|E| = "
            f"{b.sup_E:.6g} rad, {b.ratio:.3g} times E_max = {b.E_max:.4g} rad; see runs.csv)"),
            "broken by: " + ", ".join(f"{k} = {v!r}" for k, v in b.params.items())]
    if runs.unmet:
        lines.append("assumptions not met: " + "; ".join(f"{format_unmet([a.to_dict()])} in {a.runs}/{runs.n} runs"
                                                         for a in runs.unmet))
    return lines


def _plot(result: Any, stem: Path) -> Path:
    """:func:`region_figure` of the sweep's ``result`` written as ``<stem>.png``."""
    (path,) = save_figure(region_figure(result), stem, formats=("png",))
    return path


def region_figure(result: Any):
    """Fig.-7-style plot of a sweep's ``result`` (:class:`wmr_mj.experiments.sweep_result.SweepResult`):
    :func:`wmr_mj.figures.results.figure_sweep_region`, its region named as the paper's claim on the C80 only."""
    return figure_sweep_region(result, on_c80=coerced(result.spec.base).cart is None)
