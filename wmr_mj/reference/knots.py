"""Knot paths: a family of C's paths from curvature control points, feasible by construction.

A worst-case search roams over references while a certificate declares bounds on them
(:class:`~wmr_mj.reference.bounds.ReferenceBounds`: max |alpha0'|, max |alpha0''|, the largest
angle). A knot path stays inside such bounds for every choice of its knots:

    lead-in   straight, ``hold_s`` seconds (alpha0 = 0)
    knot i    a steering ramp (:func:`~wmr_mj.reference.paths.steering_ramp`) from the previous
              steady angle to a_i = asin(l1 kappa_i), as short as the bounds allow
              (:func:`ramp_length`), then an arc of curvature kappa_i held ``hold_s`` seconds;
              the last arc runs on until ``duration``

Along a ramp alpha0 follows a + (a_i - a) S7(s/L) exactly (S7 the septic smoothstep), so its
peaks are known before any integration: with V_C = V_A/cos(alpha) (C's speed),

    alpha0'  = V_C alpha_s                                  ~ 1/L
    alpha0'' = V_C^2 alpha_ss + V_C V_A sin(alpha)/cos^2(alpha) alpha_s^2     ~ 1/L^2

(alpha_s, alpha_ss: derivatives over C's arc length s), and on an arc alpha0 is steady. Every
|kappa_i| <= :func:`kappa_max` = sin(angle_max)/l1 keeps |alpha0| <= angle_max (S7 is
monotone). The search's axes are :class:`KnotSpace`'s ``path.k1 ... path.kN`` (1/m) and
``path.hold`` (s).

Usage::

    from wmr_mj import C80
    from wmr_mj.reference.bounds import reference_bounds_from
    from wmr_mj.reference.knots import KnotSpace, kappa_max, knot_path, ramp_length
    from wmr_mj.reference.paths import make_reference

    bounds = reference_bounds_from("paper")           # 0.23 rad/s, 0.4 rad/s^2, 0.6592 rad
    kappa_max(bounds, C80)                             # 1.0008 1/m: radius 0.9992 m at the angle bound
    path = knot_path([0.8, -0.5, 0.2], hold_s=3.0, bounds=bounds, params=C80, duration=20.0)
    ref = make_reference(path, C80, duration=20.0)     # ref.bounds() within `bounds`

    space = KnotSpace(knots=3, hold_range=(0.0, 5.0))
    space.ranges(bounds, C80)   # {"path.k1": (-1.0008, 1.0008), ..., "path.hold": (0.0, 5.0)}
    path = space.path({"path.k1": 0.8, "path.k2": -0.5, "path.k3": 0.2, "path.hold": 3.0},
                      bounds=bounds, params=C80, duration=20.0)

Errors: :class:`~wmr_mj.errors.ParameterError` names the argument (or knot), its value and
what is accepted: a knot beyond kappa_max, bounds beyond the steering's own limits
(:func:`~wmr_mj.reference.paths.steering_limits`), a negative hold.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar

from wmr_mj._util.checks import positive_real as _positive
from wmr_mj._util.checks import real as _number
from wmr_mj.errors import ParameterError
from wmr_mj.params import C80, C80Parameters
from wmr_mj.reference.bounds import ReferenceBounds, reference_bounds_from
from wmr_mj.reference.paths import Path, Segment, _s7, _s7_d, _s7_dd, steering_limits

__all__ = ["ramp_length", "kappa_max", "knot_path", "KnotSpace"]

_GRID = 4001  # u samples of the L = 1 ramp; the peak is then refined by a bounded search
_SAFETY = 1e-6  # relative: the ramp's peaks stay this far below the declared bounds
_MIN_LENGTH = 1e-3  # m: the shortest lead-in or final arc (a path's segments need a length > 0)
_TIME_MARGIN = 1e-3  # s: the path runs this much past ``duration`` (make_reference's integration error)
_GAUSS_U, _GAUSS_W = np.polynomial.legendre.leggauss(64)  # time over a ramp: a smooth integrand


def _bounds(value: Any) -> ReferenceBounds:
    b = reference_bounds_from(value)
    if b is None:
        raise ParameterError(f"bounds are required: {value!r} is not accepted (a ReferenceBounds, 'paper', "
                             "a mapping or 'key=value,...' text)")
    return b


def _peak(fn: Callable[[np.ndarray], np.ndarray]) -> float:
    """max over u in [0, 1] of fn(u) >= 0: a dense grid, then a bounded search around its best sample."""
    u = np.linspace(0.0, 1.0, _GRID)
    v = fn(u)
    i = int(np.argmax(v))
    lo, hi = u[max(i - 1, 0)], u[min(i + 1, _GRID - 1)]
    res = minimize_scalar(lambda x: -float(fn(np.array([x]))[0]), bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-12})
    return max(float(v[i]), -float(res.fun))


def ramp_length(a_from: float, a_to: float, *, bounds: ReferenceBounds | Mapping[str, float] | str,
                V_A: float) -> float:
    """The shortest steering ramp from ``a_from`` to ``a_to`` whose alpha0', alpha0'' keep within ``bounds``.

    The ramp: alpha(s) = a_from + (a_to - a_from) S7(s/L) over C's arc length s in [0, L].
    alpha0' scales as 1/L and alpha0'' as 1/L^2, so L = max(M1/alpha_dot_max,
    sqrt(M2/alpha_ddot_max)) from the peaks M1, M2 of the L = 1 m ramp, both taken a relative
    1e-6 high so that no sample of the reference exceeds the bound.

    Args:
        a_from, a_to: steering angles at the ramp's ends [rad], |a| < pi/2.
        bounds: the declared bounds (alpha_dot_max [rad/s], alpha_ddot_max [rad/s^2] are used);
            anything :func:`~wmr_mj.reference.bounds.reference_bounds_from` takes.
        V_A: speed of point A [m/s].

    Returns:
        float: L [m of C's arc]; 0.0 when a_from == a_to.

    Raises:
        ParameterError: an angle not below pi/2 in size, V_A <= 0, or a zero rate or
            acceleration bound with a_from != a_to (no ramp can meet it).
    """
    a0, a1 = _number("a_from", a_from), _number("a_to", a_to)
    for name, a in (("a_from", a0), ("a_to", a1)):
        if abs(a) >= 0.5 * math.pi:
            raise ParameterError(f"{name} = {a!r} rad is not accepted: |{name}| must be below pi/2")
    va = _positive("V_A", V_A, " m/s")
    b = _bounds(bounds)
    da = a1 - a0
    if da == 0.0:
        return 0.0
    for name, lim in (("alpha_dot_max", b.alpha_dot_max), ("alpha_ddot_max", b.alpha_ddot_max)):
        if lim <= 0.0:
            raise ParameterError(f"bounds.{name} = {lim!r} admits no steering ramp from {a0!r} to {a1!r} rad: "
                                 "it must be > 0")

    def rate(u: np.ndarray) -> np.ndarray:  # |alpha0'| of the L = 1 m ramp, rad/s
        a = a0 + da * _s7(u)
        return np.abs(va / np.cos(a) * da * _s7_d(u))

    def accel(u: np.ndarray) -> np.ndarray:  # |alpha0''| of the L = 1 m ramp, rad/s^2
        a = a0 + da * _s7(u)
        c = np.cos(a)
        a_s, a_ss = da * _s7_d(u), da * _s7_dd(u)
        return np.abs((va / c) ** 2 * a_ss + va * va * np.sin(a) / c**3 * a_s * a_s)

    L_rate = _peak(rate) * (1.0 + _SAFETY) / b.alpha_dot_max
    L_accel = math.sqrt(_peak(accel) * (1.0 + _SAFETY) / b.alpha_ddot_max)
    return max(L_rate, L_accel)


def kappa_max(bounds: ReferenceBounds | Mapping[str, float] | str, params: C80Parameters = C80) -> float:
    """The largest |curvature| of a knot [1/m]: sin(angle_max)/l1, whose steady angle is the bound's.

    Args:
        bounds: the declared bounds (their angle_max [rad] is used).
        params: the parameter set (its wheelbase l1 [m]).

    Returns:
        float: kappa_max [1/m] (paper bounds, C80: 1.0008 1/m, a radius of 0.9992 m).
    """
    if not isinstance(params, C80Parameters):
        raise ParameterError(f"params must be a C80Parameters, got {type(params).__name__}")
    return math.sin(_bounds(bounds).angle_max) / params.l1


def _check_within_steering(b: ReferenceBounds, params: C80Parameters) -> None:
    """Refuse declared bounds that the steering itself cannot follow."""
    lim = steering_limits(params)
    for what, declared, name, unit in (
        ("angle", b.angle_max, "max_angle", "rad"),
        ("rate alpha_dot_max", b.alpha_dot_max, "max_rate", "rad/s"),
        ("acceleration alpha_ddot_max", b.alpha_ddot_max, "max_accel", "rad/s^2"),
    ):
        if declared > lim[name]:
            raise ParameterError(
                f"declared reference bound on the steering {what} = {declared:.6g} {unit} exceeds the steering's "
                f"own limit {name} = {lim[name]:.6g} {unit} (steering_limits(params)); declare a smaller bound"
            )


def knot_path(
    curvatures: Sequence[float],
    *,
    hold_s: float,
    bounds: ReferenceBounds | Mapping[str, float] | str,
    params: C80Parameters = C80,
    duration: float,
) -> Path:
    """C's path through curvature knots: lead-in, then per knot a fastest-allowed ramp and a held arc.

    Args:
        curvatures: kappa_1 ... kappa_N [1/m] (> 0 turns left), each |kappa_i| <= kappa_max;
            an empty sequence gives a straight line.
        hold_s: how long [s] the lead-in and each arc are held (>= 0; 0: ramps follow each other,
            the lead-in and the last arc keep 1 mm).
        bounds: the declared reference bounds; every reference of the path keeps max|alpha0'| <=
            alpha_dot_max [rad/s], max|alpha0''| <= alpha_ddot_max [rad/s^2], max|alpha0| <=
            angle_max [rad]. Anything :func:`~wmr_mj.reference.bounds.reference_bounds_from` takes.
        params: the parameter set (l1 [m], V_A [m/s], the steering limits).
        duration: the run's length [s]: the last arc is extended so that the path lasts at least
            this long (1 ms more); knots past it are never reached.

    Returns:
        Path: line, then (ramp, arc) per knot; a ramp is left out where the angle does not change,
        an arc where hold_s is 0 (but the last).

    Raises:
        ParameterError: a knot beyond kappa_max (named with its value and the limit), declared
            bounds beyond :func:`~wmr_mj.reference.paths.steering_limits`, hold_s < 0,
            duration <= 0.
    """
    if not isinstance(params, C80Parameters):
        raise ParameterError(f"params must be a C80Parameters, got {type(params).__name__}")
    b = _bounds(bounds)
    _check_within_steering(b, params)
    hold = _number("hold_s", hold_s)
    if hold < 0.0:
        raise ParameterError(f"hold_s = {hold_s!r} s is not accepted: it must be >= 0")
    T = _positive("duration", duration, " s")
    l1, V_A = params.l1, params.V_A
    k_lim = math.sin(b.angle_max) / l1
    kappas = [_number(f"knot {i + 1} curvature", k) for i, k in enumerate(curvatures)]
    for i, k in enumerate(kappas):
        if abs(k) > k_lim:
            raise ParameterError(
                f"knot {i + 1} (path.k{i + 1}) = {k!r} 1/m is not accepted: |curvature| must be <= kappa_max = "
                f"{k_lim:.6g} 1/m (sin(angle_max)/l1, angle_max = {b.angle_max:.6g} rad of the declared bounds)"
            )

    segs = [Segment("line", max(V_A * hold, _MIN_LENGTH), 0.0, 0.0)]
    t_end = segs[0].length / V_A  # time [s] at the end of the path so far
    k_prev, a_prev = 0.0, 0.0
    for k in kappas:
        a = math.asin(l1 * k)
        L = ramp_length(a_prev, a, bounds=b, V_A=V_A)
        if L > 0.0:
            segs.append(Segment("ramp", L, k_prev, k, wheelbase=l1))
            # dt = cos(alpha) ds / V_A along the ramp
            alpha = a_prev + (a - a_prev) * _s7(0.5 * (_GAUSS_U + 1.0))
            t_end += 0.5 * L / V_A * float(np.dot(_GAUSS_W, np.cos(alpha)))
        if hold > 0.0:
            segs.append(Segment("arc", V_A * hold / math.cos(a), k, k))
            t_end += hold
        k_prev, a_prev = k, a
    # the last arc (or the lead-in's line) runs on until the duration
    extra = max(T + _TIME_MARGIN - t_end, 0.0) * V_A / math.cos(a_prev)
    last = segs[-1]
    if last.kind in ("line", "arc"):  # the lead-in (no ramp after it) or the last knot's arc
        segs[-1] = Segment(last.kind, last.length + extra, k_prev, k_prev)
    else:  # hold_s = 0: the last ramp gets an arc of its own
        segs.append(Segment("line" if k_prev == 0.0 else "arc", max(extra, _MIN_LENGTH), k_prev, k_prev))
    return Path(tuple(segs))


@dataclass(frozen=True)
class KnotSpace:
    """The search space of knot paths: ``knots`` curvatures and one hold time.

    Attributes:
        knots: the number of knots N (>= 1).
        hold_range: (lo, hi) of the hold time [s], 0 <= lo <= hi.

    Axes: ``path.k1`` ... ``path.kN`` (curvature of knot i [1/m], within +-kappa_max) and
    ``path.hold`` (hold_s [s]).
    """

    knots: int
    hold_range: tuple[float, float] = (0.0, 5.0)

    def __post_init__(self) -> None:
        n = self.knots
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ParameterError(f"knots = {n!r} is not accepted: a whole number >= 1")
        try:
            lo, hi = (float(v) for v in self.hold_range)
        except (TypeError, ValueError):
            raise ParameterError(f"hold_range = {self.hold_range!r} is not accepted: a pair (lo, hi) of seconds, "
                                 "0 <= lo <= hi") from None
        if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 <= lo <= hi):
            raise ParameterError(f"hold_range = {self.hold_range!r} is not accepted: a pair (lo, hi) of seconds, "
                                 "0 <= lo <= hi")
        object.__setattr__(self, "knots", int(n))
        object.__setattr__(self, "hold_range", (lo, hi))

    @property
    def names(self) -> tuple[str, ...]:
        """The axes: ('path.k1', ..., 'path.kN', 'path.hold')."""
        return tuple(f"path.k{i + 1}" for i in range(self.knots)) + ("path.hold",)

    def ranges(self, bounds: ReferenceBounds | Mapping[str, float] | str,
               params: C80Parameters = C80) -> dict[str, tuple[float, float]]:
        """{axis: (lo, hi)}: each curvature in [-kappa_max, kappa_max] [1/m] less the ramps' relative safety
        margin (a path held at kappa_max exactly measured 2e-11 over the angle bound after integration), the
        hold in hold_range [s]."""
        k = kappa_max(bounds, params) * (1.0 - _SAFETY)
        out = {name: (-k, k) for name in self.names[:-1]}
        out["path.hold"] = self.hold_range
        return out

    def path(self, values: Mapping[str, float], *, bounds: ReferenceBounds | Mapping[str, float] | str,
             params: C80Parameters = C80, duration: float) -> Path:
        """The knot path at a point of the space: ``values`` holds every axis of :attr:`names`.

        Raises:
            ParameterError: a missing or unknown axis, or what :func:`knot_path` refuses.
        """
        names = self.names
        missing = [n for n in names if n not in values]
        unknown = [n for n in values if n not in names]
        if missing or unknown:
            what = f"missing {', '.join(missing)}" if missing else f"unknown {', '.join(map(str, unknown))}"
            raise ParameterError(f"knot space values: {what}; the axes are {', '.join(names)}")
        return knot_path([values[n] for n in names[:-1]], hold_s=values["path.hold"], bounds=bounds,
                         params=params, duration=duration)
