"""One result type per command (issue 41 item 5): each is a frozen dataclass with ``to_dict``, ``.plot()``,
``.to_pandas()`` and ``_repr_html_``, and the three this file builds by hand (a design, a cart's tightness, a
cart check) draw and tabulate the numbers they hold.

The independent truth is the numbers each result is built from here (no run, no search: the fields are given),
read back from the figure's artists and the table's cells to the bit.
"""

from __future__ import annotations

import dataclasses
import html
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.figure import Figure

from wmr_mj.analysis.claim_types import Assumption
from wmr_mj.experiments.cart_check import CartCheck
from wmr_mj.experiments.compare import CompareResult
from wmr_mj.experiments.sweep_result import SweepResult
from wmr_mj.experiments.tightness import CartTightness
from wmr_mj.plant.cartcheck import COEFFICIENT_UNITS, CoefficientCheck, IdentificationCheck, RandomStepCheck
from wmr_mj.report.results import ValidateSummary
from wmr_mj.searches.design_search import DesignCertificate, DesignResult
from wmr_mj.searches.falsify import FalsifyResult
from wmr_mj.sim.closed_loop import RunResult

#: each command's one result type
RESULTS = {"run": RunResult, "sweep": SweepResult, "falsify": FalsifyResult, "compare": CompareResult,
           "validate": ValidateSummary, "design": DesignResult, "cart tightness": CartTightness,
           "cart check": CartCheck}


#: the results whose JSON cannot be read back: a run's JSON has no rows (the log holds them), a cart check's names
#: its cart file and the identification's summary, not the identification
NOT_READ_BACK = {"run", "cart check"}


@pytest.mark.parametrize("command", list(RESULTS))
def test_each_commands_result_is_frozen_and_has_the_notebooks_methods(command):
    kind = RESULTS[command]
    assert dataclasses.is_dataclass(kind) and kind.__dataclass_params__.frozen  # type: ignore[attr-defined]
    for method in ("to_dict", "plot", "to_pandas", "_repr_html_"):
        assert callable(getattr(kind, method, None)), f"{kind.__name__} has no {method}"
    assert callable(getattr(kind, "from_dict", None)) == (command not in NOT_READ_BACK)


def test_a_run_result_refuses_to_change(certified_run_10s):
    with pytest.raises(dataclasses.FrozenInstanceError):
        certified_run_10s.status = "interrupted"  # type: ignore[misc]
    copy = dataclasses.replace(certified_run_10s, status="interrupted")  # a changed copy is built, not written
    assert copy.status == "interrupted" and certified_run_10s.status == "completed"
    assert copy.summary is certified_run_10s.summary


# -- a design: each path's certificate ---------------------------------------------------------------------------
def _assumption(name: str, met: bool) -> Assumption:
    return Assumption(name=name, equation="x <= y", met=met, value=1.0, limit=2.0, note="", kind="law")


@pytest.fixture()
def design() -> DesignResult:
    """Two paths: the circle certified at 0.0412 rad and 11.5 V, the lane change valid but not certified."""
    certs = {"paper-circle": DesignCertificate(certified=True, E_max=0.0412, voltage_max=11.5, reason="",
                                               certificate="section-4", assumptions=(_assumption("a", True),)),
             "lane-change": DesignCertificate(certified=False, E_max=0.0731, voltage_max=25.0, reason="",
                                              certificate="sampled-data", assumptions=(_assumption("supply", False),))}
    settings = {"kp": 530.0, "kd": 46.0, "friction_width": 0.01, "control_period": 0.001}
    return DesignResult(settings=settings, certified=False, score=1.0, certificates=certs, binding="supply",
                        paths=tuple(certs))


def test_a_designs_plot_draws_each_paths_certificate(design):
    plot = design.plot()
    assert isinstance(plot.figure, Figure) and len(plot.axes) == 2
    e_max, voltage = ([p.get_height() for p in ax.patches] for ax in plot.axes)
    assert e_max == [0.0412, 0.0731] and voltage == [11.5, 25.0]  # one bar per path, in the paths' order
    assert [t.get_text() for t in plot.axes[0].get_xticklabels()] == ["paper-circle", "lane-change"]
    green, grey = (p.get_facecolor() for p in plot.axes[0].patches)
    assert green != grey  # certified and not certified are told apart


def test_a_designs_table_and_html_hold_its_numbers(design):
    pytest.importorskip("pandas")
    table = design.to_pandas()
    assert list(table["path"]) == ["paper-circle", "lane-change"]
    assert list(table["E_max [rad]"]) == [0.0412, 0.0731] and list(table["voltage_max [V]"]) == [11.5, 25.0]
    assert list(table["unmet"]) == ["", "supply"]
    assert design.E_max == 0.0731
    text = design._repr_html_()
    assert "<b>nothing certifies</b>" in text and "K_P = 530 1/s^2" in text and "supply binds" in text
    assert "paper-circle: E_max 0.0412 rad" in text


# -- a cart's tightness -------------------------------------------------------------------------------------------
@pytest.fixture()
def tightness() -> CartTightness:
    return CartTightness(path="lane-change", certificate="sampled-data", certified=True, E_max=0.05,
                         E_max_section4=0.08, E_max_sampled=0.05, worst_sup_E=0.02, worst_params={"m1": 750.0},
                         search_sup_E=0.02, random_sup_E=0.015, verdicts={"certified-inside": 10}, runs=10, budget=5,
                         seed=0, box={"m1": (550.0, 750.0)})


def test_a_tightness_rows_plot_draws_the_bound_the_worst_found_and_their_ratio(tightness):
    plot = tightness.plot()
    assert isinstance(plot.figure, Figure) and len(plot.axes) == 2
    bound, found = plot.axes[0].containers
    assert [p.get_height() for p in bound] == [0.05] and [p.get_height() for p in found] == [0.02]
    (ratio,) = plot.axes[1].containers
    assert [p.get_height() for p in ratio] == [0.02 / 0.05]  # worst_sup_E / E_max
    assert [float(line.get_ydata()[0]) for line in plot.axes[1].lines] == [1.0]


def test_a_tightness_rows_json_table_and_html(tightness):
    pytest.importorskip("pandas")
    d = tightness.to_dict()
    assert CartTightness.from_dict(d) == tightness and d["tightness"] == 0.02 / 0.05
    (row,) = tightness.to_pandas().to_dict("records")
    assert (row["E_max [rad]"], row["worst_sup_E [rad]"], row["tightness [-]"]) == (0.05, 0.02, 0.02 / 0.05)
    assert row["certified-inside"] == 10
    text = tightness._repr_html_()
    assert f"{0.02 / 0.05:.4g}" in text and "10 runs" in text


# -- a cart check: the model's coefficients against the plant's ---------------------------------------------------
def _coefficient(name: str, identified: float, implied: float, allowed: float) -> CoefficientCheck:
    return CoefficientCheck(name=name, identified=identified, implied=implied, paper=implied, allowed=allowed)


@pytest.fixture()
def cart_check() -> CartCheck:
    """P within its allowance (0.4 of it), F outside (1.5 times it): the check fails on F."""
    rows = (_coefficient("P", 10.4, 10.0, 1.0), _coefficient("F", 2.3, 2.0, 0.2))
    ident = IdentificationCheck(result=SimpleNamespace(diagnostics={"mujoco_warnings": 0}), rows=rows)
    steps = RandomStepCheck(duration=1.0, steps=1000, seed=0, warnings={}, finite=True)
    cart = SimpleNamespace(name="mine", version="1", path="mine.toml")
    return CartCheck(cart=cart, defaults={"sensing": "exact"}, steps=steps, identification=ident,
                     identification_error=None,
                     certified_design={"omega_r": 30.0, "certified": True, "E_max": 0.0431, "path": "paper-circle"},
                     design={"certified": True, "E_max": 0.0377})


def test_a_cart_checks_plot_draws_each_coefficient_in_its_allowance(cart_check):
    plot = cart_check.plot()
    assert isinstance(plot.figure, Figure) and len(plot.axes) == 1
    (ax,) = plot.axes
    assert len(ax.lines) == 2  # the zero line, and the identified coefficients as markers
    (identified,) = [line for line in ax.lines if line.get_marker() == "o"]
    np.testing.assert_allclose(identified.get_ydata(), [0.4, 1.5], rtol=1e-12)  # (identified - implied) / allowed
    assert [t.get_text() for t in ax.get_xticklabels()] == ["P", "F"]
    assert "FAILS" in plot.figure.texts[0].get_text()


def test_a_cart_checks_table_has_one_row_per_coefficient(cart_check):
    pytest.importorskip("pandas")
    rows = cart_check.to_pandas().to_dict("records")
    assert [r["coefficient"] for r in rows] == ["P", "F"]
    assert [(r["identified"], r["implied"], r["allowed"], r["passed"]) for r in rows] == [
        (10.4, 10.0, 1.0, True), (2.3, 2.0, 0.2, False)]
    assert [r["unit"] for r in rows] == [COEFFICIENT_UNITS["P"], COEFFICIENT_UNITS["F"]]


def test_a_cart_checks_html_says_its_answer_and_the_designs_bounds(cart_check):
    text = html.unescape(cart_check._repr_html_())
    assert "<b>FAILS</b>" in text and cart_check.answer in text
    assert "E_max 0.0431 rad" in text and "design certifies it: E_max 0.0377 rad" in text


def test_a_cart_check_without_an_identification_says_why():
    steps = RandomStepCheck(duration=1.0, steps=1000, seed=0, warnings={}, finite=True)
    check = CartCheck(cart=SimpleNamespace(name="mine", version="1", path="mine.toml"), defaults={}, steps=steps,
                      identification=None, identification_error="too few sliding samples",
                      certified_design={"omega_r": None, "reason": "no omega_r", "path": "paper-circle"},
                      design={"certified": False, "binding": "supply"})
    plot = check.plot()
    assert any("too few sliding samples" in t.get_text() for t in plot.axes[0].texts)
    text = html.unescape(check._repr_html_())
    assert "no omega_r" in text and "supply binds" in text
