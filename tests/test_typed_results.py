"""Typed results above the run: the package's docstring example runs, the falsify history plot names the
search that really ran, and the results of sweep, falsify, compare and validate round-trip through their
``to_dict`` (the JSON the commands wrote before) and ``from_dict``."""

from __future__ import annotations

import dataclasses
import textwrap

import numpy as np
import pytest

import wmr_mj
from wmr_mj.analysis.verdicts import VERDICTS
from wmr_mj.errors import ParameterError
from wmr_mj.searches import search_methods
from wmr_mj.searches.falsify import METHOD_LABELS, METHODS, Evaluation, FalsifyResult, FalsifySpec
from wmr_mj.sim.config import RunConfig


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

#: the words that name each private search of wmr_mj.searches.search_methods, as a reader knows them
_SEARCH_WORDS = {"_search_cma": "CMA-ES", "_search_de": "differential evolution",
                 "_search_vertices_polish": "Nelder-Mead"}


@pytest.mark.parametrize("method", METHODS)
def test_each_method_label_names_the_search_that_runs(method, monkeypatch):
    called: list[tuple[str, dict]] = []
    for name in _SEARCH_WORDS:
        monkeypatch.setattr(search_methods, name,
                            lambda *a, _name=name, **kw: called.append((_name, kw)))
    search_methods.search_optimiser(np.array([[0.0, 1.0]]), budget=64, method=method)
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
    from wmr_mj.figures.plots import falsify_history

    fig = falsify_history(_tiny_result(method))
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert legend[0].startswith(METHOD_LABELS[method] + ":"), legend
    assert FalsifySpec.__dataclass_fields__["method"].default == "portfolio"
    if method == "portfolio":  # the default search: vertices, then CMA-ES, never a Nelder-Mead
        assert "CMA-ES" in legend[0] and "Nelder-Mead" not in legend[0]


# -- the results round-trip: X.from_dict(x.to_dict()).to_dict() == x.to_dict() ----------------------

_CERT_OUT = {"E_max": 0.05, "E_ratio": 1.5, "certified": True,
             "assumptions": [{"name": "reachable angle", "met": True, "value": 0.5, "limit": 1.57}]}
_CERT_UNMET = {"E_max": 0.05, "E_ratio": 0.5, "certified": False,
               "assumptions": [{"name": "within the supply", "met": False, "value": 25.0, "limit": 24.0}]}


def _falsify_result() -> FalsifyResult:
    # the base coerced, as a command's is: its JSON reads back to an equal config (a config built directly is
    # coerced when it runs, and reads back as that coerced config)
    spec = FalsifySpec(base=RunConfig.from_inputs(), box={"m1": (550.0, 750.0)}, budget=12)
    search = [Evaluation(phase="search", index=0, generation=0, params={"m1": 600.0}, objective=0.5,
                         summary={"sup_E": 0.025, "sup_Edot": 0.1, "verdict": "uncertified-inside",
                                  "certificate": _CERT_UNMET}),
              Evaluation(phase="search", index=1, generation=1, params={"m1": 700.0}, objective=1.5,
                         summary={"sup_E": 0.075, "sup_Edot": 0.2, "verdict": "certified-outside",
                                  "certificate": _CERT_OUT})]
    random = [Evaluation(phase="random", index=0, generation=0, params={"m1": 650.0}, objective=0.25,
                         summary={"sup_E": 0.0125, "sup_Edot": 0.05, "verdict": "certified-inside",
                                  "certificate": _CERT_OUT | {"E_ratio": 0.25}})]
    return FalsifyResult(spec=spec, search=search, random=random, objective_source="certificate of the run")


def test_falsify_result_is_typed_and_round_trips():
    result = dataclasses.replace(_falsify_result(), log="worst.mcap")
    # read by attribute: the run that breaks the claim, the worst run, the tightness
    assert result.claim_broken.phase == "search" and result.claim_broken.run == 2 and result.claim_broken.count == 1
    assert result.claim_broken.ratio == 1.5 and result.worst.params == {"m1": 700.0} and result.falsified is True
    assert result.tightness.ratio == 1.5 and result.tightness.text.startswith("the worst run is 1.5 times")
    assert result.random_worst.params == {"m1": 650.0} and result.box == {"m1": (550.0, 750.0)}
    assert result.worst.E_max == 0.05 and result.worst.unmet == () and result.evaluations == 2
    d = result.to_dict(runs=False)
    # the JSON falsify wrote before: its keys in their order, the nested records as mappings
    assert list(d) == ["objective", "objective_label", "objective_source", "budget", "evaluations", "seed",
                       "method", "population", "generations", "requirement", "falsified", "claim_broken", "box",
                       "worst", "tightness", "random", "log"]
    assert d["claim_broken"] == {"phase": "search", "run": 2, "params": {"m1": 700.0}, "sup_E": 0.075,
                                 "sup_Edot": 0.2, "E_max": 0.05, "ratio": 1.5, "count": 1}
    assert d["box"] == {"m1": [550.0, 750.0]} and d["worst"]["unmet"] == []
    assert list(d["tightness"]) == ["ratio", "factor", "found_sup_E", "E_max", "text"]
    assert d == _falsify_result().to_dict(log="worst.mcap", runs=False)  # the log given as the command gives it
    # the whole result, every run of both phases with it, reads back as itself
    full = result.to_dict()
    assert {k: v for k, v in full.items() if k != "runs"} == d
    assert [e["params"] for e in full["runs"]["search"]] == [{"m1": 600.0}, {"m1": 700.0}]
    assert full["runs"]["spec"]["box"] == {"m1": [550.0, 750.0]} and full["runs"]["spec"]["budget"] == 12
    back = FalsifyResult.from_dict(full)
    assert back == result and back.to_dict() == full
    # falsify --json holds no runs: refused in one line, not read as a result without them
    with pytest.raises(ParameterError, match="no 'runs'"):
        FalsifyResult.from_dict(d)


def test_the_removed_record_names_warn_and_still_read_the_commands_json():
    """FalsifyReport and CompareReport were the commands' JSON, typed, beside their results; each name is kept
    one release, with a DeprecationWarning, and still reads that JSON."""
    d = _falsify_result().to_dict(runs=False)
    with pytest.warns(DeprecationWarning, match="FalsifyResult"):
        old = wmr_mj.FalsifyReport
    assert old.from_dict(d).to_dict() == d
    with pytest.warns(DeprecationWarning, match="report"):
        assert _falsify_result().report().to_dict() == d
    with pytest.warns(DeprecationWarning, match="CompareResult"):
        from wmr_mj.experiments.compare import CompareReport  # noqa: F401
    assert "FalsifyReport" not in wmr_mj.__all__ and "CompareReport" not in wmr_mj.__all__


def test_sweep_summary_is_typed_and_round_trips():
    from wmr_mj.experiments.sweep import SweepSummary

    def row(run, m1, verdict, cert, ratio):
        return {"run": run, "m1": m1, "verdict": verdict, "certificate": cert, "cert_E_ratio": ratio,
                "cert_E_max": 0.05, "sup_E": ratio / 20, "sup_Edot": 0.1, "inside": None, "left_steering_range": False,
                "saturated_fraction": 0.0, "steps": 10, "batch_law": "compiled"}

    rows = [row(0, 600.0, "uncertified-inside", _CERT_UNMET, 0.5), row(1, 700.0, "certified-outside", _CERT_OUT, 1.5),
            row(2, 710.0, "uncertified-inside", _CERT_UNMET | {"assumptions": [
                {"name": "within the supply", "met": False, "value": 26.0, "limit": 24.0}]}, 0.7)]
    s = SweepSummary.of(rows, names=("m1",))
    assert s.claim_broken.run == 1 and s.claim_broken.params == {"m1": 700.0} and s.claim_broken.count == 1
    (unmet,) = s.unmet
    assert (unmet.name, unmet.value, unmet.limit, unmet.runs) == ("within the supply", 25.0, 24.0, 2)
    out = s.sweep_dict(1.0)  # the JSON of wmr-mj sweep, keys as before
    assert out["claim_broken"] == {"run": 1, "params": {"m1": 700.0}, "sup_E": 0.075, "sup_Edot": 0.1,
                                   "E_max": 0.05, "ratio": 1.5, "count": 1}
    # the first run's value and the range over the runs (issue 36)
    assert out["unmet"] == [{"name": "within the supply", "value": 25.0, "limit": 24.0, "runs": 2,
                             "value_range": [25.0, 26.0]}]
    d = s.to_dict()
    assert d["sup_E"] == {"value": 0.075, "m1": 700.0} and d["batch_law"] == ["compiled"]
    assert SweepSummary.from_dict(d).to_dict() == d
    assert SweepSummary.from_dict(d) == s


def test_sweep_result_round_trips():
    """A sweep's one result carries its spec, its rows and their summary in its JSON (no run needed: the rows
    above, added up as :func:`wmr_mj.sweep` adds them)."""
    from wmr_mj.experiments.sweep import SweepSpec, SweepSummary
    from wmr_mj.experiments.sweep_result import SweepResult

    spec = SweepSpec(n=2, seed=3, ranges={"mu": (0.01, 0.03)}, base=RunConfig.from_inputs(duration=5.0))
    rows = ({"run": 0, "m1": 600.0, "mu": 0.02, "verdict": "certified-inside", "certificate": _CERT_OUT,
             "cert_E_ratio": 0.5, "cert_E_max": 0.05, "sup_E": 0.025, "sup_Edot": 0.1, "inside": None,
             "left_steering_range": False, "saturated_fraction": 0.0, "steps": 10, "batch_law": "compiled"},)
    result = SweepResult(spec=spec, rows=rows, summary=SweepSummary.of(rows, names=spec.names), wall_s=2.0,
                         folder="logs/sweep-x")
    d = result.to_dict()
    runs = d["runs"]
    assert runs["spec"]["n"] == 2 and runs["spec"]["ranges"] == {"mu": [0.01, 0.03]} and runs["rows"] == [rows[0]]
    assert runs["summary"] == result.summary.to_dict()
    # sweep --json's object is the same JSON without its runs: the summary's keys, then the sweep's
    assert result.to_dict(runs=False) == {k: v for k, v in d.items() if k != "runs"}
    assert d["n"] == 1 and d["steps_per_s"] == 10 / 2.0 and d["folder"] == "logs/sweep-x" and d["seed"] == 3
    back = SweepResult.from_dict(d)
    assert back.to_dict() == d
    assert back.spec.ranges == spec.ranges and back.spec.base.duration == 5.0  # the base as the workers read it
    assert back.rows == rows and back.summary == result.summary
    with pytest.raises(ParameterError, match="no 'runs'"):
        SweepResult.from_dict(result.to_dict(runs=False))
    with pytest.warns(DeprecationWarning, match="to_dict"):  # the old name of sweep --json's object
        assert result.report(wall_s=2.0, folder="logs/sweep-x") == result.to_dict(runs=False)


def test_compare_result_is_typed_and_round_trips():
    from wmr_mj.experiments.compare import CompareResult, DesignRow, ScenarioRun
    from wmr_mj.experiments.suite import load_suite

    row = DesignRow(label="certified", controller="computed-torque", tracker=None, runs=2, requirements_passed=3,
                    requirements_total=4, least_normalised=-0.25, least_at="tracking @ circle/nominal",
                    certified_inside=1, certified_outside=1, uncertified=0, no_claim=0, failed=0, claim_E_max=0.05,
                    adversary_worst=0.5, adversary_falsified=True, adversary_runs_to_falsify=3,
                    adversary_where={"m1": 700.0}, adversary_worst_sup_E=0.04, random_worst=0.25,
                    random_runs_to_falsify=None, tightness=0.8, rms_voltage=3.0, tv_voltage=9.0,
                    cross_track_max=0.02, cpu_us_per_step=4.0, law="compiled",
                    claim_broken={"where": "scenario", "scenario": "circle/nominal", "params": {"m1": 650.0},
                                  "sup_E": 0.075, "E_max": 0.05, "ratio": 1.5, "count": 1},
                    unmet=({"name": "within the supply", "value": 25.0, "limit": 24.0, "runs": 1},))
    d = row.to_dict()
    assert "cart" not in d and d == row.to_dict() and DesignRow.from_dict(d).to_dict() == d
    assert d["unmet"] == [{"name": "within the supply", "value": 25.0, "limit": 24.0, "runs": 1}]
    suite = load_suite("standard-v1")
    run = ScenarioRun(design="certified", scenario="circle/nominal", summary={"sup_E": 0.075, "verdict": "x"},
                      requirements={"tracking": {"robustness": -0.01, "satisfied": False}}, rms_voltage=3.0,
                      tv_voltage=9.0, cpu_us_per_step=4.0, law="compiled")
    result = CompareResult(suite=suite, scenarios=suite.select(["circle/*"]), rows=(row,), runs=(run,), budget=4,
                           seed=0, versions={"wmr-mj": "x"}, wall_s=2.0, steps=10)
    assert result.claims_broken == ["certified"] and result.rows[0].tightness == 0.8
    out = result.to_dict(runs=False)
    assert list(out) == ["suite", "versions", "budget", "seed", "scenarios", "rows", "claims_broken", "wall_s",
                         "steps"]
    assert out["scenarios"] == [s.id for s in suite.select(["circle/*"])] and out["claims_broken"] == ["certified"]
    # the whole result: the suite read again from its file (its SHA-256 checked), the scenarios by id, every run
    full = result.to_dict()
    assert {k: v for k, v in full.items() if k != "runs"} == out
    assert full["runs"]["scenarios"] == [{"design": "certified", "scenario": "circle/nominal",
                                          "summary": {"sup_E": 0.075, "verdict": "x"},
                                          "requirements": {"tracking": {"robustness": -0.01, "satisfied": False}},
                                          "rms_voltage": 3.0, "tv_voltage": 9.0, "cpu_us_per_step": 4.0,
                                          "law": "compiled"}]
    back = CompareResult.from_dict(full)
    assert back == result and back.to_dict() == full
    with pytest.raises(ParameterError, match="no 'runs'"):
        CompareResult.from_dict(out)
    changed = {**full, "suite": {**full["suite"], "sha256": "0" * 64}}
    with pytest.raises(ParameterError, match="has changed"):
        CompareResult.from_dict(changed)


def test_the_supply_assumption_is_named_by_its_constant():
    from wmr_mj.analysis.verdicts import WITHIN_THE_SUPPLY
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.designs import CERTIFIED

    # the certificate's JSON, as the report reads it: the supply's assumption under the constant's name
    summary = run_closed_loop(RunConfig(**CERTIFIED.config_changes()), progress=False).summary.to_dict()
    supply = [a for a in summary["certificate"]["assumptions"] if "voltage_limit" in a["equation"]]
    assert [a["name"] for a in supply] == [WITHIN_THE_SUPPLY]


def test_validate_summary_round_trips_and_is_read_by_attribute():
    import json
    from pathlib import Path

    from wmr_mj.report.results import Rung, ValidateSummary

    d = json.loads((Path(__file__).parent / "data" / "validate_summary.json").read_text())
    s = ValidateSummary.from_dict(d)
    assert s.to_dict() == d and ValidateSummary.from_dict(s.to_dict()).to_dict() == d
    first, last = s.ladder[0], s.ladder[-1]
    assert (first.n, first.index, last.passes) == (d["ladder"][0]["n"], 1, d["ladder"][-1]["passes"])
    assert s.certified_rule.omega_r_design == d["certified_rule"]["omega_r_design"]
    assert "designs" not in s.to_dict() and "token" not in last.to_dict()
    # a user's design (validate --design) is a rung with its token, nominal run and paper_law; the JSON says so
    design = Rung.from_dict({**d["ladder"][-1], "index": 7, "token": "sliding-mode", "nominal": {"sup_E": 0.01},
                             "paper_law": False})
    with_design = ValidateSummary.from_dict({**d, "designs": [design.to_dict()]})
    assert with_design.designs[0].paper_law is False and with_design.to_dict()["designs"][0]["token"] == "sliding-mode"
    assert ValidateSummary.from_dict(with_design.to_dict()).to_dict() == with_design.to_dict()

