"""The run summary: one typed record shared by run, sweep, falsify, the report, the MCAP log and replay.

``wmr_mj.sim.closed_loop.report`` builds it (the serial runner and the batched sweep both call
it, so both report alike); it is written as JSON into the MCAP log's metadata and into
``runs.csv`` rows, and read back by ``wmr_mj.logs.replay`` and ``wmr_mj.report.validate``. The keys are
typed here once (a ``TypedDict``: a plain, JSON-ready dict at run time, checked by a type
checker), with their units.

Usage::

    from wmr_mj.sim.summary import RunSummary
    def worst(rows: list[RunSummary]) -> float:
        return max(r["certificate"]["E_ratio"] or 0.0 for r in rows)
"""

from __future__ import annotations

from typing import Any, TypedDict

__all__ = ["RunSummary", "PaperRegion", "Drift", "CertificateJudgement", "AssumptionRecord"]


class AssumptionRecord(TypedDict):
    """One assumption of the certificate: met when value <= limit (or as its equation says)."""

    name: str
    equation: str
    met: bool
    value: float | None
    limit: float | None
    note: str
    kind: str  # 'checked' or 'stated'


class CertificateJudgement(TypedDict, total=False):
    """``wmr_mj.analysis.certificate.judge``: the certificate with one run judged against it."""

    E_max: float | None  # rad; None when there is no certificate
    Edot_max: float | None  # rad/s
    condition: float | None  # left side of (4.23)
    valid: bool
    certified: bool  # every assumption met
    assumptions: list[AssumptionRecord]
    unmet: list[str]
    inside: bool  # the run's (sup|E|, sup|E'|) inside region (4.21)
    E_ratio: float | None  # sup|E| / E_max
    Edot_ratio: float | None  # sup|E'| / Edot_max
    region_ratio: float | None  # <= 1 inside
    verdict: str


class PaperRegion(TypedDict):
    """The paper's claim: the region of wmr_mj.analysis.robustness (4.21)-(4.23), as the paper bounds it."""

    E_max: float  # rad (inf when (4.23) fails)
    Edot_max: float  # rad/s
    condition: float
    inside: bool


class Drift(TypedDict, total=False):
    """End of the run: is |E| still growing? (wmr_mj.analysis.verdicts.drift)"""

    final_alpha_dot: float  # rad/s
    growing: bool
    E_last_window: float  # rad, max |E| over the last window
    E_prev_window: float  # rad, over the window before it
    window_s: float
    tolerance: float  # rad


class RunSummary(TypedDict, total=False):
    """What one closed-loop run reports (``RunResult.summary``, a row of a sweep, ``run --json``)."""

    status: str  # 'completed' or 'interrupted'
    controller: str
    model: str  # model source of the estimate
    m1: float  # kg, the plant's chassis mass
    kp: float  # 1/s^2
    kd: float  # 1/s
    path: str
    duration: float  # s simulated
    steps: int  # physics steps
    control_steps: int
    wall_s: float
    realtime_factor: float | None
    sup_E: float  # rad, whole run
    sup_Edot: float  # rad/s
    settle_s: float  # s, end of the entry transient
    sup_E_settled: float
    sup_Edot_settled: float
    # the paper's claim, flat (today's keys; also under paper_region)
    E_max: float
    Edot_max: float
    condition: float
    stable: bool
    inside: bool
    E_ratio: float | None
    Edot_ratio: float | None
    saturated_fraction: float
    left_steering_range: bool
    left_steering_range_at_s: float | None
    final_alpha: float  # rad
    # the separated verdict (wmr_mj.analysis.verdicts)
    verdict: str  # one of wmr_mj.analysis.verdicts.VERDICTS
    certificate: CertificateJudgement
    paper_region: PaperRegion
    drift: Drift
    # added by the runners
    mujoco_warnings: int
    analysis: dict[str, Any]  # wmr_mj.analysis.robustness.RobustnessResult.as_dict()
    controller_config: dict[str, Any]
    log: str | None  # the MCAP path (run command)
