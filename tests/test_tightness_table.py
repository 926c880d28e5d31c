"""examples/tightness_table.py and wmr_mj.experiments.tightness: the table of covered carts, in quick mode.

The E_max columns are checked against the certificate a run computes (``resolve_run(...).claim`` and
``run_closed_loop``'s summary), the worst found against a run at its m1 (falsify's runs are reproduced bit for
bit by ``run_closed_loop``), and the printed tightness against worst / E_max of the same numbers.
"""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import example_module

import wmr_mj as wm
from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE
from wmr_mj.experiments.tightness import certificate_columns
from wmr_mj.sim.parts import resolve_run

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "examples" / "tightness_table.py"
DURATION_S = 10.0  # the paper circle's shortest run (lead-in and entry 8.09 s) rounded up: cheap
BUDGET = 5  # falsify's smallest budget on a 1-D box (one CMA-ES population): 10 runs per cart and path
CARTS = ("ideal", "sensing delay 20 ms", "12-bit axis encoder, differenced")


def _module():
    return example_module("tightness_table")


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("tightness") / "table.json"
    argv = ["--budget", str(BUDGET), "--duration", str(DURATION_S), "--paths", "paper-circle,lane-change",
            "--json", str(out)]
    for cart in CARTS + ("Gaussian noise 0.5 mrad",):
        argv += ["--cart", cart]
    proc = subprocess.run([sys.executable, str(SCRIPT), *argv], capture_output=True, text=True, cwd=ROOT,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout, json.loads(out.read_text())


def _config(row):
    base = wm.RunConfig(**wm.CERTIFIED.config_changes(), duration=DURATION_S)
    changes = dict(next(c for name, c in _module().CASES if name == row["cart"]))
    return base.replace(**changes, path=row["path"])


def test_the_columns_and_one_row_per_covered_cart_and_path(quick):
    stdout, data = quick
    lines = stdout.splitlines()
    header = lines[0]
    for column in ("cart", "path", "E_max today (section 4)", "E_max sampled-data", "E_max taken",
                   "worst sup\\|E\\| found", "tightness", "old (error term)", "verdicts"):
        assert column in header
    rows = [line for line in lines[2:] if line.startswith("| ")]
    assert len(rows) == len(data["rows"]) == len(CARTS) * 2
    assert all(r.count(" | ") == header.count(" | ") for r in rows)
    # Gaussian noise has no bound: no claim covers it, and it is listed as such, never as a row
    assert [u[0] for u in data["uncovered"]] == ["Gaussian noise 0.5 mrad"] * 2
    assert "not covered: Gaussian noise 0.5 mrad on paper-circle" in stdout


def test_tightness_is_worst_over_E_max_of_the_same_numbers(quick):
    stdout, data = quick
    rows = [line for line in stdout.splitlines()[2:] if line.startswith("| ")]
    for printed, row in zip(rows, data["rows"]):
        assert row["tightness"] == row["worst_sup_E"] / row["E_max"]
        cells = [c.strip() for c in printed.strip("|").split("|")]
        assert cells[6] == f"{row['worst_sup_E'] / row['E_max']:.2f}"
        assert cells[5].startswith(f"{row['worst_sup_E']:.5f}")
        assert row["worst_sup_E"] == max(row["search_sup_E"], row["random_sup_E"])


def test_E_max_columns_are_what_a_run_computes(quick):
    _, data = quick
    for row in data["rows"]:
        config = _config(row)
        claim = resolve_run(config).claim
        assert row["E_max"] == claim.E_max  # the certificate run takes, to the bit
        assert row["certificate"] == claim.inputs.get("certificate", "section-4")
        both = claim.inputs["certificates"]  # every cart, the ideal one included (issue 44 item 1)
        assert row["E_max_section4"] == both["section-4"]["E_max"]
        assert row["E_max_sampled"] == both["sampled-data"]["E_max"] == row["E_max"]  # the sampled one is taken
        assert row["certificate"] == "sampled-data"


def test_the_worst_found_is_a_run_and_no_run_is_certified_outside(quick):
    _, data = quick
    row = next(r for r in data["rows"] if r["cart"] == "sensing delay 20 ms" and r["path"] == "paper-circle")
    summary = wm.run_closed_loop(_config(row).replace(m1=row["worst_params"]["m1"]), progress=False).summary
    assert summary.sup_E == row["worst_sup_E"]
    assert summary.certificate.to_dict()["E_max"] == row["E_max"]
    for r in data["rows"]:
        assert sum(r["verdicts"].values()) == r["runs"] == 2 * BUDGET
        assert CERTIFIED_OUTSIDE not in r["verdicts"]
        assert r["old_tightness"] == (0.076 if "delay" in r["cart"] else 0.071 if "encoder" in r["cart"] else None)


def test_certificate_columns_without_a_claim_or_a_sampled_certificate():
    assert certificate_columns(None) == {"certificate": "", "certified": False, "E_max": None,
                                         "E_max_section4": None, "E_max_sampled": None}
    ideal = resolve_run(wm.RunConfig(**wm.CERTIFIED.config_changes(), duration=DURATION_S)).claim
    cols = certificate_columns(ideal)  # the ideal cart: the sampled-data certificate taken, section 4's beside it
    assert cols["E_max"] == cols["E_max_sampled"] == ideal.E_max and cols["certificate"] == "sampled-data"
    assert cols["E_max_section4"] == ideal.inputs["certificates"]["section-4"]["E_max"] < cols["E_max"]
    assert math.isfinite(cols["E_max"]) and cols["certified"]
    # a law's own claim alone (no sampled-data record: a what-if measurement) is taken as section 4's
    alone = dataclasses.replace(ideal, inputs=ideal.inputs.with_record({"certificate": "section-4",
                                                                        "certificates": None}))
    cols = certificate_columns(alone)
    assert cols["E_max"] == cols["E_max_section4"] == ideal.E_max and cols["E_max_sampled"] is None


def test_an_unknown_cart_is_refused_in_one_line():
    proc = subprocess.run([sys.executable, str(SCRIPT), "--cart", "no such cart"], capture_output=True,
                          text=True, cwd=ROOT, timeout=120)
    assert proc.returncode == 2 and proc.stdout == ""
    errors = [line for line in proc.stderr.splitlines() if "error:" in line]
    assert len(errors) == 1 and "'no such cart'" in errors[0] and "ideal" in errors[0]


def test_certificate_columns_of_sliding_mode_read_its_own_claim_beside_the_sampled_one():
    """Sliding mode's own claim is recorded as 'boundary-layer' (not 'section-4'): its column is that claim's E_max,
    not the one taken, where the two differ (λ 20, φ 6, k 24 on the 12-bit cart, as tests/test_sliding_sampled.py)."""
    config = wm.RunConfig(controller="sliding-mode", controller_params={"lam": 20.0, "phi": 6.0, "k": 24.0},
                          sensing=wm.Sensing.from_spec("magnetic-12bit-axis"), duration=10.0)
    cert = resolve_run(config).claim
    both = cert.inputs["certificates"]
    columns = certificate_columns(cert)
    assert columns["certificate"] == cert.inputs["certificate"] == "sampled-data"
    assert columns["E_max_section4"] == both["boundary-layer"]["E_max"] != columns["E_max"]
    assert columns["E_max_sampled"] == both["sampled-data"]["E_max"] == columns["E_max"]
