"""The actuation chain between the law's voltage and the motor: a delay, the armature inductance, a current
limit. The part declares its model change (:meth:`Actuation.model_options`: MuJoCo's actuator ``delay`` and the
``dcmotor``'s inductance and saturation, which :mod:`wmr_mj.plant.mjcf` builds), its coverage
(:meth:`Actuation.coverage`: the delay the claims charge, the electrical time constant L_a/R_a that the
sampled-data certificate holds as a state of its loop (``docs/guides/certificates.md``, "The armature inductance in
the sampled loop"; the continuous claims have no current and stay uncovered); a current limit is in no claim's
motor model) and its label (:mod:`wmr_mj.hardware.coverage`).

Usage::

    from wmr_mj.hardware import Actuation

    a = Actuation.from_spec("delay=0.002,inductance=0.0005,current_limit=20")
    a.electrical_time_constant(R_a=1.0)        # L_a / R_a = 0.0005 s
    Actuation().is_ideal                       # True: today's plant
    a.model_options()                          # {'actuation_delay_s': 0.002, 'inductance_H': 0.0005, ...}
    a.coverage(R_a=1.0).electrical_time_constant   # 0.0005 s: held by the sampled-data certificate
    a.coverage(R_a=1.0).why_not                # ('the current limit (20 A) is not in the proof's motor model',)
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from wmr_mj.errors import ParameterError
from wmr_mj.hardware.coverage import Coverage, from_model_options
from wmr_mj.hardware.presets import ACTUATION_PRESETS
from wmr_mj.hardware.spec import SpecSource, field_converters, parse_spec, to_float, whole_periods

__all__ = ["Actuation"]


@dataclass(frozen=True, kw_only=True)
class Actuation:
    """Delay, armature inductance and current limit of the steering motor; the default is ideal.

    Raises:
        ParameterError: a negative delay or inductance, a current limit that is not > 0. The limits that need the
            plant and the run (L_a/R_a <= 0.1 s, a delay shorter than the run) are
            :func:`wmr_mj.hardware.assembly.check_cart`'s.
    """

    delay: float = 0.0  # s, from the law's output to the motor's terminals
    inductance: float = 0.0  # H, the armature inductance L_a (0: the current follows the voltage at once)
    current_limit: float | None = None  # A, |i_a| <= this; None: no limit

    def __post_init__(self) -> None:
        for name, unit in (("delay", "s"), ("inductance", "H")):
            value = to_float("actuation", name, getattr(self, name))
            if value < 0.0:
                raise ParameterError(f"actuation: {name} = {getattr(self, name)!r} {unit} is not accepted; "
                                     f"a value >= 0 {unit} is required")
            object.__setattr__(self, name, value)
        if self.current_limit is not None:
            limit = to_float("actuation", "current_limit", self.current_limit)
            if limit <= 0.0:
                raise ParameterError(f"actuation: current_limit = {self.current_limit!r} A is not accepted; a "
                                     "limit > 0 A or none is required")
            object.__setattr__(self, "current_limit", limit)

    @property
    def is_ideal(self) -> bool:
        """True for today's plant: no delay, no inductance, no current limit."""
        return self.delay == 0.0 and self.inductance == 0.0 and self.current_limit is None

    def on_motor(self, *, L_a: float) -> Actuation:
        """This actuation on a motor whose cart gives the armature inductance ``L_a`` (H, the cart file's
        ``motor.L_a``): the cart's inductance where this part sets none (0), else this part's (an inductance given,
        e.g. ``--actuation inductance=``, overrides the cart's; ``--param L_a=0`` removes the cart's).

        Raises:
            ParameterError: L_a negative or not finite.
        """
        if self.inductance > 0.0:
            return self
        inductance = to_float("actuation", "L_a", L_a)
        if inductance < 0.0:
            raise ParameterError(f"actuation: L_a = {L_a!r} H is not accepted; an inductance >= 0 H is required")
        return self if inductance == 0.0 else replace(self, inductance=inductance)

    def electrical_time_constant(self, R_a: float) -> float:
        """tau_e = L_a / R_a, s, for the armature resistance ``R_a`` (Ohm, > 0).

        Raises:
            ParameterError: R_a not > 0.
        """
        r = to_float("actuation", "R_a", R_a)
        if r <= 0.0:
            raise ParameterError(f"actuation: R_a = {R_a!r} Ohm is not accepted; a resistance > 0 is required")
        return self.inductance / r

    def delay_steps(self, timestep: float) -> int:
        """The delay as a whole number of ``timestep`` (s; MuJoCo's actuator delay reads its ring buffer by
        physics steps).

        Raises:
            ParameterError: a delay that is not a whole multiple of the step (the message names both).
        """
        return whole_periods("actuation delay", self.delay, timestep)

    def to_dict(self) -> dict[str, Any]:
        """The spec form (JSON-ready; :meth:`from_spec` reads it back)."""
        return {"delay": self.delay, "inductance": self.inductance, "current_limit": self.current_limit}

    def model_options(self) -> dict[str, Any]:
        """The keywords of :func:`wmr_mj.plant.mjcf.robot_spec` this part sets ({} where ideal: today's model):
        ``actuation_delay_s`` (s), ``inductance_H`` (H), ``current_limit_A`` (A or None)."""
        if self.is_ideal:
            return {}
        return {keyword: getattr(self, field) for field, keyword in MODEL_KEYWORDS.items()}

    @classmethod
    def from_model_options(cls, **options: Any) -> Actuation:
        """The part from :meth:`model_options`'s keywords (any of them; the rest ideal).

        Raises:
            ParameterError: a value refused, the message naming its keyword (``inductance_H = -1.0 ...``).
        """
        return from_model_options(cls, MODEL_KEYWORDS, options)

    def coverage(self, *, R_a: float) -> Coverage:
        """The delay the claims charge (s), the electrical time constant L_a/R_a (s, for the armature resistance
        ``R_a``, Ohm: bounded, held by the sampled-data certificate as the current's state; a claim without the
        current leaves it uncovered, :func:`wmr_mj.analysis.measurement.coverage_assumption_fields`), and what no
        claim's motor model has: a current limit (|i_a| <= I_max clips the torque the loop asks for; no bound of
        what the clipping does to E is derived).

        Raises:
            ParameterError: R_a not > 0 where an inductance is set.
        """
        why: list[str] = []
        tau_e = self.electrical_time_constant(R_a) if self.inductance > 0 else 0.0
        if self.current_limit is not None:
            why.append(f"the current limit ({self.current_limit:g} A) is not in the proof's motor model")
        return Coverage(delay=self.delay, electrical_time_constant=tau_e, why_not=tuple(why))

    def label(self) -> str:
        """One short line: 'ideal', or e.g. 'delay 2 ms, L_a 0.5 mH, current limit 20 A'."""
        if self.is_ideal:
            return "ideal"
        parts = []
        if self.delay:
            parts.append(f"delay {self.delay * 1e3:g} ms")
        if self.inductance:
            parts.append(f"L_a {self.inductance * 1e3:g} mH")
        if self.current_limit is not None:
            parts.append(f"current limit {self.current_limit:g} A")
        return ", ".join(parts)

    @classmethod
    def from_spec(cls, spec: SpecSource) -> Actuation:
        """An Actuation from ``"delay=...,inductance=...,current_limit=..."``, a mapping, a ``.json``/``.toml``
        file, a preset name ('ideal') or None (ideal).

        Raises:
            UnknownNameError: an unknown key or preset.
            ParameterError: a malformed value or a range refused.
        """
        presets = {name: parse_spec(dict(spec), cls, what="actuation", keys=_SPEC_KEYS)
                   for name, spec in ACTUATION_PRESETS.items()}
        return parse_spec(spec, cls, what="actuation", keys=_SPEC_KEYS, presets=presets)


_SPEC_KEYS = field_converters(Actuation)
#: Each field's keyword in the model's builders (:func:`wmr_mj.plant.mjcf.robot_spec`), with its unit.
MODEL_KEYWORDS = {"delay": "actuation_delay_s", "inductance": "inductance_H", "current_limit": "current_limit_A"}
