"""The compiled law (wmr_mj/sim/_compiled_law.c as mjcb_control) against the Python law and the serial loop."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.sim import compiled_law
from wmr_mj.sim.batch import batch_law_backend, batch_model, run_batch
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig, controller_for, estimate_parameters, plant_parameters

BASE = RunConfig(model="nonholonomic", duration=10.0)
KEYS = ("sup_E", "sup_Edot", "sup_E_settled", "sup_Edot_settled", "E_max", "Edot_max", "saturated_fraction",
        "final_alpha", "inside", "left_steering_range", "left_steering_range_at_s", "verdict", "certificate",
        "paper_region", "drift", "mujoco_warnings")
OPTIONS = [dict(model="paper"), dict(model="nonholonomic"), dict(model="paper-lagrange"),
           dict(model="paper", friction_sign="reference"), dict(model="nonholonomic", friction_sign="none"),
           dict(model="paper", friction_width=0.01),
           dict(model="nonholonomic", friction_sign="reference", friction_width=0.01),
           dict(controller="pd", model="paper")]
ALPHA = (0.0, 0.31, -0.62, 0.05, 0.8, -0.1, 0.2, 0.0, 1.2)  # rad
ALPHA_DOT = (0.0, 0.4, -0.03, 0.0, -1.5, 2e-3, -2e-3, 0.1, 3.0)  # rad/s (exact zeros included)
REFERENCE = (np.array([0.3, -0.5, 0.0, 0.7]), np.array([0.1, 0.0, -0.2, 0.4]), np.array([-0.2, 0.4, 0.0, 9.0]))


def law_model(controller, *, voltage_limit: float, substeps: int = 1, reference=REFERENCE) -> mujoco.MjModel:
    params = plant_parameters(BASE)
    plain = batch_model(params)
    steer = plain.joint("steer").id
    law = compiled_law.law_vector(controller, voltage_limit=voltage_limit, substeps=substeps,
                                  nstep=len(reference[0]), qpos_adr=int(plain.jnt_qposadr[steer]),
                                  dof_adr=int(plain.jnt_dofadr[steer]), actuator=plain.actuator("steering_motor").id)
    return batch_model(params, law=(law, reference))


def test_the_compiled_law_is_built_and_runs_in_this_environment():
    # pip install builds it wherever a C compiler is found, as on the machines make test runs on
    assert compiled_law.unavailable_reason() is None
    compiled_law.install()
    compiled_law.install()  # idempotent


@pytest.mark.parametrize("options", OPTIONS)
def test_the_callback_is_bit_identical_to_the_scalar_law(options):
    compiled_law.install()
    controller = controller_for(RunConfig(**options), estimate_parameters())
    limit = 5.0  # low, so that some voltages are clipped
    m = law_model(controller, voltage_limit=limit)
    d = mujoco.MjData(m)
    qa, dv, act = m.jnt_qposadr[m.joint("steer").id], m.jnt_dofadr[m.joint("steer").id], m.actuator("steering_motor").id
    clipped = 0
    for k in range(len(REFERENCE[0])):
        ref = tuple(float(r[k]) for r in REFERENCE)
        for alpha, alpha_dot in zip(ALPHA, ALPHA_DOT):
            d.qpos[qa], d.qvel[dv], d.time = alpha, alpha_dot, k * m.opt.timestep
            mujoco.mj_forward(m, d)  # mjcb_control runs inside it, as inside mj_step
            u = controller.voltage_scalar(alpha, alpha_dot, *ref)
            applied = min(max(u, -limit), limit)
            assert d.userdata[:6].tolist() == [alpha, ref[0] - alpha, ref[1] - alpha_dot, u, alpha_dot, applied]
            assert d.ctrl[act] == applied
            assert d.userdata[6] == 0.0  # no chassis named: no heading
            clipped += abs(u) > limit
    assert 0 < clipped < len(ALPHA) * len(REFERENCE[0])


def test_the_law_holds_between_control_steps_and_stops_after_the_reference():
    compiled_law.install()
    controller = controller_for(BASE, estimate_parameters())
    m = law_model(controller, voltage_limit=24.0, substeps=5)
    d = mujoco.MjData(m)
    act = m.actuator("steering_motor").id
    d.time = 5 * m.opt.timestep  # control step 1
    mujoco.mj_forward(m, d)
    held = d.ctrl[act]
    assert held == controller.voltage_scalar(0.0, 0.0, *(float(r[1]) for r in REFERENCE)) != 0.0
    for step in (6, 9, 20):  # inside a control period; past the last control step (4 steps x 5 = 20)
        d.ctrl[act], d.time = 123.0, step * m.opt.timestep
        mujoco.mj_forward(m, d)
        assert d.ctrl[act] == 123.0


def test_a_nan_law_applies_nothing_as_the_serial_loop():
    compiled_law.install()
    controller = controller_for(BASE, estimate_parameters())
    reference = tuple(np.array([math.nan, 0.2]) for _ in range(3))
    m = law_model(controller, voltage_limit=24.0, reference=reference)
    d = mujoco.MjData(m)
    d.ctrl[:] = 7.0
    mujoco.mj_forward(m, d)
    assert math.isnan(d.userdata[3]) and d.ctrl[m.actuator("steering_motor").id] == 0.0


def test_models_without_the_law_step_as_if_no_callback_were_installed():
    compiled_law.install()
    params = plant_parameters(BASE)
    law_sized = " ".join(["0"] * len(compiled_law.LAW_FIELDS))  # the law's size, under another name
    for m in (batch_model(params), mujoco.MjModel.from_xml_string(
            f'<mujoco><size nuserdata="4"/><custom><numeric name="wmr_mj_lax" data="{law_sized}"/>'
            '<numeric name="other" data="0 0 0"/></custom><worldbody><body><joint name="j"/><geom size=".1"/>'
            '</body></worldbody><actuator><motor joint="j"/></actuator></mujoco>')):
        d = mujoco.MjData(m)
        d.ctrl[:] = 0.25
        for _ in range(3):
            mujoco.mj_step(m, d)
        assert (d.ctrl == 0.25).all() and not d.userdata.any()


@pytest.mark.slow
@pytest.mark.parametrize("options", [dict(), dict(model="paper"), dict(control_period=0.005),
                                     dict(friction_sign="reference", friction_width=0.01),
                                     dict(controller="pd", model="paper", kp=25.0, kd=10.0),
                                     dict(path="lane-change", steering_friction="soft")])
def test_a_compiled_batch_is_bit_identical_to_serial_runs_and_to_the_numpy_batch(options):
    configs = [BASE.replace(m1=m, **options) for m in (556.0, 690.0)]
    configs.append(BASE.replace(m1=640.0, plant_overrides={"mu": 0.03, "R_a": 1.25}, **options))
    compiled = run_batch(configs, nthread=2, law="compiled")
    numpy_law = run_batch(configs, nthread=2, law="numpy")
    assert {r.batch.law for r in compiled} == {"compiled"} and {r.batch.law for r in numpy_law} == {"numpy"}
    for cfg, c, n in zip(configs, compiled, numpy_law):
        serial, c, n = run_closed_loop(cfg, progress=False).summary.to_dict(), c.to_dict(), n.to_dict()
        for key in KEYS:
            assert c[key] == serial[key] == n[key], (cfg, key)
    assert len({r.sup_E for r in compiled}) == len(configs)  # the runs differ: not copies compared


def test_a_simulation_with_a_warning_is_rerun_serially(monkeypatch):
    """Rollout stops a simulation whose warnings rise; run_batch then reports the serial run."""
    from wmr_mj.sim import batch

    run_group = batch._run_group_compiled

    def with_a_warning(loop, models, idx, threads, stats, stop, progress):
        run_group(loop, models, idx, threads, stats, stop, progress)
        stats.sup_E[idx[1]] = 99.0  # what a stopped simulation might report
        stats.warnings[idx[1]] = 1

    monkeypatch.setattr(batch, "_run_group_compiled", with_a_warning)
    configs = [BASE.replace(m1=m) for m in (600.0, 700.0)]
    reports = run_batch(configs, nthread=1, law="compiled")
    serial = run_closed_loop(configs[1], progress=False).summary
    assert reports[1].sup_E == serial.sup_E != 99.0
    assert reports[1].mujoco_warnings == serial.mujoco_warnings


def test_the_law_backend_is_chosen_and_refused_clearly(monkeypatch):
    from controllers import ComputedTorque

    controller = controller_for(BASE, estimate_parameters())
    assert batch_law_backend(controller) == "compiled" and batch_law_backend(controller, "numpy") == "numpy"
    with pytest.raises(UnknownNameError, match="auto"):
        batch_law_backend(controller, "fortran")

    class Custom(ComputedTorque):
        pass

    custom = Custom(controller.model)
    assert batch_law_backend(custom) == "numpy"
    with pytest.raises(ParameterError, match="and PDController; Custom offers no pure law function"):
        batch_law_backend(custom, "compiled")
    monkeypatch.setenv("WMR_MJ_COMPILED_LAW", "0")
    assert batch_law_backend(controller) == "numpy"
    with pytest.raises(ParameterError, match="WMR_MJ_COMPILED_LAW=0"):
        batch_law_backend(controller, "compiled")


def test_attach_refuses_a_spec_it_would_misread():
    spec = mujoco.MjSpec()
    spec.add_numeric(name="first", data=[1.0])
    with pytest.raises(ParameterError, match="first numeric"):
        compiled_law.attach(spec, np.zeros(len(compiled_law.LAW_FIELDS)), REFERENCE)
    with pytest.raises(ParameterError, match="LAW_FIELDS"):
        compiled_law.attach(mujoco.MjSpec(), np.zeros(3), REFERENCE)


def test_a_law_built_for_another_mujoco_is_refused_with_the_reason(monkeypatch):
    compiled_law._library.cache_clear()
    monkeypatch.setattr(mujoco, "mj_version", lambda: 3_999_999)
    try:
        assert "built for MuJoCo 4" in compiled_law.unavailable_reason() and "this is 3999999" in \
            compiled_law.unavailable_reason()
        assert batch_law_backend(controller_for(BASE, estimate_parameters())) == "numpy"
        with pytest.raises(ParameterError, match="cannot run: .*built for MuJoCo"):
            compiled_law.install()
    finally:
        compiled_law._library.cache_clear()


def test_a_compiled_batch_too_large_for_memory_is_refused_before_it_starts(monkeypatch):
    from wmr_mj._util import memory
    from wmr_mj.errors import NotEnoughMemoryError

    monkeypatch.setattr(memory, "available_memory_bytes", lambda: 100_000)  # < 2 runs x 10,000 steps x 24 B
    with pytest.raises(NotEnoughMemoryError, match="compiled law.*WMR_MJ_COMPILED_LAW=0"):
        run_batch([BASE.replace(m1=600.0), BASE.replace(m1=700.0)], law="compiled")


def test_without_the_built_library_the_reason_says_so_and_the_batch_uses_numpy(monkeypatch):
    import sys

    compiled_law._library.cache_clear()
    import wmr_mj.sim

    monkeypatch.setitem(sys.modules, "wmr_mj.sim._compiled_law", None)  # what an install without a compiler has
    monkeypatch.delattr(wmr_mj.sim, "_compiled_law", raising=False)
    try:
        assert "is not built" in compiled_law.unavailable_reason()
        reports = run_batch([BASE.replace(m1=600.0)], law="auto")
        assert reports[0].batch.law == "numpy"
        assert reports[0].sup_E == run_closed_loop(BASE.replace(m1=600.0), progress=False).summary.sup_E
    finally:
        compiled_law._library.cache_clear()
