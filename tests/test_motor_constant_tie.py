"""The motor's one constant in a box: a box that ranges k_i and k_b (an identified cart's does) gives runs with
k_b = k_i, inside the box, never a run the cart-file rule k_b = k_i refuses.

Truth: in SI units the torque and back-EMF constants are one flux (k_i [N m/A] = k_b [V s/rad]); the diagonal
(k, k) of [lo, hi]^2 lies inside the square, so a tied run is inside the box its certificate covers.
"""

import pytest

from wmr_mj.errors import ParameterError
from wmr_mj.experiments.sweep import SweepSpec, draw_samples
from wmr_mj.params import C80, tie_motor_constant
from wmr_mj.searches.falsify import FalsifySpec
from wmr_mj.sim.config import RunConfig

K = C80.k_i
BOX = {"k_i": (0.95 * K, 1.05 * K), "k_b": (0.95 * K, 1.05 * K)}


def test_the_tie_sets_k_b_to_k_i_and_leaves_every_other_value():
    drawn = {"k_i": 1.01 * K, "k_b": 0.97 * K, "mu": 0.03}
    assert tie_motor_constant(drawn, BOX) == {"k_i": 1.01 * K, "k_b": 1.01 * K, "mu": 0.03}
    assert drawn["k_b"] == 0.97 * K  # a copy: the draw itself is kept
    assert tie_motor_constant({"k_b": 0.97 * K}, BOX) == {"k_b": 0.97 * K}  # k_b alone: nothing to tie to


def test_a_box_whose_k_b_range_does_not_hold_k_i_s_is_refused_naming_both():
    with pytest.raises(ParameterError, match=r"k_i over .* k_b over .*holding k_i's"):
        tie_motor_constant({"k_i": K, "k_b": K}, {"k_i": (0.9 * K, 1.1 * K), "k_b": (0.95 * K, 1.05 * K)})


def test_every_sweep_draw_over_both_constants_is_a_run_the_rule_accepts():
    spec = SweepSpec(n=6, seed=1, ranges=BOX, base=RunConfig.from_inputs(duration=10.0))
    points = draw_samples(spec)
    for values in points:
        config = spec.config_at(values)  # coerced here: a k_b apart from k_i would raise ParameterError
        k_i, k_b = config.plant_overrides["k_i"], config.plant_overrides["k_b"]
        assert k_b == k_i and BOX["k_b"][0] <= k_b <= BOX["k_b"][1]
        assert spec.recorded_values(values)["k_b"] == k_i  # runs.csv records what the run used
    assert len({float(v[2]) for v in points}) == len(points)  # k_b was drawn apart: the tie, not the draw, did it


def test_a_falsify_point_over_both_constants_is_tied_too():
    spec = FalsifySpec(base=RunConfig.from_inputs(duration=10.0), box={"m1": (550.0, 750.0), **BOX}, budget=8)
    config = spec.config([600.0, 1.02 * K, 0.96 * K])
    assert config.plant_overrides["k_b"] == config.plant_overrides["k_i"] == 1.02 * K
    assert spec.recorded_values([600.0, 1.02 * K, 0.96 * K])["k_b"] == 1.02 * K


def test_sweep_refuses_a_k_b_range_that_does_not_hold_k_i_s_in_one_line(tmp_path, capsys):
    from wmr_mj.cli.app import main

    code = main(["sweep", "--n", "2", "--duration", "15", "--range", f"k_i={0.9 * K}:{1.1 * K}",
                 "--range", f"k_b={0.95 * K}:{1.05 * K}", "--out", str(tmp_path / "sweep")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "k_b's range holding k_i's" in err
    assert "Traceback" not in err and not (tmp_path / "sweep").exists()  # refused before any work is written


def test_a_falsify_box_whose_k_b_range_does_not_hold_k_i_s_is_refused_at_its_spec():
    with pytest.raises(ParameterError, match=r"k_b's range holding k_i's"):
        FalsifySpec(base=RunConfig.from_inputs(duration=10.0), budget=8,
                    box={"m1": (550.0, 750.0), "k_i": (0.9 * K, 1.1 * K), "k_b": (0.95 * K, 1.05 * K)})
