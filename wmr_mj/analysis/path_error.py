"""Cartesian errors of point C against its desired path: cross-track, along-track, heading.

The steering error E = alpha0 - alpha says how well the joint follows alpha0(t); it does not
say where C goes. This module measures that, from C's positions and the chassis heading at
the run's sample times, against the :class:`~wmr_mj.reference.paths.Reference` the run was
given (C's desired path C_xy over its arc length s, the timed s(t), the desired chassis
heading theta).

- **cross-track** [m]: signed distance of C from the desired path, > 0 to the left of the
  direction of travel (the sign convention of the paths' radii). C is projected onto the path
  *with arc-length continuity*: each sample's projection is searched within ``window`` m of arc
  length around the previous one (plus the distance C travelled since), never over the whole
  path, so a figure eight's crossing or a second lap cannot make the projection jump. Beyond
  the path's ends the path is continued by arcs of its end curvatures.
- **along-track** [m]: arc length of the projection minus the timed reference's s(t): > 0 ahead
  of the reference, < 0 behind. A timed lag of tau s at C's speed V_C gives -tau V_C.
- **heading error** [rad]: chassis heading minus the desired chassis heading at the projection,
  wrapped to (-pi, pi]. The desired chassis heading is the reference's theta; it is C's path
  tangent minus alpha0 (C moves along theta + alpha), so a cart exactly on its path and its
  reference has heading error 0, while the raw tangent of C's path differs from the chassis
  heading by alpha0 (0.659 rad on the paper's 1 m circle).

Each with its sup (largest magnitude), RMS and final value, in :class:`PathErrors`.

A position so far from the path (beyond ~1.3e154 m, only a diverged run's) that its squared
distance overflows gets cross-track +-inf by its side (+inf on the chord's line), without a warning
(up to |C| ~ 1e300 m; nearer the float maximum the search's own sums overflow).

Usage::

    from wmr_mj.analysis.path_error import path_errors
    err = path_errors(reference, rows["t"], C_xy, heading)      # C_xy (n, 2) m, heading (n,) rad
    err.cross_track_max, err.along_track_final, err.to_dict()

NumPy, with the projection's loop in C where ``pip install`` built it (``_nearest_chord.c``, the same
bits; :func:`projection_backend` says which): no simulation, no file.
"""

from __future__ import annotations

import ctypes
import math
import os
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from functools import cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from wmr_mj.errors import ParameterError

__all__ = ["PathErrors", "PathErrorSeries", "PathProjector", "path_error_series", "path_errors", "wrap_angle"]

#: spacing of the polyline the projection searches [m]; a sagitta correction from the
#: reference's curvature removes the chord's offset (kappa ds^2 / 8: 2 um at 1/m)
POLYLINE_SPACING = 4e-3
#: default half-width of the arc-length window around the previous projection [m]
WINDOW = 0.1
_BLOCK = 128  # samples projected together (each block searches one window)
_COMPILED_ENV = "WMR_MJ_COMPILED_PROJECTION"  # "0": the nearest-chord loop in NumPy even where C is built


def wrap_angle(x: ArrayLike) -> np.ndarray:
    """Angles wrapped to (-pi, pi] [rad]."""
    a = np.asarray(x, dtype=float)
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


@dataclass(frozen=True, eq=False)
class PathErrorSeries:
    """Per-sample errors of C (arrays of length n, read-only).

    t [s]; C_xy [m] (n, 2): C's positions judged; s [m]: arc length of C's projection on the
    desired path; s_ref [m]: the timed reference's arc length at t; cross_track [m] (> 0:
    left of the path); along_track [m] (s - s_ref, > 0: ahead); heading_error [rad] (chassis
    heading minus the desired one at the projection, wrapped); beyond_end: the projection
    fell on a continuation of the path past its start or end.
    """

    t: np.ndarray
    C_xy: np.ndarray
    s: np.ndarray
    s_ref: np.ndarray
    cross_track: np.ndarray
    along_track: np.ndarray
    heading_error: np.ndarray
    beyond_end: np.ndarray


@dataclass(frozen=True)
class PathErrors:
    """Summary of C's Cartesian errors over a run (see the module docstring for signs).

    Fields (max = largest magnitude, rms = root mean square of the signed values, final =
    signed value at the last sample):
    """

    cross_track_max: float
    """sup |cross-track| [m]."""
    cross_track_rms: float
    """RMS cross-track [m]."""
    cross_track_final: float
    """cross-track at the last sample [m], > 0 left of the path."""
    along_track_max: float
    """sup |along-track| [m]."""
    along_track_rms: float
    """RMS along-track [m]."""
    along_track_final: float
    """along-track at the last sample [m], > 0 ahead of the timed reference, < 0 behind."""
    heading_error_max: float
    """sup |heading error| [rad]."""
    heading_error_rms: float
    """RMS heading error [rad]."""
    heading_error_final: float
    """heading error at the last sample [rad]."""
    cross_track_max_after_settle: float | None
    """sup |cross-track| over t >= settle_s [m]; None when no settle_s was given."""
    settle_s: float | None
    """the settling time used [s], or None."""
    samples: int
    """number of samples judged."""
    beyond_end_samples: int
    """samples whose projection fell on the path's continuation past its start or end."""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: the fields under their names (units as in the field docs)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> PathErrors:
        """The errors of their JSON ``d`` (what :meth:`to_dict` wrote)."""
        return cls(**d)


def _as_reference_arrays(reference: Any) -> tuple[np.ndarray, ...]:
    try:
        t = np.asarray(reference.t, float)
        s = np.asarray(reference.s, float)
        C = np.asarray(reference.C_xy, float)
        theta = np.asarray(reference.theta, float)
        alpha0 = np.asarray(reference.alpha0, float)
        kappa = np.asarray(reference.kappa, float)
    except AttributeError:
        raise ParameterError("reference must be a wmr_mj.reference.paths.Reference (t, s, C_xy, theta, alpha0, "
                             f"kappa), got {type(reference).__name__}") from None
    if t.size < 2 or C.shape != (t.size, 2):
        raise ParameterError("reference must hold at least 2 samples with C_xy of shape (n, 2)")
    return t, s, C, theta, alpha0, kappa


def _continuation(C: np.ndarray, phi: float, kappa: float, alpha0: float, lengths: np.ndarray, sign: float):
    """Points at arc lengths sign*lengths from C along an arc of curvature kappa leaving at phi."""
    u = sign * lengths
    if abs(kappa) < 1e-12:
        x = C[0] + u * math.cos(phi)
        y = C[1] + u * math.sin(phi)
    else:
        r = 1.0 / kappa
        x = C[0] + r * (np.sin(phi + kappa * u) - math.sin(phi))
        y = C[1] - r * (np.cos(phi + kappa * u) - math.cos(phi))
    ph = phi + kappa * u
    return np.column_stack([x, y]), ph - alpha0, np.full(u.shape, kappa)


def _geometry(reference: Any, spacing: float, extend: float):
    """Polyline of C's desired path: (s, xy, theta, kappa, lo, hi) with the continuations."""
    t, s, C, theta, alpha0, kappa = _as_reference_arrays(reference)
    step = max(1, int(spacing / max(float(np.median(np.diff(s))), 1e-12)))
    idx = np.arange(0, s.size, step)
    if idx[-1] != s.size - 1:
        idx = np.append(idx, s.size - 1)
    ext = np.arange(1, int(math.ceil(extend / spacing)) + 1) * spacing
    phi0, phi1 = theta[0] + alpha0[0], theta[-1] + alpha0[-1]
    pre_xy, pre_th, pre_k = _continuation(C[0], phi0, float(kappa[0]), float(alpha0[0]), ext[::-1], -1.0)
    post_xy, post_th, post_k = _continuation(C[-1], phi1, float(kappa[-1]), float(alpha0[-1]), ext, 1.0)
    gs = np.concatenate([s[0] - ext[::-1], s[idx], s[-1] + ext])
    gxy = np.concatenate([pre_xy, C[idx], post_xy])
    gth = np.concatenate([pre_th, theta[idx], post_th])
    gk = np.concatenate([pre_k, kappa[idx], post_k])
    return gs, gxy, gth, gk, float(s[0]), float(s[-1])


@cache
def _library_block() -> Any:
    """``wmr_mj_project_block`` of wmr_mj/analysis/_nearest_chord.c (ctypes; arrays passed as addresses),
    or None where it is not built (loaded once)."""
    try:
        from wmr_mj.analysis import _nearest_chord  # type: ignore[attr-defined]  # a C extension, built in place
    except ImportError:
        return None
    fn = ctypes.CDLL(_nearest_chord.__file__).wmr_mj_project_block
    address, n = ctypes.c_void_p, ctypes.c_int64
    fn.argtypes = (address, address, n, *[address] * 8, n, n, n, address, address, address, address)
    fn.restype = ctypes.c_int64
    return fn


def _compiled_block() -> Any:
    """The C block step, or None where it is not built or is switched off (``WMR_MJ_COMPILED_PROJECTION=0``,
    read at every projection, as the compiled law reads its switch)."""
    return None if os.environ.get(_COMPILED_ENV, "1") == "0" else _library_block()


def projection_backend() -> str:
    """``"C"`` where C's projection runs compiled (wmr_mj/analysis/_nearest_chord.c: the same bits as NumPy,
    a fraction of the time, without the GIL), else ``"NumPy"``."""
    return "NumPy" if _compiled_block() is None else "C"


class _Polyline:
    """The polyline's chords and a run's points as the block step reads them: float64, contiguous, and
    (for the C loop) their addresses."""

    def __init__(self, gs: np.ndarray, gxy: np.ndarray, gk: np.ndarray, X: np.ndarray) -> None:
        self.gs = np.ascontiguousarray(gs, dtype=np.float64)
        self.Ax, self.Ay = gxy[:-1, 0].copy(), gxy[:-1, 1].copy()
        self.Dx, self.Dy = np.diff(gxy[:, 0]), np.diff(gxy[:, 1])
        L2 = self.Dx * self.Dx + self.Dy * self.Dy
        self.L2 = np.where(L2 > 0.0, L2, 1e-300)
        self.seg_len = np.diff(self.gs)
        self.kmid = 0.5 * (gk[:-1] + gk[1:])
        self.Xx, self.Xy = (np.ascontiguousarray(X[:, k], dtype=np.float64) for k in (0, 1))  # read only
        self.nseg = len(self.Ax)
        self.out_s, self.out_d = np.empty(len(X)), np.empty(len(X))
        self._s_next, self._scratch = np.empty(1), np.empty(self.nseg + 1)
        self._chords = [a.ctypes.data for a in (self.Ax, self.Ay, self.Dx, self.Dy, self.L2, self.gs, self.seg_len,
                                                self.kmid)]
        self._addresses = [a.ctypes.data for a in (self.Xx, self.Xy, self.out_s, self.out_d, self._scratch,
                                                   self._s_next)]

    def block_c(self, fn: Any, b: int, e: int, lo: int, hi: int) -> tuple[int, float]:
        """:meth:`block_numpy` in C."""
        x, y, out_s, out_d, scratch, s_next = self._addresses
        m = fn(x + 8 * b, y + 8 * b, e - b, *self._chords, lo, hi, self.nseg, scratch, out_s + 8 * b, out_d + 8 * b,
               s_next)
        return int(m), float(self._s_next[0])

    def block_numpy(self, b: int, e: int, lo: int, hi: int) -> tuple[int, float]:
        """Project the points b:e on the chords lo:hi; write out_s, out_d of the first m, and return m and the
        arc length the next block starts from. m < e - b where a point's nearest chord is an end of the window."""
        Ax, Ay, Dx, Dy, L2 = self.Ax, self.Ay, self.Dx, self.Dy, self.L2
        gs, seg_len, kmid, nseg = self.gs, self.seg_len, self.kmid, self.nseg
        Dxb, Dyb = Dx[lo:hi], Dy[lo:hi]
        # x and y as separate 2-D arrays (block x chords): the same IEEE operations in the same order as a
        # dot product over the last axis of (block, chords, 2) arrays, a third of the time
        rx = self.Xx[b:e, None] - Ax[None, lo:hi]
        ry = self.Xy[b:e, None] - Ay[None, lo:hi]
        with np.errstate(over="ignore"):  # a diverged run's point, far off: handled as `far` below
            u_raw = (rx * Dxb + ry * Dyb) / L2[lo:hi]
            u = np.clip(u_raw, 0.0, 1.0)
            ex, ey = rx - u * Dxb, ry - u * Dyb
            dist2 = ex * ex + ey * ey
        j = np.argmin(dist2, axis=1)
        nb = e - b
        rows = np.arange(nb)
        uj = u[rows, j]
        # a minimum on the window's edge is no local minimum: the projection moves on past it;
        # keep the samples before the first such one, restart there with the window moved
        edge = ((j == 0) & (uj == 0.0) & (lo > 0)) | ((j == hi - lo - 1) & (uj == 1.0) & (hi < nseg))
        m = int(np.argmax(edge)) if edge.any() else nb
        jm = j[:m]
        seg = lo + jm
        uj = uj[:m]
        rows = rows[:m]
        cross = Dxb[jm] * ry[rows, jm] - Dyb[jm] * rx[rows, jm]
        dj = dist2[rows, jm]
        # a point beyond ~1.3e154 m of the path (only a diverged run's) has a squared distance that
        # overflows to inf: its cross-track is +-inf by its side (+inf on the chord's line), and it
        # keeps the clipped chord parameter (no arc correction: kappa * inf would be NaN on a line)
        far = np.isinf(dj)
        d = np.where(far, np.copysign(np.inf, cross), np.sign(cross) * np.sqrt(np.where(far, 0.0, dj)))
        # the polyline is the curve's chords; the curve lies kappa L^2 u (1-u) / 2 to their right
        d += 0.5 * kmid[seg] * seg_len[seg] ** 2 * uj * (1.0 - uj)
        # and a point d to the left of an arc of curvature kappa projects on the chord at a
        # tangential distance scaled by 1 - kappa d from the arc's: undo that about the midpoint
        scale = np.where(far, -1.0, 1.0 - kmid[seg] * np.where(far, 0.0, d))
        u_arc = 0.5 + (u_raw[rows, jm] - 0.5) / np.where(scale > 0.0, scale, 1.0)
        uj = np.where(scale > 0.0, np.clip(u_arc, 0.0, 1.0), uj)
        self.out_s[b:b + m] = gs[seg] + uj * seg_len[seg]
        self.out_d[b:b + m] = d
        return m, float(self.out_s[b + m - 1]) if m == nb else float(gs[lo] if j[m] == 0 else gs[hi])


def _project(gs: np.ndarray, gxy: np.ndarray, gk: np.ndarray, X: np.ndarray, s_start: float, window: float):
    """Continuous projection of the points X (n, 2) on the polyline: (s, signed distance).

    Points go in blocks of ``_BLOCK``; each block searches the chords within ``window`` m of arc length
    (and the block's travel) around the previous projection (:meth:`_Polyline.block_numpy`; in C where it
    is built, :func:`projection_backend`: the same bits).
    """
    n = X.shape[0]
    line = _Polyline(gs, gxy, gk, X)
    steps = np.concatenate([[0.0], np.hypot(*np.diff(X, axis=0).T)])
    compiled = _compiled_block()
    s_prev = s_start
    b = 0
    while b < n:
        e = min(n, b + _BLOCK)
        travel = float(np.sum(steps[b + 1:e]))
        lo = int(np.searchsorted(gs, s_prev - window - travel, side="right")) - 1
        hi = int(np.searchsorted(gs, s_prev + window + travel, side="left"))
        lo, hi = max(lo, 0), min(max(hi, lo + 1), line.nseg)
        if compiled is not None and lo < hi:
            m, s_prev = line.block_c(compiled, b, e, lo, hi)
        else:
            m, s_prev = line.block_numpy(b, e, lo, hi)
        b += m
    return line.out_s, line.out_d


def path_error_series(reference: Any, t: ArrayLike, C_xy: ArrayLike, heading: ArrayLike, *,
                      window: float = WINDOW, spacing: float = POLYLINE_SPACING) -> PathErrorSeries:
    """Per-sample cross-track, along-track and heading errors of C (see the module docstring).

    reference: the run's :class:`~wmr_mj.reference.paths.Reference` (C's desired path and its
    timing); t (n,) [s] sample times; C_xy (n, 2) [m] C's positions; heading (n,) [rad] the
    chassis heading (any branch: the error is wrapped). window [m]: half-width of the
    arc-length search around the previous projection (keep it below half the arc length
    between two parts of the path that come close, e.g. a figure eight's crossing);
    spacing [m]: the search polyline's spacing.
    """
    tt = np.asarray(t, dtype=float).ravel()
    X = np.asarray(C_xy, dtype=float)
    h = np.asarray(heading, dtype=float).ravel()
    if X.ndim != 2 or X.shape[1] != 2 or X.shape[0] != tt.size or h.size != tt.size:
        raise ParameterError(f"t (n,), C_xy (n, 2) and heading (n,) must agree; got {tt.shape}, {X.shape}, "
                             f"{h.shape}")
    if tt.size == 0:
        raise ParameterError("no samples: t, C_xy and heading are empty")
    if not (np.all(np.isfinite(tt)) and np.all(np.isfinite(X)) and np.all(np.isfinite(h))):
        raise ParameterError("t, C_xy and heading must be finite")
    win = float(window)
    if not (math.isfinite(win) and win > 0.0):
        raise ParameterError(f"window = {window!r} m must be finite and > 0")
    rt, rs = _as_reference_arrays(reference)[:2]
    extend = max(4.0 * win, float(rs[-1] - rs[0]))
    gs, gxy, gth, gk, s_lo, s_hi = _geometry(reference, float(spacing), extend)
    # the timed reference's s(t), continued at its end speeds
    s_ref = np.interp(tt, rt, rs)
    v0 = (rs[1] - rs[0]) / (rt[1] - rt[0])
    v1 = (rs[-1] - rs[-2]) / (rt[-1] - rt[-2])
    s_ref = np.where(tt < rt[0], rs[0] + (tt - rt[0]) * v0, s_ref)
    s_ref = np.where(tt > rt[-1], rs[-1] + (tt - rt[-1]) * v1, s_ref)
    s, d = _project(gs, gxy, gk, X, float(s_ref[0]), win)
    theta_des = np.interp(s, gs, gth)
    arrays = dict(t=tt, C_xy=X.copy(), s=s, s_ref=s_ref, cross_track=d, along_track=s - s_ref,
                  heading_error=wrap_angle(h - theta_des), beyond_end=(s < s_lo - 1e-9) | (s > s_hi + 1e-9))
    for v in arrays.values():
        v.setflags(write=False)
    return PathErrorSeries(**arrays)


def _stats(x: np.ndarray) -> tuple[float, float, float]:
    return float(np.max(np.abs(x))), float(np.sqrt(np.mean(x * x))), float(x[-1])


def summarize_series(series: PathErrorSeries, settle_s: float | None = None) -> PathErrors:
    """The :class:`PathErrors` of a :class:`PathErrorSeries` (sup, RMS, final; sup after settle_s)."""
    ct, at, he = _stats(series.cross_track), _stats(series.along_track), _stats(series.heading_error)
    after = None
    if settle_s is not None:
        late = series.t >= float(settle_s)
        after = float(np.max(np.abs(series.cross_track[late]))) if np.any(late) else None
    return PathErrors(
        cross_track_max=ct[0], cross_track_rms=ct[1], cross_track_final=ct[2],
        along_track_max=at[0], along_track_rms=at[1], along_track_final=at[2],
        heading_error_max=he[0], heading_error_rms=he[1], heading_error_final=he[2],
        cross_track_max_after_settle=after, settle_s=None if settle_s is None else float(settle_s),
        samples=int(series.t.size), beyond_end_samples=int(np.count_nonzero(series.beyond_end)),
    )


def path_errors(reference: Any, t: ArrayLike, C_xy: ArrayLike, heading: ArrayLike, *,
                settle_s: float | None = None, window: float = WINDOW) -> PathErrors:
    """C's cross-track, along-track and heading errors over a run, summarised.

    reference: the run's Reference; t (n,) [s]; C_xy (n, 2) [m]; heading (n,) [rad] (the
    chassis yaw); settle_s [s]: also the sup cross-track from then on. See
    :func:`path_error_series` for the per-sample values and ``window``.
    """
    return summarize_series(path_error_series(reference, t, C_xy, heading, window=window), settle_s)


class PathProjector:
    """C's desired path, built once, for projecting one position at a time (an outer loop's feedback).

    ``project(xy, s_prev)`` searches ``window`` m of arc length around ``s_prev`` as
    :func:`path_error_series` does (moving on past the window's edge) and returns (s [m], the
    signed cross-track [m], > 0 left, the desired chassis heading theta at s [rad]).
    """

    def __init__(self, reference: Any, *, window: float = WINDOW, spacing: float = POLYLINE_SPACING) -> None:
        rs = _as_reference_arrays(reference)[1]
        self.window = float(window)
        extend = max(4.0 * self.window, float(rs[-1] - rs[0]))
        self._gs, self._gxy, self._gth, self._gk, _, _ = _geometry(reference, float(spacing), extend)

    def project_many(self, xy: ArrayLike, s_prev: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Points (n, 2) in order, each searched from the one before (the first from ``s_prev``):
        (s, cross-track, desired heading) arrays."""
        X = np.asarray(xy, dtype=float).reshape(-1, 2)
        s, d = _project(self._gs, self._gxy, self._gk, X, float(s_prev), self.window)
        return s, d, np.interp(s, self._gs, self._gth)

    def project(self, xy: ArrayLike, s_prev: float) -> tuple[float, float, float]:
        X = np.asarray(xy, dtype=float).reshape(1, 2)
        s, d = _project(self._gs, self._gxy, self._gk, X, float(s_prev), self.window)
        return float(s[0]), float(d[0]), float(np.interp(s[0], self._gs, self._gth))
