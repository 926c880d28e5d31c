"""Scalar reduced models of the C80 steering, in the voltage form (2.12).

Both models share one form::

    P a'' + C_V a' + F sgn(a') + K sin(a)/cos^3(a) + gyro V_A a'/cos^2(a) = u      [V]

* ``paper``: Lagrange's equations applied to the kinetic energy (2.2) as if S_A
  and alpha were independent coordinates, (2.6)-(2.8) and (2.12)-(2.13). Its
  K term is the V(alpha) of (2.7) (sign as printed there: + ; Lagrange's own
  result (2.6) carries a minus, see ``paper-lagrange``). gyro = 0.
* ``paper-lagrange``: the same with (2.6)'s sign, K -> -K.
* ``nonholonomic``: the steering row of the constrained system (d'Alembert-Lagrange
  with the rolling constraints; ``wmr_mj.plant.derivation``). A virtual steering
  displacement with S_A fixed moves neither chassis nor pivot, so no
  sin/cos^3 term survives (K = 0); the chassis yaw acceleration
  V_A a'/(l1 cos^2 a) acts on the steering inertia: gyro = P / l1.

Usage::

    from wmr_mj import C80
    from wmr_mj.plant.reduced import steering_model
    model = steering_model("nonholonomic", C80)
    u = model.voltage(alpha, alpha_dot, alpha_ddot)
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Literal, cast, get_args

import numpy as np
from numpy.typing import ArrayLike

from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.params import C80Parameters, Coefficients

__all__ = ["SteeringModel", "steering_model", "ModelName", "MODEL_NAMES", "smooth_sign", "FrictionSign",
           "FRICTION_SIGNS"]

#: The sign a Coulomb compensation F^ sgn(.) uses: the measured alpha', the reference's, or none (a
#: law's choice; the certificate's friction term depends on it, so it is named here, below both).
FrictionSign = Literal["measured", "reference", "none"]
FRICTION_SIGNS: tuple[str, ...] = get_args(FrictionSign)

#: The reduced models :func:`steering_model` builds.
ModelName = Literal["paper", "paper-lagrange", "nonholonomic"]
MODEL_NAMES: tuple[str, ...] = get_args(ModelName)


def smooth_sign(x: ArrayLike, width: float) -> np.ndarray:
    """x / sqrt(x^2 + width^2); the exact sign when width == 0.

    Algebraic rather than tanh so that NumPy and ``math`` give the same bits
    (only IEEE-exact operations), which keeps batched and serial runs identical.
    """
    x = np.asarray(x, dtype=float)
    if width <= 0.0:
        return np.sign(x)
    return x / np.sqrt(x * x + width * width)


@dataclass(frozen=True)
class SteeringModel:
    """P a'' + C_V a' + F sgn(a') + K sin a/cos^3 a + gyro V_A a'/cos^2 a = u.

    Coefficients in volts (see :class:`wmr_mj.params.Coefficients`); V_A in m/s.
    """

    P: float
    C_V: float
    F: float
    K: float
    gyro: float
    V_A: float
    name: str = "custom"

    def __post_init__(self) -> None:
        for field_name in ("P", "C_V", "F", "K", "gyro", "V_A"):
            if not np.isfinite(getattr(self, field_name)):
                raise ParameterError(f"model coefficient {field_name} must be finite")
        if self.P <= 0.0:
            raise ParameterError(f"model coefficient P = {self.P} must be > 0")
        if self.F < 0.0:
            raise ParameterError(f"model coefficient F = {self.F} must be >= 0")

    @classmethod
    def from_coefficients(cls, c: Coefficients, *, V_A: float, name: str = "custom") -> SteeringModel:
        return cls(P=c.P, C_V=c.C_V, F=c.F, K=c.K, gyro=c.gyro, V_A=V_A, name=name)

    @property
    def coefficients(self) -> Coefficients:
        return Coefficients(P=self.P, C_V=self.C_V, F=self.F, K=self.K, gyro=self.gyro)

    def stiffness(self, alpha: ArrayLike) -> np.ndarray:
        """K(alpha) = K sin(alpha)/cos^3(alpha), V (2.13)."""
        alpha = np.asarray(alpha, dtype=float)
        return self.K * np.sin(alpha) / np.cos(alpha) ** 3

    def velocity_terms(
        self, alpha: ArrayLike, alpha_dot: ArrayLike, *, friction_sign: ArrayLike | None = None
    ) -> np.ndarray:
        """G(alpha') = C_V a' + F sgn(a') (2.13), plus the gyroscopic term, V.

        friction_sign: the sign (or smoothed sign) to use for the Coulomb term;
        defaults to sgn(alpha_dot).
        """
        alpha = np.asarray(alpha, dtype=float)
        alpha_dot = np.asarray(alpha_dot, dtype=float)
        sgn = np.sign(alpha_dot) if friction_sign is None else np.asarray(friction_sign, dtype=float)
        return self.C_V * alpha_dot + self.F * sgn + self.gyro * self.V_A * alpha_dot / np.cos(alpha) ** 2

    def voltage(
        self,
        alpha: ArrayLike,
        alpha_dot: ArrayLike,
        alpha_ddot: ArrayLike,
        *,
        friction_sign: ArrayLike | None = None,
    ) -> np.ndarray:
        """Inverse dynamics: the armature voltage u of (2.12) for a given motion."""
        return (
            self.P * np.asarray(alpha_ddot, dtype=float)
            + self.velocity_terms(alpha, alpha_dot, friction_sign=friction_sign)
            + self.stiffness(alpha)
        )

    def acceleration(
        self,
        alpha: ArrayLike,
        alpha_dot: ArrayLike,
        u: ArrayLike,
        *,
        friction_sign: ArrayLike | None = None,
    ) -> np.ndarray:
        """Forward dynamics: alpha'' for voltage u (sliding friction only)."""
        rest = self.velocity_terms(alpha, alpha_dot, friction_sign=friction_sign) + self.stiffness(alpha)
        return (np.asarray(u, dtype=float) - rest) / self.P

    def with_coefficients(self, **changes: float) -> SteeringModel:
        return replace(self, **cast("dict[str, Any]", changes))  # the plugin would check each float against name: str


def steering_model(name: str, params: C80Parameters) -> SteeringModel:
    """The reduced model ``name`` (one of MODEL_NAMES) evaluated on ``params``."""
    if name not in MODEL_NAMES:
        raise UnknownNameError("model", name, MODEL_NAMES)
    if name == "nonholonomic":
        c = params.coefficients("nonholonomic")
    else:
        c = params.coefficients("paper")
        if name == "paper-lagrange":
            c = Coefficients(P=c.P, C_V=c.C_V, F=c.F, K=-c.K, gyro=c.gyro)
    return SteeringModel.from_coefficients(c, V_A=params.V_A, name=name)
