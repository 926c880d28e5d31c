"""The Cartesian correction: an outer loop at point C that corrects alpha0 from C's path errors.

The inner loop (the computed-torque law) tracks alpha0(t); its certificate bounds |E| = |alpha0 - alpha|
and says nothing about where C goes (:mod:`wmr_mj.analysis.path_bound`: no Cartesian guarantee on
a straight or a varying curvature). This outer loop closes the loop on C's position, in the style
of Stanley's law applied at the steering pivot C (C is the front wheel's pivot, so the law is the
front-axle one): every ``period_s`` it projects C on its desired path (cross-track e [m], > 0
left; heading error psi [rad], the chassis heading minus the desired one) and asks for

    delta_cmd = clip(-k_e e - k_psi psi, +-delta_max).

delta_cmd is not applied as a step: a critically damped second-order filter (natural frequency
``bandwidth``) tracks it with |delta'| <= rate_max and |delta''| <= acc_max, integrated exactly
at the control period with delta'' held over each control step, so the law's reference
alpha0 + delta, alpha0' + delta', alpha0'' + delta'' is consistent. The certificate of a run
with the correction is computed for the corrected reference (:func:`corrected_bounds`:
max|alpha0| + delta_max, max|alpha0'| + rate_max, max|alpha0''| + acc_max), so the inner loop's
certificate holds for it.

Assumptions this adds (each in the certificate's assumptions list, :func:`correction_assumptions`):

- the corrected reference stays within the declared limits: |delta| <= delta_max, |delta'| <=
  rate_max, |delta''| <= acc_max (met by construction: the filter clips; checked on the run's rows);
- C's position and the chassis heading are measured, without noise, one control step before
  each outer update (the simulation's site C and chassis yaw), and held over the outer period;
- C's desired path is known as the reference's polyline; the projection searches 0.1 m of arc
  length around the previous one (a figure eight's crossing cannot make it jump);
- the correction starts at zero (delta = delta' = 0 at t = 0), so the certificate's initial
  error is the uncorrected one;
- the outer loop has no integral action: on a circle C keeps a cross-track offset of about
  E_ss / k_e (E_ss the inner loop's steady steering error); the along-track (timing) error is
  not corrected.

Usage::

    RunConfig(..., correction=True)              # wmr-mj run/sweep --correction
    CartesianCorrection(reference, period=0.001) # what the engine steps (wmr_mj.sim.engine)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from wmr_mj.analysis.certificate import Assumption
from wmr_mj.analysis.path_error import PathProjector, wrap_angle
from wmr_mj.errors import ParameterError
from wmr_mj.reference.bounds import ReferenceBounds

__all__ = ["CorrectionGains", "CartesianCorrection", "DEFAULT_GAINS", "corrected_bounds", "correction_assumptions"]


@dataclass(frozen=True)
class CorrectionGains:
    """The outer loop's gains and the limits the certificate is computed with.

    k_e [rad/m]: cross-track gain; k_psi [-]: heading-error gain; delta_max [rad]: |correction|;
    rate_max [rad/s]: |correction'|; acc_max [rad/s^2]: |correction''|; bandwidth [rad/s]: the
    filter's natural frequency; period_s [s]: the outer loop's period.
    """

    k_e: float = 4.0
    k_psi: float = 0.5
    delta_max: float = 0.1
    rate_max: float = 0.05
    acc_max: float = 0.1
    bandwidth: float = 2.0
    period_s: float = 0.05

    def __post_init__(self) -> None:
        for name in ("k_e", "k_psi", "delta_max", "rate_max", "acc_max", "bandwidth", "period_s"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0.0):
                raise ParameterError(f"correction {name} = {v!r} is not accepted: a finite number >= 0")
        if self.period_s <= 0.0 or self.bandwidth <= 0.0:
            raise ParameterError("correction period_s and bandwidth must be > 0")


DEFAULT_GAINS = CorrectionGains()


def corrected_bounds(bounds: ReferenceBounds, gains: CorrectionGains = DEFAULT_GAINS) -> ReferenceBounds:
    """The reference bounds the certificate assumes with the correction on: each plus its limit.

    sin(a)/cos^3(a) rises with |a| on [0, pi/2), so its max at max|alpha0| + delta_max bounds it.
    """
    if bounds.alpha_max is None:
        raise ParameterError("the correction needs the reference's max|alpha0| (ReferenceBounds.alpha_max)")
    a = bounds.alpha_max + gains.delta_max
    if a >= 0.5 * math.pi:
        raise ParameterError(f"max|alpha0| + delta_max = {a:.4g} rad reaches pi/2")
    return ReferenceBounds(alpha_max=a, alpha_dot_max=bounds.alpha_dot_max + gains.rate_max,
                           alpha_ddot_max=bounds.alpha_ddot_max + gains.acc_max,
                           sin_cos3_max=max(bounds.sin_cos3_max, math.sin(a) / math.cos(a) ** 3))


def correction_assumptions(gains: CorrectionGains = DEFAULT_GAINS) -> tuple[Assumption, ...]:
    """The assumptions the correction adds to the certificate (kind 'stated': met by construction)."""
    g = gains
    return (
        Assumption("correction limits", f"|delta| <= {g.delta_max:g} rad, |delta'| <= {g.rate_max:g} rad/s, "
                   f"|delta''| <= {g.acc_max:g} rad/s^2 (added to max|alpha0|, max|alpha0'|, max|alpha0''|)",
                   True, 0.0, 0.0, "the rate- and acceleration-limited filter clips; the certificate is "
                   "computed for the corrected reference's bounds", kind="stated"),
        Assumption("correction measurement", f"C's xy and the chassis heading measured exactly, one control step "
                   f"before each outer update, held {g.period_s:g} s", True, 0.0, 0.0,
                   "the simulation's site C and chassis yaw; no noise, no delay beyond one control step",
                   kind="stated"),
        Assumption("correction path", "C's desired path known (the reference's polyline); projection within "
                   "0.1 m of arc length of the previous one", True, 0.0, 0.0,
                   "wmr_mj.analysis.path_error.PathProjector", kind="stated"),
        Assumption("correction start", "delta = delta' = 0 at t = 0: the initial error is the uncorrected one",
                   True, 0.0, 0.0, "", kind="stated"),
    )


class CartesianCorrection:
    """The outer loop of one run: ``update`` gives the next block's delta, delta', delta''."""

    def __init__(self, reference: Any, *, period: float, gains: CorrectionGains = DEFAULT_GAINS) -> None:
        self.gains = gains
        self.period = float(period)
        self.block_steps = max(1, int(round(gains.period_s / self.period)))
        self.projector = PathProjector(reference)
        self._t = np.asarray(reference.t, float)
        self._s = np.asarray(reference.s, float)
        self.s_prev = float(self._s[0])
        self.d = self.dd = 0.0  # delta, delta'
        self.command = 0.0
        self._uncorrected = (np.array(reference.alpha0, float), np.array(reference.alpha0_dot, float),
                             np.array(reference.alpha0_ddot, float))

    def describe(self, rows: Any = None) -> dict[str, Any]:
        """The gains and limits, and where ``rows`` (the run's) are given the largest |delta|,
        |delta'|, |delta''| the run used (the corrected minus the path's alpha0 ...)."""
        from dataclasses import asdict

        out: dict[str, Any] = {"law": "stanley-at-C", **asdict(self.gains)}
        if rows is not None and self._uncorrected is not None:
            n = len(rows["alpha0"])
            for key, col, ref in (("delta_max_used", "alpha0", 0), ("rate_max_used", "alpha0_dot", 1),
                                  ("acc_max_used", "alpha0_ddot", 2)):
                x = np.asarray(rows[col]) - self._uncorrected[ref][:n]
                out[key] = float(np.max(np.abs(x))) if n else 0.0
        return out

    def measure(self, t: float, C_xy: Any, heading: float) -> float:
        """Set the command from C's position and the chassis heading at time t; returns it [rad]."""
        g = self.gains
        if self.s_prev is None or not (np.all(np.isfinite(C_xy)) and math.isfinite(heading)):
            return self.command  # a diverged state: hold the command
        s, e, theta = self.projector.project(C_xy, self.s_prev)
        self.s_prev = s
        psi = float(wrap_angle(heading - theta))
        self.command = float(np.clip(-g.k_e * e - g.k_psi * psi, -g.delta_max, g.delta_max))
        return self.command

    def block(self, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """delta, delta', delta'' at the next ``count`` control steps (delta'' held over each step)."""
        g, h = self.gains, self.period
        w = g.bandwidth
        d, dd, cmd = self.d, self.dd, self.command
        R, A, D = g.rate_max, g.acc_max, g.delta_max
        out = np.empty((3, count))
        for j in range(count):
            acc = w * w * (cmd - d) - 2.0 * w * dd
            # |delta''| <= A, |delta'| <= R after the step, |delta| <= D after the step (as far as A allows)
            acc = min(max(acc, -A, (-R - dd) / h), A, (R - dd) / h)
            out[0, j], out[1, j], out[2, j] = d, dd, acc
            d, dd = d + dd * h + 0.5 * acc * h * h, dd + acc * h
            if abs(d) > D:  # the limits of the filter's state: never beyond delta_max
                d = math.copysign(D, d)
                dd = 0.0
        self.d, self.dd = d, dd
        return out[0], out[1], out[2]
