"""No function of the library (wmr_mj/, controllers/) is over 100 code lines: long ones are cut into named steps.

A function's code lines: the lines from its ``def`` to its last line that hold code, its docstring, blank lines
and comment-only lines left out; a nested function's lines count in the function around it too.
"""

from __future__ import annotations

import ast
import textwrap
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
LIMIT = 100
PACKAGES = ("wmr_mj", "controllers")


def code_lines(function: ast.FunctionDef | ast.AsyncFunctionDef, source_lines: list[str]) -> int:
    """The function's code lines (module docstring: what counts)."""
    lines = set(range(function.lineno, (function.end_lineno or function.lineno) + 1))
    first = function.body[0]
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str):
        lines -= set(range(first.lineno, (first.end_lineno or first.lineno) + 1))
    return sum(1 for i in lines if source_lines[i - 1].strip() and not source_lines[i - 1].lstrip().startswith("#"))


def _functions(path: Path):
    source = path.read_text(encoding="utf-8")
    lines = source.splitlines()
    for node in ast.walk(ast.parse(source, filename=str(path))):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield f"{path.relative_to(REPO)}:{node.lineno} {node.name}", code_lines(node, lines)


def test_the_counter_counts_code_lines_only():
    source = textwrap.dedent('''
        def f(a,
              b):
            """A docstring
            of three lines.
            """
            # a comment

            x = a  # code with a comment
            def g():
                return b
            return x + g()
        ''')
    (f,) = [n for n in ast.parse(source).body if isinstance(n, ast.FunctionDef)]
    assert code_lines(f, source.splitlines()) == 6  # def (2 lines), x =, def g, return b, return
    (g,) = [n for n in ast.walk(f) if isinstance(n, ast.FunctionDef) and n.name == "g"]
    assert code_lines(g, source.splitlines()) == 2


def test_no_function_is_over_100_code_lines():
    files = [p for package in PACKAGES for p in sorted((REPO / package).rglob("*.py"))]
    assert len(files) > 50  # the packages were found
    lengths = dict(item for path in files for item in _functions(path))
    assert len(lengths) > 500
    over = {name: n for name, n in lengths.items() if n > LIMIT}
    assert not over, f"functions over {LIMIT} code lines (cut them into named steps): {over}"


@pytest.mark.parametrize("name", ["run_engine"])
def test_the_engines_entry_point_is_short(name):
    """run_engine resolves the run's steppers and hands the blocks to _BlockLoop (it was 120 code lines)."""
    lengths = dict(_functions(REPO / "wmr_mj" / "sim" / "engine.py"))
    (n,) = [v for k, v in lengths.items() if k.endswith(f" {name}")]
    assert n <= 60


#: a command's ``run`` parses, calls the library and prints (issue 41: a thin CLI)
CLI_RUN_LIMIT = 60


def test_no_commands_run_is_over_60_code_lines():
    """Each ``wmr_mj/cli/*.py``'s top-level ``run`` is at most 60 code lines (sweep's was 96, run's 70, model's 88):
    what a command computes is the library's, its JSON the result's ``to_dict``."""
    runs = {}
    for path in sorted((REPO / "wmr_mj" / "cli").glob("*.py")):
        source = path.read_text(encoding="utf-8")
        for node in ast.parse(source).body:
            if isinstance(node, ast.FunctionDef) and node.name == "run":
                runs[path.name] = code_lines(node, source.splitlines())
    assert {"run.py", "sweep.py", "cart.py", "falsify.py", "model.py"} <= set(runs)  # the commands were found
    over = {name: n for name, n in runs.items() if n > CLI_RUN_LIMIT}
    assert not over, f"cli run functions over {CLI_RUN_LIMIT} code lines (move the work into the library): {over}"
