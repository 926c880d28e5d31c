"""The cart as a run builds it, in one line and one mapping: what every summary (run, sweep, falsify,
compare, the certificate) shows of the run's sensing, actuation and transmission.

Usage::

    from wmr_mj.hardware.cart import cart_dict, cart_line

    cart_dict(config)    # {'sensing': {...}} : only the parts that are not ideal (an ideal cart: {})
    cart_line(config)    # 'cart: sensing encoder 4096/rev axis round, alpha' difference; actuation ideal; ...'

``config`` is anything with the attributes ``sensing``, ``actuation`` and ``transmission`` holding the typed
parts (a :class:`wmr_mj.sim.config.RunConfig`). A part that is ideal is left out of :func:`cart_dict`, as
``RunConfig.as_dict()`` leaves it out, so the JSON of a run on today's plant keeps the keys it always had.
"""

from __future__ import annotations

from typing import Any

__all__ = ["CART_PARTS", "cart_dict", "cart_line", "is_ideal_cart"]

#: The parts of the cart, in the order they are shown.
CART_PARTS = ("sensing", "actuation", "transmission")


def is_ideal_cart(config: Any) -> bool:
    """True where every part of ``config``'s cart is ideal (today's plant)."""
    return all(getattr(config, name).is_ideal for name in CART_PARTS)


def cart_dict(config: Any) -> dict[str, dict[str, Any]]:
    """The parts of ``config``'s cart that are not ideal, each in its spec form (``part.as_dict()``), under
    the keys ``sensing``, ``actuation``, ``transmission``; {} for an ideal cart."""
    return {name: getattr(config, name).as_dict() for name in CART_PARTS if not getattr(config, name).is_ideal}


def cart_line(config: Any) -> str:
    """One line naming every part by its ``label()``: 'cart: sensing ...; actuation ...; transmission ...'."""
    return "cart: " + "; ".join(f"{name} {getattr(config, name).label()}" for name in CART_PARTS)
