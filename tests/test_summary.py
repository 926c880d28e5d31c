"""The typed run summary (wmr_mj.sim.summary): read by attribute, frozen, and its JSON keeps every key
scripts read (run --json, the MCAP summary, runs.csv)."""

from __future__ import annotations

import dataclasses
import json

import pytest

from wmr_mj.sim.closed_loop import RunConfig
from wmr_mj.sim.sweep import RESULT_COLUMNS, flat_row

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
CERTIFICATE_KEYS = {"C_V_term", "E_max", "E_ratio", "Edot_max", "Edot_ratio", "K_term", "P_term", "alpha_max",
                    "assumptions", "certified", "condition", "dead_band", "delta1", "delta2", "delta3",
                    "friction_sign", "friction_term", "friction_width", "gamma1", "gamma2", "gyro_Edot_term",
                    "gyro_term", "inputs", "inside", "iterations", "kd", "kp", "reason", "regime", "region_ratio",
                    "sup_E", "sup_Edot", "unmet", "valid", "verdict", "vertices", "voltage_max"}


@pytest.fixture(scope="module")
def summary(certified_run_10s):
    config = RunConfig.from_inputs(model="nonholonomic", kp=100.0, kd=20.0, friction_width=0.01, duration=10.0)
    assert certified_run_10s.config == config  # the certified design, 10 s: the session's run
    return certified_run_10s.summary


def test_the_json_keeps_every_key(summary):
    d = summary.to_dict()
    assert set(d) == RUN_KEYS | PATH_KEYS | PAPER_KEYS | EFFORT_KEYS  # new keys added: every key before is kept
    assert set(d["certificate"]) == CERTIFICATE_KEYS
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
