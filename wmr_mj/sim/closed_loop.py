"""Closed-loop runs: the computed-torque law of the reduced model on the MuJoCo plant.

One run steps the C80 scene with ``mj_step`` and calls the controller every
``control_period`` (default: every 1 ms physics step), holding the voltage in
between; the motor's voltage limit is applied to what the controller asks for.
The tracking errors E = alpha0 - alpha, E' are compared with the analytic
region of ``wmr_mj.analysis.robustness`` (4.21)-(4.23) for the parameter box in use.

Usage::

    from wmr_mj.sim.closed_loop import RunConfig, run_closed_loop
    result = run_closed_loop(RunConfig(model="nonholonomic", m1=700.0))
    print(result.summary["sup_E"], result.summary["E_max"], result.summary["inside"])

``wmr_mj.sim.batch`` runs many of these at once on ``mujoco.batch``; a test keeps
the two bit-identical.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

from controllers import SteeringController, make_controller, model_from_source
from controllers.computed_torque import CONTROLLER_NAMES, FRICTION_SIGNS, MODEL_SOURCES
from wmr_mj._util.memory import require_run_memory
from wmr_mj._util.progress import progress_bar
from wmr_mj.analysis.certificate import certificate_for
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.params import C80, M1_NOMINAL, M1_RANGE, PAPER_KD, PAPER_KP, C80Parameters, parameter_names, with_params
from wmr_mj.plant.mjcf import STEERING_FRICTION_MODELS, TIMESTEP, TYRE_CONTACT_MODELS, Plant
from wmr_mj.sim.summary import RunSummary

__all__ = [
    "RunConfig",
    "RunResult",
    "run_closed_loop",
    "build_reference",
    "analysis_for",
    "analysis_box",
    "plant_parameters",
    "estimate_parameters",
    "report",
    "run_on_reduced_model",
    "PATH_NAMES",
    "ROW_FIELDS",
]

PATH_NAMES = ("paper-circle", "lane-change", "figure-eight")
# scalar fields recorded for every control step (see RunResult.rows)
ROW_FIELDS = ("t", "alpha", "alpha_dot", "alpha0", "alpha0_dot", "alpha0_ddot", "E", "E_dot",
              "voltage_cmd", "voltage", "current", "steer_torque", "heading")


@dataclass(frozen=True, kw_only=True)
class RunConfig:
    """Everything that defines a closed-loop run (JSON-able via ``as_dict``)."""

    controller: str = "computed-torque"
    model: str = "paper"  # model source of the controller's estimate
    m1: float = M1_NOMINAL  # plant chassis mass, kg
    duration: float = 35.0  # s
    control_period: float | None = None  # s; None: every physics step
    kp: float = PAPER_KP
    kd: float = PAPER_KD
    friction_sign: str = "measured"
    friction_width: float = 0.0  # rad/s, tanh smoothing of the Coulomb sign (0: exact sign)
    path: str = "paper-circle"
    plant_overrides: Mapping[str, float] = field(default_factory=dict)  # other plant parameters
    m1_inertia: str = "payload"
    identified: Any = None  # path or mapping from `wmr-mj identify` for model='identified'
    coefficients: Mapping[str, float] | None = None  # for model='explicit'
    box: str = "derived"  # 'derived' from the parameter set over m1_range, or 'paper' (5.1)
    m1_range: tuple[float, float] = M1_RANGE
    box_ranges: Mapping[str, tuple[float, float]] = field(default_factory=dict)  # other ranged parameters
    seed: int = 0  # recorded; a single run draws nothing at random
    steering_friction: str = "stiction"  # plant's steering friction law: one of STEERING_FRICTION_MODELS
    tyre_contact: str = "stiff"  # plant's tyre-floor contact law: one of TYRE_CONTACT_MODELS

    def __post_init__(self) -> None:
        if self.controller not in CONTROLLER_NAMES:
            raise UnknownNameError("controller", self.controller, CONTROLLER_NAMES)
        if self.model not in MODEL_SOURCES:
            raise UnknownNameError("model source", self.model, MODEL_SOURCES)
        if self.friction_sign not in FRICTION_SIGNS:
            raise UnknownNameError("friction sign", self.friction_sign, FRICTION_SIGNS)
        if self.path not in PATH_NAMES:
            raise UnknownNameError("path", self.path, PATH_NAMES)
        if self.box not in ("derived", "paper"):
            raise UnknownNameError("box", self.box, ("derived", "paper"))
        if self.steering_friction not in STEERING_FRICTION_MODELS:
            raise UnknownNameError("steering friction model", self.steering_friction, STEERING_FRICTION_MODELS)
        if self.tyre_contact not in TYRE_CONTACT_MODELS:
            raise UnknownNameError("tyre contact model", self.tyre_contact, TYRE_CONTACT_MODELS)
        for name in ("m1", "duration", "kp", "kd"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
                raise ParameterError(f"{name} = {value!r} is not accepted; a finite number > 0 is required")
        if self.control_period is not None and (not math.isfinite(self.control_period) or self.control_period <= 0):
            raise ParameterError(f"control_period = {self.control_period!r} s must be finite and > 0")
        lo, hi = self.m1_range
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
            raise ParameterError(f"m1_range = {self.m1_range!r} must be (lo, hi) with 0 < lo < hi")
        names = parameter_names()
        for name in self.plant_overrides:
            if name not in names:
                raise UnknownNameError("parameter", name, names)

    def as_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["plant_overrides"] = dict(self.plant_overrides)
        d["m1_range"] = list(self.m1_range)
        d["box_ranges"] = {k: list(v) for k, v in self.box_ranges.items()}
        if self.identified is not None and not isinstance(self.identified, (str, bytes)):
            d["identified"] = dict(self.identified.get("identified", self.identified))
        return d

    def replace(self, **changes: Any) -> RunConfig:
        return dataclasses.replace(self, **changes)


def plant_parameters(config: RunConfig, base: C80Parameters = C80) -> C80Parameters:
    """The plant's parameter set: base with m1 and the overrides (mass and inertia consistent)."""
    return with_params(base, m1_inertia=config.m1_inertia, m1=config.m1, **dict(config.plant_overrides))


def estimate_parameters(base: C80Parameters = C80) -> C80Parameters:
    """The controller's belief: the nominal parameter set (m1 = 650 kg)."""
    return base


def build_reference(path: str, params: C80Parameters, *, dt: float, duration: float):
    """(reference, settle_s) for a named path of C on a grid of step dt.

    settle_s is when the entry transient ends: for the paper's circle, the
    time C enters the circle; 0 for the other paths.
    """
    from wmr_mj.reference import paths as ref

    if path == "paper-circle":
        p = ref.paper_circle(params, duration=duration)
    elif path == "lane-change":
        p = ref.line(0.5) + ref.lane_change(0.5, 4.0) + ref.line(max(duration * params.V_A, 1.0))
    elif path == "figure-eight":
        p = ref.line(0.5) + ref.figure_eight(1.5, laps=max(1, int(duration * params.V_A / 20.0) + 1))
    else:
        raise UnknownNameError("path", path, PATH_NAMES)
    reference = ref.make_reference(p, params, dt=dt, duration=duration)
    settle_s = 0.0
    if path == "paper-circle":
        circle_start = float(p.starts[-2])  # starts ends with the total length
        reached = np.nonzero(np.asarray(reference.s) >= circle_start)[0]
        settle_s = float(reference.t[reached[0]]) if reached.size else float(reference.t[-1])
    return reference, settle_s


def analysis_box(config: RunConfig, params: C80Parameters = C80):
    """The parameter box of the analysis: the paper's (5.1), or derived from ``params`` over
    the config's m1 range (and box ranges) with the model the controller's source stands on
    ('nonholonomic' for nonholonomic and identified, 'paper' otherwise)."""
    from wmr_mj.analysis.robustness import ParameterBox

    if config.box == "paper":
        return ParameterBox.paper()
    box_model = "nonholonomic" if config.model in ("nonholonomic", "identified") else "paper"
    return ParameterBox.from_parameters(params, m1_range=tuple(config.m1_range), model=box_model,
                                        m1_inertia=config.m1_inertia,
                                        ranges={k: tuple(v) for k, v in config.box_ranges.items()} or None)


def analysis_for(config: RunConfig, reference, params: C80Parameters = C80, *, estimate=None):
    """The robustness analysis (4.17)-(4.23) for the run's box, gains and reference bounds.

    estimate: the controller's coefficients (P^, C_V^, F^, K^); the parameter
    errors are then truth-anywhere-in-the-box minus this estimate. None: the
    estimate is anywhere in the box too, as in the paper's (4.2).
    """
    from wmr_mj.analysis.robustness import ReferenceBounds, analyse

    box = analysis_box(config, params)
    b = reference.bounds()
    bounds = ReferenceBounds(alpha_ddot_max=max(b["max_abs_alpha0_ddot"], 1e-12),
                             alpha_dot_max=max(b["max_abs_alpha0_dot"], 1e-12),
                             sin_cos3_max=max(b["max_sin_cos3"], 1e-12))
    return analyse(box, kp=config.kp, kd=config.kd, bounds=bounds, estimate=estimate)


@dataclass
class RunResult:
    """Time histories (one row per control step) and the run's summary."""

    config: RunConfig
    rows: dict[str, np.ndarray]
    summary: RunSummary
    status: str = "completed"


def _controller(config: RunConfig, params: C80Parameters) -> SteeringController:
    model = model_from_source(config.model, params=params, identified=config.identified,
                              coefficients=config.coefficients)
    return make_controller(config.controller, model, kp=config.kp, kd=config.kd,
                           friction_sign=config.friction_sign, friction_width=config.friction_width)


def _estimate_of(controller: SteeringController) -> dict[str, float]:
    """The coefficients the controller's model-based part uses (K^ etc.); a PD has none but P^."""
    c = controller.model.coefficients.as_dict()
    if controller.name == "pd":
        return {"P": c["P"], "C_V": 0.0, "F": 0.0, "K": 0.0}
    if getattr(controller, "friction_sign", None) == "none":
        c["F"] = 0.0
    return {k: c[k] for k in ("P", "C_V", "F", "K")}


def _substeps(config: RunConfig, timestep: float) -> int:
    if config.control_period is None:
        return 1
    n = round(config.control_period / timestep)
    if n < 1 or abs(n * timestep - config.control_period) > 1e-9:
        raise ParameterError(f"control_period = {config.control_period} s must be a multiple of the "
                             f"physics step {timestep} s")
    return n


def report(config: RunConfig, *, analysis, params: C80Parameters, settle_s: float, sup_E: float, sup_Edot: float,
           sup_E_settled: float, sup_Edot_settled: float, saturated_fraction: float, left_range_at: float | None,
           final_alpha: float, control_steps: int, steps: int, wall_s: float, status: str,
           certificate=None, drift: Mapping[str, Any] | None = None) -> RunSummary:
    """The run's report: sup errors (whole run and after the entry transient) against the region.

    Shared by the serial runner and the batched sweep so both report alike. E_max,
    Edot_max, inside, E_ratio, Edot_ratio are the paper's claim (``analysis``); with a
    ``certificate`` (:mod:`wmr_mj.analysis.certificate`) and the end-of-run ``drift``
    (:func:`wmr_mj.analysis.verdicts.drift`) the separated verdict is added
    (:func:`wmr_mj.analysis.verdicts.judge_run`: verdict, certificate, paper_region, drift).
    """
    sup_E, sup_Edot = float(sup_E), float(sup_Edot)
    from wmr_mj.analysis.verdicts import judge_run, paper_region

    paper = paper_region(analysis, sup_E, sup_Edot)
    E_max, Ed_max = paper["E_max"], paper["Edot_max"]
    out: RunSummary = {
        "status": status,
        "controller": config.controller,
        "model": config.model,
        "m1": float(params.m1),
        "kp": config.kp,
        "kd": config.kd,
        "path": config.path,
        "duration": steps * TIMESTEP,
        "steps": int(steps),
        "control_steps": int(control_steps),
        "wall_s": float(wall_s),
        "realtime_factor": float(steps * TIMESTEP / wall_s) if wall_s > 0 else None,
        "sup_E": float(sup_E),
        "sup_Edot": float(sup_Edot),
        "settle_s": float(settle_s),
        "sup_E_settled": float(sup_E_settled),
        "sup_Edot_settled": float(sup_Edot_settled),
        "E_max": E_max,
        "Edot_max": Ed_max,
        "condition": paper["condition"],
        "stable": bool(analysis.stable),
        "inside": paper["inside"],
        "E_ratio": sup_E / E_max if math.isfinite(E_max) and E_max > 0 else None,
        "Edot_ratio": sup_Edot / Ed_max if math.isfinite(Ed_max) and Ed_max > 0 else None,
        "saturated_fraction": float(saturated_fraction),
        "left_steering_range": left_range_at is not None,
        "left_steering_range_at_s": left_range_at,
        "final_alpha": float(final_alpha),
    }
    if certificate is not None:
        out.update(judge_run(certificate=certificate, analysis=analysis, sup_E=sup_E, sup_Edot=sup_Edot,
                             drift=drift or {}))
    return out


def _sup(x: np.ndarray) -> float:
    return float(np.max(np.abs(x))) if x.size else 0.0


def _drift_of(E: np.ndarray, final_alpha_dot: float, period: float) -> dict[str, Any]:
    """End-of-run drift from the serial rows (the batch computes the same windows per block).

    final_alpha_dot: alpha' of the last control step, as alpha0' - E' (the batch keeps E', not alpha').
    """
    from wmr_mj.analysis.verdicts import drift, drift_window_steps

    k = len(E)
    w = drift_window_steps(k, period)
    return drift(prev_window=_sup(E[max(0, k - 2 * w):k - w]), last_window=_sup(E[k - w:]),
                 final_alpha_dot=final_alpha_dot)


def run_closed_loop(
    config: RunConfig = RunConfig(),
    *,
    logger_factory: Callable[..., Any] | None = None,
    progress: bool | None = None,
    base: C80Parameters = C80,
) -> RunResult:
    """Run ``config`` on the MuJoCo plant; optionally stream rows to an MCAP logger.

    logger_factory(mjcf_xml=..., config=..., parameters=..., initial_state=..., timestep=...,
    control_substeps=..., reference_path=..., bounds={"E_max", "Edot_max"}, model=the compiled
    plant) returns a ``wmr_mj.logs.writer.RunLogger``; it
    receives a block of rows every simulated second and is closed with the summary,
    also when the run is interrupted (KeyboardInterrupt or SIGTERM).
    """
    params = plant_parameters(config, base)
    estimate = estimate_parameters(base)
    controller = _controller(config, estimate)
    plant = Plant(params, steering_friction=config.steering_friction, tyre_contact=config.tyre_contact)
    m, d = plant.model, plant.data
    dt = m.opt.timestep
    substeps = _substeps(config, dt)
    period = substeps * dt
    n = int(round(config.duration / period))
    require_run_memory(duration_s=n * period, control_period_s=period)  # before the arrays
    reference, settle_s = build_reference(config.path, estimate, dt=period, duration=n * period)
    analysis = analysis_for(config, reference, estimate, estimate=_estimate_of(controller))
    certificate = certificate_for(config, reference, params=base)
    a0_all, a0d_all, a0dd_all = reference.alpha0, reference.alpha0_dot, reference.alpha0_ddot
    if len(a0_all) < n:
        raise ParameterError(f"reference shorter than the run: {len(a0_all)} < {n} samples")

    full = logger_factory is not None
    block_len = max(1, int(round(1.0 / period)))  # one simulated second per block
    rows = {k: np.empty(n) for k in ROW_FIELDS}
    if full:  # per logged row: qpos, qvel, ctrl in one mj_getState call, and the site positions
        log_spec = int(mujoco.mjtState.mjSTATE_QPOS | mujoco.mjtState.mjSTATE_QVEL | mujoco.mjtState.mjSTATE_CTRL)
        log_state = np.empty((block_len, mujoco.mj_stateSize(m, log_spec)))
        log_sites = np.empty((block_len, m.nsite, 3))
        state_rows, site_rows, get_state = list(log_state), list(log_sites), mujoco.mj_getState  # cheaper per step
    logger = None
    if full:
        state = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
        mujoco.mj_getState(m, d, state, mujoco.mjtState.mjSTATE_INTEGRATION)
        logger = logger_factory(mjcf_xml=plant.xml, config=config.as_dict(), parameters=params.as_dict(),
                                initial_state=state, timestep=dt, control_substeps=substeps,
                                bounds={"E_max": certificate.E_max, "Edot_max": certificate.Edot_max}, model=m,
                                reference_path=np.asarray(reference.C_xy)[::max(1, len(reference.C_xy) // 2000)])

    qpos, qvel, ctrl = d.qpos, d.qvel, d.ctrl
    qa, dv, act = plant.steer_qpos, plant.steer_dof, plant.steer_actuator
    chassis, site_A, site_C = plant.chassis_body, plant.site_A, plant.site_C
    xquat, site_xpos, act_force, qfrc_act = d.xquat, d.site_xpos, d.actuator_force, d.qfrc_actuator
    limit = params.voltage_limit
    range_limit = params.steering_range - 1e-3
    k_i = params.k_i
    law = controller.voltage_scalar
    r_t, r_a, r_ad, r_a0, r_a0d, r_a0dd = (rows[k] for k in ("t", "alpha", "alpha_dot", "alpha0", "alpha0_dot",
                                                              "alpha0_ddot"))
    r_E, r_Ed, r_uc, r_u, r_i, r_tau, r_h = (rows[k] for k in ("E", "E_dot", "voltage_cmd", "voltage", "current",
                                                                "steer_torque", "heading"))
    saturated = 0
    left_range_at = None
    bar = progress_bar(n, desc="run", unit="step", unit_scale=True, enabled=progress)
    status = "completed"
    k = 0
    block_start = 0
    wall0 = time.perf_counter()

    def flush(upto: int) -> None:
        nonlocal block_start
        if logger is None or upto <= block_start:
            return
        sl = slice(block_start, upto)
        block = {key: rows[key][sl] for key in ROW_FIELDS}
        cnt = upto - block_start
        st, nq, nv = log_state[:cnt], m.nq, m.nv
        block.update(qpos=st[:, :nq].copy(), qvel=st[:, nq:nq + nv].copy(), ctrl=st[:, nq + nv:].copy(),
                     A_pos=log_sites[:cnt, site_A, :2].copy(), C_pos=log_sites[:cnt, site_C, :2].copy())
        block_start = upto  # first: an interrupt raised as the block is written must not send it twice
        logger.write_block(block)

    try:
        while k < n:
            a = float(qpos[qa])
            ad = float(qvel[dv])
            a0, a0d, a0dd = float(a0_all[k]), float(a0d_all[k]), float(a0dd_all[k])
            u_cmd = law(a, ad, a0, a0d, a0dd)
            if u_cmd != u_cmd:  # NaN from a diverged law: apply nothing, keep the record
                u = 0.0
            else:
                u = limit if u_cmd > limit else (-limit if u_cmd < -limit else u_cmd)
            if u != u_cmd:
                saturated += 1
            ctrl[act] = u
            if full:
                j = k - block_start
                get_state(m, d, state_rows[j], log_spec)
            for _ in range(substeps):
                mujoco.mj_step(m, d)
            # after mj_step, forces and kinematics belong to the state the step started from
            r_t[k] = k * period
            r_a[k] = a
            r_ad[k] = ad
            r_a0[k] = a0
            r_a0d[k] = a0d
            r_a0dd[k] = a0dd
            r_E[k] = a0 - a
            r_Ed[k] = a0d - ad
            r_uc[k] = u_cmd
            r_u[k] = u
            r_i[k] = act_force[act] / k_i
            r_tau[k] = qfrc_act[dv]
            q = xquat[chassis]
            r_h[k] = math.atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]))
            if full:
                site_rows[j][...] = site_xpos
            if left_range_at is None and abs(a) >= range_limit:
                left_range_at = k * period
            k += 1
            if full and k - block_start == block_len:
                flush(k)
            if k & 1023 == 0:
                bar.update(1024)
    except KeyboardInterrupt:
        status = "interrupted"
    finally:
        bar.close()
    wall = time.perf_counter() - wall0
    done = {key: v[:k] for key, v in rows.items()}
    if k == 0:
        raise KeyboardInterrupt  # nothing simulated: nothing to report
    after = done["t"] >= settle_s
    summary = report(config, analysis=analysis, params=params, settle_s=settle_s, sup_E=_sup(done["E"]),
                     sup_Edot=_sup(done["E_dot"]), sup_E_settled=_sup(done["E"][after]),
                     sup_Edot_settled=_sup(done["E_dot"][after]), saturated_fraction=saturated / k,
                     left_range_at=left_range_at, final_alpha=done["alpha"][-1], control_steps=k,
                     steps=k * substeps, wall_s=wall, status=status, certificate=certificate,
                     drift=_drift_of(done["E"], done["alpha0_dot"][-1] - done["E_dot"][-1], period))
    summary["mujoco_warnings"] = int(sum(w.number for w in d.warning))
    summary["analysis"] = analysis.as_dict()
    summary["controller_config"] = controller.describe()
    if logger is not None:
        flush(k)
        logger.close(summary, status=status)
    return RunResult(config=config, rows=done, summary=summary, status=status)


def run_on_reduced_model(
    controller: SteeringController,
    plant_model,
    reference,
    *,
    duration: float | None = None,
    friction_width: float = 0.0,
    rtol: float = 1e-10,
    atol: float = 1e-12,
) -> dict[str, np.ndarray]:
    """The paper's view: the same controller on a reduced model as the plant, with scipy.

    Integrates P a'' + G(a') + K(a) = u (``plant_model``, a
    :class:`wmr_mj.plant.reduced.SteeringModel`) with u from ``controller`` evaluated
    continuously (no sampling, no voltage limit), from zero error. The plant's
    Coulomb sign is x/sqrt(x^2+w^2) with w = friction_width (0: exact sign).
    Returns rows t, alpha, alpha_dot, alpha0, alpha0_dot, E, E_dot, voltage on the
    reference's grid.
    """
    from scipy.integrate import solve_ivp

    from wmr_mj.plant.reduced import smooth_sign

    T = float(reference.duration if duration is None else duration)
    law = controller.voltage_scalar

    def rhs(t, x):
        a, ad = float(x[0]), float(x[1])
        a0, a0d, a0dd = (float(v) for v in reference.at(t))
        u = law(a, ad, a0, a0d, a0dd)
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
