"""The Coulomb sign's charge in the sampled-data certificate (issue 44 item 2): the smoothed sign of the measured
alpha' is 1/w-Lipschitz, so its mismatch is max(F_max, F^) + F^ eps_v/w, beside the old F_max + F^; each checked
against a closed form (a synthetic plant the law models exactly but for its friction) and the lemma by sampling."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmr_mj.analysis.plant_box import PlantBox, PlantLimits
from wmr_mj.analysis.robustness import ParameterBox
from wmr_mj.analysis.sampled_certificate import SampledCart, sampled_certificate
from wmr_mj.analysis.small_gain import Compensation, Estimate, Gains
from wmr_mj.hardware.sensing import Sensing
from wmr_mj.reference.bounds import ReferenceBounds

T = 0.001
P, F = 0.385, 1.5  # V s^2/rad, V: F^ = F, the law's estimate exact
KP, KD = 400.0, 40.0
LIMITS = PlantLimits(steering_range=0.9, voltage_limit=24.0)
STILL = ReferenceBounds(alpha_max=0.0, alpha_dot_max=0.0, alpha_ddot_max=0.0, sin_cos3_max=0.0)
MOVING = ReferenceBounds(alpha_max=0.3, alpha_dot_max=0.2, alpha_ddot_max=0.4, sin_cos3_max=0.3)


def _certify(sign: str, width: float, *, reference: ReferenceBounds = STILL, sensing: Sensing | None = None):
    """A plant the law models exactly (P = P^, no C_V, K, gyro) but for its Coulomb friction F in [F, F]."""
    box = ParameterBox(P=(P, P), C_V=(0.0, 0.0), F=(F, F), K=(0.0, 0.0))
    plant = PlantBox(box=box, gyro=(0.0, 0.0), V_A=(0.2, 0.2))
    estimate = Estimate(P=P, C_V=0.0, F=0.0 if sign == "none" else F, K=0.0, gyro=0.0, V_A=0.2)
    cart = SampledCart.of(sensing or Sensing(), control_period=T, gear_ratio=60.0)
    return sampled_certificate(plant=plant, estimate=estimate, gains=Gains(kp=KP, kd=KD), reference=reference,
                               limits=LIMITS, compensation=Compensation(friction_sign=sign, friction_width=width),
                               control_period=T, cart=cart)


def test_the_lemma_by_sampling():
    """|f - F^ s(v_m)| <= max(F, F^) + F^ |v - v_m|/w for f in F Sgn(v) (stiction: any f in [-F, F] at v = 0),
    s(x) = x/sqrt(x^2 + w^2), over random states, and the old charge F + F^ always."""
    rng = np.random.default_rng(0)
    w, F_hat = 0.05, 1.2
    v = np.concatenate([rng.normal(0.0, 0.1, 50_000), np.zeros(10_000)])
    v_m = v + rng.normal(0.0, 0.05, v.size) * rng.integers(0, 2, v.size)
    f = np.where(v == 0.0, rng.uniform(-F, F, v.size), F * np.sign(v))
    mismatch = np.abs(f - F_hat * v_m / np.sqrt(v_m ** 2 + w * w))
    assert np.all(mismatch <= max(F, F_hat) + F_hat * np.abs(v - v_m) / w + 1e-12)
    assert np.all(mismatch <= F + F_hat + 1e-12)
    assert mismatch.max() > max(F, F_hat)  # a wrong sign is drawn: the extra term is needed


def test_a_vanishing_width_keeps_the_old_charge_to_the_bit():
    """With w -> 0 the Lipschitz charge grows without bound: the old F_max + F^ is taken, the certificate is the
    width-0 one."""
    old, tiny = _certify("measured", 0.0), _certify("measured", 1e-9, reference=STILL)
    assert old.inputs["terms"]["friction_term"] == (F + F) / P
    assert tiny.E_max == old.E_max and tiny.inputs["terms"] == old.inputs["terms"]


def test_a_wide_sign_tends_to_no_compensation():
    """With w -> infinity the compensation F^ x/sqrt(x^2 + w^2) vanishes: the mismatch is the plant's friction
    alone, F/P, the charge of the law without compensation ('none'), and so is the certificate's E_max."""
    none = _certify("none", 0.0)
    wide = _certify("measured", 1e7)
    assert none.inputs["terms"]["friction_term"] == F / P
    assert wide.inputs["terms"]["friction_term"] == pytest.approx(F / P, rel=1e-9)
    assert wide.E_max == pytest.approx(none.E_max, rel=1e-6)
    assert wide.E_max < _certify("measured", 0.0).E_max / 1.9  # the old charge is twice F/P here


def test_the_charge_in_closed_form():
    """At a moderate width, on the ideal cart (e_v = 0, lag = T: the compensation is one period old at most) and a
    moving reference: friction_term = max(F, F^)/P + F^ T max|alpha0''|/(w P), and sup|E''| enters with
    F^ T/(w P) (k_A; nothing else has an age here)."""
    w = 0.3
    cert = _certify("measured", w, reference=MOVING)
    terms = cert.inputs["terms"]
    assert terms["friction_term"] == pytest.approx(F / P + F * T * MOVING.alpha_ddot_max / (w * P), rel=1e-12)
    assert terms["k_A"] == pytest.approx(F * T / (w * P), rel=1e-12)
    old = _certify("measured", 0.0, reference=MOVING)
    assert cert.certified and old.certified and cert.E_max < 0.6 * old.E_max


def test_a_coarse_velocity_keeps_the_old_charge():
    """A differenced 12-bit angle's e_v = Delta/T = 1.53 rad/s is many widths: eps_v/w > 1, the old charge binds."""
    sensing = Sensing.from_spec("magnetic-12bit-axis")
    assert _certify("measured", 0.3, sensing=sensing).E_max == _certify("measured", 0.0, sensing=sensing).E_max


def test_the_reference_sign_keeps_the_old_charge():
    """sgn(alpha0') is not a function of alpha': no Lipschitz argument, F_max + F^ whatever the width."""
    assert (_certify("reference", 0.3, reference=MOVING).inputs["terms"]["friction_term"]
            == pytest.approx((F + F) / P, rel=1e-12))
    assert math.isfinite(_certify("reference", 0.3, reference=MOVING).E_max)
