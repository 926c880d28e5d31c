"""STL requirements (wmr_mj.analysis.requirements): robustness against hand computations on short
signals, the windowed operators against rtamt's own, presets, and the CLI's refusals."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from wmr_mj.analysis.requirements import (
    SIGNALS,
    RequirementResult,
    _robustness,
    _spec,
    evaluate,
    evaluate_run,
    parse_requirement,
    preset_formula,
)
from wmr_mj.errors import ParameterError, UnknownNameError

X = np.array([0.1, -0.5, 0.3, 0.9, 0.2, -1.4, 0.0])


def _rob(formula: str, x=X, period: float = 1.0) -> float:
    return evaluate(parse_requirement(formula, period=period, signals=("x",)), {"x": x}, period=period).robustness


def test_bounded_always_is_the_window_min_of_the_margin():
    # always[0,2](abs(x) <= 1) at t = 0: min over samples 0, 1, 2 of 1 - |x|
    assert _rob("always[0,2](abs(x) <= 1)") == min(1 - abs(v) for v in X[0:3]) == pytest.approx(0.5)
    # the window moves with its bounds: samples 3..5 hold 0.9, 0.2, -1.4
    assert _rob("always[3,5](abs(x) <= 1)") == pytest.approx(1 - 1.4)
    # the same with a 10 ms period: bounds in seconds
    assert _rob("always[0.03,0.05](abs(x) <= 1)", period=0.01) == pytest.approx(1 - 1.4)
    # unbounded: the whole trace; eventually: the max
    assert _rob("always(abs(x) <= 1)") == pytest.approx(1 - 1.4)
    assert _rob("eventually[1,3](x >= 0.5)") == pytest.approx(0.9 - 0.5)


def test_result_is_frozen_and_reports_satisfaction():
    r = evaluate(parse_requirement("always[0,2](abs(x) <= 1)", period=1.0, signals=("x",)), {"x": X}, period=1.0)
    assert isinstance(r, RequirementResult) and r.satisfied
    assert r.to_dict() == {"formula": "always[0,2](abs(x) <= 1)", "robustness": 0.5, "satisfied": True}
    with pytest.raises(AttributeError):
        r.robustness = 0.0  # type: ignore[misc]
    assert not evaluate(parse_requirement("always(abs(x) <= 1)", period=1.0, signals=("x",)), {"x": X},
                        period=1.0).satisfied


@pytest.mark.parametrize("formula", ["always[0,2](abs(x) <= 1)", "eventually[1,3](x > 0.5)",
                                     "historically[0,4](x < 1)", "once[2,5](x >= 0.2)", "always[3,3](x < 1)",
                                     "always[0,7](eventually[0,1](x > 0) and historically[1,2](abs(x) <= 2))"])
def test_windowed_operators_equal_rtamt_own_to_the_bit(formula):
    rng = np.random.default_rng(0)
    for n in (2, 3, 5, 8, 40):
        x = rng.normal(size=n).tolist()
        data = {"time": list(range(n)), "x": x}
        assert _spec(formula, 1.0, ("x",)).evaluate(data) == _spec(formula, 1.0, ("x",), stock=True).evaluate(data)


@pytest.mark.parametrize("formula", ["always(abs(x) <= 0.7)", "eventually(x >= 0.5)", "always(x == 0.1)",
                                     "eventually(abs(x) !== 0.2)", "always((x < 1) and (y > -1))",
                                     "eventually(always(abs(x - y) <= 1.5))", "always[1,4](abs(x) >= 0.1)"])
@pytest.mark.parametrize("nan", [False, True], ids=["finite", "with-nan"])
def test_the_numpy_visitor_equals_rtamt_own_to_the_bit(formula, nan):
    """abs, the comparisons and unbounded always/eventually in NumPy: rtamt's loops' bits, NaN included."""
    rng = np.random.default_rng(1)
    for n in (2, 5, 40, 1000):
        x, y = rng.normal(size=n), rng.normal(size=n)
        if nan:
            x[n // 2] = np.nan
        data = {"time": list(range(n)), "x": x.tolist(), "y": y.tolist()}
        ours = _spec(formula, 1.0, ("x", "y")).evaluate(data)
        stock = _spec(formula, 1.0, ("x", "y"), stock=True).evaluate(data)
        assert np.array_equal(np.asarray(ours, float), np.asarray(stock, float), equal_nan=True), formula


@pytest.mark.parametrize("formula", ["always[1,4](abs(x) <= 0.7)", "eventually(x >= 0.5)", "always(x == 0.1)",
                                     "always((x < 1) and (y > -1))", "eventually[0,3](always(abs(x - y) <= 1.5))",
                                     "historically[0,2](x < 1)", "not(always[2,9](x <= y))"])
@pytest.mark.parametrize("nan", [False, True], ids=["finite", "with-nan"])
def test_the_robustness_at_zero_is_rtamts_evaluate_to_the_bit(formula, nan):
    """The monitor's robustness (the tree visited on arrays, rtamt's formatting skipped) against rtamt's own
    ``evaluate`` with its own visitor: its first sample's value, NaN included."""
    rng = np.random.default_rng(2)
    for n in (2, 5, 40, 1000):
        x, y = rng.normal(size=n), rng.normal(size=n)
        if nan:
            x[n // 3] = np.nan
        stock = _spec(formula, 1.0, ("x", "y"), stock=True).evaluate({"time": list(range(n)), "x": x.tolist(),
                                                                      "y": y.tolist()})[0][1]
        ours = _robustness(_spec(formula, 1.0, ("x", "y")), formula, {"x": x, "y": y}, 1.0)
        assert np.array_equal(ours, stock, equal_nan=True), (formula, n, ours, stock)


def test_presets_resolve_against_the_run_bounds():
    rows = {s: np.zeros(4) for s in SIGNALS}
    rows["E"] = np.array([0.0, 0.01, -0.03, 0.02])
    rows["E_dot"] = np.array([0.0, 0.1, 0.0, -0.2])
    summary = {"certificate": {"E_max": 0.05, "Edot_max": 0.3}, "paper_region": {"E_max": 0.02, "Edot_max": 1.0}}
    reqs = [parse_requirement(t, period=1e-3) for t in ("certificate", "paper")]
    cert, paper = evaluate_run(reqs, rows, summary, period=1e-3)
    assert cert.robustness == pytest.approx(min(0.05 - 0.03, 0.3 - 0.2)) and cert.satisfied
    assert paper.robustness == pytest.approx(0.02 - 0.03) and not paper.satisfied
    assert cert.to_dict()["requirement"] == "certificate" and "0.05" in cert.formula
    # no certificate (an unbounded region): nothing to satisfy, no robustness
    (none,) = evaluate_run(reqs[:1], rows, {"certificate": {"E_max": None, "Edot_max": None}}, period=1e-3)
    assert none.robustness is None and not none.satisfied
    assert preset_formula("certificate", 1e-5, 2.0) == "always((abs(E) <= 0.00001) and (abs(E_dot) <= 2))"


@pytest.mark.parametrize("text,error,names", [
    ("always(abs(Q) <= 1)", UnknownNameError, ("'Q'", "E_dot", "alpha0", "voltage")),
    ("always[0,2](abs(E) <=", ParameterError, ("not an STL formula",)),
    ("always[0,0.0005](abs(E) <= 1)", ParameterError, ("multiple", "0.001 s")),
    ("", ParameterError, ("empty",)),
])
def test_bad_requirements_are_refused(text, error, names):
    with pytest.raises(error) as info:
        parse_requirement(text, period=1e-3)
    assert all(n in str(info.value) for n in names), str(info.value)


def _cli(*argv, check=True):
    return subprocess.run([sys.executable, "-m", "wmr_mj.cli", "run", "--preset", "certified", "--no-log",
                           "--duration", "10", *argv], capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_cli_run_reports_each_requirement():
    proc = _cli("--json", "--require", "always(abs(E) <= 0.05)", "--require", "always[8,10](abs(E) <= 0.001)",
                "--require", "certificate")
    assert proc.returncode == 0, proc.stderr
    s = json.loads(proc.stdout)
    whole, late, cert = s["requirements"]
    assert whole["formula"] == "always(abs(E) <= 0.05)" and whole["satisfied"]
    assert whole["robustness"] == pytest.approx(0.05 - s["sup_E"], abs=1e-15)  # min(0.05 - |E|) by hand
    assert set(late) == {"formula", "robustness", "satisfied"}
    assert cert["requirement"] == "certificate" and cert["satisfied"]
    assert cert["robustness"] == pytest.approx(min(s["certificate"]["E_max"] - s["sup_E"],
                                                   s["certificate"]["Edot_max"] - s["sup_Edot"]), abs=1e-15)


@pytest.mark.slow
@pytest.mark.parametrize("formula,names", [("always(abs(Q) <= 1)", ("'Q'", "E_dot", "alpha0", "voltage")),
                                           ("always[0,2](abs(E) <=", ("always[0,2](abs(E) <=", "alpha_dot"))])
def test_cli_run_bad_requirement_exits_2(formula, names):
    proc = _cli("--require", formula)
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert all(n in proc.stderr for n in names), proc.stderr
    assert proc.stdout == ""  # refused before the run


def test_cross_track_preset_is_the_steady_bound_minus_the_largest_cross_track():
    """The preset `cross-track`: from the settling time on, the cross-track bound less C's largest
    |cross-track| at the control steps (a hand computation on the same rows); the per-step maximum
    agrees with the summary's sampled one to 1e-6 m."""
    import math

    from wmr_mj.analysis.requirements import evaluate_run, parse_requirement
    from wmr_mj.sim.closed_loop import requirement_rows, run_closed_loop
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED

    result = run_closed_loop(RunConfig(**CERTIFIED.config_changes(), duration=20.0), progress=False)
    reqs = [parse_requirement("cross-track", period=1e-3)]
    rows = requirement_rows(result, reqs)
    summary = result.summary.to_dict()
    (judged,) = evaluate_run(reqs, rows, summary, period=1e-3)
    bound = summary["path_verdict"]["cross_track_bound"]
    start = math.ceil(summary["settle_s"] / 1e-3 - 1e-9)
    by_hand = bound - np.max(np.abs(rows["cross_track"][start:]))
    assert judged.robustness == pytest.approx(by_hand, abs=1e-15) and judged.satisfied
    assert np.max(np.abs(rows["cross_track"][start:])) == pytest.approx(summary["path_error"]["cross_track_max"],
                                                                         abs=1e-6)
    assert "cross_track" not in requirement_rows(result, [parse_requirement("always(abs(E) <= 1)", period=1e-3)])
