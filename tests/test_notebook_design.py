"""A design and a cart's tightness in a notebook: ``.to_pandas()`` and ``_repr_html_`` (issue 36's contract for
every result, extended to ``DesignResult`` and ``CartTightness``).

The independent truth is each result's own fields: the table's cells are the certificates' numbers and the
tightness the result computes, to the bit, and the lines name the design's gains and its binding assumption. Small
budgets and 9 s runs (the circle's entry takes 8.1 s) keep it to seconds.
"""

from __future__ import annotations

import html
import math

import pytest

import wmr_mj as wm

pytest.importorskip("pandas")


@pytest.fixture(scope="module")
def found():
    base = wm.RunConfig(**wm.CERTIFIED.config_changes(), sensing=wm.Sensing.from_spec("magnetic-12bit-axis"),
                        duration=9.0)
    return base, wm.search_design(wm.DesignProblem(base=base, paths=("paper-circle", "lane-change"), budget=12))


def test_a_design_as_a_table_and_a_few_lines(found):
    _, result = found
    assert result.certified
    table = result.to_pandas()
    assert list(table["path"]) == ["paper-circle", "lane-change"]
    for (_, row), cert in zip(table.iterrows(), result.certificates.values()):
        assert row["E_max [rad]"] == cert.E_max and row["voltage_max [V]"] == cert.voltage_max
        assert row["certified"] == cert.certified and row["unmet"] == ""
    assert max(table["E_max [rad]"]) == result.E_max
    lines = result._repr_html_()
    assert "<b>certified</b>" in lines and f"{result.settings['kp']:.4g}" in lines
    assert lines.count(": E_max ") == 2  # one line per path


def test_a_design_that_nothing_certifies_names_what_binds():
    base = wm.RunConfig(**wm.CERTIFIED.config_changes(), sensing=wm.Sensing.from_spec(
        "encoder_ticks=256,velocity=difference"), duration=9.0)
    result = wm.search_design(wm.DesignProblem(base=base, budget=8))
    assert not result.certified and result.binding
    text = html.unescape(result._repr_html_())
    assert "nothing certifies" in text and f"{result.binding} binds" in text
    assert math.isinf(result.E_max) or not all(row for row in result.to_pandas()["certified"])


def test_a_tightness_row_as_a_table_and_a_few_lines(found):
    base, result = found
    row = wm.cart_tightness(base.replace(**result.settings), budget=5)
    table = row.to_pandas()
    assert len(table) == 1
    got = table.iloc[0]
    assert got["E_max [rad]"] == row.E_max and got["worst_sup_E [rad]"] == row.worst_sup_E
    assert got["tightness [-]"] == row.worst_sup_E / row.E_max
    assert sum(int(got[v]) for v in row.verdicts) == row.runs
    lines = row._repr_html_()
    assert f"{row.tightness:.4g}" in lines and f"{row.runs} runs" in lines


def test_a_design_round_trips_through_its_json(found):
    """``DesignResult.to_dict`` is the design file's content (what ``design --json`` and ``--out`` write), and
    ``from_dict`` reads it back: the certificates as the file records them, the settings as the run's parts."""
    from wmr_mj.searches.design_search import DesignResult, design_dict

    _, result = found
    d = result.to_dict()
    assert d == design_dict(result)
    back = DesignResult.from_dict(d)
    assert back.to_dict() == d
    assert back.E_max == result.E_max and back.settings["sensing"] == result.settings["sensing"]
    assert [c.certified for c in back.certificates.values()] == [c.certified for c in result.certificates.values()]
    assert list(back.to_pandas()["E_max [rad]"]) == list(result.to_pandas()["E_max [rad]"])


def test_a_tightness_row_round_trips_through_its_json(found):
    from wmr_mj.experiments.tightness import CartTightness

    base, result = found
    row = wm.cart_tightness(base.replace(**result.settings), budget=5)
    d = row.to_dict()
    assert d["tightness"] == row.tightness and d["worst_sup_E"] == row.worst_sup_E
    back = CartTightness.from_dict(d)
    assert back == row and back.to_dict() == d


@pytest.fixture(scope="module")
def twenty_volt_run(tmp_path_factory):
    """A 9 s run of the certified design on a copy of c80.toml whose supply is 20 V."""
    from wmr_mj.carts import CARTS_DIR

    text = (CARTS_DIR / "c80.toml").read_text(encoding="utf-8")
    old = "[supply.voltage_limit]\nvalue = 24.0"
    assert old in text
    cart = tmp_path_factory.mktemp("cart") / "twenty.toml"
    cart.write_text(text.replace(old, "[supply.voltage_limit]\nvalue = 20.0"), encoding="utf-8")
    return wm.run_closed_loop(wm.RunConfig(**wm.CERTIFIED.config_changes(), cart=str(cart), duration=9.0),
                              progress=False)


def _levels(ax) -> set[float]:
    """The heights of an axis's horizontal lines."""
    import numpy as np

    return {float(line.get_ydata()[0]) for line in ax.lines if len(set(np.asarray(line.get_ydata()))) == 1}


def test_a_runs_plot_draws_the_supply_of_its_own_cart(twenty_volt_run):
    """The voltage axis's limits are the supply of the plant the run simulated: a cart file's (20 V here), not the
    C80's 24 V (the figure once read only --param overrides on the C80's parameter set)."""
    levels = _levels(twenty_volt_run.plot().axes[2])
    assert {20.0, -20.0} <= levels and 24.0 not in levels


def test_validates_history_figure_draws_the_supply_of_its_cart(twenty_volt_run):
    """validate --cart's history figures likewise (they drew the C80's 24 V on every cart)."""
    from wmr_mj.report.figures import _history_figures

    fig = _history_figures({"certified": twenty_volt_run}, "the (4.21)-(4.23) region on this cart")["history_certified"]
    levels = set().union(*(_levels(ax) for ax in fig.axes))
    assert {20.0, -20.0} <= levels and 24.0 not in levels
