"""The velocity estimators and the delay, defined once as discrete linear systems (wmr_mj/hardware/estimators.py),
against the three implementations that run or analyse them: the compiled law's C (``sense()`` in
wmr_mj/sim/_compiled_law.c, driven through wmr_mj.sim.compiled_law on random inputs), the Python sensing chain
(SensingChain.step) and the certificate's loop (sampled_data.sampled_loop, built from the matrices).

The delay is a shift register: the C's reading is the matrices' output to the bit. The estimate runs in its
factored form in C and Python ((alpha_m[k] - alpha_m[k-1]) / T, then a y + (1 - a) v) and as C x + D u here;
the two round differently, so they are compared at each step from the C's own state (no accumulation) within
the bound :func:`_rounding_bound` derives.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from wmr_mj.analysis.sampled_data import sampled_loop
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware import Sensing, SensingChain
from wmr_mj.hardware.estimators import delay_line, velocity_estimator
from wmr_mj.hardware.sensing import (
    P_FILTER_A,
    P_FILTER_ONE_MINUS_A,
    P_PERIOD,
    S_FILTER,
    S_PREVIOUS_ALPHA,
)
from wmr_mj.sim import compiled_law

needs_compiled = pytest.mark.skipif(compiled_law.unavailable_reason() is not None,
                                    reason=f"the compiled law cannot run: {compiled_law.unavailable_reason()}")

_MODEL = """<mujoco><option timestep="0.001"/><worldbody>
<body><joint name="steer" type="hinge"/><geom size="0.1" mass="1"/></body>
<body><joint name="motor" type="hinge"/><geom size="0.1" mass="1"/></body>
</worldbody><actuator><motor joint="steer"/></actuator></mujoco>"""
_STATE = compiled_law.SENSING_STATE_ADR  # the chain's state in userdata (its layout: sensing.S_*)
_MEASURED = len(compiled_law.USERDATA_FIELDS)  # alpha_m, alpha'_m in userdata
EPS = float(np.finfo(float).eps)


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


def _rounding_bound(a: float, one_minus_a: float, T: float, y: float, u: float, p: float) -> float:
    """|factored - matrix form| of one step from the same state (p = alpha_m[k-1], y = y[k-1]) and input u.

    Both approximate z = a y + b (u - p)/T (b = 1 - a as stored; the difference: a = 0, b = 1). With u_r = eps/2
    and gamma_n = n u_r / (1 - n u_r) (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed., Lemma
    3.1): the factored form rounds u - p, / T, a y, b v and their sum, so it is within gamma_2 |a y| + gamma_4
    |b| |u - p| / T of z; the matrix form rounds 1/T, g = b (1/T), the three products and two sums, so it is
    within gamma_3 |a y| + gamma_5 |b| (|u| + |p|) / T. Their difference is at most (gamma_4 + gamma_5)
    (|a y| + |b| (|u| + |p|) / T) <= 5 eps (...)."""
    return 5.0 * EPS * (abs(a * y) + abs(one_minus_a) / T * (abs(u) + abs(p)))


@needs_compiled
@pytest.mark.parametrize("spec", [
    "encoder_ticks=4096,velocity=difference,delay=0.003,noise=uniform:0.0005,seed=3",
    "encoder_ticks=16384,encoder_rounding=floor,velocity=filtered,filter_tau=0.002,delay=0.002",
    "encoder_ticks=500,encoder_side=motor,encoder_rounding=floor,velocity=filtered,filter_tau=0.05",
    "velocity=difference",  # the unquantised angle: every step's difference is a full-width double
])
def test_the_compiled_estimate_is_the_estimators_matrices_within_rounding(spec):
    sensing = Sensing.from_spec(spec)
    alpha, alpha_dot, motor = _inputs(400, seed=len(spec))
    chain, out, before, after = _drive_c(sensing, alpha, alpha_dot, motor, gear_ratio=60.0)
    # the C reads the coefficients the matrices are built from
    p = chain.parameters
    est = velocity_estimator(sensing.velocity, control_period=float(p[P_PERIOD]), filter_tau=sensing.filter_tau)
    system = est.system
    assert chain.estimator == est
    if est.filters:
        assert (p[P_FILTER_A], p[P_FILTER_ONE_MINUS_A]) == (system.A[1, 1], est.one_minus_a)
        assert system.D[0, 0] == p[P_FILTER_ONE_MINUS_A] * (1.0 / p[P_PERIOD])
    else:
        assert system.D[0, 0] == 1.0 / p[P_PERIOD]
    # the Python chain is the C, to the bit
    py = np.array(chain.run(alpha, alpha_dot, 60.0 * motor)).T
    assert py.tobytes() == out.tobytes()
    a, b = (est.a, est.one_minus_a) if est.filters else (0.0, 1.0)
    worst = 0.0
    for k in range(alpha.size):
        u = out[k, 0]
        # the chain's start (its first difference is 0) is the estimator started at x = (alpha_m[0], 0)
        x = np.array([u, 0.0]) if k == 0 else before[k]
        x = x[:system.n_states]
        y_matrix = float(system.C[0] @ x + system.D[0, 0] * u)
        x_next = system.A @ x + system.B[:, 0] * u
        bound = _rounding_bound(a, b, est.control_period, x[1] if est.filters else 0.0, u, x[0])
        assert abs(out[k, 1] - y_matrix) <= bound, (k, out[k, 1], y_matrix)
        assert after[k, 0] == x_next[0] == u  # the previous angle is stored to the bit
        if est.filters:
            assert abs(after[k, 1] - x_next[1]) <= bound and after[k, 1] == out[k, 1]
        worst = max(worst, abs(out[k, 1] - y_matrix))
    assert worst > 0.0 or spec != "velocity=difference"  # the two forms do round differently: the bound is needed


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
