"""The steering motor's actuation options in the C80 model: delay, inductance, current limit.

Measured 2026-11-26 on the 2-core machine (MuJoCo 4.0.0): ``pytest tests/test_actuation_model.py``.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from wmr_mj import C80
from wmr_mj.errors import ParameterError
from wmr_mj.plant import mjcf

K = math.sqrt(C80.k_i * C80.k_b)  # N m/A, the dcmotor's constant
HELD = 1e12  # kg m^2 on the steering joint: it does not move, so no back-EMF


def _held(**options) -> tuple[mujoco.MjModel, mujoco.MjData, mjcf.SteeringAddresses]:
    model, _ = mjcf.compile_model(**options)
    at = mjcf.steering_joint_addresses(model)
    model.dof_armature[at.motor_dof] = HELD
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    return model, data, at


def test_defaults_write_todays_model_byte_for_byte():
    explicit = {"actuation_delay_s": 0.0, "inductance_H": 0.0, "current_limit_A": None, "backlash_rad": 0.0}
    assert mjcf.robot_xml(**explicit) == (mjcf.MODELS_DIR / "c80.xml").read_text()
    assert mjcf.scene_xml(**explicit) == mjcf.scene_xml()
    assert Path(mjcf.MODELS_DIR / "c80.xml").read_text().count("nsample") == 0


def test_inductance_current_rises_as_one_minus_exp():
    """i(t) = V/R (1 - exp(-t R/L)) for a voltage step on the held joint.

    MuJoCo advances the dcmotor's current exactly over a step of constant voltage (an
    exponential: 2.1752 A after the first 1 ms at 12 V and L/R = 5 ms, where explicit Euler
    would give 2.4 A and implicit Euler 2.0 A), so the tolerance is rounding: measured
    |error| < 1e-9 A; tolerance 1e-6 A. actearly: the force uses the step's new current.
    """
    inductance, volts = 0.005, 12.0
    model, data, at = _held(inductance_H=inductance)
    assert at.current_act is not None and model.na == 1
    data.ctrl[at.actuator] = volts
    currents, forces = [], []
    for _ in range(50):
        mujoco.mj_step(model, data)
        currents.append(data.act[at.current_act])
        forces.append(data.actuator_force[at.actuator])
    t = np.arange(1, 51) * model.opt.timestep
    expected = volts / C80.R_a * (1 - np.exp(-t * C80.R_a / inductance))
    assert np.max(np.abs(np.asarray(currents) - expected)) < 1e-6
    assert np.asarray(forces) == pytest.approx(K * np.asarray(currents), rel=1e-9)


def test_current_limit_bounds_the_delivered_current_and_the_state_winds_up():
    """saturation's current limit clamps the force to +-K I_max (the docs: a torque limit).

    Without inductance the current is algebraic and never exceeds the limit. With inductance
    the delivered current (force / K) never exceeds it, but the current state does not stop
    there: MuJoCo 4.0 does not clamp a dcmotor's activation (actlimited/actrange are ignored;
    measured: 23.94 A with a 5 A limit and actrange +-5). After a reversal the delivered
    current stays at the limit for tau ln((i + V/R)/(I_max + V/R)) = 2.52 ms (3 steps),
    predicted and measured. Physically, a driver's current loop would hold the current at
    the limit; the windup delays the reversal by at most tau ln 2.
    """
    limit, volts = 5.0, 24.0
    model, data, at = _held(current_limit_A=limit)
    data.ctrl[at.actuator] = volts
    for _ in range(5):
        mujoco.mj_step(model, data)
        assert abs(data.actuator_force[at.actuator]) / K == pytest.approx(limit, rel=1e-9)
    inductance = 0.005
    model, data, at = _held(current_limit_A=limit, inductance_H=inductance)
    data.ctrl[at.actuator] = volts
    delivered = []
    for _ in range(60):
        mujoco.mj_step(model, data)
        delivered.append(data.actuator_force[at.actuator] / K)
    state = data.act[at.current_act]
    assert max(np.abs(delivered)) <= limit * (1 + 1e-9) and state > 4 * limit
    data.ctrl[at.actuator] = -volts
    held = 0
    while data.actuator_force[at.actuator] / K >= limit * (1 - 1e-9):
        mujoco.mj_step(model, data)
        held += 1
    tau = inductance / C80.R_a
    predicted = tau * math.log((state + volts / C80.R_a) / (limit + volts / C80.R_a))
    assert held == math.ceil(predicted / model.opt.timestep)


@pytest.mark.parametrize("delay_steps", [1, 3, 20])
def test_delay_reads_the_voltage_from_exactly_d_steps_before(delay_steps):
    """The force sequence is the undelayed one shifted by d steps (zeros before)."""
    model, data, at = _held(actuation_delay_s=delay_steps * mjcf.TIMESTEP)
    volts = np.linspace(1.0, 20.0, 40)
    forces = []
    for v in volts:
        data.ctrl[at.actuator] = v
        mujoco.mj_step(model, data)
        forces.append(data.actuator_force[at.actuator])
    expected = K / C80.R_a * np.concatenate([np.zeros(delay_steps), volts[:-delay_steps]])
    assert np.asarray(forces) == pytest.approx(expected, rel=1e-9, abs=1e-12)


def test_mujocos_own_delay_case_reads_0_0_10():
    """engine_forward_test.cc ActuatorDelay: dt 0.01, delay 0.02, ctrl 10 -> forces 0, 0, 10."""
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><option timestep="0.01"/><worldbody><body><joint name="j"/><geom size=".1"/></body>'
        '</worldbody><actuator><motor joint="j" nsample="2" delay="0.02"/></actuator></mujoco>')
    data = mujoco.MjData(model)
    forces = []
    for _ in range(3):
        data.ctrl[0] = 10.0
        mujoco.mj_step(model, data)
        forces.append(float(data.actuator_force[0]))
    assert forces == [0.0, 0.0, 10.0]


@pytest.mark.parametrize("options, culprit", [
    ({"actuation_delay_s": 0.0025}, "actuation_delay_s = 0.0025 s is not a whole number of physics steps"),
    ({"actuation_delay_s": -0.001}, "actuation_delay_s"),
    ({"inductance_H": -1.0}, "inductance_H"),
    ({"current_limit_A": 0.0}, "current_limit_A"),
    ({"current_limit_A": math.inf}, "current_limit_A"),
])
def test_bad_actuation_is_one_parameter_error(options, culprit):
    with pytest.raises(ParameterError, match=culprit):
        mjcf.compile_model(**options)


KP, KD = 100.0, 20.0  # the certified design's gains


@pytest.mark.parametrize("fraction, stable", [(0.9, True), (1.1, False)])
def test_routh_actuator_lag_limit_tau_e_below_kd_over_kp(fraction, stable):
    """tau_e s^3 + s^2 + K_D s + K_P is stable iff tau_e < K_D / K_P (0.2 s here): the roots
    (np.roots) and a simulation of e'' = a, tau_e a' = v - a, v = -K_P e - K_D e' agree."""
    tau = fraction * KD / KP
    roots = np.roots([tau, 1.0, KD, KP])
    assert (np.max(roots.real) < 0) == stable

    def lagged(_t, x):
        e, de, a = x
        return [de, a, (-KP * e - KD * de - a) / tau]

    run = solve_ivp(lagged, (0.0, 60.0), [0.01, 0.0, 0.0], rtol=1e-9, atol=1e-12, dense_output=True)
    early = np.max(np.abs(run.sol(np.linspace(0.0, 10.0, 2000))[0]))
    late = np.max(np.abs(run.sol(np.linspace(50.0, 60.0, 2000))[0]))
    # the slowest mode's rate |max Re| is 0.225 /s (0.9) and 0.180 /s (1.1): over 50 s the envelope
    # changes by e^(+-5) or more, far beyond the integration's error
    assert (late < early / 10) == stable and (late > early * 10) == (not stable)
