"""Output-error identification of a cart's steering from its own recordings, with sound 95 % intervals.

The model is the non-holonomic reduced steering model (``wmr_mj.plant.reduced``) in the voltage form::

    P alpha'' + C_V alpha' + F sgn(alpha') + gyro V alpha'/cos^2(alpha) = u(t)

with gyro = P / l1 and K = 0 fixed from the cart's structure: the gyroscopic term and C_V move together when the
speed is constant (no recording separates them), and K is absent from the plant (physics notes, sections 3 and
6). At rest the Coulomb friction holds any voltage within +-F (stiction), as the MuJoCo plant's steering does.
The free coefficients are P, C_V and F (F at the first recording's m1; another recording's F is scaled by its
total weight Q, as (2.5) says), and the delay between the voltage and the angle read, a whole number of
control periods.

Output error: the recorded voltage drives a simulation of the model, and the simulated angle is compared with
the recorded one. The steering angle integrates its rate, so a simulation over a whole recording drifts on any
error; the recordings are cut into segments of :data:`SEGMENT_S`, each simulated from the state recorded at its
start (the angle read, and the rate of a least-squares line through :data:`RATE_WINDOW_S` of it). A
closed-loop recording (the cart doing its job under its own law) serves as well as an open-loop test: the
voltage is taken as recorded. Every segment is simulated at once (NumPy over the segments, one loop over the
steps), so 150 s of 1 kHz data take about a second per evaluation on one core.

Intervals: the residuals of a quantised, closed-loop recording are neither white nor independent, so the
Jacobian's covariance from s^2 (what ``mujoco.sysid.calculate_intervals`` computes) is far too narrow. The
95 % intervals here are a block bootstrap over the segments (each segment a block, far longer than the
residuals' correlation): each of :data:`BOOTSTRAP_DRAWS` draws resamples the segments with replacement and
takes one Gauss-Newton step from the fit with the drawn segments' gradients and curvatures (the linearised
bootstrap, equal to the cluster-robust sandwich covariance for small spreads); the interval is the 2.5 and 97.5
percentiles. The delay's interval is the same bootstrap over the delay's profile. A coefficient the data do
not excite comes out wide, never narrow.

Usage::

    from wmr_mj.plant.output_error import fit_recordings
    fit = fit_recordings([rec1, rec2], params)
    fit.coefficients["P"].value, fit.coefficients["P"].interval, fit.delay_steps, fit.encoder_ticks
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares
from scipy.stats import t as student_t

from wmr_mj.errors import ParameterError
from wmr_mj.params import C80Parameters, with_params
from wmr_mj.plant.recordings import Recording

__all__ = ["Interval", "SteeringFit", "fit_recordings", "simulate_recording", "encoder_ticks_of", "noise_of",
           "SEGMENT_S", "RATE_WINDOW_S", "MAX_DELAY_S", "BOOTSTRAP_DRAWS", "CONFIDENCE", "physical_of",
           "IDENTIFIED_PARAMETERS", "holdout_error", "HOLDOUT_NRMSE_MAX", "BURN_IN_S", "MODEL_ERROR_FLOOR",
           "POORLY_DETERMINED", "ENCODER_BITS", "QUADRATURE_LINES", "GRID_CONCENTRATION"]

#: Segment length, s: long enough for the slowest response (stick-slip under a PD law, a few hundred ms) to
#: show in it, short enough that a simulation from the recorded state does not drift on a few per cent of error.
SEGMENT_S = 1.0
#: The window, s, of the least-squares line whose slope is a segment's initial rate (+-half of it about the
#: start): 20 samples at 1 kHz each side: a 12-bit encoder's tick (1.5 mrad) gives +-0.04 rad/s, which the
#: steering's own time constant P/C_V (tens of ms) forgets within the segment.
RATE_WINDOW_S = 0.04
#: The start of each segment left out of its residuals, s: the error of the initial rate (a 12-bit tick over
#: the window) and of the initial angle (half a tick) leave, once the rate's transient has died (a few P/C_V,
#: tens of ms), an offset of the whole segment: each segment's residuals are taken about their mean (the offset
#: fitted per segment), after this burn-in.
BURN_IN_S = 0.1
#: The longest delay searched, s (a CAN bus and a filtered encoder: a few periods to tens of ms).
MAX_DELAY_S = 0.05
#: Bootstrap draws: the 2.5 % percentile of 2000 draws moves by about 0.1 standard deviation between seeds.
BOOTSTRAP_DRAWS = 2000
#: The intervals' confidence.
CONFIDENCE = 0.95
#: The reduced model's own error against the plant, relative: every interval of P, C_V and F holds at least
#: +-this about the value (and the cart-file parameters the corners of that box). Measured (2026-11-28): on the
#: tests' truth cart (MuJoCo plant, 12-bit encoder, 5 ms delay, 20 s closed-loop recordings), the fit's P,
#: C_V, F and mu differ from the file's by up to 1.6 %, beyond the bootstrap's spread (which sees the data's
#: variation, not a bias the model carries); the physics notes measure P within 1 % between MuJoCo and Drake.
MODEL_ERROR_FLOOR = 0.02
#: A 95 % half-width above this (relative) is poorly determined: identify warns, and where the inertia (P) is
#: poorly determined the delay's interval becomes the whole search, 0 to MAX_DELAY_S: a lag looks like inertia,
#: and a recording that does not excite the one does not fix the other (measured: a PD tracking a lane change
#: without dither, truth 5 ms, profile minimum at 16 ms with P 70 % off).
POORLY_DETERMINED = 0.25
#: The cart-file parameters identification replaces, with what carries each (the rest fixed from the cart).
IDENTIFIED_PARAMETERS: dict[str, str] = {
    "front_axle_mass": "P = (R_a/k_i) J/i2: the steering inertia J, through the front beam's mass (the wheels, "
                       "the geometry and R_a fixed from the cart file)",
    "k_i": "C_V = k_b i2: the motor constant (i2 fixed from the gear's data)",
    "k_b": "C_V = k_b i2: equal to k_i (one flux in SI units)",
    "mu": "F = (R_a/k_i) (l3 l4/(l1 i2)) mu Q: the steering's Coulomb coefficient",
}
#: A recorded applied voltage (``u_applied_V``) must follow u_V delayed by whole control periods: its RMS residual
#: at the best delay at most this fraction of its own RMS variation (an ADC's noise and the driver's rounding are
#: far below it; a wrong column, or a voltage in other units, is far above).
APPLIED_MATCH_MAX = 0.1
_COEFFICIENTS = ("P", "C_V", "F")


@dataclass(frozen=True)
class Interval:
    """A value with its 95 % interval [lo, hi], in the quantity's unit."""

    value: float
    lo: float
    hi: float

    @property
    def interval(self) -> tuple[float, float]:
        return (self.lo, self.hi)

    @property
    def relative_half_width(self) -> float:
        return 0.5 * (self.hi - self.lo) / abs(self.value) if self.value else math.inf

    def contains(self, x: float) -> bool:
        return self.lo <= x <= self.hi

    def to_dict(self) -> dict[str, object]:
        return {"value": self.value, "interval": [self.lo, self.hi]}


@dataclass(frozen=True)
class SteeringFit:
    """What the recordings say about the steering.

    Attributes:
        coefficients: 'P', 'C_V', 'F', 'K', 'gyro' at the first recording's m1 -> :class:`Interval` (K = 0 and
            gyro = P/l1 fixed from the cart's structure).
        physical: the cart-file parameters of :data:`IDENTIFIED_PARAMETERS` -> :class:`Interval`.
        delay_steps: the delay between the applied voltage and the angle read, control periods: the sensing and
            the actuation delays together (a pure delay commutes with the plant: from the voltage the controller
            applied and the angle it read, only their sum is identifiable).
        delay: its :class:`Interval`, s. :attr:`sensing_delay` and :attr:`actuation_delay`: what the recordings
            allow of each.
        period: the control period, s (the recordings' median step).
        encoder_ticks: ticks per revolution of the steering axis read from the angle's quantisation, or None
            where the angle is not on one grid (noise above the quantisation, or no encoder).
        noise_rad: the standard deviation of the noise on the angle beyond the quantisation, rad (0 where every
            reading is on the encoder's grid).
        residual_rms_rad: RMS of recorded minus simulated angle over the segments, rad.
        segments, segment_steps: how many segments, and their length in control periods.
        m1: the chassis mass of each recording, kg.
        draws: the bootstrap's draws of (P, C_V, F), (BOOTSTRAP_DRAWS, 3).
        jacobian_half_width: 'P', 'C_V', 'F' -> the 95 % half-width the Jacobian and s^2 of the residuals give
            (t quantile x sqrt(s^2 diag((J^T J)^-1)), what ``mujoco.sysid.calculate_intervals`` computes): beside
            the intervals above, to show how narrow it is on coloured residuals; not used.
    """

    coefficients: dict[str, Interval]
    physical: dict[str, Interval]
    delay_steps: int
    delay: Interval
    period: float
    encoder_ticks: int | None
    noise_rad: float
    residual_rms_rad: float
    segments: int
    segment_steps: int
    m1: tuple[float, ...]
    draws: np.ndarray = field(repr=False)
    jacobian_half_width: dict[str, float] = field(default_factory=dict)
    actuation_steps: int | None = None
    actuation: Interval | None = None

    @property
    def delay_split(self) -> str:
        """'known' where an actuator-side signal (``u_applied_V``) gave the actuation delay; 'unknown' where the
        recordings fix only the sum."""
        return "unknown" if self.actuation_steps is None else "known"

    @property
    def sensing_steps(self) -> int:
        """The sensing delay as the cart file runs it, control periods: the sum less the actuation delay where it
        was measured, else the whole sum (the recorded convention)."""
        return self.delay_steps - (self.actuation_steps or 0)

    @property
    def sensing_delay(self) -> Interval:
        """The sensing delay, s. Without an actuator-side signal: the whole delay as the cart file runs it (its
        value), anywhere in [0, the sum's upper end] as far as the recordings say (they fix only the sum). With
        one: the sum less the actuation delay, its interval the sum's less the actuation delay's."""
        if self.actuation is None:
            return Interval(self.delay.value, 0.0, self.delay.hi)
        T, a = self.period, self.actuation
        lo = max(0, round(self.delay.lo / T) - round(a.hi / T))
        hi = max(0, round(self.delay.hi / T) - round(a.lo / T))
        return Interval(self.sensing_steps * T, lo * T, hi * T)

    @property
    def actuation_delay(self) -> Interval:
        """The actuation delay, s: measured from ``u_applied_V`` where recorded; else 0 as the cart file runs it,
        anywhere in [0, the sum's upper end] as far as the recordings say."""
        return self.actuation if self.actuation is not None else Interval(0.0, 0.0, self.delay.hi)

    def to_dict(self) -> dict[str, object]:
        return {
            "coefficients": {k: v.to_dict() for k, v in self.coefficients.items()},
            "physical": {k: v.to_dict() for k, v in self.physical.items()},
            "delay_steps": self.delay_steps,
            "delay_s": self.delay.to_dict(),
            "sensing_delay_s": self.sensing_delay.to_dict(),
            "actuation_delay_s": self.actuation_delay.to_dict(),
            "delay_split": self.delay_split,
            "period_s": self.period,
            "encoder_ticks": self.encoder_ticks,
            "noise_rad": self.noise_rad,
            "residual_rms_rad": self.residual_rms_rad,
            "segments": self.segments,
            "segment_steps": self.segment_steps,
            "m1_kg": list(self.m1),
        }


# ------------------------------------------------------------------------------------------- segments


@dataclass(frozen=True)
class _Segments:
    """Recordings cut into segments, laid out (steps, segments) so that one step reads contiguous rows."""

    voltage: np.ndarray  # (Dmax + L, S): the voltage from the segment's start
    speed: np.ndarray  # (Dmax + L, S)
    alpha: np.ndarray  # (Dmax + L, S): the angle read from the segment's start
    rate: np.ndarray  # (Dmax + 1, S): the initial rate estimate at each delay
    friction_scale: np.ndarray  # (S,): Q of the segment's recording / Q of the first
    steps: int  # L
    burn_in: int  # the first steps of a segment left out of its residuals


def _rate_at(alpha: np.ndarray, centres: np.ndarray, half: int, dt: float) -> np.ndarray:
    """Slope (rad/s) of the least-squares line through alpha[c - half .. c + half] for each centre."""
    k = np.arange(-half, half + 1)
    idx = np.clip(centres[:, None] + k[None, :], 0, alpha.size - 1)
    return (alpha[idx] @ k) / (float(k @ k) * dt)


def _segments(recs: Sequence[Recording], params: C80Parameters, *, period: float, steps: int,
              max_delay: int) -> _Segments:
    q_ref = _total_weight(params, recs[0].m1)
    half = max(1, int(round(0.5 * RATE_WINDOW_S / period)))
    cols: dict[str, list[np.ndarray]] = {"u": [], "v": [], "a": [], "r": [], "f": []}
    span = steps + max_delay
    for rec in recs:
        n = rec.samples
        starts = np.arange(0, n - span + 1, steps)
        if starts.size == 0:
            continue
        window = starts[:, None] + np.arange(span)[None, :]
        speed = rec.speed if rec.speed is not None else np.full(n, params.V_A)
        cols["u"].append(rec.voltage[window].T)
        cols["v"].append(speed[window].T)
        cols["a"].append(rec.alpha[window].T)
        centres = starts[None, :] + np.arange(max_delay + 1)[:, None]
        cols["r"].append(np.stack([_rate_at(rec.alpha, c, half, period) for c in centres]))
        cols["f"].append(np.full(starts.size, _total_weight(params, rec.m1) / q_ref))
    if not cols["u"]:
        raise ParameterError(f"no recording is {span * period:.3g} s long (a {SEGMENT_S:g} s segment and the "
                             f"{max_delay * period:.3g} s delay search); accepted: longer recordings")
    cat = {k: np.concatenate(v, axis=-1) for k, v in cols.items()}
    return _Segments(voltage=np.ascontiguousarray(cat["u"]), speed=np.ascontiguousarray(cat["v"]),
                     alpha=np.ascontiguousarray(cat["a"]), rate=cat["r"], friction_scale=cat["f"], steps=steps,
                     burn_in=max(1, int(round(BURN_IN_S / period))))


def _total_weight(params: C80Parameters, m1: float | None) -> float:
    return params.Q if m1 is None else with_params(params, m1=m1).Q


def _simulate_columns(P: np.ndarray, C_V: np.ndarray, F: np.ndarray, alpha0: np.ndarray, rate0: np.ndarray,
                      seg: _Segments, columns: np.ndarray, *, period: float, inv_l1: float) -> np.ndarray:
    """The simulated angle (L, C) of C columns, column c being segment ``columns[c]`` under its own (P, C_V, F)
    from its own initial angle and rate (each (C,)): the implicit Euler step of the rate with the Coulomb friction
    as a set-valued law (the rate stops where the friction's impulse over the step exceeds it: stiction), then
    alpha += dt alpha'. One loop over the steps; the columns (segments, delays, perturbed coefficients) at once."""
    dt = period
    a = alpha0.astype(float).copy()
    w = rate0.astype(float).copy()
    friction = dt * F * seg.friction_scale[columns]
    Pw = P.copy()
    damping = dt * C_V
    gyro = dt * P * inv_l1
    out = np.empty((seg.steps, a.size))
    out[0] = a
    u, v = seg.voltage, seg.speed
    for k in range(seg.steps - 1):
        c = np.cos(a)
        denom = Pw + damping + gyro * v[k, columns] / (c * c)
        wt = Pw * w + dt * u[k, columns]
        w = np.sign(wt) * np.maximum(np.abs(wt) - friction, 0.0) / denom
        a = a + dt * w
        out[k + 1] = a
    return out


def _simulate(theta: np.ndarray, seg: _Segments, delay: int, *, period: float, inv_l1: float) -> np.ndarray:
    """The simulated angle (L, S) of each segment under ``theta`` = (P, C_V, F), the voltage ``delay`` periods
    before the angle read (:func:`_simulate_columns`)."""
    S = seg.alpha.shape[1]
    ones = np.ones(S)
    return _simulate_columns(theta[0] * ones, theta[1] * ones, theta[2] * ones, seg.alpha[delay], seg.rate[delay],
                             seg, np.arange(S), period=period, inv_l1=inv_l1)


def _residuals(theta: np.ndarray, seg: _Segments, delay: int, *, period: float, inv_l1: float) -> np.ndarray:
    """Recorded minus simulated angle, (L - 1, S) (the first row is the recorded start, not a residual)."""
    sim = _simulate(theta, seg, delay, period=period, inv_l1=inv_l1)
    burn = seg.burn_in
    r = seg.alpha[delay + burn: delay + seg.steps] - sim[burn:]
    return r - r.mean(axis=0)


# ------------------------------------------------------------------------------------------- the fit


#: Encoders whose grid is looked for where noise after the quantisation hides it (readings off the grid): absolute
#: encoders of 8 to 24 bits on the axis, and quadrature encoders (4 x lines per motor revolution) of the common
#: line counts on the motor, x i2 at the axis (wmr_mj.hardware.presets.quadrature_encoder_spec).
ENCODER_BITS = tuple(range(8, 25))
QUADRATURE_LINES = (100, 200, 250, 256, 360, 400, 500, 512, 1000, 1024, 2000, 2048, 2500, 4096, 5000)
#: The concentration |mean exp(i N alpha)| a grid of N ticks must reach to be read through noise: a uniform noise
#: of bound B gives sinc(2 pi B N / 2 pi) = sin(B N)/(B N), 0.43 at B = a third of a tick; readings spread over many
#: ticks give about 1/sqrt(samples) on a grid that is not theirs (0.003 at 100k samples).
GRID_CONCENTRATION = 0.2


def encoder_ticks_of(alphas: Sequence[np.ndarray], *, gear_ratio: float | None = None,
                     max_ticks: int = 2**30) -> int | None:
    """The encoder's ticks per revolution of the steering axis, from the angle's quantisation; None where no grid
    is found.

    Every reading on one grid 2 pi/N (within 1e-6 of a tick): N exactly, from the smallest step between distinct
    readings (one tick where the steering moved slowly enough to be read at neighbouring ticks; a recording at
    1 kHz always is). Readings off every grid (noise after the quantisation): the candidate N of
    :data:`ENCODER_BITS` and :data:`QUADRATURE_LINES` (x ``gear_ratio`` where given) whose grid the readings
    concentrate on most (|mean exp(i N alpha)|, at least :data:`GRID_CONCENTRATION`; a finer grid than the true
    one concentrates them less, a coarser one spreads the ticks over its phases).
    """
    values = np.concatenate([np.asarray(a, float).ravel() for a in alphas])
    distinct = np.unique(values)
    if distinct.size < 2:
        return None
    ticks = int(round(2 * math.pi / float(np.diff(distinct).min())))
    if 1 <= ticks <= max_ticks:
        counts = distinct * ticks / (2 * math.pi)
        if float(np.max(np.abs(counts - np.rint(counts)))) <= 1e-6:
            return ticks
    candidates = {2**b for b in ENCODER_BITS}
    if gear_ratio is not None and float(gear_ratio).is_integer():
        candidates |= {4 * lines * int(gear_ratio) for lines in QUADRATURE_LINES}
    score = {n: abs(complex(np.mean(np.exp(1j * n * values)))) for n in sorted(candidates)}
    best = max(score, key=score.__getitem__)
    return best if score[best] >= GRID_CONCENTRATION else None


def noise_of(alphas: Sequence[np.ndarray], residuals: np.ndarray, encoder_ticks: int | None) -> float:
    """The noise on the angle beyond the quantisation, rad (standard deviation).

    With the encoder's grid known: the readings' distance to their nearest tick (0 where every reading is on the
    grid; the noise itself where it stays within half a tick). Without: the white part of the output error's
    residuals (white noise of variance s^2 gives successive differences of variance 2 s^2; the model's error,
    smooth, adds little to it, the quantisation some)."""
    if encoder_ticks is not None:
        values = np.concatenate([np.asarray(a, float).ravel() for a in alphas])
        tick = 2 * math.pi / encoder_ticks
        off = values - tick * np.rint(values / tick)
        sd = float(np.sqrt(np.mean(off * off)))
        return 0.0 if sd <= 1e-9 * tick else sd
    d = np.diff(residuals, axis=0)
    return float(math.sqrt(0.5 * float(np.mean(d * d))))


def _fit_theta(theta0: np.ndarray, seg: _Segments, delay: int, *, period: float, inv_l1: float) -> np.ndarray:
    def fun(x: np.ndarray) -> np.ndarray:
        return _residuals(np.exp(x), seg, delay, period=period, inv_l1=inv_l1).ravel()

    sol = least_squares(fun, np.log(theta0), method="trf", diff_step=1e-4, x_scale=1.0, xtol=1e-8, ftol=1e-10)
    return np.asarray(np.exp(sol.x))


#: The most simulation columns one batch of the delay profile steps at once (memory: steps x columns doubles).
_PROFILE_COLUMNS = 8192


def _delay_costs(theta: np.ndarray, seg: _Segments, max_delay: int, *, period: float, inv_l1: float) -> np.ndarray:
    """(max_delay + 1, S): each segment's sum of squared residuals at each delay, the coefficients re-fitted at
    each (a profile: one Gauss-Newton step from ``theta`` by forward differences), so that a delay the coefficients
    can make up for (a lag looks like inertia) costs no more than it should. All delays and perturbations are
    simulated as columns of one batch (:func:`_simulate_columns`)."""
    S = seg.alpha.shape[1]
    burn, L = seg.burn_in, seg.steps
    h = 1e-4
    variants = np.tile(theta, (4, 1))
    for i in range(3):
        variants[i + 1, i] *= 1 + h
    per_delay = max(1, _PROFILE_COLUMNS // (4 * S))
    thetas = np.empty((max_delay + 1, 3))
    plain = np.empty((max_delay + 1, S))  # each segment's cost at theta itself
    for first in range(0, max_delay + 1, per_delay):
        delays = np.arange(first, min(first + per_delay, max_delay + 1))
        # columns ordered (delay, variant, segment)
        d_col = np.repeat(delays, 4 * S)
        v_col = np.tile(np.repeat(np.arange(4), S), delays.size)
        s_col = np.tile(np.arange(S), 4 * delays.size)
        th = variants[v_col]
        sim = _simulate_columns(th[:, 0], th[:, 1], th[:, 2], seg.alpha[d_col, s_col], seg.rate[d_col, s_col], seg,
                                s_col, period=period, inv_l1=inv_l1).reshape(L, delays.size, 4, S)
        for j, d in enumerate(delays):
            rec = seg.alpha[d + burn: d + L]
            res = rec[:, None, :] - sim[burn:, j]  # (L', 4, S)
            res = res - res.mean(axis=0)
            r = res[:, 0]
            plain[d] = np.sum(r * r, axis=0)
            J = (res[:, 1:] - r[:, None, :]) / (h * theta)[None, :, None]  # (L', 3, S)
            flat = np.moveaxis(J, 1, -1).reshape(-1, 3)
            step = np.linalg.lstsq(flat, -r.ravel(), rcond=None)[0]
            thetas[d] = theta + step if np.all(theta + step > 0) else theta
    d_col = np.repeat(np.arange(max_delay + 1), S)
    s_col = np.tile(np.arange(S), max_delay + 1)
    th = thetas[d_col]
    costs = np.empty((max_delay + 1, S))
    chunk = max(1, _PROFILE_COLUMNS // S)
    for first in range(0, max_delay + 1, chunk):
        sel = slice(first * S, min(first + chunk, max_delay + 1) * S)
        best = _simulate_columns(th[sel, 0], th[sel, 1], th[sel, 2], seg.alpha[d_col[sel], s_col[sel]],
                                 seg.rate[d_col[sel], s_col[sel]], seg, s_col[sel], period=period,
                                 inv_l1=inv_l1).reshape(L, -1, S)
        for j in range(best.shape[1]):
            d = first + j
            res = seg.alpha[d + burn: d + L] - best[burn:, j]
            res = res - res.mean(axis=0)
            costs[d] = np.sum(res * res, axis=0)
    # a step that made a delay worse (far from theta the linearisation fails) keeps theta's own cost there
    worse = costs.sum(axis=1) > plain.sum(axis=1)
    costs[worse] = plain[worse]
    return costs


def _segment_jacobian(theta: np.ndarray, seg: _Segments, delay: int, *, period: float,
                      inv_l1: float) -> tuple[np.ndarray, np.ndarray]:
    """Residuals r (L-1, S) and their derivatives J (L-1, S, 3) by theta, by central differences."""
    r = _residuals(theta, seg, delay, period=period, inv_l1=inv_l1)
    J = np.empty(r.shape + (3,))
    for i in range(3):
        h = 1e-4 * theta[i]
        tp, tm = theta.copy(), theta.copy()
        tp[i] += h
        tm[i] -= h
        J[..., i] = (_residuals(tp, seg, delay, period=period, inv_l1=inv_l1)
                     - _residuals(tm, seg, delay, period=period, inv_l1=inv_l1)) / (2 * h)
    return r, J


def _bootstrap(fits: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]], costs: np.ndarray,
               counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Block bootstrap over the segments, the delay's choice in it.

    Args:
        fits: delay -> (theta fitted at it, residuals r (L', S), their Jacobian J (L', S, 3)).
        costs: (delays, S) each segment's cost at each delay (at the best fit's theta).
        counts: (draws, S) how often each draw takes each segment.

    Returns:
        (draws, 3) coefficients and (draws,) delays: each draw picks its delay by its own segments' costs, then
        takes one Gauss-Newton step from the fit at that delay with its segments' gradients and curvatures.
    """
    delays = np.argmin(counts @ costs.T, axis=1)
    out = np.empty((counts.shape[0], 3))
    for d, (theta, r, J) in fits.items():
        rows = np.flatnonzero(delays == d)
        if rows.size == 0:
            continue
        S = r.shape[1]
        H = np.einsum("ksi,ksj->sij", J, J).reshape(S, 9)  # each segment's curvature J^T J
        g = np.einsum("ksi,ks->si", J, r)  # and gradient J^T r
        Hb = (counts[rows] @ H).reshape(rows.size, 3, 3)
        gb = counts[rows] @ g
        out[rows] = theta[None, :] - np.linalg.solve(Hb, gb[..., None])[..., 0]  # J = dr/dtheta: step -H^-1 J^T r
    return out, delays


def physical_of(coefficients: np.ndarray, params: C80Parameters, m1: float | None) -> dict[str, np.ndarray]:
    """The cart-file parameters carrying (P, C_V, F) (:data:`IDENTIFIED_PARAMETERS`), for rows of coefficients
    (..., 3) at chassis mass m1 (None: the cart's); the rest of ``params`` fixed."""
    P, C_V, F = (np.asarray(coefficients)[..., i] for i in range(3))
    p = params if m1 is None else with_params(params, m1=m1)
    k = C_V / p.i2
    J = P * k * p.i2 / p.R_a
    beam = (2 * p.l4) ** 2 / 12  # the front beam's yaw inertia per kg (C80Parameters.front_axle_yaw_inertia)
    J_without_beam = p.steering_inertia - p.front_axle_mass * beam
    front_axle_mass = (J - J_without_beam) / beam
    Q = (p.m1 + p.m2 + 2 * p.front_wheel_mass + front_axle_mass) * p.g  # m3 moves with the beam's mass
    mu = F * k * p.i2 / (p.R_a * p.l3 * p.l4 / p.l1 * Q)
    return {"front_axle_mass": front_axle_mass, "k_i": k, "k_b": k, "mu": mu}


def _interval(value: float, draws: np.ndarray, corners: np.ndarray | None = None) -> Interval:
    """The bootstrap's percentile interval, widened to hold ``value`` and the model-error ``corners``."""
    lo, hi = np.percentile(draws, [50 * (1 - CONFIDENCE), 50 * (1 + CONFIDENCE)])
    extra = [float(value)] if corners is None else [float(value), *np.asarray(corners, float).tolist()]
    return Interval(float(value), float(min(lo, *extra)), float(max(hi, *extra)))


def fit_recordings(recordings: Sequence[Recording], params: C80Parameters, *, seed: int = 0,
                   segment_s: float = SEGMENT_S, max_delay_s: float = MAX_DELAY_S,
                   draws: int = BOOTSTRAP_DRAWS) -> SteeringFit:
    """Identify P, C_V, F, the delay, the encoder and the noise from recordings of one cart.

    Args:
        recordings: checked recordings (:func:`wmr_mj.plant.recordings.check_recording`) at one control period.
        params: the cart's parameter set (the start: its values begin the search and fix the rest).
        seed: seed of the bootstrap's draws.
        segment_s, max_delay_s: segment length and the longest delay searched, s.
        draws: bootstrap draws.

    Returns:
        The :class:`SteeringFit`.

    Raises:
        ParameterError: recordings at different control periods, none long enough, or a fit that fails.
    """
    periods = [rec.period for rec in recordings]
    period = periods[0]
    if any(abs(p - period) > 1e-6 * period for p in periods):
        raise ParameterError(f"the recordings have different control periods ({', '.join(f'{p:.6g}' for p in periods)}"
                             " s); accepted: one control period")
    steps = max(2, int(round(segment_s / period)))
    max_delay = int(round(max_delay_s / period))
    seg = _segments(recordings, params, period=period, steps=steps, max_delay=max_delay)
    kw = {"period": period, "inv_l1": 1.0 / params.l1}
    start = params.coefficients("nonholonomic")
    scale = 1.0 if recordings[0].m1 is None else _total_weight(params, recordings[0].m1) / params.Q
    theta = _fit_theta(np.array([start.P, start.C_V, start.F * scale]), seg, 0, **kw)  # without delay first,
    delay = int(np.argmin(_delay_costs(theta, seg, max_delay, **kw).sum(axis=1)))  # then the delay's profile,
    theta = _fit_theta(theta, seg, delay, **kw)  # and the fit at the best delay
    costs = _delay_costs(theta, seg, max_delay, **kw)
    S = costs.shape[1]
    counts = np.random.default_rng(seed).multinomial(S, np.full(S, 1.0 / S), size=draws).astype(float)
    fits = {}
    for d in sorted(set(np.argmin(counts @ costs.T, axis=1).tolist()) | {delay}):  # each delay a draw may pick
        theta_d = theta if d == delay else _fit_theta(theta, seg, d, **kw)
        fits[d] = (theta_d, *_segment_jacobian(theta_d, seg, d, **kw))
    boot, boot_delays = _bootstrap(fits, costs, counts)
    r, J = fits[delay][1], fits[delay][2]
    coefficients, physical = _intervals(theta, boot, params, recordings[0].m1)
    delay_interval = _interval(delay * period, boot_delays * period)
    if coefficients["P"].relative_half_width > POORLY_DETERMINED:
        delay_interval = Interval(delay * period, 0.0, max_delay * period)
    ticks = encoder_ticks_of([rec.alpha for rec in recordings], gear_ratio=params.i2)
    applied = actuation_delay_of(recordings, steps=steps, max_delay=max_delay, total=delay)
    return SteeringFit(
        coefficients=coefficients, physical=physical, delay_steps=delay,
        delay=delay_interval, period=period, encoder_ticks=ticks,
        noise_rad=noise_of([rec.alpha for rec in recordings], r, ticks),
        residual_rms_rad=float(np.sqrt(np.mean(r * r))), segments=int(r.shape[1]),
        segment_steps=steps, m1=tuple(float(rec.m1) if rec.m1 is not None else params.m1 for rec in recordings),
        draws=boot, jacobian_half_width=_jacobian_half_width(r, J),
        actuation_steps=None if applied is None else applied[0],
        actuation=None if applied is None else Interval(*(k * period for k in applied)))


def actuation_delay_of(recordings: Sequence[Recording], *, steps: int, max_delay: int,
                       total: int) -> tuple[int, int, int] | None:
    """The actuation delay from an actuator-side signal: the whole periods d_a by which ``u_applied_V`` follows
    ``u_V`` (u_applied[k] = u[k - d_a]), least squares over every recording; its interval the range of each
    segment's own best (segments of ``steps`` rows in which one delay is best; a constant voltage says nothing).

    Returns:
        (d_a, lo, hi) in control periods, or None where no recording has ``u_applied_V``.

    Raises:
        ParameterError: ``u_applied_V`` in some recordings only, one that follows ``u_V`` at no delay up to
            ``max_delay`` (its residual above :data:`APPLIED_MATCH_MAX` of its RMS variation), or an actuation delay
            beyond the voltage-to-angle delay ``total`` (the angle would answer before the motor).
    """
    have = [rec.applied is not None for rec in recordings]
    if not any(have):
        return None
    if not all(have):
        named = ", ".join(r.name for r in recordings if r.applied is not None)
        raise ParameterError(f"u_applied_V is recorded in {named} but not in the others; accepted: in every "
                             "recording or in none")
    costs, counts, spread = np.zeros(max_delay + 1), 0, 0.0
    bests: list[int] = []
    for rec in recordings:
        u, a = rec.voltage, rec.applied
        assert a is not None
        n = (u.size - max_delay) // steps * steps  # whole segments after max_delay rows of history
        if n <= 0:
            continue
        target = a[max_delay:max_delay + n]
        sq = np.stack([(target - u[max_delay - d:max_delay - d + n]) ** 2 for d in range(max_delay + 1)])
        costs += sq.sum(axis=1)
        counts += n
        spread += float(np.sum((target - target.mean()) ** 2))
        per_segment = sq.reshape(max_delay + 1, -1, steps).sum(axis=2)  # (delays, segments)
        ordered = np.sort(per_segment, axis=0)
        informative = ordered[1] > ordered[0] * (1.0 + 1e-9) + 1e-300  # one delay strictly best
        bests += np.argmin(per_segment, axis=0)[informative].tolist()
    if counts == 0:
        raise ParameterError(f"u_applied_V: the recordings are shorter than the {max_delay} periods searched")
    best = int(np.argmin(costs))
    residual, variation = math.sqrt(costs[best] / counts), math.sqrt(spread / counts)
    if not residual <= APPLIED_MATCH_MAX * variation:
        raise ParameterError(f"u_applied_V does not follow u_V at any delay of 0-{max_delay} control periods (at the "
                             f"best, {best} periods, a residual of {residual:.3g} V rms against {variation:.3g} V of "
                             f"its own variation; accepted: at most {APPLIED_MATCH_MAX:g} of it): not the voltage the "
                             "driver applied from this u_V")
    if best > total:
        raise ParameterError(f"u_applied_V follows u_V by {best} control periods, beyond the {total} from u_V to the "
                             "angle: the angle would answer before the motor is driven; accepted: an actuator-side "
                             "signal of this recording (check the columns)")
    bests.append(best)
    return best, min(bests), max(bests)


def _jacobian_half_width(r: np.ndarray, J: np.ndarray) -> dict[str, float]:
    """The 95 % half-widths of P, C_V, F from s^2 and the Jacobian (t quantile x sqrt(s^2 diag((J^T J)^-1)))."""
    flat_J = J.reshape(-1, 3)
    dof = max(r.size - 3, 1)
    cov = float(np.sum(r * r)) / dof * np.linalg.pinv(flat_J.T @ flat_J)
    half = student_t.ppf(0.5 + CONFIDENCE / 2, dof) * np.sqrt(np.maximum(np.diag(cov), 0.0))
    return dict(zip(_COEFFICIENTS, half.tolist()))


def _intervals(theta: np.ndarray, boot: np.ndarray, params: C80Parameters,
               m1: float | None) -> tuple[dict[str, Interval], dict[str, Interval]]:
    """The coefficients' and the cart parameters' intervals: the bootstrap's percentiles, widened to the corners
    of +-MODEL_ERROR_FLOOR about the fit; K = 0 and gyro = P/l1 from the structure."""
    l1 = params.l1
    factors = np.array(np.meshgrid(*([[1 - MODEL_ERROR_FLOOR, 1 + MODEL_ERROR_FLOOR]] * 3), indexing="ij"))
    corners = theta * factors.reshape(3, -1).T  # (8, 3)
    coefficients = {name: _interval(theta[i], boot[:, i], corners[:, i]) for i, name in enumerate(_COEFFICIENTS)}
    coefficients["K"] = Interval(0.0, 0.0, 0.0)
    coefficients["gyro"] = _interval(theta[0] / l1, boot[:, 0] / l1, corners[:, 0] / l1)
    value, draws, corner = (physical_of(x, params, m1) for x in (theta, boot, corners))
    physical = {name: _interval(float(value[name]), draws[name], corner[name]) for name in IDENTIFIED_PARAMETERS}
    return coefficients, physical


#: The hold-out check's threshold: a normalised RMS error (:func:`holdout_error`) above it says the identified
#: model fails to predict the held-out recording. Measured (2026-11-28, tests/test_identify_data.py's truth cart,
#: 20 s figure-eight held out, 12-bit encoder): 0.039 for the model identified from a lane change, 0.039 for the
#: truth's own coefficients (the encoder's quantisation is most of it), 0.38 for the start cart file (P 34 % high,
#: C_V 17 % and F 18 % low); 0.1 lies between, at 2.5 times the quantisation's floor.
HOLDOUT_NRMSE_MAX = 0.1


def simulate_recording(fit: SteeringFit, rec: Recording, params: C80Parameters) -> tuple[np.ndarray, np.ndarray]:
    """The identified model's angle beside the recorded one on ``rec`` (a hold-out): each segment simulated
    from its recorded state with the recorded voltage, the identified delay applied, after the burn-in, its
    offset fitted (as the fit does).

    Returns:
        (recorded, simulated), each (segments x (steps - burn-in),) rad, the segments one after the other.
    """
    seg = _segments([rec], params, period=fit.period, steps=fit.segment_steps, max_delay=fit.delay_steps)
    theta = np.array([fit.coefficients[k].value for k in _COEFFICIENTS])
    scale = _total_weight(params, rec.m1) / _total_weight(params, fit.m1[0])
    seg = dataclasses.replace(seg, friction_scale=np.full_like(seg.friction_scale, scale))
    d = fit.delay_steps
    recorded = seg.alpha[d + seg.burn_in: d + seg.steps]
    residual = _residuals(theta, seg, d, period=fit.period, inv_l1=1.0 / params.l1)
    return recorded.T.ravel(), (recorded - residual).T.ravel()


def holdout_error(fit: SteeringFit, rec: Recording, params: C80Parameters) -> float:
    """The normalised RMS error of the identified model on ``rec``: RMS(recorded - simulated) over RMS of the
    recorded angle's motion within the segments (each segment's mean removed from both, as the fit does)."""
    seg = _segments([rec], params, period=fit.period, steps=fit.segment_steps, max_delay=fit.delay_steps)
    d = fit.delay_steps
    recorded = seg.alpha[d + seg.burn_in: d + seg.steps]
    motion = recorded - recorded.mean(axis=0)
    recorded_s, simulated = simulate_recording(fit, rec, params)
    err = recorded_s - simulated
    return float(np.sqrt(np.mean(err * err)) / max(float(np.sqrt(np.mean(motion * motion))), 1e-300))
