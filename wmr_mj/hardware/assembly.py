"""The cart as a run builds it, its parts assembled, in one line and one mapping: what every summary (run, sweep,
falsify, compare, the certificate) shows of the run's sensing, actuation and transmission. (The cart *file*, its
parameters and defaults, is :mod:`wmr_mj.carts`'s; this module was ``wmr_mj.hardware.cart`` before.)

Usage::

    from wmr_mj.hardware.assembly import cart_dict, cart_line

    cart_dict(config)    # {'sensing': {...}} : only the parts that are not ideal (an ideal cart: {})
    cart_line(config)    # 'cart: sensing encoder 4096/rev axis round, alpha' difference; actuation ideal; ...'

``config`` is anything with the attributes ``sensing``, ``actuation`` and ``transmission`` holding the typed
parts (a :class:`wmr_mj.sim.config.RunConfig`). A part that is ideal is left out of :func:`cart_dict`, as
``RunConfig.to_dict()`` leaves it out, so the JSON of a run on today's plant keeps the keys it always had.

:func:`check_cart` refuses a cart that cannot be built on the run's plant (each part alone checks only its
own ranges; these limits need the plant's parameter set and the run's duration):

- a sensing or actuation delay not shorter than the run: the law (or the motor) would act on nothing but
  the state at t = 0;
- an angle reading whose error bound (the encoder's Delta/2 rounding or Delta truncation, plus a uniform
  noise's bound) reaches pi/2 from the steering stops: the laws and their claims divide by cos(alpha) of
  the measured angle (tan, 1/cos^2), undefined at pi/2. With the stops at +-0.9 rad this is at least 5 ticks
  (3 bits) for a rounding encoder on the axis, 10 (4 bits) for a truncating one, 1 on the motor side;
- play wider than the steering stops: a half-width b >= steering_range leaves a gap 2 b as wide as the
  steering's whole travel between its stops;
- an armature electrical time constant L_a / R_a above :data:`MAX_ELECTRICAL_TIME_CONSTANT_S`.
"""

from __future__ import annotations

import math
from typing import Any

from wmr_mj.errors import DurationError, ParameterError

__all__ = ["CART_PARTS", "cart_dict", "cart_line", "is_ideal_cart", "check_cart", "MAX_ELECTRICAL_TIME_CONSTANT_S",
           "smallest_encoder_ticks"]

#: The largest armature electrical time constant L_a / R_a accepted, s. DC and servo motor datasheets give L_a/R_a
#: from a fraction of a millisecond to about 10 ms (e.g. Parker's EX620EAO servo motor: 14 mH / 1.63 Ohm =
#: 8.6 ms); 0.1 s is ten times the top of that range and 100 periods of the 1 ms control loop. It stays below
#: K_D / K_P = 0.2 s, the Routh limit of the certified design's loop with an actuator lag
#: (tests/test_actuation_model.py), so every accepted inductance leaves that loop's linear part stable.
MAX_ELECTRICAL_TIME_CONSTANT_S = 0.1

#: The parts of the cart, in the order they are shown.
CART_PARTS = ("sensing", "actuation", "transmission")


def is_ideal_cart(config: Any) -> bool:
    """True where every part of ``config``'s cart is ideal (today's plant)."""
    return all(getattr(config, name).is_ideal for name in CART_PARTS)


def cart_dict(config: Any) -> dict[str, dict[str, Any]]:
    """The parts of ``config``'s cart that are not ideal, each in its spec form (``part.to_dict()``), under
    the keys ``sensing``, ``actuation``, ``transmission``; {} for an ideal cart."""
    return {name: getattr(config, name).to_dict() for name in CART_PARTS if not getattr(config, name).is_ideal}


def cart_line(config: Any) -> str:
    """One line naming every part by its ``label()``: 'cart: sensing ...; actuation ...; transmission ...'."""
    return "cart: " + "; ".join(f"{name} {getattr(config, name).label()}" for name in CART_PARTS)


def smallest_encoder_ticks(*, side: str, rounding: str, gear_ratio: float, steering_range: float) -> int:
    """The fewest ticks per revolution whose error bound keeps the measured angle below pi/2 from the stops.

    The reading's error is at most e = c Delta with Delta = 2 pi / N at the axis (2 pi / (N i2) on the motor
    side) and c = 1/2 rounding, 1 truncation; |alpha| <= steering_range, so the measured angle stays below
    pi/2 iff e < pi/2 - steering_range, i.e. N > 2 pi c / (i2' (pi/2 - steering_range)).

    Args:
        side: 'axis' or 'motor'.
        rounding: 'round' or 'floor'.
        gear_ratio: i2 (> 0), used on the motor side.
        steering_range: rad, the stops' half-range (< pi/2).

    Returns:
        N_min >= 1.
    """
    c = 0.5 if rounding == "round" else 1.0
    i2 = gear_ratio if side == "motor" else 1.0
    return max(1, math.floor(2.0 * math.pi * c / (i2 * (0.5 * math.pi - steering_range))) + 1)


def check_cart(config: Any, parameters: Any) -> None:
    """Refuse a cart that cannot be built on the run's plant (module docstring), one line naming the culprit,
    the reason and what is accepted.

    Args:
        config: with ``sensing``, ``actuation``, ``transmission`` (typed parts) and ``duration`` (s).
        parameters: the plant's parameter set, with ``i2``, ``R_a`` (Ohm) and ``steering_range`` (rad).

    Raises:
        ParameterError: a delay not shorter than the run, an angle reading that can reach pi/2 within the stops,
            play wider than the stops, an electrical time constant above the limit.
    """
    sensing, actuation, transmission = config.sensing, config.actuation, config.transmission
    duration = float(config.duration)
    for part, delay, who in (("sensing", sensing.delay, "the law would read only the state at t = 0"),
                             ("actuation", actuation.delay, "the motor would receive no voltage of the law")):
        if delay >= duration:
            raise DurationError(f"{part}: delay = {delay:g} s is not shorter than the run (duration = {duration:g} "
                                 f"s): {who}; accepted: a delay below the duration")
    stops = float(parameters.steering_range)
    _check_reading(sensing, gear_ratio=float(parameters.i2), stops=stops)
    if transmission.backlash >= stops:
        raise ParameterError(f"transmission: backlash = {transmission.backlash:g} rad is not accepted: play of "
                             f"+-{transmission.backlash:g} rad is as wide as the steering's +-{stops:g} rad stops or "
                             f"wider (the gap 2b would span the whole travel between them), which cannot be; "
                             f"accepted: 0 <= backlash < {stops:g} rad (steering_range)")
    R_a = float(parameters.R_a)
    tau_e = actuation.inductance / R_a
    if tau_e > MAX_ELECTRICAL_TIME_CONSTANT_S:
        raise ParameterError(f"actuation: inductance = {actuation.inductance:g} H is not accepted: its electrical time "
                             f"constant L_a/R_a = {tau_e:.3g} s (R_a = {R_a:g} Ohm) exceeds "
                             f"{MAX_ELECTRICAL_TIME_CONSTANT_S:g} s, ten times the top of the range DC motor "
                             f"datasheets give (about 0.1-10 ms); accepted: inductance <= "
                             f"{MAX_ELECTRICAL_TIME_CONSTANT_S * R_a:g} H (R_a = {R_a:g} Ohm)")


def _check_reading(sensing: Any, *, gear_ratio: float, stops: float) -> None:
    """The angle reading's error bound below pi/2 - stops (:func:`smallest_encoder_ticks`), the encoder first."""
    margin = 0.5 * math.pi - stops
    encoder = sensing.encoder_bound(gear_ratio)
    if sensing.encoder_ticks is not None and encoder >= margin:
        n = smallest_encoder_ticks(side=sensing.encoder_side, rounding=sensing.encoder_rounding,
                                   gear_ratio=gear_ratio, steering_range=stops)
        half = "Delta/2" if sensing.encoder_rounding == "round" else "Delta"
        raise ParameterError(f"sensing: encoder_ticks = {sensing.encoder_ticks} is too coarse: its error {half} = "
                             f"{encoder:.3g} rad ({sensing.encoder_rounding}, on the {sensing.encoder_side} side) "
                             f"reaches pi/2 from the +-{stops:g} rad steering stops, where the laws and their "
                             f"claims divide by cos(alpha); accepted: encoder_ticks >= {n} (encoder_bits >= "
                             f"{math.ceil(math.log2(n))}) for this encoder")
    if sensing.noise_kind == "uniform" and encoder + sensing.noise >= margin:
        raise ParameterError(f"sensing: noise = uniform:{sensing.noise:g} rad is not accepted: with the encoder's "
                             f"{encoder:.3g} rad the reading's error reaches pi/2 from the +-{stops:g} rad steering "
                             f"stops, where the laws and their claims divide by cos(alpha); accepted: a bound "
                             f"below {margin - encoder:.4g} rad")
