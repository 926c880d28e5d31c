"""The Cartesian correction (controllers.tracking.StanleyAtC): limits, assumptions, both laws alike."""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers.tracking import DEFAULT_GAINS, TRACKER_BOUNDS_ASSUMPTION, CorrectionGains, StanleyAtC, corrected_bounds
from wmr_mj.errors import ParameterError
from wmr_mj.reference.bounds import ReferenceBounds
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.designs import CERTIFIED

BASE = RunConfig(**CERTIFIED.config_changes()).replace(path="lane-change", duration=12.0)


def test_the_filter_keeps_rate_and_acceleration_within_the_limits():
    from wmr_mj.params import C80
    from wmr_mj.sim.config import build_reference, estimate_parameters

    ref, _ = build_reference("lane-change", estimate_parameters(C80), dt=0.001, duration=12.0)
    c = StanleyAtC()
    c.reset(ref, control_period=0.001)
    c.command = 0.1  # a step to the largest correction
    d, dd, ddd = (np.concatenate(x) for x in zip(*(c.corrections(50) for _ in range(200))))
    g = DEFAULT_GAINS
    # the filter clips each to its limit: 1e-12 (rad, rad/s, rad/s^2 of order 0.1-10) is rounding only
    assert np.max(np.abs(d)) <= g.delta_max + 1e-12
    assert np.max(np.abs(dd)) <= g.rate_max + 1e-12
    assert np.max(np.abs(ddd)) <= g.acc_max + 1e-12
    assert d[-1] == pytest.approx(0.1, abs=1e-3)
    # consistent: delta' integrates delta'', delta integrates delta'
    assert np.allclose(np.diff(dd), ddd[:-1] * 0.001)


def test_corrected_bounds_add_the_limits():
    b = ReferenceBounds(alpha_ddot_max=0.1, alpha_dot_max=0.2, sin_cos3_max=1.0, alpha_max=0.6)
    c = corrected_bounds(b, CorrectionGains(delta_max=0.1, rate_max=0.05, acc_max=0.2))
    assert (c.alpha_max, c.alpha_dot_max, c.alpha_ddot_max) == pytest.approx((0.7, 0.25, 0.3))
    assert c.sin_cos3_max == pytest.approx(math.sin(0.7) / math.cos(0.7) ** 3)
    with pytest.raises(ParameterError):
        CorrectionGains(k_e=-1.0)


def test_config_without_the_correction_is_written_as_before():
    assert "correction" not in BASE.to_dict()
    assert BASE.replace(correction=True).to_dict()["correction"] is True
    with pytest.raises(ParameterError):
        BASE.replace(correction="yes")


def test_a_corrected_run_names_its_assumptions_and_keeps_its_limits():
    from wmr_mj.sim import compiled_law

    cfg = BASE.replace(correction=True)
    new = run_closed_loop(cfg, progress=False)
    plain = run_closed_loop(BASE, progress=False).summary
    s = new.summary
    names = [a.name for a in s.certificate.assumptions]
    for name in (TRACKER_BOUNDS_ASSUMPTION, "correction measurement", "correction path", "correction start"):
        assert name in names
    measured = next(a for a in s.certificate.assumptions if a.name == TRACKER_BOUNDS_ASSUMPTION)
    assert measured.kind == "checked" and measured.met and 0.0 < measured.value <= 1.0  # measured on the run
    for used, limit in (("delta_max_used", "delta_max"), ("rate_max_used", "rate_max"), ("acc_max_used", "acc_max")):
        assert s.correction[used] <= s.correction[limit] + 1e-12  # clipped to the limit: rounding
    assert s.certificate.E_max >= plain.certificate.E_max  # the corrected reference's wider bounds
    assert s.path_error.cross_track_max < plain.path_error.cross_track_max  # the correction's purpose
    assert "Cartesian correction" in s.path_verdict.text
    if compiled_law.unavailable_reason() is None:
        other = run_closed_loop(cfg, progress=False, law="numpy")
        for key in new.rows:
            assert new.rows[key].tobytes() == other.rows[key].tobytes(), key


def test_a_batch_with_the_correction_runs_its_runs_singly():
    from wmr_mj.sim.batch import run_batch

    cfgs = [BASE.replace(correction=True, m1=m, duration=10.0) for m in (600.0, 700.0)]
    out = run_batch(cfgs, nthread=1)
    for r, c in zip(out, cfgs):
        single = run_closed_loop(c, progress=False).summary
        assert r.path_error == single.path_error and r.sup_E == single.sup_E
        assert r.correction == single.correction


@pytest.mark.slow
def test_a_tracker_runs_with_a_disturbance_and_a_load_change_compiled_as_in_python():
    """With a tracker the compiled law runs on the run's own model (its reference is rewritten between blocks),
    so a load change sets that model's fields, as the Python stepper does: the two give the same bits."""
    from wmr_mj.sim import compiled_law

    cfg = BASE.replace(correction=True, signals={
        "disturbance": {"kind": "pulse", "amplitude": 0.5, "t1": 3.0, "t2": 4.0}, "d_max": 0.5,
        "loads": [{"kind": "step", "t": 6.0, "m1": 720.0}]})
    a = run_closed_loop(cfg, progress=False)
    assert a.summary.certificate.certified  # the signals' assumptions and the tracker's measured one all met
    if compiled_law.unavailable_reason() is None:
        assert a.law == "compiled"
        b = run_closed_loop(cfg, progress=False, law="numpy")
        for key in a.rows:
            assert a.rows[key].tobytes() == b.rows[key].tobytes(), key
