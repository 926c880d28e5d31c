"""The sensing's error model checked on the run: what the law read against the truth, against the bound its
claim assumed.

A claim on a sensed cart takes the bounds of :func:`wmr_mj.sim.certify.measurement_errors_of` as given
(|alpha_m - alpha_d| <= e_alpha, and for an exact or tachometer velocity |alpha_m' - alpha_d'| <= e_alpha',
alpha_d the true state ``delay`` earlier). Where that model is wrong (a part's bound too small, a model
effect no bound names), the claim would certify a region the run can leave. So every sensed run measures
the largest error of what the law read and adds it to the claim as the measured assumption
:data:`MEASURED_ERRORS`: a wrong error model makes the run uncertified, never certified-outside.

Usage::

    from wmr_mj.sim.measured_errors import with_measured_errors
    certificate = with_measured_errors(certificate, sensing=parts.sensing, measurement=parts.measurement,
                                       rows=rows, period=parts.period)

A run whose law reads the true state (ideal sensing: no ``alpha_measured`` rows) gains nothing: its error
is 0 by construction, and its JSON keeps the keys it had.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from wmr_mj.analysis.certificate import Assumption, Certificate
from wmr_mj.analysis.claim import with_measured
from wmr_mj.analysis.measurement import MeasurementErrors
from wmr_mj.hardware import Sensing

__all__ = ["MEASURED_ERRORS", "measured_errors", "with_measured_errors"]

#: Name of the measured assumption "what the law read stayed within the bounds its claim assumed".
MEASURED_ERRORS = "measured errors within the assumed bounds"

# The error alpha_m - alpha is formed in doubles: the noise's add and this subtraction each round by at
# most half an ulp of the angle (<= max|alpha| 2**-53); 4 ulp of the largest angle is a slack above both.
_ULP_SLACK = 4.0 * 2.0 ** -52


def _delayed(x: np.ndarray, d: int) -> np.ndarray:
    """x[k - d] at step k; x[0] before d steps have passed (the sensing chain's ring starts full of x[0])."""
    if d == 0:
        return x
    return np.concatenate((np.full(min(d, x.size), x[0]), x[:max(x.size - d, 0)]))


def measured_errors(rows: Any, *, delay_steps: int) -> tuple[float, float]:
    """(max|alpha_m[k] - alpha[k - d]| rad, max|alpha_m'[k] - alpha'[k - d]| rad/s) over a sensed run's rows.

    Args:
        rows: the run's rows with ``alpha``, ``alpha_dot`` (the true state at each control step) and
            ``alpha_measured``, ``alpha_dot_measured`` (what the law read there).
        delay_steps: d, the sensing delay in control periods (the truth the reading stands for is d steps old).

    Returns:
        The two largest errors; (0, 0) for an empty run.
    """
    alpha = np.asarray(rows["alpha"], dtype=float)
    if alpha.size == 0:
        return 0.0, 0.0
    alpha_dot = np.asarray(rows["alpha_dot"], dtype=float)
    e_alpha = np.asarray(rows["alpha_measured"], dtype=float) - _delayed(alpha, delay_steps)
    e_alpha_dot = np.asarray(rows["alpha_dot_measured"], dtype=float) - _delayed(alpha_dot, delay_steps)
    return float(np.max(np.abs(e_alpha))), float(np.max(np.abs(e_alpha_dot)))


def measured_errors_assumption(rows: Any, measurement: MeasurementErrors, *, delay_steps: int,
                               velocity_bounded: bool) -> Assumption:
    """The measured assumption :data:`MEASURED_ERRORS` of a sensed run.

    Args:
        rows: as :func:`measured_errors`.
        measurement: the bounds the claim assumed (its ``alpha_error_max`` rad, ``alpha_dot_error_max`` rad/s).
        delay_steps: d, as :func:`measured_errors`.
        velocity_bounded: True where ``alpha_dot_error_max`` bounds the velocity's error alone (an exact or
            tachometer velocity); a differenced or filtered velocity's bound holds only with its lag, charged
            as a delay, so its error is shown but not checked.

    Returns:
        met where every checked error is within its bound plus 4 ulp of the largest angle or rate (the
        rounding of forming the error); value: the largest ratio of a measured error to its bound.
    """
    e_alpha, e_alpha_dot = measured_errors(rows, delay_steps=delay_steps)
    scale_alpha = float(np.max(np.abs(np.asarray(rows["alpha"], dtype=float)), initial=0.0))
    scale_dot = float(np.max(np.abs(np.asarray(rows["alpha_dot"], dtype=float)), initial=0.0))
    checks = [("max|alpha_m - alpha|", e_alpha, measurement.alpha_error_max, scale_alpha * _ULP_SLACK, "rad")]
    if velocity_bounded:
        checks.append(("max|alpha_m' - alpha'|", e_alpha_dot, measurement.alpha_dot_error_max,
                       scale_dot * _ULP_SLACK, "rad/s"))
    met = all(error <= bound + slack for _, error, bound, slack, _ in checks)
    ratios = [(error / bound if bound > 0 else (0.0 if error <= slack else np.inf), label, error, bound, unit)
              for label, error, bound, slack, unit in checks]
    worst, label, error, bound, unit = max(ratios, key=lambda r: r[0])
    shown = ", ".join(f"{lab} = {err:.6g} {u} against {bnd:.6g}" for lab, err, bnd, _, u in checks)
    if not velocity_bounded:
        shown += (f"; max|alpha_m' - alpha'| = {e_alpha_dot:.6g} rad/s (not checked: its bound holds with the "
                  "estimate's lag, charged as a delay)")
    delay = f", the truth taken {delay_steps} control periods earlier" if delay_steps else ""
    return Assumption(MEASURED_ERRORS, "max|alpha_m - alpha_d| <= e_alpha (and max|alpha_m' - alpha_d'| <= e_alpha' "
                      "for an exact or tachometer velocity), measured on the run",
                      bool(met), float(worst), 1.0,
                      f"{shown}{delay}; largest ratio {label}: {error:.6g} against {bound:.6g} {unit} assumed",
                      kind="checked")


def with_measured_errors(certificate: Certificate | None, *, sensing: Sensing, measurement: MeasurementErrors,
                         rows: Any, period: float) -> Certificate | None:
    """``certificate`` with :data:`MEASURED_ERRORS` measured on ``rows``, where the run was sensed and its
    claim's sensing was covered; else ``certificate`` itself (an ideal sensor, no claim, or an error model
    already refused by the assumption 'sensing and actuation covered').

    Args:
        certificate: the run's claim, or None.
        sensing: the run's sensing (:class:`wmr_mj.hardware.Sensing`).
        measurement: the error bounds the claim assumed (``RunParts.measurement``).
        rows: the run's rows (:data:`wmr_mj.sim.engine.SENSED_ROW_FIELDS` among them where sensed).
        period: T, s, the control period.
    """
    if certificate is None or sensing.is_ideal or "alpha_measured" not in rows or not measurement.covered:
        return certificate
    assumption = measured_errors_assumption(rows, measurement, delay_steps=sensing.delay_steps(period),
                                            velocity_bounded=sensing.velocity in ("exact", "tachometer"))
    return with_measured(certificate, assumption)
