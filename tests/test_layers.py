"""The package's layers import downwards only, and no module imports itself back through others.

Every import counts, the ones inside functions too: the test reads each module's source
with ``ast`` and walks all ``import`` and ``from ... import`` nodes. The layers, lowest first:

====  ==========================================  =====================================================
rank  modules                                     what
====  ==========================================  =====================================================
0     wmr_mj.errors, params, carts, _version,     errors, the parameter set and its cart files, files,
      _util                                       memory, progress
1     wmr_mj.hardware                             sensing, actuation, transmission: typed parts, presets
2     wmr_mj.plant                                MJCF model, derivation, reduced models, friction, identification
3     wmr_mj.reference                            paths of C and alpha0(t)
4     wmr_mj.analysis                             the paper's section 4, the certificate, verdicts
5     controllers                                 steering laws and path trackers, each with its claim
6     wmr_mj.figures                              headless figures: the drawing, and each result's ``.plot()``
7     wmr_mj.sim                                  the run: its config and coercion, parts, closed loop, batch
                                                  engine, certify, designs, many runs at once
8     wmr_mj.searches                             what asks for runs to find a point: falsify, design search,
                                                  their optimisers
9     wmr_mj.experiments                          what asks for runs and searches for one answer: sweep,
                                                  compare and its suites, tightness, cart check
10    wmr_mj.logs                                 MCAP format, writer, reader, replay, video
11    wmr_mj.report                               validate, text, HTML, the figures it writes
12    wmr_mj.cli                                  the wmr-mj commands
13    wmr_mj (its ``__init__``)                   the public API: may import any layer
====  ==========================================  =====================================================
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LAYERS: tuple[tuple[str, ...], ...] = (
    ("wmr_mj.errors", "wmr_mj.params", "wmr_mj.carts", "wmr_mj._version", "wmr_mj._util"),
    ("wmr_mj.hardware",),
    ("wmr_mj.plant",),
    ("wmr_mj.reference",),
    ("wmr_mj.analysis",),
    ("controllers",),
    ("wmr_mj.figures",),
    ("wmr_mj.sim",),
    ("wmr_mj.searches",),
    ("wmr_mj.experiments",),
    ("wmr_mj.logs",),
    ("wmr_mj.report",),
    ("wmr_mj.cli",),
    ("wmr_mj",),
)


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for pkg in ("wmr_mj", "controllers") for p in (ROOT / pkg).rglob("*.py")}


def rank(module: str) -> int | None:
    """The layer of ``module`` (the longest matching prefix); None outside the project."""
    best, best_len = None, -1
    for r, prefixes in enumerate(LAYERS):
        for prefix in prefixes:
            if (module == prefix or module.startswith(prefix + ".")) and len(prefix) > best_len:
                best, best_len = r, len(prefix)
    return best


def imports_of(module: str, path: Path, known: set[str]) -> set[str]:
    """Project modules ``module`` imports, anywhere in its source; ``from pkg import name`` counts as
    ``pkg.name`` when that is a module."""
    is_pkg = path.name == "__init__.py"
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".") if is_pkg else module.split(".")[:-1]
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            out.add(target)
            out.update(f"{target}.{a.name}" for a in node.names if f"{target}.{a.name}" in known)
    return {m for m in out if rank(m) is not None and m != module}


def _graph() -> dict[str, set[str]]:
    mods = _modules()
    known = set(mods)
    return {m: {i for i in imports_of(m, p, known) if i in known or rank(i) is not None} for m, p in mods.items()}


def test_rank_of_known_modules():
    assert rank("wmr_mj.plant.mjcf") == 2
    assert rank("wmr_mj.params") == 0
    assert rank("wmr_mj.hardware.sensing") == 1
    assert rank("wmr_mj") == len(LAYERS) - 1
    assert rank("controllers.computed_torque") == 5
    assert rank("wmr_mj.figures.results") < rank("wmr_mj.sim.closed_loop")  # a result's plot() imports it
    # the run below what asks for runs: a search below an experiment, which may run one (compare's adversary)
    assert rank("wmr_mj.sim.many_runs") < rank("wmr_mj.searches.falsify") < rank("wmr_mj.experiments.compare")
    assert rank("numpy") is None


def test_walker_sees_function_level_and_relative_imports(tmp_path):
    src = tmp_path / "mod.py"
    src.write_text("from ..analysis import certificate\n\ndef f():\n    from wmr_mj.sim.closed_loop import run\n")
    found = imports_of("wmr_mj.plant.mod", src, {"wmr_mj.analysis.certificate"})
    assert {"wmr_mj.analysis.certificate", "wmr_mj.sim.closed_loop"} <= found


def test_every_module_has_a_layer():
    assert [m for m in _modules() if rank(m) is None] == []


def test_imports_point_down_only():
    upward = sorted(f"{m} (layer {rank(m)}) imports {i} (layer {rank(i)})"
                    for m, deps in _graph().items() for i in deps
                    if m != "wmr_mj" and rank(i) > rank(m))  # type: ignore[operator]
    assert upward == [], "\n".join(upward)


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_cycle_finder_finds_a_planted_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_cycles():
    # a package's __init__ that re-exports its modules is not a cycle with them: edges into a package
    # __init__ from inside that package are what re-exporting looks like, so they are left out
    graph = _graph()
    mods = _modules()
    pruned = {m: {i for i in deps if not (mods.get(i, Path()).name == "__init__.py" and m.startswith(i + "."))}
              for m, deps in graph.items()}
    assert _cycles(pruned) == []
