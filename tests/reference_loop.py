"""Today's serial closed loop, kept as the reference the one engine is compared against, bit for bit.

This is ``wmr_mj.sim.closed_loop.run_closed_loop`` as it was before a single run became a batch of
one through the compiled law (issue 17): one ``mj_step`` at a time, the law in Python, per-step
reads, clipping and row copies. It is not part of the product; tests/test_engine.py runs both and
compares rows, summaries and logs.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np

from wmr_mj._util.memory import require_run_memory
from wmr_mj._util.progress import progress_bar
from wmr_mj.errors import ParameterError
from wmr_mj.params import C80, C80Parameters
from wmr_mj.plant.mjcf import Plant
from wmr_mj.sim.certify import certificate_for
from wmr_mj.sim.closed_loop import (
    ROW_FIELDS,
    RunMeasures,
    RunResult,
    _drift_of,
    _sup,
    judge_path,
    path_sample_index,
    report,
)
from wmr_mj.sim.config import (
    RunConfig,
    analysis_for,
    build_reference,
    coerce,
    controller_for,
    estimate_of,
    estimate_parameters,
    plant_parameters,
)
from wmr_mj.sim.log_header import LogHeader
from wmr_mj.sim.parts import RunLabels, control_substeps
from wmr_mj.sim.summary import voltage_effort


def reference_run(
    config: RunConfig = RunConfig(),
    *,
    logger_factory: Callable[..., Any] | None = None,
    progress: bool | None = None,
    base: C80Parameters = C80,
) -> RunResult:
    """Run ``config`` on the MuJoCo plant; optionally stream rows to an MCAP logger.

    logger_factory(header) takes the run's ``wmr_mj.sim.log_header.LogHeader`` and returns a
    ``wmr_mj.logs.writer.RunLogger``; it
    receives a block of rows every simulated second and is closed with the summary,
    also when the run is interrupted (KeyboardInterrupt or SIGTERM).
    """
    config = coerce(config)  # as resolve_run does: a config given directly, its references read
    params = plant_parameters(config, base)
    estimate = estimate_parameters(base)
    controller = controller_for(config, estimate)
    plant = Plant(params, steering_friction=config.steering_friction, tyre_contact=config.tyre_contact)
    m, d = plant.model, plant.data
    dt = m.opt.timestep
    substeps = control_substeps(config.control_period, dt)
    period = substeps * dt
    n = int(round(config.duration / period))
    require_run_memory(duration_s=n * period, control_period_s=period)  # before the arrays
    reference, settle_s = build_reference(config.path, estimate, dt=period, duration=n * period)
    analysis = analysis_for(config, reference, estimate, estimate=estimate_of(controller))
    certificate = certificate_for(config, reference, params=base)
    a0_all, a0d_all, a0dd_all = reference.alpha0, reference.alpha0_dot, reference.alpha0_ddot
    if len(a0_all) < n:
        raise ParameterError(f"reference shorter than the run: {len(a0_all)} < {n} samples")

    full = logger_factory is not None
    block_len = max(1, int(round(1.0 / period)))  # one simulated second per block
    rows = {k: np.empty(n) for k in ROW_FIELDS}
    r_C = np.empty((n, 2))  # C's xy at every control step (the path errors)
    if full:  # per logged row: qpos, qvel, ctrl in one mj_getState call, and the site positions
        log_spec = int(mujoco.mjtState.mjSTATE_QPOS | mujoco.mjtState.mjSTATE_QVEL | mujoco.mjtState.mjSTATE_CTRL)
        log_state = np.empty((block_len, mujoco.mj_stateSize(m, log_spec)))
        log_sites = np.empty((block_len, m.nsite, 3))
        state_rows, site_rows, get_state = list(log_state), list(log_sites), mujoco.mj_getState  # cheaper per step
    logger = None
    if full:
        state = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
        mujoco.mj_getState(m, d, state, mujoco.mjtState.mjSTATE_INTEGRATION)
        logger = logger_factory(LogHeader(
            mjcf_xml=plant.xml, config=config.to_dict(), parameters=params.to_dict(),
            initial_state=state, timestep=dt, control_substeps=substeps,
            bounds={"E_max": certificate.E_max, "Edot_max": certificate.Edot_max}, model=m,
            reference_path=np.asarray(reference.C_xy)[::max(1, len(reference.C_xy) // 2000)]))

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
            r_C[k] = site_xpos[site_C, :2]
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
    at = path_sample_index(k, period)
    measured = RunMeasures(status=status, settle_s=settle_s, sup_E=_sup(done["E"]), sup_Edot=_sup(done["E_dot"]),
                           sup_E_settled=_sup(done["E"][after]), sup_Edot_settled=_sup(done["E_dot"][after]),
                           saturated_fraction=saturated / k, left_range_at=left_range_at,
                           final_alpha=done["alpha"][-1], control_steps=k, steps=k * substeps, wall_s=wall,
                           effort=voltage_effort(done["voltage"], period))  # the applied voltage's
    summary = report(RunLabels.of(config), measured, analysis=analysis, params=params, certificate=certificate,
                     drift=_drift_of(done["E"], done["alpha0_dot"][-1] - done["E_dot"][-1], period),
                     path=judge_path(reference, done["t"][at], r_C[:k][at], done["heading"][at], settle_s=settle_s,
                                     certificate=certificate, steering_range=params.steering_range))
    summary = dataclasses.replace(summary, mujoco_warnings=int(sum(w.number for w in d.warning)),
                                  analysis=analysis.to_dict(), controller_config=controller.describe())
    from wmr_mj.reference.route import RouteProgress, route_length
    from wmr_mj.sim.config import manoeuvre_length

    route_m = route_length(config.path) or manoeuvre_length(config.path)  # a route's, or a lane change's manoeuvre
    if route_m is not None:
        summary = dataclasses.replace(summary, route=RouteProgress.along(route_m, reference, summary.duration))
    if logger is not None:
        flush(k)
        logger.close(summary.to_dict(), status=status)
    return RunResult(config=config, rows=done, summary=summary, status=status)
