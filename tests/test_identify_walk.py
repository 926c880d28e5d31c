"""The walk of issue 43's "done when": two CSV recordings of a cart the project has never seen -> ``identify`` ->
``design`` -> ``validate``, and the design's runs on the true cart within its certificate.

The true cart (tests/data/identify_truth.toml, never given to identify or design) is recorded by the testbed's own
run with its real sensor (a 12-bit axis encoder, a 5 ms delay) under the dithered PD of
tests/data/identify_dithered_pd.py, as tests/test_identify_data.py records it. The user's start
(tests/data/identify_start.toml) has the steering beam's mass, the motor constant and the friction written wrong.
Independent truth: the true cart's own numbers (the file), the recordings' bytes (SHA-256 by hashlib), and MuJoCo
runs of the design's gains on the true cart, measured, against the design file's certificate.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from wmr_mj.carts import load_cart
from wmr_mj.cli.app import main
from wmr_mj.hardware.sensing import Sensing
from wmr_mj.params import parameters_of_cart
from wmr_mj.plant.recordings import write_csv

DATA = Path(__file__).resolve().parent / "data"
TRUTH = DATA / "identify_truth.toml"
START = DATA / "identify_start.toml"
LAW = DATA / "identify_dithered_pd.py"
SENSING = "encoder_ticks=4096,velocity=difference,delay=0.005"  # the true cart's sensor: 12 bits, 5 ms
TICKS, DELAY_S = 4096, 0.005
SWEEP_RUNS = 4  # runs of the design on the true cart over its m1 box (LHS)

pytestmark = pytest.mark.slow


def _record_csv(path: str, seed: int, duration: float, out: Path) -> Path:
    """A recording of the true cart as its board logs it: the voltage applied and the angle its encoder read."""
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig

    cfg = RunConfig.from_inputs(cart=str(TRUTH), sensing=SENSING, path=path, duration=duration,
                                controller=f"{LAW}:DitheredPD", controller_params={"seed": seed})
    rows = run_closed_loop(cfg, progress=False).rows
    return write_csv(out, {"t_s": rows["t"], "u_V": rows["voltage"], "alpha_rad": rows["alpha_measured"]})


def _main(argv: list[str]) -> tuple[int, str]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(argv)
    return code, buf.getvalue()


def _json(argv: list[str]) -> tuple[int, dict[str, Any]]:
    code, printed = _main(argv)
    return code, json.loads(printed)


@pytest.fixture(scope="module")
def walk(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """identify -> design -> runs on the true cart, as a user types them (one fixture: ~20 s on 2 cores)."""
    folder = tmp_path_factory.mktemp("walk")
    lane = _record_csv("lane-change", 0, 20.0, folder / "lane.csv")
    eight = _record_csv("figure-eight", 1, 20.0, folder / "eight.csv")
    new, design = folder / "new.toml", folder / "design.json"
    identify_code, identified = _json(["identify", "--cart", str(START), "--data", f"{lane}:m1=100",
                                       "--data", f"{eight}:m1=100", "--out", str(new), "--json"])
    # design over the identified box (--uncertainty full: the intervals identify wrote) on the measured sensing
    # (the new cart's default); a small budget: a certified design, not the best one
    design_code, printed = _main(["design", "--cart", str(new), "--uncertainty", "full", "--objective", "E_max",
                                  "--budget", "12", "--out", str(design)])
    # the design's gains on the TRUE cart with its real sensor, m1 over the box: measured sup|E| of each run
    sweep_code, swept = _json(["sweep", "--design", str(design), "--cart", str(TRUTH), "--sensing", SENSING,
                               "--n", str(SWEEP_RUNS), "--out", str(folder / "sweep"), "--json"])
    return {"folder": folder, "lane": lane, "eight": eight, "new": new, "design": design,
            "identify": (identify_code, identified), "design_run": (design_code, printed),
            "sweep": (sweep_code, swept)}


def test_the_identified_box_contains_the_truth(walk):
    code, _obj = walk["identify"]
    assert code == 0
    truth = parameters_of_cart(load_cart(TRUTH))
    box = load_cart(walk["new"]).uncertainty["full"]
    for name in ("front_axle_mass", "k_i", "k_b", "mu"):  # identified: the start's values lie outside
        assert name in box
    for name, (lo, hi) in box.items():  # every ranged parameter of the box the design covers
        assert lo <= getattr(truth, name) <= hi, (name, lo, hi, getattr(truth, name))


def test_a_measured_delay_and_encoder(walk):
    _code, obj = walk["identify"]
    sensing = Sensing.from_spec(load_cart(walk["new"]).defaults["sensing"])
    assert obj["encoder_ticks"] == TICKS and sensing.encoder_ticks == TICKS and sensing.encoder_side == "axis"
    assert abs(sensing.delay - DELAY_S) <= 1e-12  # found to the control period (1 ms); here exactly


def test_a_design_certified_over_that_box_naming_its_data(walk):
    code, printed = walk["design_run"]
    design = json.loads(walk["design"].read_text(encoding="utf-8"))
    new = load_cart(walk["new"])
    assert code == 0 and design["certified"] and np.isfinite(design["E_max"])
    assert all(cert["certified"] for cert in design["certificates"].values())
    for name, (lo, hi) in new.uncertainty["full"].items():  # the box certified is the identified one
        ranges = design["box"]["box_ranges"] if name != "m1" else design["box"]["m1_range"]
        assert (ranges[name] if name != "m1" else ranges) == [lo, hi], name
    named = [(d["file"], d["sha256"]) for d in design["cart"]["identified_from"]]
    assert named == [(str(p), hashlib.sha256(p.read_bytes()).hexdigest()) for p in (walk["lane"], walk["eight"])]
    assert f"is identified from {walk['lane']} (SHA-256 " in printed


def test_its_runs_on_the_true_cart_stay_within_its_certificate(walk):
    code, swept = walk["sweep"]
    design = json.loads(walk["design"].read_text(encoding="utf-8"))
    assert code == 0 and swept["n"] == SWEEP_RUNS and swept["hit_steering_stop"] == 0
    assert swept["sensing"]["encoder_ticks"] == TICKS and swept["sensing"]["delay"] == DELAY_S
    assert 0 < swept["worst_sup_E"] <= design["E_max"], (swept["worst_sup_E"], design["E_max"])


def test_validate_on_the_identified_cart_names_its_data_first(walk):
    # over the identified box (--uncertainty full): its runs take k_b = k_i (one flux; wmr_mj.params.tie_motor_constant)
    out = walk["folder"] / "validate"
    code, printed = _main(["validate", "--cart", str(walk["new"]), "--design", str(walk["design"]),
                           "--uncertainty", "full", "--n", "2", "--duration", "10", "--search-budget", "0",
                           "--identify-duration", "5", "--out", str(out)])
    lines = printed.splitlines()
    assert code == 0
    assert lines[0].startswith("Question: ")  # the verdict's first line names the data the cart rests on
    assert ("(identified from lane.csv and eight.csv; the answer assumes the real cart inside its identified box, its "
            "delay in any split between sensing and actuation)") in lines[0]  # the data fix only the delay's sum
    sha = hashlib.sha256(walk["lane"].read_bytes()).hexdigest()  # and, after the details, each file's SHA-256
    assert f"is identified from {walk['lane']} (SHA-256 {sha[:12]}" in printed
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    (mine,) = summary["designs"]
    assert mine["verdicts"]["certified-inside"] == mine["n"] == 2
