"""``wmr-mj design`` (issue 35 item 4): the gains a given cart can certify, its file read back by ``run --design``.

The truth each test checks against is independent of the search: the certificate ``resolve_run`` computes for a
RunConfig built by hand (the run's own pieces), the certified preset's certificate on the same cart, the exit
status and one line of the command.
"""

from __future__ import annotations

import json
import math

import pytest

from wmr_mj.cli.app import main

CART = "magnetic-12bit-axis"
BUDGET = "120"  # certificate evaluations: a design in a few seconds (the search's quality is the bench's)


@pytest.fixture(scope="module")
def designed(tmp_path_factory):
    """The design for the 12-bit axis encoder, its file and the command's JSON."""
    out = tmp_path_factory.mktemp("design") / "design.json"
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["design", "--sensing", CART, "--budget", BUDGET, "--out", str(out), "--json"])
    return rc, out, json.loads(buf.getvalue())


def _run_json(capsys, argv):
    capsys.readouterr()
    rc = main(argv)
    return rc, json.loads(capsys.readouterr().out)


def test_design_certifies_the_12bit_cart_and_run_reads_it_back(designed, capsys):
    rc, out, printed = designed
    assert rc == 0 and printed["certified"] is True
    assert printed["run"] == f"wmr-mj run --design {out}"  # the default box and path: nothing more to give
    rc, run = _run_json(capsys, ["run", "--design", str(out), "--m1", "750", "--no-log", "--json"])
    # the run's certificate is the one design printed, to the bit (the same function on the same parts)
    assert run["certificate"]["E_max"] == printed["E_max"] == printed["certificates"]["paper-circle"]["E_max"]
    assert run["verdict"] == "certified-inside"
    assert run["kp"] == printed["settings"]["kp"] and run["kd"] == printed["settings"]["kd"]


def test_design_file_round_trip_is_the_same_config(designed):
    """run --design FILE builds the RunConfig the design's settings give, field by field."""
    import argparse

    from wmr_mj.cli.run import config_from_args
    from wmr_mj.cli.run_options import add_options
    from wmr_mj.hardware import Sensing
    from wmr_mj.sim.config import RunConfig

    _, out, printed = designed
    p = argparse.ArgumentParser()
    add_options(p, "run")
    add_options(p, "cart")
    config = config_from_args(p.parse_args(["--design", str(out)]))
    s = printed["settings"]
    expected = RunConfig.from_inputs(controller="computed-torque", model=s["model"], kp=s["kp"], kd=s["kd"],
                                     friction_sign=s["friction_sign"], friction_width=s["friction_width"],
                                     control_period=s["control_period"], sensing=Sensing.from_spec(CART))
    for name in ("controller", "model", "kp", "kd", "friction_sign", "friction_width", "control_period",
                 "sensing", "actuation", "transmission"):
        assert getattr(config, name) == getattr(expected, name), name
    # an explicit option overrides the file, as it overrides a preset
    assert config_from_args(p.parse_args(["--design", str(out), "--kp", "50"])).kp == 50.0


def test_design_beats_or_equals_the_certified_preset_on_the_cart(designed):
    from wmr_mj.hardware import Sensing
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED
    from wmr_mj.sim.parts import resolve_run

    _, _, printed = designed
    preset = resolve_run(RunConfig(**CERTIFIED.config_changes(), control_period=0.001,
                                   sensing=Sensing.from_spec(CART))).claim
    assert preset.certified  # the sampled-data certificate's 0.0463 rad at omega_r 30 (docs/guides/hardware.md)
    assert printed["E_max"] <= preset.E_max


@pytest.mark.parametrize("method", ["cma", "de"])
def test_same_seed_same_design(method):
    from wmr_mj.hardware import Sensing
    from wmr_mj.searches.design_search import DesignProblem, search_design
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED

    problem = DesignProblem(base=RunConfig(**CERTIFIED.config_changes(), sensing=Sensing.from_spec(CART)),
                            budget=40, seed=3, method=method)
    a, b = search_design(problem), search_design(problem)
    assert a.settings == b.settings and a.score == b.score


def test_nothing_certifies_names_the_binding_assumption(tmp_path, capsys):
    # an 8-bit axis encoder, differenced: every point the search tries needs more than the supply
    rc = main(["design", "--sensing", "encoder_ticks=256,velocity=difference", "--budget", "40",
               "--out", str(tmp_path / "d.json")])
    line = capsys.readouterr().out.strip()
    assert rc == 1
    assert line.startswith("no gains in the box certify this cart: the assumption ") and " binds" in line
    data = json.loads((tmp_path / "d.json").read_text())
    assert data["certified"] is False and data["binding"] in line


@pytest.mark.parametrize(("argv", "culprit"), [
    (["--m1-range", "750", "550"], "--m1-range 750 550 is an empty box"),
    (["--range", "R_a=1.3:1.0"], "the range of R_a is empty or inverted"),
    (["--periods", "0.001,0.0015"], "--periods: 0.0015 s is not a whole number"),
    (["--periods", "0.004", "--duration", "35.002"], "does not divide the run"),
    (["--objective", "speed"],
     "--objective 'speed' is not accepted; one of E_max, voltage, margin, E_max-then-voltage"),
    (["--sensing", "noise=gaussian:0.001"], "Gaussian noise has no bound: no certificate can cover it"),
])
def test_bad_input_is_one_line_exit_2(argv, culprit, tmp_path, capsys):
    rc = main(["design", *argv, "--budget", "10", "--out", str(tmp_path / "d.json")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and culprit in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "d.json").exists()


def test_design_with_preset_is_refused(designed, capsys):
    _, out, _ = designed
    rc = main(["run", "--design", str(out), "--preset", "certified", "--no-log"])
    assert rc == 2 and "not both" in capsys.readouterr().err


def test_objectives_score_the_certificate():
    """voltage and margin read the certificate's own numbers; an uncertified point scores above every one."""
    from wmr_mj.hardware import Sensing
    from wmr_mj.searches.design_search import PENALTY, score
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED
    from wmr_mj.sim.parts import resolve_run

    cert = resolve_run(RunConfig(**CERTIFIED.config_changes(), sensing=Sensing.from_spec(CART))).claim
    assert score({"p": cert}, "E_max") == cert.E_max
    assert score({"p": cert}, "voltage") == cert.voltage_max
    margins = [1 - a.value / a.limit for a in cert.assumptions
               if a.kind == "checked" and math.isfinite(a.limit) and a.limit > 0 and math.isfinite(a.value)]
    assert score({"p": cert}, "margin") == -min(margins) and min(margins) > 0
    assert score({"p": None}, "E_max") >= PENALTY


def test_filtered_cart_searches_tau_f_and_the_period(tmp_path, capsys):
    """On a filtered velocity estimate the filter's tau_f and the period are the design's too: the run reads both
    back from the file, and its certificate is the design's, to the bit."""
    out = tmp_path / "d.json"
    rc, printed = _run_json(capsys, ["design", "--sensing", "encoder_ticks=4096,velocity=filtered,filter_tau=0.01",
                                     "--periods", "0.001,0.002", "--budget", "40", "--out", str(out), "--json"])
    assert rc == 0
    s = printed["settings"]
    assert s["control_period"] in (0.001, 0.002) and s["sensing"]["filter_tau"] != 0.01
    rc, run = _run_json(capsys, ["run", "--design", str(out), "--duration", "35", "--no-log", "--json"])
    assert run["sensing"]["filter_tau"] == s["sensing"]["filter_tau"]
    assert run["certificate"]["E_max"] == printed["E_max"]
