"""Named hardware presets, each in the spec form that :meth:`Sensing.from_spec` reads, with its source.

Usage::

    from wmr_mj.hardware import Sensing, sensing_preset_names, SENSING_PRESET_SOURCES

    sensing_preset_names()                       # ('ideal', 'magnetic-12bit-axis', ...)
    Sensing.from_spec("magnetic-12bit-axis")     # the preset
    Sensing.from_spec("preset=magnetic-12bit-axis,delay=0.005")   # the preset with a 5 ms delay
    quadrature_encoder_spec(1024)                # an incremental encoder of 1024 lines on the motor shaft

The presets are data (plain mappings), so this module imports nothing of the package: the parts build them.

Which velocity estimate each board uses: an absolute encoder read over SPI every control period gives an
angle, and the firmware differences it (Brown, Schneider & Mulligan, IEEE TIE 39(1), 1992: the "M" method
at a fixed period); at 14 bits and 1 ms the difference moves by 2 pi/16384/0.001 = 0.38 rad/s per tick, so
such boards low-pass it. Absolute encoders are mounted with their zero calibrated, which centres the tick:
rounding. An incremental counter changes at an edge and holds between edges: floor (Drake's
``RotaryEncoders`` model it so).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

__all__ = [
    "SENSING_PRESETS",
    "SENSING_PRESET_SOURCES",
    "ACTUATION_PRESETS",
    "ACTUATION_PRESET_SOURCES",
    "sensing_preset_names",
    "actuation_preset_names",
    "quadrature_encoder_spec",
]


def quadrature_encoder_spec(lines: int, *, velocity: str = "difference") -> dict[str, object]:
    """An incremental quadrature encoder of ``lines`` lines per revolution on the motor shaft, in spec form.

    Quadrature decoding counts both edges of both channels: 4 ``lines`` counts per motor revolution, so
    4 ``lines`` i2 per steering revolution. The ``lines`` check is the part's (``encoder_ticks >= 1``).
    """
    return {"encoder_ticks": 4 * lines, "encoder_side": "motor", "encoder_rounding": "floor", "velocity": velocity}


_SENSING: dict[str, tuple[dict[str, object], str]] = {
    "ideal": ({}, "today's plant: the simulator's exact alpha and alpha' at the control instant"),
    "magnetic-12bit-axis": (
        {"encoder_ticks": 4096, "encoder_side": "axis", "encoder_rounding": "round", "velocity": "difference"},
        "ams AS5045 datasheet: 12-bit absolute magnetic rotary encoder, 4096 positions per revolution "
        "(0.0879 deg); on the steering axis, alpha' a backward difference over the control period"),
    "magnetic-14bit-axis": (
        {"encoder_ticks": 16384, "encoder_side": "axis", "encoder_rounding": "round", "velocity": "filtered",
         "filter_tau": 0.002},
        "ams AS5047P datasheet: 14-bit absolute magnetic rotary encoder, 16384 positions per revolution "
        "(0.022 deg); on the steering axis, alpha' a backward difference through a 2 ms first-order low-pass "
        "(chosen: a tick moves the 1 ms difference by 0.38 rad/s)"),
    "incremental-500-motor": (
        quadrature_encoder_spec(500),
        "Broadcom HEDS-5540 datasheet: 500 counts (lines) per revolution, two channels in quadrature: "
        "2000 counts per motor revolution, 2000 i2 = 120000 per steering revolution at i2 = 60; "
        "alpha' a backward difference of the count"),
}

#: name -> spec mapping (keys of :meth:`Sensing.from_spec`).
SENSING_PRESETS: Mapping[str, Mapping[str, object]] = MappingProxyType({k: MappingProxyType(v[0])
                                                                         for k, v in _SENSING.items()})
#: name -> where its numbers come from.
SENSING_PRESET_SOURCES: Mapping[str, str] = MappingProxyType({k: v[1] for k, v in _SENSING.items()})

#: name -> spec mapping (keys of :meth:`Actuation.from_spec`).
ACTUATION_PRESETS: Mapping[str, Mapping[str, object]] = MappingProxyType({"ideal": MappingProxyType({})})
ACTUATION_PRESET_SOURCES: Mapping[str, str] = MappingProxyType(
    {"ideal": "today's plant: no actuation delay, no armature inductance, no current limit"})


def sensing_preset_names() -> tuple[str, ...]:
    """The sensing presets' names, 'ideal' first."""
    return tuple(_SENSING)


def actuation_preset_names() -> tuple[str, ...]:
    """The actuation presets' names."""
    return tuple(ACTUATION_PRESETS)
