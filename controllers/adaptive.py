"""An adaptive computed-torque steering law: Slotine & Li, "On the adaptive control of robot
manipulators", Int. J. Robotics Research 6(3), 1987, pp. 49-59, for the scalar steering model.

Plant (voltage form) and law, with E = alpha0 - a, s = E' + lam E (so s = a_r' - a with
a_r' = alpha0' + lam E, a_r'' = alpha0'' + lam E')::

    plant:  P a'' + C_V a' + F sigma(a') + K S(a) + Gam a'/cos^2(a) = u
    law:    u = Y theta^ + K^ S(a) + Gam^ a'/cos^2(a) + k_d s
            Y = [a_r'', a', sigma(a')],   theta^ = [P^, C_V^, F^]
    update: theta^' = Gamma Y^T s       (Gamma = diag(gamma_P, gamma_C, gamma_F) > 0)

sigma(x) = x/sqrt(x^2 + w^2) with w = ``friction_width`` (> 0: the regressor must be a function
of the measured state for the argument below). K^ and Gam^ (= gyro^ V_A^) are taken from the
model and not adapted. With theta = [P, C_V, F] and K^ = K, Gam^ = Gam, Y theta = P a_r'' + C_V a' +
F sigma(a'), and the plant minus the law gives P s' = -k_d s - Y theta~ (theta~ = theta^ - theta).
Slotine & Li's Lyapunov function V = P s^2/2 + theta~^T Gamma^-1 theta~/2 has
V' = -k_d s^2 <= 0 under the update: s is square integrable and bounded, theta^ stays bounded, and
with a bounded reference s -> 0 (Barbalat), hence E, E' -> 0. Where Y(t) is persistently exciting
(a reference with enough frequencies: two sinusoids for three parameters), theta^ -> theta.

The sign: Slotine & Li write s = q~' + Lambda q~ with q~ = q - q_d and u = Y theta^ - K_D s,
theta^' = -Gamma Y^T s; here s has the opposite sign (E = alpha0 - a), so both signs flip.

Parameter projection: P^ is kept >= ``P_floor`` and F^ >= 0 (clipped back onto that set after
each update step); with a diagonal Gamma this keeps V' <= -k_d s^2 (Ioannou & Sun,
Robust Adaptive Control, 1996, 4.4.1).

Sampling: :meth:`AdaptiveComputedTorque.step` applies the law with the current estimates and then
integrates the update over the control period (explicit Euler, Y and s held over the period, as
the voltage is). :meth:`voltage_scalar` (and :meth:`voltage`) return the law with the current
estimates without updating them: a probe, not a run (the testbed calls :meth:`step`).

No claim. The Lyapunov argument gives s in L2 and s -> 0, not a bound on sup|E| that holds from
the start of a run: the transient depends on theta~(0), Gamma and the reference through V(0),
which bounds |s| only by sqrt(2 V(0)/P) = sqrt(theta~(0)^T Gamma^-1 theta~(0)/P) with theta~(0)
unknown inside the box, and the friction at rest (stiction: f anywhere in [-F, F], not
F sigma(a')) and the unmodelled K, gyro mismatch enter as a disturbance that the pure gradient
update does not tolerate (parameter drift) without a robust modification (sigma- or
e1-modification, dead zone) whose bound would then be the claim. :meth:`claim` returns None,
so a run of this law is judged by its requirements only.

Usage::

    from controllers.adaptive import AdaptiveComputedTorque
    law = AdaptiveComputedTorque(model, lam=5.0, kd=10.0, gamma=(1.0, 20.0, 20.0))
    law.reset(control_period=1e-3)
    u = law.step(t, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)
    law.estimates            # {'P': ..., 'C_V': ..., 'F': ...}
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from controllers.base import BuildContext, SteeringController
from wmr_mj.errors import ParameterError
from wmr_mj.plant.reduced import SteeringModel

__all__ = ["AdaptiveComputedTorque"]


def _number(name: str, value: Any, *, minimum: float = 0.0, strict: bool = True) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"adaptive-computed-torque {name} = {value!r} is not accepted: a finite number") from None
    if not math.isfinite(v) or v < minimum or (strict and v == minimum):
        raise ParameterError(f"adaptive-computed-torque {name} = {value!r} is not accepted: a finite number "
                             f"{'>' if strict else '>='} {minimum:g}")
    return v


class AdaptiveComputedTorque(SteeringController):
    """u = P^ a_r'' + C_V^ a' + F^ sigma(a') + K^ S(a) + Gam^ a'/cos^2(a) + k_d s, with
    [P^, C_V^, F^]' = Gamma Y^T s (module docstring).

    Parameters: lam [1/s]; kd [V s/rad] (k_d, the gain on s); gamma: Gamma's diagonal
    (gamma_P, gamma_C, gamma_F; each in units of theta_i^2/(V s): theta_i' = gamma_i Y_i s), three
    numbers or one for all;
    friction_width w [rad/s] of sigma (> 0); P_floor [V s^2/rad], the projection's lower bound on P^.
    Initial estimates P^, C_V^, F^ from ``model`` (the run's estimate).

    Defaults (measured on the default path, 20 s through the MuJoCo plant, nonholonomic estimate):
    sup|E| = 0.019 rad, the estimates end at P^ 0.395, C_V^ 4.77, F^ 1.59 (from 0.385, 4.77, 1.52).
    With much larger gains on that plant (gamma = (20, 200, 100)) P^ drifts to 0.60: stiction and
    the unadapted terms act as a disturbance on the gradient update (no claim, module docstring).
    """

    name = "adaptive-computed-torque"
    # its K^ and gyro^ are not adapted: the non-holonomic model's (K^ = 0), the plant's own reduced model
    default_model = "nonholonomic"
    model: SteeringModel

    def __init__(self, model: SteeringModel, *, lam: float = 5.0, kd: float = 10.0,
                 gamma: float | Sequence[float] = (1.0, 20.0, 20.0), friction_width: float = 0.02,
                 P_floor: float | None = None) -> None:
        if not isinstance(model, SteeringModel):
            raise ParameterError(f"adaptive-computed-torque needs a SteeringModel, got {type(model).__name__}")
        self.model = model
        self.lam = _number("lam", lam)
        self.kd = _number("kd", kd)
        g = [gamma] * 3 if isinstance(gamma, (int, float)) else list(gamma)
        if len(g) != 3:
            raise ParameterError(f"adaptive-computed-torque gamma = {gamma!r}: one number or three (P, C_V, F)")
        self.gamma = tuple(_number("gamma", x, strict=False) for x in g)
        self.friction_width = _number("friction_width", friction_width)
        self.P_floor = _number("P_floor", 0.1 * model.P if P_floor is None else P_floor)
        self._K = model.K
        self._gyro_V = model.gyro * model.V_A
        self.period = math.nan
        self._init = (model.P, model.C_V, max(model.F, 0.0))
        self.theta = list(self._init)

    @classmethod
    def from_context(cls, context: BuildContext, **params: Any) -> AdaptiveComputedTorque:
        """The law on the run's model (``context.model``: the initial P^, C_V^, F^ and the fixed K^, gyro^)."""
        return cls(context.model, **params)

    @property
    def estimates(self) -> dict[str, float]:
        """The current P^ [V s^2/rad], C_V^ [V s/rad], F^ [V]."""
        return {"P": self.theta[0], "C_V": self.theta[1], "F": self.theta[2]}

    def reset(self, *, control_period: float) -> None:
        """The estimates back to the model's; ``control_period`` [s] is the update's step."""
        self.period = _number("control_period", control_period)
        self.theta = list(self._init)

    def _terms(self, alpha: float, alpha_dot: float, alpha0: float, alpha0_dot: float,
               alpha0_ddot: float) -> tuple[float, tuple[float, float, float], float]:
        """(u, Y, s) with the current estimates."""
        E, Ed = alpha0 - alpha, alpha0_dot - alpha_dot
        s = Ed + self.lam * E
        w = self.friction_width
        Y = (alpha0_ddot + self.lam * Ed, alpha_dot, alpha_dot / math.sqrt(alpha_dot * alpha_dot + w * w))
        th = self.theta
        u = th[0] * Y[0] + th[1] * Y[1] + th[2] * Y[2] + self.kd * s
        c = math.cos(alpha)
        if self._K:
            u += self._K * math.sin(alpha) / (c * c * c)
        if self._gyro_V:
            u += self._gyro_V * alpha_dot / (c * c)
        return u, Y, s

    def voltage_scalar(self, alpha: float, alpha_dot: float, alpha0: float, alpha0_dot: float,
                       alpha0_ddot: float) -> float:
        """The law with the current estimates, which it does not update (a probe; runs call :meth:`step`)."""
        return self._terms(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)[0]

    def step(self, t: float, alpha: float, alpha_dot: float, alpha0: float, alpha0_dot: float,
             alpha0_ddot: float) -> float:
        """The voltage with the current estimates; then theta^ += T Gamma Y^T s (projected)."""
        if not math.isfinite(self.period):
            raise ParameterError("adaptive-computed-torque: call reset(control_period=...) before step()")
        u, Y, s = self._terms(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)
        if math.isfinite(s):
            th = self.theta
            for i in range(3):
                th[i] += self.period * self.gamma[i] * Y[i] * s
            th[0] = max(th[0], self.P_floor)
            th[2] = max(th[2], 0.0)
        return u

    def describe(self) -> dict:
        """Name, gains and the initial and current (at the end of a run: final) estimates."""
        init = dict(zip(("P", "C_V", "F"), self._init))
        return {"controller": self.name, "model": self.model.name, "lam": self.lam, "kd": self.kd,
                "gamma": list(self.gamma), "friction_width": self.friction_width, "P_floor": self.P_floor,
                "initial_estimates": init, "final_estimates": self.estimates,
                "fixed": {"K": self._K, "gyro_V": self._gyro_V}}
