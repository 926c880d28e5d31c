"""A plug-in law's own linear part, closed around the steering's error dynamics as the cart runs it: its l1 gains
and the peak bounds of E, E' and the servo command u from each bounded source (issue 35 item 6).

The built-in PD servo's sampled loop is :func:`wmr_mj.analysis.sampled_data.sampled_loop`. A law of one's own
(an observer, a filter, a lead-lag) gives its linear part here instead: a transfer function or a state-space
model from what it reads to its servo command, discrete at the control period T or continuous (then discretised
by zero-order hold at T: the law must run that discretisation). :func:`sampled_loop_of` closes it around the
same double integrator, delays and velocity estimate as :func:`~wmr_mj.analysis.sampled_data.sampled_loop` (the
same :class:`~wmr_mj.analysis.sampled_data.SampledLoop`, read by the same
:func:`~wmr_mj.analysis.sampled_data.peak_gains`, whose tail bound is sound), and :func:`linear_part_bounds`
does the rest for a claim: the sensing of the run (``context.sensing``), the gains, and the bounds per source.

Usage (a claim; ``context`` is the :class:`~wmr_mj.analysis.claim.ClaimContext` the testbed hands it)::

    from wmr_mj.analysis import linear_part_bounds

    def claim(self, context):
        b = linear_part_bounds((A, B, C, D), context=context, w=w_max)   # discrete (A, B, C, D) at T
        b.E_max, b.Edot_max, b.u_max          # rad, rad/s, rad/s^2: sums over the sources (inf: unstable)
        b.by_source["quantisation"]           # (E, E', u) from the encoder alone

The loop (as :mod:`wmr_mj.analysis.sampled_data`, with alpha0 = 0): the error E = alpha0 - alpha of
E'' = -u(t) + w(t), u held over each period; the law reads E^[k] = E[k - d_s] - e[k] (e the angle's error:
quantisation, noise, play) and, where its model has a second input, the sensing's velocity estimate E^'[k]
(exact, tachometer, difference or filtered, with its noise n_v); its linear part

    x_c[k+1] = A_c x_c[k] + B_c y[k],   u[k] = C_c x_c[k] + D_c y[k],   y = E^ (one input) or (E^, E^')

(u in rad/s^2, the sign as the PD's u = K_P E^ + K_D E^'), and u reaches the plant d_a periods late.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from wmr_mj._util.checks import positive_real
from wmr_mj.analysis.sampled_data import (
    SOURCES,
    PeakGains,
    SampledLoop,
    _check_estimate,
    _delayed,
    _estimate,
    _Rows,
    peak_bounds,
    peak_gains,
)
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware.estimators import velocity_estimator
from wmr_mj.hardware.spec import whole_period_count, whole_periods

if TYPE_CHECKING:
    from wmr_mj.analysis.claim import ClaimContext

__all__ = ["sampled_loop_of", "linear_part_bounds", "LinearPartBounds", "discrete_controller"]

#: The law's linear part: (num, den), a transfer function E^ -> u (coefficients highest power first), or
#: (A, B, C, D), a state-space model with one input (E^) or two (E^, E^').
LinearModel = Sequence[Any]


def discrete_controller(controller: LinearModel, *, control_period: float,
                        continuous: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The law's linear part as discrete (A_c, B_c, C_c, D_c) at the control period, u a (1,) output.

    Args:
        controller: (num, den), a proper transfer function E^ -> u (in z, or in s where ``continuous``), or
            (A, B, C, D) with one or two input columns (E^ rad, E^' rad/s) and one output (u, rad/s^2).
        control_period: T, s (> 0).
        continuous: the model is in continuous time; discretised by zero-order hold at T
            (scipy.signal.cont2discrete, 'zoh').

    Returns:
        (A_c (n, n), B_c (n, m), C_c (1, n), D_c (1, m)), float arrays, m = 1 or 2.

    Raises:
        ParameterError: not 2 or 4 parts, an improper transfer function, shapes that do not agree, not one
            output, more than two inputs, or a non-finite entry.
    """
    import scipy.signal

    T = positive_real("control_period", control_period, " s")
    parts = tuple(controller)
    if len(parts) == 2:
        num, den = (np.atleast_1d(np.asarray(p, dtype=float)) for p in parts)
        num, den = np.trim_zeros(num, "f"), np.trim_zeros(den, "f")
        if den.size == 0 or num.size > den.size:
            raise ParameterError(f"controller transfer function (num {parts[0]!r}, den {parts[1]!r}) is not "
                                 "accepted: a proper one (deg num <= deg den, den nonzero) is required")
        A, B, C, D = scipy.signal.tf2ss(num if num.size else [0.0], den)
    elif len(parts) == 4:
        A, B, C, D = (np.atleast_2d(np.asarray(p, dtype=float)) for p in parts)
        if A.size == 0:
            A = np.zeros((0, 0))
            B = np.zeros((0, D.shape[1]))
            C = np.zeros((D.shape[0], 0))
    else:
        raise ParameterError(f"controller has {len(parts)} parts; (num, den) or (A, B, C, D) is accepted")
    n = A.shape[0]
    if (A.shape != (n, n) or B.shape[0] != n or C.shape[1] != n or D.shape != (C.shape[0], B.shape[1])):
        raise ParameterError(f"controller (A, B, C, D) shapes {A.shape}, {B.shape}, {C.shape}, {D.shape} do not "
                             "agree: A (n, n), B (n, m), C (1, n), D (1, m)")
    if D.shape[0] != 1 or D.shape[1] not in (1, 2):
        raise ParameterError(f"controller has {D.shape[0]} output(s) and {D.shape[1]} input(s); one output (u) and "
                             "one input (E^) or two (E^, E^') are accepted")
    if not all(np.all(np.isfinite(x)) for x in (A, B, C, D)):
        raise ParameterError("controller has a non-finite entry; finite numbers are required")
    if continuous and n:
        A, B, C, D, _ = scipy.signal.cont2discrete((A, B, C, D), T, method="zoh")
    return tuple(np.array(x, dtype=float) for x in (A, B, C, D))  # type: ignore[return-value]


def sampled_loop_of(controller: LinearModel, *, control_period: float, continuous: bool = False,
                    velocity: str = "none", filter_tau: float | None = None, sensing_delay: int = 0,
                    actuation_delay: int = 0) -> SampledLoop:
    """:func:`~wmr_mj.analysis.sampled_data.sampled_loop` with the law's own linear part in place of the PD.

    The state is sampled_loop's (E, E', the delayed E and E' lines, the estimator's memory) with the
    controller's n_c states after the estimator's and before the u line; with no controller state and
    D_c = [K_P, K_D] every array equals sampled_loop's, bit for bit.

    Args:
        controller: see :func:`discrete_controller`.
        control_period: T, s (> 0).
        continuous: discretise a continuous model by zero-order hold at T.
        velocity: the sensing's estimate the second input reads ('exact', 'tachometer', 'difference',
            'filtered'), or 'none': the law reads the angle only (one input; the velocity noise then enters
            nothing).
        filter_tau: tau_f, s, for 'filtered' only.
        sensing_delay: d_s, whole control periods (>= 0): the law reads the state of step k - d_s.
        actuation_delay: d_a, whole control periods (>= 0): the command of step k acts over step k + d_a.

    Returns:
        The :class:`~wmr_mj.analysis.sampled_data.SampledLoop` (kp, kd nan: the gains are the controller's;
        ``velocity`` as given).

    Raises:
        ParameterError: as :func:`discrete_controller` and sampled_loop, or a model whose inputs do not match
            ``velocity`` (one input with 'none', two otherwise).
        UnknownNameError: an unknown velocity estimate.
    """
    T = positive_real("control_period", control_period, " s")
    velocity = str(velocity)
    if velocity != "none":
        tau = _check_estimate(velocity, filter_tau)
    elif filter_tau is not None:
        raise ParameterError(f"filter_tau = {filter_tau!r} s applies to velocity='filtered' only (velocity is 'none')")
    else:
        tau = None
    if velocity not in ("none", "exact", "tachometer", "difference", "filtered"):
        raise UnknownNameError("velocity estimate", velocity, ("none", "exact", "tachometer", "difference", "filtered"))
    Ac, Bc, Cc, Dc = discrete_controller(controller, control_period=T, continuous=continuous)
    m = Dc.shape[1]
    if m != (1 if velocity == "none" else 2):
        raise ParameterError(f"controller has {m} input(s) but velocity is {velocity!r}: one input (E^) goes with "
                             "'none', two (E^, E^') with a velocity estimate of the sensing")
    d_s = whole_period_count("sensing_delay", sensing_delay)
    d_a = whole_period_count("actuation_delay", actuation_delay)
    return _assemble(Ac, Bc, Cc, Dc, T=T, velocity=velocity, tau=tau, d_s=d_s, d_a=d_a)


class _RowsOf(_Rows):
    """sampled_loop's rows with n_c controller states between the estimator's and the u line."""

    def __init__(self, velocity: str, d_s: int, d_a: int, n_c: int):
        super().__init__("difference" if velocity == "none" else velocity, d_s, d_a)
        if velocity == "none":  # no difference is taken: no E^[k-1] state
            self.has_prev, self.prev = False, -1
            self.u_line = [i - 1 for i in self.u_line]
            self.n -= 1
        first = self.u_line[0] if d_a else self.n
        self.ctrl = list(range(first, first + n_c))
        self.u_line = [i + n_c for i in self.u_line]
        self.n += n_c


def _assemble(Ac: np.ndarray, Bc: np.ndarray, Cc: np.ndarray, Dc: np.ndarray, *, T: float, velocity: str,
              tau: float | None, d_s: int, d_a: int) -> SampledLoop:
    r = _RowsOf(velocity, d_s, d_a, Ac.shape[0])
    n = r.n
    E_hat = _delayed(r.unit(0), r.E_line, r)[1] - r.unit(n)  # E[k - d_s] - e[k]
    estimator_rows: list[np.ndarray] = []
    if velocity == "none":
        inputs = [E_hat]
    else:  # as sampled_loop: the sensing's estimate, from its matrices
        estimate, estimator_rows = _estimate(r, velocity_estimator(velocity, control_period=T, filter_tau=tau), E_hat)
        inputs = [E_hat, estimate - r.unit(n + 1)]
    xc = [r.unit(i) for i in r.ctrl]
    u = Dc[0, 0] * inputs[0]
    for j in range(1, len(inputs)):
        u = u + Dc[0, j] * inputs[j]
    for i, row in enumerate(xc):
        u = u + Cc[0, i] * row
    nxt = r.plant_step(u=u, estimator_rows=estimator_rows, T=T)
    for i, idx in enumerate(r.ctrl):
        row = np.zeros(n + 2)
        for j, src in enumerate(xc):
            row = row + Ac[i, j] * src
        for j, y in enumerate(inputs):
            row = row + Bc[i, j] * y
        nxt[idx] = row
    arrays = r.arrays(nxt, u, T)
    return SampledLoop(**arrays, kp=math.nan, kd=math.nan, control_period=T, velocity=velocity, filter_tau=tau,
                       sensing_delay=d_s, actuation_delay=d_a)


@dataclass(frozen=True)
class LinearPartBounds:
    """What :func:`linear_part_bounds` returns: the peak bounds of the law's linear part on the run's cart.

    Attributes:
        E_max: sup|E| rad, E'_max: sup|E'| rad/s, u_max: sup|u| rad/s^2 (the servo command), summed over the
            sources (inf where the loop is not Schur-stable and a source is on). Between the sampling instants
            too where asked (``between_samples``).
        by_source: source (:data:`~wmr_mj.analysis.sampled_data.SOURCES`) -> (E, E', u) from that source alone,
            at the sampling instants.
        source_bounds: source -> its bound (rad, rad/s or rad/s^2 for w) as charged.
        gains: the :class:`~wmr_mj.analysis.sampled_data.PeakGains` (``gains.reason`` where unstable).
        loop: the :class:`~wmr_mj.analysis.sampled_data.SampledLoop`.
    """

    E_max: float
    Edot_max: float
    u_max: float
    by_source: dict[str, tuple[float, float, float]]
    source_bounds: dict[str, float]
    gains: PeakGains
    loop: SampledLoop

    @property
    def stable(self) -> bool:
        """True where the sampled loop is Schur-stable (the gains are finite)."""
        return self.gains.stable


def _source_bounds(context: ClaimContext) -> dict[str, float]:
    """Each bounded source of the run's cart, from its sensing and transmission (rad, rad/s)."""
    s, i2 = context.sensing, float(context.gear_ratio or 1.0)
    play = context.play if s.reads_motor_side else 0.0
    return {"quantisation": s.encoder_bound(i2), "angle_noise": s.noise_bound(), "play": play,
            "velocity_noise": s.velocity_noise_bound() if s.velocity != "none" else 0.0}


def linear_part_bounds(controller: LinearModel, *, context: ClaimContext, w: float = 0.0, continuous: bool = False,
                       between_samples: bool = True, reference_rate: float = 0.0) -> LinearPartBounds:
    """The law's linear part closed around the run's cart (``context.sensing``, the control period, the sensing
    and actuation delays in whole periods) and its peak bounds from every bounded source.

    The sources: the angle's quantisation (Delta/2 round, Delta floor), its noise bound, the play where the
    encoder reads the motor shaft, the velocity noise (where the law reads the sensing's estimate), and w, the
    continuous disturbance (rad/s^2) the claim charges for everything nonlinear (model mismatch over the box,
    friction against its compensation, the reference's own terms): the caller bounds w, e.g. in a small-gain
    fixed point on E_max, Edot_max and u_max (the example in ``docs/guides/plugins.md``). A Gaussian noise has
    no bound: E_max is then inf.

    Args:
        controller: (num, den) or (A, B, C, D) (:func:`discrete_controller`): one input (E^) where the sensing's
            velocity is 'none', else one or two (E^, E^').
        context: the claim's context (its ``sensing``, ``control_period``, ``actuation_delay``, ``gear_ratio``,
            ``play``).
        w: sup|w|, rad/s^2 (>= 0, finite).
        continuous: the model is continuous (discretised by zero-order hold at T).
        between_samples: bound E and E' between the sampling instants too (peak_bounds).
        reference_rate: max|alpha0'| [rad/s] where the law forms its error from the reference now and the angle
            read d_s periods late (alpha0(t_k) - alpha_m[k]): the reference's shift d_s T max|alpha0'| is then
            charged in the angle's channel, with the noise (``by_source['angle_noise']``). 0: the law delays its
            reference as the reading is delayed, or there is no sensing delay.

    Returns:
        :class:`LinearPartBounds`.

    Raises:
        ParameterError: as :func:`sampled_loop_of`, a delay that is not a whole number of control periods, or
            w not a finite number >= 0.
    """
    sensing, T = context.sensing, context.control_period
    parts = tuple(controller)
    reads_velocity = sensing.velocity != "none"
    if reads_velocity and len(parts) == 4 and np.atleast_2d(np.asarray(parts[3], dtype=float)).shape[1] == 1:
        reads_velocity = False  # the law reads the angle only, though the sensing offers an estimate
    if reads_velocity and len(parts) == 2:
        reads_velocity = False
    loop = sampled_loop_of(parts, control_period=T, continuous=continuous,
                           velocity=sensing.velocity if reads_velocity else "none",
                           filter_tau=sensing.filter_tau if reads_velocity else None,
                           sensing_delay=sensing.delay_steps(T),
                           actuation_delay=whole_periods("actuation delay", context.actuation_delay, T))
    gains = peak_gains(loop)
    bounds = _source_bounds(context)
    if not (isinstance(reference_rate, (int, float)) and 0.0 <= reference_rate < math.inf):
        raise ParameterError(f"reference_rate = {reference_rate!r} rad/s is not accepted; a finite number >= 0")
    bounds["angle_noise"] += loop.sensing_delay * T * float(reference_rate)
    if not reads_velocity:
        bounds["velocity_noise"] = 0.0
    bounds["w"] = w
    if any(math.isinf(v) for v in bounds.values()):
        inf = (math.inf, math.inf, math.inf)
        return LinearPartBounds(E_max=math.inf, Edot_max=math.inf, u_max=math.inf,
                                by_source={s: inf for s in SOURCES}, source_bounds=bounds, gains=gains, loop=loop)
    by_source = {s: peak_bounds(gains, **{s: bounds[s]}) for s in SOURCES}  # type: ignore[arg-type]
    E, Ed, u = peak_bounds(gains, between_samples=between_samples, w=bounds["w"], quantisation=bounds["quantisation"],
                           angle_noise=bounds["angle_noise"], play=bounds["play"],
                           velocity_noise=bounds["velocity_noise"])
    return LinearPartBounds(E_max=E, Edot_max=Ed, u_max=u, by_source=by_source, source_bounds=bounds, gains=gains,
                            loop=loop)

