"""A run carries its claims by name: a second claim is one more entry of ``RunParts.claims``, measured and judged
as the law's is, and the run's numbers and verdict stay the law's claim's."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from wmr_mj.analysis.claim_types import LAW_CLAIM, Claims, judge
from wmr_mj.analysis.regions import BoxRegion
from wmr_mj.sim.closed_loop import run_parts
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.designs import CERTIFIED
from wmr_mj.sim.parts import resolve_run

MY_PID = f"{Path(__file__).resolve().parents[1] / 'examples' / 'my_pid.py'}:MyPID"

#: the two runs' clocks, the only keys of a summary that differ between two runs of one config
TIMING = ("wall_s", "realtime_factor")

#: a sensed, corrected run: the run measures two of its claims' assumptions (the sensing's error bounds, the
#: tracker's declared bounds), which a second claim must get as the law's does
SENSED = dict(**CERTIFIED.config_changes(), path="lane-change", duration=3.0, sensing="magnetic-14bit-axis",
              reference_bounds="paper", correction=True)


def _numbers(result) -> dict:
    return {k: v for k, v in result.summary.to_dict().items() if k not in TIMING}


def test_the_law_claim_is_the_entry_law_and_a_law_without_one_has_none():
    parts = resolve_run(RunConfig(path="lane-change", duration=3.0))
    assert isinstance(parts.claims, Claims) and list(parts.claims) == [LAW_CLAIM]
    assert parts.claim is parts.claims[LAW_CLAIM]
    silent = resolve_run(RunConfig(controller=MY_PID, path="lane-change", duration=3.0))  # it states no claim
    assert silent.claim is None and dict(silent.claims) == {}


def test_a_second_claim_is_one_more_entry_judged_as_the_law_claim_without_moving_a_number():
    plain = run_parts(resolve_run(RunConfig(**SENSED)), progress=False)
    parts = resolve_run(RunConfig(**SENSED))
    law = parts.claim
    assert law is not None
    E_max = law.E_max / 2.0  # a tighter box than the law's: a claim of the test's own, with the law's assumptions
    second = dataclasses.replace(law, region=BoxRegion(E_max=E_max), claimant="test-box")
    result = run_parts(dataclasses.replace(parts, claims=Claims({**parts.claims, "test-box": second})),
                       progress=False)

    # nothing the run measured or reported moved, and its verdict is still the law's claim's
    assert _numbers(result) == _numbers(plain)
    assert set(result.rows) == set(plain.rows)
    for name, column in plain.rows.items():
        assert np.array_equal(result.rows[name], column, equal_nan=True), name
    assert result.claims[LAW_CLAIM] is result.summary.certificate
    assert set(result.claims) == {LAW_CLAIM, "test-box"} and set(plain.claims) == {LAW_CLAIM}

    # the second claim got what the run measured of its assumptions, as the law's did ...
    judged = result.claims["test-box"]
    measured_names = {"measured errors within the assumed bounds", "reference within the declared bounds"}
    assert measured_names <= {a.name for a in judged.assumptions}
    assert judged.assumptions == result.summary.certificate.assumptions
    # ... and is judged by `judge` on the run's sup|E|, sup|E'|: its box's closed form |E| <= E_max
    sup_E, sup_Edot = result.summary.sup_E, result.summary.sup_Edot
    assert judged == judge(judged.certificate, sup_E, sup_Edot)
    assert judged.inside == (sup_E <= E_max)
    assert judged.E_ratio == sup_E / E_max and judged.Edot_ratio == 0.0
    assert judged.region_ratio == sup_E / E_max and math.isfinite(judged.region_ratio)
