"""The run summary: one typed record shared by run, sweep, falsify, the report, the MCAP log and replay.

``wmr_mj.sim.closed_loop.report`` builds it (the serial runner and the batched sweep both call
it, so both report alike). It is a frozen dataclass read by attribute; :meth:`RunSummary.to_dict`
writes the JSON interface (``run --json``, the MCAP log's summary metadata, the rows of
``runs.csv``), with the keys and values it has always had, so that scripts and logs written
before keep reading. An MCAP log's summary is read back as that JSON (``wmr_mj.logs.reader``).

Usage::

    from wmr_mj.sim.summary import RunSummary
    def worst(summaries: list[RunSummary]) -> float:
        return max(s.certificate.E_ratio or 0.0 for s in summaries)
    summary.to_dict()["certificate"]["E_ratio"]      # the same number, as JSON
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from wmr_mj.analysis.certificate import Assumption, CertificateJudgement
from wmr_mj.analysis.claim_types import MeasurementCause
from wmr_mj.analysis.path_bound import PathBound, PathVerdict
from wmr_mj.analysis.path_error import PathErrors
from wmr_mj.analysis.requirements import RequirementResult
from wmr_mj.analysis.verdicts import FAILED, NO_CLAIM, Drift, PaperRegion
from wmr_mj.reference.route import RouteProgress

__all__ = ["RunSummary", "VoltageEffort", "voltage_effort",
           "PaperRegion", "Drift", "CertificateJudgement", "Assumption", "BatchFigures",
           "PAPER_KEYS_DEPRECATED", "PAPER_REGION_KEYS", "shown_config"]


#: The run summary's keys of the paper's region, deprecated (kept for one version, wmr-mj 0.1), and the
#: names that replace them: unprefixed, they read as the verdict's, which is the certificate's.
PAPER_KEYS_DEPRECATED = {"E_max": "paper_E_max", "Edot_max": "paper_Edot_max", "condition": "paper_condition",
                         "inside": "paper_inside", "E_ratio": "paper_E_ratio", "Edot_ratio": "paper_Edot_ratio"}

#: A run summary's keys of the paper's region: null in the summary of a law outside the paper's family.
PAPER_REGION_KEYS = (*PAPER_KEYS_DEPRECATED, *PAPER_KEYS_DEPRECATED.values(), "stable", "paper_region")


@dataclass(frozen=True)
class VoltageEffort:
    """What a run asked of its motor: the applied voltage's peak, its RMS and its activity.

    Attributes:
        peak_voltage: max |u| over the run [V].
        rms_voltage: the RMS of u [V].
        tv_voltage: the total variation of u per second, sum |u[k+1] - u[k]| / duration [V/s]: chattering
            (as ``wmr-mj compare`` and validate's sensing section compute it).
    """

    peak_voltage: float
    rms_voltage: float
    tv_voltage: float

    def to_dict(self) -> dict[str, Any]:
        """The summary keys peak_voltage, rms_voltage, tv_voltage."""
        return {"peak_voltage": self.peak_voltage, "rms_voltage": self.rms_voltage, "tv_voltage": self.tv_voltage}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> VoltageEffort:
        """The effort of its summary keys ``d`` (what :meth:`to_dict` wrote)."""
        return cls(peak_voltage=d["peak_voltage"], rms_voltage=d["rms_voltage"], tv_voltage=d["tv_voltage"])


def voltage_effort(voltage: Any, control_period: float) -> VoltageEffort:
    """The effort of the applied voltage ``voltage`` [V] at each control step (a contiguous 1-D array: the
    serial run's rows and the batch's column give the same bits), ``control_period`` [s] apart."""
    import numpy as np

    u = np.ascontiguousarray(voltage, dtype=float)
    if u.size == 0:
        return VoltageEffort(peak_voltage=math.nan, rms_voltage=math.nan, tv_voltage=0.0)
    return VoltageEffort(peak_voltage=float(np.max(np.abs(u))), rms_voltage=float(np.sqrt(np.mean(u * u))),
                         tv_voltage=float(np.sum(np.abs(np.diff(u))) / (u.size * control_period)))


@dataclass(frozen=True)
class BatchFigures:
    """What a run of a batch (``wmr_mj.sim.batch.run_batch``) adds to its summary.

    Attributes:
        final_alpha_after_step: alpha after the last physics step [rad] (the serial run reports
            the last row's, ``RunSummary.final_alpha``).
        wall_s: the whole batch's wall time [s].
        steps_per_s: physics steps of the whole batch per wall second [1/s]; None for no time.
        cpu_s: CPU time of the batch's threads [s] (robust to a shared machine).
        law: how the batch evaluated the law (``wmr_mj.sim.batch.LAW_BACKENDS``).
    """

    final_alpha_after_step: float
    wall_s: float
    steps_per_s: float | None
    cpu_s: float
    law: str

    def to_dict(self) -> dict[str, Any]:
        """The summary keys final_alpha_after_step, batch_wall_s, batch_steps_per_s, batch_cpu_s, batch_law."""
        return {"final_alpha_after_step": self.final_alpha_after_step, "batch_wall_s": self.wall_s,
                "batch_steps_per_s": self.steps_per_s, "batch_cpu_s": self.cpu_s, "batch_law": self.law}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> BatchFigures:
        """The figures of their summary keys ``d`` (what :meth:`to_dict` wrote)."""
        return cls(final_alpha_after_step=d["final_alpha_after_step"], wall_s=d["batch_wall_s"],
                   steps_per_s=d["batch_steps_per_s"], cpu_s=d["batch_cpu_s"], law=d["batch_law"])


@dataclass(frozen=True)
class RunSummary:
    """What one closed-loop run reports (``RunResult.summary``, a run of a sweep, ``run --json``).

    Attributes:
        status: 'completed' or 'interrupted'.
        controller: the controller's name.
        model: the model source of the controller's estimate.
        m1: the plant's chassis mass [kg].
        kp: K_P [1/s^2].
        kd: K_D [1/s].
        path: the reference path's name.
        duration: time simulated [s].
        steps: physics steps.
        control_steps: control steps.
        wall_s: wall time of the run [s] (a batch: its share of the batch).
        realtime_factor: simulated over wall time [-]; None for no wall time.
        sup_E: sup |E| over the whole run [rad].
        sup_Edot: sup |E'| over the whole run [rad/s].
        settle_s: end of the entry transient [s].
        sup_E_settled: sup |E| after settle_s [rad].
        sup_Edot_settled: sup |E'| after settle_s [rad/s].
        stable: (4.23) of the paper's claim holds.
        saturated_fraction: fraction of the control steps whose voltage was limited [-].
        effort: the applied voltage's peak [V], RMS [V] and total variation per second [V/s]
            (:class:`VoltageEffort`); None where the run did not measure it.
        left_steering_range_at_s: when |alpha| first reached the steering stop [s]; None if never.
        final_alpha: alpha at the last control step [rad].
        paper_region: the paper's claim, judged (its E_max, Edot_max, condition, inside).
        certificate: the certificate, judged; None when the run was reported without one.
        drift: the end-of-run drift; None when the run was reported without a certificate.
        mujoco_warnings: MuJoCo's warning count (added by the runners).
        analysis: the paper's region as ``RobustnessResult.to_dict()`` (the serial runner).
        controller_config: the controller's ``describe()`` (the serial runner).
        batch: what a batch adds (``run_batch``).
        path_error: C's Cartesian errors against its desired path (cross-track, along-track,
            heading: sup, RMS, final; ``wmr_mj.analysis.path_error``); None when not measured.
        path_bound: what the certificate's E_max implies for C's path (``wmr_mj.analysis.path_bound``).
        path_verdict: the run's cross-track against ``path_bound``: 'within-bound', 'beyond-bound'
            or 'no-guarantee'.
        correction: the Cartesian correction's gains, limits and the largest values it used
            (``controllers.tracking``); None when the run had none.
        requirements: each STL requirement judged on the run (``wmr_mj.analysis.requirements``:
            formula, robustness, satisfied); None when none was asked for.
        route: the route's length, the distance its reference covers in the run and whether that
            finishes it (``wmr_mj.reference.route.RouteProgress``); None when the path is no route.
    """

    status: str
    controller: str
    model: str
    m1: float
    kp: float
    kd: float
    path: str
    duration: float
    steps: int
    control_steps: int
    wall_s: float
    realtime_factor: float | None
    sup_E: float
    sup_Edot: float
    settle_s: float
    sup_E_settled: float
    sup_Edot_settled: float
    stable: bool
    saturated_fraction: float
    left_steering_range_at_s: float | None
    final_alpha: float
    paper_region: PaperRegion
    certificate: CertificateJudgement | None = None
    drift: Drift | None = None
    mujoco_warnings: int | None = None
    analysis: Mapping[str, Any] | None = None
    controller_config: Mapping[str, Any] | None = None
    batch: BatchFigures | None = None
    path_error: PathErrors | None = None
    path_bound: PathBound | None = None
    path_verdict: PathVerdict | None = None
    correction: Mapping[str, Any] | None = None
    requirements: tuple[RequirementResult, ...] | None = None
    route: RouteProgress | None = None
    failure: str | None = None  # status 'failed': why the law (or tracker) failed; the run has no verdict but this
    claimed: bool = True  # False: the controller states no claim (judged by its requirements only, never a pass)
    paper_law: bool = True  # False: the law is not the paper's family, so the paper's region says nothing of it
    # the RunConfig settings (model, kp, kd, ...) the law reads (wmr_mj.sim.config.controller_and_settings);
    # None: all of them (the computed-torque law, and a summary of a caller that did not say)
    law_settings: frozenset[str] | None = None
    effort: VoltageEffort | None = None  # the applied voltage's peak, RMS and activity; None: not measured

    # the paper's claim, read through paper_region (the JSON also writes these at the top level)
    @property
    def E_max(self) -> float:
        """The paper's bound on |E| [rad]; inf when (4.23) fails."""
        return self.paper_region.E_max

    @property
    def Edot_max(self) -> float:
        """The paper's bound on |E'| [rad/s]; inf when (4.23) fails."""
        return self.paper_region.Edot_max

    @property
    def condition(self) -> float:
        """The left side of the paper's (4.23) [-]."""
        return self.paper_region.condition

    @property
    def inside(self) -> bool:
        """The run is inside the paper's claim."""
        return self.paper_region.inside

    @property
    def E_ratio(self) -> float | None:
        """sup|E| / the paper's E_max [-]; None when that bound is not finite and positive."""
        E_max = self.paper_region.E_max
        return self.sup_E / E_max if math.isfinite(E_max) and E_max > 0 else None

    @property
    def Edot_ratio(self) -> float | None:
        """sup|E'| / the paper's Edot_max [-]; None when that bound is not finite and positive."""
        Ed_max = self.paper_region.Edot_max
        return self.sup_Edot / Ed_max if math.isfinite(Ed_max) and Ed_max > 0 else None

    @property
    def left_steering_range(self) -> bool:
        """The steering reached its stop during the run."""
        return self.left_steering_range_at_s is not None

    @property
    def verdict(self) -> str | None:
        """The separated verdict (``wmr_mj.analysis.verdicts``): 'failed' for a run whose law failed
        (:attr:`failure`), 'no-claim' for a controller that states no claim, else the certificate's;
        None without a certificate (a summary of a caller that judged none)."""
        if self.failure is not None:
            return FAILED
        if not self.claimed:
            return NO_CLAIM
        return None if self.certificate is None else self.certificate.verdict

    def _not_applicable(self) -> dict[str, Any]:
        """For a law outside the paper's family: the paper's region's keys and the settings the law does not
        read (model, kp, kd) as null, and ``not_applicable``, each such key's reason."""
        law = f"controller {self.controller!r}"
        region = f"the paper's region is for its computed-torque law (computed-torque, pd), not {law}"
        out: dict[str, Any] = dict.fromkeys(PAPER_REGION_KEYS)
        reasons = {"paper_region": region}
        read = self.law_settings
        if read is not None:
            out["law_settings"] = sorted(read)  # the run's settings that reach the law (its config's others do not)
        for key in ("model", "kp", "kd"):
            if read is not None and key not in read:
                out[key] = None
                reasons[key] = f"{law} does not read the run's {key} (its own parameters: controller_config)"
        out["not_applicable"] = reasons
        return out

    def to_dict(self) -> dict[str, Any]:
        """The JSON interface: every key the summary has always written, with the same values.

        inf stays inf (the JSON writers write null); the keys of the verdict (verdict,
        certificate, paper_region, drift) appear only with a certificate, those the runners
        add (mujoco_warnings, analysis, controller_config, the batch's, path_error, path_bound,
        path_verdict) only when set.
        """
        out: dict[str, Any] = {
            "status": self.status,
            "controller": self.controller,
            "model": self.model,
            "m1": self.m1,
            "kp": self.kp,
            "kd": self.kd,
            "path": self.path,
            "duration": self.duration,
            "steps": self.steps,
            "control_steps": self.control_steps,
            "wall_s": self.wall_s,
            "realtime_factor": self.realtime_factor,
            "sup_E": self.sup_E,
            "sup_Edot": self.sup_Edot,
            "settle_s": self.settle_s,
            "sup_E_settled": self.sup_E_settled,
            "sup_Edot_settled": self.sup_Edot_settled,
            "E_max": self.E_max,
            "Edot_max": self.Edot_max,
            "condition": self.condition,
            "stable": self.stable,
            "inside": self.inside,
            "E_ratio": self.E_ratio,
            "Edot_ratio": self.Edot_ratio,
            "saturated_fraction": self.saturated_fraction,
            "left_steering_range": self.left_steering_range,
            "left_steering_range_at_s": self.left_steering_range_at_s,
            "final_alpha": self.final_alpha,
        }
        # the same numbers under names that say whose region they are (the unprefixed keys above are kept
        # for one version, deprecated: PAPER_KEYS_DEPRECATED)
        out.update({new: out[old] for old, new in PAPER_KEYS_DEPRECATED.items()})
        out["deprecated_keys"] = dict(PAPER_KEYS_DEPRECATED)
        if self.certificate is not None:
            out["verdict"] = self.certificate.verdict
            out["certificate"] = self.certificate.to_dict()
            out["paper_region"] = self.paper_region.to_dict()
            out["drift"] = {} if self.drift is None else self.drift.to_dict()
        elif self.failure is not None or not self.claimed:
            out["verdict"] = self.verdict
            out["paper_region"] = self.paper_region.to_dict()
            out["drift"] = {} if self.drift is None else self.drift.to_dict()
        if self.failure is not None:
            out["failure"] = self.failure
        if not self.paper_law:
            out["paper_claim_applies"] = False  # the paper's region is for its computed-torque family only
            out.update(self._not_applicable())
        if self.mujoco_warnings is not None:
            out["mujoco_warnings"] = self.mujoco_warnings
        if self.analysis is not None and self.paper_law:
            out["analysis"] = dict(self.analysis)
        if self.controller_config is not None:
            out["controller_config"] = dict(self.controller_config)
        if self.batch is not None:
            out.update(self.batch.to_dict())
        if self.path_error is not None:
            out["path_error"] = self.path_error.to_dict()
        if self.path_bound is not None:
            out["path_bound"] = self.path_bound.to_dict()
        if self.path_verdict is not None:
            out["path_verdict"] = self.path_verdict.to_dict()
        if self.correction is not None:
            out["correction"] = dict(self.correction)
        if self.requirements is not None:
            out["requirements"] = [r.to_dict() for r in self.requirements]
        if self.route is not None:
            out.update(self.route.to_dict())
        if self.effort is not None:
            out.update(self.effort.to_dict())
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, measurement_cause: MeasurementCause | None = None) -> RunSummary:
        """The summary of its JSON ``d`` (what :meth:`to_dict` wrote, or a run's JSON, whose further keys are not
        read), such that ``to_dict()`` writes the same keys and values again.

        Every number the JSON holds is restored as written. Not in the JSON, so not restored: for a law outside
        the paper's family (``paper_claim_applies`` false), the paper's region (NaN, not inside), ``stable``
        (False), ``analysis`` (None), and the settings the law does not read (``model`` None, ``kp``/``kd`` NaN);
        for a law of the paper's family, ``law_settings`` (None: all of them);
        a certificate's terms' ``delta1_parts`` and ``measurement_cause`` (``measurement_cause``: the run JSON's
        ``measurement_errors``, which :meth:`wmr_mj.sim.closed_loop.RunResult.from_dict` passes), its
        ``analysis`` and its typed inputs (:meth:`wmr_mj.analysis.claim_types.Certificate.from_dict`).
        """
        paper_law = d.get("paper_claim_applies", True) is not False
        certificate = d.get("certificate")
        drift = d.get("drift")

        def number(key: str) -> float:  # a setting the law does not read is null in the JSON
            return math.nan if d[key] is None else d[key]

        region = (PaperRegion.from_dict({k: d[k] for k in ("E_max", "Edot_max", "condition", "inside")}) if paper_law
                  else PaperRegion(E_max=math.nan, Edot_max=math.nan, condition=math.nan, inside=False))
        requirements = d.get("requirements")
        law_settings = d.get("law_settings")

        def record(kind: Any, key: str) -> Any:
            value = d.get(key)
            return None if value is None else kind.from_dict(value)

        return cls(
            status=d["status"], controller=d["controller"], model=d["model"], m1=d["m1"], kp=number("kp"),
            kd=number("kd"), path=d["path"], duration=d["duration"], steps=d["steps"], control_steps=d["control_steps"],
            wall_s=d["wall_s"], realtime_factor=d["realtime_factor"], sup_E=d["sup_E"], sup_Edot=d["sup_Edot"],
            settle_s=d["settle_s"], sup_E_settled=d["sup_E_settled"], sup_Edot_settled=d["sup_Edot_settled"],
            stable=bool(d["stable"]), saturated_fraction=d["saturated_fraction"],
            left_steering_range_at_s=d["left_steering_range_at_s"], final_alpha=d["final_alpha"], paper_region=region,
            certificate=(None if certificate is None
                         else CertificateJudgement.from_dict(certificate, measurement_cause=measurement_cause)),
            drift=Drift.from_dict(drift) if drift else None,
            mujoco_warnings=d.get("mujoco_warnings"), analysis=d.get("analysis"),
            controller_config=d.get("controller_config"),
            batch=BatchFigures.from_dict(d) if "batch_law" in d else None,
            path_error=record(PathErrors, "path_error"), path_bound=record(PathBound, "path_bound"),
            path_verdict=record(PathVerdict, "path_verdict"), correction=d.get("correction"),
            requirements=None if requirements is None else tuple(RequirementResult.from_dict(r) for r in requirements),
            route=RouteProgress.from_dict(d) if "route_length_m" in d else None,
            failure=d.get("failure"), claimed=d.get("verdict") != NO_CLAIM, paper_law=paper_law,
            law_settings=None if law_settings is None else frozenset(law_settings),
            effort=VoltageEffort.from_dict(d) if "peak_voltage" in d else None)


def shown_config(config: Mapping[str, Any], summary: Mapping[str, Any] | None) -> dict[str, Any]:
    """A run's config (``RunConfig.to_dict()``) as its outputs show it: without the law settings (model, kp,
    kd, friction_sign, friction_width) that the run's law does not read, as its summary records them
    (``law_settings``); unchanged for the computed-torque and PD laws and for a summary that does not say."""
    read = (summary or {}).get("law_settings")
    if read is None:
        return dict(config)
    unread = {"model", "kp", "kd", "friction_sign", "friction_width"} - set(read)
    return {k: v for k, v in config.items() if k not in unread}
