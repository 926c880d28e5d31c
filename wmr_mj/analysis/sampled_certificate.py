"""The sampled-data certificate: the computed-torque law as it runs, on every cart (issue 35 item 1; the ideal cart,
e_alpha = e_v = 0 and no delay, since issue 44, where it is the certificate a run is judged by).

Section 4's certificate (:mod:`wmr_mj.analysis.small_gain`) bounds a continuous loop and charges every
measurement error at every instant as if it were free. Here the linear part of the law runs as it does: at
the control period T under zero-order hold, with the sensing and actuation delays and the velocity estimate
inside the loop (:mod:`wmr_mj.analysis.sampled_data`), and each bounded error is priced by its l1 gain, so a
differenced encoder's error telescopes. What the linear loop does not hold (model mismatch over the box,
friction against its compensation (F_max + F^, or for a smoothed sign of the measured rate max(F_max, F^) +
F^ eps_v/w, whichever bound is smaller), the gyroscopic and K S(alpha) terms, the reference's own terms, the
back-EMF's hold) is a bounded disturbance w through the same kind of small-gain fixed point as section 4,
with the sampled loop's l1 gains in place of gamma1, gamma2. Derivation, step by step:
``docs/guides/certificates.md``, "The sampled-data certificate".

The loop (``e_hat`` the law's error, ``c^ = C_V^/P^``)::

    E'' = -u[k - d_a] - c^ E'[k] + w(t)          on [t_k, t_k + T)
    u[k] = K_P E^[k] + (K_D - c^) E^'[k]         the law's servo with its back-EMF compensation folded in

and |w| <= W0 + delta_u sup|u| + k_y sup|E'| + k_A sup|E''| (:class:`SampledDataTerms`), closed by
W = (W0 + ...)/(1 - lambda) where lambda, the loop gain, is < 1.

Usage::

    from wmr_mj.analysis.sampled_certificate import sampled_certificate, SampledCart
    cert = sampled_certificate(plant=..., estimate=..., gains=..., reference=..., limits=..., compensation=...,
                               control_period=0.001, cart=SampledCart.of(sensing, gear_ratio=60.0))
    cert.E_max, cert.claimant                     # rad, 'sampled-data'
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from wmr_mj.analysis.claim import least_fixed_point, shared_assumptions, tangent_reason
from wmr_mj.analysis.claim_types import Assumption, Certificate, ClaimInputs
from wmr_mj.analysis.measurement import MeasurementErrors, coverage_assumption_fields, inv_cos2_slope, sin_cos3_slope
from wmr_mj.analysis.plant_box import PlantBox, PlantLimits
from wmr_mj.analysis.regions import BoxRegion
from wmr_mj.analysis.sampled_data import (
    PeakGains,
    SampledLoop,
    _norm_bound,
    _Rows,
    current_moments,
    peak_gains,
    sampled_loop,
)
from wmr_mj.analysis.small_gain import Compensation, Estimate, Gains, _Bound
from wmr_mj.errors import ParameterError
from wmr_mj.hardware.estimators import velocity_estimator
from wmr_mj.hardware.sensing import Sensing, measurement_error_bounds
from wmr_mj.hardware.spec import whole_periods
from wmr_mj.reference.bounds import ReferenceBounds, sin_cos3

__all__ = ["SAMPLED_DATA", "SampledCart", "SampledDataTerms", "SampledDataInputs", "sampled_certificate",
           "damped_loop"]

#: The sampled-data certificate's claimant (its JSON ``claimant``, and the ``certificate`` a run names).
SAMPLED_DATA = "sampled-data"
_ITERATIONS = 2000


@dataclass(frozen=True, kw_only=True)
class SampledCart:
    """The cart as the sampled loop sees it: the estimate, its delays in control periods, its error bounds.

    Attributes:
        velocity: the estimate ('exact', 'tachometer', 'difference', 'filtered'). filter_tau: tau_f, s.
        sensing_delay, actuation_delay: d_s, d_a, whole control periods.
        angle_error: sup|alpha_m - alpha(t - delay)|, rad (quantisation, uniform noise, play read on the motor).
        velocity_noise: the velocity's own noise bound, rad/s (what is added after the estimate).
        velocity_error: the estimate's static error bound, rad/s (with ``velocity_lag``, s, times sup|alpha''|):
            used only where the law's velocity enters outside the linear loop (the gyro compensation).
        measurement: the run's coverage (an uncovered part makes the certificate uncertified).
        electrical_time_constant: tau_e = L_a/R_a, s, the armature current's lag (0: none; > 0: a state of the
            sampled loop, ``docs/guides/certificates.md``, "The armature inductance in the sampled loop").
    """

    velocity: str
    filter_tau: float | None
    sensing_delay: int
    actuation_delay: int
    angle_error: float
    velocity_noise: float
    velocity_error: float
    velocity_lag: float
    measurement: MeasurementErrors
    electrical_time_constant: float = 0.0

    @classmethod
    def of(cls, sensing: Sensing, *, control_period: float, gear_ratio: float, play: float = 0.0,
           actuation_delay_s: float = 0.0, measurement: MeasurementErrors | None = None) -> SampledCart:
        """From the sensing's specification (:func:`wmr_mj.hardware.sensing.measurement_error_bounds`).

        Args:
            sensing: the sensor. control_period: T, s. gear_ratio: i2. play: b, rad (counted where the encoder is
                on the motor side). actuation_delay_s: s, a whole number of control periods.
            measurement: the run's coverage (default: covered); its ``electrical_time_constant_s`` is the cart's.

        Raises:
            ParameterError: a delay that is not a whole number of control periods.
        """
        b = measurement_error_bounds(sensing, control_period=control_period, gear_ratio=gear_ratio, backlash=play)
        return cls(velocity=str(sensing.velocity), filter_tau=sensing.filter_tau,
                   sensing_delay=sensing.delay_steps(control_period),
                   actuation_delay=whole_periods("actuation delay", actuation_delay_s, control_period),
                   angle_error=b.alpha_error_max, velocity_noise=sensing.velocity_noise_bound(),
                   velocity_error=b.alpha_dot_error_max, velocity_lag=b.alpha_dot_lag,
                   measurement=measurement if measurement is not None else MeasurementErrors.exact(),
                   electrical_time_constant=measurement.electrical_time_constant_s if measurement is not None else 0.0)


@dataclass(frozen=True, kw_only=True)
class SampledDataTerms:
    """The parts of the certificate, each with its unit (the JSON's ``inputs['sampled_data']['terms']``).

    Attributes:
        gain_E_w [s^2], gain_Edot_w [s], gain_u_w [-]: the sampled loop's l1 gains from w.
        gain_E_angle [-], gain_E_velocity [s]: from the angle channel and the velocity channel into E.
        angle_channel [rad], velocity_channel [rad/s]: the bounds on the two channels (the sensor's error plus
            the reference's own terms under the delay).
        initial_transient_E [rad]: what the estimator's start (its first difference is 0) can add to E.
        friction_term, P_term, feedforward_hold_term, C_V_term, K_term, gyro_term, disturbance_term [rad/s^2]:
            the parts of W0 (each at the P corner where W0 is largest, friction at P_min).
        delta_u [-], k_y [1/s], k_A [-]: the coefficients of sup|u|, sup|E'|, sup|E''| in |w|.
        loop_gain [-]: lambda, < 1 for a bound. W [rad/s^2]: the bound on |w| at the fixed point.
        spectral_radius [-]: of the sampled loop. U [rad/s^2]: sup|u|.
    """

    gain_E_w: float
    gain_Edot_w: float
    gain_u_w: float
    gain_E_angle: float
    gain_E_velocity: float
    angle_channel: float
    velocity_channel: float
    initial_transient_E: float
    friction_term: float
    P_term: float
    feedforward_hold_term: float
    C_V_term: float
    K_term: float
    gyro_term: float
    disturbance_term: float
    delta_u: float
    k_y: float
    k_A: float
    loop_gain: float
    W: float
    U: float
    spectral_radius: float

    def to_dict(self) -> dict[str, float | None]:
        """JSON-ready (inf -> None)."""
        return {k: (float(v) if math.isfinite(v) else None) for k, v in dataclasses.asdict(self).items()}


@dataclass(frozen=True, kw_only=True)
class SampledDataInputs:
    """What the sampled-data certificate rests on (its JSON ``inputs``)."""

    control_period: float
    cart: SampledCart
    kp: float
    kd: float
    c_hat: float
    friction_sign: str
    terms: SampledDataTerms | None
    reference: ReferenceBounds

    def to_dict(self) -> dict[str, Any]:
        cart = self.cart
        return {"certificate": SAMPLED_DATA, "control_period": self.control_period, "kp": self.kp, "kd": self.kd,
                "c_hat": self.c_hat, "friction_sign": self.friction_sign,
                "cart": {"velocity": cart.velocity, "filter_tau": cart.filter_tau,
                         "sensing_delay_periods": cart.sensing_delay, "actuation_delay_periods": cart.actuation_delay,
                         "angle_error": cart.angle_error, "velocity_noise": cart.velocity_noise,
                         "velocity_error": cart.velocity_error, "velocity_lag": cart.velocity_lag,
                         "measurement": cart.measurement.to_dict(),
                         "electrical_time_constant": cart.electrical_time_constant},
                "reference": {"alpha0_max": self.reference.alpha_max, "alpha0_dot_max": self.reference.alpha_dot_max,
                              "alpha0_ddot_max": self.reference.alpha_ddot_max},
                "terms": self.terms.to_dict() if self.terms is not None else None}


def damped_loop(*, kp: float, kd: float, c_hat: float, control_period: float, cart: SampledCart) -> SampledLoop:
    """The sampled loop of E'' = -u[k - d_a] - c^ E'(t) + w with u = K_P E^ + (K_D - c^) E^', to second order in c^ T.

    :func:`~wmr_mj.analysis.sampled_data.sampled_loop` with the derivative gain K_D - c^ (the law's back-EMF
    compensation C_V^ alpha_m' = C_V^ (alpha0' - E^') reads the same estimate), then the plant's back-EMF over the
    period: with s = t - t_k and u_a the held command, -c^ E'(t) = -c^ E'[k] + c^ s (u_a + c^ E'[k]) + rho(t),
    |rho| <= c^^2 s^2/2 sup|E''| + c^ s sup|w| (left in the disturbance), so over one period
    E gains -(T^2/2 - c^ T^3/6)(u_a + c^ E'[k]) and E' gains -(T - c^ T^2/2)(u_a + c^ E'[k]). With the armature
    current j (``cart.electrical_time_constant`` > 0), u_a is j(t) and its integrals over the period are exact
    (:func:`~wmr_mj.analysis.sampled_data.current_moments`): E' gains -(m1 - c^ m2) - c^ (T - c^ T^2/2) E'[k], E
    gains -(m2 - c^ m3) - c^ (T^2/2 - c^ T^3/6) E'[k], m_i the i-fold integral of j.

    Raises:
        ParameterError: K_D - c^ <= 0 (the sampled servo then has no damping of its own), as sampled_loop.
    """
    kd_loop = kd - c_hat
    if not kd_loop > 0.0:
        raise ParameterError(f"K_D - C_V^/P^ = {kd:g} - {c_hat:g} <= 0: the sampled servo has no damping of its own")
    loop = sampled_loop(kp=kp, kd=kd_loop, control_period=control_period, velocity=cart.velocity,
                        filter_tau=cart.filter_tau, sensing_delay=cart.sensing_delay,
                        actuation_delay=cart.actuation_delay, electrical_time_constant=cart.electrical_time_constant)
    T, n = control_period, loop.n_states
    applied = loop.applied_row()  # u[k - d_a] over (state, e, n_v)
    rows = np.zeros((2, n + 2))
    rows[0, 0], rows[0, 1], rows[1, 1] = 1.0, T, 1.0
    if loop.current_index is None:
        drive = applied.copy()
        drive[1] += c_hat  # u_a + c^ E'[k]
        rows[0] -= (0.5 * T * T - c_hat * T ** 3 / 6.0) * drive
        rows[1] -= (T - 0.5 * c_hat * T * T) * drive
    else:
        m = current_moments(T, cart.electrical_time_constant)
        j = np.zeros(n + 2)
        j[loop.current_index] = 1.0
        m1, m2, m3 = (m[i, 0] * applied + m[i, 1] * j for i in (1, 2, 3))
        rows[0] -= m2 - c_hat * m3
        rows[0, 1] -= c_hat * (0.5 * T * T - c_hat * T ** 3 / 6.0)
        rows[1] -= m1 - c_hat * m2
        rows[1, 1] -= c_hat * (T - 0.5 * c_hat * T * T)
    A, B = np.array(loop.A), np.array(loop.B)
    A[:2], B[:2] = rows[:, :n], rows[:, n:]
    for x in (A, B):
        x.flags.writeable = False
    return dataclasses.replace(loop, A=A, B=B)


def _initial_transient(loop: SampledLoop, cart: SampledCart, radius: float) -> np.ndarray:
    """Per unit of E^[0], sup_k |y_i A^k e_prev| for (E, E', u): the chain's first difference is 0, the model's
    (E^[0] - E^[-1])/T; the model with E^[-1] = E^[0] as its initial state is the chain (0 for exact rates).

    The largest |C A^k x0| over k < N, and beyond N the norm bound |c A^k x0| <= ||c||_P* ||A^N x0||_P
    (||A||_P <= rho < 1, :func:`wmr_mj.analysis.sampled_data._norm_bound`), N where that is below 1e-3 of the
    largest seen."""
    if cart.velocity in ("exact", "tachometer"):
        return np.zeros(3)
    prev = _Rows(cart.velocity, cart.sensing_delay, cart.actuation_delay).prev
    P, rho = _norm_bound(loop.A, radius)
    if not rho < 1.0:
        return np.full(3, math.inf)
    dual = np.sqrt(np.einsum("ij,ij->i", loop.C, np.linalg.solve(P, loop.C.T).T))
    x = np.zeros(loop.n_states)
    x[prev] = 1.0
    top = np.zeros(3)
    for _ in range(1_000_000 // 64):
        for _ in range(64):
            top = np.maximum(top, np.abs(loop.C @ x))
            x = loop.A @ x
        tail = dual * math.sqrt(float(x @ P @ x))
        if np.all(tail <= 1e-3 * top):
            break
    return np.maximum(top, tail) * (1.0 + 1e-9)


@dataclass(frozen=True)
class _Linear:
    """The sampled loop's numbers, which the angle reached leaves alone."""

    gains: PeakGains
    M: np.ndarray  # (E, E', u) from the measurement channels and the start, at the samples
    g: np.ndarray  # (E, E', u) per unit of |w|
    angle_channel: float
    velocity_channel: float
    initial: float


def _linear(bound: _Bound, cart: SampledCart, T: float, c_hat: float) -> _Linear:
    loop = damped_loop(kp=bound.kp, kd=bound.kd, c_hat=c_hat, control_period=T, cart=cart)
    gains = peak_gains(loop)
    d_s = cart.sensing_delay
    angle_channel = cart.angle_error + d_s * T * bound.a0d  # e[k] - (alpha0(t_k) - alpha0(t_{k - d_s}))
    if cart.velocity in ("exact", "tachometer"):
        ref_rate = d_s * T * bound.a0dd  # alpha0'(t_k) - alpha0'(t_{k - d_s})
    elif cart.velocity == "difference":
        ref_rate = 0.5 * T * bound.a0dd  # alpha0'(t_k) - (alpha0(t_k) - alpha0(t_{k-1}))/T
    else:
        tau = float(cart.filter_tau or 0.0)
        a = velocity_estimator("filtered", control_period=T, filter_tau=tau).a
        ref_rate = (T * a / (1.0 - a) + 0.5 * T + tau / math.e) * bound.a0dd  # mean age, and the missing weight
    velocity_channel = cart.velocity_noise + ref_rate
    if not gains.stable:
        inf = np.full(3, math.inf)
        return _Linear(gains, inf, inf, angle_channel, velocity_channel, math.inf)
    G = gains.gains
    initial = cart.angle_error + 1e-9  # |E^[0]| <= |e[0]| + |alpha0(0)| (zero initial error, its tolerance)
    start = _initial_transient(loop, cart, gains.spectral_radius) * initial
    M = G[:, 1] * angle_channel + (G[:, 4] * velocity_channel if velocity_channel > 0.0 else 0.0) + start
    return _Linear(gains, M, np.asarray(G[:, 0], dtype=float), angle_channel, velocity_channel, float(start[0]))


@dataclass(frozen=True)
class _Solved:
    """The bound at one iterate of the fixed point (x = sup|E|, y = sup|E'|, both over all t)."""

    x: float
    y: float
    U: float
    W: float
    A2: float  # sup|E''|
    eps_a: float
    eps_v: float
    alpha_m: float
    terms: SampledDataTerms | None
    failure: str = ""
    Wt: float = math.nan  # sup|w + rho| [rad/s^2], what drives the loop (the sliding-mode layer check reads it)


def _solve_at(bound: _Bound, lin: _Linear, cart: SampledCart, T: float, c_hat: float, x: float, y: float,
              friction_width: float = 0.0) -> _Solved:
    """One step of the fixed point: the coefficients at (x, y), the linear small gain solved for W.

    The Coulomb sign's mismatch has two sound charges (``docs/guides/certificates.md``, "The Coulomb sign"): any
    |s| <= 1 of either sign, F_max + F^ per P; and, for the law's smoothed sign of its measured alpha'
    (``friction_width`` w > 0), max(F_max, F^) + F^ eps_v/w per P, x/sqrt(x^2 + w^2) being 1/w-Lipschitz and
    eps_v >= |alpha'(t) - alpha_m'[k']| linear in sup|E''|. Both are solved; each bound (E, E', u, w, E'') is the
    smaller of the two, each coordinate being a bound under either charge.
    """
    inf = math.inf
    b, est = bound, bound.estimate
    # t - t_{k - d_a - d_s} < span; the current's lag weighs the law's past outputs at mean age tau_e beyond it
    span = (cart.sensing_delay + cart.actuation_delay + 1) * T + cart.electrical_time_constant
    A = b.a0 + x
    eps_a = cart.angle_error + span * (b.a0d + y)
    A_m = A + eps_a
    if A_m >= 0.5 * math.pi:
        return _Solved(x, y, inf, inf, inf, eps_a, inf, A_m, None,
                       f"the measured angle reaches pi/2 (max|alpha0| + E_max + e_alpha = {A_m:.4g} rad)")
    S, c2, c2m = sin_cos3(A), math.cos(A) ** 2, math.cos(A_m) ** 2
    P_lo, corners = b.P_corners[0], b.P_corners
    F, r = b.plant.box.F, b.plant.friction_over_P
    hold_dd = 2.0 * b.a0dd  # alpha0''(t) - alpha0''(t_k'): no jerk bound
    hold_d = (cart.actuation_delay + 1) * T * b.a0dd  # alpha0'(t) - alpha0'(t_k')
    # the law's velocity outside the loop (gyro^, the smoothed sign): its static error and its age times sup|alpha''|
    lag = cart.velocity_lag + span
    lipschitz = (b.friction_sign == "measured" and friction_width > 0.0 and b.F_comp > 0.0
                 and math.isfinite(cart.velocity_error))

    def parts(p: float, smoothed: bool) -> tuple[float, ...]:
        F_p = F[1] if r is None else min(F[1], r * p)
        if smoothed:  # max(F_max, F^) + F^ (e_v + lag max|alpha0''|)/w; the lag times sup|E''| in k_A below
            phi = max(F_p, b.F_comp) + b.F_comp * (cart.velocity_error + lag * b.a0dd) / friction_width
        else:
            phi = F_p + b.F_comp  # any |s| <= 1 of either sign
        return (phi / p, abs(p - b.P_ff) * b.a0dd / p, b.P_ff * hold_dd / p,
                (b.dC * b.a0d + abs(est.C_V) * hold_d) / p, b.dK * S / p, b.dG * b.a0d / c2 / p,
                (b.dist_at(p) if b.plant.disturbance else 0.0) / p)

    gam = abs(b.Gam_hat) / P_lo
    K_slope = abs(est.K) / P_lo * sin_cos3_slope(A_m) * eps_a
    gyro_age = gam * ((cart.velocity_error + lag * b.a0dd) / c2m + (b.a0d + y) * inv_cos2_slope(A_m) * eps_a)
    C_V_lo, C_V_hi = b.plant.box.C_V
    delta_u = max(abs(m) for m in b.mis.values())
    delta_c = max(abs(c_hat - cv / p) for cv in (C_V_lo, C_V_hi) for p in corners)
    k_y = delta_c + b.dG / (c2 * P_lo)
    k_A = gam * lag / c2m  # the gyro compensation's age times sup|E''|
    k_A += c_hat * cart.electrical_time_constant  # c^ |E' - H[E']| <= c^ tau_e sup|E''| (the current's back-EMF lag)

    def solve(smoothed: bool) -> _Solved:
        worst = max((parts(p, smoothed) for p in corners), key=sum)
        W0 = sum(worst)
        W0 += K_slope
        W0 += gyro_age
        kA = k_A + (b.F_comp * lag / (friction_width * P_lo) if smoothed else 0.0)
        return _close(lin, cart, T, c_hat, x, y, eps_a, A_m, lag, W0, worst, delta_u, k_y, kA, b.a0dd)

    first = solve(False)
    if not lipschitz:
        return first
    second = solve(True)
    if first.failure or second.failure:
        return second if first.failure and not second.failure else first
    taken = first if first.x <= second.x else second
    return dataclasses.replace(taken, x=min(first.x, second.x), y=min(first.y, second.y), U=min(first.U, second.U),
                               W=min(first.W, second.W), A2=min(first.A2, second.A2),
                               eps_v=min(first.eps_v, second.eps_v), Wt=min(first.Wt, second.Wt))


def _close(lin: _Linear, cart: SampledCart, T: float, c_hat: float, x: float, y: float, eps_a: float, A_m: float,
           lag: float, W0: float, worst: tuple[float, ...], delta_u: float, k_y: float, k_A: float,
           a0dd: float) -> _Solved:
    """The linear small gain at one iterate: |w| <= W0 + delta_u U + k_y sup|E'| + k_A sup|E''| through the loop."""
    inf = math.inf
    (gE, gV, gU), (ME, MV, MU) = lin.g, lin.M
    # unknowns: W = sup|w| (the remainder), Wt = sup|w + rho| (what the loop is driven by), A2 = sup|E''|
    q = 1.0 / (1.0 - c_hat * T)
    h = 0.5 * c_hat * c_hat * T * T
    K = k_y * T + k_A
    a_W = W0 + delta_u * MU + k_y * MV + K * q * (MU + c_hat * MV)
    b_W = delta_u * gU + k_y * gV + K * q * (gU + c_hat * gV)
    r_W = 1.0 + c_hat * T + h * q
    inner = K * q
    loop_gain = (h * q * (gU + c_hat * gV) + r_W * b_W / (1.0 - inner)) if inner < 1.0 else math.inf
    terms = SampledDataTerms(
        gain_E_w=gE, gain_Edot_w=gV, gain_u_w=gU, gain_E_angle=float(lin.gains.gains[0, 1]),
        gain_E_velocity=float(lin.gains.gains[0, 4]), angle_channel=lin.angle_channel,
        velocity_channel=lin.velocity_channel, initial_transient_E=lin.initial, friction_term=worst[0],
        P_term=worst[1], feedforward_hold_term=worst[2], C_V_term=worst[3], K_term=worst[4], gyro_term=worst[5],
        disturbance_term=worst[6], delta_u=delta_u, k_y=k_y, k_A=k_A, loop_gain=loop_gain, W=inf, U=inf,
        spectral_radius=lin.gains.spectral_radius)
    if not loop_gain < 1.0:
        return _Solved(x, y, inf, inf, inf, eps_a, inf, A_m, terms,
                       f"the sampled small gain fails: loop gain {loop_gain:.4g} >= 1")
    Wt = (r_W * a_W / (1.0 - inner) + h * q * (MU + c_hat * MV)) / (1.0 - loop_gain)
    W = (a_W + b_W * Wt) / (1.0 - inner)
    Es, Ys, U = ME + gE * Wt, MV + gV * Wt, MU + gU * Wt
    A2 = q * (U + c_hat * Ys + W)
    y_new = Ys + T * A2
    x_new = Es + T * Ys + 0.5 * T * T * A2
    eps_v = cart.velocity_error + lag * (a0dd + A2)
    return _Solved(x_new, y_new, U, W, A2, eps_a, eps_v, A_m, dataclasses.replace(terms, W=W, U=U), Wt=Wt)


def _fixed_point(step: Any, a0: float) -> tuple[_Solved | None, int, str]:
    """The least (x, y) with (x, y) = step(x, y), iterated from (0, 0) (each coordinate rises; ``step`` is
    increasing in both) by :func:`wmr_mj.analysis.claim.least_fixed_point`, checked not tangent: step at
    (x, y) (1 + h) lies below it; the step at the settled point returned."""
    def rise(v: tuple[float, ...]) -> tuple[tuple[float, ...], str]:
        s = step(*v)
        if s.failure:
            return v, f"no sampled-data bound: {s.failure}"
        if a0 + s.x >= 0.5 * math.pi:
            return v, f"no sampled-data bound: max|alpha0| + E_max reaches pi/2 (E_max = {s.x:.4g} rad)"
        return (s.x, s.y), ""

    def tangent(previous: tuple[float, ...], _settled: tuple[float, ...]) -> str:
        x, y = previous
        h = 1e-6
        bumped = step(x * (1.0 + h) + 1e-12, y * (1.0 + h) + 1e-12)
        if bumped.failure or not (bumped.x < x * (1.0 + h) + 1e-12 and bumped.y < y * (1.0 + h) + 1e-12):
            return tangent_reason(x)
        return ""

    point, k, reason = least_fixed_point(rise, 2, tangent=tangent, max_iterations=_ITERATIONS,
                                         what="no sampled-data bound")
    return (None, k, reason) if point is None else (step(*point), k, "")


def sampled_certificate(*, plant: PlantBox, estimate: Estimate, gains: Gains, reference: ReferenceBounds,
                        limits: PlantLimits, compensation: Compensation, control_period: float, cart: SampledCart,
                        initial_error: tuple[float, float] = (0.0, 0.0),
                        stated: Sequence[Assumption] = ()) -> Certificate:
    """The sampled-data certificate of the law (3.2)-(3.3) (or the PD law) on ``plant``, on the cart ``cart``.

    Args:
        plant, estimate, gains, reference, limits, compensation: as :func:`wmr_mj.analysis.small_gain.certify`.
        control_period: T, s (> 0).
        cart: the sampled cart (:class:`SampledCart`).
        initial_error: (E(0) rad, E'(0) rad/s). stated: the run's assumptions, appended.

    Returns:
        A :class:`~wmr_mj.analysis.claim_types.Certificate` whose region is a
        :class:`~wmr_mj.analysis.regions.BoxRegion` (E_max rad over all t, Edot_max rad/s), claimant
        :data:`SAMPLED_DATA`, its terms in ``inputs['terms']`` (:class:`SampledDataTerms`); ``valid`` False with
        the reason where the sampled loop is unstable, the small gain fails or the fixed point leaves pi/2.

    Raises:
        ParameterError: max|alpha0| unknown or >= pi/2, a control period that is not > 0.
    """
    if reference.alpha_max is None or not reference.alpha_max < 0.5 * math.pi:
        raise ParameterError(f"alpha0_max = {reference.alpha_max!r} rad: the sampled-data certificate needs a "
                             "max|alpha0| below pi/2")
    T = float(control_period)
    if not (math.isfinite(T) and T > 0.0):
        raise ParameterError(f"control_period = {control_period!r} s is not accepted; a period > 0 s is required")
    bound = _Bound.of(plant, estimate, gains, reference, compensation, reference.alpha_max)
    c_hat = estimate.C_V / estimate.P
    if not all(math.isfinite(v) for v in (cart.angle_error, cart.velocity_noise, cart.velocity_error,
                                           cart.velocity_lag)):
        return _invalid("a measurement error has no finite bound (Gaussian noise): no sampled-data bound", T, cart,
                        bound, c_hat, limits, initial_error, stated, reference)
    try:
        lin = _linear(bound, cart, T, c_hat)
    except ParameterError as exc:
        return _invalid(str(exc), T, cart, bound, c_hat, limits, initial_error, stated, reference)
    if not lin.gains.stable:
        return _invalid(f"the sampled loop is unstable: {lin.gains.reason}", T, cart, bound, c_hat, limits,
                        initial_error, stated, reference)
    width = compensation.friction_width
    solved, iterations, reason = _fixed_point(lambda x, y: _solve_at(bound, lin, cart, T, c_hat, x, y, width),
                                              bound.a0)
    if solved is None:
        return _invalid(reason, T, cart, bound, c_hat, limits, initial_error, stated, reference,
                        loop_gain=None)
    E_max, Edot_max = float(solved.x), float(solved.y)
    alpha_max = bound.a0 + E_max
    est = bound.estimate
    voltage_max = (est.P * (bound.P_ff / est.P * bound.a0dd + solved.U) + abs(est.C_V) * bound.a0d
                   + abs(est.K) * sin_cos3(solved.alpha_m) + bound.F_comp
                   + abs(bound.Gam_hat) * (bound.a0d + Edot_max + solved.eps_v)
                   / math.cos(solved.alpha_m) ** 2)
    assert solved.terms is not None
    assumptions = _assumptions(alpha_max=alpha_max, alpha_m=solved.alpha_m, voltage_max=voltage_max, limits=limits,
                               initial_error=initial_error, cart=cart, loop_gain=solved.terms.loop_gain,
                               radius=lin.gains.spectral_radius, reason="", iterations=iterations, stated=stated)
    inputs = SampledDataInputs(control_period=T, cart=cart, kp=bound.kp, kd=bound.kd, c_hat=c_hat,
                               friction_sign=bound.friction_sign, terms=solved.terms, reference=reference)
    return Certificate(region=BoxRegion(E_max=E_max, Edot_max=Edot_max), valid=True, assumptions=assumptions,
                       alpha_max=alpha_max, voltage_max=voltage_max, reason="", iterations=iterations,
                       inputs=ClaimInputs(law=inputs), claimant=SAMPLED_DATA)


def _assumptions(*, alpha_max: float, alpha_m: float, voltage_max: float, limits: PlantLimits,
                 initial_error: tuple[float, float], cart: SampledCart, loop_gain: float, radius: float, reason: str,
                 iterations: int, stated: Sequence[Assumption]) -> tuple[Assumption, ...]:
    valid = not reason
    shared = shared_assumptions(
        alpha_max=alpha_max, voltage_max=voltage_max, limits=limits, initial_error=initial_error,
        angle_equation="alpha_m,max = max|alpha0| + E_max + e_alpha < pi/2 (fixed point)",
        angle_met=valid and alpha_m < 0.5 * math.pi, angle_note=reason or f"{iterations} iterations",
        supply_equation="P^(|a0''| + sup|u|) + |C_V^||a0'| + |K^| S + F^ + |Gam^| sup|a_m'|/cos^2 <= voltage_limit",
        initial_equation="E(0) = E'(0) = 0, the estimator at rest")
    own = (
        Assumption("sampled loop stable", "spectral radius of the sampled loop < 1 (Jury)", radius < 1.0, radius, 1.0,
                   f"T, delays {cart.sensing_delay} + {cart.actuation_delay} periods, velocity {cart.velocity}",
                   kind="checked"),
        Assumption("sampled small gain", "delta_u g_u + k_y g_E' + (k_y T + k_A)(g_u + c^ g_E' + 1) < 1",
                   valid and loop_gain < 1.0, loop_gain, 1.0, "the nonlinear remainder through the sampled loop",
                   kind="checked"),
        Assumption(**coverage_assumption_fields(cart.measurement, SAMPLED_DATA, absorbs_electrical_lag=True)),
    )
    return (shared.reachable, shared.stops, shared.supply, shared.initial, *own, *stated)


def _invalid(reason: str, T: float, cart: SampledCart, bound: _Bound, c_hat: float, limits: PlantLimits,
             initial_error: tuple[float, float], stated: Sequence[Assumption], reference: ReferenceBounds,
             loop_gain: float | None = None) -> Certificate:
    inf = math.inf
    assumptions = _assumptions(alpha_max=inf, alpha_m=inf, voltage_max=inf, limits=limits,
                               initial_error=initial_error, cart=cart,
                               loop_gain=inf if loop_gain is None else loop_gain, radius=inf, reason=reason,
                               iterations=0, stated=stated)
    inputs = SampledDataInputs(control_period=T, cart=cart, kp=bound.kp, kd=bound.kd, c_hat=c_hat,
                               friction_sign=bound.friction_sign, terms=None, reference=reference)
    return Certificate(region=BoxRegion(E_max=inf, Edot_max=inf), valid=False, assumptions=assumptions,
                       alpha_max=inf, voltage_max=inf, reason=reason, inputs=ClaimInputs(law=inputs),
                       claimant=SAMPLED_DATA)
