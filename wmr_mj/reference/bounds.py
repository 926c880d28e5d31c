"""Bounds on the desired steering trajectory alpha0(t): the quantities of the paper's (5.1).

:meth:`wmr_mj.reference.paths.Reference.bounds` measures them on a reference's grid; the
paper's region (:func:`wmr_mj.analysis.robustness.analyse`) and the certificate
(:func:`wmr_mj.analysis.certificate.certify`) read them.

The two angle bounds say the same thing twice: sin(a)/cos^3(a) = tan(a)(1 + tan^2(a)) rises
monotonically on [0, pi/2), so a bound on it is a bound on |alpha0|.
:attr:`ReferenceBounds.angle_max` is the largest |alpha0| both allow;
:func:`reference_bounds_from` reads bounds from a word, a mapping or ``key=value`` text and
makes the two agree.

Usage::

    from wmr_mj.reference.bounds import PAPER_BOUNDS, ReferenceBounds, reference_bounds_from
    PAPER_BOUNDS.alpha_dot_max                       # 0.23 rad/s, the paper's (5.1)
    PAPER_BOUNDS.angle_max                           # 0.6596 rad: sin/cos^3 = 1.24 inverted
    ReferenceBounds(alpha_ddot_max=0.155, alpha_dot_max=0.23, sin_cos3_max=0.98, alpha_max=0.659)
    reference_bounds_from("paper")                   # PAPER_BOUNDS with alpha_max = 0.6596 rad
    reference_bounds_from("alpha_dot_max=0.3,alpha_max=0.5")   # the rest from PAPER_BOUNDS
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from wmr_mj.errors import ParameterError

__all__ = ["ReferenceBounds", "PAPER_BOUNDS", "angle_of_sin_cos3", "sin_cos3", "sin_cos3_of_samples",
           "reference_bounds_from"]


def sin_cos3(angle: float) -> float:
    """S(a) = sin(a)/cos^3(a) of an angle |a| < pi/2 [rad] (the stiffness's shape in (2.13), the paper's (5.1)
    quantity) [-]; its one scalar definition: the certificates (small_gain, sampled_certificate) call it."""
    return math.sin(angle) / math.cos(angle) ** 3


def sin_cos3_of_samples(angles: np.ndarray) -> np.ndarray:
    """S(a) of each of ``angles`` [rad], shape kept: :func:`sin_cos3` on NumPy's sin and cos (a path's
    samples; NumPy's and libm's sin may differ in the last bit, so the scalar stays libm's)."""
    return np.sin(angles) / np.cos(angles) ** 3


def angle_of_sin_cos3(value: float) -> float:
    """The angle a in [0, pi/2) [rad] with sin(a)/cos^3(a) = ``value`` (>= 0).

    sin/cos^3 = t (1 + t^2) with t = tan(a): the one real root of t^3 + t - value = 0
    (Cardano, written as u - 1/(3u) to avoid cancellation, then one Newton step).
    """
    c = float(value)
    if not math.isfinite(c) or c < 0.0:
        raise ParameterError(f"sin_cos3_max = {value!r} is not accepted: a finite number >= 0 is required")
    u = (0.5 * c + math.sqrt(0.25 * c * c + 1.0 / 27.0)) ** (1.0 / 3.0)
    t = u - 1.0 / (3.0 * u)
    t -= (t * t * t + t - c) / (3.0 * t * t + 1.0)
    return math.atan(t)


@dataclass(frozen=True)
class ReferenceBounds:
    """Bounds on the desired trajectory alpha0, the paper's (5.1); each a finite number >= 0.

    Attributes:
        alpha_ddot_max: max |alpha0''| [rad/s^2].
        alpha_dot_max: max |alpha0'| [rad/s].
        sin_cos3_max: max |sin(alpha0)/cos^3(alpha0)| [-].
        alpha_max: max |alpha0| [rad]; None where it is not known (the paper's (5.1) gives
            none; the certificate needs it).

    Raises:
        ParameterError: a bound that is not a finite number >= 0.
    """

    alpha_ddot_max: float = 0.4
    alpha_dot_max: float = 0.23
    sin_cos3_max: float = 1.24
    alpha_max: float | None = None

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is None and f.name == "alpha_max":
                continue
            try:
                v = float(value)
            except (TypeError, ValueError):
                raise ParameterError(f"reference bound {f.name} must be a number, got {value!r}") from None
            if not math.isfinite(v) or v < 0.0:
                raise ParameterError(
                    f"reference bound {f.name} = {value!r} is not accepted: a finite number >= 0 is required"
                )
            object.__setattr__(self, f.name, v)

    @property
    def angle_max(self) -> float:
        """The largest |alpha0| [rad] these bounds allow: alpha_max where given, capped by the angle
        whose sin/cos^3 is sin_cos3_max (both are bounds; they agree when made by
        :func:`reference_bounds_from`)."""
        a = angle_of_sin_cos3(self.sin_cos3_max)
        return a if self.alpha_max is None else min(self.alpha_max, a)

    def to_dict(self) -> dict[str, float]:
        """JSON-ready: alpha_ddot_max, alpha_dot_max, sin_cos3_max (and alpha_max when known)."""
        out = dataclasses.asdict(self)
        if self.alpha_max is None:
            del out["alpha_max"]
        return out


#: The reference bounds of the paper's numerical example (5.1).
PAPER_BOUNDS = ReferenceBounds()

_KEYS = tuple(f.name for f in dataclasses.fields(ReferenceBounds))
_ACCEPTED = f"'paper', a ReferenceBounds, a mapping or text 'key=value,...' with keys {', '.join(_KEYS)}"
_AGREE_RTOL = 1e-9  # how closely a given alpha_max and sin_cos3_max must agree


def reference_bounds_from(value: Any) -> ReferenceBounds | None:
    """Reference bounds from what a user or a config gives.

    Args:
        value: None (gives None); a :class:`ReferenceBounds` (returned as it is); the word
            ``"paper"`` (:data:`PAPER_BOUNDS` with alpha_max filled in from sin_cos3_max,
            0.6596 rad); a mapping or text ``"alpha_dot_max=0.23,alpha_ddot_max=0.4,alpha_max=0.6"``
            with keys alpha_ddot_max [rad/s^2], alpha_dot_max [rad/s], sin_cos3_max [-],
            alpha_max [rad]. Missing keys take PAPER_BOUNDS' values; the angle bounds are made
            to agree: alpha_max alone sets sin_cos3_max = sin/cos^3(alpha_max), sin_cos3_max (or
            neither) sets alpha_max to its angle, both must agree within 1e-9 relative.

    Returns:
        ReferenceBounds | None: the bounds (alpha_max always filled in), or None for None.

    Raises:
        ParameterError: an unknown word or key, a repeated key, a value that is not a finite
            number >= 0, alpha_max >= pi/2, or alpha_max and sin_cos3_max that disagree; the
            one-line message names the culprit and lists what is accepted.
    """
    if value is None or isinstance(value, ReferenceBounds):
        return value
    if isinstance(value, str):
        text = value.strip()
        if text.lower() == "paper":
            return _agreeing({})
        return _agreeing(_parse_text(text))
    if isinstance(value, Mapping):
        given = dict(value)
        unknown = [k for k in given if k not in _KEYS]
        if unknown:
            raise ParameterError(f"reference bounds: unknown key {unknown[0]!r}; accepted: {_ACCEPTED}")
        return _agreeing({k: _bound_value(k, v) for k, v in given.items() if v is not None})
    raise ParameterError(f"reference bounds {value!r} are not accepted: give {_ACCEPTED}")


def _parse_text(text: str) -> dict[str, float]:
    """key=value pairs of ``text``, checked: {key: value}."""
    out: dict[str, float] = {}
    for item in text.split(","):
        key, sep, raw = (part.strip() for part in item.partition("="))
        if not sep or not key:
            raise ParameterError(f"reference bounds {text!r}: {item.strip()!r} is not accepted; "
                                 f"give {_ACCEPTED}")
        if key not in _KEYS:
            raise ParameterError(f"reference bounds {text!r}: unknown key {key!r}; accepted: {_ACCEPTED}")
        if key in out:
            raise ParameterError(f"reference bounds {text!r}: key {key!r} is given twice")
        out[key] = _bound_value(key, raw)
    return out


def _bound_value(key: str, raw: Any) -> float:
    """One bound's value: a finite number >= 0 (alpha_max below pi/2)."""
    try:
        v = float(raw) if not isinstance(raw, bool) else math.nan
    except (TypeError, ValueError):
        v = math.nan
    if not math.isfinite(v) or v < 0.0:
        raise ParameterError(f"reference bound {key} = {raw!r} is not accepted: a finite number >= 0 is required "
                             f"(keys: {', '.join(_KEYS)})")
    if key == "alpha_max" and v >= 0.5 * math.pi:
        raise ParameterError(f"reference bound alpha_max = {raw!r} rad is not accepted: it must be below pi/2 "
                             f"(keys: {', '.join(_KEYS)})")
    return v


def _agreeing(given: dict[str, float]) -> ReferenceBounds:
    """ReferenceBounds from checked values, the rest from PAPER_BOUNDS, alpha_max and sin_cos3_max agreeing."""
    a, c = given.get("alpha_max"), given.get("sin_cos3_max")
    if a is None:
        c = PAPER_BOUNDS.sin_cos3_max if c is None else c
        a = angle_of_sin_cos3(c)
    elif c is None:
        c = sin_cos3(a)
    elif abs(sin_cos3(a) - c) > _AGREE_RTOL * max(abs(c), 1e-300):
        raise ParameterError(
            f"reference bounds disagree: alpha_max = {a!r} rad has sin/cos^3 = {sin_cos3(a)!r}, but "
            f"sin_cos3_max = {c!r}; give one of them (or both agreeing within {_AGREE_RTOL:g} relative)"
        )
    return ReferenceBounds(
        alpha_ddot_max=given.get("alpha_ddot_max", PAPER_BOUNDS.alpha_ddot_max),
        alpha_dot_max=given.get("alpha_dot_max", PAPER_BOUNDS.alpha_dot_max),
        sin_cos3_max=c, alpha_max=a,
    )
