"""A researcher's own steering law: found by name, file, module or entry point; run through run, sweep,
falsify, --require, the log and replay --verify, named as itself; bad plug-ins refused in one line."""

from __future__ import annotations

import json
import math
import shutil
from importlib.metadata import EntryPoint
from pathlib import Path

import numpy as np
import pytest
from helpers import one_error_line

from controllers.registry import PluginSource, parse_params, resolve
from wmr_mj.analysis.verdicts import NO_CLAIM, is_pass
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig, config_from_dict, controller_for, estimate_parameters

REPO = Path(__file__).resolve().parents[1]
EXAMPLE = REPO / "examples" / "my_pid.py"

LAW = '''
from controllers import SteeringController

class Law(SteeringController):
    name = "tmp-law"
    def __init__(self, k=50.0):
        self.k = float(k)
    def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        return 0.385 * (alpha0_ddot + 15.0 * (alpha0_dot - alpha_dot) + self.k * (alpha0 - alpha))
    def describe(self):
        return {"controller": self.name, "k": self.k}

class Raises(Law):
    name = "raises"
    def step(self, t, *state):
        if t >= 0.5:
            raise RuntimeError("gain table exhausted")
        return super().step(t, *state)

class TwoVoltages(Law):
    name = "two-voltages"
    def voltage_scalar(self, *state):
        return [1.0, 2.0]

class NoLaw(SteeringController):
    name = "no-law"

class NotALaw:
    pass
'''


@pytest.fixture
def law_file(tmp_path):
    path = tmp_path / "law.py"
    path.write_text(LAW)
    return path



# --------------------------------------------------------------------------- finding a law
def test_a_file_a_module_and_an_entry_point_give_the_same_class(law_file, monkeypatch):
    cls, source = resolve(f"{law_file}:Law", {"k": 40.0})
    assert cls.name == "tmp-law" and source.origin == "file" and source.params == {"k": 40.0}
    assert source.import_path == f"{law_file.resolve()}:Law" and len(source.source_sha256) == 64
    monkeypatch.syspath_prepend(str(law_file.parent))
    by_module, from_module = resolve("law:Law")
    assert by_module.name == "tmp-law" and from_module.origin == "module"
    entry = EntryPoint(name="tmp-law", value="law:Law", group="wmr_mj.controllers")
    monkeypatch.setattr("controllers.registry.entry_points", lambda group: [entry] if group == entry.group else [])
    by_entry, from_entry = resolve("tmp-law")
    assert by_entry is by_module and from_entry.origin == "entry-point"
    from controllers.registry import controller_names

    assert "tmp-law" in controller_names()


def test_parameters_are_read_as_json_where_they_parse():
    assert parse_params(["k=2.5", "name=fast", "on=true", "gains=[1, 2]"]) == {
        "k": 2.5, "name": "fast", "on": True, "gains": [1, 2]}
    for bad in (["k"], ["=1"], ["2k=1"], ["k=1", "k=2"]):
        with pytest.raises(ParameterError):
            parse_params(bad)


@pytest.mark.parametrize("spec, words", [
    ("{dir}/missing.py:Law", ["does not exist"]),
    ("{file}:Missing", ["no class 'Missing'", "Law"]),
    ("{file}:NoLaw", ["defines none of voltage_scalar, voltage, step"]),
    ("{file}:NotALaw", ["not a steering law", "SteeringController"]),
    ("{file}", ["name the class too"]),
    ("no_such_module_xyz:Law", ["cannot be imported"]),
    ("sliding-modes", ["unknown controller", "computed-torque"]),
], ids=["missing-file", "missing-class", "no-method", "not-a-law", "no-class-given", "missing-module", "unknown-name"])
def test_a_bad_plug_in_is_one_line_and_exit_2_before_any_run(law_file, tmp_path, capsys, spec, words):
    spec = spec.format(dir=tmp_path, file=law_file)
    out = tmp_path / "out.mcap"
    assert main(["run", "--controller", spec, "--duration", "10", "--out", str(out)]) == 2
    line = one_error_line(capsys)
    for w in words:
        assert w in line, line
    assert not out.exists()  # refused before any run


@pytest.mark.parametrize("param, words", [
    ("kk=3", ["does not take these parameters", "accepted: k"]),
    ("k", ["NAME=VALUE"]),
])
def test_a_bad_controller_param_is_one_line(law_file, capsys, param, words):
    assert main(["run", "--controller", f"{law_file}:Law", "--controller-param", param, "--duration", "10",
                 "--no-log"]) == 2
    line = one_error_line(capsys)
    for w in words:
        assert w in line, line


def test_params_for_a_built_in_configured_by_fields_are_refused():
    with pytest.raises(ParameterError, match="RunConfig fields"):
        RunConfig(controller="computed-torque", controller_params={"kp": 5})
    with pytest.raises(UnknownNameError):  # a name read where it is coerced (an entry point is looked up)
        RunConfig.from_inputs(controller="no-such-law")
    with pytest.raises(ParameterError, match="not accepted"):
        RunConfig(controller=42)


# --------------------------------------------------------------------------- a law as an object
def test_an_object_and_a_factory_run_as_themselves_and_each_run_gets_its_own_copy(law_file):
    cls, _ = resolve(f"{law_file}:Law")
    law = cls(k=60.0)
    config = RunConfig(controller=law, duration=10.0)
    by_object = run_closed_loop(config, progress=False)
    by_name = run_closed_loop(RunConfig(controller=f"{law_file}:Law", controller_params={"k": 60.0}, duration=10.0),
                              progress=False)
    by_factory = run_closed_loop(RunConfig(controller=lambda: cls(k=60.0), duration=10.0), progress=False)
    for r in (by_object, by_name, by_factory):
        assert r.summary.controller == "tmp-law" and r.summary.verdict == NO_CLAIM and r.law == "python"
        assert r.rows["voltage"].tobytes() == by_name.rows["voltage"].tobytes()
    assert controller_for(config, estimate_parameters()) is not law  # a fresh copy: no state shared between runs
    d = config.to_dict()
    assert d["controller"] == "tmp-law" and d["controller_plugin"]["origin"] == "instance"
    with pytest.raises(ParameterError, match="given as an object"):
        config_from_dict(d)


def test_a_law_without_a_claim_is_never_a_pass(law_file):
    s = run_closed_loop(RunConfig(controller=f"{law_file}:Law", duration=10.0), progress=False).summary
    assert s.verdict == NO_CLAIM and not is_pass(s.verdict) and s.certificate is None
    d = s.to_dict()
    assert d["verdict"] == NO_CLAIM and d["paper_claim_applies"] is False and d["controller_config"]["k"] == 50.0


# --------------------------------------------------------------------------- a law that fails mid-run
def test_a_law_that_raises_mid_run_fails_that_run_with_its_message(law_file, tmp_path, capsys):
    log = tmp_path / "raises.mcap"
    code = main(["run", "--controller", f"{law_file}:Raises", "--duration", "10", "--out", str(log), "--json"])
    report = json.loads(capsys.readouterr().out)
    assert code == 1 and report["status"] == "failed" and report["verdict"] == "failed"
    assert "raises" in report["failure"] and "gain table exhausted" in report["failure"] and "t = 0.5" in report[
        "failure"]
    assert report["control_steps"] == 500  # the steps before the failing one: nothing lost
    from wmr_mj.logs.reader import load_log

    read = load_log(log)
    assert len(read.state["t"]) == 500 and read.summary["status"] == "failed"  # the log holds them, readable


def test_a_law_that_fails_at_its_first_step_is_one_line_and_exit_2(law_file, capsys):
    from wmr_mj.sim.engine import ControllerFailure

    with pytest.raises(ControllerFailure, match="one voltage"):  # nothing simulated: nothing to judge
        run_closed_loop(RunConfig(controller=f"{law_file}:TwoVoltages", duration=10.0), progress=False)
    assert main(["run", "--controller", f"{law_file}:TwoVoltages", "--duration", "10", "--no-log"]) == 2
    line = one_error_line(capsys)
    assert "'two-voltages' returned list" in line and "t = 0 s" in line, line


# --------------------------------------------------------------------------- the example through every command
@pytest.mark.slow
def test_the_example_plug_in_through_run_sweep_falsify_require_and_replay(tmp_path, capsys, monkeypatch):
    example = tmp_path / "my_pid.py"
    shutil.copy(EXAMPLE, example)
    monkeypatch.chdir(tmp_path)
    spec = "my_pid.py:MyPID"
    log = tmp_path / "pid.mcap"
    assert main(["run", "--controller", spec, "--controller-param", "ki=20", "--duration", "10", "--out", str(log),
                 "--require", "always(abs(E) <= 0.2)", "--json"]) == 0
    run = json.loads(capsys.readouterr().out)
    assert run["controller"] == "my-pid" and run["verdict"] == NO_CLAIM
    assert run["requirements"][0]["satisfied"] is True and run["controller_config"]["ki"] == 20.0
    # the log records the law: name, import path, parameters, the source's hash
    from wmr_mj.logs.reader import load_log

    plugin = load_log(log).config["controller_plugin"]
    assert plugin["name"] == "my-pid" and plugin["params"] == {"ki": 20}
    assert plugin["import_path"] == f"{example.resolve()}:MyPID" and len(plugin["source_sha256"]) == 64
    assert main(["replay", str(log), "--verify"]) == 0
    out = capsys.readouterr().out
    assert "controller 'my-pid' re-run: the voltages it applied are bit-identical" in out
    # a sweep with a requirement, named as the law
    sweep_dir = tmp_path / "sweep"
    assert main(["sweep", "--controller", spec, "--controller-param", "ki=20", "--n", "2", "--duration", "10",
                 "--out", str(sweep_dir), "--require", "always(abs(E) <= 0.2)"]) == 0
    text = capsys.readouterr().out
    assert "controller my-pid (kp = 100, kd = 20, ki = 20" in text and "no-claim 2" in text
    assert "paper's claim: not applicable" in text
    # the same folder with another law is refused, not resumed
    assert main(["sweep", "--controller", spec, "--controller-param", "ki=30", "--n", "2", "--duration", "10",
                 "--out", str(sweep_dir)]) == 2
    assert "holds the runs of another controller" in one_error_line(capsys)
    # falsify: the certificate's ratio says nothing of a law without a claim; a requirement does
    assert main(["falsify", "--controller", spec, "--budget", "8", "--duration", "10", "--out",
                 str(tmp_path / "f0")]) == 2
    assert "states no claim" in one_error_line(capsys)
    assert main(["falsify", "--controller", spec, "--controller-param", "ki=20", "--budget", "8", "--duration", "10",
                 "--out", str(tmp_path / "f1"), "--require", "always[5,10](abs(E) <= 0.01)", "--json"]) == 3
    fals = json.loads(capsys.readouterr().out)  # exit 3: the requirement falsified (sup|E| > 0.01 rad)
    assert fals["worst"]["verdict"] == NO_CLAIM and fals["falsified"] is True and fals["worst"]["sup_E"] > 0.01
    assert main(["replay", str(tmp_path / "f1" / "worst.mcap"), "--verify"]) == 0
    capsys.readouterr()
    # a changed source: replay refuses it in one line, before importing it (tests/test_replay_trust.py)
    example.write_text(example.read_text() + "\n# changed\n")
    assert main(["replay", str(log), "--verify"]) == 2
    line = one_error_line(capsys)
    assert str(example.resolve()) in line and "has changed since it ran" in line and "SHA-256" in line


def test_a_recorded_plug_in_is_found_again_from_another_folder(law_file, tmp_path, monkeypatch):
    monkeypatch.chdir(law_file.parent)
    config = RunConfig(controller="law.py:Law", controller_params={"k": 30.0}, duration=10.0)
    d = json.loads(json.dumps(config.to_dict()))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    again = config_from_dict(d)  # law.py is not here: the record's absolute path finds it
    assert again.controller == f"{law_file.resolve()}:Law" and again.controller_params == {"k": 30.0}


def test_plugin_source_is_json():
    s = PluginSource(spec="a.py:B", name="b", origin="file", import_path="/x/a.py:B", params={"k": 1.0},
                     source_sha256="0" * 64)
    assert json.loads(json.dumps(s.to_dict())) == s.to_dict()


def test_a_stateful_law_is_reset_before_every_run(tmp_path):
    from importlib import util

    spec = util.spec_from_file_location("my_pid_example", EXAMPLE)
    module = util.module_from_spec(spec)
    spec.loader.exec_module(module)
    law = module.MyPID(ki=50.0)
    config = RunConfig(controller=law, duration=10.0)
    first = run_closed_loop(config, progress=False)
    second = run_closed_loop(config, progress=False)
    assert first.rows["voltage"].tobytes() == second.rows["voltage"].tobytes()
    # the integral is the law's state: with ki > 0 the law differs from ki = 0 once E has been integrated
    plain = run_closed_loop(config.replace(controller=module.MyPID(ki=0.0)), progress=False)
    assert not np.array_equal(first.rows["voltage"], plain.rows["voltage"])
    assert math.isfinite(first.summary.sup_E)


TRACKER = '''
from controllers.tracking import StanleyAtC

class GentleStanley(StanleyAtC):
    name = "gentle-stanley"
    def __init__(self, k_e=2.0):
        super().__init__(k_e=k_e)
'''


@pytest.mark.slow
def test_a_tracker_of_ones_own_runs_named_as_itself_and_replays(tmp_path, capsys):
    path = tmp_path / "tracker.py"
    path.write_text(TRACKER)
    log = tmp_path / "tracked.mcap"
    assert main(["run", "--preset", "certified", "--tracker", f"{path}:GentleStanley", "--tracker-param", "k_e=3",
                 "--path", "lane-change", "--duration", "10", "--out", str(log), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["correction"]["law"] == "gentle-stanley" and report["correction"]["k_e"] == 3.0
    measured = [a for a in report["certificate"]["assumptions"] if a["name"] == "tracker within its declared bounds"]
    assert measured and measured[0]["kind"] == "checked" and "gentle-stanley" in measured[0]["note"]
    from wmr_mj.logs.reader import load_log

    plugin = load_log(log).config["tracker_plugin"]
    assert plugin["name"] == "gentle-stanley" and plugin["params"] == {"k_e": 3} and plugin["origin"] == "file"
    assert main(["replay", str(log), "--verify"]) == 0
    assert "bit-identical at all 10000 control steps" in capsys.readouterr().out
    # a bad tracker parameter: one line, exit 2, before any run
    assert main(["run", "--tracker", f"{path}:GentleStanley", "--tracker-param", "k_x=1", "--duration", "10",
                 "--no-log"]) == 2
    line = one_error_line(capsys)
    assert "tracker" in line and "accepted: k_e" in line
