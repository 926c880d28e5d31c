"""examples/attack_table.py: falsify on every cart of the tightness table, random sampling beside, in quick mode.

The truth: each row's E_max is the certificate a run computes (``resolve_run(...).claim``), the worst found is a
run reproduced by ``run_closed_loop`` at its m1, the verdict counts add up to the runs, and a row already on disk
is read back, not run again.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import wmr_mj as wm
from wmr_mj.sim.parts import resolve_run

pytestmark = pytest.mark.slow  # falsify's runs in a subprocess: about 20 s

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "examples" / "attack_table.py"
DURATION_S = 10.0  # the paper circle's shortest run (lead-in and entry 8.09 s) rounded up: cheap
BUDGET = 5  # falsify's smallest budget on a 1-D box (one CMA-ES population)
ARGV = ["--budget", str(BUDGET), "--duration", str(DURATION_S), "--paths", "paper-circle", "--cart", "ideal",
        "--cart", "Gaussian noise 0.5 mrad", "--random-seeds", "1"]


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("attack")
    proc = subprocess.run([sys.executable, str(SCRIPT), *ARGV, "--out", str(out)], capture_output=True, text=True,
                          cwd=ROOT, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return out, proc.stdout


def _rows(out: Path) -> dict[tuple[str, int], dict]:
    rows = [json.loads(f.read_text()) for f in sorted(out.glob("*.json"))]
    return {(r["cart"], r["seed"]): r for r in rows}


def test_each_cart_at_each_seed_has_a_row_and_the_uncovered_cart_none(quick):
    out, stdout = quick
    rows = _rows(out)
    assert set(rows) == {("ideal", 0), ("ideal", 1), ("Gaussian noise 0.5 mrad", 0), ("Gaussian noise 0.5 mrad", 1)}
    gaussian = wm.RunConfig(**wm.CERTIFIED.config_changes(), duration=DURATION_S, path="paper-circle",
                            sensing="noise=gaussian:0.0005,seed=1")
    unmet = resolve_run(gaussian).claim.unmet
    assert unmet and rows[("Gaussian noise 0.5 mrad", 0)]["uncovered"] == ", ".join(unmet)
    assert "search" not in rows[("Gaussian noise 0.5 mrad", 0)]
    assert (out / "table.md").read_text().count("| ideal | certified preset | paper-circle |") == 2
    assert "not covered: Gaussian noise 0.5 mrad on paper-circle" in stdout


def test_the_numbers_are_the_runs_and_the_certificate(quick):
    out, _ = quick
    rows = _rows(out)
    first, second = rows[("ideal", 0)], rows[("ideal", 1)]
    config = wm.RunConfig(**wm.CERTIFIED.config_changes(), duration=DURATION_S, path="paper-circle")
    claim = resolve_run(config).claim
    assert first["E_max"] == second["E_max"] == claim.E_max and first["certificate"] == "sampled-data"
    search = first["search"]
    assert sum(search["verdicts"].values()) == search["runs"] >= BUDGET
    assert sum(first["random"]["verdicts"].values()) == first["random"]["runs"] == search["runs"]
    assert "search" not in second and sum(second["random"]["verdicts"].values()) == second["random"]["runs"] == BUDGET
    assert "certified-outside" not in {**search["verdicts"], **first["random"]["verdicts"]}
    assert first["worst_sup_E"] == max(search["worst_sup_E"], first["random"]["worst_sup_E"])
    assert first["tightness"] == first["worst_sup_E"] / first["E_max"]
    rerun = wm.run_closed_loop(config.replace(**search["worst_params"]), progress=False).summary
    assert rerun.sup_E == search["worst_sup_E"]  # the worst found is a run, to the bit
    assert first["binding"] == "friction_term" and search["worst_binding_term"][0] == "friction_term"


def test_a_row_on_disk_is_read_back_not_run_again(quick):
    out, _ = quick
    before = {f.name: f.stat().st_mtime_ns for f in out.glob("*.json")}
    proc = subprocess.run([sys.executable, str(SCRIPT), *ARGV, "--out", str(out)], capture_output=True, text=True,
                          cwd=ROOT, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert {f.name: f.stat().st_mtime_ns for f in out.glob("*.json")} == before
