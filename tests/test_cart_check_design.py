"""``wmr-mj cart check`` answers whether ``wmr-mj design`` can certify the cart on its default sensing (issue 37
item 3): its third line, and ``--json``'s "design".

The independent truth is ``wmr-mj design --cart FILE --seed S`` itself, run through its own options: cart check's
answer must be that command's, to the bit (the same seeded search, so compared exactly). A cart that no gains can
certify: the C80 on a 3 V supply, below what the certified design needs (8.83 V) and what the design search finds
on the C80 (7.59 V), where design names 'within the supply' as binding.
"""

from __future__ import annotations

import json

import pytest

from wmr_mj.carts import CARTS_DIR, cart_names
from wmr_mj.cli.app import main

SUPPLY_LINE = 'value = 24.0\nunit = "V"'


def _json(capsys, argv: list[str]) -> tuple[int, dict]:
    code = main(argv)
    return code, json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("name", cart_names())
def test_cart_check_answers_as_design_does(name, tmp_path, capsys):
    code, check = _json(capsys, ["cart", "check", name, "--json"])
    assert code == 0
    answer = check["design"]
    assert answer["command"] == f"wmr-mj design --cart {CARTS_DIR / f'{name}.toml'} --seed 0"
    code, design = _json(capsys, ["design", "--cart", name, "--seed", "0", "--json", "--out", str(tmp_path / "d.json")])
    assert code == 0 and answer["certified"] and design["certified"]
    settings = design["settings"]
    assert (answer["E_max"], answer["kp"], answer["kd"], answer["friction_width"]) == (
        design["E_max"], settings["kp"], settings["kd"], settings["friction_width"])
    assert answer["voltage_max"] == design["certificates"]["paper-circle"]["voltage_max"]
    assert main(["cart", "check", name]) == 0
    third = capsys.readouterr().out.splitlines()[2]
    assert third.startswith(f"design certifies it: E_max {answer['E_max']:.4g} rad (K_P {answer['kp']:.6g}, "
                            f"K_D {answer['kd']:.6g}, ")


def test_cart_check_says_no_gains_certify_a_cart_on_a_3_v_supply(tmp_path, capsys):
    text = (CARTS_DIR / "c80.toml").read_text(encoding="utf-8")
    assert text.count(SUPPLY_LINE) == 1
    mine = tmp_path / "low.toml"
    mine.write_text(text.replace(SUPPLY_LINE, SUPPLY_LINE.replace("24.0", "3.0")), encoding="utf-8")
    code, design = _json(capsys, ["design", "--cart", str(mine), "--json", "--out", str(tmp_path / "d.json")])
    assert code == 1 and not design["certified"] and design["binding"] == "the assumption 'within the supply'"
    main(["cart", "check", str(mine)])  # its exit status is the file's checks', not this answer's
    third = capsys.readouterr().out.splitlines()[2]
    assert third.startswith("no gains in the box certify this cart: the assumption 'within the supply' binds "
                            f"(wmr-mj design --cart {mine} --seed 0: ")
    code, check = _json(capsys, ["cart", "check", str(mine), "--json"])
    assert check["design"]["certified"] is False and check["design"]["binding"] == design["binding"]


def test_cart_check_answers_where_the_cart_cannot_follow_the_paper_circle(tmp_path, capsys):
    """Stops at 0.5 rad: the paper circle needs 0.66 rad, so design refuses the cart on it in one line; cart check
    still answers (no certified design, no gains, the path's reason), not a refusal. (A 1 V supply, this test's cart
    before, is now refused as absurd: it cannot break the steering's 1.52 V of friction, tests/test_absurd_carts.py.)
    The circle is asked for with --path: the cart's own default is a path its stops steer
    (tests/test_default_path.py)."""
    import re

    from helpers import refused_line

    text = (CARTS_DIR / "c80.toml").read_text(encoding="utf-8")
    mine = tmp_path / "short-stops.toml"
    text, n = re.subn(r"(\[supply\.steering_range\]\nvalue = )[^\n]+", lambda m: m.group(1) + "0.5", text)
    assert n == 1
    mine.write_text(text, encoding="utf-8")
    refusal = refused_line(capsys, ["design", "--cart", str(mine), "--path", "paper-circle",
                                    "--out", str(tmp_path / "d.json")])
    reason = refusal.removeprefix("wmr-mj: error: ")
    assert reason.startswith("path infeasible at s = ") and "0.5 rad" in reason
    assert main(["cart", "check", str(mine), "--path", "paper-circle"]) == 0  # the cart itself passes its checks
    lines = capsys.readouterr().out.splitlines()
    assert ": passes: " in lines[0]
    assert lines[1] == f"certified design: none on this cart ({reason})"
    assert lines[2].startswith(f"no gains in the box certify this cart: the path paper-circle's feasibility ({reason}) "
                               "binds (")
