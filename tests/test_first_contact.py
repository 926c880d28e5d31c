"""A new user's slips: the paper's region under names that say so, the replay line and plot that show both
regions, panels in reading order."""

from __future__ import annotations

import json

import pytest

from wmr_mj.cli.app import main
from wmr_mj.experiments.sweep import SWEEP_KEYS_DEPRECATED
from wmr_mj.sim.summary import PAPER_KEYS_DEPRECATED


@pytest.fixture(scope="module")
def logged(tmp_path_factory):
    """A certified run's log and its --json summary (10 s: the paper circle's entry ends at 8.1 s)."""
    folder = tmp_path_factory.mktemp("log")
    log = folder / "run.mcap"
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["run", "--preset", "certified", "--duration", "10", "--out", str(log), "--json"]) == 0
    return log, json.loads(out.getvalue())


def test_the_run_summary_names_the_paper_region_as_the_papers(logged):
    _, report = logged
    for old, new in PAPER_KEYS_DEPRECATED.items():
        assert report[new] == report[old], new  # the same number, its name says whose region it is
    assert report["deprecated_keys"] == PAPER_KEYS_DEPRECATED
    # the verdict is the certificate's, and the paper's region disagrees with it here: the names must tell them apart
    assert report["verdict"] == "certified-inside" and report["paper_inside"] is False


def test_the_replay_line_shows_the_paper_keys_by_their_names(logged, capsys):
    log, _ = logged
    assert main(["replay", str(log)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("summary"))
    assert "paper_E_max=" in line and "paper_inside=False" in line and "verdict=certified-inside" in line
    for old in PAPER_KEYS_DEPRECATED:
        assert f"  {old}=" not in line, old


def test_the_replay_plot_draws_both_regions_with_panels_in_reading_order(logged):
    from wmr_mj.logs.reader import load_log
    from wmr_mj.logs.replay import replay_figure, summarize

    log = load_log(logged[0])
    fig = replay_figure(log, summarize(log))
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    rows = sorted((round(ax.get_position().y0, 2) * -1, ax.get_position().x0, ax.get_title()) for ax in fig.axes
                   if ax.get_title())
    assert [t[:3] for _, _, t in rows] == ["(a)", "(b)", "(c)", "(d)", "(e)", "(f)"], titles
    plane = next(ax for ax in fig.axes if ax.get_title().startswith("(e)"))
    labels = plane.get_legend_handles_labels()[1]
    assert any(lb.startswith("certificate's region") and "certified-inside" in lb for lb in labels), labels
    assert any(lb.startswith("paper's claim") for lb in labels), labels


@pytest.mark.slow
def test_the_sweep_summary_names_the_paper_region_as_the_papers(tmp_path, capsys):
    assert main(["sweep", "--preset", "certified", "--n", "2", "--duration", "10", "--out", str(tmp_path / "s"),
                 "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    for old, new in SWEEP_KEYS_DEPRECATED.items():  # the paper's aliases: under ``paper``, never at the top
        assert summary["paper"][old] == summary[new] and old not in summary, new
    assert "deprecated_keys" not in summary
