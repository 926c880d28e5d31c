"""Designs and presets: the certified design follows its written rule; the ladder changes one thing per rung."""

from __future__ import annotations

import argparse

import pytest

from wmr_mj.errors import UnknownNameError
from wmr_mj.params import PAPER_KD, PAPER_KP
from wmr_mj.sim.designs import CERTIFIED, ERROR_SPEC, LADDER, PAPER, PRESETS, certified_omega_r, preset


def test_certified_design_is_what_its_rule_gives():
    """The preset is the rule's answer (one answer, not two): the smallest omega_r of the grid whose certificate --
    the sampled-data one a run is judged by since issue 44 -- is valid with E_max <= ERROR_SPEC. It is omega_r 30
    (K_P 225, K_D 30): at omega_r 20 the held Coulomb sign alone, (F_max + F^)/P_min / K_P = 0.084 rad, is past
    ERROR_SPEC, and the certificate there is |E| <= 0.0922 rad."""
    w = certified_omega_r()
    assert w == 30.0
    assert (CERTIFIED.kp, CERTIFIED.kd) == (w ** 2 / 4.0, w)  # critical damping (3.6), K_P = omega_r^2/4, K_D = omega_r
    assert CERTIFIED.kd ** 2 == pytest.approx(4 * CERTIFIED.kp)


def test_rule_picks_the_smallest_gain_meeting_the_spec():
    # a looser spec can only pick a gain at most as large; an impossible one picks none
    w = certified_omega_r()
    assert certified_omega_r(error_spec=2 * ERROR_SPEC) <= w
    assert certified_omega_r(error_spec=1e-6) is None


def test_paper_preset_is_the_papers_design():
    assert (PAPER.model, PAPER.kp, PAPER.kd, PAPER.friction_sign, PAPER.friction_width) == (
        "paper", PAPER_KP, PAPER_KD, "measured", 0.0)


def test_ladder_changes_one_thing_per_rung_from_paper_to_certified():
    assert LADDER[0] == PAPER
    last = LADDER[-1].config_changes()
    assert last == CERTIFIED.config_changes()
    for a, b in zip(LADDER, LADDER[1:], strict=False):
        ca, cb = a.config_changes(), b.config_changes()
        changed = {k for k in ca if ca[k] != cb[k]}
        groups = [{"model"}, {"friction_sign", "friction_width"}, {"kp", "kd"}]
        assert any(changed and changed <= g for g in groups), (a.name, b.name, changed)


def test_unknown_preset_lists_the_valid_ones():
    with pytest.raises(UnknownNameError, match="certified, paper"):
        preset("robust")


def _config(argv):
    from wmr_mj.cli.run import config_from_args
    from wmr_mj.cli.run_options import add_options

    p = argparse.ArgumentParser()
    add_options(p, "run")
    add_options(p, "cart")
    p.add_argument("--m1", type=float, default=650.0)
    args = p.parse_args(argv)
    return config_from_args(args, m1=args.m1)


def test_preset_sets_the_configuration_and_explicit_options_override_it():
    c = _config(["--preset", "certified"])
    assert {k: getattr(c, k) for k in CERTIFIED.config_changes()} == CERTIFIED.config_changes()
    c = _config(["--preset", "certified", "--kp", "50", "--friction-width", "0"])
    assert (c.kp, c.kd, c.friction_width, c.model) == (50.0, CERTIFIED.kd, 0.0, CERTIFIED.model)
    c = _config([])  # default: the paper's design
    assert (c.model, c.kp, c.kd, c.friction_width) == ("paper", PAPER_KP, PAPER_KD, 0.0)
    assert set(PRESETS) == {"paper", "certified"}
