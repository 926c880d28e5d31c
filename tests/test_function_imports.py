"""Imports at module top: a project import inside a function stays only with a comment saying why.

The developers' guide ("Imports at module top"): a module's top shows what it depends on, so a function-level
import is kept only for a heavy optional dependency, a plug-in, a C extension that may be missing, or a module
that must not load yet (MuJoCo picks its OpenGL backend when first imported); each says so in a comment on its
own line or the line above. This test reads each module of the packages and top-level modules below with ``ast``
and lists every import of ``wmr_mj`` or ``controllers`` inside a function (at any depth) without one. Every package
is swept but those of ``NOT_YET``, which join the list when their function-level imports are moved or explained.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("wmr_mj/logs", "wmr_mj/report", "wmr_mj/analysis", "wmr_mj/plant", "wmr_mj/figures", "wmr_mj/_util",
            "controllers")
#: the run, what asks for runs, and the layers below them; and wmr_mj's own top-level modules (files)
PACKAGES += ("wmr_mj/cli", "wmr_mj/sim", "wmr_mj/searches", "wmr_mj/experiments", "wmr_mj/reference",
             "wmr_mj/hardware", "wmr_mj/carts", "wmr_mj/__init__.py", "wmr_mj/errors.py", "wmr_mj/params.py",
             "wmr_mj/_version.py")
#: the packages not swept yet
NOT_YET: tuple[str, ...] = ()
PROJECT = ("wmr_mj", "controllers")


def _is_project(node: ast.Import | ast.ImportFrom) -> bool:
    if isinstance(node, ast.ImportFrom):
        return node.level > 0 or (node.module or "").split(".")[0] in PROJECT
    return any(alias.name.split(".")[0] in PROJECT for alias in node.names)


def unexplained_function_imports(source: str) -> list[int]:
    """Line numbers of the project imports inside a function of ``source`` with no comment on their own lines
    or on the line directly above."""
    lines = source.splitlines()
    found: set[int] = set()
    for fn in ast.walk(ast.parse(source)):
        if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for node in ast.walk(fn):
            if isinstance(node, (ast.Import, ast.ImportFrom)) and _is_project(node):
                own = lines[node.lineno - 1:node.end_lineno]
                above = lines[node.lineno - 2].strip() if node.lineno >= 2 else ""
                if not any("#" in line for line in own) and not above.startswith("#"):
                    found.add(node.lineno)
    return sorted(found)


def test_the_finder_sees_nested_and_relative_imports_and_reads_comments():
    source = '''
from wmr_mj.errors import ParameterError

def f():
    from wmr_mj.sim import closed_loop

    def g():
        from .reader import load_log
    import numpy
    from controllers import registry  # a plug-in's registry, loaded on use
    # MuJoCo picks its OpenGL backend on import
    from wmr_mj.plant.mjcf import compile_model
    import controllers.base

class A:
    def m(self):
        from wmr_mj import params
'''
    assert unexplained_function_imports(source) == [5, 8, 13, 17]


def _paths(package: str) -> list[Path]:
    """The modules of ``package``: a folder's, at any depth, or the one file."""
    where = ROOT / package
    return [where] if where.is_file() else sorted(where.rglob("*.py"))


def test_every_module_is_swept_but_those_not_yet():
    swept = {path for package in PACKAGES for path in _paths(package)}
    left = {path for package in NOT_YET for path in _paths(package)}
    every = {path for package in ("wmr_mj", "controllers") for path in _paths(package)}
    assert [package for package in PACKAGES + NOT_YET if not (ROOT / package).exists()] == []  # each name is there
    assert sorted(str(p.relative_to(ROOT)) for p in every - swept - left) == []


def test_project_imports_inside_functions_say_why():
    paths = [path for package in PACKAGES for path in _paths(package)]
    found = [f"{path.relative_to(ROOT)}:{line}" for path in paths
             for line in unexplained_function_imports(path.read_text(encoding="utf-8"))]
    assert len(paths) > 50  # the packages are there
    assert found == [], ("move these imports to the module's top, or say on the line (or the line above) why "
                         "one must stay in its function:\n" + "\n".join(found))
