"""The verdict names the real cause (issue 35, item 7): what a claim assumed the law reads and which error binds,
a delta1 breakdown that adds up, no path guarantee without a certificate that holds, "no certificate" where
there is no region, and sliding mode's sampling check named for the quantity that moved.

Independent truth: the quantiser's closed forms (Delta/2, Delta/T, T/2 for a differenced angle), certificates
re-solved by hand with one error set to 0, delta1 itself (the parts must add up to it), and the reference's own
path (cross-track 0, inside any bound).
"""

from __future__ import annotations

import dataclasses
import json
import math
import re

import pytest

from controllers.sliding_mode import MEASURED_STEP, SlidingMode
from wmr_mj.analysis.certificate import (
    Compensation,
    Estimate,
    Gains,
    PlantBox,
    PlantLimits,
    certify,
)
from wmr_mj.analysis.claim import ClaimContext
from wmr_mj.analysis.measurement import MeasurementErrors
from wmr_mj.analysis.path_bound import guaranteed_E_max, path_bound
from wmr_mj.analysis.robustness import ParameterBox
from wmr_mj.analysis.verdicts import format_measurement_cause, format_verdict
from wmr_mj.cli.app import main
from wmr_mj.params import C80
from wmr_mj.plant.reduced import SteeringModel
from wmr_mj.reference.bounds import ReferenceBounds
from wmr_mj.sim.closed_loop import judge_path
from wmr_mj.sim.config import build_reference, estimate_parameters

#: The certified design's box and estimate (the numbers of analysis/small_gain.py's usage block).
BOX = ParameterBox(P=(0.385, 0.385), C_V=(4.77, 4.77), F=(1.313, 1.724), K=(-0.02, 0.02))
PLANT = PlantBox(box=BOX, gyro=(0.472, 0.723), V_A=(0.2, 0.2))
ESTIMATE = Estimate(P=0.385, C_V=4.77, F=1.518, K=0.0, gyro=0.629, V_A=0.2)
REFERENCE = ReferenceBounds(alpha_max=0.659, alpha_dot_max=0.23, alpha_ddot_max=0.155)
LIMITS = PlantLimits(steering_range=0.9, voltage_limit=24.0)
T = 0.001  # s, the control period
#: a 12-bit angle on the steering axis, rounded, alpha' differenced: |e_a| <= Delta/2, |e_v| <= Delta/T, and
#: the difference lags by T/2 (hardware guide)
DELTA_12 = 2.0 * math.pi / 4096
ENCODER_12 = MeasurementErrors(alpha_error_max=DELTA_12 / 2, alpha_dot_error_max=DELTA_12 / T, delay_s=T / 2)
#: printed numbers carry 6 significant digits: each part is off by at most half a unit in its 6th digit
PRINT_REL = 5e-6


def _certify(**changes):
    args = dict(plant=PLANT, estimate=ESTIMATE, gains=Gains(kp=100.0, kd=20.0), reference=REFERENCE, limits=LIMITS,
                compensation=Compensation(friction_sign="measured", friction_width=0.01), control_period=T)
    args.update(changes)
    return certify(**args)


def _without(m: MeasurementErrors, field: str) -> MeasurementErrors:
    return dataclasses.replace(m, **{field: 0.0})


# --------------------------------------------------------------------------- 1. the errors assumed, the one that binds
def test_the_cause_is_the_differenced_velocity_and_re_solving_without_it_agrees():
    cert = _certify(measurement=ENCODER_12)
    assert not cert.valid  # today's 12-bit answer: no fixed point
    cause = cert.terms.measurement_cause
    assert (cause.e_a, cause.e_v, cause.tau) == (DELTA_12 / 2, DELTA_12 / T, T / 2)
    assert cause.binding == ("e_v",)
    # by hand: with e_v = 0 the certificate closes at the E_max the cause gives; without e_a or tau it does not
    no_ev = _certify(measurement=_without(ENCODER_12, "alpha_dot_error_max"))
    assert no_ev.valid and dict(cause.E_max_without)["e_v"] == no_ev.E_max
    assert not _certify(measurement=_without(ENCODER_12, "alpha_error_max")).valid
    assert not _certify(measurement=_without(ENCODER_12, "delay_s")).valid
    assert cause.E_max_exact == _certify().E_max  # the ideal cart's certificate
    line = format_measurement_cause(cause)
    assert "|e_v| <= 1.534 rad/s" in line and "tau = 0.0005 s" in line and "fails by e_v:" in line
    assert f"E_max = {no_ev.E_max:.4g} rad" in line


def test_two_errors_that_each_bind_are_both_named():
    late = dataclasses.replace(ENCODER_12, alpha_error_max=DELTA_12 / 8, alpha_dot_error_max=DELTA_12 / 4 / T,
                               delay_s=0.0055)  # a 14-bit encoder and 5 ms more
    cause = _certify(measurement=late).terms.measurement_cause
    for name, field in (("e_v", "alpha_dot_error_max"), ("tau", "delay_s")):
        assert dict(cause.E_max_without)[name] == _certify(measurement=_without(late, field)).E_max
    assert cause.binding == ("e_v", "tau")
    assert "fails by e_v or tau" in format_measurement_cause(cause)


def test_a_certificate_with_a_fixed_point_names_the_errors_and_no_binding_one():
    small = MeasurementErrors(alpha_error_max=1e-4, alpha_dot_error_max=0.01, delay_s=0.0)
    cause = _certify(measurement=small).terms.measurement_cause
    assert cause.binding == () and cause.E_max_exact is None
    assert format_measurement_cause(cause).endswith("tau = 0 s")
    assert _certify().terms.measurement_cause is None  # the law reads the truth: nothing to name


def test_run_prints_and_writes_the_errors_the_claim_assumed(capsys):
    # the paper circle, just past its lead-in and entry (8.09 s), on the 12-bit cart: section 4 has no fixed point
    # there (its binding error is tested by hand above); the claim taken is the sampled-data certificate, which
    # has a bound, so the errors it assumed are printed and none binds
    argv = ["run", "--preset", "certified", "--sensing", "magnetic-12bit-axis", "--duration", "9", "--no-log"]
    assert main([*argv, "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    errors = report["measurement_errors"]
    # the run's bounds carry the sensing's 1e-9 relative pad for the float operations of the step (sensing.py)
    assert errors["e_a"] == pytest.approx(DELTA_12 / 2, rel=2e-9) and errors["e_a"] >= DELTA_12 / 2
    assert errors["e_v"] == pytest.approx(DELTA_12 / T, rel=2e-9) and errors["e_v"] >= DELTA_12 / T
    assert errors["tau"] == T / 2
    assert errors["binding"] == [] and report["certificate"]["inputs"]["certificate"] == "sampled-data"
    section4 = report["certificate"]["inputs"]["certificates"]["section-4"]
    assert not section4["certified"]  # section 4 gives the 12-bit cart no pass (0.376 rad at omega_r 30, uncertified)
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "measurement errors assumed: |e_a| <= 0.000767 rad, |e_v| <= 1.534 rad/s, tau = 0.0005 s\n" in text
    assert "the sampled-data certificate (section 4's: " in text  # section 4's beside it, not taken


def test_an_ideal_run_writes_no_measurement_errors(capsys):
    assert main(["run", "--preset", "certified", "--path", "lane-change", "--duration", "6", "--no-log", "--json"]) == 0
    assert "measurement_errors" not in json.loads(capsys.readouterr().out)


# --------------------------------------------------------------------------- 2. delta1's breakdown adds up
@pytest.mark.parametrize("case", ["ideal", "P box", "disturbance", "12-bit", "encoder, no delay", "14-bit, 5.5 ms",
                                  "no feedforward"])
def test_delta1_parts_add_up_to_delta1(case):
    wide = PlantBox(box=dataclasses.replace(BOX, P=(0.37, 0.40)), gyro=(0.472, 0.723), V_A=(0.2, 0.2),
                    friction_over_P=4.3)
    cert = {
        "ideal": lambda: _certify(),
        "P box": lambda: _certify(plant=wide),
        "disturbance": lambda: _certify(plant=dataclasses.replace(wide, disturbance=0.3, disturbance_over_P=0.8)),
        "12-bit": lambda: _certify(measurement=ENCODER_12),
        "encoder, no delay": lambda: _certify(measurement=MeasurementErrors(1e-4, 0.05, 0.0)),
        "14-bit, 5.5 ms": lambda: _certify(plant=wide, measurement=MeasurementErrors(DELTA_12 / 8, 0.38, 0.0055)),
        "no feedforward": lambda: _certify(estimate=dataclasses.replace(ESTIMATE, F=0.0),
                                           compensation=Compensation(friction_sign="none", feedforward=False)),
    }[case]()
    parts = dict(cert.terms.delta1_parts)
    assert math.isfinite(cert.delta1) and parts
    # a sum of about ten positive terms: a few ulps of delta1
    assert math.fsum(parts.values()) == pytest.approx(cert.delta1, rel=1e-13)
    assert min(parts.values()) >= 0.0


def test_the_measurement_terms_are_in_the_breakdown_the_old_one_left_out():
    cert = _certify(measurement=ENCODER_12, limits=PlantLimits(steering_range=0.9, voltage_limit=24.0))
    parts = dict(cert.terms.delta1_parts)
    # the old line, friction + K~ + gyro + P~ + C_V~ at the ideal friction, missed most of delta1
    old = cert.friction_term + cert.K_term + cert.gyro_term + cert.P_term + cert.C_V_term
    assert old < 0.2 * cert.delta1
    assert parts["velocity error e_v"] > 0.5 * cert.delta1
    assert {"angle error e_a", "delay tau", "delay loop 1/(1 - tau c_v)", "delayed reference"} <= set(parts)


def test_robustness_certificate_prints_and_writes_parts_that_add_up(capsys):
    # section 4's breakdown on the full box (where the old line's terms summed to 5.877 against delta1 5.841);
    # on a sensed cart the claim taken is the sampled-data certificate (below), whose parts are its own
    # (since issue 44 the run takes the sampled-data certificate; section 4's is printed and written beside it)
    argv = ["robustness", "--certificate", "--preset", "certified", "--uncertainty", "full"]
    assert main([*argv, "--json"]) == 0
    taken = json.loads(capsys.readouterr().out)
    out = taken["section_4"]
    assert out["E_max"] == taken["inputs"]["certificates"]["section-4"]["E_max"]  # the record beside the one taken
    assert math.fsum(out["delta1_parts"].values()) == pytest.approx(out["delta1"], rel=1e-13)
    assert main(argv) == 0
    text = capsys.readouterr().out
    row = next(line for line in text.splitlines() if "delta1 (4.18)" in line)
    total, terms = re.search(r"\]\s+(\S+) = (.*) \(every term", row).groups()
    values = [float(v) for v in re.findall(r" (-?[0-9.]+(?:e[-+]?\d+)?)(?= \+|$)", terms)]
    assert len(values) == len(out["delta1_parts"])
    assert math.fsum(values) == pytest.approx(float(total), rel=len(values) * PRINT_REL)


def test_robustness_certificate_names_the_certificate_taken_on_a_sensed_cart(capsys):
    argv = ["robustness", "--certificate", "--preset", "certified", "--sensing", "magnetic-12bit-axis", "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["inputs"]["certificate"] == "sampled-data"
    assert not out["inputs"]["certificates"]["section-4"]["certified"]  # section 4 gives it no pass


# --------------------------------------------------------------------------- 3. no path guarantee without a certificate
def test_a_valid_certificate_whose_assumptions_fail_bounds_no_path():
    cramped = _certify(limits=PlantLimits(steering_range=0.9, voltage_limit=5.0))  # the law needs 8.8 V
    assert cramped.valid and cramped.unmet == ("within the supply",)
    ref, settle = build_reference("paper-circle", estimate_parameters(C80), dt=0.01, duration=20.0)
    # C exactly on its desired path: inside any bound there is
    held = judge_path(ref, ref.t, ref.C_xy, ref.theta, settle_s=settle, certificate=_certify())
    assert held.verdict.verdict == "within-bound" and held.bound.cross_track_bound > 0
    none = judge_path(ref, ref.t, ref.C_xy, ref.theta, settle_s=settle, certificate=cramped)
    assert none.verdict.verdict == "no-guarantee" and none.bound.cross_track_bound is None
    assert "does not hold" in none.verdict.text and "within the supply" in none.bound.reason
    # the number itself would have given a bound: it is the assumptions that take it away
    assert path_bound(ref, cramped.E_max, settle_s=settle).cross_track_bound is not None


def test_guaranteed_E_max():
    assert guaranteed_E_max(E_max=0.05, valid=True, unmet=()) == (0.05, "")
    assert guaranteed_E_max(E_max=None, valid=False, unmet=("reachable angle",)) == (None, "")
    E, why = guaranteed_E_max(E_max=0.05, valid=True, unmet=("within the supply",))
    assert E is None and "within the supply" in why


# --------------------------------------------------------------------------- 4. sliding mode: what moved
def test_sliding_mode_under_a_delay_names_the_step_of_s_not_the_control_period():
    ref, _ = build_reference("paper-circle", estimate_parameters(C80), dt=T, duration=35.0)
    box = ParameterBox(P=(0.385, 0.385), C_V=(4.77, 4.77), F=(1.313, 1.724), K=(-0.02, 0.02))
    ideal = ClaimContext(plant=PlantBox(box=box, gyro=(0.472, 0.723), V_A=(0.2, 0.2)), reference=ref.bounds(),
                         limits=LIMITS, control_period=T, initial_error=(0.0, 0.0), estimate=estimate_parameters(C80))
    late = dataclasses.replace(ideal, measurement=MeasurementErrors(0.0, 0.0, 0.02))
    law = SlidingMode(SteeringModel(P=0.385, C_V=4.77, F=1.518, K=0.0, gyro=0.629, V_A=0.2, name="est"))
    before = {a.name: a for a in law.claim(ideal).assumptions}["control period"]
    after = {a.name: a for a in law.claim(late).assumptions}
    assert "control period" not in after
    step = after[MEASURED_STEP]
    # T (D + k)/(P_min phi): T is the same 1 ms, D is the measured layer's
    D = law.measured_layer(late).D
    assert step.value == pytest.approx(T * (D + law.k) / (0.385 * law.phi), rel=1e-12)
    assert step.value > before.value and "T = 0.001 s" in step.note and f"D = {D:.4g} V" in step.note


# --------------------------------------------------------------------------- 5. "no certificate", not OUTSIDE
def _summary(cert, verdict):
    return {"verdict": verdict, "sup_E": 0.0383, "controller": "computed-torque",
            "certificate": {**cert.to_dict(), "inside": False}, "paper_region": {}}


def test_no_region_reads_no_certificate_and_keeps_the_verdict_name():
    broken = _certify(measurement=ENCODER_12)
    lines = format_verdict(_summary(broken, "uncertified-outside"))
    assert lines[0].startswith("verdict: UNCERTIFIED-OUTSIDE") and "no certificate" in lines[0]
    cert_line = next(line for line in lines if line.startswith("certificate:"))
    assert "no certificate" in cert_line and "OUTSIDE" not in cert_line and "n/a" not in cert_line
    assert "0.0383" in cert_line
    # a region that exists is still judged inside or OUTSIDE
    held = format_verdict(_summary(_certify(), "certified-outside"))
    assert any(line.startswith("certificate:   |E| <= ") and line.endswith("run OUTSIDE") for line in held)
