"""The certificate and the claims a run is judged by: one import for the names that have always lived here.

The pieces live in modules of their own, lowest first:

* :mod:`wmr_mj.analysis.regions`: the :class:`Region` protocol, section 4's :class:`SmallGainRegion` (4.21)
  and the :class:`BoxRegion` of a law's own claim;
* :mod:`wmr_mj.analysis.claim_types`: :class:`Assumption`, :class:`Certificate` (the claim type, also
  :data:`Claim`: a region, its assumptions, section 4's :class:`SmallGainTerms`, :class:`ClaimInputs`),
  :func:`judge` and :class:`CertificateJudgement`, :class:`Claims` (a run's claims by name);
* :mod:`wmr_mj.analysis.plant_box`: :class:`PlantBox`, :class:`PlantLimits`, the plant's K and gyro bands,
  the derived box of a run's ranges and the bound on F/P over its corners;
* :mod:`wmr_mj.analysis.claim`: what a run gives a claim (:class:`~wmr_mj.analysis.claim.ClaimContext`),
  the fixed point and the four assumptions every claim shares, :func:`~wmr_mj.analysis.claim.box_claim`;
* :mod:`wmr_mj.analysis.small_gain`: section 4 redone for the law as run on the plant as simulated
  (:func:`certify`), with its derivation.

Usage::

    from wmr_mj.analysis.certificate import Certificate, certify, judge      # as always
    from wmr_mj.analysis.regions import BoxRegion, SmallGainRegion
    isinstance(cert.region, SmallGainRegion)                               # section 4's, not a name
"""

from __future__ import annotations

from wmr_mj.analysis.claim import fixed_point, replace_inputs
from wmr_mj.analysis.claim_types import (
    VERDICTS,
    Assumption,
    Certificate,
    CertificateJudgement,
    Claim,
    Claims,
    SmallGainTerms,
    Verdict,
    judge,
)
from wmr_mj.analysis.plant_box import (
    GYRO_BAND,
    GYRO_MEASURED_RATIOS,
    PLANT_K_BAND,
    PLANT_K_MEASURED,
    PlantBox,
    PlantLimits,
    derived_box,
    friction_over_P_max,
)
from wmr_mj.analysis.regions import BoxRegion, Region, SmallGainRegion
from wmr_mj.analysis.small_gain import (
    CONTROL_PERIOD_FRACTION,
    MEASURED_SIGN,
    Compensation,
    Estimate,
    Gains,
    certify,
    friction_term,
    loop_crossover,
)

__all__ = [
    "friction_over_P_max",
    "derived_box",
    "Verdict",
    "VERDICTS",
    "Assumption",
    "Certificate",
    "Claim",
    "Claims",
    "Region",
    "SmallGainRegion",
    "BoxRegion",
    "SmallGainTerms",
    "CertificateJudgement",
    "PlantBox",
    "Estimate",
    "Gains",
    "PlantLimits",
    "Compensation",
    "MEASURED_SIGN",
    "certify",
    "judge",
    "friction_term",
    "fixed_point",
    "loop_crossover",
    "replace_inputs",
    "PLANT_K_BAND",
    "PLANT_K_MEASURED",
    "GYRO_BAND",
    "GYRO_MEASURED_RATIOS",
    "CONTROL_PERIOD_FRACTION",
]


