"""A PD steering law with a box claim whose bound the test chooses (tests/test_loud_claims.py).

The claim is |E| <= claim_scale * 0.5 rad, with the assumptions every box claim shares
(:func:`wmr_mj.analysis.claim.box_claim`); ``unmet=true`` adds one that fails on purpose
("deliberately unmet", value 2 against limit 1). claim_scale = 1 holds on the nominal runs
(sup|E| a few mrad); claim_scale = 1e-6 (0.5 urad) is broken by any run.
"""

from __future__ import annotations

from controllers import SteeringController
from wmr_mj.analysis.certificate import Assumption
from wmr_mj.analysis.claim import box_claim

#: The claim's bound at claim_scale = 1, rad.
E_CLAIM = 0.5


class TightPD(SteeringController):
    name = "tight-pd"

    def __init__(self, kp=50.0, kd=15.0, claim_scale=1.0, unmet=False):
        self.kp, self.kd, self.claim_scale, self.unmet = float(kp), float(kd), float(claim_scale), bool(unmet)

    def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        return 0.385 * (alpha0_ddot + self.kd * (alpha0_dot - alpha_dot) + self.kp * (alpha0 - alpha))

    def claim(self, context):
        E_max = self.claim_scale * E_CLAIM
        own = (Assumption("deliberately unmet", "2 <= 1", False, 2.0, 1.0),) if self.unmet else ()
        return box_claim(claimant=self.name, E_max=E_max, context=context,
                         alpha_max=context.reference.alpha_max + E_max,
                         voltage_max=context.limits.voltage_limit, own=own)

    def describe(self):
        return {"controller": self.name, "kp": self.kp, "kd": self.kd, "claim_scale": self.claim_scale,
                "unmet": self.unmet}
