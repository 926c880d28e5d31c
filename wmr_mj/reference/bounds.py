"""Bounds on the desired steering trajectory alpha0(t): the quantities of the paper's (5.1).

:meth:`wmr_mj.reference.paths.Reference.bounds` measures them on a reference's grid; the
paper's region (:func:`wmr_mj.analysis.robustness.analyse`) and the certificate
(:func:`wmr_mj.analysis.certificate.certify`) read them.

Usage::

    from wmr_mj.reference.bounds import PAPER_BOUNDS, ReferenceBounds
    PAPER_BOUNDS.alpha_dot_max                       # 0.23 rad/s, the paper's (5.1)
    ReferenceBounds(alpha_ddot_max=0.155, alpha_dot_max=0.23, sin_cos3_max=0.98, alpha_max=0.659)
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from wmr_mj.errors import ParameterError

__all__ = ["ReferenceBounds", "PAPER_BOUNDS"]


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

    def as_dict(self) -> dict[str, float]:
        """JSON-ready: alpha_ddot_max, alpha_dot_max, sin_cos3_max (and alpha_max when known)."""
        out = dataclasses.asdict(self)
        if self.alpha_max is None:
            del out["alpha_max"]
        return out


#: The reference bounds of the paper's numerical example (5.1).
PAPER_BOUNDS = ReferenceBounds()
