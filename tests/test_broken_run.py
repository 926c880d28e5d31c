"""One record for the run that breaks a claim most, a sweep's and a search's (``wmr_mj.sim.records.BrokenRun``).

The independent truth is the JSON each command wrote before the two near-twin records became one: a search's
``claim_broken`` begins with its ``phase``, a sweep's has no ``phase`` key; each reads back to an equal record.
"""

from __future__ import annotations

import json

from wmr_mj.experiments.sweep import SweepSummary
from wmr_mj.searches.falsify import _FalsifyRecord
from wmr_mj.sim.records import BrokenRun

COMMON = {"params": {"m1": 750.0}, "sup_E": 0.05, "sup_Edot": 0.2, "E_max": 0.04, "ratio": 1.25, "count": 2}


def test_a_searchs_broken_run_begins_with_its_phase():
    run = BrokenRun(phase="search", run=3, **COMMON)
    d = run.to_dict()
    assert list(d) == ["phase", "run", "params", "sup_E", "sup_Edot", "E_max", "ratio", "count"]
    assert BrokenRun.from_dict(json.loads(json.dumps(d))) == run


def test_a_sweeps_broken_run_has_no_phase():
    run = BrokenRun(run=7, **COMMON)
    d = run.to_dict()
    assert list(d) == ["run", "params", "sup_E", "sup_Edot", "E_max", "ratio", "count"]
    assert BrokenRun.from_dict(d) == run and run.phase is None


def test_both_results_hold_the_one_record():
    assert _FalsifyRecord._records["claim_broken"] is BrokenRun and SweepSummary._records["claim_broken"] is BrokenRun
