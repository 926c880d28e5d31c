"""The velocity estimators and the delay, defined once as discrete linear systems (wmr_mj/hardware/estimators.py),
against the three implementations that run or analyse them: the compiled law's C (``sense()`` in
wmr_mj/sim/_compiled_law.c, driven through wmr_mj.sim.compiled_law on random inputs), the Python sensing chain
(SensingChain.step) and the certificate's loop (sampled_data.sampled_loop, built from the matrices).

Everything is compared to the last bit. The delay is a shift register. The estimate is the series of its stages
(the difference Delta, the division by T, the low-pass L), each stage's matrices evaluated by
DiscreteSystem.step, as the C and the chain evaluate them; the certificate's one system is those stages in
series, entry by entry. (The series system's C x + D u itself rounds differently from the stages, since
v (1/T) is not v / T for every v: hence the stages.)
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from wmr_mj.analysis.sampled_data import sampled_loop
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware import Sensing, SensingChain
from wmr_mj.hardware.estimators import DiscreteSystem, delay_line, velocity_estimator
from wmr_mj.hardware.sensing import S_FILTER, S_PREVIOUS_ALPHA
from wmr_mj.sim import compiled_law

needs_compiled = pytest.mark.skipif(compiled_law.unavailable_reason() is not None,
                                    reason=f"the compiled law cannot run: {compiled_law.unavailable_reason()}")

_MODEL = """<mujoco><option timestep="0.001"/><worldbody>
<body><joint name="steer" type="hinge"/><geom size="0.1" mass="1"/></body>
<body><joint name="motor" type="hinge"/><geom size="0.1" mass="1"/></body>
</worldbody><actuator><motor joint="steer"/></actuator></mujoco>"""
_STATE = compiled_law.SENSING_STATE_ADR  # the chain's state in userdata (its layout: sensing.S_*)
_MEASURED = len(compiled_law.USERDATA_FIELDS)  # alpha_m, alpha'_m in userdata


def _drive_c(sensing: Sensing, alpha: np.ndarray, alpha_dot: np.ndarray, motor: np.ndarray, *, gear_ratio: float):
    """The C's sense() over the random inputs, one control step per mj_forward (the callback runs in it): per
    step the measured (alpha_m, alpha'_m), and the chain's state before and after the step."""
    n = alpha.size
    chain = SensingChain(sensing, control_period=0.001, n_steps=n, gear_ratio=gear_ratio)
    spec = mujoco.MjSpec.from_string(_MODEL)
    values = dict.fromkeys(compiled_law.LAW_FIELDS, 0.0)
    values.update(kind=1.0, voltage_limit=1.0, substeps=1.0, nstep=float(n), chassis=-1.0)  # PD, steer joint 0
    law = np.array([values[f] for f in compiled_law.LAW_FIELDS])
    compiled_law.attach(spec, law, [np.zeros(n)] * 3,
                        sensing=(compiled_law.sensing_numeric(chain, motor_qpos_adr=1), chain.state.size))
    m = spec.compile()
    d = mujoco.MjData(m)
    compiled_law.install()
    out, before, after = np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 2))
    state = [_STATE + S_PREVIOUS_ALPHA, _STATE + S_FILTER]
    for k in range(n):
        d.time = k * m.opt.timestep
        d.qpos[:] = alpha[k], motor[k]
        d.qvel[:] = alpha_dot[k], 0.0
        before[k] = d.userdata[state]
        mujoco.mj_forward(m, d)
        out[k], after[k] = d.userdata[_MEASURED:_MEASURED + 2], d.userdata[state]
    return chain, out, before, after


def _inputs(n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-0.6, 0.6, n), rng.uniform(-3.0, 3.0, n), rng.uniform(-30.0, 30.0, n)


@needs_compiled
@pytest.mark.parametrize("spec", [
    "velocity=tachometer,velocity_noise=uniform:0.05,delay=0.002,seed=5",
    "encoder_ticks=4096,velocity=difference,delay=0.003,noise=uniform:0.0005,seed=3",
    "velocity=difference",  # the unquantised angle: every step's difference is a full-width double
    "encoder_ticks=16384,encoder_rounding=floor,velocity=filtered,filter_tau=0.002,delay=0.002",
    "encoder_ticks=500,encoder_side=motor,encoder_rounding=floor,velocity=filtered,filter_tau=0.05",
    "velocity=filtered,filter_tau=0.005,velocity_noise=gaussian:0.01,seed=8",
])
def test_the_compiled_estimate_is_the_estimators_matrices_to_the_bit(spec):
    """The C's estimate and its state, step by step over seeded random inputs, are those of the estimator's stages
    (VelocityEstimator.step: each stage's matrices, the division by T between them) and of delay_line(d) for the
    rate, to the last bit. The estimate's input is the C's measured angle (the encoder and the angle's noise sit
    before it); a velocity noise is added after it, as the C adds it."""
    sensing = Sensing.from_spec(spec)
    alpha, alpha_dot, motor = _inputs(400, seed=len(spec))
    chain, out, _, after = _drive_c(sensing, alpha, alpha_dot, motor, gear_ratio=60.0)
    T = chain.control_period
    est = velocity_estimator(sensing.velocity, control_period=T, filter_tau=sensing.filter_tau)
    assert chain.estimator == est
    if est.filters:  # the discretisation, from its definition (an independent truth for the coefficients)
        assert (est.a, est.one_minus_a) == (math.exp(-T / sensing.filter_tau), 1.0 - math.exp(-T / sensing.filter_tau))
    delay = delay_line(chain.delay_steps)
    x_delay, x = np.full(delay.n_states, alpha_dot[0]), np.array([out[0, 0], 0.0])[:est.system.n_states]
    estimate, state = np.empty(alpha.size), np.empty((alpha.size, est.system.n_states))
    for k in range(alpha.size):
        x_delay, (rate,) = delay.step(x_delay, [alpha_dot[k]])
        x, (estimate[k],) = est.step(x, [out[k, 0], rate])
        state[k] = x
        if sensing.velocity_noise_kind != "none":
            estimate[k] = estimate[k] + chain.alpha_dot_noise[k]
    assert estimate.tobytes() == out[:, 1].tobytes()
    assert state.tobytes() == after[:, :est.system.n_states].tobytes()
    assert not np.array_equal(estimate, alpha_dot)  # the estimate (or its delay, or noise) acts
    # the Python chain is the C, to the bit
    py = np.array(chain.run(alpha, alpha_dot, 60.0 * motor)).T
    assert py.tobytes() == out.tobytes()


def test_the_estimators_system_is_its_stages_in_series():
    """VelocityEstimator.system, the certificate's one system, is Delta, 1/T and L in series: each entry the
    product of the stages' entries along its path (1/T times a coefficient first, as the certificate built g)."""
    T, tau = 0.001, 0.005
    inv_T = 1.0 / T
    diff = velocity_estimator("difference", control_period=T)
    d = diff.difference
    assert (d.A.tolist(), d.B.tolist(), d.C.tolist(), d.D.tolist()) == ([[0.0]], [[1.0]], [[-1.0]], [[1.0]])
    s = diff.system
    assert (s.A.tolist(), s.B.tolist(), s.C.tolist(), s.D.tolist()) == ([[0.0]], [[1.0, 0.0]], [[-inv_T]],
                                                                       [[inv_T, 0.0]])
    filt = velocity_estimator("filtered", control_period=T, filter_tau=tau)
    a = math.exp(-T / tau)
    low = filt.low_pass
    assert (low.A.tolist(), low.B.tolist(), low.C.tolist(), low.D.tolist()) == ([[a]], [[1.0 - a]], [[a]], [[1.0 - a]])
    g = (1.0 - a) * inv_T
    s = filt.system
    assert s.A.tolist() == [[0.0, 0.0], [-g, a]] and s.B.tolist() == [[1.0, 0.0], [g, 0.0]]
    assert s.C.tolist() == [[-g, a]] and s.D.tolist() == [[g, 0.0]]
    with pytest.raises(ValueError, match="no low-pass"):
        _ = diff.low_pass
    with pytest.raises(ValueError, match="does not difference"):
        _ = velocity_estimator("tachometer", control_period=T).difference


def test_discrete_system_step_sums_the_nonzero_terms_in_order():
    """A row is its nonzero terms summed left to right, state first, from the first term: -0 stays -0, and
    (x0 + u0) + x1 rounds as written (not as x0 + (x1 + u0))."""
    s = DiscreteSystem(A=[[0.0]], B=[[1.0]], C=[[-1.0]], D=[[1.0]])
    _, y = s.step([0.0], [-0.0])
    assert math.copysign(1.0, y[0]) == -1.0  # -0 + -0; 0.0 + ... would give +0
    s = DiscreteSystem(A=np.zeros((2, 2)), B=np.zeros((2, 1)), C=[[1.0, 1.0]], D=[[1.0]])
    _, y = s.step([1.0, 2.0**-53], [2.0**-53])
    assert y[0] == (1.0 + 2.0**-53) + 2.0**-53 == 1.0  # state terms first, left to right
    _, y = DiscreteSystem(A=np.zeros((0, 0)), B=np.zeros((0, 1)), C=np.zeros((1, 0)), D=[[0.0]]).step([], [math.inf])
    assert y.tolist() == [0.0]  # a structural zero is no operation (0 * inf would be NaN)


@needs_compiled
@pytest.mark.parametrize("d", [0, 1, 4])
def test_the_compiled_delay_is_the_delay_lines_matrices_to_the_bit(d):
    """An exact sensor with a delay of d periods: the C reads (alpha, alpha') through the shift register of
    ``delay_line(d)``, started full of the first sample (the chain's rule before d steps have passed)."""
    sensing = Sensing(delay=d * 0.001)
    alpha, alpha_dot, motor = _inputs(200, seed=10 + d)
    _, out, _, _ = _drive_c(sensing, alpha, alpha_dot, motor, gear_ratio=60.0)
    system = delay_line(d)
    for column, signal in ((0, alpha), (1, alpha_dot)):
        x = np.full(d, signal[0])
        y = np.empty(signal.size)
        for k, u in enumerate(signal):
            y[k] = system.C[0] @ x + system.D[0, 0] * u
            x = system.A @ x + system.B[:, 0] * u
        assert y.tobytes() == out[:, column].tobytes()
        if d:
            assert not np.array_equal(y, signal)  # the delay acts


def test_the_certificates_loop_reads_the_estimators_matrices():
    """sampled_loop's estimator rows are the matrices' entries: the filter's state row holds a at its own place,
    -g at the previous angle and g at the measured angle (g = (1 - a)(1/T)); with no delay the angle read is E."""
    T, tau = 0.002, 0.01
    loop = sampled_loop(kp=100.0, kd=20.0, control_period=T, velocity="filtered", filter_tau=tau)
    est = velocity_estimator("filtered", control_period=T, filter_tau=tau)
    prev, filt = 2, 3  # the state: E, E', E^[k-1], y[k-1]
    g = est.one_minus_a * (1.0 / T)
    assert loop.A[filt].tolist() == [g, 0.0, -g, est.a]
    assert loop.A[prev].tolist() == [1.0, 0.0, 0.0, 0.0]
    assert loop.B[filt, 0] == -g  # E^ = E - e
    assert est.a == math.exp(-T / tau)


def test_delay_line_is_a_shift_register():
    s = delay_line(3)
    x = np.array([1.0, 2.0, 3.0])
    assert (s.A @ x + s.B[:, 0] * 9.0).tolist() == [9.0, 1.0, 2.0]
    assert float(s.C[0] @ x + s.D[0, 0] * 9.0) == 3.0
    assert delay_line(0).D.tolist() == [[1.0]] and delay_line(0).n_states == 0
    with pytest.raises(ParameterError, match="whole number"):
        delay_line(-1)


def test_velocity_estimator_refuses_bad_input():
    with pytest.raises(UnknownNameError):
        velocity_estimator("none", control_period=0.001)
    with pytest.raises(ParameterError, match="needs filter_tau"):
        velocity_estimator("filtered", control_period=0.001)
    with pytest.raises(ParameterError, match="applies to velocity='filtered' only"):
        velocity_estimator("difference", control_period=0.001, filter_tau=0.01)
    with pytest.raises(ParameterError, match="control_period"):
        velocity_estimator("exact", control_period=0.0)
