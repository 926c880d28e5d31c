"""Steering laws with claims of their own, for the tests of claims through every command
(tests/test_claims.py): a PD law on the run's estimate with a boundary-layer-style box claim, and
two whose claim() is broken (it raises, or it returns the wrong type)."""

from controllers import SteeringController
from wmr_mj.analysis.claim import box_claim


class ClaimedPD(SteeringController):
    """u = P^ (alpha0'' + kd E' + kp E): a PD law on the estimate's P^, claiming |E| <= bound rad."""

    name = "claimed-pd"

    def __init__(self, P_hat, *, kp=400.0, kd=40.0, bound=0.05):
        self.P_hat, self.kp, self.kd, self.bound = float(P_hat), float(kp), float(kd), float(bound)

    @classmethod
    def from_context(cls, context, **params):
        return cls(context.model.P, **params)

    def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        return self.P_hat * (alpha0_ddot + self.kd * (alpha0_dot - alpha_dot) + self.kp * (alpha0 - alpha))

    def claim(self, context):
        ref = context.reference
        return box_claim(claimant=self.name, E_max=self.bound, context=context,
                         alpha_max=(ref.alpha_max or 0.0) + self.bound, voltage_max=10.0)

    def describe(self):
        return {"controller": self.name, "kp": self.kp, "kd": self.kd, "bound": self.bound}


class ClaimDividesByZero(ClaimedPD):
    """Its claim() raises ZeroDivisionError."""

    name = "claim-divides-by-zero"

    def claim(self, context):
        return 1.0 / 0.0


class ClaimReturnsNumber(ClaimedPD):
    """Its claim() returns a number, not a Certificate or None."""

    name = "claim-returns-number"

    def claim(self, context):
        return 0.05
