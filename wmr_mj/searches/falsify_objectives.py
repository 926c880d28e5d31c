"""What falsify maximises, read from a run's summary (:data:`OBJECTIVES`), and the checks that refuse, before
any run, an objective that says nothing of the run's controller or is undefined for every run.

- ``certificate``: sup|E| / E_max of the run's certificate (the default);
- ``paper``: sup|E| / E_max of the paper's region;
- ``sup-E``: sup|E| itself, rad;
- ``requirement``: minus the robustness of an STL requirement (> 0: falsified).

Whatever the objective, a run's certificate is read the same way: its E_max (:func:`certificate_E_max`) and the
largest term of its delta1 (:func:`binding_term`), which falsify's worst run carries.

Usage::

    from wmr_mj.searches.falsify_objectives import objective_value
    objective_value({"sup_E": 0.05, "certificate": {"E_ratio": 0.4}}, "certificate")   # 0.4
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from controllers import SteeringController
from wmr_mj.analysis.verdicts import PAPER_REGION_ON_CART
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.searches.search_space import hardware_axis, path_axis, signal_axis
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.config import RunConfig, estimate_of

__all__ = ["OBJECTIVES", "OBJECTIVE_LABELS", "objective_label", "objective_value", "objective_source",
           "check_objective_applies", "check_objective_defined", "shares_the_base_certificate", "verdict_of",
           "certificate_E_max", "binding_term"]

OBJECTIVES = ("certificate", "paper", "sup-E", "requirement")
OBJECTIVE_LABELS = {"certificate": "sup|E|/E_max of the certificate", "paper": "sup|E|/E_max of the paper's region",
                    "sup-E": "sup|E| [rad]", "requirement": "-robustness of the requirement (> 0: falsified)"}


def objective_label(objective: str, *, on_c80: bool = True) -> str:
    """The objective in words (:data:`OBJECTIVE_LABELS`); on another cart than the paper's C80 (``on_c80`` False:
    the run's cart record is not None) the paper's region is named as this cart's
    (:data:`wmr_mj.analysis.verdicts.PAPER_REGION_ON_CART`)."""
    if objective == "paper" and not on_c80:
        return f"sup|E|/E_max of {PAPER_REGION_ON_CART}"
    return OBJECTIVE_LABELS[objective]


def _ratio(sup: float, bound: Any) -> float | None:
    if bound is None:
        return None
    bound = float(bound)
    return sup / bound if math.isfinite(bound) and bound > 0 else None


def objective_value(summary: Mapping[str, Any], objective: str) -> float | None:
    """The number falsify maximises for one run's summary (None where it is undefined,
    e.g. a region that does not exist). The one place that reads it; see objective_source."""
    if objective not in OBJECTIVES:
        raise UnknownNameError("objective", objective, OBJECTIVES)
    if objective == "sup-E":
        return float(summary["sup_E"])
    if objective == "requirement":
        (req,) = summary["requirements"]
        return None if req["robustness"] is None else -float(req["robustness"])
    if objective == "paper":
        region = summary.get("paper_region")
        if isinstance(region, Mapping) and region.get("E_max") is not None:
            return _ratio(float(summary["sup_E"]), region["E_max"])
        return summary.get("E_ratio")
    certificate = summary.get("certificate")
    if isinstance(certificate, Mapping) and "E_ratio" in certificate:
        return certificate["E_ratio"]
    return summary.get("E_ratio")


def check_objective_applies(law: Any, objective: str) -> None:
    """Refuse, before any run, an objective that says nothing of the run's controller (``law``, the resolved
    run's: :attr:`wmr_mj.sim.parts.RunParts.controller`): the certificate's ratio for a law that states no
    claim, the paper's for a law that is not the paper's.

    Raises:
        ParameterError: naming the controller and the objectives that apply.
    """
    if objective not in ("certificate", "paper"):
        return
    if objective == "certificate" and type(law).claim is SteeringController.claim:
        raise ParameterError(f"controller {law.name!r} states no claim, so there is no certificate to search "
                             "against: falsify a requirement (--require STL) or maximise sup|E| (--objective sup-E)")
    if objective == "paper" and estimate_of(law) is None:
        raise ParameterError(f"the paper's region is for its computed-torque law, not controller {law.name!r}: "
                             "falsify a requirement (--require STL) or maximise sup|E| (--objective sup-E)")


def shares_the_base_certificate(base: RunConfig, names: Sequence[str]) -> bool:
    """Whether every run of ``base`` searched over ``names`` is judged by the base's certificate: m1 and plant
    parameters only (the certificate is over the config's box, whatever the run's plant in it), none of
    which reaches the certificate otherwise: the plant's limits (voltage_limit, steering_range), the gear
    ratio i2 where the sensing is not ideal, the armature inductance L_a, and R_a where the actuation is not
    ideal (their coverage reads them:
    :func:`wmr_mj.sim.certify.measurement_errors_of`). The cart's, the signals' and the path's axes give
    each run its own."""
    base = coerced(base)  # a base given directly: its parts typed (wmr_mj.sim.coerce)
    reaching = {"voltage_limit", "steering_range", "L_a"}  # L_a: the armature's lag, in the sampled loop
    if not base.sensing.is_ideal or not base.transmission.is_ideal:
        reaching.add("i2")
    if not base.actuation.is_ideal:
        reaching.add("R_a")
    return not any(hardware_axis(n) or signal_axis(n) or path_axis(n) or n in reaching for n in names)


def check_objective_defined(parts: Any, spec: Any) -> None:
    """Refuse, before any step, a search whose objective is undefined for every run: the certificate's
    ratio where the base's certificate has no finite bound and every run shares it
    (:func:`shares_the_base_certificate`); ``run`` knows this before it steps, and so does falsify.

    Args:
        parts: ``spec.base`` resolved (:func:`wmr_mj.searches.falsify.check_runnable`).
        spec: the search (a :class:`wmr_mj.searches.falsify.FalsifySpec`): its objective, base and names.

    Raises:
        ParameterError: one line naming why there is no bound and what to search instead.
    """
    claim = parts.claim
    if spec.objective != "certificate" or claim is None or not shares_the_base_certificate(spec.base, spec.names):
        return
    if claim.valid and 0.0 < claim.E_max < math.inf and 0.0 < claim.Edot_max:
        return
    why = getattr(claim, "reason", None) or ", ".join(claim.unmet) or "no finite bound"
    raise ParameterError(f"the objective sup|E|/E_max of the certificate is undefined for every run: controller "
                         f"{parts.controller.name!r} has no certificate over this box ({why}; see wmr-mj robustness "
                         "--certificate): search --objective sup-E or a requirement (--require STL) instead")


def objective_source(summary: Mapping[str, Any], objective: str) -> str:
    """Which field of the summary :func:`objective_value` read, in words (for the report)."""
    if objective == "sup-E":
        return "sup_E"
    if objective == "requirement":
        return f"-robustness of {summary['requirements'][0]['formula']} (rtamt, runs one by one)"
    if objective == "paper":
        region = summary.get("paper_region")
        if isinstance(region, Mapping) and region.get("E_max") is not None:
            return "sup_E / paper_region.E_max"
        return "E_ratio (the run's analysis region; the summary has no paper_region)"
    certificate = summary.get("certificate")
    if isinstance(certificate, Mapping) and "E_ratio" in certificate:
        return "certificate.E_ratio"
    return ("E_ratio of the run's analysis region: the run summary carries no certificate yet, so the "
            "objective falls back to the region the run is judged by today")


def verdict_of(summary: Mapping[str, Any]) -> str:
    verdict = summary.get("verdict")
    if verdict is not None:
        return str(verdict)
    return "inside" if summary.get("inside") else "outside"


def certificate_E_max(summary: Mapping[str, Any]) -> float | None:
    """The E_max [rad] of a run's certificate (its summary's ``certificate``); None where the run has none."""
    certificate = summary.get("certificate")
    e_max = certificate.get("E_max") if isinstance(certificate, Mapping) else None
    return None if e_max is None else float(e_max)


def binding_term(summary: Mapping[str, Any]) -> tuple[str, float] | None:
    """The largest part of delta1 [rad/s^2] of a run's certificate, the term that binds its E_max most, as
    (its JSON name, its value): among the ``*_term`` parts at the certificate's top level (section 4's) or, where
    none of those is above 0, under its ``inputs.terms`` (the sampled-data certificate's); gyro_Edot_term, a part
    of delta3 [1/s], is not one. The first of equals; None where the run has no certificate or no term above 0."""
    certificate = summary.get("certificate")
    if not isinstance(certificate, Mapping):
        return None
    inputs = certificate.get("inputs")
    nested = inputs.get("terms") if isinstance(inputs, Mapping) else None
    for terms in (certificate, nested if isinstance(nested, Mapping) else {}):
        parts = {name: float(v) for name, v in terms.items()
                 if name.endswith("_term") and name != "gyro_Edot_term" and isinstance(v, (int, float))
                 and not isinstance(v, bool) and math.isfinite(v)}
        if parts and max(parts.values()) > 0.0:
            name = max(parts, key=lambda n: parts[n])  # max keeps the first of equals
            return name, parts[name]
    return None
