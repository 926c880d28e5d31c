"""Issue 37's done-when, as a new user does it: copy c80.toml, change the motor, the masses and the stops, then
``wmr-mj cart check mine.toml`` and ``wmr-mj validate --cart mine.toml``; both answer in their first lines.

The independent truth is the file itself and the library on it: the box the answer names is the file's m1 box,
the certified design's bound it prints is the certificate ``resolve_run`` computes for that design on the cart,
and cart check's design line is ``search_design``'s answer. validate is run small (2 runs, 10 s, a 5-run search),
as tests/test_validate.py runs it.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest

from wmr_mj.carts import CARTS_DIR, load_cart

#: the user's changes: (section.key, value) of the motor, the masses and the stops
#: (the chassis' own mass 500 kg, the box's lower edge: m1 beyond it is the payload, which cannot be negative)
CHANGES = {"motor.R_a": "1.2", "motor.k_i": "0.09", "motor.k_b": "0.09", "chassis.m1": "600.0",
           "chassis.chassis_inertia_mass": "600.0", "supply.steering_range": "0.8"}  # m1 >= its chassis' own mass
M1_BOX = (500.0, 700.0)


def _cli(*args: str, cwd) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "wmr_mj.cli", *args], capture_output=True, text=True, timeout=300,
                          cwd=cwd, env={**os.environ, "MPLBACKEND": "Agg"})


@pytest.fixture(scope="module")
def mine(tmp_path_factory):
    text = (CARTS_DIR / "c80.toml").read_text(encoding="utf-8").replace('name = "C80"', 'name = "mine"', 1)
    for key, value in CHANGES.items():
        text, n = re.subn(rf"(\[{re.escape(key)}\]\nvalue = )[^\n]+", rf"\g<1>{value}", text)
        assert n == 1, key
    for box in ("m1", "full"):  # the m1 box of both boxes; the armature's range moved with its nominal 1.2 Ohm
        old = f'[uncertainty.{box}.m1]\nrange = [550.0, 750.0]'
        assert old in text
        text = text.replace(old, f"[uncertainty.{box}.m1]\nrange = [{M1_BOX[0]}, {M1_BOX[1]}]")
    text = text.replace("[uncertainty.full.R_a]\nrange = [1.0, 1.3]", "[uncertainty.full.R_a]\nrange = [1.2, 1.5]")
    path = tmp_path_factory.mktemp("user") / "mine.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_cart_check_answers_in_its_first_lines(mine):
    from wmr_mj.searches.design_search import DesignProblem, search_design
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED

    proc = _cli("cart", "check", "mine.toml", cwd=mine.parent)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith(f"cart mine {load_cart(mine).version} (mine.toml): passes")
    assert lines[1].startswith("certified design on this cart:") and "CERTIFIED" in lines[1]
    found = search_design(DesignProblem(base=RunConfig(**CERTIFIED.config_changes(), cart=str(mine))))
    assert found.certified
    assert lines[2].startswith(f"design certifies it: E_max {found.E_max:.4g} rad")


def test_validate_on_the_users_cart_answers_first(mine):
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import certified_design
    from wmr_mj.sim.parts import resolve_run

    proc = _cli("validate", "--cart", "mine.toml", "--n", "2", "--duration", "10", "--identify-duration", "10",
                "--search-budget", "5", "--seed", "3", "--out", "report", cwd=mine.parent)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("Question: does the (4.21)-(4.23) region, computed for this cart, hold for the cart "
                               f"mine {load_cart(mine).version} under m1 in 500-700 kg?")
    assert lines[1].startswith("The paper's design")
    claim = resolve_run(RunConfig(**certified_design(str(mine)).config_changes(), cart=str(mine),
                                  duration=10.0)).claim
    assert claim.certified
    assert f"|E| <= {claim.E_max:.3g} rad" in lines[2]  # the certified design's certificate on this cart
    assert lines[3].startswith("The certified design") and "2/2 runs certified-inside" in lines[3]
