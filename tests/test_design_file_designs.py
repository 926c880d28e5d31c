"""A design file (``wmr-mj design --out FILE.json``) named as a design: in ``compare`` and in ``validate --design``.

The truth is ``wmr-mj run --design FILE`` itself: compare's run of the file on a scenario must give the numbers of
``run --design FILE`` on the same path, m1, box and duration, to the last bit; the file's cart must be the row's;
a bad file gets one line naming it and exit status 2 from both commands.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers import refused_line

from wmr_mj.cli.app import main

CART = "magnetic-12bit-axis"
DURATION = 10.0  # s: C reaches the paper circle (its entry takes 8.09 s); each run a fraction of a second
M1 = 720.0  # kg: inside the box, not its nominal (so the scenario's m1 must reach the run)

SUITE = f"""
[suite]
name = "design-file-test"
version = 1
duration = {DURATION}
reference_bounds = "paper"
d_max = 1.0

[plants.heavy]
m1 = {M1}

[signals.none]

[requirements]
settled-error = "always(abs(E) <= 0.05)"

[adversary]
requirement = "settled-error"
path = "paper-circle"
uncertainty = "full"
path_knots = 2
hold_range = [0.0, 3.0]
disturbance = {{ kind = "pulse", t1 = [2.0, 6.0], amplitude = [-1.0, 1.0], width = 1.0 }}

[[scenario]]
id = "circle/heavy/none"
path = "paper-circle"
plant = "heavy"
signals = "none"
"""


@pytest.fixture(scope="module")
def design_file(tmp_path_factory) -> Path:
    """A design for the 12-bit axis encoder, found with a small budget (its quality is not what is tested)."""
    from wmr_mj.searches.design_search import DesignProblem, search_design, write_design
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED

    out = tmp_path_factory.mktemp("design") / "design.json"
    base = RunConfig(**CERTIFIED.config_changes(), sensing=CART, duration=DURATION)
    write_design(search_design(DesignProblem(base=base, budget=20, seed=1)), out)
    return out


def _json(capsys, argv: list[str]) -> dict:
    capsys.readouterr()
    assert main(argv) in (0, 3), argv
    return json.loads(capsys.readouterr().out)


@pytest.mark.slow
def test_compares_row_of_a_design_file_is_run_design_file(design_file, tmp_path, capsys):
    suite = tmp_path / "suite.toml"
    suite.write_text(SUITE)
    out = tmp_path / "compare"
    report = _json(capsys, ["compare", "certified", str(design_file), "--suite", str(suite), "--budget", "0",
                            "--nthread", "1", "--out", str(out), "--json"])
    row = report["rows"][1]
    assert row["label"] == str(design_file) and row["runs"] == 1
    settings = json.loads(design_file.read_text())["settings"]
    assert row["cart"]["sensing"] == settings["sensing"]  # the file's cart, not the ideal one
    runs = [json.loads(line) for line in Path(report["files"]["runs"]).read_text().splitlines()]
    mine = next(r["summary"] for r in runs if r["design"] == str(design_file))

    single = _json(capsys, ["run", "--design", str(design_file), "--path", "paper-circle", "--m1", str(M1),
                            "--duration", str(DURATION), "--uncertainty", "full", "--reference-bounds", "paper",
                            "--no-log", "--json"])
    assert single["kp"] == settings["kp"] and single["m1"] == M1
    for key in ("sup_E", "sup_Edot", "verdict", "m1", "steps"):
        assert mine[key] == single[key], key  # bit for bit: JSON keeps every digit of a float
    for key in ("E_max", "Edot_max", "valid", "certified"):
        assert mine["certificate"][key] == single["certificate"][key], key
    counts = {"certified-inside": row["certified_inside"], "certified-outside": row["certified_outside"]}
    assert counts.get(single["verdict"], 0) == 1 or single["verdict"].startswith("uncertified")


def test_validate_judges_a_design_file_on_its_own_cart(design_file):
    """``validate --design FILE`` builds the file's law and cart (its gains kept as found), as ``run --design``."""
    from wmr_mj.experiments.compare import FileDesign, design_file_changes
    from wmr_mj.report.settings import ValidateSettings

    settings = ValidateSettings(n=1, duration=DURATION, search_budget=0, designs=(str(design_file),))
    config = settings.config(FileDesign(str(design_file)))
    written = json.loads(design_file.read_text())["settings"]
    assert (config.kp, config.kd, config.friction_width) == (written["kp"], written["kd"], written["friction_width"])
    assert config.sensing.to_dict() == written["sensing"] and config.duration == DURATION
    # validate's own --sensing replaces the file's: the option given wins, as for run --design FILE --sensing
    other = ValidateSettings(n=1, duration=DURATION, search_budget=0, sensing="magnetic-14bit-axis")
    assert other.config(FileDesign(str(design_file))).sensing.encoder_ticks == 16384
    assert design_file_changes(str(design_file))["sensing"].encoder_ticks == 4096


def test_a_design_file_is_told_by_its_suffix_only():
    from wmr_mj.experiments.compare import is_design_file

    assert is_design_file("design.json") and is_design_file("logs/d.JSON")
    for token in ("certified", "sliding-mode,k=5", "my_law.py:MyLaw", "pkg.mod:Law", "design"):
        assert not is_design_file(token), token


@pytest.fixture
def bad_files(tmp_path: Path, design_file: Path) -> dict[str, tuple[Path, str]]:
    """Each bad file and a word its refusal must name."""
    not_json = tmp_path / "garbled.json"
    not_json.write_text("{not json")
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"format": "something else", "settings": {}}))
    bad_sensing = tmp_path / "bad-sensing.json"
    data = json.loads(design_file.read_text())
    data["settings"]["sensing"] = {**data["settings"]["sensing"], "encoder_ticks": -3}
    bad_sensing.write_text(json.dumps(data))
    return {"missing": (tmp_path / "missing.json", "cannot be read"), "garbled": (not_json, "cannot be read"),
            "other": (other, "not a design file"), "bad-sensing": (bad_sensing, "encoder_ticks")}


@pytest.mark.parametrize("case", ["missing", "garbled", "other", "bad-sensing"])
def test_a_bad_design_file_is_one_line_exit_2(case, bad_files, tmp_path, capsys):
    path, word = bad_files[case]
    for argv in (["compare", str(path), "--budget", "0", "--out", str(tmp_path / "c")],
                 ["validate", "--design", str(path), "--n", "1", "--out", str(tmp_path / "v")]):
        line = refused_line(capsys, argv)
        assert str(path.name) in line and word in line, line
    assert not (tmp_path / "c").exists() and not (tmp_path / "v").exists()


def test_a_design_file_takes_no_settings(design_file, capsys, tmp_path):
    line = refused_line(capsys, ["compare", f"{design_file},kp=3", "--budget", "0", "--out", str(tmp_path / "c")])
    assert "takes no ,key=value settings" in line
