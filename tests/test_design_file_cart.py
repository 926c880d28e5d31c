"""A design file runs on the cart it was found on (``wmr-mj design --cart``), unless a command names another.

Without it ``run --design FILE`` with no ``--cart`` ran a design found on another cart on the C80, with that
cart's gains: its certificate was then silently another cart's. The independent truth is the certificate the
design file states (the search's, on the cart): ``run --design FILE`` alone must give it, to the bit. Where the
cart file is no longer where it was with the same text, the run is refused in one line; compare and validate run
every design on one cart: without ``--cart`` the CLI brings the design's (tests/test_design_travels.py), and the
library's design_file_changes refuses a design found on another where it is given none. Budgets and durations
are small (a few seconds each); the numbers compared are the same computation's, so they are compared exactly.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from helpers import refused_line

from wmr_mj.carts import CARTS_DIR
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError
from wmr_mj.experiments.compare import design_file_changes
from wmr_mj.searches.design_search import design_cart

SMALL = ["--budget", "12", "--duration", "10"]


def _design_on(capsys, cart: str, out: Path) -> dict:
    code = main(["design", *SMALL, "--cart", cart, "--out", str(out), "--json"])
    got = json.loads(capsys.readouterr().out)
    assert code == 0 and got["certified"], got["binding"]
    return json.loads(out.read_text(encoding="utf-8"))


def _certificate(capsys, argv: list[str]) -> dict:
    assert main(["run", *argv, "--duration", "10", "--no-log", "--json"]) == 0
    return json.loads(capsys.readouterr().out)["certificate"]


def test_run_of_a_design_file_is_on_the_cart_it_was_found_on(tmp_path, capsys):
    design = _design_on(capsys, "c80-magmotor", tmp_path / "d.json")
    stated = design["certificates"]["paper-circle"]
    cert = _certificate(capsys, ["--design", str(tmp_path / "d.json")])
    assert (cert["E_max"], cert["voltage_max"]) == (stated["E_max"], stated["voltage_max"])
    assert [a["value"] for a in cert["assumptions"]] == [a["value"] for a in stated["assumptions"]]
    # an explicit --cart overrides the file, as every explicit option does: on the C80 another certificate
    on_c80 = _certificate(capsys, ["--design", str(tmp_path / "d.json"), "--cart", "c80"])
    assert on_c80["E_max"] != stated["E_max"]


def test_a_moved_cart_file_is_found_beside_the_design_or_refused(tmp_path, capsys):
    mine = tmp_path / "made" / "mine.toml"
    mine.parent.mkdir()
    shutil.copy(CARTS_DIR / "c80-magmotor.toml", mine)
    _design_on(capsys, str(mine), tmp_path / "made" / "d.json")
    shared = tmp_path / "shared"
    shared.mkdir()
    shutil.copy(tmp_path / "made" / "d.json", shared / "d.json")
    shutil.copy(mine, shared / "mine.toml")
    mine.write_text(mine.read_text(encoding="utf-8").replace('name = "', 'name = "changed '), encoding="utf-8")
    # the text the design was found on lies beside the copied design file (the changed original is not taken)
    assert design_cart(shared / "d.json") == str(shared / "mine.toml")
    (shared / "mine.toml").unlink()
    # the copy was verbatim: among the shipped carts, c80-magmotor.toml holds the very text
    assert design_cart(shared / "d.json") == str(CARTS_DIR / "c80-magmotor.toml")


def test_a_changed_cart_file_is_refused_in_one_line(tmp_path, capsys):
    mine = tmp_path / "mine.toml"
    text = (CARTS_DIR / "c80-magmotor.toml").read_text(encoding="utf-8")
    mine.write_text(text.replace('name = "', 'name = "mine ', 1), encoding="utf-8")
    _design_on(capsys, str(mine), tmp_path / "d.json")
    mine.write_text(text, encoding="utf-8")  # changed since the design was found: not the cart it was found on
    line = refused_line(capsys, ["run", "--design", str(tmp_path / "d.json"), "--no-log"])
    assert str(tmp_path / "d.json") in line and "give --cart FILE" in line and "no longer there" in line
    # named explicitly, it runs on the cart named
    assert main(["run", "--design", str(tmp_path / "d.json"), "--cart", str(mine), "--duration", "10",
                 "--no-log", "--json"]) == 0
    capsys.readouterr()


def test_compare_refuses_a_design_found_on_another_cart_without_cart(tmp_path, capsys):
    _design_on(capsys, "c80-magmotor", tmp_path / "d.json")
    with pytest.raises(ParameterError, match="give --cart FILE"):
        design_file_changes(str(tmp_path / "d.json"))
    changes = design_file_changes(str(tmp_path / "d.json"), cart="c80-magmotor")
    assert changes["controller"] == "computed-torque"


def test_every_writer_of_a_design_file_records_its_cart(tmp_path):
    """write_design itself records the cart (validate's section (e) writes its design file through it, not
    through the design command): the file then runs on that cart, and a C80 design's file records none."""
    from wmr_mj.searches.design_search import DesignProblem, search_design, write_design
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED

    for cart, expected in (("c80-magmotor", str(CARTS_DIR / "c80-magmotor.toml")), (None, None)):
        base = RunConfig(**CERTIFIED.config_changes(), duration=10.0, cart=cart)
        write_design(search_design(DesignProblem(base=base, budget=4)), tmp_path / "d.json")
        written = json.loads((tmp_path / "d.json").read_text(encoding="utf-8"))
        assert ("cart" in written) == (cart is not None)
        assert design_cart(tmp_path / "d.json") == expected
