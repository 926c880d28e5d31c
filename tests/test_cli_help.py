"""Building the ``wmr-mj`` parser imports no simulation: ``wmr-mj --help`` and a bad option answer at once.

The truth is ``sys.modules`` of a fresh interpreter (a subprocess: this one has imported everything already)
after ``import wmr_mj.cli.app``, building the parser as ``main`` builds it for a command line and refusing a bad
option with it; and the help pages, whose lists of names (the laws, the paths, the suites) are computed when
shown, name what the library holds. Timed by bench/bench_cli_help.py, not here.
"""

from __future__ import annotations

import importlib
import json
import subprocess
import sys

import pytest

from wmr_mj.cli.app import COMMANDS, build_parser

#: what only a command's implementation needs: MuJoCo, scipy, the laws and the layers that simulate
HEAVY_PACKAGES = ("mujoco", "scipy", "controllers")
HEAVY_LAYERS = ("wmr_mj.sim", "wmr_mj.searches", "wmr_mj.experiments", "wmr_mj.reference", "wmr_mj.plant",
                "wmr_mj.analysis", "wmr_mj.report", "wmr_mj.figures", "wmr_mj.logs")
#: of those, the modules that hold a command's defaults and import only the standard library at their top (and their
#: packages): validate's and design's
DEFAULTS_MODULES = ("wmr_mj.report", "wmr_mj.report.defaults", "wmr_mj.searches", "wmr_mj.searches.design_options")

_PROBE = """
import contextlib, io, json, sys
from wmr_mj.cli.app import build_parser
for command in json.loads(sys.argv[1]):
    parser = build_parser(tuple(command))
    with contextlib.redirect_stderr(io.StringIO()) as err:
        try:  # a bad option, refused as main refuses it
            parser.parse_args([*command, "--bogus"])
        except SystemExit as exc:
            assert exc.code == 2 and len(err.getvalue().splitlines()) == 1, err.getvalue()
        else:
            raise AssertionError("--bogus was accepted")
heavy = sorted(m for m in sys.modules if m.split(".")[0] in json.loads(sys.argv[2])
               or m.startswith(tuple(p + "." for p in json.loads(sys.argv[3]))) or m in json.loads(sys.argv[3]))
print(json.dumps(heavy))
"""


def _imported_by_building(commands: list[list[str]]) -> list[str]:
    proc = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(commands), json.dumps(HEAVY_PACKAGES),
                           json.dumps(HEAVY_LAYERS)], capture_output=True, text=True, timeout=60, check=True)
    return [m for m in json.loads(proc.stdout) if m not in DEFAULTS_MODULES]


def test_the_top_level_parser_imports_no_simulation():
    """``wmr-mj --help``, ``wmr-mj`` and ``wmr-mj --bogus`` build the parser with no command registered."""
    assert _imported_by_building([[]]) == []


@pytest.mark.parametrize("command", COMMANDS)
def test_a_commands_parser_imports_no_simulation(command):
    """``wmr-mj run --bogus`` builds run's options, helps included, and refuses the option in one line without
    importing what runs it."""
    assert _imported_by_building([[command]]) == []


def test_main_builds_only_the_command_given(capsys):
    from wmr_mj.cli.app import _commands_of

    assert _commands_of(["run", "--kp", "3"]) == ("run",)
    assert _commands_of(["--help"]) == _commands_of([]) == _commands_of(["no-such-command"]) == ()
    parser = build_parser(("run",))
    assert parser.parse_args(["run", "--kp", "3"]).kp == 3.0
    with pytest.raises(SystemExit) as exc:
        parser.parse_args(["sweep", "--n", "3"])  # listed, not registered: main never builds it for a run line
    assert exc.value.code == 2
    with pytest.raises(SystemExit):
        build_parser(()).parse_args(["--help"])
    listing = capsys.readouterr().out
    for command in COMMANDS:  # every command, with its one line
        module = importlib.import_module(f"wmr_mj.cli.parsers.{command}")
        assert f"    {command} " in listing and " ".join(module.HELP.split()[:3]) in " ".join(listing.split())


def test_each_command_is_a_parser_and_an_implementation_run_by_name():
    """``main`` runs ``wmr_mj.cli.<name>.run`` for the command given (wmr_mj/cli/app.py): every command has its parser
    module (HELP, register) and its implementation module (run), and the dispatch finds the latter by name."""
    from wmr_mj.cli.app import PARSERS, _implementation

    assert tuple(PARSERS) == COMMANDS
    for command in COMMANDS:
        implementation = importlib.import_module(f"wmr_mj.cli.{command}")
        assert PARSERS[command] is importlib.import_module(f"wmr_mj.cli.parsers.{command}")
        assert PARSERS[command].HELP and callable(PARSERS[command].register)
        assert _implementation(command) is implementation.run


def test_a_help_that_names_the_librarys_names_lists_them(capsys, monkeypatch):
    """The helps computed when shown (the table of run options, compare's --suite) name what the library holds."""
    monkeypatch.setenv("COLUMNS", "10000")  # one line per help: argparse wraps at a hyphen (sliding-mode)
    from controllers.registry import controller_names, tracker_names
    from wmr_mj.experiments.suite import suite_names
    from wmr_mj.sim.config import PATH_NAMES
    from wmr_mj.sim.designs import PRESET_NAMES

    pages = {}
    for command in ("run", "compare"):
        with pytest.raises(SystemExit):
            build_parser((command,)).parse_args([command, "--help"])
        pages[command] = " ".join(capsys.readouterr().out.split())
    for names in (controller_names(), tracker_names(), PATH_NAMES, PRESET_NAMES):
        assert f"one of {', '.join(names)}" in pages["run"]
    assert f"one of {', '.join(suite_names())}" in pages["compare"]
