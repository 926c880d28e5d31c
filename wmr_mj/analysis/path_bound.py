"""What a bound on the steering error implies for C's path: kinematics, no simulation.

The certificate bounds |E| = |alpha0 - alpha| <= E_max. Where C goes follows from the paper's
kinematics (section 2; ``wmr_mj.reference.paths``): the rear axle rolls without side slip, so
the chassis turns at theta' = V_A tan(alpha) / l1 about a point on the rear-axle line, and C,
the steering pivot l1 ahead of A, moves along theta + alpha at V_C = V_A / cos(alpha) with path
curvature

    kappa_C = sin(alpha) / l1 + alpha' cos(alpha) / V_A.

**Circle** of radius R (steady angle alpha0 = asin(l1 / R), 0.659 rad for the C80 on 1 m). With
the steering held at a constant alpha (alpha' = 0) C moves on a circle of radius

    R_C(alpha) = l1 / sin(alpha),      dR_C/dalpha = -l1 cos(alpha) / sin^2(alpha)

(-1.29 m/rad at 0.659 rad). A constant offset |e| <= E_max keeps alpha in
[alpha0 - E_max, alpha0 + E_max], so C's circle lies in [l1/sin(alpha0 + E_max),
l1/sin(alpha0 - E_max)]: R_C is convex and falling, the larger shift is on the side of the
smaller angle, and it is at most max|dR_C/dalpha| E_max = l1 cos(alpha0 - E_max)/sin^2(alpha0 -
E_max) E_max (``radius_shift_linear``; ``radius_shift`` is the exact one). If C is on the desired
circle, along its tangent, when the offset sets in, its circle touches the desired one there,
and C strays up to twice the radius shift from it, half a lap later: ``cross_track_bound`` =
2 ``radius_shift``. No bound holds along the path: C goes round its circle at V_A tan(alpha)/l1
instead of V_A tan(alpha0)/l1, so it falls behind (or runs ahead of) the timed reference at up to
R V_A |tan(alpha0 +- E_max) - tan(alpha0)| / l1 (``along_track_rate_max``), without bound.

**Straight line** (alpha0 = 0). A constant offset e turns the chassis at V_A tan(e) / l1 and
moves C sideways at V_A tan(e) from the first instant: C leaves the line on a circle of
radius l1 / sin|e| (:func:`straight_line_drift`, closed form). A joint-space loop has no
position feedback that could bring C back: **no Cartesian guarantee**, with the drift rates.

The assumptions are listed in each :class:`PathBound`; transients (E' != 0: the entry of a
circle, a curvature change) and offsets that vary with time (one at the lap frequency moves
C's circle lap after lap) are not covered: they need their own term.

Only a certificate that holds (valid, every assumption met) bounds |E|: :func:`guaranteed_E_max` gives
its E_max, or None with the reason (a certificate whose assumptions fail gives no path guarantee).

Usage::

    from wmr_mj.analysis.path_bound import guaranteed_E_max, path_bound, path_verdict
    E_max, why_not = guaranteed_E_max(E_max=cert.E_max, valid=cert.valid, unmet=cert.unmet)
    bound = path_bound(reference, E_max=E_max, settle_s=settle_s)
    bound.cross_track_bound, bound.reason, bound.assumptions
    path_verdict(errors, bound).verdict    # 'within-bound', 'beyond-bound' or 'no-guarantee'
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from wmr_mj.errors import ParameterError
from wmr_mj.params import C80

__all__ = [
    "PathBound",
    "PathVerdict",
    "PATH_VERDICTS",
    "steady_radius",
    "steady_radius_slope",
    "steady_angle",
    "circle_bound",
    "line_bound",
    "path_bound",
    "path_verdict",
    "guaranteed_E_max",
    "without_guarantee",
    "straight_line_drift",
]

PATH_VERDICTS = ("within-bound", "beyond-bound", "no-guarantee")

_NO_SLIP = ("no side slip: C moves about the instantaneous centre on the rear-axle line, the kinematics of the "
            "paper's section 2 (kappa_C = sin(alpha)/l1 + alpha' cos(alpha)/V_A)")
_V_A = "V_A constant"
_NO_FEEDBACK = "the controller steers alpha towards alpha0(t) only: it has no feedback of C's position"


def steady_radius(alpha: ArrayLike, l1: float = C80.l1) -> np.ndarray | float:
    """C's circle at a steady steering angle: l1 / |sin(alpha)| [m] (inf at alpha = 0)."""
    a = np.asarray(alpha, dtype=float)
    with np.errstate(divide="ignore"):
        r = l1 / np.abs(np.sin(a))
    return float(r) if r.ndim == 0 else r


def steady_radius_slope(alpha: ArrayLike, l1: float = C80.l1) -> np.ndarray | float:
    """dR_C/dalpha = -l1 cos(alpha) / sin^2(alpha) [m/rad] (for alpha > 0)."""
    a = np.asarray(alpha, dtype=float)
    with np.errstate(divide="ignore"):
        r = -l1 * np.cos(a) / np.sin(a) ** 2
    return float(r) if r.ndim == 0 else r


def steady_angle(radius: float, l1: float = C80.l1) -> float:
    """The steering angle that holds C on a circle of radius |radius|: asin(l1/|R|) [rad]."""
    R = abs(float(radius))
    if not (math.isfinite(R) and R > l1):
        raise ParameterError(f"radius = {radius!r} m is not accepted: C's circle needs |radius| > l1 = {l1:.4g} m")
    return math.asin(l1 / R)


@dataclass(frozen=True)
class PathBound:
    """What |E| <= E_max implies for C's path (see the module docstring)."""

    kind: str
    """'circle' (a steady bound exists or fails for a stated reason), 'line', or 'none' (no |E| bound, or
    a path whose curvature varies where it is judged)."""
    cross_track_bound: float | None
    """bound on |cross-track| [m], or None: no Cartesian guarantee."""
    reason: str
    """one sentence: what the bound is, or why there is none."""
    assumptions: tuple[str, ...]
    """what the bound rests on, each a sentence."""
    E_max: float | None
    """the steering-error bound used [rad]."""
    radius: float | None = None
    """desired radius of C's path [m] (circle), signed: > 0 turns left."""
    alpha0: float | None = None
    """steady steering angle of the desired circle [rad]."""
    radius_range: tuple[float, float] | None = None
    """C's steady circle over |e| <= E_max: (smallest, largest) radius [m]."""
    radius_shift: float | None = None
    """max |R_C(alpha) - R| over |alpha - alpha0| <= E_max [m] (exact)."""
    radius_shift_linear: float | None = None
    """max |dR_C/dalpha| E_max over the same range [m] (the linear estimate; >= radius_shift)."""
    heading_rate_max: float | None = None
    """chassis heading drift against the reference under an offset E_max, max V_A |tan(alpha) - tan(alpha0)| / l1
    [rad/s]."""
    along_track_rate_max: float | None = None
    """along-track drift rate [m/s]: no along-track bound exists, the lag grows at up to this rate."""
    cross_track_rate_initial: float | None = None
    """line: C's sideways speed the moment an offset E_max sets in, V_A tan(E_max) [m/s]."""
    settle_s: float | None = None
    """the path is judged from this time on [s] (None: the whole reference)."""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (assumptions as a list, radius_range as a list)."""
        d = asdict(self)
        d["assumptions"] = list(self.assumptions)
        d["radius_range"] = None if self.radius_range is None else list(self.radius_range)
        return d

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> PathBound:
        """The bound of its JSON ``d`` (what :meth:`to_dict` wrote: the lists as tuples again)."""
        radius_range = d.get("radius_range")
        return cls(**{**d, "assumptions": tuple(d["assumptions"]),
                      "radius_range": None if radius_range is None else tuple(radius_range)})


#: How a path bound without a bound on |E| says so.
_NO_E_BOUND = "there is no bound on the steering error |E|"


def guaranteed_E_max(*, E_max: float | None, valid: bool, unmet: Any = ()) -> tuple[float | None, str]:
    """The steering-error bound a path bound may rest on: the certificate's E_max when it holds.

    A certificate that is not valid has no bound; one whose assumptions are not all met has a number that
    is no guarantee, so neither bounds C's path.

    Args:
        E_max: the certificate's bound on |E| [rad] (None or inf: none).
        valid: the certificate's bound exists (its fixed point was found).
        unmet: the names of its assumptions that are not met (empty: it holds).

    Returns:
        (E_max [rad] or None, why a finite E_max is no bound: '' when E_max is returned or there is none).
    """
    names = [str(n) for n in unmet or ()]
    if not valid or E_max is None or not math.isfinite(float(E_max)):
        return None, ""  # the path bound's own reason says it (_NO_E_BOUND)
    if names:
        return None, f"the certificate's |E| <= {float(E_max):.4g} rad does not hold: {', '.join(names)} not met"
    return float(E_max), ""


def without_guarantee(bound: PathBound, why: str) -> PathBound:
    """``bound`` (computed with no E_max) with its reason saying why the certificate's E_max was not used.

    Args:
        bound: a :class:`PathBound` of :func:`path_bound` with E_max None.
        why: :func:`guaranteed_E_max`'s reason ('' leaves the bound as it is).
    """
    if not why:
        return bound
    reason = (bound.reason.replace(_NO_E_BOUND, f"{_NO_E_BOUND} ({why})", 1) if _NO_E_BOUND in bound.reason
              else f"{bound.reason} ({why})")
    return replace(bound, reason=reason)


def _check_E(E_max: Any) -> float | None:
    if E_max is None:
        return None
    if isinstance(E_max, bool) or not isinstance(E_max, (int, float, np.integer, np.floating)):
        raise ParameterError(f"E_max must be a number [rad] or None, got {E_max!r}")
    e = float(E_max)
    if math.isnan(e) or e < 0.0:
        raise ParameterError(f"E_max = {E_max!r} rad is not accepted: >= 0, inf or None for no bound")
    return e if math.isfinite(e) else None


def _no_bound(kind: str, why: str, *, settle_s: float | None = None, **extra: Any) -> PathBound:
    return PathBound(kind=kind, cross_track_bound=None, reason=f"no Cartesian guarantee: {why}",
                     assumptions=(_NO_SLIP, _NO_FEEDBACK), E_max=None, settle_s=settle_s, **extra)


def circle_bound(radius: float, E_max: float | None, *, l1: float = C80.l1, V_A: float = C80.V_A,
                 max_angle: float | None = None, settle_s: float | None = None) -> PathBound:
    """The steady cross-track bound on a circle of signed ``radius`` [m] for |E| <= E_max [rad].

    max_angle [rad]: the steering stops, which cap alpha (and so C's smallest circle).
    """
    R = float(radius)
    a0 = steady_angle(R, l1)
    E = _check_E(E_max)
    if E is None:
        return _no_bound("circle", _NO_E_BOUND, radius=R, alpha0=a0,
                         settle_s=settle_s)
    lo, hi = a0 - E, a0 + E
    if max_angle is not None:
        hi = min(hi, float(max_angle))
    t0 = math.tan(a0)
    heading_rate = V_A * max(math.tan(hi) - t0, t0 - math.tan(max(lo, 0.0))) / l1 if hi < 0.5 * math.pi else math.inf
    along = abs(R) * heading_rate
    assumptions = (
        _NO_SLIP,
        "steady state: alpha constant (E' = 0), so C moves on a circle; the entry of the circle and any other "
        "transient are not covered and need their own term",
        f"a constant steering offset |e| <= E_max = {E:.4g} rad; an offset that varies with time (at the lap "
        "frequency in particular) moves C's circle lap after lap and is not covered",
        "C on the desired circle and along its tangent when the offset sets in: C's circle then touches the "
        "desired one, and C strays up to twice the radius shift from it",
        f"{_V_A}: it does not enter the steady radius, only the drift rates",
    )
    if lo <= 0.0:
        return PathBound(kind="circle", cross_track_bound=None, E_max=E, radius=R, alpha0=a0,
                         radius_range=(l1 / math.sin(hi), math.inf), heading_rate_max=heading_rate,
                         along_track_rate_max=along, assumptions=assumptions, settle_s=settle_s,
                         reason=f"no Cartesian guarantee: alpha0 - E_max = {lo:.4g} rad <= 0, so C may go straight "
                                f"(its steady radius l1/sin(alpha) is unbounded)")
    r_small, r_large = l1 / math.sin(hi), l1 / math.sin(lo)
    shift = max(r_large - abs(R), abs(R) - r_small)
    linear = l1 * math.cos(lo) / math.sin(lo) ** 2 * E
    bound = 2.0 * shift
    return PathBound(
        kind="circle", cross_track_bound=bound, E_max=E, radius=R, alpha0=a0, radius_range=(r_small, r_large),
        radius_shift=shift, radius_shift_linear=linear, heading_rate_max=heading_rate,
        along_track_rate_max=along, assumptions=assumptions, settle_s=settle_s,
        reason=(f"steady state on the R = {abs(R):.4g} m circle: |E| <= {E:.4g} rad keeps C's circle within "
                f"{r_small:.4g}..{r_large:.4g} m (radius shift <= {shift:.4g} m; max|dR/dalpha| E_max = "
                f"{linear:.4g} m), so |cross-track| <= 2 x {shift:.4g} = {bound:.4g} m; along the path no bound: "
                f"C drifts from the timed reference at up to {along:.3g} m/s"),
    )


def line_bound(E_max: float | None, *, l1: float = C80.l1, V_A: float = C80.V_A,
               settle_s: float | None = None) -> PathBound:
    """On a straight line: no Cartesian guarantee; the drift rates an offset E_max [rad] gives."""
    E = _check_E(E_max)
    if E is None:
        return _no_bound("line", _NO_E_BOUND, settle_s=settle_s)
    rate = V_A * math.tan(E) / l1 if E < 0.5 * math.pi else math.inf
    side = V_A * math.tan(E) if E < 0.5 * math.pi else math.inf
    return PathBound(
        kind="line", cross_track_bound=None, E_max=E, heading_rate_max=rate, along_track_rate_max=None,
        cross_track_rate_initial=side, settle_s=settle_s,
        assumptions=(_NO_SLIP, _NO_FEEDBACK, f"a steering offset |e| <= E_max = {E:.4g} rad", _V_A),
        reason=(f"no Cartesian guarantee on a straight line: a steering offset E_max = {E:.4g} rad turns the chassis "
                f"at up to V_A tan(E_max)/l1 = {rate:.3g} rad/s and moves C sideways at up to {side:.3g} m/s from "
                f"the first instant (C then circles at radius l1/sin(E_max) = "
                f"{(l1 / math.sin(E) if E > 0 else math.inf):.4g} m); without position feedback nothing brings C "
                "back, and the along-track lag is unbounded too"),
    )


def path_bound(reference: Any, E_max: float | None, *, settle_s: float | None = None,
               max_angle: float | None = None, tol: float = 1e-9) -> PathBound:
    """The path bound for a run: its ``reference`` (a Reference: t, kappa, l1, V_A) judged from
    ``settle_s`` [s] on (None: from the start), with the steering-error bound ``E_max`` [rad]
    (the certificate's; None or inf: no bound).

    A constant non-zero curvature there gives :func:`circle_bound`, a zero one :func:`line_bound`;
    a curvature that varies (a lane change, a figure eight, a route, the paper circle's lead-in
    and entry when settle_s is None) gives no Cartesian guarantee: its straights and transitions
    have none.
    """
    try:
        t = np.asarray(reference.t, float)
        kappa = np.asarray(reference.kappa, float)
        l1, V_A = float(reference.l1), float(reference.V_A)
    except AttributeError:
        raise ParameterError("reference must be a wmr_mj.reference.paths.Reference (t, kappa, l1, V_A), got "
                             f"{type(reference).__name__}") from None
    k = kappa if settle_s is None else kappa[t >= float(settle_s)]
    if k.size == 0:
        raise ParameterError(f"settle_s = {settle_s!r} s is not accepted: the reference ends at {t[-1]:.6g} s")
    E = _check_E(E_max)
    where = "" if settle_s is None else f" after t = {float(settle_s):g} s"
    if float(np.max(k) - np.min(k)) <= tol:
        kc = float(np.mean(k))
        if abs(kc) <= tol:
            return line_bound(E, l1=l1, V_A=V_A, settle_s=settle_s)
        return circle_bound(1.0 / kc, E, l1=l1, V_A=V_A, max_angle=max_angle, settle_s=settle_s)
    straight = bool(np.any(np.abs(k) <= tol))
    rate = None
    if E is not None and E < 0.5 * math.pi:
        a0 = np.arcsin(np.clip(l1 * np.abs(k), 0.0, 1.0 - 1e-12))
        hi = np.minimum(a0 + E, 0.5 * math.pi - 1e-9)
        rate = float(V_A * np.max(np.tan(hi) - np.tan(a0)) / l1)
    why = (f"the path's curvature varies{where} ({float(np.min(k)):.4g}..{float(np.max(k)):.4g} 1/m"
           + (", with straights" if straight else "") + "); the steady circle bound does not apply, and "
           "straights and transitions give no bound without position feedback")
    if E is None:
        why = f"{_NO_E_BOUND}; " + why
    return PathBound(kind="none", cross_track_bound=None, reason=f"no Cartesian guarantee: {why}",
                     assumptions=(_NO_SLIP, _NO_FEEDBACK), E_max=E, heading_rate_max=rate, settle_s=settle_s)


@dataclass(frozen=True)
class PathVerdict:
    """A run's cross-track against its :class:`PathBound`."""

    verdict: str
    """'within-bound', 'beyond-bound' (the run left the bound: a transient, a varying offset, slip, or a bug), or
    'no-guarantee' (no bound to judge against)."""
    cross_track_max: float
    """the run's sup |cross-track| judged [m] (after settle_s when the bound starts there)."""
    cross_track_bound: float | None
    """the bound [m], or None."""
    ratio: float | None
    """cross_track_max / cross_track_bound, or None."""
    text: str
    """one line for the report."""

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> PathVerdict:
        """The verdict of its JSON ``d`` (what :meth:`to_dict` wrote)."""
        return cls(**d)


def path_verdict(errors: Any, bound: PathBound) -> PathVerdict:
    """Judge a run's path errors (a PathErrors or its to_dict()) against ``bound``.

    When the bound starts at settle_s and the errors carry cross_track_max_after_settle, that
    one is judged; else the whole run's cross_track_max.
    """
    e = errors if isinstance(errors, Mapping) else errors.to_dict()
    late = e.get("cross_track_max_after_settle")
    use_late = bound.settle_s is not None and late is not None
    ct = float(late) if use_late and late is not None else float(e["cross_track_max"])
    span = f"after t = {bound.settle_s:g} s" if use_late else "whole run"
    if bound.cross_track_bound is None:
        return PathVerdict("no-guarantee", ct, None, None,
                           f"{bound.reason}; measured sup|cross-track| = {ct:.4g} m ({span})")
    b = bound.cross_track_bound
    ratio = ct / b if b > 0 else math.inf
    v = "within-bound" if ct <= b else "beyond-bound"
    word = "within" if ct <= b else "BEYOND"
    return PathVerdict(v, ct, b, ratio, f"sup|cross-track| = {ct:.4g} m ({span}) {word} the steady-state "
                                        f"bound {b:.4g} m ({ratio:.3g} of it); {bound.reason}")


def straight_line_drift(e: float, t: ArrayLike, *, l1: float = C80.l1, V_A: float = C80.V_A):
    """C's cross-track [m] and chassis heading [rad] at times t [s] after a constant steering
    angle e [rad] is held from the start of a straight line (A at the origin, heading 0): the
    kinematic model's closed form. The chassis turns at w = V_A tan(e)/l1, and
    cross-track = l1 sin(w t) + (l1/tan e)(1 - cos(w t)) (> 0 left), heading = w t."""
    tt = np.asarray(t, dtype=float)
    ee = float(e)
    if ee == 0.0:
        return np.zeros_like(tt), np.zeros_like(tt)
    w = V_A * math.tan(ee) / l1
    return l1 * np.sin(w * tt) + (l1 / math.tan(ee)) * (1.0 - np.cos(w * tt)), w * tt
