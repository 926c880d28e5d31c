"""The engine with a steering sensor (wmr_mj.hardware.sensing between the plant and the law): the compiled
callback's chain (C, wmr_mj/sim/_compiled_law.c) and the Python stepper's (SensingChain.step) give the same
rows to the bit, with a tracker, with signals and across a fall-back to the Python law mid-run; the measured
rows are SensingChain.run applied offline to the true rows (an independent check of the C port), and the law
was fed them (its voltage recomputed from the measured rows)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from wmr_mj.hardware import Sensing, SensingChain
from wmr_mj.sim import compiled_law
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.engine import SENSED_ROW_FIELDS
from wmr_mj.sim.parts import resolve_run

REPO = Path(__file__).resolve().parents[1]
needs_compiled = pytest.mark.skipif(compiled_law.unavailable_reason() is not None,
                                    reason=f"the compiled law cannot run: {compiled_law.unavailable_reason()}")
needs_numba = pytest.mark.skipif(importlib.util.find_spec("numba") is None,
                                 reason="numba is not installed (pip install 'wmr-mj[fast]')")

# the certified design; 10 s of the paper circle (its lead-in and entry take 8.1 s)
CERTIFIED = RunConfig(model="nonholonomic", kp=100.0, kd=20.0, friction_width=0.01, duration=10.0)
SENSINGS = [
    "encoder_ticks=4096,velocity=difference",  # axis, rint; no delay
    "encoder_ticks=4096,velocity=difference,delay=0.005",  # the bench case
    "encoder_ticks=16384,encoder_rounding=floor,velocity=filtered,filter_tau=0.002,delay=0.005",
    "incremental-500-motor",  # motor side, floor, difference
    "encoder_ticks=2000,encoder_side=motor,velocity=tachometer,velocity_noise=gaussian:0.01,seed=4",
    "encoder_ticks=4096,velocity=difference,delay=0.005,noise=uniform:0.0005,seed=3",
    "noise=gaussian:0.0002,velocity_noise=uniform:0.02,seed=7",  # exact angle and rate, noisy
]


def _runs(config: RunConfig):
    """(compiled run, Python run) of ``config``, each checked to have taken its path."""
    compiled = run_closed_loop(config, progress=False, law="compiled")
    python = run_closed_loop(config, progress=False, law="numpy")
    assert compiled.law == "compiled" and compiled.law_note is None
    assert python.law == "python"
    return compiled, python


def _assert_same_bits(a, b) -> None:
    assert a.status == b.status == "completed"
    assert a.rows.keys() == b.rows.keys() and set(SENSED_ROW_FIELDS) <= a.rows.keys()
    for key in a.rows:
        assert a.rows[key].tobytes() == b.rows[key].tobytes(), key
    assert a.C_xy.tobytes() == b.C_xy.tobytes()


def _offline(config: RunConfig, rows) -> tuple[np.ndarray, np.ndarray]:
    """The chain applied afterwards to the run's true alpha and alpha' (motor side: i2 alpha, no play)."""
    parts = resolve_run(config)
    chain = SensingChain(parts.sensing, control_period=parts.period, n_steps=parts.n, gear_ratio=parts.plant.i2)
    return chain.run(rows["alpha"], rows["alpha_dot"])


@needs_compiled
@pytest.mark.parametrize("spec", SENSINGS)
def test_compiled_and_python_sensed_runs_are_the_same_bits_and_the_offline_chain(spec):
    config = CERTIFIED.replace(sensing=spec)
    compiled, python = _runs(config)
    _assert_same_bits(compiled, python)
    rows = compiled.rows
    alpha_m, alpha_dot_m = _offline(config, rows)
    assert rows["alpha_measured"].tobytes() == alpha_m.tobytes()
    assert rows["alpha_dot_measured"].tobytes() == alpha_dot_m.tobytes()
    # the sensor acts: what the law read is not the state (every case quantises, delays or adds noise)
    assert not np.array_equal(rows["alpha_measured"], rows["alpha"])
    # E and E' are judged on the true state
    assert rows["E"].tobytes() == (rows["alpha0"] - rows["alpha"]).tobytes()
    assert rows["E_dot"].tobytes() == (rows["alpha0_dot"] - rows["alpha_dot"]).tobytes()
    # the law was fed the measured state: its voltage recomputed from the measured rows, step by step
    law = resolve_run(config).controller
    u = [law.voltage_scalar(a, ad, a0, a0d, a0dd) for a, ad, a0, a0d, a0dd in
         zip(rows["alpha_measured"], rows["alpha_dot_measured"], rows["alpha0"], rows["alpha0_dot"],
             rows["alpha0_ddot"])]
    assert np.asarray(u).tobytes() == rows["voltage_cmd"].tobytes()


@needs_compiled
def test_the_sensors_delay_reads_the_true_angle_exactly_d_steps_before():
    """Exact angle, exact rate, 5 ms late: the measured rows are the true rows shifted by 5 control steps."""
    compiled, python = _runs(CERTIFIED.replace(sensing="delay=0.005"))
    _assert_same_bits(compiled, python)
    rows, d = compiled.rows, 5
    for true, measured in (("alpha", "alpha_measured"), ("alpha_dot", "alpha_dot_measured")):
        assert rows[measured][d:].tobytes() == rows[true][:-d].tobytes()
        assert np.all(rows[measured][:d] == rows[true][0])  # before d steps: the state at t = 0


@needs_compiled
def test_a_sensed_run_with_the_correction_is_the_same_bits_on_both_paths():
    """The tracker's outer loop rewrites the reference in the compiled model (own_model) block by block."""
    config = CERTIFIED.replace(sensing="encoder_ticks=4096,velocity=difference,delay=0.005,noise=uniform:0.0005,"
                                       "seed=3", correction=True)
    compiled, python = _runs(config)
    _assert_same_bits(compiled, python)
    ideal = run_closed_loop(config.replace(sensing=None), progress=False)
    assert not np.array_equal(ideal.rows["alpha0"], compiled.rows["alpha0"])  # the tracker saw the sensed run
    alpha_m, alpha_dot_m = _offline(config, compiled.rows)
    assert compiled.rows["alpha_measured"].tobytes() == alpha_m.tobytes()
    assert compiled.rows["alpha_dot_measured"].tobytes() == alpha_dot_m.tobytes()


@needs_compiled
def test_a_sensed_run_with_a_load_change_and_a_disturbance_is_the_same_bits_on_both_paths():
    """A load change steps the block in parts: the chain's state runs on through them."""
    signals = {"disturbance": {"kind": "step", "amplitude": 1.0, "t1": 2.0},
               "loads": [{"kind": "step", "t": 4.5, "m1": 700.0}]}
    config = CERTIFIED.replace(sensing="incremental-500-motor", signals=signals)
    compiled, python = _runs(config)
    _assert_same_bits(compiled, python)
    alpha_m, alpha_dot_m = _offline(config, compiled.rows)
    assert compiled.rows["alpha_measured"].tobytes() == alpha_m.tobytes()
    assert compiled.rows["alpha_dot_measured"].tobytes() == alpha_dot_m.tobytes()
    plain = run_closed_loop(config.replace(signals=None), progress=False)
    assert not np.array_equal(plain.rows["E"], compiled.rows["E"])  # the signals act


@needs_compiled
def test_a_fall_back_mid_run_carries_the_chains_state_into_the_python_stepper(monkeypatch):
    """MuJoCo warns in the third block: the Python stepper steps it again from the compiled block's state,
    the sensor's memory (ring, last angle, filter) read back from userdata (_PythonStepper.set_state). Without
    it the chain would start over at step 2000 (SensingChain.step refuses a step out of turn) or, reset,
    would read other values."""
    from wmr_mj.sim import engine

    step = engine._CompiledStepper.step
    calls = []

    def warn_in_the_third_block(self, block, k0, count):
        step(self, block, k0, count)
        calls.append(k0)
        if len(calls) == 3:
            self.batch.warning[0, 0, 1] += 1  # as if MuJoCo had warned
            block.alpha[:] = block.alpha_measured[:] = block.alpha_dot_measured[:] = 99.0  # a stopped record

    config = CERTIFIED.replace(sensing="encoder_ticks=4096,encoder_rounding=floor,velocity=filtered,"
                                       "filter_tau=0.002,delay=0.005,noise=uniform:0.0005,seed=3")
    python = run_closed_loop(config, progress=False, law="numpy")
    monkeypatch.setattr(engine._CompiledStepper, "step", warn_in_the_third_block)
    fell_back = run_closed_loop(config, progress=False)
    assert fell_back.law == "python" and "warned" in fell_back.law_note and calls == [0, 1000, 2000]
    _assert_same_bits(fell_back, python)


@needs_compiled
def test_set_state_restores_the_chain_from_the_compiled_models_userdata():
    """The state read back from a compiled stepper puts its chain's memory into the Python stepper's chain."""
    from wmr_mj.sim import engine

    config = CERTIFIED.replace(sensing="encoder_ticks=4096,velocity=filtered,filter_tau=0.002,delay=0.003")
    parts = resolve_run(config)
    chain = engine._sensing_chain(engine.Schedule(reference=(np.zeros(parts.n),) * 3, n=parts.n, substeps=1,
                                                  period=parts.period, sensing=parts.sensing), parts.plant)
    assert chain is not None
    plain = engine.batch_model(parts.plant, **parts.options)
    where = engine._Plant(plain)
    reference = tuple(np.asarray(r, dtype=float) for r in (parts.reference.alpha0, parts.reference.alpha0_dot,
                                                            parts.reference.alpha0_ddot))
    schedule = engine.Schedule(reference=reference, n=parts.n, substeps=1, period=parts.period, sensing=parts.sensing)
    parts.controller.reset(control_period=parts.period)
    stepper, lawful, _ = engine._compiled_stepper(parts.plant, parts.controller, parts.options, where, schedule,
                                                  reference, None, False, chain)
    block = engine._Block(6000, plain, False, True)
    stepper.step(block, 0, 6000)  # into the circle's entry: alpha moves
    python = engine._PythonStepper(plain, where, 1, False, parts.controller.step, reference, 12.0, chain=chain)
    python.set_state(lawful, stepper.state())
    offline = SensingChain(parts.sensing, control_period=parts.period, n_steps=parts.n, gear_ratio=parts.plant.i2)
    offline.run(block.alpha, block.alpha_dot)  # the chain after steps 0 .. 5999 of the true rows
    assert chain.state.tobytes() == offline.state.tobytes()
    assert chain.state[0] == 6000 and chain.state[2] != 0.0  # the next step, the filter's memory


@needs_compiled
@needs_numba
def test_a_plug_ins_compiled_law_compiles_with_sensing_and_reads_the_measured_state():
    """examples/fast_pd.py:FastPD (a pure ``law``) runs compiled by numba with a sensor, the same bits as its
    Python path; its voltage is its ``law`` of the measured rows."""
    config = CERTIFIED.replace(controller=f"{REPO / 'examples' / 'fast_pd.py'}:FastPD",
                               sensing="encoder_ticks=4096,velocity=difference,delay=0.005,noise=uniform:0.0005,"
                                       "seed=3")
    compiled, python = _runs(config)
    _assert_same_bits(compiled, python)
    law = resolve_run(config).controller
    p = law.law_parameters()
    rows = compiled.rows
    u = [law.law(p, a, ad, a0, a0d, a0dd) for a, ad, a0, a0d, a0dd in
         zip(rows["alpha_measured"], rows["alpha_dot_measured"], rows["alpha0"], rows["alpha0_dot"],
             rows["alpha0_ddot"])]
    assert np.asarray(u).tobytes() == rows["voltage_cmd"].tobytes()
    assert not np.array_equal(rows["voltage_cmd"], run_closed_loop(config.replace(sensing=None),
                                                                   progress=False).rows["voltage_cmd"])


def test_an_ideal_sensor_adds_no_rows():
    run = run_closed_loop(CERTIFIED.replace(sensing=Sensing()), progress=False)
    assert not set(SENSED_ROW_FIELDS) & run.rows.keys()
