"""Section 4 redone: the certificate for the controller actually run on the plant actually simulated.

A module of its own beside the other claims (:mod:`wmr_mj.analysis.claim`, a law's box claim), as
python-control keeps ``statesp`` and ``robust`` apart: :func:`certify` returns a
:class:`~wmr_mj.analysis.claim_types.Certificate` whose region is a
:class:`~wmr_mj.analysis.regions.SmallGainRegion` (4.21), whose terms are a
:class:`~wmr_mj.analysis.claim_types.SmallGainTerms` and whose inputs a :class:`SmallGainInputs`; it shares
the fixed point and the four run assumptions with :mod:`wmr_mj.analysis.claim`. Its public names are also
importable from :mod:`wmr_mj.analysis.certificate`, as they always were.

:mod:`wmr_mj.analysis.robustness` keeps the paper's region ("the paper's claim"). This module
redoes the section-4 analysis for the computed-torque law (3.2)-(3.3) *as it is run*
(its model source, its Coulomb compensation, its gains, its control period) against
the plant *as it is simulated* (stiction at rest, a gyroscopic term, no sin/cos^3
stiffness, the angle it actually reaches), and lists every assumption the bound rests
on with its number and whether it holds.

Plant and controller (voltage form, X~ = X - X^ truth minus estimate)::

    plant:  P a'' + C_V a' + f + K S(a) + Gam a'/cos^2(a) = u + d_V,   S(a) = sin(a)/cos^3(a)
            f = F sgn(a') while sliding, f anywhere in [-F, F] at rest (stiction)
            Gam = gyro V_A  (the non-holonomic plant: gyro = P/l1; wmr_mj.plant.reduced)
            d_V = R_a d/(k_i i2): a disturbance torque d [N m] on the steering joint, |d| <= d_max
    law:    u = P^ (a0'' + K_D E' + K_P E) + K^ S(a) + C_V^ a' + F^ s + Gam^ a'/cos^2(a)   (3.2)-(3.3)
            s: sgn(a') ('measured', exact or x/sqrt(x^2+w^2)), sgn(a0') ('reference'), 0 ('none')

With a'' = a0'' - E'' and a' = a0' - E' the error equation is (4.10) with::

    eta = (1 - P^/P)(K_D E' + K_P E)
          + P^-1 [P~ a0'' + (f - F^ s) + K~ S(a) + C~_V a0' + Gam~ a0'/cos^2(a) - (C~_V + Gam~/cos^2(a)) E']
          - d_V/P

so that, with alpha_max = max|a0| + E_max the largest reachable |a| (S and 1/cos^2 grow with |a|)::

    ||eta|| <= delta1 + delta2 ||E|| + delta3 ||E'||                                       (4.19)
    delta1 = max_P [ |P - P^| max|a0''| + phi + |K~| S(alpha_max) + |C~_V| max|a0'|
                     + |Gam~| max|a0'| / cos^2(alpha_max) + d_V,max ] / P                 (4.18)
    delta2 = max_P |1 - P^/P| K_P                              (coefficient of ||E||, corrected (4.20))
    delta3 = max |(1 - P^/P) K_D - (C~_V + Gam~/c2)/P|  over P, C~_V, Gam~ corners, c2 in {cos^2(alpha_max), 1}
    condition = gamma1 delta2 + gamma2 delta3 < 1                                         (4.23)
    E_max = gamma1 delta1 / (1 - condition),   Edot_max = gamma2 delta1 / (1 - condition)  (4.21)

(a PD controller has no feedforward: its a0'' term is |P - 0| max|a0''| / P = max|a0''|).

Disturbance torque (``PlantBox.disturbance`` = d_V,max; 0 leaves every number as it was). The
steering motor is MuJoCo's dcmotor (wmr_mj.plant.mjcf): at the joint it gives the torque
i2 k_i (u - k_b i2 a')/R_a. A torque d on the same joint adds to it, so dividing the joint's
equation J a'' + ... = i2 k_i u/R_a + ... + d by i2 k_i/R_a gives the voltage form (2.12) with
u + d_V, d_V = R_a d/(k_i i2) (the factor that gives P = (R_a/k_i) 2D/i2 and F = (R_a/(k_i i2))
tau_f, wmr_mj.params.C80Parameters.coefficients). In the error equation d_V enters as -d_V/P,
beside the other P^-1 terms, so |d| <= d_max adds d_V,max/P to delta1 at every P corner, with
d_V,max = d_max max(R_a)/min(k_i i2) over the box (:func:`wmr_mj.sim.certify.certificate_for`).
d_V and P move together as F and P do: d_V/P = d/(2D), which R_a, k_i, i2 leave alone, so with
r_d >= d_max/(2D) over the box (``PlantBox.disturbance_over_P``) the term at P is
min(d_V,max, r_d P)/P, and d_V,max/r_d joins the P corners (between corners each term stays of
the form A + B/P, monotone).
delta2, delta3 and (4.23) do not change; E_max and Edot_max grow with delta1 (linearly, but for
the fixed point on alpha_max). The supply assumption bounds the law's voltage, which d does not
enter. Check (tests/test_disturbance.py): the PD loop u = P^ (K_D E' + K_P E) on a plant with
F = K = 0 and a constant d settles, with a0 constant, at a'' = a' = 0, i.e. at
P^ K_P E_ss + d_V = 0: E_ss = -d_V/(P^ K_P). For critical damping gamma1 = 1/K_P, so with
P = P^ and nothing else uncertain the certificate's E_max = d_V/(P K_P) = |E_ss|: tight.

Time-varying chassis mass (load steps and ramps, :mod:`wmr_mj.sim.signals`). Of the plant's
coefficients only F (through the front axle's normal load Q) depends on m1: P (the steering
unit's inertia 2D), C_V and gyro = P/l1 do not (K, of the paper's model only, is not in the
plant: its band is stated). So m1(t) moves F(t) alone and no dP/dt a' term appears. Every bound
above is pointwise in t: |eta(t)| <= delta1 + delta2 |E(t)| + delta3 |E'(t)| holds at each t as
long as the plant's parameters at that t are in the box, and the L-infinity argument (4.17)-(4.21)
uses nothing else. So a run whose m1 steps or ramps between values inside the box keeps the
certificate of the box; an m1 outside it fails an assumption ("load inside the box"), as a
disturbance beyond the declared d_max does ("disturbance within the bound").

Friction term phi = sup |f - F^ s| over sliding and rest, by compensation mode:

* 'none' (F^ s = 0): |f| <= F at rest and sliding, phi = F_max.
* 'measured' (s = sgn a', exact or smoothed; |s| <= 1 with the sign of a'). Sliding:
  f - F^ s = sgn(a') (F - F^ |s|), so |.| <= max(F_max, F^ - F_min). At rest with s = 0
  (exact sign of a' = 0): |f| <= F_max. A joint that creeps (soft friction, or a sampled
  a' of a few urad/s) has s != 0 locked to the creep direction, which is the direction of
  the net drive tau + F^ s (tau: every other term); it sticks while |tau + F^ s| <= F, and
  then f - F^ s = tau with tau + F^ s of the sign of s, so -F^ |s| < tau sgn(s) <= F - F^ |s|:
  |f - F^ s| <= max(F^, F_max). Over all cases: phi = max(F_max, F^) (= F_max when
  F^ <= F_max, physics.md section 5).
* 'reference' (s = sgn a0', moving with the reference, not with the joint): f and s are
  independent, phi = F_max + F^ (physics.md section 5).

F and P move together. In volts F = (R_a/(k_i i2)) tau_f and P = (R_a/k_i) 2D/i2, so
F/P = tau_f/(2D) does not depend on R_a: a box where R_a is uncertain holds no plant with
F_max and P_min at once. With r >= F/P over the box (:func:`friction_over_P_max`) the
friction level at P is min(F_max, r P), and phi/P is taken per P rather than F_max/P_min.

gamma1 >= 1/K_P (the DC gain of 1/(s^2 + K_D s + K_P)), so no valid bound lies below
the static dead band F_max/(P^ K_P): with P = P^ and nothing else uncertain, E_max is
exactly F_max/(P^ K_P) for critical damping.

Reachable angle (fixed point). K~ S(a) and Gam~/cos^2(a) are bounded over the plant's
angle, |a| <= max|a0| + E_max, so E_max = Phi(E_max) with Phi(x) the bound above at
alpha_max = max|a0| + x. Phi is increasing; the iteration x <- Phi(x) from x = 0 rises to
the least fixed point x*. Along a run x(T) = sup_[0,T] |E| is continuous from 0 and
always satisfies x(T) <= Phi(x(T)), so it stays in [0, x*] provided Phi(x) < x just above
x* (checked: a tangent fixed point is refused). If the iteration reaches pi/2 or (4.23)
fails on the way, there is no certificate (``valid`` False, with the reason). The
paper's own (5.1) example (K~ = 0.09 V, (4.23) = 0.26204) moves from E_max = 0.105 rad
(sin/cos^3 = 1.24 at a0) to 0.1663 rad (alpha_max = 0.825 rad) under this alone.

Assumptions (each an :class:`Assumption` with its value, limit and whether it is met;
``verdict`` says "certified-*" only when all are met):

* (4.23) condition < 1;
* reachable angle: the fixed point exists, alpha_max < pi/2;
* steering stops: alpha_max = max|a0| + E_max < steering_range (else the stop's
  torque, outside the model, acts);
* supply: the voltage the law needs anywhere in the region,
  P^ (max|a0''| + K_D Edot_max + K_P E_max) + |K^| S(alpha_max) + |C_V^| (max|a0'| + Edot_max)
  + F^ + |Gam^| (max|a0'| + Edot_max)/cos^2(alpha_max) <= voltage_limit (the analysis
  has no saturation);
* control period (stated, not bounded): the analysis is continuous time; the sampled
  law holds u for T, a delay of at most T. The condition is T <= 0.1 x the loop's
  delay margin PM/omega_c (omega_c the crossover of (K_D s + K_P)/s^2, PM its phase
  margin), i.e. the hold costs at most a tenth of the phase margin;
* zero initial error (the bound (4.17) is for zero initial conditions);
* stated ones (``kind='stated'``) passed in by the caller, e.g. the plant's gyro band.

A run is inside when (sup|E|, sup|E'|) satisfies both inequalities of (4.21), the
region itself, which lies inside the rectangle E_max x Edot_max (a point of the
rectangle outside the region contradicts the bound as much as one beyond E_max).

Usage::

    from wmr_mj import C80
    from wmr_mj.analysis.certificate import (Compensation, Estimate, Gains, PlantBox, PlantLimits, certify,
                                             judge)   # or from wmr_mj.analysis.small_gain
    from wmr_mj.analysis.robustness import ParameterBox
    from wmr_mj.reference.bounds import ReferenceBounds
    box = ParameterBox(P=(0.385, 0.385), C_V=(4.77, 4.77), F=(1.313, 1.724), K=(-0.02, 0.02))
    cert = certify(plant=PlantBox(box=box, gyro=(0.472, 0.723), V_A=(0.2, 0.2)),
                   estimate=Estimate(P=0.385, C_V=4.77, F=1.518, K=0.0, gyro=0.629, V_A=0.2),
                   gains=Gains(kp=100.0, kd=20.0),
                   reference=ReferenceBounds(alpha_max=0.659, alpha_dot_max=0.23, alpha_ddot_max=0.155),
                   limits=PlantLimits(steering_range=0.9, voltage_limit=24.0),
                   compensation=Compensation(friction_sign="measured", friction_width=0.01),
                   control_period=0.001)
    cert.E_max, cert.Edot_max, cert.voltage_max     # 0.0463 rad, 0.341 rad/s, 8.8 V
    cert.verdict(0.031, 0.2)                         # 'certified-inside'
    judge(cert, 0.031, 0.2).E_ratio                  # a CertificateJudgement; .to_dict() for JSON

    from wmr_mj.sim.certify import certificate_for          # the certificate of a configured run
    from wmr_mj.sim.config import RunConfig, build_reference
    cfg = RunConfig(model="nonholonomic", kp=100.0, kd=20.0, friction_width=0.01)
    cert = certificate_for(cfg, build_reference("paper-circle", C80, dt=1e-3, duration=35.0)[0])
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from wmr_mj._util.checks import finite_number as _number
from wmr_mj.analysis.claim import fixed_point, shared_assumptions
from wmr_mj.analysis.claim_types import Assumption, Certificate, ClaimInputs, MeasurementCause, SmallGainTerms
from wmr_mj.analysis.measurement import (
    DELAY_FIXED_POINT,
    MeasurementErrors,
    coverage_assumption_fields,
    inv_cos2_slope,
    sin_cos3_slope,
)
from wmr_mj.analysis.plant_box import PlantBox, PlantLimits
from wmr_mj.analysis.regions import SmallGainRegion
from wmr_mj.analysis.robustness import _check_gains, exact_gammas
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.plant.reduced import FRICTION_SIGNS
from wmr_mj.reference.bounds import ReferenceBounds, sin_cos3

__all__ = [
    "Estimate",
    "Gains",
    "Compensation",
    "MEASURED_SIGN",
    "SmallGainInputs",
    "certify",
    "friction_term",
    "loop_crossover",
    "CONTROL_PERIOD_FRACTION",
]

#: The control period may use at most this fraction of the loop's delay margin.
CONTROL_PERIOD_FRACTION = 0.1
#: The measurement errors by the names the printout gives them, and their MeasurementErrors fields.
_ERRORS = (("e_a", "alpha_error_max"), ("e_v", "alpha_dot_error_max"), ("tau", "delay_s"))


# --------------------------------------------------------------------------- pieces
def friction_term(mode: str, *, F: tuple[float, float], F_hat: float) -> float:
    """phi = sup |f - F^ s| [V] over sliding and rest (stiction), by compensation mode.

    'measured' max(F_max, F^); 'none' F_max; 'reference' F_max + F^ (module docstring).
    """
    if mode not in FRICTION_SIGNS:
        raise UnknownNameError("friction sign", str(mode), FRICTION_SIGNS)
    F_max = float(F[1])
    if mode == "none":
        return F_max
    if mode == "measured":
        return max(F_max, abs(F_hat))
    return F_max + abs(F_hat)


def loop_crossover(kp: float, kd: float) -> tuple[float, float]:
    """(omega_c [rad/s], phase margin [rad]) of the loop (K_D s + K_P)/s^2 of (3.2).

    |K_D j w + K_P| = w^2: w^2 = K_D^2 (1 + sqrt(1 + 4 q^2))/2 with q = K_P/K_D^2
    (written to avoid overflow for extreme gains); PM = atan(K_D omega_c / K_P).
    """
    kp, kd = _check_gains(kp, kd)
    q = (kp / kd) / kd
    if q <= 1.0:
        wc = kd * math.sqrt(0.5 * (1.0 + math.sqrt(1.0 + 4.0 * q * q)))
    else:
        iq = 1.0 / q
        wc = math.sqrt(kp) * math.sqrt(0.5 * (iq + math.sqrt(iq * iq + 4.0)))
    return wc, math.atan2(kd, kp / wc)


# --------------------------------------------------------------------------- certify: inputs
@dataclass(frozen=True)
class Estimate:
    """The controller's estimate ^ of the plant (the law (3.2)-(3.3) uses these).

    Attributes:
        P: P^ [V s^2/rad], > 0.
        C_V: C_V^ [V s/rad].
        F: F^ [V], >= 0: the Coulomb compensation's amplitude (0 for 'none').
        K: K^ [V] (sin/cos^3).
        gyro: gyro^ [V s/m].
        V_A: V_A^ [m/s].

    Raises:
        ParameterError: a value that is not a finite number, P <= 0 or F < 0.
    """

    P: float
    C_V: float
    F: float
    K: float
    gyro: float
    V_A: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "P", _number("P_hat", self.P, minimum=0.0, strict=True))
        for name in ("C_V", "K", "gyro", "V_A"):
            object.__setattr__(self, name, _number(f"{name}_hat", getattr(self, name)))
        object.__setattr__(self, "F", _number("F_hat", self.F, minimum=0.0))


@dataclass(frozen=True)
class Gains:
    """The PD servo's gains of (3.2).

    Attributes:
        kp: K_P [1/s^2], > 0.
        kd: K_D [1/s], > 0.

    Raises:
        ParameterError: a gain that is not a finite normal number > 0.
    """

    kp: float
    kd: float

    def __post_init__(self) -> None:
        kp, kd = _check_gains(self.kp, self.kd)
        object.__setattr__(self, "kp", kp)
        object.__setattr__(self, "kd", kd)


@dataclass(frozen=True)
class Compensation:
    """How the law compensates Coulomb friction, and whether it has the feedforward P^ a0''.

    Attributes:
        friction_sign: the sign it multiplies F^ by: 'measured' (sgn a'), 'reference' (sgn a0')
            or 'none' (:data:`FRICTION_SIGNS`).
        friction_width: the sign's smoothing w [rad/s], >= 0 (recorded; the friction term covers
            any |s| <= 1).
        feedforward: False for a PD law without P^ a0'' (which has no compensation either).

    Raises:
        UnknownNameError: an unknown friction_sign.
        ParameterError: friction_width < 0, or compensation without feedforward.
    """

    friction_sign: str = "measured"
    friction_width: float = 0.0
    feedforward: bool = True

    def __post_init__(self) -> None:
        if self.friction_sign not in FRICTION_SIGNS:
            raise UnknownNameError("friction sign", str(self.friction_sign), FRICTION_SIGNS)
        object.__setattr__(self, "friction_width", _number("friction_width", self.friction_width, minimum=0.0))
        if not self.feedforward and self.friction_sign != "none":
            raise ParameterError("a law without feedforward (PD) has no Coulomb compensation: use friction_sign='none'")


#: The computed-torque law's compensation by default: the sign of the measured a', exact.
MEASURED_SIGN = Compensation()


# --------------------------------------------------------------------------- certify
def certify(
    *,
    plant: PlantBox,
    estimate: Estimate,
    gains: Gains,
    reference: ReferenceBounds,
    limits: PlantLimits,
    compensation: Compensation = MEASURED_SIGN,
    control_period: float,
    initial_error: tuple[float, float] = (0.0, 0.0),
    stated: Sequence[Assumption] = (),
    measurement: MeasurementErrors | None = None,
) -> Certificate:
    """The certificate for the law (3.2)-(3.3) with ``estimate`` on any plant of ``plant``.

    Args:
        plant: the plants covered (P, C_V, F, K ranges, gyro, V_A, and the bound on F/P).
        estimate: the controller's estimate ^ (F: the compensation's amplitude, 0 for 'none').
        gains: K_P [1/s^2], K_D [1/s].
        reference: the reference's bounds; alpha_max (max|alpha0|) [rad], alpha_dot_max [rad/s],
            alpha_ddot_max [rad/s^2] are read.
        limits: the plant's steering stops [rad] and supply [V].
        compensation: the law's friction sign and smoothing, and whether it has feedforward.
        control_period: the law's period [s], > 0.
        initial_error: (E(0) [rad], E'(0) [rad/s]).
        stated: the caller's stated assumptions, appended to the checked ones.
        measurement: bounds on what the law reads instead of the true state, and its delay
            (:class:`~wmr_mj.analysis.measurement.MeasurementErrors`); None or ``exact()``: today's
            certificate, bit for bit. Otherwise the terms of :class:`_Measured` enter delta1, delta2,
            delta3 inside the fixed point, and the assumptions 'sensing and actuation covered' and
            (with a delay) 'delay inside the fixed point' are appended after the checked ones.

    Returns:
        Certificate: E_max, Edot_max and every assumption with its value and limit; ``valid``
        False (E_max = inf, with the reason) when there is no bound. With
        ``plant.friction_over_P`` = r, delta1 is maximised over P in {P_min, P_max, P^, F_max/r,
        F^/r}: between these points each term of delta1 is monotone in P.

    Raises:
        ParameterError: a group of the wrong type, max|alpha0| unknown or >= pi/2, a control period
            or initial error that is not a finite number (> 0 for the period).
    """
    _check_groups(plant, estimate, gains, reference, limits, compensation)
    if reference.alpha_max is None:
        raise ParameterError("alpha0_max (the reference's max|alpha0|, ReferenceBounds.alpha_max) is required")
    a0 = reference.alpha_max
    if a0 >= 0.5 * math.pi:
        raise ParameterError(f"alpha0_max = {a0} rad is not accepted: the reference must stay below pi/2")
    control_period = _number("control_period", control_period, minimum=0.0, strict=True)
    E0, Ed0 = (_number("initial_error", v) for v in initial_error)

    bound = _Bound.of(plant, estimate, gains, reference, compensation, a0)
    if measurement is not None and not isinstance(measurement, MeasurementErrors):
        raise ParameterError(f"measurement must be a MeasurementErrors, got {type(measurement).__name__}")
    setting = _Setting(compensation=compensation, reference=reference, limits=limits, gains=gains,
                       control_period=control_period, initial_error=(E0, Ed0), stated=tuple(stated))
    if measurement is not None and not measurement.is_exact:
        return _certificate(_Measured(bound, measurement, compensation.friction_width), setting)
    return _certificate(_Exact(bound, compensation.friction_width), setting)


def _check_groups(plant: Any, estimate: Any, gains: Any, reference: Any, limits: Any, compensation: Any) -> None:
    for name, value, kind in (("plant", plant, PlantBox), ("estimate", estimate, Estimate), ("gains", gains, Gains),
                              ("reference", reference, ReferenceBounds), ("limits", limits, PlantLimits),
                              ("compensation", compensation, Compensation)):
        if not isinstance(value, kind):
            raise ParameterError(f"{name} must be a {kind.__name__}, got {type(value).__name__}")


@dataclass(frozen=True)
class _AtAngle:
    """The terms of the bound that grow with the plant's angle, at alpha_max.

    delta1 [rad/s^2], delta2 [1/s^2] (the bound's, which the angle leaves alone), delta3 [1/s], condition:
    the left side of (4.23), S = sin/cos^3(alpha_max) [-], c2 = cos^2(alpha_max) [-].
    """

    delta1: float
    delta2: float
    delta3: float
    condition: float
    S: float
    c2: float


@dataclass(frozen=True)
class _Bound:
    """The parts of (4.18)-(4.23) that do not depend on the angle reached: the mismatches, the
    corners of P and the friction term; :meth:`at` gives delta1, delta3 and (4.23) at alpha_max."""

    g1: float
    g2: float
    kp: float
    kd: float
    a0: float  # max|alpha0| [rad]
    a0d: float  # max|alpha0'| [rad/s]
    a0dd: float  # max|alpha0''| [rad/s^2]
    P_ff: float  # the feedforward's P^ (0 without feedforward) [V s^2/rad]
    P_hat: float
    P_corners: tuple[float, ...]
    mis: Mapping[float, float]  # 1 - P^/P at each corner
    delta2: float
    dC_lo: float
    dC_hi: float
    dC: float
    dK: float
    dG_lo: float
    dG_hi: float
    dG: float
    Gam_hat: float
    F_comp: float  # the compensation's amplitude, 0 for 'none' [V]
    estimate: Estimate
    plant: PlantBox
    friction_sign: str

    @classmethod
    def of(cls, plant: PlantBox, estimate: Estimate, gains: Gains, reference: ReferenceBounds,
           compensation: Compensation, a0: float) -> _Bound:
        kp, kd = gains.kp, gains.kd
        box, F_hat, friction_over_P = plant.box, estimate.F, plant.friction_over_P
        g1, g2 = exact_gammas(kp, kd)
        P_lo, P_hi = box.P
        P_hat = estimate.P
        P_corners = sorted({P_lo, P_hi, *([P_hat] if P_lo < P_hat < P_hi else [])})
        if friction_over_P is not None:
            breaks = (box.F[1] / friction_over_P, F_hat / friction_over_P)
            P_corners = sorted({*P_corners, *(b for b in breaks if P_lo < b < P_hi)})
        if plant.disturbance and plant.disturbance_over_P is not None:
            b = plant.disturbance / plant.disturbance_over_P
            P_corners = sorted({*P_corners, *([b] if P_lo < b < P_hi else [])})
        dC_lo, dC_hi = box.C_V[0] - estimate.C_V, box.C_V[1] - estimate.C_V
        Gam = [g * v for g in plant.gyro for v in plant.V_A]
        Gam_hat = estimate.gyro * estimate.V_A
        dG_lo, dG_hi = min(Gam) - Gam_hat, max(Gam) - Gam_hat
        mis = {p: 1.0 - P_hat / p for p in P_corners}  # 1 - P^/P
        return cls(
            g1=g1, g2=g2, kp=kp, kd=kd, a0=a0, a0d=reference.alpha_dot_max, a0dd=reference.alpha_ddot_max,
            P_ff=P_hat if compensation.feedforward else 0.0, P_hat=P_hat, P_corners=tuple(P_corners), mis=mis,
            delta2=max(abs(m) for m in mis.values()) * kp,
            dC_lo=dC_lo, dC_hi=dC_hi, dC=max(abs(dC_lo), abs(dC_hi)),
            dK=max(abs(box.K[0] - estimate.K), abs(box.K[1] - estimate.K)),
            dG_lo=dG_lo, dG_hi=dG_hi, dG=max(abs(dG_lo), abs(dG_hi)), Gam_hat=Gam_hat,
            F_comp=0.0 if compensation.friction_sign == "none" else F_hat, estimate=estimate, plant=plant,
            friction_sign=compensation.friction_sign,
        )

    def phi_at(self, p: float) -> float:
        """sup |f - F^ s| [V] for the plants with this P."""
        F, r = self.plant.box.F, self.plant.friction_over_P
        F_p = F[1] if r is None else min(F[1], r * p)
        return friction_term(self.friction_sign, F=(F[0], F_p), F_hat=self.estimate.F)

    def dist_at(self, p: float) -> float:
        """sup |d_V| [V] for the plants with this P (module docstring)."""
        d, r = self.plant.disturbance, self.plant.disturbance_over_P
        return d if r is None else min(d, r * p)

    @property
    def phi(self) -> float:
        """sup |f - F^ s| [V] over the box."""
        return max(self.phi_at(p) for p in self.P_corners)

    def at(self, alpha_max: float) -> _AtAngle:
        """delta1, delta3 and (4.23) with the plant's angle up to ``alpha_max`` [rad]."""
        S, c2 = sin_cos3(alpha_max), math.cos(alpha_max) ** 2
        rest = self.dK * S + self.dC * self.a0d + self.dG * self.a0d / c2
        if self.plant.disturbance:  # |d_V|/P beside the other terms (module docstring)
            delta1 = max((abs(p - self.P_ff) * self.a0dd + self.phi_at(p) + rest + self.dist_at(p)) / p
                         for p in self.P_corners)
        else:
            delta1 = max((abs(p - self.P_ff) * self.a0dd + self.phi_at(p) + rest) / p for p in self.P_corners)
        delta3 = max(abs(self.mis[p] * self.kd - (c + g / cc) / p)
                     for p in self.P_corners for c in (self.dC_lo, self.dC_hi) for g in (self.dG_lo, self.dG_hi)
                     for cc in (c2, 1.0))
        cond = self.g1 * self.delta2 + self.g2 * delta3
        return _AtAngle(delta1=delta1, delta2=self.delta2, delta3=delta3, condition=cond, S=S, c2=c2)

    def parts_at(self, S: float, c2: float, phi_at: Callable[[float], float],
                 ff: float = 0.0) -> tuple[tuple[str, float], ...]:
        """delta1's terms [rad/s^2] at the P corner where it is reached, so that they add up to it.

        Args:
            S: sin/cos^3 at the angle bound [-]. c2: cos^2 there [-].
            phi_at: the friction term [V] at P (the measured path's may count a wrong sign).
            ff: the delayed feedforward's term [V] (0 without a delay).

        Returns:
            ((name, value [rad/s^2]), ...): friction, P~, K~, C_V~, gyro, then the disturbance and the
            delayed reference where they are not 0.
        """
        rest = self.dK * S + self.dC * self.a0d + self.dG * self.a0d / c2
        dist = self.dist_at if self.plant.disturbance else (lambda p: 0.0)
        p = max(self.P_corners, key=lambda p: (abs(p - self.P_ff) * self.a0dd + phi_at(p) + rest + ff + dist(p)) / p)
        parts = [("friction", phi_at(p) / p), ("P~", abs(p - self.P_ff) * self.a0dd / p), ("K~", self.dK * S / p),
                 ("C_V~", self.dC * self.a0d / p), ("gyro", self.dG * self.a0d / c2 / p)]
        parts += [(name, v / p) for name, v in (("disturbance", dist(p)), ("delayed reference", ff)) if v]
        return tuple(parts)

    def E_max_at(self, x: float) -> float:
        """The bound on |E| [rad] at alpha_max = max|alpha0| + x: Phi(x) of the fixed point."""
        b = self.at(self.a0 + x)
        return self.g1 * b.delta1 / (1.0 - b.condition) if b.condition < 1.0 else math.inf

def _voltage_max(bound: _Bound, b: _AtAngle, E_max: float, Edot_max: float) -> float:
    """The voltage [V] the law asks for anywhere in the region (triangle inequality on (3.2)-(3.3))."""
    est = bound.estimate
    rate = bound.a0d + Edot_max
    return (est.P * (bound.P_ff / est.P * bound.a0dd + bound.kd * Edot_max + bound.kp * E_max)
            + abs(est.K) * b.S + abs(est.C_V) * rate + bound.F_comp + abs(bound.Gam_hat) * rate / b.c2)


@dataclass(frozen=True)
class _MeasuredAt:
    """The bound with the measurement terms at the candidate E_max = x (:meth:`_Measured.at`).

    delta1 [rad/s^2], delta2 [1/s^2], delta3 [1/s], condition: (4.18)-(4.23) with the terms in;
    delta1_exact: today's delta1 at the same angle; S, c2: sin/cos^3 and cos^2 of the true angle bound;
    alpha_m [rad]: the bound on the measured angle; eps_alpha [rad]: the law's angle error (static plus
    the delay's); rho [-]: tau c_v, the delay's velocity-error loop; c_v [1/s], c_a [1/s^2]: the
    coefficients of the velocity and angle errors in |w|; failure: why there is no bound ('' if there is).
    """

    delta1: float
    delta2: float
    delta3: float
    condition: float
    delta1_exact: float
    S: float
    c2: float
    alpha_m: float
    eps_alpha: float
    rho: float
    c_v: float
    c_a: float
    failure: str = ""


@dataclass(frozen=True)
class _Measured:
    """The section-4 bound for a law that reads alpha + e_a, alpha' + e_v and acts tau late.

    With the law's inputs off by e_a, e_v the error equation E'' + K_D E' + K_P E = w gains
    (P^ (K_P e_a + K_D e_v) + C_V^ e_v + K^ (S(a_m) - S(a)) + Gam^ (a_m'/cos^2 a_m - a'/cos^2 a)
    + F^ (s(a_m') - s(a')))/P, bounded per unit error by c_a = (P^ K_P + |K^| S'(alpha_m)
    + |Gam^| (2 sin/cos^3)(alpha_m) (max|a0'| + |E'|))/P_min and c_v = (P^ K_D + |C_V^| + |Gam^|/cos^2
    alpha_m)/P_min; the compensation's sign from a measured a' may be wrong, so the friction term is
    F_max + F^ (smoothed sign, no delay: max(F_max, F^) + F^ min(2, e_v/w), whichever is less).
    A delay tau adds e_a <= tau (max|a0'| + |E'|), e_v <= tau (max|a0''| + K_P |E| + K_D |E'| + |w|) and,
    where the reference is delayed with the law, the feedforward's 2 P^ max|a0''|; |w| appears on both
    sides and is solved for with rho = tau c_v < 1. Derivation: docs/guides/certificates.md.
    """

    bound: _Bound
    measurement: MeasurementErrors
    friction_width: float

    def _phi_at(self, p: float, flip: bool) -> float:
        b = self.bound
        base = b.phi_at(p)
        if not flip:
            return base
        F, r = b.plant.box.F, b.plant.friction_over_P
        cap = (F[1] if r is None else min(F[1], r * p)) + b.F_comp  # |f| <= F, |s| <= 1 of either sign
        m = self.measurement
        if m.delay_s == 0.0 and self.friction_width > 0.0:  # x/sqrt(x^2+w^2) is 1/w-Lipschitz
            return min(cap, base + b.F_comp * min(2.0, m.alpha_dot_error_max / self.friction_width))
        return cap

    def at(self, x: float) -> _MeasuredAt:
        """The terms with |E| <= x and |E'| <= (gamma2/gamma1) x (the region's corner), x [rad]."""
        b, m = self.bound, self.measurement
        tau = m.delay_s
        A = b.a0 + x
        y = b.g2 / b.g1 * x
        rate = b.a0d + y
        eps_a = m.alpha_error_max + tau * rate
        A_m = A + eps_a
        inf = math.inf
        if A >= 0.5 * math.pi or A_m >= 0.5 * math.pi:
            exact = b.at(min(A, 0.5 * math.pi))  # the true angle's terms, finite: an invalid certificate shows them
            return _MeasuredAt(inf, inf, inf, inf, exact.delta1, exact.S, exact.c2, A_m, eps_a, inf, inf, inf,
                               (f"the measured angle reaches pi/2 (max|alpha0| + E_max + e_alpha = {A_m:.4g} rad)"
                                if math.isfinite(A_m) else "the measured angle's error e_alpha is unbounded (no bound "
                                "derived)"))
        exact = b.at(A)
        est, P_lo = b.estimate, b.P_corners[0]
        c2_m = math.cos(A_m) ** 2
        c_v = (b.P_hat * b.kd + abs(est.C_V) + abs(b.Gam_hat) / c2_m) / P_lo
        c_a = (b.P_hat * b.kp + abs(est.K) * sin_cos3_slope(A_m) + abs(b.Gam_hat) * inv_cos2_slope(A_m) * rate) / P_lo
        rho = c_v * tau
        if rho >= 1.0:
            return _MeasuredAt(inf, inf, inf, inf, exact.delta1, exact.S, exact.c2, A_m, eps_a, rho, c_v, c_a,
                               f"tau c_v = {tau:g} s x {c_v:.4g} 1/s = {rho:.4g} >= 1: the delayed velocity's error "
                               "feeds back on itself")
        flip = b.friction_sign == "measured" and (m.alpha_dot_error_max > 0.0 or tau > 0.0)
        ff = 2.0 * b.P_ff * b.a0dd if tau > 0.0 else 0.0  # a0''(t - tau) - a0''(t), no jerk bound [V]
        rest = b.dK * exact.S + b.dC * b.a0d + b.dG * b.a0d / exact.c2
        delta1_0 = max((abs(p - b.P_ff) * b.a0dd + self._phi_at(p, flip) + rest + ff
                        + (b.dist_at(p) if b.plant.disturbance else 0.0)) / p for p in b.P_corners)
        q = 1.0 / (1.0 - rho)
        delta1 = (delta1_0 + c_a * (m.alpha_error_max + tau * b.a0d) + c_v * (m.alpha_dot_error_max + tau * b.a0dd)) * q
        delta2 = (b.delta2 + rho * b.kp) * q
        delta3 = (exact.delta3 + c_a * tau + rho * b.kd) * q
        cond = b.g1 * delta2 + b.g2 * delta3
        return _MeasuredAt(delta1, delta2, delta3, cond, exact.delta1, exact.S, exact.c2, A_m, eps_a, rho, c_v, c_a)

    def eps_alpha_dot(self, at: _MeasuredAt, E_max: float, Edot_max: float) -> float:
        """The law's velocity error [rad/s] in the region: static plus tau sup|a''|."""
        b, m = self.bound, self.measurement
        w = at.delta1 + at.delta2 * E_max + at.delta3 * Edot_max
        return m.alpha_dot_error_max + m.delay_s * (b.a0dd + b.kp * E_max + b.kd * Edot_max + w)

    def voltage_max(self, at: _MeasuredAt, E_max: float, Edot_max: float) -> float:
        """The law's |u| bound [V] in the region, with its inputs off by e_alpha, e_alpha'."""
        b, est = self.bound, self.bound.estimate
        eps_v = self.eps_alpha_dot(at, E_max, Edot_max)
        rate = b.a0d + Edot_max + eps_v
        return (est.P * (b.P_ff / est.P * b.a0dd + b.kd * (Edot_max + eps_v) + b.kp * (E_max + at.eps_alpha))
                + abs(est.K) * sin_cos3(at.alpha_m) + abs(est.C_V) * rate + b.F_comp
                + abs(b.Gam_hat) * rate / math.cos(at.alpha_m) ** 2)

    def solve(self) -> tuple[float, int, str]:
        """The fixed point E_max [rad] with the measurement terms in, its iterations, and why there is none."""
        failures: list[str] = []

        def phi(x: float) -> float:
            at = self.at(x)
            if at.failure or at.condition >= 1.0:
                failures.append(at.failure or f"(4.23) with the measurement terms = {at.condition:.4g} >= 1 at "
                                              f"E_max = {x:.4g} rad")
                return math.inf
            return self.bound.g1 * at.delta1 / (1.0 - at.condition)

        E_max, iterations, reason = fixed_point(phi, self.bound.a0)
        if not math.isfinite(E_max) and failures:
            reason = "no fixed point with the measurement terms: " + failures[-1]
        return E_max, iterations, reason

    def own_assumptions(self, at: _MeasuredAt, valid: bool, reason: str) -> tuple[Assumption, ...]:
        """'sensing and actuation covered', and with a delay 'delay inside the fixed point'."""
        m = self.measurement
        own = [Assumption(**coverage_assumption_fields(m))]
        if m.delay_s > 0.0:
            own.append(Assumption(
                DELAY_FIXED_POINT, "tau c_v < 1 and a fixed point with |a(t-tau) - a(t)| <= tau sup|a'|, "
                "|a'(t-tau) - a'(t)| <= tau sup|a''| inside it", valid and at.rho < 1.0,
                at.rho if valid else math.inf, 1.0,  # without a fixed point there is no rho to show as met
                f"tau = {m.delay_s:g} s, c_v = {at.c_v:.4g} 1/s" + (f"; {reason}" if not valid else ""),
                kind="checked"))
        return tuple(own)

    def record(self, at: _MeasuredAt, E_max: float, Edot_max: float) -> dict[str, Any]:
        """The measurement's bounds and the errors they give in the region (``inputs['measurement']``)."""
        eps_v = self.eps_alpha_dot(at, E_max, Edot_max) if math.isfinite(E_max) else math.inf
        return {**self.measurement.to_dict(), "eps_alpha": at.eps_alpha, "eps_alpha_dot": eps_v,
                "alpha_m_max": at.alpha_m, "rho": at.rho, "c_v": at.c_v, "c_a": at.c_a}

    @staticmethod
    def measurement_term(at: _MeasuredAt) -> float:
        """The measurement's part of delta1 [rad/s^2]."""
        return at.delta1 - at.delta1_exact

    def delta1_parts(self, at: _MeasuredAt) -> tuple[tuple[str, float], ...]:
        """Every term of delta1 [rad/s^2] (:meth:`at`'s sum, term by term); () where it is not finite."""
        if at.failure or not math.isfinite(at.delta1):
            return ()
        b, m = self.bound, self.measurement
        tau = m.delay_s
        flip = b.friction_sign == "measured" and (m.alpha_dot_error_max > 0.0 or tau > 0.0)
        ff = 2.0 * b.P_ff * b.a0dd if tau > 0.0 else 0.0
        inner = [*b.parts_at(at.S, at.c2, lambda p: self._phi_at(p, flip), ff),
                 ("angle error e_a", at.c_a * m.alpha_error_max),
                 ("velocity error e_v", at.c_v * m.alpha_dot_error_max)]
        if tau > 0.0:
            inner.append(("delay tau", at.c_a * tau * b.a0d + at.c_v * tau * b.a0dd))
            inner.append(("delay loop 1/(1 - tau c_v)", at.rho / (1.0 - at.rho) * math.fsum(v for _, v in inner)))
        return tuple(inner)

    def cause(self, valid: bool) -> MeasurementCause:
        """The errors assumed and, without a fixed point, the fixed point re-solved with each set to 0 alone
        and with none of them: which error binds."""
        m = self.measurement
        if valid:
            return MeasurementCause(e_a=m.alpha_error_max, e_v=m.alpha_dot_error_max, tau=m.delay_s)
        without = []
        for name, field_name in _ERRORS:
            if getattr(m, field_name) != 0.0:
                zeroed = MeasurementErrors(**{**m.to_dict(), field_name: 0.0})
                path: _Path = (_Exact(self.bound, self.friction_width) if zeroed.is_exact
                               else _Measured(self.bound, zeroed, self.friction_width))
                without.append((name, path.solve()[0]))
        exact = _Exact(self.bound, self.friction_width).solve()[0]
        return MeasurementCause(e_a=m.alpha_error_max, e_v=m.alpha_dot_error_max, tau=m.delay_s,
                                E_max_without=tuple(without), E_max_exact=exact)


@dataclass(frozen=True)
class _Exact:
    """The section-4 bound for a law that reads the true state at once (:class:`_Measured`'s counterpart)."""

    bound: _Bound
    friction_width: float

    def solve(self) -> tuple[float, int, str]:
        """The fixed point E_max [rad], its iterations, and why there is none."""
        E_max, iterations, reason = fixed_point(self.bound.E_max_at, self.bound.a0)
        if not math.isfinite(E_max):
            cond = self.at(0.0).condition
            if cond >= 1.0:
                reason = f"(4.23) fails: gamma1 delta2 + gamma2 delta3 = {cond:.4g} >= 1 already at alpha = max|alpha0|"
        return E_max, iterations, reason

    def at(self, x: float) -> _AtAngle:
        """The bound's terms at alpha_max = max|alpha0| + x, x [rad]."""
        return self.bound.at(self.bound.a0 + x)

    def voltage_max(self, at: _AtAngle, E_max: float, Edot_max: float) -> float:
        return _voltage_max(self.bound, at, E_max, Edot_max)

    @staticmethod
    def own_assumptions(at: _AtAngle, valid: bool, reason: str) -> tuple[Assumption, ...]:
        return ()

    @staticmethod
    def record(at: _AtAngle, E_max: float, Edot_max: float) -> None:
        return None

    @staticmethod
    def measurement_term(at: _AtAngle) -> float:
        return 0.0

    def delta1_parts(self, at: _AtAngle) -> tuple[tuple[str, float], ...]:
        """Every term of delta1 [rad/s^2] at the corner where it is reached."""
        return self.bound.parts_at(at.S, at.c2, self.bound.phi_at)

    @staticmethod
    def cause(valid: bool) -> None:
        return None


@dataclass(frozen=True)
class _Setting:
    """What :func:`certify` checks the bound against, beside the bound itself (its arguments, checked)."""

    compensation: Compensation
    reference: ReferenceBounds
    limits: PlantLimits
    gains: Gains
    control_period: float
    initial_error: tuple[float, float]
    stated: tuple[Assumption, ...]


class _Path(Protocol):
    """One way to the bound (:class:`_Exact`, :class:`_Measured`); ``at`` is its terms at E_max = x."""

    @property
    def bound(self) -> _Bound: ...

    @property
    def friction_width(self) -> float: ...

    def solve(self) -> tuple[float, int, str]: ...

    def at(self, x: float) -> Any: ...

    def voltage_max(self, at: Any, E_max: float, Edot_max: float) -> float: ...

    def own_assumptions(self, at: Any, valid: bool, reason: str) -> tuple[Assumption, ...]: ...

    def record(self, at: Any, E_max: float, Edot_max: float) -> dict[str, Any] | None: ...

    def measurement_term(self, at: Any) -> float: ...

    def delta1_parts(self, at: Any) -> tuple[tuple[str, float], ...]: ...

    def cause(self, valid: bool) -> MeasurementCause | None: ...


def _certificate(path: _Path, setting: _Setting) -> Certificate:
    """The certificate of either path (exact or measured): the fixed point, the corner (4.21), the law's
    voltage, the assumptions, and the terms of delta1, each written once."""
    bound = path.bound
    E_max, iterations, reason = path.solve()
    valid = math.isfinite(E_max)
    at = path.at(E_max if valid else 0.0)
    alpha_max = bound.a0 + E_max if valid else math.inf
    Edot_max = bound.g2 * at.delta1 / (1.0 - at.condition) if valid else math.inf
    voltage_max = path.voltage_max(at, E_max, Edot_max) if valid else math.inf
    assumptions = _assumptions(cond=at.condition, valid=valid, alpha_max=alpha_max, reason=reason,
                               iterations=iterations, voltage_max=voltage_max, setting=setting,
                               own=path.own_assumptions(at, valid, reason))
    P_lo, corners = bound.P_corners[0], bound.P_corners
    terms = SmallGainTerms(
        friction_term=max(bound.phi_at(p) / p for p in corners), gyro_term=bound.dG * bound.a0d / at.c2 / P_lo,
        K_term=bound.dK * at.S / P_lo, P_term=max(abs(p - bound.P_ff) / p for p in corners) * bound.a0dd,
        C_V_term=bound.dC * bound.a0d / P_lo, gyro_Edot_term=bound.dG / at.c2 / P_lo,
        dead_band=bound.plant.box.F[1] / (bound.estimate.P * bound.kp),
        disturbance_term=max(bound.dist_at(p) / p for p in corners) if bound.plant.disturbance else 0.0,
        measurement_term=path.measurement_term(at),
        kp=bound.kp, kd=bound.kd, friction_sign=bound.friction_sign, friction_width=path.friction_width,
        delta1_parts=path.delta1_parts(at), measurement_cause=path.cause(valid))
    inputs = SmallGainInputs(plant=bound.plant, estimate=bound.estimate, compensation=setting.compensation,
                             reference=setting.reference, limits=setting.limits,
                             control_period=setting.control_period, initial_error=setting.initial_error,
                             friction_amplitude_phi=bound.phi,
                             measurement=path.record(at, E_max, Edot_max))
    region = SmallGainRegion(gamma1=bound.g1, gamma2=bound.g2, delta1=at.delta1, delta2=at.delta2,
                             delta3=at.delta3, E_max=E_max, Edot_max=Edot_max)
    return Certificate(region=region, valid=valid, assumptions=assumptions, alpha_max=alpha_max,
                       voltage_max=voltage_max, terms=terms, reason=reason, iterations=iterations,
                       inputs=ClaimInputs(law=inputs))


#: How section 4 words three of the four assumptions it shares with every claim
#: (:func:`wmr_mj.analysis.claim.shared_assumptions`): its fixed point, its voltage bound, (4.17).
_ANGLE_EQUATION = "alpha_max = max|alpha0| + E_max(alpha_max) < pi/2 (fixed point)"
_SUPPLY_EQUATION = ("P^(|a0''| + K_D Edot_max + K_P E_max) + |K^| S + |C_V^||a'| + F^ + |Gam^||a'|/cos^2 "
                    "<= voltage_limit")
_INITIAL_EQUATION = "E(0) = E'(0) = 0 ((4.17) is for zero initial conditions)"


def _assumptions(*, cond: float, valid: bool, alpha_max: float, reason: str, iterations: int, voltage_max: float,
                 setting: _Setting, own: Sequence[Assumption]) -> tuple[Assumption, ...]:
    """(4.23), the shared four with the control period before the initial error, then ``own`` (the
    measurement's), then the caller's stated ones (each an :class:`Assumption`)."""
    gains, control_period = setting.gains, setting.control_period
    wc, pm = loop_crossover(gains.kp, gains.kd)
    delay_margin = pm / wc
    period_ratio = control_period * wc / pm if pm > 0.0 else math.inf  # no phase margin: no delay tolerated
    shared = shared_assumptions(alpha_max=alpha_max, voltage_max=voltage_max, limits=setting.limits,
                                initial_error=setting.initial_error, angle_equation=_ANGLE_EQUATION,
                                angle_met=valid, angle_note=reason or f"{iterations} iterations",
                                supply_equation=_SUPPLY_EQUATION, initial_equation=_INITIAL_EQUATION)
    assumptions = (
        Assumption("(4.23) small gain", "gamma1 delta2 + gamma2 delta3 < 1 (4.23)", cond < 1.0, cond, 1.0,
                   "at alpha_max" if valid else "at alpha = max|alpha0|"),
        shared.reachable,
        shared.stops,
        shared.supply,
        Assumption("control period", f"T <= {CONTROL_PERIOD_FRACTION:g} x delay margin PM/omega_c "
                   "(continuous-time analysis; stated, not bounded)", period_ratio <= CONTROL_PERIOD_FRACTION,
                   period_ratio, CONTROL_PERIOD_FRACTION,
                   f"T = {control_period:g} s, omega_c = {wc:.4g} rad/s, PM = {math.degrees(pm):.1f} deg, "
                   f"delay margin {delay_margin:.4g} s"),
        shared.initial,
        *own,
        *setting.stated,
    )
    for a in assumptions:
        if not isinstance(a, Assumption):
            raise ParameterError(f"stated assumptions must be Assumption records, got {type(a).__name__}")
    return assumptions


@dataclass(frozen=True, kw_only=True)
class SmallGainInputs:
    """What section 4's certificate rests on; :meth:`to_dict` is its JSON ``inputs`` (keys as they have
    always been).

    Attributes:
        plant: the plants covered. estimate: the law's estimate. compensation: its friction sign and whether
        it has feedforward. reference: the reference's bounds [rad, rad/s, rad/s^2]. limits: the steering stops
        [rad] and supply [V]. control_period [s]. initial_error: (E(0) [rad], E'(0) [rad/s]).
        friction_amplitude_phi: sup |f - F^ s| over the box [V]. measurement: the measurement's bounds and
        the errors they give in the region (None: exact measurement).
    """

    plant: PlantBox
    estimate: Estimate
    compensation: Compensation
    reference: ReferenceBounds
    limits: PlantLimits
    control_period: float
    initial_error: tuple[float, float]
    friction_amplitude_phi: float
    measurement: Mapping[str, Any] | None = None

    def to_dict(self) -> dict[str, Any]:
        """The JSON record (not cleaned of inf: :meth:`Certificate.to_dict` does it)."""
        plant, estimate, ref = self.plant, self.estimate, self.reference
        out = {
            "box": plant.box.to_dict(), "gyro": list(plant.gyro), "V_A": list(plant.V_A),
            "estimate": {"P": estimate.P, "C_V": estimate.C_V, "F": estimate.F, "K": estimate.K,
                         "gyro": estimate.gyro, "V_A": estimate.V_A},
            "feedforward": bool(self.compensation.feedforward),
            "reference": {"alpha0_max": ref.alpha_max, "alpha0_dot_max": ref.alpha_dot_max,
                          "alpha0_ddot_max": ref.alpha_ddot_max},
            "steering_range": self.limits.steering_range, "voltage_limit": self.limits.voltage_limit,
            "control_period": self.control_period, "initial_error": list(self.initial_error),
            "friction_amplitude_phi": self.friction_amplitude_phi,
            **({"disturbance_V": plant.disturbance, "disturbance_over_P": plant.disturbance_over_P}
               if plant.disturbance else {}),
        }
        if self.measurement is not None:
            out["measurement"] = dict(self.measurement)
        return out
