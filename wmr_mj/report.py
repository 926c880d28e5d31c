"""The headline validation (``wmr-mj validate``): identify, sweep, judge, and write a report folder.

Steps (:func:`run_validate`):

(a) identify the MuJoCo plant at the nominal m1 (``identify_plant``) -> identified.json;
(b) per model source ('paper', 'nonholonomic', 'identified') sweep the plant's m1
    over its range (``run_sweep``; atomic and resumable in sweep-<source>/), plus
    one nominal run (m1 = 650 kg) per source for its time history;
(c) a verdict per source: are the analysis's assumptions met by the identified
    plant (identified P, C_V, F, K inside the box the analysis uses for that
    source; the identified gyro term is reported, the analysis has none),
    condition (4.23), runs inside the region / n, worst sup|E|/E_max and
    sup|E'|/E'_max, fraction of runs that hit the steering stop, mean
    voltage-saturation fraction;
(d) figures (PNG + SVG) in figures/;
(e) summary.csv and summary.json (verdicts, identification, versions, settings);
(f) index.md and index.html.

Every number in the report comes from this run. The per-source verdict is
computed from the sweep's runs.csv (:func:`summarise_runs`), so a resumed
sweep reports exactly like a fresh one.

Usage::

    from wmr_mj.report import ValidateSettings, run_validate, format_verdict_table
    summary = run_validate(ValidateSettings(n=20, duration=20.0), "logs/my-validate")
    print(format_verdict_table(summary))
"""

from __future__ import annotations

import csv
import html
import io
import math
import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .errors import ParameterError, UnknownNameError
from .io import software_versions

__all__ = [
    "SOURCES",
    "DEFAULT_N",
    "DEFAULT_DURATION",
    "ValidateSettings",
    "analysis_box",
    "check_assumptions",
    "summarise_runs",
    "run_validate",
    "format_verdict_table",
    "format_identification_table",
    "findings",
    "software_versions",
    "write_pointer",
]

SOURCES = ("paper", "nonholonomic", "identified")
#: Defaults of ``wmr-mj validate``: 3 x 100 runs of 35 s finish in about 2 minutes on 2 cores.
DEFAULT_N = 100
DEFAULT_DURATION = 35.0
COEFFICIENTS = ("P", "C_V", "F", "K")
UNITS = {"P": "V s^2/rad", "C_V": "V s/rad", "F": "V", "K": "V", "gyro": "V s/m"}
REST_RATE = 1e-3  # rad/s: |alpha'| below this counts as "the steering stands still"


# --------------------------------------------------------------------------- settings
@dataclass(frozen=True, kw_only=True)
class ValidateSettings:
    """What ``wmr-mj validate`` runs. Bad values raise ParameterError / UnknownNameError."""

    n: int = DEFAULT_N
    seed: int = 0
    sampling: str = "lhs"
    duration: float = DEFAULT_DURATION
    identify_duration: float = 60.0
    nthread: int = 0
    m1_range: tuple[float, float] = (550.0, 750.0)
    nominal_m1: float = 650.0
    kp: float = 6.0
    kd: float = 9.0
    sources: tuple[str, ...] = SOURCES

    def __post_init__(self) -> None:
        from .sweep import SAMPLINGS

        if isinstance(self.n, bool) or not isinstance(self.n, int) or self.n < 1:
            raise ParameterError(f"n = {self.n!r} is not accepted; the number of runs must be an integer >= 1")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int):
            raise ParameterError(f"seed = {self.seed!r} is not accepted; an integer is required")
        if self.sampling not in SAMPLINGS:
            raise UnknownNameError("sampling", str(self.sampling), SAMPLINGS)
        for name in ("duration", "identify_duration", "nominal_m1", "kp", "kd"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
                raise ParameterError(f"{name} = {v!r} is not accepted; a finite number > 0 is required")
        if isinstance(self.nthread, bool) or not isinstance(self.nthread, int) or self.nthread < 0:
            raise ParameterError(f"nthread = {self.nthread!r} is not accepted; an integer >= 0 (0: all CPUs) is required")
        lo, hi = self.m1_range
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
            raise ParameterError(f"m1_range = {self.m1_range!r} must be (lo, hi) with 0 < lo < hi")
        for s in self.sources:
            if s not in SOURCES:
                raise UnknownNameError("model source", s, SOURCES)

    def as_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["m1_range"] = list(self.m1_range)
        d["sources"] = list(self.sources)
        return d


# --------------------------------------------------------------------------- verdict pieces
def analysis_box(source: str, params: Any = None, *, m1_range: tuple[float, float] = (550.0, 750.0),
                 m1_inertia: str = "payload"):
    """The parameter box the analysis uses for ``source`` (as ``simulate.analysis_for`` with box='derived').

    'paper' -> the paper model's coefficients over m1_range; 'nonholonomic' and
    'identified' -> the non-holonomic model's.
    """
    from .params import C80
    from .simulate import RunConfig
    from .simulate import analysis_box as box_of

    if source not in SOURCES:
        raise UnknownNameError("model source", source, SOURCES)
    return box_of(RunConfig(model=source, m1_range=tuple(m1_range), m1_inertia=m1_inertia),
                  C80 if params is None else params)


def check_assumptions(identified: Mapping[str, float], box, std_error: Mapping[str, float] | None = None
                      ) -> dict[str, Any]:
    """Is each identified coefficient P, C_V, F, K inside ``box``? (strict interval test)

    Returns {'met': bool, 'outside': [names], 'coefficients': {name: {value, lo, hi, inside,
    outside_by (signed distance to the box, 0 inside), outside_by_rel (that over the box's
    scale max(|lo|, |hi|), None when the box is [0, 0]), outside_by_se (in standard errors)}}}.
    """
    se = std_error or {}
    coeffs: dict[str, Any] = {}
    outside = []
    for name in COEFFICIENTS:
        v = float(identified[name])
        lo, hi = (float(x) for x in getattr(box, name))
        inside = lo <= v <= hi
        dist = 0.0 if inside else (v - hi if v > hi else v - lo)
        scale = max(abs(lo), abs(hi))
        s = se.get(name)
        coeffs[name] = {
            "value": v, "lo": lo, "hi": hi, "inside": inside, "outside_by": dist,
            "outside_by_rel": (dist / scale) if scale > 0 else None,
            "outside_by_se": (dist / s) if s else None,
        }
        if not inside:
            outside.append(name)
    return {"met": not outside, "outside": outside, "coefficients": coeffs}


def _max_or_none(values: Sequence[float | None]) -> float | None:
    vals = [float(v) for v in values if v is not None]
    return max(vals) if vals else None


def summarise_runs(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The verdict numbers of one sweep from its runs (rows of runs.csv, ``sweep.read_results``).

    inside (sup|E| <= E_max and sup|E'| <= E'_max over the whole run), inside_settled
    (the same after C entered the circle), worst ratios sup|E|/E_max, sup|E'|/E'_max
    (None when the region is unbounded), the fraction of runs that reached the steering
    stop, the mean voltage-saturation fraction, and the ranges of m1 and sup errors.
    """
    n = len(rows)
    if n == 0:
        raise ParameterError("no runs to summarise")

    def settled_inside(r: Mapping[str, Any]) -> bool:
        E_max, Ed_max = r.get("E_max"), r.get("Edot_max")
        if E_max is None or Ed_max is None:
            return False
        return r["sup_E_settled"] <= E_max and r["sup_Edot_settled"] <= Ed_max

    return {
        "n": n,
        "inside": int(sum(bool(r["inside"]) for r in rows)),
        "inside_settled": int(sum(settled_inside(r) for r in rows)),
        "worst_E_ratio": _max_or_none([r.get("E_ratio") for r in rows]),
        "worst_Edot_ratio": _max_or_none([r.get("Edot_ratio") for r in rows]),
        "worst_sup_E": max(float(r["sup_E"]) for r in rows),
        "worst_sup_Edot": max(float(r["sup_Edot"]) for r in rows),
        "best_sup_E": min(float(r["sup_E"]) for r in rows),
        "stop_fraction": sum(bool(r["left_steering_range"]) for r in rows) / n,
        "mean_saturated_fraction": sum(float(r["saturated_fraction"]) for r in rows) / n,
        "m1_min": min(float(r["m1"]) for r in rows),
        "m1_max": max(float(r["m1"]) for r in rows),
    }


def _result_from_dict(d: Mapping[str, Any]):
    """A RobustnessResult rebuilt from its ``as_dict()`` (enough for plotting and vertices)."""
    from .robustness import RobustnessResult

    inf = math.inf
    return RobustnessResult(
        gamma1=d["gamma1"], gamma2=d["gamma2"], delta1=d["delta1"], delta_E=d["delta_E"],
        delta_Edot=d["delta_Edot"], condition=inf if d["condition"] is None else d["condition"],
        stable=bool(d["stable"]), E_max=inf if d["E_max"] is None else d["E_max"],
        Edot_max=inf if d["Edot_max"] is None else d["Edot_max"], kp=d["kp"], kd=d["kd"],
        reading=d.get("reading", "corrected"), gammas=d.get("gammas", "exact"),
    )


def nominal_behaviour(rows: Mapping[str, np.ndarray], summary: Mapping[str, Any], steering_range: float
                      ) -> dict[str, Any]:
    """What the nominal run did after C entered the circle (the entry transient is over).

    rest_fraction: share of that time the steering stood still (|alpha'| < REST_RATE)
    away from its stops; at_stop_fraction: share spent at a stop; final_E, sup_E_after.
    """
    t = np.asarray(rows["t"])
    after = t >= float(summary["settle_s"])
    a = np.asarray(rows["alpha"])[after]
    ad = np.asarray(rows["alpha_dot"])[after]
    E = np.asarray(rows["E"])[after]
    if a.size == 0:
        return {"rest_fraction": None, "at_stop_fraction": None, "final_E": float(rows["E"][-1]),
                "sup_E_after": None, "sup_E_at_rest": None}
    at_stop = np.abs(a) >= steering_range - 0.01
    rest = (np.abs(ad) < REST_RATE) & ~at_stop
    # the entry: time the steering moved against the reference's direction
    tt = np.asarray(rows["t"])
    a0d_all = np.asarray(rows["alpha0_dot"])
    ad_all = np.asarray(rows["alpha_dot"])
    entry = tt < float(summary["settle_s"])
    against = entry & (np.abs(a0d_all) > 0.01) & (ad_all * a0d_all < 0) & (np.abs(ad_all) >= REST_RATE)
    dt = float(tt[1] - tt[0]) if tt.size > 1 else 0.0
    E_all = np.abs(np.asarray(rows["E"]))
    k_sup = int(np.argmax(E_all)) if E_all.size else 0
    return {
        "t_sup_E": float(tt[k_sup]) if tt.size else None,
        "sup_E_in_entry": bool(tt.size and tt[k_sup] < float(summary["settle_s"])),
        "against_reference_s": float(against.sum() * dt),
        "rest_fraction": float(rest.mean()),
        "at_stop_fraction": float(at_stop.mean()),
        "final_E": float(E[-1]),
        "sup_E_after": float(np.max(np.abs(E))),
        "sup_E_at_rest": float(np.max(np.abs(E[rest]))) if rest.any() else None,
        "min_abs_alpha_dot_after": float(np.min(np.abs(ad))),
        "final_alpha_dot": float(ad[-1]),
        "growing_at_end": bool(abs(E[-1]) >= 0.99 * float(np.max(np.abs(E))) and abs(ad[-1]) >= REST_RATE
                               and E.size > 1 and abs(E[-1]) > abs(E[0])),
    }


# --------------------------------------------------------------------------- the run
def write_pointer(folder: str | os.PathLike) -> Path:
    """Write ``<parent>/validate-latest``: a text file holding the folder's absolute path."""
    from .io import write_text_atomic

    folder = Path(folder)
    return write_text_atomic(folder.parent / "validate-latest", str(folder.resolve()) + "\n")


def run_validate(settings: ValidateSettings, out_dir: str | os.PathLike, *, log: bool = True,
                 stream=None, tty: bool | None = None) -> dict[str, Any]:
    """Run the validation into ``out_dir`` (created; sweeps resume there). Returns the summary.

    Stage lines go to ``stream`` (default stderr) when ``log``; ``tty`` forces or
    suppresses the live counter (default: whether the stream is a terminal).
    """
    from . import plots
    from .identify import identify_plant
    from .io import write_json_atomic, write_text_atomic
    from .params import C80, with_params
    from .progress import Stages
    from .simulate import RunConfig, run_closed_loop
    from .sweep import SweepSpec, read_results, run_sweep

    wall0 = time.perf_counter()
    folder = Path(out_dir)
    folder.mkdir(parents=True, exist_ok=True)
    fig_dir = folder / "figures"
    st = Stages("validate", stream=stream, enabled=log, tty=tty)
    figures: dict[str, list[str]] = {}

    def rel(p: Path) -> str:
        return p.relative_to(folder).as_posix()

    # (a) identification --------------------------------------------------------------
    nominal = with_params(C80, m1=settings.nominal_m1)
    st.start("identify", f"identify the plant (m1 = {settings.nominal_m1:g} kg, {settings.identify_duration:g} s "
                         "excitation)")
    ident = identify_plant(nominal, duration=settings.identify_duration, seed=settings.seed)
    ident_dict = ident.as_dict()
    write_json_atomic(folder / "identified.json", ident_dict)
    idc = ident.identified
    st.done(f"K = {idc.K:.3g} V, gyro = {idc.gyro:.3g} V s/m, {ident.diagnostics['samples']} samples")

    # (b) sweeps and nominal runs ----------------------------------------------------------
    sources: dict[str, Any] = {}
    nominal_runs: dict[str, Any] = {}
    for src in settings.sources:
        base = RunConfig(model=src, duration=settings.duration, kp=settings.kp, kd=settings.kd,
                         m1_range=tuple(settings.m1_range), seed=settings.seed,
                         identified=ident_dict if src == "identified" else None)
        spec = SweepSpec(n=settings.n, seed=settings.seed, sampling=settings.sampling,
                         m1_range=tuple(settings.m1_range), base=base)
        sweep_dir = folder / f"sweep-{src}"
        st.start(f"sweep-{src}", f"sweep {src}: {settings.n} runs of {settings.duration:g} s, m1 "
                                 f"{settings.m1_range[0]:g}-{settings.m1_range[1]:g} kg ({settings.sampling})")
        resumed: list[int] = []

        def sweep_progress(done: int, total: int, resumed: list[int] = resumed) -> None:
            if not resumed:
                resumed.append(done)  # the first call reports the runs found in runs.csv
            st.update(done, total)

        run_sweep(spec, out_dir=sweep_dir, nthread=settings.nthread, progress=sweep_progress)
        rows = read_results(sweep_dir / "runs.csv")
        verdict = summarise_runs(rows)
        again = f" ({resumed[0]} resumed from runs.csv)" if resumed and resumed[0] else ""
        st.done(f"{verdict['inside']}/{verdict['n']} inside the region{again}")

        st.start(f"nominal-{src}", f"nominal run {src} (m1 = {settings.nominal_m1:g} kg)")
        run = run_closed_loop(base.replace(m1=settings.nominal_m1), progress=False)
        nominal_runs[src] = run
        st.done(f"sup|E| = {run.summary['sup_E']:.3g} rad, E_max = {run.summary['E_max']:.3g} rad")

        analysis = run.summary["analysis"]
        box = analysis_box(src, C80, m1_range=settings.m1_range)
        assumptions = check_assumptions(idc.as_dict(), box, ident.diagnostics.get("std_error"))
        sources[src] = {
            **verdict,
            "condition": analysis["condition"],
            "stable": analysis["stable"],
            "E_max": analysis["E_max"],
            "Edot_max": analysis["Edot_max"],
            "assumptions_met": assumptions["met"],
            "assumptions": assumptions,
            "box": box.as_dict(),
            "box_model": "paper" if src == "paper" else "nonholonomic",
            "estimate": run.summary["controller_config"].get("estimate"),
            "gyro_identified": idc.gyro,
            "gyro_estimate": (run.summary["controller_config"].get("estimate") or {}).get("gyro"),
            "analysis": analysis,
            "nominal": {
                "m1": run.summary["m1"],
                "sup_E": run.summary["sup_E"],
                "sup_Edot": run.summary["sup_Edot"],
                "sup_E_settled": run.summary["sup_E_settled"],
                "sup_Edot_settled": run.summary["sup_Edot_settled"],
                "settle_s": run.summary["settle_s"],
                "inside": run.summary["inside"],
                "saturated_fraction": run.summary["saturated_fraction"],
                "left_steering_range_at_s": run.summary["left_steering_range_at_s"],
                "final_alpha": run.summary["final_alpha"],
                "friction_sign": run.summary["controller_config"].get("friction_sign"),
                **nominal_behaviour(run.rows, run.summary, C80.steering_range),
            },
            "runs_csv": rel(sweep_dir / "runs.csv"),
            "_rows": rows,
        }

    # (d) figures ---------------------------------------------------------------------------
    st.start("figures", "figures (PNG + SVG)")
    figs: dict[str, Any] = {}
    for src, v in sources.items():
        rows = v.pop("_rows")
        result = _result_from_dict(v["analysis"])
        pts = plots.Series(label=f"{src}: (sup|E|, sup|E'|) of each run", kind="points",
                           E=np.array([r["sup_E"] for r in rows]), E_dot=np.array([r["sup_Edot"] for r in rows]),
                           values=np.array([r["m1"] for r in rows]), tag="runs")
        cond = v["condition"]
        figs[f"region_{src}"] = plots.figure_region(
            result, [pts],
            title=(f"{src} model: {v['inside']}/{v['n']} runs inside the region, (4.23) = "
                   f"{'n/a' if cond is None else format(cond, '.4f')}"),
            region_label=(f"region (4.21)-(4.23), {v['box_model']} box over m1: ||E|| <= "
                          f"{_fmt(v['E_max'])} rad, ||E'|| <= {_fmt(v['Edot_max'])} rad/s"))
        run = nominal_runs[src]
        figs[f"history_{src}"] = plots.figure_time_history(
            run.rows, run.summary, voltage_limit=C80.voltage_limit,
            title=f"{src} model on the MuJoCo plant, m1 = {run.summary['m1']:g} kg")
    example = plots.paper_example(duration=settings.duration, mujoco=False)
    if ("paper" in nominal_runs and settings.nominal_m1 == 650.0 and settings.kp == 6.0 and settings.kd == 9.0
            and tuple(settings.m1_range) == (550.0, 750.0)):  # the same run as Fig. 7's (b)
        example.mujoco_rows = nominal_runs["paper"].rows
        example.mujoco_summary = nominal_runs["paper"].summary
    else:
        from .simulate import run_closed_loop as _rcl

        r = _rcl(RunConfig(model="paper", duration=settings.duration), progress=False)
        example.mujoco_rows, example.mujoco_summary = r.rows, r.summary
    figs.update(plots.paper_figures(example))
    for stem, fig in figs.items():
        figures[stem] = [rel(p) for p in plots.save_figure(fig, fig_dir / stem)]
    paper_fig7 = {"condition": example.result.condition, "E_max": example.result.E_max,
                  "Edot_max": example.result.Edot_max,
                  "reduced": [{"case": name, "sup_E": float(np.max(np.abs(r["E"]))),
                               "sup_Edot": float(np.max(np.abs(r["E_dot"])))} for name, r in example.reduced]}
    st.done(f"{sum(len(v) for v in figures.values())} files")

    # (e) tables ------------------------------------------------------------------------------
    st.start("tables", "summary.json, summary.csv, index.md, index.html")
    summary: dict[str, Any] = {
        "folder": str(folder),
        "settings": settings.as_dict(),
        "seed": settings.seed,
        "identification": ident_dict,
        "identification_verdict": ident.verdict(),
        "sources": sources,
        "paper_example": paper_fig7,
        "figures": figures,
        "versions": software_versions(),
        "created": time.strftime("%Y-%m-%d %H:%M:%S %z"),
    }
    summary["findings"] = findings(summary)
    write_text_atomic(folder / "summary.csv", _summary_csv(summary))
    write_text_atomic(folder / "index.md", render_markdown(summary))
    write_text_atomic(folder / "index.html", render_html(summary))
    summary["timings_s"] = dict(st.timings)
    summary["wall_s"] = time.perf_counter() - wall0
    write_json_atomic(folder / "summary.json", summary)
    st.done()
    summary["timings_s"] = dict(st.timings)
    return summary


# --------------------------------------------------------------------------- formatting
def _fmt(x: Any, spec: str = ".3g", none: str = "n/a") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return none
    return format(float(x), spec)


def _pct(x: Any, spec: str = ".0f") -> str:
    return "n/a" if x is None else f"{100 * float(x):{spec}}%"


def _assumption_cell(v: Mapping[str, Any]) -> str:
    a = v["assumptions"]
    if a["met"]:
        return "yes"
    parts = []
    for name in a["outside"]:
        c = a["coefficients"][name]
        rel = c["outside_by_rel"]
        parts.append(f"{name} {'+' if c['outside_by'] > 0 else '-'}{_pct(abs(rel), '.1f')}" if rel is not None
                     else f"{name} {c['outside_by']:+.2g}")
    return "no: " + ", ".join(parts)


VERDICT_COLUMNS = ("source", "assumptions met (outside the box by)", "(4.23)", "inside", "worst |E|/E_max",
                   "worst |E'|/E'_max", "hit stop", "mean V-sat")


def verdict_rows(summary: Mapping[str, Any]) -> list[list[str]]:
    out = []
    for src, v in summary["sources"].items():
        out.append([src, _assumption_cell(v), _fmt(v["condition"], ".4f"), f"{v['inside']}/{v['n']}",
                    _fmt(v["worst_E_ratio"], ".2f"), _fmt(v["worst_Edot_ratio"], ".2f"),
                    _pct(v["stop_fraction"]), _pct(v["mean_saturated_fraction"], ".1f")])
    return out


def format_verdict_table(summary: Mapping[str, Any]) -> str:
    """The verdict table as aligned text, with the identified gyro term under it."""
    rows = [list(VERDICT_COLUMNS)] + verdict_rows(summary)
    widths = [max(len(r[i]) for r in rows) for i in range(len(VERDICT_COLUMNS))]
    lines = []
    for k, r in enumerate(rows):
        lines.append("  ".join(c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths))))
        if k == 0:
            lines.append("  ".join("-" * w for w in widths))
    ident = summary["identification"]
    g = ident["identified"]["gyro"]
    g_nh = ident["predicted"]["nonholonomic"]["gyro"]
    lines.append(f"identified gyro term (not in the analysis): {g:.4g} V s/m "
                 f"(non-holonomic model {g_nh:.4g}, paper model 0)")
    return "\n".join(lines)


def identification_rows(summary: Mapping[str, Any]) -> list[list[str]]:
    ident = summary["identification"]
    se = ident.get("diagnostics", {}).get("std_error", {})
    out = []
    for k in ("P", "C_V", "F", "K", "gyro"):
        row = [k, _fmt(ident["identified"][k], ".5g"), _fmt(se.get(k), ".2g")]
        for model in ("paper", "nonholonomic"):
            r = ident["relative_difference"][model][k]
            row += [_fmt(ident["predicted"][model][k], ".4g"), "n/a" if r is None else f"{100 * r:+.1f}%"]
        row.append(UNITS[k])
        out.append(row)
    return out


IDENT_COLUMNS = ("coef", "identified", "+-", "paper", "diff", "nonholonomic", "diff", "unit")


def format_identification_table(summary: Mapping[str, Any]) -> str:
    rows = [list(IDENT_COLUMNS)] + identification_rows(summary)
    widths = [max(len(r[i]) for r in rows) for i in range(len(IDENT_COLUMNS))]
    return "\n".join("  ".join(c.rjust(w) if 0 < i < 7 else c.ljust(w) for i, (c, w) in enumerate(zip(r, widths)))
                     for r in rows)


def findings(summary: Mapping[str, Any]) -> list[str]:
    """Plain-language statements of what the plant shows, every number from ``summary``."""
    ident = summary["identification"]
    idv = ident["identified"]
    se = ident.get("diagnostics", {}).get("std_error", {})
    pp = ident["predicted"]["paper"]
    nh = ident["predicted"]["nonholonomic"]
    out = []
    K, Kp = idv["K"], pp["K"]
    ratio = K / Kp if Kp else None
    if ratio is not None and abs(ratio) < 0.1:
        verdict = ("the paper's K term (V(alpha) of (2.7)) has no counterpart in the plant, as the "
                   "non-holonomic model predicts (K = 0)")
    else:
        verdict = "the plant does show a term of that form"
    out.append(f"Steering stiffness: the plant shows K = {K:.3g} V (+-{_fmt(se.get('K'), '.1g')}), "
               f"{_pct(ratio, '.1f')} of the paper's prediction {Kp:.4g} V: {verdict}.")
    g, gn = idv["gyro"], nh["gyro"]
    out.append(f"Gyroscopic term: the plant shows {g:.3g} V s/m (+-{_fmt(se.get('gyro'), '.1g')}) on "
               f"V_A alpha'/cos^2(alpha), {_pct(g / gn if gn else None)} of the non-holonomic prediction "
               f"{gn:.3g} V s/m; the paper's model and its analysis (4.17)-(4.23) have no such term.")
    rel = ident["relative_difference"]
    agree = ", ".join(f"{k} {100 * rel['paper'][k]:+.1f}%" for k in ("P", "C_V", "F") if rel["paper"][k] is not None)
    out.append(f"P, C_V, F identified against both models' prediction (same for both): {agree}.")
    P_hat, kp = pp["P"], summary["settings"]["kp"]
    band = idv["F"] / (P_hat * kp)
    for src, v in summary["sources"].items():
        nom = v["nominal"]
        a = v["assumptions"]
        box_txt = ("inside the analysis's box" if a["met"] else
                   "outside the analysis's " + v["box_model"] + " box in " + ", ".join(a["outside"]))
        stop = nom.get("left_steering_range_at_s")
        parts = [f"{src} model: the identified plant is {box_txt}; (4.23) = {_fmt(v['condition'], '.4f')}; "
                 f"{v['inside']}/{v['n']} runs keep (sup|E|, sup|E'|) inside the region "
                 f"(worst sup|E|/E_max = {_fmt(v['worst_E_ratio'], '.2f')}, sup|E'|/E'_max = "
                 f"{_fmt(v['worst_Edot_ratio'], '.2f')}); {_pct(v['stop_fraction'])} of runs hit the steering stop."]
        if stop is not None:
            parts.append(f"At m1 = {nom['m1']:g} kg the steering reached its stop at t = {stop:.2f} s.")
        if nom.get("sup_E_in_entry"):
            msg = (f"Its largest error |E| = {nom['sup_E']:.3g} rad comes at t = {nom['t_sup_E']:.2f} s, in the entry "
                   f"(C reaches the circle at {nom['settle_s']:.1f} s)")
            if nom.get("against_reference_s") and nom.get("friction_sign") == "measured":
                msg += (f"; the steering moved against the reference's direction for {nom['against_reference_s']:.2f} s "
                        f"there, with the Coulomb compensation F^ sgn(alpha') pushing it that way")
            parts.append(msg + ".")
        rf = nom.get("rest_fraction")
        if rf is not None:
            if rf > 0.5:
                parts.append(f"After C entered the circle ({nom['settle_s']:.1f} s) the steering stood still "
                             f"{_pct(rf)} of the time away from its stops, holding |E| up to "
                             f"{_fmt(nom['sup_E_at_rest'])} rad: the Coulomb dead band (up to F/(P^ K_P) = "
                             f"{band:.3g} rad with the identified F).")
            else:
                at_stop = nom.get("at_stop_fraction") or 0.0
                parts.append(f"After C entered the circle ({nom['settle_s']:.1f} s) sup|E| = "
                             f"{_fmt(nom['sup_E_after'])} rad (final E = {nom['final_E']:.3g} rad, "
                             f"E_max = {_fmt(v['E_max'])} rad); the steering "
                             + (f"sat at its stop {_pct(at_stop)} of that time and " if at_stop > 0 else "")
                             + f"stood still {_pct(rf)} of that time away from its stops"
                             + (f" (no Coulomb sticking; dead band bound F/(P^ K_P) = {band:.3g} rad)."
                                if rf == 0 and at_stop < 0.5 else "."))
                if nom.get("growing_at_end"):
                    parts.append(f"|E| is still growing at the end of the run: the steering creeps on at "
                                 f"alpha' = {nom['final_alpha_dot']:.2g} rad/s, past the reference.")
        out.append(" ".join(parts))
    ex = summary.get("paper_example")
    if ex:
        red = "; ".join(f"{r['case']}: sup|E| = {r['sup_E']:.3g} rad, sup|E'| = {r['sup_Edot']:.3g} rad/s"
                        for r in ex["reduced"])
        inside = all(r["sup_E"] <= ex["E_max"] and r["sup_Edot"] <= ex["Edot_max"] for r in ex["reduced"])
        out.append(f"Paper's view (Fig. 7): the same law on the reduced paper model as the plant ({red}) stays "
                   f"{'inside' if inside else 'OUTSIDE'} the region of the paper's (5.1) example (E_max = "
                   f"{ex['E_max']:.3g} rad, E'_max = {ex['Edot_max']:.3g} rad/s, (4.23) = {ex['condition']:.4f}; "
                   f"the paper reports 0.2613).")
    return out


def _summary_csv(summary: Mapping[str, Any]) -> str:
    cols = ["source", "n", "inside", "inside_settled", "worst_E_ratio", "worst_Edot_ratio", "worst_sup_E",
            "worst_sup_Edot", "E_max", "Edot_max", "condition", "stable", "assumptions_met", "outside_box",
            "stop_fraction", "mean_saturated_fraction", "gyro_identified", "runs_csv"]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    for src, v in summary["sources"].items():
        row = {**v, "source": src, "outside_box": " ".join(v["assumptions"]["outside"])}
        w.writerow(["" if row.get(c) is None else (repr(row[c]) if isinstance(row[c], float) else row[c])
                    for c in cols])
    return buf.getvalue()


def _md_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    esc = [[c.replace("|", "\\|") for c in r] for r in [list(header), *rows]]
    lines = ["| " + " | ".join(esc[0]) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in esc[1:]]
    return "\n".join(lines)


def _figure_groups(summary: Mapping[str, Any]) -> list[tuple[str, list[tuple[str, str]]]]:
    """[(heading, [(caption, stem)])] in reading order."""
    figs = summary["figures"]
    srcs = list(summary["sources"])
    groups = [
        ("Region and runs per model source (colour: plant m1)",
         [(f"{s}: region (4.21)-(4.23) and every run's (sup|E|, sup|E'|)", f"region_{s}") for s in srcs]),
        ("Nominal run (m1 = 650 kg) per model source",
         [(f"{s}: E, E', voltage", f"history_{s}") for s in srcs]),
        ("The paper's figures",
         [("Fig. 4 desired trajectory", "fig4_trajectory"), ("Fig. 5 alpha0(t)", "fig5_alpha0"),
          ("Fig. 6 alpha0'(t), alpha0''(t)", "fig6_alpha0_rates"),
          ("Fig. 7 region of the (5.1) example with the paper's view and the MuJoCo plant", "fig7_region")]),
    ]
    return [(h, [(c, s) for c, s in items if s in figs]) for h, items in groups]


def _fig_path(summary: Mapping[str, Any], stem: str, ext: str) -> str:
    for p in summary["figures"][stem]:
        if p.endswith("." + ext):
            return p
    return summary["figures"][stem][0]


def _settings_line(summary: Mapping[str, Any]) -> str:
    s = summary["settings"]
    return (f"n = {s['n']} runs per source, {s['sampling']} sampling of m1 over {s['m1_range'][0]:g}-"
            f"{s['m1_range'][1]:g} kg, seed {s['seed']}, {s['duration']:g} s per run, K_P = {s['kp']:g}, "
            f"K_D = {s['kd']:g}; identification {s['identify_duration']:g} s at m1 = {s['nominal_m1']:g} kg")


def render_markdown(summary: Mapping[str, Any]) -> str:
    v = summary["versions"]
    out = [
        "# wmr-mj validate: computed-torque steering robustness on the MuJoCo C80",
        "",
        f"{summary['created']} - {_settings_line(summary)}.",
        "",
        "## Verdict per model source",
        "",
        "The analysis (4.17)-(4.23) assumes the plant's P, C_V, F, K lie in its box (derived from the "
        "source's reduced model over the m1 range); 'inside' counts runs whose sup|E| <= E_max and "
        "sup|E'| <= E'_max over the whole run.",
        "",
        _md_table(VERDICT_COLUMNS, verdict_rows(summary)),
        "",
        "## What the plant shows",
        "",
        *[f"- {line}" for line in summary["findings"]],
        "",
        "## Identification (m1 = {:g} kg)".format(summary["identification"]["m1"]),
        "",
        _md_table(IDENT_COLUMNS, identification_rows(summary)),
        "",
        "diff = (identified - predicted) / |predicted|.",
        "",
        "## Figures",
        "",
    ]
    for heading, items in _figure_groups(summary):
        out += [f"### {heading}", ""]
        for caption, stem in items:
            out += [f"[![{caption}]({_fig_path(summary, stem, 'png')})]({_fig_path(summary, stem, 'svg')})",
                    "", f"*{caption}*", ""]
    out += ["## Files", "",
            "- `summary.json`, `summary.csv`: the verdicts and settings; `identified.json`: the identification",
            *[f"- `{sv['runs_csv']}`: per-run results ({src})" for src, sv in summary["sources"].items()],
            "", "## Software", "",
            ", ".join(f"{k} {val}" for k, val in v.items()), ""]
    return "\n".join(out)


def _html_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    h = "".join(f"<th>{html.escape(c)}</th>" for c in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><thead><tr>{h}</tr></thead><tbody>{body}</tbody></table>"


_CSS = """body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1100px;margin:2em auto;
padding:0 1em;color:#222;line-height:1.4}table{border-collapse:collapse;margin:.5em 0 1em}th,td{border:1px solid #ccc;
padding:.25em .6em;text-align:right}th{background:#f2f4f7}td:first-child,th:first-child,td:nth-child(2){text-align:left}
figure{display:inline-block;margin:.5em;vertical-align:top;max-width:48%}figure img{max-width:100%;border:1px solid #ddd}
figcaption{font-size:.85em;color:#555}code{background:#f4f4f4;padding:0 .2em}.small{font-size:.85em;color:#555}"""


def render_html(summary: Mapping[str, Any]) -> str:
    e = html.escape
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        "<title>wmr-mj validate</title>", f"<style>{_CSS}</style></head><body>",
        "<h1>wmr-mj validate: computed-torque steering robustness on the MuJoCo C80</h1>",
        f"<p class='small'>{e(summary['created'])} &mdash; {e(_settings_line(summary))}.</p>",
        "<h2>Verdict per model source</h2>",
        "<p>The analysis (4.17)-(4.23) assumes the plant's P, C_V, F, K lie in its box (derived from the source's "
        "reduced model over the m1 range); <em>inside</em> counts runs whose sup|E| &le; E_max and sup|E'| &le; "
        "E'_max over the whole run.</p>",
        _html_table(VERDICT_COLUMNS, verdict_rows(summary)),
        "<h2>What the plant shows</h2><ul>",
        *[f"<li>{e(line)}</li>" for line in summary["findings"]],
        "</ul>",
        f"<h2>Identification (m1 = {summary['identification']['m1']:g} kg)</h2>",
        _html_table(IDENT_COLUMNS, identification_rows(summary)),
        "<p class='small'>diff = (identified &minus; predicted) / |predicted|.</p>",
        "<h2>Figures</h2><p class='small'>Click a figure for its SVG.</p>",
    ]
    for heading, items in _figure_groups(summary):
        parts.append(f"<h3>{e(heading)}</h3><div>")
        for caption, stem in items:
            png, svg = _fig_path(summary, stem, "png"), _fig_path(summary, stem, "svg")
            parts.append(f"<figure><a href='{e(svg)}'><img src='{e(png)}' alt='{e(caption)}'></a>"
                         f"<figcaption>{e(caption)}</figcaption></figure>")
        parts.append("</div>")
    parts += ["<h2>Files</h2><ul>",
              "<li><a href='summary.json'>summary.json</a>, <a href='summary.csv'>summary.csv</a>, "
              "<a href='identified.json'>identified.json</a></li>",
              *[f"<li><a href='{e(sv['runs_csv'])}'>{e(sv['runs_csv'])}</a> ({e(src)})</li>"
                for src, sv in summary["sources"].items()],
              "</ul><h2>Software</h2>",
              f"<p class='small'>{e(', '.join(f'{k} {v}' for k, v in summary['versions'].items()))}</p>",
              "</body></html>", ""]
    return "\n".join(parts)


def json_summary(summary: Mapping[str, Any]) -> dict[str, Any]:
    """The object ``validate --json`` prints (summary.json without bulky analysis internals)."""
    out = dict(summary)
    out["sources"] = {src: {k: v for k, v in sv.items() if k != "analysis"} for src, sv in summary["sources"].items()}
    return out
