"""Cart files: a front-steered cart written down as a whole, in TOML, checked against a JSON Schema.

``c80.toml`` here is the C80, the one source of :mod:`wmr_mj.params`; ``cart.schema.json`` states every key,
unit and accepted range. ``wmr-mj cart check FILE|NAME`` compiles, steps and identifies a cart.

Usage::

    from wmr_mj.carts import load_cart, cart_names

    cart_names()                          # ('c80', 'c80-magmotor')
    cart = load_cart("mine.toml")         # one line and ParameterError for a wrong file
"""

from wmr_mj.carts.cartfile import (
    CARTS_DIR,
    DEFAULT_KEYS,
    PARAMETER_SECTIONS,
    CartFile,
    cart_names,
    cart_of,
    cart_of_text,
    cart_path,
    load_cart,
    load_cart_text,
)
from wmr_mj.carts.schema import SCHEMA_PATH, load_schema

__all__ = ["CARTS_DIR", "CartFile", "DEFAULT_KEYS", "PARAMETER_SECTIONS", "SCHEMA_PATH", "cart_names", "cart_of",
           "cart_of_text", "cart_path",
           "load_cart", "load_cart_text", "load_schema"]
