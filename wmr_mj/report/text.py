"""The validation report as text, Markdown and HTML: the answer first, every number from the summary.

:func:`document` lays the report out once, as a list of blocks (headings, paragraphs,
lists, tables, figures); :func:`render_markdown`, :func:`render_html` and
:func:`format_headline` (stdout: the verdict, then sections (a)-(d)) render those blocks. Each
opens with :func:`verdict_lines`, five lines: the question, the answer for the paper's design,
why, the answer for the certified design, where the report is; in index.html Fig. 4 (the desired
path and the paths C travelled under both designs) follows directly. Then, in order:

(a) the paper's design against the paper's claim and against its own certificate;
(b) the ladder from the paper's design to the certified one, verdict counts per rung;
(c) the certified design: its rule, its certificate with every assumption, its counts,
    the worst-case search beside the Monte-Carlo worst and the certificate, the full box;
(d) the plant's measured friction law; (e) the certified design on realistic sensing (encoders on the
steering axis and the motor shaft: verdict, voltage activity, dead band; where the report has it), then the
design ``wmr-mj design`` finds for the 12-bit axis encoder beside the certified design on it (gains,
certificate, verdict counts and worst sup|E|/E_max over the same m1 draws; where the report has it);
(f) identification; (g) findings (computed sentences); figures; files; software.

A ``certified-outside`` run (a bug or a modelling gap) is announced in a banner directly under
the verdict, above the details, wherever it appears (the verdict's certified-design line names
its own). ``uncertified-*`` runs are never counted as a pass.

Each public function takes the :class:`~wmr_mj.report.results.ValidateSummary` that ``run_validate``
returns, or a summary.json read back (a mapping, read through ``ValidateSummary.of``), and reads the
summary and its rungs by attribute; the sections other modules write (certificates, searches, sensing,
friction, identification) are read as the mappings they are.

Usage::

    import json
    from wmr_mj.report.text import format_headline, render_markdown
    summary = json.load(open("logs/validate-latest/summary.json"))
    print(format_headline(summary))
"""

from __future__ import annotations

import csv
import html
import io
import math
from collections.abc import Mapping, Sequence
from pathlib import PurePath
from typing import Any

from wmr_mj.analysis.certificate import VERDICTS
from wmr_mj.analysis.verdicts import WITHIN_THE_SUPPLY, format_unmet, paper_region_name
from wmr_mj.carts.provenance import delay_split_unknown, identified_from
from wmr_mj.hardware import Actuation, Sensing, Transmission
from wmr_mj.params import COEFFICIENT_MODELS, COEFFICIENT_NAMES
from wmr_mj.plant.mjcf import STEERING_FRICTION_MODELS
from wmr_mj.reference.route import path_name
from wmr_mj.report.results import Rung, ValidateSummary

#: a summary as run_validate returns it, or its JSON read back (summary.json); each public function takes either
Summary = ValidateSummary | Mapping[str, Any]

__all__ = [
    "document",
    "answer_blocks",
    "verdict_lines",
    "format_headline",
    "render_markdown",
    "render_html",
    "summary_csv",
    "findings",
    "ladder_rows",
    "LADDER_COLUMNS",
]

#: A block of the document: ("h1" | "h2" | "h3" | "p" | "loud", text), ("ul", [text]),
#: ("answer", [five lines]), ("lead", caption, stem) (the figure under the answer),
#: ("table", header, rows), ("figures", [(caption, stem)]) or ("files", [(path, what)]).
Block = tuple

UNITS = {"P": "V s^2/rad", "C_V": "V s/rad", "F": "V", "K": "V", "gyro": "V s/m"}


# --------------------------------------------------------------------------- numbers
def _fmt(x: Any, spec: str = ".3g", none: str = "n/a") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return none
    return format(float(x), spec)


def _pct(x: Any, spec: str = ".0f") -> str:
    return "n/a" if x is None else f"{100 * float(x):{spec}}%"


def _counts(verdicts: Mapping[str, int]) -> str:
    return ", ".join(f"{v} {k.upper() if k == 'certified-outside' and v else k}" for k, v in verdicts.items())


def _unmet(cert: Mapping[str, Any]) -> list[Mapping[str, Any]]:
    return [a for a in cert.get("assumptions", []) if not a.get("met")]


def _unmet_text(cert: Mapping[str, Any]) -> str:
    parts = []
    for a in _unmet(cert):
        value = "unbounded" if a.get("value") is None else _fmt(a["value"], ".4g")
        parts.append(f"{a['name']} ({value} against the limit {_fmt(a.get('limit'), '.4g')})")
    return "; ".join(parts)


def _why_no_certificate(cert: Mapping[str, Any]) -> str:
    """Why a design has no certificate, with the numbers behind it."""
    margin = None
    if cert.get("steering_range") is not None and cert.get("alpha0_max") is not None:
        margin = cert["steering_range"] - cert["alpha0_max"]
    terms = ", ".join(f"{name} {_fmt(cert.get(key), '.3g')}" for name, key in
                      (("K~ term", "K_term"), ("friction", "friction_term"), ("gyro", "gyro_term"),
                       ("P~", "P_term"), ("C_V~", "C_V_term"), ("disturbance", "disturbance_term")) if cert.get(key))
    reason = cert.get("reason") or "an assumption fails"
    text = f"{reason[:1].upper() + reason[1:]}. Not met: {_unmet_text(cert)}."
    if "delta1" in cert:  # section 4's terms (a sampled-data certificate records its own under inputs)
        text += (f" delta1 = {_fmt(cert.get('delta1'), '.3g')} rad/s^2 ({terms}), gamma1 = "
                 f"{_fmt(cert.get('gamma1'), '.3g')} s^2, (4.23) = {_fmt(cert.get('condition'), '.4f')}.")
    band = cert.get("dead_band")
    if band is not None and margin is not None and band > margin:
        text += (f" The static dead band F_max/(P^ K_P) = {band:.3g} rad alone exceeds the {margin:.3g} rad "
                 f"between max|alpha0| = {cert['alpha0_max']:.3g} rad and the steering stops at "
                 f"{cert['steering_range']:g} rad.")
    return text


def _cert_cell(cert: Mapping[str, Any]) -> str:
    if cert.get("certified"):
        return f"|E| <= {_fmt(cert['E_max'])} rad, {_fmt(cert['voltage_max'])} V"
    if cert.get("valid"):
        return f"|E| <= {_fmt(cert['E_max'])} rad, NOT met: {', '.join(cert['unmet'])}"
    return "none: " + ", ".join(cert.get("unmet", []))


# --------------------------------------------------------------------------- the verdict: five lines
def _path_text(summary: ValidateSummary) -> str:
    """'its 1 m circle' on the paper circle (radius from the run's reference), else 'its path'."""
    radius = None if summary.path is None else summary.path.circle_radius
    return f"its {_fmt(radius, '.3g')} m circle" if radius else "its path"


def _paper_verdict(summary: ValidateSummary) -> str:
    rung = summary.ladder[0]
    # rung 1 is the paper's own law, always judged by the paper's region (None: no run of it was)
    n, inside, pr = rung.n, 0 if rung.paper_inside is None else rung.paper_inside, rung.paper_region
    answer = "Yes" if inside == n else "No"
    ratio = rung.worst_paper_ratio
    on_c80 = not summary.settings.get("cart")  # the paper's region on its C80; on another cart, computed for it
    region, e_max = ("the paper's region", "the paper's E_max") if on_c80 else (_claim(summary), "its E_max")
    parts = [f"{n - inside}/{n} runs leave {region}" if inside < n else f"{n}/{n} runs stay inside it"]
    cross = rung.worst_path_cross_track
    if cross is not None:
        parts.append(f"C leaves {_path_text(summary)} by up to {_fmt(cross, '.3g')} m")
    parts.append(f"{rung.hit_stop}/{n} runs reach the steering stop")
    parts.append(f"worst sup|E| = {_fmt(rung.worst_sup_E, '.3g')} rad, {_fmt(ratio, '.3g')} times {e_max} = "
                 f"{_fmt(pr['E_max'], '.3g')} rad")
    return f"The paper's design ({rung.design}): {answer}. " + "; ".join(parts) + "."


def _why_verdict(summary: ValidateSummary) -> str:
    first, last = summary.ladder[0].certificate, summary.ladder[-1].certificate
    if first.get("certified"):
        head = (f"Why: redone for the plant actually simulated, the paper's analysis certifies the paper's design "
                f"only to |E| <= {_fmt(first.get('E_max'), '.3g')} rad")
    else:
        head = ("Why: redone for the plant actually simulated, the paper's analysis gives the paper's design no "
                f"certificate (not met: {', '.join(first.get('unmet') or []) or 'none'})")
    if last.get("certified"):
        tail = (f"the certified design's certificate meets all {len(last.get('assumptions', []))} of its assumptions "
                f"(|E| <= {_fmt(last.get('E_max'), '.3g')} rad, at most {_fmt(last.get('voltage_max'), '.3g')} V)")
    else:
        tail = f"the certified design's certificate fails too (not met: {', '.join(last.get('unmet') or [])})"
    return f"{head}; {tail}."


def _certified_verdict(summary: ValidateSummary) -> str:
    rung = summary.ladder[-1]
    n, cert, passes = rung.n, rung.certificate, rung.passes
    head = f"The certified design (rung {rung.index}: {rung.design})"
    cross = rung.worst_path_cross_track
    keeps = f" keeps C within {_fmt(cross, '.3g')} m of {_path_text(summary)}" if cross is not None else ""
    if not cert.get("certified"):
        return (f"{head}{keeps}, but has NO certificate here: {passes}/{n} runs certified-inside; worst sup|E| = "
                f"{_fmt(rung.worst_sup_E, '.3g')} rad.")
    text = (f"{head}{keeps}: {passes}/{n} runs certified-inside (|E| <= {_fmt(cert.get('E_max'), '.3g')} rad); "
            f"worst sup|E| = {_fmt(rung.worst_sup_E, '.3g')} rad = "
            f"{_fmt(rung.worst_certificate_ratio, '.3f')} of its certificate")
    if rung.certified_outside:
        return text + f"; !!! {rung.certified_outside}/{n} CERTIFIED-OUTSIDE: a bug or a modelling gap !!!"
    return text + "."


def verdict_lines(summary: Summary) -> list[str]:
    """The five-line verdict that opens stdout, index.md and index.html: the question, the answer
    for the paper's design, why, the answer for the certified design, where the report is. Every
    number from ``summary`` (rung 1 and the last rung of the ladder, the settings, the folder)."""
    summary = ValidateSummary.of(summary)
    s = summary.settings
    lo, hi = s["m1_range"]
    cart = s.get("cart")  # validate --cart: the cart's name (settings without it: the C80)
    vehicle = _vehicle(summary)
    text = str(cart.get("text", "")) if cart else ""
    data = identified_from(text) if cart else ()  # a cart identify --data wrote
    if data:
        files = " and ".join(PurePath(name).name for name, _sha256 in data)
        split = ", its delay in any split between sensing and actuation" if delay_split_unknown(text) else ""
        vehicle += f" (identified from {files}; the answer assumes the real cart inside its identified box{split})"
    region = "the paper's robustness region" if not cart else "the (4.21)-(4.23) region, computed for this cart,"
    question = (f"Question: does {region} hold for {vehicle} under m1 in {lo:g}-{hi:g} kg? "
                f"({summary.ladder[0].n} MuJoCo runs per design on {_path_words(s)}, {s['duration']:g} s each)")
    report = (f"Report: {summary.folder}/index.html (also index.md, summary.json); the details follow: (a) the "
              "paper's design, (b) the ladder between the designs, (c) the certified design, (d) the friction law, "
              "(e) the certified design on realistic sensing.")
    return [question, _paper_verdict(summary), _why_verdict(summary), _certified_verdict(summary), report]


def _vehicle(summary: ValidateSummary) -> str:
    """The report's vehicle: the C80, or the cart validate was given (its name and version)."""
    cart = summary.settings.get("cart")
    return "the C80" if not cart else f"the cart {cart['name']} {cart['version']}"


# --------------------------------------------------------------------------- (a) the paper's design
def _claim(summary: ValidateSummary) -> str:
    """The region (4.21)-(4.23)'s name in the report: the paper's claim on the C80 only
    (:func:`wmr_mj.analysis.verdicts.paper_region_name`)."""
    return paper_region_name(not summary.settings.get("cart"))


def _claim_4_21(summary: ValidateSummary) -> str:
    """:func:`_claim` with its equations named once."""
    claim = _claim(summary)
    return claim if "(4.21)-(4.23)" in claim else f"{claim} (4.21)-(4.23)"


def paper_design_lines(summary: Summary) -> list[str]:
    rung = ValidateSummary.of(summary).ladder[0]
    n, pr, cert = rung.n, rung.paper_region, rung.certificate
    lines = [f"Design: {rung.design}, {n} runs over m1 {rung.m1_min:.0f}-{rung.m1_max:.0f} kg.",
             f"Against {_claim(ValidateSummary.of(summary))} (|E| <= {_fmt(pr['E_max'])} rad, |E'| <= "
             f"{_fmt(pr['Edot_max'])} rad/s, "
             f"(4.23) = {_fmt(pr['condition'], '.4g')}): {rung.paper_inside}/{n} runs inside; worst sup|E|/E_max "
             f"= {_fmt(rung.worst_paper_ratio)} (m1 = {_fmt(rung.worst_paper_ratio_m1, '.0f')} kg), worst "
             f"sup|E| = {_fmt(rung.worst_sup_E)} rad."]
    if cert.get("certified"):
        lines.append(f"Against its own certificate (|E| <= {_fmt(cert['E_max'])} rad): "
                     f"{rung.passes}/{n} certified-inside.")
    else:
        lines.append("Against its own certificate: there is none. " + _why_no_certificate(cert))
    lines.append(f"Verdicts: {_counts(rung.verdicts)}; only certified-inside is a pass: "
                 f"{rung.passes}/{n} pass.")
    lines.append(f"Runs that reached the steering stop: {rung.hit_stop}/{n}; runs whose |E| is still growing "
                 f"at the end: {rung.growing}/{n}.")
    return lines


# --------------------------------------------------------------------------- (b) the ladder
LADDER_COLUMNS = ("rung", "design", "change", "certificate", "cert-in", "CERT-OUT", "uncert-in", "uncert-out",
                  "paper in", "worst sup|E| rad", "sup|E|/E_max", "stop", "growing", "cross-track m")


def _all_rungs(summary: ValidateSummary) -> list[Rung]:
    """The ladder's rungs, then the correction rung (where the report has it), then the user's designs."""
    extra = [summary.correction_rung] if summary.correction_rung is not None else []
    return [*summary.ladder, *extra, *summary.designs]


def ladder_rows(summary: Summary) -> list[list[str]]:
    out = []
    for r in _all_rungs(ValidateSummary.of(summary)):
        v, n = r.verdicts, r.n
        out.append([str(r.index), r.label, r.change or "-", _cert_cell(r.certificate),
                    f"{v['certified-inside']}/{n}",
                    f"{v['certified-outside']}/{n}" + (" !!!" if v["certified-outside"] else ""),
                    f"{v['uncertified-inside']}/{n}", f"{v['uncertified-outside']}/{n}",
                    f"{r.paper_inside}/{n}" if r.paper_law else "n/a",
                    _fmt(r.worst_sup_E), _fmt(r.worst_certificate_ratio, ".3f"), f"{r.hit_stop}/{n}",
                    f"{r.growing}/{n}", _fmt(r.worst_path_cross_track, ".3g")])
    return out


# --------------------------------------------------------------------------- (c) the certified design
ASSUMPTION_COLUMNS = ("assumption", "equation", "value", "limit", "met", "kind")


def assumption_rows(cert: Mapping[str, Any]) -> list[list[str]]:
    return [[a["name"], a["equation"], "unbounded" if a.get("value") is None else _fmt(a["value"], ".4g"),
             _fmt(a.get("limit"), ".4g"), "yes" if a["met"] else "NO", a.get("kind", "")]
            for a in cert.get("assumptions", [])]


def _rule_line(summary: ValidateSummary, brief: bool) -> str:
    rule = summary.certified_rule
    now = (f"it gives omega_r = {_fmt(rule.omega_r_rule, 'g')} rad/s now (designs.certified_omega_r, certificates "
           f"only); the design uses {_fmt(rule.omega_r_design, 'g')}.")
    if brief:
        return (f"Rule, written before any run (wmr_mj/sim/designs.py): the smallest omega_r on a "
                f"{_fmt(rule.omega_r_grid_step, 'g')} rad/s grid whose certificate over the m1 box is valid with "
                f"E_max <= {_fmt(rule.error_spec, 'g')} rad; " + now)
    return f"Rule, written before any run (wmr_mj/sim/designs.py): {rule.text} Now " + now


def _limit(cert: Mapping[str, Any], key: str, assumption: str) -> Any:
    """The cert's ``key`` (section 4 records 'voltage_limit' and 'steering_range'), else the limit of its assumption
    ``assumption`` (every claim checks the supply and the stops: :func:`wmr_mj.analysis.claim.shared_assumptions`)."""
    if cert.get(key) is not None:
        return cert[key]
    return next((a.get("limit") for a in cert.get("assumptions") or () if a.get("name") == assumption), None)


def certified_lines(summary: Summary, *, brief: bool = False) -> list[str]:
    summary = ValidateSummary.of(summary)
    rung = summary.ladder[-1]
    cert, n = rung.certificate, rung.n
    lines = [f"Design: {rung.design} (rung {rung.index}).", _rule_line(summary, brief)]
    if cert.get("certified"):
        lines.append(f"Certificate: |E| <= {_fmt(cert['E_max'], '.4g')} rad, |E'| <= "
                     f"{_fmt(cert['Edot_max'], '.4g')} rad/s, at most {_fmt(cert['voltage_max'])} V of the "
                     f"{_fmt(_limit(cert, 'voltage_limit', 'within the supply'), 'g')} V supply, reachable |alpha| <= "
                     f"{_fmt(cert['alpha_max'])} rad (stops at "
                     f"{_fmt(_limit(cert, 'steering_range', 'inside the steering stops'), 'g')} rad); all "
                     f"{len(cert['assumptions'])} "
                     "assumptions met (table below).")
    else:
        lines.append("Certificate: NOT valid. " + _why_no_certificate(cert))
    lines.append(f"Runs: {rung.passes}/{n} certified-inside ({_counts(rung.verdicts)}); worst sup|E| = "
                 f"{_fmt(rung.worst_sup_E, '.4g')} rad = {_fmt(rung.worst_certificate_ratio, '.3f')} of E_max "
                 f"(m1 = {_fmt(rung.worst_certificate_ratio_m1, '.0f')} kg); {rung.growing}/{n} with |E| still "
                 f"growing, {rung.hit_stop}/{n} at the stop.")
    lines += search_lines(summary)
    return lines


SEARCH_COLUMNS = ("search", "objective", "runs", "search worst", "at", "Monte-Carlo worst", "bound",
                  "verdicts (cert-in/CERT-OUT/uncert-in/uncert-out)")


def _params_text(params: Mapping[str, float], names: Sequence[str] = ()) -> str:
    """name = value, in the order of ``names`` (the box's), then any other."""
    order = [n for n in names if n in params] + [n for n in params if n not in names]
    return ", ".join(f"{k} = {params[k]:.4g}" for k in order)


def search_rows(summary: Summary) -> list[list[str]]:
    summary = ValidateSummary.of(summary)
    out = []
    for s in summary.searches:
        w, mc = s.get("worst") or {}, s.get("mc") or {}
        ratio = s["objective"] != "sup-E"
        m1_cert = summary.ladder[-1].certificate
        bound = "1 (region boundary)" if ratio else f"{_fmt(m1_cert.get('E_max'), '.4g')} rad (m1-box certificate)"
        v = s["verdicts"]
        out.append([s["title"], s["objective_label"], str(s["evaluations"]), _fmt(w.get("objective"), ".4g"),
                    _params_text(w.get("params", {}), s.get("names", ())),
                    f"{_fmt(mc.get('worst_objective'), '.4g')} ({mc.get('n')} runs, rung {mc.get('rung')})"
                    if mc else "none (no sweep of this box)", bound,
                    "/".join(str(v[k]) for k in VERDICTS) + (" !!!" if v["certified-outside"] else "")])
    return out


def search_lines(summary: Summary) -> list[str]:
    """The search beside the Monte-Carlo worst and the certificate, in sentences."""
    summary = ValidateSummary.of(summary)
    searches = summary.searches
    if not searches:
        return ["Worst-case search: not run (--search-budget 0)."]
    lines = [_tightness_line(s) for s in searches if s["objective"] == "certificate" and (s.get("worst") or {})
             .get("objective")]  # the section leads with how tight the certificate is
    for s in searches:
        w, mc = s.get("worst") or {}, s.get("mc")
        at = _params_text(w.get("params", {}), s.get("names", ()))
        how = (f"the vertices, then CMA-ES, {s['population']} per generation" if s.get("method") == "portfolio" else
               f"{s['generations']} generation(s) of {s['population']}")
        head = (f"Search, {s['title']}: worst {s['objective_label']} = {_fmt(w.get('objective'), '.4g')} at {at} "
                f"({s['evaluations']} runs: {how})")
        if mc:
            head += (f"; the Monte-Carlo worst of rung {mc['rung']} is {_fmt(mc['worst_objective'], '.4g')} "
                     f"({mc['n']} runs, m1 = {_fmt(mc['worst_m1'], '.0f')} kg): "
                     + _versus(w.get("objective"), mc["worst_objective"]))
        lines.append(head + ". " + _search_bound_sentence(s, summary))
    return lines


def _tightness_line(s: Mapping[str, Any]) -> str:
    """falsify's tightness sentence for a search against the certificate: the worst found (a lower bound on
    the worst case) beside the certificate's E_max (an upper bound)."""
    w, e_max = s["worst"], s["certificate"].get("E_max")
    x = w["objective"]
    return (f"Tightness ({s['title']}): the worst found is {x:.4g} of the certificate's bound: the certificate is "
            f"{1.0 / x:.3g} times the worst case found (sup|E| >= {_fmt(w.get('sup_E'), '.4g')} rad found by the "
            f"search, <= {_fmt(e_max, '.4g')} rad certified).")


def _versus(search: float | None, mc: float | None) -> str:
    """The search's worst against the Monte-Carlo worst, in words."""
    if search is None or mc is None:
        return "one of them is undefined"
    rel = (search - mc) / abs(mc) if mc else math.inf
    if search >= mc:
        return f"the search found a case at least as bad ({100 * rel:+.3g}%)"
    return (f"the search's worst is {100 * -rel:.2g}% below it: at this budget the search did not beat the "
            "Monte-Carlo sample")


def _search_bound_sentence(s: Mapping[str, Any], summary: ValidateSummary) -> str:
    w, cert = s.get("worst") or {}, s["certificate"]
    worst_ratio = max(x for x in (w.get("objective"), (s.get("mc") or {}).get("worst_objective"), -math.inf)
                      if x is not None)
    if s["objective"] == "paper":
        where = (f"is exceeded {worst_ratio:.3g} times over at its worst" if worst_ratio > 1.0 else
                 f"holds at its worst, at {worst_ratio:.3g} of its bound")
        claim = _claim(summary)
        text = (f"{claim[0].upper()}{claim[1:]} {where}; the design has "
                f"{'a certificate' if cert.get('certified') else 'no certificate'} to compare with.")
        rung = summary.ladder[(s.get("mc") or {}).get("rung", 1) - 1]
        if rung.hit_stop and cert.get("alpha0_max") is not None and cert.get("steering_range") is not None:
            text += (f" {rung.hit_stop}/{rung.n} runs of rung {rung.index} reached the steering stop, which "
                     f"caps sup|E| near max|alpha0| + stop = {cert['alpha0_max'] + cert['steering_range']:.4g} rad.")
        return text
    if s["objective"] == "certificate":
        slack = 1.0 / worst_ratio if worst_ratio > 0 else math.inf
        return (f"Tightness: the largest error found is {worst_ratio:.3f} of the certificate's E_max = "
                f"{_fmt(cert.get('E_max'), '.4g')} rad: the certificate is {slack:.2f} times the worst case found"
                + ("." if worst_ratio <= 1 else " -- OUTSIDE the certificate (see the banner)."))
    m1_cert = summary.ladder[-1].certificate
    names = ", ".join(s.get("names") or s["box"])
    if cert.get("certified"):
        head = f"Over the full box ({names}) the certificate holds: |E| <= {_fmt(cert.get('E_max'), '.4g')} rad."
    elif cert.get("valid") and cert.get("unmet") == [WITHIN_THE_SUPPLY]:
        head = (f"Over the full box ({names}) the certified design has no certificate: its bound |E| <= "
                f"{_fmt(cert.get('E_max'), '.4g')} rad needs {_fmt(cert.get('voltage_max'), '.4g')} V, more than the "
                f"{_fmt(_limit(cert, 'voltage_limit', 'within the supply'), 'g')} V supply.")
    else:
        head = f"Over the full box ({names}) the certified design has no certificate: not met: {_unmet_text(cert)}."
    ratio = _div(w.get("sup_E"), m1_cert.get("E_max"))
    return (head + f" The worst sup|E| the search found there, {_fmt(w.get('sup_E'), '.4g')} rad, is "
            f"{_fmt(ratio, '.3f')} of the m1-box certificate's E_max = {_fmt(m1_cert.get('E_max'), '.4g')} rad"
            + (" (beyond it: that certificate covers the m1 box only)" if ratio and ratio > 1 else "")
            + f"; the search's runs: {_counts(s['verdicts'])}.")


def _div(a: Any, b: Any) -> float | None:
    return None if a is None or not b else float(a) / float(b)


# --------------------------------------------------------------------------- (d) friction, (e) identification
FRICTION_COLUMNS = ("plant law", "F (2.13) V", "break-away V", "creep at 0.5 F rad/s", "creep at 0.9 F rad/s",
                    "rate at 1.3 F rad/s", "(2.13) predicts", "holds below break-away")


def _friction_laws(summary: ValidateSummary) -> list[tuple[str, Mapping[str, Any]]]:
    """The measured laws in the report's order (stiction first), whatever the mapping's order."""
    laws = summary.friction
    return [(n, laws[n]) for n in STEERING_FRICTION_MODELS if n in laws] + [
        (n, v) for n, v in laws.items() if n not in STEERING_FRICTION_MODELS]


def friction_rows(summary: Summary) -> list[list[str]]:
    out = []
    for name, law in _friction_laws(ValidateSummary.of(summary)):
        creep, slide = law["creep_rates"], law["slide_rates"]
        out.append([name, _fmt(law["friction_voltage"], ".4g"),
                    f"{_fmt(law['breakaway_voltage'], '.4g')} (+-{_fmt(law['breakaway_resolution'], '.1g')})",
                    _fmt(creep.get("0.5"), ".2g"), _fmt(creep.get("0.9"), ".2g"), _fmt(slide.get("1.3"), ".3g"),
                    _fmt(law["predicted_slide_rates"].get("1.3"), ".3g"), "yes" if law["holds"] else "NO (creeps)"])
    return out


IDENT_COLUMNS = ("coef", "identified", "+-", "paper", "diff", "nonholonomic", "diff", "unit")


def identification_rows(summary: Summary) -> list[list[str]]:
    ident = ValidateSummary.of(summary).identification
    se = ident.get("diagnostics", {}).get("std_error", {})
    out = []
    for k in COEFFICIENT_NAMES:
        row = [k, _fmt(ident["identified"][k], ".5g"), _fmt(se.get(k), ".2g")]
        for model in COEFFICIENT_MODELS:
            r = ident["relative_difference"][model][k]
            row += [_fmt(ident["predicted"][model][k], ".4g"), "n/a" if r is None else f"{100 * r:+.1f}%"]
        row.append(UNITS[k])
        out.append(row)
    return out


# --------------------------------------------------------------------------- (e) realistic sensing
SENSING_COLUMNS = ("sensing", "verdict", "its E_max rad", "sup|E|/E_max (exact)", "settled |E| rad", "RMS u V",
                   "TV u V/s", "max |u| V", "unmet (value vs limit)")


def sensing_rows(summary: Summary) -> list[list[str]]:
    """One row per run of summary.json's ``sensing`` (:mod:`wmr_mj.report.sensing`)."""
    out = []
    for r in (ValidateSummary.of(summary).sensing or {}).get("runs", []):
        plateau = r["settled_E"]
        name = r["sensing"] if r["label"] == r["sensing"] else f"{r['sensing']} ({r['label']})"
        out.append([name, r["verdict"], _fmt(r["certificate_E_max"], ".3g", "none"),
                    _fmt(r["sup_E_over_ideal_E_max"]), f"{_fmt(plateau['mean'])} ({_fmt(plateau['min'])}-"
                    f"{_fmt(plateau['max'])})", _fmt(r["rms_voltage"]), _fmt(r["tv_voltage"]),
                    _fmt(r["max_abs_voltage"]), format_unmet(r["unmet"]) or "-"])
    return out


def sensing_blocks(summary: Summary) -> list[Block]:
    """Section (e), where the report has it (reports written before it have no ``sensing``)."""
    summary = ValidateSummary.of(summary)
    sec = summary.sensing
    if not sec:
        return []
    return [("h2", f"(e) The certified design on realistic sensing (m1 = {sec['m1']:g} kg, {sec['duration']:g} s)"),
            ("table", SENSING_COLUMNS, sensing_rows(summary)),
            ("p", f"The law reads the encoder (alpha' its backward difference, filtered for the 14-bit preset); E is "
                  f"judged on the true state. Each run is judged against its own certificate, which covers the "
                  f"sensing's measurement errors or names the assumption it lacks; sup|E|/E_max is of the exact-"
                  f"measurement certificate (E_max = {_fmt(sec['ideal_E_max'], '.4g')} rad). TV u: total variation "
                  f"of the voltage per second. Settled |E|: mean (min-max) of |E| over the last "
                  f"{_fmt(sec['runs'][0]['settled_E']['window_s'], 'g')} s, beside the dead band F^/(P^ K_P) = "
                  f"{_fmt(sec['F_estimate'])}/({_fmt(sec['P_estimate'])} x {_fmt(sec['kp'], 'g')}) = "
                  f"{_fmt(sec['dead_band'])} rad, where the PD part alone supplies the Coulomb voltage once the "
                  f"differenced velocity reads 0.")]


CART_DESIGN_COLUMNS = ("design", "K_P 1/s^2", "K_D 1/s", "sign width rad/s", "certificate", "E_max rad", "needs V",
                       "runs (cert-in/CERT-OUT/uncert-in/uncert-out)", "worst sup|E| rad", "worst sup|E|/E_max",
                       "TV u V/s")


def cart_design_rows(summary: Summary) -> list[list[str]]:
    """One row per design of summary.json's ``cart_design`` (:mod:`wmr_mj.report.cart_design`)."""
    sec = ValidateSummary.of(summary).cart_design
    out = []
    for d in () if sec is None else sec.designs:
        v = d.verdicts
        out.append([d.label, _fmt(d.kp, ".6g"), _fmt(d.kd, ".6g"), _fmt(d.friction_width, ".4g"),
                    d.certificate or "none", _fmt(d.E_max, ".4g", "none"), _fmt(d.voltage_max, ".3g", "-"),
                    "/".join(str(v.get(k, 0)) for k in VERDICTS) + (" !!!" if d.certified_outside else ""),
                    _fmt(d.worst_sup_E, ".4g"), _fmt(d.worst_certificate_ratio, ".3f"), _fmt(d.mean_tv_voltage)])
    return out


#: what the design of the supply-weighing objective is, in section (e)'s words (a report of the E_max objective, or
#: one written before the search recorded it, keeps the E_max words)
_SUPPLY_WORDS = ("that certify on this cart with the least supply among those whose certificate over the box is "
                 "within 10 % of the smallest found")


def cart_design_blocks(summary: Summary) -> list[Block]:
    """The design ``wmr-mj design`` finds for the 12-bit axis encoder beside the certified design on it, in
    section (e), where the report has it (reports written before it have no ``cart_design``)."""
    summary = ValidateSummary.of(summary)
    sec = summary.cart_design
    if sec is None:
        return []
    search = sec.search
    found = ("" if not sec.binding else f" Nothing in the search's box certifies this cart: {sec.binding} binds; "
             "the row shows the best point found.")
    return [("h3", f"The design for {sec.sensing} ({sec.label}) beside the certified design, {sec.n} runs each "
                   f"over m1 {sec.m1_range[0]:g}-{sec.m1_range[1]:g} kg ({sec.sampling}, seed {sec.seed}), "
                   f"{sec.duration:g} s"),
            ("table", CART_DESIGN_COLUMNS, cart_design_rows(summary)),
            ("p", f"The design is what '{sec.command}' finds ({search['method']}, seed {search['seed']}, "
                  f"{search['evaluations']} certificates): the gains, sign width and period "
                  + (_SUPPLY_WORDS if search.get("objective") == "E_max-then-voltage" else
                     "whose certificate on this cart is the smallest over the box")
                  + f"; it is written to {sec.design_file} ('wmr-mj run "
                  f"--design {summary.folder}/{sec.design_file}') and swept as that file reads back. Both designs "
                  "run the same m1 draws on the same cart; each run is judged against its own design's "
                  "certificate, and sup|E|/E_max is of that certificate. TV u: the voltage's total variation per "
                  "second, the mean over the runs." + found)]


def cart_design_finding(sec: Any) -> str:
    """One sentence: the found design's certificate and runs beside the certified design's on the cart."""
    certified, designed = sec.designs[0], sec.designs[1]

    def runs(d: Any) -> str:
        return (f"{d.verdicts.get('certified-inside', 0)}/{d.n} runs certified-inside, worst sup|E| "
                f"{_fmt(d.worst_sup_E, '.3g')} rad = {_fmt(d.worst_certificate_ratio, '.3f')} of its E_max")

    def bound(d: Any) -> str:
        return "no certificate" if d.E_max is None else f"E_max {_fmt(d.E_max, '.3g')} rad ({d.certificate})"

    return (f"On the {sec.sensing} cart, '{sec.command}' finds K_P = {_fmt(designed.kp, '.4g')}, K_D = "
            f"{_fmt(designed.kd, '.4g')}: {bound(designed)}, {runs(designed)}; the certified design there has "
            f"{bound(certified)}, {runs(certified)}.")


def sensing_finding(section: Mapping[str, Any]) -> str:
    """One sentence: which presets keep the certificate, what the coarsest costs, where the dead band sits."""
    runs = section["runs"]
    ideal, others = runs[0], runs[1:]
    kept = [r["sensing"] for r in others if r["verdict"] == "certified-inside"]
    worst = max(others, key=lambda r: r["tv_voltage"]) if others else ideal
    return (f"On realistic sensing (m1 = {section['m1']:g} kg) the certified design's certificate still closes on "
            f"{len(kept)}/{len(others)} presets ({', '.join(kept) or 'none'}); the most active, {worst['sensing']}, "
            f"asks {worst['tv_voltage']:.3g} V/s of total variation of u against {ideal['tv_voltage']:.3g} V/s with "
            f"exact sensing, and its |E| settles at {worst['settled_E']['mean']:.3g} rad, beside "
            f"F^/(P^ K_P) = {section['dead_band']:.3g} rad.")


# --------------------------------------------------------------------------- (g) findings
def _rung_finding(before: Rung, r: Rung, claim: str) -> str:
    def step(key: str, fmt: str = "d") -> str:
        a, b = getattr(before, key), getattr(r, key)
        return f"{_fmt(a, fmt) if fmt != 'd' else a} -> {_fmt(b, fmt) if fmt != 'd' else b}"

    cb, ca = before.certificate, r.certificate
    cert = ("certificate: " + ("none" if not cb.get("certified") else f"E_max {_fmt(cb['E_max'])} rad") + " -> "
            + ("none" if not ca.get("certified") else f"E_max {_fmt(ca['E_max'], '.4g')} rad, all assumptions met"))
    paper = "" if r.paper_inside is None else f", inside {claim} {step('paper_inside')}"
    return (f"Rung {r.index} ({r.change}): certified-inside {step('passes')}{paper}, "
            f"at the stop {step('hit_stop')}, |E| growing {step('growing')} of {r.n}; "
            f"worst sup|E| {step('worst_sup_E', '.3g')} rad; {cert}.")


def _friction_finding(summary: ValidateSummary) -> list[str]:
    out = []
    for name, law in _friction_laws(summary):
        creep = ", ".join(f"{_fmt(v, '.2g')} rad/s at {k} F" for k, v in law["creep_rates"].items())
        out.append(f"Steering friction '{name}': break-away at {_fmt(law['breakaway_voltage'], '.4g')} V against "
                   f"F = {_fmt(law['friction_voltage'], '.4g')} V of (2.13); below it the joint "
                   f"{'holds' if law['holds'] else 'CREEPS'} ({creep}; holding means <= {law['hold_rate']:g} rad/s); "
                   f"at 1.3 F it slides at {_fmt(law['slide_rates'].get('1.3'), '.3g')} rad/s ((2.13) predicts "
                   f"{_fmt(law['predicted_slide_rates'].get('1.3'), '.3g')}, with the gyroscopic term "
                   f"{_fmt(law['predicted_slide_rates_gyro'].get('1.3'), '.3g')}).")
    return out


def _identification_finding(summary: ValidateSummary) -> list[str]:
    ident = summary.identification
    idv, se = ident["identified"], ident.get("diagnostics", {}).get("std_error", {})
    pp, nh = ident["predicted"]["paper"], ident["predicted"]["nonholonomic"]
    ratio = _div(idv["K"], pp["K"])
    absent = ratio is not None and abs(ratio) < 0.1
    K_text = ("the paper's K term (V(alpha) of (2.7)) has no counterpart in the plant, as the non-holonomic model "
              "predicts (K = 0)") if absent else "the plant does show a term of that form"
    return [f"Steering stiffness: the plant shows K = {idv['K']:.3g} V (+-{_fmt(se.get('K'), '.1g')}), "
            f"{_pct(ratio, '.1f')} of the paper's prediction {pp['K']:.4g} V: {K_text}.",
            f"Gyroscopic term: the plant shows {idv['gyro']:.3g} V s/m (+-{_fmt(se.get('gyro'), '.1g')}) on V_A "
            f"alpha'/cos^2(alpha), {_pct(_div(idv['gyro'], nh['gyro']))} of the non-holonomic prediction "
            f"{nh['gyro']:.3g} V s/m; the paper's model and its analysis (4.17)-(4.23) have no such term."]


def _paper_view_finding(summary: ValidateSummary) -> list[str]:
    ex = summary.paper_example
    if not ex:
        return []
    red = "; ".join(f"{r['case']}: sup|E| = {r['sup_E']:.3g} rad, sup|E'| = {r['sup_Edot']:.3g} rad/s"
                    for r in ex["reduced"])
    inside = all(r["sup_E"] <= ex["E_max"] and r["sup_Edot"] <= ex["Edot_max"] for r in ex["reduced"])
    return [f"Paper's view (Fig. 7): the same law on the reduced paper model as the plant ({red}) stays "
            f"{'inside' if inside else 'OUTSIDE'} the region of the paper's (5.1) example (E_max = {ex['E_max']:.3g} "
            f"rad, E'_max = {ex['Edot_max']:.3g} rad/s, (4.23) = {ex['condition']:.4f}; the paper reports 0.2613); "
            f"the MuJoCo plant is the rung-1 design at m1 = {summary.settings['nominal_m1']:g} kg."]


def _search_findings(summary: ValidateSummary) -> list[str]:
    searches = summary.searches
    if not searches:
        return ["No worst-case search was run (--search-budget 0)."]
    parts = []
    for s in searches:
        w, mc = s.get("worst") or {}, s.get("mc")
        text = f"{s['key']}: {_fmt(w.get('objective'), '.5g')} ({s['objective_label']}, {s['evaluations']} runs)"
        if mc:
            text += f" against the Monte-Carlo {_fmt(mc['worst_objective'], '.5g')} ({mc['n']} runs)"
        parts.append(text)
    out = ["Worst-case search: " + "; ".join(parts) + "."]
    logged = [s for s in searches if s.get("log")]
    bad = [s["key"] for s in logged if not s.get("reproduced")]
    out.append(f"The worst run of each search, re-run serially with an MCAP log (search-<key>/worst.mcap), gives "
               f"the search's sup|E| exactly in {len(logged) - len(bad)} of {len(logged)} searches"
               + (f"; NOT in {', '.join(bad)}: the batch and the serial run differ." if bad else "."))
    return out


def findings(summary: Summary) -> list[str]:
    """Plain-language statements of what this run shows, every number from ``summary``."""
    summary = ValidateSummary.of(summary)
    ladder = summary.ladder
    first, last = ladder[0], ladder[-1]
    out = [f"The paper's design keeps {first.paper_inside}/{first.n} runs inside {_claim(summary)} and has no "
           f"valid certificate ({', '.join(first.certificate['unmet']) or 'none unmet'}), so none of its runs is "
           f"a pass." if not first.certificate.get("certified") else
           f"The paper's design: {first.passes}/{first.n} certified-inside."]
    out += [_rung_finding(a, b, _claim(summary)) for a, b in zip(ladder, ladder[1:])]
    out.append(f"The certified design ({last.design}): {last.passes}/{last.n} runs certified-inside, worst "
               f"sup|E| = {_fmt(last.worst_sup_E, '.4g')} rad against E_max = "
               f"{_fmt(last.certificate.get('E_max'), '.4g')} rad.")
    out += _search_findings(summary)
    out += _friction_finding(summary) + _identification_finding(summary) + _paper_view_finding(summary)
    if summary.sensing:
        out.append(sensing_finding(summary.sensing))
    if summary.cart_design is not None and len(summary.cart_design.designs) == 2:
        out.append(cart_design_finding(summary.cart_design))
    n_out = summary.certified_outside
    out.append("No run of this report is certified-outside." if not n_out else
               f"!!! {n_out} run(s) are CERTIFIED-OUTSIDE: a bug or a modelling gap; report it. !!!")
    return out


# --------------------------------------------------------------------------- the document
def banner(summary: Summary) -> list[Block]:
    summary = ValidateSummary.of(summary)
    n = summary.certified_outside
    if not n:
        return []
    where = [f"rung {r.index} ({r.certified_outside})" for r in summary.ladder if r.certified_outside]
    where += [f"search {s['key']} ({s['verdicts']['certified-outside']})" for s in summary.searches
              if s["verdicts"]["certified-outside"]]
    if (summary.sensing or {}).get("certified_outside"):
        where.append(f"realistic sensing ({(summary.sensing or {})['certified_outside']})")
    if summary.cart_design is not None and summary.cart_design.certified_outside:
        where.append(f"the design for {summary.cart_design.sensing} ({summary.cart_design.certified_outside})")
    return [("loud", f"!!! CERTIFIED-OUTSIDE: {n} run(s) ({', '.join(where)}) are outside a certificate whose "
                     "assumptions all hold. This is a bug or a modelling gap: report it. !!!")]


def answer_blocks(summary: Summary, *, brief: bool = False, with_banner: bool = True) -> list[Block]:
    """Sections (a)-(d), after the certified-outside banner (``with_banner``); ``brief``
    (stdout): the rule in one sentence and the assumptions without their equations."""
    summary = ValidateSummary.of(summary)
    rung = summary.ladder[-1]
    assumptions = assumption_rows(rung.certificate)
    header: tuple[str, ...] = ASSUMPTION_COLUMNS
    if brief:
        header, assumptions = tuple(c for c in header if c != "equation"), [r[:1] + r[2:] for r in assumptions]
    return [
        *(banner(summary) if with_banner else []),
        ("h2", "(a) The paper's design"),
        ("ul", paper_design_lines(summary)),
        ("h2", "(b) The ladder: from the paper's design to the certified one, one change per rung"),
        ("table", LADDER_COLUMNS, ladder_rows(summary)),
        ("p", "cert-in = certified-inside, the only pass; CERT-OUT = certified-outside (a bug or a modelling gap); "
              "uncert-* = an assumption of the certificate fails: never a pass. paper in: inside "
              f"{_claim_4_21(ValidateSummary.of(summary))}; sup|E|/E_max: of the certificate; stop: reached the "
              "steering stop; growing: |E| still growing at the end."),
        ("h2", "(c) The certified design"),
        ("ul", certified_lines(summary, brief=brief)),
        ("h3", "Its certificate, every assumption"),
        ("table", header, assumptions),
        *([("h3", "Worst-case search vs Monte Carlo vs certificate"), ("table", SEARCH_COLUMNS, search_rows(summary))]
          if summary.searches else []),
        ("h2", "(d) The plant's measured friction law (steering joint, m1 = "
               f"{summary.settings['nominal_m1']:g} kg, constant voltages from the home keyframe)"),
        ("table", FRICTION_COLUMNS, friction_rows(summary)),
        *sensing_blocks(summary),
        *cart_design_blocks(summary),
    ]


def _path_words(settings: Mapping[str, Any]) -> str:
    """The runs' path of C in words: 'the paper circle' (also for reports written before --path)."""
    path = settings.get("path", "paper-circle")
    return "the paper circle" if path == "paper-circle" else f"the path {path_name(path)}"


def _settings_line(summary: Summary) -> str:
    # only the settings are read: a mapping that holds just them will do (tests give one)
    s = summary.settings if isinstance(summary, ValidateSummary) else summary["settings"]
    box = s.get("uncertainty", "m1")
    search = (f"search budget {s['search_budget']} runs per {box}-box search" if s["search_budget"] else "no search")
    others = "" if box == "m1" else " and the rest of the full uncertainty box (wmr_mj/params.py)"
    return (f"{s['n']} runs per rung, {s['sampling']} sampling of m1 over {s['m1_range'][0]:g}-{s['m1_range'][1]:g} "
            f"kg{others}, seed {s['seed']}, {s['duration']:g} s per run on {_path_words(s)}; {search}; identification "
            f"{s['identify_duration']:g} s at m1 = {s['nominal_m1']:g} kg" + _cart_words(s))


def _cart_words(settings: Mapping[str, Any]) -> str:
    """'; cart: ...' naming the parts of the cart that are not ideal (the settings carry only those); '' for
    today's plant."""
    parts = [(name, cls) for name, cls in (("sensing", Sensing), ("actuation", Actuation),
                                           ("transmission", Transmission)) if settings.get(name)]
    return "".join(("; cart: " if i == 0 else ", ") + f"{name} {cls.from_spec(settings[name]).label()}"
                   for i, (name, cls) in enumerate(parts))


def fig4_caption(summary: Summary) -> str:
    """The caption of Fig. 4 under the answer."""
    return (f"Fig. 4: C's desired path and the paths C travelled under the paper's design and the certified design "
            f"(MuJoCo plant, m1 = {ValidateSummary.of(summary).settings['nominal_m1']:g} kg)")

FIGURE_GROUPS = (
    ("The ladder", [("verdict counts per rung", "ladder")]),
    ("Every run of each rung by verdict, with the certificate's region and {claim}", None),
    ("Nominal runs (m1 = {nominal_m1:g} kg)", [("the paper's design: E, E', voltage", "history_paper"),
                                    ("the certified design: E, E', voltage", "history_certified")]),
    ("Worst-case search", [("each run's objective, the running worst, the Monte-Carlo worst", "search_history")]),
    ("The paper's figures", [("Fig. 4 desired path and the paths C travelled", "fig4_trajectory"),
                             ("Fig. 5 alpha0(t)", "fig5_alpha0"),
                             ("Fig. 6 alpha0'(t), alpha0''(t)", "fig6_alpha0_rates"),
                             ("Fig. 7 region of the (5.1) example, the paper's view and the MuJoCo plant",
                              "fig7_region")]),
)


def _figure_blocks(summary: ValidateSummary) -> list[Block]:
    figs = summary.figures
    out: list[Block] = []
    for heading, items in FIGURE_GROUPS:
        if items is None:
            items = [(f"rung {r.index}: {r.label}", f"rung_{r.index}_{r.name}") for r in summary.ladder]
        items = [(c, s) for c, s in items if s in figs]
        if items:
            words = {"claim": _claim(summary), "nominal_m1": summary.settings["nominal_m1"]}
            out += [("h3", heading.format(**words)), ("figures", items)]
    return out


def _files(summary: ValidateSummary) -> list[tuple[str, str]]:
    out = [("summary.json", "every number of this report"), ("summary.csv", "one row per rung"),
           ("identified.json", "the identification")]
    out += [(r.runs_csv, f"per-run results of rung {r.index} ({r.label})") for r in summary.ladder]
    for s in summary.searches:
        out.append((s["evaluations_csv"], f"every run of the search '{s['key']}'"))
        if s.get("log"):
            out.append((s["log"], f"the worst run of the search '{s['key']}' (wmr-mj replay opens it)"))
    if summary.cart_design is not None:
        sec = summary.cart_design
        out.append((sec.design_file, f"the design for {sec.sensing} (wmr-mj run --design FILE reads it)"))
        out += [(d.runs_csv, f"per-run results of {d.label} on {sec.sensing}") for d in sec.designs]
    return out


def document(summary: Summary) -> list[Block]:
    """The whole report as blocks, the answer first."""
    summary = ValidateSummary.of(summary)
    ident = summary.identification
    lead = [("lead", fig4_caption(summary), "fig4_trajectory")] if "fig4_trajectory" in summary.figures else []
    return [
        ("answer", verdict_lines(summary)),
        *banner(summary),
        *lead,
        ("h1", "wmr-mj validate: does the paper's steering controller keep its promise on the MuJoCo "
               f"{_vehicle(summary).removeprefix('the ')}?"),
        ("p", f"{summary.created} - {_settings_line(summary)}."),
        *answer_blocks(summary, with_banner=False),
        ("h2", f"(f) Identification (m1 = {ident['m1']:g} kg, {ident['duration']:g} s excitation)"),
        ("table", IDENT_COLUMNS, identification_rows(summary)),
        ("p", "diff = (identified - predicted) / |predicted|."),
        ("h2", "(g) Findings"),
        ("ul", list(summary.findings)),
        ("h2", "Figures"),
        *_figure_blocks(summary),
        ("h2", "Files"),
        ("files", _files(summary)),
        ("h2", "Software"),
        ("p", ", ".join(f"{k} {v}" for k, v in summary.versions.items())),
    ]


# --------------------------------------------------------------------------- renderers
def _text_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    table = [list(header), *[list(r) for r in rows]]
    widths = [max(len(r[i]) for r in table) for i in range(len(header))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in table]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return lines


def format_headline(summary: Summary) -> str:
    """The answer as text (what ``wmr-mj validate`` prints on stdout)."""
    summary = ValidateSummary.of(summary)
    out = [*verdict_lines(summary)]
    out += [line for b in banner(summary) for line in ("", b[1])]
    out += ["", f"wmr-mj validate - {_settings_line(summary)}"]
    for block in answer_blocks(summary, brief=True, with_banner=False):
        kind = block[0]
        if kind == "loud":
            out += ["", block[1], ""]
        elif kind in ("h2", "h3"):
            out += ["", block[1] + ":"]
        elif kind == "p":
            out.append(block[1])
        elif kind == "ul":
            out += [f"- {line}" for line in block[1]]
        elif kind == "table":
            out += _text_table(block[1], block[2])
    return "\n".join(out)


def _md_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    esc = [[c.replace("|", "\\|") for c in r] for r in [list(header), *rows]]
    lines = ["| " + " | ".join(esc[0]) + " |", "|" + "|".join("---" for _ in header) + "|"]
    return "\n".join(lines + ["| " + " | ".join(r) + " |" for r in esc[1:]])


def _fig_path(summary: ValidateSummary, stem: str, ext: str) -> str:
    return next((p for p in summary.figures[stem] if p.endswith("." + ext)), summary.figures[stem][0])


def render_markdown(summary: Summary) -> str:
    summary = ValidateSummary.of(summary)
    out: list[str] = []
    for block in document(summary):
        kind = block[0]
        if kind in ("h1", "h2", "h3"):
            out += [{"h1": "#", "h2": "##", "h3": "###"}[kind] + " " + block[1], ""]
        elif kind == "p":
            out += [block[1], ""]
        elif kind == "answer":  # the five lines, one per line (Markdown hard breaks)
            out += [line + "  " for line in block[1][:-1]] + [block[1][-1], ""]
        elif kind == "loud":
            out += [f"> **{block[1]}**", ""]
        elif kind == "ul":
            out += [*(f"- {line}" for line in block[1]), ""]
        elif kind == "table":
            out += [_md_table(block[1], block[2]), ""]
        elif kind in ("figures", "lead"):
            for caption, stem in (block[1] if kind == "figures" else [block[1:]]):
                out += [f"[![{caption}]({_fig_path(summary, stem, 'png')})]({_fig_path(summary, stem, 'svg')})", "",
                        f"*{caption}*", ""]
        elif kind == "files":
            out += [*(f"- `{path}`: {what}" for path, what in block[1]), ""]
    return "\n".join(out)


_CSS = """body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1200px;
margin:2em auto;padding:0 1em;color:#222;line-height:1.4}table{border-collapse:collapse;margin:.5em 0 1em;
font-size:.9em}th,td{border:1px solid #ccc;padding:.25em .5em;text-align:left}th{background:#f2f4f7}
figure{display:inline-block;margin:.5em;vertical-align:top;max-width:48%}figure img{max-width:100%;
border:1px solid #ddd}figcaption{font-size:.85em;color:#555}code{background:#f4f4f4;padding:0 .2em}
.small{font-size:.85em;color:#555}.answer{margin:0 0 .4em}.answer p{margin:.15em 0}
.answer .question{font-size:1.2em;font-weight:bold}figure.lead{display:block;max-width:none;margin:.3em 0 1em}
figure.lead img{max-height:520px;max-width:100%;width:auto}
.loud{background:#fde2e2;border:2px solid #e00000;padding:.6em;font-weight:bold}"""


def _html_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    h = "".join(f"<th>{html.escape(c)}</th>" for c in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><thead><tr>{h}</tr></thead><tbody>{body}</tbody></table>"


def _html_block(block: Block, summary: ValidateSummary) -> str:
    e = html.escape
    kind = block[0]
    if kind in ("h1", "h2", "h3"):
        return f"<{kind}>{e(block[1])}</{kind}>"
    if kind == "p":
        return f"<p>{e(block[1])}</p>"
    if kind == "loud":
        return f"<p class='loud'>{e(block[1])}</p>"
    if kind == "answer":
        first, *rest = block[1]
        return ("<section id='answer' class='answer'>" + f"<p class='question'>{e(first)}</p>"
                + "".join(f"<p>{e(line)}</p>" for line in rest) + "</section>")
    if kind == "ul":
        return "<ul>" + "".join(f"<li>{e(line)}</li>" for line in block[1]) + "</ul>"
    if kind == "table":
        return _html_table(block[1], block[2])
    if kind == "lead":
        caption, stem = block[1], block[2]
        return (f"<figure class='lead'><a href='{e(_fig_path(summary, stem, 'svg'))}'><img src='"
                f"{e(_fig_path(summary, stem, 'png'))}' alt='{e(caption)}'></a><figcaption>{e(caption)}</figcaption>"
                "</figure>")
    if kind == "figures":
        return "<div>" + "".join(
            f"<figure><a href='{e(_fig_path(summary, stem, 'svg'))}'><img src='{e(_fig_path(summary, stem, 'png'))}' "
            f"alt='{e(caption)}'></a><figcaption>{e(caption)}</figcaption></figure>" for caption, stem in block[1]
        ) + "</div>"
    if kind == "files":
        return "<ul>" + "".join(f"<li><a href='{e(p)}'>{e(p)}</a>: {e(w)}</li>" for p, w in block[1]) + "</ul>"
    raise ValueError(f"unknown block kind {kind!r}")


def render_html(summary: Summary) -> str:
    summary = ValidateSummary.of(summary)
    parts = ["<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>", "<title>wmr-mj validate</title>",
             f"<style>{_CSS}</style></head><body>"]
    parts += [_html_block(b, summary) for b in document(summary)]
    parts += ["</body></html>", ""]
    return "\n".join(parts)


SUMMARY_CSV_COLUMNS = ("rung", "name", "design", "certificate_valid", "certificate_E_max", "certificate_Edot_max",
                       "certificate_voltage_max", "unmet", "n", *VERDICTS, "paper_inside", "worst_sup_E",
                       "worst_certificate_ratio", "worst_paper_ratio", "hit_stop", "growing", "runs_csv",
                       "worst_path_cross_track")


def summary_csv(summary: Summary) -> str:
    """summary.csv: one row per rung (floats round-trip: repr)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(SUMMARY_CSV_COLUMNS)
    for r in _all_rungs(ValidateSummary.of(summary)):
        c = r.certificate
        row = [r.index, r.name, r.design, c["certified"], c.get("E_max"), c.get("Edot_max"),
               c.get("voltage_max"), " ".join(x.replace(" ", "_") for x in c["unmet"]), r.n,
               *(r.verdicts[v] for v in VERDICTS),
               r.paper_inside, r.worst_sup_E, r.worst_certificate_ratio, r.worst_paper_ratio,
               r.hit_stop, r.growing, r.runs_csv, r.worst_path_cross_track]
        w.writerow(["" if x is None else (repr(x) if isinstance(x, float) else x) for x in row])
    return buf.getvalue()
