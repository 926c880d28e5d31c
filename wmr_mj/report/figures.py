"""Stage 6 of ``wmr-mj validate``: every figure of the report, PNG + SVG, in figures/.

- ``ladder``: the verdict counts of each rung (:func:`wmr_mj.figures.plots.figure_ladder`);
- ``rung_<k>_<name>``: every run of rung k at (sup|E|, sup|E'|) by verdict, with the
  certificate's region (when it exists) and the paper's claim
  (:func:`wmr_mj.figures.plots.figure_verdict_plane`);
- ``history_paper``, ``history_certified``: the nominal runs' E, E', voltage against the
  certificate's bounds, or the paper's claim where there is no certificate;
- ``search_history``: each search's runs, its running worst, the Monte-Carlo worst;
- the paper's Figs. 4-7 (:func:`wmr_mj.figures.plots.paper_figures`): Fig. 4 with the paths C
  travelled in the nominal runs (the paper's and the certified design, :func:`travelled_paths`),
  Fig. 7 with the paper's design on the MuJoCo plant at m1 = 650 kg.

Usage::

    paths, fig7 = figures_stage(settings, folder, stages, rungs, searches, nominal)
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from wmr_mj._util.progress import Stages
from wmr_mj.analysis.verdicts import paper_region_name
from wmr_mj.experiments.sweep import read_runs
from wmr_mj.figures import plots
from wmr_mj.report.paper_example import paper_example
from wmr_mj.report.results import Rung
from wmr_mj.report.settings import ValidateSettings
from wmr_mj.sim.config import plant_parameters

__all__ = ["figures_stage", "travelled_paths"]


def _rung_figure(rung: Rung, folder: Path, claim: str):
    rows = read_runs((folder / rung.runs_csv).parent)
    cert, paper = rung.certificate, rung.paper_region
    regions = [plots.DrawnRegion(f"certificate: |E| <= {cert['E_max']:.3g} rad, |E'| <= {cert['Edot_max']:.3g} rad/s",
                            [tuple(v) for v in cert["vertices"]], gid=plots.CERTIFICATE_GID)] if cert["valid"] else []
    if paper["vertices"]:
        regions.append(plots.DrawnRegion(f"{claim.removeprefix('the ')}: |E| <= {paper['E_max']:.3g} rad, |E'| <= "
                                    f"{paper['Edot_max']:.3g} rad/s", [tuple(v) for v in paper["vertices"]],
                                    color=plots.PAPER_CLAIM_COLOR, filled=False, gid=plots.REGION_GID))
    note = None if cert["valid"] else "no certificate:\n" + _wrap(cert["reason"] or ", ".join(cert["unmet"]), 48)
    return plots.figure_verdict_plane([r["sup_E"] for r in rows], [r["sup_Edot"] for r in rows],
                                      [r["verdict"] for r in rows], regions, note=note,
                                      title=f"rung {rung.index}: {rung.design}")


def _wrap(text: str, width: int) -> str:
    return "\n".join(textwrap.wrap(text, width))


def _history_figures(nominal: Mapping[str, Any], claim: str) -> dict[str, Any]:
    figs = {}
    for name, run in nominal.items():
        s = run.summary
        if s.certificate is not None and s.certificate.certified:
            bounds, whose = (s.certificate.E_max, s.certificate.Edot_max), "certificate"
        else:
            bounds, whose = (s.E_max, s.Edot_max), claim.removeprefix("the ")
        figs[f"history_{name}"] = plots.figure_time_history(
            run.rows, s, voltage_limit=plant_parameters(run.config).voltage_limit, bounds=bounds, bound_name=whose,
            title=f"{name} design on the MuJoCo plant, m1 = {s.m1:g} kg: {s.verdict}")
    return figs


def _search_figure(searches: Sequence[Mapping[str, Any]], rungs: Sequence[Rung]):
    histories = []
    for s in searches:
        mc = s.get("mc") or {}
        ratio = s["objective"] != "sup-E"
        histories.append(plots.SearchHistory(
            title=f"{s['design']} design, {s['box_name']} box ({len(s['box'])} parameter(s))",
            ylabel=s["objective_label"], values=s["values"], mc_worst=mc.get("worst_objective"),
            mc_label=f"Monte Carlo, rung {mc.get('rung')} ({mc.get('n')} runs)",
            bound=1.0 if ratio else rungs[-1].certificate.get("E_max"),
            bound_label="region boundary" if ratio else "E_max of the m1-box certificate"))
    return plots.figure_search_history(histories, title="worst-case search (differential evolution)")


def travelled_paths(nominal: Mapping[str, Any]) -> list[tuple[str, np.ndarray]]:
    """(label, C's xy) of the nominal runs for Fig. 4: the paths C travelled under the paper's
    and the certified design, each labelled with its largest cross-track error."""
    words = {"paper": "the paper's design", "certified": "the certified design"}
    out = []
    for name, run in nominal.items():
        if run.C_xy is None:
            continue
        s = run.summary
        cross = "" if s.path_error is None else f", cross-track max {s.path_error.cross_track_max:.3g} m"
        out.append((f"{words.get(name, name)}{cross}", np.asarray(run.C_xy)))
    return out


def figures_stage(settings: ValidateSettings, folder: Path, st: Stages, rungs: Sequence[Rung],
                  searches: Sequence[Mapping[str, Any]], nominal: Mapping[str, Any]
                  ) -> tuple[dict[str, list[str]], dict[str, Any]]:
    """Write every figure (PNG + SVG) into figures/: ({stem: [relative paths]}, Fig. 7's numbers)."""
    st.start("figures", "figures (PNG + SVG)")
    claim = paper_region_name(settings.cart is None)  # the region (4.21)-(4.23): the paper's claim on its C80 only
    figs: dict[str, Any] = {"ladder": plots.figure_ladder(
        [f"{r.index}. {r.label}" for r in rungs], [r.verdicts for r in rungs],
        [r.paper_inside for r in rungs], title=f"Verdicts per rung, {settings.n} runs over m1 each",
        claim=claim.removeprefix("the "))}
    for rung in rungs:
        figs[f"rung_{rung.index}_{rung.name}"] = _rung_figure(rung, folder, claim)
    figs.update(_history_figures(nominal, claim))
    if searches:
        figs["search_history"] = _search_figure(searches, rungs)
    example = paper_example(duration=settings.duration, mujoco=False)
    example.mujoco_rows, example.mujoco_summary = nominal["paper"].rows, nominal["paper"].summary
    example.actual_paths = travelled_paths(nominal)
    figs.update(plots.paper_figures(example))
    paths = {stem: [p.relative_to(folder).as_posix() for p in plots.save_figure(fig, folder / "figures" / stem)]
             for stem, fig in figs.items()}
    fig7 = {"condition": example.result.condition, "E_max": example.result.E_max,
            "Edot_max": example.result.Edot_max,
            "reduced": [{"case": name, "sup_E": float(np.max(np.abs(r["E"]))),
                         "sup_Edot": float(np.max(np.abs(r["E_dot"])))} for name, r in example.reduced]}
    st.done(f"{sum(len(v) for v in paths.values())} files")
    return paths, fig7
