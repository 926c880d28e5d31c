"""Deprecated (kept one release): :mod:`wmr_mj.hardware.assembly`, the cart's parts assembled. The module was
named ``cart`` beside the cart files' package :mod:`wmr_mj.carts`; each of its names warns here and is the same
object there (or ``wmr_mj.hardware.NAME``)."""

from __future__ import annotations

from wmr_mj._util.deprecation import deprecated_names
from wmr_mj.hardware import assembly as _assembly

__all__: list[str] = []

__getattr__ = deprecated_names(__name__, {name: (getattr(_assembly, name), f"use wmr_mj.hardware.assembly.{name}")
                                          for name in _assembly.__all__})
