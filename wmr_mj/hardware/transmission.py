"""The steering gear's transmission: backlash (play) of half-width b, in rad at the steering axis. The typed
specification only; the model (two coaxial hinges, the second limited to +-b) reads it.

Usage::

    from wmr_mj.hardware import Transmission

    t = Transmission(backlash=0.002)           # +-2 mrad of play at the steering axis
    t = Transmission.from_spec("0.002")        # the CLI's --backlash RAD; also "backlash=0.002", a file
    Transmission().is_ideal                    # True: no play, today's plant
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from wmr_mj.errors import ParameterError
from wmr_mj.hardware.spec import SpecSource, field_converters, parse_spec, to_float

__all__ = ["Transmission"]


@dataclass(frozen=True, kw_only=True)
class Transmission:
    """The gear between the motor and the steering axis; the default has no play.

    Raises:
        ParameterError: a negative or non-finite backlash.
    """

    backlash: float = 0.0  # rad at the steering axis: the half-width b of the play (the gap is 2 b)

    def __post_init__(self) -> None:
        b = to_float("transmission", "backlash", self.backlash)
        if b < 0.0:
            raise ParameterError(f"transmission: backlash = {self.backlash!r} rad is not accepted; a half-width "
                                 ">= 0 rad is required")
        object.__setattr__(self, "backlash", b)

    @property
    def is_ideal(self) -> bool:
        """True without play (today's plant)."""
        return self.backlash == 0.0

    def as_dict(self) -> dict[str, Any]:
        """The spec form (JSON-ready)."""
        return {"backlash": self.backlash}

    def label(self) -> str:
        """One short line: 'ideal' or 'backlash +-2 mrad'."""
        return "ideal" if self.is_ideal else f"backlash +-{self.backlash * 1e3:g} mrad"

    @classmethod
    def from_spec(cls, spec: SpecSource | float) -> Transmission:
        """A Transmission from a number (rad, or a string of one: ``--backlash 0.002``), ``"backlash=..."``,
        a mapping, a ``.json``/``.toml`` file, or None (no play).

        Raises:
            UnknownNameError: an unknown key.
            ParameterError: a malformed value or a negative backlash.
        """
        if isinstance(spec, bool):
            raise ParameterError(f"transmission: backlash = {spec!r} is not a number; a half-width >= 0 rad is "
                                 "accepted")
        if isinstance(spec, (int, float)):
            return cls(backlash=float(spec))
        if isinstance(spec, str) and "=" not in spec and not spec.strip().lower().endswith((".json", ".toml")):
            return cls(backlash=to_float("transmission", "backlash", spec))
        return parse_spec(spec, cls, what="transmission", keys=_SPEC_KEYS)


_SPEC_KEYS = field_converters(Transmission)
