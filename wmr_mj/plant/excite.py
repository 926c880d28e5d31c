"""An excitation plan for a real cart (``wmr-mj excite``): what to play so that identification can see the steering.

The plan is a target angle (a multisine within 60 % of the stops, ramped in over 2 s) for the cart's own
servo, plus a voltage dither (a multisine of 0.3-6 Hz, a quarter of the supply) added to its output: the
closed-loop experiment the identification tests record (tests/data/identify_dithered_pd.py). The dither makes
the inertia and the delay visible (a smooth tracking run hides them: P alpha'' is a few per cent of the voltage
there); the target sweeps the friction and the back-EMF over the range of rates the cart uses.

:func:`preview` plays the plan on the reduced model of the cart file (a PD of the cart's own coefficients,
the encoder and delay of its default sensing) and identifies from the result: the intervals identification
would give, before the experiment.

Usage::

    from wmr_mj.plant.excite import excitation_plan, preview
    plan = excitation_plan(params, duration=60.0, seed=0)   # plan.t, plan.alpha0, plan.dither
    fit = preview(plan, params, sensing)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wmr_mj.errors import ParameterError
from wmr_mj.hardware.sensing import Sensing
from wmr_mj.params import C80Parameters
from wmr_mj.plant.output_error import SteeringFit, fit_recordings
from wmr_mj.plant.recordings import Recording

__all__ = ["ExcitationPlan", "excitation_plan", "preview", "plan_csv"]


@dataclass(frozen=True)
class ExcitationPlan:
    """t (s), the target angle alpha0 (rad) and the voltage dither (V) to add to the servo's output."""

    t: np.ndarray
    alpha0: np.ndarray
    dither: np.ndarray


def _multisine(rng: np.random.Generator, t: np.ndarray, freqs: np.ndarray) -> np.ndarray:
    phases = rng.uniform(0.0, 2 * np.pi, freqs.size)
    s = np.sin(2 * np.pi * freqs[:, None] * t[None, :] + phases[:, None]).sum(axis=0)
    return s / max(float(np.max(np.abs(s))), 1e-12)


def excitation_plan(params: C80Parameters, *, duration: float, seed: int = 0, period: float = 0.001) -> ExcitationPlan:
    """The plan for ``duration`` s at the control ``period`` (s): within 60 % of the stops and 25 % of the supply."""
    if not (math.isfinite(duration) and duration >= 4.0):
        raise ParameterError(f"duration = {duration!r} s; accepted: at least 4 s (a 2 s ramp and two 1 s segments)")
    rng = np.random.default_rng(seed)
    t = np.arange(int(round(duration / period))) * period
    ramp = np.minimum(t / 2.0, 1.0)
    alpha0 = 0.6 * params.steering_range * ramp * _multisine(rng, t, np.linspace(0.05, 0.5, 6))
    dither = 0.25 * params.voltage_limit * ramp * _multisine(rng, t, np.linspace(0.3, 6.0, 15))
    return ExcitationPlan(t=t, alpha0=alpha0, dither=dither)


def plan_csv(plan: ExcitationPlan) -> str:
    """The plan as CSV: t_s,alpha0_rad,u_dither_V."""
    rows = ["t_s,alpha0_rad,u_dither_V"]
    rows.extend(f"{t:.6f},{a!r},{u!r}" for t, a, u in zip(plan.t.tolist(), plan.alpha0.tolist(), plan.dither.tolist()))
    return "\n".join(rows) + "\n"


def preview(plan: ExcitationPlan, params: C80Parameters, sensing: Sensing, *, seed: int = 0) -> SteeringFit:
    """Play the plan on the cart's reduced model under a PD (K_P = 400, K_D = 40 on the cart's P) with the
    sensing's encoder and delay, and identify from it: the intervals the experiment would give."""
    c = params.coefficients("nonholonomic")
    dt = float(plan.t[1] - plan.t[0])
    delay = int(round(sensing.delay / dt))
    step = 0.0 if sensing.encoder_ticks is None else 2 * math.pi / sensing.encoder_ticks
    n = plan.t.size
    alpha, rate = 0.0, 0.0
    true = np.zeros(n)
    u_rec = np.zeros(n)
    for k in range(n):
        true[k] = alpha
        read = true[max(k - delay, 0)]
        read = round(read / step) * step if step else read
        prev = true[max(k - delay - 1, 0)]
        prev = round(prev / step) * step if step else prev
        u = c.P * (400.0 * (plan.alpha0[k] - read) - 40.0 * (read - prev) / dt) + plan.dither[k]
        u = min(max(u, -params.voltage_limit), params.voltage_limit)
        u_rec[k] = u
        denom = c.P + dt * (c.C_V + c.gyro * params.V_A)
        wt = c.P * rate + dt * u
        rate = math.copysign(max(abs(wt) - dt * c.F, 0.0), wt) / denom
        alpha += dt * rate
    measured = np.array([true[max(k - delay, 0)] for k in range(n)])
    if step:
        measured = np.rint(measured / step) * step
    rec = Recording(name="preview", sha256="", t=plan.t, voltage=u_rec, alpha=measured)
    return fit_recordings([rec], params, seed=seed, draws=500)
