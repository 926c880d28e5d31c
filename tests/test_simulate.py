"""Closed loop: controllers, the reduced-model check of the loop, and runs on the MuJoCo plant."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from controllers import ComputedTorque, PDController, gains_from_omega_r, model_from_source
from wmr_mj import C80, ParameterError, UnknownNameError
from wmr_mj.analysis.robustness import ParameterBox, ReferenceBounds, analyse
from wmr_mj.plant.reduced import SteeringModel
from wmr_mj.sim.closed_loop import run_closed_loop, run_on_reduced_model
from wmr_mj.sim.config import RunConfig, build_reference


@pytest.fixture(scope="module")
def reference():
    return build_reference("paper-circle", C80, dt=1e-3, duration=20.0)[0]


def _bounds(reference):
    b = reference.bounds()
    return ReferenceBounds(alpha_ddot_max=b.alpha_ddot_max, alpha_dot_max=b.alpha_dot_max,
                           sin_cos3_max=b.sin_cos3_max)


@pytest.mark.parametrize("friction_sign,width",
                         [("measured", 0.0), ("reference", 0.0), ("measured", 0.05), ("none", 0.0)])
def test_scalar_and_vector_laws_are_bit_identical(friction_sign, width):
    rng = np.random.default_rng(1)
    a, ad, a0, a0d, a0dd = (rng.uniform(-0.8, 0.8, 200) for _ in range(5))
    ad[:5] = 0.0
    for model in ("paper", "nonholonomic"):
        ctrl = ComputedTorque(model_from_source(model, params=C80), kp=7.0, kd=5.0, friction_sign=friction_sign,
                              friction_width=width)
        vec = ctrl.voltage(a, ad, a0, a0d, a0dd)
        sca = np.array([ctrl.voltage_scalar(*map(float, x)) for x in zip(a, ad, a0, a0d, a0dd)])
        assert np.array_equal(vec, sca)
    pd = PDController(model_from_source("paper", params=C80))
    assert np.array_equal(pd.voltage(a, ad, a0, a0d, a0dd),
                          [pd.voltage_scalar(*map(float, x)) for x in zip(a, ad, a0, a0d, a0dd)])


def test_computed_torque_is_equation_3_2():
    """u = P^ (a0'' + K_D E' + K_P E) + K^(a) + G^(a') written out by hand."""
    m = SteeringModel(P=0.4, C_V=4.7, F=1.5, K=5.3, gyro=0.6, V_A=0.2)
    c = ComputedTorque(m, kp=6.0, kd=9.0)
    a, ad, a0, a0d, a0dd = 0.3, -0.1, 0.35, 0.05, 0.2
    expected = (0.4 * (a0dd + 9 * (a0d - ad) + 6 * (a0 - a)) + 5.3 * math.sin(a) / math.cos(a) ** 3
                + 4.7 * ad - 1.5 + 0.6 * 0.2 * ad / math.cos(a) ** 2)
    assert c.voltage_scalar(a, ad, a0, a0d, a0dd) == pytest.approx(expected, rel=1e-14)
    assert gains_from_omega_r(6.0) == (9.0, 6.0)


@pytest.mark.slow
def test_exact_model_on_reduced_plant_tracks_to_1e_6(reference):
    plant = SteeringModel(P=0.385, C_V=4.77, F=1.52, K=5.33, gyro=0.0, V_A=0.2)
    r = run_on_reduced_model(ComputedTorque(plant, friction_width=1e-3), plant, reference, friction_width=1e-3)
    assert np.max(np.abs(r["E"])) < 1e-6


@pytest.mark.slow
def test_mismatched_model_on_reduced_plant_stays_inside_region(reference):
    """Plant and estimate at opposite corners of the paper's (5.1) box: inside (4.21)."""
    plant = SteeringModel(P=0.37, C_V=4.81, F=1.53, K=5.38, gyro=0.0, V_A=0.2)
    estimate = dict(P=0.40, C_V=4.73, F=1.50, K=5.29)
    r = run_on_reduced_model(ComputedTorque(SteeringModel(**estimate, gyro=0.0, V_A=0.2), friction_width=1e-3),
                             plant, reference, friction_width=1e-3)
    res = analyse(ParameterBox.paper(), bounds=_bounds(reference), estimate=estimate)
    sup_E, sup_Ed = np.max(np.abs(r["E"])), np.max(np.abs(r["E_dot"]))
    assert res.stable
    assert sup_E <= res.E_max and sup_Ed <= res.Edot_max
    assert sup_E > 1e-3  # the mismatch is felt: the check is not vacuous


@pytest.mark.parametrize("model", ["paper", "nonholonomic"])
def test_mujoco_runs_report_honestly(model):
    r = run_closed_loop(RunConfig(model=model, duration=20.0), progress=False)
    s = r.summary
    assert s.status == "completed" and s.control_steps == 20_000
    for key in ("sup_E", "sup_Edot", "E_max", "Edot_max", "inside", "m1", "model", "controller", "steps", "wall_s"):
        assert key in s.to_dict()
    assert s.sup_E == pytest.approx(np.max(np.abs(r.rows["E"])))
    assert s.inside == (s.sup_E <= s.E_max and s.sup_Edot <= s.Edot_max)
    if model == "paper":
        # the K^ sin/cos^3 term the plant does not have drives the steering into its stop
        assert s.left_steering_range and s.left_steering_range_at_s < 15.0
    assert s.mujoco_warnings == 0


def test_control_period_holds_voltage():
    r = run_closed_loop(RunConfig(model="nonholonomic", duration=10.0, control_period=0.005), progress=False)
    assert r.summary.control_steps == 2000 and r.summary.steps == 10_000
    with pytest.raises(ParameterError, match="multiple"):
        run_closed_loop(RunConfig(duration=10.0, control_period=0.0015), progress=False)


@pytest.mark.parametrize("changes,error", [({"model": "magic"}, UnknownNameError),
                                           ({"controller": "lqr"}, UnknownNameError),
                                            ({"kp": -1.0}, ParameterError), ({"m1": float("inf")}, ParameterError),
                                            ({"m1_range": (750.0, 550.0)}, ParameterError),
                                            ({"plant_overrides": {"wheelbase": 1.0}}, UnknownNameError)])
def test_bad_config_raises(changes, error):
    with pytest.raises(error):  # refused by the coercer (a name that may be an entry point is looked up there)
        RunConfig.from_inputs(**changes)


@pytest.mark.slow
def test_cli_run_json():
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "run", "--model", "nonholonomic", "--duration", "12",
                           "--no-log", "--json"], capture_output=True, text=True, check=True)
    obj = json.loads(proc.stdout)
    for key in ("sup_E", "sup_Edot", "E_max", "Edot_max", "inside", "m1", "model", "controller", "steps", "wall_s"):
        assert key in obj
    assert obj["model"] == "nonholonomic" and obj["steps"] == 12_000
    # no progress bar when not on a terminal: only the one-line note that these gains' claim holds under no estimate
    assert [line for line in proc.stderr.splitlines() if not line.startswith("wmr-mj: note: ")] == []
    assert "\r" not in proc.stderr


@pytest.mark.slow
@pytest.mark.parametrize("argv,names", [
    (["--control-period", "50"], ("control_period = 50", "longer than the run", "duration = 10")),
    (["--control-period", "0.003"], ("control_period = 0.003", "whole multiple", "--duration 9.999")),
    (["--duration", "10.0005"], ("physics step", "whole multiple", "--duration 10"))])
def test_cli_run_refuses_a_period_that_does_not_fit_the_run(argv, names):
    # --control-period 50 on a 10 s run once ran one control step (sup|E| = 0, judged inside)
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "run", "--no-log", "--duration", "10", *argv],
                          capture_output=True, text=True)
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stderr.startswith("wmr-mj: error: ") and all(n in proc.stderr for n in names), proc.stderr
    assert proc.stdout == ""


def test_config_refuses_a_period_longer_than_the_run():
    with pytest.raises(ParameterError, match="longer than the run"):
        RunConfig(duration=35.0, control_period=50.0)
    assert RunConfig(duration=35.0, control_period=0.005).control_period == 0.005  # 7000 periods: fits


@pytest.mark.slow
@pytest.mark.parametrize("argv", [["--kp", "0"], ["--kd", "-2"], ["--model", "oracle"], ["--controller", "mpc"],
                                  ["--m1", "-650"], ["--m1", "inf"], ["--m1-range", "700", "600"],
                                  ["--omega-r", "3", "--kp", "2"], ["--param", "l9=1"], ["--box", "huge"]])
def test_cli_run_bad_input_exits_2(argv):
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "run", "--no-log", "--duration", "10", *argv],
                          capture_output=True, text=True)
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "Traceback" not in proc.stderr
