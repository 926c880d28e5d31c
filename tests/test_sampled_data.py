"""The sampled loop's l1 gains and delay margin (wmr_mj/analysis/sampled_data.py) against independent truth.

Truth here: closed forms (a first-order system's l1 norm; the continuous limit of h(t) = t e^(-10 t); the
zero-order-hold PD loop's Jury conditions and the continuous delay margin, ../shared/notes/mismatch.md items
1 and 2), a plain loop written from the law's side (true angle, ring buffers, the sensing chain's formulas;
no matrix of the module), and numpy's polynomial roots.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmr_mj.analysis.sampled_data import (
    OUTPUTS,
    SOURCES,
    SampledLoop,
    characteristic_polynomial,
    delay_margin,
    jury_stable,
    peak_bounds,
    peak_gains,
    sampled_loop,
    sampled_loop_for,
)
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware import Sensing

KP, KD, T = 100.0, 20.0, 1e-3  # the certified design's gains, the run's control period (s)
DELTA_12 = 2.0 * math.pi / 4096  # a 12-bit encoder's tick, rad


def plain_loop(e, *, kp=KP, kd=KD, T=T, velocity="exact", tau=None, d_s=0, d_a=0, nv=None, w=None,
               between=None):
    """E, E', u over len(e) steps from rest: the law reads alpha d_s steps late plus e[k], forms alpha' as
    SensingChain does (from rest: the previous measured angle starts at 0), u = K_P (0 - alpha_m) + K_D
    (0 - alpha'_m) is applied d_a steps late, held over each period on alpha'' = u - w[k] (E'' = -u + w; exact:
    alpha += T alpha' + T^2/2 alpha'', alpha' += T alpha''). ``between``: a list that gets max |E| over 20
    points inside each period."""
    n = len(e)
    nv = np.zeros(n) if nv is None else nv
    w = np.zeros(n) if w is None else w
    inside = np.linspace(0.0, T, 21)[1:-1]
    a = math.exp(-T / tau) if tau else 0.0
    alpha, rate, prev, filt = 0.0, 0.0, 0.0, 0.0
    history = [(0.0, 0.0)] * (d_s + 1)  # (alpha, alpha') of steps k - d_s .. k
    sent = [0.0] * (d_a + 1)
    E, Edot, U = np.zeros(n), np.zeros(n), np.zeros(n)
    for k in range(n):
        history = history[1:] + [(alpha, rate)]
        alpha_d, rate_d = history[0]
        alpha_m = alpha_d + e[k]
        if velocity in ("exact", "tachometer"):
            v = rate_d
        else:
            v = (alpha_m - prev) / T
            if velocity == "filtered":
                v = a * filt + (1.0 - a) * v
                filt = v
        prev = alpha_m
        u = kp * (0.0 - alpha_m) + kd * (0.0 - (v + nv[k]))
        sent = sent[1:] + [u]
        E[k], Edot[k], U[k] = -alpha, -rate, u
        acc = sent[0] - w[k]
        if between is not None:
            between.append(np.max(np.abs(alpha + inside * rate + 0.5 * inside**2 * acc)))
        alpha, rate = alpha + T * rate + 0.5 * T * T * acc, rate + T * acc
    return E, Edot, U


# --- the l1 norm and its tail -------------------------------------------------------------------------------


def first_order(a: float) -> SampledLoop:
    """x[k+1] = a x[k] + u[k], y = x: the angle column is u, E is y, the rest zero."""
    z = np.zeros(1)
    return SampledLoop(A=np.array([[a]]), B=np.array([[1.0, 0.0]]), C=np.array([[1.0], [0.0], [0.0]]),
                       D=np.zeros((3, 2)), w_position=z, w_rate=z, w_held=z, kp=1.0, kd=1.0, control_period=1.0,
                       velocity="exact", filter_tau=None, sensing_delay=0, actuation_delay=0)


@pytest.mark.parametrize("a", [0.5, -0.5, 0.9, -0.99, 0.999])
def test_first_order_l1_norm_is_one_over_one_minus_abs_a(a):
    """sum |a|^k = 1/(1 - |a|) (geometric series); the default stop leaves a tail within 1e-6 of the sum."""
    g = peak_gains(first_order(a))
    exact = 1.0 / (1.0 - abs(a))
    assert exact <= g.gain("E", "quantisation") <= exact * (1.0 + 1.1e-6)
    assert g.reached[0, SOURCES.index("quantisation")] <= exact  # the sign sequence cannot beat the norm


@pytest.mark.parametrize("a", [0.9, -0.999])
def test_first_order_tail_bound_is_sound_at_any_n(a):
    """With N = 10 terms the gain (sum + tail) is still >= 1/(1 - |a|): the tail covers the rest."""
    exact = 1.0 / (1.0 - abs(a))
    g = peak_gains(first_order(a), n_terms=10)
    assert g.n_terms == 10 and g.gain("E", "quantisation") >= exact
    assert g.reached[0, 1] == pytest.approx((1 - abs(a) ** 10) / (1 - abs(a)), rel=1e-12)


@pytest.mark.parametrize("velocity, tau, d_s, d_a", [("exact", None, 3, 2), ("difference", None, 5, 0),
                                                     ("filtered", 0.004, 2, 3)])
def test_tail_bound_is_an_upper_bound_of_the_long_sum(velocity, tau, d_s, d_a):
    """N = 300 terms + tail >= the sum to N = 20,000 (whose own tail is below 1e-12 of it)."""
    loop = sampled_loop(kp=KP, kd=KD, control_period=T, velocity=velocity, filter_tau=tau, sensing_delay=d_s,
                        actuation_delay=d_a)
    short, long = peak_gains(loop, n_terms=300), peak_gains(loop, n_terms=20_000)
    assert np.all(long.tail <= 1e-12 * long.reached)
    assert np.all(short.gains >= long.reached)
    assert np.all(short.tail > 0.0)  # the short sum alone would not be a bound


# --- the loop against a plain simulation ------------------------------------------------------------------


@pytest.mark.parametrize("velocity, tau, d_s, d_a", [("exact", None, 0, 0), ("difference", None, 0, 0),
                                                     ("difference", None, 5, 2), ("filtered", 0.005, 3, 1),
                                                     ("tachometer", None, 4, 4)])
def test_worst_case_sequence_reaches_the_quantisation_bound(velocity, tau, d_s, d_a):
    """The sign of the time-reversed impulse response (Dahleh and Pearson), |q| = Delta/2, in the plain loop:
    E at the last step reaches the computed bound to within 1% and no step exceeds it; u likewise."""
    loop = sampled_loop(kp=KP, kd=KD, control_period=T, velocity=velocity, filter_tau=tau, sensing_delay=d_s,
                        actuation_delay=d_a)
    gains = peak_gains(loop)
    n = 4000  # steps; the response decays as e^(-10 t): 4 s leaves below 1e-12 of it
    impulse = np.zeros(n)
    impulse[0] = 1.0
    E_h, _, U_h = plain_loop(impulse, velocity=velocity, tau=tau, d_s=d_s, d_a=d_a)
    for output, h in (("E", E_h), ("u", U_h)):
        bound = gains.gain(output, "quantisation") * DELTA_12 / 2
        q = (DELTA_12 / 2) * np.sign(h[::-1])  # the last step sees h[n-1-k] q[k]
        E, _, U = plain_loop(q, velocity=velocity, tau=tau, d_s=d_s, d_a=d_a)
        y = E if output == "E" else U
        assert abs(y[-1]) >= 0.99 * bound
        assert np.max(np.abs(y)) <= bound


def test_between_samples_bound_holds_for_the_worst_sampled_sequences():
    """q and a held w at their worst sampled sequences together (an underdamped loop, K_D = 5, so the kernel
    changes sign), 1 ms, difference, 3 ms delay: |E| on 20 points inside every period stays within
    peak_bounds(between_samples=True), and the held w's own l1 gain (its sign sequence, plain loop) is at
    most the continuous w's."""
    kd, n, q_max, w_max = 5.0, 6000, DELTA_12 / 2, 0.5
    gains = peak_gains(sampled_loop(kp=KP, kd=kd, control_period=T, velocity="difference", sensing_delay=3))
    unit = np.zeros(n)
    unit[0] = 1.0
    h_q = plain_loop(unit, kd=kd, velocity="difference", d_s=3)[0]
    h_w = plain_loop(np.zeros(n), kd=kd, velocity="difference", d_s=3, w=unit)[0]
    held_w_gain = np.sum(np.abs(h_w))
    assert held_w_gain <= gains.gain("E", "w")  # sum_k |int kernel_k| <= sum_k int |kernel_k|
    between: list[float] = []
    E, _, _ = plain_loop(q_max * np.sign(h_q[::-1]), kd=kd, velocity="difference", d_s=3,
                         w=w_max * np.sign(h_w[::-1]), between=between)
    sampled = peak_bounds(gains, quantisation=q_max, w=w_max)[0]
    anywhere = peak_bounds(gains, quantisation=q_max, w=w_max, between_samples=True)[0]
    assert np.max(np.abs(E)) <= sampled and max(between) <= anywhere
    assert abs(E[-1]) >= 0.9 * (gains.gain("E", "quantisation") * q_max + held_w_gain * w_max)


@pytest.mark.parametrize("velocity, tau", [("exact", None), ("difference", None), ("filtered", 0.002)])
def test_state_space_impulse_response_is_the_plain_loops(velocity, tau):
    """C A^k B (+ D at k = 0) of the augmented loop equals the plain loop's response to a unit angle error,
    a unit velocity noise and a unit w held over the first period (w_held), step by step (rounding only)."""
    loop = sampled_loop(kp=KP, kd=KD, control_period=T, velocity=velocity, filter_tau=tau, sensing_delay=2,
                        actuation_delay=3)
    n = 200
    unit, zero = np.zeros(n), np.zeros(n)
    unit[0] = 1.0
    columns = ((loop.B[:, 0], loop.D[:, 0], {"e": unit}), (loop.B[:, 1], loop.D[:, 1], {"e": zero, "nv": unit}),
               (loop.w_held, np.zeros(3), {"e": zero, "w": unit}))
    for b, d, inputs in columns:
        x, got = b.copy(), [d]
        for _ in range(n - 1):
            got.append(loop.C @ x)
            x = loop.A @ x
        plain = plain_loop(inputs.pop("e"), velocity=velocity, tau=tau, d_s=2, d_a=3, **inputs)
        np.testing.assert_allclose(np.array(got), np.column_stack(plain), rtol=1e-9, atol=1e-12)


def test_hold_is_scipys_zoh_discretisation():
    """The plant's step (exact alpha', no delay: A = Phi - Gamma K) against scipy.signal.cont2discrete's ZOH
    of E'' = -u, for two periods."""
    from scipy.signal import cont2discrete

    for period in (1e-3, 0.05):
        Phi, Gamma, *_ = cont2discrete((np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [-1.0]]),
                                        np.eye(2), np.zeros((2, 1))), period, method="zoh")
        loop = sampled_loop(kp=KP, kd=KD, control_period=period)
        np.testing.assert_allclose(loop.A, Phi + Gamma @ np.array([[KP, KD]]), rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(loop.w_held, -Gamma[:, 0], rtol=1e-12)


# --- closed forms: mismatch.md's table and the continuous limit -------------------------------------------


def test_the_table_of_mismatch_md():
    """../shared/notes/mismatch.md, "Sampled-data peak-to-peak (l1) gains" (its ten-line script, T = 1 ms,
    K_P = 100, K_D = 20): q -> E is 1.000 / 1.324 / 4.748 (exact alpha', 0 / 50 / 60 ms) and 1.273 / 1.295 /
    1.440 / 5.51 / 23.4 (backward difference, 0 / 5 / 20 / 50 / 60 ms), to the digits it prints."""
    table = {("exact", 0): "1.000", ("exact", 5): "1.000", ("exact", 20): "1.000", ("exact", 50): "1.324",
             ("exact", 60): "4.748", ("difference", 0): "1.273", ("difference", 5): "1.295",
             ("difference", 20): "1.440", ("difference", 50): "5.51", ("difference", 60): "23.4"}
    for (velocity, d), printed in table.items():
        g = peak_gains(sampled_loop(kp=KP, kd=KD, control_period=T, velocity=velocity, sensing_delay=d))
        half_unit = 0.5 * 10.0 ** -len(printed.split(".")[1])  # the table's rounding
        assert abs(g.gain("E", "quantisation") - float(printed)) <= half_unit, (velocity, d)


def test_continuous_limit_of_the_gains():
    """h(t) = t e^(-10 t) for K_P = 100, K_D = 20: ||h||_1 = 1/K_P = 0.01, TV(h) = 2 max h = 0.2/e; a
    differenced angle error enters as K_P h + K_D h' = e^(-10t)(20 - 100 t), L1 norm 1 + 2 e^-2 = 1.2707.
    The sampled gains converge at first order in T (the hold's T/2 and the difference's T/2)."""
    TV = 0.2 / math.e
    coded = 1.0 + 2.0 * math.exp(-2.0)
    errors = []
    for period in (1e-3, 5e-4, 2e-4):
        g = peak_gains(sampled_loop(kp=KP, kd=KD, control_period=period, velocity="difference"))
        # the kernel from a continuous w to E is >= 0 here, so the gain is the DC gain 1/K_P at every T
        assert g.gain("E", "w") == pytest.approx(1.0 / KP, rel=1e-6)
        assert 0.0 < g.gain("E_dot", "w") - TV <= 0.5 * period  # observed 0.37 T
        assert 0.0 < g.gain("E", "quantisation") - coded <= 3.0 * period  # observed 2.7 T
        errors.append(g.gain("E", "quantisation") - coded)
    assert errors[1] / errors[0] == pytest.approx(0.5, abs=0.05)  # first order: halving T halves it
    # exact alpha': only the P term sees the angle error, K_P ||h||_1 = 1
    assert peak_gains(sampled_loop(kp=KP, kd=KD, control_period=T)).gain("E", "quantisation") == pytest.approx(
        1.0, rel=1e-6)


def test_the_issues_encoder_numbers():
    """Issue 35: a 12-bit angle error costs at most (K_P ||h||_1 + K_D TV(h)) Delta/2 = 0.0019 rad by the
    triangle inequality; the sampled loop's exact l1 gain 1.27 (T = 1 ms, differenced) costs 0.001 rad; the
    free charge K_D (Delta/T) ||h||_1 is 0.306 rad."""
    triangle = (KP * 0.01 + KD * 0.2 / math.e) * DELTA_12 / 2
    assert round(triangle, 4) == 0.0019
    assert round(KD * (DELTA_12 / T) * 0.01, 3) == 0.307  # the issue prints 0.306 (Delta/T = 1.53 rounded)
    g = peak_gains(sampled_loop(kp=KP, kd=KD, control_period=T, velocity="difference"))
    E_max, _, _ = peak_bounds(g, quantisation=DELTA_12 / 2)
    assert round(g.gain("E", "quantisation"), 2) == 1.27 and round(E_max, 3) == 0.001
    assert E_max < triangle


# --- Jury and the delay margin ----------------------------------------------------------------------------


def test_characteristic_polynomial_is_the_zoh_closed_form():
    """mismatch.md item 2 (Franklin, Powell and Workman): z^2 - (2 - K_P T^2/2 - K_D T) z + (1 - K_D T + K_P T^2/2)."""
    for kp, kd, period in ((100.0, 20.0, 1e-3), (6.0, 9.0, 0.05), (400.0, 5.0, 0.02)):
        p = characteristic_polynomial(kp=kp, kd=kd, control_period=period)
        want = [1.0, -(2 - kp * period**2 / 2 - kd * period), 1 - kd * period + kp * period**2 / 2]
        np.testing.assert_allclose(p, want, rtol=1e-14, atol=1e-15)


def test_jury_matches_the_zoh_stability_condition():
    """Jury's test on the ZOH PD loop is stable iff K_P T^2/2 < K_D T < 2 (mismatch.md item 2), over a grid
    that crosses both edges."""
    checked = {True: 0, False: 0}
    for kp in (1.0, 100.0, 1e4):
        for kd in (0.5, 20.0, 300.0):
            for period in np.geomspace(1e-4, 1.0, 25):
                closed_form = kp * period**2 / 2 < kd * period < 2
                got = jury_stable(characteristic_polynomial(kp=kp, kd=kd, control_period=float(period)))
                assert got == closed_form, (kp, kd, period)
                checked[got] += 1
    assert min(checked.values()) > 20  # both verdicts occur


def test_jury_matches_numpy_roots_on_random_polynomials():
    """Real polynomials of degree 1-9 from random roots (pairs and real ones, |z| in 0.3-1.3)."""
    rng = np.random.default_rng(7)
    for _ in range(400):
        pairs = rng.uniform(0.3, 1.3, int(rng.integers(0, 4))) * np.exp(1j * rng.uniform(0.1, 3.0))
        real = rng.uniform(-1.3, 1.3, int(rng.integers(1, 4)))
        p = np.real(np.poly(np.concatenate([pairs, pairs.conj(), real])))
        radius = np.max(np.abs(np.roots(p)))
        if abs(radius - 1.0) > 1e-6:
            assert jury_stable(p) == (radius < 1.0)


@pytest.mark.parametrize("kp, kd", [(100.0, 20.0), (100.0, 10.0), (25.0, 10.0)])
def test_delay_margin_against_the_continuous_closed_form(kp, kd):
    """mismatch.md item 1 (Astrom and Murray): tau_max = atan(K_D w_c / K_P) / w_c, w_c^2 = (K_D^2 +
    sqrt(K_D^4 + 4 K_P^2))/2: 64.7 ms for 100/20. The hold adds T/2 (the difference another T/2), and the
    margin counts whole periods: d_max T + lag lies within one period below tau_max."""
    w_c = math.sqrt((kd**2 + math.sqrt(kd**4 + 4 * kp**2)) / 2)
    tau_max = math.atan(kd * w_c / kp) / w_c
    if (kp, kd) == (100.0, 20.0):
        assert round(tau_max, 4) == 0.0647
    for velocity, lag in (("exact", T / 2), ("difference", T)):
        d_max = delay_margin(kp=kp, kd=kd, control_period=T, velocity=velocity)
        assert d_max is not None and tau_max - T <= d_max * T + lag <= tau_max + 1e-4 * tau_max


@pytest.mark.parametrize("velocity, tau", [("exact", None), ("difference", None), ("filtered", 0.003)])
def test_delay_margin_is_the_augmented_loops_spectral_radius(velocity, tau):
    """At d_max the augmented A (delay split between sensing and actuation) has spectral radius < 1, at
    d_max + 1 >= 1; its nonzero eigenvalues are the characteristic polynomial's roots."""
    d_max = delay_margin(kp=KP, kd=KD, control_period=T, velocity=velocity, filter_tau=tau)
    assert d_max is not None
    for d, stable in ((d_max, True), (d_max + 1, False)):
        loop = sampled_loop(kp=KP, kd=KD, control_period=T, velocity=velocity, filter_tau=tau,
                            sensing_delay=d // 3, actuation_delay=d - d // 3)
        radius = np.max(np.abs(np.linalg.eigvals(loop.A)))
        assert (radius < 1.0) == stable
        assert (peak_gains(loop).stable) == stable
    small = sampled_loop(kp=KP, kd=KD, control_period=T, velocity=velocity, filter_tau=tau, sensing_delay=2,
                         actuation_delay=1)
    eig = np.sort_complex(np.linalg.eigvals(small.A))
    roots = np.sort_complex(np.roots(characteristic_polynomial(kp=KP, kd=KD, control_period=T,
                                                               velocity=velocity, filter_tau=tau, delay=3)))
    nonzero = eig[np.abs(eig) > 1e-6]
    np.testing.assert_allclose(np.sort_complex(nonzero), roots[np.abs(roots) > 1e-6], atol=1e-7)


def test_unstable_loop_gives_inf_with_the_reason():
    g = peak_gains(sampled_loop(kp=KP, kd=KD, control_period=T, sensing_delay=70))
    assert not g.stable and np.all(np.isinf(g.gains)) and "spectral radius" in g.reason
    assert math.isinf(peak_bounds(g, quantisation=1e-4)[0])
    fast = peak_gains(sampled_loop(kp=KP, kd=KD, control_period=0.11))  # K_D T = 2.2 > 2
    assert not fast.stable and fast.spectral_radius >= 1.0
    assert delay_margin(kp=KP, kd=KD, control_period=0.11) is None


# --- monotonicity -----------------------------------------------------------------------------------------


def test_bounds_grow_with_delta_noise_and_play():
    g = peak_gains(sampled_loop(kp=KP, kd=KD, control_period=T, velocity="difference", sensing_delay=5))
    previous = (0.0, 0.0, 0.0)
    for bits in (16, 14, 12, 10):
        now = peak_bounds(g, quantisation=math.pi / 2**bits)
        assert all(b > a for a, b in zip(previous, now))
        previous = now
    for name in ("angle_noise", "play", "velocity_noise", "w"):
        low, high = peak_bounds(g, **{name: 1e-4}), peak_bounds(g, **{name: 2e-4})
        assert all(h > lo > 0 for lo, h in zip(low, high)), name
    both = peak_bounds(g, quantisation=1e-4, angle_noise=1e-4)
    assert both[0] == pytest.approx(2 * peak_bounds(g, quantisation=1e-4)[0], rel=1e-12)  # one input column


@pytest.mark.parametrize("velocity, tau", [("exact", None), ("difference", None), ("filtered", 0.005)])
def test_gain_grows_with_the_delay(velocity, tau):
    """q -> E, E' and u do not fall as the sensing delay grows (0 to 56 ms in 8 ms steps; exact alpha' is
    flat at K_P ||h||_1 = 1 while the kernel stays >= 0, so 'not fall' is within the tail's 1e-6)."""
    previous = None
    for d in range(0, 57, 8):
        g = peak_gains(sampled_loop(kp=KP, kd=KD, control_period=T, velocity=velocity, filter_tau=tau,
                                    sensing_delay=d))
        now = g.gains[:, SOURCES.index("quantisation")]
        if previous is not None:
            assert np.all(now >= previous * (1 - 2e-6)), d
        previous = now
    assert previous[0] > 1.2  # and it does grow by 56 ms


# --- inputs -----------------------------------------------------------------------------------------------


def test_sampled_loop_for_a_sensing_spec():
    s = Sensing.from_spec("encoder_ticks=4096,velocity=filtered,filter_tau=0.005,delay=0.003")
    a = sampled_loop_for(s, kp=KP, kd=KD, control_period=T, actuation_delay=1)
    b = sampled_loop(kp=KP, kd=KD, control_period=T, velocity="filtered", filter_tau=0.005, sensing_delay=3,
                     actuation_delay=1)
    assert np.array_equal(a.A, b.A) and np.array_equal(a.B, b.B) and np.array_equal(a.D, b.D)
    assert a.n_states == 2 + 3 + 1 + 1 + 1


def test_bad_inputs_name_the_culprit():
    with pytest.raises(ParameterError, match="kp"):
        sampled_loop(kp=0.0, kd=KD, control_period=T)
    with pytest.raises(ParameterError, match="sensing_delay"):
        sampled_loop(kp=KP, kd=KD, control_period=T, sensing_delay=-1)
    with pytest.raises(ParameterError, match="actuation_delay"):
        sampled_loop(kp=KP, kd=KD, control_period=T, actuation_delay=1.5)
    with pytest.raises(ParameterError, match="filter_tau"):
        sampled_loop(kp=KP, kd=KD, control_period=T, velocity="filtered")
    with pytest.raises(ParameterError, match="filter_tau"):
        sampled_loop(kp=KP, kd=KD, control_period=T, velocity="difference", filter_tau=0.01)
    with pytest.raises(UnknownNameError, match="velocity estimate"):
        sampled_loop(kp=KP, kd=KD, control_period=T, velocity="observer")
    g = peak_gains(sampled_loop(kp=KP, kd=KD, control_period=T))
    with pytest.raises(UnknownNameError):
        g.gain("E", "stiction")
    with pytest.raises(ParameterError, match="quantisation"):
        peak_bounds(g, quantisation=-1.0)
    with pytest.raises(ParameterError, match="n_terms"):
        peak_gains(sampled_loop(kp=KP, kd=KD, control_period=T), n_terms=0)
    assert OUTPUTS == ("E", "E_dot", "u")
