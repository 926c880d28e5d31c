"""The sliding-mode law as it runs on a sensed cart: its boundary layer as a sampled loop (issue 35 item 2).

The continuous claim (:meth:`controllers.sliding_mode.SlidingMode.measured_layer`) grows the layer by the law's
input errors charged as free at every instant: a differenced 12-bit angle's velocity error Delta/T = 1.53 rad/s
against a layer phi = 0.2 rad/s. Here the layer is analysed as the law runs. Inside the layer (|s^| <= phi, s^
the law's s = E^' + lam E^ from the measured angle and its velocity estimate) sat(s^/phi) = s^/phi, so the law::

    u = P^ (a0'' + lam E^') + C_V^ a_m' + F^ sgn(a_m') + K^ S(a_m) + Gam^ a_m'/cos^2(a_m) + (k/phi) (E^' + lam E^)
      = P^ (a0'' + K_D E^' + K_P E^) + the same compensations,   K_P = lam g, K_D = lam + g, g = k/(P^ phi)

is the computed-torque law (3.2)-(3.3) with those gains, exactly (the error dynamics (p + lam)(p + g)). Its
sampled-data certificate (:func:`wmr_mj.analysis.sampled_certificate.sampled_certificate`: zero-order hold at
T, the delays as states, the velocity estimate as it runs, every bounded error at its l1 gain, so a differenced
quantised angle telescopes; the nonlinear remainder through the sampled small gain) bounds E, E' and u, and the
same fixed point bounds s^ at every sample: sup|s^| <= S^ = M_s + g_s W~ (the l1 gains into s^ from the
measurement channels and from the remainder W~). Where S^ <= phi the saturation never acts (by induction over
the samples: up to step k the loop is the linear one, whose bound puts s^[k] inside), so the certificate holds
for the sliding-mode law. Where S^ > phi the assumption "measured s within the layer" is unmet (no sound
argument is made for a saturated layer here: the run is then uncertified under this certificate, and the
continuous claim stands as it is). Derivation: ``docs/guides/certificates.md``, "The sliding-mode layer as a
sampled loop".

Usage::

    from wmr_mj.analysis.sliding_sampled import sliding_sampled_certificate
    cert = sliding_sampled_certificate(plant=..., estimate=..., lam=5.0, phi=1.0, k=3.0, reference=...,
                                       limits=..., compensation=..., control_period=0.001, cart=cart)
    cert.E_max, cert.inputs["sliding_mode"]["s_hat_max"]
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from wmr_mj.analysis.certificate import replace_inputs
from wmr_mj.analysis.claim_types import Assumption, Certificate
from wmr_mj.analysis.plant_box import PlantBox, PlantLimits
from wmr_mj.analysis.sampled_certificate import (
    SampledCart,
    _Bound,
    _initial_transient,
    _linear,
    _solve_at,
    damped_loop,
    sampled_certificate,
)
from wmr_mj.analysis.sampled_data import PeakGains, SampledLoop, peak_gains, sampled_loop
from wmr_mj.analysis.small_gain import Compensation, Estimate, Gains
from wmr_mj.errors import ParameterError
from wmr_mj.reference.bounds import ReferenceBounds

__all__ = ["LAYER_NOT_SATURATED", "equivalent_gains", "layer_loop", "sliding_sampled_certificate"]

#: Name of the assumption that the law's measured s stays inside the layer at every sample (sat is linear).
LAYER_NOT_SATURATED = "measured s within the layer"


def equivalent_gains(*, lam: float, phi: float, k: float, P_hat: float) -> tuple[float, float]:
    """(K_P 1/s^2, K_D 1/s) of the sliding-mode law inside its layer: lam g and lam + g, g = k/(P^ phi) (1/s).

    Args:
        lam: the surface's slope, 1/s. phi: the layer, rad/s. k: the switching gain, V. P_hat: P^, V s^2/rad.

    Raises:
        ParameterError: k = 0 (no layer gain: the law has no servo of its own inside the layer).
    """
    g = k / (P_hat * phi)
    if not (math.isfinite(g) and g > 0.0):
        raise ParameterError(f"k = {k!r} V: the layer's gain k/(P^ phi) is not > 0, so the law inside the layer "
                             "has no servo to analyse (no sampled-data bound)")
    return lam * g, lam + g


def layer_loop(loop: SampledLoop, *, lam: float) -> SampledLoop:
    """``loop`` with its third output the law's s^ = E^' + lam E^ (rad/s) in place of u: the same state and rows.

    The rows of E^ and E^' over [state, e, n_v] do not depend on the gains (:class:`_Rows` lays the state out by
    the estimate and the delays only), so the servo row of the same loop built with K_P = lam, K_D = 1 is s^.
    """
    probe = sampled_loop(kp=lam, kd=1.0, control_period=loop.control_period, velocity=loop.velocity,
                         filter_tau=loop.filter_tau, sensing_delay=loop.sensing_delay,
                         actuation_delay=loop.actuation_delay, electrical_time_constant=loop.electrical_time_constant)
    C, D = np.array(loop.C), np.array(loop.D)
    C[2], D[2] = probe.C[2], probe.D[2]
    for x in (C, D):
        x.flags.writeable = False
    return dataclasses.replace(loop, C=C, D=D)


def _layer_bound(bound: _Bound, cart: SampledCart, T: float, c_hat: float, lam: float, E_max: float,
                 Edot_max: float, friction_width: float) -> tuple[float, dict[str, float]]:
    """S^ = sup_k |s^[k]| (rad/s) at the certificate's fixed point, and its parts.

    The remainder's bound W~ is taken from one step of the fixed point at (E_max, Edot_max), which lie at or above
    the least fixed point (the iteration rises to it from 0 and returns the step there), so W~ is an upper bound
    (every coefficient of the step increases with the angle and the rate reached).
    """
    lin = _linear(bound, cart, T, c_hat)
    solved = _solve_at(bound, lin, cart, T, c_hat, E_max, Edot_max, friction_width)
    loop = layer_loop(damped_loop(kp=bound.kp, kd=bound.kd, c_hat=c_hat, control_period=T, cart=cart), lam=lam)
    gains: PeakGains = peak_gains(loop)
    if solved.failure or not gains.stable or not math.isfinite(solved.Wt):
        return math.inf, {}
    G = gains.gains[2]
    start = float(_initial_transient(loop, cart, gains.spectral_radius)[2]) * (cart.angle_error + 1e-9)
    parts = {"from_angle": float(G[1]) * lin.angle_channel,
             "from_velocity": float(G[4]) * lin.velocity_channel if lin.velocity_channel > 0.0 else 0.0,
             "from_start": start, "from_remainder": float(G[0]) * solved.Wt,
             "gain_s_angle": float(G[1]), "gain_s_velocity": float(G[4]), "gain_s_w": float(G[0]), "Wt": solved.Wt}
    total = parts["from_angle"] + parts["from_velocity"] + parts["from_start"] + parts["from_remainder"]
    return total * (1.0 + 1e-12), parts


def sliding_sampled_certificate(*, plant: PlantBox, estimate: Estimate, lam: float, phi: float, k: float,
                                reference: ReferenceBounds, limits: PlantLimits, compensation: Compensation,
                                control_period: float, cart: SampledCart,
                                initial_error: tuple[float, float] = (0.0, 0.0),
                                stated: Sequence[Assumption] = ()) -> Certificate:
    """The sampled-data certificate of the sliding-mode law (module docstring) on ``cart``.

    Args:
        plant, reference, limits, control_period, cart, initial_error, stated: as
            :func:`~wmr_mj.analysis.sampled_certificate.sampled_certificate`.
        estimate: the law's model (P^, C_V^, F^ (0 for the sign 'none'), K^, gyro^, V_A^).
        lam: 1/s. phi: rad/s. k: V (> 0). compensation: the law's Coulomb sign and its smoothing.

    Returns:
        The computed-torque sampled-data certificate at K_P = lam g, K_D = lam + g (:func:`equivalent_gains`) with
        the assumption :data:`LAYER_NOT_SATURATED` (S^ <= phi) added, and ``inputs['sliding_mode']``: lam, phi, k,
        the equivalent gains, S^ and its parts.

    Raises:
        ParameterError: k = 0, or as ``sampled_certificate``.
    """
    kp, kd = equivalent_gains(lam=lam, phi=phi, k=k, P_hat=estimate.P)
    gains = Gains(kp=kp, kd=kd)
    cert = sampled_certificate(plant=plant, estimate=estimate, gains=gains, reference=reference, limits=limits,
                               compensation=compensation, control_period=control_period, cart=cart,
                               initial_error=initial_error, stated=stated)
    s_hat, parts = math.inf, dict[str, float]()
    if cert.valid:
        assert reference.alpha_max is not None  # sampled_certificate checked it
        bound = _Bound.of(plant, estimate, gains, reference, compensation, reference.alpha_max)
        s_hat, parts = _layer_bound(bound, cart, float(control_period), estimate.C_V / estimate.P, lam,
                                    cert.E_max, cert.Edot_max, compensation.friction_width)
    layer = Assumption(LAYER_NOT_SATURATED, "sup_k |s^[k]| <= phi, s^ = E^' + lam E^ as the law forms it (l1 gains "
                       "into s^ at the sampled certificate's fixed point): sat(s^/phi) is linear at every sample, so "
                       "the law is the servo K_P = lam k/(P^ phi), K_D = lam + k/(P^ phi)",
                       bool(cert.valid and s_hat <= phi), s_hat, phi,
                       (f"S^ = {s_hat:.4g} rad/s against phi = {phi:g} rad/s (" + ", ".join(
                           f"{n} {v:.4g}" for n, v in parts.items() if n.startswith("from_")) + ")")
                       if parts else f"no bound on s^ ({cert.reason or 'the loop'})", kind="checked")
    cert = dataclasses.replace(cert, assumptions=(*cert.assumptions, layer))
    record: dict[str, Any] = {"lam": lam, "phi": phi, "k": k, "kp": kp, "kd": kd,
                              "s_hat_max": s_hat if math.isfinite(s_hat) else None, **parts}
    return replace_inputs(cert, {**dict(cert.inputs), "sliding_mode": record})
