"""wmr_mj.hardware alone, against closed forms: the encoder's quantiser, the delay line, the noise's
statistics, the velocity estimates, the parser's errors, the measurement error bounds, and the loop facts of
mismatch.md items 1, 2 and 4 on a double integrator (delay margin, Jury's condition for the hold, the L1
bound of a bounded measurement error)."""

from __future__ import annotations

import ast
import json
import math
from pathlib import Path

import numpy as np
import pytest
import scipy.integrate
import scipy.signal

from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware import (
    SENSING_PRESET_SOURCES,
    Actuation,
    Sensing,
    SensingChain,
    Transmission,
    measurement_error_bounds,
    sensing_preset,
    sensing_preset_names,
)

I2 = 60.0  # the C80's steering gear ratio (params.py)
T = 0.001  # s, the testbed's control period
KP, KD = 100.0, 20.0  # the certified design (mismatch.md)
ROOT = Path(__file__).resolve().parents[1]


def _chain(sensing: Sensing, n: int, *, period: float = T, gear_ratio: float = I2) -> SensingChain:
    return SensingChain(sensing, control_period=period, n_steps=n, gear_ratio=gear_ratio)


# ---------------------------------------------------------------- the package stands alone

def test_hardware_imports_only_errors_of_the_package():
    for path in (ROOT / "wmr_mj" / "hardware").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            assert not (isinstance(node, ast.ImportFrom) and node.level), f"{path.name}: relative import"
            for name in names:
                if name.startswith("wmr_mj"):
                    # the deprecated module name's shim (hardware/cart.py) warns through _util's one mechanism
                    assert name in ("wmr_mj.errors", "wmr_mj._util.deprecation") or name.startswith(
                        "wmr_mj.hardware"), f"{path.name}: {name}"


# ---------------------------------------------------------------- (b) the encoder

@pytest.mark.parametrize("ticks", [1024, 4096, 16384, 2000])
@pytest.mark.parametrize("side", ["axis", "motor"])
@pytest.mark.parametrize("rounding", ["round", "floor"])
def test_encoder_equals_round_or_floor_of_theta_times_ticks_per_rad(ticks, side, rounding):
    rng = np.random.default_rng(ticks)
    alpha = rng.uniform(-1.2, 1.2, 3000)  # rad, beyond the steering range either way
    motor = I2 * alpha + rng.uniform(-1e-3, 1e-3, alpha.size)  # a motor angle that is not i2 alpha to the bit
    chain = _chain(Sensing(encoder_ticks=ticks, encoder_side=side, encoder_rounding=rounding), alpha.size)
    measured, _ = chain.run(alpha, np.zeros_like(alpha), motor)
    c = ticks / (2 * math.pi)  # ticks per rad, as the chain computes it once
    theta = motor if side == "motor" else alpha
    count = np.rint(theta * c) if rounding == "round" else np.floor(theta * c)
    expected = count / c / (I2 if side == "motor" else 1.0)
    assert np.array_equal(measured, expected)
    # independently of the formula: a whole number of ticks, within one resolution step of the angle
    delta = 2 * math.pi / ticks / (I2 if side == "motor" else 1.0)
    at_shaft = measured * (I2 if side == "motor" else 1.0) * c
    assert np.abs(at_shaft - np.round(at_shaft)).max() < 1e-6  # 1e-6 tick: float error of |count| < 2e5
    err = measured - theta / (I2 if side == "motor" else 1.0)
    if rounding == "round":
        assert np.abs(err).max() <= delta / 2 * (1 + 1e-9)
    else:
        assert err.max() <= 1e-12 and err.min() > -delta * (1 + 1e-9)  # floor: theta - Delta < q <= theta


def test_exact_angle_on_the_motor_side_is_the_motor_angle_over_i2():
    motor = np.linspace(-30.0, 30.0, 101)
    measured, _ = _chain(Sensing(encoder_side="motor"), motor.size).run(np.zeros(101), np.zeros(101), motor)
    assert np.array_equal(measured, motor / I2)


# ---------------------------------------------------------------- (a) the delay

@pytest.mark.parametrize("d", [0, 1, 7, 50])
def test_delay_returns_the_sample_from_exactly_d_steps_before(d):
    rng = np.random.default_rng(d)
    alpha, alpha_dot, motor = rng.normal(size=(3, 400))
    sensing = Sensing(delay=d * T, encoder_side="axis")
    assert sensing.delay_steps(T) == d
    a_m, ad_m = _chain(sensing, 400).run(alpha, alpha_dot, motor)
    source = np.maximum(np.arange(400) - d, 0)  # before d steps, the first sample (the state at t = 0)
    assert np.array_equal(a_m, alpha[source]) and np.array_equal(ad_m, alpha_dot[source])
    a_motor, _ = _chain(Sensing(delay=d * T, encoder_side="motor"), 400).run(alpha, alpha_dot, motor)
    assert np.array_equal(a_motor, motor[source] / I2)


def test_steps_out_of_turn_are_refused():
    chain = _chain(Sensing(), 10)
    chain.step(0, 0.1, 0.0, 6.0)
    with pytest.raises(ValueError, match="step 2 called where step 1 is next"):
        chain.step(2, 0.1, 0.0, 6.0)
    for k in range(1, 10):
        chain.step(k, 0.1, 0.0, 6.0)
    with pytest.raises(ValueError, match="step 10 called where step 10 is next \\(of 10\\)"):
        chain.step(10, 0.1, 0.0, 6.0)


# ---------------------------------------------------------------- (c) noise

@pytest.mark.parametrize("kind", ["uniform", "gaussian"])
def test_noise_has_its_mean_and_standard_deviation_and_the_uniform_bound(kind):
    n, magnitude = 200_000, 5e-4
    sensing = Sensing(noise_kind=kind, noise=magnitude, velocity="tachometer",
                      velocity_noise_kind=kind, velocity_noise=2 * magnitude, seed=11)
    chain = _chain(sensing, n)
    for noise, m in ((chain.alpha_noise, magnitude), (chain.alpha_dot_noise, 2 * magnitude)):
        sigma = m / math.sqrt(3) if kind == "uniform" else m
        kurtosis = 1.8 if kind == "uniform" else 3.0
        # 5 standard errors: the mean's sigma/sqrt(n); the sample deviation's sigma sqrt((kurtosis - 1)/(4 n))
        assert abs(noise.mean()) < 5 * sigma / math.sqrt(n)
        assert abs(noise.std() - sigma) < 5 * sigma * math.sqrt((kurtosis - 1) / (4 * n))
        if kind == "uniform":
            assert np.abs(noise).max() <= m  # numpy's uniform draws [-B, B)
            assert np.abs(noise).max() > 0.999 * m  # and reaches it: the bound is the one drawn from
    # the chain adds exactly these numbers, on alpha and on the measured alpha'
    alpha = np.linspace(0.0, 0.3, 500)
    alpha_dot = np.full(500, 0.7)
    a_m, ad_m = chain.run(alpha, alpha_dot)
    assert np.array_equal(a_m, alpha + chain.alpha_noise[:500])
    assert np.array_equal(ad_m, alpha_dot + chain.alpha_dot_noise[:500])


def test_noise_is_drawn_in_the_documented_order():
    s = Sensing(noise_kind="uniform", noise=1e-3, velocity_noise_kind="gaussian",
                velocity_noise=0.02, seed=5)
    chain = _chain(s, 1000)
    rng = np.random.default_rng(5)
    assert np.array_equal(chain.alpha_noise, rng.uniform(-1e-3, 1e-3, 1000))
    assert np.array_equal(chain.alpha_dot_noise, rng.normal(0.0, 0.02, 1000))


def test_same_seed_same_bits_other_seed_other_bits():
    spec = "encoder_ticks=4096,velocity=difference,delay=0.005,noise=uniform:0.0005,velocity_noise=gaussian:0.01"
    t = np.arange(2000) * T
    alpha, alpha_dot = 0.3 * np.sin(2 * t), 0.6 * np.cos(2 * t)
    runs = [_chain(Sensing.from_spec(f"{spec},seed={seed}"), 2000).run(alpha, alpha_dot) for seed in (3, 3, 4)]
    assert np.array_equal(runs[0][0], runs[1][0]) and np.array_equal(runs[0][1], runs[1][1])
    assert not np.array_equal(runs[0][0], runs[2][0]) and not np.array_equal(runs[0][1], runs[2][1])


# ---------------------------------------------------------------- (d) velocity estimates

def test_difference_of_a_finely_quantised_ramp_is_its_slope():
    w, n = 0.37, 3000  # rad/s
    s = Sensing(encoder_ticks=2**24, velocity="difference")
    t = np.arange(n) * T
    _, v = _chain(s, n).run(w * t, np.full(n, w))
    bound = measurement_error_bounds(s, control_period=T, gear_ratio=I2)
    assert v[0] == 0.0  # no earlier sample
    assert np.abs(v[1:] - w).max() <= bound.alpha_dot_error_max  # Delta/T = 3.7e-4 rad/s (a ramp: no lag)
    assert abs(v[1:].mean() - w) < 2 * bound.alpha_dot_error_max / n  # the differences telescope


def test_filter_step_response_is_one_minus_a_to_the_k():
    # alpha_k = k T with T = 2**-10 s: every difference is exactly 1 rad/s from k = 1 on (0 at k = 0)
    period, tau_f, n = 2.0**-10, 0.02, 400
    s = Sensing(velocity="filtered", filter_tau=tau_f)
    _, y = _chain(s, n, period=period).run(np.arange(n) * period, np.zeros(n))
    a = math.exp(-period / tau_f)
    k = np.arange(n)
    # a unit step entering at k = 1 answers 1 - a^k (1 - a^(k+1) for one entering at k = 0); 1e-14: pow vs
    # the recursion's rounding over 400 steps
    assert np.allclose(y, 1.0 - a**k, rtol=0.0, atol=1e-14)


# ---------------------------------------------------------------- the specification

@pytest.mark.parametrize(("spec", "error", "fragment"), [
    ("encoder_ticks=4096,colour=red", UnknownNameError, "unknown sensing key 'colour'; valid sensing keys: delay"),
    ("delay=-0.005", ParameterError, "delay = -0.005 s is not accepted"),
    ("encoder_ticks=0", ParameterError, "encoder_ticks = 0 is not accepted; an integer >= 1"),
    ("encoder_ticks=4096.5", ParameterError, "encoder_ticks = '4096.5' is not an integer"),
    ("delay=fast", ParameterError, "delay = 'fast' is not a number"),
    ("no-such-encoder", UnknownNameError, "unknown sensing preset 'no-such-encoder'; valid sensing presets:"),
    ("preset=no-such-encoder,delay=0.001", UnknownNameError, "valid sensing presets: ideal, incremental-500-motor"),
    ("noise=uniform", ParameterError, "noise = 'uniform' is not accepted; accepted: 'none', 'uniform:BOUND'"),
    ("noise=laplace:0.1", ParameterError, "noise = 'laplace:0.1' is not accepted"),
    ("noise=uniform:-0.1", ParameterError, "noise = -0.1 rad is not accepted"),
    ("velocity=kalman", UnknownNameError, "unknown sensing velocity value 'kalman'; valid sensing velocity values: "
                                          "difference, exact, filtered, none, tachometer"),
    ("velocity=filtered", ParameterError, "velocity=filtered needs filter_tau"),
    ("velocity=filtered,filter_tau=0", ParameterError, "filter_tau = 0.0 s is not accepted"),
    ("filter_tau=0.01", ParameterError, "filter_tau = 0.01 s applies to velocity=filtered only"),
    ("delay=0.001,delay=0.002", ParameterError, "key 'delay' is given twice"),
    ("delay=0.001,,seed=1", ParameterError, "'' is not KEY=VALUE"),
    ("seed=-1", ParameterError, "seed = -1 is not accepted"),
    ("missing.toml", ParameterError, "cannot read 'missing.toml'"),
])
def test_bad_specs_raise_one_line_naming_the_culprit(spec, error, fragment):
    with pytest.raises(error) as info:
        Sensing.from_spec(spec)
    assert fragment in str(info.value) and "\n" not in str(info.value)


def test_a_delay_that_is_not_a_whole_number_of_periods_names_both():
    with pytest.raises(ParameterError, match=r"sensing delay = 0.0015 s is not a whole number of periods of "
                                             r"0.001 s \(1.5 periods\); accepted: a multiple such as 0.001 s"):
        Sensing(delay=0.0015).delay_steps(0.001)
    with pytest.raises(ParameterError, match="sensing delay = 0.0015 s is not a whole number"):
        SensingChain(Sensing(delay=0.0015), control_period=0.001, n_steps=10, gear_ratio=I2)
    assert Sensing(delay=0.005).delay_steps(0.001) == 5  # 0.005/0.001 = 5.000000000000001 in doubles


def test_the_issues_string_a_mapping_and_files_give_one_sensing(tmp_path):
    text = "encoder_ticks=4096,encoder_side=axis,velocity=difference,delay=0.005,noise=uniform:0.0005,seed=3"
    s = Sensing.from_spec(text)
    assert (s.encoder_ticks, s.encoder_side, s.velocity, s.delay, s.noise_kind, s.noise, s.seed) == (
        4096, "axis", "difference", 0.005, "uniform", 0.0005, 3)
    (tmp_path / "s.json").write_text(json.dumps(s.to_dict()))
    (tmp_path / "s.toml").write_text('encoder_ticks = 4096\nvelocity = "difference"\ndelay = 0.005\n'
                                     'noise = "uniform:0.0005"\nseed = 3\n')
    assert Sensing.from_spec(s.to_dict()) == s
    assert Sensing.from_spec(tmp_path / "s.json") == s
    assert Sensing.from_spec(str(tmp_path / "s.toml")) == s
    assert Sensing.from_spec("preset=magnetic-12bit-axis,delay=0.005,noise=uniform:0.0005,seed=3") == s


def test_ideal_is_the_default_and_passes_its_inputs_to_the_bit():
    assert Sensing() == Sensing.from_spec(None) == Sensing.from_spec("ideal") == sensing_preset("ideal")
    assert Sensing().is_ideal and Sensing().label() == "ideal"
    assert Sensing(noise_kind="gaussian", noise=0.0).is_ideal  # a zero noise is no noise
    for not_ideal in ("encoder_ticks=4096", "encoder_side=motor", "velocity=difference", "delay=0.001",
                      "noise=uniform:0.001", "velocity_noise=gaussian:0.1"):
        assert not Sensing.from_spec(not_ideal).is_ideal, not_ideal
    rng = np.random.default_rng(0)
    alpha, alpha_dot = rng.normal(size=(2, 1000))
    alpha[3], alpha_dot[4] = -0.0, -0.0  # a signed zero stays signed: nothing is added
    a_m, ad_m = _chain(Sensing(), 1000).run(alpha, alpha_dot)
    assert a_m.tobytes() == alpha.tobytes() and ad_m.tobytes() == alpha_dot.tobytes()


def test_presets_have_sources_and_the_cited_resolutions():
    names = sensing_preset_names()
    assert names[0] == "ideal" and set(names) == set(SENSING_PRESET_SOURCES)
    assert sensing_preset("magnetic-12bit-axis").encoder_ticks == 2**12
    assert sensing_preset("magnetic-14bit-axis").encoder_ticks == 2**14
    motor = sensing_preset("incremental-500-motor")
    assert (motor.encoder_ticks, motor.encoder_side, motor.encoder_rounding) == (2000, "motor", "floor")
    assert all(len(SENSING_PRESET_SOURCES[n]) > 40 for n in names)
    with pytest.raises(UnknownNameError, match="unknown sensing preset 'as5045'; valid sensing presets: ideal"):
        sensing_preset("as5045")


def test_actuation_and_transmission_parts():
    a = Actuation.from_spec("delay=0.002,inductance=0.0005,current_limit=20")
    assert (a.delay, a.inductance, a.current_limit) == (0.002, 0.0005, 20.0) and not a.is_ideal
    assert a.electrical_time_constant(1.0) == 0.0005 and a.delay_steps(0.001) == 2
    assert Actuation.from_spec(a.to_dict()) == a and Actuation.from_spec("ideal") == Actuation()
    assert Actuation().is_ideal and Actuation().label() == "ideal"
    for bad, fragment in (("delay=-0.001", "delay = -0.001 s is not accepted"),
                          ("inductance=-1e-3", "inductance = -0.001 H is not accepted"),
                          ("current_limit=0", "current_limit = 0.0 A is not accepted")):
        with pytest.raises(ParameterError, match=fragment):
            Actuation.from_spec(bad)
    with pytest.raises(UnknownNameError, match="unknown actuation key 'resistance'"):
        Actuation.from_spec("resistance=1")
    with pytest.raises(ParameterError, match="R_a = 0 Ohm"):
        a.electrical_time_constant(0)
    t = Transmission.from_spec("0.002")
    assert t == Transmission.from_spec("backlash=0.002") == Transmission.from_spec(0.002) == Transmission(backlash=2e-3)
    assert Transmission().is_ideal and not t.is_ideal and t.label() == "backlash +-2 mrad"
    with pytest.raises(ParameterError, match="backlash = -0.1 rad is not accepted"):
        Transmission.from_spec("-0.1")


# ---------------------------------------------------------------- measurement error bounds

def _smooth_signal(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """alpha, alpha' and sup|alpha''| of a signal at rest at t <= 0 (the bounds' assumption)."""
    terms = ((0.3, 2 * math.pi * 0.8), (0.05, 2 * math.pi * 2.3))
    tt = np.maximum(t, 0.0)
    alpha = sum(A * (1 - np.cos(w * tt)) for A, w in terms)
    alpha_dot = sum(A * w * np.sin(w * tt) for A, w in terms)
    return alpha, alpha_dot, sum(A * w * w for A, w in terms)


@pytest.mark.parametrize("spec", [
    "encoder_ticks=4096,velocity=difference,noise=uniform:0.0002,delay=0.005,seed=1",
    "encoder_ticks=1024,encoder_rounding=floor,velocity=filtered,filter_tau=0.004,seed=2",
    "encoder_ticks=2000,encoder_side=motor,encoder_rounding=floor,velocity=difference,delay=0.003",
    "velocity=tachometer,velocity_noise=uniform:0.05,noise=uniform:0.001,seed=4",
])
def test_measurement_error_bounds_hold_on_a_synthetic_run(spec):
    s, n, backlash = Sensing.from_spec(spec), 6000, 0.002
    t = np.arange(n) * T
    alpha, alpha_dot, sup_acc = _smooth_signal(t)
    play = backlash * np.sin(2 * math.pi * 1.7 * t) ** 2 * np.sign(np.sin(2 * math.pi * 0.3 * t))  # |play| <= b
    a_m, ad_m = _chain(s, n).run(alpha, alpha_dot, I2 * (alpha + play))
    b = measurement_error_bounds(s, control_period=T, gear_ratio=I2, backlash=backlash)
    alpha_d, alpha_dot_d, _ = _smooth_signal(t - s.delay)
    alpha_err = np.abs(a_m - alpha_d).max()
    dot_err = np.abs(ad_m - alpha_dot_d).max()
    assert b.covered and b.why_not is None and b.delay == s.delay
    assert alpha_err <= b.alpha_error_max
    assert dot_err <= b.alpha_dot_error_max + b.alpha_dot_lag * sup_acc
    assert alpha_err > 0.5 * b.alpha_error_max  # the alpha bound is nearly reached: quantiser, noise, play


def test_bounds_closed_forms_and_gaussian_is_not_covered():
    b = measurement_error_bounds(Sensing.from_spec("magnetic-12bit-axis"), control_period=T, gear_ratio=I2)
    delta = 2 * math.pi / 4096
    assert b.alpha_error_max == pytest.approx(delta / 2, rel=1e-8)
    assert b.alpha_dot_error_max == pytest.approx(1.534, rel=1e-3)  # mismatch.md item 4: Delta/T = 1.5 rad/s
    assert b.alpha_dot_lag == T / 2
    f = measurement_error_bounds(Sensing(velocity="filtered", filter_tau=0.002), control_period=T, gear_ratio=I2)
    assert f.alpha_dot_lag == 0.002 + T / 2 and f.alpha_error_max == 0.0
    m = measurement_error_bounds(Sensing.from_spec("incremental-500-motor"), control_period=T, gear_ratio=I2,
                                 backlash=0.001)
    assert m.alpha_error_max == pytest.approx(2 * math.pi / 2000 / I2 + 0.001, rel=1e-8)
    g = measurement_error_bounds(Sensing(noise_kind="gaussian", noise=1e-4), control_period=T, gear_ratio=I2)
    assert not g.covered and g.why_not == "Gaussian noise has no bound" and g.alpha_error_max == math.inf


# ---------------------------------------------------------------- the loop: mismatch.md items 1, 2, 4

def _pd_with_sensing(sensing: Sensing, *, step: float, duration: float, e0: float) -> tuple[np.ndarray, ...]:
    """e'' = v, v = -K_P e_m - K_D e'_m held over each step (exact integration of the double integrator)."""
    n = round(duration / step)
    chain = _chain(sensing, n, period=step, gear_ratio=1.0)
    e, ed = np.empty(n + 1), np.empty(n + 1)
    e[0], ed[0] = e0, 0.0
    em, edm = np.empty(n), np.empty(n)
    for k in range(n):
        em[k], edm[k] = chain.step(k, e[k], ed[k], e[k])
        v = -KP * em[k] - KD * edm[k]
        e[k + 1] = e[k] + step * ed[k] + 0.5 * step * step * v
        ed[k + 1] = ed[k] + step * v
    return e, ed, em, edm


def test_pd_loop_with_a_delay_decays_below_and_grows_above_the_delay_margin():
    omega_c = math.sqrt((KD**2 + math.sqrt(KD**4 + 4 * KP**2)) / 2)
    tau_max = math.atan(KD * omega_c / KP) / omega_c
    assert tau_max == pytest.approx(0.0647, abs=5e-5)  # mismatch.md item 1: 64.7 ms
    step = 1e-4  # s: the delays are whole steps; the hold adds step/2 = 0.05 ms, beside the 3.2 ms of 5 %
    window = round(2.0 / step)
    peaks = {}
    for factor in (0.95, 1.05):
        delay = round(factor * tau_max / step) * step
        e, *_ = _pd_with_sensing(Sensing(delay=delay), step=step, duration=10.0, e0=1.0)
        peaks[factor] = [np.abs(e[i * window:(i + 1) * window]).max() for i in range(1, 5)]
    # from 2-4 s to 8-10 s the envelope shrinks (grows) by e^(6 s |Re s|) with |Re s| ~ 0.6/s: about 36
    assert peaks[0.95][-1] < peaks[0.95][0] / 10 and np.all(np.diff(peaks[0.95]) < 0)
    assert peaks[1.05][-1] > peaks[1.05][0] * 10 and np.all(np.diff(peaks[1.05]) > 0)


def _hold_matrix(kp: float, kd: float, period: float) -> np.ndarray:
    """x = (e, e'), v held over the period: x+ = (Phi + Gamma K) x, exact for the double integrator."""
    phi = np.array([[1.0, period], [0.0, 1.0]])
    gamma = np.array([[period**2 / 2], [period]])
    return phi + gamma @ np.array([[-kp, -kd]])


@pytest.mark.parametrize(("kp", "kd", "boundary"), [
    (100.0, 20.0, 0.1),  # K_D T < 2 binds: T < 2/K_D
    (100.0, 2.0, 0.04),  # K_P T^2/2 < K_D T binds: T < 2 K_D / K_P
])
def test_jury_condition_of_the_zero_order_hold(kp, kd, boundary):
    for period, stable in ((boundary * 0.98, True), (boundary * 1.02, False)):
        a = _hold_matrix(kp, kd, period)
        # the characteristic polynomial of mismatch.md item 2
        expected = [1.0, -(2 - kp * period**2 / 2 - kd * period), 1 - kd * period + kp * period**2 / 2]
        assert np.allclose(np.poly(a), expected, rtol=0, atol=1e-12)
        jury = kp * period**2 / 2 < kd * period < 2
        radius = np.abs(np.linalg.eigvals(a)).max()
        assert jury == stable and (radius < 1) == stable, (period, radius)


def _h_l1_closed_form(kp: float, kd: float) -> float:
    wn, zeta = math.sqrt(kp), kd / (2 * math.sqrt(kp))
    if zeta >= 1:
        return 1 / wn**2
    return 1 / (wn**2 * math.tanh(math.pi * zeta / (2 * math.sqrt(1 - zeta**2))))


@pytest.mark.parametrize(("kp", "kd"), [(100.0, 20.0), (100.0, 5.0), (100.0, 30.0)])
def test_l1_norm_of_the_closed_loop_impulse_response(kp, kd):
    sigma = kd / 2 - math.sqrt(max(kd**2 / 4 - kp, 0.0))  # the slowest decay rate, 1/s
    t = np.linspace(0.0, 40.0 / sigma, 20_001)  # tail below e^-40
    _, h = scipy.signal.impulse(([1.0], [1.0, kd, kp]), T=t)
    # trapezoid on 2e4 intervals: error O(dt^2), 2.3e-6 relative measured at (100, 30), 1e-7 at 1e5 intervals
    assert scipy.integrate.trapezoid(np.abs(h), t) == pytest.approx(_h_l1_closed_form(kp, kd), rel=1e-5)


def test_l1_bound_holds_for_quantised_feedback():
    s = Sensing(encoder_ticks=1024, velocity="difference")  # coarse: 6.1 mrad a tick, 6.1 rad/s per tick
    e, ed, em, edm = _pd_with_sensing(s, step=T, duration=10.0, e0=0.2)
    # the measurement error over the whole hold interval [t_k, t_k+1): e' is linear there (its extremes at the
    # ends) and e moves by at most T max|e'|
    ed_max = np.maximum(np.abs(ed[:-1]), np.abs(ed[1:]))
    eta = np.abs(em - e[:-1]) + T * ed_max
    eta_dot = np.maximum(np.abs(edm - ed[:-1]), np.abs(edm - ed[1:]))
    settle, late = round(3.0 / T), round(5.0 / T)  # 2 s apart: int_2^inf |h| < 1e-9 of the earlier input
    bound = _h_l1_closed_form(KP, KD) * (KP * eta[settle:].max() + KD * eta_dot[settle:].max())
    # 1e-9: the bound and the error are computed from the same doubles; here they coincide (below)
    assert np.abs(e[late:]).max() <= bound * (1 + 1e-9)
    # ... and the bound is attained: the loop sticks where the quantised angle reads 0 (|e| < Delta/2, e' = 0),
    # a constant error, and h >= 0 at zeta = 1, so |e| = ||h||_1 K_P |eta| exactly
    assert np.abs(e[late:]).max() > 0.99 * bound
    # the a priori bounds of the sensing hold too, with the hold's and the difference's lag terms
    b = measurement_error_bounds(s, control_period=T, gear_ratio=1.0)
    acc_max = np.abs(KP * em + KD * edm)[settle:].max()  # sup|e''| = sup|v|
    assert eta[settle:].max() <= b.alpha_error_max + T * np.abs(ed[settle:]).max()
    assert eta_dot[settle:].max() <= b.alpha_dot_error_max + (b.alpha_dot_lag + T) * acc_max
    # quantised feedback bounds the error, it does not drive it to 0 (Delchamps 1990): the loop settles within
    # a few ticks and stays off zero
    assert 0 < np.abs(e[late:]).max() < 5 * 2 * math.pi / 1024
