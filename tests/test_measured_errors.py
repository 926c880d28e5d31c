"""Every sensed run checks what its law read against the bound its claim assumed (issue 35, item 0).

The break an adversary found: sliding mode with a motor-side 8000-tick floor encoder, a tachometer and
0.005 rad of play was certified-outside with every assumption met. The play's bound took the motor angle
over i2 within b of alpha, but MuJoCo's stop is soft: the measured error is 0.00554 rad against the assumed
b + Delta/i2 = 0.005013 rad. Now the play with a motor-side encoder is not covered, and a wrong error model
is caught on the run by the measured assumption ``MEASURED_ERRORS``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmr_mj import C80
from wmr_mj.analysis.measurement import MEASUREMENT_COVERED, MeasurementErrors
from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE
from wmr_mj.cli.app import main
from wmr_mj.hardware import Sensing
from wmr_mj.sim.certify import measurement_errors_of
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.designs import CERTIFIED
from wmr_mj.sim.measured_errors import MEASURED_ERRORS, measured_errors, measured_errors_assumption

#: the command of issue 35, item 0 (certified-outside at sup|E| 0.0081622 against E_max 0.0080131 before)
BREAK = ["run", "--controller", "sliding-mode", "--model", "nonholonomic", "--controller-param", "lam=40",
         "--controller-param", "phi=0.12", "--controller-param", "k=1.8", "--controller-param", "eta=0.001",
         "--controller-param", "friction_sign=none",
         "--sensing", "encoder_ticks=8000,encoder_side=motor,encoder_rounding=floor,velocity=tachometer",
         "--backlash", "0.005", "--path", "paper-circle", "--m1", "750", "--reference-bounds", "paper",
         "--duration", "20", "--no-log", "--json"]
B = 0.005  # rad, the break's play
TICKS = 8000


def _assumption(certificate: dict, name: str) -> dict | None:
    return next((a for a in certificate["assumptions"] if a["name"] == name), None)


def test_the_break_of_issue_35_is_not_certified_outside(capsys):
    status = main(BREAK)
    out = json.loads(capsys.readouterr().out)
    assert status != 3 and out["verdict"] != CERTIFIED_OUTSIDE
    covered = _assumption(out["certificate"], MEASUREMENT_COVERED)
    assert covered is not None and not covered["met"]
    assert "the play's stop is soft: its penetration is not bounded" in covered["note"]


def test_the_break_reads_beyond_the_rigid_play_bound_and_the_measured_assumption_says_so():
    """The cause, measured: max|alpha_m - alpha| exceeds b + Delta/i2 (a rigid stop's bound) by the stop's
    penetration; checked against that bound, the measured assumption is unmet (the run uncertified)."""
    config = RunConfig(controller="sliding-mode", model="nonholonomic",
                       controller_params={"lam": 40.0, "phi": 0.12, "k": 1.8, "eta": 0.001, "friction_sign": "none"},
                       sensing=Sensing(encoder_ticks=TICKS, encoder_side="motor", encoder_rounding="floor",
                                       velocity="tachometer"),
                       transmission={"backlash": B}, path="paper-circle", m1=750.0, reference_bounds="paper",
                       duration=20.0)
    result = run_closed_loop(config, progress=False)
    rigid = B + 2 * math.pi / TICKS / C80.i2  # 0.005013 rad: the play's bound with a rigid stop
    # a plain loop over the rows: the law read alpha_measured where the truth was alpha (no delay)
    worst = max(abs(m - a) for m, a in zip(result.rows["alpha_measured"], result.rows["alpha"]))
    assert measured_errors(result.rows, delay_steps=0)[0] == worst
    assert rigid < worst < rigid + 0.001  # measured 0.00554 rad: 0.53 mrad of penetration
    wrong = MeasurementErrors(alpha_error_max=rigid, alpha_dot_error_max=0.0, delay_s=0.0)
    check = measured_errors_assumption(result.rows, wrong, delay_steps=0, velocity_bounded=True)
    assert not check.met and check.value == pytest.approx(worst / rigid, rel=1e-12)
    # the tachometer reads the true rate: its error is exactly 0
    assert np.array_equal(result.rows["alpha_dot_measured"], result.rows["alpha_dot"])


def test_measured_errors_compare_with_the_truth_d_steps_earlier():
    # alpha_m[k] = alpha[k - 2] + 0.1 k / 100 with alpha[k] = k^2: the truth two steps back, then the chain's
    # start (alpha[0] before d steps have passed)
    k = np.arange(100.0)
    alpha = k**2
    taken = np.concatenate(([0.0, 0.0], alpha[:-2]))
    rows = {"alpha": alpha, "alpha_dot": 2 * k, "alpha_measured": taken + 0.001 * k,
            "alpha_dot_measured": np.concatenate(([0.0, 0.0], 2 * k[:-2]))}
    e_alpha, e_dot = measured_errors(rows, delay_steps=2)
    assert e_alpha == pytest.approx(0.099, rel=1e-9) and e_dot == 0.0
    assert measured_errors(rows, delay_steps=0)[0] > 100  # read against the current truth: the delay's change
    bounds = MeasurementErrors(alpha_error_max=0.1, alpha_dot_error_max=0.0, delay_s=0.002)
    assert measured_errors_assumption(rows, bounds, delay_steps=2, velocity_bounded=True).met
    tight = MeasurementErrors(alpha_error_max=0.098, alpha_dot_error_max=0.0, delay_s=0.002)
    assert not measured_errors_assumption(rows, tight, delay_steps=2, velocity_bounded=True).met


def test_a_covered_sensed_run_measures_its_errors_within_the_bounds_an_ideal_run_adds_nothing():
    """An axis encoder with a 3 ms delay and a tachometer: the angle's error within Delta/2 of the angle 3 steps
    back, the rate read exactly 3 steps late; the ideal cart gains no assumption."""
    sensing = Sensing(encoder_ticks=4096, velocity="tachometer", delay=0.003)
    config = RunConfig(**CERTIFIED.config_changes(), m1=750.0, duration=10.0, sensing=sensing)
    result = run_closed_loop(config, progress=False)
    e_alpha, e_dot = measured_errors(result.rows, delay_steps=3)
    assert e_alpha <= math.pi / 4096 * (1 + 1e-9) and e_dot == 0.0
    check = _assumption(result.summary.to_dict()["certificate"], MEASURED_ERRORS)
    assert check is not None and check["met"]
    assert measurement_errors_of(config, C80).alpha_error_max == pytest.approx(math.pi / 4096, rel=1e-8)
    ideal = run_closed_loop(RunConfig(**CERTIFIED.config_changes(), m1=750.0, duration=10.0), progress=False)
    assert _assumption(ideal.summary.to_dict()["certificate"], MEASURED_ERRORS) is None
