"""Identification: a synthetic plant with known answers, then the MuJoCo plant."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from wmr_mj import C80
from wmr_mj.plant.identify import fit_steering_model, identify_plant
from wmr_mj.plant.reduced import SteeringModel

TRUE = dict(P=0.41, C_V=4.5, F=1.2, K=3.1, gyro=0.8)


def _synthetic(model: SteeringModel, *, duration=40.0, dt=1e-3, seed=3):
    """Integrate the reduced model under a multisine voltage with scipy; return samples."""
    rng = np.random.default_rng(seed)
    freqs = np.linspace(0.05, 3.0, 15)
    phases = rng.uniform(0, 2 * np.pi, freqs.size)
    def speed(t):  # a varying V_A separates gyro from C_V
        return model.V_A * (1.0 + 0.3 * np.sin(0.7 * t))

    slow = np.linspace(0.03, 0.4, 6)
    slow_phases = rng.uniform(0, 2 * np.pi, slow.size)

    def u_of(t, a):
        """A servo towards a random multisine angle (about +-0.6 rad) plus a voltage multisine."""
        target = 0.6 * np.sum(np.sin(2 * np.pi * slow * t + slow_phases)) / slow.size * 2.0
        dither = 3.0 * np.sum(np.sin(2 * np.pi * freqs * t + phases)) / np.sqrt(freqs.size)
        return 25.0 * (target - a) + dither

    width = 1e-4  # a smoothed sign keeps the ODE well posed through zero rate

    def rhs(t, x):
        a, ad = x
        m = model.with_coefficients(V_A=float(speed(t)))
        return [ad, float(m.acceleration(a, ad, u_of(t, a), friction_sign=np.tanh(ad / width)))]

    t = np.arange(0.0, duration, dt)
    sol = solve_ivp(rhs, (0, duration), [0.0, 0.0], t_eval=t, rtol=1e-10, atol=1e-12, method="LSODA")
    a, ad = sol.y
    u = np.array([u_of(ti, ai) for ti, ai in zip(t, a)])
    v = speed(t)
    add = np.array([model.with_coefficients(V_A=float(vi)).acceleration(ai, adi, ui, friction_sign=np.tanh(adi / width))
                    for ai, adi, ui, vi in zip(a, ad, u, v)])
    return a, ad, add, u, v


@pytest.mark.slow
def test_fit_recovers_known_coefficients_from_synthetic_plant():
    model = SteeringModel(**TRUE, V_A=0.2)
    a, ad, add, u, v = _synthetic(model)
    assert np.max(np.abs(a)) > 0.3  # the K term was exercised
    coeffs, diag = fit_steering_model(a, ad, add, u, v, min_rate=0.02)
    for k, value in TRUE.items():
        assert getattr(coeffs, k) == pytest.approx(value, rel=0.01), k
    assert diag["samples"] > 1000


@pytest.mark.slow
def test_mujoco_plant_p_and_cv_match_parameter_set():
    result = identify_plant(C80, duration=30.0, seed=0)
    pred = result.predicted["paper"]
    assert result.identified.P == pytest.approx(pred.P, rel=0.03)
    assert result.identified.C_V == pytest.approx(pred.C_V, rel=0.03)
    # with stiction the sliding friction is the joint's frictionloss, F of (2.13), and the fit is clean
    # (MuJoCo's soft friction left about 0.1 V of residual)
    assert result.identified.F == pytest.approx(pred.F, rel=0.01)
    assert result.diagnostics["residual_rms_V"] < 0.01
    assert result.diagnostics["mujoco_warnings"] == 0
    # what the plant shows about K is reported with numbers, whatever it is
    assert f"{result.identified.K:.4g}" in result.verdict()


@pytest.mark.slow
def test_cli_json_keys_and_three_way_comparison():
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "identify", "--duration", "10", "--json"],
                          capture_output=True, text=True, check=True)
    obj = json.loads(proc.stdout)
    for k in ("P", "C_V", "F", "K", "gyro"):
        assert isinstance(obj[k], float)
        for model in ("paper", "nonholonomic"):
            assert k in obj["predicted"][model]
    assert obj["predicted"]["paper"]["K"] == pytest.approx(C80.coefficients("paper").K)
    assert obj["predicted"]["nonholonomic"]["K"] == 0.0
    text = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "identify", "--duration", "5"],
                          capture_output=True, text=True, check=True).stdout
    assert "paper" in text and "nonholon" in text and "identified" in text


@pytest.mark.slow
@pytest.mark.parametrize("argv", [["--m1", "-1"], ["--m1", "nan"], ["--duration", "0"], ["--param", "nope=1"]])
def test_cli_bad_input_exits_2(argv):
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "identify", *argv], capture_output=True, text=True)
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1
    assert "Traceback" not in proc.stderr
