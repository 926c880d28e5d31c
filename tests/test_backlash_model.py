"""The gear's play in the C80 model (``backlash_rad``): structure, dead zone, describing function.

Measured 2026-11-26 on the 2-core machine (MuJoCo 4.0.0):
``pytest tests/test_backlash_model.py``.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.signal import find_peaks

from wmr_mj import C80
from wmr_mj.errors import ParameterError
from wmr_mj.plant import mjcf

B = 0.01  # rad, half-width of the play in these tests


def test_play_keeps_steer_as_the_axle_and_adds_the_motor_side_last():
    today = mjcf.compile_model()[0]
    model, xml = mjcf.compile_model(backlash_rad=B)
    at = mjcf.steering_joint_addresses(model)
    plain = mjcf.steering_joint_addresses(today)
    # today's addresses are kept; the motor side is appended; no play: motor side == axle
    assert (at.axle_qpos, at.axle_dof) == (plain.axle_qpos, plain.axle_dof) == (9, 8)
    assert (at.motor_qpos, at.motor_dof) == (today.nq, today.nv) == (model.nq - 1, model.nv - 1)
    assert (plain.motor_qpos, plain.play_tendon, plain.current_act) == (plain.axle_qpos, None, None)
    assert at.has_play and not plain.has_play
    assert model.actuator_trnid[at.actuator, 0] == model.joint(mjcf.MOTOR_JOINT).id
    # friction and stops on the axle (load side), armature on the motor side
    steer, motor = model.joint("steer").id, model.joint(mjcf.MOTOR_JOINT).id
    assert model.dof_frictionloss[at.axle_dof] == pytest.approx(C80.steering_friction_torque, rel=1e-5)
    assert model.dof_frictionloss[at.motor_dof] == 0 and model.dof_armature[at.axle_dof] == 0
    assert model.dof_armature[at.motor_dof] == mjcf.MOTOR_ARMATURE
    assert model.jnt_limited[steer] and not model.jnt_limited[motor]
    tendon = at.play_tendon
    assert list(model.tendon_range[tendon]) == [-B, B] and model.tendon_limited[tendon]
    assert 'joint name="steer_motor"' not in mjcf.scene_xml() and 'joint name="steer_motor"' in xml


@pytest.mark.parametrize("kwargs", [{"backlash_rad": -0.01}, {"backlash_rad": math.nan},
                                    {"backlash_rad": 0.01, "motor_armature_kgm2": 0.0}])
def test_bad_play_is_one_parameter_error(kwargs):
    with pytest.raises(ParameterError, match="backlash_rad|motor_armature_kgm2"):
        mjcf.scene_spec(**kwargs)


def _welded_c80(b: float) -> tuple[mujoco.MjModel, mjcf.SteeringAddresses]:
    """The C80 with play, the chassis fixed to the world and no floor contact: the steering alone."""
    spec = mjcf.scene_spec(backlash_rad=b)
    spec.delete(spec.joint("chassis_free"))
    spec.delete(spec.key("home"))
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    model = spec.compile()
    return model, mjcf.steering_joint_addresses(model)


def test_slow_triangle_of_the_motor_side_moves_the_axle_after_2b_of_travel():
    """A dead zone of width 2b on each reversal.

    The motor side follows a 0.01 rad/s triangle of +-0.04 rad (a stiff PD on its own angle
    through the dcmotor); the axle's stiction (7.24 N m) holds it while the motor side crosses
    the play. The travel from a reversal until the axle moves 10 µrad is 2b plus part of the
    stops' penetration under the transmitted torque. Measured: 0.02057 and 0.02056 rad for
    2b = 0.02; the stop pressed 2.37 mrad by the axle's friction, against 2.9 mrad from its
    stiffness J_m / timeconst^2 = 2500 N m/rad (tolerance 30%: the estimate ignores the impedance
    and the damping). Tolerance of the dead zone: [2b, 2b + penetration].
    """
    model, at = _welded_c80(B)
    data = mujoco.MjData(model)
    rate, amplitude, dt = 0.01, 0.04, model.opt.timestep
    period = 4 * amplitude / rate
    steps = int(round(1.25 * period / dt))
    t = np.arange(steps) * dt
    reference = amplitude * (2 / math.pi) * np.arcsin(np.sin(2 * math.pi * t / period))  # triangle
    motor, axle = np.empty(steps), np.empty(steps)
    for k in range(steps):
        error = reference[k] - data.qpos[at.motor_qpos]
        data.ctrl[at.actuator] = np.clip(2000.0 * error - 20.0 * data.qvel[at.motor_dof], -24, 24)
        mujoco.mj_step(model, data)
        motor[k], axle[k] = data.qpos[at.motor_qpos], data.qpos[at.axle_qpos]
    travels, penetrations = [], []
    for peak in (period / 4, 3 * period / 4):  # the triangle's reversals
        k0 = int(np.argmax(motor) if peak < period / 2 else np.argmin(motor[: int(period / dt)]))
        moved = np.nonzero(np.abs(axle[k0:] - axle[k0]) > 1e-5)[0][0]
        travels.append(abs(motor[k0 + moved] - motor[k0]))
        penetrations.append(abs(axle[k0] - motor[k0]) - B)  # the stop's violation under the friction torque
    print("travel on reversal [rad]:", travels, "penetration at the stop [rad]:", penetrations)
    # the stop's compliance: stiffness about J_m / timeconst^2 (MuJoCo's soft constraint with
    # solref timeconst, the motor side's inertia the smaller one), pressed by the axle's friction
    stiffness = mjcf.MOTOR_ARMATURE / mjcf.GEAR_PLAY_SOLREF[0] ** 2
    assert penetrations == pytest.approx([C80.steering_friction_torque / stiffness] * 2, rel=0.3)
    # a dead zone of 2b: never less, and more by less than the stop's penetration
    assert all(2 * B <= travel <= 2 * B + max(penetrations) for travel in travels)


def _backlash_df(amplitude: float, b: float) -> complex:
    """Describing function N(A) of backlash of half-width b (mismatch.md item 5; Slotine & Li ch. 5)."""
    r = b / amplitude
    real = (math.pi / 2 + math.asin(1 - 2 * r) + 2 * (1 - 2 * r) * math.sqrt(r * (1 - r))) / math.pi
    return complex(real, -(4 * r / math.pi) * (1 - r))


def _predicted_limit_cycle(kp: float, kd: float, inertia: float, b: float) -> tuple[float, float]:
    """(A, omega) where G(jw) = -1/N(A), G(s) = (kp + kd s) / (inertia s^2): the motor side
    (a double integrator) under a PD on the axle angle that the play passes on."""
    def omega_of(amplitude: float) -> float:  # the phase condition: atan(kd w / kp) = -arg N(A)
        return kp * math.tan(-np.angle(_backlash_df(amplitude, b))) / kd

    def gain_residual(amplitude: float) -> float:
        w = omega_of(amplitude)
        return abs((kp + 1j * kd * w) / (inertia * (1j * w) ** 2)) * abs(_backlash_df(amplitude, b)) - 1

    grid = np.geomspace(b * 1.001, b * 100, 2000)
    residual = [gain_residual(a) for a in grid]
    roots = [brentq(gain_residual, grid[i], grid[i + 1]) for i in range(len(grid) - 1)
             if residual[i] * residual[i + 1] < 0]
    assert len(roots) == 1, roots
    return roots[0], omega_of(roots[0])


def _reduced_play_model(inertia: float, b: float) -> mujoco.MjModel:
    """The builder's play (two coaxial hinges, the tendon axle - motor limited to +-b with
    GEAR_PLAY_SOLREF) on a reduced plant: a torque on the motor side's inertia, a light axle
    (1e-6 kg m^2, damping 0.002 N m s/rad) that stops within ~1 ms once the play opens, as the
    describing function's backlash (the output stays where it was left) assumes."""
    spec = mujoco.MjSpec()
    spec.option.timestep = mjcf.TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.compiler.autolimits = True
    for name, armature, damping in ((mjcf.MOTOR_JOINT, inertia, 0.0), (mjcf.STEERING_JOINT, 1e-6, 0.002)):
        body = spec.worldbody.add_body(name=f"{name}_body")
        body.explicitinertial = True
        body.mass, body.inertia = 1e-6, [1e-9, 1e-9, 1e-9]
        body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], armature=armature,
                       damping=damping)
    play = spec.add_tendon(name=mjcf.GEAR_PLAY_TENDON, range=[-b, b])
    play.solref_limit = list(mjcf.GEAR_PLAY_SOLREF)
    play.solimp_limit = list(mjcf.GEAR_PLAY_SOLIMP)
    play.wrap_joint(mjcf.STEERING_JOINT, 1.0)
    play.wrap_joint(mjcf.MOTOR_JOINT, -1.0)
    spec.add_actuator(name="torque", target=mjcf.MOTOR_JOINT, trntype=mujoco.mjtTrn.mjTRN_JOINT)
    return spec.compile()


@pytest.mark.parametrize("kd, amplitude_tol", [(0.02, 0.2), (0.01, 0.2)])
def test_describing_function_predicts_the_limit_cycle_through_the_play(kd, amplitude_tol):
    """A PD on the axle angle through the play hunts; N(A) predicts its amplitude and frequency.

    Reduced model (:func:`_reduced_play_model`): motor side 0.01 kg m^2, kp = 1 N m/rad,
    b = 0.01 rad, 60 s from 0.05 rad, the last 20 s measured (amplitude of the motor side's
    angle, the backlash's input; frequency from its peaks). Measured: kd = 0.02: predicted
    A = 0.0619 rad, w = 9.64 rad/s; simulated 0.0569 rad (-8%), 9.58 rad/s (-0.6%); kd = 0.01:
    0.123 rad, 9.85 rad/s against 0.107 rad (-13%), 9.82 rad/s. Tolerances: amplitude 20%
    (the method's usual accuracy: it keeps the first harmonic of a wave that is far from a
    sine), frequency 5%. The C80 itself (stiction 7.24 N m on the axle, a PD of 100 V/rad on
    alpha) is not tested here: its stiction holds the axle inside the dead band.
    """
    inertia, kp, b = 0.01, 1.0, B
    predicted_a, predicted_w = _predicted_limit_cycle(kp, kd, inertia, b)
    model = _reduced_play_model(inertia, b)
    data = mujoco.MjData(model)
    motor, axle = model.joint(mjcf.MOTOR_JOINT).id, model.joint(mjcf.STEERING_JOINT).id
    data.qpos[[motor, axle]] = 0.05
    steps, tail = 60_000, 20_000
    angle = np.empty(steps)
    for k in range(steps):
        data.ctrl[0] = -kp * data.qpos[axle] - kd * data.qvel[axle]
        mujoco.mj_step(model, data)
        angle[k] = data.qpos[motor]
    last = angle[-tail:]
    amplitude = (last.max() - last.min()) / 2
    peaks, _ = find_peaks(last)
    omega = 2 * math.pi / (np.mean(np.diff(peaks)) * model.opt.timestep)
    print(f"kd={kd}: predicted A={predicted_a:.4f} w={predicted_w:.3f}; simulated A={amplitude:.4f} w={omega:.3f}")
    assert amplitude == pytest.approx(predicted_a, rel=amplitude_tol)
    assert omega == pytest.approx(predicted_w, rel=0.05)
