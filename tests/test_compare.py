"""The versioned suite and `wmr-mj compare`: stable scenario ids, the same numbers as single runs, bad input."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest
from helpers import one_error_line

from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.experiments.compare import compare, design_from_token
from wmr_mj.experiments.suite import SUITES_DIR, load_suite, suite_names
from wmr_mj.sim.closed_loop import run_closed_loop

REPO = Path(__file__).resolve().parents[1]
#: standard-v1 as released: any change to the file must come as a new suite version (standard-v2)
STANDARD_V1_SHA256 = "004a627a34e8"
STANDARD_V1_IDS = [f"{p}/{plant}/{sig}" for p in ("circle", "lane", "eight", "agv", "knots")
                   for plant in ("nominal", "vertex") for sig in ("none", "pulse", "payload")]



def test_the_suite_loads_and_its_ids_are_stable():
    assert "standard-v1" in suite_names()
    suite = load_suite("standard-v1")
    assert (suite.name, suite.version) == ("standard-v1", 1)
    assert [s.id for s in suite.scenarios] == STANDARD_V1_IDS
    # the file itself is pinned: a changed scenario, requirement or adversary makes a new version
    raw = (SUITES_DIR / "standard-v1.toml").read_bytes()
    assert hashlib.sha256(raw).hexdigest()[:12] == suite.sha256[:12] == STANDARD_V1_SHA256
    vertex = suite.scenario("lane/vertex/payload")
    assert vertex.plant_params["m1"] == 750.0 and vertex.signals["loads"][0]["m1"] == 550.0
    assert suite.scenario("circle/nominal/pulse").signals["disturbance"]["amplitude"] == suite.d_max
    assert [s.id for s in suite.select(["circle/*"])] == STANDARD_V1_IDS[:6]
    with pytest.raises(UnknownNameError):
        suite.select(["nowhere/*"])


def test_a_scenario_sets_path_plant_and_signals_on_the_design():
    suite = load_suite("standard-v1")
    design = design_from_token("certified", suite)
    cfg = suite.scenario("agv/vertex/pulse").config(design.config)
    assert cfg.path == "agv-loop" and cfg.m1 == 750.0 and cfg.plant_overrides["V_A"] == 0.25
    assert cfg.signals.disturbance.kind == "pulse" and cfg.signals.d_max == 1.0
    assert cfg.kp == design.config.kp and cfg.box_ranges["V_A"] == (0.15, 0.25)  # the suite's box is declared
    plug = design_from_token("sliding-mode,lam=4,tracker=pure-pursuit", suite).config
    assert plug.controller == "sliding-mode" and plug.controller_params == {"lam": 4}
    assert plug.tracker == "pure-pursuit" and plug.model == "nonholonomic"


@pytest.mark.parametrize("token, error", [
    ("paper,lam=3", ParameterError), ("no-such-law", UnknownNameError), (",k=1", ParameterError),
    ("computed-torque,k=1", ParameterError), ("sliding-mode,nope=1", ParameterError),
    ("certified,tracker=pure-pursuit,lookahead=-1", ParameterError)])
def test_a_bad_design_is_refused(token, error):
    with pytest.raises(error):
        design_from_token(token, load_suite("standard-v1"))


@pytest.mark.slow
def test_compare_gives_the_single_runs_numbers_to_the_bit(tmp_path):
    suite = load_suite("standard-v1")
    example = REPO / "examples" / "my_pid.py"
    designs = [design_from_token("certified", suite), design_from_token(f"{example}:MyPID,ki=10", suite)]
    chosen = ["lane/nominal/none", "circle/vertex/pulse"]
    result = compare(designs, suite, scenarios=chosen, budget=0, nthread=2)
    assert [(r.design, r.scenario) for r in result.runs] == [(d.label, s) for d in designs for s in chosen]
    for r in result.runs:
        design = next(d for d in designs if d.label == r.design)
        single = run_closed_loop(suite.scenario(r.scenario).config(design.config), progress=False)
        s = single.summary.to_dict()
        for key in ("sup_E", "sup_Edot", "verdict", "control_steps"):
            assert r.summary[key] == s[key], (r.design, r.scenario, key)
        assert r.summary["cross_track_max"] == s["path_error"]["cross_track_max"]
        u = single.rows["voltage"]
        assert r.rms_voltage == float((u * u).mean() ** 0.5)
    # the physics steps it counts (its steps per second's numerator): 4 runs of 35 s at the 1 ms step
    assert result.steps == 4 * 35_000 and result.steps_per_s == result.steps / result.wall_s
    rows = {row.label: row for row in result.rows}
    assert rows["certified"].controller == "computed-torque" and rows["certified"].requirements_total == 8
    assert rows[designs[1].label].controller == "my-pid" and rows[designs[1].label].no_claim == 2
    from wmr_mj.report.compare import write_report

    paths = write_report(result, tmp_path)
    md = Path(paths["markdown"]).read_text()
    assert "standard-v1 (version 1" in md and "my-pid" in md and "MuJoCo" in md
    assert json.loads(Path(paths["json"]).read_text())["suite"]["name"] == "standard-v1"


@pytest.mark.parametrize("argv, words", [
    (["compare", "certified", "--suite", "standard-v9"], ["unknown suite", "standard-v1"]),
    (["compare", "no-such-law"], ["unknown controller", "sliding-mode"]),
    (["compare", "certified", "--budget", "2"], ["budget", "below one"]),
    (["compare", "certified", "--scenarios", "moon/*"], ["unknown scenario", "circle/nominal/none"]),
    (["compare", "certified", "certified"], ["named twice"]),
], ids=["suite", "controller", "budget", "scenario", "twice"])
def test_bad_compare_input_is_one_line_and_exit_2(tmp_path, capsys, argv, words):
    out = tmp_path / "out"
    assert main([*argv, "--out", str(out)]) == 2
    line = one_error_line(capsys)
    for w in words:
        assert w in line, line
    assert not out.exists()


@pytest.mark.slow
def test_compare_on_dask_gives_the_local_numbers():
    distributed = pytest.importorskip("distributed")
    suite = load_suite("standard-v1")
    example = REPO / "examples" / "my_pid.py"
    designs = [design_from_token("certified", suite), design_from_token(f"{example}:MyPID", suite)]
    local = compare(designs, suite, scenarios=["lane/nominal/pulse"], budget=0, nthread=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        remote = compare(designs, suite, scenarios=["lane/nominal/pulse"], budget=0,
                         scheduler=cluster.scheduler_address)
    for a, b in zip(local.runs, remote.runs):
        assert (a.design, a.scenario) == (b.design, b.scenario)
        assert a.summary["sup_E"] == b.summary["sup_E"] and a.requirements == b.requirements
        assert a.rms_voltage == b.rms_voltage and a.tv_voltage == b.tv_voltage


# ----------------------------------------------------------------------------- standard-v2: the cart as built
V2_HARDWARE = ("magnetic-12bit", "magnetic-14bit", "incremental-500", "sensing-delay-5ms", "inductance-1.5mH",
               "backlash-2mrad")
STANDARD_V2_IDS = STANDARD_V1_IDS + [f"{p}/nominal/none/{h}" for p in ("circle", "lane") for h in V2_HARDWARE]


def test_standard_v2_is_v1_then_the_cart_as_built_and_v1_stays_pinned():
    from wmr_mj.hardware import Actuation, Sensing, Transmission
    from wmr_mj.params import C80

    v1, v2 = load_suite("standard-v1"), load_suite("standard-v2")
    assert (v2.name, v2.version) == ("standard-v2", 2) and [s.id for s in v2.scenarios] == STANDARD_V2_IDS
    assert v1.sha256[:12] == STANDARD_V1_SHA256 and "hardware" not in v1.to_dict()  # v1's JSON keys as before
    design = design_from_token("certified", v2)
    for a, b in zip(v1.scenarios, v2.scenarios):  # v1's scenarios, unchanged: the same configs to the field
        assert a == b and a.hardware is None
        assert a.config(design.config) == b.config(design.config)
    built = {s.id.rsplit("/", 1)[1]: s for s in v2.scenarios[30:] if s.path == "paper-circle"}
    assert built["magnetic-12bit"].sensing == Sensing.from_spec("magnetic-12bit-axis")
    assert built["incremental-500"].sensing.encoder_side == "motor"
    assert built["sensing-delay-5ms"].sensing == Sensing(delay=0.005)
    # L_a / R_a = 1.5 ms at the nominal R_a (1.0 Ohm): inside the 1-2 ms the suite's comment gives
    assert built["inductance-1.5mH"].actuation.electrical_time_constant(C80.R_a) == pytest.approx(1.5e-3)
    assert built["backlash-2mrad"].transmission == Transmission(backlash=0.002)
    assert built["backlash-2mrad"].sensing.encoder_side == "motor"  # the play is seen from the motor side
    cfg = built["inductance-1.5mH"].config(design.config)
    assert cfg.actuation == Actuation(inductance=0.0015) and cfg.sensing.is_ideal and cfg.m1 == 650.0
    assert set(v2.to_dict()["hardware"]) == set(STANDARD_V2_IDS[30:])


@pytest.mark.parametrize("table, words", [
    ('[hardware.x]\nsensing = "encoder_ticks=0"\n', ["[hardware.x]", "encoder_ticks"]),
    ('[hardware.x]\nnoise = 1\n', ["[hardware.x] key", "sensing"]),
    ('[hardware.x]\nbacklash = -0.1\n', ["[hardware.x]", "backlash"]),
], ids=["ticks", "key", "backlash"])
def test_a_bad_hardware_table_is_one_line_naming_it(tmp_path, table, words):
    text = (SUITES_DIR / "standard-v2.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("[hardware.magnetic-12bit]", table + "\n[hardware.magnetic-12bit]", 1))
    with pytest.raises((ParameterError, UnknownNameError)) as info:
        load_suite(str(bad))
    message = str(info.value)
    assert "\n" not in message and all(w in message for w in words), message
    bad.write_text(text.replace('hardware = "magnetic-14bit"', 'hardware = "nope"', 1))
    with pytest.raises(UnknownNameError, match="hardware 'nope'"):
        load_suite(str(bad))


@pytest.mark.slow
def test_compare_on_a_sensed_scenario_gives_the_single_runs_numbers():
    suite = load_suite("standard-v2")
    design = design_from_token("certified", suite)
    chosen = ["circle/nominal/none/incremental-500", "lane/nominal/none/backlash-2mrad"]
    result = compare([design], suite, scenarios=chosen, budget=0, nthread=2)
    for r in result.runs:
        single = run_closed_loop(suite.scenario(r.scenario).config(design.config), progress=False)
        assert "alpha_measured" in single.rows  # the law read the encoder
        for key in ("sup_E", "sup_Edot", "verdict"):
            assert r.summary[key] == single.summary.to_dict()[key], (r.scenario, key)
        assert r.summary["verdict"] != "certified-outside"
