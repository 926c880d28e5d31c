"""An observer-based steering law of one's own, for a cart that reads the quantised angle only, and its claim.

The law reads the measured angle alone (``--sensing velocity=none``: alpha_dot is NaN) and estimates E and E'
with a Luenberger observer of the error E = alpha0 - alpha on the model E'' = -v (the computed-torque
feed-forward cancels the rest), in current-estimator form at the control period T::

    E^ = alpha0 - alpha_m                                   the measured error
    x = x_pred + L (E^ - x_pred[0])                         correct (x = (E_est, E'_est))
    v = K_P x[0] + K_D x[1]                                 the servo command, rad/s^2
    x_pred = Phi x - Gamma v,  Phi = [[1, T], [0, 1]], Gamma = [T^2/2, T]      predict
    u = P_hat (alpha0'' + v) + C_V_hat alpha0'               volts (the viscous term on the reference's rate)

The observer's model lacks what the feed-forward does not cancel (friction at rest, the model's mismatch): a
constant such acceleration biases its estimate of E' (measured 0.024 rad/s on the circle with the steering
stuck), which the claim charges with the rest of w below. It logs its estimates beside the rows
(``signal_names``: rows ``law_E_est``, ``law_Edot_est``, ``law_alpha_dot_est`` and the log's ``/law``).

Its linear part E^ -> v is the state-space model (A_c, B_c, C_c, D_c) of :meth:`ObserverLaw.linear_part`, and
its claim analyses it with :func:`wmr_mj.analysis.linear_part_bounds` on the run's cart (the encoder, the
delays), charging everything nonlinear as a disturbance w of E'' = -v + w, bounded over the run's plant box
(the plant P alpha'' + C_V alpha' + f + K S(alpha) + Gam alpha'/cos^2(alpha) = u + d_V of section 4, f the
friction, anywhere in [-F, F] at rest)::

    w = alpha0''(t) - (P_hat/P) alpha0''[k] + (1 - P_hat/P) v + [C_V alpha' - C_V_hat alpha0'[k] + f
        + Gam alpha'/cos^2(alpha) + K S(alpha) - d_V] / P

    |w| <= max|alpha0''| (1 + P_hat/P_min) + max|1 - P_hat/P| u_max
           + [ |C_V - C_V_hat|max max|alpha0'| + C_V,max ((d_a + 1) T max|alpha0''| + Edot_max) + F_max
               + Gam_max (max|alpha0'| + Edot_max)/cos^2(alpha_max) + |K|max S(alpha_max) + d_V,max ] / P_min

(alpha' = alpha0' - E'; the voltage applied over [t_k, t_k + T) is the law's of step k - d_a, d_a the actuation
delay in periods, whose alpha0' is within (d_a + 1) T max|alpha0''| of alpha0'(t), and alpha0''(t) and the
feed-forward's alpha0''[k - d_a] are each within max|alpha0''|). The bound depends on E_max,
Edot_max and u_max, which depend on w: a small-gain fixed point, closed as section 4's, on alpha_max =
max|alpha0| + E_max (:func:`wmr_mj.analysis.claim.fixed_point`). The reading's delay d_s T makes the law
compare alpha0(t_k) with alpha(t_k - d_s T): E^[k] = E[k - d_s] + (alpha0(t_k) - alpha0(t_k - d_s T)) - e, so
the angle's error is charged d_s T max|alpha0'| besides the encoder's (``linear_part_bounds(reference_rate=)``).

The gains: K_P = 1600/s^2, K_D = 80/s (a double pole at 40/s) and observer poles at 300/s. Slower gains (400,
40) run as well but do not close the claim's small gain over falsify's full box, where the plant's damping fed
back through E', (C_V + Gam/cos^2)/P times the loop's gain from w to E', is 0.80 of the budget alone. On the
m1 box (run's and sweep's default) the claim closes; over the full box (falsify's default) it closes too, but
its bound on the law's voltage (71 V) exceeds the supply (24 V): uncertified, never certified-outside.

Run it from the repository root::

    wmr-mj run --controller examples/observer_law.py:ObserverLaw \\
        --sensing encoder_bits=13,velocity=none,delay=0.003 --path paper-circle --m1 750 --no-log
"""

from __future__ import annotations

import math

import numpy as np

from controllers import SteeringController


class ObserverLaw(SteeringController):
    """Luenberger observer of (E, E') from the measured angle, a PD servo on the estimate, computed-torque
    feed-forward. Parameters: kp [1/s^2], kd [1/s], observer_pole [1/s] (both observer poles at
    z = exp(-observer_pole T)), P_hat [V s^2/rad], C_V_hat [V s/rad]."""

    name = "observer-pd"
    reads_velocity = False  # it reads the angle only: runs with --sensing velocity=none
    signal_names = ("E_est", "Edot_est", "alpha_dot_est")  # logged beside the rows as law_E_est, ...

    def __init__(self, kp: float = 1600.0, kd: float = 80.0, observer_pole: float = 300.0, P_hat: float = 0.385,
                 C_V_hat: float = 4.77) -> None:
        self.kp, self.kd, self.observer_pole = float(kp), float(kd), float(observer_pole)
        self.P_hat, self.C_V_hat = float(P_hat), float(C_V_hat)
        self.reset(control_period=0.001)

    def observer_gain(self, T: float) -> np.ndarray:
        """L (2,) placing both eigenvalues of (I - L H) Phi at z = exp(-observer_pole T) (current estimator)."""
        z = math.exp(-self.observer_pole * T)
        # the characteristic polynomial of (I - L H) Phi is z^2 - (2 - l1 - T l2) z + (1 - l1) = (z - p)^2
        l1 = 1.0 - z * z
        l2 = (2.0 - l1 - 2.0 * z) / T
        return np.array([l1, l2])

    def linear_part(self, T: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(A_c, B_c, C_c, D_c): the measured error E^ (rad) in, the servo command v (rad/s^2) out, at period T."""
        Phi = np.array([[1.0, T], [0.0, 1.0]])
        Gamma = np.array([[0.5 * T * T], [T]])
        K = np.array([[self.kp, self.kd]])
        L = self.observer_gain(T).reshape(2, 1)
        I_LH = np.eye(2) - L @ np.array([[1.0, 0.0]])
        closed = Phi - Gamma @ K
        return closed @ I_LH, closed @ L, K @ I_LH, K @ L

    def reset(self, *, control_period: float) -> None:
        self.T = float(control_period)
        self.L = self.observer_gain(self.T)
        self.x_pred = np.zeros(2)
        self.estimate = (0.0, 0.0, 0.0)

    def step(self, t, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        T = self.T
        E_meas = alpha0 - alpha  # alpha_dot is not read (NaN with velocity=none)
        innovation = E_meas - self.x_pred[0]
        E_est = self.x_pred[0] + self.L[0] * innovation
        Edot_est = self.x_pred[1] + self.L[1] * innovation
        v = self.kp * E_est + self.kd * Edot_est
        self.x_pred = np.array([E_est + T * Edot_est - 0.5 * T * T * v, Edot_est - T * v])
        self.estimate = (E_est, Edot_est, alpha0_dot - Edot_est)
        return self.P_hat * (alpha0_ddot + v) + self.C_V_hat * alpha0_dot

    def signals(self):
        """The observer's estimates of this step: E (rad), E' and alpha' (rad/s), logged beside the rows."""
        return dict(zip(self.signal_names, self.estimate))

    def describe(self):
        return {"controller": self.name, "kp": self.kp, "kd": self.kd, "observer_pole": self.observer_pole,
                "P_hat": self.P_hat, "C_V_hat": self.C_V_hat}

    def claim(self, context):
        return observer_claim(self, context)


def observer_claim(law: ObserverLaw, context):
    """The claim of the module docstring: the linear part's peak bounds, the remainder w, the fixed point."""
    from wmr_mj.analysis import linear_part_bounds
    from wmr_mj.analysis.claim import box_claim, fixed_point
    from wmr_mj.analysis.claim_types import Assumption
    from wmr_mj.analysis.measurement import MEASUREMENT_COVERED

    T, ref, box = context.control_period, context.reference, context.plant
    P_lo, P_hi = box.box.P
    C_lo, C_hi = box.box.C_V
    F_max = box.box.F[1]
    K_abs = max(abs(k) for k in box.box.K)
    Gam_max = max(abs(g) for g in box.gyro) * max(abs(v) for v in box.V_A)
    a0, a0d, a0dd = ref.angle_max, ref.alpha_dot_max, ref.alpha_ddot_max
    linear = law.linear_part(T)
    sources = linear_part_bounds(linear, context=context, w=0.0, reference_rate=a0d)
    own = []
    measured_ok = context.measurement.covered and context.play == 0.0
    if not sources.stable or not math.isfinite(sources.E_max) or not measured_ok:
        why = sources.gains.reason or context.measurement.why_not or "the gear's play is not covered"
        return box_claim(claimant=law.name, E_max=math.inf, context=context, alpha_max=math.inf,
                         voltage_max=math.inf, reason=f"observer claim: {why}")
    from wmr_mj.analysis.sampled_data import peak_bounds

    gE, gD, gU = peak_bounds(sources.gains, w=1.0, between_samples=True)  # per unit w (the bounds are linear in w)
    E_q, D_q, U_q = sources.E_max, sources.Edot_max, sources.u_max
    ratio = max(abs(1.0 - law.P_hat / P_lo), abs(1.0 - law.P_hat / P_hi))
    d_a = sources.loop.actuation_delay  # the voltage applied is d_a periods old: its alpha0' that much older

    def solve(alpha_max: float) -> tuple[float, float, float, float]:
        c2 = math.cos(alpha_max) ** 2
        S = math.sin(alpha_max) / c2 / math.cos(alpha_max)
        a_u = ratio
        a_d = (C_hi + Gam_max / c2) / P_lo
        c0 = (a0dd * (1.0 + law.P_hat / P_lo)
              + (max(abs(C_lo - law.C_V_hat), abs(C_hi - law.C_V_hat)) * a0d + C_hi * (d_a + 1) * T * a0dd + F_max
                 + Gam_max * a0d / c2 + K_abs * S + box.disturbance) / P_lo)
        gain = a_u * gU + a_d * gD
        if not gain < 1.0:
            return math.inf, math.inf, math.inf, gain
        w = (c0 + a_u * U_q + a_d * D_q) / (1.0 - gain)
        return E_q + gE * w, D_q + gD * w, U_q + gU * w, w

    E_max, iterations, reason = fixed_point(lambda x: solve(a0 + x)[0], a0)
    E_max, Edot_max, u_max, w = solve(a0 + E_max) if math.isfinite(E_max) else (math.inf,) * 4
    if not math.isfinite(E_max) and "(4.23)" in reason:  # fixed_point words it for section 4: say which gain
        reason = (f"no fixed point: the small gain of w's own terms, |1 - P_hat/P| g_u + (C_V + Gam/cos^2)/P g_E' = "
                  f"{solve(a0)[3]:.4g} >= 1 at alpha_max = {a0:.4g} rad (or beyond, as alpha_max grows)")
    voltage_max = law.P_hat * (a0dd + u_max) + law.C_V_hat * a0d
    own.append(Assumption(MEASUREMENT_COVERED, "the encoder, the delays and the observer in the sampled loop",
                          True, 0.0, 0.0, "linear_part_bounds: quantisation, noise, delays, the reference's shift"))
    return box_claim(claimant=law.name, E_max=E_max, Edot_max=Edot_max, context=context, alpha_max=a0 + E_max,
                     voltage_max=voltage_max, own=own, reason=reason,
                     inputs={"w_max": w, "u_max": u_max, "iterations": iterations,
                             "E_from_sensing": E_q, "E_per_w": gE})
