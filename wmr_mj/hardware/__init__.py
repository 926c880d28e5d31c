"""The cart as it is built: sensing, actuation and transmission as typed parts, each tested alone.

Pure Python and NumPy; imports nothing of wmr_mj but :mod:`wmr_mj.errors`, so every layer above may use it.

Usage::

    from wmr_mj.hardware import Sensing, SensingChain, Actuation, Transmission, measurement_error_bounds

    sensing = Sensing.from_spec("magnetic-12bit-axis")          # or "encoder_ticks=4096,velocity=difference"
    chain = SensingChain(sensing, control_period=0.001, n_steps=35_000, gear_ratio=60.0)
    alpha_m, alpha_dot_m = chain.step(0, alpha, alpha_dot, motor_angle)
    measurement_error_bounds(sensing, control_period=0.001, gear_ratio=60.0)

Each part declares, in its one class, its model change (``model_options()``: what :mod:`wmr_mj.plant.mjcf`
builds), its coverage (``coverage(...)``: a :class:`Coverage`, the error bound a claim may use or why none is
derived) and its ``label()``; the model, the engine and the claims read them there (:mod:`.coverage`).

Modules: :mod:`.spec` (the one parser, the whole-periods check), :mod:`.coverage`, :mod:`.sensing`,
:mod:`.estimators` (the velocity estimates and the delay as discrete linear systems), :mod:`.actuation`,
:mod:`.transmission`, :mod:`.presets` (named hardware with sources), :mod:`.assembly` (the three parts together:
one line, one mapping, the checks against the plant; the cart *file* is :mod:`wmr_mj.carts`'s).
"""

from __future__ import annotations

from wmr_mj.hardware.actuation import Actuation
from wmr_mj.hardware.assembly import CART_PARTS, cart_dict, cart_line, check_cart, is_ideal_cart
from wmr_mj.hardware.coverage import Coverage
from wmr_mj.hardware.presets import (
    SENSING_PRESET_SOURCES,
    actuation_preset_names,
    quadrature_encoder_spec,
    sensing_preset_names,
)
from wmr_mj.hardware.sensing import (
    SENSING_SPEC_KEYS,
    MeasurementBounds,
    Sensing,
    SensingChain,
    measurement_error_bounds,
    sensing_preset,
)
from wmr_mj.hardware.spec import parse_spec, whole_periods
from wmr_mj.hardware.transmission import Transmission

__all__ = [
    "Sensing",
    "SensingChain",
    "MeasurementBounds",
    "measurement_error_bounds",
    "SENSING_SPEC_KEYS",
    "sensing_preset",
    "sensing_preset_names",
    "SENSING_PRESET_SOURCES",
    "quadrature_encoder_spec",
    "Actuation",
    "actuation_preset_names",
    "Transmission",
    "Coverage",
    "parse_spec",
    "whole_periods",
    "CART_PARTS",
    "cart_dict",
    "cart_line",
    "is_ideal_cart",
    "check_cart",
]
