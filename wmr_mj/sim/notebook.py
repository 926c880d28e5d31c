"""A result in a notebook: its table (``.to_pandas()``), its figure (``.plot()``) and its verdict in a few lines
(``_repr_html_``), for a run, a sweep, a search, a comparison and the validation (a design, a cart's tightness
and a cart check build theirs from :func:`records_frame` and :func:`html_lines` in their own modules).

The tables name every column once here, with its unit (:data:`ROW_UNITS` for a run's rows, :data:`RUN_COLUMNS`
for the per-run tables of a sweep and a search), as python-control's ``TimeResponseData.to_pandas`` and
PyBaMM's variables ("Terminal voltage [V]") do. pandas is imported only when a table is asked for: it is the
optional extra ``wmr-mj[notebook]``, and without it :func:`require_pandas` says in one line what to install.

The figures are drawn by :mod:`wmr_mj.figures.results` (a :class:`~wmr_mj.figures.results.ResultPlot` each),
in the layer below this one: each result's ``plot()`` imports its ``plot_<kind>`` from there.

This module is a leaf of ``wmr_mj.sim``: the results' modules import it inside their methods, so it imports
none of them (their data is handed in, read by attribute).
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from wmr_mj.analysis.verdicts import format_unmet
from wmr_mj.errors import WmrMjError

__all__ = ["NOTEBOOK_INSTALL", "require_pandas", "ROW_UNITS", "row_column", "RUN_COLUMNS", "run_column", "rows_frame",
           "runs_frame", "records_frame", "compare_frame", "validate_frame", "html_lines", "verdict_counts_text",
           "number", "run_html", "falsify_html", "compare_html", "validate_html"]

#: what to run for the tables and the notebook (pyproject's optional extra)
NOTEBOOK_INSTALL = "pip install 'wmr-mj[notebook]'"

#: a run's recorded quantity (``RunResult.rows``, ``wmr_mj.sim.engine.ROW_FIELDS`` and SENSED_ROW_FIELDS; C's
#: position) -> its unit: the one table of a run's names and units
ROW_UNITS: dict[str, str] = {
    "t": "s",
    "alpha": "rad", "alpha_dot": "rad/s",
    "alpha0": "rad", "alpha0_dot": "rad/s", "alpha0_ddot": "rad/s^2",
    "E": "rad", "E_dot": "rad/s",
    "voltage_cmd": "V", "voltage": "V", "current": "A", "steer_torque": "N m",
    "heading": "rad",
    "alpha_measured": "rad", "alpha_dot_measured": "rad/s",  # what the law read, where the run has a sensor
    "C_x": "m", "C_y": "m",  # the tracked point C (RunResult.C_xy)
    "cross_track": "m",
}

#: a per-run column (runs.csv's name, :data:`wmr_mj.sim.many_runs.RESULT_COLUMNS`) -> its name in a sweep's and a
#: search's table: the certificate's bounds and ratios prefixed ``certificate_``, the paper's claim ``paper_``
#: (runs.csv's bare ``E_max`` is the paper's, easy to plot as the certificate's), units in brackets
RUN_COLUMNS: dict[str, str] = {
    "run": "run",
    "m1": "m1 [kg]",
    "verdict": "verdict",
    "sup_E": "sup_E [rad]",
    "sup_Edot": "sup_Edot [rad/s]",
    "sup_E_settled": "sup_E_settled [rad]",
    "sup_Edot_settled": "sup_Edot_settled [rad/s]",
    "cert_valid": "certificate_valid",
    "cert_E_max": "certificate_E_max [rad]",
    "cert_Edot_max": "certificate_Edot_max [rad/s]",
    "cert_E_ratio": "certificate_E_ratio [-]",
    "cert_Edot_ratio": "certificate_Edot_ratio [-]",
    "cert_inside": "certificate_inside",
    "E_max": "paper_E_max [rad]",
    "Edot_max": "paper_Edot_max [rad/s]",
    "E_ratio": "paper_E_ratio [-]",
    "Edot_ratio": "paper_Edot_ratio [-]",
    "inside": "paper_inside",
    "saturated_fraction": "saturated_fraction [-]",
    "left_steering_range": "left_steering_range",
    "final_alpha": "final_alpha [rad]",
    "final_alpha_dot": "final_alpha_dot [rad/s]",
    "drift_growing": "drift_growing",
    "path_cross_track_max": "path_cross_track_max [m]",
    "path_along_track_final": "path_along_track_final [m]",
    "path_heading_error_max": "path_heading_error_max [rad]",
    "path_verdict": "path_verdict",
    "path_cross_track_bound": "path_cross_track_bound [m]",
}


def require_pandas() -> Any:
    """pandas, or one line saying what to install.

    Raises:
        WmrMjError: pandas is not installed.
    """
    try:
        import pandas
    except ImportError:
        raise WmrMjError(f"a table needs pandas, which is not installed: {NOTEBOOK_INSTALL}") from None
    return pandas


def row_column(name: str) -> str:
    """A run's row name with its unit, ``E [rad]`` (:data:`ROW_UNITS`); a name without a unit there as it is."""
    unit = ROW_UNITS.get(name)
    return name if unit is None else f"{name} [{unit}]"


def run_column(name: str, units: Mapping[str, str] | None = None) -> str:
    """A per-run column's name in a table: :data:`RUN_COLUMNS`, else a ranged parameter with its unit from
    ``units`` (``sensing.delay [s]``), else the name as it is."""
    if name in RUN_COLUMNS:
        return RUN_COLUMNS[name]
    unit = (units or {}).get(name)
    return name if not unit else f"{name} [{unit}]"


def rows_frame(rows: Mapping[str, np.ndarray], C_xy: np.ndarray | None = None) -> Any:
    """A run's rows as a wide DataFrame: one row per control step, every recorded quantity a column named
    with its unit (:func:`row_column`), C's x and y where the run recorded them (``C_x [m]``, ``C_y [m]``)."""
    pandas = require_pandas()
    columns: dict[str, np.ndarray] = {row_column(k): np.asarray(v) for k, v in rows.items()}
    n = len(next(iter(rows.values()))) if rows else 0
    if C_xy is not None and len(C_xy) >= n:
        columns[row_column("C_x")] = np.asarray(C_xy)[:n, 0]
        columns[row_column("C_y")] = np.asarray(C_xy)[:n, 1]
    return pandas.DataFrame(columns)


def runs_frame(rows: Sequence[Mapping[str, Any]], *, parameters: Sequence[str] = (),
               units: Mapping[str, str] | None = None, first: Sequence[str] = ()) -> Any:
    """Per-run rows (runs.csv's columns, :func:`wmr_mj.sim.many_runs.flat_row`) as a DataFrame: one row per run,
    ``first`` then ``run``, the ranged ``parameters`` (the values each run used, with their ``units``), then
    :data:`RUN_COLUMNS` and any other scalar column (requirements' robustness); nested summaries left out."""
    pandas = require_pandas()
    order = [*first, "run", *parameters, *(c for c in RUN_COLUMNS if c not in ("run", *parameters))]
    present = [c for c in order if any(c in r for r in rows)]
    extra = [c for c in dict.fromkeys(k for r in rows for k in r)
             if c not in present and c.startswith("requirement_")]
    names = present + extra
    return pandas.DataFrame([[_scalar(r.get(c)) for c in names] for r in rows],
                            columns=[run_column(c, units) for c in names])


def records_frame(records: Sequence[Mapping[str, Any]]) -> Any:
    """Plain records (one mapping per row, scalar values) as a DataFrame, columns in first-seen order."""
    pandas = require_pandas()
    names = list(dict.fromkeys(k for r in records for k in r))
    return pandas.DataFrame([[_scalar(r.get(c)) for c in names] for r in records], columns=names)


def _scalar(value: Any) -> Any:
    """A table's cell: a number, a word, a flag or None (pandas makes None NaN in a column of numbers); never
    a mapping or a sequence, whose Python repr a table would hold: those are the caller's to flatten.

    Raises:
        TypeError: a mapping or a sequence.
    """
    if isinstance(value, Mapping | list | tuple):
        raise TypeError(f"a table cell must be a scalar, not {type(value).__name__}")
    return value


def verdict_counts_text(verdicts: Mapping[str, int]) -> str:
    """``certified-inside 12, uncertified 4`` (the non-zero counts, in the verdicts' order)."""
    return ", ".join(f"{v} {n}" for v, n in verdicts.items() if n) or "no verdict"


def html_lines(title: str, verdict: str, lines: Sequence[str]) -> str:
    """A result's few lines for a notebook: its kind, its verdict in bold, then its key numbers."""
    items = "".join(f"<li>{html.escape(line)}</li>" for line in lines)
    return (f"<div><b>{html.escape(title)}</b>: <b>{html.escape(verdict)}</b>"
            f"<ul style='margin:0.2em 0'>{items}</ul></div>")


def number(value: Any, unit: str = "", spec: str = ".4g") -> str:
    """``0.0123 rad`` (``n/a`` for None or NaN, ``inf`` as itself)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    text = format(float(value), spec)
    return f"{text} {unit}" if unit else text


# -- each result's table and lines, from its data (read by attribute; the results' modules call these) --------

def compare_frame(runs: Sequence[Any], rows: Sequence[Any]) -> Any:
    """A comparison's runs (``ScenarioRun``) as one row per design and scenario, plain columns: the run's
    verdict and errors, the certificate's bound, each requirement's robustness, whether it held and its
    robustness over its threshold, effort and C's path, then the design's adversary (``DesignRow``)."""
    by_label = {r.label: r for r in rows}
    records = []
    for run in runs:
        s, cert = run.summary, run.summary.get("certificate") or {}
        record: dict[str, Any] = {
            "design": run.design, "scenario": run.scenario, "controller": s.get("controller"),
            "status": s.get("status"), "verdict": s.get("verdict"), "failure": s.get("failure"),
            "m1 [kg]": s.get("m1"), "sup_E [rad]": s.get("sup_E"), "sup_Edot [rad/s]": s.get("sup_Edot"),
            "certificate_E_max [rad]": cert.get("E_max"), "certificate_Edot_max [rad/s]": cert.get("Edot_max"),
            "certificate_E_ratio [-]": cert.get("E_ratio"),
            "unmet": format_unmet(cert.get("unmet_assumptions") or ()),
            "saturated_fraction [-]": s.get("saturated_fraction"),
            "left_steering_range": s.get("left_steering_range"),
            "cross_track_max [m]": s.get("cross_track_max"),
            "rms_voltage [V]": run.rms_voltage, "tv_voltage [V/s]": run.tv_voltage,
            "cpu_us_per_step [us]": run.cpu_us_per_step, "law": run.law,
        }
        for name, judged in run.requirements.items():
            record[f"{name} robustness"] = judged.get("robustness")
            record[f"{name} satisfied"] = judged.get("satisfied")
            record[f"{name} normalised [-]"] = judged.get("normalised")
        design = by_label.get(run.design)
        if design is not None:
            record.update({
                "claim_E_max [rad]": design.claim_E_max, "adversary_worst": design.adversary_worst,
                "adversary_falsified": design.adversary_falsified,
                "adversary_runs_to_falsify": design.adversary_runs_to_falsify,
                "adversary_worst_sup_E [rad]": design.adversary_worst_sup_E, "random_worst": design.random_worst,
                "tightness [-]": design.tightness})
        records.append(record)
    return records_frame(records)


def run_html(summary: Any) -> str:
    """A run's verdict and key numbers (``RunSummary``)."""
    judged = summary.certificate
    lines = [f"{summary.controller} on {summary.path}, m1 {number(summary.m1, 'kg', '.6g')}, "
             f"{number(summary.duration, 's', '.4g')} simulated ({summary.status})",
             f"sup|E| {number(summary.sup_E, 'rad')}, sup|E'| {number(summary.sup_Edot, 'rad/s')}"]
    if judged is not None:
        lines.append(f"certificate's E_max {number(judged.E_max, 'rad')}, E'_max {number(judged.Edot_max, 'rad/s')}; "
                     f"sup|E|/E_max {number(judged.E_ratio)}")
    lines.append(f"time at the voltage limit {number(100 * summary.saturated_fraction, spec='.3g')} %")
    if summary.failure:
        lines.append(f"failed: {summary.failure}")
    return html_lines("run", str(summary.verdict or "no verdict"), lines)


def falsify_html(result: Any) -> str:
    """A search's verdict and key numbers (``FalsifyResult``)."""
    w, r = result.worst, result.random_worst
    verdict = {True: "FALSIFIED", False: "not falsified", None: "no claim to falsify"}[result.falsified]
    where = ", ".join(f"{k} = {v:.6g}" for k, v in w.params.items())
    lines = [f"{result.objective_label}: {result.method}, {result.evaluations} runs over {', '.join(result.box)}",
             f"worst {number(w.objective)} at {where} ({w.verdict}, sup|E| {number(w.sup_E, 'rad')})",
             f"random sample's worst {number(r.objective)} in {len(result.random)} runs"]
    tightness, broken = result.tightness, result.claim_broken
    if tightness is not None:
        lines.append(tightness.text)
    if broken is not None:
        lines.append(f"claim broken in {broken.count} runs")
    return html_lines("falsify", verdict, lines)


def compare_html(rows: Sequence[Any], claims_broken: Sequence[str]) -> str:
    """A comparison's verdict (the claims broken) and each design's line (``DesignRow``)."""
    verdict = f"CLAIM BROKEN: {', '.join(claims_broken)}" if claims_broken else "no claim broken"
    lines = [f"{r.label}: requirements {r.requirements_passed}/{r.requirements_total} held, certified-inside "
             f"{r.certified_inside}/{r.runs}, adversary {'falsified' if r.adversary_falsified else 'not falsified'}"
             f", RMS voltage {number(r.rms_voltage, 'V', '.3g')}" for r in rows]
    return html_lines("compare", verdict, lines)


def validate_frame(rungs: Sequence[Any]) -> Any:
    """validate's rungs (``Rung``: the ladder, the correction rung, the user's designs) as one row each."""
    records = []
    for r in rungs:
        cert = r.certificate or {}
        records.append({
            "index": r.index, "name": r.name, "label": r.label, "runs": r.n,
            **{v: n for v, n in r.verdicts.items()},
            "paper_inside": r.paper_inside,
            "certificate_certified": cert.get("certified"),
            "certificate_E_max [rad]": cert.get("E_max"), "certificate_Edot_max [rad/s]": cert.get("Edot_max"),
            "worst_sup_E [rad]": r.worst_sup_E, "worst_sup_E_m1 [kg]": r.worst_sup_E_m1,
            "worst_sup_Edot [rad/s]": r.worst_sup_Edot,
            "worst_certificate_ratio [-]": r.worst_certificate_ratio,
            "worst_paper_ratio [-]": r.worst_paper_ratio,
            "hit_stop": r.hit_stop, "growing": r.growing,
            "mean_saturated_fraction [-]": r.mean_saturated_fraction,
            "m1_min [kg]": r.m1_min, "m1_max [kg]": r.m1_max,
            "worst_path_cross_track [m]": r.worst_path_cross_track,
        })
    return records_frame(records)


def validate_html(summary: Any) -> str:
    """validate's verdict (runs certified-outside) and each rung's line (``ValidateSummary``)."""
    verdict = (f"CERTIFIED-OUTSIDE in {summary.certified_outside} runs" if summary.certified_outside
               else "no run certified-outside")
    lines = [f"{r.index}. {r.label}: {r.passes}/{r.n} certified-inside, worst sup|E| "
             f"{number(r.worst_sup_E, 'rad')}, worst sup|E|/E_max {number(r.worst_certificate_ratio)}"
             for r in (*summary.ladder, *summary.designs)]
    return html_lines("validate", verdict, [*lines, *summary.findings[:3]])
