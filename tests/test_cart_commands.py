"""Every command on a cart file (issue 37 items 2-4): ``--cart FILE|NAME`` and ``RunConfig(cart=...)``.

The independent truths: the C80 run without ``--cart`` (the C80 file must give it to the bit); the C80 with the
same m1 range given explicitly (a cart that changes only the m1 box must give that certificate); the certified
design's rule called directly (:func:`wmr_mj.sim.designs.certified_omega_r`), against what ``--preset certified``
runs; the file's own text, against what a log carries; the MJCF replayed by ``replay --verify``.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers import refused_line

from wmr_mj.carts import CARTS_DIR, load_cart
from wmr_mj.cli.app import main
from wmr_mj.sim.config import RunConfig, base_for
from wmr_mj.sim.designs import CERTIFIED, certified_design, certified_omega_r, preset
from wmr_mj.sim.parts import resolve_run

C80_TEXT = (CARTS_DIR / "c80.toml").read_text(encoding="utf-8")
#: what differs between two runs of one config: the machine's timings (RunSummary.wall_s, realtime_factor)
TIMINGS = ("wall_s", "realtime_factor")
#: the C80's m1 box in its file, and a wider one for a cart of our own (300-1000 kg)
M1_BOX_LINE = 'range = [550.0, 750.0]\nunit = "kg"\nsource = "(5.1): chassis mass 550-750 kg"\n[uncertainty.full.m1]'
WIDE_BOX = (300.0, 1000.0)


def _cart(tmp_path: Path, *changes: tuple[str, str], name: str = "mine.toml") -> Path:
    """A copy of c80.toml with each (old, new) text replaced once (each must be there)."""
    text = C80_TEXT
    for old, new in changes:
        assert text.count(old) >= 1, old
        text = text.replace(old, new, 1)
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _wide_box_cart(tmp_path: Path) -> Path:
    return _cart(tmp_path, (M1_BOX_LINE, M1_BOX_LINE.replace("[550.0, 750.0]", f"[{WIDE_BOX[0]!r}, {WIDE_BOX[1]!r}]")))


def _run_json(capsys, *extra: str) -> dict:
    assert main(["run", "--duration", "10", "--no-log", "--json", *extra]) == 0
    obj = json.loads(capsys.readouterr().out)
    return {k: v for k, v in obj.items() if k not in TIMINGS}



# -- the C80 to the bit -------------------------------------------------------------------------------------------
def test_cart_c80_gives_the_run_without_cart_to_the_bit(tmp_path, capsys):
    """--cart c80, its file, and a copy of it elsewhere: the summary JSON of the run without --cart, every key."""
    without = _run_json(capsys, "--preset", "certified")
    copy = _cart(tmp_path, ("# The C80 cart", "# A copy of the C80 cart"), name="copy.toml")
    for cart in ("c80", str(CARTS_DIR / "c80.toml"), str(copy)):
        assert _run_json(capsys, "--preset", "certified", "--cart", cart) == without, cart
    assert "cart" not in without.get("config", {})  # the C80's record gains no key


def test_run_config_cart_c80_is_the_c80_record():
    # coerced (RunConfig(cart=...) keeps the name as a reference until from_inputs or resolve_run reads it)
    c80 = RunConfig.from_inputs(cart="c80")
    assert c80 == RunConfig.from_inputs() and "cart" not in c80.to_dict()
    assert c80.to_dict() == RunConfig().to_dict() == RunConfig(cart="c80").to_dict()


# -- the cart's box, stops and design -----------------------------------------------------------------------------
def test_a_cart_with_another_m1_box_changes_the_certificate_box(tmp_path):
    """The cart's m1 box is the run's m1_range and its certificate's: the certificate of the C80 over the same
    range given explicitly (the second method: nothing else of the cart differs), not the C80's default one."""
    config = RunConfig.from_inputs(cart=str(_wide_box_cart(tmp_path)), **CERTIFIED.config_changes())
    assert config.m1_range == WIDE_BOX and config.m1 == 650.0
    claim = resolve_run(config).claim
    explicit = resolve_run(RunConfig(m1_range=WIDE_BOX, **CERTIFIED.config_changes())).claim
    c80 = resolve_run(RunConfig(**CERTIFIED.config_changes())).claim
    assert tuple(claim.inputs["m1_range"]) == WIDE_BOX
    assert (claim.E_max, claim.Edot_max, claim.voltage_max) == (explicit.E_max, explicit.Edot_max,
                                                                 explicit.voltage_max)
    assert claim.E_max > c80.E_max  # a wider box: a larger bound (the same gains)
    assert config.to_dict()["cart"]["text"] == (_wide_box_cart(tmp_path)).read_text(encoding="utf-8")


def test_a_carts_stops_refuse_a_path_that_needs_more_steering(tmp_path, capsys):
    """The paper circle needs asin(l1/R) = 0.659 rad; a cart with 0.6 rad stops refuses it in one line (exit 2),
    the C80's 0.9 rad stops take it. (Asked for with --path: the cart's own default is a path its stops steer,
    tests/test_default_path.py.)"""
    stops = _cart(tmp_path, ('[supply.steering_range]\nvalue = 0.9', '[supply.steering_range]\nvalue = 0.6'))
    line = refused_line(capsys, ["run", "--cart", str(stops), "--path", "paper-circle", "--duration", "10",
                                 "--no-log"])
    assert line.startswith("wmr-mj: error: path infeasible") and "max_angle = 0.6 rad" in line
    assert main(["run", "--duration", "10", "--no-log", "--json"]) == 0


def test_the_certified_rule_on_a_cart_gives_its_own_omega_r(tmp_path, capsys):
    """--preset certified on a cart runs the rule on it: omega_r from certified_omega_r(cart=) called directly.
    On tests/data/anycart.toml the rule gives 15 rad/s, not the C80's 30 (so a copy of the C80's gains would fail
    here); on the wide-box cart and on c80-magmotor (30 rad/s, as on the C80 since the sampled-data certificate)
    its value is the rule's too."""
    anycart = str(Path(__file__).parent / "data" / "anycart.toml")
    assert certified_omega_r(cart=anycart) != CERTIFIED.kd
    on_anycart = preset("certified", cart=anycart)
    assert (on_anycart.kp, on_anycart.kd) != (CERTIFIED.kp, CERTIFIED.kd)
    wide = str(_wide_box_cart(tmp_path))
    omega_r = certified_omega_r(cart=wide)
    assert omega_r is not None
    design = preset("certified", cart=wide)
    assert (design.kp, design.kd) == (omega_r * omega_r / 4.0, omega_r)
    summary = _run_json(capsys, "--preset", "certified", "--cart", wide)
    assert (summary["kp"], summary["kd"]) == (omega_r * omega_r / 4.0, omega_r)
    re40 = certified_design("c80-magmotor")
    assert re40.kd == certified_omega_r(cart="c80-magmotor") and re40.kp == re40.kd ** 2 / 4.0
    assert preset("certified") is CERTIFIED  # the C80's design, as before


def test_the_second_cart_is_its_file(tmp_path):
    """c80-magmotor: the motor and gear of its file, every other parameter the C80's. The motor's numbers are its
    data sheet's lines (Rt = 0.31 Ohm; Ke = 13.3 V/krpm in V s/rad), the gear the Beckhoff NP045's 2-stage 32:1."""
    import math

    cart = load_cart("c80-magmotor")
    base = base_for(RunConfig(cart="c80-magmotor"))
    c80 = load_cart("c80").parameters
    k = 13.3 * 60.0 / (2.0 * math.pi * 1000.0)
    assert (base.R_a, base.k_i, base.k_b, base.i2) == (0.31, k, k, 32.0)
    assert {k: v for k, v in cart.parameters.items() if k not in ("R_a", "k_i", "k_b", "i2")} == \
        {k: v for k, v in c80.items() if k not in ("R_a", "k_i", "k_b", "i2")}
    assert all(("Magmotor" in cart.sources[k]) for k in ("R_a", "k_i", "k_b"))
    assert "Beckhoff" in cart.sources["i2"]
    assert all(cart.sources[k].startswith("assumption") for k in cart.parameters if k not in ("R_a", "k_i", "k_b",
                                                                                             "i2"))


def test_cart_check_reports_the_certified_design_in_its_second_line(capsys):
    assert main(["cart", "check", "c80-magmotor", "--json"]) == 0
    got = json.loads(capsys.readouterr().out)["certified_design"]
    config = RunConfig(cart="c80-magmotor", **certified_design("c80-magmotor").config_changes())
    claim = resolve_run(config).claim
    assert got["omega_r"] == certified_omega_r(cart="c80-magmotor")
    assert (got["E_max"], got["voltage_max"], got["certified"]) == (claim.E_max, claim.voltage_max, claim.certified)
    assert got["voltage_limit"] == 24.0 and got["unmet"] == list(claim.unmet)
    assert main(["cart", "check", "c80-magmotor"]) == 0
    second = capsys.readouterr().out.splitlines()[1]
    assert second.startswith(f"certified design on this cart: omega_r = {got['omega_r']:g} rad/s")
    assert f"E_max = {claim.E_max:.4g} rad" in second


def test_robustness_box_derived_on_a_cart_is_the_carts_box(capsys):
    """robustness --box derived --cart: the box spanned by the cart's parameter set over its m1 box, computed
    here with the closed forms of C80Parameters.coefficients at the box's two m1 ends."""
    from wmr_mj.params import with_params

    assert main(["robustness", "--box", "derived", "--cart", "c80-magmotor", "--json"]) == 0
    box = json.loads(capsys.readouterr().out)["box"]
    base = base_for(RunConfig(cart="c80-magmotor"))
    ends = [with_params(base, m1=m).coefficients("paper") for m in load_cart("c80-magmotor").uncertainty["m1"]["m1"]]
    for name in ("P", "C_V", "F", "K"):
        values = [getattr(c, name) for c in ends]
        assert box[name] == pytest.approx([min(values), max(values)], rel=1e-12), name  # rel: rounding only
    assert box["P"][0] != pytest.approx(0.385, rel=0.1)  # not the C80's P


# -- logs -----------------------------------------------------------------------------------------------------------
def test_a_cart_in_a_log_verifies_by_replay(tmp_path, capsys):
    """The log carries the cart file (its config record and the attachment cart.toml, the file's text to the
    byte); replay --verify re-simulates it bit for bit and re-runs the law built from the record."""
    from wmr_mj.logs.reader import load_log
    from wmr_mj.sim.config import config_from_dict

    log = tmp_path / "re40.mcap"
    assert main(["run", "--cart", "c80-magmotor", "--preset", "certified", "--duration", "10", "--out", str(log)]) == 0
    capsys.readouterr()
    text = (CARTS_DIR / "c80-magmotor.toml").read_text(encoding="utf-8")
    loaded = load_log(log)
    assert loaded.attachments["cart.toml"].decode("utf-8") == text
    assert loaded.config["cart"]["text"] == text
    again = config_from_dict(loaded.config)
    assert base_for(again) == base_for(RunConfig(cart="c80-magmotor"))
    assert main(["replay", str(log), "--verify"]) == 0
    out = capsys.readouterr().out
    assert "verify     bit-identical" in out and "re-run: the voltages it applied are bit-identical" in out


# -- bad input ------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("command", [["run", "--duration", "10", "--no-log"], ["sweep", "--n", "1"],
                                     ["identify"], ["model", "params"], ["validate", "--n", "1"],
                                     ["compare", "paper"], ["falsify"]])
@pytest.mark.parametrize("cart", ["no-such-cart", "missing/cart.toml"])
def test_a_bad_cart_is_one_line_and_exit_2(command, cart, capsys):
    line = refused_line(capsys, [*command, "--cart", cart])
    assert line == (f"wmr-mj: error: cart {cart!r} is neither a file nor a shipped cart; accepted: a path to a "
                    ".toml cart file or one of c80, c80-magmotor")
