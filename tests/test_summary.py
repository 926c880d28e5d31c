"""The typed run summary (wmr_mj.sim.summary): read by attribute, frozen, and its JSON keeps every key
scripts read (run --json, the MCAP summary, runs.csv)."""

from __future__ import annotations

import dataclasses
import json

import pytest

from wmr_mj import C80
from wmr_mj.analysis.measurement import MeasurementErrors
from wmr_mj.sim.certify import certificate_for
from wmr_mj.sim.closed_loop import RunConfig
from wmr_mj.sim.config import build_reference
from wmr_mj.sim.designs import CERTIFIED
from wmr_mj.sim.many_runs import RESULT_COLUMNS, flat_row

# the keys `wmr-mj run --json` wrote before the summary was typed (less "log", which the command adds)
RUN_KEYS = {"E_max", "E_ratio", "Edot_max", "Edot_ratio", "analysis", "certificate", "condition", "control_steps",
            "controller", "controller_config", "drift", "duration", "final_alpha", "inside", "kd", "kp",
            "left_steering_range", "left_steering_range_at_s", "m1", "model", "mujoco_warnings", "paper_region",
            "path", "realtime_factor", "saturated_fraction", "settle_s", "stable", "status", "steps", "sup_E",
            "sup_E_settled", "sup_Edot", "sup_Edot_settled", "verdict", "wall_s"}
# added with C's path errors (wmr_mj.analysis.path_error, path_bound)
PATH_KEYS = {"path_error", "path_bound", "path_verdict"}
# added with the paper's region under names that say so (the unprefixed ones deprecated, kept)
PAPER_KEYS = {"paper_E_max", "paper_Edot_max", "paper_condition", "paper_inside", "paper_E_ratio",
              "paper_Edot_ratio", "deprecated_keys"}
# added with the applied voltage's effort (wmr_mj.sim.summary.VoltageEffort; issue 36)
EFFORT_KEYS = {"peak_voltage", "rms_voltage", "tv_voltage"}
# every claim's keys (the Interface's and the claim's own bounds), whichever claimant's
CLAIM_KEYS = {"E_max", "Edot_max", "alpha_max", "assumptions", "certified", "inputs", "iterations", "reason", "unmet",
              "valid", "vertices", "voltage_max"}
# the run's judgement of the claim it is judged by (the summary's certificate)
JUDGEMENT_KEYS = {"E_ratio", "Edot_ratio", "inside", "region_ratio", "sup_E", "sup_Edot", "verdict"}
# section 4's own (its region's (4.23) and gains, its terms and regime): written by section 4's certificate only
SECTION_4_KEYS = {"C_V_term", "K_term", "P_term", "condition", "dead_band", "delta1", "delta2", "delta3",
                  "friction_sign", "friction_term", "friction_width", "gamma1", "gamma2", "gyro_Edot_term",
                  "gyro_term", "kd", "kp", "regime"}
# a box claim's (the sampled-data certificate's): its region's kind and whose claim it is
BOX_CLAIM_KEYS = {"claimant", "region"}
# what the sampled-data certificate rests on (its own, then the run's record and the second opinion beside it)
SAMPLED_DATA_INPUT_KEYS = {"certificate", "control_period", "kp", "kd", "c_hat", "friction_sign", "cart", "reference",
                           "terms", "certificates", "model", "controller", "box_rule", "m1_range", "box_ranges",
                           "plant_m1", "notes", "steering_friction"}
SAMPLED_DATA_TERM_KEYS = {"gain_E_w", "gain_Edot_w", "gain_u_w", "gain_E_angle", "gain_E_velocity", "angle_channel",
                          "velocity_channel", "initial_transient_E", "friction_term", "P_term", "feedforward_hold_term",
                          "C_V_term", "K_term", "gyro_term", "disturbance_term", "delta_u", "k_y", "k_A", "loop_gain",
                          "W", "U", "spectral_radius"}


@pytest.fixture(scope="module")
def summary(certified_run_10s):
    config = RunConfig.from_inputs(model="nonholonomic", kp=CERTIFIED.kp, kd=CERTIFIED.kd, friction_width=0.01,
                                   duration=10.0)
    assert certified_run_10s.config == config  # the certified design, 10 s: the session's run
    return certified_run_10s.summary


def test_the_json_keeps_every_key(summary, certified_run_10s):
    d = summary.to_dict()
    assert set(d) == RUN_KEYS | PATH_KEYS | PAPER_KEYS | EFFORT_KEYS  # new keys added: every key before is kept
    # the run is judged by the sampled-data certificate (issue 44 item 1), which writes its own keys only
    assert d["certificate"]["claimant"] == "sampled-data"
    assert set(d["certificate"]) == CLAIM_KEYS | JUDGEMENT_KEYS | BOX_CLAIM_KEYS
    assert set(d["certificate"]["inputs"]) == SAMPLED_DATA_INPUT_KEYS
    assert set(d["certificate"]["inputs"]["terms"]) == SAMPLED_DATA_TERM_KEYS
    assert set(d["certificate"]["inputs"]["certificates"]) == {"section-4", "sampled-data"}  # the second opinion
    # section 4's certificate of the same run (the what-if 'exact measurement': the law's continuous claim alone)
    # keeps every key it wrote
    config = certified_run_10s.config
    reference = build_reference(config.path, C80, dt=1e-3, duration=config.duration)[0]
    section_4 = certificate_for(config, reference, measurement=MeasurementErrors.exact())
    assert set(section_4.to_dict()) == CLAIM_KEYS | SECTION_4_KEYS
    assert set(d["paper_region"]) == {"E_max", "Edot_max", "condition", "inside"}
    assert set(d["drift"]) == {"final_alpha_dot", "growing", "E_last_window", "E_prev_window", "window_s",
                               "tolerance"}
    assert set(RESULT_COLUMNS) - {"run"} <= set(flat_row(d))  # every runs.csv column
    json.dumps(d, default=float)


def test_one_quantity_one_value_by_attribute_and_in_the_json(summary):
    d = summary.to_dict()
    assert summary.certificate.E_ratio == d["certificate"]["E_ratio"] == flat_row(d)["cert_E_ratio"]
    assert summary.sup_E / summary.certificate.E_max == pytest.approx(summary.certificate.E_ratio)
    assert summary.E_max == summary.paper_region.E_max == d["E_max"] == d["paper_region"]["E_max"] == d["paper_E_max"]
    assert summary.verdict == summary.certificate.verdict == d["verdict"] == d["certificate"]["verdict"]
    assert summary.drift.growing is d["drift"]["growing"]
    assert summary.left_steering_range is (summary.left_steering_range_at_s is not None)


def test_frozen(summary):
    with pytest.raises(dataclasses.FrozenInstanceError):
        summary.sup_E = 0.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        summary.certificate.verdict = "certified-inside"
