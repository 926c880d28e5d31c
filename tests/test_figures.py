"""wmr-mj figures and wmr_mj.figures.plots: the paper's Figs. 4-7 as PNG + SVG, headless."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections import Counter

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from wmr_mj.analysis.robustness import ParameterBox, analyse  # noqa: E402
from wmr_mj.cli.app import main  # noqa: E402
from wmr_mj.figures.plots import (  # noqa: E402
    PAPER_FIGURE_NAMES,
    REGION_GID,
    Series,
    figure_region,
    new_figure,
    paper_figures,
    plot_region,
)
from wmr_mj.report.paper_example import paper_example  # noqa: E402

DURATION = "10"  # long enough to reach the paper circle (entry ends at ~8.1 s)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("figs") / "figures"
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["figures", "--out", str(out), "--duration", DURATION])
    return rc, out, buf.getvalue().split()


@pytest.fixture(scope="module")
def example():
    return paper_example(duration=10.0)


def _region_patches(fig):
    return [p for ax in fig.axes for p in ax.patches if p.get_gid() == REGION_GID]


@pytest.mark.slow
def test_figures_command_writes_png_and_svg_of_figs_4_to_7(written):
    rc, out, printed = written
    assert rc == 0
    expected = [out / f"{stem}.{ext}" for stem in PAPER_FIGURE_NAMES for ext in ("png", "svg")]
    assert sorted(printed) == sorted(str(p) for p in expected)
    for path in expected:
        assert path.is_file() and path.stat().st_size > 1000, path
        if path.suffix == ".png":
            img = mpimg.imread(path)
            assert img.ndim == 3 and img.shape[2] in (3, 4) and min(img.shape[:2]) > 200
        else:
            root = ET.parse(path).getroot()
            assert root.tag.endswith("svg")


@pytest.mark.slow
def test_fig7_svg_carries_the_region_polygon(written):
    _, out, _ = written
    root = ET.parse(out / "fig7_region.svg").getroot()
    ids = {el.get("id") for el in root.iter()}
    assert REGION_GID in ids


@pytest.mark.slow
def test_fig7_region_polygon_is_the_analysis_vertices(example):
    expected = analyse(ParameterBox.paper(), kp=6.0, kd=9.0).vertices  # the (5.1) example, independently
    assert len(expected) == 4
    fig = paper_figures(example)["fig7_region"]
    patches = _region_patches(fig)
    assert patches, "no region polygon on Fig. 7"
    for patch in patches:  # one per panel
        xy = patch.get_xy()
        if np.allclose(xy[0], xy[-1]) and len(xy) == len(expected) + 1:
            xy = xy[:-1]
        np.testing.assert_allclose(xy, np.asarray(expected), rtol=0, atol=0)


@pytest.mark.slow
def test_fig7_shows_both_views_and_says_when_the_mujoco_run_leaves_the_range(example):
    fig = paper_figures(example)["fig7_region"]
    labels = [t.get_text() for leg in fig.legends for t in leg.get_texts()]
    assert any(label.startswith("(a) paper's view") for label in labels)
    assert any(label.startswith("(b) MuJoCo plant") for label in labels)
    r = example.result
    sup_E = float(np.max(np.abs(example.mujoco_rows["E"])))
    sup_Ed = float(np.max(np.abs(example.mujoco_rows["E_dot"])))
    if sup_E > 3 * r.E_max or sup_Ed > 3 * r.Edot_max:
        titles = " ".join(ax.get_title() for ax in fig.axes)
        assert "leaves this range" in titles and f"{sup_E:.3g}" in titles
        assert len([ax for ax in fig.axes if ax.patches]) == 2  # region scale + full range
    # the paper's view stays inside its region
    for _, rows in example.reduced:
        assert np.max(np.abs(rows["E"])) <= r.E_max and np.max(np.abs(rows["E_dot"])) <= r.Edot_max


def test_plot_region_points_with_colorbar_and_unbounded_region():
    r = analyse(ParameterBox.paper(), kp=6.0, kd=9.0)
    fig, ax = new_figure()
    arts = plot_region(ax, r, points=[[0.01, 0.02], [0.03, 0.04]], values=[560.0, 740.0],
                       trajectory=([0.0, 0.01], [0.0, 0.02]), label="traj")
    np.testing.assert_array_equal(arts["region"].get_xy()[:4], np.asarray(r.vertices))
    assert arts["colorbar"] is not None and arts["scatter"] is not None and arts["trajectory"] is not None
    # (4.23) failing: no polygon, a note instead
    bad = analyse(ParameterBox(P=(0.1, 0.5), C_V=(1, 9), F=(0, 3), K=(0, 9)), kp=6.0, kd=9.0)
    assert not bad.stable
    fig2 = figure_region(bad, [Series(label="x", E=np.array([0.1, 0.2]), E_dot=np.array([0.1, 0.3]))])
    assert not _region_patches(fig2)
    assert any("(4.23) fails" in t.get_text() for ax in fig2.axes for t in ax.texts)


def test_figures_bad_duration_is_one_line_exit_2(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["figures", "--duration", "0"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0]


# --------------------------------------------------------------------------- the validation's figures
def _legend_labels(fig):
    return [t.get_text() for leg in fig.legends for t in leg.get_texts()] + [
        t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]


def test_verdict_plane_draws_each_region_exactly_and_counts_each_verdict():
    from wmr_mj.figures.plots import CERTIFICATE_GID, DrawnRegion, figure_verdict_plane

    cert = [(0.0, 0.0), (0.04, 0.0), (0.046, 0.34), (0.0, 0.33)]
    paper = [(0.0, 0.0), (0.005, 0.0), (0.005, 0.04), (0.0, 0.04)]
    regions = [DrawnRegion("certificate", cert, gid=CERTIFICATE_GID), DrawnRegion("paper's claim", paper, filled=False,
                                                                        gid=REGION_GID)]
    E, Ed = [0.02, 0.03, 0.05, 0.01], [0.1, 0.1, 0.2, 0.01]
    verdicts = ["certified-inside", "certified-inside", "certified-outside", "uncertified-inside"]
    fig = figure_verdict_plane(E, Ed, verdicts, regions)
    for gid, verts in ((CERTIFICATE_GID, cert), (REGION_GID, paper)):
        patches = [p for ax in fig.axes for p in ax.patches if p.get_gid() == gid]
        assert len(patches) == 1
        np.testing.assert_array_equal(patches[0].get_xy()[:4], np.asarray(verts))
    labels = _legend_labels(fig)
    assert "certified-inside: 2 runs" in labels and "CERTIFIED-OUTSIDE: 1 runs" in labels
    assert "uncertified-inside: 1 runs" in labels and not any(x.startswith("uncertified-outside") for x in labels)


def test_verdict_plane_splits_into_region_scale_and_full_range_when_runs_leave_it():
    from wmr_mj.figures.plots import DrawnRegion, figure_verdict_plane

    region = DrawnRegion("r", [(0.0, 0.0), (0.1, 0.0), (0.1, 0.1), (0.0, 0.1)])
    E = [0.05, 1.5, 0.6]  # two beyond 3x the region
    fig = figure_verdict_plane(E, [0.05, 2.0, 2.3], ["uncertified-outside"] * 3, [region], note="no certificate")
    panels = [ax for ax in fig.axes if ax.patches]
    assert len(panels) == 2
    assert "2 of 3 runs lie beyond it" in panels[0].get_title() and f"{max(E):.3g} rad" in panels[0].get_title()
    assert any(t.get_text() == "no certificate" for t in panels[1].texts)
    one = figure_verdict_plane([0.05], [0.05], ["certified-inside"], [region])  # all near: one panel
    assert len([ax for ax in one.axes if ax.patches]) == 1


def test_ladder_bars_add_up_to_each_rungs_runs():
    from wmr_mj.figures.plots import VERDICT_COLORS, figure_ladder

    counts = [{"uncertified-outside": 5}, {"uncertified-inside": 2, "uncertified-outside": 3},
              {"certified-inside": 5}]
    fig = figure_ladder(["a", "b", "c"], counts, [0, 2, 1])
    ax = fig.axes[0]
    widths = Counter()
    for bar in ax.patches:
        widths[round(bar.get_y() + bar.get_height() / 2)] += bar.get_width()
    assert sorted(widths.values()) == [5, 5, 5]
    labels = _legend_labels(fig)
    assert [x.split(":")[0] for x in labels] == list(VERDICT_COLORS)
    assert "certified-inside: 5" in labels and "uncertified-outside: 8" in labels
    assert any(t.get_text() == "paper's claim: 2/5 inside" for t in ax.texts)


def test_search_history_running_worst_and_reference_lines():
    from wmr_mj.figures.plots import SearchHistory, figure_search_history

    values = [0.3, None, 0.5, 0.4, 0.7, 0.6]
    fig = figure_search_history([SearchHistory("t", "ratio", values, mc_worst=0.65, bound=1.0),
                                 SearchHistory("u", "sup|E|", [0.01, 0.02])])
    ax = fig.axes[0]
    step = next(line for line in ax.get_lines() if line.get_label().startswith("search: worst"))
    expected = np.maximum.accumulate([0.3, -np.inf, 0.5, 0.4, 0.7, 0.6])
    np.testing.assert_array_equal(step.get_ydata(), expected)
    assert step.get_label() == "search: worst 0.7"
    flat = {line.get_label(): line.get_ydata()[0] for line in ax.get_lines() if len(set(line.get_ydata())) == 1}
    assert flat["Monte-Carlo worst: 0.65"] == 0.65 and flat["bound: 1"] == 1.0
    assert len(fig.axes) == 2


@pytest.mark.slow
def test_time_history_draws_the_bounds_it_is_given(example):
    from wmr_mj.figures.plots import figure_time_history

    fig = figure_time_history(example.mujoco_rows, example.mujoco_summary, voltage_limit=24.0,
                              bounds=(0.0463, 0.341), bound_name="certificate")
    a1, a2, _ = fig.axes
    assert {abs(line.get_ydata()[0]) for line in a1.get_lines() if "certificate" in line.get_label()} == {0.0463}
    levels = {abs(y) for line in a2.get_lines() for y in line.get_ydata() if len(set(line.get_ydata())) == 1}
    assert 0.341 in levels
