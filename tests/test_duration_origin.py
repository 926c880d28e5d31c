"""A refused duration says where it came from (issue 42, "the duration message names where the duration came
from"): the command's default --duration where none was given, the option where one was, and, for ``cart check``
(whose --duration is the identification's excitation), its runs on the path with the options that change it.

The truth is the command line itself: a slow cart (the C80's file at V_A = 0.01 m/s, whose paper circle's lead-in
and entry alone take 46 s) refuses the 35 s runs every command defaults to. Before: each said "duration = 35.0 s is
not accepted" (run excepted) although the user gave no duration.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest
from helpers import refused_line

from wmr_mj.carts import CARTS_DIR
from wmr_mj.cli.app import _with_where_duration_came_from, main
from wmr_mj.errors import DurationError, ParameterError
from wmr_mj.sim.config import RunConfig

DEFAULT_SAID = "(the duration is --duration's default, 35 s, as none was given; give --duration)"


@pytest.fixture(scope="module")
def slow(tmp_path_factory) -> Path:
    text = (CARTS_DIR / "c80.toml").read_text(encoding="utf-8").replace('name = "C80"', 'name = "slow"', 1)
    text, n = re.subn(r"(\[operation\.V_A\]\nvalue = )[^\n]+", r"\g<1>0.01", text)
    text, m = re.subn(r"(\[uncertainty\.full\.V_A\]\nrange = )[^\n]+", r"\g<1>[0.008, 0.012]", text)
    assert n == m == 1
    path = tmp_path_factory.mktemp("slow") / "slow.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _error_line(capsys, argv: list[str]) -> str:
    """The error line of a refused command that may have printed progress before it (exit status 2)."""
    assert main(argv) == 2
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("wmr-mj: error: ")]
    assert len(lines) == 1
    return lines[0]


@pytest.mark.parametrize("argv", [["run", "--no-log"], ["design", "--budget", "4"]], ids=["run", "design"])
def test_a_default_duration_refused_says_it_is_the_default(slow, capsys, argv):
    line = refused_line(capsys, [*argv, "--cart", str(slow)])
    assert "duration = 35.0 s is not accepted: the lead-in and entry alone take 46.089 s" in line
    assert line.endswith(DEFAULT_SAID)


def test_validates_default_duration_refused_says_it_is_the_default(slow, capsys):
    line = _error_line(capsys, ["validate", "--cart", str(slow), "--n", "1", "--search-budget", "0"])
    assert "duration = 35.0 s is not accepted" in line and line.endswith(DEFAULT_SAID)


def test_a_given_duration_refused_is_the_users(slow, capsys):
    line = refused_line(capsys, ["run", "--no-log", "--cart", str(slow), "--duration", "20"])
    assert "duration = 20.0 s is not accepted" in line and "default" not in line


def test_cart_checks_runs_refused_name_the_runs_and_the_options_that_change_them(slow, capsys):
    line = refused_line(capsys, ["cart", "check", str(slow)])
    assert "duration = 35.0 s is not accepted" in line and "cart check's runs on the path" in line
    assert "--path" in line and "[paths] default" in line and "--duration's default" not in line


def test_the_note_follows_the_errors_type_not_its_words():
    """Only a run's refused duration (:class:`DurationError`) gets the note: an excitation's "duration = ..." (a
    ParameterError, as identify's) is left as it is, and the note's default is the command's own."""
    plain = ParameterError("duration = 1.0 s must be finite and > 0")
    identify = argparse.Namespace(command="identify", duration=20.0)
    assert _with_where_duration_came_from(plain, identify, []) == str(plain)
    run = DurationError("duration = 35.0 s is not accepted")
    said = _with_where_duration_came_from(run, argparse.Namespace(command="run", duration=35.0), [])
    assert said == f"{run} {DEFAULT_SAID}"
    assert _with_where_duration_came_from(run, argparse.Namespace(command="run", duration=35.0),
                                          ["run", "--duration", "35"]) == str(run)


@pytest.mark.parametrize("changes", [{"duration": -1.0}, {"duration": 1.0, "control_period": 3.0},
                                     {"duration": 1.0, "control_period": 0.3}], ids=["negative", "longer", "part"])
def test_a_runs_refused_duration_is_a_duration_error(changes):
    with pytest.raises(DurationError):
        RunConfig(**changes)
