"""``wmr-mj design --cart FILE|NAME`` (issue 37 item 2): the search runs on the cart, and its file reproduces.

The independent truth is ``wmr-mj run``: the design file written on a cart, run with ``run --design FILE --cart``
(the very line design prints), must give the certificate the file states, to the bit; the same file run with
``--cart c80`` (on the C80) must not, or the search would not have run on the cart at all. The cart's m1 box is read
from the cart file itself. Budgets and durations are small (a few seconds each); the numbers compared are the
same computation's, so they are compared exactly.
"""

from __future__ import annotations

import json
import shlex
from pathlib import Path

from wmr_mj.carts import CARTS_DIR, load_cart
from wmr_mj.cli.app import main

C80_TEXT = (CARTS_DIR / "c80.toml").read_text(encoding="utf-8")
#: the C80's m1 box as c80.toml writes it, and a wider box for a cart of our own
M1_BOX_LINE = 'range = [550.0, 750.0]\nunit = "kg"\nsource = "(5.1): chassis mass 550-750 kg"\n[uncertainty.full.m1]'
WIDE_BOX = [300.0, 1000.0]
#: a design search small enough for a test: CMA-ES's first generations, a 10 s run
SMALL = ["--budget", "12", "--duration", "10"]


def _design(capsys, out: Path, *extra: str) -> dict:
    code = main(["design", *SMALL, "--out", str(out), "--json", *extra])
    got = json.loads(capsys.readouterr().out)
    assert code == (0 if got["certified"] else 1)
    return got


def _run_certificate(capsys, line: str) -> dict:
    """The certificate of ``wmr-mj run`` given by ``line`` (design's printed run line)."""
    words = shlex.split(line)
    assert words[:2] == ["wmr-mj", "run"]
    main([*words[1:], "--no-log", "--json"])
    return json.loads(capsys.readouterr().out)["certificate"]


def test_design_on_a_cart_is_reproduced_by_run_with_the_cart(tmp_path, capsys):
    out = tmp_path / "design.json"
    got = _design(capsys, out, "--cart", "c80-magmotor")
    assert got["certified"], got["binding"]
    assert got["run"] == f"wmr-mj run --design {out} --cart c80-magmotor --duration 10.0"
    written = json.loads(out.read_text(encoding="utf-8"))
    text = (CARTS_DIR / "c80-magmotor.toml").read_text(encoding="utf-8")
    assert written["cart"]["text"] == text and written["cart"]["name"] == load_cart("c80-magmotor").name
    assert written["box"]["m1_range"] == list(load_cart("c80-magmotor").uncertainty["m1"]["m1"])
    stated = written["certificates"]["paper-circle"]
    cert = _run_certificate(capsys, got["run"])
    assert cert["certified"] and (cert["E_max"], cert["voltage_max"]) == (stated["E_max"], stated["voltage_max"])
    assert [a["value"] for a in cert["assumptions"]] == [a["value"] for a in stated["assumptions"]]
    # the same design run on the C80 (--cart c80) has another certificate: the search did run on the cart
    on_c80 = _run_certificate(capsys, got["run"].replace(" --cart c80-magmotor", " --cart c80"))
    assert on_c80["E_max"] != stated["E_max"] and on_c80["voltage_max"] != stated["voltage_max"]


def test_design_on_a_cart_takes_its_m1_box_unless_given(tmp_path, capsys):
    mine = tmp_path / "wide.toml"
    assert C80_TEXT.count(M1_BOX_LINE) == 1
    mine.write_text(C80_TEXT.replace(M1_BOX_LINE, M1_BOX_LINE.replace("[550.0, 750.0]", "[300.0, 1000.0]")),
                    encoding="utf-8")
    got = _design(capsys, tmp_path / "wide.json", "--cart", str(mine))
    assert got["box"]["m1_range"] == WIDE_BOX
    given = _design(capsys, tmp_path / "given.json", "--cart", str(mine), "--m1-range", "550", "750")
    assert given["box"]["m1_range"] == [550.0, 750.0]
    assert "--m1-range 550.0 750.0" in given["run"]  # given on a cart whose box differs: run must be told


def test_design_without_a_cart_writes_no_cart_key(tmp_path, capsys):
    """The C80's design file is as before: no 'cart' key, the C80's box, no --cart in its run line."""
    out = tmp_path / "design.json"
    got = _design(capsys, out)
    assert "cart" not in json.loads(out.read_text(encoding="utf-8")) and "cart" not in got
    assert got["box"]["m1_range"] == [550.0, 750.0] and "--cart" not in got["run"]
