"""Identification of the steering dynamics of the driving MuJoCo plant.

The cart drives at V_A while the steering motor gets a rich voltage: a PD
servo tracking a random multisine angle (seeded) plus a voltage multisine. Each
physics step gives alpha, alpha', alpha'' (MuJoCo's own qacc at that step), the
applied voltage u and the measured speed of A. Least squares then fits::

    u = P alpha'' + C_V alpha' + F sgn(alpha') + K sin(alpha)/cos^3(alpha)
        + gyro V_A alpha'/cos^2(alpha)                                  (2.12) + gyro

on samples where the joint slides (|alpha'| above a threshold: at rest the
Coulomb friction is a constraint force, not F sgn(alpha')) and is away from its
stops. ``P``, ``C_V``, ``F`` are the paper's; ``K`` is the coefficient the
paper's (2.7) predicts and ``gyro`` the one the non-holonomic model predicts.

Usage::

    from wmr_mj import C80
    from wmr_mj.plant.identify import identify_plant
    result = identify_plant(C80, duration=60.0, seed=0)
    print(result.identified.K, result.predicted["paper"].K)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from wmr_mj.errors import ParameterError
from wmr_mj.params import C80, COEFFICIENT_NAMES, M1_NOMINAL, C80Parameters, Coefficients
from wmr_mj.plant.mjcf import Plant

__all__ = ["IdentificationResult", "fit_steering_model", "excite_plant", "identify_plant"]


def _regressors(alpha, alpha_dot, alpha_ddot, speed) -> np.ndarray:
    c = np.cos(alpha)
    return np.column_stack([alpha_ddot, alpha_dot, np.sign(alpha_dot), np.sin(alpha) / c**3, speed * alpha_dot / c**2])


def fit_steering_model(
    alpha: np.ndarray,
    alpha_dot: np.ndarray,
    alpha_ddot: np.ndarray,
    voltage: np.ndarray,
    speed: np.ndarray,
    *,
    min_rate: float = 0.02,
    max_angle: float | None = None,
) -> tuple[Coefficients, dict]:
    """Least-squares fit of (P, C_V, F, K, gyro) to samples of the steering motion.

    Samples with |alpha'| < min_rate (rad/s) or |alpha| > max_angle are left out.
    Returns the coefficients and fit diagnostics (samples used, residual RMS in V,
    regressor condition number, standard errors).
    """
    arrays = [np.asarray(a, dtype=float).ravel() for a in (alpha, alpha_dot, alpha_ddot, voltage, speed)]
    n = arrays[0].size
    if any(a.size != n for a in arrays):
        raise ParameterError("identification arrays must have equal lengths")
    alpha, alpha_dot, alpha_ddot, voltage, speed = arrays
    keep = np.abs(alpha_dot) >= min_rate
    if max_angle is not None:
        keep &= np.abs(alpha) <= max_angle
    keep &= np.all(np.isfinite(np.column_stack(arrays)), axis=1)
    if keep.sum() < 20:
        raise ParameterError(f"only {int(keep.sum())} usable samples (|alpha'| >= {min_rate} rad/s); excite longer")
    Phi = _regressors(alpha[keep], alpha_dot[keep], alpha_ddot[keep], speed[keep])
    y = voltage[keep]
    # scale columns so the condition number means something
    scale = np.linalg.norm(Phi, axis=0)
    scale[scale == 0] = 1.0
    theta_s, *_ = np.linalg.lstsq(Phi / scale, y, rcond=None)
    theta = theta_s / scale
    resid = y - Phi @ theta
    dof = max(len(y) - Phi.shape[1], 1)
    sigma2 = float(resid @ resid) / dof
    cov = sigma2 * np.linalg.pinv(Phi.T @ Phi)
    diagnostics = {
        "samples": int(keep.sum()),
        "samples_total": int(n),
        "residual_rms_V": float(math.sqrt(float(resid @ resid) / len(y))),
        "condition": float(np.linalg.cond(Phi / scale)),
        "std_error": dict(zip(COEFFICIENT_NAMES, np.sqrt(np.maximum(np.diag(cov), 0.0)).tolist())),
    }
    return Coefficients(*theta.tolist()), diagnostics


@dataclass
class Excitation:
    """Recorded excitation of the plant (one row per physics step)."""

    t: np.ndarray
    alpha: np.ndarray
    alpha_dot: np.ndarray
    alpha_ddot: np.ndarray
    voltage: np.ndarray
    speed: np.ndarray
    warnings: int = 0


def _multisine(rng: np.random.Generator, t: np.ndarray, freqs: np.ndarray, amplitude: float) -> np.ndarray:
    phases = rng.uniform(0, 2 * np.pi, size=freqs.size)
    weights = rng.uniform(0.5, 1.0, size=freqs.size) / np.sqrt(freqs.size)
    s = (weights[:, None] * np.sin(2 * np.pi * freqs[:, None] * t[None, :] + phases[:, None])).sum(axis=0)
    return amplitude * s / max(np.max(np.abs(s)), 1e-12)


def excite_plant(params: C80Parameters = C80, *, duration: float = 60.0, seed: int = 0,
                 angle_amplitude: float = 0.75, dither_amplitude: float = 4.0,
                 steering_friction: str = "stiction", tyre_contact: str = "stiff") -> Excitation:
    """Drive the MuJoCo plant at V_A and excite its steering; record every step.

    steering_friction, tyre_contact: the plant's friction and contact laws (``wmr_mj.plant.mjcf``).
    """
    if not math.isfinite(duration) or duration <= 0:
        raise ParameterError(f"duration = {duration!r} s must be finite and > 0")
    plant = Plant(params, steering_friction=steering_friction, tyre_contact=tyre_contact)
    m, d = plant.model, plant.data
    dt = m.opt.timestep
    n = int(round(duration / dt))
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    target = _multisine(rng, t, np.linspace(0.03, 0.6, 12), min(angle_amplitude, 0.9 * params.steering_range))
    ramp = np.minimum(t / 2.0, 1.0)  # start from straight running
    target *= ramp
    target_dot = np.gradient(target, dt)
    dither = _multisine(rng, t, np.linspace(0.2, 8.0, 25), dither_amplitude) * ramp
    coeffs = params.coefficients("paper")
    kp_v, kd_v = 40.0 * coeffs.P, 10.0 * coeffs.P  # a gentle PD in volts
    out = {k: np.empty(n) for k in ("alpha", "alpha_dot", "alpha_ddot", "voltage", "speed")}
    qa, dv, act = plant.steer_qpos, plant.steer_dof, plant.steer_actuator
    heading_axis = np.empty(3)
    limit = params.voltage_limit
    for k in range(n):
        a, ad = d.qpos[qa], d.qvel[dv]
        u = kp_v * (target[k] - a) + kd_v * (target_dot[k] - ad) + coeffs.C_V * target_dot[k] + dither[k]
        u = min(max(u, -limit), limit)
        d.ctrl[act] = u
        mujoco.mj_step(m, d)
        # after mj_step, qacc and the kinematics belong to the state the step started from
        out["alpha"][k] = a
        out["alpha_dot"][k] = ad
        out["alpha_ddot"][k] = d.qacc[dv]
        out["voltage"][k] = u
        heading_axis[:] = d.xmat[plant.chassis_body].reshape(3, 3)[:, 0]
        vel = d.sensor("A_vel").data
        out["speed"][k] = float(vel @ heading_axis)
    warnings = sum(w.number for w in d.warning)
    return Excitation(t=t, warnings=warnings, **out)


@dataclass
class IdentificationResult:
    """Identified coefficients beside both reduced models' predictions."""

    identified: Coefficients
    predicted: dict[str, Coefficients]
    diagnostics: dict = field(default_factory=dict)
    m1: float = M1_NOMINAL
    duration: float = 60.0
    seed: int = 0

    def relative_difference(self, model: str) -> dict[str, float | None]:
        """(identified - predicted) / |predicted|; None where the prediction is 0."""
        pred = self.predicted[model].to_dict()
        ident = self.identified.to_dict()
        return {k: (None if pred[k] == 0 else (ident[k] - pred[k]) / abs(pred[k])) for k in COEFFICIENT_NAMES}

    def to_dict(self) -> dict:
        return {
            **self.identified.to_dict(),
            "identified": self.identified.to_dict(),
            "predicted": {name: c.to_dict() for name, c in self.predicted.items()},
            "relative_difference": {name: self.relative_difference(name) for name in self.predicted},
            "diagnostics": self.diagnostics,
            "m1": self.m1,
            "duration": self.duration,
            "seed": self.seed,
        }

    def verdict(self) -> str:
        """A plain statement of what the plant shows about K and the gyroscopic term."""
        K_id, K_paper = self.identified.K, self.predicted["paper"].K
        se = self.diagnostics.get("std_error", {})
        g_id, g_nh = self.identified.gyro, self.predicted["nonholonomic"].gyro
        return (
            f"K (sin/cos^3 coefficient): the plant shows {K_id:.4g} V (+-{se.get('K', float('nan')):.2g}), "
            f"{100 * K_id / K_paper:.2g}% of the paper's (2.7) prediction {K_paper:.4g} V; "
            f"the non-holonomic model predicts 0. "
            f"gyro (V_A alpha'/cos^2 coefficient): the plant shows {g_id:.4g} V s/m, "
            f"{100 * g_id / g_nh:.1f}% of the non-holonomic prediction {g_nh:.4g}; the paper's model has none."
        )


def identify_plant(params: C80Parameters = C80, *, duration: float = 60.0, seed: int = 0,
                   min_rate: float = 0.02, steering_friction: str = "stiction",
                   tyre_contact: str = "stiff") -> IdentificationResult:
    """Excite the MuJoCo plant for ``duration`` s and fit the steering model.

    steering_friction, tyre_contact: the plant's friction and contact laws (``wmr_mj.plant.mjcf``).
    """
    exc = excite_plant(params, duration=duration, seed=seed, steering_friction=steering_friction,
                       tyre_contact=tyre_contact)
    coeffs, diag = fit_steering_model(exc.alpha, exc.alpha_dot, exc.alpha_ddot, exc.voltage, exc.speed,
                                      min_rate=min_rate, max_angle=params.steering_range - 0.02)
    diag["mujoco_warnings"] = int(exc.warnings)
    predicted = {"paper": params.coefficients("paper"), "nonholonomic": params.coefficients("nonholonomic")}
    return IdentificationResult(identified=coeffs, predicted=predicted, diagnostics=diag, m1=params.m1,
                                duration=duration, seed=seed)
