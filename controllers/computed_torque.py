"""Computed-torque steering control (3.2)-(3.3) and a PD baseline.

The law of the paper, with the model-based part taken from a reduced model
``model`` (:class:`wmr_mj.plant.reduced.SteeringModel`, the estimate P^, K^, G^)::

    u = P^ (alpha0'' + K_D E' + K_P E) + K^(alpha) + G^(alpha', alpha)        (3.2)-(3.3)
    E = alpha0 - alpha,   G^ = C_V^ alpha' + F^ s + gyro^ V_A alpha'/cos^2 alpha

with s the Coulomb sign. The paper writes s = sgn(alpha') (2.5); the joint
holds still under any torque within +-F (a dead band the analysis does not
see), so the sign is a design choice exposed here: ``friction_sign`` =
'measured' (sgn alpha', the paper), 'reference' (sgn alpha0') or 'none', each
optionally smoothed as x / sqrt(x^2 + friction_width^2).

Gains: K_P, K_D directly, or ``gains_from_omega_r`` (3.6): K_P = omega_r^2/4,
K_D = omega_r (critical damping).

Usage::

    from wmr_mj import C80
    from controllers import ComputedTorque, model_from_source
    ctrl = ComputedTorque(model_from_source("paper", params=C80), kp=6.0, kd=9.0)
    u = ctrl.voltage(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Literal, get_args

import numpy as np

from controllers.base import SteeringController
from controllers.sampled_claim import with_sampled_data
from wmr_mj.analysis.certificate import Certificate, Compensation, Estimate, Gains, certify
from wmr_mj.analysis.claim import ClaimContext
from wmr_mj.analysis.robustness import gains_from_omega_r
from wmr_mj.analysis.sampled_certificate import sampled_certificate
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.params import C80, COEFFICIENT_NAMES, PAPER_KD, PAPER_KP, C80Parameters
from wmr_mj.plant.reduced import (
    FRICTION_SIGNS,
    MODEL_NAMES,
    FrictionSign,
    ModelName,
    SteeringModel,
    smooth_sign,
    steering_model,
)

__all__ = [
    "ComputedTorque",
    "PDController",
    "gains_from_omega_r",
    "model_from_source",
    "ModelSource",
    "MODEL_SOURCES",
    "FrictionSign",
    "FRICTION_SIGNS",
    "CONTROLLER_NAMES",
    "make_controller",
    "SECTION_4",
]

#: Where the controller's model comes from: a reduced model on the parameters, the identified
#: coefficients, or explicit ones.
ModelSource = Literal[ModelName, "identified", "explicit"]
MODEL_SOURCES: tuple[str, ...] = get_args(ModelSource)
CONTROLLER_NAMES = ("computed-torque", "pd")
#: the name of section 4's certificate in a run's ``inputs['certificate']`` (beside 'sampled-data')
SECTION_4 = "section-4"


def _check_gain(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value) or value <= 0:
        raise ParameterError(f"gain {name} = {value!r} is not accepted; gains must be finite and > 0")
    return value


def _read_identified(identified: str | Path | Mapping) -> Mapping:
    if isinstance(identified, Mapping):
        return identified
    path = Path(identified)
    if not path.is_file():
        raise ParameterError(f"identified-model file {str(path)!r} does not exist; "
                             "write one with: wmr-mj identify --out PATH")
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError):
        raise ParameterError(f"identified-model file {str(path)!r} is not JSON from wmr-mj identify") from None


def model_from_source(
    source: str,
    *,
    params: C80Parameters = C80,
    identified: str | Path | Mapping | None = None,
    coefficients: Mapping[str, float] | None = None,
) -> SteeringModel:
    """The controller's model (the estimate) from a named source.

    'paper', 'paper-lagrange', 'nonholonomic': evaluated on ``params`` (the
    estimate's parameter set). 'identified': the ``identified`` mapping or JSON
    file written by ``wmr-mj identify`` (keys P, C_V, F, K, gyro). 'explicit':
    ``coefficients`` given as numbers (missing ones are 0, P required).
    """
    if source not in MODEL_SOURCES:
        raise UnknownNameError("model source", source, MODEL_SOURCES)
    if source in MODEL_NAMES:
        return steering_model(source, params)
    if source == "identified":
        if identified is None:
            raise ParameterError("model source 'identified' needs an identification (wmr-mj identify --out PATH)")
        data = _read_identified(identified)
        values = data.get("identified", data)
    else:
        if coefficients is None:
            raise ParameterError("model source 'explicit' needs coefficients P, C_V, F, K, gyro")
        values = coefficients
    unknown = set(values) - set(COEFFICIENT_NAMES) - {"V_A"}
    if source == "explicit" and unknown:
        raise UnknownNameError("coefficient", sorted(unknown)[0], COEFFICIENT_NAMES)
    if "P" not in values:
        raise ParameterError(f"model source {source!r}: coefficient P is required")
    try:
        coeffs = {k: float(values.get(k, 0.0)) for k in COEFFICIENT_NAMES}
    except (TypeError, ValueError):
        raise ParameterError(f"model source {source!r}: coefficients must be numbers") from None
    return SteeringModel(**coeffs, V_A=float(values.get("V_A", params.V_A)), name=source)


class ComputedTorque(SteeringController):
    """u = P^ (alpha0'' + K_D E' + K_P E) + K^(alpha) + G^(alpha'), (3.2)-(3.3)."""

    name = "computed-torque"
    model: SteeringModel

    def __init__(
        self,
        model: SteeringModel,
        *,
        kp: float = PAPER_KP,
        kd: float = PAPER_KD,
        friction_sign: str = "measured",
        friction_width: float = 0.0,
    ):
        if friction_sign not in FRICTION_SIGNS:
            raise UnknownNameError("friction sign", friction_sign, FRICTION_SIGNS)
        if not math.isfinite(friction_width) or friction_width < 0:
            raise ParameterError(f"friction_width = {friction_width!r} must be finite and >= 0 (rad/s)")
        self.model = model
        self.kp = _check_gain("K_P", kp)
        self.kd = _check_gain("K_D", kd)
        self.friction_sign = friction_sign
        self.friction_width = float(friction_width)
        m = model
        self._P, self._C_V, self._F, self._K = m.P, m.C_V, m.F, m.K
        self._gyro_V = m.gyro * m.V_A
        if friction_sign == "none":
            self._F = 0.0

    def law_constants(self) -> dict[str, float | str]:
        """The numbers the law uses: P^, K_P, K_D, C_V^, F^ (0 with friction_sign 'none'), K^,
        gyro^ V_A (V s/rad), friction_width (rad/s) and friction_sign (what wmr_mj.sim.compiled_law reads)."""
        return {"P": self._P, "K_P": self.kp, "K_D": self.kd, "C_V": self._C_V, "F": self._F, "K": self._K,
                "gyro_V": self._gyro_V, "friction_width": self.friction_width, "friction_sign": self.friction_sign}

    def _sign_source(self, alpha_dot, alpha0_dot):
        return alpha0_dot if self.friction_sign == "reference" else alpha_dot

    # The three forms of the law below (arrays, floats, a batch writing into buffers) do the
    # same IEEE operations in the same order, so they give the same bits; a term whose
    # coefficient is exactly 0 (K^ of the non-holonomic model, gyro^ of the paper's, F^ with
    # friction_sign='none') is left out of all three rather than added as 0.

    def voltage(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot) -> np.ndarray:
        alpha = np.asarray(alpha, dtype=float)
        alpha_dot = np.asarray(alpha_dot, dtype=float)
        servo = (np.asarray(alpha0_ddot, dtype=float) + self.kd * (np.asarray(alpha0_dot, dtype=float) - alpha_dot)
                 + self.kp * (np.asarray(alpha0, dtype=float) - alpha))
        c = np.cos(alpha)
        u = self._P * servo
        if self._K:
            u = u + self._K * np.sin(alpha) / (c * c * c)
        if self._C_V:
            u = u + self._C_V * alpha_dot
        if self._F:
            u = u + self._F * smooth_sign(self._sign_source(alpha_dot, np.asarray(alpha0_dot, dtype=float)),
                                          self.friction_width)
        if self._gyro_V:
            u = u + self._gyro_V * alpha_dot / (c * c)
        return u

    def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot) -> float:
        servo = alpha0_ddot + self.kd * (alpha0_dot - alpha_dot) + self.kp * (alpha0 - alpha)
        c = math.cos(alpha)
        u = self._P * servo
        if self._K:
            u = u + self._K * math.sin(alpha) / (c * c * c)
        if self._C_V:
            u = u + self._C_V * alpha_dot
        if self._F:
            x = alpha0_dot if self.friction_sign == "reference" else alpha_dot
            if self.friction_width > 0.0:
                s = x / math.sqrt(x * x + self.friction_width * self.friction_width)
            else:
                s = 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)
            u = u + self._F * s
        if self._gyro_V:
            u = u + self._gyro_V * alpha_dot / (c * c)
        return u

    def batch_law(self, n: int):
        """(3.2)-(3.3) for n simulations with NumPy ``out=`` buffers: no allocation per call.

        About 20 small ufunc calls per control step; in a batch their per-call cost, not the
        arithmetic, is what the law adds to the physics (see bench/bench_sweep.py).
        """
        P, K, C_V, F, gyro_V = self._P, self._K, self._C_V, self._F, self._gyro_V
        width, reference_sign = self.friction_width, self.friction_sign == "reference"
        width2 = width * width
        # gains as arrays: an array-array ufunc call costs less than one with a Python float
        kd, kp, Pv = np.full(n, self.kd), np.full(n, self.kp), np.full(n, P)
        Kv, C_Vv, Fv, gyro_Vv = np.full(n, K), np.full(n, C_V), np.full(n, F), np.full(n, gyro_V)
        c, t, t2 = np.empty(n), np.empty(n), np.empty(n)
        sub, add, mul, div, cos = np.subtract, np.add, np.multiply, np.divide, np.cos

        def law(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot, E, E_dot, u):
            sub(alpha0, alpha, out=E)
            sub(alpha0_dot, alpha_dot, out=E_dot)
            mul(kd, E_dot, out=u)
            add(u, alpha0_ddot, out=u)  # alpha0'' + K_D E' (addition commutes exactly)
            mul(kp, E, out=t)
            add(u, t, out=u)  # the servo of (3.2)
            mul(Pv, u, out=u)
            if K:
                cos(alpha, out=c)
                np.sin(alpha, out=t)
                mul(Kv, t, out=t)
                mul(c, c, out=t2)
                mul(t2, c, out=t2)
                div(t, t2, out=t)
                add(u, t, out=u)
            if C_V:
                mul(C_Vv, alpha_dot, out=t)
                add(u, t, out=u)
            if F:
                if reference_sign:  # one sign for the whole batch
                    x = float(alpha0_dot)
                    s = (x / math.sqrt(x * x + width2) if width > 0.0
                         else (1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)))
                    add(u, F * s, out=u)
                else:
                    if width > 0.0:
                        mul(alpha_dot, alpha_dot, out=t2)
                        add(t2, width2, out=t2)
                        np.sqrt(t2, out=t2)
                        div(alpha_dot, t2, out=t)
                    else:
                        np.sign(alpha_dot, out=t)
                    mul(Fv, t, out=t)
                    add(u, t, out=u)
            if gyro_V:
                if not K:
                    cos(alpha, out=c)
                mul(gyro_Vv, alpha_dot, out=t)
                mul(c, c, out=t2)
                div(t, t2, out=t)
                add(u, t, out=u)
            return u

        return law

    def label(self) -> str:
        return f"{self.model.name} model, K_P = {self.kp:g}, K_D = {self.kd:g}"

    def paper_estimate(self) -> dict[str, float]:
        """The coefficients the paper's analysis takes as this law's estimate: P^, C_V^, F^ (0 with
        friction_sign 'none'), K^."""
        c = self.model.coefficients.to_dict()
        if self.friction_sign == "none":
            c["F"] = 0.0
        return {k: c[k] for k in ("P", "C_V", "F", "K")}

    def claim(self, context: ClaimContext) -> Certificate:
        """The section-4 analysis redone for this law on the run's plant box
        (:func:`wmr_mj.analysis.certificate.certify`), named 'section-4', beside the sampled-data certificate of
        its loop on the cart's parts (``context.wants_sampled_data``, the ideal cart included;
        :func:`wmr_mj.analysis.sampled_certificate.sampled_certificate`), which is taken: the law runs sampled
        (:func:`controllers.sampled_claim.with_sampled_data`)."""
        c = self.model.coefficients
        sign = self.friction_sign
        estimate = Estimate(P=c.P, C_V=c.C_V, F=0.0 if sign == "none" else c.F, K=c.K, gyro=c.gyro,
                            V_A=self.model.V_A)
        compensation = Compensation(friction_sign=sign, friction_width=self.friction_width)
        own = _section4(context, estimate, compensation, kp=self.kp, kd=self.kd)
        gains = Gains(kp=self.kp, kd=self.kd)
        return with_sampled_data(own, SECTION_4, context, lambda cart: sampled_certificate(
            plant=context.plant, estimate=estimate, gains=gains, reference=context.reference, limits=context.limits,
            compensation=compensation, control_period=context.control_period, cart=cart,
            initial_error=context.initial_error, stated=context.stated))

    def describe(self) -> dict:
        return {"controller": self.name, "model": self.model.name, "kp": self.kp, "kd": self.kd,
                "friction_sign": self.friction_sign, "friction_width": self.friction_width,
                "estimate": self.model.coefficients.to_dict()}


class PDController(SteeringController):
    """PD baseline without the model-based part: u = P^ (K_D E' + K_P E).

    P^ scales the servo into volts so that the gains mean the same as in the
    computed-torque law.
    """

    name = "pd"
    model: SteeringModel

    def __init__(self, model: SteeringModel, *, kp: float = PAPER_KP, kd: float = PAPER_KD):
        self.model = model
        self.kp = _check_gain("K_P", kp)
        self.kd = _check_gain("K_D", kd)
        self._P = model.P

    def voltage(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot) -> np.ndarray:
        return self._P * (self.kd * (np.asarray(alpha0_dot, dtype=float) - np.asarray(alpha_dot, dtype=float))
                          + self.kp * (np.asarray(alpha0, dtype=float) - np.asarray(alpha, dtype=float)))

    def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot) -> float:
        return self._P * (self.kd * (alpha0_dot - alpha_dot) + self.kp * (alpha0 - alpha))

    def law_constants(self) -> dict[str, float]:
        """The numbers the law uses: P^, K_P, K_D."""
        return {"P": self._P, "K_P": self.kp, "K_D": self.kd}

    def batch_law(self, n: int):
        """The PD law for n simulations with NumPy ``out=`` buffers: no allocation per call."""
        kd, kp, Pv, t = np.full(n, self.kd), np.full(n, self.kp), np.full(n, self._P), np.empty(n)

        def law(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot, E, E_dot, u):
            np.subtract(alpha0, alpha, out=E)
            np.subtract(alpha0_dot, alpha_dot, out=E_dot)
            np.multiply(kd, E_dot, out=u)
            np.multiply(kp, E, out=t)
            np.add(u, t, out=u)
            np.multiply(Pv, u, out=u)
            return u

        return law

    def label(self) -> str:
        return f"PD, {self.model.name} model, K_P = {self.kp:g}, K_D = {self.kd:g}"

    def paper_estimate(self) -> dict[str, float]:
        """A PD law has no model-based part but P^ (its gain scale)."""
        return {"P": self.model.coefficients.P, "C_V": 0.0, "F": 0.0, "K": 0.0}

    def claim(self, context: ClaimContext) -> Certificate:
        """The section-4 analysis for a law without feedforward or compensation, named 'section-4', beside the
        sampled-data certificate of its loop on the cart's parts, which is taken
        (:func:`controllers.sampled_claim.with_sampled_data`)."""
        c = self.model.coefficients
        estimate = Estimate(P=c.P, C_V=0.0, F=0.0, K=0.0, gyro=0.0, V_A=self.model.V_A)
        compensation = Compensation(friction_sign="none", friction_width=0.0, feedforward=False)
        own = _section4(context, estimate, compensation, kp=self.kp, kd=self.kd)
        return with_sampled_data(own, SECTION_4, context, lambda cart: sampled_certificate(
            plant=context.plant, estimate=estimate, gains=Gains(kp=self.kp, kd=self.kd), reference=context.reference,
            limits=context.limits, compensation=compensation, control_period=context.control_period, cart=cart,
            initial_error=context.initial_error, stated=context.stated))

    def describe(self) -> dict:
        return {"controller": self.name, "model": self.model.name, "kp": self.kp, "kd": self.kd,
                "estimate": {"P": self._P}}


def _section4(context: ClaimContext, estimate: Estimate, compensation: Compensation, *, kp: float,
              kd: float) -> Certificate:
    """:func:`wmr_mj.analysis.certificate.certify` on the run's context."""
    return certify(plant=context.plant, estimate=estimate, gains=Gains(kp=kp, kd=kd), reference=context.reference,
                   limits=context.limits, compensation=compensation, control_period=context.control_period,
                   initial_error=context.initial_error, stated=context.stated, measurement=context.measurement)


def make_controller(name: str, model: SteeringModel, *, kp: float = PAPER_KP, kd: float = PAPER_KD,
                    friction_sign: str = "measured", friction_width: float = 0.0) -> SteeringController:
    """A controller by name ('computed-torque' or 'pd')."""
    if name == "computed-torque":
        return ComputedTorque(model, kp=kp, kd=kd, friction_sign=friction_sign, friction_width=friction_width)
    if name == "pd":
        return PDController(model, kp=kp, kd=kd)
    raise UnknownNameError("controller", name, CONTROLLER_NAMES)
