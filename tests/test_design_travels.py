"""compare and validate given a design file take what the design was found on (issue 42: "run, sweep, falsify,
compare and validate given --design FILE use its cart, box, path and sensing unless an option overrides one; an
override beyond the design's prints one note naming both").

Both read the file as ``run --design FILE`` does (wmr_mj.cli.run.with_design_file). The independent truth is the
design file itself: found by ``wmr-mj design`` on the new user's cart (tests/data/anycart.toml: its 80-120 kg m1
box, its own path anycart-loop.toml, a 12-bit axis encoder read 10 ms late). Before, compare refused such a file
without --cart, and validate ran the C80 with the paper circle and its 550-750 kg box.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from wmr_mj.cli.compare import design_files_found_on
from wmr_mj.cli.validate import _design_file_options
from wmr_mj.experiments.compare import design_from_token
from wmr_mj.experiments.suite import load_suite

DATA = Path(__file__).resolve().parent / "data"
CART_BOX = (80.0, 120.0)  # the cart file's [uncertainty.m1.m1] range, kg


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "wmr_mj.cli", *args], capture_output=True, text=True, timeout=300,
                          cwd=cwd, env={**os.environ, "MPLBACKEND": "Agg"})


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """A folder with the cart, its loop and a design found on them (10 certificates: a design file is what is read)."""
    where = tmp_path_factory.mktemp("travels")
    for name in ("anycart.toml", "anycart-loop.toml"):
        shutil.copy(DATA / name, where / name)
    proc = _cli("design", "--cart", "anycart.toml", "--budget", "10", "--duration", "10", "--out", "d.json",
                cwd=where)
    assert proc.returncode in (0, 1), proc.stderr  # 1: not certified in 10 evaluations; the file is written
    design = json.loads((where / "d.json").read_text())
    assert design["box"]["m1_range"] == list(CART_BOX) and design["search"]["paths"] == ["anycart-loop.toml"]
    return where


def _compare_args(folder: Path, *designs: str, cart: str | None = None) -> argparse.Namespace:
    return argparse.Namespace(designs=[str(folder / d) if d.endswith(".json") else d for d in designs], cart=cart)


def test_compare_takes_the_design_files_cart_box_and_path(folder):
    args = _compare_args(folder, "d.json", "certified")
    found = design_files_found_on(args)
    assert Path(args.cart).name == "anycart.toml"  # the design's cart: every design of the comparison runs on it
    suite = load_suite("standard-v1")
    on = {"cart": args.cart}
    file_design = design_from_token(args.designs[0], suite, cart=on, **found[args.designs[0]])
    assert file_design.config.m1_range == CART_BOX
    assert Path(file_design.config.path).name == "anycart-loop.toml"
    assert file_design.config.cart["name"] == "anycart"
    assert file_design.config.sensing.encoder_ticks == 4096 and file_design.config.sensing.delay == 0.01
    named = design_from_token("certified", suite, cart=on)  # a named design on the same cart: the cart's own box
    assert named.config.m1_range == CART_BOX and named.config.cart["name"] == "anycart"


def test_compare_with_another_cart_says_so_once_and_takes_that_carts_box(folder, capsys):
    args = _compare_args(folder, "d.json", cart="c80")
    found = design_files_found_on(args)
    notes = [line for line in capsys.readouterr().err.splitlines() if "not the cart the design" in line]
    assert len(notes) == 1 and "--cart c80" in notes[0] and "anycart 1.0.0" in notes[0]
    assert found[args.designs[0]]["m1_range"] is None  # the C80's box then, from the suite


def test_compare_cli_runs_a_design_file_found_on_another_cart_without_cart(folder):
    proc = _cli("compare", "d.json", "--scenarios", "lane/nominal/none", "--budget", "0", "--json", "--out", "cmp",
                cwd=folder)
    assert proc.returncode == 0, proc.stderr  # before: refused, "give --cart FILE"
    rows = [json.loads(line) for line in (folder / "cmp" / "runs.jsonl").read_text().splitlines()]
    assert rows and all(r["summary"]["m1"] == 100.0 for r in rows)  # the cart's nominal m1, not the C80's 650 kg


def test_validate_design_file_fills_cart_box_path_and_sensing_unless_given(folder, capsys):
    ns = argparse.Namespace(design=[str(folder / "d.json")], cart=None, path=None, sensing=None, actuation=None,
                            backlash=None)
    assert _design_file_options(ns) == CART_BOX
    assert Path(ns.cart).name == "anycart.toml" and ns.path.endswith("anycart-loop.toml")
    assert ns.sensing["encoder_ticks"] == 4096
    given = argparse.Namespace(design=[str(folder / "d.json")], cart="c80", path="lane-change", sensing="ideal",
                               actuation=None, backlash=None)
    assert _design_file_options(given) is None  # another cart: its own box
    assert (given.cart, given.path, given.sensing) == ("c80", "lane-change", "ideal")
    notes = [line for line in capsys.readouterr().err.splitlines() if "not the cart the design" in line]
    assert len(notes) == 1 and "--cart c80" in notes[0] and "anycart 1.0.0" in notes[0]


def test_validate_design_file_runs_on_the_designs_cart_box_and_path(folder):
    proc = _cli("validate", "--design", "d.json", "--n", "2", "--duration", "10", "--identify-duration", "10",
                "--search-budget", "0", "--seed", "3", "--out", "report", cwd=folder)
    assert proc.returncode == 0, proc.stderr
    first = proc.stdout.splitlines()[0]
    assert "the cart anycart 1.0.0 under m1 in 80-120 kg" in first and "anycart-loop.toml" in first
    for word in ("550", "750", "paper-circle", "paper circle"):
        assert word not in proc.stdout, word


#: a suite of the user's whose first scenario and adversary name no path: each runs the design's own
_OWN_PATH_SUITE = """
[suite]
name = "own-path"
version = 1
duration = 15.0

[plants.nominal]

[signals.none]

[requirements]
settled-error = "always[10,15](abs(E) <= 0.05)"

[adversary]
requirement = "settled-error"
uncertainty = "m1"
hold_range = [0.0, 3.0]
disturbance = { kind = "pulse", t1 = [5.0, 10.0], amplitude = [-1.0, 1.0], width = 1.0 }

[[scenario]]
id = "own/nominal/none"
plant = "nominal"
signals = "none"

[[scenario]]
id = "lane/nominal/none"
path = "lane-change"
plant = "nominal"
signals = "none"
"""


def test_compare_runs_a_scenario_that_names_no_path_on_the_design_files_path(folder):
    """A scenario (and the adversary) that names no path runs the design file's own (anycart-loop.toml, the path the
    design was found on); one that names its path runs that. Before: every scenario had to name one (the suite
    refused a scenario without ``path``), so the design file's path was never used by compare."""
    from wmr_mj.experiments.compare import adversary_spec

    (folder / "own-path.toml").write_text(_OWN_PATH_SUITE, encoding="utf-8")
    suite = load_suite(str(folder / "own-path.toml"))
    args = _compare_args(folder, "d.json")
    found = design_files_found_on(args)
    design = design_from_token(args.designs[0], suite, cart={"cart": args.cart}, **found[args.designs[0]])
    own, lane = suite.scenarios
    assert own.path is None and Path(own.config(design.config).path).name == "anycart-loop.toml"
    assert lane.config(design.config).path == "lane-change"
    assert Path(adversary_spec(design, suite, budget=16, seed=0).base.path).name == "anycart-loop.toml"
    proc = _cli("compare", "d.json", "--suite", "own-path.toml", "--scenarios", "own/*", "--budget", "0", "--json",
                "--out", "cmp-own", cwd=folder)
    assert proc.returncode == 0, proc.stderr
    rows = [json.loads(line) for line in (folder / "cmp-own" / "runs.jsonl").read_text().splitlines()]
    assert len(rows) == 1 and Path(rows[0]["summary"]["path"]).name == "anycart-loop.toml", rows
