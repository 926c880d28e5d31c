"""The armature inductance in the sampled loop (issue 42 item 6): the current as one more state, exact over the period.

Independent truths: the first-order step response j(t) = u (1 - exp(-t/tau_e)) and its integrals in closed form; the
zero-order hold of the continuous plant E'' = -j, tau_e j' = u - j computed by scipy's matrix exponential (Van Loan's
augmented matrix, not the moments the module uses); today's loop (tau_e = 0) as the limit.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import scipy.linalg

from wmr_mj.analysis.measurement import MeasurementErrors, coverage_assumption_fields
from wmr_mj.analysis.sampled_certificate import SampledCart, damped_loop
from wmr_mj.analysis.sampled_data import current_moments, peak_gains, sampled_loop
from wmr_mj.hardware import Actuation

T = 0.001
TAU = 0.001  # the target: L_a/R_a = 1 ms


def _zoh(tau: float) -> tuple[np.ndarray, np.ndarray]:
    """exp of the augmented [[A_c, B_c], [0, 0]] T for x = (E, E', j), input u held: (A_d, B_d)."""
    M = np.zeros((4, 4))
    M[0, 1] = 1.0
    M[1, 2] = -1.0
    M[2, 2], M[2, 3] = -1.0 / tau, 1.0 / tau
    X = scipy.linalg.expm(M * T)
    return X[:3, :3], X[:3, 3]


@pytest.mark.parametrize("tau", [1e-4, 1e-3, 1e-2])
def test_held_step_current_matches_the_first_order_solution(tau):
    """From j = 0 under a held u = 1: j(T) = 1 - exp(-T/tau), int j = T - tau (1 - exp(-T/tau)), and the double and
    triple integrals in closed form (each a textbook integral of 1 - exp(-s/tau)); to 1e-12 relative."""
    m = current_moments(T, tau)
    e = math.exp(-T / tau)
    exact = [1.0 - e, T - tau * (1.0 - e), T * T / 2 - tau * T + tau * tau * (1.0 - e),
             T ** 3 / 6 - tau * T * T / 2 + tau * tau * T - tau ** 3 * (1.0 - e)]
    assert m[:, 0] == pytest.approx(exact, rel=1e-9, abs=1e-18)
    # from j_k = 1 under u = 0 the current decays: exp(-T/tau), tau (1 - exp(-T/tau)), ...
    assert m[0, 1] == pytest.approx(e, rel=1e-12)
    assert m[1, 1] == pytest.approx(tau * (1.0 - e), rel=1e-12)
    # a held u from j_k = u stays u: the coefficients of (u, j_k) sum to today's (1, T, T^2/2, T^3/6)
    assert m.sum(axis=1) == pytest.approx([1.0, T, T * T / 2, T ** 3 / 6], rel=1e-12)


@pytest.mark.parametrize("tau", [2e-4, 1e-3, 5e-3])
def test_loop_rows_are_the_exact_zero_order_hold(tau):
    """The plant rows (E, E', j) of the loop equal expm of the continuous plant with the held u (Van Loan)."""
    loop = sampled_loop(kp=100.0, kd=20.0, control_period=T, electrical_time_constant=tau)
    A_d, B_d = _zoh(tau)
    j = loop.current_index
    assert j == loop.n_states - 1 == 2
    u_row = loop.C[2]  # the law's command, no delay: u = K_P E^ + K_D E^' with E^ = E (exact estimate)
    for i, row in enumerate((0, 1, j)):
        expected = A_d[i].copy()
        expected[:2] += B_d[i] * u_row[:2]
        assert loop.A[row, [0, 1, j]] == pytest.approx(expected, rel=1e-9, abs=1e-15)


def test_zero_inductance_is_todays_loop_bit_for_bit():
    a = sampled_loop(kp=100.0, kd=20.0, control_period=T, velocity="difference", sensing_delay=3, actuation_delay=2)
    b = sampled_loop(kp=100.0, kd=20.0, control_period=T, velocity="difference", sensing_delay=3, actuation_delay=2,
                     electrical_time_constant=0.0)
    assert b.current_index is None and np.array_equal(a.A, b.A) and np.array_equal(a.B, b.B)


@pytest.mark.parametrize("velocity,d_s,d_a", [("exact", 0, 0), ("difference", 0, 0), ("difference", 5, 2)])
def test_small_inductance_converges_to_todays_loop(velocity, d_s, d_a):
    """L -> 0: the matrices (less the current's row and column) converge to today's at rate tau_e (the current's
    weight in E' is tau_e (1 - exp(-T/tau_e))), the current's own eigenvalue exp(-T/tau_e) goes to 0, and the l1 gains
    converge."""
    today = sampled_loop(kp=100.0, kd=20.0, control_period=T, velocity=velocity, sensing_delay=d_s, actuation_delay=d_a)
    g0 = peak_gains(today).gains
    errors = []
    for tau in (1e-5, 1e-6, 1e-7):
        loop = sampled_loop(kp=100.0, kd=20.0, control_period=T, velocity=velocity, sensing_delay=d_s,
                            actuation_delay=d_a, electrical_time_constant=tau)
        gap = max(np.abs(loop.A[:-1, :-1] - today.A).max(), np.abs(loop.A[:-1, -1]).max())
        # E' loses (T - tau (1 - exp(-T/tau))) u + tau (1 - exp(-T/tau)) j_k: u's row moves by <= tau |u's row|
        assert gap <= 2.0 * tau * (1.0 + np.abs(today.C[2]).max())
        errors.append(np.abs(peak_gains(loop).gains - g0).max() / np.abs(g0).max())
    assert errors[-1] < 1e-5 and errors[0] > errors[-1]


def test_current_lag_costs_little_at_one_millisecond():
    """The target cart's loop (12-bit encoder, differenced rate, T = 1 ms) with L_a/R_a = 1 ms stays stable and its
    gain from the angle's quantisation moves by under 5 % (a 1 ms lag is far inside the 64 ms delay margin)."""
    today = peak_gains(sampled_loop(kp=100.0, kd=20.0, control_period=T, velocity="difference"))
    lag = peak_gains(sampled_loop(kp=100.0, kd=20.0, control_period=T, velocity="difference",
                                  electrical_time_constant=TAU))
    assert lag.stable
    ratio = lag.gain("E", "quantisation") / today.gain("E", "quantisation")
    assert 1.0 <= ratio < 1.05


def _cart(tau: float, d_a: int = 0) -> SampledCart:
    return SampledCart(velocity="difference", filter_tau=None, sensing_delay=0, actuation_delay=d_a,
                       angle_error=2 * math.pi / 4096 / 2, velocity_noise=0.0, velocity_error=1.5, velocity_lag=T / 2,
                       measurement=MeasurementErrors.exact(), electrical_time_constant=tau)


@pytest.mark.parametrize("d_a", [0, 3])
def test_damped_loop_with_a_tiny_inductance_converges_to_todays(d_a):
    """The back-EMF rows (c^ = 5/s) with the current converge to today's second-order rows as tau_e -> 0."""
    today = damped_loop(kp=100.0, kd=20.0, c_hat=5.0, control_period=T, cart=_cart(0.0, d_a))
    small = damped_loop(kp=100.0, kd=20.0, c_hat=5.0, control_period=T, cart=_cart(1e-7, d_a))
    scale = 2.0 * (1e-7 / T) * (1.0 + max(np.abs(today.A).max(), np.abs(today.B).max()))  # tau_e/T of the rows
    assert np.abs(small.A[:-1, :-1] - today.A).max() < scale
    assert np.abs(small.B[:-1] - today.B).max() < scale
    assert today.applied_row()[small.n_states - 2 if d_a else 0] == small.applied_row()[
        small.n_states - 2 if d_a else 0]


def test_damped_loop_with_current_is_the_exact_hold_to_second_order_in_c():
    """c^ = 5/s, tau_e = 1 ms: the E' row of the damped loop against expm of E'' = -j - c^ E', tau_e j' = u - j
    (the rows keep c^ to second order: the gap is O(c^^3 T^3) per unit of E', far below the rows' size)."""
    c, tau = 5.0, TAU
    loop = damped_loop(kp=100.0, kd=20.0, c_hat=c, control_period=T, cart=dataclasses.replace(_cart(tau),
                                                                                                velocity="exact"))
    M = np.zeros((4, 4))
    M[0, 1], M[1, 1], M[1, 2] = 1.0, -c, -1.0
    M[2, 2], M[2, 3] = -1.0 / tau, 1.0 / tau
    X = scipy.linalg.expm(M * T)
    j = loop.current_index
    u = loop.applied_row()
    for i in (0, 1):  # E, E': the state part of (A_d x + B_d u)
        expected = X[i, :3].copy()
        expected[:2] += X[i, 3] * u[:2]
        got = loop.A[i, [0, 1, j]]
        assert got == pytest.approx(expected, abs=(c * T) ** 3 * 10.0)


def test_only_the_sampled_certificate_covers_the_inductance():
    m = MeasurementErrors(0.0, 0.0, 0.0, electrical_time_constant_s=TAU)
    assert not m.is_exact
    assert not coverage_assumption_fields(m, "section-4")["met"]
    assert "armature inductance" in coverage_assumption_fields(m, "section-4")["note"]
    assert coverage_assumption_fields(m, "sampled-data", absorbs_electrical_lag=True)["met"]
    limited = Actuation(inductance=0.001, current_limit=20.0).coverage(R_a=1.0)
    assert limited.electrical_time_constant == pytest.approx(0.001) and limited.why_not  # the limit stays uncovered
    assert Actuation(inductance=0.001).coverage(R_a=1.0).covered


def test_the_carts_inductance_is_the_default_and_an_actuation_overrides_it():
    assert Actuation().on_motor(L_a=0.002).inductance == 0.002
    assert Actuation(inductance=0.001).on_motor(L_a=0.002).inductance == 0.001
    assert Actuation(delay=0.002).on_motor(L_a=0.0) == Actuation(delay=0.002)


def test_the_cart_files_limit_is_the_actuations():
    from wmr_mj.carts.cartfile import MAX_ELECTRICAL_TIME_CONSTANT_S as in_cart_file
    from wmr_mj.hardware.assembly import MAX_ELECTRICAL_TIME_CONSTANT_S

    assert in_cart_file == MAX_ELECTRICAL_TIME_CONSTANT_S


# -- the cart's motor.L_a, end to end (the plant, the coverage, the claim) ----------------------------------------
def _cart_with_inductance(tmp_path, L_a: float):
    from wmr_mj.carts import CARTS_DIR

    text = (CARTS_DIR / "c80.toml").read_text(encoding="utf-8")
    anchor = '[motor.L_a]\nvalue = 0.0\n'
    assert anchor in text
    path = tmp_path / "inductive.toml"
    path.write_text(text.replace(anchor, f"[motor.L_a]\nvalue = {L_a!r}\n"), encoding="utf-8")
    return path


def test_the_carts_inductance_reaches_the_dcmotor_and_an_actuation_overrides_it():
    from wmr_mj.params import C80, with_params
    from wmr_mj.plant.mjcf import compile_model

    steer = 0  # the steering motor is the first actuator
    assert compile_model(C80)[0].na == 0  # the C80: no current state, today's model
    model, _ = compile_model(with_params(C80, L_a=0.001))
    assert model.na == 1 and model.actuator_dynprm[steer][0] == 0.001
    model, _ = compile_model(with_params(C80, L_a=0.001), inductance_H=0.002)
    assert model.actuator_dynprm[steer][0] == 0.002


def test_a_cart_file_with_inductance_is_certified_on_the_12bit_encoder(tmp_path):
    """motor.L_a = R_a x 1 ms in the cart file, no --actuation: the measurement carries L_a/R_a = 1 ms, section 4
    leaves it uncovered, and the sampled-data certificate holds it: certified, E_max as with --actuation inductance=
    (the same number, 0.05062 rad at m1 = 750 kg, docs/guides/certificates.md)."""
    import wmr_mj as wm
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.parts import resolve_run

    base = {**wm.CERTIFIED.config_changes(), "sensing": "magnetic-12bit-axis", "m1": 750.0}
    from_cart = resolve_run(RunConfig(**base, cart=str(_cart_with_inductance(tmp_path, 0.001)))).claim
    from_option = resolve_run(RunConfig(**base, actuation="inductance=0.001")).claim
    without = resolve_run(RunConfig(**base)).claim
    assert from_cart.certified and from_cart.inputs["certificate"] == "sampled-data"
    assert not from_cart.inputs["certificates"]["section-4"]["certified"]
    assert from_cart.E_max == from_option.E_max
    assert without.E_max < from_cart.E_max < 1.2 * without.E_max  # the lag costs a little, never nothing
    assert from_cart.inputs["cart"]["electrical_time_constant"] == pytest.approx(0.001)


def test_a_cart_file_without_L_a_reads_0_and_one_beyond_the_limit_is_refused_in_one_line():
    from wmr_mj.carts import CARTS_DIR, load_cart_text
    from wmr_mj.errors import ParameterError
    from wmr_mj.params import parameters_of_cart

    text = (CARTS_DIR / "c80.toml").read_text(encoding="utf-8")
    entry = text[text.index("[motor.L_a]"):text.index("[motor.k_i]")]
    omitted = load_cart_text(text.replace(entry, ""))
    assert omitted.parameters["L_a"] == 0.0 and omitted.units["L_a"] == "H"
    assert parameters_of_cart(omitted) == parameters_of_cart(load_cart_text(text))
    with pytest.raises(ParameterError) as refused:  # R_a = 1 Ohm: 0.2 H is 0.2 s, beyond 0.1 s
        load_cart_text(text.replace("[motor.L_a]\nvalue = 0.0\n", "[motor.L_a]\nvalue = 0.2\n"))
    message = str(refused.value)
    assert "\n" not in message and "motor.L_a.value = 0.2 H is not accepted" in message and "L_a <= 0.1 H" in message
