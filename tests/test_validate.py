"""wmr-mj validate: the report folder, its numbers recomputed from the per-run CSVs, bad input."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg  # noqa: E402
import pytest  # noqa: E402

from wmr_mj import C80  # noqa: E402
from wmr_mj.report import SOURCES, check_assumptions, summarise_runs  # noqa: E402
from wmr_mj.robustness import ParameterBox  # noqa: E402

N = 3


def _cli(*args: str, timeout: float = 240) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "wmr_mj.cli", *args], capture_output=True, text=True,
                          timeout=timeout, env={**os.environ, "MPLBACKEND": "Agg"})


@pytest.fixture(scope="module")
def validated(tmp_path_factory):
    folder = tmp_path_factory.mktemp("validate") / "report"
    proc = _cli("validate", "--n", str(N), "--duration", "10", "--identify-duration", "10", "--seed", "3",
                "--out", str(folder), "--json")
    assert proc.returncode == 0, proc.stderr
    return folder, json.loads(proc.stdout), proc.stderr


def _runs(folder: Path, src: str) -> list[dict[str, str]]:
    with open(folder / f"sweep-{src}" / "runs.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_validate_writes_the_report_folder(validated):
    folder, out, err = validated
    for name in ("index.md", "index.html", "summary.json", "summary.csv", "identified.json"):
        assert (folder / name).is_file() and (folder / name).stat().st_size > 100, name
    stems = [f"region_{s}" for s in SOURCES] + [f"history_{s}" for s in SOURCES] + [
        "fig4_trajectory", "fig5_alpha0", "fig6_alpha0_rates", "fig7_region"]
    for stem in stems:
        png, svg = folder / "figures" / f"{stem}.png", folder / "figures" / f"{stem}.svg"
        assert mpimg.imread(png).ndim == 3
        assert ET.parse(svg).getroot().tag.endswith("svg")
    for src in SOURCES:
        assert len(_runs(folder, src)) == N
    md = (folder / "index.md").read_text()
    html = (folder / "index.html").read_text()
    for stem in stems:
        assert f"figures/{stem}.png" in md and f"figures/{stem}.png" in html
    assert html.lstrip().startswith("<!DOCTYPE html>") and html.rstrip().endswith("</html>")
    # the pointer beside the folder
    assert Path((folder.parent / "validate-latest").read_text().strip()) == folder.resolve()
    # one stage line per stage on stderr (not a terminal: no counter), then the total
    lines = err.strip().splitlines()
    assert all(line.startswith("validate: ") for line in lines)
    assert sum("sweep" in line for line in lines) == len(SOURCES)
    assert "total wall time" in lines[-1]


def test_json_summary_matches_summary_json(validated):
    folder, out, _ = validated
    saved = json.loads((folder / "summary.json").read_text())
    assert Path(out["folder"]) == folder
    assert set(out["identification"]) >= {"P", "C_V", "F", "K", "gyro", "identified", "predicted"}
    for src in SOURCES:
        got = out["sources"][src]
        for key in ("inside", "n", "worst_E_ratio", "worst_Edot_ratio", "assumptions_met", "condition"):
            assert key in got
            assert got[key] == saved["sources"][src][key]
    assert saved["versions"]["mujoco"] and saved["settings"]["n"] == N and saved["seed"] == 3


def test_summary_numbers_recomputed_from_runs_csv(validated):
    folder, _, _ = validated
    saved = json.loads((folder / "summary.json").read_text())
    with open(folder / "summary.csv", newline="") as f:
        table = {row["source"]: row for row in csv.DictReader(f)}
    for src in SOURCES:
        rows = _runs(folder, src)
        inside = sum(r["inside"] == "True" for r in rows)
        ratios_E = [float(r["E_ratio"]) for r in rows if r["E_ratio"] != ""]
        ratios_Ed = [float(r["Edot_ratio"]) for r in rows if r["Edot_ratio"] != ""]
        stop = sum(r["left_steering_range"] == "True" for r in rows) / len(rows)
        sat = sum(float(r["saturated_fraction"]) for r in rows) / len(rows)
        v = saved["sources"][src]
        assert v["n"] == len(rows) == N
        assert v["inside"] == inside
        assert v["worst_E_ratio"] == (max(ratios_E) if ratios_E else None)
        assert v["worst_Edot_ratio"] == (max(ratios_Ed) if ratios_Ed else None)
        assert v["stop_fraction"] == pytest.approx(stop, abs=1e-15)
        assert v["mean_saturated_fraction"] == pytest.approx(sat, rel=1e-12, abs=1e-15)
        assert v["worst_sup_E"] == max(float(r["sup_E"]) for r in rows)
        # the runs' own ratios agree with their sup and bound
        for r in rows:
            if r["E_ratio"]:
                assert float(r["E_ratio"]) == pytest.approx(float(r["sup_E"]) / float(r["E_max"]), rel=1e-12)
        assert int(table[src]["inside"]) == inside and int(table[src]["n"]) == N


def test_assumptions_met_follows_the_identified_plant_and_the_box(validated):
    folder, _, _ = validated
    saved = json.loads((folder / "summary.json").read_text())
    ident = json.loads((folder / "identified.json").read_text())["identified"]
    for src in SOURCES:
        box = ParameterBox.from_parameters(C80, m1_range=(550.0, 750.0),
                                           model="paper" if src == "paper" else "nonholonomic")
        inside = {k: getattr(box, k)[0] <= ident[k] <= getattr(box, k)[1] for k in ("P", "C_V", "F", "K")}
        assert saved["sources"][src]["assumptions_met"] is all(inside.values())
        if src == "paper":
            lo, hi = box.K
            assert not (lo <= ident["K"] <= hi), "the plant's K lies in the paper box: the premise changed"
            assert saved["sources"][src]["assumptions_met"] is False
            assert "K" in saved["sources"][src]["assumptions"]["outside"]


def test_check_assumptions_and_summarise_runs_units():
    box = ParameterBox.paper()
    ok = check_assumptions({"P": 0.38, "C_V": 4.77, "F": 1.51, "K": 5.3}, box)
    assert ok["met"] and ok["outside"] == []
    bad = check_assumptions({"P": 0.38, "C_V": 4.77, "F": 1.51, "K": 0.0}, box, {"K": 0.01})
    assert not bad["met"] and bad["outside"] == ["K"]
    assert bad["coefficients"]["K"]["outside_by"] == pytest.approx(-5.29)
    assert bad["coefficients"]["K"]["outside_by_se"] == pytest.approx(-529.0)
    rows = [dict(m1=600.0, sup_E=0.1, sup_Edot=0.2, sup_E_settled=0.05, sup_Edot_settled=0.05, E_max=0.2,
                 Edot_max=0.1, E_ratio=0.5, Edot_ratio=2.0, inside=False, saturated_fraction=0.1,
                 left_steering_range=True),
            dict(m1=700.0, sup_E=0.1, sup_Edot=0.05, sup_E_settled=0.05, sup_Edot_settled=0.05, E_max=0.2,
                 Edot_max=0.1, E_ratio=0.5, Edot_ratio=0.5, inside=True, saturated_fraction=0.0,
                 left_steering_range=False)]
    s = summarise_runs(rows)
    assert (s["n"], s["inside"], s["inside_settled"]) == (2, 1, 2)
    assert (s["worst_E_ratio"], s["worst_Edot_ratio"], s["stop_fraction"]) == (0.5, 2.0, 0.5)
    assert s["mean_saturated_fraction"] == pytest.approx(0.05)
    for r in rows:
        r["E_ratio"] = r["Edot_ratio"] = None
    assert summarise_runs(rows)["worst_E_ratio"] is None


@pytest.mark.parametrize("args", [("--n", "0"), ("--duration", "0"), ("--duration", "-3"), ("--sampling", "sobol"),
                                  ("--identify-duration", "nan"), ("--nthread", "-1")])
def test_bad_input_exits_2_with_one_line(args, tmp_path):
    proc = _cli("validate", *args, "--out", str(tmp_path / "x"), timeout=60)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr and "error" in lines[0]
    assert not (tmp_path / "x").exists()
