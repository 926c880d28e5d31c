"""A law's sampled-data certificate beside its continuous claim: the cart it is computed on, and the pair judged.

On every cart the run's parts describe (``ClaimContext.wants_sampled_data``, the ideal cart included), the
computed-torque, PD and sliding-mode laws compute, beside their continuous claim (section 4's, the boundary
layer), the sampled-data certificate of their loop on the cart's own parts
(:mod:`wmr_mj.analysis.sampled_certificate`, :mod:`wmr_mj.analysis.sliding_sampled`), and claim it, the
continuous one recorded beside it as a second opinion (:func:`wmr_mj.analysis.claim.best_certificate`: a
sampled law is never certified by a bound that assumes sampling away). A subclass inherits its parent's pair
with its :meth:`~controllers.base.SteeringController.claim`.

Usage::

    from controllers.sampled_claim import with_sampled_data
    def claim(self, context):
        own = ...                                          # the continuous claim
        return with_sampled_data(own, "section-4", context,
                                 lambda cart: sampled_certificate(..., cart=cart))
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from wmr_mj.analysis.claim import SAMPLED_DATA_NAME, ClaimContext, best_certificate, covers_measurement
from wmr_mj.analysis.claim_types import Certificate
from wmr_mj.analysis.delay_split import delay_splits, worst_over_splits
from wmr_mj.analysis.sampled_certificate import SampledCart
from wmr_mj.errors import ParameterError

__all__ = ["MAX_SAMPLED_DELAY_PERIODS", "sampled_cart", "with_sampled_data", "over_delay_splits", "named"]

#: the longest delay, in control periods (sensing plus actuation), for which the sampled-data certificate is computed:
#: its loop carries one state per period of delay, so a delay of seconds at a 1 ms period would cost minutes; far
#: beyond the delay margin of any gains the designs use (64 periods for K_P = 100, K_D = 20 at 1 ms). A longer
#: delay leaves the continuous claim alone, uncertified (the assumption 'sampling bounded' unmet).
MAX_SAMPLED_DELAY_PERIODS = 256


def sampled_cart(context: ClaimContext) -> SampledCart:
    """The run's cart as the sampled-data certificate takes it (:meth:`SampledCart.of`): the sensing, the control
    period, the gear ratio, the play where the encoder reads the motor side, the actuation delay, the coverage.

    Raises:
        ParameterError: a delay that is not a whole number of control periods, or one longer than
            :data:`MAX_SAMPLED_DELAY_PERIODS`.
    """
    sensing = context.sensing
    play = context.play if sensing.reads_motor_side else 0.0
    assert context.gear_ratio is not None  # ClaimContext sets it (the estimate's i2 where none is given)
    cart = SampledCart.of(sensing, control_period=context.control_period, gear_ratio=context.gear_ratio, play=play,
                          actuation_delay_s=context.actuation_delay, measurement=context.measurement)
    delay_periods = cart.sensing_delay + cart.actuation_delay
    if delay_periods > MAX_SAMPLED_DELAY_PERIODS:  # a state per period of delay: its matrices grow as d^2
        raise ParameterError(f"not computed: a delay of {delay_periods} control periods is beyond the "
                             f"{MAX_SAMPLED_DELAY_PERIODS} the sampled-data certificate evaluates")
    return cart


def named(cert: Certificate, analysis: str) -> Certificate:
    """``cert`` with the name of the analysis that gave it (:attr:`Certificate.analysis`)."""
    return dataclasses.replace(cert, analysis=analysis)


def with_sampled_data(own: Certificate, own_name: str, context: ClaimContext,
                      sampled: Callable[[SampledCart], Certificate]) -> Certificate:
    """The law's claim: ``own`` (named ``own_name``) alone where the run asks for no sampled-data analysis (a
    what-if measurement the cart's parts do not describe), else ``sampled(cart)`` with ``own`` beside it
    (:func:`wmr_mj.analysis.claim.best_certificate`; ``own`` with the assumption 'sampling bounded' unmet and
    the reason where the cart cannot be evaluated; over every split of the delay where the context's ``delay_split`` is
    'unknown': :func:`over_delay_splits`).

    Args:
        own: the law's continuous claim. own_name: its name ('section-4', 'boundary-layer').
        context: the run's (:class:`~wmr_mj.analysis.claim.ClaimContext`).
        sampled: the sampled-data certificate of the law's loop on a cart (:func:`sampled_cart`).
    """
    own = named(own, own_name)
    if not context.wants_sampled_data:
        return own
    own = covers_measurement(own, context.measurement)
    try:
        cart = sampled_cart(context)
        total = cart.sensing_delay + cart.actuation_delay
        if context.delay_split == "unknown" and total:  # only the sum is measured: every split, the worst claimed
            cert = over_delay_splits(cart, context, sampled)
        else:
            cert = sampled(cart)
    except ParameterError as exc:  # e.g. an actuation delay that is not a whole number of control periods
        return best_certificate(own, own_name, str(exc))
    return best_certificate(own, own_name, named(cert, SAMPLED_DATA_NAME))


def over_delay_splits(cart: SampledCart, context: ClaimContext,
                      sampled: Callable[[SampledCart], Certificate]) -> Certificate:
    """``sampled`` on every split (d_s, d_a) of the cart's whole delay d_s + d_a, the worst claimed
    (:func:`wmr_mj.analysis.delay_split.worst_over_splits`): each split is the cart with its sensing delay d_s and
    its actuation delay d_a, all else as it is; the run simulates the cart's own split."""
    total = cart.sensing_delay + cart.actuation_delay
    certificates = {(d_s, d_a): sampled(dataclasses.replace(cart, sensing_delay=d_s, actuation_delay=d_a))
                    for d_s, d_a in delay_splits(total)}
    return worst_over_splits(certificates, control_period=context.control_period,
                             simulated=(cart.sensing_delay, cart.actuation_delay))
