"""The steering joint's friction law, measured on the plant against closed forms.

Independent truths: the creep bound of issue 8 (<= 1e-4 rad/s below break-away);
MuJoCo's documented friction-constraint dynamics, whose steady creep under a torque
tau is v = (1 - d)/d * tau/J * d_w * timeconst/2 (modeling guide, "Friction"); and the
steady sliding rate of (2.13), (u - F)/C_V.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from wmr_mj import C80, UnknownNameError
from wmr_mj.cli.app import main
from wmr_mj.plant.friction import HOLD_RATE, constant_voltage_rates, measure_friction_law
from wmr_mj.plant.mjcf import STICTION_SOLIMP, STICTION_SOLREF, Plant, compile_model

F = C80.coefficients("paper").F  # V, friction voltage of (2.13)
C_V = C80.coefficients("paper").C_V
FRACTIONS = np.array([0.5, 0.9, 1.3])
MUJOCO_DEFAULT_SOLREF = (0.02, 1.0)
MUJOCO_DEFAULT_SOLIMP = (0.9, 0.95)


def _creep_closed_form(fraction: float, solref, solimp) -> float:
    """MuJoCo's steady creep of a frictionloss constraint under the motor torque at rest, rad/s."""
    tau = fraction * C80.steering_friction_torque  # u = fraction F gives fraction of the friction torque
    d, d_w = solimp[0], solimp[1]
    return (1 - d) / d * tau / C80.steering_yaw_inertia * d_w * solref[0] / 2


@pytest.fixture(scope="module")
def rates():
    return {name: constant_voltage_rates(C80, FRACTIONS * F, steering_friction=name)
            for name in ("stiction", "soft")}


def test_stiction_holds_below_breakaway_and_slides_above(rates):
    r, warnings = rates["stiction"]
    assert warnings == 0
    assert abs(r[0]) <= HOLD_RATE and abs(r[1]) <= HOLD_RATE  # 0.5 F, 0.9 F: holds
    for k, fraction in enumerate(FRACTIONS[:2]):
        assert r[k] == pytest.approx(_creep_closed_form(fraction, STICTION_SOLREF, STICTION_SOLIMP), rel=0.05)
    # 1.3 F: slides at the non-holonomic model's steady rate, whose gyroscopic term adds gyro V_A
    # to (2.13)'s C_V near alpha = 0; (2.13) alone is 2.7% faster
    gyro = C80.coefficients("nonholonomic").gyro
    assert r[2] == pytest.approx(0.3 * F / (C_V + gyro * C80.V_A), rel=0.01)
    assert r[2] < 0.3 * F / C_V
    assert r[2] > 100 * HOLD_RATE


def test_soft_friction_creeps_at_mrad_per_s_as_first_found(rates):
    """MuJoCo's default frictionloss: 2.8 mrad/s at 0.5 F and 5.1 mrad/s at 0.9 F (issue 8)."""
    r, warnings = rates["soft"]
    assert warnings == 0
    assert r[0] == pytest.approx(2.8e-3, rel=0.05)
    assert r[1] == pytest.approx(5.1e-3, rel=0.05)
    for k, fraction in enumerate(FRACTIONS[:2]):
        assert r[k] == pytest.approx(_creep_closed_form(fraction, MUJOCO_DEFAULT_SOLREF, MUJOCO_DEFAULT_SOLIMP),
                                     rel=0.05)
    assert r[2] == pytest.approx(rates["stiction"][0][2], rel=0.02)  # sliding is the same law


@pytest.mark.slow
def test_measured_breakaway_brackets_the_friction_voltage():
    law = measure_friction_law(C80, steering_friction="stiction", rounds=2)
    lo, hi = law.breakaway_voltage - law.breakaway_resolution, law.breakaway_voltage
    assert law.breakaway_resolution == pytest.approx(2 * F / 81)
    # the joint starts to move where the motor torque at rest reaches the friction torque
    assert lo <= F + C_V * HOLD_RATE * 1.1 and hi >= F
    assert law.breakaway_torque == pytest.approx(hi * C80.i2 * C80.k_i / C80.R_a)
    assert law.holds() and law.mujoco_warnings == 0
    soft = measure_friction_law(C80, steering_friction="soft", rounds=1)
    # the least voltage tried, 2F/9, already moves the joint: the bracket starts at 0
    assert not soft.holds() and soft.breakaway_voltage == pytest.approx(2 * F / 9)
    # both ends are voltages of the tried grid: a difference of V-scale numbers, rounding only
    assert soft.breakaway_voltage - soft.breakaway_resolution == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("call", [
    lambda: Plant(C80, steering_friction="viscous"),
    lambda: compile_model(C80, steering_friction="viscous"),
    lambda: measure_friction_law(C80, steering_friction="viscous"),
])
def test_unknown_friction_model_is_an_unknown_name(call):
    with pytest.raises(UnknownNameError, match="valid steering friction models: soft, stiction"):
        call()


@pytest.mark.slow
def test_run_config_validates_and_passes_the_friction_model():
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig

    with pytest.raises(UnknownNameError, match="steering friction"):
        RunConfig(steering_friction="viscous")
    with pytest.raises(UnknownNameError, match="valid tyre contact models: soft, stiff"):
        RunConfig(tyre_contact="rubber")
    # issue 8: with soft friction the nominal non-holonomic run creeps off the circle; with stiction it holds
    final = {}
    for name in ("stiction", "soft"):
        result = run_closed_loop(RunConfig(model="nonholonomic", duration=25.0, steering_friction=name),
                                 progress=False)
        final[name] = abs(float(result.rows["E"][-1]))
    assert final["stiction"] < 0.01
    assert final["soft"] > 0.05


@pytest.mark.slow
def test_cli_friction_json(capsys):
    assert main(["model", "friction", "--json"]) == 0
    obj = json.loads(capsys.readouterr().out)
    assert set(obj) == {"stiction", "soft"}
    assert obj["stiction"]["holds"] is True and obj["soft"]["holds"] is False
    assert obj["stiction"]["creep_rates"]["0.9"] <= HOLD_RATE


@pytest.mark.slow
def test_cli_run_unknown_friction_model_is_one_line():
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "run", "--duration", "1", "--no-log",
                           "--steering-friction", "viscous"], capture_output=True, text=True)
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and "soft, stiction" in proc.stderr
    assert "Traceback" not in proc.stderr
