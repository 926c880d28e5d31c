"""wmr-mj figures and wmr_mj.plots: the paper's Figs. 4-7 as PNG + SVG, headless."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from wmr_mj.cli import main  # noqa: E402
from wmr_mj.plots import (PAPER_FIGURE_NAMES, REGION_GID, Series, figure_region, new_figure,  # noqa: E402
                          paper_example, paper_figures, plot_region)
from wmr_mj.robustness import ParameterBox, analyse  # noqa: E402

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


def test_fig7_svg_carries_the_region_polygon(written):
    _, out, _ = written
    root = ET.parse(out / "fig7_region.svg").getroot()
    ids = {el.get("id") for el in root.iter()}
    assert REGION_GID in ids


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
