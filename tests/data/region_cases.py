"""Certificates of a few configurations, built through the public API only, for tests/test_regions.py.

``python tests/data/region_cases.py OUT.json`` writes ``{name: cert.to_dict()}`` of every case;
``tests/data/regions_golden.json`` was written so at commit b6fcf5d, before claims held typed regions
(run with ``PYTHONPATH`` set to a checkout of that commit), and the test compares today's JSON with it.
"""

from __future__ import annotations

import json
import math
import sys

from wmr_mj.analysis.certificate import Assumption, Compensation, Estimate, Gains, PlantBox, PlantLimits, certify
from wmr_mj.analysis.claim import ClaimContext, box_claim
from wmr_mj.analysis.measurement import MeasurementErrors
from wmr_mj.analysis.robustness import ParameterBox
from wmr_mj.params import C80
from wmr_mj.reference.bounds import ReferenceBounds

BOX = ParameterBox(P=(0.37, 0.40), C_V=(4.7, 4.85), F=(1.313, 1.724), K=(-0.02, 0.02))
PLANT = PlantBox(box=BOX, gyro=(0.472, 0.723), V_A=(0.2, 0.2), friction_over_P=4.3)
ESTIMATE = Estimate(P=0.385, C_V=4.77, F=1.518, K=0.0, gyro=0.629, V_A=0.2)
REFERENCE = ReferenceBounds(alpha_max=0.659, alpha_dot_max=0.23, alpha_ddot_max=0.155)
LIMITS = PlantLimits(steering_range=0.9, voltage_limit=24.0)
STATED = (Assumption("plant K band", "|K_plant| <= 0.02 V", True, 0.0104, 0.02, "a stated band", kind="stated"),)


def _certify(**changes):
    args = dict(plant=PLANT, estimate=ESTIMATE, gains=Gains(kp=100.0, kd=20.0), reference=REFERENCE, limits=LIMITS,
                compensation=Compensation(friction_sign="measured", friction_width=0.01), control_period=0.001,
                stated=STATED)
    args.update(changes)
    return certify(**args)


def _box(**changes):
    context = ClaimContext(plant=PLANT, reference=REFERENCE, limits=LIMITS, control_period=0.001,
                           initial_error=(0.0, 0.0), stated=STATED, estimate=C80)
    args = dict(claimant="my-law", E_max=0.04, Edot_max=0.4, context=context, alpha_max=0.699, voltage_max=9.5,
                own=(Assumption("gain above the bound", "k >= D", True, 2.0, 3.0),), inputs={"lam": 5.0, "phi": 0.2})
    args.update(changes)
    return box_claim(**args)


def cases():
    """{name: certificate}: section 4's (exact, no feedforward, a disturbance, sensed with a delay, and three
    without a bound) and a law's box claim (|E| and |E'|, |E| alone, no finite bound)."""
    return {
        "small-gain": _certify(),
        "small-gain-pd": _certify(estimate=Estimate(P=0.385, C_V=4.77, F=0.0, K=0.0, gyro=0.629, V_A=0.2),
                                  compensation=Compensation(friction_sign="none", feedforward=False)),
        "small-gain-disturbance": _certify(plant=PlantBox(box=BOX, gyro=(0.472, 0.723), V_A=(0.2, 0.2),
                                                          friction_over_P=4.3, disturbance=0.3,
                                                          disturbance_over_P=0.8)),
        "small-gain-sensed": _certify(measurement=MeasurementErrors(alpha_error_max=0.0008,
                                                                    alpha_dot_error_max=0.02, delay_s=0.003)),
        "small-gain-no-fixed-point": _certify(gains=Gains(kp=4.0, kd=1.0)),
        "small-gain-4.23-fails": _certify(estimate=Estimate(P=0.15, C_V=4.77, F=1.518, K=0.0, gyro=0.629, V_A=0.2)),
        "small-gain-sensed-fails": _certify(measurement=MeasurementErrors(alpha_error_max=0.0008,
                                                                          alpha_dot_error_max=0.02, delay_s=0.2)),
        "box": _box(),
        "box-E-alone": _box(Edot_max=math.inf),
        "box-no-bound": _box(E_max=math.nan, reason="the layer does not exist"),
    }


def as_json(cert) -> str:
    """The certificate's JSON as the commands write it (key order kept, inf/NaN as null)."""
    return json.dumps(cert.to_dict())


if __name__ == "__main__":
    with open(sys.argv[1], "w") as f:
        json.dump({name: as_json(c) for name, c in cases().items()}, f, indent=1)
