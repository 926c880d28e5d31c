"""Pure pursuit at the steering pivot C: R. C. Coulter, "Implementation of the Pure Pursuit Path
Tracking Algorithm", Carnegie Mellon University, Robotics Institute, CMU-RI-TR-92-01, 1992.

Every outer period (``period_s``) the tracker projects C on its desired path (arc length s_C) and
takes the goal point G on the path at arc length s_C + L_d (``lookahead`` [m]; past the path's
end, on the straight continuation of its last direction). Coulter's construction is the circular
arc through the vehicle's point, tangent to its direction of travel, through G: with G at lateral
offset y (> 0 left) and distance l from the point, its curvature is

    kappa = 2 y / l^2 = 2 sin(eta) / l          (Coulter (1992), section 2: gamma = 2 x / l^2)

eta the angle from the direction of travel to G. Here the point is C (the path is C's), and C
travels along the front axle's wheel plane: heading theta + alpha (wmr_mj.reference.paths: C moves
along phi_C = theta + alpha). The tracker measures the chassis heading theta but not alpha; it
takes alpha as the steering reference it last wrote (the filter's state below), which the inner
loop holds to within its claim's E_max (a stated assumption).

Curvature to steering angle: as the path's own feedforward does (wmr_mj.reference.paths,
make_reference), a cart turning steadily with C on a circle of curvature kappa has
sin(alpha) = l1 kappa (the rear axle A turns about the circle's centre, with C, A and the centre
a right triangle with hypotenuse R = 1/kappa and leg l1): the command is
alpha_cmd = asin(l1 kappa), clipped to +-alpha_max.

alpha0 follows alpha_cmd through :class:`controllers.tracking.RateLimitedFilter` (critically damped,
natural frequency ``bandwidth`` [rad/s], |alpha0'| <= rate_max, |alpha0''| <= acc_max,
|alpha0| <= alpha_max, alpha0'' held over each control step and integrated exactly), starting at
the path's alpha0(0). Pure pursuit writes the whole angle, not a correction of the path's
feedforward, so its declared bounds (:meth:`PurePursuit.declared_bounds`) are its own limits,
independent of the path's.

Closed forms (tests/test_pure_pursuit.py): with C on a circle of radius R and its direction of
travel tangent, every goal point on the circle gives kappa = 1/R exactly, so alpha_cmd = asin(l1/R),
the path's steady angle; on a straight path with C at lateral offset e (heading along the path),
kappa = -2 e/(L_d^2 + e^2).

Usage::

    RunConfig(tracker="pure-pursuit", tracker_params={"lookahead": 0.5}, path="lane-change")
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from controllers.tracking import PathTracker, RateLimitedFilter
from wmr_mj.analysis.certificate import Assumption
from wmr_mj.analysis.path_error import PathProjector
from wmr_mj.errors import ParameterError
from wmr_mj.reference.bounds import ReferenceBounds, sin_cos3

__all__ = ["PurePursuit"]


class PurePursuit(PathTracker):
    """Coulter's pure pursuit at C, curvature to angle by sin(alpha) = l1 kappa (module docstring).

    Parameters: lookahead L_d [m]; alpha_max [rad], rate_max [rad/s], acc_max [rad/s^2]: the
    declared bounds of alpha0 (the filter's limits); bandwidth [rad/s]: the filter's natural
    frequency; period_s [s]: the outer loop's period.
    """

    name = "pure-pursuit"

    def __init__(self, *, lookahead: float = 0.5, alpha_max: float = 0.75, rate_max: float = 0.3,
                 acc_max: float = 0.5, bandwidth: float = 3.0, period_s: float = 0.05) -> None:
        vals = {"lookahead": lookahead, "alpha_max": alpha_max, "rate_max": rate_max, "acc_max": acc_max,
                "bandwidth": bandwidth, "period_s": period_s}
        for name, v in vals.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0.0:
                raise ParameterError(f"pure-pursuit {name} = {v!r} is not accepted: a finite number > 0")
        if alpha_max >= 0.5 * math.pi:
            raise ParameterError(f"pure-pursuit alpha_max = {alpha_max!r} rad must be below pi/2")
        self.lookahead, self.alpha_max = float(lookahead), float(alpha_max)
        self.rate_max, self.acc_max = float(rate_max), float(acc_max)
        self.bandwidth, self.period_s = float(bandwidth), float(period_s)
        self.command = 0.0
        self.kappa = 0.0

    def reset(self, reference: Any, *, control_period: float) -> None:
        self.period = float(control_period)
        self._block_steps = max(1, int(round(self.period_s / self.period)))
        self.projector = PathProjector(reference)
        self.l1 = float(reference.l1)
        self._s = np.asarray(reference.s, float)
        self._xy = np.asarray(reference.C_xy, float)
        theta, a0 = np.asarray(reference.theta, float), np.asarray(reference.alpha0, float)
        self._end_dir = float(theta[-1] + a0[-1])  # C's direction of travel at the path's end
        self.s_prev = float(self._s[0])
        start = float(np.clip(a0[0], -self.alpha_max, self.alpha_max))
        self.command = start
        self.kappa = math.sin(start) / self.l1
        self.filter = RateLimitedFilter(bandwidth=self.bandwidth, rate_max=self.rate_max, acc_max=self.acc_max,
                                        value_max=self.alpha_max, period=self.period, value=start)

    def goal(self, s: float) -> np.ndarray:
        """The path's point at arc length ``s`` [m] (linear between the reference's samples; past
        the end, on the straight continuation of C's last direction)."""
        s_end = float(self._s[-1])
        if s > s_end:
            return self._xy[-1] + (s - s_end) * np.array([math.cos(self._end_dir), math.sin(self._end_dir)])
        return np.array([np.interp(s, self._s, self._xy[:, 0]), np.interp(s, self._s, self._xy[:, 1])])

    def curvature(self, C_xy: Any, direction: float, s_C: float) -> float:
        """kappa = 2 y/l^2 [1/m] of the arc from C (travelling along ``direction`` [rad]) through the
        goal point at arc length s_C + lookahead."""
        g = self.goal(s_C + self.lookahead) - np.asarray(C_xy, float)
        left = -math.sin(direction) * g[0] + math.cos(direction) * g[1]
        l2 = float(g[0] * g[0] + g[1] * g[1])
        return 2.0 * left / l2 if l2 > 0.0 else 0.0

    def measure(self, t: float, C_xy: Any, heading: float, speed: float = math.nan) -> None:
        if not (np.all(np.isfinite(C_xy)) and math.isfinite(heading)):
            return  # a diverged state: hold the command
        s, _, _ = self.projector.project(C_xy, self.s_prev)
        self.s_prev = s
        self.kappa = self.curvature(C_xy, heading + self.filter.d, s)
        limit = math.sin(self.alpha_max)
        self.command = math.asin(min(limit, max(-limit, self.l1 * self.kappa)))

    def block(self, k0: int, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        out = self.filter.run(self.command, count)
        return out[0], out[1], out[2]

    def declared_bounds(self, path_bounds: ReferenceBounds) -> ReferenceBounds:
        """Its own limits: |alpha0| <= alpha_max, |alpha0'| <= rate_max, |alpha0''| <= acc_max (the
        path's bounds do not enter: pure pursuit writes the whole angle)."""
        return ReferenceBounds(alpha_ddot_max=self.acc_max, alpha_dot_max=self.rate_max,
                               sin_cos3_max=sin_cos3(self.alpha_max), alpha_max=self.alpha_max)

    def stated_assumptions(self) -> tuple[Assumption, ...]:
        return (
            Assumption("pure-pursuit direction of travel", "C travels along heading + alpha, alpha taken as the "
                       "alpha0 the tracker last wrote", True, 0.0, 0.0,
                       "alpha is not measured by the tracker; the inner loop holds |alpha - alpha0| <= E_max",
                       kind="stated"),
            Assumption("pure-pursuit measurement", f"C's xy and the chassis heading measured exactly, held "
                       f"{self.period_s:g} s", True, 0.0, 0.0, "the simulation's site C and chassis yaw",
                       kind="stated"),
            Assumption("pure-pursuit path", "C's desired path known (the reference's polyline); projection within "
                       "0.1 m of arc length of the previous one", True, 0.0, 0.0,
                       "wmr_mj.analysis.path_error.PathProjector", kind="stated"),
        )

    def describe(self, rows: Any = None) -> dict[str, Any]:
        out: dict[str, Any] = {"tracker": self.name, "lookahead": self.lookahead, "alpha_max": self.alpha_max,
                               "rate_max": self.rate_max, "acc_max": self.acc_max, "bandwidth": self.bandwidth,
                               "period_s": self.period_s}
        if rows is not None:
            for key, col in (("alpha_max_used", "alpha0"), ("rate_max_used", "alpha0_dot"),
                             ("acc_max_used", "alpha0_ddot")):
                x = np.asarray(rows[col])
                out[key] = float(np.max(np.abs(x))) if x.size else 0.0
        return out
