"""Closed-loop runs: the computed-torque law of the reduced model on the MuJoCo plant.

One run steps the C80 scene and applies the controller every ``control_period``
(default: every 1 ms physics step), holding the voltage in between; the motor's
voltage limit is applied to what the controller asks for. The run is a batch of one
on :mod:`wmr_mj.sim.engine`: the law compiled into MuJoCo's control callback, a
simulated second of steps per ``mujoco.batch`` rollout call, every control step
recorded as arrays (the Python law in the same engine where the compiled one cannot
run). tests/test_engine.py holds it to the bit against the serial loop it replaced
(tests/reference_loop.py).
The tracking errors E = alpha0 - alpha, E' are compared with the analytic
region of ``wmr_mj.analysis.robustness`` (4.21)-(4.23) for the parameter box in use.

Usage::

    from wmr_mj.sim.closed_loop import RunConfig, run_closed_loop
    result = run_closed_loop(RunConfig(model="nonholonomic", m1=700.0))
    print(result.summary.sup_E, result.summary.E_max, result.summary.inside)

``wmr_mj.sim.batch`` runs many of these at once on ``mujoco.batch``; a test keeps
the two bit-identical.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from controllers import SteeringController
from controllers.tracking import within_declared
from wmr_mj._util.memory import require_run_memory
from wmr_mj._util.progress import progress_bar
from wmr_mj.analysis.claim import with_measured
from wmr_mj.analysis.claim_types import LAW_CLAIM, Assumption, CertificateJudgement, judge
from wmr_mj.analysis.path_bound import (
    PathBound,
    PathVerdict,
    guaranteed_E_max,
    path_bound,
    path_verdict,
    without_guarantee,
)
from wmr_mj.analysis.path_error import (
    PathErrors,
    PathErrorSeries,
    PathProjector,
    path_error_series,
    summarize_series,
    wrap_angle,
)
from wmr_mj.analysis.requirements import evaluate_run
from wmr_mj.analysis.verdicts import Drift, drift, drift_window_steps, judge_run, paper_region
from wmr_mj.errors import ParameterError, WmrMjError
from wmr_mj.params import C80, C80Parameters
from wmr_mj.plant.mjcf import TIMESTEP, scene_xml
from wmr_mj.plant.reduced import smooth_sign
from wmr_mj.reference.route import RouteProgress
from wmr_mj.sim import notebook
from wmr_mj.sim.config import (
    RunConfig,
    estimate_parameters,
    plant_parameters,
)
from wmr_mj.sim.engine import (
    ROW_FIELDS,
    ControllerFailure,
    Schedule,
    batch_model,
    run_engine,
)
from wmr_mj.sim.log_header import LogHeader
from wmr_mj.sim.measured_errors import measured_errors_assumption
from wmr_mj.sim.parts import RunLabels, RunParts, control_substeps, resolve_run, run_reference
from wmr_mj.sim.run_report import config_of_report, run_report, summary_of_report
from wmr_mj.sim.summary import RunSummary, voltage_effort

__all__ = ["RunResult", "RunMeasures", "run_closed_loop", "report", "run_on_reduced_model", "ROW_FIELDS", "judge_path",
           "path_sample_index", "PathJudgement", "PATH_SAMPLE_S"]



@dataclass(frozen=True)
class RunResult:
    """Time histories (one row per control step) and the run's summary (a :class:`RunSummary`); frozen: a run's
    result is what it measured, built once (``dataclasses.replace`` for a changed copy)."""

    config: RunConfig
    rows: dict[str, np.ndarray]
    summary: RunSummary
    status: str = "completed"
    law: str = "compiled"  # the law that ran: "compiled" (C, MuJoCo's control callback) or "python"
    law_note: str | None = None  # why the Python law ran
    cpu_s: float | None = None  # CPU time of the run's loop on its thread (wall_s is in the summary)
    C_xy: np.ndarray | None = None  # (control steps, 2) xy of point C [m], as the log's C_pos
    reference: Any = None  # C's reference the run followed (RunParts.reference): its path, for C's errors
    # (control steps, C's cross-track [m] there) of the path verdict's samples (path_sample_index), where all
    # are finite: what requirement_rows interpolates between
    path_samples: tuple[np.ndarray, np.ndarray] | None = None
    # every claim of the run (RunParts.claims), with what the run measured of it, judged against its sup|E|,
    # sup|E'|, by name; the law's (LAW_CLAIM) is summary.certificate. Empty where the law failed.
    claims: Mapping[str, CertificateJudgement] = dataclasses.field(default_factory=dict)

    def to_dict(self, *, measurement: Any = None, log: str | None = None, requirements: Sequence[Any] = (),
                period: float | None = None) -> dict[str, Any]:
        """The run's JSON, as ``wmr-mj run --json`` prints it (:func:`wmr_mj.sim.run_report.run_report`).

        Args:
            measurement: the run's measurement errors (``RunParts.measurement``): its claim's assumed errors.
            log: the run's MCAP log (the JSON's ``log``), or None.
            requirements: parsed requirements judged on the run (:func:`judge_requirements`) at the control
                period ``period`` [s] (None: the config's, else the physics step).
        """
        period = (self.config.control_period or TIMESTEP) if period is None else period
        judged = judge_requirements(self, requirements, period=period) if requirements else []
        return run_report(self, measurement=measurement, log=log, judged=judged)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, config: RunConfig | None = None) -> RunResult:
        """The run of its JSON ``d`` (what :meth:`to_dict` wrote), such that ``to_dict()`` with the same arguments
        writes ``d`` again: the summary with every number as written (:func:`~wmr_mj.sim.run_report.summary_of_report`),
        the status, and the law's claim judged (``claims``, under :data:`~wmr_mj.analysis.claim_types.LAW_CLAIM`).

        Not in the JSON, so not restored: the rows, C's xy, the reference and the path verdict's samples (the run's
        MCAP log holds them: :mod:`wmr_mj.logs.reader`); the run's other claims (a sampled-data certificate beside
        the law's); which law ran (``law``: 'compiled'), ``law_note`` and ``cpu_s`` (None); what :meth:`to_dict`
        takes as arguments (``log``, ``measurement``); and for a claim without section 4's terms, the measurement
        errors it assumed (pass the run's ``measurement`` to :meth:`to_dict` again). The requirements :meth:`to_dict`
        judged are read back as the summary's (``to_dict()`` writes the same rows, without judging them again).

        Args:
            d: the run's JSON (``wmr-mj run --json``).
            config: the run's config, where the caller has it; None: what the JSON records of it
                (:func:`~wmr_mj.sim.run_report.config_of_report`: the law, model, m1, gains, path, duration,
                signals and the cart's parts; the other fields their defaults).
        """
        summary = summary_of_report(d)
        claims = {} if summary.certificate is None else {LAW_CLAIM: summary.certificate}
        return cls(config=config_of_report(d) if config is None else config, rows={}, summary=summary,
                   status=d["status"], claims=claims)

    # -- in a notebook (wmr_mj.sim.notebook): the rows as a table, the figure, the verdict in a few lines
    def to_pandas(self) -> Any:
        """The rows as a wide DataFrame: one row per control step, each column named with its unit (``t [s]``,
        ``E [rad]``, ``E_dot [rad/s]``, ``voltage [V]``, ``alpha_measured [rad]`` where sensed, C's ``C_x [m]``,
        ``C_y [m]``: :data:`wmr_mj.sim.notebook.ROW_UNITS`).

        Raises:
            WmrMjError: pandas is not installed (``pip install 'wmr-mj[notebook]'``).
        """
        return notebook.rows_frame(self.rows, self.C_xy)

    def plot(self, **options: Any) -> Any:
        """E and E' between the certificate's bounds, the voltage between the supply limits, and C's path
        (a :class:`wmr_mj.figures.results.ResultPlot`: ``.figure``, ``.axes``)."""
        from wmr_mj.figures.results import plot_run  # matplotlib loads only when a figure is asked for

        # the supply of the plant the run simulated: its cart's, with its --param overrides
        return plot_run(self, supply=float(plant_parameters(self.config).voltage_limit), **options)

    def _repr_html_(self) -> str:
        return notebook.run_html(self.summary)


def requirement_rows(result: RunResult, requirements: Sequence[Any], *, base: C80Parameters = C80
                     ) -> Mapping[str, np.ndarray]:
    """The run's rows as a requirement monitor reads them (``wmr_mj.analysis.requirements.SIGNALS``):
    ``result.rows``, with ``cross_track`` (C's signed distance from its path at every control step [m])
    added when a requirement reads it.

    cross_track is the run's path verdict's projection of C every :data:`PATH_SAMPLE_S` (the same samples:
    ``result.path_samples``), linear in between, as :data:`CROSS_TRACK_BETWEEN_SAMPLES` states; where the
    run has none (a sample not finite, a result made elsewhere) C is projected at every control step, as
    the log's /path channel is.
    """
    if not any(r.names("cross_track") for r in requirements) or result.C_xy is None:
        return result.rows
    n = len(result.rows["t"])
    if result.path_samples is not None and n:
        at, cross_track = result.path_samples
        return {**result.rows, "cross_track": np.interp(np.arange(n, dtype=float), at.astype(float), cross_track)}
    config = result.config
    period = control_substeps(config.control_period, TIMESTEP) * TIMESTEP
    reference = result.reference
    if reference is None:  # a result made elsewhere: the run's reference built again, as resolve_run builds it
        reference, _ = run_reference(config.path, estimate_parameters(base), period=period, duration=config.duration)
    block = {"t": result.rows["t"], "C_pos": result.C_xy[:n], "heading": result.rows["heading"]}
    return {**result.rows, "cross_track": _PathRows(reference, period)(block, 1)["path_cross_track"]}


def judge_requirements(result: RunResult, requirements: Sequence[Any], *, period: float, base: C80Parameters = C80,
                       monitor: Any = None) -> list[Any]:
    """Each requirement (parsed: :func:`wmr_mj.analysis.requirements.parse_requirement`) judged on the run's
    rows (:func:`requirement_rows`), the presets against its summary; ``monitor``: a lock held around rtamt's
    monitor (pure Python, process-wide logging: one run at a time where runs share threads)."""
    import contextlib

    with monitor if monitor is not None else contextlib.nullcontext():
        rows = requirement_rows(result, requirements, base=base)
        return evaluate_run(requirements, rows, result.summary.to_dict(), period=period)


@dataclass(frozen=True, kw_only=True)
class RunMeasures:
    """What a run measured, before it is judged: the inputs of :func:`report` that come from its steps."""

    status: str  # 'completed' or 'interrupted'
    settle_s: float  # end of the entry transient [s]
    sup_E: float  # sup |E| over the run [rad]
    sup_Edot: float  # sup |E'| over the run [rad/s]
    sup_E_settled: float  # sup |E| after settle_s [rad]
    sup_Edot_settled: float  # sup |E'| after settle_s [rad/s]
    saturated_fraction: float  # fraction of control steps whose voltage was limited [-]
    left_range_at: float | None  # when the steering first reached its stop [s]; None if never
    final_alpha: float  # alpha at the last control step [rad]
    control_steps: int  # control steps simulated
    steps: int  # physics steps simulated
    wall_s: float  # wall time [s]
    effort: Any = None  # the applied voltage's (wmr_mj.sim.summary.VoltageEffort); None: not measured


def report(labels: RunLabels, measured: RunMeasures, *, analysis, params: C80Parameters, certificate=None,
           drift: Drift | None = None, path: PathJudgement | None = None, claims_nothing: bool = False
           ) -> RunSummary:
    """The run's report: sup errors (whole run and after the entry transient) against the region.

    Shared by the single run and the batched sweep so both report alike.

    Args:
        labels: what the summary calls the run's law, estimate, gains and path (``RunParts.labels``, read from
            the config once by ``resolve_run``; :meth:`RunLabels.of` for a config of one's own).
        analysis: the paper's region (``RobustnessResult``): the summary's E_max, Edot_max, inside,
            E_ratio, Edot_ratio are the paper's claim.
        measured: what the run measured (:class:`RunMeasures`, units there).
        params: the plant's parameters (its m1 [kg]).
        certificate: the run's :class:`wmr_mj.analysis.certificate.Certificate`; with it and the
            end-of-run ``drift`` (:func:`wmr_mj.analysis.verdicts.drift`) the separated verdict is
            added (:func:`wmr_mj.analysis.verdicts.judge_run`).
        path: C's path errors, bound and verdict (:func:`judge_path`); None: not measured.
        claims_nothing: the controller states no claim (``certificate_for`` gave None): the verdict
            is 'no-claim', never a pass.

    Returns:
        RunSummary: ``to_dict()`` writes the JSON interface.
    """
    m = measured
    sup_E, sup_Edot = float(m.sup_E), float(m.sup_Edot)
    steps, wall_s = m.steps, m.wall_s

    judged = None
    if certificate is not None:
        judged = judge_run(certificate=certificate, analysis=analysis, sup_E=sup_E, sup_Edot=sup_Edot, drift=drift)
    return RunSummary(
        status=m.status,
        controller=labels.controller,
        model=labels.model,
        m1=float(params.m1),
        kp=labels.kp,
        kd=labels.kd,
        path=labels.path,
        duration=steps * TIMESTEP,
        steps=int(steps),
        control_steps=int(m.control_steps),
        wall_s=float(wall_s),
        realtime_factor=float(steps * TIMESTEP / wall_s) if wall_s > 0 else None,
        sup_E=sup_E,
        sup_Edot=sup_Edot,
        settle_s=float(m.settle_s),
        sup_E_settled=float(m.sup_E_settled),
        sup_Edot_settled=float(m.sup_Edot_settled),
        stable=bool(analysis.stable),
        saturated_fraction=float(m.saturated_fraction),
        left_steering_range_at_s=m.left_range_at,
        final_alpha=float(m.final_alpha),
        paper_region=paper_region(analysis, sup_E, sup_Edot) if judged is None else judged.paper_region,
        certificate=None if judged is None else judged.certificate,
        drift=drift if judged is None else judged.drift,
        claimed=not claims_nothing,
        path_error=None if path is None else path.errors,
        path_bound=None if path is None else path.bound,
        path_verdict=None if path is None else path.verdict,
        effort=m.effort,
    )


#: C's path errors are judged on a grid of this spacing [s] (and at the last control step): the
#: projection costs ~0.45 s per 35 000 control steps at every step, ~0.18 s at 5 ms; C moves
#: < 5 mm in 5 ms, and the sup cross-track changes by < 1e-6 m (measured on the paper circle)
PATH_SAMPLE_S = 0.005

#: How ``cross_track`` (requirements' signal) is made between the path samples, and what that costs, measured
#: against projecting C at every 1 ms control step over the suite standard-v1's 30 scenarios under the paper's,
#: the certified, the PD and the sliding-mode designs (120 runs): where C stays within 0.5 m of its path (61
#: runs) the two differ by at most 5.9e-7 m (2.0e-7 m in the 30 runs within 0.15 m); where C runs 0.5-1.3 m
#: off (56 runs) by up to 1.2 mm, and by 0.59 m for the paper's design on the knot path, which it leaves
#: (1.7 m off): so far off, which part of the path is nearest depends on the sampling, and the two
#: projections part. Projecting every step cost 55 ms per 35 s run, 12% of its physics; this, under 1 ms.
CROSS_TRACK_BETWEEN_SAMPLES = "linear interpolation between the path verdict's samples (PATH_SAMPLE_S apart)"


@dataclass(frozen=True)
class PathJudgement:
    """A run's path errors of C, what its certificate implies for the path, and the verdict."""

    errors: PathErrors
    bound: PathBound
    verdict: PathVerdict
    # the judged samples' errors (t and cross_track at the finite samples); not part of the report
    series: PathErrorSeries | None = dataclasses.field(default=None, compare=False, repr=False)


class _PathRows:
    """C's path errors of logged rows (the log's /path channel, ``LogHeader.path_errors``), at the rows
    the logger plots (every ``every``-th control step), projected with continuity across calls; the
    log's writer calls it, on its own thread when it has one, so the run does not wait for it."""

    def __init__(self, reference, period: float) -> None:
        self.projector = PathProjector(reference)
        self.rt, self.rs = np.asarray(reference.t, float), np.asarray(reference.s, float)
        self.s_prev = float(self.rs[0])
        self.period = period

    def __call__(self, block: Mapping[str, np.ndarray], every: int) -> dict[str, np.ndarray]:
        every = max(1, int(every))
        t = np.asarray(block["t"], float)
        n = t.size
        out = {key: np.full(n, np.nan) for key in ("path_cross_track", "path_along_track", "path_heading_error")}
        k = np.rint(t / self.period)
        X, h = np.asarray(block["C_pos"], float).reshape(n, 2), np.asarray(block["heading"], float)
        sel = np.flatnonzero((k % every == 0) & np.isfinite(X).all(axis=1) & np.isfinite(h) & np.isfinite(t))
        if sel.size:
            s, d, theta = self.projector.project_many(X[sel], self.s_prev)
            self.s_prev = float(s[-1])
            out["path_cross_track"][sel] = d
            out["path_along_track"][sel] = s - np.interp(t[sel], self.rt, self.rs)
            out["path_heading_error"][sel] = wrap_angle(h[sel] - theta)
        return out


def path_sample_index(k: int, period: float) -> np.ndarray:
    """The control steps (of ``k``) at which a run's path errors are judged: every ``PATH_SAMPLE_S``
    and the last one."""
    stride = max(1, int(round(PATH_SAMPLE_S / period)))
    idx = np.arange(0, k, stride)
    if idx.size and idx[-1] != k - 1:
        idx = np.append(idx, k - 1)
    return idx


def judge_path(reference, t: np.ndarray, C_xy: np.ndarray, heading: np.ndarray, *, settle_s: float,
               certificate=None, steering_range: float | None = None, corrected: bool = False) -> PathJudgement | None:
    """C's Cartesian errors over a run, judged against what its certificate implies for the path.

    reference: the run's Reference; t, C_xy (m, 2), heading: C's samples (the control steps of
    :func:`path_sample_index`, from the engine's rows and ``EngineRun.C_xy``, or the batch's);
    the bound from the certificate's E_max when it holds (valid, every assumption met: else no bound, and
    the bound's reason says why; :func:`~wmr_mj.analysis.path_bound.guaranteed_E_max`), judged from
    ``settle_s`` on (from the start where the reference ends before it). None when no sample
    is finite (a diverged run): nothing to project. ``corrected``: the run had the Cartesian
    correction (position feedback at C); the bound and verdict say that no bound is proven for it.
    """
    tt, X, h = np.asarray(t, float), np.asarray(C_xy, float), np.asarray(heading, float)
    ok = np.isfinite(tt) & np.isfinite(X).all(axis=1) & np.isfinite(h)
    if not ok.any():
        return None
    series = path_error_series(reference, tt[ok], X[ok], h[ok])
    errors = summarize_series(series, settle_s)  # path_errors(...), with the series kept
    E_max, why_not = (None, "") if certificate is None else guaranteed_E_max(
        E_max=certificate.E_max, valid=certificate.valid, unmet=certificate.unmet)
    try:
        bound = path_bound(reference, E_max, settle_s=settle_s, max_angle=steering_range)
    except WmrMjError:  # the reference ends before settle_s
        bound = path_bound(reference, E_max, max_angle=steering_range)
    bound = without_guarantee(bound, why_not)
    verdict = path_verdict(errors, bound)
    if corrected:
        note = ("; with the Cartesian correction C's position is fed back, but no bound on C's path is proven "
                "for that loop (the certificate covers the inner loop on the corrected alpha0)")
        bound = dataclasses.replace(bound, reason=bound.reason + note)
        verdict = dataclasses.replace(verdict, text=verdict.text + note)
    return PathJudgement(errors=errors, bound=bound, verdict=verdict, series=series)


def _sup(x: np.ndarray) -> float:
    return float(np.max(np.abs(x))) if x.size else 0.0


def _drift_of(E: np.ndarray, final_alpha_dot: float, period: float) -> Drift:
    """End-of-run drift from a run's rows (the batch computes the same windows per block).

    final_alpha_dot: alpha' of the last control step, as alpha0' - E' (the batch keeps E', not alpha').
    """
    k = len(E)
    w = drift_window_steps(k, period)
    h = k - w + w // 2  # the last window's halves: [k - w, h) and [h, k)
    return drift(prev_window=_sup(E[max(0, k - 2 * w):k - w]), last_window=_sup(E[k - w:]),
                 final_alpha_dot=final_alpha_dot,
                 last_halves=(_sup(E[k - w:h]), _sup(E[h:])) if w >= 2 else None)


def run_closed_loop(
    config: RunConfig = RunConfig(),
    *,
    logger_factory: Callable[..., Any] | None = None,
    progress: bool | None = None,
    base: C80Parameters = C80,
    law: str = "auto",
) -> RunResult:
    """Run ``config`` on the MuJoCo plant; optionally stream rows to an MCAP logger.

    The run is a batch of one on :func:`wmr_mj.sim.engine.run_engine`: the compiled law where it
    can run, else the Python law (``RunResult.law``, ``RunResult.law_note`` say which and why);
    ``law`` ("auto", "compiled", "numpy") chooses as ``run_batch`` does.

    logger_factory(header) takes the run's :class:`~wmr_mj.sim.log_header.LogHeader` (MJCF,
    config, parameters, initial state, timestep, control substeps, reference path, bounds
    E_max/Edot_max, the compiled plant) and returns a ``wmr_mj.logs.writer.RunLogger``; it
    receives a block of rows every simulated second and is closed with the summary,
    also when the run is interrupted (KeyboardInterrupt or SIGTERM).
    """
    # a run's rows, refused before anything is built where they would not fit (not in resolve_run: a batch resolves
    # its first run and keeps fewer bytes a step, and refuses on its own count)
    require_run_memory(duration_s=config.duration, control_period_s=(config.control_period or TIMESTEP))
    parts = resolve_run(config, base=base)  # before the arrays: what the run is made of, resolved once
    return run_parts(parts, logger_factory=logger_factory, progress=progress, law=law)


def _labels(parts: RunParts) -> RunLabels:
    """The run's labels, as ``resolve_run`` read them (parts made elsewhere, without them: from the config)."""
    return parts.labels if parts.labels is not None else RunLabels.named(parts.config, parts.controller_name)


def _record(parts: RunParts) -> dict[str, Any]:
    """The config as the run's log records it, as ``resolve_run`` took it (a copy: the log may keep it)."""
    return dict(parts.record) if parts.record is not None else parts.config.to_dict()


def run_parts(parts: RunParts, *, logger_factory: Callable[..., Any] | None = None, progress: bool | None = None,
              law: str = "auto") -> RunResult:
    """:func:`run_closed_loop` of a config already resolved (:func:`wmr_mj.sim.parts.resolve_run`)."""
    config, params, controller, outer = parts.config, parts.plant, parts.controller, parts.tracker
    labels = _labels(parts)
    dt, substeps, period, n = TIMESTEP, parts.substeps, parts.period, parts.n
    reference, settle_s, analysis = parts.reference, parts.settle_s, parts.analysis
    a0_all, a0d_all, a0dd_all = reference.alpha0, reference.alpha0_dot, reference.alpha0_ddot
    if len(a0_all) < n:
        raise ParameterError(f"reference shorter than the run: {len(a0_all)} < {n} samples")

    options = parts.options
    plain = batch_model(params, **options)  # the plant without its sky texture (no physics in it)
    logger = None
    if logger_factory is not None:
        m, d = plain, mujoco.MjData(plain)
        mujoco.mj_resetDataKeyframe(m, d, m.key("home").id)
        mujoco.mj_forward(m, d)
        state = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
        mujoco.mj_getState(m, d, state, mujoco.mjtState.mjSTATE_INTEGRATION)
        # the log carries the scene's MJCF as the plant compiles it, sky included
        logger = logger_factory(LogHeader(
            mjcf_xml=scene_xml(params, **options), config=_record(parts), parameters=params.to_dict(),
            initial_state=state, timestep=dt, control_substeps=substeps, model=m,
            bounds=({"E_max": parts.claim.E_max, "Edot_max": parts.claim.Edot_max} if parts.claim is not None
                    else {"E_max": math.inf, "Edot_max": math.inf}),
            reference_path=np.asarray(reference.C_xy)[::max(1, len(reference.C_xy) // 2000)],
            path_errors=_PathRows(reference, period), sensed=not parts.sensing.is_ideal))

    disturbance, loads = parts.disturbance, list(parts.loads)
    on_block = None if logger is None else logger.write_block
    bar = progress_bar(n, desc="run", unit="step", unit_scale=True, enabled=progress)
    try:
        schedule = Schedule(reference=(a0_all, a0d_all, a0dd_all), n=n, substeps=substeps, period=period,
                            disturbance=disturbance, loads=loads, tracker=outer, path_reference=reference,
                            sensing=parts.sensing)
        run = run_engine(params=params, controller=controller, options=options, model=plain, schedule=schedule,
                         law=law, on_block=on_block, on_progress=bar.update)
    finally:
        bar.close()
    done, k, status, wall = run.rows, run.steps, run.status, run.wall_s
    if k == 0:
        if run.failure is not None:
            if logger is not None:
                logger.close({"status": "failed", "failure": run.failure}, status="failed")
            raise ControllerFailure(run.failure)  # nothing simulated: nothing to judge
        raise KeyboardInterrupt  # nothing simulated: nothing to report
    claims = _measured_claims(parts, done, warnings=run.warnings, warning_text=run.warning_text)
    certificate = claims.get(LAW_CLAIM)  # the run's verdict is the law's claim's
    after = done["t"] >= settle_s
    at = path_sample_index(k, period)
    saturated = int(np.count_nonzero(done["voltage"] != done["voltage_cmd"]))  # NaN included: 0 V applied
    hit = np.flatnonzero(np.abs(done["alpha"]) >= params.steering_range - 1e-3)
    left_range_at = int(hit[0]) * period if hit.size else None
    measured = RunMeasures(status=status, settle_s=settle_s, sup_E=_sup(done["E"]), sup_Edot=_sup(done["E_dot"]),
                           sup_E_settled=_sup(done["E"][after]), sup_Edot_settled=_sup(done["E_dot"][after]),
                           saturated_fraction=saturated / k, left_range_at=left_range_at,
                           final_alpha=done["alpha"][-1], control_steps=k, steps=k * substeps, wall_s=wall,
                           effort=voltage_effort(done["voltage"], period))
    path = judge_path(reference, done["t"][at], run.C_xy[at], done["heading"][at], settle_s=settle_s,
                      certificate=certificate, steering_range=params.steering_range, corrected=outer is not None)
    summary = report(labels, measured, analysis=analysis, params=params,
                     certificate=None if run.failure is not None else certificate, claims_nothing=certificate is None,
                     drift=_drift_of(done["E"], done["alpha0_dot"][-1] - done["E_dot"][-1], period),
                     path=path)
    # every claim judged against the run's sup errors, beside the law's (the summary's verdict)
    judged = {} if run.failure is not None else {
        name: summary.certificate if name == LAW_CLAIM and summary.certificate is not None
        else judge(cert, summary.sup_E, summary.sup_Edot) for name, cert in claims.items()}
    if outer is not None:
        summary = dataclasses.replace(summary, correction=outer.describe(done))
    summary = dataclasses.replace(summary, mujoco_warnings=run.warnings, failure=run.failure,
                                  paper_law=parts.paper_law, law_settings=parts.law_settings,
                                  analysis=analysis.to_dict(), controller_config=controller.describe())
    if parts.route_length_m is not None:
        summary = dataclasses.replace(summary, route=RouteProgress.along(parts.route_length_m, reference,
                                                                         summary.duration))
    if logger is not None:
        logger.close(summary.to_dict(), status=status)
    path_samples = None
    if path is not None and path.series is not None and path.series.t.size == at.size:  # every sample finite
        path_samples = (at, path.series.cross_track)
    return RunResult(config=config, rows=done, summary=summary, status=status, law=run.law, law_note=run.law_note,
                     C_xy=run.C_xy, cpu_s=run.cpu_s, reference=reference, path_samples=path_samples, claims=judged)


#: the assumption a run with MuJoCo warnings does not meet (:func:`with_mujoco_warnings`)
MUJOCO_WITHOUT_WARNINGS = "MuJoCo stepped without a warning"


def with_mujoco_warnings(certificate: Any, count: int, text: str | None) -> Any:
    """``certificate`` with the assumption :data:`MUJOCO_WITHOUT_WARNINGS` unmet: MuJoCo warned ``count`` times
    during the run (``text``: its first warning, as MuJoCo words it), so the steps it warned of (a NaN, an
    unstable acceleration, a singular inertia) are not the plant the claim is of, and the run is not certified."""
    return with_measured(certificate, mujoco_warnings_assumption(count, text))


def mujoco_warnings_assumption(count: int, text: str | None) -> Assumption:
    """The assumption :data:`MUJOCO_WITHOUT_WARNINGS`, unmet: MuJoCo warned ``count`` times (``text``: its first
    warning) during the run (:func:`with_mujoco_warnings`)."""
    first = f"MuJoCo's first: {text.strip()}" if text else "MuJoCo's warning counters rose"
    return Assumption(name=MUJOCO_WITHOUT_WARNINGS, equation="MuJoCo's warnings during the run = 0", met=False,
                      value=float(count), limit=0.0, note=f"{count} warning(s); {first}")


def _measured_claims(parts: RunParts, rows: Mapping[str, np.ndarray], *, warnings: int = 0,
                     warning_text: str | None = None) -> dict[str, Any]:
    """Each of the run's claims (``parts.claims``, by name) with what the run measured of its assumptions, each
    measured once and handed to every claim: the tracker's declared bounds on the reference the law received,
    the sensing's error bounds on what the law read (:func:`measured_errors_assumption`, where its claim's
    sensing was covered), and, for the law's claim, MuJoCo's warnings (:func:`with_mujoco_warnings`: a run MuJoCo
    warned of is not the plant any claim is of)."""
    sensing, measurement = parts.sensing, parts.measurement
    errors = None
    if not sensing.is_ideal and "alpha_measured" in rows and measurement.covered:
        errors = measured_errors_assumption(rows, measurement, delay_steps=sensing.delay_steps(parts.period),
                                            velocity_bounded=sensing.velocity in ("exact", "tachometer"))
    warned = mujoco_warnings_assumption(warnings, warning_text) if warnings else None
    declared = None
    if parts.tracker is not None:
        declared = within_declared(rows, parts.tracker.declared_bounds(parts.reference_bounds),
                                   tracker=parts.tracker.name)
    out = {}
    for name, cert in parts.claims.items():
        measured = (declared, errors, warned if name == LAW_CLAIM else None)
        for assumption in measured:  # in this order: the claim's assumptions keep the order they always had
            if assumption is not None:
                cert = with_measured(cert, assumption)
        out[name] = cert
    return out


def run_on_reduced_model(
    controller: SteeringController,
    plant_model,
    reference,
    *,
    duration: float | None = None,
    friction_width: float = 0.0,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    disturbance: float | Callable[[float], float] = 0.0,
) -> dict[str, np.ndarray]:
    """The paper's view: the same controller on a reduced model as the plant, with scipy.

    Integrates P a'' + G(a') + K(a) = u (``plant_model``, a
    :class:`wmr_mj.plant.reduced.SteeringModel`) with u from ``controller`` evaluated
    continuously (no sampling, no voltage limit), from zero error. The plant's
    Coulomb sign is x/sqrt(x^2+w^2) with w = friction_width (0: exact sign).
    ``disturbance``: d_V [V] added to u in the plant (a number, or a function of t), the voltage
    equivalent R_a d/(k_i i2) of a torque d on the steering joint
    (:meth:`wmr_mj.params.C80Parameters.steering_torque_voltage`).
    Returns rows t, alpha, alpha_dot, alpha0, alpha0_dot, E, E_dot, voltage on the
    reference's grid.
    """
    from scipy.integrate import solve_ivp

    T = float(reference.duration if duration is None else duration)
    law = controller.voltage_scalar
    disturbed = callable(disturbance) or disturbance != 0.0

    def rhs(t, x):
        a, ad = float(x[0]), float(x[1])
        a0, a0d, a0dd = (float(v) for v in reference.at(t))
        u = law(a, ad, a0, a0d, a0dd)
        if disturbed:
            u = u + float(disturbance(t) if callable(disturbance) else disturbance)
        s = float(smooth_sign(ad, friction_width))
        return [ad, float(plant_model.acceleration(a, ad, u, friction_sign=s))]

    t_eval = np.asarray(reference.t)
    t_eval = t_eval[t_eval <= T + 1e-12]
    x0 = [float(reference.alpha0[0]), float(reference.alpha0_dot[0])]
    sol = solve_ivp(rhs, (0.0, float(t_eval[-1])), x0, t_eval=t_eval, rtol=rtol, atol=atol, method="DOP853")
    if not sol.success:
        raise RuntimeError(f"reduced-model integration failed: {sol.message}")
    a, ad = sol.y
    n = len(sol.t)
    a0, a0d, a0dd = (np.asarray(reference.alpha0)[:n], np.asarray(reference.alpha0_dot)[:n],
                     np.asarray(reference.alpha0_ddot)[:n])
    u = controller.voltage(a, ad, a0, a0d, a0dd)
    return {"t": sol.t, "alpha": a, "alpha_dot": ad, "alpha0": a0, "alpha0_dot": a0d, "E": a0 - a,
            "E_dot": a0d - ad, "voltage": u}
