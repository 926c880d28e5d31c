"""What each part of the cart declares besides its spec: its change of the MuJoCo model, its coverage (the
error bound a claim may use, or why none is derived) and its label.

Every part (:class:`~wmr_mj.hardware.sensing.Sensing`, :class:`~wmr_mj.hardware.actuation.Actuation`,
:class:`~wmr_mj.hardware.transmission.Transmission`) offers the same three things, so the model
(:mod:`wmr_mj.plant.mjcf`), the engine (:func:`wmr_mj.sim.engine.plant_options`) and the claims
(:func:`wmr_mj.sim.certify.measurement_errors_of`) read them from the part, and nothing restates them:

- ``part.model_options()``: the keywords of :func:`wmr_mj.plant.mjcf.robot_spec` the part sets ({} where it
  changes nothing of today's model); ``Part.from_model_options(**keywords)`` reads them back (the model's
  builders validate their keywords through the part, naming the keyword);
- ``part.coverage(...)``: a :class:`Coverage`;
- ``part.label()``: one short line.

Usage::

    from wmr_mj.hardware import Actuation, Coverage

    a = Actuation(delay=0.002)
    a.model_options()                  # {'actuation_delay_s': 0.002, 'inductance_H': 0.0, 'current_limit_A': None}
    a.coverage(R_a=1.0)                # Coverage(delay=0.002): a delay the claims charge, covered
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, TypeVar

from wmr_mj.errors import ParameterError

__all__ = ["Coverage", "from_model_options"]

T = TypeVar("T")


@dataclass(frozen=True, kw_only=True)
class Coverage:
    """What one part adds to the errors a claim may assume (:class:`wmr_mj.analysis.measurement.MeasurementErrors`
    is their sum over the cart), or why no bound is derived.

    With alpha_d(t) = alpha(t - delay) the delayed truth, at every control step:
    |alpha_m - alpha_d| <= ``alpha_error`` and |alpha_m' - alpha_d'| <= ``alpha_dot_error`` plus ``lag``
    sup|alpha''| (the lag is charged as a delay, beside ``delay``).
    """

    alpha_error: float = 0.0  # rad, on what the law reads of alpha
    alpha_dot_error: float = 0.0  # rad/s, on what it reads of alpha'
    delay: float = 0.0  # s, between the state and the voltage it produces
    lag: float = 0.0  # s, a velocity estimate's lag (times sup|alpha''|)
    electrical_time_constant: float = 0.0  # s, L_a/R_a: the current's lag, held by the sampled-data certificate alone
    why_not: tuple[str, ...] = ()  # what has no derived bound, one sentence each; () where covered

    @property
    def covered(self) -> bool:
        """True where every error of the part has a derived bound."""
        return not self.why_not


def from_model_options(cls: type[T], keywords: Mapping[str, str], options: Mapping[str, Any]) -> T:
    """A part from the model builders' keywords: ``keywords`` maps each field of ``cls`` to its keyword
    (:meth:`model_options`'s names), ``options`` holds some of those keywords.

    Raises:
        ParameterError: an unknown keyword, or a value the part refuses; the message names the keyword.
    """
    by_keyword = {keyword: field for field, keyword in keywords.items()}
    unknown = sorted(set(options) - set(by_keyword))
    if unknown:
        raise ParameterError(f"{cls.__name__}: unknown model option(s) {', '.join(unknown)}; accepted: "
                             f"{', '.join(by_keyword)}")
    fields = {by_keyword[keyword]: value for keyword, value in options.items()}
    for field, value in fields.items():  # each alone: the message names the keyword that is refused
        try:
            cls(**{field: value})
        except ParameterError as exc:
            raise ParameterError(f"{keywords[field]} = {value!r} is not accepted ({exc})") from None
    return cls(**fields)
