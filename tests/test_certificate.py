"""Tests of the certificate (wmr_mj.analysis.certificate) against closed forms, a brute-force friction
enumeration, direct substitution of the fixed point, and one MuJoCo run at the dead band."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmr_mj import C80, with_params
from wmr_mj.analysis.certificate import (
    GYRO_BAND,
    PLANT_K_BAND,
    VERDICTS,
    Assumption,
    Compensation,
    Estimate,
    Gains,
    PlantBox,
    PlantLimits,
    certify,
    fixed_point,
    friction_term,
    judge,
    loop_crossover,
)
from wmr_mj.analysis.measurement import MeasurementErrors
from wmr_mj.analysis.robustness import ParameterBox, analyse, exact_gammas
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.reference.bounds import ReferenceBounds
from wmr_mj.sim.certify import certificate_for as run_claim
from wmr_mj.sim.config import RunConfig, build_reference


def certificate_for(config, reference):
    """Section 4's certificate of the run (the paper's analysis, this file's subject): the law's continuous claim
    alone, as certificate_for gives it for the what-if 'exact measurement' (no sampled-data certificate beside
    it). A run is judged by the sampled-data certificate (issue 44 item 1; tests/test_sampled_certificate.py)."""
    return run_claim(config, reference, measurement=MeasurementErrors.exact())


def _S(a: float) -> float:
    return math.sin(a) / math.cos(a) ** 3


# A plant box with nothing uncertain but the Coulomb level (the closed-form cases).
EXACT = dict(P=0.385, C_V=4.77, gyro=0.629, V_A=0.2)
REF = dict(alpha0_max=0.659, alpha0_dot_max=0.23, alpha0_ddot_max=0.155)
LIMITS = dict(steering_range=0.9, voltage_limit=24.0, control_period=0.001)


def _certify(*, F=(1.313, 1.724), F_hat=1.518, K=(0.0, 0.0), K_hat=0.0, gyro=None, gyro_hat=None, kp=100.0,
             kd=20.0, sign="measured", **kw):
    box = ParameterBox(P=(EXACT["P"],) * 2, C_V=(EXACT["C_V"],) * 2, F=F, K=K)
    g = EXACT["gyro"]
    args = dict(box=box, gyro=gyro or (g, g), V_A=(EXACT["V_A"],) * 2, P_hat=EXACT["P"], C_V_hat=EXACT["C_V"],
                F_hat=F_hat, K_hat=K_hat, gyro_hat=g if gyro_hat is None else gyro_hat, V_A_hat=EXACT["V_A"],
                kp=kp, kd=kd, friction_sign=sign, **REF, **LIMITS)
    args.update(kw)
    return _certify_flat(**args)


def _certify_flat(*, box, gyro, V_A, P_hat, C_V_hat, F_hat, K_hat, gyro_hat, V_A_hat, kp, kd, friction_sign="measured",
                  friction_width=0.0, feedforward=True, alpha0_max, alpha0_dot_max, alpha0_ddot_max, steering_range,
                  voltage_limit, control_period, initial_error=(0.0, 0.0), stated=(), friction_over_P=None):
    """certify() of the inputs named one by one (the groups built here)."""
    return certify(plant=PlantBox(box=box, gyro=gyro, V_A=V_A, friction_over_P=friction_over_P),
                   estimate=Estimate(P=P_hat, C_V=C_V_hat, F=F_hat, K=K_hat, gyro=gyro_hat, V_A=V_A_hat),
                   gains=Gains(kp=kp, kd=kd),
                   reference=ReferenceBounds(alpha_max=alpha0_max, alpha_dot_max=alpha0_dot_max,
                                             alpha_ddot_max=alpha0_ddot_max),
                   limits=PlantLimits(steering_range=steering_range, voltage_limit=voltage_limit),
                   compensation=Compensation(friction_sign=friction_sign, friction_width=friction_width,
                                             feedforward=feedforward),
                   control_period=control_period, initial_error=initial_error, stated=stated)


@pytest.fixture(scope="module")
def circle(paper_reference):
    return paper_reference


# ----------------------------------------------------------------- friction term by mode
@pytest.mark.parametrize("F_hat", [0.0, 1.0, 1.518, 2.5])
def test_friction_term_closed_forms(F_hat):
    F = (1.313, 1.724)
    assert friction_term("none", F=F, F_hat=F_hat) == 1.724
    assert friction_term("measured", F=F, F_hat=F_hat) == max(1.724, F_hat)
    assert friction_term("reference", F=F, F_hat=F_hat) == pytest.approx(1.724 + F_hat)
    with pytest.raises(UnknownNameError, match="measured, none, reference"):
        friction_term("paper", F=F, F_hat=F_hat)


def _brute_friction(mode: str, F_range, F_hat: float) -> float:
    """sup |f - F^ s| by enumeration: sliding (f = F sgn a'), stuck (|tau + F^ s| <= F, f = tau + F^ s)
    with s = 0 (exact sign at rest) or locked to the creep direction sgn(tau + F^ s) ('measured'),
    s anything in [-1, 1] ('reference'), s = 0 ('none')."""
    worst = 0.0
    s_all = np.linspace(-1.0, 1.0, 41)
    for F in np.linspace(*F_range, 5):
        for direction in (-1.0, 1.0):  # sliding
            if mode == "measured":
                ss = direction * np.linspace(0.0, 1.0, 21)  # smoothed or exact, same sign as a'
            elif mode == "reference":
                ss = s_all
            else:
                ss = [0.0]
            worst = max(worst, max(abs(F * direction - F_hat * s) for s in ss))
        for tau in np.linspace(-F - F_hat - 0.1, F + F_hat + 0.1, 801):  # stuck
            if mode == "measured":
                cand = [0.0] + [s for s in s_all if s != 0 and (tau + F_hat * s) * s > 0]
            elif mode == "reference":
                cand = s_all
            else:
                cand = [0.0]
            for s in cand:
                if abs(tau + F_hat * s) <= F:
                    worst = max(worst, abs(tau))  # f - F^ s = tau
    return worst


@pytest.mark.parametrize("mode", ["measured", "reference", "none"])
@pytest.mark.parametrize("F_hat", [1.0, 1.518, 2.5])
def test_friction_term_matches_enumeration(mode, F_hat):
    F = (1.313, 1.724)
    F_hat_eff = 0.0 if mode == "none" else F_hat
    brute = _brute_friction(mode, F, F_hat_eff)
    phi = friction_term(mode, F=F, F_hat=F_hat_eff)
    assert brute <= phi + 1e-12
    assert brute == pytest.approx(phi, rel=0.01)  # the bound is reached


@pytest.mark.parametrize("sign,phi", [("none", 1.724), ("measured", 1.724), ("reference", 1.724 + 1.518)])
def test_delta1_is_friction_over_P_when_nothing_else_is_uncertain(sign, phi):
    c = _certify(sign=sign, F_hat=0.0 if sign == "none" else 1.518)
    assert c.delta1 == pytest.approx(phi / 0.385, rel=1e-12)
    assert c.friction_term == pytest.approx(phi / 0.385, rel=1e-12)
    assert c.delta2 == 0.0 and c.delta3 == 0.0 and c.condition == 0.0
    # critical damping: gamma1 = 1/K_P, so E_max is exactly phi/(P^ K_P); 'none'/'measured' = the dead band
    assert c.E_max == pytest.approx(phi / (0.385 * 100.0), rel=1e-12)
    if sign != "reference":
        assert c.E_max == pytest.approx(c.dead_band, rel=1e-12)
    assert c.Edot_max == pytest.approx(4.0 / (math.e * 20.0) * phi / 0.385, rel=1e-12)


# ----------------------------------------------------------------- fixed point
def test_paper_example_moves_to_0166():
    """(5.1): K~ sin/cos^3 over the reachable angle instead of over alpha0 (0.105 -> 0.166 rad)."""
    r = analyse(ParameterBox.paper())
    assert r.condition == pytest.approx(0.26204, abs=1e-5) and r.E_max == pytest.approx(0.10499, abs=1e-5)
    from scipy.optimize import brentq

    a0 = brentq(lambda a: _S(a) - 1.24, 0.3, 1.2)

    def phi(x):
        d1 = (0.03 * 0.4 + 0.03 + 0.08 * 0.23 + 0.09 * _S(a0 + x)) / 0.37
        return r.gamma1 * d1 / (1.0 - r.condition)

    assert phi(0.0) == pytest.approx(r.E_max, rel=1e-9)  # a0 from brentq (xtol 2e-12 rad): ~1e-11 relative
    x, iterations, reason = fixed_point(phi, a0)
    assert reason == "" and iterations > 3
    assert x == pytest.approx(phi(x), rel=1e-12)  # direct substitution
    assert x == pytest.approx(0.1663, abs=5e-4)


def test_fixed_point_refusals():
    # leaves (-pi/2, pi/2)
    x, _, reason = fixed_point(lambda x: 1.0 + 2.0 * x, 0.5)
    assert math.isinf(x) and "pi/2" in reason
    # (4.23) fails on the way
    x, _, reason = fixed_point(lambda x: 0.1 + x if x < 0.3 else math.inf, 0.0)
    assert math.isinf(x) and "(4.23)" in reason
    # tangent: phi(x) = x at x = 0.25 and phi >= x beyond (x + (x - 1/4)^2 ... touches)
    x, _, reason = fixed_point(lambda x: x + (x - 0.25) ** 2, 0.0, max_iterations=200000)
    assert math.isinf(x)


def test_design_fixed_point_by_substitution(circle):
    """certificate_for's E_max solves E = Phi(E), recomputed here from the closed forms."""
    cfg = RunConfig(model="nonholonomic", kp=100.0, kd=20.0, friction_width=0.01)
    c = certificate_for(cfg, circle)
    assert c.certified, c.unmet
    b = circle.bounds()
    P, F_max = C80.coefficients("nonholonomic").P, c.inputs["box"]["F"][1]
    G_hat = C80.coefficients("nonholonomic").gyro * C80.V_A
    G_lo, G_hi = GYRO_BAND[0] * G_hat, GYRO_BAND[1] * G_hat  # P fixed over m1
    dG = max(G_hat - G_lo, G_hi - G_hat)
    a_max = b.alpha_max + c.E_max
    c2 = math.cos(a_max) ** 2
    d1 = (F_max + PLANT_K_BAND * _S(a_max) + dG * b.alpha_dot_max / c2) / P
    d3 = dG / c2 / P
    g1, g2 = exact_gammas(100.0, 20.0)
    cond = g2 * d3
    assert c.delta1 == pytest.approx(d1, rel=1e-12)
    assert c.condition == pytest.approx(cond, rel=1e-12)
    assert c.E_max == pytest.approx(g1 * d1 / (1 - cond), rel=1e-11)
    assert c.Edot_max == pytest.approx(g2 * d1 / (1 - cond), rel=1e-11)
    assert c.alpha_max == pytest.approx(b.alpha_max + c.E_max)


@pytest.mark.parametrize("omega_r", [20.0, 40.0])
def test_high_gain_approaches_dead_band_from_above(circle, omega_r):
    kp, kd = omega_r**2 / 4, omega_r
    c = certificate_for(RunConfig(model="nonholonomic", kp=kp, kd=kd, friction_sign="none"), circle)
    F_max = c.inputs["box"]["F"][1]
    dead = F_max / (C80.coefficients("nonholonomic").P * kp)
    assert c.dead_band == pytest.approx(dead)
    assert 1.0 < c.E_max / dead < 1.05


# ----------------------------------------------------------------- gyro
def test_gyro_term_zero_when_model_has_it():
    c = _certify()  # plant gyro range == the estimate's
    assert c.gyro_term == 0.0 and c.gyro_Edot_term == 0.0
    # the paper's model (no gyro): the whole plant term is unmodelled, through max|a0'| and ||E'||
    p = _certify(gyro_hat=0.0)
    a_max = REF["alpha0_max"] + p.E_max
    G = EXACT["gyro"] * EXACT["V_A"]
    c2 = math.cos(a_max) ** 2
    assert p.gyro_term == pytest.approx(G * REF["alpha0_dot_max"] / c2 / EXACT["P"], rel=1e-12)
    assert p.gyro_Edot_term == pytest.approx(G / c2 / EXACT["P"], rel=1e-12)
    assert p.delta3 == pytest.approx(G / c2 / EXACT["P"], rel=1e-12)
    assert p.E_max > c.E_max


def test_paper_design_is_not_certified(circle):
    """The paper's design (paper model, 6/9, exact sign) on this plant: K^ = 5.33 V has no counterpart."""
    c = certificate_for(RunConfig(), circle)
    assert not c.valid and not c.certified
    assert {"reachable angle", "inside the steering stops", "within the supply"} <= set(c.unmet)
    assert "(4.23) small gain" not in c.unmet  # (4.23) itself holds
    assert c.K_term == pytest.approx((5.3336 + PLANT_K_BAND) * 1.2372 / 0.385, rel=2e-3)
    assert c.dead_band == pytest.approx(c.inputs["box"]["F"][1] / (0.385 * 6.0), rel=1e-3)  # 0.746 rad
    assert c.verdict(0.001, 0.001) == "uncertified-outside"
    d = c.to_dict()
    json.dumps(d, allow_nan=False)
    assert d["E_max"] is None and d["valid"] is False


# ----------------------------------------------------------------- assumptions and verdicts
def test_supply_and_stops_assumptions_by_hand():
    c = _certify(sign="none", F_hat=0.0)
    a_max = REF["alpha0_max"] + c.E_max
    rate = REF["alpha0_dot_max"] + c.Edot_max
    u = (EXACT["P"] * (REF["alpha0_ddot_max"] + 20.0 * c.Edot_max + 100.0 * c.E_max) + EXACT["C_V"] * rate
         + EXACT["gyro"] * EXACT["V_A"] * rate / math.cos(a_max) ** 2)
    assert c.voltage_max == pytest.approx(u, rel=1e-12)
    assert c.certified
    low = _certify(sign="none", F_hat=0.0, voltage_limit=u * 0.99)
    assert low.unmet == ("within the supply",)
    tight = _certify(sign="none", F_hat=0.0, steering_range=a_max * 0.999)
    assert tight.unmet == ("inside the steering stops",)


def test_control_period_assumption():
    wc, pm = loop_crossover(100.0, 20.0)
    assert abs(complex(100.0, 20.0 * wc)) == pytest.approx(wc * wc, rel=1e-12)  # |L(j wc)| = 1
    assert pm == pytest.approx(math.atan(20.0 * wc / 100.0))
    ok = _certify(control_period=0.001)
    limit = 0.1 * pm / wc
    assert ok.certified
    slow = _certify(control_period=limit * 1.01)
    assert slow.unmet == ("control period",)
    assert _certify(control_period=limit * 0.99).certified


def test_verdict_table():
    good = _certify()
    bad = _certify(stated=(Assumption("x", "x", False, 2.0, 1.0, kind="stated"),))
    assert good.certified and not bad.certified and bad.unmet == ("x",)
    E, Ed = good.E_max, good.Edot_max
    table = {
        (good, 0.5 * E, 0.5 * Ed): "certified-inside",
        (good, 1.01 * E, 0.1 * Ed): "certified-outside",
        (good, 0.1 * E, 1.01 * Ed): "certified-outside",
        (bad, 0.5 * E, 0.5 * Ed): "uncertified-inside",
        (bad, 2.0 * E, 0.5 * Ed): "uncertified-outside",
    }
    for (cert, x, y), verdict in table.items():
        assert cert.verdict(x, y) == verdict
        assert verdict in VERDICTS
    # the region (4.21) is the polygon, not the rectangle E_max x Edot_max: with delta3 > 0 and
    # ||E'|| = 0, ||E|| <= gamma1 delta1 < E_max = gamma1 delta1 / (1 - gamma2 delta3)
    g = _certify(gyro=(0.3, 1.0))
    assert g.delta2 == 0.0 and g.gamma2 * g.delta3 > 0.01
    assert g.inside(g.E_max, g.Edot_max)  # the corner is in the region
    assert g.vertices[1][0] == pytest.approx(g.gamma1 * g.delta1)
    assert not g.inside(0.999 * g.E_max, 0.0)  # inside the rectangle, outside the region
    assert g.inside(0.999 * g.gamma1 * g.delta1, 0.0)
    judged = judge(good, 0.5 * E, 0.25 * Ed)
    j = judged.to_dict()
    for key in ("E_max", "Edot_max", "condition", "valid", "assumptions", "inside", "E_ratio", "Edot_ratio",
                "verdict"):
        assert key in j
    assert judged.E_ratio == pytest.approx(0.5) and judged.Edot_ratio == pytest.approx(0.25)
    assert all({"name", "met", "value", "limit"} <= set(a) for a in j["assumptions"])
    json.dumps(j, allow_nan=False)
    assert good.verdict(math.nan, 0.0) == "certified-outside"  # a diverged run is outside
    assert judge(good, math.inf, 0.0).E_ratio is None
    with pytest.raises(ParameterError, match="sup_E"):
        good.inside(-1.0, 0.0)


def test_certify_validation():
    with pytest.raises(UnknownNameError, match="friction sign"):
        _certify(sign="exact")
    with pytest.raises(ParameterError, match="P_hat"):
        _certify(P_hat=0.0)
    with pytest.raises(ParameterError, match="alpha0_max"):
        _certify(alpha0_max=2.0)
    with pytest.raises(ParameterError, match="PD"):
        _certify(feedforward=False)


def test_pd_has_no_feedforward():
    c = _certify(sign="none", F_hat=0.0, feedforward=False, C_V_hat=0.0, gyro_hat=0.0)
    assert c.P_term == pytest.approx(REF["alpha0_ddot_max"])  # |P - 0| a0''/P


def test_identified_two_sigma_hull(circle, tmp_path):
    ident = {"identified": {"P": 0.39, "C_V": 4.8, "F": 1.5, "K": -0.005, "gyro": 0.70},
             "diagnostics": {"std_error": {"P": 0.01, "C_V": 0.02, "F": 0.2, "K": 0.03, "gyro": 0.2}}}
    c = certificate_for(RunConfig(model="identified", identified=ident, kp=100.0, kd=20.0,
                                  friction_width=0.01), circle)
    box = c.inputs["box"]
    assert box["P"] == pytest.approx([0.37, 0.41])  # hull of 0.385 (box) and 0.39 +- 0.02
    assert box["C_V"] == pytest.approx([4.76, 4.84])
    assert box["F"] == pytest.approx([1.1, 1.9])
    assert box["K"] == pytest.approx([-0.065, 0.055])
    assert c.inputs["gyro"][1] == pytest.approx(1.1)
    assert c.inputs["estimate"]["gyro"] == 0.70
    # the same from a file written by `wmr-mj identify --out`
    path = tmp_path / "ident.json"
    path.write_text(json.dumps(ident))
    from_file = certificate_for(RunConfig(model="identified", identified=str(path), kp=100.0, kd=20.0,
                                          friction_width=0.01), circle)
    assert from_file.inputs["box"] == c.inputs["box"] and from_file.E_max == c.E_max


# ----------------------------------------------------------------- CLI
def test_cli_certificate(capsys):
    assert main(["robustness", "--certificate", "--model", "nonholonomic", "--omega-r", "20",
                 "--friction-width", "0.01", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("E_max", "Edot_max", "valid", "assumptions", "paper_region"):
        assert key in out
    assert out["valid"] and out["certified"]
    # the run's certificate is the sampled-data one (issue 44 item 1); section 4's (the paper's analysis) beside it
    assert out["claimant"] == "sampled-data" and out["E_max"] == pytest.approx(0.0922, abs=5e-4)
    assert out["inputs"]["certificates"]["section-4"]["E_max"] == pytest.approx(0.0463, abs=5e-4)
    assert all({"name", "met", "value", "limit"} <= set(a) for a in out["assumptions"])
    assert main(["robustness", "--certificate"]) == 0  # the paper's design: a table with what fails
    text = capsys.readouterr().out
    assert "[NOT met] reachable angle" in text and "NOT CERTIFIED" in text and "section-4" in text
    assert main(["robustness", "--certificate", "--uncertainty", "full", "--model", "nonholonomic",
                 "--omega-r", "20", "--json"]) == 0
    full = json.loads(capsys.readouterr().out)
    P_hat = C80.coefficients("nonholonomic").P
    assert full["inputs"]["terms"]["delta_u"] == pytest.approx(1 - P_hat / 0.5005, abs=2e-3)  # R_a 1.3 Ohm moves P


@pytest.mark.parametrize("argv,pattern", [
    (["--kp", "6", "--certificate"], "before --certificate"),
    (["--certificate", "--model", "bogus"], "unknown model source"),
    (["--certificate", "--friction-sign", "exact"], "friction sign"),
    (["--certificate", "--range", "bogus=1:2"], "unknown parameter"),
])
def test_cli_certificate_bad_input(capsys, argv, pattern):
    assert main(["robustness", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and pattern in err


def test_cli_certificate_extreme_gains(capsys):
    assert main(["robustness", "--certificate", "--kp", "1e308", "--kd", "1e308", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["E_max"] is None or math.isfinite(out["E_max"])


def test_cli_without_certificate_unchanged(capsys):
    assert main(["robustness"]) == 0
    text = capsys.readouterr().out
    assert "0.26204" in text and "+0.28%" in text and "Certificate" not in text


# ----------------------------------------------------------------- MuJoCo: the dead band
def test_mujoco_none_at_high_gain_reaches_dead_band():
    """With no Coulomb compensation the PD must carry the whole friction while the joint slides:
    sup|E| = F/(P^ K_P) (critical damping does not overshoot). At m1 = 750 kg, F = F_max of the box."""
    from wmr_mj.sim.closed_loop import run_closed_loop

    cfg = RunConfig(model="nonholonomic", kp=100.0, kd=20.0, friction_sign="none", m1=750.0, duration=12.0)
    result = run_closed_loop(cfg, progress=False)
    reference = build_reference(cfg.path, C80, dt=1e-3, duration=cfg.duration)[0]
    cert = certificate_for(cfg, reference)
    sup_E = result.summary.sup_E
    F_plant = with_params(C80, m1=750.0).coefficients("nonholonomic").F
    assert cert.inputs["box"]["F"][1] == pytest.approx(F_plant, rel=1e-12)  # m1 = 750 kg is the box's F_max
    assert cert.dead_band == pytest.approx(F_plant / (C80.coefficients("nonholonomic").P * 100.0), rel=1e-12)
    assert sup_E == pytest.approx(cert.dead_band, rel=0.03)
    assert sup_E < cert.E_max
    assert cert.verdict(sup_E, result.summary.sup_Edot) == "certified-inside"


def test_extreme_gains_certify_or_refuse_cleanly():
    """Any finite gains: a certificate (JSON-clean) or a WmrMjError, never another exception."""
    from wmr_mj.errors import WmrMjError

    rng = np.random.default_rng(0)
    made = 0
    for _ in range(300):
        kp, kd = 10.0 ** rng.uniform(-307, 308, size=2)
        try:
            c = _certify(kp=kp, kd=kd)
        except WmrMjError:
            continue
        json.dumps(c.to_dict(), allow_nan=False)
        assert c.verdict(0.01, 0.01) in VERDICTS
        made += 1
    assert made > 100


# ----------------------------------------------------------------- F and P move together with R_a
def test_correlated_friction_term_is_F_over_P_not_F_max_over_P_min():
    """A plant family F = r P (R_a scales both): with friction_over_P = r the friction part of delta1
    is r (closed form), not F_max/P_min; with a bound that does not bind it is the box's own."""
    r, P = 4.0, (0.385, 0.5)
    box = ParameterBox(P=P, C_V=(4.77, 4.77), F=(r * P[0], r * P[1]), K=(0.0, 0.0))
    common = dict(box=box, gyro=(0.629, 0.629), V_A=(0.2, 0.2), P_hat=0.385, C_V_hat=4.77, F_hat=1.0, K_hat=0.0,
                  gyro_hat=0.629, V_A_hat=0.2, kp=100.0, kd=20.0, friction_sign="none", **REF, **LIMITS)
    loose = _certify_flat(**common)
    tight = _certify_flat(**common, friction_over_P=r)
    assert loose.friction_term == pytest.approx(r * P[1] / P[0], rel=1e-12)
    assert tight.friction_term == pytest.approx(r, rel=1e-12)
    assert tight.E_max < loose.E_max
    same = _certify_flat(**common, friction_over_P=r * P[1] / P[0])  # F_max/P_min: binds nowhere
    assert same.E_max == loose.E_max and same.delta1 == loose.delta1


def test_friction_over_P_bounds_every_plant_of_the_full_box():
    from wmr_mj.analysis.certificate import friction_over_P_max
    from wmr_mj.params import uncertainty_ranges

    full = {k: v for k, v in uncertainty_ranges("full").items() if k != "m1"}
    ratio = friction_over_P_max(C80, (550.0, 750.0), "payload", tuple(sorted(full.items())))
    rng = np.random.default_rng(0)
    seen = []
    for _ in range(200):  # random plants of the box: none above the bound, the top one at a corner
        pick = {k: rng.uniform(*v) for k, v in full.items()}
        c = with_params(C80, m1=rng.uniform(550.0, 750.0), **pick).coefficients("nonholonomic")
        seen.append(c.F / c.P)
    top = with_params(C80, m1=750.0, mu=full["mu"][1]).coefficients("nonholonomic")
    assert max(seen) <= ratio and ratio == pytest.approx(top.F / top.P, rel=1e-12)
    # F/P does not move with R_a (both scale with it)
    a, b = (with_params(C80, R_a=x).coefficients("nonholonomic") for x in (1.0, 1.3))
    assert a.F / a.P == pytest.approx(b.F / b.P, rel=1e-12)
    # a parameter F/P is not monotone in gives no bound
    assert friction_over_P_max(C80, (550.0, 750.0), "payload", (("l4", (0.2, 0.3)),)) is None


# -- the box says where it ends: a plant outside the declared box is not covered ----------------

CERTIFIED_CFG = dict(model="nonholonomic", kp=100.0, kd=20.0, friction_width=0.01)


@pytest.mark.parametrize("changes,name,value,limit,widen", [
    (dict(m1=800.0), "m1", 800.0, 750.0, "--m1-range 550 800"),
    (dict(m1=500.0), "m1", 500.0, 550.0, "--m1-range 500 750"),
    (dict(plant_overrides={"mu": 0.03}, box_ranges={"mu": (0.0129, 0.0215)}), "mu", 0.03, 0.0215,
     "--range mu=0.0129:0.03"),
    (dict(plant_overrides={"l3": 0.15}), "l3", 0.15, 0.142, "--range l3=0.142:0.15"),
])
def test_a_plant_outside_the_box_fails_an_assumption_and_leaves_the_box_alone(circle, changes, name, value, limit,
                                                                            widen):
    inside = certificate_for(RunConfig(**CERTIFIED_CFG, **{k: v for k, v in changes.items() if k == "box_ranges"}),
                             circle)
    outside = certificate_for(RunConfig(**CERTIFIED_CFG, **changes), circle)
    assert inside.certified and not outside.certified
    assert outside.E_max == inside.E_max and outside.inputs["box"] == inside.inputs["box"]  # no hull with the plant
    (failed,) = [a for a in outside.assumptions if not a.met]
    assert failed.name == f"plant inside the box: {name}"
    assert failed.value == pytest.approx(value) and failed.limit == pytest.approx(limit)
    assert widen in failed.note
    assert judge(outside, 0.0, 0.0).verdict == "uncertified-inside"


def test_a_plant_inside_the_box_has_the_assumptions_it_had(circle):
    c = certificate_for(RunConfig(**CERTIFIED_CFG, m1=750.0, plant_overrides={"mu": 0.0129},
                                  box_ranges={"mu": (0.0129, 0.0215)}), circle)
    assert c.certified and not any(a.name.startswith("plant inside the box") for a in c.assumptions)
    assert len(c.assumptions) == 8


@pytest.mark.slow
def test_cli_run_outside_the_box_is_uncertified(tmp_path):
    import subprocess
    import sys

    def run(*argv):
        proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "run", "--preset", "certified", "--no-log",
                               "--duration", "10", *argv], capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0, proc.stderr
        return proc.stdout

    out = run("--m1", "800")
    assert "UNCERTIFIED-" in out and "plant inside the box: m1 (800 vs 750)" in out and "--m1-range 550 800" in out
    s = json.loads(run("--m1", "800", "--json"))
    assert s["verdict"].startswith("uncertified-")
    # the declared box's, not hulled: the same certificate as a plant inside the box gets (m1 = 750 kg), the
    # sampled-data one a run takes, section 4's beside it (issue 44)
    inside = json.loads(run("--m1", "750", "--json"))
    assert inside["verdict"] == "certified-inside"
    assert s["certificate"]["claimant"] == inside["certificate"]["claimant"] == "sampled-data"
    assert s["certificate"]["E_max"] == inside["certificate"]["E_max"]
    section_4 = s["certificate"]["inputs"]["certificates"]["section-4"]["E_max"]
    assert section_4 == inside["certificate"]["inputs"]["certificates"]["section-4"]["E_max"]
    assert section_4 < s["certificate"]["E_max"]
    assert json.loads(run("--m1", "800", "--m1-range", "550", "800", "--json"))["verdict"] == "certified-inside"
