"""``wmr-mj design --controller sliding-mode`` (issue 35 item 4, the sliding-mode family).

Truths independent of the search: the certificate ``run --design FILE`` computes (``resolve_run`` on the file's
settings, through the run's own option parsing), the law's default on the same cart, the exit status and one line.
"""

from __future__ import annotations

import contextlib
import io
import json

import pytest

from wmr_mj.cli.app import main

CART = "magnetic-12bit-axis"
BUDGET = "80"  # certificate evaluations: a design in a few seconds (the search's quality is the bench's)


@pytest.fixture(scope="module")
def designed(tmp_path_factory):
    out = tmp_path_factory.mktemp("design") / "sliding.json"
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["design", "--controller", "sliding-mode", "--sensing", CART, "--budget", BUDGET,
                   "--out", str(out), "--json"])
    return rc, out, json.loads(buf.getvalue())


def test_sliding_design_certifies_the_12bit_cart_and_run_reads_it_back_to_the_bit(designed, capsys):
    rc, out, printed = designed
    assert rc == 0 and printed["certified"] is True
    s = printed["settings"]
    assert s["controller"] == "sliding-mode" and set(s["controller_params"]) == {"lam", "phi", "k", "eta"}
    capsys.readouterr()
    assert main(["run", "--design", str(out), "--m1", "750", "--no-log", "--json"]) == 0
    run = json.loads(capsys.readouterr().out)
    assert run["certificate"]["E_max"] == printed["E_max"] == printed["certificates"]["paper-circle"]["E_max"]
    assert run["certificate"]["inputs"]["certificate"] == printed["certificates"]["paper-circle"]["certificate"]
    assert run["verdict"] == "certified-inside"


def test_the_sliding_default_does_not_certify_the_cart_the_design_does(designed):
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.parts import resolve_run

    default = resolve_run(RunConfig(controller="sliding-mode", model="nonholonomic", sensing=CART)).claim
    assert not default.certified  # its measured s leaves the layer on the quantum's spike (Delta/T = 1.53 rad/s)
    assert designed[2]["certified"]


def test_an_unknown_law_is_one_line_exit_2(tmp_path, capsys):
    rc = main(["design", "--controller", "pd", "--budget", "10", "--out", str(tmp_path / "d.json")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1
    assert "--controller 'pd' is not accepted; one of computed-torque, sliding-mode" in err
    assert not (tmp_path / "d.json").exists()


def test_on_the_ideal_cart_the_sliding_design_is_judged_by_its_sampled_layer(tmp_path, capsys):
    """Since issue 44 the ideal cart computes the sampled layer too and the design is judged by it (the boundary
    layer's phi/lam is never taken alone), and the file names it; run reads the file back to the same bound."""
    from wmr_mj.experiments.compare import design_file_changes
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.parts import resolve_run

    out = tmp_path / "ideal.json"
    assert main(["design", "--controller", "sliding-mode", "--budget", "30", "--out", str(out), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["certificates"]["paper-circle"]["certificate"] == "sampled-data"
    claim = resolve_run(RunConfig(**design_file_changes(str(out)))).claim
    assert claim.inputs["certificate"] == "sampled-data" and printed["E_max"] == claim.E_max


def test_compare_and_validate_read_a_sliding_design_file_as_run_does(designed):
    """compare FILE.json and validate --design FILE.json build the design through design_file_changes: the
    sliding-mode law's own parameters (lam, phi, k, eta) must reach it, as they reach run --design FILE (they once
    did not: the law ran with its defaults). The truth: the file's certificate, which run reproduces above."""
    from wmr_mj.experiments.compare import design_file_changes
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.parts import resolve_run

    _, out, printed = designed
    changes = design_file_changes(str(out))
    for name, value in printed["settings"]["controller_params"].items():
        assert changes["controller_params"][name] == value, name
    cert = resolve_run(RunConfig(**changes)).claim
    assert cert.E_max == printed["certificates"]["paper-circle"]["E_max"]
