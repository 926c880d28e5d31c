"""Absurd carts are refused before any step, in one line, exit status 2 (issue 42, item 5).

Each case is a cart a new user wrote (a copy of the C80's file with one thing absurd) that, before these checks,
hung (`cart check` over 120 s in the reference's integrator), printed millions of MuJoCo warnings, or ended in the
wrong cause ("no identification ... excite longer") or passed. The thresholds are checked against their closed
forms: F = (R_a/k_i) (l3 l4/(l1 i2)) mu Q against the supply, the body-mass ratio, the wheelbases integrated.
"""

from __future__ import annotations

import math
import re
import time
import tomllib
from pathlib import Path

import pytest
from helpers import refused_line

from wmr_mj.carts import CARTS_DIR, cart_names, load_cart
from wmr_mj.errors import ParameterError, StiffReferenceError
from wmr_mj.params import C80, MAX_BODY_MASS_RATIO, check_physical_sense, parameters_of_cart, with_params
from wmr_mj.reference.paths import MAX_WHEELBASES_INTEGRATED
from wmr_mj.sim.config import build_reference


def _c80_text() -> str:
    return (CARTS_DIR / "c80.toml").read_text(encoding="utf-8")


def _cart(tmp_path: Path, changes: dict[str, float], box_m1: tuple[float, float] | None = None) -> Path:
    """The C80's file with ``changes`` ('section.name' -> value) and, if given, every m1 box replaced."""
    text = _c80_text()
    for key, value in changes.items():
        section, name = key.split(".")
        text, n = re.subn(rf"(\[{section}\.{name}\]\nvalue = )[^\n]+",
                          lambda m, value=value: m.group(1) + repr(value), text)
        assert n == 1, key
    if box_m1 is not None:
        text, n = re.subn(r"(\[uncertainty\.(m1|full)\.m1\]\nrange = )[^\n]+",
                          lambda m: m.group(1) + repr(list(box_m1)), text)
        assert n == 2
    path = tmp_path / "absurd.toml"
    path.write_text(text.replace('name = "C80"', 'name = "absurd"'), encoding="utf-8")
    tomllib.loads(path.read_text())  # still TOML
    return path


@pytest.mark.parametrize("changes, box_m1, says", [
    ({"supply.voltage_limit": 0.001}, None, "the motor cannot move the steering"),
    ({"motor.R_a": 1e9}, None, "the motor cannot move the steering"),
    ({"motor.i2": 1e-9}, None, "the motor cannot move the steering"),
    ({"steering_axle.mu": 50.0}, None, "the motor cannot move the steering"),
    ({"chassis.m1": 300.0, "chassis.chassis_inertia_mass": 200.0}, (80.0, 120.0), "inside its own box"),
    ({"chassis.m1": 600.0}, None, "at least chassis.chassis_inertia_mass.value = 650.0 kg"),
    ({"chassis.m1": 1e30}, (1e29, 1e31), "accepted: a ratio of at most"),
])
def test_an_absurd_cart_is_refused_by_cart_check_in_one_line(tmp_path, capsys, changes, box_m1, says):
    path = _cart(tmp_path, changes, box_m1)
    line = refused_line(capsys, ["cart", "check", str(path)])
    assert says in line and "absurd.toml" in line


def test_a_tiny_wheelbase_is_refused_before_any_step_not_integrated_for_hours(tmp_path, capsys):
    path = _cart(tmp_path, {"chassis.l1": 1e-6, "chassis.l3": 1e-7})
    t0 = time.perf_counter()
    line = refused_line(capsys, ["cart", "check", str(path)])
    assert "cannot be integrated in bounded time" in line and "l1 = 1e-06 m" in line
    # before: over 120 s in solve_ivp; now refused before the reference's first step (the import and the cart's
    # parsing take well under a second; 60 s leaves room for a loaded machine)
    assert time.perf_counter() - t0 < 60
    line = refused_line(capsys, ["run", "--cart", str(path), "--no-log", "--duration", "2"])
    assert "cannot be integrated in bounded time" in line


def test_the_bounded_time_limit_is_the_number_of_wheelbases_integrated():
    # refused: the message gives the length of C's path being integrated and the least wheelbase that integrates
    # it (the paper circle integrates its entry, then the circle, each checked); 1 % above it, that part builds
    l1, refusals = 1e-5, []
    for _ in range(4):
        try:
            build_reference("paper-circle", with_params(C80, l1=l1, l3=0.1 * l1), dt=1e-3, duration=35.0)
            break
        except StiffReferenceError as exc:
            span = float(re.search(r"C's ([0-9.e+]+) m of path", str(exc)).group(1))
            least = float(re.search(r"a wheelbase of at least ([0-9.e+-]+) m", str(exc)).group(1))
            assert math.isclose(least, span / MAX_WHEELBASES_INTEGRATED, rel_tol=1e-3)  # the message's rounding
            assert span / l1 > MAX_WHEELBASES_INTEGRATED
            refusals.append(least)
            l1 = 1.01 * least
    else:
        pytest.fail(f"still refused after {refusals}")
    assert refusals, "l1 = 1e-5 m was integrated"


def test_the_supply_check_is_the_friction_voltage_in_closed_form():
    p = C80
    F = (p.R_a / p.k_i) * (p.l3 * p.l4 / (p.l1 * p.i2)) * p.mu * p.Q  # (2.13)'s F, written out here
    assert math.isclose(F, p.coefficients("paper").F, rel_tol=1e-12)
    check_physical_sense(with_params(C80, voltage_limit=F * (1 + 1e-9)))  # just above: accepted
    with pytest.raises(ParameterError, match="the motor cannot move the steering"):
        check_physical_sense(with_params(C80, voltage_limit=F * (1 - 1e-9)))


def test_the_mass_ratio_check_is_the_largest_over_the_smallest_body():
    # the heaviest body is m1 (650 kg); a front wheel just light enough is accepted, 1 % lighter refused
    check_physical_sense(with_params(C80, front_wheel_mass=C80.m1 / (0.99 * MAX_BODY_MASS_RATIO)))
    with pytest.raises(ParameterError, match="m1 = 650 kg is 1.01e[+]06 times front_wheel_mass"):
        check_physical_sense(with_params(C80, front_wheel_mass=C80.m1 / (1.01 * MAX_BODY_MASS_RATIO)))


@pytest.mark.parametrize("name", cart_names())
def test_every_shipped_cart_is_of_physical_sense(name):
    check_physical_sense(parameters_of_cart(load_cart(name)))
