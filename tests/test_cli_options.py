"""Every command's options come from the options table (wmr_mj/cli/command_options.py, wmr_mj/cli/run_options.py).

Two truths, each independent of the table's own code: the parser modules' source (read with ``ast``: no module of
``wmr_mj/cli`` but the table's adder calls argparse's ``add_argument``), and the parsers ``wmr-mj`` builds (each
action of each command's parser, in order, is a row of that command's table, with the row's flag, settings and
help).
"""

from __future__ import annotations

import argparse
import ast
from pathlib import Path

import pytest

from wmr_mj.cli.app import COMMANDS, build_parser
from wmr_mj.cli.command_options import COMMAND_OPTIONS, JSON, OUT, SEED, rows_of
from wmr_mj.cli.parsers.robustness import certificate_parser

CLI = Path(__file__).resolve().parents[1] / "wmr_mj" / "cli"
#: the only module that adds an option to a parser: the table row's own adder (and the help-on-read variant)
ADDER = CLI / "options.py"


def _calls_to(tree: ast.AST, names: tuple[str, ...]) -> list[int]:
    """Line numbers of the calls in ``tree`` to a function or method named one of ``names``."""
    lines = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
            if name in names:
                lines.append(node.lineno)
    return lines


def test_no_cli_module_adds_an_option_by_hand():
    """No parser (and no other module of the CLI) calls ``add_argument``: each option is a row that adds itself."""
    by_hand = {}
    for path in sorted(CLI.rglob("*.py")):
        if path == ADDER:
            continue
        lines = _calls_to(ast.parse(path.read_text()), ("add_argument", "add_argument_with_help_of"))
        if lines:
            by_hand[str(path.relative_to(CLI))] = lines
    assert by_hand == {}


def _parser_of(command: str) -> argparse.ArgumentParser:
    if command == "robustness --certificate":
        return certificate_parser()
    parser = build_parser((command,))
    return parser._subparsers._group_actions[0].choices[command]  # type: ignore[union-attr]


_REGISTRY = argparse.ArgumentParser()


def _help_of(row) -> str:
    return row.help() if callable(row.help) else row.help


@pytest.mark.parametrize("command", [*COMMANDS, "robustness --certificate"])
def test_each_option_of_each_parser_is_a_row_of_its_commands_table(command):
    """The command's parser holds exactly its table's rows, in the table's order, each with the row's flag,
    argparse settings and help."""
    assert set(COMMAND_OPTIONS) == {*COMMANDS, "robustness --certificate"}
    actions = [a for a in _parser_of(command)._actions if not isinstance(a, argparse._HelpAction)]
    rows = rows_of(command)
    # an option's first string is its row's flag (BooleanOptionalAction adds --no-FLAG); a positional's, its dest
    assert [(a.option_strings or [a.dest])[0] for a in actions] == [row.flag for row in rows]
    for action, row in zip(actions, rows):
        for key, value in row.settings.items():
            if key == "action":  # a class, or argparse's name of one ('append')
                assert isinstance(action, _REGISTRY._registry_get("action", value, value)), row.flag
            else:
                assert getattr(action, key) == value, (row.flag, key)
        assert action.help == _help_of(row), row.flag


def test_a_shared_option_is_one_row_with_the_commands_words():
    """--json, --out and --seed are one row each, used by every command that takes them: the same flag and type
    (cart's and design's --seed are int, kept as they were: a negative seed passes argparse there)."""
    taken = {"--json": JSON, "--out": OUT, "--seed": SEED}
    for command in COMMAND_OPTIONS:
        for row in rows_of(command):
            if row.flag in taken:
                shared = taken[row.flag]
                differing = {k for k in {*row.settings, *shared.settings}
                             if row.settings.get(k) != shared.settings.get(k)}
                assert differing <= {"metavar", "default", "required", "type"}, (command, row.flag, differing)
                if "type" in differing:
                    assert (command, row.settings["type"]) in {("cart", int), ("design", int)}
