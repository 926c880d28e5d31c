"""What a law reads instead of the true state: bounded measurement errors and a delay, as the
certificates take them (derivations in ``docs/guides/certificates.md``, "Measurement errors and delays").

A law reads alpha_m = alpha + e_a and alpha_m' = alpha' + e_v (the true state plus an error) with
|e_a| <= ``alpha_error_max`` and |e_v| <= ``alpha_dot_error_max``, and acts ``delay_s`` late (a
sensing delay, an actuation delay, or both: the sum). The error E = alpha0 - alpha is judged on the
true state. :func:`wmr_mj.analysis.certificate.certify` (``measurement=``) and the sliding-mode claim
(:meth:`controllers.sliding_mode.SlidingMode.claim`, through ``ClaimContext.measurement``) absorb
these bounds; where no bound is derived (Gaussian noise, backlash between the motor and an encoder on the
steering axis, an inductance or a current limit, which the proof's model has not) the caller passes
``covered=False`` with ``why_not``, and
the certificate gets the unmet assumption :data:`MEASUREMENT_COVERED`.

Usage::

    from wmr_mj.analysis.measurement import MeasurementErrors
    exact = MeasurementErrors.exact()                       # today's: every number unchanged
    encoder = MeasurementErrors(alpha_error_max=2 * math.pi / 4096 / 2, alpha_dot_error_max=1.5, delay_s=0.0)
    late = MeasurementErrors(alpha_error_max=0.0, alpha_dot_error_max=0.0, delay_s=0.005)
    gauss = MeasurementErrors(math.inf, 0.0, 0.0, covered=False, why_not="Gaussian noise on alpha has no bound")
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from wmr_mj._util.checks import finite_number
from wmr_mj.errors import ParameterError

__all__ = [
    "MeasurementErrors",
    "MEASUREMENT_COVERED",
    "DELAY_FIXED_POINT",
    "coverage_assumption_fields",
    "sin_cos3_slope",
    "inv_cos2_slope",
    "delayed_switching_bound",
]

#: Name of the assumption "every measurement and actuation error of the run has a derived bound".
MEASUREMENT_COVERED = "sensing and actuation covered"
#: Name of the assumption "the delay's terms close inside the certificate's fixed point".
DELAY_FIXED_POINT = "delay inside the fixed point"


@dataclass(frozen=True)
class MeasurementErrors:
    """Bounds on what a law reads instead of the true state (module docstring).

    Attributes:
        alpha_error_max: sup |alpha_m - alpha| [rad], >= 0 (quantisation Delta/2 or Delta, a
            uniform noise bound, a backlash half-width with the encoder on the far side); math.inf where
            the error has no bound (Gaussian noise), with ``covered`` False.
        alpha_dot_error_max: sup |alpha_m' - alpha'| [rad/s], >= 0 (a differenced velocity's error
            and lag, a filter's lag, a tachometer's noise bound).
        delay_s: the delay [s] >= 0 between the state and the voltage it produces (sensing plus
            actuation; the reference may be delayed by any part of it).
        covered: False where some error of the run has no derived bound; the certificate is then
            uncertified (assumption :data:`MEASUREMENT_COVERED`).
        why_not: what is not covered (required when ``covered`` is False).
        electrical_time_constant_s: the armature current's lag L_a/R_a [s] >= 0 (0: none). Bounded, but only a
            certificate whose loop holds the current absorbs it (the sampled-data one); any other claim leaves the
            run uncovered (:func:`coverage_assumption_fields`).

    Raises:
        ParameterError: a bound that is not a finite number >= 0, ``covered`` not a bool, or
            ``covered`` False without ``why_not``.
    """

    alpha_error_max: float
    alpha_dot_error_max: float
    delay_s: float
    covered: bool = True
    why_not: str | None = None
    electrical_time_constant_s: float = 0.0

    def __post_init__(self) -> None:
        for name in ("alpha_error_max", "alpha_dot_error_max", "delay_s", "electrical_time_constant_s"):
            unbounded = self.covered is False and getattr(self, name) == math.inf
            if name in ("alpha_error_max", "alpha_dot_error_max") and unbounded:
                continue  # an error with no bound (Gaussian noise) is infinite, and never covered
            object.__setattr__(self, name, finite_number(name, getattr(self, name), minimum=0.0))
        if not isinstance(self.covered, bool):
            raise ParameterError(f"covered = {self.covered!r} is not accepted: True or False")
        if not self.covered and not (isinstance(self.why_not, str) and self.why_not.strip()):
            raise ParameterError("covered = False needs why_not: a sentence naming what has no derived bound")

    @classmethod
    def exact(cls) -> MeasurementErrors:
        """The law reads the true state at once (today's runs): all bounds 0, covered."""
        return cls(alpha_error_max=0.0, alpha_dot_error_max=0.0, delay_s=0.0)

    @property
    def is_exact(self) -> bool:
        """No error, no delay, covered: the certificates are today's, bit for bit."""
        return (self.covered and self.alpha_error_max == 0.0 and self.alpha_dot_error_max == 0.0
                and self.delay_s == 0.0 and self.electrical_time_constant_s == 0.0)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the fields (the electrical time constant only where there is one: no key changes elsewhere)."""
        out = {"alpha_error_max": self.alpha_error_max, "alpha_dot_error_max": self.alpha_dot_error_max,
               "delay_s": self.delay_s, "covered": self.covered, "why_not": self.why_not}
        if self.electrical_time_constant_s:
            out["electrical_time_constant_s"] = self.electrical_time_constant_s
        return out


def coverage_assumption_fields(measurement: MeasurementErrors, claimant: str = "", *,
                               absorbs_electrical_lag: bool = False) -> dict[str, Any]:
    """The fields of the assumption :data:`MEASUREMENT_COVERED` (an ``Assumption(**fields)``).

    value 0 (covered) or 1 (not) against the limit 0; the note names what is missing. An armature inductance
    (``measurement.electrical_time_constant_s`` > 0) is covered only by a claim that ``absorbs_electrical_lag`` (its
    loop holds the current: the sampled-data certificate).
    """
    who = f"{claimant}: " if claimant else ""
    tau_e = measurement.electrical_time_constant_s
    why = [measurement.why_not] if not measurement.covered else []
    if tau_e and not absorbs_electrical_lag:
        why.append(f"the armature inductance (L_a/R_a = {tau_e * 1e3:.3g} ms) is not in this claim's motor model")
    covered = not why
    note = (f"{who}bounds |e_alpha| <= {measurement.alpha_error_max:.4g} rad, |e_alpha'| <= "
            f"{measurement.alpha_dot_error_max:.4g} rad/s, delay {measurement.delay_s:.4g} s"
            + (f", L_a/R_a {tau_e:.4g} s in the loop" if tau_e else ""))
    if not covered:
        note = f"{who}no bound derived: {'; '.join(str(w) for w in why)}"
    return dict(name=MEASUREMENT_COVERED, equation="every sensing and actuation error of the run has a derived bound",
                met=covered, value=0.0 if covered else 1.0, limit=0.0, note=note, kind="checked")


def sin_cos3_slope(alpha: float) -> float:
    """max |d/da sin(a)/cos^3(a)| over |a| <= alpha < pi/2: (1 + 2 sin^2 alpha)/cos^4 alpha (increasing)."""
    s, c = math.sin(alpha), math.cos(alpha)
    return (1.0 + 2.0 * s * s) / c ** 4


def inv_cos2_slope(alpha: float) -> float:
    """max |d/da 1/cos^2(a)| over |a| <= alpha < pi/2: 2 sin(alpha)/cos^3(alpha) (increasing)."""
    return 2.0 * math.sin(abs(alpha)) / math.cos(alpha) ** 3


def delayed_switching_bound(k: float, d_max: float, tau: float) -> float:
    """sup|s| for s' = -k sign(s(t - tau)) + d, |d| <= d_max < k, s = 0 on [-tau, 0]: (k + d_max) tau.

    While |s| <= (k + d_max) tau fails, s(t - tau) has the sign of s(t) (|s'| <= k + d_max moves s by
    at most (k + d_max) tau in tau), so s' = -k sign(s) + d drives |s| down: it cannot cross the level.

    Raises:
        ParameterError: a negative argument, or d_max >= k (no sliding).
    """
    k = finite_number("k", k, minimum=0.0, strict=True)
    d_max = finite_number("d_max", d_max, minimum=0.0)
    tau = finite_number("tau", tau, minimum=0.0)
    if d_max >= k:
        raise ParameterError(f"d_max = {d_max:g} >= k = {k:g}: the switching does not dominate, no bound")
    return (k + d_max) * tau
