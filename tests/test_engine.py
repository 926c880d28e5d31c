"""The one engine (wmr_mj.sim.engine): a single run, compiled law or Python law, is bit for bit the serial loop
of tests/reference_loop.py (rows, summary, log)."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from helpers import StopAfter3000Rows
from reference_loop import reference_run

from wmr_mj.sim.closed_loop import ROW_FIELDS, run_closed_loop
from wmr_mj.sim.config import RunConfig

BASE = RunConfig(model="nonholonomic", duration=10.0)
VOLATILE = ("wall_s", "realtime_factor")
# the six variants of the compiled batch's tests (tests/test_compiled_law.py)
VARIANTS = [dict(), dict(model="paper"), dict(control_period=0.005),
            dict(friction_sign="reference", friction_width=0.01),
            dict(controller="pd", model="paper", kp=25.0, kd=10.0),
            dict(path="lane-change", steering_friction="soft")]


def _same(x, y) -> bool:
    """Equal to the bit (NaN equal to NaN), for nested summaries."""
    if isinstance(x, dict) and isinstance(y, dict):
        return x.keys() == y.keys() and all(_same(x[k], y[k]) for k in x)
    if isinstance(x, (list, tuple)) and isinstance(y, (list, tuple)):
        return len(x) == len(y) and all(_same(a, b) for a, b in zip(x, y))
    if isinstance(x, float) and isinstance(y, float):
        return (math.isnan(x) and math.isnan(y)) or np.float64(x).tobytes() == np.float64(y).tobytes()
    return type(x) is type(y) and x == y


def assert_identical(new, old) -> None:
    assert new.status == old.status
    assert new.rows.keys() == old.rows.keys() == set(ROW_FIELDS)
    for key in ROW_FIELDS:
        assert new.rows[key].tobytes() == old.rows[key].tobytes(), key
    a = {k: v for k, v in new.summary.to_dict().items() if k not in VOLATILE}
    b = {k: v for k, v in old.summary.to_dict().items() if k not in VOLATILE}
    assert _same(a, b), [k for k in a if not _same(a.get(k), b.get(k))]


@pytest.mark.parametrize("law", ["compiled", "numpy"])
@pytest.mark.parametrize("options", VARIANTS)
def test_a_single_run_is_the_serial_loop_bit_for_bit(options, law):
    cfg = BASE.replace(m1=640.0, plant_overrides={"mu": 0.03, "R_a": 1.25}, **options)
    new = run_closed_loop(cfg, progress=False, law=law)
    assert new.law == ("compiled" if law == "compiled" else "python")
    assert (new.law_note is None) == (law == "compiled")
    assert_identical(new, reference_run(cfg, progress=False))


def test_the_steering_stop_is_detected_as_in_the_serial_loop():
    cfg = RunConfig(model="paper", duration=10.0, m1=740.0)
    new, old = run_closed_loop(cfg, progress=False), reference_run(cfg, progress=False)
    assert_identical(new, old)
    assert new.summary.left_steering_range == old.summary.left_steering_range


def test_a_logged_run_writes_the_serial_loops_log(tmp_path):
    from wmr_mj.logs.reader import load_log
    from wmr_mj.logs.writer import LogOptions, RunLogger

    cfg = RunConfig(duration=12.5)  # a last block shorter than a second
    background = LogOptions(background=True)  # as wmr-mj run logs: a writer thread
    new = run_closed_loop(cfg, logger_factory=functools.partial(RunLogger, tmp_path / "new.mcap", options=background),
                          progress=False)
    old = reference_run(cfg, logger_factory=functools.partial(RunLogger, tmp_path / "old.mcap"), progress=False)
    assert new.law == "compiled"
    assert_identical(new, old)
    a, b = load_log(tmp_path / "new.mcap"), load_log(tmp_path / "old.mcap")
    assert a.rows == b.rows == len(new.rows["t"]) and a.status == b.status == "completed"
    for got, want in ((a.signals, b.signals), (a.state, b.state)):
        assert got.keys() == want.keys()
        for key in want:
            assert np.asarray(got[key]).tobytes() == np.asarray(want[key]).tobytes(), key
    assert np.array_equal(a.initial_state, b.initial_state) and a.mjcf_xml == b.mjcf_xml


def test_a_block_with_a_warning_is_stepped_again_with_the_python_law(monkeypatch):
    """Rollout stops a simulation whose warnings rise; the engine steps that block again, stepwise."""
    from wmr_mj.sim import engine

    step = engine._CompiledStepper.step
    calls = []

    def warn_in_the_third_block(self, block, k0, count):
        step(self, block, k0, count)
        calls.append(k0)
        if len(calls) == 3:
            self.batch.warning[0, 0, 1] += 1  # as if MuJoCo had warned
            block.alpha[:] = 99.0  # what a stopped simulation might record

    monkeypatch.setattr(engine._CompiledStepper, "step", warn_in_the_third_block)
    cfg = BASE
    new = run_closed_loop(cfg, progress=False)
    assert new.law == "python" and "warned" in new.law_note and len(calls) == 3
    # the stopped attempt's records and warning are dropped: the block as the serial loop steps it
    assert_identical(new, reference_run(cfg, progress=False))


@pytest.mark.parametrize("background", [False, True])
def test_an_interrupted_logged_run_leaves_a_finished_log_of_its_rows(tmp_path, background):
    from wmr_mj.logs.reader import load_log
    from wmr_mj.logs.writer import LogOptions

    path = tmp_path / "run.mcap"

    result = run_closed_loop(RunConfig(duration=12.0), progress=False,
                             logger_factory=lambda header: StopAfter3000Rows(path, header,
                                                                           options=LogOptions(background=background)))
    assert result.status == "interrupted" and len(result.rows["t"]) == 3000
    log = load_log(path)
    assert log.status == "interrupted" and not log.truncated and log.rows == 3000
    assert log.signals["E"].tobytes() == result.rows["E"].tobytes()
