"""The sliding-mode layer as a sampled loop (issue 35 item 2; wmr_mj/analysis/sliding_sampled.py).

Independent truths: the law's own code (inside the layer it is the computed-torque law at the equivalent gains),
the closed form of the discrete reaching law (its invariant layer W/g, and its delay margin
2 sin(pi/(2(2d+1)))/T, Jury), a plain loop of the discretised law with its saturation and a quantised,
differenced angle (the worst sign sequence reaches the l1 bound, a random one stays below it), monotonicity in
the quantum, the noise bound and the delay, and runs of the plant on the 12-bit and the 20 ms carts.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers.computed_torque import ComputedTorque
from wmr_mj import C80
from wmr_mj.analysis.sampled_data import characteristic_polynomial, jury_stable, peak_gains, sampled_loop
from wmr_mj.analysis.sliding_sampled import LAYER_NOT_SATURATED, equivalent_gains, layer_loop
from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE
from wmr_mj.hardware import Sensing
from wmr_mj.sim.config import RunConfig, controller_for, estimate_parameters
from wmr_mj.sim.parts import resolve_run

#: parameters where the sampled layer certifies on the 12-bit axis encoder and the 20 ms delay (1 ms period)
CERTIFYING = {"lam": 20.0, "phi": 6.0, "k": 24.0}
BASE = dict(controller="sliding-mode", model="nonholonomic", path="paper-circle", m1=750.0, reference_bounds="paper")


def _claim(duration: float = 35.0, **changes):
    config = RunConfig(**{**BASE, "duration": duration, **changes})
    return resolve_run(config).claim


def test_inside_the_layer_the_law_is_computed_torque_at_the_equivalent_gains():
    """Truth: the two laws' own code, at random states inside the layer (|s| < phi), both compensations on."""
    law = controller_for(RunConfig(controller="sliding-mode", model="nonholonomic",
                                   controller_params=dict(CERTIFYING)), estimate_parameters(C80))
    rng = np.random.default_rng(0)
    model = law.model
    kp, kd = equivalent_gains(lam=law.lam, phi=law.phi, k=law.k, P_hat=model.P)
    ct = ComputedTorque(model, kp=kp, kd=kd, friction_sign="measured")
    for _ in range(200):
        a, a0 = rng.uniform(-0.5, 0.5, 2)
        ad, a0d, a0dd = rng.uniform(-1.0, 1.0, 3)
        if abs(law.surface(a, ad, a0, a0d)) >= law.phi:
            continue
        u_sm = law.voltage_scalar(a, ad, a0, a0d, a0dd)
        u_ct = ct.voltage_scalar(a, ad, a0, a0d, a0dd)
        assert u_sm == pytest.approx(u_ct, rel=1e-12, abs=1e-12)  # the same sum, grouped differently


def test_reaching_law_invariant_layer_closed_form():
    """Exact velocity, no delay, a fine period: the layer loop's l1 gain from w into s^ is the first-order reaching
    law's W/g (s' = -g s + w; its sampled sum T sum (1 - gT)^k = 1/g), to O((lam + g) T) = 0.25 %."""
    lam, g, T = 5.0, 20.0, 1e-4
    loop = layer_loop(sampled_loop(kp=lam * g, kd=lam + g, control_period=T, velocity="exact"), lam=lam)
    gains = peak_gains(loop)
    assert gains.gain("u", "w") == pytest.approx(1.0 / g, rel=0.01)  # the third output is s^ here


@pytest.mark.parametrize("d", [0, 1, 2, 5])
def test_reaching_law_delay_margin_closed_form(d):
    """With lam -> 0 the layer is the discrete reaching law E'[k+1] = E'[k] - gT E'[k - d] (exact under the hold):
    stable iff gT < 2 sin(pi/(2(2d + 1))) (the roots of z^(d+1) - z^d + gT). Jury on the loop's own
    characteristic polynomial, 1 % either side (the lam = 1e-4 pole near 1 moves it by O(lam T))."""
    T, lam = 1e-3, 1e-4
    edge = 2.0 * math.sin(math.pi / (2.0 * (2 * d + 1))) / T
    for g, stable in ((0.99 * edge, True), (1.01 * edge, False)):
        poly = characteristic_polynomial(kp=lam * g, kd=lam + g, control_period=T, velocity="exact", delay=d)
        assert jury_stable(poly) is stable


def _plain_loop(*, lam: float, g: float, phi: float, T: float, d: int, e: np.ndarray) -> tuple[float, float]:
    """The discretised law with its saturation, on the double integrator E'' = -u held over each period, the law
    reading E d periods late with the angle error e[k] and differencing it: (sup|s^|, sup|E|) at the samples."""
    E = Ed = 0.0
    hist = [0.0] * (d + 1)  # E[k - d .. k]
    prev = 0.0
    s_top = E_top = 0.0
    for ek in e:
        hist = hist[1:] + [E]
        E_hat = hist[0] - ek
        rate = (E_hat - prev) / T
        prev = E_hat
        s_hat = rate + lam * E_hat
        u = lam * rate + g * phi * min(1.0, max(-1.0, s_hat / phi))
        s_top, E_top = max(s_top, abs(s_hat)), max(E_top, abs(E))
        E, Ed = E + T * Ed - 0.5 * T * T * u, Ed - T * u
    return s_top, E_top


def test_worst_quantisation_sequence_reaches_the_layer_bound_and_random_ones_stay_below():
    """A differenced 12-bit angle (q bounded by Delta/2), 3 periods of delay: the sign of the time-reversed impulse
    response of s^ from the angle channel reaches the l1 bound within 1 % in a plain loop of the law with its
    saturation (phi above the bound, so sat stays linear), and random bounded sequences stay below it."""
    lam, g, T, d = 20.0, 40.0, 1e-3, 3
    q = 2.0 * math.pi / 4096 / 2.0
    loop = layer_loop(sampled_loop(kp=lam * g, kd=lam + g, control_period=T, velocity="difference",
                                   sensing_delay=d), lam=lam)
    bound = peak_gains(loop).gain("u", "quantisation") * q
    assert bound < 2.0 * q / T + 0.5  # telescoped: about 2 Delta/2/T, not an independent Delta/T per step
    n = 400
    h = np.empty(n)  # s^'s impulse response from e: C A^k B plus the direct part at k = 0
    x = np.array(loop.B[:, 0])
    h[0] = loop.D[2, 0]
    for k in range(1, n):
        h[k] = loop.C[2] @ x
        x = loop.A @ x
    worst = -q * np.sign(h[::-1])  # reaches sum|h| q at the last step (the model's e enters E^ with a minus)
    phi = 2.0 * bound
    s_top, _ = _plain_loop(lam=lam, g=g, phi=phi, T=T, d=d, e=worst)
    assert s_top == pytest.approx(bound, rel=0.01)
    E_bound = peak_gains(loop).gain("E", "quantisation") * q  # E's own row: the telescoped difference
    rng = np.random.default_rng(1)
    for _ in range(5):
        s_top, E_top = _plain_loop(lam=lam, g=g, phi=phi, T=T, d=d, e=rng.uniform(-q, q, 1500))
        assert s_top <= bound and E_top <= E_bound


def _sampled(**changes):
    cert = _claim(controller_params=dict(CERTIFYING), **changes)
    assert cert.inputs["certificates"]["sampled-data"]["E_max"] is not None
    return cert.inputs["certificates"]["sampled-data"]["E_max"]


def test_monotone_in_the_quantum_the_noise_and_the_delay():
    by_bits = [_sampled(sensing=Sensing(encoder_ticks=2 ** b, velocity="difference")) for b in (16, 14, 12)]
    by_noise = [_sampled(sensing=Sensing(noise_kind="uniform", noise=v, velocity="tachometer"))
                for v in (1e-5, 1e-4, 5e-4)]
    by_delay = [_sampled(sensing=Sensing(delay=t)) for t in (0.001, 0.005, 0.02)]
    for seq in (by_bits, by_noise, by_delay):
        assert seq == sorted(seq) and seq[0] < seq[-1]


def test_ideal_cart_takes_the_sampled_layer():
    """Issue 44 item 1: on the ideal cart too the layer is judged as a sampled loop; the boundary layer's
    phi/lam (a continuous-time bound) is recorded beside it, never taken alone."""
    cert = _claim(controller_params=dict(CERTIFYING))
    assert cert.inputs["certificate"] == "sampled-data" and cert.certified
    record = cert.inputs["certificates"]
    assert record["boundary-layer"]["E_max"] == CERTIFYING["phi"] / CERTIFYING["lam"]
    assert record["sampled-data"]["E_max"] == cert.E_max < CERTIFYING["phi"] / CERTIFYING["lam"]
    assert any(a.name == LAYER_NOT_SATURATED and a.met for a in cert.assumptions)
    # the ideal cart has no quantum: a smaller bound than the 12-bit cart's (0.0526 rad there)
    assert cert.E_max < _claim(sensing="magnetic-12bit-axis", controller_params=dict(CERTIFYING)).E_max


@pytest.mark.parametrize("sensing", ["magnetic-12bit-axis", Sensing(delay=0.02)])
def test_the_sampled_layer_certifies_the_12bit_and_20ms_carts(sensing):
    before = _claim(sensing=sensing)  # the default parameters: the layer saturates on the quantum's spike
    cert = _claim(sensing=sensing, controller_params=dict(CERTIFYING))
    assert cert.certified and cert.inputs["certificate"] == "sampled-data"
    record = cert.inputs["certificates"]
    assert record["sampled-data"]["E_max"] < (record["boundary-layer"]["E_max"] or math.inf)
    assert not before.certified


@pytest.mark.parametrize("sensing", ["magnetic-12bit-axis", "delay=0.02"])
def test_runs_are_certified_inside_or_uncertified(sensing):
    """A small sweep over the m1 box: never certified-outside (4 runs of 10 s each)."""
    from wmr_mj.experiments.sweep import SweepSpec, run_sweep

    spec = Sensing.from_spec(sensing)
    base = RunConfig.from_inputs(**{**BASE, "duration": 10.0, "controller_params": dict(CERTIFYING), "sensing": spec})
    runs = run_sweep(SweepSpec(n=4, seed=0, sampling="lhs", m1_range=tuple(base.m1_range), ranges={}, base=base))
    verdicts = [r["verdict"] for r in runs]
    assert len(verdicts) == 4 and CERTIFIED_OUTSIDE not in verdicts
    assert any(v.startswith("certified-inside") for v in verdicts)


def test_a_law_without_layer_gain_gets_no_sampled_bound():
    cert = _claim(sensing="magnetic-12bit-axis", controller_params={"lam": 5.0, "phi": 0.2, "k": 0.0, "eta": 0.0})
    assert "k = 0.0 V" in cert.inputs["certificates"]["sampled-data"]["reason"]


def test_the_run_names_the_boundary_layer_beside_the_sampled_certificate(capsys):
    from wmr_mj.cli.app import main

    argv = ["run", "--controller", "sliding-mode", "--model", "nonholonomic", "--sensing", "delay=0.02",
            "--m1", "750", "--duration", "10", "--no-log"]
    for name, value in CERTIFYING.items():
        argv += ["--controller-param", f"{name}={value}"]
    assert main(argv) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("certificate:"))
    assert "the sampled-data certificate (the boundary layer's: none: the layer did not settle" in line
