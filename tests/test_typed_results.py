"""Typed results above the run: the package's docstring example runs, the falsify history plot names the
search that really ran, and the results of sweep, falsify, compare and validate round-trip through their
``to_dict`` (the JSON the commands wrote before) and ``from_dict``."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

import wmr_mj
from wmr_mj.analysis.verdicts import VERDICTS
from wmr_mj.sim import falsify as falsify_module
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.falsify import METHOD_LABELS, METHODS, Evaluation, FalsifyResult, FalsifySpec


def _usage_block(doc: str) -> str:
    """The indented block after the first ``::`` of a docstring, dedented."""
    lines = doc.split("::", 1)[1].splitlines()[1:]
    block = []
    for line in lines:
        if line.strip() and not line.startswith("    "):
            break
        block.append(line)
    return textwrap.dedent("\n".join(block)).strip()


def test_the_package_docstring_example_runs():
    code = _usage_block(wmr_mj.__doc__)
    *body, last = code.splitlines()
    namespace: dict = {}
    exec("\n".join(body), namespace)  # noqa: S102  (the package's own example)
    verdict = eval(last.split("#")[0], namespace)  # noqa: S307
    # the example's last line reads the verdict by attribute; the JSON of the run says the same
    assert verdict in VERDICTS
    assert verdict == namespace["result"].summary.to_dict()["verdict"]


# -- the falsify history plot's label names the search that runs ------------------------------------

#: the words that name each private search of wmr_mj.sim.falsify, as a reader knows them
_SEARCH_WORDS = {"_search_cma": "CMA-ES", "_search_de": "differential evolution",
                 "_search_vertices_polish": "Nelder-Mead"}


@pytest.mark.parametrize("method", METHODS)
def test_each_method_label_names_the_search_that_runs(method, monkeypatch):
    called: list[tuple[str, dict]] = []
    for name in _SEARCH_WORDS:
        monkeypatch.setattr(falsify_module, name,
                            lambda *a, _name=name, **kw: called.append((_name, kw)))
    falsify_module.search_worst(lambda p: np.zeros(len(p)), np.array([[0.0, 1.0]]), budget=64, method=method)
    (name, kwargs), = called
    label = METHOD_LABELS[method]
    assert _SEARCH_WORDS[name] in label, (method, name, label)
    for other in set(_SEARCH_WORDS.values()) - {_SEARCH_WORDS[name]}:
        assert other not in label, (method, label)
    # the vertices first where the search takes them first (the portfolio, vertices-polish), else not
    vertices_first = kwargs.get("vertices", kwargs.get("first") == "vertices")
    assert label.startswith("vertices") == bool(vertices_first), (method, kwargs, label)
    assert ("Latin hypercube" in label) == (kwargs.get("first") == "lhs"), (method, kwargs, label)


def _tiny_result(method: str) -> FalsifyResult:
    spec = FalsifySpec(base=RunConfig(), box={"m1": (550.0, 750.0)}, budget=12, method=method)
    summary = {"sup_E": 0.01, "sup_Edot": 0.02, "verdict": "uncertified-inside"}
    evals = [Evaluation(phase=phase, index=i, generation=0, params={"m1": 600.0 + i}, objective=0.1 * i,
                        summary=summary) for phase in ("search", "random") for i in range(3)]
    return FalsifyResult(spec=spec, search=evals[:3], random=evals[3:], objective_source="test")


@pytest.mark.parametrize("method", ["portfolio", "de", "vertices-polish"])
def test_the_history_plot_legend_carries_the_method_label(method):
    from wmr_mj.report.plots import falsify_history

    fig = falsify_history(_tiny_result(method))
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert legend[0].startswith(METHOD_LABELS[method] + ":"), legend
    assert FalsifySpec.__dataclass_fields__["method"].default == "portfolio"
    if method == "portfolio":  # the default search: vertices, then CMA-ES, never a Nelder-Mead
        assert "CMA-ES" in legend[0] and "Nelder-Mead" not in legend[0]
