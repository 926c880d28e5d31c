"""Claims hold typed regions: section 4's (4.21) and a law's box, checked against their closed forms at
points worked by hand; anything else is refused; and the JSON of a certificate is what it was before
the regions were typed (tests/data/regions_golden.json, written at b6fcf5d by tests/data/region_cases.py).
"""

from __future__ import annotations

import json
import math
import pickle
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import pytest

from wmr_mj.analysis.certificate import Certificate, judge
from wmr_mj.analysis.claim_types import LAW_CLAIM, Claim, claim_set
from wmr_mj.analysis.regions import BoxRegion, Region, SmallGainRegion, check_region

sys.path.insert(0, str(Path(__file__).parent / "data"))
from region_cases import as_json, cases  # noqa: E402

GOLDEN = Path(__file__).parent / "data" / "regions_golden.json"

# gamma1 = 0.01 s^2, gamma2 = 0.1 s, delta1 = 2, delta2 = 5, delta3 = 0.5: condition (4.23) = 0.05 + 0.05 = 0.1,
# the corner (4.21) E_max = gamma1 delta1/(1 - 0.1) = 0.02/0.9, Edot_max = gamma2 delta1/0.9 = 0.2/0.9
G1, G2, D1, D2, D3 = 0.01, 0.1, 2.0, 5.0, 0.5
SMALL_GAIN = SmallGainRegion(gamma1=G1, gamma2=G2, delta1=D1, delta2=D2, delta3=D3, E_max=0.02 / 0.9,
                             Edot_max=0.2 / 0.9)
# rounding of a handful of operations on numbers of order 1 (a few ulps)
REL = 1e-14


def _claim(region: object, *, valid: bool = True) -> Certificate:
    return Certificate(region=region, valid=valid, assumptions=(), alpha_max=0.7, voltage_max=9.0)  # type: ignore[arg-type]


# --------------------------------------------------------------------------- section 4's region (4.21)
def test_small_gain_condition_and_vertices_are_the_closed_form():
    assert SMALL_GAIN.condition == pytest.approx(0.1, rel=REL)
    # the first line ||E|| = gamma1 (delta1 + delta2 ||E||) meets ||E'|| = 0 at gamma1 delta1/(1 - gamma1 delta2)
    # = 0.02/0.95; the second meets ||E|| = 0 at gamma2 delta1/(1 - gamma2 delta3) = 0.2/0.95
    expected = ((0.0, 0.0), (0.02 / 0.95, 0.0), (0.02 / 0.9, 0.2 / 0.9), (0.0, 0.2 / 0.95))
    for got, want in zip(SMALL_GAIN.vertices, expected, strict=True):
        assert got == pytest.approx(want, rel=REL)


def test_small_gain_ratio_at_hand_computed_points():
    # (0.01, 0.1): eta = 2 + 0.05 + 0.05 = 2.1; 0.01/(0.01 x 2.1) = 0.1/(0.1 x 2.1) = 10/21
    assert SMALL_GAIN.ratio(0.01, 0.1) == pytest.approx(10.0 / 21.0, rel=REL)
    assert SMALL_GAIN.contains(0.01, 0.1)
    # the corner lies on both lines: ratio 1, inside (the tolerance covers the rounding)
    assert SMALL_GAIN.ratio(0.02 / 0.9, 0.2 / 0.9) == pytest.approx(1.0, rel=REL)
    assert SMALL_GAIN.contains(0.02 / 0.9, 0.2 / 0.9)
    # (0.0215, 0): inside the rectangle E_max x Edot_max, beyond the first line (0.02/0.95 = 0.02105):
    # eta = 2 + 5 x 0.0215 = 2.1075, ratio = 0.0215/0.021075
    assert SMALL_GAIN.ratio(0.0215, 0.0) == pytest.approx(0.0215 / 0.021075, rel=REL)
    assert 0.0215 < SMALL_GAIN.E_max and not SMALL_GAIN.contains(0.0215, 0.0)
    # beyond the corner in |E'| alone: outside though the ratio's second side is what fails
    assert not SMALL_GAIN.contains(0.0, 0.25)
    assert SMALL_GAIN.ratio(0.0, 0.25) == pytest.approx(0.25 / (0.1 * (2.0 + 0.125)), rel=REL)


def test_small_gain_region_of_certify_is_4_21_at_its_terms():
    cert = cases()["small-gain"]
    r = cert.region
    assert isinstance(r, SmallGainRegion) and cert.valid
    # Edot_max is (4.21) at the fixed point's terms exactly; E_max the fixed point, to its tolerance 1e-13
    assert r.Edot_max == r.gamma2 * r.delta1 / (1.0 - r.condition)
    assert r.E_max == pytest.approx(r.gamma1 * r.delta1 / (1.0 - r.condition), rel=1e-12)
    assert cert.condition == r.condition and cert.gamma1 == r.gamma1 and cert.delta3 == r.delta3
    assert cert.terms is not None and cert.friction_term == cert.terms.friction_term


# --------------------------------------------------------------------------- a law's box
def test_box_ratio_contains_and_vertices():
    box = BoxRegion(E_max=0.04, Edot_max=0.4)
    assert box.ratio(0.02, 0.1) == 0.5  # max(0.02/0.04, 0.1/0.4) = max(0.5, 0.25)
    assert box.ratio(0.01, 0.3) == pytest.approx(0.75, rel=REL)
    assert box.contains(0.04, 0.4) and box.ratio(0.04, 0.4) == 1.0
    assert not box.contains(0.041, 0.0) and box.ratio(0.041, 0.0) == pytest.approx(1.025, rel=REL)
    assert not box.contains(0.0, 0.41)
    assert box.vertices == ((0.0, 0.0), (0.04, 0.0), (0.04, 0.4), (0.0, 0.4))


def test_box_with_E_alone_and_a_zero_bound():
    alone = BoxRegion(E_max=0.04)
    assert alone.Edot_max == math.inf and alone.ratio(0.02, 1e6) == 0.5 and alone.contains(0.02, 1e6)
    assert alone.vertices == ((0.0, 0.0), (0.04, 0.0), (0.04, 0.0), (0.0, 0.0))  # drawn on the ||E|| axis
    assert BoxRegion(E_max=0.0, Edot_max=1.0).ratio(0.0, 0.0) == math.inf


def test_a_claim_judges_through_its_region():
    claim = _claim(BoxRegion(E_max=0.04, Edot_max=0.4))
    j = judge(claim, 0.02, 0.1)
    assert j.inside and j.verdict == "certified-inside" and j.region_ratio == 0.5
    assert judge(claim, 0.05, 0.1).verdict == "certified-outside"
    assert _claim(SMALL_GAIN).verdict(0.0215, 0.0) == "certified-outside"  # in the rectangle, not in (4.21)
    invalid = _claim(BoxRegion(E_max=math.inf, Edot_max=math.inf), valid=False)
    assert invalid.vertices == () and invalid.region_ratio(0.0, 0.0) == math.inf and not invalid.inside(0.0, 0.0)


# --------------------------------------------------------------------------- anything else is refused
@pytest.mark.parametrize("region", ["box", "small-gain", None, object(), (0.04, 0.4)])
def test_a_region_that_is_not_a_region_is_a_type_error(region):
    with pytest.raises(TypeError, match="must be a Region"):
        _claim(region)
    with pytest.raises(TypeError, match="must be a Region"):
        check_region(region)


@dataclass(frozen=True)
class _Disk:
    """A third shape (as a sampled-data certificate would be): |(E/a, E'/b)| <= 1."""

    kind: ClassVar[str] = "disk"
    E_max: float
    Edot_max: float

    @property
    def vertices(self) -> tuple[tuple[float, float], ...]:
        return tuple((self.E_max * math.cos(t), self.Edot_max * math.sin(t))
                     for t in (k * math.pi / 8 for k in range(5)))

    def ratio(self, sup_E: float, sup_Edot: float) -> float:
        return math.hypot(sup_E / self.E_max, sup_Edot / self.Edot_max)

    def contains(self, sup_E: float, sup_Edot: float) -> bool:
        return self.ratio(sup_E, sup_Edot) <= 1.0


def test_a_third_region_needs_no_change_to_the_claim():
    disk = _Disk(E_max=0.04, Edot_max=0.4)
    assert isinstance(disk, Region)
    claim = _claim(disk)
    # (0.03, 0.3): inside the rectangle, outside the disk (hypot(0.75, 0.75) = 1.06)
    assert claim.verdict(0.03, 0.3) == "certified-outside"
    assert judge(claim, 0.02, 0.2).region_ratio == pytest.approx(math.hypot(0.5, 0.5), rel=REL)
    out = claim.to_dict()
    assert out["region"] == "disk" and "condition" not in out and len(out["vertices"]) == 5


def test_a_run_carries_its_claims_by_name():
    law, other = cases()["small-gain"], cases()["box"]
    claims = claim_set(**{LAW_CLAIM: law, "sampled-data": other, "none-stated": None})
    assert dict(claims) == {LAW_CLAIM: law, "sampled-data": other}
    with pytest.raises(TypeError):
        claims["x"] = law  # type: ignore[index]
    with pytest.raises(TypeError, match="must be a Certificate"):
        claim_set(law={"E_max": 0.1})  # type: ignore[arg-type]
    again = pickle.loads(pickle.dumps(claims))  # a batch sends a run's parts to its workers
    assert dict(again) == dict(claims) and again[LAW_CLAIM].inputs.to_dict() == law.inputs.to_dict()
    assert Claim is Certificate


# --------------------------------------------------------------------------- the JSON is what it was
@pytest.mark.parametrize("name", list(json.loads(GOLDEN.read_text())))
def test_certificate_json_is_byte_identical_to_before(name):
    before = json.loads(GOLDEN.read_text())[name]
    assert as_json(cases()[name]) == before


def test_the_inputs_are_typed_and_read_as_before():
    cert = cases()["small-gain-sensed"]
    law = cert.inputs.law
    assert law.estimate.P == 0.385 and law.limits.voltage_limit == 24.0  # type: ignore[union-attr]
    assert cert.inputs["estimate"]["P"] == 0.385 and list(cert.inputs)[-1] == "measurement"
    run = cert.inputs.with_record({**cert.inputs, "model": "nonholonomic"})
    assert run.run == {"model": "nonholonomic"} and run["model"] == "nonholonomic" and run.law is law
