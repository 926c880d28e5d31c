"""The default path of a cart whose file declares none (issue 42: "when none is declared, the default is a path the
cart can steer, and it is named").

The rule (wmr_mj.reference.named.default_path): the paper circle where the cart steers it at no more than 85 % of its
stops (the C80 and the shipped carts: asin(0.612) = 0.659 rad of +-0.9 rad, 73 %, so their numbers do not move; issue
37's cart with +-0.8 rad stops, 82 %, keeps it too); else a closed loop of two half-circles whose steady steering
angle is 85 % of the stops, R = l1 / sin(0.85 x stops). The cart here
is the new user's (tests/data/anycart.toml: l1 = 0.9 m, stops +-0.7 rad) without its [paths] section: the 1 m circle
needs asin(0.9) = 1.12 rad, beyond the stops, so before this every command answered "the paper circle's
feasibility binds". The independent truth: the steady angle on a circle of radius R is asin(l1/R) (the kinematics
of wmr_mj/reference/paths.py's docstring), so the loop's reference peaks at exactly 0.85 x 0.7 = 0.595 rad.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from wmr_mj.carts import load_cart
from wmr_mj.errors import InfeasiblePathError
from wmr_mj.params import parameters_of_cart
from wmr_mj.reference.named import default_path, default_path_note
from wmr_mj.reference.route import DEFAULT_PATH_STOP_FRACTION, load_route
from wmr_mj.sim.builders import build_reference
from wmr_mj.sim.config import RunConfig, coerce

DATA = Path(__file__).resolve().parent / "data"
STOPS_RAD, L1_M = 0.7, 0.9  # the file's steering_range and l1
STEADY_RAD = 0.595  # 0.85 x the stops
LOOP_NAME = "loop-of-1.61-m-turns"  # R = 0.9 / sin(0.595) = 1.606 m


def _without_paths(text: str) -> str:
    """anycart.toml's text with its [paths] section (and the comment above it) left out."""
    start, end = text.index("# the cart's own path"), text.index("# the default sensing")
    return text[:start] + text[end:]


@pytest.fixture(scope="module")
def cart_file(tmp_path_factory) -> Path:
    where = tmp_path_factory.mktemp("nopath") / "nopath.toml"
    where.write_text(_without_paths((DATA / "anycart.toml").read_text()))
    return where


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "wmr_mj.cli", *args], capture_output=True, text=True, timeout=300,
                          cwd=cwd, env={**os.environ, "MPLBACKEND": "Agg"})


def test_carts_that_steer_the_paper_circle_keep_it_and_a_declared_path_stays():
    for name in ("c80", "c80-magmotor"):  # the shipped carts: 0.659 rad is 73 % of their +-0.9 rad stops
        cart = load_cart(name)
        assert cart.default_path is None and default_path(cart) == "paper-circle"
        assert default_path_note(cart) is None
    assert default_path(None) == "paper-circle" and default_path_note(None) is None
    declared = load_cart(DATA / "anycart.toml")
    assert default_path(declared) == declared.default_path and default_path_note(declared) is None


def test_a_cart_that_cannot_steer_the_paper_circle_gets_a_loop_at_three_quarters_of_its_stops(cart_file):
    cart = load_cart(cart_file)
    params = parameters_of_cart(cart)
    with pytest.raises(InfeasiblePathError):  # why the rule is needed: the 1 m circle is beyond the stops
        build_reference("paper-circle", params, dt=1e-3, duration=35.0)
    path = default_path(cart)
    route = load_route(path)
    assert route.name == LOOP_NAME and route.closed
    reference, _ = build_reference(path, params, dt=1e-3, duration=120.0)  # more than one lap (about 14 m)
    steady = STEADY_RAD
    assert DEFAULT_PATH_STOP_FRACTION * STOPS_RAD == pytest.approx(steady, rel=1e-12)
    assert float(max(abs(reference.alpha0))) == pytest.approx(steady, abs=1e-9)  # asin(l1/R) on the turns
    assert float(reference.alpha0[0]) == 0.0 and float(reference.alpha0_dot[0]) == pytest.approx(0.0, abs=1e-12)
    on_turns = np.asarray(reference.kappa)[np.asarray(reference.alpha0) > steady - 1e-9]  # ramp ends overshoot
    radius = 1.0 / float(np.median(on_turns))
    assert radius == pytest.approx(L1_M / math.sin(steady), rel=1e-9)
    assert coerce(RunConfig(cart=str(cart_file), path=None)).path == path  # every run on the cart takes it
    note = default_path_note(cart)
    assert note is not None and f"route '{LOOP_NAME}'" in note and "radius 1.61 m" in note
    assert "declare [paths] default" in note


def test_cart_check_answers_on_the_derived_path_and_names_it(cart_file):
    proc = _cli("cart", "check", cart_file.name, cwd=cart_file.parent)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[1].startswith(f"default path: route '{LOOP_NAME}', two half-circles of radius 1.61 m")
    assert lines[2].startswith("certified design") and f"path route '{LOOP_NAME}'" in lines[2]
    assert lines[3].startswith("design certifies it")
    assert "feasibility" not in proc.stdout and "paper-circle" not in proc.stdout and "{" not in proc.stdout
    check = json.loads(_cli("cart", "check", cart_file.name, "--json", cwd=cart_file.parent).stdout)
    assert check["path_note"] == lines[1] and load_route(check["design"]["path"]).name == LOOP_NAME


def test_design_answers_on_the_derived_path_and_names_it(cart_file):
    proc = _cli("design", "--cart", cart_file.name, "--budget", "10", "--duration", "10", "--out", "d.json",
                cwd=cart_file.parent)
    assert proc.returncode in (0, 1), proc.stderr  # 1: not certified within 10 evaluations, still an answer
    assert proc.stdout.splitlines()[0].startswith(f"default path: route '{LOOP_NAME}'")
    assert "feasibility" not in proc.stdout and "paper-circle" not in proc.stdout
    design = json.loads((cart_file.parent / "d.json").read_text())
    assert load_route(design["search"]["paths"][0]).name == LOOP_NAME


def test_a_run_on_the_cart_names_the_derived_path_once(cart_file):
    proc = _cli("run", "--cart", cart_file.name, "--no-log", "--duration", "2", cwd=cart_file.parent)
    notes = [line for line in proc.stderr.splitlines() if "default path:" in line]
    assert len(notes) == 1 and LOOP_NAME in notes[0]
    named = _cli("run", "--cart", cart_file.name, "--path", "lane-change", "--no-log", "--duration", "2",
                 cwd=cart_file.parent)
    assert "default path:" not in named.stderr  # a path given: nothing to name


def test_validate_names_a_derived_path_by_its_route_name(cart_file):
    from wmr_mj.report.text import _path_words

    path = default_path(load_cart(cart_file))
    assert _path_words({"path": path}) == f"the path route '{LOOP_NAME}'"  # not its canonical JSON
    assert _path_words({"path": "paper-circle"}) == "the paper circle"
    assert _path_words({"path": "lane-change"}) == "the path lane-change"


def test_a_config_built_directly_reads_its_path_none_as_the_default_of_its_parameters(cart_file):
    """RunConfig's path is None (the cart's own) until it is coerced; Python code that builds a reference from
    ``config.path`` directly (``build_reference(config.path, C80, ...)``, as before the field became None) gets
    the default path of the parameters it passes: the paper circle on the C80, the derived loop on this cart."""
    config = RunConfig()
    assert config.path is None
    c80_default, _ = build_reference(config.path, parameters_of_cart(load_cart("c80")), dt=1e-3, duration=20.0)
    c80_circle, _ = build_reference("paper-circle", parameters_of_cart(load_cart("c80")), dt=1e-3, duration=20.0)
    assert np.array_equal(c80_default.alpha0, c80_circle.alpha0)
    params = parameters_of_cart(load_cart(str(cart_file)))
    loop, _ = build_reference(None, params, dt=1e-3, duration=20.0)
    coerced_path = coerce(RunConfig(cart=str(cart_file))).path  # what a run on the cart resolves
    assert coerced_path == default_path(load_cart(str(cart_file))) != "paper-circle"
    assert np.array_equal(loop.alpha0, build_reference(coerced_path, params, dt=1e-3, duration=20.0)[0].alpha0)
    assert float(np.max(np.abs(loop.alpha0))) == pytest.approx(STEADY_RAD, abs=1e-9)  # as above: asin(l1/R)
