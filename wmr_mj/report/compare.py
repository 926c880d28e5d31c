"""The comparison's table (Markdown, CSV, HTML) and files (``wmr-mj compare``); its figure is
:func:`wmr_mj.figures.results.figure_compare`.

Usage::

    from wmr_mj.report.compare import write_report
    paths = write_report(result, out_dir)      # compare.md, compare.csv, compare.html, compare.png, compare.json
"""

from __future__ import annotations

import csv
import html
import io
import json
import math
from pathlib import Path
from types import SimpleNamespace
from typing import Any

from wmr_mj._util.files import write_json_atomic, write_text_atomic
from wmr_mj.analysis.verdicts import certified_outside_banner, format_unmet
from wmr_mj.experiments.compare import CompareResult, DesignRow, runs_json
from wmr_mj.figures.plots import save_figure
from wmr_mj.figures.results import figure_compare
from wmr_mj.hardware import Actuation, Sensing, Transmission, cart_line

__all__ = ["table_rows", "markdown", "csv_text", "html_page", "write_report", "COLUMNS", "legend_lines",
           "banner_lines", "cart_text"]

#: (header, what it says) of every column, in order
COLUMNS = (
    ("design", "the design as named (a preset, a built-in law, FILE.py:Class; ,key=value settings)"),
    ("law", "the steering law's name (and its tracker)"),
    ("requirements passed", "requirement checks held over every scenario (the suite's STL requirements)"),
    ("least robustness", "the least robustness / its threshold over every requirement and scenario (< 0: violated)"),
    ("claim", "the law's own claim: certified-inside runs / runs, and |E| <= E_max on the adversary's box"),
    ("not met", "why the claim does not certify: each assumption not met (value vs limit, the assumption's "
                "units), in how many scenario runs"),
    ("worst found", "the adversary's worst: -robustness of the suite's requirement (> 0: falsified), beside "
                    "random sampling at the same budget and seed"),
    ("where", "the worst case's plant and signal (m1, V_A, the pulse)"),
    ("tightness", "worst sup|E| found (certified runs) / the claim's E_max: a lower bound over an upper bound"),
    ("RMS u [V]", "RMS of the applied voltage, mean over scenarios"),
    ("TV u [V/s]", "total variation of the applied voltage per second, mean over scenarios: chattering"),
    ("cross-track [m]", "the largest |cross-track| of C over every scenario"),
    ("us/step", "CPU time of the closed loop per control step (physics included), median, and the law's path"),
)


def _num(x: Any, spec: str = ".3g") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    return format(x, spec)


def _claim(r: DesignRow) -> str:
    if r.no_claim == r.runs and r.runs:
        return "none"
    e = "" if r.claim_E_max is None else f", E_max {_num(r.claim_E_max)} rad"
    loud = f", {r.certified_outside} CERTIFIED-OUTSIDE" if r.certified_outside else ""
    return f"{r.certified_inside}/{r.runs} certified-inside{loud}{e}"


def _not_met(r: DesignRow) -> str:
    return "; ".join(f"{format_unmet([a])} in {a['runs']}/{r.runs}" for a in r.unmet) or "none"


def banner_lines(result: CompareResult) -> list[str]:
    """``run``'s banner for each design whose claim a run breaks, with that run (its scenario or its
    plant and signal); [] when no claim is broken."""
    out = []
    for r in result.rows:
        b = r.claim_broken
        if b is None:
            continue
        run = f"scenario {b['scenario']}" if b["scenario"] else str(b["where"])
        out.append(certified_outside_banner(
            f"design {r.label}: {b['count']} run(s) break its claim; the worst, {run} (sup|E| = "
            f"{_num(b['sup_E'], '.6g')} rad, {_num(b['ratio'])} times E_max = {_num(b['E_max'], '.4g')} rad), "
            "broken by " + ", ".join(f"{k} = {v!r}" for k, v in b["params"].items())))
    return out


def legend_lines() -> list[str]:
    """What each column says, one Markdown item per column (compare.md's and the console's legend)."""
    return [f"- **{c}**: {what}" for c, what in COLUMNS]


def _worst(r: DesignRow) -> str:
    if r.adversary_worst is None:
        return "n/a"
    verdict = (f"falsified at run {r.adversary_runs_to_falsify}" if r.adversary_falsified else "held")
    rv = "held" if r.random_runs_to_falsify is None else f"falsified at run {r.random_runs_to_falsify}"
    return f"{_num(r.adversary_worst, '+.4g')} ({verdict}); random {_num(r.random_worst, '+.4g')} ({rv})"


def _where(r: DesignRow) -> str:
    w = r.adversary_where
    if not w:
        return "n/a"
    keys = [k for k in ("m1", "V_A", "disturbance.t1", "disturbance.amplitude") if k in w]
    return ", ".join(f"{k.replace('disturbance.', 'pulse ')} {w[k]:.4g}" for k in keys)


def table_rows(result: CompareResult) -> list[list[str]]:
    """The table's cells, one list per design (:data:`COLUMNS`)."""
    out = []
    for r in result.rows:
        law = r.controller + ("" if r.tracker is None else f" + {r.tracker}")
        out.append([r.label, law, f"{r.requirements_passed}/{r.requirements_total}",
                    f"{_num(r.least_normalised, '+.3g')} ({r.least_at})" if r.least_at else "n/a",
                    _claim(r), _not_met(r), _worst(r), _where(r), _num(r.tightness), _num(r.rms_voltage),
                    _num(r.tv_voltage), _num(r.cross_track_max), f"{_num(r.cpu_us_per_step, '.1f')} ({r.law})"])
    return out


def _heading(result: CompareResult) -> str:
    s = result.suite
    v = result.versions
    return (f"Suite {s.name} (version {s.version}, sha256 {s.sha256[:12]}), {len(result.scenarios)} scenarios of "
            f"{s.duration:g} s; adversary: {2 * result.budget} runs per design ({result.budget} searched, "
            f"{result.budget} random), seed {result.seed}; wmr-mj {v.get('wmr_mj')}, MuJoCo {v.get('mujoco')}"
            + cart_text(result))


def cart_text(result: CompareResult) -> str:
    """'' where every design runs the ideal cart; else '. Cart (...): sensing ...; actuation ...; transmission
    ...', once where every design shares it, else per design (a scenario that names its own cart keeps it)."""
    carts = [dict(r.cart) for r in result.rows]
    if not any(carts):
        return ""

    def line(cart: dict[str, Any]) -> str:
        parts = SimpleNamespace(sensing=Sensing.from_spec(cart.get("sensing")),
                                actuation=Actuation.from_spec(cart.get("actuation")),
                                transmission=Transmission.from_spec(cart.get("transmission")))
        return cart_line(parts)[len("cart: "):]

    where = " (a scenario that names its own cart keeps it)"
    if all(c == carts[0] for c in carts):
        return f". Cart of every design{where}: {line(carts[0])}"
    return f". Cart{where}: " + " | ".join(f"{r.label}: {line(c)}" for r, c in zip(result.rows, carts))


def markdown(result: CompareResult) -> str:
    """The comparison as Markdown: the heading, the table, what each column says."""
    head = [c for c, _ in COLUMNS]
    banners = banner_lines(result)
    lines = [f"# wmr-mj compare\n\n{_heading(result)}\n", *(f"**{b}**\n" for b in banners),
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in table_rows(result):
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in row) + " |")
    lines.append("")
    lines += legend_lines()
    reqs = result.suite.requirements
    lines.append("\nRequirements: " + "; ".join(f"`{k}` = `{v}`" for k, v in reqs.items()))
    lines.append(f"\nAdversary requirement: `{result.suite.adversary.requirement}`. Scenarios: "
                 + ", ".join(s.id for s in result.scenarios) + ".")
    return "\n".join(lines) + "\n"


def csv_text(result: CompareResult) -> str:
    """One CSV line per design with every figure of :class:`~wmr_mj.experiments.compare.DesignRow` (full precision)."""
    rows = [r.to_dict() for r in result.rows]
    buf = io.StringIO()
    names = list(dict.fromkeys(k for r in rows for k in r))  # "cart" only where a design's cart is not ideal
    w = csv.DictWriter(buf, fieldnames=names, lineterminator="\n")
    w.writeheader()
    for r in rows:
        cells = {k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()}
        cells["claim_broken"] = "" if r["claim_broken"] is None else json.dumps(r["claim_broken"])
        if "cart" in r:
            cells["cart"] = json.dumps(r["cart"])
        cells["unmet"] = format_unmet(r["unmet"])  # name (value vs limit); ...
        w.writerow(cells)
    return buf.getvalue()


def html_page(result: CompareResult, figure_name: str = "compare.png") -> str:
    """A self-contained page: the heading, the figure, the table, the columns explained."""
    head = "".join(f"<th title='{html.escape(what, quote=True)}'>{html.escape(c)}</th>" for c, what in COLUMNS)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>"
                   for row in table_rows(result))
    notes = "".join(f"<li><b>{html.escape(c)}</b>: {html.escape(w)}</li>" for c, w in COLUMNS)
    return (f"<!doctype html><html><head><meta charset='utf-8'><title>wmr-mj compare</title><style>"
            "body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse;font-size:13px}"
            "td,th{border:1px solid #ccc;padding:3px 6px;text-align:left}th{background:#f3f3f3}</style></head>"
            f"<body><h1>wmr-mj compare</h1><p>{html.escape(_heading(result))}</p>"
            + "".join(f"<p style='color:#e00000'><b>{html.escape(b)}</b></p>" for b in banner_lines(result)) +
            f"<img src='{html.escape(figure_name)}' style='max-width:900px'><table><tr>{head}</tr>{body}</table>"
            f"<ul>{notes}</ul></body></html>\n")


def write_report(result: CompareResult, out: Path) -> dict[str, str]:
    """compare.md, compare.csv, compare.html, compare.png and compare.json (and runs.jsonl) in ``out``,
    each written atomically; returns their paths by kind."""
    out.mkdir(parents=True, exist_ok=True)
    paths = {"markdown": out / "compare.md", "csv": out / "compare.csv", "html": out / "compare.html",
             "json": out / "compare.json", "runs": out / "runs.jsonl"}
    write_text_atomic(paths["markdown"], markdown(result))
    write_text_atomic(paths["csv"], csv_text(result))
    write_text_atomic(paths["html"], html_page(result))
    write_text_atomic(paths["runs"], runs_json(result))
    write_json_atomic(paths["json"], json.loads(json.dumps(result.to_dict(runs=False), default=str)))
    (png,) = save_figure(figure_compare(result), out / "compare", formats=("png",))
    return {**{k: str(v) for k, v in paths.items()}, "figure": str(png)}
