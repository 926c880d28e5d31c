"""The PD servo as it runs: sampled at the control period, delayed, fed by the velocity estimate it really
forms, and its peak-to-peak (l1) gains from each bounded measurement error (issue 35 item 1, the linear core).

Derivations: ``docs/guides/certificates.md``, "The sampled loop: l1 gains and the delay margin". Not yet
wired into a run's verdicts: the continuous certificate (:mod:`wmr_mj.analysis.certificate`) is unchanged.

Usage::

    from wmr_mj.analysis.sampled_data import sampled_loop, peak_gains, peak_bounds, delay_margin

    loop = sampled_loop(kp=100.0, kd=20.0, control_period=0.001, velocity="difference",
                        sensing_delay=5)                       # 5 periods = 5 ms
    gains = peak_gains(loop)                                   # inf with gains.reason where unstable
    gains.gain("E", "quantisation")                            # about 1.295 (rad of E per rad of |q|)
    E_max, Edot_max, u_max = peak_bounds(gains, quantisation=2 * math.pi / 4096 / 2)
    delay_margin(kp=100.0, kd=20.0, control_period=0.001, velocity="exact")   # 64 periods (Jury)

The model, once per control step k (t_k = k T): the error E = alpha0 - alpha of a double integrator
E'' = -u(t) + w(t), u held over [t_k, t_k + T) (zero-order hold), w a bounded continuous disturbance
(everything the nonlinear remainder sends through the loop). The law reads the angle d_s periods late with an
additive error e[k] (quantisation q, noise on alpha, play with the encoder on the motor side: they enter the
same way, so they share one input column), forms the velocity estimate as
:class:`wmr_mj.hardware.SensingChain` does, adds the velocity noise n_v[k], and its servo command
u[k] = K_P E^[k] + K_D E^'[k] (rad/s^2; the law's volts are P^ times it) reaches the plant d_a periods late.
With alpha0 = 0 (the reference's own terms are exogenous and not part of this core), E^ = alpha0 - alpha_m:

- E^[k]  = E[k - d_s] - e[k];
- E^'[k] = E'[k - d_s] - n_v[k]                                  (exact, tachometer)
- E^'[k] = (E^[k] - E^[k-1]) / T - n_v[k]                        (difference)
- E^'[k] = y[k] - n_v[k], y[k] = a y[k-1] + (1 - a)(E^[k] - E^[k-1]) / T, a = exp(-T / tau_f)   (filtered)

With an armature inductance (``electrical_time_constant`` tau_e = L_a/R_a > 0) the held command reaches the plant
through the motor's current: E'' = -j(t) + w(t) with tau_e j' = u[k - d_a] - j, exact over the period (the current j
is one more state, its step the zero-order hold of a first-order lag: :func:`current_moments`); tau_e = 0 is the loop
above, bit for bit. Derivation: ``docs/guides/certificates.md``, "The armature inductance in the sampled loop".

Outputs: E[k], E'[k] (at the sampling instants) and u[k]. The estimate and the delay lines are the systems of
:mod:`wmr_mj.hardware.estimators` (defined there once): the loop's rows are read from their matrices.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg

from wmr_mj._util.checks import positive_real
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware.estimators import VelocityEstimator, delay_line, velocity_estimator
from wmr_mj.hardware.sensing import Sensing, VelocityEstimate
from wmr_mj.hardware.spec import whole_period_count

__all__ = [
    "SampledLoop",
    "PeakGains",
    "sampled_loop",
    "sampled_loop_for",
    "peak_gains",
    "peak_bounds",
    "characteristic_polynomial",
    "current_moments",
    "jury_stable",
    "delay_margin",
    "OUTPUTS",
    "SOURCES",
    "VELOCITY_ESTIMATES",
]

VELOCITY_ESTIMATES: tuple[str, ...] = ("exact", "tachometer", "difference", "filtered")
#: The loop's outputs: E (rad), E' (rad/s), the servo command u (rad/s^2).
OUTPUTS: tuple[str, ...] = ("E", "E_dot", "u")
#: The bounded sources, in :attr:`PeakGains.gains`' column order: the continuous disturbance w (rad/s^2), the
#: angle's quantisation error (rad), its noise (rad), the play read through a motor-side encoder (rad at the
#: axis), the velocity estimate's noise (rad/s).
SOURCES: tuple[str, ...] = ("w", "quantisation", "angle_noise", "play", "velocity_noise")
# the discrete input columns of SampledLoop.B and .D; the three angle errors share the first
_CHANNELS: tuple[str, ...] = ("angle", "velocity")
_CHANNEL_OF = {"quantisation": 0, "angle_noise": 0, "play": 0, "velocity_noise": 1}
_BLOCK = 64  # impulse-response steps per batched product (and between two tail checks)


@dataclass(frozen=True, eq=False)
class SampledLoop:
    """The augmented closed loop x[k+1] = A x[k] + B [e[k], n_v[k]] + (w over the period), y[k] = C x[k] + D [e, n_v].

    The state x = (E rad, E' rad/s, E[k-1..k-d_s], E'[k-1..k-d_s] (exact and tachometer only), E^[k-1]
    (difference and filtered), y[k-1] (filtered), u[k-1..k-d_a]); the outputs y = (E, E', u) (:data:`OUTPUTS`).
    A continuous w(t) over [t_k, t_k + T) adds its integral of (T - s) w(t_k + s) to E and of w to E', i.e.
    ``w_position`` and ``w_rate`` (unit columns at E and E'); held over the period it adds ``w_held`` w[k].

    Attributes:
        A: (n, n). B: (n, 2), columns for the angle error e (rad) and the velocity noise n_v (rad/s).
        C: (3, n). D: (3, 2), the direct path of e and n_v into u (E and E' have none).
        w_position, w_rate, w_held: (n,) each.
        kp: K_P, 1/s^2. kd: K_D, 1/s. control_period: T, s. velocity: the estimate. filter_tau: tau_f, s
        (filtered only). sensing_delay, actuation_delay: d_s, d_a, whole control periods.
        electrical_time_constant: tau_e = L_a/R_a, s (0: no current state; > 0: the current j, rad/s^2, is the last
            state).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    w_position: np.ndarray
    w_rate: np.ndarray
    w_held: np.ndarray
    kp: float
    kd: float
    control_period: float
    velocity: str
    filter_tau: float | None
    sensing_delay: int
    actuation_delay: int
    electrical_time_constant: float = 0.0

    @property
    def n_states(self) -> int:
        """The augmented state's dimension n."""
        return int(self.A.shape[0])

    @property
    def current_index(self) -> int | None:
        """The index of the current state j (the last), None without inductance."""
        return self.n_states - 1 if self.electrical_time_constant > 0.0 else None

    def applied_row(self) -> np.ndarray:
        """The command acting over step k, u[k - d_a], as a row over [x (n), e, n_v]: the last of the command's
        shift register (before the current state, where there is one), or the law's own row without delay."""
        n = self.n_states
        row = np.zeros(n + 2)
        if self.actuation_delay:
            row[n - 1 - (self.current_index is not None)] = 1.0
        else:
            row[:n], row[n:] = self.C[2], self.D[2]
        return row


@dataclass(frozen=True, eq=False)
class PeakGains:
    """Peak-to-peak gains of a :class:`SampledLoop` (``peak_gains``).

    ``gains[i, j]`` is a sound upper bound of sup_k |y_i[k]| / sup |source_j| over every bounded source
    sequence from rest (output i of :data:`OUTPUTS`, source j of :data:`SOURCES`): the l1 sum ``reached``
    over the first ``n_terms`` steps, which a sign sequence attains, plus ``tail``, the geometric bound on
    the rest. inf everywhere where the loop is not Schur-stable (``reason`` says why; None otherwise).

    Attributes:
        gains, reached, tail: (3, 5) arrays, units of the output per unit of the source.
        n_terms: N, the steps summed. spectral_radius: max |eig A|. control_period: T, s (the loop's).
        rho, M: the norm bound ||A^k||_2 <= M rho^k used for the tail (nan where unstable).
    """

    gains: np.ndarray
    reached: np.ndarray
    tail: np.ndarray
    n_terms: int
    spectral_radius: float
    rho: float
    M: float
    control_period: float
    reason: str | None = field(default=None)

    @property
    def stable(self) -> bool:
        """True where the loop is Schur-stable and the gains are finite."""
        return self.reason is None

    def gain(self, output: str, source: str) -> float:
        """The gain from ``source`` (:data:`SOURCES`) into ``output`` (:data:`OUTPUTS`).

        Raises:
            UnknownNameError: an unknown output or source.
        """
        if output not in OUTPUTS:
            raise UnknownNameError("sampled-loop output", output, OUTPUTS)
        if source not in SOURCES:
            raise UnknownNameError("sampled-loop source", source, SOURCES)
        return float(self.gains[OUTPUTS.index(output), SOURCES.index(source)])


def _check_estimate(velocity: str, filter_tau: float | None) -> float | None:
    if velocity not in VELOCITY_ESTIMATES:
        raise UnknownNameError("velocity estimate", velocity, VELOCITY_ESTIMATES)
    if velocity != "filtered":
        if filter_tau is not None:
            raise ParameterError(f"filter_tau = {filter_tau!r} s applies to velocity='filtered' only "
                                 f"(velocity is {velocity!r})")
        return None
    if filter_tau is None:
        raise ParameterError("velocity='filtered' needs filter_tau (s, > 0), the low-pass time constant")
    return positive_real("filter_tau", filter_tau, " s")


class _Rows:
    """Index bookkeeping of the augmented state; each row is over [x (n), e, n_v]."""

    def __init__(self, velocity: str, d_s: int, d_a: int, current: bool = False):
        self.delayed_rate = velocity in ("exact", "tachometer")
        self.has_prev = not self.delayed_rate
        self.has_filter = velocity == "filtered"
        i = 2
        self.E_line = list(range(i, i + d_s))
        i += d_s
        self.V_line = list(range(i, i + d_s)) if self.delayed_rate else []
        i += len(self.V_line)
        self.prev = i if self.has_prev else -1
        i += self.has_prev
        self.filt = i if self.has_filter else -1
        i += self.has_filter
        self.u_line = list(range(i, i + d_a))
        i += d_a
        self.current = i if current else -1  # the armature current j (last), -1: none
        self.n = i + current

    def unit(self, j: int) -> np.ndarray:
        r = np.zeros(self.n + 2)
        r[j] = 1.0
        return r

    def plant_step(self, *, u: np.ndarray, estimator_rows: Sequence[np.ndarray], T: float,
                   tau_e: float = 0.0) -> np.ndarray:
        """The next state's rows [x, e, n_v] of every line but a law's own states: the held plant step under the
        command applied (u through the actuation delay; through the current j where tau_e > 0), the delay lines
        shifted (each a :func:`~wmr_mj.hardware.estimators.delay_line`), the estimator's next state
        (``estimator_rows``, from :func:`_estimate`)."""
        n = self.n
        u_applied = _delayed(u, self.u_line, self)[1]
        nxt = np.zeros((n, n + 2))
        if self.current < 0:
            nxt[0] = self.unit(0) + T * self.unit(1) - (T * T / 2.0) * u_applied
            nxt[1] = self.unit(1) - T * u_applied
        else:  # E'' = -j: E' loses the integral of j over the period, E its double integral
            m = current_moments(T, tau_e)
            j = self.unit(self.current)
            nxt[0] = self.unit(0) + T * self.unit(1) - (m[2, 0] * u_applied + m[2, 1] * j)
            nxt[1] = self.unit(1) - (m[1, 0] * u_applied + m[1, 1] * j)
            nxt[self.current] = m[0, 0] * u_applied + m[0, 1] * j
        for line, head in ((self.E_line, self.unit(0)), (self.V_line, self.unit(1)), (self.u_line, u)):
            for idx, row in zip(line, _delayed(head, line, self)[0]):
                nxt[idx] = row
        for idx, row in zip((self.prev, self.filt)[:len(estimator_rows)], estimator_rows):
            nxt[idx] = row
        return nxt

    def arrays(self, nxt: np.ndarray, u: np.ndarray, T: float) -> dict[str, Any]:
        """The loop's A, B (from [e, n_v]), C, D (rows E, E', u) and the disturbance columns, read-only."""
        n = self.n
        out = np.stack([self.unit(0), self.unit(1), u])
        w_position, w_rate = np.zeros(n), np.zeros(n)
        w_position[0], w_rate[1] = 1.0, 1.0
        arrays = {"A": nxt[:, :n], "B": nxt[:, n:], "C": out[:, :n], "D": out[:, n:], "w_position": w_position,
                  "w_rate": w_rate, "w_held": (T * T / 2.0) * w_position + T * w_rate}
        for x in arrays.values():
            x.flags.writeable = False
        return arrays


def _combine(M: np.ndarray, rows: Sequence[np.ndarray], width: int) -> list[np.ndarray]:
    """M times the stacked ``rows``: row i is the sum over j of M[i, j] rows[j] (each a row over [x, e, n_v]), in
    order of j, the terms whose coefficient is 0 skipped (a sparse product: the same linear map; an entry that
    one term alone reaches is that term's product, so a coefficient 1 copies its row to the bit)."""
    out = []
    for coefficients in M:
        total: np.ndarray | None = None
        for c, row in zip(coefficients, rows):
            if c != 0.0:
                total = c * row if total is None else total + c * row
        out.append(np.zeros(width) if total is None else total)
    return out


def _delayed(head: np.ndarray, line: Sequence[int], r: _Rows) -> tuple[list[np.ndarray], np.ndarray]:
    """The delay :func:`~wmr_mj.hardware.estimators.delay_line` of len(line) periods on the signal ``head``, its
    state the rows ``line``: (the state's next rows, the output row: ``head`` len(line) periods late)."""
    system = delay_line(len(line))
    state, width = [r.unit(i) for i in line], r.n + 2
    nxt = _combine(np.hstack([system.A, system.B]), [*state, head], width)
    return nxt, _combine(np.hstack([system.C, system.D]), [*state, head], width)[0]


def _estimate(r: _Rows, estimator: VelocityEstimator, E_hat: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """The velocity estimate's row (before its noise) and its state's next rows, from the estimator's matrices
    (:attr:`~wmr_mj.hardware.estimators.VelocityEstimator.system`): its inputs the measured angle E^ and the rate
    read d_s periods late, its state (E^[k-1], y[k-1]) at ``r.prev``, ``r.filt``."""
    system, width = estimator.system, r.n + 2
    state = [r.unit(i) for i in (r.prev, r.filt)[:system.n_states]]
    rate = _delayed(r.unit(1), r.V_line, r)[1] if r.delayed_rate else r.unit(1)  # unread where it differences
    inputs = [*state, E_hat, rate]
    estimate = _combine(np.hstack([system.C, system.D]), inputs, width)[0]
    return estimate, _combine(np.hstack([system.A, system.B]), inputs, width)


def current_moments(control_period: float, electrical_time_constant: float) -> np.ndarray:
    """The current over one period, exactly: j(s) = u + (j_k - u) exp(-s/tau_e) for the held command u from j(0) = j_k.

    Row 0 is j(T), rows 1-3 the integrals of j over [0, T] once, twice and three times (int_0^T (T - s)^(m-1)/(m-1)!
    j(s) ds), each as its coefficients of (u, j_k). With M_0 = tau_e (1 - exp(-T/tau_e)) and M_m = tau_e (T^m/m! -
    M_(m-1)) (the moments of exp(-s/tau_e), by parts), row m is (T^m/m! - M_(m-1), M_(m-1)). tau_e = 0: j = u at once,
    rows (1, 0), (T, 0), (T^2/2, 0), (T^3/6, 0).

    Args:
        control_period: T, s (> 0). electrical_time_constant: tau_e = L_a/R_a, s (>= 0).

    Returns:
        (4, 2) array.
    """
    T, tau = float(control_period), float(electrical_time_constant)
    powers = (1.0, T, T * T / 2.0, T ** 3 / 6.0)
    if tau == 0.0:
        return np.array([[p, 0.0] for p in powers])
    decay = math.exp(-T / tau)
    M = [-tau * math.expm1(-T / tau)]
    for m in (1, 2):
        M.append(tau * (powers[m] - M[-1]))
    return np.array([[1.0 - decay, decay]] + [[powers[m] - M[m - 1], M[m - 1]] for m in (1, 2, 3)])


def sampled_loop(*, kp: float, kd: float, control_period: float, velocity: VelocityEstimate | str = "exact",
                 filter_tau: float | None = None, sensing_delay: int = 0, actuation_delay: int = 0,
                 electrical_time_constant: float = 0.0) -> SampledLoop:
    """The PD servo on the double integrator at period T under zero-order hold, with delays and the estimator.

    The plant's step is exact: exp([[0, 1], [0, 0]] T) = [[1, T], [0, 1]], and the held u enters through
    int_0^T exp(A_c s) ds B_c = [T^2/2, T] (with E'' = -u, the sign is -); the estimator's rows are the
    matrices of the sensing chain's own estimator (:func:`wmr_mj.hardware.estimators.velocity_estimator`), the
    delays those of :func:`~wmr_mj.hardware.estimators.delay_line`.

    Args:
        kp: K_P, 1/s^2 (> 0). kd: K_D, 1/s (> 0).
        control_period: T, s (> 0).
        velocity: 'exact', 'tachometer' (the delayed true rate), 'difference' ((alpha_m[k] - alpha_m[k-1]) / T)
            or 'filtered' (that difference through 1/(tau_f s + 1), discretised as the chain does).
        filter_tau: tau_f, s (> 0), for 'filtered' only.
        sensing_delay: d_s, whole control periods (>= 0): the law reads the state of step k - d_s.
        actuation_delay: d_a, whole control periods (>= 0): the command of step k acts over step k + d_a.
        electrical_time_constant: tau_e = L_a/R_a, s (>= 0): the command reaches the plant through the armature
            current, tau_e j' = u[k - d_a] - j, E'' = -j (one more state, the last); 0: at once (no state).

    Returns:
        The :class:`SampledLoop` (arrays read-only).

    Raises:
        ParameterError: a gain or period not finite and > 0, a delay that is not a whole number >= 0,
            filter_tau missing for 'filtered', not > 0, or given for another estimate.
        UnknownNameError: an unknown velocity estimate.
    """
    K_P, K_D = positive_real("kp", kp, " 1/s^2"), positive_real("kd", kd, " 1/s")
    T = positive_real("control_period", control_period, " s")
    tau = _check_estimate(str(velocity), filter_tau)
    d_s = whole_period_count("sensing_delay", sensing_delay)
    d_a = whole_period_count("actuation_delay", actuation_delay)
    tau_e = 0.0 if electrical_time_constant == 0 else positive_real("electrical_time_constant",
                                                                     electrical_time_constant, " s")
    r = _Rows(str(velocity), d_s, d_a, current=tau_e > 0.0)
    n = r.n
    E_hat = _delayed(r.unit(0), r.E_line, r)[1] - r.unit(n)  # E[k - d_s] - e[k]
    estimate, estimator_rows = _estimate(r, velocity_estimator(str(velocity), control_period=T, filter_tau=tau),
                                         E_hat)
    rate_hat = estimate - r.unit(n + 1)
    u = K_P * E_hat + K_D * rate_hat
    nxt = r.plant_step(u=u, estimator_rows=estimator_rows, T=T, tau_e=tau_e)
    arrays = r.arrays(nxt, u, T)
    return SampledLoop(**arrays, kp=K_P, kd=K_D, control_period=T, velocity=str(velocity), filter_tau=tau,
                       sensing_delay=d_s, actuation_delay=d_a, electrical_time_constant=tau_e)


def sampled_loop_for(sensing: Sensing, *, kp: float, kd: float, control_period: float,
                     actuation_delay: int = 0) -> SampledLoop:
    """:func:`sampled_loop` for a :class:`~wmr_mj.hardware.Sensing` (its estimate, tau_f and delay in periods).

    Args:
        sensing: the specification; its delay must be a whole number of control periods.
        kp, kd, control_period, actuation_delay: as :func:`sampled_loop`.

    Raises:
        ParameterError: as :func:`sampled_loop`, or a sensing delay that is not a whole number of periods.
    """
    return sampled_loop(kp=kp, kd=kd, control_period=control_period, velocity=sensing.velocity,
                        filter_tau=sensing.filter_tau, sensing_delay=sensing.delay_steps(control_period),
                        actuation_delay=actuation_delay)


def _norm_bound(A: np.ndarray, radius: float) -> tuple[np.ndarray, float]:
    """(P, rho): a P > 0 with ||A v||_P <= rho ||v||_P, from the Lyapunov equation of the balanced A / s.

    With A_b = S^-1 A S balanced (scipy.linalg.matrix_balance: S diagonal, powers of 2, exact), P_b solves
    (A_b/s)^T P_b (A_b/s) - P_b = -I, s = (1 + radius) / 2, and P = S^-T P_b S^-1. Whatever rounding did to
    P_b, rho is then computed as the P_b-norm of A_b (= the P-norm of A: the largest generalised eigenvalue
    of (A_b^T P_b A_b, P_b)), so the bound holds for the P actually used; a relative 1e-12 covers eigh's
    rounding. rho = inf where P_b is not positive definite.
    """
    A_b, S = scipy.linalg.matrix_balance(A, permute=False, separate=True)
    s = 0.5 * (1.0 + radius)
    P_b = scipy.linalg.solve_discrete_lyapunov((A_b / s).T, np.eye(A.shape[0]), method="bilinear")
    P_b = 0.5 * (P_b + P_b.T)
    scale = 1.0 / S[0]
    P = P_b * np.outer(scale, scale)
    try:
        top = scipy.linalg.eigh(A_b.T @ P_b @ A_b, P_b, eigvals_only=True, subset_by_index=[A.shape[0] - 1] * 2)
    except np.linalg.LinAlgError:
        return P, math.inf
    return P, math.sqrt(max(float(top[0]), 0.0)) * (1.0 + 1e-12)


def _hold_integrals(c1: np.ndarray, c2: np.ndarray, T: float) -> np.ndarray:
    """int_0^T |c1 tau + c2| d tau, elementwise (a line's absolute area: two triangles where it crosses 0)."""
    f0, fT = c2, c1 * T + c2
    crosses = f0 * fT < 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        split = np.where(crosses, -c2 / np.where(crosses, c1, 1.0), 0.0)  # where c1 tau + c2 = 0
    two_triangles = 0.5 * (np.abs(f0) * split + np.abs(fT) * (T - split))
    return np.where(crosses, two_triangles, 0.5 * T * np.abs(f0 + fT))


def _unstable(radius: float, reason: str, T: float) -> PeakGains:
    inf = np.full((len(OUTPUTS), len(SOURCES)), np.inf)
    return PeakGains(gains=inf, reached=inf.copy(), tail=inf.copy(), n_terms=0, spectral_radius=radius,
                     rho=math.nan, M=math.nan, control_period=T, reason=reason)


def _sum_blocks(loop: SampledLoop, n_terms: int | None, rtol: float, max_terms: int,
                P: np.ndarray, rho: float) -> tuple[np.ndarray, np.ndarray, int]:
    """The l1 sums over steps 0..N-1 of C A^k [B, w_position, w_rate] and the tail bound after N (see peak_gains)."""
    A, C, T = loop.A, loop.C, loop.control_period
    n, L = loop.n_states, _BLOCK
    powers = np.empty((L + 1, n, n))
    powers[0] = np.eye(n)
    for j in range(1, L + 1):
        powers[j] = powers[j - 1] @ A
    CA = C @ powers[:L]  # (L, 3, n): C A^j
    dual = np.sqrt(np.einsum("ij,ij->i", C, np.linalg.solve(P, C.T).T))  # ||c_i||_{P*} = sqrt(c P^-1 c^T)
    X = np.column_stack([loop.B, loop.w_position, loop.w_rate])  # A^k of the four columns, k = 0 first
    sums, k = np.zeros((len(OUTPUTS), 3)), 0  # columns: angle, velocity, w
    goal = max_terms if n_terms is None else n_terms
    while True:
        m = min(L, goal - k)
        Y = CA[:m] @ X  # (m, 3, 4)
        sums[:, :2] += np.abs(Y[:, :, :2]).sum(axis=0)
        sums[:, 2] += _hold_integrals(Y[:, :, 2], Y[:, :, 3], T).sum(axis=0)
        X, k = powers[m] @ X, k + m
        pn = np.sqrt(np.einsum("ij,ik,kj->j", X, P, X))  # ||A^k b||_P per column
        tail = np.outer(dual, [pn[0], pn[1], 0.5 * T * T * pn[2] + T * pn[3]]) / (1.0 - rho)
        if k >= goal or (n_terms is None and np.all(tail <= rtol * sums + 1e-300)):
            return sums, tail, k


def peak_gains(loop: SampledLoop, *, n_terms: int | None = None, rtol: float = 1e-6,
               max_terms: int = 1_000_000) -> PeakGains:
    """Peak-to-peak (l1) gains of ``loop`` from every source of :data:`SOURCES` into E, E' and u, with a sound tail.

    For a discrete source with input column b and direct part d_i, sup_k |y_i[k]| over |source| <= 1 from rest
    is |d_i| + sum_{k>=0} |c_i A^k b| (Dahleh and Pearson 1987), attained by the sign of the time-reversed
    impulse response. For the continuous w, the response at step k + 1 to w over one period is
    int_0^T c_i A^k (tau w_position + w_rate) w dtau, so its l1 sum has int_0^T |c_i A^k (tau e_E + e_E')| dtau
    per period (at the sampling instants; the intersample peak is not in this number).

    The tail: with P > 0 and rho = ||A||_P < 1 (:func:`_norm_bound`: the discrete Lyapunov equation of A / s,
    s = (1 + spectral radius) / 2, then rho measured for that P), |c A^k v| <= ||c||_{P*} ||A^k v||_P and
    ||A^(N+j) b||_P <= rho^j ||A^N b||_P, so sum_{k>=N} |c A^k b| <= ||c||_{P*} ||A^N b||_P / (1 - rho), and for
    w the same with T^2/2 ||A^N e_E||_P + T ||A^N e_E'||_P. In the Euclidean norm this is
    ||A^k||_2 <= M rho^k with M = sqrt(cond P) (reported; the tail uses the sharper P form above).

    Args:
        loop: the sampled loop.
        n_terms: N, the steps summed; None: sum until every tail is within ``rtol`` of its sum (or
            ``max_terms``; the tail is added either way, so the gain stays an upper bound).
        rtol: the relative tail at which the sum stops (n_terms None).
        max_terms: the most steps summed.

    Returns:
        :class:`PeakGains`: inf with the reason where the spectral radius is >= 1 or no norm bound < 1 is found.
        Rounding: ``gains`` is (reached + tail) (1 + 4 (N + n + 64) eps): Higham's bound (N - 1) u on a sum of N
        terms of one sign, plus the n-term products, each step's own rounding (the error of A^k itself,
        propagated by a stable A, is of the same order and not bounded separately).

    Raises:
        ParameterError: n_terms or max_terms not >= 1, rtol not > 0.
    """
    for name, v in (("n_terms", n_terms), ("max_terms", max_terms)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, int) or v < 1):
            raise ParameterError(f"{name} = {v!r} is not accepted; a whole number of steps >= 1 is required")
    positive_real("rtol", rtol)
    radius = float(np.max(np.abs(np.linalg.eigvals(loop.A))))
    if not radius < 1.0:
        return _unstable(radius, f"spectral radius {radius:.6g} >= 1: the sampled loop is not Schur-stable "
                                 "(no bounded gain)", loop.control_period)
    P, rho = _norm_bound(loop.A, radius)
    if not rho < 1.0:
        return _unstable(radius, f"no norm bound below 1 found (rho {rho:.6g}, spectral radius {radius:.6g})",
                         loop.control_period)
    sums, tail, N = _sum_blocks(loop, n_terms, rtol, max_terms, P, rho)
    columns = [2 if s == "w" else _CHANNEL_OF[s] for s in SOURCES]
    direct = np.column_stack([np.abs(loop.D), np.zeros(len(OUTPUTS))])  # w has no direct part
    reached = (sums + direct)[:, columns]
    tails = tail[:, columns]
    eig_P = np.linalg.eigvalsh(P)
    rounding = 1.0 + 4.0 * (N + loop.n_states + _BLOCK) * np.finfo(float).eps  # see Returns
    return PeakGains(gains=(reached + tails) * rounding, reached=reached, tail=tails, n_terms=N, spectral_radius=radius,
                     rho=rho, M=math.sqrt(float(eig_P[-1] / eig_P[0])), control_period=loop.control_period)


def peak_bounds(gains: PeakGains, *, quantisation: float = 0.0, angle_noise: float = 0.0, play: float = 0.0,
                velocity_noise: float = 0.0, w: float = 0.0,
                between_samples: bool = False) -> tuple[float, float, float]:
    """sup|E| (rad), sup|E'| (rad/s), sup|u| (rad/s^2) for sources within the given bounds, from rest.

    The sum over sources of gain x bound (each source's worst case need not coincide with another's, so the
    sum is an upper bound; the three angle errors share one input, where the sum is exact). At the sampling
    instants; with ``between_samples``, over all t: on [t_k, t_k + T) E'' = -u[k - d_a] + w(t), so
    |E(t_k + s)| <= |E[k]| + T |E'[k]| + T^2/2 (sup|u| + sup|w|) and |E'(t_k + s)| <= |E'[k]| + T (sup|u| +
    sup|w|) (u is held: its bound stands).

    Args:
        gains: from :func:`peak_gains`.
        quantisation: sup|q|, rad (Delta/2 rounding, Delta floor). angle_noise: rad. play: rad at the axis.
        velocity_noise: rad/s. w: rad/s^2. Each >= 0.
        between_samples: bound E and E' between the sampling instants too.

    Returns:
        (E, E', u) bounds; inf where the loop is unstable and a source is on.

    Raises:
        ParameterError: a bound that is not a finite number >= 0.
    """
    bounds = np.zeros(len(SOURCES))
    for name, v in (("w", w), ("quantisation", quantisation), ("angle_noise", angle_noise), ("play", play),
                    ("velocity_noise", velocity_noise)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (0.0 <= v < math.inf):
            raise ParameterError(f"{name} = {v!r} is not accepted; a bound >= 0 (finite) is required")
        bounds[SOURCES.index(name)] = v
    used = bounds > 0.0  # 0 x inf is no cost: a source that is off
    E, Edot, u = (float(x) for x in (gains.gains[:, used] * bounds[used]).sum(axis=1))
    if between_samples:
        T = gains.control_period
        E, Edot = E + T * Edot + 0.5 * T * T * (u + w), Edot + T * (u + w)
    return E, Edot, u


def characteristic_polynomial(*, kp: float, kd: float, control_period: float,
                              velocity: VelocityEstimate | str = "exact", filter_tau: float | None = None,
                              delay: int = 0) -> np.ndarray:
    """The closed loop's characteristic polynomial in z, highest power first, for a total delay of d periods.

    With G(z) = T^2/2 (z + 1)/(z - 1)^2 (E per held -u), G_v(z) = T/(z - 1) (E' per held -u) and the estimate's
    C(z) = N_c/D_c from E^ to u, the loop 1 + z^-d C G = 0 gives D_c (z - 1)^2 z^d + N_c-terms:

    - exact, tachometer: (z - 1)^2 z^d + K_P T^2/2 (z + 1) + K_D T (z - 1);
    - difference: C = K_P + K_D (z - 1)/(T z);
    - filtered: C = K_P + K_D (1 - a)(z - 1)/(T (z - a)).

    Only d = d_s + d_a matters (the delays commute in a single loop). Its roots are the nonzero
    eigenvalues of :func:`sampled_loop`'s A (the rest are 0: the delayed E' line of the exact estimate).

    Raises:
        ParameterError, UnknownNameError: as :func:`sampled_loop`.
    """
    K_P, K_D = positive_real("kp", kp, " 1/s^2"), positive_real("kd", kd, " 1/s")
    T = positive_real("control_period", control_period, " s")
    tau = _check_estimate(str(velocity), filter_tau)
    d = whole_period_count("delay", delay)
    P = np.polynomial.polynomial  # coefficients lowest power first below
    plant_den, plant_num = np.array([1.0, -2.0, 1.0]), np.array([T * T / 2.0, T * T / 2.0])
    if velocity in ("exact", "tachometer"):
        num = P.polyadd(P.polymul([K_P], plant_num), [-K_D * T, K_D * T])
        den = plant_den
    else:
        a = velocity_estimator(str(velocity), control_period=T, filter_tau=tau).a  # 0 for the difference
        c_den = [-a * T, T]  # T (z - a); a = 0 gives the difference's T z
        c_num = P.polyadd(P.polymul([K_P], c_den), P.polymul([K_D * (1.0 - a)], [-1.0, 1.0]))
        num, den = P.polymul(c_num, plant_num), P.polymul(c_den, plant_den)
    return np.asarray(P.polyadd(P.polymul(den, [0.0] * d + [1.0]), num))[::-1]


def jury_stable(coefficients: np.ndarray) -> bool:
    """Jury's test (Schur-Cohn form): True iff every root of the real polynomial lies strictly inside |z| = 1.

    Each row of Jury's table is p_{m-1}(z) = (a_m p_m(z) - a_0 p_m*(z)) / z with p_m*(z) = z^m p_m(1/z), a_m
    the leading and a_0 the constant coefficient; p_m is Schur-stable iff |a_0| < |a_m| and p_{m-1} is
    (Jury 1964; Astrom and Wittenmark, Computer-Controlled Systems, sec. 3.3). Each row is scaled by its
    largest coefficient (a positive scale changes no root).

    Args:
        coefficients: highest power first, the leading one nonzero.

    Raises:
        ParameterError: an empty, non-finite or zero-leading coefficient list.
    """
    p = np.trim_zeros(np.asarray(coefficients, dtype=float), "f")
    if p.size == 0 or not np.all(np.isfinite(p)):
        raise ParameterError(f"jury_stable: coefficients {coefficients!r} are not accepted; finite numbers with "
                             "a nonzero leading one are required")
    while p.size > 1:
        lead, const = p[0], p[-1]
        if not abs(const) < abs(lead):
            return False
        p = (lead * p - const * p[::-1])[:-1]
        p = p / np.max(np.abs(p))
    return True


def delay_margin(*, kp: float, kd: float, control_period: float, velocity: VelocityEstimate | str = "exact",
                 filter_tau: float | None = None, max_delay: int = 100_000) -> int | None:
    """The largest d (control periods, d_s + d_a) such that the loop is Schur-stable for every delay 0..d (Jury).

    Args:
        kp, kd, control_period, velocity, filter_tau: as :func:`sampled_loop`.
        max_delay: the most periods tried; returned where the loop is still stable there.

    Returns:
        d, or None where the loop is unstable with no delay.

    Raises:
        ParameterError, UnknownNameError: as :func:`sampled_loop`.
    """
    whole_period_count("max_delay", max_delay)
    for d in range(max_delay + 1):
        poly = characteristic_polynomial(kp=kp, kd=kd, control_period=control_period, velocity=velocity,
                                         filter_tau=filter_tau, delay=d)
        if not jury_stable(poly):
            return None if d == 0 else d - 1
    return max_delay
