"""A sliding-mode steering law with a boundary layer (Slotine & Li, *Applied Nonlinear Control*,
Prentice Hall 1991, chapter 7: 7.1.3 and 7.2, the boundary layer of thickness phi).

Plant and law (voltage form; X~ = X - X^, truth minus the estimate of ``model``)::

    plant:  P a'' + C_V a' + f + K S(a) + Gam a'/cos^2(a) = u + d_V,   S(a) = sin(a)/cos^3(a)
            f = F sgn(a') sliding, any f in [-F, F] at rest (stiction);  Gam = gyro V_A
    E = alpha0 - a,   s = E' + lam E,   a_r'' = alpha0'' + lam E'
    law:    u = P^ a_r'' + C_V^ a' + F^ sgn(a') + K^ S(a) + Gam^ a'/cos^2(a) + k sat(s/phi)

Since s' = a_r'' - a'', multiplying by P and using the plant's equation::

    P s' = Delta - k sat(s/phi)
    Delta = P~ a_r'' + C~_V a' + (f - F^ sgn a') + K~ S(a) + Gam~ a'/cos^2(a) - d_V

(exact at every instant, at rest too, with f the friction the joint actually has). Outside the
layer (|s| >= phi) P s s' = s Delta - k |s| <= -(k - |Delta|) |s| <= -eta |s| when
k >= sup|Delta| + eta (Slotine & Li's sliding condition (7.5), with P > 0 multiplying s'): |s|
cannot grow past phi, so |s(0)| <= phi gives |s(t)| <= phi for all t (the layer is invariant).
Then E is s through the filter 1/(p + lam): with E(0) = 0, |E(t)| <= phi/lam, and
|E'| = |s - lam E| <= 2 phi (Slotine & Li 7.2, eq. (7.36)-(7.37) with n = 2).

The bound on |Delta| (volts), over the plant box's corners (:class:`~wmr_mj.analysis.claim.ClaimContext`),
inside the layer (|E| <= phi/lam, |E'| <= 2 phi, so |a_r''| <= max|alpha0''| + 2 lam phi,
|a'| <= max|alpha0'| + 2 phi, |a| <= alpha_max = max|alpha0| + phi/lam)::

    D = max_P |P - P^| (max|alpha0''| + 2 lam phi) + max|C~_V| (max|alpha0'| + 2 phi)
        + phi_f + max|K~| S(alpha_max) + max|Gam~| (max|alpha0'| + 2 phi)/cos^2(alpha_max) + d_V,max

with phi_f = sup|f - F^ s| over sliding and rest, the certificate's friction term
(:func:`wmr_mj.analysis.certificate.friction_term`: max(F_max, F^) for the measured sign, exact
or smoothed, covering stiction and creep; F_max for 'none'). The claim (:meth:`SlidingMode.claim`)
is the box |E| <= phi/lam, |E'| <= 2 phi with the checked assumption k >= D + eta.

Sampling. The law is held over each control period T; the argument above is continuous. The
claim states the check that one period moves s by a small part of the layer: with
|P s'| <= D + k, the change of s over T is at most T (D + k)/P_min, required
<= :data:`SAMPLING_FRACTION` phi, and the layer's gain k/phi must not overshoot the layer in one
period (T k/(P_min phi) <= 1). Under measurement errors or a delay the same check is named for
what it measures, :data:`MEASURED_STEP`: D grows by the law's measured-input terms, T does not.
These are a stated margin, not a sampled-data proof; the tests
(tests/test_sliding_mode.py) check the bound on a zero-order-hold simulation. On every cart a run
also computes the layer as a sampled loop (:mod:`wmr_mj.analysis.sliding_sampled`: inside the layer the law is
computed torque at K_P = lam k/(P^ phi), K_D = lam + k/(P^ phi), and the law's measured s is bounded by its l1
gains), and is judged by it, the ideal cart included (:meth:`SlidingMode.claim`,
:func:`controllers.sampled_claim.with_sampled_data`; this claim is named 'boundary-layer' and recorded beside it).

Usage::

    from controllers.sliding_mode import SlidingMode
    law = SlidingMode(model, lam=5.0, phi=0.2, k=3.0, eta=0.2)
    u = law.voltage_scalar(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)
    law.uncertainty_bound(context)       # D [V] over the run's plant box
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from controllers.base import BuildContext, DesignParameter, SteeringController
from controllers.sampled_claim import with_sampled_data
from wmr_mj.analysis.certificate import Assumption, Certificate, Compensation, Estimate, friction_term
from wmr_mj.analysis.claim import ClaimContext, box_claim
from wmr_mj.analysis.measurement import (
    DELAY_FIXED_POINT,
    coverage_assumption_fields,
    inv_cos2_slope,
    sin_cos3_slope,
)
from wmr_mj.analysis.sliding_sampled import sliding_sampled_certificate
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.plant.reduced import SteeringModel, smooth_sign
from wmr_mj.reference.bounds import sin_cos3

__all__ = ["SlidingMode", "Uncertainty", "MeasuredLayer", "SAMPLING_FRACTION", "SLIDING_FRICTION_SIGNS",
           "MEASURED_STEP", "BOUNDARY_LAYER"]

#: The name of the boundary layer's claim in a run's ``inputs['certificate']`` (beside 'sampled-data').
BOUNDARY_LAYER = "boundary-layer"
#: The largest change of s over one control period, as a fraction of the layer phi.
SAMPLING_FRACTION = 0.1
#: Name of the sampling check under measurement errors and a delay: what it measures, the step
#: T (D + k)/P_min of s over one period, grows with D (its measured-input and delay terms) while T stays.
MEASURED_STEP = "step of s per period with the measured errors"
#: The Coulomb compensation's sign: the measured a' (as computed-torque's default) or none.
SLIDING_FRICTION_SIGNS = ("measured", "none")
_LAYER_ITERATIONS = 10000


def _positive(name: str, value: Any, *, allow_zero: bool = False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"sliding-mode {name} = {value!r} is not accepted: a finite number") from None
    if not math.isfinite(v) or v < 0.0 or (v == 0.0 and not allow_zero):
        raise ParameterError(f"sliding-mode {name} = {value!r} is not accepted: a finite number "
                             f"{'>= 0' if allow_zero else '> 0'}")
    return v


@dataclass(frozen=True)
class Uncertainty:
    """The parts of the bound D on |Delta| [V] (module docstring), each its maximum over the box.

    P_term: |P - P^| max|a_r''|; C_V_term; friction_term (phi_f); K_term; gyro_term;
    disturbance; total D = their sum; alpha_max [rad], the reachable angle it is computed at.
    """

    P_term: float
    C_V_term: float
    friction_term: float
    K_term: float
    gyro_term: float
    disturbance: float
    alpha_max: float

    @property
    def total(self) -> float:
        return (self.P_term + self.C_V_term + self.friction_term + self.K_term + self.gyro_term
                + self.disturbance)

    def to_dict(self) -> dict[str, float]:
        return {"P_term": self.P_term, "C_V_term": self.C_V_term, "friction_term": self.friction_term,
                "K_term": self.K_term, "gyro_term": self.gyro_term, "disturbance": self.disturbance,
                "total": self.total, "alpha_max": self.alpha_max}


@dataclass(frozen=True)
class MeasuredLayer:
    """The boundary layer under measurement errors and a delay (:meth:`SlidingMode.measured_layer`).

    layer: Phi [rad/s], |s| <= Phi (inf when it does not close); D [V]: the bound on |Delta| with the law's
    measured-input terms; e_alpha [rad], e_alpha_dot [rad/s]: the law's input errors (static plus the
    delay's); rho [-]: tau c_v/P_min; alpha_m [rad]: the measured angle's bound; voltage_max [V]: the
    law's |u| bound; uncertainty: today's terms at the layer; reason: why there is no layer ('' if there is).
    """

    layer: float
    D: float
    e_alpha: float
    e_alpha_dot: float
    rho: float
    alpha_m: float
    voltage_max: float
    uncertainty: Uncertainty | None
    reason: str


class SlidingMode(SteeringController):
    """u = P^ a_r'' + C_V^ a' + F^ sgn(a') + K^ S(a) + Gam^ a'/cos^2(a) + k sat(s/phi) (module docstring).

    Parameters: lam [1/s] (the surface's slope), phi [rad/s] (the boundary layer), k [V] (the
    switching gain), eta [V] (the margin of the sliding condition, used by the claim only),
    friction_sign 'measured' (F^ sgn a') or 'none', friction_width [rad/s] (sgn smoothed as
    x/sqrt(x^2 + w^2); 0: exact). Defaults: certified on the default run
    (``RunConfig(controller="sliding-mode", model="nonholonomic")``, the paper circle, m1 550-750 kg):
    |E| <= 0.04 rad, |E'| <= 0.4 rad/s, D = 1.80 V < k - eta = 2.8 V, |u| <= 8.5 V.
    """

    name = "sliding-mode"
    #: what ``wmr-mj design`` searches of this law: lam, phi, k, eta (each in log), graded (its default layer saturates)
    design_parameters = (DesignParameter("lam", "1/s"), DesignParameter("phi", "rad/s"), DesignParameter("k", "V"),
                         DesignParameter("eta", "V", ".4g"))
    design_graded = True
    # under the paper's model K^ = 5.33 V while the plant's K is about 0: the uncertainty bound D = 9.6 V
    # exceeds the default switching gain k = 3 V, so the claim cannot hold; the non-holonomic model's K^ = 0
    default_model = "nonholonomic"
    model: SteeringModel

    def __init__(self, model: SteeringModel, *, lam: float = 5.0, phi: float = 0.2, k: float = 3.0,
                 eta: float = 0.2, friction_sign: str = "measured", friction_width: float = 0.0) -> None:
        if not isinstance(model, SteeringModel):
            raise ParameterError(f"sliding-mode needs a SteeringModel, got {type(model).__name__}")
        if friction_sign not in SLIDING_FRICTION_SIGNS:
            raise UnknownNameError("friction sign", str(friction_sign), SLIDING_FRICTION_SIGNS)
        self.model = model
        self.lam = _positive("lam", lam)
        self.phi = _positive("phi", phi)
        self.k = _positive("k", k, allow_zero=True)
        self.eta = _positive("eta", eta, allow_zero=True)
        self.friction_sign = friction_sign
        self.friction_width = _positive("friction_width", friction_width, allow_zero=True)
        self._F = 0.0 if friction_sign == "none" else model.F
        self._gyro_V = model.gyro * model.V_A

    @classmethod
    def from_context(cls, context: BuildContext, **params: Any) -> SlidingMode:
        """The law on the run's model (``context.model``: P^, C_V^, F^, K^, gyro^, V_A)."""
        return cls(context.model, **params)

    # ------------------------------------------------------------------ the law
    def surface(self, alpha: float, alpha_dot: float, alpha0: float, alpha0_dot: float) -> float:
        """s = E' + lam E [rad/s]."""
        return (alpha0_dot - alpha_dot) + self.lam * (alpha0 - alpha)

    def _sign(self, x: float) -> float:
        w = self.friction_width
        if w > 0.0:
            return x / math.sqrt(x * x + w * w)
        return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)

    def voltage_scalar(self, alpha: float, alpha_dot: float, alpha0: float, alpha0_dot: float,
                       alpha0_ddot: float) -> float:
        m = self.model
        E, Ed = alpha0 - alpha, alpha0_dot - alpha_dot
        s = Ed + self.lam * E
        sat = min(1.0, max(-1.0, s / self.phi))
        c = math.cos(alpha)
        u = m.P * (alpha0_ddot + self.lam * Ed) + m.C_V * alpha_dot + self.k * sat
        if self._F:
            u += self._F * self._sign(alpha_dot)
        if m.K:
            u += m.K * math.sin(alpha) / (c * c * c)
        if self._gyro_V:
            u += self._gyro_V * alpha_dot / (c * c)
        return u

    def voltage(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot) -> np.ndarray:
        m = self.model
        a, ad = np.asarray(alpha, dtype=float), np.asarray(alpha_dot, dtype=float)
        E = np.asarray(alpha0, dtype=float) - a
        Ed = np.asarray(alpha0_dot, dtype=float) - ad
        s = Ed + self.lam * E
        c = np.cos(a)
        u = m.P * (np.asarray(alpha0_ddot, dtype=float) + self.lam * Ed) + m.C_V * ad
        u = u + self.k * np.clip(s / self.phi, -1.0, 1.0)
        if self._F:
            u = u + self._F * smooth_sign(ad, self.friction_width)
        if m.K:
            u = u + m.K * np.sin(a) / (c * c * c)
        if self._gyro_V:
            u = u + self._gyro_V * ad / (c * c)
        return u

    # ------------------------------------------------------------------ the claim
    def uncertainty(self, context: ClaimContext, *, layer: float | None = None) -> Uncertainty:
        """The bound on |Delta| [V] over ``context.plant``'s box inside the layer |s| <= ``layer`` [rad/s]
        (None: phi, the law's own; module docstring)."""
        plant, ref, m = context.plant, context.reference, self.model
        if ref.alpha_max is None:
            raise ParameterError("sliding-mode's claim needs the reference's max|alpha0| (ReferenceBounds.alpha_max)")
        lam, phi = self.lam, (self.phi if layer is None else float(layer))
        a_max = ref.alpha_max + phi / lam
        ar_dd = ref.alpha_ddot_max + 2.0 * lam * phi
        rate = ref.alpha_dot_max + 2.0 * phi
        box = plant.box
        P_term = max(abs(p - m.P) for p in box.P) * ar_dd
        C_term = max(abs(c - m.C_V) for c in box.C_V) * rate
        phi_f = friction_term(self.friction_sign, F=box.F, F_hat=self._F)
        if a_max < 0.5 * math.pi:
            K_term = max(abs(kk - m.K) for kk in box.K) * sin_cos3(a_max)
            c2 = math.cos(a_max) ** 2
            gam = [g * v for g in plant.gyro for v in plant.V_A]
            G_term = max(abs(g - self._gyro_V) for g in gam) * rate / c2
        else:
            K_term = G_term = math.inf
        return Uncertainty(P_term=P_term, C_V_term=C_term, friction_term=phi_f, K_term=K_term, gyro_term=G_term,
                           disturbance=plant.disturbance, alpha_max=a_max)

    def uncertainty_bound(self, context: ClaimContext) -> float:
        """D [V]: the bound on |Delta| over the box (:meth:`uncertainty`)."""
        return self.uncertainty(context).total

    def voltage_bound(self, context: ClaimContext) -> float:
        """The law's |u| bound [V] inside the layer (triangle inequality on the law)."""
        ref, m = context.reference, self.model
        a_max = (ref.alpha_max or 0.0) + self.phi / self.lam
        if a_max >= 0.5 * math.pi:
            return math.inf
        rate = ref.alpha_dot_max + 2.0 * self.phi
        return (m.P * (ref.alpha_ddot_max + 2.0 * self.lam * self.phi) + abs(m.C_V) * rate + self._F
                + abs(m.K) * sin_cos3(a_max) + abs(self._gyro_V) * rate / math.cos(a_max) ** 2 + self.k)

    def measured_layer(self, context: ClaimContext) -> MeasuredLayer:
        """The layer |s| <= Phi [rad/s] when the law reads alpha + e_a, alpha' + e_v and acts tau late
        (``context.measurement``; module docstring, "Measurement errors and delay").

        Phi = phi + e_s with e_s = e_v + lam e_a the error of the law's s, e_a <= e_a,max + tau sup|a'|,
        e_v <= e_v,max + tau sup|a''|, sup|a'| <= max|a0'| + 2 Phi, sup|a''| <= max|a0''| + (D_m + k)/P_min
        + 2 lam Phi; D_m = (D(Phi) + the law's measured-input terms)/(1 - rho), rho = tau c_v/P_min, solved
        as the least fixed point of Phi (iterated from phi). ``valid`` False with the reason when it
        does not close (rho >= 1, the measured angle reaching pi/2, no convergence).
        """
        meas, ref = context.measurement, context.reference
        tau, P_lo = meas.delay_s, context.plant.box.P[0]
        flip = self.friction_sign == "measured" and (meas.alpha_dot_error_max > 0.0 or tau > 0.0)
        layer, last = self.phi, None
        for _ in range(_LAYER_ITERATIONS):
            step = self._layer_step(context, layer, tau, P_lo, flip)
            if step.reason:
                return step
            last = step
            if step.layer <= layer * (1.0 + 1e-13):
                return replace(step, layer=max(layer, step.layer))
            layer = step.layer
            if (ref.alpha_max or 0.0) + layer / self.lam >= 0.5 * math.pi:
                break
        reason = "the layer did not settle" if last is None else f"the layer did not settle (Phi = {layer:.4g})"
        return MeasuredLayer(layer=math.inf, D=math.inf, e_alpha=math.inf, e_alpha_dot=math.inf, rho=math.inf,
                             alpha_m=math.inf, voltage_max=math.inf, uncertainty=None, reason=reason)

    def _layer_step(self, context: ClaimContext, layer: float, tau: float, P_lo: float, flip: bool) -> MeasuredLayer:
        """One step Phi -> phi + e_s(Phi) of :meth:`measured_layer`."""
        meas, ref, m = context.measurement, context.reference, self.model
        lam, k = self.lam, self.k
        unc = self.uncertainty(context, layer=layer)
        rate = ref.alpha_dot_max + 2.0 * layer
        e_a = meas.alpha_error_max + tau * rate
        A_m = unc.alpha_max + e_a
        if not math.isfinite(unc.total) or A_m >= 0.5 * math.pi:
            return MeasuredLayer(layer=math.inf, D=math.inf, e_alpha=e_a, e_alpha_dot=math.inf, rho=math.inf,
                                 alpha_m=A_m, voltage_max=math.inf, uncertainty=unc,
                                 reason=(f"the measured angle reaches pi/2 (alpha_max + e_alpha = {A_m:.4g} rad)"
                                         if math.isfinite(A_m) else "the measured angle's error e_alpha is unbounded "
                                         "(no bound derived)"))
        c2_m = math.cos(A_m) ** 2
        c_v = m.P * lam + abs(m.C_V) + abs(self._gyro_V) / c2_m  # V per rad/s of the law's velocity error
        c_a = abs(m.K) * sin_cos3_slope(A_m) + abs(self._gyro_V) * inv_cos2_slope(A_m) * rate  # V per rad
        rho = tau * c_v / P_lo
        if rho >= 1.0:
            return MeasuredLayer(layer=math.inf, D=math.inf, e_alpha=e_a, e_alpha_dot=math.inf, rho=rho,
                                 alpha_m=A_m, voltage_max=math.inf, uncertainty=unc,
                                 reason=f"tau c_v/P_min = {rho:.4g} >= 1: the delayed velocity's error feeds back")
        F_max = context.plant.box.F[1]
        flip_V = (F_max + self._F - unc.friction_term) if flip else 0.0  # the sign of a measured a' may be wrong
        ff = 2.0 * m.P * ref.alpha_ddot_max if tau > 0.0 else 0.0  # a0''(t - tau) - a0''(t) [V]
        e_v0 = meas.alpha_dot_error_max + tau * (ref.alpha_ddot_max + k / P_lo + 2.0 * lam * layer)
        D = (unc.total + flip_V + ff + c_a * e_a + c_v * e_v0) / (1.0 - rho)
        e_v = e_v0 + tau * D / P_lo
        new_layer = self.phi + e_v + lam * e_a
        rate_m = rate + e_v
        voltage = (m.P * (ref.alpha_ddot_max + lam * (2.0 * layer + e_v)) + abs(m.C_V) * rate_m + self._F
                   + abs(m.K) * sin_cos3(A_m) + abs(self._gyro_V) * rate_m / c2_m + k)
        return MeasuredLayer(layer=new_layer, D=D, e_alpha=e_a, e_alpha_dot=e_v, rho=rho, alpha_m=A_m,
                             voltage_max=voltage, uncertainty=unc, reason="")

    def claim(self, context: ClaimContext) -> Certificate:
        """The boundary layer (:meth:`layer_claim`), named 'boundary-layer', beside the layer as a sampled loop
        on the cart's parts (``context.wants_sampled_data``, the ideal cart included;
        :func:`wmr_mj.analysis.sliding_sampled.sliding_sampled_certificate`), which is taken: the law runs sampled
        (:func:`controllers.sampled_claim.with_sampled_data`)."""
        m = self.model
        c = m.coefficients
        estimate = Estimate(P=c.P, C_V=c.C_V, F=0.0 if self.friction_sign == "none" else c.F, K=c.K, gyro=c.gyro,
                            V_A=m.V_A)
        compensation = Compensation(friction_sign=self.friction_sign, friction_width=self.friction_width)
        return with_sampled_data(self.layer_claim(context), BOUNDARY_LAYER, context,
                                 lambda cart: sliding_sampled_certificate(
                                     plant=context.plant, estimate=estimate, lam=self.lam, phi=self.phi, k=self.k,
                                     reference=context.reference, limits=context.limits, compensation=compensation,
                                     control_period=context.control_period, cart=cart,
                                     initial_error=context.initial_error, stated=context.stated))

    def layer_claim(self, context: ClaimContext) -> Certificate:
        """|E| <= phi/lam, |E'| <= 2 phi (the boundary layer, Slotine & Li 7.2) with its assumptions:
        the switching gain above the uncertainty, the sampling margin, and the run's. Under
        ``context.measurement`` (not exact) the layer grows to :meth:`measured_layer`'s Phi."""
        if not context.measurement.is_exact:
            return self._measured_claim(context)
        unc = self.uncertainty(context)
        D = unc.total
        T = float(context.control_period)
        P_min = context.plant.box.P[0]
        ds = T * (D + self.k) / P_min  # the largest change of s over one period [rad/s]
        layer_gain = T * self.k / (P_min * self.phi)
        own = (
            Assumption("switching gain above the uncertainty", "k >= D + eta, D = sup|Delta| over the box "
                       "inside the layer (Slotine & Li (7.5))", self.k >= D + self.eta, D + self.eta, self.k,
                       "D [V] = " + ", ".join(f"{n} {v:.4g}" for n, v in unc.to_dict().items()
                                              if n not in ("total", "alpha_max"))
                       + f"; k = {self.k:g} V, eta = {self.eta:g} V", kind="checked"),
            Assumption("control period", f"T (D + k)/P_min <= {SAMPLING_FRACTION:g} phi (s moves a small part "
                       "of the layer in one period) and T k/(P_min phi) <= 1 (continuous-time analysis; a "
                       "margin, not a sampled-data proof)",
                       ds <= SAMPLING_FRACTION * self.phi and layer_gain <= 1.0, ds / self.phi, SAMPLING_FRACTION,
                       f"T = {T:g} s, change of s per period {ds:.4g} rad/s against phi = {self.phi:g} rad/s; "
                       f"T k/(P_min phi) = {layer_gain:.4g}", kind="checked"),
        )
        E_max = self.phi / self.lam
        return box_claim(claimant=self.name, E_max=E_max, Edot_max=2.0 * self.phi, context=context,
                         alpha_max=unc.alpha_max, voltage_max=self.voltage_bound(context), own=own,
                         inputs={"lam": self.lam, "phi": self.phi, "k": self.k, "eta": self.eta,
                                 "uncertainty_V": unc.to_dict(), "estimate": self.model.coefficients.to_dict(),
                                 "friction_sign": self.friction_sign, "friction_width": self.friction_width})

    def _measured_claim(self, context: ClaimContext) -> Certificate:
        """The claim with the layer of :meth:`measured_layer` and the assumption 'sensing and actuation covered'."""
        meas = context.measurement
        lay = self.measured_layer(context)
        T, P_min = float(context.control_period), context.plant.box.P[0]
        D = lay.D
        ds = T * (D + self.k) / P_min
        layer_gain = T * self.k / (P_min * self.phi)
        unc = lay.uncertainty
        own = [
            Assumption("switching gain above the uncertainty", "k >= D + eta, D = sup|Delta| over the box inside "
                       "the grown layer, with the law's measured-input terms (Slotine & Li (7.5))",
                       bool(math.isfinite(D) and self.k >= D + self.eta), D + self.eta, self.k,
                       f"D = {D:.4g} V with e_alpha = {lay.e_alpha:.4g} rad, e_alpha' = {lay.e_alpha_dot:.4g} rad/s, "
                       f"delay {meas.delay_s:g} s; k = {self.k:g} V, eta = {self.eta:g} V", kind="checked"),
            Assumption(MEASURED_STEP, f"T (D + k)/P_min <= {SAMPLING_FRACTION:g} phi with D grown by the law's "
                       "measured-input and delay terms, and T k/(P_min phi) <= 1 (continuous-time analysis; a margin, "
                       "not a sampled-data proof)",
                       bool(ds <= SAMPLING_FRACTION * self.phi and layer_gain <= 1.0), ds / self.phi,
                       SAMPLING_FRACTION, self._step_note(T, ds, D, unc, layer_gain), kind="checked"),
            Assumption(**coverage_assumption_fields(meas, self.name)),
        ]
        if meas.delay_s > 0.0:
            own.append(Assumption(DELAY_FIXED_POINT, "tau c_v/P_min < 1 and the grown layer Phi = phi + e_v + lam e_a "
                                  "settles", not lay.reason, lay.rho, 1.0,
                                  lay.reason or f"Phi = {lay.layer:.4g} rad/s against phi = {self.phi:g}",
                                  kind="checked"))
        a0 = context.reference.alpha_max or 0.0
        E_max = lay.layer / self.lam
        return box_claim(claimant=self.name, E_max=E_max, Edot_max=2.0 * lay.layer, context=context,
                         alpha_max=a0 + E_max if math.isfinite(E_max) else math.inf, voltage_max=lay.voltage_max,
                         own=own, reason=lay.reason,
                         inputs={"lam": self.lam, "phi": self.phi, "k": self.k, "eta": self.eta,
                                 "layer": lay.layer, "measurement": {**meas.to_dict(), "eps_alpha": lay.e_alpha,
                                                                     "eps_alpha_dot": lay.e_alpha_dot, "rho": lay.rho},
                                 "uncertainty_V": unc.to_dict() if unc is not None else None,
                                 "estimate": self.model.coefficients.to_dict(),
                                 "friction_sign": self.friction_sign, "friction_width": self.friction_width})

    def _step_note(self, T: float, ds: float, D: float, unc: Uncertainty | None, layer_gain: float) -> str:
        """The note of :data:`MEASURED_STEP`: what moved (D, by the measured errors), the period that did not."""
        ideal = f" ({unc.total:.4g} V without the measured-input and delay terms)" if unc is not None else ""
        return (f"the step of s per period T (D + k)/P_min = {ds:.4g} rad/s against phi = {self.phi:g} rad/s, with "
                f"D = {D:.4g} V{ideal}; T = {T:g} s; T k/(P_min phi) = {layer_gain:.4g}")

    def describe(self) -> dict:
        return {"controller": self.name, "model": self.model.name, "lam": self.lam, "phi": self.phi, "k": self.k,
                "eta": self.eta, "friction_sign": self.friction_sign, "friction_width": self.friction_width,
                "estimate": self.model.coefficients.to_dict()}
