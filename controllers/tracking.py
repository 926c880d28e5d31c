"""The path-tracker interface: C's pose and speed and the path in, the steering reference alpha0 out.

The steering law tracks alpha0(t); on its own, alpha0(t) is the path's feedforward
(:mod:`wmr_mj.reference.paths`) and nothing feeds back where C actually is. A path tracker is the
outer loop that does: every ``period_s`` it reads C's position, the chassis heading and C's speed,
and writes the reference the steering law receives for the next outer period::

    tracker.reset(reference, control_period=0.001)          # before every run
    tracker.measure(t, C_xy, heading, speed)                # C's pose [m, m, rad] and speed [m/s] at t [s]
    a0, a0_dot, a0_ddot = tracker.block(k0, count)          # alpha0, alpha0', alpha0'' at control steps k0..

The three must be consistent (alpha0' the derivative of alpha0 ...): the steering law's
feedforward uses them and its claim bounds them. :class:`RateLimitedFilter` is the declared filter
most trackers want: it follows a commanded angle with |a'| <= rate_max and |a''| <= acc_max,
integrated exactly at the control period.

A tracker declares the bounds of the reference it can output (:meth:`PathTracker.declared_bounds`):
the steering law's claim is computed for them, and every run checks them on the reference the
tracker actually wrote (the assumption "tracker within its declared bounds", measured, not
stated). A tracker that exceeds them makes its run uncertified.

Two trackers come with the testbed: :class:`StanleyAtC` (``--correction``, ``--tracker stanley-at-C``),
a correction added to the path's alpha0, and :class:`controllers.pure_pursuit.PurePursuit`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from wmr_mj.analysis.certificate import Assumption
from wmr_mj.analysis.path_error import PathProjector, wrap_angle
from wmr_mj.errors import ParameterError
from wmr_mj.reference.bounds import ReferenceBounds, sin_cos3

if TYPE_CHECKING:
    from controllers.base import BuildContext

__all__ = ["PathTracker", "RateLimitedFilter", "StanleyAtC", "CorrectionGains", "DEFAULT_GAINS", "corrected_bounds",
           "correction_assumptions", "within_declared", "TRACKER_BOUNDS_ASSUMPTION"]

#: The name of the measured assumption a tracker's run adds (:func:`within_declared`).
TRACKER_BOUNDS_ASSUMPTION = "tracker within its declared bounds"


class PathTracker:
    """The outer loop on C: pose and speed in, the steering reference out (module docstring).

    Override :meth:`reset`, :meth:`measure`, :meth:`block` and :meth:`declared_bounds`; set
    ``name`` and ``period_s`` (the outer loop's period [s]).
    """

    name: str = "tracker"
    period_s: float = 0.05

    @classmethod
    def from_context(cls, context: BuildContext, **params: Any) -> PathTracker:
        """The tracker built by name (``--tracker NAME --tracker-param k=v``): ``cls(**params)``."""
        return cls(**params)

    def reset(self, reference: Any, *, control_period: float) -> None:
        """Before each run: the path's :class:`~wmr_mj.reference.paths.Reference` (C's desired path, its
        alpha0 feedforward) and the control period [s]."""
        raise NotImplementedError(f"{type(self).__name__}.reset")

    @property
    def block_steps(self) -> int:
        """Control steps per outer period (set by :meth:`reset`)."""
        return int(getattr(self, "_block_steps", 1))

    def measure(self, t: float, C_xy: np.ndarray, heading: float, speed: float) -> None:
        """C's position [m] (2,), the chassis heading [rad] and C's speed [m/s] at time ``t`` [s]."""
        raise NotImplementedError(f"{type(self).__name__}.measure")

    def block(self, k0: int, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """alpha0 [rad], alpha0' [rad/s], alpha0'' [rad/s^2] at control steps k0 .. k0 + count - 1."""
        raise NotImplementedError(f"{type(self).__name__}.block")

    def declared_bounds(self, path_bounds: ReferenceBounds) -> ReferenceBounds:
        """The bounds of any reference this tracker outputs, given the path's own (``path_bounds``)."""
        raise NotImplementedError(f"{type(self).__name__}.declared_bounds")

    def stated_assumptions(self) -> tuple[Assumption, ...]:
        """What the tracker assumes that a run cannot measure (kind 'stated', each with its source)."""
        return ()

    def describe(self, rows: Any = None) -> dict[str, Any]:
        """JSON-able: the tracker's name and parameters (and, with the run's rows, what it used)."""
        return {"tracker": self.name}


def within_declared(rows: Any, declared: ReferenceBounds, *, tracker: str) -> Assumption:
    """The measured assumption "tracker within its declared bounds": the largest ratio of the run's
    max|alpha0|, max|alpha0'|, max|alpha0''| (the rows the steering law received) to ``declared``.

    A ratio up to 1 + 1e-12 counts as met: alpha0 = path + delta rounds once (half an ulp, 1.1e-16
    relative) where the filter clips delta at its limit exactly.
    """
    tol = 1e-12
    pairs = [("max|alpha0''|", np.asarray(rows["alpha0_ddot"]), declared.alpha_ddot_max),
             ("max|alpha0'|", np.asarray(rows["alpha0_dot"]), declared.alpha_dot_max)]
    if declared.alpha_max is not None:
        pairs.append(("max|alpha0|", np.asarray(rows["alpha0"]), declared.alpha_max))
    ratios = []
    for label, x, limit in pairs:
        used = float(np.max(np.abs(x))) if x.size else 0.0
        ratio = used / limit if limit > 0 else (math.inf if used > 0 else 0.0)
        ratios.append((ratio, label, used, limit))
    worst, label, used, limit = max(ratios)
    return Assumption(TRACKER_BOUNDS_ASSUMPTION, "max|alpha0|, max|alpha0'|, max|alpha0''| the steering law received "
                      "<= the tracker's declared bounds (measured on the run)", worst <= 1.0 + tol, worst, 1.0,
                      f"{tracker}: largest ratio {label}: {used:.6g} against {limit:.6g} declared; the steering "
                      "law's claim is computed for the declared bounds", kind="checked")


class RateLimitedFilter:
    """A critically damped second-order filter (natural frequency ``bandwidth`` [rad/s]) that follows a
    command with |a'| <= rate_max [rad/s], |a''| <= acc_max [rad/s^2] and |a - offset| <= value_max
    [rad], a'' held over each control step of ``period`` [s] and integrated exactly, so that
    (a, a', a'') is consistent."""

    def __init__(self, *, bandwidth: float, rate_max: float, acc_max: float, value_max: float, period: float,
                 value: float = 0.0) -> None:
        self.w, self.R, self.A, self.D, self.h = bandwidth, rate_max, acc_max, value_max, period
        self.d, self.dd = float(value), 0.0

    def run(self, command: float, count: int) -> np.ndarray:
        """(3, count): a, a', a'' at the next ``count`` control steps, following ``command``."""
        w, h, R, A, D = self.w, self.h, self.R, self.A, self.D
        d, dd, cmd = self.d, self.dd, command
        out = np.empty((3, count))
        for j in range(count):
            acc = w * w * (cmd - d) - 2.0 * w * dd
            # |a''| <= A, |a'| <= R after the step, |a| <= D after the step (as far as A allows)
            acc = min(max(acc, -A, (-R - dd) / h), A, (R - dd) / h)
            out[0, j], out[1, j], out[2, j] = d, dd, acc
            d, dd = d + dd * h + 0.5 * acc * h * h, dd + acc * h
            if abs(d) > D:  # the limits of the filter's state: never beyond value_max
                d = math.copysign(D, d)
                dd = 0.0
        self.d, self.dd = d, dd
        return out


# --------------------------------------------------------------------------- Stanley at C
@dataclass(frozen=True)
class CorrectionGains:
    """The Stanley-at-C loop's gains and the limits its declared bounds add.

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
    """The reference bounds with the correction on: each plus its limit.

    sin(a)/cos^3(a) rises with |a| on [0, pi/2), so its max at max|alpha0| + delta_max bounds it.
    """
    if bounds.alpha_max is None:
        raise ParameterError("the correction needs the reference's max|alpha0| (ReferenceBounds.alpha_max)")
    a = bounds.alpha_max + gains.delta_max
    if a >= 0.5 * math.pi:
        raise ParameterError(f"max|alpha0| + delta_max = {a:.4g} rad reaches pi/2")
    return ReferenceBounds(alpha_max=a, alpha_dot_max=bounds.alpha_dot_max + gains.rate_max,
                           alpha_ddot_max=bounds.alpha_ddot_max + gains.acc_max,
                           sin_cos3_max=max(bounds.sin_cos3_max, sin_cos3(a)))


def correction_assumptions(gains: CorrectionGains = DEFAULT_GAINS) -> tuple[Assumption, ...]:
    """What the Stanley-at-C loop assumes that a run cannot measure (kind 'stated'); its limits are
    measured on every run instead (:func:`within_declared`)."""
    g = gains
    return (
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


class StanleyAtC(PathTracker):
    """Stanley's law at the steering pivot C, as a correction of the path's alpha0.

    Every ``period_s`` it projects C on its desired path (cross-track e [m], > 0 left; heading
    error psi [rad], the chassis heading minus the desired one) and asks for
    delta_cmd = clip(-k_e e - k_psi psi, +-delta_max); :class:`RateLimitedFilter` follows it, and
    the steering law receives alpha0 + delta, alpha0' + delta', alpha0'' + delta''. No integral
    action: on a circle C keeps a cross-track offset of about E_ss / k_e (E_ss the inner loop's
    steady steering error); the along-track (timing) error is not corrected.
    """

    name = "stanley-at-C"

    def __init__(self, gains: CorrectionGains = DEFAULT_GAINS, **params: float) -> None:
        if params:
            try:
                gains = CorrectionGains(**{**asdict(gains), **{k: float(v) for k, v in params.items()}})
            except TypeError:
                unknown = sorted(set(params) - set(asdict(gains)))
                raise ParameterError(f"stanley-at-C has no parameter {unknown[0]!r}; accepted: "
                                     f"{', '.join(asdict(gains))}") from None
        self.gains = gains
        self.period_s = gains.period_s

    def reset(self, reference: Any, *, control_period: float) -> None:
        g = self.gains
        self.period = float(control_period)
        self._block_steps = max(1, int(round(g.period_s / self.period)))
        self.projector = PathProjector(reference)
        self.s_prev = float(np.asarray(reference.s, float)[0])
        self.command = 0.0
        self._path = (np.asarray(reference.alpha0, float), np.asarray(reference.alpha0_dot, float),
                      np.asarray(reference.alpha0_ddot, float))
        self.filter = RateLimitedFilter(bandwidth=g.bandwidth, rate_max=g.rate_max, acc_max=g.acc_max,
                                        value_max=g.delta_max, period=self.period)

    def measure(self, t: float, C_xy: Any, heading: float, speed: float = math.nan) -> None:
        g = self.gains
        if not (np.all(np.isfinite(C_xy)) and math.isfinite(heading)):
            return  # a diverged state: hold the command
        s, e, theta = self.projector.project(C_xy, self.s_prev)
        self.s_prev = s
        psi = float(wrap_angle(heading - theta))
        self.command = float(np.clip(-g.k_e * e - g.k_psi * psi, -g.delta_max, g.delta_max))

    def corrections(self, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """delta, delta', delta'' at the next ``count`` control steps (delta'' held over each step)."""
        out = self.filter.run(self.command, count)
        return out[0], out[1], out[2]

    def block(self, k0: int, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        d, dd, ddd = self.corrections(count)
        sl = slice(k0, k0 + count)
        a0, a0d, a0dd = self._path
        return a0[sl] + d, a0d[sl] + dd, a0dd[sl] + ddd

    def declared_bounds(self, path_bounds: ReferenceBounds) -> ReferenceBounds:
        return corrected_bounds(path_bounds, self.gains)

    def stated_assumptions(self) -> tuple[Assumption, ...]:
        return correction_assumptions(self.gains)

    def describe(self, rows: Any = None) -> dict[str, Any]:
        """The gains and limits, and where ``rows`` (the run's) are given the largest |delta|,
        |delta'|, |delta''| the run used (the corrected minus the path's alpha0 ...)."""
        out: dict[str, Any] = {"law": self.name, **asdict(self.gains)}
        if rows is not None and hasattr(self, "_path"):
            n = len(rows["alpha0"])
            for key, col, ref in (("delta_max_used", "alpha0", 0), ("rate_max_used", "alpha0_dot", 1),
                                  ("acc_max_used", "alpha0_ddot", 2)):
                x = np.asarray(rows[col]) - self._path[ref][:n]
                out[key] = float(np.max(np.abs(x))) if n else 0.0
        return out
