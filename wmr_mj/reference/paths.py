"""Reference trajectories: a path of point C turned into the steering reference alpha0(t).

The paper (Hendzel, section 5) tracks "point C" of the C80 along a circle of
radius R = 1 m at V_A = 0.2 m/s (Fig. 4, desired trajectory) and feeds the
computed-torque controller the joint-space reference alpha0(t), alpha0'(t)
(Figs. 5 and 6), whose bounds enter the robustness test as (5.1):
||alpha0'|| = 0.23 rad/s, ||alpha0''|| = 0.4 rad/s^2, ||sin/cos^3|| = 1.24.
This module builds such paths and converts them to joint space.

Kinematics (top view; see ``wmr_mj.params`` for the geometry)::

    A      rear-axle midpoint; moves at V_A (constant, params.V_A) along the
           chassis heading theta;   theta' = V_A tan(alpha) / l1
    C      the tracked point, the steering pivot O:  C = A + l1 (cos theta, sin theta)
           C moves along theta + alpha at V_C = V_A / cos(alpha)

If C's path has curvature kappa(s) over C's arc length s, then
kappa = (theta' + alpha') / V_C, which gives

    d alpha / ds = kappa(s) - sin(alpha) / l1,        dt = ds cos(alpha) / V_A
    alpha'  = V_C f,                                   f = kappa - sin(alpha)/l1
    alpha'' = V_C [V_A sin(alpha)/cos^2(alpha) f^2 + V_C (kappa'(s) - cos(alpha) f / l1)]

(alpha'' by the chain rule, with the analytic kappa'(s) of each segment; no
finite differences). On a circle of radius R the steady angle is
sin(alpha) = l1/R (C80: 0.659 rad on R = 1 m, sin/cos^3 = 1.24 as in (5.1));
the ODE relaxes towards it over a length l1 / cos(alpha). A radius below l1
has no steady angle: such a path is infeasible.

Paths. A :class:`Path` is C's curvature over C's arc length, a sequence of
:class:`Segment`: ``line``, ``circle`` (signed radius: > 0 turns left),
``transition`` (quintic smoothstep blend of curvature), ``steering_ramp`` (an
entry whose curvature is matched to a wheelbase so that alpha follows a septic
smoothstep exactly and arrives at the steady angle), ``lane_change`` and
``figure_eight``. Every segment has kappa' = kappa'' = 0 at both ends, so paths
whose curvatures agree at the joints are C^2 in curvature and alpha0, alpha0',
alpha0'' are continuous; ``a + b`` refuses a curvature jump, ``join(...,
transition=L)`` bridges jumps with blends of length L.

The paper's experiment, :func:`paper_circle`: a straight lead-in, an entry, then
the R = 1 m circle for the rest of a 35 s run. Its entry is chosen as the
shortest one that respects both (5.1) bounds, max|alpha0'| <= peak_rate (0.23)
and max|alpha0''| <= peak_accel (0.4). Note: an entry whose curvature rises
monotonically to 1/R can never reach the paper's 0.23 rad/s, because
alpha' = V_C (kappa - sin(alpha)/l1) <= V_A / R = 0.2 rad/s for kappa <= 1/R.
The default ``entry="ramp"`` (steering ramp) therefore lets C's curvature
overshoot 1/R during the entry (C80: to 1.70 /m, radius 0.59 m, just past
mid-ramp; only transiently, so no steady angle is needed there). The rate bound
binds: a 1.33 m ramp, max|alpha0'| = 0.23 exactly, max|alpha0''| = 0.155
rad/s^2, max sin/cos^3 = 1.237, and alpha0 sits exactly on asin(l1/R) on the
circle. ``entry="blend"`` keeps C's curvature monotone (a quintic blend): the
acceleration bound binds (a 0.174 m blend, max|alpha0''| = 0.4), max|alpha0'|
is 0.177, and alpha0 creeps to asin(l1/R) (2e-5 rad short after 35 s).

Conversion, :func:`make_reference`: integrates the ODE in s with
``scipy.integrate.solve_ivp`` (DOP853, rtol 1e-10) segment by segment, checks
the steering limits (angle, no-load rate V_max/(k_b i2), acceleration V_max/P;
each can be overridden), and samples a :class:`Reference` on a uniform time
grid (Newton iteration on the dense solution for s(t)). ``Reference.at(t)``
interpolates between grid samples: cubic Hermite for alpha0 (with alpha0') and
for alpha0' (with alpha0''), linear for alpha0''.

Usage::

    from wmr_mj import C80
    from wmr_mj.reference.paths import make_reference, paper_circle, line, circle, transition

    ref = make_reference(paper_circle(C80), C80)           # Figs. 4-6
    ref.bounds()        # ReferenceBounds(alpha_ddot_max=..., alpha_dot_max=0.23, ...)
    a0, a0_dot, a0_ddot = ref.at(12.3456)                   # vectorised in t

    path = line(0.5) + transition(1.0, to_radius=-2.0) + circle(-2.0, angle=1.5)
    ref = make_reference(path, C80, dt=2e-3, max_rate=0.5)  # InfeasiblePathError if too fast

Errors: bad arguments raise :class:`~wmr_mj.errors.ParameterError` naming the
argument and what is accepted; a path the steering cannot follow raises
:class:`~wmr_mj.errors.InfeasiblePathError` saying where (s in m, t in s) and why.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from wmr_mj._util.checks import positive_real as _positive
from wmr_mj._util.checks import real as _number
from wmr_mj.errors import DurationError, InfeasiblePathError, ParameterError, StiffReferenceError
from wmr_mj.params import C80, C80Parameters
from wmr_mj.reference.bounds import PAPER_BOUNDS, ReferenceBounds, sin_cos3_of_samples

__all__ = [
    "Segment",
    "Path",
    "Reference",
    "line",
    "circle",
    "transition",
    "steering_ramp",
    "lane_change",
    "figure_eight",
    "join",
    "paper_circle",
    "make_reference",
    "steering_limits",
    "PAPER_BOUNDS",
]


SegmentKind = Literal["line", "arc", "transition", "ramp", "lane_change"]

_RTOL = 1e-10
_ATOL = 1e-12
#: The most wheelbases of C's path one reference may integrate. alpha relaxes towards its circle's angle over
#: a length l1 / cos(alpha), so the explicit integrator's steps grow as (path length) / l1. Measured building
#: the paper circle's reference (35 s, 8.8 m of C's path) on a loaded 2-core machine (2026-11-28): l1 = 1e-3 m
#: (8.8e3 wheelbases) took 1.1 s, 1e-4 m (8.8e4) 9 s, 3e-5 m (2.9e5) 36 s; 1e-6 m would take hours. The C80
#: (l1 = 0.612 m) integrates 14 wheelbases there.
MAX_WHEELBASES_INTEGRATED = 1e4
_JOIN_TOL = 1e-9  # curvature mismatch accepted at a joint, 1/m


# --------------------------------------------------------------------------
# argument checks
def _terminal_event(fn: Callable[..., float], *, direction: int) -> Callable[..., float]:
    """``fn`` as a terminal event of ``solve_ivp``, which reads the two attributes off the function."""
    fn.terminal = True  # type: ignore[attr-defined]  # solve_ivp's event protocol: attributes on a function
    fn.direction = direction  # type: ignore[attr-defined]
    return fn


def _radius_curvature(name: str, value: object) -> float:
    """Curvature 1/R of a signed radius; +-inf means straight (curvature 0)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(f"{name} must be a real number (signed radius in m, inf for straight), got {value!r}")
    r = float(value)
    if math.isnan(r) or r == 0.0:
        raise ParameterError(
            f"{name} = {value!r} is not accepted: a signed radius in m (> 0 turns left, "
            "< 0 right) or inf for a straight line"
        )
    return 0.0 if math.isinf(r) else 1.0 / r


# --------------------------------------------------------------------------
# blend polynomials
def _s5(u):  # quintic smoothstep: 0 -> 1, first and second derivative 0 at both ends
    return u**3 * (10.0 - 15.0 * u + 6.0 * u * u)


def _s5_d(u):
    return 30.0 * u * u * (1.0 - u) ** 2


def _s5_int(u):  # integral of _s5 from 0
    return u**4 * (2.5 - 3.0 * u + u * u)


def _s7(u):  # septic smoothstep: derivatives 1..3 vanish at both ends
    return u**4 * (35.0 - 84.0 * u + 70.0 * u * u - 20.0 * u**3)


def _s7_d(u):
    return 140.0 * u**3 * (1.0 - u) ** 3


def _s7_dd(u):
    return 420.0 * u * u * (1.0 - u) ** 2 * (1.0 - 2.0 * u)


def _bump(u):  # lane-change heading shape: 0 -> 1 (at u = 1/2) -> 0, C^3 at the ends
    return 256.0 * u**4 * (1.0 - u) ** 4


def _bump_d(u):
    return 1024.0 * u**3 * (1.0 - u) ** 3 * (1.0 - 2.0 * u)


def _bump_dd(u):
    return 1024.0 * u * u * (1.0 - u) ** 2 * (3.0 - 14.0 * u + 14.0 * u * u)


# --------------------------------------------------------------------------
@dataclass(frozen=True)
class Segment:
    """One piece of C's path: curvature over a local arc length in [0, length].

    kind: 'line', 'arc' (constant curvature), 'transition' (quintic blend of
    curvature from start_curvature to end_curvature), 'ramp' (curvature such
    that a vehicle of wheelbase ``wheelbase`` steers along a septic smoothstep
    from asin(l1 k_start) to asin(l1 k_end)), 'lane_change' (heading
    amplitude * 256 u^4 (1-u)^4, u = s/length). Curvatures in 1/m, > 0 left.
    Every kind has curvature' = curvature'' = 0 at both ends.
    """

    kind: SegmentKind
    length: float
    start_curvature: float
    end_curvature: float
    heading_amplitude: float = 0.0  # lane_change only, rad
    wheelbase: float = 0.0  # ramp only, m

    def __post_init__(self) -> None:
        kinds = ("line", "arc", "transition", "ramp", "lane_change")
        if self.kind not in kinds:
            raise ParameterError(f"segment kind {self.kind!r} is not accepted: one of {', '.join(kinds)}")
        _positive("length", self.length, " m")
        for name in ("start_curvature", "end_curvature", "heading_amplitude", "wheelbase"):
            _number(name, getattr(self, name))
        if self.kind == "ramp" and self.wheelbase <= 0.0:
            raise ParameterError("a ramp segment needs wheelbase > 0 (m)")

    def curvature(self, s: ArrayLike) -> np.ndarray:
        """kappa at local arc length s (1/m)."""
        u = np.clip(np.asarray(s, dtype=float) / self.length, 0.0, 1.0)
        k0, k1 = self.start_curvature, self.end_curvature
        if self.kind in ("line", "arc"):
            return np.full_like(u, k0)
        if self.kind == "transition":
            return k0 + (k1 - k0) * _s5(u)
        if self.kind == "lane_change":
            return self.heading_amplitude * _bump_d(u) / self.length
        a, a_s, _ = self._ramp_alpha(u)
        return a_s + np.sin(a) / self.wheelbase

    def curvature_rate(self, s: ArrayLike) -> np.ndarray:
        """d kappa / ds at local arc length s (1/m^2)."""
        u = np.clip(np.asarray(s, dtype=float) / self.length, 0.0, 1.0)
        k0, k1, L = self.start_curvature, self.end_curvature, self.length
        if self.kind in ("line", "arc"):
            return np.zeros_like(u)
        if self.kind == "transition":
            return (k1 - k0) * _s5_d(u) / L
        if self.kind == "lane_change":
            return self.heading_amplitude * _bump_dd(u) / (L * L)
        a, a_s, a_ss = self._ramp_alpha(u)
        return a_ss + np.cos(a) * a_s / self.wheelbase

    def _ramp_alpha(self, u):
        l1, L = self.wheelbase, self.length
        a0 = math.asin(l1 * self.start_curvature)
        da = math.asin(l1 * self.end_curvature) - a0
        return a0 + da * _s7(u), da * _s7_d(u) / L, da * _s7_dd(u) / (L * L)

    @property
    def heading_change(self) -> float:
        """Change of C's direction of motion over the segment (rad)."""
        k0, k1, L = self.start_curvature, self.end_curvature, self.length
        if self.kind in ("line", "arc"):
            return k0 * L
        if self.kind == "transition":
            return 0.5 * (k0 + k1) * L
        if self.kind == "lane_change":
            return 0.0
        return quad(lambda s: float(self.curvature(s)), 0.0, L, epsabs=1e-13, epsrel=1e-13, limit=200)[0]


@dataclass(frozen=True)
class Path:
    """C's path: curvature over C's arc length, a tuple of :class:`Segment`.

    ``a + b`` concatenates (the curvature must agree at the joint, see
    :func:`join` to bridge a jump). The path starts where the vehicle is put
    (:func:`make_reference`'s pose); C's initial direction is the chassis
    heading plus the initial steering angle.
    """

    segments: tuple[Segment, ...]

    def __post_init__(self) -> None:
        if not self.segments:
            raise ParameterError("a Path needs at least one segment")
        for seg in self.segments:
            if not isinstance(seg, Segment):
                raise ParameterError(f"a Path holds Segment objects, got {seg!r}")
        for left, right in zip(self.segments[:-1], self.segments[1:]):
            if abs(left.end_curvature - right.start_curvature) > _JOIN_TOL:
                raise ParameterError(
                    f"curvature jumps from {left.end_curvature:.6g} to {right.start_curvature:.6g} 1/m "
                    f"where a {left.kind} meets a {right.kind}: a path must have continuous curvature; "
                    "insert a transition(...) or use join(..., transition=length)"
                )

    def __add__(self, other: Path) -> Path:
        if not isinstance(other, Path):
            return NotImplemented
        return Path(self.segments + other.segments)

    @property
    def length(self) -> float:
        """Total arc length of C (m)."""
        return float(sum(seg.length for seg in self.segments))

    @property
    def starts(self) -> np.ndarray:
        """Arc length at the start of each segment, plus the total length (m)."""
        return np.concatenate([[0.0], np.cumsum([seg.length for seg in self.segments])])

    @property
    def start_curvature(self) -> float:
        return self.segments[0].start_curvature

    @property
    def end_curvature(self) -> float:
        return self.segments[-1].end_curvature

    @property
    def heading_change(self) -> float:
        """Total change of C's direction of motion (rad)."""
        return float(sum(seg.heading_change for seg in self.segments))

    def _locate(self, s: np.ndarray) -> np.ndarray:
        starts = self.starts
        return np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(self.segments) - 1)

    def _piecewise(self, s: ArrayLike, method: str) -> np.ndarray:
        """Segment.<method> evaluated on each segment's share of s (local arc length)."""
        s = np.asarray(s, dtype=float)
        idx, starts, out = self._locate(s), self.starts, np.empty_like(s)
        for i, seg in enumerate(self.segments):
            m = idx == i
            if np.any(m):
                out[m] = getattr(seg, method)(s[m] - starts[i])
        return out

    def curvature(self, s: ArrayLike) -> np.ndarray:
        """kappa at arc length s (vectorised; 1/m)."""
        return self._piecewise(s, "curvature")

    def curvature_rate(self, s: ArrayLike) -> np.ndarray:
        """d kappa / ds at arc length s (vectorised; 1/m^2)."""
        return self._piecewise(s, "curvature_rate")


# --------------------------------------------------------------------------
# path constructors
def line(length: float) -> Path:
    """A straight segment of C's path, ``length`` m."""
    L = _positive("length", length, " m")
    return Path((Segment("line", L, 0.0, 0.0),))


def circle(
    radius: float,
    *,
    turns: float | None = None,
    angle: float | None = None,
    length: float | None = None,
) -> Path:
    """An arc of C's path of signed ``radius`` m (> 0 turns left, < 0 right).

    Give at most one of ``turns`` (full turns), ``angle`` (rad turned, a
    magnitude; the radius's sign gives the direction) or ``length`` (arc
    length, m); default one full turn.
    """
    k = _radius_curvature("radius", radius)
    if math.isinf(float(radius)):
        raise ParameterError(f"radius = {radius!r} is not accepted: a circle needs a finite non-zero radius (m)")
    given = [n for n, v in (("turns", turns), ("angle", angle), ("length", length)) if v is not None]
    if len(given) > 1:
        raise ParameterError(f"circle takes one of turns, angle, length; got {', '.join(given)}")
    R = abs(float(radius))
    if length is not None:
        L = _positive("length", length, " m")
    elif angle is not None:
        L = R * _positive("angle", angle, " rad")
    else:
        L = 2.0 * math.pi * R * (1.0 if turns is None else _positive("turns", turns))
    return Path((Segment("arc", L, k, k),))


def transition(length: float, *, from_radius: float = math.inf, to_radius: float = math.inf) -> Path:
    """A curvature blend of C's path over ``length`` m (quintic smoothstep).

    Curvature goes from 1/from_radius to 1/to_radius (signed radii in m, inf
    for straight) with zero slope and zero second derivative at both ends.
    The steering angle lags such a blend (relaxation length l1/cos(alpha)).
    """
    L = _positive("length", length, " m")
    k0 = _radius_curvature("from_radius", from_radius)
    k1 = _radius_curvature("to_radius", to_radius)
    return Path((Segment("transition", L, k0, k1),))


_curvature_blend = transition  # for functions whose keyword ``transition`` shadows it


def steering_ramp(
    length: float, *, l1: float, from_radius: float = math.inf, to_radius: float = math.inf
) -> Path:
    """An entry of C's path matched to wheelbase ``l1`` over ``length`` m.

    Its curvature kappa(s) = alpha_s(s) + sin(alpha(s))/l1 with
    alpha(s) = a0 + (a1 - a0) S7(s/length), S7 the septic smoothstep and
    a = asin(l1/R): a vehicle of wheelbase l1 that starts it at the steady
    angle of ``from_radius`` steers along exactly alpha(s) and arrives at the
    steady angle of ``to_radius``. C's curvature may overshoot 1/to_radius.
    """
    L = _positive("length", length, " m")
    wb = _positive("l1", l1, " m")
    k0 = _radius_curvature("from_radius", from_radius)
    k1 = _radius_curvature("to_radius", to_radius)
    for name, k in (("from_radius", k0), ("to_radius", k1)):
        if abs(k) * wb >= 1.0:
            raise ParameterError(
                f"{name} = {1.0 / k:.6g} m is not accepted: |radius| must exceed the wheelbase l1 = {wb:.6g} m"
            )
    return Path((Segment("ramp", L, k0, k1, wheelbase=wb),))


def lane_change(offset: float, length: float) -> Path:
    """A lateral shift of C by ``offset`` m (> 0 left) over ``length`` m forward.

    C's heading follows p 256 u^4 (1-u)^4 over the arc length (u = s/L_arc),
    so it leaves and returns at heading 0 with curvature, its slope and its
    second derivative 0; p and the arc length L_arc are solved so that C ends
    exactly ``offset`` m to the side and ``length`` m ahead.
    """
    d = _number("offset", offset)
    if d == 0.0:
        raise ParameterError("offset = 0 is not accepted: a lane change needs a non-zero lateral offset (m); "
                             "use line()")
    X = _positive("length", length, " m")
    opts = dict(epsabs=1e-14, epsrel=1e-13, limit=200)

    def isin(p: float) -> float:
        return quad(lambda u: math.sin(p * _bump(u)), 0.0, 1.0, **opts)[0]

    def icos(p: float) -> float:
        return quad(lambda u: math.cos(p * _bump(u)), 0.0, 1.0, **opts)[0]

    ratio = abs(d) / X
    p_max = 0.5 * math.pi * 0.999
    if isin(p_max) / icos(p_max) <= ratio:
        raise ParameterError(
            f"lane_change(offset={d}, length={X}) is not accepted: |offset|/length = {ratio:.4g} needs C's "
            f"heading to reach 90 deg; |offset|/length must stay below {isin(p_max) / icos(p_max):.4g}"
        )
    p = brentq(lambda q: isin(q) - ratio * icos(q), 1e-12, p_max, xtol=1e-15, rtol=1e-15)
    L = X / icos(p)
    return Path((Segment("lane_change", L, 0.0, 0.0, heading_amplitude=math.copysign(p, d)),))


def figure_eight(radius: float, *, transition: float | None = None, laps: int = 1) -> Path:
    """A closed figure eight of C, two lobes of signed ``radius`` m (> 0: left lobe first).

    Each lobe is transition(0 -> 1/R) + arc + transition(1/R -> 0), both
    transitions ``transition`` m long (default |radius|), with the arc angle
    solved so that the lobe closes: C starts and ends every lap at its start
    point with heading 0 and zero curvature, crossing itself there.
    """
    k = _radius_curvature("radius", radius)
    if math.isinf(float(radius)):
        raise ParameterError(f"radius = {radius!r} is not accepted: a figure eight needs a finite radius (m)")
    R = abs(float(radius))
    b = R if transition is None else _positive("transition", transition, " m")
    if isinstance(laps, bool) or not isinstance(laps, (int, np.integer)) or laps < 1:
        raise ParameterError(f"laps = {laps!r} is not accepted: a whole number >= 1")
    ka = 1.0 / R  # build the left lobe, mirror for the sign

    def chord(theta: float) -> float:
        # component of (end - start) of the lobe along its mid heading psi/2;
        # the perpendicular component vanishes by the lobe's symmetry
        psi = ka * b + theta
        h = 0.5 * psi
        opts = dict(epsabs=1e-14, epsrel=1e-13, limit=200)
        c1 = quad(lambda s: math.cos(ka * b * _s5_int(s / b) - h), 0.0, b, **opts)[0]
        c2 = R * (math.sin(0.5 * ka * b + theta - h) - math.sin(0.5 * ka * b - h))
        phi2 = 0.5 * ka * b + theta
        c3 = quad(lambda s: math.cos(phi2 + ka * (s - b * _s5_int(s / b)) - h), 0.0, b, **opts)[0]
        return c1 + c2 + c3

    lo = max(0.0, math.pi - ka * b)
    hi = 2.0 * math.pi - ka * b
    if hi <= lo or not (chord(lo) > 0.0 > chord(hi)):
        raise ParameterError(
            f"transition = {b} m is not accepted for radius {radius} m: a closing lobe needs a shorter "
            f"transition (up to about {math.pi * R:.3g} m)"
        )
    theta = brentq(chord, lo, hi, xtol=1e-15, rtol=1e-15)
    kk = math.copysign(ka, k)
    lobe1 = (
        Segment("transition", b, 0.0, kk),
        Segment("arc", R * theta, kk, kk),
        Segment("transition", b, kk, 0.0),
    )
    lobe2 = tuple(Segment(s.kind, s.length, -s.start_curvature, -s.end_curvature) for s in lobe1)
    return Path((lobe1 + lobe2) * int(laps))


def join(*paths: Path, transition: float | None = None) -> Path:
    """Concatenate ``paths``; where the curvature jumps, insert a curvature blend.

    transition: length (m) of each inserted blend; None refuses jumps.
    """
    if not paths:
        raise ParameterError("join needs at least one Path")
    for p in paths:
        if not isinstance(p, Path):
            raise ParameterError(f"join takes Path objects, got {p!r}")
    L = None if transition is None else _positive("transition", transition, " m")
    segs: list[Segment] = list(paths[0].segments)
    for p in paths[1:]:
        k0, k1 = segs[-1].end_curvature, p.start_curvature
        if abs(k0 - k1) > _JOIN_TOL:
            if L is None:
                raise ParameterError(
                    f"curvature jumps from {k0:.6g} to {k1:.6g} 1/m between joined paths; "
                    "give transition=<length in m> to bridge it"
                )
            segs.append(Segment("transition", L, k0, k1))
        segs.extend(p.segments)
    return Path(tuple(segs))


# --------------------------------------------------------------------------
# joint space
def steering_limits(params: C80Parameters = C80) -> dict[str, float]:
    """Default steering limits: max_angle (rad), max_rate (rad/s), max_accel (rad/s^2).

    max_angle = steering_range; max_rate = voltage_limit / (k_b i2), the no-load
    speed; max_accel = voltage_limit / P, P of (2.13).
    """
    return {
        "max_angle": params.steering_range,
        "max_rate": params.voltage_limit / (params.k_b * params.i2),
        "max_accel": params.voltage_limit / params.coefficients().P,
    }


def _alpha_dots(a, k, dk, l1: float, V_A: float):
    c = np.cos(a)
    sn = np.sin(a)
    f = k - sn / l1
    vc = V_A / c
    ad = vc * f
    add = vc * (V_A * sn / (c * c) * f * f + vc * (dk - c * f / l1))
    return ad, add


@dataclass
class _Piece:
    s0: float  # global arc length at the start
    length: float  # integrated local length (may be short of the segment if stopped)
    segment: Segment
    sol: Callable  # dense output in local s: state [alpha, t, phi, xC, yC]
    s_steps: np.ndarray  # local s of the solver's steps
    t_steps: np.ndarray


@dataclass
class _Run:
    pieces: list[_Piece] = field(default_factory=list)
    stopped: bool = False  # t_stop reached

    @property
    def s_end(self) -> float:
        return self.pieces[-1].s0 + self.pieces[-1].length

    @property
    def t_end(self) -> float:
        return float(self.pieces[-1].t_steps[-1])


def _where(s: float, t: float) -> str:
    return f"at s = {s:.4f} m (t = {t:.3f} s)"


def _integrate(
    path: Path,
    l1: float,
    V_A: float,
    alpha_init: float,
    *,
    max_angle: float,
    max_rate: float = math.inf,
    max_accel: float = math.inf,
    t_stop: float | None = None,
) -> _Run:
    """Integrate [alpha, t, phi_C, x_C, y_C] over s, segment by segment (C starts at 0, heading phi0 = alpha_init)."""
    _check_integrable(path, l1, V_A, max_angle=max_angle, t_stop=t_stop)
    run = _Run()
    y = np.array([alpha_init, 0.0, alpha_init, 0.0, 0.0])
    s0 = 0.0
    for seg in path.segments:
        k0 = float(seg.curvature(0.0))
        if seg.kind == "arc" and abs(k0) * l1 >= 1.0:
            raise InfeasiblePathError(
                f"path infeasible {_where(s0, y[1])}: a circle of radius {1.0 / abs(k0):.4g} m starts there, "
                f"below the wheelbase l1 = {l1:.4g} m; holding it needs sin(alpha) = l1/R = "
                f"{l1 * abs(k0):.4g} >= 1"
            )

        def rhs(s, z, seg=seg):
            a = z[0]
            k = float(seg.curvature(s))
            c = math.cos(a)
            return [k - math.sin(a) / l1, c / V_A, k, math.cos(z[2]), math.sin(z[2])]

        def margins(s, z, seg=seg):
            a = z[0]
            ad, add = _alpha_dots(a, float(seg.curvature(s)), float(seg.curvature_rate(s)), l1, V_A)
            return (max_angle - abs(a), max_rate - abs(ad), max_accel - abs(add))

        events: list[Callable[..., float]] = []
        for j in range(3):
            def ev(s, z, j=j, margins=margins):
                return margins(s, z)[j]
            events.append(_terminal_event(ev, direction=-1))
        if t_stop is not None:
            def ev_t(s, z):
                return z[1] - t_stop
            events.append(_terminal_event(ev_t, direction=1))

        names = ("angle", "rate", "accel")
        m0 = margins(0.0, y)
        for j in range(3):
            if m0[j] <= 0.0:
                _raise_limit(names[j], s0, y, seg, 0.0, l1, V_A, max_angle, max_rate, max_accel)
        res = solve_ivp(
            rhs, (0.0, seg.length), y, method="DOP853", rtol=_RTOL, atol=_ATOL,
            dense_output=True, events=events,
        )
        if res.status == -1:
            raise InfeasiblePathError(f"path integration failed {_where(s0, y[1])}: {res.message}")
        run.pieces.append(_Piece(s0, float(res.t[-1]), seg, res.sol, res.t.copy(), res.y[1].copy()))
        if res.status == 1:
            for j in range(3):
                if res.t_events[j].size:
                    sj = float(res.t_events[j][0])
                    _raise_limit(names[j], s0, res.y_events[j][0], seg, sj, l1, V_A,
                                 max_angle, max_rate, max_accel)
            run.stopped = True
            return run
        y = res.y[:, -1].copy()
        s0 += seg.length
    return run


def _check_integrable(path: Path, l1: float, V_A: float, *, max_angle: float, t_stop: float | None) -> None:
    """Refuses, before any step, a reference whose integration would not end in bounded time.

    Raises:
        StiffReferenceError: C's path (up to ``t_stop``: C moves at most V_A / cos(max_angle) per second) is more
            than :data:`MAX_WHEELBASES_INTEGRATED` wheelbases long.
    """
    span = float(path.length)
    if t_stop is not None:
        span = min(span, V_A * t_stop / max(math.cos(min(max_angle, math.pi / 2)), 1e-3))
    if span > MAX_WHEELBASES_INTEGRATED * l1:
        raise StiffReferenceError(
            f"path cannot be integrated in bounded time: the steering angle relaxes over the wheelbase l1 = {l1:.4g} m "
            f"and C's {span:.4g} m of path are {span / l1:.3g} wheelbases; accepted: at most "
            f"{MAX_WHEELBASES_INTEGRATED:.0f} (a wheelbase of at least {span / MAX_WHEELBASES_INTEGRATED:.3g} m for "
            "this path, or a shorter path or --duration)")


def _raise_limit(name, s0, z, seg, s_local, l1, V_A, max_angle, max_rate, max_accel):
    s, t, a = s0 + s_local, float(z[1]), float(z[0])
    where = _where(s, t)
    k = float(seg.curvature(s_local))
    if name == "angle":
        msg = (f"path infeasible {where}: steering angle |alpha0| reaches {abs(a):.4g} rad, "
               f"the limit max_angle = {max_angle:.4g} rad")
        if abs(k) * l1 >= 1.0:
            msg += (f"; C's path radius there, {1.0 / abs(k):.4g} m, is below the wheelbase "
                    f"l1 = {l1:.4g} m, which would need sin(alpha) = l1/R = {abs(k) * l1:.4g} >= 1")
        raise InfeasiblePathError(msg)
    # the peak the segment asks for (integrate on without the rate/accel limits)
    sl = np.linspace(s_local, seg.length, 2001)
    peak = math.nan
    try:
        sub = solve_ivp(
            lambda q, y: [float(seg.curvature(q)) - math.sin(y[0]) / l1], (s_local, seg.length), [a],
            method="DOP853", rtol=1e-9, atol=1e-12, dense_output=True,
            events=[_guard(max_angle)],
        )
        sl = sl[sl <= sub.t[-1]]
        aa = sub.sol(sl)[0]
        ad, add = _alpha_dots(aa, seg.curvature(sl), seg.curvature_rate(sl), l1, V_A)
        peak = float(np.max(np.abs(ad if name == "rate" else add)))
    except Exception:  # pragma: no cover - the report stays useful without the peak
        pass
    if name == "rate":
        what, lim, unit = "steering rate |alpha0'|", max_rate, "rad/s"
    else:
        what, lim, unit = "steering acceleration |alpha0''|", max_accel, "rad/s^2"
    need = f" (this {seg.kind} segment asks for up to {peak:.4g} {unit})" if math.isfinite(peak) else ""
    raise InfeasiblePathError(
        f"path infeasible {where}: {what} exceeds the limit max_{name} = {lim:.4g} {unit}{need}"
    )


def _guard(max_angle):
    def ev(s, y):
        return max_angle - abs(y[0])
    ev.terminal = True
    return ev


def _s_of_t(piece: _Piece, t: np.ndarray, V_A: float) -> np.ndarray:
    """Local s at times t inside the piece: interpolation on the steps, then Newton."""
    s = np.interp(t, piece.t_steps, piece.s_steps)
    for _ in range(8):
        z = piece.sol(s)
        step = (z[1] - t) * V_A / np.cos(z[0])
        s = np.clip(s - step, 0.0, piece.length)
        if np.max(np.abs(step), initial=0.0) < 1e-14:
            break
    return s


@dataclass(frozen=True, eq=False)
class Reference:
    """The steering reference on a uniform time grid, with C's and A's paths.

    Arrays (length N, read-only): t (s), s (C's arc length, m), alpha0 (rad),
    alpha0_dot (rad/s), alpha0_ddot (rad/s^2), theta (chassis heading, rad),
    kappa (C's path curvature, 1/m), A_xy and C_xy (N, 2) in m. ``l1`` and
    ``V_A`` are the vehicle values it was made for.
    """

    t: np.ndarray
    s: np.ndarray
    alpha0: np.ndarray
    alpha0_dot: np.ndarray
    alpha0_ddot: np.ndarray
    theta: np.ndarray
    kappa: np.ndarray
    A_xy: np.ndarray
    C_xy: np.ndarray
    l1: float
    V_A: float

    @property
    def dt(self) -> float:
        return float(self.t[1] - self.t[0])

    @property
    def duration(self) -> float:
        """Time of the last sample (s)."""
        return float(self.t[-1])

    def __len__(self) -> int:
        return int(self.t.size)

    def at(self, t: ArrayLike) -> tuple[Any, Any, Any]:
        """(alpha0, alpha0', alpha0'') at times t, vectorised; floats for a scalar t.

        Cubic Hermite between grid samples for alpha0 (slopes alpha0') and for
        alpha0' (slopes alpha0''), linear for alpha0''. Times outside
        [0, duration] (beyond 1e-9 s) raise ParameterError.
        """
        tt = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(tt)):
            raise ParameterError("t must be finite")
        T = self.duration
        if tt.size and (tt.min() < -1e-9 or tt.max() > T + 1e-9):
            raise ParameterError(f"t must lie in [0, {T:.6g}] s (the reference's duration), "
                                 f"got {tt.min():.6g}..{tt.max():.6g}")
        h = self.dt
        tc = np.clip(tt, 0.0, T)
        i = np.clip(np.floor(tc / h).astype(np.int64), 0, self.t.size - 2)
        x = (tc - self.t[i]) / h
        h00 = (1 + 2 * x) * (1 - x) ** 2
        h10 = x * (1 - x) ** 2
        h01 = x * x * (3 - 2 * x)
        h11 = x * x * (x - 1)
        a, ad, add = self.alpha0, self.alpha0_dot, self.alpha0_ddot
        alpha = h00 * a[i] + h10 * h * ad[i] + h01 * a[i + 1] + h11 * h * ad[i + 1]
        alpha_d = h00 * ad[i] + h10 * h * add[i] + h01 * ad[i + 1] + h11 * h * add[i + 1]
        alpha_dd = (1 - x) * add[i] + x * add[i + 1]
        if tt.ndim == 0:
            return float(alpha), float(alpha_d), float(alpha_dd)
        return alpha, alpha_d, alpha_dd

    def bounds(self) -> ReferenceBounds:
        """Maxima over the grid, the quantities of (5.1).

        Returns:
            ReferenceBounds: alpha_ddot_max = max|alpha0''| [rad/s^2], alpha_dot_max =
            max|alpha0'| [rad/s], sin_cos3_max = max|sin(alpha0)/cos^3(alpha0)| [-],
            alpha_max = max|alpha0| [rad].
        """
        a = self.alpha0
        return ReferenceBounds(
            alpha_ddot_max=float(np.max(np.abs(self.alpha0_ddot))),
            alpha_dot_max=float(np.max(np.abs(self.alpha0_dot))),
            sin_cos3_max=float(np.max(np.abs(sin_cos3_of_samples(a)))),
            alpha_max=float(np.max(np.abs(a))),
        )


def make_reference(
    path: Path,
    params: C80Parameters = C80,
    *,
    dt: float = 1e-3,
    duration: float | None = None,
    initial_alpha: float | None = None,
    origin: Sequence[float] = (0.0, 0.0),
    heading: float = 0.0,
    max_angle: float | None = None,
    max_rate: float | None = None,
    max_accel: float | None = None,
) -> Reference:
    """Convert C's ``path`` into the steering reference for ``params`` (l1, V_A).

    Args:
        path: the path of point C.
        params: the parameter set (l1 [m], V_A [m/s] and the steering limits).
        dt: time step of the uniform grid [s].
        duration: stop there [s], at most the path's time; None: the whole path.
        initial_alpha: steering angle at t = 0 [rad]; None: the steady angle asin(l1 kappa(0)) of the
            path's initial curvature.
        origin, heading: pose of A at t = 0 [m, m], [rad].
        max_angle, max_rate, max_accel: steering limits [rad, rad/s, rad/s^2]; None: :func:`steering_limits`.

    Returns:
        The :class:`Reference` on the grid: alpha0 and its derivatives, s, theta, kappa, A_xy and C_xy.

    Raises:
        ParameterError: a bad argument.
        InfeasiblePathError: the path violates a steering limit (the message says where, s and t).
    """
    if not isinstance(path, Path):
        raise ParameterError(f"path must be a wmr_mj.reference.paths.Path, got {type(path).__name__}")
    if not isinstance(params, C80Parameters):
        raise ParameterError(f"params must be a C80Parameters, got {type(params).__name__}")
    h = _positive("dt", dt, " s")
    T_req = None if duration is None else _positive("duration", duration, " s")
    amax, rmax, accmax = _limits(params, max_angle, max_rate, max_accel)
    ox, oy, th0 = _pose(origin, heading)
    l1, V_A = params.l1, params.V_A
    a0 = _initial_angle(path, l1, initial_alpha, amax)

    run = _integrate(path, l1, V_A, a0, max_angle=amax, max_rate=rmax, max_accel=accmax, t_stop=T_req)
    t = _grid(run, h, T_req)
    s, z, k, dk = _sample(run, t, V_A)
    alpha, phi = z[0], z[2]
    ad, add = _alpha_dots(alpha, k, dk, l1, V_A)
    # C's path in the frame of its start, moved to the pose: C0 = A0 + l1 (cos th0, sin th0),
    # C's initial direction th0 + a0 (the integration used a0)
    rot = th0
    cx = ox + l1 * math.cos(th0) + math.cos(rot) * z[3] - math.sin(rot) * z[4]
    cy = oy + l1 * math.sin(th0) + math.sin(rot) * z[3] + math.cos(rot) * z[4]
    theta = th0 + phi - alpha
    ax = cx - l1 * np.cos(theta)
    ay = cy - l1 * np.sin(theta)

    arrays = dict(
        t=t, s=s, alpha0=alpha.copy(), alpha0_dot=ad, alpha0_ddot=add, theta=theta, kappa=k,
        A_xy=np.column_stack([ax, ay]), C_xy=np.column_stack([cx, cy]),
    )
    for v in arrays.values():
        v.setflags(write=False)
    return Reference(**arrays, l1=l1, V_A=V_A)


def _limits(params: C80Parameters, max_angle: float | None, max_rate: float | None,
            max_accel: float | None) -> tuple[float, float, float]:
    """The steering limits (angle [rad], rate [rad/s], acceleration [rad/s^2]): given or the plant's."""
    lim = steering_limits(params)
    amax = lim["max_angle"] if max_angle is None else _positive("max_angle", max_angle, " rad")
    if amax >= 0.5 * math.pi:
        raise ParameterError(f"max_angle = {amax} rad is not accepted: it must be below pi/2")
    rmax = lim["max_rate"] if max_rate is None else _positive("max_rate", max_rate, " rad/s")
    accmax = lim["max_accel"] if max_accel is None else _positive("max_accel", max_accel, " rad/s^2")
    return amax, rmax, accmax


def _pose(origin: Sequence[float], heading: float) -> tuple[float, float, float]:
    """A's starting pose (x [m], y [m], heading [rad]), checked."""
    try:
        ox, oy = (float(v) for v in origin)
    except (TypeError, ValueError):
        raise ParameterError(f"origin must be a pair of finite numbers (m), got {origin!r}") from None
    if not (math.isfinite(ox) and math.isfinite(oy)):
        raise ParameterError(f"origin must be a pair of finite numbers (m), got {origin!r}")
    return ox, oy, _number("heading", heading)


def _initial_angle(path: Path, l1: float, initial_alpha: float | None, amax: float) -> float:
    """The steering angle at t = 0 [rad]: given, or the steady angle of the path's initial curvature."""
    k0 = path.start_curvature
    if initial_alpha is None:
        if abs(k0) * l1 >= 1.0:
            raise InfeasiblePathError(
                f"path infeasible {_where(0.0, 0.0)}: its initial radius {1.0 / abs(k0):.4g} m is below the "
                f"wheelbase l1 = {l1:.4g} m; a steady start needs sin(alpha) = l1/R = {abs(k0) * l1:.4g} >= 1"
            )
        return math.asin(l1 * k0)
    a0 = _number("initial_alpha", initial_alpha)
    if abs(a0) >= amax:
        raise ParameterError(f"initial_alpha = {a0} rad is not accepted: |initial_alpha| must be below "
                             f"max_angle = {amax} rad")
    return a0


def _grid(run: _Run, h: float, T_req: float | None) -> np.ndarray:
    """The uniform time grid [s] of step h over the requested duration (or the whole path)."""
    T_path = run.t_end
    if T_req is not None and not run.stopped and T_req > T_path * (1 + 1e-12):
        raise DurationError(
            f"duration = {T_req} s is not accepted: the path takes {T_path:.6g} s; give duration <= that or None"
        )
    T = T_req if T_req is not None else T_path
    n = int(math.floor(T / h + 1e-6)) + 1
    if n < 2:
        raise ParameterError(f"dt = {h} s is not accepted: it must be below the reference's duration {T:.6g} s")
    return np.arange(n) * h


def _sample(run: _Run, t: np.ndarray, V_A: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(s [m], the integrated state z (5, n), kappa [1/m], dkappa/ds [1/m^2]) at the times t, piece by piece."""
    n = len(t)
    s = np.empty(n)
    z = np.empty((5, n))
    k = np.empty(n)
    dk = np.empty(n)
    t_starts = np.array([p.t_steps[0] for p in run.pieces])
    idx = np.clip(np.searchsorted(t_starts, t, side="right") - 1, 0, len(run.pieces) - 1)
    for j, piece in enumerate(run.pieces):
        m = idx == j
        if not np.any(m):
            continue
        sl = _s_of_t(piece, t[m], V_A)
        s[m] = piece.s0 + sl
        z[:, m] = piece.sol(sl)
        k[m] = piece.segment.curvature(sl)
        dk[m] = piece.segment.curvature_rate(sl)
    return s, z, k, dk


# --------------------------------------------------------------------------
def _entry_peaks(entry: Path, l1: float, V_A: float) -> tuple[float, float]:
    """max |alpha'|, max |alpha''| over ``entry`` (starting straight, alpha = 0)."""
    run = _integrate(entry, l1, V_A, 0.0, max_angle=0.5 * math.pi - 1e-6)
    pr = pa = 0.0
    for piece in run.pieces:
        sl = np.linspace(0.0, piece.length, 4001)
        a = piece.sol(sl)[0]
        ad, add = _alpha_dots(a, piece.segment.curvature(sl), piece.segment.curvature_rate(sl), l1, V_A)
        pr, pa = max(pr, float(np.max(np.abs(ad)))), max(pa, float(np.max(np.abs(add))))
    return pr, pa


def paper_circle(
    params: C80Parameters = C80,
    *,
    radius: float = 1.0,
    lead_in: float = 0.4,
    duration: float = 35.0,
    entry: Literal["ramp", "blend"] = "ramp",
    transition: float | None = None,
    peak_rate: float = PAPER_BOUNDS.alpha_dot_max,
    peak_accel: float = PAPER_BOUNDS.alpha_ddot_max,
) -> Path:
    """The paper's experiment (Figs. 4-6): C on a circle of ``radius`` m at params.V_A.

    A straight ``lead_in`` (m), an entry of length ``transition`` (m), then the
    circle until ``duration`` s in all (the circle's arc length is solved for
    it, so ``make_reference(path, params)`` lasts exactly ``duration``).

    entry='ramp' (default): :func:`steering_ramp` matched to params.l1, alpha0
    rises along a septic smoothstep to asin(l1/R). entry='blend': a quintic
    curvature blend (:func:`transition`), alpha0 lags and creeps to asin(l1/R).
    transition=None chooses the shortest entry with max|alpha0'| <= peak_rate
    and max|alpha0''| <= peak_accel ((5.1): 0.23 rad/s, 0.4 rad/s^2). For the
    ramp both scale exactly as 1/L and 1/L^2, so L = max(M1/peak_rate,
    sqrt(M2/peak_accel)) from the peaks M1, M2 of a 1 m ramp; for the blend L
    is found by bisection. C80: ramp L = 1.33 m, the rate bound binds.
    """
    if not isinstance(params, C80Parameters):
        raise ParameterError(f"params must be a C80Parameters, got {type(params).__name__}")
    R = _number("radius", radius)
    if R == 0.0:
        raise ParameterError("radius = 0 is not accepted: a signed radius in m (> 0 turns left)")
    lead = _positive("lead_in", lead_in, " m")
    T = _positive("duration", duration, " s")
    pr = _positive("peak_rate", peak_rate, " rad/s")
    pa = _positive("peak_accel", peak_accel, " rad/s^2")
    if entry not in ("ramp", "blend"):
        raise ParameterError(f"entry = {entry!r} is not accepted: 'ramp' or 'blend'")
    l1, V_A = params.l1, params.V_A
    if abs(R) <= l1:
        raise InfeasiblePathError(
            f"path infeasible {_where(lead, lead / V_A)}: the circle's radius {abs(R):.4g} m is below the "
            f"wheelbase l1 = {l1:.4g} m; holding it needs sin(alpha) = l1/R = {l1 / abs(R):.4g} >= 1"
        )
    a_ss = math.asin(l1 / abs(R))
    tail = circle(R, length=2.0 * l1 / math.cos(a_ss))  # enough for the blend's lag to decay

    def make_entry(L: float) -> Path:
        if entry == "ramp":
            return steering_ramp(L, l1=l1, to_radius=R)
        return _curvature_blend(L, to_radius=R)

    if transition is not None:
        L = _positive("transition", transition, " m")
    elif entry == "ramp":
        m1, m2 = _entry_peaks(make_entry(1.0), l1, V_A)
        L = max(m1 / pr, math.sqrt(m2 / pa))
    else:
        def excess(L: float) -> float:
            r, a = _entry_peaks(make_entry(L) + tail, l1, V_A)
            return max(r / pr, a / pa) - 1.0
        lo, hi = 1e-3, 1.0
        while excess(hi) > 0.0:
            hi *= 2.0
            if hi > 1e3:
                raise ParameterError(f"peak_rate = {pr}, peak_accel = {pa} cannot be met by a blend entry")
        L = brentq(excess, lo, hi, xtol=1e-9, rtol=1e-12) if excess(lo) > 0.0 else lo

    head = line(lead) + make_entry(L)
    # time to the circle, then the circle's arc length that fills the duration
    guess = head + circle(R, length=(T * V_A / math.cos(a_ss)) * 1.05 + 1.0)
    run = _integrate(guess, l1, V_A, 0.0, max_angle=0.5 * math.pi - 1e-6, t_stop=T)
    if not run.stopped or run.s_end <= head.length:
        # C's time over the lead-in and entry alone: the circle starts only after it
        t_head = _integrate(head, l1, V_A, 0.0, max_angle=0.5 * math.pi - 1e-6).t_end
        raise DurationError(
            f"duration = {T} s is not accepted: the lead-in and entry alone take {t_head:.3f} s; "
            f"give a longer duration (at least {math.ceil(t_head * 1e3) / 1e3:.3f} s)"
        )
    return head + circle(R, length=run.s_end - head.length)
