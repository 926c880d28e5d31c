"""One result type per command (issue 41 item 5): each is a frozen dataclass with ``to_dict``/``from_dict``,
``.plot()``, ``.to_pandas()`` and ``_repr_html_``; every one reads its own JSON back to the bit, and the three this
file builds by hand (a design, a cart's tightness, a cart check) draw and tabulate the numbers they hold.

The independent truth is the numbers each result is built from here (the fields are given; a run's are those the
run measured), read back from the JSON, the figure's artists and the table's cells to the bit.
"""

from __future__ import annotations

import dataclasses
import html
import json
import math
import struct
from collections.abc import Mapping
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.figure import Figure

from wmr_mj._util.files import json_safe
from wmr_mj.analysis.claim_types import LAW_CLAIM, Assumption
from wmr_mj.analysis.requirements import parse_requirement
from wmr_mj.errors import ParameterError
from wmr_mj.experiments.cart_check import CartCheck, NamedCart
from wmr_mj.experiments.compare import CompareResult, DesignRow, ScenarioRun
from wmr_mj.experiments.suite import load_suite
from wmr_mj.experiments.sweep import SweepSpec, SweepSummary
from wmr_mj.experiments.sweep_result import SweepResult
from wmr_mj.experiments.tightness import CartTightness
from wmr_mj.hardware import Actuation, Sensing, Transmission
from wmr_mj.params import COEFFICIENT_NAMES, Coefficients
from wmr_mj.plant.cartcheck import COEFFICIENT_UNITS, CoefficientCheck, IdentificationCheck, RandomStepCheck
from wmr_mj.plant.identify import IdentificationResult
from wmr_mj.report.results import ValidateSummary
from wmr_mj.searches.design_search import DesignCertificate, DesignResult
from wmr_mj.searches.falsify import Evaluation, FalsifyResult, FalsifySpec
from wmr_mj.sim.closed_loop import RunResult, run_parts
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.parts import resolve_run

#: each command's one result type
RESULTS = {"run": RunResult, "sweep": SweepResult, "falsify": FalsifyResult, "compare": CompareResult,
           "validate": ValidateSummary, "design": DesignResult, "cart tightness": CartTightness,
           "cart check": CartCheck}


@pytest.mark.parametrize("command", list(RESULTS))
def test_each_commands_result_is_frozen_and_has_the_notebooks_methods(command):
    kind = RESULTS[command]
    assert dataclasses.is_dataclass(kind) and kind.__dataclass_params__.frozen  # type: ignore[attr-defined]
    for method in ("to_dict", "from_dict", "plot", "to_pandas", "_repr_html_"):
        assert callable(getattr(kind, method, None)), f"{kind.__name__} has no {method}"


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
def _identification(rows: tuple[CoefficientCheck, ...]) -> IdentificationResult:
    """An identification whose coefficients are the rows' (identified, implied, paper), NaN where no row."""
    by_name = {r.name: r for r in rows}

    def model(key: str) -> Coefficients:
        return Coefficients(**{n: getattr(by_name[n], key) if n in by_name else math.nan for n in COEFFICIENT_NAMES})

    return IdentificationResult(identified=model("identified"),
                                predicted={"nonholonomic": model("implied"), "paper": model("paper")},
                                diagnostics={"samples": 9001, "residual_rms_V": 0.0123, "mujoco_warnings": 0},
                                duration=20.0, seed=3)


def _coefficient(name: str, identified: float, implied: float, allowed: float) -> CoefficientCheck:
    return CoefficientCheck(name=name, identified=identified, implied=implied, paper=implied, allowed=allowed)


@pytest.fixture()
def cart_check() -> CartCheck:
    """P within its allowance (0.4 of it), F outside (1.5 times it): the check fails on F."""
    rows = (_coefficient("P", 10.4, 10.0, 1.0), _coefficient("F", 2.3, 2.0, 0.2))
    ident = IdentificationCheck(result=_identification(rows), rows=rows)
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


# -- every result reads its own JSON back, to the bit ---------------------------------------------------------------
def _bit_equal(a, b, where="") -> None:
    """``a`` and ``b`` hold the same JSON values: the same keys (the commands write them sorted), floats to the bit
    (NaN and -0.0 told apart), bools as bools."""
    if isinstance(a, (bool, np.bool_)) or isinstance(b, (bool, np.bool_)):  # a NumPy bool is written as a bool
        both = isinstance(a, (bool, np.bool_)) and isinstance(b, (bool, np.bool_))
        assert both and a == b, f"{where}: {a!r} != {b!r}"
    elif isinstance(a, float) or isinstance(b, float):
        assert isinstance(a, float) and isinstance(b, float), f"{where}: {a!r} != {b!r}"
        assert struct.pack("<d", a) == struct.pack("<d", b), f"{where}: {a!r} != {b!r}"
    elif isinstance(a, Mapping):
        assert isinstance(b, Mapping) and sorted(a) == sorted(b), f"{where}: keys {sorted(a)} != {sorted(b)}"
        for key in a:
            _bit_equal(a[key], b[key], f"{where}.{key}")
    elif isinstance(a, (list, tuple)):
        assert isinstance(b, (list, tuple)) and len(a) == len(b), f"{where}: {a!r} != {b!r}"
        for i, (x, y) in enumerate(zip(a, b)):
            _bit_equal(x, y, f"{where}[{i}]")
    else:
        assert type(a) is type(b) and a == b, f"{where}: {a!r} != {b!r}"


_CERT = {"E_max": 0.05, "E_ratio": 1.5, "certified": True,
         "assumptions": [{"name": "reachable angle", "met": True, "value": 0.5, "limit": 1.57}]}


@pytest.fixture()
def sweep_result() -> SweepResult:
    spec = SweepSpec(n=2, seed=3, ranges={"mu": (0.01, 0.03)}, base=RunConfig.from_inputs(duration=5.0))
    rows = ({"run": 0, "m1": 600.0, "mu": 0.02, "verdict": "certified-outside", "certificate": _CERT,
             "cert_E_ratio": 1.5, "cert_E_max": 0.05, "sup_E": 0.075, "sup_Edot": 0.1, "inside": None,
             "left_steering_range": False, "saturated_fraction": 0.0, "steps": 10, "batch_law": "compiled"},)
    return SweepResult(spec=spec, rows=rows, summary=SweepSummary.of(rows, names=spec.names))


@pytest.fixture()
def falsify_result() -> FalsifyResult:
    spec = FalsifySpec(base=RunConfig.from_inputs(), box={"m1": (550.0, 750.0)}, budget=12)
    summary = {"sup_E": 0.075, "sup_Edot": 0.2, "verdict": "certified-outside", "certificate": _CERT}
    return FalsifyResult(spec=spec, search=[Evaluation(phase="search", index=0, generation=0, params={"m1": 0.1 + 700},
                                                       objective=1.5, summary=summary)],
                         random=[Evaluation(phase="random", index=0, generation=0, params={"m1": 650.0},
                                            objective=0.25, summary={**summary, "sup_E": 0.0125})],
                         objective_source="certificate of the run", log="worst.mcap")


@pytest.fixture()
def compare_result() -> CompareResult:
    row = DesignRow(label="certified", controller="computed-torque", tracker=None, runs=1, requirements_passed=1,
                    requirements_total=2, least_normalised=-0.25, least_at="tracking @ circle/nominal",
                    certified_inside=0, certified_outside=1, uncertified=0, no_claim=0, failed=0, claim_E_max=0.05,
                    adversary_worst=0.5, adversary_falsified=True, adversary_runs_to_falsify=3,
                    adversary_where={"m1": 700.0}, adversary_worst_sup_E=0.04, random_worst=0.25,
                    random_runs_to_falsify=None, tightness=0.1 + 0.7, rms_voltage=3.0, tv_voltage=9.0,
                    cross_track_max=0.02, cpu_us_per_step=4.0, law="compiled")
    suite = load_suite("standard-v1")
    run = ScenarioRun(design="certified", scenario="circle/nominal", summary={"sup_E": 0.075, "verdict": "x"},
                      requirements={"tracking": {"robustness": -0.01, "satisfied": False}}, rms_voltage=3.0,
                      tv_voltage=9.0, cpu_us_per_step=4.0, law="compiled")
    return CompareResult(suite=suite, scenarios=suite.select(["circle/*"]), rows=(row,), runs=(run,), budget=4,
                         seed=0, versions={"wmr-mj": "x"}, wall_s=2.0, steps=10)


@pytest.fixture()
def design_file(design) -> DesignResult:
    """The design above with every setting a design file writes: a 12-bit encoder, the 2 ms period."""
    settings = {"controller": "computed-torque", "controller_params": {}, "model": "nonholonomic", "kp": 530.0,
                "kd": 46.0, "friction_sign": "measured", "friction_width": 0.01, "control_period": 0.002,
                "sensing": Sensing.from_spec("encoder_ticks=4096"), "actuation": Actuation(),
                "transmission": Transmission(backlash=0.001)}
    return dataclasses.replace(design, settings=settings, evaluations=40, objective="E_max", seed=2,
                               periods=(0.001, 0.002), box={"m1_range": [550.0, 750.0], "duration": 35.0})


@pytest.fixture()
def validate_summary() -> ValidateSummary:
    return ValidateSummary.from_dict(json.loads((Path(__file__).parent / "data" / "validate_summary.json").read_text()))


@pytest.fixture(scope="module")
def sensed_run() -> tuple[RunResult, dict]:
    """A run on a 4096-tick encoder with a differenced velocity at 2 ms, a 2 ms actuation delay and play, judged by
    two requirements: its JSON has the cart's parts, the measurement errors and the requirements."""
    config = RunConfig.from_inputs(duration=9.0, path="lane-change", control_period=0.002,
                                   sensing="encoder_ticks=4096,velocity=difference", actuation="delay=0.002",
                                   transmission="backlash=0.001")
    parts = resolve_run(config)
    requirements = [parse_requirement("always[0,9](abs(E) <= 0.5)", period=0.002),
                    parse_requirement("cross-track", period=0.002)]
    return run_parts(parts, progress=False), {"measurement": parts.measurement, "requirements": requirements}


#: each result, by the fixture that builds it, and what its to_dict takes (a run's: the log, the measurement errors)
ROUND_TRIPS = {"run": "certified_run_10s", "run on a sensed cart": "sensed_run", "sweep": "sweep_result",
               "falsify": "falsify_result", "compare": "compare_result", "validate": "validate_summary",
               "design": "design_file", "cart tightness": "tightness", "cart check": "cart_check"}


def test_every_commands_result_is_in_the_round_trip():
    assert {k for k in ROUND_TRIPS if k in RESULTS} == set(RESULTS)


@pytest.mark.parametrize("case", list(ROUND_TRIPS))
def test_each_result_reads_its_own_json_back_to_the_bit(case, request):
    """``X.from_dict(x.to_dict())`` writes the same JSON again (floats to the bit), directly and through a JSON
    file; a result whose JSON holds all of it reads back equal, a run and a cart check restore what their JSON
    holds (each from_dict's docstring names what it does not)."""
    made = request.getfixturevalue(ROUND_TRIPS[case])
    result, arguments = made if isinstance(made, tuple) else (made, {})
    kind = type(result)
    if kind is RunResult:
        arguments = {**arguments, "log": "run.mcap"}
    rewrite = {k: v for k, v in arguments.items() if k != "requirements"}  # judged once, then in the summary
    d = result.to_dict(**arguments)
    back = kind.from_dict(d)
    _bit_equal(back.to_dict(**rewrite), d)
    text = json.dumps(json_safe(d), sort_keys=True, allow_nan=False)  # as a command writes its JSON file
    again = kind.from_dict(json.loads(text))
    assert json.dumps(json_safe(again.to_dict(**rewrite)), sort_keys=True, allow_nan=False) == text
    if kind is RunResult:
        _a_runs_restored_fields_match(result, back, d)
    elif kind is CartCheck:
        _a_cart_checks_restored_fields_match(result, back)
    else:
        assert back == result


def _a_runs_restored_fields_match(result: RunResult, back: RunResult, d: dict) -> None:
    s, b = result.summary, back.summary
    for field in dataclasses.fields(s):  # every number and name of the summary, to the bit
        value = getattr(s, field.name)
        if field.name != "requirements" and (value is None or isinstance(value, (str, bool, int, float))):
            _bit_equal(getattr(b, field.name), value, field.name)
    assert b.paper_region == s.paper_region and b.drift == s.drift and b.path_error == s.path_error
    assert b.path_bound == s.path_bound and b.path_verdict == s.path_verdict and b.effort == s.effort
    assert b.route == s.route and b.batch == s.batch
    # the requirements the summary had, or those to_dict judged (read back as the summary's)
    assert [r.to_dict() for r in b.requirements or ()] == d.get("requirements", [])
    cert, cert_back = s.certificate.certificate, b.certificate.certificate
    assert (cert_back.region, cert_back.valid) == (cert.region, cert.valid)

    def finite(x: float) -> float:  # a value the JSON writes null (not finite) reads back NaN
        return x if math.isfinite(x) else math.nan

    _bit_equal([dataclasses.astuple(a) for a in cert_back.assumptions],
               [dataclasses.astuple(dataclasses.replace(a, value=finite(a.value), limit=finite(a.limit)))
                for a in cert.assumptions])
    _bit_equal([cert_back.alpha_max, cert_back.voltage_max, cert_back.iterations],
               [cert.alpha_max, cert.voltage_max, cert.iterations])
    if cert.terms is not None:  # section 4's terms, but delta1's parts (not in the JSON)
        assert cert_back.terms == dataclasses.replace(cert.terms, delta1_parts=())
    assert back.claims[LAW_CLAIM] is b.certificate and back.status == result.status and back.rows == {}
    typed = coerced(result.config)
    for name in ("controller", "model", "m1", "kp", "kd", "path", "duration", "signals", "sensing", "actuation",
                 "transmission", "controller_plugin"):
        assert getattr(back.config, name) == getattr(typed, name), name


def _a_cart_checks_restored_fields_match(check: CartCheck, back: CartCheck) -> None:
    cart = check.cart
    assert back.cart == NamedCart(name=cart.name, version=cart.version, path=str(cart.path))
    assert back.steps == check.steps and back.identification.rows == check.identification.rows
    r, rb = check.identification.result, back.identification.result
    assert (rb.identified, rb.predicted, rb.duration, rb.seed) == (r.identified, r.predicted, r.duration, r.seed)
    assert (back.defaults, back.certified_design, back.design) == (check.defaults, check.certified_design, check.design)
    assert (back.passed, back.answer, back.design_wall_s) == (check.passed, check.answer, 0.0)


@pytest.mark.parametrize("result, holds", [(SweepResult, "sweep --json and summary.json hold the summary only"),
                                           (FalsifyResult, "falsify --json and falsify.json hold the worst run only"),
                                           (CompareResult, "compare.json and compare --json hold the rows only")],
                         ids=["sweep", "falsify", "compare"])
def test_a_commands_json_without_its_runs_is_refused_naming_what_holds_them(result, holds):
    """A command's own JSON (no ``runs``) read back by ``from_dict``: one line naming what it holds and what writes
    every run, the same words for each result."""
    with pytest.raises(ParameterError) as caught:
        result.from_dict({"wall_s": 1.0})
    assert str(caught.value) == (f"this JSON has no 'runs' ({holds}): {result.__name__}.to_dict() writes every run, "
                                 "and from_dict reads that back")
