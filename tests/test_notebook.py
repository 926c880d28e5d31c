"""Results in a notebook (wmr_mj.sim.notebook, wmr_mj.figures.results, examples/notebook.ipynb).

Each ``.to_pandas()`` is held against the result's own arrays and records (the same values under the unit
names of wmr_mj.sim.notebook), each ``.plot()`` against the data it draws (the E line's points are the rows),
each ``_repr_html_`` against the verdict; without pandas a table says in one line what to install; the
example notebook runs in its quick mode, and its text twin (jupytext) says the same.
"""

from __future__ import annotations

import dataclasses
import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest

import wmr_mj as wm
from wmr_mj.errors import WmrMjError
from wmr_mj.experiments.sweep import run_sweep
from wmr_mj.sim import notebook

pd = pytest.importorskip("pandas", reason="pandas is not installed: pip install -e '.[notebook]'")

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
DURATION = 9.0  # [s]: the paper's circle's lead-in and entry take 8.1 s


def _certified(**changes) -> wm.RunConfig:
    return wm.RunConfig(**{**wm.CERTIFIED.config_changes(), "duration": DURATION, **changes})


@pytest.fixture(scope="module")
def sensed_run():
    """A certified run on a sensed cart (the rows gain what the law read)."""
    return wm.run_closed_loop(_certified(m1=700.0, sensing="magnetic-14bit-axis"), progress=False)


# -- a run ------------------------------------------------------------------------------------------------

def test_every_recorded_quantity_has_its_unit():
    from wmr_mj.sim.engine import ROW_FIELDS, SENSED_ROW_FIELDS

    assert set(ROW_FIELDS) | set(SENSED_ROW_FIELDS) <= set(notebook.ROW_UNITS)
    assert notebook.row_column("E") == "E [rad]" and notebook.row_column("voltage") == "voltage [V]"


@pytest.mark.slow
def test_a_runs_table_is_its_rows_under_unit_names(sensed_run):
    rows, table = sensed_run.rows, sensed_run.to_pandas()
    assert len(table) == len(rows["t"]) > 0
    for name, values in rows.items():
        np.testing.assert_array_equal(table[f"{name} [{notebook.ROW_UNITS[name]}]"].to_numpy(), values)
    for column in ("t [s]", "E [rad]", "E_dot [rad/s]", "voltage [V]", "alpha_measured [rad]"):
        assert column in table.columns
    np.testing.assert_array_equal(table[["C_x [m]", "C_y [m]"]].to_numpy(), sensed_run.C_xy[: len(table)])


@pytest.mark.slow
def test_a_runs_plot_draws_its_rows_between_its_bounds(sensed_run):
    plot = sensed_run.plot()
    assert isinstance(plot, wm.ResultPlot) and len(plot.axes) == 4 and plot.figure.axes[0] is plot.axes[0]
    e_ax, edot_ax, v_ax, path_ax = plot.axes
    t, s = sensed_run.rows["t"], sensed_run.summary
    E_line, Edot_line = e_ax.lines[0], edot_ax.lines[0]
    np.testing.assert_array_equal(E_line.get_xdata(), t)
    np.testing.assert_array_equal(E_line.get_ydata(), sensed_run.rows["E"])
    np.testing.assert_array_equal(Edot_line.get_ydata(), sensed_run.rows["E_dot"])
    assert s.certificate.E_max is not None  # so the bounds drawn are the certificate's

    def levels(ax):  # the horizontal lines' heights
        return {float(line.get_ydata()[0]) for line in ax.lines if len(set(np.asarray(line.get_ydata()))) == 1}

    assert {s.certificate.E_max, -s.certificate.E_max} <= levels(e_ax)
    assert {s.certificate.Edot_max, -s.certificate.Edot_max} <= levels(edot_ax)
    assert {wm.C80.voltage_limit, -wm.C80.voltage_limit} <= levels(v_ax)
    applied = [line for line in v_ax.lines if line.get_label() == "applied"]
    np.testing.assert_array_equal(applied[0].get_ydata(), sensed_run.rows["voltage"])
    C = [line for line in path_ax.lines if line.get_label() == "C (MuJoCo)"]
    np.testing.assert_array_equal(C[0].get_xydata(), sensed_run.C_xy)


@pytest.mark.slow
def test_a_runs_html_says_its_verdict(sensed_run):
    text = sensed_run._repr_html_()
    assert sensed_run.summary.verdict in text and "sup|E|" in text and text.count("<li>") <= 6


# -- a sweep ----------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def delay_sweep():
    spec = wm.SweepSpec(n=3, m1_range=(699.9, 700.0), ranges={"sensing.delay": (0.0, 0.02)}, base=_certified())
    return spec, wm.sweep(spec)


@pytest.mark.slow
def test_a_sweep_result_holds_run_sweeps_rows_and_their_summary(delay_sweep):
    spec, result = delay_sweep
    with pytest.warns(DeprecationWarning, match="wm.sweep"):  # the top-level alias, kept one release
        alias = wm.run_sweep
    assert alias is run_sweep
    rows = run_sweep(spec)  # the list-of-rows API, unchanged

    def timeless(r):  # wall and CPU time differ between two sweeps, every number measured does not (NaN: "NaN")
        kept = {k: v for k, v in r.items() if not k.startswith("batch_") and k not in ("wall_s", "realtime_factor")}
        return json.dumps(kept, sort_keys=True, default=str)

    assert [timeless(r) for r in result.rows] == [timeless(r) for r in rows]
    assert result.summary == wm.SweepSummary.of(rows, spec.requirements, names=spec.names)


@pytest.mark.slow
def test_a_sweeps_table_has_one_row_per_run_with_the_values_it_used(delay_sweep):
    _, result = delay_sweep
    table = result.to_pandas()
    assert len(table) == len(result.rows) == 3
    for column, key in (("m1 [kg]", "m1"), ("sensing.delay [s]", "sensing.delay"), ("sup_E [rad]", "sup_E"),
                        ("certificate_E_max [rad]", "cert_E_max"), ("paper_E_max [rad]", "E_max"),
                        ("certificate_E_ratio [-]", "cert_E_ratio"), ("verdict", "verdict")):
        expected = [r[key] for r in result.rows]
        if column == "verdict":
            assert table[column].tolist() == expected
        else:  # None (no certificate) is NaN in a float column
            assert table[column].tolist() == pytest.approx([np.nan if v is None else v for v in expected],
                                                           nan_ok=True)
    assert "E_max" not in table.columns and "cert_E_max" not in table.columns  # no name left ambiguous
    # the delay each run used is a whole number of 1 ms control periods (search_space.hardware_values)
    assert np.allclose(np.round(table["sensing.delay [s]"] / 1e-3) * 1e-3, table["sensing.delay [s]"])


@pytest.mark.slow
def test_a_sweeps_plot_is_sup_E_against_each_ranged_parameter(delay_sweep):
    _, result = delay_sweep
    plot = result.plot()
    assert [ax.get_xlabel() for ax in plot.axes] == ["m1 [kg]", "sensing.delay [s]"]
    for ax, name in zip(plot.axes, result.spec.names):
        runs = [c for c in ax.collections if c.get_label() != "certificate's E_max, each run's"]  # the runs' dots
        points = np.vstack([c.get_offsets() for c in runs])
        expected = np.array([[r[name], r["sup_E"]] for r in result.rows])
        assert sorted(map(tuple, points)) == sorted(map(tuple, expected))
    # the delay changes each run's claim: each run's certificate E_max drawn at the delay it used
    bounds = sorted((r["sensing.delay"], r["cert_E_max"]) for r in result.rows if r["cert_E_max"] is not None)
    dashes = [c for c in plot.axes[1].collections if c.get_label() == "certificate's E_max, each run's"]
    lines = [line for line in plot.axes[1].lines if line.get_label().startswith("certificate's E_max")]
    if len({b for _, b in bounds}) > 1:
        assert sorted(map(tuple, dashes[0].get_offsets())) == bounds
    elif bounds:
        assert np.allclose(lines[0].get_ydata(), bounds[0][1])
    passes = f"{result.summary.passes}/3 certified-inside"
    expected = "CERTIFIED-OUTSIDE" if result.summary.certified_outside else passes
    assert expected in result._repr_html_()


# -- falsify ----------------------------------------------------------------------------------------------

@pytest.mark.slow
def test_a_searchs_table_plot_and_html():
    result = wm.falsify(wm.FalsifySpec(base=_certified(), box={"m1": (600.0, 800.0)}, budget=5))
    table = result.to_pandas()
    evals = [*result.search, *result.random]
    assert len(table) == len(evals) and table["phase"].tolist() == [e.phase for e in evals]
    assert table["m1 [kg]"].tolist() == [e.params["m1"] for e in evals]
    assert table["objective"].tolist() == pytest.approx([e.objective for e in evals])
    assert table["sup_E [rad]"].tolist() == [e.sup_E for e in evals]
    assert table["verdict"].tolist() == [e.verdict for e in evals]
    plot = result.plot()
    (ax,) = plot.axes
    running = np.maximum.accumulate([e.objective for e in result.search])
    assert any(np.allclose(line.get_ydata(), running) for line in ax.lines)  # the search's running worst
    running_random = np.maximum.accumulate([e.objective for e in result.random])
    assert any(np.allclose(line.get_ydata(), running_random) for line in ax.lines)  # beside random's
    expected = {True: "FALSIFIED", False: "not falsified", None: "no claim"}[result.falsified]
    assert expected in result._repr_html_()


# -- compare ----------------------------------------------------------------------------------------------

@pytest.mark.slow
def test_a_comparisons_table_has_one_plain_row_per_design_and_scenario():
    suite = dataclasses.replace(wm.load_suite("standard-v1"), duration=DURATION)
    designs = [wm.design_from_token(t, suite) for t in ("certified", f"{EXAMPLES / 'my_pid.py'}:MyPID")]
    result = wm.compare(designs, suite, scenarios=["circle/nominal/none"], budget=0, nthread=2)
    table = result.to_pandas()
    assert [tuple(x) for x in table[["design", "scenario"]].to_numpy()] == \
        [(r.design, r.scenario) for r in result.runs]
    assert table["sup_E [rad]"].tolist() == [r.summary["sup_E"] for r in result.runs]
    assert table["verdict"].tolist() == [r.verdict for r in result.runs]
    assert table["rms_voltage [V]"].tolist() == [r.rms_voltage for r in result.runs]
    first = result.runs[0]
    for name, judged in first.requirements.items():
        assert table.loc[0, f"{name} robustness"] == judged["robustness"]
    assert not any(isinstance(v, dict | list | tuple) for v in table.to_numpy().ravel())  # no reprs in cells
    assert len(result.plot().axes) == 2
    html = result._repr_html_()
    assert ("no claim broken" in html) == (not result.claims_broken) and "certified" in html


# -- validate ---------------------------------------------------------------------------------------------

def test_validates_table_plot_and_html_from_a_summary_json():
    from wmr_mj.report.results import ValidateSummary

    summary = ValidateSummary.from_dict(json.loads((ROOT / "tests" / "data" / "validate_summary.json").read_text()))
    table = summary.to_pandas()
    assert table["label"].tolist() == [r.label for r in summary.rungs]
    assert table["runs"].tolist() == [r.n for r in summary.rungs]
    assert table["certified-inside"].tolist() == [r.passes for r in summary.rungs]
    assert table["worst_sup_E [rad]"].tolist() == pytest.approx([r.worst_sup_E for r in summary.rungs])
    plot = summary.plot()
    assert len(plot.axes) == 1 and len(plot.axes[0].get_yticklabels()) == len(summary.rungs)
    assert ("no run certified-outside" in summary._repr_html_()) == (summary.certified_outside == 0)


# -- without pandas, the top level, the notebook ----------------------------------------------------------

def test_without_pandas_a_table_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas raises ImportError
    with pytest.raises(WmrMjError) as info:
        notebook.rows_frame({"t": np.zeros(2)})
    message = str(info.value)
    assert "pip install 'wmr-mj[notebook]'" in message and "\n" not in message


def test_a_notebook_needs_nothing_below_the_top_level():
    for name in ("sweep", "SweepResult", "design_from_token", "Design", "CompareResult", "DesignRow", "ResultPlot",
                 "load_suite", "compare", "falsify", "FalsifySpec", "SweepSpec", "run_closed_loop", "RunConfig"):
        assert name in wm.__all__ and getattr(wm, name) is not None
    from wmr_mj.figures import results  # the drawing, in the layer below the results

    assert all(hasattr(results, f"plot_{kind}") for kind in ("run", "sweep", "falsify", "compare", "validate"))


def _cells(nb) -> list[tuple[str, str]]:
    return [(c.cell_type, c.source.strip()) for c in nb.cells]


def test_the_notebook_is_stored_without_outputs_and_paired_with_its_text():
    nbformat = pytest.importorskip("nbformat", reason="pip install -e '.[notebook]'")
    jupytext = pytest.importorskip("jupytext", reason="pip install -e '.[notebook]'")
    stored = nbformat.read(EXAMPLES / "notebook.ipynb", as_version=4)
    assert all(not c.get("outputs") and c.get("execution_count") is None for c in stored.cells
               if c.cell_type == "code")
    assert _cells(stored) == _cells(jupytext.read(EXAMPLES / "notebook.py"))


@pytest.mark.slow
def test_the_example_notebook_runs_in_its_quick_mode():
    nbformat = pytest.importorskip("nbformat", reason="pip install -e '.[notebook]'")
    nbclient = pytest.importorskip("nbclient", reason="pip install -e '.[notebook]'")
    nb = nbformat.read(EXAMPLES / "notebook.ipynb", as_version=4)
    env = {"WMR_MJ_NOTEBOOK_QUICK": "1", "MPLBACKEND": "Agg"}
    old = {k: os.environ.get(k) for k in env}
    os.environ.update(env)  # the kernel inherits this process's environment
    try:
        nbclient.NotebookClient(nb, timeout=120, kernel_name="python3",
                                resources={"metadata": {"path": str(EXAMPLES)}}).execute()
    finally:
        for k, v in old.items():
            os.environ.pop(k) if v is None else os.environ.__setitem__(k, v)
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    html = [o["data"]["text/html"] for o in outputs if "text/html" in o.get("data", {})]
    assert any("certified-inside" in h for h in html) and any("no-claim" in h for h in html)
    assert any("image/png" in o.get("data", {}) for o in outputs)  # the figures
