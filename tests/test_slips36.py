"""The slips of issue 36 ("Sweeps and searches", "A mismatch study"), one test (or a few) each."""

from __future__ import annotations

import csv
import math

import pytest

from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.sweep import (
    CSV_SIGNIFICANT_DIGITS,
    PRECISE_ROWS,
    SWEEP_KEYS_DEPRECATED,
    SweepSpec,
    SweepSummary,
    csv_number,
    read_results,
    read_runs,
    run_sweep,
)

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
    # notes whose words differ: the first, and how many others
    assert merged_note(["a 1", "b 2", "b 3"]).startswith("a 1 (in the first such run; 2 other note(s)")


def test_the_unmet_record_round_trips_its_range():
    from wmr_mj.sim.records import UnmetAssumption

    a = UnmetAssumption.from_dict({"name": "x", "value": 1.0, "limit": 0.5, "runs": 2, "value_range": [1.0, 2.0]})
    assert a.value_range == (1.0, 2.0) and a.to_dict()["value_range"] == [1.0, 2.0]
    assert "value_range" not in UnmetAssumption(name="x", value=1.0, limit=0.5).to_dict()
