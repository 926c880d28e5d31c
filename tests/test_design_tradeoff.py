"""examples/design_tradeoff.py in quick mode: the figure's data, checked for what must hold.

Monotone trends in bits or delay are physics, not a given, and are not asserted. What must hold: no run of the
worst-found searches is certified-outside (so the worst found never exceeds a certified E_max), the design is
certified wherever the preset is and its E_max is at most the preset's (the search scores the preset's point
first), and the preset's E_max is the certificate a run computes for that cart.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import example_module

import wmr_mj as wm
from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE
from wmr_mj.sim.parts import resolve_run

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "examples" / "design_tradeoff.py"


def _module():
    return example_module("design_tradeoff")


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("tradeoff") / "t"
    proc = subprocess.run([sys.executable, str(SCRIPT), "--quick", "--out", str(out)], capture_output=True,
                          text=True, cwd=ROOT, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return out, json.loads(out.with_suffix(".json").read_text())


def test_the_figure_and_its_numbers_are_written(quick):
    out, data = quick
    assert out.with_suffix(".png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert data["settings"] == {"duration": 10.0, "design_budget": 12, "falsify_budget": 5, "path": "paper-circle",
                                "box": "m1 550-750 kg", "seed": 0}
    assert [(p["axis"], p["value"]) for p in data["points"]] == [("bits", 10), ("bits", 14), ("delay", 0.0),
                                                                 ("delay", 0.02)]


def test_no_certified_outside_and_the_worst_found_within_E_max(quick):
    _, data = quick
    checked = 0
    for p in data["points"]:
        for who in ("preset", "design"):
            c = p[who]
            if not c["certified"]:
                assert c["E_max"] is None and c["worst_sup_E"] is None and c["binding"]
                continue
            checked += 1
            assert CERTIFIED_OUTSIDE not in c["verdicts"]
            assert sum(c["verdicts"].values()) == 10  # falsify budget 5: 5 searched, 5 random
            assert 0.0 < c["worst_sup_E"] <= c["E_max"]
            assert c["E_max_falsify"] == c["E_max"]  # the searched runs' certificate is the point's
    assert checked >= 4


def test_the_design_is_never_worse_than_the_preset(quick):
    _, data = quick
    for p in data["points"]:
        pre, des = p["preset"], p["design"]
        if pre["certified"]:
            assert des["certified"] and des["E_max"] <= pre["E_max"]


def test_the_preset_column_is_the_run_certificate(quick):
    _, data = quick
    module = _module()
    p = next(p for p in data["points"] if p["axis"] == "delay" and p["value"] == 0.02)
    config = wm.RunConfig(**wm.CERTIFIED.config_changes(), duration=10.0, path="paper-circle",
                          sensing=module.sensing_of("delay", 0.02))
    assert p["preset"]["E_max"] == resolve_run(config).claim.E_max
    assert module.sensing_of("bits", 12) == ("encoder_ticks=4096,encoder_side=axis,encoder_rounding=round,"
                                             "velocity=difference")
