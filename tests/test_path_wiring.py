"""C's path errors in every run's summary: the single run, the batch (both laws), runs.csv, the sweep summary."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from wmr_mj.experiments.sweep import SweepSummary
from wmr_mj.sim.batch import run_batch
from wmr_mj.sim.closed_loop import PATH_SAMPLE_S, path_sample_index, run_closed_loop
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.designs import CERTIFIED
from wmr_mj.sim.many_runs import RESULT_COLUMNS, flat_row

BASE = RunConfig.from_inputs(**CERTIFIED.config_changes()).replace(duration=10.0)


def test_path_sample_index_spacing_and_last():
    idx = path_sample_index(1003, 0.001)
    assert idx[0] == 0 and idx[-1] == 1002
    assert np.all(np.diff(idx[:-1]) == round(PATH_SAMPLE_S / 0.001))
    assert list(path_sample_index(3, 0.01)) == [0, 1, 2]  # a period above the spacing: every step


def test_run_summary_has_path_error_bound_and_verdict(tmp_path):
    from wmr_mj.logs.reader import load_log
    from wmr_mj.logs.writer import RunLogger

    log = tmp_path / "r.mcap"
    result = run_closed_loop(BASE, progress=False, logger_factory=functools.partial(RunLogger, str(log)))
    s = result.summary
    d = s.to_dict()
    for key in ("cross_track_max", "cross_track_rms", "along_track_final", "heading_error_max"):
        assert np.isfinite(d["path_error"][key])
    assert d["path_verdict"]["verdict"] in ("within-bound", "beyond-bound", "no-guarantee")
    assert d["path_bound"]["kind"]
    assert s.path_error.samples == len(path_sample_index(s.control_steps, 0.001))
    # C's xy of the summary are the log's C_pos rows
    loaded = load_log(log)
    assert loaded.summary["path_error"] == d["path_error"]
    from wmr_mj.analysis.path_error import path_errors
    from wmr_mj.params import C80
    from wmr_mj.sim.config import build_reference, estimate_parameters

    ref, settle = build_reference(BASE.path, estimate_parameters(C80), dt=0.001, duration=10.0)
    at = path_sample_index(len(loaded.signals["t"]), 0.001)
    again = path_errors(ref, loaded.signals["t"][at], loaded.signals["C_pos"][at], loaded.signals["heading"][at],
                        settle_s=settle)
    assert again == s.path_error


@pytest.mark.parametrize("law", ["compiled", "numpy"])
def test_batch_path_errors_equal_the_single_runs(law):
    from wmr_mj.sim import compiled_law

    if law == "compiled" and compiled_law.unavailable_reason() is not None:
        pytest.skip(compiled_law.unavailable_reason())
    configs = [BASE.replace(m1=m, path="lane-change", control_period=0.005) for m in (560.0, 740.0)]
    batch = run_batch(configs, nthread=1, law=law)
    for b, c in zip(batch, configs):
        single = run_closed_loop(c, progress=False).summary
        assert b.path_error == single.path_error
        assert b.path_verdict == single.path_verdict


def test_runs_csv_columns_and_sweep_summary(certified_run_10s):
    assert certified_run_10s.config == BASE  # run_closed_loop(BASE), run once for the session
    s = certified_run_10s.summary
    row = flat_row({**s.to_dict(), "run": 0})
    for col in ("path_cross_track_max", "path_along_track_final", "path_heading_error_max", "path_verdict",
                "path_cross_track_bound"):
        assert col in RESULT_COLUMNS
    assert row["path_verdict"] == s.path_verdict.verdict
    assert row["path_cross_track_max"] == s.path_error.cross_track_max
    summary = SweepSummary.of([row])
    assert summary.path_cross_track.value == s.path_error.cross_track_max
    assert summary.path_verdicts[s.path_verdict.verdict] == 1
    assert summary.rung_dict()["worst_path_cross_track"] == s.path_error.cross_track_max
    # rows without the path columns (a runs.csv written before): no path figures
    old = {k: v for k, v in row.items() if not k.startswith("path_")}
    assert SweepSummary.of([old]).path_verdicts is None


def test_requirements_cross_track_interpolates_the_path_verdicts_samples():
    """cross_track as requirements read it: at the path verdict's samples (every PATH_SAMPLE_S) their
    projection to the bit, linear in between; against projecting C at every control step (the result's
    samples dropped: the fallback) it is within the linear interpolation's error bound h^2/8 max|d''|
    (h = 5 ms; d'' from the per-step series' second differences), doubled for that estimate."""
    import dataclasses

    from wmr_mj.analysis.requirements import parse_requirement
    from wmr_mj.sim.closed_loop import requirement_rows

    result = run_closed_loop(RunConfig(**CERTIFIED.config_changes(), duration=12.0, path="lane-change"),
                             progress=False)
    reqs = [parse_requirement("always(abs(cross_track) <= 0.1)", period=1e-3)]
    at, judged = result.path_samples
    interpolated = requirement_rows(result, reqs)["cross_track"]
    assert np.array_equal(interpolated[at], judged)
    per_step = requirement_rows(dataclasses.replace(result, path_samples=None), reqs)["cross_track"]
    h = PATH_SAMPLE_S
    d2 = np.abs(np.diff(per_step, 2)).max() / 1e-3 ** 2  # [m/s^2]
    assert 0.0 < np.abs(interpolated - per_step).max() <= 2.0 * h * h / 8.0 * d2
