"""Separated verdicts and the end-of-run drift, against runs with known behaviour."""

from __future__ import annotations

import pytest

from wmr_mj.analysis.verdicts import DRIFT_TOLERANCE, VERDICTS, count_verdicts, drift, drift_window_steps, is_pass


def test_drift_compares_the_last_two_windows():
    assert drift(prev_window=0.01, last_window=0.01 + 2 * DRIFT_TOLERANCE, final_alpha_dot=0.0).growing
    assert not drift(prev_window=0.01, last_window=0.01 + 0.5 * DRIFT_TOLERANCE, final_alpha_dot=0.0).growing
    assert not drift(prev_window=0.02, last_window=0.01, final_alpha_dot=0.0).growing
    assert drift(prev_window=0.01, last_window=float("nan"), final_alpha_dot=0.0).growing


def test_drift_windows():
    assert drift_window_steps(35000, 1e-3) == 5000
    assert drift_window_steps(8000, 1e-3) == 2000  # a quarter of a short run
    assert drift_window_steps(2, 1e-3) == 1


def test_only_certified_inside_passes_and_counts_cover_all_four():
    assert [is_pass(v) for v in VERDICTS] == [True, False, False, False]
    counts = count_verdicts(["certified-inside", "uncertified-inside", "certified-inside"])
    assert counts == {"certified-inside": 2, "certified-outside": 0, "uncertified-inside": 1,
                      "uncertified-outside": 0}


@pytest.mark.slow
@pytest.mark.parametrize("friction, growing", [("soft", True), ("stiction", False)])
def test_soft_friction_creep_shows_as_drift(friction, growing):
    """The known finding: with MuJoCo's soft frictionloss the exact-sign compensation keeps the joint
    creeping (|E| still growing at 35 s); with stiction it settles."""
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig

    s = run_closed_loop(RunConfig(model="nonholonomic", steering_friction=friction), progress=False).summary
    assert s.drift.growing is growing
    if growing:
        assert abs(s.drift.final_alpha_dot) > 1e-3  # creeping at mrad/s
    else:
        assert abs(s.drift.final_alpha_dot) < 1e-4
    # the paper's gains leave the non-holonomic design without a certificate: never a pass
    assert s.verdict.startswith("uncertified-")
