"""A run carries its claims by name: a second claim is one more entry of ``RunParts.claims``, measured and judged
as the law's is, and the run's numbers and verdict stay the law's claim's."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from wmr_mj.analysis.claim_types import LAW_CLAIM, Claims, judge
from wmr_mj.analysis.regions import BoxRegion
from wmr_mj.sim.closed_loop import run_parts
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.designs import CERTIFIED
from wmr_mj.sim.parts import resolve_run

MY_PID = f"{Path(__file__).resolve().parents[1] / 'examples' / 'my_pid.py'}:MyPID"

#: the two runs' clocks, the only keys of a summary that differ between two runs of one config
TIMING = ("wall_s", "realtime_factor")

#: a sensed, corrected run: the run measures two of its claims' assumptions (the sensing's error bounds, the
#: tracker's declared bounds), which a second claim must get as the law's does
SENSED = dict(**CERTIFIED.config_changes(), path="lane-change", duration=3.0, sensing="magnetic-14bit-axis",
              reference_bounds="paper", correction=True)


def _numbers(result) -> dict:
    return {k: v for k, v in result.summary.to_dict().items() if k not in TIMING}


def test_the_law_claim_is_the_entry_law_and_a_law_without_one_has_none():
    parts = resolve_run(RunConfig(path="lane-change", duration=3.0))
    assert isinstance(parts.claims, Claims) and list(parts.claims) == [LAW_CLAIM]
    assert parts.claim is parts.claims[LAW_CLAIM]
    silent = resolve_run(RunConfig(controller=MY_PID, path="lane-change", duration=3.0))  # it states no claim
    assert silent.claim is None and dict(silent.claims) == {}


def test_a_second_claim_is_one_more_entry_judged_as_the_law_claim_without_moving_a_number():
    plain = run_parts(resolve_run(RunConfig(**SENSED)), progress=False)
    parts = resolve_run(RunConfig(**SENSED))
    law = parts.claim
    assert law is not None
    E_max = law.E_max / 2.0  # a tighter box than the law's: a claim of the test's own, with the law's assumptions
    second = dataclasses.replace(law, region=BoxRegion(E_max=E_max), claimant="test-box")
    result = run_parts(dataclasses.replace(parts, claims=Claims({**parts.claims, "test-box": second})),
                       progress=False)

    # nothing the run measured or reported moved, and its verdict is still the law's claim's
    assert _numbers(result) == _numbers(plain)
    assert set(result.rows) == set(plain.rows)
    for name, column in plain.rows.items():
        assert np.array_equal(result.rows[name], column, equal_nan=True), name
    assert result.claims[LAW_CLAIM] is result.summary.certificate
    assert set(result.claims) == {LAW_CLAIM, "test-box"} and set(plain.claims) == {LAW_CLAIM}

    # the second claim got what the run measured of its assumptions, as the law's did ...
    judged = result.claims["test-box"]
    measured_names = {"measured errors within the assumed bounds", "reference within the declared bounds"}
    assert measured_names <= {a.name for a in judged.assumptions}
    assert judged.assumptions == result.summary.certificate.assumptions
    # ... and is judged by `judge` on the run's sup|E|, sup|E'|: its box's closed form |E| <= E_max
    sup_E, sup_Edot = result.summary.sup_E, result.summary.sup_Edot
    assert judged == judge(judged.certificate, sup_E, sup_Edot)
    assert judged.inside == (sup_E <= E_max)
    assert judged.E_ratio == sup_E / E_max and judged.Edot_ratio == 0.0
    assert judged.region_ratio == sup_E / E_max and math.isfinite(judged.region_ratio)


# --------------------------------------------------------------------------- the reproduce line parses back
#: `wmr-mj run` command lines, each a config the reproduce line must build again: a preset, a plug-in with
#: parameters, a sensed cart, trackers, ranged values (the --uncertainty box with --range added and replaced),
#: signals, a control period, plant overrides, a law's own estimate with a preset's unread settings
RUN_LINES = {
    "preset": ["--preset", "certified"],
    "plug-in": ["--controller", "examples/my_pid.py:MyPID", "--controller-param", "ki=20",
                "--controller-param", "P_hat=0.39", "--path", "lane-change", "--duration", "12.5"],
    "sensed-cart": ["--preset", "certified", "--sensing", "magnetic-14bit-axis", "--actuation",
                    "delay=0.002,inductance=0.0005,current_limit=20", "--backlash", "0.0015"],
    "tracker": ["--controller", "sliding-mode", "--tracker", "pure-pursuit", "--tracker-param", "lookahead=0.7",
                "--path", "lane-change", "--reference-bounds", "paper"],
    "correction": ["--preset", "certified", "--correction", "--path", "lane-change", "--m1", "712.25"],
    "ranged": ["--preset", "certified", "--uncertainty", "full", "--range", "R_a=1.0:1.4", "--range",
               "l3=0.14:0.15", "--m1-range", "500", "800", "--m1", "720.125"],
    "ranged-m1-box": ["--range", "mu=0.013:0.03", "--box", "derived", "--m1-inertia", "scale"],
    "signals": ["--preset", "certified", "--disturbance", "kind=step,amplitude=1,t1=5", "--d-max", "1.5",
                "--control-period", "0.002", "--param", "mu=0.02", "--steering-friction", "soft",
                "--tyre-contact", "soft"],
    "own-estimate": ["--preset", "certified", "--controller", "sliding-mode"],
    "omega-r": ["--omega-r", "4.5", "--friction-sign", "reference", "--friction-width", "0.02"],
}


def _run_config(argv):
    from wmr_mj.cli.app import build_parser
    from wmr_mj.cli.run import config_from_args

    args = build_parser().parse_args(["run", *argv])
    return config_from_args(args, m1=args.m1), args


@pytest.mark.parametrize("argv", list(RUN_LINES.values()), ids=list(RUN_LINES))
def test_the_reproduce_line_parses_back_into_the_same_config(argv):
    import shlex

    from wmr_mj.cli.falsify import reproduce_command

    config, args = _run_config(argv)
    line = reproduce_command(config, {}, args, law_settings=resolve_run(config).law_settings)
    words = shlex.split(line)
    assert words[:2] == ["wmr-mj", "run"], line
    again, _ = _run_config(words[2:])
    assert again.to_dict() == config.to_dict(), line
    assert reproduce_command(again, {}, args) == line  # a fixed point: the line of the line is the line


def test_the_reproduce_line_writes_what_falsify_wrote():
    """The table writes the options in the order falsify's hand-written line did, so its JSON keeps its text."""
    from wmr_mj.cli.falsify import reproduce_command

    config, args = _run_config(["--preset", "certified", "--uncertainty", "full", "--duration", "15",
                                "--m1", "692.3300677526303", "--param", "mu=0.02054295349737046"])
    assert reproduce_command(config, {}, args) == (
        "wmr-mj run --preset certified --controller computed-torque --model nonholonomic --kp 225.0 --kd 30.0 "
        "--friction-sign measured --friction-width 0.01 --path paper-circle --duration 15.0 --m1 692.3300677526303 "
        "--param mu=0.02054295349737046 --steering-friction stiction --tyre-contact stiff --m1-inertia payload "
        "--box derived --m1-range 550.0 750.0 --uncertainty full")


def test_every_run_option_is_in_the_table_and_the_table_is_the_parser():
    """The run command's parser has each row of the table (its flag, default and help), and every option of
    `wmr-mj run` that sets a RunConfig field is a row."""
    import argparse

    from wmr_mj.cli.run_options import add_options, run_options

    p = argparse.ArgumentParser()
    for group in ("run", "cart", "signals", "require"):
        add_options(p, group)
    actions = {a.option_strings[0]: a for a in p._actions if a.option_strings}
    rows = {r.flag: r for r in run_options()}
    for flag, row in rows.items():
        if row.group == "command":
            assert flag not in actions  # each command adds its own (--m1, --range)
            continue
        if "default" in row.settings:
            assert actions[flag].default == row.settings["default"], flag
        assert actions[flag].help and actions[flag].help == (row.help() if callable(row.help) else row.help)
    assert set(actions) - {"-h"} <= set(rows)


# --------------------------------------------------------------------------- one rule for --range
#: (--range item, the one line every command gives): names refused by the one rule, whatever the command
REFUSED = [
    ("m1=600:700", "give m1's range with --m1-range LO HI, not --range m1=..."),
    ("nope=1:2", "unknown parameter 'nope'; valid parameters: "),
    ("mu=0.03:0.01", "--range 'mu=0.03:0.01': the range of mu is empty or inverted; LO < HI is required"),
    ("mu=abc", "--range 'mu=abc' is not NAME=LO:HI (e.g. --range mu=0.015:0.02)"),
    ("mu=0:inf", "--range 'mu=0:inf': LO and HI must be finite numbers"),
]

#: each command with --range, as a user types it (refused before any run)
COMMANDS = {
    "run": ["run", "--no-log", "--duration", "10"],
    "sweep": ["sweep", "--n", "2", "--duration", "10"],
    "falsify": ["falsify", "--budget", "10", "--duration", "10"],
    "robustness": ["robustness", "--box", "derived"],
    "robustness --certificate": ["robustness", "--certificate"],
}


@pytest.mark.parametrize("command", list(COMMANDS))
@pytest.mark.parametrize(("item", "line"), REFUSED, ids=[r[0] for r in REFUSED])
def test_every_command_refuses_the_same_range_names_with_the_same_line(command, item, line, capsys, tmp_path):
    from wmr_mj.cli.app import main

    argv = [*COMMANDS[command], "--range", item]
    if command in ("sweep", "falsify"):
        argv += ["--out", str(tmp_path / "out")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"wmr-mj: error: {line}"), err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_command_reads_a_plant_range_the_same_way(command):
    """A plant parameter (R_a) replaces the range the --uncertainty box gives it, and adds one it has not (l3),
    in every command, by the one parser; the kinds a command does not vary are refused by name."""
    from wmr_mj.cli.ranges import RANGE_ACCEPTS, RANGE_KINDS, parse_ranges

    key = command.split()[0]
    items = ["R_a=1.0:1.4", "l3=0.14:0.15"]
    ranges = parse_ranges(items, command=key, accepts=RANGE_ACCEPTS[key])
    assert ranges.plant == {"R_a": (1.0, 1.4), "l3": (0.14, 0.15)}
    from wmr_mj.errors import ParameterError

    for name, kind in (("sensing.delay", "cart"), ("disturbance.amplitude", "signal"), ("path.k1", "path")):
        if kind in RANGE_ACCEPTS[key]:
            assert getattr(parse_ranges([f"{name}=0:1"], command=key, accepts=RANGE_ACCEPTS[key]), kind) == {
                name: (0.0, 1.0)}
        else:
            with pytest.raises(ParameterError, match=f"--range {name}: {key} does not vary "
                                                     f"{RANGE_KINDS[kind].split(' (')[0]}"):
                parse_ranges([f"{name}=0:1"], command=key, accepts=RANGE_ACCEPTS[key])


def test_the_box_of_a_run_has_its_range():
    """`wmr-mj run --range` (written by falsify's reproduce line) puts the range in the run's analysis box."""
    config, _ = _run_config(["--preset", "certified", "--uncertainty", "full", "--range", "R_a=1.0:1.4"])
    from wmr_mj.params import uncertainty_ranges

    full = {k: v for k, v in uncertainty_ranges("full").items() if k != "m1"}
    assert dict(config.box_ranges) == {**full, "R_a": (1.0, 1.4)}


@pytest.mark.slow
def test_falsify_reproduce_line_runs_and_gives_the_worst_run_bits(tmp_path, capsys):
    """End to end, with a ranged plant parameter (the old line's --range was refused by `wmr-mj run`): the
    reproduce line runs, and its run's sup|E| and claim are the search's worst run's, to the bit."""
    import json
    import shlex

    from wmr_mj.cli.app import main

    assert main(["falsify", "--preset", "certified", "--path", "lane-change", "--duration", "3", "--uncertainty",
                 "m1", "--range", "R_a=1.0:1.3", "--budget", "10", "--nthread", "1", "--out", str(tmp_path / "f"),
                 "--json"]) in (0, 3)
    found = json.loads(capsys.readouterr().out)
    words = shlex.split(found["reproduce"])
    assert words[:2] == ["wmr-mj", "run"] and "--range" in words, found["reproduce"]
    assert main([*words[1:], "--no-log", "--json"]) in (0, 3)
    run = json.loads(capsys.readouterr().out)
    assert run["sup_E"] == found["worst"]["sup_E"] and run["sup_Edot"] == found["worst"]["sup_Edot"]
    assert run["verdict"] == found["worst"]["verdict"]
    assert run["certificate"]["unmet"] == found["worst"]["unmet"]
    assert run["certificate"]["inputs"]["box_ranges"] == {"R_a": [1.0, 1.3]}  # the claim covers the searched box
