"""The second shipped cart's numbers (issue 37 item 4): each value names its source, and an assumption says so.

c80-magmotor.toml takes its motor from a published data sheet (Magmotor's MOTOR PERFORMANCE / SPECIFICATIONS of
the C40-A-200FX, product no. 500400180 rev B). The independent truth is the sheet's own lines, typed here from it:
Rt = 0.31 Ohm at 20 C, R ah = 0.41 Ohm at 105 C, Ke = 13.3 V/krpm, Kt = 18.0 oz-in/A. Each value read from the
sheet must be that line's number in SI units, and its source must name the document, the part and the line. The
gear's ratio is the Beckhoff NP045 planetary gear unit's 2-stage 32:1, from its published technical data ('Ratio i':
25, 32, 50, 64, 100 for 2 stages). Every other value's source must begin with "assumption", so no number of the
file passes for a real vehicle's.
"""

from __future__ import annotations

import math

import pytest

from wmr_mj.carts import CARTS_DIR, cart_names, load_cart

CART = "c80-magmotor"
#: what a source taken from the sheet must name: the maker, the model, the product number and revision, the URL
SHEET = ("Magmotor", "C40-A-200FX", "500400180 rev B",
         "https://cdn.shopify.com/s/files/1/0563/1226/6948/files/500400180revB_with_perf_curve_magmotor_servo_motor.pdf")
#: what the gear's source must name: the maker, the part, the page, the line
GEAR_SHEET = ("Beckhoff", "NP045", "https://infosys.beckhoff.com/content/1033/ag3210_ba/6298098187.html", "'Ratio i'")
#: the NP045's 2-stage ratios, as its technical data lists them
NP045_TWO_STAGE_RATIOS = (25.0, 32.0, 50.0, 64.0, 100.0)
#: Ke = 13.3 V/krpm in V s/rad (1 krpm = 1000 * 2 pi / 60 rad/s)
KE_SI = 13.3 / (1000.0 * 2.0 * math.pi / 60.0)
#: 1 oz-in in N m: 1 ozf = 0.028349523125 kg * 9.80665 m/s^2, 1 in = 0.0254 m (exact definitions)
OZ_IN = 0.028349523125 * 9.80665 * 0.0254


def _all_sources(cart) -> dict[str, str]:
    out = {f"parameter {k}": v for k, v in cart.sources.items()}
    out.update({f"uncertainty.{box}.{k}": v for box, srcs in cart.uncertainty_sources.items() for k, v in srcs.items()})
    out.update({f"defaults.{k}": v for k, v in cart.default_sources.items()})
    return out


@pytest.mark.parametrize("name", cart_names())
def test_every_value_of_every_shipped_cart_has_a_source(name):
    sources = _all_sources(load_cart(name))
    assert sources and all(isinstance(s, str) and s.strip() for s in sources.values()), sources


def test_every_value_is_the_sheets_or_labelled_an_assumption():
    sources = _all_sources(load_cart(CART))
    from_sheet = {key for key, s in sources.items() if not s.startswith("assumption")}
    assert from_sheet == {"parameter R_a", "parameter k_i", "parameter k_b", "uncertainty.full.R_a", "parameter i2"}
    for key in from_sheet - {"parameter i2"}:
        assert all(part in sources[key] for part in SHEET), key
        assert "line" in sources[key] and "assumption" not in sources[key], key
    assert all(part in sources["parameter i2"] for part in GEAR_SHEET) and "line" in sources["parameter i2"]
    assert load_cart(CART).parameters["i2"] in NP045_TWO_STAGE_RATIOS
    # the rest: every one labelled, none of them naming the sheet as its source
    # 31 parameters (with L_a), 6 ranges (m1: m1; full: m1, mu, ground_friction, R_a, V_A), 3 defaults
    assert len(sources) == 31 + 6 + 3
    assert not any(SHEET[1] in s and not s.startswith("assumption") for k, s in sources.items() if k not in from_sheet)


def test_the_sheets_numbers_are_the_sheets_lines():
    cart = load_cart(CART)
    assert cart.parameters["R_a"] == 0.31 and "'Rt = 0.31 Ohms(@20 C)" in cart.sources["R_a"]
    assert cart.uncertainty["full"]["R_a"] == (0.31, 0.41)
    assert "'R ah = 0.41 Ohms(@105 C)" in cart.uncertainty_sources["full"]["R_a"]
    for key in ("k_i", "k_b"):
        assert cart.parameters[key] == KE_SI and "'Ke = 13.3 V/krpm" in cart.sources[key], key
    # the sheet's other line for the same constant, Kt = 18.0 oz-in/A: the same to its rounding (3 digits, 0.3 %)
    assert cart.parameters["k_i"] == pytest.approx(18.0 * OZ_IN, rel=3e-3)
    # and its own stall current, 77.4 A = V in / Rt: the sheet's R_a is the one it computes with (3 digits)
    assert 24.0 / cart.parameters["R_a"] == pytest.approx(77.4, rel=1e-3)


def test_the_file_says_it_is_not_a_real_vehicle():
    text = (CARTS_DIR / f"{CART}.toml").read_text(encoding="utf-8")
    assert "this is not a real vehicle's parameter set" in text
    changelog = load_cart(CART).changelog
    assert changelog[0].startswith("2.2.0 (2026-11-28): the armature inductance motor.L_a, 0 H")
    assert changelog[1].startswith("2.1.0 (2026-11-27): the gear is the Beckhoff NP045")
    assert changelog[2].startswith("2.0.0 (2026-11-27): the steering motor is the Magmotor")
