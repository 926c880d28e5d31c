"""Argument checks shared by every layer: each raises ParameterError with a message that names the
argument, the value given and what is accepted, or returns the value as a float (or a pair).

Usage::

    from wmr_mj._util.checks import finite_number, interval

    k_band = finite_number("k_band", k_band, minimum=0.0)      # 'k_band = -1 is not accepted: ...'
    gyro_band = interval("gyro_band", gyro_band, positive=True)

The messages are part of the interface (tests match them); each function keeps the wording of the
module it came from.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any, cast

import numpy as np

from wmr_mj.errors import ParameterError

__all__ = [
    "runs_of",
    "real",
    "positive_real",
    "finite_number",
    "positive_number",
    "integer_at_least",
    "interval",
    "box_interval",
    "positive_range",
    "as_pair",
]


def real(name: str, value: object) -> float:
    """A finite real number (NumPy scalars accepted, bool refused), as a float."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(f"{name} must be a real number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise ParameterError(f"{name} = {value!r} is not accepted: it must be finite")
    return x


def positive_real(name: str, value: object, unit: str = "") -> float:
    """A finite real number > 0, as a float; ``unit`` follows the value in the message."""
    x = real(name, value)
    if x <= 0.0:
        raise ParameterError(f"{name} = {value!r}{unit} is not accepted: it must be finite and > 0")
    return x


def finite_number(name: str, value: Any, *, minimum: float | None = None, strict: bool = False) -> float:
    """Anything ``float()`` takes (bool refused), finite, >= ``minimum`` (> with ``strict``)."""
    if isinstance(value, bool):
        raise ParameterError(f"{name} must be a number, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ParameterError(f"{name} = {value!r} is not accepted: a finite number is required")
    if minimum is not None and (v < minimum or (strict and v == minimum)):
        need = ">" if strict else ">="
        raise ParameterError(f"{name} = {value!r} is not accepted: a finite number {need} {minimum:g} is required")
    return v


def positive_number(name: str, value: Any) -> None:
    """An int or float (bool refused), finite and > 0."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise ParameterError(f"{name} = {value!r} is not accepted; a finite number > 0 is required")


def integer_at_least(name: str, value: Any, minimum: int, what: str) -> None:
    """An int (bool refused) >= ``minimum``; ``what`` says what is accepted."""
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise ParameterError(f"{name} = {value!r} is not accepted; {what}")


def interval(name: str, value: Any, *, positive: bool = False) -> tuple[float, float]:
    """A pair (lo, hi) of finite numbers with lo <= hi (and lo > 0 with ``positive``)."""
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a pair (lo, hi) of numbers, got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi < lo:
        raise ParameterError(f"{name} = ({lo}, {hi}) is not accepted: finite lo <= hi is required")
    if positive and lo <= 0:
        raise ParameterError(f"{name} = ({lo}, {hi}) is not accepted: lo > 0 is required")
    return lo, hi


def box_interval(name: str, value: Any, *, allow_degenerate: bool, what: str) -> tuple[float, float]:
    """A pair (lo, hi) of finite numbers, lo < hi (lo <= hi with ``allow_degenerate``); ``what``
    names the kind of interval in the message."""
    try:
        lo, hi = value
        lo, hi = float(lo), float(hi)
    except (TypeError, ValueError):
        raise ParameterError(f"{what} {name} must be a pair (lo, hi) of numbers, got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ParameterError(f"{what} {name} = ({lo}, {hi}) is not finite; finite lo < hi is required")
    if hi < lo or (hi == lo and not allow_degenerate):
        need = "lo <= hi" if allow_degenerate else "lo < hi"
        raise ParameterError(f"{what} {name} = ({lo}, {hi}) is empty or inverted; {need} is required")
    return lo, hi


def positive_range(name: str, lo: float, hi: float) -> tuple[float, float]:
    """The range of a C80 parameter: finite, 0 < lo < hi."""
    lo, hi = float(lo), float(hi)
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ParameterError(f"range of {name} = ({lo}, {hi}) must be finite")
    if lo >= hi:
        raise ParameterError(f"range of {name} = ({lo}, {hi}) is empty or inverted; give LO < HI")
    if lo <= 0:
        raise ParameterError(f"range of {name} = ({lo}, {hi}) must be > 0 (every C80 parameter is positive)")
    return lo, hi


def as_pair(value: Iterable[float]) -> tuple[float, float]:
    """``tuple(value)`` typed as the (lo, hi) pair it is: a range the caller already checked (a
    RunConfig, the CLI's two-value options); no conversion and no check here."""
    return cast("tuple[float, float]", tuple(value))


def runs_of(d: Any, *, result: str, holds: str) -> Any:
    """``d["runs"]``: every run of a result's JSON, as ``result.to_dict()`` wrote it (``from_dict`` reads it back).

    Args:
        d: the JSON object; result: the result type's name ('SweepResult'); holds: what the command's own JSON,
            which has no runs, holds instead ('sweep --json and summary.json hold the summary only').

    Raises:
        ParameterError: ``d`` has no ``runs``, in one line naming what does.
    """
    runs = d.get("runs")
    if runs is None:
        raise ParameterError(f"this JSON has no 'runs' ({holds}): {result}.to_dict() writes every run, and "
                             "from_dict reads that back")
    return runs
