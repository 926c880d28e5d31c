"""A cart's model card speaks of its own cart: the C80's sentences about the paper's (5.1) intervals and the
paper's speeds only on the C80's card (issue 42 item 4). The sections are rendered alone (the whole card takes
about a minute of measurements); the C80's card is held to its file by tests/test_plant.py."""

from __future__ import annotations

from wmr_mj.carts import load_cart
from wmr_mj.params import C80, parameters_of_cart, with_params
from wmr_mj.plant import modelcard

SLIP = {"max_slip_m_s": 1e-4, "max_slip_fraction": 5e-4, "max_slip_angle_rad": 5e-4, "rms_slip_m_s": 5e-5,
        "max_side_force_ratio": 0.1}


def _rendered(section, *args, **options) -> str:
    out: list[str] = []
    section(out.append, *args, **options)
    return "\n".join(out)


def test_another_carts_card_states_its_own_K_and_F_spans_not_the_papers():
    cart = load_cart("c80-magmotor")
    p = parameters_of_cart(cart)
    box = cart.uncertainty["m1"]["m1"]
    text = _rendered(modelcard._coefficient_section, p, p.coefficients("paper"), p.coefficients("nonholonomic"), box,
                     paper_cart=False)
    assert "K spans the paper's interval" not in text and "than (5.1) prints" not in text
    lo, hi = sorted(with_params(p, m1=m).coefficients("paper").K for m in box)
    assert f"K spans ({modelcard._g(lo)}, {modelcard._g(hi)}) V" in text  # the cart's own, from its m1 box
    assert "the paper's C80, shown for comparison only" in text


def test_the_c80s_card_keeps_its_reading_of_the_paper():
    text = _rendered(modelcard._coefficient_section, C80, C80.coefficients("paper"), C80.coefficients("nonholonomic"))
    assert "K spans the paper's interval" in text


def test_another_carts_slip_is_on_the_measurements_circle_at_its_own_speed():
    p = parameters_of_cart(load_cart("c80-magmotor"))
    text = _rendered(modelcard._slip_section, p, SLIP, paper_cart=False)
    assert "the paper's speeds" not in text and "at this cart's V_A" in text
    assert "paper's speeds" in _rendered(modelcard._slip_section, C80, SLIP)
