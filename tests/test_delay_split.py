"""A delay known only as its sum (issue 43): the sampled-data certificate over every split of it.

Independent truth: each split's certificate computed alone, by a run on a cart file without
``[defaults.delay_split]`` whose sensing and actuation delays are that split (``SampledCart.of`` from the run's own
parts, not the split loop's ``dataclasses.replace``); the worst over the splits must be at least each of them and
equal one. A certificate assembled by hand (one split uncertified) checks the rule that no split may fail. The
actuation delay read from an actuator-side signal (u_applied_V) against the shift the recordings were built with.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from wmr_mj.analysis.claim import ClaimContext
from wmr_mj.analysis.claim_types import Assumption, Certificate
from wmr_mj.analysis.delay_split import (
    DELAY_SPLIT_COVERED,
    covered_split,
    delay_splits,
    split_label,
    worst_over_splits,
)
from wmr_mj.analysis.plant_box import PlantBox, PlantLimits
from wmr_mj.analysis.regions import BoxRegion
from wmr_mj.analysis.robustness import ParameterBox
from wmr_mj.carts import load_cart, load_cart_text
from wmr_mj.carts.provenance import delay_split_unknown
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.params import C80
from wmr_mj.plant.output_error import actuation_delay_of
from wmr_mj.plant.recordings import Recording
from wmr_mj.reference.bounds import ReferenceBounds
from wmr_mj.sim.coerce import delay_split_of
from wmr_mj.sim.parts import resolve_run
from wmr_mj.sim.run_config import RunConfig

DATA = Path(__file__).resolve().parent / "data"
TRUTH = DATA / "identify_truth.toml"  # the lab cart of tests/test_identify_walk.py (100 kg, 50:1, 12 bits)
T = 0.001
# the walk's design (docs/guides/identify.md, section 4): the gains identify -> design found on the identified cart
GAINS = {"model": "nonholonomic", "kp": 904.536, "kd": 53.7673, "friction_width": 0.002722}
SPLIT_BLOCK = ('\n[defaults.delay_split]\nvalue = "unknown"\nsource = "the tests: only the sum of the sensing and '
               'actuation delays is known"\n')


def _unknown_split_cart(tmp_path: Path) -> Path:
    path = tmp_path / "split-unknown.toml"
    path.write_text(TRUTH.read_text(encoding="utf-8") + SPLIT_BLOCK, encoding="utf-8")
    return path


def _claim(cart: Path, d_s: int, d_a: int, controller: str = "computed-torque"):
    gains = GAINS if controller == "computed-torque" else {}
    cfg = RunConfig.from_inputs(cart=str(cart), controller=controller, **gains, control_period=T,
                                sensing=f"encoder_ticks=4096,velocity=difference,delay={d_s * T!r}",
                                actuation=f"delay={d_a * T!r}", path="paper-circle")
    parts = resolve_run(cfg)
    return parts, parts.claim


def test_delay_splits_all_sensing_first():
    assert delay_splits(5) == ((5, 0), (4, 1), (3, 2), (2, 3), (1, 4), (0, 5))
    assert delay_splits(0) == ((0, 0),)
    for bad in (-1, 1.5, True):
        with pytest.raises(ParameterError, match="whole number"):
            delay_splits(bad)  # type: ignore[arg-type]
    assert split_label(5, T) == "delay 5 ms, any split sensing/actuation"


def test_the_worst_over_splits_is_at_least_each_split_and_equals_one(tmp_path):
    """3 ms sensing + 2 ms actuation on a cart whose split is unknown: the claim covers all six splits of 5 periods."""
    parts, claim = _claim(_unknown_split_cart(tmp_path), 3, 2)
    # the run simulates the split it was given; the certificate covers every split
    assert parts.sensing.delay == 3 * T and parts.actuation.delay == 2 * T
    alone = {(d_s, d_a): _claim(TRUTH, d_s, d_a)[1] for d_s, d_a in delay_splits(5)}
    assert all(c.certified and math.isfinite(c.E_max) for c in alone.values())
    assert len({c.E_max for c in alone.values()}) == 6  # the split moves the bound (else there is nothing to cover)
    for split, cert in alone.items():
        assert claim.E_max >= cert.E_max, split
        assert claim.voltage_max >= cert.voltage_max, split
    worst = max(alone, key=lambda s: alone[s].E_max)
    assert claim.E_max == alone[worst].E_max  # one of them, exactly: no margin added, none lost
    assert claim.voltage_max == max(c.voltage_max for c in alone.values())
    record = claim.inputs["delay_split"]
    assert record["total_periods"] == 5 and record["simulated"] == [3, 2] and record["worst"] == list(worst)
    assert {(r["sensing_periods"], r["actuation_periods"]): r["E_max"] for r in record["splits"]} == \
        {s: c.E_max for s, c in alone.items()}
    assert claim.certified and DELAY_SPLIT_COVERED not in claim.unmet
    cart = claim.inputs["cart"]  # the claimed numbers are the worst split's, and say so
    assert [cart["sensing_delay_periods"], cart["actuation_delay_periods"]] == list(worst)
    assert covered_split(claim.assumptions) == "delay 5 ms, any split sensing/actuation"
    # the split the run simulates alone is not the worst here: the claim is larger than that split's
    assert claim.E_max > alone[(3, 2)].E_max


def test_a_known_split_is_certified_as_written():
    """Without [defaults.delay_split] nothing changes: no split assumption, the run's own split certified."""
    _parts, claim = _claim(TRUTH, 3, 2)
    assert DELAY_SPLIT_COVERED not in {a.name for a in claim.assumptions}
    assert "delay_split" not in claim.inputs and covered_split(claim.assumptions) is None
    cart = claim.inputs["cart"]
    assert (cart["sensing_delay_periods"], cart["actuation_delay_periods"]) == (3, 2)


def test_the_sliding_mode_layer_is_covered_over_the_splits_too(tmp_path):
    _parts, claim = _claim(_unknown_split_cart(tmp_path), 5, 0, controller="sliding-mode")
    assert DELAY_SPLIT_COVERED in {a.name for a in claim.assumptions}
    assert [(r["sensing_periods"], r["actuation_periods"]) for r in claim.inputs["delay_split"]["splits"]] == \
        list(delay_splits(5))


def _cert(E_max: float, *, met: bool = True, voltage: float = 5.0) -> Certificate:
    return Certificate(region=BoxRegion(E_max=E_max, Edot_max=10 * E_max), valid=True,
                       assumptions=(Assumption("supply", "|u| <= 24 V", met, voltage, 24.0),),
                       alpha_max=0.5 + E_max, voltage_max=voltage)


def test_one_split_uncertified_leaves_the_whole_uncertified():
    certs = {(2, 0): _cert(0.03), (1, 1): _cert(0.01, met=False, voltage=30.0), (0, 2): _cert(0.02)}
    cert = worst_over_splits(certs, control_period=T, simulated=(2, 0))
    assert not cert.certified
    covered = next(a for a in cert.assumptions if a.name == DELAY_SPLIT_COVERED)
    assert not covered.met and (covered.value, covered.limit) == (2.0, 3.0)
    assert "1+1: E_max 0.01 rad (not certified: supply)" in covered.note
    assert cert.assumptions[0].met is False  # the failing split's own assumptions are the ones carried
    assert cert.E_max == 0.03 and cert.Edot_max == 0.3 and cert.voltage_max == 30.0  # the box of the boxes
    assert covered_split(cert.assumptions) is None
    with pytest.raises(ParameterError, match="not of one total"):
        worst_over_splits({(1, 0): _cert(0.01), (1, 1): _cert(0.01)}, control_period=T)
    with pytest.raises(ParameterError, match="no certificate"):
        worst_over_splits({}, control_period=T)


def test_the_cart_file_key_is_checked(tmp_path):
    cart = load_cart(_unknown_split_cart(tmp_path))
    assert cart.defaults["delay_split"] == "unknown" and delay_split_unknown(cart.text)
    assert not delay_split_unknown(TRUTH.read_text(encoding="utf-8")) and "delay_split" not in load_cart(TRUTH).defaults
    assert delay_split_of(None) == "known"
    assert delay_split_of({"text": cart.text, "path": str(cart.path)}) == "unknown"
    bad = TRUTH.read_text(encoding="utf-8") + SPLIT_BLOCK.replace('"unknown"', '"maybe"')
    with pytest.raises(ParameterError, match=r"defaults.delay_split.value = 'maybe' is not accepted; accepted: "
                                             r"'known' or 'unknown'"):
        load_cart_text(bad, path="bad.toml")


def test_a_claim_context_refuses_an_unknown_split_word():
    ref = ReferenceBounds(alpha_max=0.5, alpha_dot_max=0.2, alpha_ddot_max=0.1)
    box = PlantBox(box=ParameterBox(P=(0.385, 0.385), C_V=(4.77, 4.77), F=(1.5, 1.5), K=(0.0, 0.0)),
                   gyro=(0.6, 0.6), V_A=(0.2, 0.2))
    with pytest.raises(UnknownNameError):
        ClaimContext(plant=box, reference=ref, limits=PlantLimits(steering_range=0.9, voltage_limit=24.0),
                     control_period=T, initial_error=(0.0, 0.0), estimate=C80, delay_split="maybe")


# -- an actuator-side signal separates them (u_applied_V) --------------------------------------------------------
def _recording(d_a: int, *, seconds: float = 4.0, seed: int = 0, applied: bool = True) -> Recording:
    """A voltage of 1 kHz steps and its copy d_a periods later (what a driver logging its output would record)."""
    rng = np.random.default_rng(seed)
    n = int(seconds / T)
    u = np.repeat(rng.uniform(-5.0, 5.0, n // 20 + 1), 20)[:n] + rng.normal(0.0, 0.5, n)
    late = np.concatenate([np.zeros(d_a), u[:n - d_a]])
    t = np.arange(n) * T
    return Recording(name=f"rec{seed}.csv", sha256="", t=t, voltage=u, alpha=np.zeros(n),
                     applied=late if applied else None)


def test_the_applied_voltage_gives_the_actuation_delay_exactly():
    # independent truth: the shift the recordings were built with
    assert actuation_delay_of([_recording(2), _recording(2, seed=1)], steps=1000, max_delay=50, total=5) == (2, 2, 2)
    assert actuation_delay_of([_recording(0)], steps=1000, max_delay=50, total=5) == (0, 0, 0)
    assert actuation_delay_of([_recording(2, applied=False)], steps=1000, max_delay=50, total=5) is None


def test_an_applied_voltage_that_does_not_fit_is_one_line():
    with pytest.raises(ParameterError, match="u_applied_V is recorded in rec0.csv but not in the others"):
        actuation_delay_of([_recording(2), _recording(2, seed=1, applied=False)], steps=1000, max_delay=50, total=5)
    with pytest.raises(ParameterError, match="beyond the 1 from u_V to the angle"):
        actuation_delay_of([_recording(2)], steps=1000, max_delay=50, total=1)
    other = _recording(2)
    wrong = Recording(name="wrong.csv", sha256="", t=other.t, voltage=other.voltage, alpha=other.alpha,
                      applied=_recording(2, seed=7).voltage)  # another recording's voltage
    with pytest.raises(ParameterError, match="u_applied_V does not follow u_V at any delay of 0-50 control periods"):
        actuation_delay_of([wrong], steps=1000, max_delay=50, total=5)


def test_a_run_says_which_delay_it_was_certified_for(tmp_path, capsys):
    cart = _unknown_split_cart(tmp_path)
    argv = ["run", "--cart", str(cart), "--model", "nonholonomic", "--kp", str(GAINS["kp"]), "--kd", str(GAINS["kd"]),
            "--friction-width", str(GAINS["friction_width"]), "--sensing", "encoder_ticks=4096,velocity=difference,"
            "delay=0.003", "--actuation", "delay=0.002", "--path", "paper-circle", "--duration", "8",
            "--out", str(tmp_path / "run.mcap"), "--no-progress"]
    assert main(argv) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("certificate:"))
    assert "the sampled-data certificate (delay 5 ms, any split sensing/actuation; section 4's" in line


def test_a_plug_in_claim_that_does_not_cover_the_splits_is_not_certified(tmp_path):
    """examples/observer_law.py computes its claim on the split the run simulates: on a cart whose split is unknown
    the assumption is added unmet (as an uncovered sensing is), and on a cart whose split is known nothing is."""
    law = str(Path(__file__).resolve().parent.parent / "examples" / "observer_law.py") + ":ObserverLaw"

    def claim(cart: Path):
        cfg = RunConfig.from_inputs(cart=str(cart), controller=law, control_period=T, path="paper-circle",
                                    sensing="encoder_bits=13,velocity=none,delay=0.003")
        return resolve_run(cfg).claim

    unknown, known = claim(_unknown_split_cart(tmp_path)), claim(TRUTH)
    added = next(a for a in unknown.assumptions if a.name == DELAY_SPLIT_COVERED)
    assert not added.met and not unknown.certified and "does not state that it covers every split" in added.note
    assert added.equation.endswith("delay 3 ms, any split sensing/actuation")
    assert DELAY_SPLIT_COVERED not in {a.name for a in known.assumptions}
    assert [a for a in unknown.assumptions if a.name != DELAY_SPLIT_COVERED] == list(known.assumptions)
