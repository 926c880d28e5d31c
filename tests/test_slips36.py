"""The slips of issue 36 ("Sweeps and searches", "A mismatch study"), one test (or a few) each."""

from __future__ import annotations

import csv
import math

import pytest

from wmr_mj.experiments.sweep import (
    PRECISE_ROWS,
    SWEEP_KEYS_DEPRECATED,
    SweepSpec,
    SweepSummary,
    read_results,
    read_runs,
    run_sweep,
)
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.many_runs import CSV_SIGNIFICANT_DIGITS, csv_number

BASE = RunConfig(model="nonholonomic", duration=10.0)


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """A small sweep's folder and its rows as run_sweep returns them (full precision)."""
    folder = tmp_path_factory.mktemp("sweep")
    rows = run_sweep(SweepSpec(n=3, seed=2, sampling="lhs", base=BASE), out_dir=folder, nthread=1)
    return folder, rows


# -- 10: rounded CSV values, full precision kept in the JSON ------------------------------------

def test_csv_number_rounds_to_the_stated_significant_digits():
    assert CSV_SIGNIFICANT_DIGITS == 12
    assert csv_number(0.009000000000000001) == "0.009"  # the cell
    assert csv_number(0.1 + 0.2) == "0.3"
    assert csv_number(650.0) == "650.0" and csv_number(-1.5e-9) == "-1.5e-09"
    assert csv_number(math.inf) == "inf" and csv_number(math.nan) == "nan"
    x = 0.123456789012345678
    assert float(csv_number(x)) == float(f"{x:.12g}") and csv_number(x) == "0.123456789012"


def test_runs_csv_is_rounded_and_the_folder_keeps_every_bit(swept):
    folder, rows = swept
    with open(folder / "runs.csv", newline="") as f:
        cells = list(csv.DictReader(f))
    for cell, row in zip(cells, rows):
        for key in ("m1", "sup_E", "sup_Edot", "saturated_fraction", "final_alpha"):
            # the CSV's text is the 12-digit rounding of the run's float (an independent format here)
            assert cell[key] == repr(float(format(row[key], ".12g"))), key
            assert len(cell[key].replace("-", "").replace(".", "").lstrip("0").split("e")[0]) <= 12
    precise = read_runs(folder)  # what resume and validate read: every bit
    assert [r["sup_E"] for r in precise] == [r["sup_E"] for r in rows]
    assert [r["m1"] for r in precise] == [r["m1"] for r in rows]
    assert (folder / PRECISE_ROWS).is_file()
    # the CSV alone (a folder written before the precise file) still reads
    assert [r["run"] for r in read_results(folder / "runs.csv")] == [0, 1, 2]


# -- 8: the paper's deprecated aliases under `paper`, not at the top level -----------------------

def test_sweep_summary_keeps_the_papers_aliases_under_paper_only(swept):
    _, rows = swept
    out = SweepSummary.of(rows).sweep_dict(1.0)
    for old, new in SWEEP_KEYS_DEPRECATED.items():
        assert old not in out, old
        assert out["paper"][old] == out[new], old
    assert "deprecated_keys" not in out
    assert out["paper"]["worst_E_ratio"] == max(r["E_ratio"] for r in rows)  # the paper's region, not the certificate's
    assert out["paper"]["E_max"] == rows[0]["E_max"]


# -- 6: aggregated reasons give the range over the runs -----------------------------------------

def test_aggregated_unmet_assumptions_give_the_range_over_the_runs():
    from wmr_mj.analysis.verdicts import DELAY_FIXED_POINT, count_unmet, format_unmet, merged_note

    def run(value: float, b: float) -> list[dict]:
        return [{"name": "(4.23) small gain", "value": value, "limit": 1.0},
                {"name": DELAY_FIXED_POINT, "value": None, "limit": 1.0,
                 "note": f"the gear's play (b = {b:g} rad) lies between the motor and an encoder"}]

    counted = count_unmet([run(1.2, 0.001), run(1.05, 0.01), run(1.3, 0.004)])
    gain, play = counted
    assert gain["runs"] == 3 and gain["value"] == 1.2 and gain["value_range"] == [1.05, 1.3]
    assert play["note"] == "the gear's play (b = 0.001-0.01 rad) lies between the motor and an encoder"
    assert "value_range" not in play  # no finite value to range over
    text = format_unmet(counted)
    assert "(4.23) small gain (1.05-1.3 vs 1)" in text and "b = 0.001-0.01 rad" in text
    # one run, or runs that agree: the value as it is, no range
    single = count_unmet([run(1.2, 0.001), run(1.2, 0.001)])
    assert "value_range" not in single[0] and single[1]["note"].count("b = 0.001 rad") == 1
    # notes whose words differ (another reason): each, merged with its like, and how many runs gave it
    assert merged_note(["a 1", "b 2", "b 3"]) == "a 1 (1 run) | b 2-3 (2 runs)"


def test_the_unmet_record_round_trips_its_range():
    from wmr_mj.sim.records import UnmetAssumption

    a = UnmetAssumption.from_dict({"name": "x", "value": 1.0, "limit": 0.5, "runs": 2, "value_range": [1.0, 2.0]})
    assert a.value_range == (1.0, 2.0) and a.to_dict()["value_range"] == [1.0, 2.0]
    assert "value_range" not in UnmetAssumption(name="x", value=1.0, limit=0.5).to_dict()


# -- 2: falsify records the value each run used --------------------------------------------------

def test_falsify_records_the_encoder_bits_each_run_used(tmp_path):
    """A search over sensing.encoder_bits proposes fractional bits; the run has 2**round(bits) ticks, and the
    JSON, the evaluations and evaluations.csv record those whole bits (as sweep's runs.csv does)."""
    from wmr_mj.searches.falsify import FalsifySpec, falsify, worst_config
    from wmr_mj.sim.designs import CERTIFIED

    base = RunConfig(**CERTIFIED.config_changes(), duration=9.0, sensing="magnetic-12bit-axis")
    spec = FalsifySpec(base=base, box={"sensing.encoder_bits": (10.6, 13.4)}, objective="sup-E", budget=5,
                       method="vertices-polish", seed=1)
    assert spec.recorded_values([11.533]) == {"sensing.encoder_bits": 12.0}
    assert spec.config([11.533]).sensing.encoder_ticks == 4096
    result = falsify(spec, nthread=1)
    for e in (*result.search, *result.random):
        bits = e.params["sensing.encoder_bits"]
        assert bits == round(e.point[0]) and bits.is_integer()  # the run's, not the proposed point
        assert spec.config(e.point).sensing.encoder_ticks == 2 ** int(bits)
    assert any(e.point[0] != e.params["sensing.encoder_bits"] for e in result.random)  # the sample is fractional
    assert worst_config(result).sensing.encoder_ticks == 2 ** int(result.worst.params["sensing.encoder_bits"])
    out = result.to_dict(runs=False)
    assert out["worst"]["params"]["sensing.encoder_bits"] == result.worst.params["sensing.encoder_bits"]

    from wmr_mj.cli.falsify import _table

    rows = list(csv.DictReader(_table(result).splitlines()))
    assert {float(r["sensing.encoder_bits"]) for r in rows} <= {11.0, 12.0, 13.0}


# -- 3: an objective undefined for every run, refused before any step -----------------------------

def test_falsify_refuses_an_objective_undefined_for_every_run_before_any_step(tmp_path, capsys):
    from wmr_mj.cli.app import main

    out = tmp_path / "f"
    # the paper's design has no certificate over the box (its bound on |alpha| passes pi/2: docs/guides/claim.md),
    # whatever the run's plant in it: every run's sup|E|/E_max is undefined, known before any step
    code = main(["falsify", "--preset", "paper", "--budget", "8", "--duration", "10", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert "undefined for every run" in err[0] and "--objective sup-E" in err[0]
    assert not out.exists()  # nothing written, nothing stepped


def test_a_box_that_reaches_the_certificate_is_not_refused_up_front():
    """Where a run's certificate may differ from the base's (a cart axis, its limits), the base's says nothing of
    every run's: no refusal before the runs."""
    from wmr_mj.searches.falsify import shares_the_base_certificate

    ideal = RunConfig()
    sensed = RunConfig(sensing="magnetic-12bit-axis")
    assert shares_the_base_certificate(ideal, ["m1", "mu", "R_a", "i2"])
    assert not shares_the_base_certificate(ideal, ["m1", "sensing.delay"])
    assert not shares_the_base_certificate(ideal, ["m1", "voltage_limit"])
    assert shares_the_base_certificate(sensed, ["m1", "R_a"]) and not shares_the_base_certificate(sensed, ["i2"])


# -- 4: falsify warns of runs its objective leaves blank ------------------------------------------

def _evaluations(phase: str, objectives: list[float | None]):
    from wmr_mj.searches.falsify import Evaluation

    return [Evaluation(phase=phase, index=i, generation=0, params={"m1": 600.0 + i}, objective=v,
                       summary={"sup_E": 0.01 * (i + 1), "sup_Edot": 0.1}) for i, v in enumerate(objectives)]


def test_falsify_warns_how_many_runs_have_no_certificate_objective():
    from wmr_mj.searches.falsify import FalsifyResult, FalsifySpec, undefined_objective_warning

    spec = FalsifySpec(box={"m1": (600.0, 700.0)}, budget=16)
    blank = FalsifyResult(spec=spec, search=_evaluations("search", [None] * 11 + [0.5] * 5),
                          random=_evaluations("random", [0.2, None]), objective_source="certificate.E_ratio")
    text = undefined_objective_warning(blank)
    assert text is not None and text.startswith("WARNING: 11 of 16 search runs, 1 of 2 random runs")
    assert "sup|E|/E_max of the certificate" in text and "--objective sup-E" in text
    full = FalsifyResult(spec=spec, search=_evaluations("search", [0.1, 0.2]),
                         random=_evaluations("random", [0.3]), objective_source="certificate.E_ratio")
    assert undefined_objective_warning(full) is None


# -- 9: a drift test that does not fire on a settled run ------------------------------------------

def _drift_of_signal(E, period: float = 0.001):
    from wmr_mj.sim.closed_loop import _drift_of

    return _drift_of(E, 0.0, period)


def test_a_run_settled_onto_a_larger_plateau_is_not_growing():
    """|E| rises through the window before the last and settles (to the last bits) early in the last one:
    the last window's max exceeds the previous one's by 1.8e-4 rad (the old test fired), and yet it is settled."""
    import numpy as np

    t = np.arange(20000) * 0.001  # 20 s at 1 kHz: windows [10, 15) and [15, 20)
    E = np.where(t < 14.0, 0.0, 0.005 * (1.0 - np.exp(-(t - 14.0) / 0.3)))
    E = E + 1e-13 * np.sin(997.0 * t)  # a rounding floor
    d = _drift_of_signal(E)
    assert d.E_last_window - d.E_prev_window > 1e-4  # what fired before
    assert d.growing is False


def test_a_genuinely_growing_run_is_growing_and_a_creeping_one_is_not():
    import numpy as np

    t = np.arange(20000) * 0.001
    assert _drift_of_signal(1e-4 * t).growing is True  # 100 urad/s to the end: 5x the tolerance's rate
    assert _drift_of_signal(0.002 + 5e-6 * t).growing is False  # stiction's creep: a few urad/s (model card)
    growing_oscillation = 0.01 * np.exp(0.1 * t) * np.sin(2 * np.pi * t)  # an unstable mode's envelope
    assert _drift_of_signal(growing_oscillation).growing is True
    assert _drift_of_signal(np.full(20000, np.inf)).growing is True  # diverged: never settled


def test_the_drift_without_halves_is_the_two_windows_test():
    from wmr_mj.analysis.verdicts import DRIFT_TOLERANCE, drift

    assert drift(prev_window=0.0, last_window=2 * DRIFT_TOLERANCE, final_alpha_dot=0.0).growing is True
    assert drift(prev_window=0.0, last_window=2 * DRIFT_TOLERANCE, final_alpha_dot=0.0,
                 last_halves=(2 * DRIFT_TOLERANCE, 2 * DRIFT_TOLERANCE)).growing is False
    assert drift(prev_window=0.0, last_window=2 * DRIFT_TOLERANCE, final_alpha_dot=0.0,
                 last_halves=(0.5 * DRIFT_TOLERANCE, 2 * DRIFT_TOLERANCE)).growing is True


def test_the_batch_judges_the_drift_as_the_serial_run():
    """The batch folds the same halves per block as the serial run reads from its rows: the same Drift."""
    from wmr_mj.sim.batch import run_batch
    from wmr_mj.sim.closed_loop import run_closed_loop

    configs = [RunConfig(model="nonholonomic", duration=10.0, m1=m1) for m1 in (560.0, 740.0)]
    for config, batched in zip(configs, run_batch(configs, nthread=1)):
        assert batched.drift == run_closed_loop(config, progress=False).summary.drift


# -- 1: a fixed m1 on sweep and falsify ------------------------------------------------------------

def test_a_sweep_with_a_fixed_m1_sweeps_the_delay_alone(tmp_path, capsys):
    import json

    from wmr_mj.cli.app import main

    out = tmp_path / "s"
    assert main(["sweep", "--preset", "certified", "--m1", "650", "--range", "sensing.delay=0:0.004", "--n", "3",
                 "--sampling", "grid", "--duration", "9", "--nthread", "1", "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    rows = read_runs(out)
    assert [r["m1"] for r in rows] == [650.0] * 3  # exactly: a zero-width draw
    assert [r["sensing.delay"] for r in rows] == [0.0, 0.002, 0.004]  # a 3-point grid over the delay alone
    assert summary["fixed_m1"] == 650.0 and summary["ranges"]["m1"] == [550.0, 750.0]  # the box stays


def test_a_zero_width_m1_range_is_a_fixed_m1(tmp_path, capsys):
    """--m1-range 650 650 was refused; it is --m1 650 (the certificate's box: the default range)."""
    from wmr_mj.cli.app import build_parser
    from wmr_mj.cli.falsify import _base_and_box
    from wmr_mj.cli.sweep import fixed_m1_from_args

    parser = build_parser()
    args = parser.parse_args(["sweep", "--m1-range", "650", "650", "--range", "sensing.delay=0:0.01"])
    assert fixed_m1_from_args(args) == 650.0 and list(args.m1_range) == [550.0, 750.0]
    spec = SweepSpec(n=4, m1=650.0, ranges={"sensing.delay": (0.0, 0.01)}, base=RunConfig(), sampling="lhs")
    assert {float(x) for x in spec.bounds[0]} == {650.0}
    assert spec.fingerprint() != SweepSpec(n=4, ranges={"sensing.delay": (0.0, 0.01)}, base=RunConfig()).fingerprint()
    args = parser.parse_args(["falsify", "--m1-range", "650", "650", "--uncertainty", "m1", "--range", "mu=0.015:0.02",
                              "--range", "sensing.delay=0:0.01"])
    base, box = _base_and_box(args)
    assert "m1" not in box and set(box) == {"mu", "sensing.delay"} and base.m1 == 650.0
    args = parser.parse_args(["falsify", "--m1", "700", "--uncertainty", "m1", "--range", "mu=0.015:0.02"])
    base, box = _base_and_box(args)
    assert set(box) == {"mu"} and base.m1 == 700.0 and base.m1_range == (550.0, 750.0)


@pytest.mark.parametrize("argv, words", [
    (["sweep", "--m1-range", "900", "900"], "outside the certificate's default box"),
    (["sweep", "--m1", "600", "--m1-range", "650", "650"], "fix two masses"),
    (["falsify", "--m1", "650", "--uncertainty", "m1"], "the box is empty"),
    (["sweep", "--m1", "650", "--sampling", "grid", "--n", "4"], "needs a ranged parameter"),
])
def test_fixed_m1_bad_input_is_one_line(tmp_path, capsys, argv, words):
    from wmr_mj.cli.app import main

    assert main([*argv, "--duration", "9", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0], err


# -- 5: effort in every sweep summary, overall and per level of a ranged axis ----------------------

def test_voltage_effort_against_a_plain_loop():
    import numpy as np

    from wmr_mj.sim.summary import voltage_effort

    u = np.array([0.0, 3.0, -24.0, 24.0, 1.5])
    peak, sq, tv = 0.0, 0.0, 0.0
    for k, x in enumerate(u):  # a plain loop, the definitions written out
        peak, sq = max(peak, abs(x)), sq + x * x
        tv += abs(x - u[k - 1]) if k else 0.0
    e = voltage_effort(u, 0.002)
    assert e.peak_voltage == peak == 24.0
    assert e.rms_voltage == pytest.approx(math.sqrt(sq / 5), rel=1e-15)  # summation order only
    assert e.tv_voltage == pytest.approx(tv / (5 * 0.002), rel=1e-15) and tv == 3 + 27 + 48 + 22.5


def test_the_batch_measures_the_effort_of_the_serial_run_bit_for_bit(swept):
    from wmr_mj.sim.closed_loop import run_closed_loop

    _, rows = swept
    single = run_closed_loop(BASE.replace(m1=rows[1]["m1"]), progress=False).summary.to_dict()
    for key in ("peak_voltage", "rms_voltage", "tv_voltage", "saturated_fraction"):
        assert rows[1][key] == single[key], key


def test_the_sweep_summary_has_the_effort_overall_and_per_level():
    """A 2 x 2 grid of (m1, mu): two levels of each axis, two runs at each; the figures are the rows' (a
    plain computation over them)."""
    from wmr_mj.cli.sweep import effort_lines

    rows = []
    for i, (m1, mu) in enumerate([(550.0, 0.01), (550.0, 0.02), (750.0, 0.01), (750.0, 0.02)]):
        rows.append({"run": i, "m1": m1, "mu": mu, "verdict": "certified-inside", "sup_E": 0.01, "sup_Edot": 0.1,
                     "left_steering_range": False, "saturated_fraction": i / 10, "peak_voltage": 20.0 + i,
                     "rms_voltage": 5.0 + i, "tv_voltage": 100.0 * (i + 1)})
    runs = SweepSummary.of(rows, names=("m1", "mu"))
    e = runs.effort
    assert e.runs == 4 and e.mean_saturated_fraction == pytest.approx(0.15, rel=1e-15)  # the sum's rounding
    assert e.max_saturated_fraction == 0.3
    assert e.peak_voltage == 23.0 and e.mean_rms_voltage == 6.5 and e.mean_tv_voltage == 250.0
    assert e.max_tv_voltage == 400.0
    by = {a.axis: a.levels for a in runs.effort_by_level}
    assert [lv.value for lv in by["m1"]] == [550.0, 750.0] and [lv.value for lv in by["mu"]] == [0.01, 0.02]
    assert by["m1"][1].effort.peak_voltage == 23.0 and by["m1"][0].effort.mean_tv_voltage == 150.0
    assert by["mu"][0].effort.runs == 2 and by["mu"][0].effort.mean_rms_voltage == 6.0  # runs 0 and 2
    out = runs.sweep_dict(1.0)
    assert out["effort"]["peak_voltage"] == 23.0
    assert [lv["value"] for lv in out["effort_by_level"]["mu"]] == [0.01, 0.02]
    assert SweepSummary.from_dict(runs.to_dict()) == runs
    lines = effort_lines(runs)
    assert lines[0].startswith("effort: saturated 15% of the time (at most 30%), peak |u| 23 V")
    assert any(line.startswith("  mu = 0.02 (2 runs)") for line in lines)
    # rows without the effort columns (a runs.csv written before them): no effort, no lines
    old = [{k: v for k, v in r.items() if k not in ("peak_voltage", "rms_voltage", "tv_voltage")} for r in rows]
    assert SweepSummary.of(old, names=("m1", "mu")).effort is None and effort_lines(SweepSummary.of(old)) == []


def test_runs_csv_has_the_effort_columns(swept):
    folder, rows = swept
    with open(folder / "runs.csv", newline="") as f:
        header = next(csv.reader(f))
    assert {"peak_voltage", "rms_voltage", "tv_voltage"} <= set(header)
    assert SweepSummary.of(rows).effort.peak_voltage == max(r["peak_voltage"] for r in rows)


# -- 11: compare's adversary over the cart's axes; a figure that tells designs apart ----------------

def test_the_adversary_searches_the_carts_axes_where_a_scenario_declares_a_non_ideal_cart():
    from wmr_mj.experiments.compare import adversary_spec, design_from_token
    from wmr_mj.experiments.suite import load_suite

    v2 = load_suite("standard-v2")
    design = design_from_token("certified", v2)
    hardware = v2.select(["circle/*"])
    spec = adversary_spec(design, v2, budget=16, seed=0, scenarios=hardware)
    declared = {"sensing.delay": 0.005, "actuation.inductance": 0.0015, "transmission.backlash": 0.002}
    for axis, top in declared.items():  # the largest each scenario's [hardware.<name>] declares (standard-v2.toml)
        assert spec.box[axis] == (0.0, top), axis
    assert "actuation.delay" not in spec.box  # no scenario sets it
    top = spec.config([spec.box[n][1] for n in spec.names])  # the box's far corner: a cart the run builds
    assert (top.sensing.delay, top.actuation.inductance, top.transmission.backlash) == (0.005, 0.0015, 0.002)
    # the ideal scenarios alone, or a suite without hardware: the box is the plant's, the signals', the path's
    ideal = adversary_spec(design, v2, budget=16, seed=0, scenarios=v2.select(["circle/nominal/none"]))
    v1 = load_suite("standard-v1")
    plain = adversary_spec(design_from_token("certified", v1), v1, budget=16, seed=0, scenarios=v1.scenarios)
    for s in (ideal, plain):
        assert not any(n.startswith(("sensing.", "actuation.", "transmission.")) for n in s.names)
    assert set(spec.names) - set(ideal.names) == set(declared)


def test_the_compare_figure_draws_each_design_in_its_own_colour_with_a_legend():
    from types import SimpleNamespace

    from matplotlib.colors import to_hex

    from wmr_mj.figures.results import figure_compare

    rows = tuple(SimpleNamespace(label=name, requirements_passed=k, requirements_total=4, rms_voltage=1.0 + k,
                                 cross_track_max=0.01 * (k + 1)) for k, name in enumerate(("certified", "pd", "smc")))
    fig = figure_compare(SimpleNamespace(rows=rows))
    bars_ax, scatter_ax = fig.axes[:2]
    bars = [to_hex(p.get_facecolor()) for p in bars_ax.patches]
    points = [to_hex(c.get_facecolor()[0]) for c in scatter_ax.collections]
    assert len(set(bars)) == 3 and bars == points  # one colour per design, the same in both panels
    assert [t.get_text() for t in scatter_ax.get_legend().get_texts()] == ["certified", "pd", "smc"]


# -- 7: a lane change too short to cover the manoeuvre, judged as partial ---------------------------

def test_a_lane_change_cut_short_is_judged_as_partial(capsys):
    """run --path lane-change --duration 3 printed CERTIFIED-INSIDE covering 0.6 m of the 4.5 m manoeuvre
    (lead-in 0.5 m + lane change 4 m, wmr_mj/sim/config.py) with nothing said: its verdict says PARTIAL."""
    from wmr_mj.analysis.verdicts import format_verdict
    from wmr_mj.cli.app import main
    from wmr_mj.sim.config import manoeuvre_length
    from wmr_mj.sim.designs import CERTIFIED

    assert manoeuvre_length("lane-change") == 4.5 and manoeuvre_length("paper-circle") is None
    assert main(["run", "--preset", "certified", "--path", "lane-change", "--duration", "3", "--no-log"]) == 0
    verdict = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("verdict:"))
    assert verdict.startswith("verdict: CERTIFIED-INSIDE") and "PARTIAL" in verdict and "4.5 m" in verdict
    from wmr_mj.sim.closed_loop import run_closed_loop

    short = run_closed_loop(RunConfig(**CERTIFIED.config_changes(), path="lane-change", duration=3.0),
                            progress=False).summary.to_dict()
    # C's reference at V_A = 0.2 m/s (a little faster where it turns): about 0.6 m in 3 s
    assert short["route_finished"] is False and 0.55 < short["route_driven_m"] < 0.7
    assert short["route_length_m"] == 4.5
    whole = run_closed_loop(RunConfig(**CERTIFIED.config_changes(), path="lane-change", duration=24.0),
                            progress=False).summary.to_dict()
    assert whole["route_finished"] is True and "PARTIAL" not in " ".join(format_verdict(whole))


def test_the_batch_reports_the_same_partial_lane_change():
    from wmr_mj.sim.batch import run_batch
    from wmr_mj.sim.closed_loop import run_closed_loop

    configs = [RunConfig(model="nonholonomic", path="lane-change", duration=3.0, m1=m1) for m1 in (600.0, 700.0)]
    for config, batched in zip(configs, run_batch(configs, nthread=1)):
        assert batched.route == run_closed_loop(config, progress=False).summary.route
        assert batched.route is not None and not batched.route.finished


def test_a_random_sample_without_the_objective_is_no_error():
    """falsify --range sensing.delay=0:0.05: one search run had a certificate and no random run; the command
    said "the objective is undefined for every run" after both phases. The search's worst stands; the random
    sample's is its largest sup|E|, without an objective."""
    from wmr_mj.searches.falsify import FalsifyResult, FalsifySpec, undefined_objective_warning

    spec = FalsifySpec(box={"m1": (600.0, 700.0)}, budget=16)
    result = FalsifyResult(spec=spec, search=_evaluations("search", [None, 0.4, None]),
                           random=_evaluations("random", [None, None, None]), objective_source="certificate.E_ratio")
    assert result.worst.objective == 0.4 and result.random_worst.index == 2  # sup_E 0.03, the largest
    random = result.to_dict(runs=False)["random"]
    assert random["worst_objective"] is None and random["sup_E"] == 0.03
    assert undefined_objective_warning(result).startswith("WARNING: 2 of 3 search runs, 3 of 3 random runs")
