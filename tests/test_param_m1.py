"""``--param m1=KG`` is ``--m1 KG`` wherever ``--m1`` is an option, and MuJoCo's warnings are counted and said once
(issue 42, item 5).

Before: ``wmr-mj run --param m1=700`` and ``sweep --param m1=700`` ended in a traceback (``with_params() got
multiple values for keyword argument 'm1'``), and a run MuJoCo warned of printed MuJoCo's "WARNING: ..." on the
console and could still be judged certified. The truth each test holds to is the run given ``--m1``: the same
mass by the other option is the same run, to the bit.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from helpers import refused_line

from wmr_mj.cli.app import main
from wmr_mj.sim.closed_loop import MUJOCO_WITHOUT_WARNINGS, with_mujoco_warnings
from wmr_mj.sim.config import RunConfig, coerce, plant_parameters
from wmr_mj.sim.parts import resolve_run

RUN = ["run", "--no-log", "--json", "--duration", "10"]


def _json_of(capsys, argv: list[str]) -> dict:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_run_param_m1_is_the_run_of_m1(capsys):
    by_param = _json_of(capsys, [*RUN, "--param", "m1=700"])
    by_option = _json_of(capsys, [*RUN, "--m1", "700"])
    assert by_param["m1"] == 700.0
    for key in ("sup_E", "sup_Edot", "verdict", "final_alpha"):
        assert by_param[key] == by_option[key], key


def test_the_same_mass_twice_is_accepted_and_two_masses_are_refused_in_one_line(capsys):
    assert _json_of(capsys, [*RUN, "--m1", "700", "--param", "m1=700"])["m1"] == 700.0
    line = refused_line(capsys, [*RUN, "--m1", "600", "--param", "m1=700"])
    assert "--m1" in line and "--param m1=" in line and "600" in line and "700" in line


def test_sweep_param_m1_fixes_every_run_as_sweep_m1_does(tmp_path, capsys):
    common = ["sweep", "--n", "2", "--duration", "10", "--json"]
    by_param = _json_of(capsys, [*common, "--param", "m1=700", "--out", str(tmp_path / "a")])
    by_option = _json_of(capsys, [*common, "--m1", "700", "--out", str(tmp_path / "b")])
    assert by_param["fixed_m1"] == by_option["fixed_m1"] == 700.0
    assert by_param["verdicts"] == by_option["verdicts"]


def test_falsify_param_m1_fixes_the_mass_as_falsify_m1_does(tmp_path, capsys):
    """falsify's --m1 fixes every run's m1 (the other axes searched alone): --param m1= the same search, to the bit."""
    common = ["falsify", "--range", "R_a=1.0:1.3", "--budget", "8", "--duration", "10", "--objective", "sup-E",
              "--json"]
    by_param = _json_of(capsys, [*common, "--param", "m1=700", "--out", str(tmp_path / "a")])
    by_option = _json_of(capsys, [*common, "--m1", "700", "--out", str(tmp_path / "b")])
    assert "m1" not in by_param["worst"]["params"]  # not searched: fixed
    assert by_param["worst"] == by_option["worst"]


def test_identify_param_m1_is_identify_m1(capsys):
    common = ["identify", "--duration", "5", "--json"]
    by_param = _json_of(capsys, [*common, "--param", "m1=700"])
    assert by_param == _json_of(capsys, [*common, "--m1", "700"]) and by_param["m1"] == 700.0


def test_a_run_config_takes_an_override_of_m1_as_its_m1():
    config = RunConfig(plant_overrides={"m1": 700.0, "mu": 0.02})
    assert config.m1 == 700.0 and dict(config.plant_overrides) == {"mu": 0.02}
    assert plant_parameters(coerce(config)).m1 == 700.0
    assert resolve_run(config.replace(duration=10.0)).plant.m1 == 700.0
    with pytest.raises(Exception, match="two masses"):
        RunConfig(m1=600.0, plant_overrides={"m1": 700.0})


def test_a_run_mujoco_warned_of_says_so_once_and_is_not_certified():
    # m1 = 1e9 kg: MuJoCo warns (a huge acceleration) part-way; run as a new process so that MuJoCo's own
    # console printing, which is C's, would be seen
    out = subprocess.run([sys.executable, "-m", "wmr_mj.cli", *RUN[:-2], "--duration", "10", "--param", "m1=1e9"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "WARNING:" not in out.stdout + out.stderr
    summary = json.loads(out.stdout)
    assert summary["mujoco_warnings"] >= 1
    unmet = [a for a in summary["certificate"]["assumptions"] if a["name"] == MUJOCO_WITHOUT_WARNINGS]
    assert len(unmet) == 1 and unmet[0]["met"] is False and "QACC" in unmet[0]["note"]
    assert not summary["verdict"].startswith("certified")
    text = subprocess.run([sys.executable, "-m", "wmr_mj.cli", *[a for a in RUN if a != "--json"],
                           "--param", "m1=1e9"], capture_output=True, text=True, timeout=300)
    said = [line for line in (text.stdout + text.stderr).splitlines() if line.startswith("MuJoCo warned")]
    assert len(said) == 1 and "not certified" in said[0]


def test_a_certified_claim_with_a_warning_is_no_longer_certified():
    parts = resolve_run(RunConfig.from_inputs(duration=10.0, kp=100.0, kd=20.0, model="nonholonomic"))
    claim = parts.claim
    assert claim is not None and claim.certified  # the certified design (docs/guides: --preset certified)
    warned = with_mujoco_warnings(claim, 3, "Nan, Inf or huge value in QACC at DOF 0.")
    assert not warned.certified and MUJOCO_WITHOUT_WARNINGS in warned.unmet
    assert warned.verdict(0.0, 0.0) == "uncertified-inside"
