"""The headline validation (``wmr-mj validate``): the answer first, every number from this run.

:func:`run_validate` runs one function per stage, in this order, into one folder:

1. :func:`identify_stage`: identify the plant at the nominal m1 (identified.json);
2. :func:`friction_stage`: the steering joint's measured friction law, stiction and soft
   (``wmr_mj.plant.friction.measure_friction_law``);
3. :func:`ladder_stage`: for each rung of :data:`wmr_mj.sim.designs.LADDER` (the paper's design,
   then one change per rung up to the certified design) a sweep of n runs over m1
   (``run_sweep``, atomic and resumable in ladder-<k>-<name>/), judged by the separated
   verdicts (:mod:`wmr_mj.analysis.verdicts`) and summarised from its runs.csv (:func:`summarise_rung`);
4. :func:`wmr_mj.report.search.search_stage`: the worst-case search (falsify's portfolio: the
   vertices, then CMA-ES on whole generations) for the paper's design against the paper's claim and for the
   certified design against its certificate over the m1 box, beside the Monte-Carlo worst
   of the same rung; and for the certified design over the 'full' uncertainty box;
5. :func:`nominal_stage`: the paper's and the certified design at m1 = 650 kg (time histories);
5b. :func:`wmr_mj.report.sensing.sensing_stage`: the certified design at the top of the m1 box on exact
   sensing and on realistic encoders (verdict, voltage activity, dead band; summary.json's ``sensing``);
5c. :func:`wmr_mj.report.cart_design.cart_design_stage`: the design ``wmr-mj design`` finds for the 12-bit axis
   encoder, and it and the certified design swept on that cart over the same m1 draws (summary.json's
   ``cart_design``);
6. :func:`wmr_mj.report.figures.figures_stage`: PNG + SVG in figures/;
7. :func:`write_report`: summary.json, summary.csv, index.md, index.html (atomic), rendered
   by :mod:`wmr_mj.report.text`, which opens with the answer.

A resumed folder reports exactly like a fresh one: every count is recomputed from the
rung's runs.csv, and a search whose search.json matches its spec is read back.

Usage::

    from wmr_mj.report.validate import ValidateSettings, run_validate
    from wmr_mj.report.text import format_headline
    summary = run_validate(ValidateSettings(n=8, search_budget=10), "logs/my-validate")
    print(format_headline(summary))
    summary.ladder[-1].passes, summary.ladder[-1].n  # read by attribute (summary.json: summary.to_dict())
"""

from __future__ import annotations

import dataclasses
import os
import re
import shutil
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from wmr_mj._util.checks import as_pair
from wmr_mj._util.files import software_versions, write_json_atomic, write_text_atomic
from wmr_mj._util.progress import Stages
from wmr_mj.experiments.compare import FileDesign, is_design_file
from wmr_mj.experiments.sweep import SweepSpec, SweepSummary, read_runs, run_sweep
from wmr_mj.params import with_params
from wmr_mj.plant.friction import measure_friction_law
from wmr_mj.plant.identify import identify_plant
from wmr_mj.plant.mjcf import STEERING_FRICTION_MODELS
from wmr_mj.reference.route import path_name
from wmr_mj.report.cart_design import cart_design_stage
from wmr_mj.report.figures import figures_stage
from wmr_mj.report.results import CertifiedRule, PathSummary, Rung, ValidateSummary
from wmr_mj.report.search import search_stage
from wmr_mj.report.sensing import sensing_stage
from wmr_mj.report.settings import (
    LADDER_GROUPS,
    ValidateSettings,
    certificate_summary,
    loud,
    reference_of,
    stage_progress,
)
from wmr_mj.report.text import findings, render_html, render_markdown, summary_csv
from wmr_mj.sim import designs
from wmr_mj.sim.closed_loop import run_closed_loop, run_parts
from wmr_mj.sim.designs import CERTIFIED, CORRECTION_RUNG, LADDER, PAPER, DesignLike, DesignPreset, TokenDesign
from wmr_mj.sim.parts import resolve_run

__all__ = [
    "ValidateSettings",  # defined in wmr_mj.report.settings, with the defaults; here beside run_validate
    "ladder_changes",
    "summarise_rung",
    "certificate_summary",
    "identify_stage",
    "friction_stage",
    "ladder_stage",
    "nominal_stage",
    "write_report",
    "run_validate",
    "write_pointer",
    "software_versions",
]

# --------------------------------------------------------------------------- summaries
def summarise_rung(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The numbers of one rung from its runs (rows of runs.csv, ``sweep.read_results``).

    :meth:`wmr_mj.experiments.sweep.SweepSummary.rung_dict` of the sweep's one aggregator: verdicts
    (a count for each of the four), passes, certified_outside, paper_inside (runs inside the
    paper's claim), the worst sup|E| [rad] (and its m1 [kg]), sup|E'| [rad/s], sup|E|/E_max of
    the certificate and of the paper's claim (and their m1), hit_stop (runs that reached the
    steering stop), growing (runs whose |E| still grows), mean_saturated_fraction, m1_min, m1_max.

    Raises:
        ParameterError: no rows.
    """
    return SweepSummary.of(rows).rung_dict()


def ladder_changes(before: DesignLike, after: DesignLike) -> list[str]:
    """The groups of :data:`LADDER_GROUPS` in which ``after`` differs from ``before``."""
    a, b = before.config_changes(), after.config_changes()
    return [group for group, fields in LADDER_GROUPS.items() if any(a[f] != b[f] for f in fields)]


def _change_text(before: DesignLike, after: DesignLike) -> str:
    a, b = before.config_changes(), after.config_changes()
    parts = []
    for group in ladder_changes(before, after):
        fields = [f for f in LADDER_GROUPS[group] if a[f] != b[f]]
        named = len(LADDER_GROUPS[group]) > 1  # name the field where the group has several
        parts.append(f"{group}: " + ", ".join((f"{f} " if named else "") + (
            f"{a[f]:g} -> {b[f]:g}" if isinstance(a[f], float) else f"{a[f]} -> {b[f]}") for f in fields))
    return "; ".join(parts)


def _paper_region(parts: Any) -> dict[str, Any]:
    """The paper's claim for a resolved run (:class:`wmr_mj.sim.parts.RunParts`): the region (4.21)-(4.23)
    its runs are judged by."""
    d = parts.analysis.to_dict()
    return {k: d[k] for k in ("E_max", "Edot_max", "condition", "stable", "vertices")}


# --------------------------------------------------------------------------- stages 1-2
def identify_stage(settings: ValidateSettings, folder: Path, st: Stages) -> dict[str, Any]:
    """Identify the plant at the nominal m1; writes identified.json; its ``to_dict`` and verdict."""
    st.start("identify", f"identify the plant (m1 = {settings.nominal_m1:g} kg, {settings.identify_duration:g} s "
                         "excitation)")
    ident = identify_plant(with_params(settings.base, m1=settings.nominal_m1), duration=settings.identify_duration,
                           seed=settings.seed)
    out = ident.to_dict()
    write_json_atomic(folder / "identified.json", out)
    out["verdict"] = ident.verdict()
    st.done(f"K = {ident.identified.K:.3g} V, gyro = {ident.identified.gyro:.3g} V s/m, "
            f"{ident.diagnostics['samples']} samples")
    return out


def friction_stage(settings: ValidateSettings, st: Stages) -> dict[str, dict[str, Any]]:
    """The steering joint's measured friction law for each of :data:`STEERING_FRICTION_MODELS`."""
    st.start("friction", "the steering joint's friction law (stiction, soft): constant voltages")
    plant = with_params(settings.base, m1=settings.nominal_m1)
    laws = {name: measure_friction_law(plant, steering_friction=name).to_dict() for name in STEERING_FRICTION_MODELS}
    st.done(", ".join(f"{name}: break-away {law['breakaway_voltage']:.3g} V, "
                      f"{'holds' if law['holds'] else 'creeps'} below it" for name, law in laws.items()))
    return laws


# --------------------------------------------------------------------------- stage 3: the ladder
def run_rung(settings: ValidateSettings, k: int, design: DesignLike, folder: Path, st: Stages,
             before: DesignPreset | None, *, parts: Any = None) -> dict[str, Any]:
    """Sweep one rung over m1 (resumable in ladder-<k>-<name>/) and summarise it; its certificate and the
    paper's region are the base run's (``settings.config(design)``), resolved once: ``parts``
    (:func:`wmr_mj.sim.parts.resolve_run`), resolved here where None."""
    base = settings.config(design)
    parts = resolve_run(base) if parts is None else parts
    spec = SweepSpec(n=settings.n, seed=settings.seed, sampling=settings.sampling,
                     m1_range=as_pair(settings.m1_range), ranges=settings.ranges, base=base)
    sweep_dir = folder / f"ladder-{k}-{design.name}"
    st.start(f"ladder-{k}", f"rung {k} ({design.label}): {settings.n} runs of {settings.duration:g} s over m1 "
                            f"{settings.m1_range[0]:g}-{settings.m1_range[1]:g} kg ({settings.sampling})")
    run_sweep(spec, out_dir=sweep_dir, nthread=settings.nthread, progress=stage_progress(st))
    rung = summarise_rung(read_runs(sweep_dir))  # full precision: runs.csv is rounded
    if isinstance(design, DesignPreset) and (base.kp, base.kd) != (design.kp, design.kd):
        design = dataclasses.replace(design, kp=base.kp, kd=base.kd)  # the gains it ran: the rule's on the cart
    rung.update(index=k, name=design.name, label=design.label, design=design.describe(),
                config=design.config_changes(), changed=[] if before is None else ladder_changes(before, design),
                change="" if before is None else _change_text(before, design),
                certificate=certificate_summary(parts.claim),
                paper_region=_paper_region(parts),
                runs_csv=(sweep_dir / "runs.csv").relative_to(folder).as_posix())
    paper = ("" if rung["paper_inside"] is None
             else f", {rung['paper_inside']}/{rung['n']} inside the paper's claim")
    st.done(f"{rung['passes']}/{rung['n']} certified-inside{paper}" + loud(rung["certified_outside"], f"rung {k}"))
    return rung


def ladder_stage(settings: ValidateSettings, folder: Path, st: Stages) -> list[dict[str, Any]]:
    """Every rung of :data:`LADDER`, in order (see :func:`run_rung`)."""
    rungs = []
    for k, design in enumerate(LADDER, start=1):
        rungs.append(run_rung(settings, k, design, folder, st, LADDER[k - 2] if k > 1 else None))
    return rungs


def correction_stage(settings: ValidateSettings, folder: Path, st: Stages) -> dict[str, Any]:
    """The rung after the ladder: the certified design with the Cartesian correction at C
    (:data:`wmr_mj.sim.designs.CORRECTION_RUNG`; summary.json's ``correction_rung``)."""
    rung = run_rung(settings, len(LADDER) + 1, CORRECTION_RUNG, folder, st, CERTIFIED)
    rung.update(changed=["correction"], change="Cartesian correction at C (outer loop on alpha0, "
                                              "controllers/tracking.py)")
    return rung


def designs_stage(settings: ValidateSettings, folder: Path, st: Stages, *, first_index: int) -> list[dict[str, Any]]:
    """``validate --design TOKEN``: each design of the user's (a plug-in law, a tracker, other gains; a token
    as ``wmr-mj compare`` takes it, a design file ``FILE.json`` among them) judged beside the ladder: its rung
    (:func:`run_rung`: the same m1 sweep, its verdicts against its own claim) and its nominal run
    (summary.json's ``designs``)."""
    out = []
    for k, token in enumerate(settings.designs, start=first_index):
        design: DesignLike = FileDesign(token, settings.cart) if is_design_file(token) else TokenDesign(token)
        parts = resolve_run(settings.config(design))  # the rung's claim and its nominal run: one resolution
        rung = run_rung(settings, k, design, folder, st, None, parts=parts)
        st.start(f"design-{k}", f"nominal run of {token} at m1 = {settings.nominal_m1:g} kg")
        nominal = run_parts(parts, progress=False)
        st.done(f"sup|E| = {nominal.summary.sup_E:.3g} rad, {nominal.summary.verdict}")
        law = "no-claim: judged by requirements only" if nominal.summary.verdict == "no-claim" else ""
        rung.update(token=token, change="a design of the user's (validate --design)" + (f"; {law}" if law else ""),
                    nominal=_nominal_summary(nominal), paper_law=nominal.summary.paper_law)
        out.append(rung)
    return out


# --------------------------------------------------------------------------- stage 5: nominal runs
def nominal_stage(settings: ValidateSettings, st: Stages) -> dict[str, Any]:
    """The paper's and the certified design at the nominal m1: {name: RunResult}."""
    st.start("nominal", f"nominal runs at m1 = {settings.nominal_m1:g} kg (paper's and certified design)")
    runs = {d.name: run_closed_loop(settings.config(d), progress=False) for d in (PAPER, CERTIFIED)}
    st.done(", ".join(f"{name}: sup|E| = {r.summary.sup_E:.3g} rad, {r.summary.verdict}"
                      for name, r in runs.items()))
    return runs


def _nominal_summary(run) -> dict[str, Any]:
    """The report's JSON of one nominal run (keys of its summary, the certificate's ratio, the drift)."""
    s = run.summary
    return {"m1": s.m1, "sup_E": s.sup_E, "sup_Edot": s.sup_Edot, "settle_s": s.settle_s,
            "sup_E_settled": s.sup_E_settled, "verdict": s.verdict, "inside": s.inside, "E_ratio": s.E_ratio,
            "left_steering_range_at_s": s.left_steering_range_at_s, "final_alpha": s.final_alpha,
            "saturated_fraction": s.saturated_fraction,
            "certificate_E_ratio": None if s.certificate is None else s.certificate.E_ratio,
            "cross_track_max": None if s.path_error is None else s.path_error.cross_track_max,
            "drift": None if s.drift is None else s.drift.to_dict()}


# --------------------------------------------------------------------------- stage 7: the report
def write_report(summary: ValidateSummary | Mapping[str, Any], folder: Path) -> None:
    """summary.csv, index.md, index.html and summary.json (last, ``summary.to_dict()``), each written atomically
    (``summary``: the summary, or its JSON read back)."""
    summary = ValidateSummary.of(summary)
    write_text_atomic(folder / "summary.csv", summary_csv(summary))
    write_text_atomic(folder / "index.md", render_markdown(summary))
    write_text_atomic(folder / "index.html", render_html(summary))
    write_json_atomic(folder / "summary.json", summary.to_dict())


def write_pointer(folder: str | os.PathLike) -> Path:
    """Point ``<parent>/validate-latest`` at the report ``folder``: a relative symlink, replaced
    atomically (a temporary link, then ``os.replace``). Where symlinks are unavailable (``os.symlink``
    raises OSError) it is a folder holding a copy of the report instead. Either way
    ``validate-latest/summary.json`` reads the latest report."""
    folder = Path(folder)
    link = folder.parent / "validate-latest"
    tmp = folder.parent / f".validate-latest.{os.getpid()}.tmp"
    _remove(tmp)
    try:
        os.symlink(os.path.relpath(folder.resolve(), link.parent.resolve()), tmp, target_is_directory=True)
    except OSError:  # no symlinks here (Windows without the privilege, some file systems): a copy
        shutil.copytree(folder, tmp, symlinks=True)
    old = folder.parent / f".validate-latest.{os.getpid()}.old"
    if link.is_dir() and not link.is_symlink():  # a copy from before: os.replace cannot replace a folder
        _remove(old)
        os.replace(link, old)
    elif tmp.is_dir() and not tmp.is_symlink() and (link.is_symlink() or link.exists()):
        link.unlink()  # a folder cannot replace a link or a file (nor the text pointer of old versions)
    os.replace(tmp, link)
    _remove(old)
    return link


def _remove(path: Path) -> None:
    if path.is_symlink() or path.is_file():
        path.unlink()
    elif path.is_dir():
        shutil.rmtree(path)


def _path_summary(settings: ValidateSettings) -> PathSummary:
    """The runs' path of C: its name and, on the paper circle, the circle's radius [m] from the
    reference's final curvature (the verdict's 'its 1 m circle')."""
    import numpy as np

    radius = None
    if settings.path == "paper-circle":
        kappa = float(np.asarray(reference_of(settings).kappa)[-1])
        radius = 1.0 / abs(kappa) if kappa else None
    return PathSummary(name=settings.path, circle_radius=radius)


def _certified_rule(settings: ValidateSettings) -> CertifiedRule:
    """The certified design's rule as designs.py writes it (its C80 box, path and wheelbase replaced by the cart's
    where the report is of another cart), and the omega_r it gives now on the cart."""
    cart = settings.cart
    doc = designs.__doc__ or ""
    rule = " ".join(re.sub(r":\w+:`([^`]*)`", r"\1", doc.split("``certified``:", 1)[-1].split("The ladder", 1)[0])
                    .replace("``", "").split())
    if cart is not None:  # the rule run on this cart: its box, path and wheelbase, not the C80's
        l1 = settings.base.l1
        lo, hi = settings.m1_range
        for c80, own in ((designs.RULE_C80_BOX, f"{lo:g}-{hi:g} kg, {path_name(settings.path)}"),
                         (designs.RULE_C80_OFFSET, f"about {designs.ERROR_SPEC * l1 * 100:.2g} cm of lateral offset of "
                                                   f"C at this cart's {l1:g} m wheelbase")):
            assert c80 in rule, c80  # designs.py's docstring holds the C80's words the rule is written with
            rule = rule.replace(c80, own)
    return CertifiedRule(text=rule, error_spec=designs.ERROR_SPEC,
                         omega_r_grid_step=designs.OMEGA_R_GRID[1] - designs.OMEGA_R_GRID[0],
                         omega_r_rule=designs.certified_omega_r(cart=cart),
                         omega_r_design=designs.certified_design(cart).kd)


def run_validate(settings: ValidateSettings, out_dir: str | os.PathLike, *, log: bool = True,
                 stream=None, tty: bool | None = None) -> ValidateSummary:
    """Run the validation into ``out_dir`` (created; sweeps and searches resume there).

    Returns the summary, read by attribute (summary.json is its ``to_dict()``). Stage lines go to ``stream`` (default
    stderr) when ``log``; ``tty`` forces or suppresses the live counter.
    """
    wall0 = time.perf_counter()
    folder = Path(out_dir)
    folder.mkdir(parents=True, exist_ok=True)
    st = Stages("validate", stream=stream, enabled=log, tty=tty)
    identification = identify_stage(settings, folder, st)
    friction = friction_stage(settings, st)
    # the stages build each rung's JSON (run_rung); the summary holds them typed, read by attribute
    ladder = ladder_stage(settings, folder, st)
    rungs = [Rung.from_dict(r) for r in ladder]
    corrected = Rung.from_dict(correction_stage(settings, folder, st))
    designs = [Rung.from_dict(r) for r in designs_stage(settings, folder, st, first_index=len(LADDER) + 2)]
    searches = search_stage(settings, folder, st, ladder)  # the search stage reads the rungs' JSON
    nominal = nominal_stage(settings, st)
    sensing = sensing_stage(settings, st)
    cart_design = cart_design_stage(settings, folder, st)
    figures, fig7 = figures_stage(settings, folder, st, rungs, searches, nominal)
    st.start("report", "summary.json, summary.csv, index.md, index.html")
    summary = ValidateSummary(
        folder=str(folder), created=time.strftime("%Y-%m-%d %H:%M:%S %z"), settings=settings.to_dict(),
        seed=settings.seed, ladder=tuple(rungs), certified_rule=_certified_rule(settings),
        searches=tuple(searches),
        nominal={name: _nominal_summary(run) for name, run in nominal.items()}, friction=friction,
        identification=identification, paper_example=fig7, figures=figures,
        correction_rung=corrected, path=_path_summary(settings), designs=tuple(designs),
        certified_outside=sum(r.certified_outside for r in [*rungs, *designs]) + corrected.certified_outside
        + sum(s["verdicts"]["certified-outside"] for s in searches) + sensing["certified_outside"]
        + cart_design.certified_outside,
        sensing=sensing, cart_design=cart_design, versions=software_versions())
    summary = dataclasses.replace(summary, findings=tuple(findings(summary)))
    summary = dataclasses.replace(summary, timings_s=dict(st.timings), wall_s=time.perf_counter() - wall0)
    write_report(summary, folder)
    st.done()
    return summary
