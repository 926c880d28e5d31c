"""wmr_mj._util.progress (tqdm): silent off a terminal, counts right on one; the sweep command's outputs."""

from __future__ import annotations

import csv
import io
import json

import pytest

from wmr_mj._util.progress import Stages, counter_callback, progress_bar
from wmr_mj.cli.app import main


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_bar_is_silent_off_a_terminal_and_draws_on_one():
    off = io.StringIO()
    with progress_bar(100, desc="run", stream=off) as bar:
        bar.update(50)
    assert off.getvalue() == ""
    on = _Terminal()
    with progress_bar(100, desc="run", unit="step", stream=on, mininterval=0) as bar:
        bar.update(50)
        assert "50/100" in on.getvalue() and "run" in on.getvalue()


def test_counter_callback_counts_resumed_runs_as_initial():
    out = _Terminal()
    with progress_bar(10, desc="sweep", unit="runs", fractional=True, stream=out, mininterval=0) as bar:
        progress = counter_callback(bar)
        progress(4, 10)  # found in runs.csv
        assert (bar.initial, bar.n) == (4, 4)
        progress(5.5, 10)  # fractional while a chunk steps
        assert bar.n == 5.5 and "5.5/10" in out.getvalue()
        progress(10, 10)
        assert bar.n == 10 and bar.format_dict["initial"] == 4  # the rate counts the 6 runs done now


def test_stages_write_one_line_per_stage_off_a_terminal():
    out = io.StringIO()
    st = Stages("validate", stream=out)
    st.start("a", "first stage")
    st.update(3, 10)
    st.done("fine")
    st.start("b", "second")
    st.done()
    lines = out.getvalue().splitlines()
    assert len(lines) == 2 and "\r" not in out.getvalue()
    assert lines[0].startswith("validate: first stage ... ") and lines[0].endswith(" s: fine")
    assert lines[1].startswith("validate: second ... ") and lines[1].endswith(" s")
    assert set(st.timings) == {"a", "b"} and all(t >= 0 for t in st.timings.values())


def test_stages_show_a_live_count_on_a_terminal():
    out = _Terminal()
    st = Stages("validate", stream=out)
    st.start("sweep", "sweep paper")
    st.update(2.5, 8)
    st.done("8/8 inside")
    text = out.getvalue()
    assert "2.5/8 runs" in text and "\r" in text
    assert "\rvalidate: sweep paper ... " in text and text.endswith(" s: 8/8 inside\n")  # bar erased, then the line


@pytest.mark.slow
def test_sweep_command_writes_table_summary_and_plot(tmp_path, capsys):
    out = tmp_path / "sweep"
    code = main(["sweep", "--n", "2", "--duration", "10", "--chunk", "2", "--nthread", "1", "--out", str(out),
                 "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert captured.err == ""  # no progress bar off a terminal
    summary = json.loads(captured.out)
    assert summary["plot"] == str(out / "region.png")
    assert (out / "region.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = list(csv.DictReader((out / "runs.csv").open()))
    assert len(rows) == summary["n"] == 2
    inside = sum(float(r["sup_E"]) <= float(r["E_max"]) and float(r["sup_Edot"]) <= float(r["Edot_max"]) for r in rows)
    assert summary["paper_inside"] == inside and summary["paper_outside"] == 2 - inside
    assert json.loads((out / "summary.json").read_text())["n"] == 2
