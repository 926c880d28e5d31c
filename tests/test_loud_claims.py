"""A broken claim is loud everywhere: run, falsify, sweep and compare print run's banner, name the run
that broke it, say so in their JSON and exit with CLAIM_BROKEN_EXIT; a held claim exits 0. Beside the
verdict, the claim's unmet assumptions (name, value vs limit).

The law under test is tests/data/tight_claim.py: a PD law whose claim is |E| <= claim_scale * 0.5 rad.
On lane-change for 3 s its sup|E| is about 2.5e-5 rad, so claim_scale = 1e-6 (E_max = 5e-7 rad) is
broken by every run and claim_scale = 1 (0.5 rad) holds by four orders of magnitude.
"""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from wmr_mj.analysis.verdicts import certified_outside_banner, count_unmet, format_unmet, unmet_assumptions
from wmr_mj.cli._common import CLAIM_BROKEN_EXIT
from wmr_mj.cli.app import main
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig

LAW = str(Path(__file__).resolve().parent / "data" / "tight_claim.py") + ":TightPD"
E_CLAIM = 0.5  # rad: tests/data/tight_claim.py's bound at claim_scale = 1
TIGHT = ["--controller", LAW, "--controller-param", "claim_scale=1e-6", "--path", "lane-change", "--duration", "3"]
HELD = ["--controller", LAW, "--path", "lane-change", "--duration", "3"]
BANNER = certified_outside_banner().split(": ")[0]  # "!!! CERTIFIED-OUTSIDE", as run prints it


def test_the_exit_status_is_distinct_from_bad_inputs_and_a_failed_runs():
    assert CLAIM_BROKEN_EXIT not in (0, 1, 2, 130)


def test_run_prints_the_banner_and_exits_with_the_status_when_its_claim_breaks(capsys):
    assert main(["run", *TIGHT, "--no-log"]) == CLAIM_BROKEN_EXIT
    out = capsys.readouterr().out
    assert out.count(BANNER) == 1 and "verdict: CERTIFIED-OUTSIDE" in out
    assert main(["run", *HELD, "--no-log"]) == 0
    out = capsys.readouterr().out
    assert BANNER not in out and "verdict: CERTIFIED-INSIDE" in out


def test_falsify_breaks_a_tight_claim_whatever_the_objective(tmp_path, capsys):
    # sup-E: an objective that is not the claim's ratio; the claim broken is still reported
    assert main(["falsify", *TIGHT, "--uncertainty", "m1", "--budget", "8", "--objective", "sup-E",
                 "--out", str(tmp_path / "f")]) == CLAIM_BROKEN_EXIT
    out = capsys.readouterr().out
    assert BANNER in out and "broken by: m1 = " in out
    summary = json.loads((tmp_path / "f" / "falsify.json").read_text())  # what --json prints
    assert summary["objective"] == "sup-E" and summary["falsified"] is True
    broken = summary["claim_broken"]
    assert broken["count"] == 16  # every run of both phases: sup|E| ~ 2.5e-5 rad against 5e-7 rad
    assert broken["E_max"] == pytest.approx(1e-6 * E_CLAIM, rel=1e-12)  # the plug-in's bound (1 ulp)
    assert broken["ratio"] == pytest.approx(broken["sup_E"] / broken["E_max"], rel=1e-12)
    # the run that broke it, re-run from its parameters alone, gives its sup|E| to the bit
    config = RunConfig(controller=LAW, controller_params={"claim_scale": 1e-6}, path="lane-change", duration=3.0,
                       m1=broken["params"]["m1"])
    assert run_closed_loop(config, progress=False).summary.sup_E == broken["sup_E"]


def test_falsify_with_the_ratio_objective_reads_the_tightness_as_the_claim_exceeded(tmp_path, capsys):
    assert main(["falsify", *TIGHT, "--uncertainty", "m1", "--budget", "8", "--json",
                 "--out", str(tmp_path / "f")]) == CLAIM_BROKEN_EXIT
    summary = json.loads(capsys.readouterr().out)
    assert summary["falsified"] is True and summary["worst"]["verdict"] == "certified-outside"
    text = summary["tightness"]["text"]
    assert text.startswith(f"the worst run is {summary['tightness']['ratio']:.3g} times the claimed bound")
    assert "the certificate is" not in text and summary["tightness"]["ratio"] > 1


def test_falsify_of_a_held_claim_exits_0_and_says_not_falsified(tmp_path, capsys):
    assert main(["falsify", *HELD, "--uncertainty", "m1", "--budget", "8", "--json",
                 "--out", str(tmp_path / "f")]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["falsified"] is False and summary["claim_broken"] is None
    assert summary["worst"]["verdict"] == "certified-inside" and summary["worst"]["unmet"] == []
    assert "the certificate is" in summary["tightness"]["text"]  # below 1: the margin, as before


def test_falsify_prints_the_unmet_assumption_beside_the_verdict(tmp_path, capsys):
    assert main(["falsify", *TIGHT, "--controller-param", "unmet=true", "--uncertainty", "m1", "--budget", "8",
                 "--out", str(tmp_path / "f")]) == 0  # uncertified: not a broken claim
    out = capsys.readouterr().out
    assert BANNER not in out
    assert "assumptions not met: deliberately unmet (2 vs 1)" in out
    assert "not a broken claim" in out  # the tightness above 1 without the claim's assumptions
    summary = json.loads((tmp_path / "f" / "falsify.json").read_text())
    assert summary["worst"]["unmet"] == [{"name": "deliberately unmet", "value": 2.0, "limit": 1.0}]
    assert summary["falsified"] is False and summary["claim_broken"] is None


def test_sweep_names_the_run_that_broke_the_claim(tmp_path, capsys):
    out_dir = tmp_path / "s"
    assert main(["sweep", *TIGHT, "--n", "2", "--out", str(out_dir)]) == CLAIM_BROKEN_EXIT
    out = capsys.readouterr().out
    assert BANNER in out and "2 of 2 run(s) break the claim" in out
    summary = json.loads((out_dir / "summary.json").read_text())
    broken = summary["claim_broken"]
    assert broken["count"] == summary["verdicts"]["certified-outside"] == 2
    assert broken["E_max"] == pytest.approx(1e-6 * E_CLAIM, rel=1e-12) and set(broken["params"]) == {"m1"}
    assert summary["unmet"] == []
    assert main(["sweep", *HELD, "--n", "2", "--out", str(tmp_path / "held"), "--json"]) == 0
    held = json.loads(capsys.readouterr().out)
    assert held["claim_broken"] is None and held["verdicts"]["certified-inside"] == 2


def test_sweep_summary_counts_the_unmet_assumption(tmp_path, capsys):
    assert main(["sweep", *HELD, "--controller-param", "unmet=true", "--n", "2", "--out", str(tmp_path / "s"),
                 "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["unmet"] == [{"name": "deliberately unmet", "value": 2.0, "limit": 1.0, "runs": 2}]


@pytest.mark.slow
def test_compare_is_loud_and_its_table_says_why(tmp_path, capsys):
    # budget 0: the scenario's own run breaks the tight claim; the adversary's is falsify's claim_broken
    out_dir = tmp_path / "c"
    assert main(["compare", f"{LAW},claim_scale=1e-6", f"{LAW},unmet=true", "--scenarios", "lane/nominal/none",
                 "--budget", "0", "--out", str(out_dir), "--no-progress"]) == CLAIM_BROKEN_EXIT
    console = capsys.readouterr().out
    assert console.count(BANNER) == 1 and "scenario lane/nominal/none" in console
    # the console explains its columns with compare.md's legend, the one source
    from wmr_mj.report.compare import legend_lines

    assert all(line in console for line in legend_lines())
    result = json.loads((out_dir / "compare.json").read_text())
    tight, unmet = result["rows"]
    assert result["claims_broken"] == [f"{LAW},claim_scale=1e-6"]
    assert tight["claim_broken"]["scenario"] == "lane/nominal/none" and tight["claim_broken"]["count"] == 1
    assert tight["claim_broken"]["E_max"] == pytest.approx(1e-6 * E_CLAIM, rel=1e-12)
    assert unmet["claim_broken"] is None
    assert {"name": "deliberately unmet", "value": 2.0, "limit": 1.0, "runs": 1} in unmet["unmet"]
    for name in ("compare.md", "compare.csv", "compare.html"):
        assert "deliberately unmet (2 vs 1)" in (out_dir / name).read_text(), name
    assert "deliberately unmet (2 vs 1) in 1/1" in console


def test_compare_counts_a_claim_broken_by_the_adversary_beside_the_scenarios():
    from wmr_mj.experiments.compare import _claim_broken

    scenario = SimpleNamespace(verdict="certified-outside", scenario="lane/nominal/none",
                               summary={"m1": 650.0, "sup_E": 2.0, "certificate": {"E_max": 1.0, "E_ratio": 2.0}})
    adversary = SimpleNamespace(claim_broken={"phase": "search", "run": 3, "params": {"m1": 700.0}, "sup_E": 3.0,
                                              "E_max": 1.0, "ratio": 3.0, "count": 5})
    broken = _claim_broken([scenario], adversary)
    assert broken["count"] == 6 and broken["where"] == "adversary search run 3" and broken["ratio"] == 3.0
    assert _claim_broken([scenario], None)["scenario"] == "lane/nominal/none"
    assert _claim_broken([], SimpleNamespace(claim_broken=None)) is None


def test_unmet_assumptions_are_counted_once_each_with_the_first_runs_value():
    cert = {"assumptions": [{"name": "a", "met": True, "value": 1.0, "limit": 2.0},
                            {"name": "b", "met": False, "value": 3.0, "limit": 2.0}]}
    later = {"assumptions": [{"name": "b", "met": False, "value": 4.0, "limit": 2.0}]}
    assert unmet_assumptions(cert) == [{"name": "b", "value": 3.0, "limit": 2.0}]
    assert unmet_assumptions(None) == [] and unmet_assumptions({"E_max": 1.0}) == []
    counted = count_unmet([unmet_assumptions(cert), unmet_assumptions(later), []])
    # the first run's value, and the range over the runs (issue 36: an aggregate never quotes one run's alone)
    assert counted == [{"name": "b", "value": 3.0, "limit": 2.0, "runs": 2, "value_range": [3.0, 4.0]}]
    assert format_unmet(counted) == "b (3-4 vs 2)" and format_unmet([{"name": "c", "value": None}]) == "c (n/a vs n/a)"
    assert format_unmet(unmet_assumptions(cert)) == "b (3 vs 2)"  # one run's: its value
