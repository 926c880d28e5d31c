"""Separated verdicts: how every run is judged (run, sweep, validate, the report, the MCAP summary).

A run's (sup|E|, sup|E'|) is judged against the certificate of the controller actually
run (:mod:`wmr_mj.analysis.certificate`), and, beside it, against the paper's claim (the region of
:mod:`wmr_mj.analysis.robustness`, (4.21)-(4.23) as the paper bounds it):

* ``certified-inside``: every assumption of the certificate holds and the run is inside it;
* ``certified-outside``: the assumptions hold and the run is outside: a bug or a
  modelling gap, printed loudly;
* ``uncertified-inside`` / ``uncertified-outside``: an assumption is not met; never a pass.

Beside the verdict: the paper's-claim verdict, the tightness sup|E|/E_max of the
certificate, and the end-of-run drift: the final alpha' and whether |E| is still growing
(the largest |E| of the last :data:`DRIFT_WINDOW_S` seconds exceeds that of the window
before it by more than :data:`DRIFT_TOLERANCE`).

Usage::

    from wmr_mj.analysis.verdicts import judge_run, is_pass
    judged = judge_run(certificate=cert, analysis=analysis, sup_E=0.03, sup_Edot=0.2,
                       drift=drift(prev_window=0.02, last_window=0.02, final_alpha_dot=0.0))
    judged.verdict, judged.paper_region.inside, judged.drift.growing
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from wmr_mj.analysis.certificate import VERDICTS, Certificate, CertificateJudgement, judge
from wmr_mj.analysis.claim_types import MeasurementCause
from wmr_mj.analysis.measurement import DELAY_FIXED_POINT, MEASUREMENT_COVERED

__all__ = [
    "CART_ASSUMPTIONS",
    "WITHIN_THE_SUPPLY",
    "VERDICTS",
    "PASS",
    "NO_CLAIM",
    "FAILED",
    "OUTSIDE_THE_BOX",
    "DRIFT_WINDOW_S",
    "DRIFT_TOLERANCE",
    "Drift",
    "PaperRegion",
    "RunJudgement",
    "drift",
    "drift_window_steps",
    "judge_run",
    "paper_region",
    "is_pass",
    "count_verdicts",
    "CERTIFIED_OUTSIDE",
    "certified_outside_banner",
    "unmet_assumptions",
    "count_unmet",
    "partial_text",
    "format_unmet",
    "format_measurement_cause",
    "format_delta1_parts",
]

PASS = "certified-inside"
#: The verdict of a run whose controller states no claim: judged by its requirements only, never a pass.
NO_CLAIM = "no-claim"
#: The verdict of a run whose law (or tracker) failed mid-run (raised, returned NaN or not one voltage).
FAILED = "failed"
#: Name (prefix) of the assumption a plant outside the certificate's box fails (wmr_mj.sim.certify).
OUTSIDE_THE_BOX = "plant inside the box"
#: The verdict of a run that breaks its law's claim: every assumption holds and the run is outside.
CERTIFIED_OUTSIDE = "certified-outside"
#: Length of each of the two windows that compare |E| at the end of a run, s.
DRIFT_WINDOW_S = 5.0
#: |E| grows when the last window's max exceeds the previous window's by more than this, rad.
#: The stiction plant creeps at a few urad/s below break-away (model card): 25 urad per window.
DRIFT_TOLERANCE = 1e-4


def drift_window_steps(control_steps: int, period: float) -> int:
    """Control steps per drift window: DRIFT_WINDOW_S, or a quarter of a shorter run (>= 1)."""
    w = int(round(DRIFT_WINDOW_S / period))
    return max(1, min(w, control_steps // 4))


@dataclass(frozen=True)
class Drift:
    """End of the run: is |E| still growing? (:func:`drift`)

    Attributes:
        final_alpha_dot: alpha' at the last control step [rad/s].
        growing: the last window's max |E| exceeds the previous window's by more than ``tolerance``
            (or either is not finite: a diverged run is not settled).
        E_last_window: max |E| over the last window [rad].
        E_prev_window: max |E| over the window before it [rad].
        window_s: the length of each window [s] (:data:`DRIFT_WINDOW_S`).
        tolerance: the growth that counts [rad] (:data:`DRIFT_TOLERANCE`).
    """

    final_alpha_dot: float
    growing: bool
    E_last_window: float
    E_prev_window: float
    window_s: float = DRIFT_WINDOW_S
    tolerance: float = DRIFT_TOLERANCE

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, the run summary's drift keys."""
        return {"final_alpha_dot": self.final_alpha_dot, "growing": self.growing,
                "E_last_window": self.E_last_window, "E_prev_window": self.E_prev_window,
                "window_s": self.window_s, "tolerance": self.tolerance}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Drift:
        """The drift of its JSON ``d`` (what :meth:`to_dict` wrote)."""
        return cls(**d)


@dataclass(frozen=True)
class PaperRegion:
    """The paper's claim judged for one run: the region (4.21)-(4.23) as the paper bounds it.

    Attributes:
        E_max: the bound on |E| [rad]; inf when (4.23) fails.
        Edot_max: the bound on |E'| [rad/s]; inf when (4.23) fails.
        condition: the left side of (4.23) [-].
        inside: the run's sup|E| <= E_max and sup|E'| <= Edot_max (and (4.23) holds).
    """

    E_max: float
    Edot_max: float
    condition: float
    inside: bool

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, the run summary's paper_region keys (inf stays inf; the writers make it null)."""
        return {"E_max": self.E_max, "Edot_max": self.Edot_max, "condition": self.condition, "inside": self.inside}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> PaperRegion:
        """The region of its JSON ``d`` (what :meth:`to_dict` wrote; a null bound, as a JSON file writes inf, is
        inf again)."""
        return cls(E_max=_inf_if_none(d["E_max"]), Edot_max=_inf_if_none(d["Edot_max"]),
                   condition=_inf_if_none(d["condition"]), inside=d["inside"])


def _inf_if_none(x: float | None) -> float:
    """A bound as JSON wrote it: null (inf, as the writers make it) is inf."""
    return math.inf if x is None else x


@dataclass(frozen=True)
class RunJudgement:
    """:func:`judge_run`: the verdict of one run and what it rests on."""

    verdict: str
    certificate: CertificateJudgement
    paper_region: PaperRegion
    drift: Drift | None


def drift(*, prev_window: float, last_window: float, final_alpha_dot: float,
          last_halves: tuple[float, float] | None = None) -> Drift:
    """The end-of-run drift.

    A run that settles onto a larger steady |E| (a transient that rose through the previous window, then a
    plateau) has a last window above the previous one, yet is settled: growth counts only where it goes on
    through the last window itself, its second half above its first by more than half the tolerance (the same
    rate, :data:`DRIFT_TOLERANCE` per :data:`DRIFT_WINDOW_S`, over half the time). A settled |E| (constant to
    the last bits) never grows; |E| that rises at that rate or faster to the end does.

    Args:
        prev_window: max |E| over the window before the last [rad].
        last_window: max |E| over the last window [rad].
        final_alpha_dot: alpha' at the last control step [rad/s].
        last_halves: max |E| over the first and the second half of the last window [rad]; None (or a
            window of one step): the two windows alone judge.

    Returns:
        Drift: growing when the last window exceeds the previous by more than :data:`DRIFT_TOLERANCE` and
        (with ``last_halves``) the last window's second half exceeds its first by more than half of it, or
        when either window is not finite.
    """
    growing = bool(math.isfinite(last_window) and math.isfinite(prev_window)
                   and last_window - prev_window > DRIFT_TOLERANCE)
    if growing and last_halves is not None:
        first, second = last_halves
        growing = bool(not (math.isfinite(first) and math.isfinite(second))
                       or second - first > 0.5 * DRIFT_TOLERANCE)
    if not (math.isfinite(last_window) and math.isfinite(prev_window)):
        growing = True  # a diverged run is not settled
    return Drift(final_alpha_dot=float(final_alpha_dot), growing=growing, E_last_window=float(last_window),
                 E_prev_window=float(prev_window), window_s=DRIFT_WINDOW_S, tolerance=DRIFT_TOLERANCE)


def paper_region(analysis: Any, sup_E: float, sup_Edot: float) -> PaperRegion:
    """The paper's claim judged: its bounds (inf when (4.23) fails) and whether the run is inside.

    Args:
        analysis: a :class:`wmr_mj.analysis.robustness.RobustnessResult`.
        sup_E: the run's sup|E| [rad].
        sup_Edot: the run's sup|E'| [rad/s].
    """
    stable = bool(analysis.stable)
    E_max = float(analysis.E_max) if stable else math.inf
    Ed_max = float(analysis.Edot_max) if stable else math.inf
    return PaperRegion(E_max=E_max, Edot_max=Ed_max, condition=float(analysis.condition),
                       inside=bool(stable and sup_E <= E_max and sup_Edot <= Ed_max))


def judge_run(*, certificate: Certificate, analysis: Any, sup_E: float, sup_Edot: float,
              drift: Drift | None) -> RunJudgement:
    """verdict, certificate (judged), paper_region (the paper's claim, judged) and drift of one run.

    Args:
        certificate: the run's certificate.
        analysis: the paper's region for the run (a ``RobustnessResult``).
        sup_E: the run's sup|E| [rad].
        sup_Edot: the run's sup|E'| [rad/s].
        drift: the run's end-of-run drift (:func:`drift`); None: not measured.
    """
    judged = judge(certificate, sup_E, sup_Edot)
    return RunJudgement(verdict=judged.verdict, certificate=judged,
                        paper_region=paper_region(analysis, sup_E, sup_Edot), drift=drift)


def is_pass(verdict: str) -> bool:
    """Only ``certified-inside`` is a pass."""
    return verdict == PASS


def count_verdicts(verdicts: Iterable[str]) -> dict[str, int]:
    """{verdict: count} for each of the four verdicts (zeros included)."""
    counts = dict.fromkeys(VERDICTS, 0)
    for v in verdicts:
        counts[v] = counts.get(v, 0) + 1
    return counts


def _num(x: Any, spec: str = ".5g") -> str:
    return "n/a" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, spec)


#: What every output says of the paper's region for a law outside the paper's family.
PAPER_CLAIM_NOT_APPLICABLE = "not applicable (its region is for the paper's computed-torque law, not this one)"
#: What outputs call the region (4.21)-(4.23) of the paper's analysis on a cart that is not the paper's C80: the
#: paper claims it for its C80 only (:func:`paper_region_name`).
PAPER_REGION_ON_CART = "the (4.21)-(4.23) region on this cart"


def paper_region_name(on_c80: bool) -> str:
    """The name of the region (4.21)-(4.23) in an output: "the paper's claim" on the paper's C80 (``on_c80``: the
    run's cart record is None), else :data:`PAPER_REGION_ON_CART`, the paper's analysis on a cart it never claimed."""
    return "the paper's claim" if on_c80 else PAPER_REGION_ON_CART


def certified_outside_banner(where: str = "") -> str:
    """The one banner of a broken claim, as ``run`` prints it above its verdict and ``falsify``, ``sweep``
    and ``compare`` print it above the run that broke it.

    Args:
        where: the run (or runs) that broke it, e.g. "search run 7 of 16"; empty: this run.
    """
    subject = f"{where}: " if where else ""
    return (f"!!! CERTIFIED-OUTSIDE: {subject}every assumption of the certificate holds and the run is OUTSIDE it. "
            "This is a bug or a modelling gap: report it. !!!")


#: The assumptions about the cart (sensing, actuation, play) whose value and limit say little alone (1 vs 0:
#: not covered): an unmet one carries its note (why: what has no derived bound) wherever it is listed.
CART_ASSUMPTIONS = (MEASUREMENT_COVERED, DELAY_FIXED_POINT)
#: The assumption that the law's voltage stays within the supply (section 4's certificate and the box claim
#: both make it under this name; the report says why a certificate fails when only it is unmet).
WITHIN_THE_SUPPLY = "within the supply"


def unmet_assumptions(certificate: Mapping[str, Any] | None) -> list[dict[str, Any]]:
    """The assumptions a judged certificate does not meet, each as {name, value, limit} (value and limit
    in the assumption's own units; None where not finite), in the certificate's order; an assumption about
    the cart (:data:`CART_ASSUMPTIONS`) also with its ``note`` (why it is not met), the others without (the
    JSON of a run on an ideal cart keeps its keys).

    Args:
        certificate: a certificate's JSON (``Certificate.to_dict()``, a run summary's ``certificate``);
            None or one without ``assumptions`` (a slim summary, a law without a claim): [].
    """
    return [{"name": str(a.get("name")), "value": a.get("value"), "limit": a.get("limit"),
             **({"note": a.get("note")} if a.get("name") in CART_ASSUMPTIONS and a.get("note") else {})}
            for a in (certificate or {}).get("assumptions") or [] if not a.get("met")]


def count_unmet(per_run: Iterable[Iterable[Mapping[str, Any]]]) -> list[dict[str, Any]]:
    """Each assumption unmet in some run, once, in the order first met: {name, value, limit} of the first
    run that does not meet it, ``runs``, how many do not, and, where the runs' finite values differ,
    ``value_range`` [lo, hi] over them (the assumption's units). A cart assumption's ``note`` quotes the
    range over the runs of each number that differs between their notes (``b = 0.001-0.01 rad``), so that
    no aggregate quotes one run's value as the runs'.

    Args:
        per_run: each run's unmet assumptions ({name, value, limit}: :func:`unmet_assumptions`).
    """
    seen: dict[str, dict[str, Any]] = {}
    values: dict[str, list[float]] = {}
    notes: dict[str, list[str]] = {}
    for unmet in per_run:
        for a in unmet:
            name = str(a["name"])
            first = {"name": name, "value": a.get("value"), "limit": a.get("limit"),
                     **({"note": a["note"]} if a.get("note") and a["name"] in CART_ASSUMPTIONS else {}), "runs": 0}
            seen.setdefault(name, first)["runs"] += 1
            value = a.get("value")
            if isinstance(value, (int, float)) and math.isfinite(value):
                values.setdefault(name, []).append(float(value))
            if a.get("note") and name in CART_ASSUMPTIONS:
                notes.setdefault(name, []).append(str(a["note"]))
    for name, entry in seen.items():
        finite = values.get(name, [])
        if finite and min(finite) != max(finite):
            entry["value_range"] = [min(finite), max(finite)]
        if "note" in entry:
            entry["note"] = merged_note(notes[name])
    return list(seen.values())


def _which_certificate(cert: dict) -> str:
    """Which analysis gave the run's certificate: section 4's condition (4.23), or, where a cart that is not
    ideal gave the sampled-data certificate the smaller bound (:func:`wmr_mj.sim.certify.certificate_of`), its
    name beside what section 4 gave (and, on a cart whose delay split is unknown, that every split was covered)."""
    inputs = cert.get("inputs") or {}
    if inputs.get("certificate") != "sampled-data":
        return f"(4.23) = {_num(cert.get('condition'), '.4f')}"
    record = inputs.get("certificates") or {}
    name = "boundary-layer" if "boundary-layer" in record else "section-4"  # the sliding-mode law's own claim
    other = record.get(name) or {}
    section4 = (f"|E| <= {_num(other.get('E_max'))} rad" if other.get("E_max") is not None
                else f"none: {other.get('reason') or 'no finite bound'}")
    label = "the boundary layer's" if name == "boundary-layer" else "section 4's"
    split = inputs.get("delay_split")  # a delay known as its sum: every split certified (analysis/delay_split.py)
    over = f"{split['label']}; " if isinstance(split, dict) and split.get("label") else ""
    return f"the sampled-data certificate ({over}{label}: {section4})"


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def merged_note(notes: Sequence[str]) -> str:
    """One note for many runs' notes of one assumption: notes that are the same text but for their numbers are
    one, each number that differs between them its range over those runs, 'LO-HI' (as the notes write them);
    notes whose words differ (another reason) are each given so, with how many runs gave it, ' | ' between.

    Args:
        notes: the runs' notes, in run order (at least one).
    """
    groups: dict[tuple[str, ...], list[str]] = {}
    for note in notes:  # in the order first met
        groups.setdefault(tuple(_NUMBER.split(note)), []).append(note)

    def merged(skeleton: tuple[str, ...], members: list[str]) -> str:
        pieces = [skeleton[0]]
        for texts, tail in zip(zip(*(_NUMBER.findall(n) for n in members)), skeleton[1:]):
            lo, hi = min(texts, key=float), max(texts, key=float)
            pieces += [lo if float(lo) == float(hi) else f"{lo}-{hi}", tail]
        return "".join(pieces)

    if len(groups) == 1:
        ((skeleton, members),) = groups.items()
        return merged(skeleton, members)
    return " | ".join(f"{merged(k, m)} ({len(m)} run{'s' if len(m) > 1 else ''})" for k, m in groups.items())


def format_unmet(unmet: Iterable[Mapping[str, Any]]) -> str:
    """'name (value vs limit); ...' of unmet assumptions ({name, value, limit}: :func:`unmet_assumptions`); an
    assumption about the cart (:data:`CART_ASSUMPTIONS`) with its note, 'name (value vs limit: note)'."""
    def why(a: Mapping[str, Any]) -> str:
        return f": {a['note']}" if a.get("note") and a.get("name") in CART_ASSUMPTIONS else ""

    def value(a: Mapping[str, Any]) -> str:
        span = a.get("value_range")  # over the runs (count_unmet), where their values differ
        return (f"{_num(span[0], '.4g')}-{_num(span[1], '.4g')}" if span else _num(a.get("value"), ".4g"))

    return "; ".join(f"{a['name']} ({value(a)} vs {_num(a.get('limit'), '.4g')}{why(a)})" for a in unmet)


def partial_text(summary: Mapping[str, Any]) -> str:
    """Beside the verdict of a run whose reference does not cover its route or manoeuvre (``route_finished``
    False: a lane change cut short by the duration, an open route longer than the run): PARTIAL, how much it
    covers and what duration covers it; '' otherwise."""
    if summary.get("route_finished") is not False:
        return ""
    driven, length = summary.get("route_driven_m"), summary.get("route_length_m")
    if not isinstance(driven, (int, float)) or not isinstance(length, (int, float)) or length <= 0:
        return ""
    return (f"  -- PARTIAL: the run's reference covers {driven:.3g} m of the {length:.3g} m its path must drive "
            f"({100 * driven / length:.0f}%), and the verdict that part only: give a longer --duration to judge "
            "the whole manoeuvre")


def format_verdict(summary: Mapping[str, Any]) -> list[str]:
    """Text lines of a judged run summary: the verdict first, then both regions and the drift.

    Args:
        summary: the summary as written (``RunSummary.to_dict()``, or an MCAP log's summary,
            also one written before verdicts existed).
    """
    verdict = summary.get("verdict")
    if verdict is None:
        return ["no certificate in this summary (written before verdicts existed)"]
    if verdict == FAILED:
        return [f"verdict: FAILED -- not a pass: {summary.get('failure', 'the controller failed')}"]
    if verdict == NO_CLAIM:
        return [f"verdict: NO-CLAIM -- not a pass: controller {summary.get('controller')!r} states no claim; "
                "the run is judged by its requirements only (--require)"]
    cert = summary.get("certificate") or {}
    paper = summary.get("paper_region") or {}
    dr = summary.get("drift") or {}
    lines = []
    if verdict == CERTIFIED_OUTSIDE:
        lines.append(certified_outside_banner())
    ratio = cert.get("E_ratio")
    no_region = cert.get("valid") is False  # no bound: the run is neither inside nor outside of anything
    lines.append(f"verdict: {verdict.upper()}"
                 + ("" if ratio is None else f"  (tightness sup|E|/E_max = {ratio:.3f})")
                 + ("" if is_pass(verdict) else "  -- not a pass") + partial_text(summary)
                 + (": no certificate, so no region to be inside or outside of" if no_region else ""))
    unmet = [a for a in cert.get("assumptions", []) if not a.get("met")]
    if unmet:
        lines.append("certificate NOT valid; assumptions not met: " + format_unmet(unmet))
    for a in unmet:
        if str(a.get("name", "")).startswith(OUTSIDE_THE_BOX):
            lines.append(f"plant outside the box: {a.get('equation', '')} fails; {a.get('note', '')}")
    if no_region:
        lines.append(f"certificate:   no certificate ({cert.get('reason') or 'no finite bound'}); the run's "
                     f"sup|E| = {_num(summary.get('sup_E'))} rad is judged against no region")
    else:
        lines.append(f"certificate:   |E| <= {_num(cert.get('E_max'))} rad, |E'| <= {_num(cert.get('Edot_max'))} "
                     f"rad/s, {_which_certificate(cert)}, run {'inside' if cert.get('inside') else 'OUTSIDE'}")
    if summary.get("paper_claim_applies") is False:
        lines.append(f"paper's claim: {PAPER_CLAIM_NOT_APPLICABLE}")
    else:
        lines.append(f"paper's claim: |E| <= {_num(paper.get('E_max'))} rad, |E'| <= "
                     f"{_num(paper.get('Edot_max'))} rad/s, (4.23) = {_num(paper.get('condition'), '.4f')}, run "
                     f"{'inside' if paper.get('inside') else 'OUTSIDE'}")
    if dr:
        lines.append(f"drift: final alpha' = {_num(dr.get('final_alpha_dot'), '.3g')} rad/s, |E| "
                     f"{'STILL GROWING' if dr.get('growing') else 'not growing'} over the last "
                     f"{_num(dr.get('window_s'), 'g')} s")
    return lines


def format_measurement_cause(cause: MeasurementCause) -> str:
    """One line: the measurement errors a certificate assumed and, without a fixed point, the one that binds.

    Args:
        cause: the certificate's :class:`~wmr_mj.analysis.claim_types.MeasurementCause`
            (``certificate.terms.measurement_cause``).

    Returns:
        e.g. "measurement errors assumed: |e_a| <= 0.000767 rad, |e_v| <= 1.534 rad/s, tau = 0.0005 s; the
        fixed point fails by e_v: with e_v = 0 (the others kept) E_max = 0.09648 rad".
    """
    text = (f"measurement errors assumed: |e_a| <= {_num(cause.e_a, '.4g')} rad, |e_v| <= {_num(cause.e_v, '.4g')} "
            f"rad/s, tau = {_num(cause.tau, '.4g')} s")
    if cause.E_max_exact is None:
        return text
    if not math.isfinite(cause.E_max_exact):
        return text + ("; the fixed point fails without any measurement error too: the law and the plant box "
                       "alone have none")
    binding = cause.binding
    if not binding:
        return text + ("; the fixed point fails by the errors together: with any one of them set to 0 it still "
                       f"fails, with none of them E_max = {cause.E_max_exact:.4g} rad")
    without = dict(cause.E_max_without)
    each = "; ".join(f"with {name} = 0 (the others kept) E_max = {without[name]:.4g} rad" for name in binding)
    return text + f"; the fixed point fails by {' or '.join(binding)}: {each}"


def format_delta1_parts(delta1: float, parts: Iterable[tuple[str, float]]) -> str:
    """'delta1 = name value + ...' with every term, which add up to delta1 (to rounding).

    Args:
        delta1: the certificate's delta1 [rad/s^2].
        parts: its terms as (name, value [rad/s^2]) (``certificate.terms.delta1_parts``); empty: unbounded.
    """
    terms = list(parts)
    if not terms or not math.isfinite(delta1):
        return f"{_num(delta1, '.4g') if math.isfinite(delta1) else 'unbounded'} (no finite breakdown)"
    return f"{delta1:.6g} = " + " + ".join(f"{name} {value:.6g}" for name, value in terms)
