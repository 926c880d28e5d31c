"""The steering gear's transmission: backlash (play) of half-width b, in rad at the steering axis. The part
declares its model change (:meth:`Transmission.model_options`: two coaxial hinges, the tendon between them
limited to +-b, which :mod:`wmr_mj.plant.mjcf` builds), its coverage (:meth:`Transmission.coverage`: none, with
the reason) and its label (:mod:`wmr_mj.hardware.coverage`).

No bound is derived for the play. With the encoder on the steering axis the play lies between the motor and
the measured angle, on the actuator's side. With the encoder on the motor side a rigid stop would keep the
motor angle / i2 within b of alpha, but the model's stop is MuJoCo's soft limit, pressed in under torque,
and its penetration has no bound derived (docs/guides/hardware.md, "The play's stop": 0.526 to 0.552 mrad
past b measured in issue 35's break).

Usage::

    from wmr_mj.hardware import Transmission

    t = Transmission(backlash=0.002)           # +-2 mrad of play at the steering axis
    t = Transmission.from_spec("0.002")        # the CLI's --backlash RAD; also "backlash=0.002", a file
    Transmission().is_ideal                    # True: no play, today's plant
    t.model_options()                          # {'backlash_rad': 0.002}
    t.coverage(encoder_on_motor=True).why_not  # ("the play's stop is soft: its penetration is not bounded ...",)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from wmr_mj.errors import ParameterError
from wmr_mj.hardware.coverage import Coverage, from_model_options
from wmr_mj.hardware.spec import SpecSource, field_converters, parse_spec, to_float

__all__ = ["Transmission"]


@dataclass(frozen=True, kw_only=True)
class Transmission:
    """The gear between the motor and the steering axis; the default has no play.

    Raises:
        ParameterError: a negative or non-finite backlash. Play as wide as the steering stops or wider is refused
            where the plant is known (:func:`wmr_mj.hardware.assembly.check_cart`).
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

    def to_dict(self) -> dict[str, Any]:
        """The spec form (JSON-ready)."""
        return {"backlash": self.backlash}

    def model_options(self) -> dict[str, Any]:
        """The keyword of :func:`wmr_mj.plant.mjcf.robot_spec` this part sets: ``backlash_rad`` (rad at the
        steering axis); {} without play (today's model)."""
        return {} if self.is_ideal else {MODEL_KEYWORDS["backlash"]: self.backlash}

    @classmethod
    def from_model_options(cls, **options: Any) -> Transmission:
        """The part from :meth:`model_options`'s keyword.

        Raises:
            ParameterError: a value refused, the message naming ``backlash_rad``.
        """
        return from_model_options(cls, MODEL_KEYWORDS, options)

    def coverage(self, *, encoder_on_motor: bool) -> Coverage:
        """Not covered where there is play (module docstring), saying why; ``alpha_error`` is what a rigid stop
        would add to an encoder on the motor side (b; 0 on the axis), which the sensing's bounds carry.

        Args:
            encoder_on_motor: True where the sensor reads the motor shaft, through an encoder or exactly
                (:attr:`Sensing.reads_motor_side <wmr_mj.hardware.sensing.Sensing.reads_motor_side>`; the play then
                lies between the measured angle and alpha).
        """
        if self.is_ideal:
            return Coverage()
        b = self.backlash
        if not encoder_on_motor:
            why = (f"the gear's play (b = {b:g} rad) lies between the motor and an encoder on the steering axis: "
                   "no bound is derived for play on the actuator's side")
        else:
            why = (f"the play's stop is soft: its penetration is not bounded (b = {b:g} rad; MuJoCo's limit on the "
                   "gear_play tendon is pressed in under torque, so the motor angle / i2 can lie more than b from "
                   "alpha)")
        return Coverage(alpha_error=b if encoder_on_motor else 0.0, why_not=(why,))

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
#: The field's keyword in the model's builders (:func:`wmr_mj.plant.mjcf.robot_spec`).
MODEL_KEYWORDS = {"backlash": "backlash_rad"}
