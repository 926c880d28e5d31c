"""Issue 43's delays against a known truth: a cart whose 5 ms is 3 ms of sensing and 2 ms of actuation.

The true cart (tests/data/identify_truth.toml with a 12-bit axis encoder read 3 ms late and a motor that acts 2 ms
late) is recorded by the testbed's own run under the dithered PD of tests/data/identify_dithered_pd.py, as
tests/test_identify_walk.py records it: the voltage the law applied and the angle its encoder read. From those
only the sum is identifiable (a pure delay commutes with the plant). Independent truth: the true cart's own
delays (3 and 2 periods, set here), the per-split certificates of tests/test_delay_split.py, and MuJoCo runs of
the design on the true cart with its true split, measured, against the design file's certificate.
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from wmr_mj.analysis.delay_split import DELAY_SPLIT_COVERED
from wmr_mj.carts import load_cart
from wmr_mj.cli.app import main
from wmr_mj.hardware import Actuation, Sensing
from wmr_mj.plant.recordings import write_csv
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig

DATA = Path(__file__).resolve().parent / "data"
TRUTH = DATA / "identify_truth.toml"
START = DATA / "identify_start.toml"
LAW = DATA / "identify_dithered_pd.py"
PERIOD_S = 0.001  # the recordings' control period (every physics step)
SENSING_S, ACTUATION_S = 0.003, 0.002  # the truth: 3 ms of sensing, 2 ms of actuation
SENSING = f"encoder_ticks=4096,velocity=difference,delay={SENSING_S}"
ACTUATION = f"delay={ACTUATION_S}"
SWEEP_RUNS = 3

pytestmark = pytest.mark.slow


def _record_csv(path: str, seed: int, duration: float, out: Path) -> tuple[Path, Path]:
    """The true cart as its board logs it: the voltage the law applied (before the motor's 2 ms) and the angle read;
    and the same with the voltage at the motor as its driver would log it (``u_applied_V``: the law's voltage 2
    periods later, MuJoCo's actuator delay of the run, 0 V before the first)."""
    cfg = RunConfig.from_inputs(cart=str(TRUTH), sensing=SENSING, actuation=ACTUATION, path=path, duration=duration,
                                controller=f"{LAW}:DitheredPD", controller_params={"seed": seed})
    rows = run_closed_loop(cfg, progress=False).rows
    d_a = round(ACTUATION_S / PERIOD_S)
    applied = np.concatenate([np.zeros(d_a), rows["voltage"][:-d_a]])
    recorded = {"t_s": rows["t"], "u_V": rows["voltage"], "alpha_rad": rows["alpha_measured"]}
    return (write_csv(out, recorded),
            write_csv(out.with_name(out.stem + "-applied.csv"), {**recorded, "u_applied_V": applied}))


def _main(argv: list[str]) -> tuple[int, str]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(argv)
    return code, buf.getvalue()


@pytest.fixture(scope="module")
def walk(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Recordings of the 3 + 2 ms cart -> identify -> design over the identified box -> runs on the true cart."""
    folder = tmp_path_factory.mktemp("split")
    lane, lane_applied = _record_csv("lane-change", 0, 20.0, folder / "lane.csv")
    eight, eight_applied = _record_csv("figure-eight", 1, 20.0, folder / "eight.csv")
    new, design = folder / "new.toml", folder / "design.json"
    code, printed = _main(["identify", "--cart", str(START), "--data", f"{lane}:m1=100", "--data", f"{eight}:m1=100",
                           "--out", str(new), "--json"])
    identified = (code, json.loads(printed))
    separated = folder / "separated.toml"
    code, printed = _main(["identify", "--cart", str(START), "--data", f"{lane_applied}:m1=100",
                           "--data", f"{eight_applied}:m1=100", "--out", str(separated), "--json"])
    identified_apart = (code, json.loads(printed))
    designed = _main(["design", "--cart", str(new), "--uncertainty", "full", "--objective", "E_max", "--budget", "12",
                      "--out", str(design)])
    code, printed = _main(["sweep", "--design", str(design), "--cart", str(TRUTH), "--sensing", SENSING,
                           "--actuation", ACTUATION, "--n", str(SWEEP_RUNS), "--out", str(folder / "sweep"), "--json"])
    return {"new": new, "design": design, "identify": identified, "design_run": designed,
            "sweep": (code, json.loads(printed)), "separated": separated, "identify_apart": identified_apart}


def test_the_sum_is_found_to_one_period_and_each_interval_holds_its_truth(walk):
    code, obj = walk["identify"]
    assert code == 0 and obj["delay_split"] == "unknown"
    assert abs(obj["delay_s"]["value"] - (SENSING_S + ACTUATION_S)) <= PERIOD_S + 1e-12
    lo, hi = obj["delay_s"]["interval"]
    assert lo - 1e-12 <= SENSING_S + ACTUATION_S <= hi + 1e-12
    for key, truth in (("sensing_delay_s", SENSING_S), ("actuation_delay_s", ACTUATION_S)):
        lo, hi = obj[key]["interval"]
        assert lo == 0.0 and lo <= truth <= hi + 1e-12, (key, lo, hi)  # the data allow any split of the sum
        assert hi == obj["delay_s"]["interval"][1]


def test_the_cart_file_says_the_split_is_unknown_and_runs_one(walk):
    cart = load_cart(walk["new"])
    assert cart.defaults["delay_split"] == "unknown"
    assert "fix only the sum" in cart.default_sources["delay_split"]
    _code, obj = walk["identify"]
    sensing, actuation = Sensing.from_spec(cart.defaults["sensing"]), Actuation.from_spec(cart.defaults["actuation"])
    assert (sensing.delay, actuation.delay) == (obj["delay_s"]["value"], 0.0)  # the convention: all of it as sensing


def test_the_design_is_certified_over_every_split(walk):
    code, printed = walk["design_run"]
    design = json.loads(walk["design"].read_text(encoding="utf-8"))
    assert code == 0 and design["certified"]
    total = round(walk["identify"][1]["delay_s"]["value"] / PERIOD_S)
    for cert in design["certificates"].values():
        covered = next(a for a in cert["assumptions"] if a["name"] == DELAY_SPLIT_COVERED)
        assert covered["met"] and covered["value"] == covered["limit"] == total + 1  # every split certified
    assert f"delay {total:g} ms, any split sensing/actuation" in printed
    assert "they cover the measured delay in any split between sensing and actuation" in printed


def test_the_true_cart_with_its_true_split_stays_within_the_certificate(walk):
    code, swept = walk["sweep"]
    design = json.loads(walk["design"].read_text(encoding="utf-8"))
    assert code == 0 and swept["n"] == SWEEP_RUNS and swept["hit_steering_stop"] == 0
    assert swept["sensing"]["delay"] == SENSING_S and swept["actuation"]["delay"] == ACTUATION_S
    assert 0 < swept["worst_sup_E"] <= design["E_max"], (swept["worst_sup_E"], design["E_max"])


def test_the_voltage_at_the_motor_separates_them(walk):
    """With u_applied_V each delay is measured: 2 periods from u_V to the motor, the other 3 from the motor to the
    angle; the cart file runs the true split and says it is known (no split to cover)."""
    code, obj = walk["identify_apart"]
    assert code == 0 and obj["delay_split"] == "known"
    for key, truth in (("sensing_delay_s", SENSING_S), ("actuation_delay_s", ACTUATION_S)):
        lo, hi = obj[key]["interval"]
        assert abs(obj[key]["value"] - truth) <= PERIOD_S + 1e-12 and lo - 1e-12 <= truth <= hi + 1e-12, (key, obj[key])
    assert obj["actuation_delay_s"]["interval"] == [ACTUATION_S, ACTUATION_S]  # the driver's log: exact
    cart = load_cart(walk["separated"])
    assert cart.defaults["delay_split"] == "known"
    sensing, actuation = Sensing.from_spec(cart.defaults["sensing"]), Actuation.from_spec(cart.defaults["actuation"])
    assert (sensing.delay, actuation.delay) == (obj["sensing_delay_s"]["value"], obj["actuation_delay_s"]["value"])
