"""The cart through the commands: --sensing, --actuation, --backlash on run, sweep, falsify, compare, validate and
robustness --certificate; the cart in every summary; the cart's axes of sweep --range and falsify; bad values as
one line and exit status 2."""

from __future__ import annotations

import csv
import json
import math

import pytest
from helpers import one_error_line

from wmr_mj.analysis.measurement import MEASUREMENT_COVERED
from wmr_mj.analysis.verdicts import format_unmet, unmet_assumptions
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware import Sensing
from wmr_mj.searches.search_space import HARDWARE_AXES, config_for, with_hardware
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.designs import design_changes

#: a short run: the lane change reaches its manoeuvre in 6 s
SHORT = ["--preset", "certified", "--path", "lane-change", "--duration", "6"]


def _json(capsys) -> dict:
    return json.loads(capsys.readouterr().out)


def test_run_with_a_preset_reports_its_sensing_and_runs_the_same_config(capsys):
    assert main(["run", *SHORT, "--no-log", "--json", "--sensing", "magnetic-12bit-axis"]) == 0
    report = _json(capsys)
    # the preset's spec, written in presets.py: 4096 ticks on the axis, rounded, alpha' differenced
    assert report["sensing"] == {"encoder_ticks": 4096, "encoder_side": "axis", "encoder_rounding": "round",
                                 "velocity": "difference", "filter_tau": None, "noise": "none",
                                 "velocity_noise": "none", "delay": 0.0, "seed": 0}
    assert "actuation" not in report and "transmission" not in report  # only the parts that are not ideal
    single = run_closed_loop(RunConfig(**design_changes("certified"), path="lane-change", duration=6.0,
                                       sensing=Sensing(encoder_ticks=4096, velocity="difference")), progress=False)
    assert report["sup_E"] == single.summary.sup_E  # the option is RunConfig's sensing, to the bit


def test_run_with_a_spec_prints_the_cart_line(capsys):
    assert main(["run", *SHORT, "--no-log", "--sensing", "encoder_ticks=1024,velocity=difference,delay=0.005",
                 "--backlash", "0.002"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert ("cart: sensing encoder 1024/rev axis round, alpha' difference, delay 5 ms; actuation ideal; "
            "transmission backlash +-2 mrad") in out


def test_an_ideal_run_keeps_its_keys_and_prints_no_cart(capsys):
    assert main(["run", *SHORT, "--no-log", "--json"]) == 0
    report = _json(capsys)
    assert not {"sensing", "actuation", "transmission"} & set(report)
    assert main(["run", *SHORT, "--no-log"]) == 0
    assert "cart:" not in capsys.readouterr().out


def test_an_uncovered_cart_says_why_where_unmet_assumptions_are_printed(capsys):
    assert main(["run", *SHORT, "--no-log", "--sensing", "noise=gaussian:0.0005,seed=2"]) == 0
    out = capsys.readouterr().out
    line = next(x for x in out.splitlines() if x.startswith("certificate NOT valid"))
    assert MEASUREMENT_COVERED in line and "Gaussian noise has no bound" in line
    # the JSON form carries the note of the cart's assumptions only: the others keep their keys
    cert = {"assumptions": [{"name": MEASUREMENT_COVERED, "met": False, "value": 1.0, "limit": 0.0, "note": "why"},
                            {"name": "within the supply", "met": False, "value": 30.0, "limit": 24.0, "note": "n"}]}
    unmet = unmet_assumptions(cert)
    assert unmet == [{"name": MEASUREMENT_COVERED, "value": 1.0, "limit": 0.0, "note": "why"},
                     {"name": "within the supply", "value": 30.0, "limit": 24.0}]
    assert format_unmet(unmet) == f"{MEASUREMENT_COVERED} (1 vs 0: why); within the supply (30 vs 24)"


@pytest.mark.parametrize("argv, words", [
    (["--sensing", "delay=-0.001"], ["sensing", "delay", "-0.001", ">= 0"]),
    (["--sensing", "encoder_ticks=0"], ["encoder_ticks", "0", ">= 1"]),
    (["--sensing", "colour=red"], ["colour", "encoder_ticks", "velocity"]),
    (["--sensing", "delay=0.0015"], ["0.0015", "0.001 s", "0.002 s"]),
    (["--sensing", "magnetic-13bit"], ["magnetic-13bit", "magnetic-12bit-axis"]),
    (["--backlash", "-1"], ["backlash", "-1", ">= 0"]),
    (["--backlash", "wide"], ["backlash", "wide"]),
    (["--actuation", "inductance=-0.001"], ["inductance", ">= 0"]),
    (["--actuation", "delay=0.0005"], ["actuation delay", "0.0005", "0.001 s"]),
], ids=["negative-delay", "zero-ticks", "unknown-key", "delay-off-grid", "unknown-preset", "negative-backlash",
        "backlash-word", "negative-inductance", "actuation-off-grid"])
def test_bad_cart_is_one_line_and_exit_2(capsys, argv, words):
    assert main(["run", "--duration", "6", "--no-log", *argv]) == 2
    line = one_error_line(capsys)
    assert all(w in line for w in words), line


def test_a_sensing_delay_off_a_coarser_control_period_is_refused(capsys):
    # 3 ms is 1.5 periods of a 2 ms control period: the sensing runs at the law's period
    assert main(["run", "--duration", "6", "--no-log", "--control-period", "0.002", "--sensing", "delay=0.003"]) == 2
    assert "0.003" in one_error_line(capsys)


@pytest.mark.parametrize("argv, words", [
    (["sweep", "--n", "2", "--range", "sensing.colour=0:1"],
     ["sensing.colour", "sensing.delay", "transmission.backlash"]),
    (["sweep", "--n", "2", "--range", "sensing.delay=-0.01:0"], ["sensing.delay", "0 <= LO <= HI"]),
    (["falsify", "--budget", "10", "--range", "transmission.play=0:1"], ["transmission.play",
                                                                        "transmission.backlash"]),
    (["sweep", "--n", "2", "--range", "sensing.filter_tau=0.001:0.01"], ["filter_tau", "velocity=filtered"]),
], ids=["sweep-unknown-axis", "sweep-negative", "falsify-unknown-axis", "filter-without-filtered"])
def test_bad_hardware_axes_are_one_line_and_exit_2(tmp_path, capsys, argv, words):
    assert main([*argv, *SHORT, "--out", str(tmp_path / "out")]) == 2
    line = one_error_line(capsys)
    assert all(w in line for w in words), line


def test_hardware_axes_round_to_what_a_run_can_have():
    base = RunConfig(control_period=0.002)
    cfg = with_hardware(base, {"sensing.delay": 0.0051, "actuation.delay": 0.0026, "sensing.encoder_bits": 11.6,
                               "transmission.backlash": 0.002, "sensing.noise": 0.001})
    assert cfg.sensing.delay == 3 * 0.002  # 2.55 periods of 2 ms -> 3 (nearest)
    assert cfg.actuation.delay == 3 * 0.001  # 2.6 physics steps -> 3
    assert cfg.sensing.encoder_ticks == 4096  # 11.6 bits -> 12 -> 2**12 ticks
    assert (cfg.sensing.noise_kind, cfg.sensing.noise) == ("uniform", 0.001)  # the kind where none was set
    assert cfg.transmission.backlash == 0.002
    assert with_hardware(base, {"sensing.encoder_ticks": 1000.5}).sensing.encoder_ticks == 1000  # ties to even
    gauss = RunConfig(sensing="noise=gaussian:0.0001")
    assert with_hardware(gauss, {"sensing.noise": 0.0003}).sensing.noise_kind == "gaussian"  # the base's kind
    plain = RunConfig.from_inputs(m1=700.0)  # config_for coerces a direct config (wmr_mj.sim.coerce)
    assert config_for(plain, ["m1"], [700.0]) == plain  # no hardware axis: the config as before
    with pytest.raises(UnknownNameError, match="sensing.delay"):
        with_hardware(base, {"sensing.lag": 0.001})
    with pytest.raises(ParameterError, match="current_limit"):
        with_hardware(base, {"actuation.current_limit": 0.0})
    assert "sensing.encoder_bits" in HARDWARE_AXES


def test_sweep_over_the_sensing_delay_records_the_cart_and_the_axis(tmp_path, capsys):
    out = tmp_path / "sweep"
    argv = ["sweep", *SHORT, "--n", "3", "--range", "sensing.delay=0:0.01", "--sensing", "encoder_ticks=4096",
            "--out", str(out)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "cart: sensing encoder 4096/rev axis round, alpha' exact" in printed and "sensing.delay" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["sensing"]["encoder_ticks"] == 4096 and summary["ranges"]["sensing.delay"] == [0.0, 0.01]
    assert set(summary["hardware_axes"]) == {"sensing.delay"}
    rows = list(csv.DictReader((out / "runs.csv").open()))
    assert len(rows) == 3
    for row in rows:
        delay = float(row["sensing.delay"])
        periods = delay / 0.001
        assert 0.0 <= delay <= 0.01 and abs(periods - round(periods)) < 1e-9  # whole 1 ms periods
    # a sensed run goes one by one on the engine; the same config alone gives the same bits (the folder's
    # rows at full precision: runs.csv rounds to 12 digits)
    from wmr_mj.experiments.sweep import read_runs

    row = read_runs(out)[1]
    single = run_closed_loop(RunConfig(**design_changes("certified"), path="lane-change", duration=6.0,
                                       m1=float(row["m1"]), m1_range=(550.0, 750.0),
                                       sensing=Sensing(encoder_ticks=4096, delay=float(row["sensing.delay"]))),
                             progress=False)
    assert float(row["sup_E"]) == single.summary.sup_E


@pytest.mark.slow
def test_falsify_searches_a_hardware_axis_and_reproduces_its_worst(tmp_path, capsys):
    argv = ["falsify", *SHORT, "--uncertainty", "m1", "--range", "sensing.encoder_bits=8:14", "--budget", "10",
            "--json", "--out", str(tmp_path / "f")]
    assert main(argv) in (0, 3)
    summary = _json(capsys)
    assert summary["reproduced"] is True  # the serial re-run of the worst gives the search's bits
    assert set(summary["box"]) == {"m1", "sensing.encoder_bits"}
    bits = summary["worst"]["params"]["sensing.encoder_bits"]
    assert summary["worst"]["sensing"]["encoder_ticks"] == 2 ** round(bits)
    assert "--sensing" in summary["reproduce"] and f"encoder_ticks={2 ** round(bits)}" in summary["reproduce"]
    assert "sensing" not in summary  # the base's cart is ideal
    # every evaluation's sup|E| is a run of its own cart: the search repeated with the same seed, the same bits
    again = tmp_path / "g"
    assert main([*argv[:-1], str(again)]) in (0, 3)
    assert _json(capsys)["worst"] == summary["worst"]


@pytest.mark.slow
def test_compare_runs_every_design_on_the_cart_given(tmp_path, capsys):
    argv = ["compare", "certified", "--scenarios", "lane/nominal/none", "--budget", "0", "--sensing",
            "magnetic-12bit-axis", "--json", "--out", str(tmp_path / "c")]
    assert main(argv) == 0
    result = _json(capsys)
    row = result["rows"][0]
    assert row["cart"] == {"sensing": Sensing.from_spec("magnetic-12bit-axis").to_dict()}
    assert row["uncertified"] == 1  # the claim does not derive a bound for a differenced 12-bit alpha' here
    md = (tmp_path / "c" / "compare.md").read_text()
    assert "Cart of every design" in md and "encoder 4096/rev axis round" in md


def test_robustness_certificate_and_validate_take_the_cart(capsys):
    assert main(["robustness", "--certificate", "--preset", "certified", "--duration", "10", "--sensing",
                 "magnetic-14bit-axis"]) == 0
    assert "cart: sensing encoder 16384/rev axis round, alpha' filtered tau_f 2 ms" in capsys.readouterr().out
    from wmr_mj.report.settings import ValidateSettings
    from wmr_mj.sim.designs import CERTIFIED

    settings = ValidateSettings(sensing="magnetic-12bit-axis", transmission=0.001)
    assert settings.config(CERTIFIED).sensing == Sensing.from_spec("magnetic-12bit-axis")
    assert settings.config(CERTIFIED).transmission.backlash == 0.001
    assert settings.to_dict()["sensing"]["encoder_ticks"] == 4096 and "actuation" not in settings.to_dict()
    assert not {"sensing", "actuation", "transmission"} & set(ValidateSettings().to_dict())
    assert main(["validate", "--n", "1", "--sensing", "delay=0.0007"]) == 2
    assert "0.0007" in one_error_line(capsys)
    assert math.isclose(Sensing.from_spec("delay=0.002").delay, 0.002)


def test_validate_s_report_names_a_built_cart_and_keeps_today_s_line():
    """The report's settings line (index.md, the console) names the cart where one part is not ideal, from the
    settings' own record; today's plant keeps the line it had."""
    from wmr_mj.report.settings import ValidateSettings
    from wmr_mj.report.text import _settings_line

    ideal = _settings_line({"settings": ValidateSettings().to_dict()})
    built = _settings_line({"settings": ValidateSettings(sensing="magnetic-12bit-axis", transmission=0.002).to_dict()})
    assert "cart" not in ideal and built.startswith(ideal)
    assert built[len(ideal):] == ("; cart: sensing " + Sensing.from_spec("magnetic-12bit-axis").label()
                                  + ", transmission backlash +-2 mrad")
