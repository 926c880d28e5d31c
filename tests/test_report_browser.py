"""The validate report in a real browser: headless Chromium at 1400x900 shows the answer and Fig. 4
in the first screen, before any table (marked ``browser``; the order of the HTML is checked
without a browser too).

The report is written by the report writer (``wmr_mj.report.validate.write_report``) from
tests/data/validate_summary.json, the summary.json of a small validate run
(``wmr-mj validate --n 3 --duration 10 --identify-duration 10 --search-budget 5 --seed 3``, the
searches' per-run values cut to 5), with Fig. 4 drawn by ``plots.figure_paths`` over the paper
circle and a placeholder for every other figure; and from another cart's (c80-magmotor's)
tests/data/validate_summary_magmotor.json. Skips where no Chromium binary is found (on Debian:
``apt-get install chromium``; CI's .ci/run installs it).
"""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

# the C80's, and another cart's: the summary of `wmr-mj validate --cart c80-magmotor --n 3 --duration 10
# --identify-duration 10 --search-budget 5 --seed 3` (2026-11-28), its folder's paths made relative
FIXTURES = {name: Path(__file__).parent / "data" / f"{name}.json"
            for name in ("validate_summary", "validate_summary_magmotor")}
WIDTH, HEIGHT = 1400, 900
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome")
CHROMIUM = next((path for path in map(shutil.which, BROWSERS) if path), None)
needs_chromium = pytest.mark.skipif(CHROMIUM is None, reason="no Chromium binary on PATH (tried "
                                    + ", ".join(BROWSERS) + "); on Debian: apt-get install chromium")

# measures, once the page has loaded, where the answer, the figure under it and the first table are
PROBE = """<script>window.addEventListener('load', function () {
  function box(sel) { var b = document.querySelector(sel).getBoundingClientRect(); return [b.top, b.bottom, b.height]; }
  document.body.setAttribute('data-probe', JSON.stringify({answer: box('#answer'), figure: box('figure.lead'),
                                                           image: box('figure.lead img'), table: box('table')}));
});</script>"""


def _chromium(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    assert CHROMIUM is not None
    with tempfile.TemporaryDirectory() as profile:
        return subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
                               "--disable-background-networking", "--disable-component-update", "--disable-sync",
                               "--no-first-run",
                               f"--user-data-dir={profile}", f"--window-size={WIDTH},{HEIGHT}", *args],
                              capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module", params=sorted(FIXTURES))
def report(request, tmp_path_factory) -> tuple[Path, dict]:
    """A report folder written by the report writer from a fixture summary (the C80's, another cart's)."""
    from wmr_mj import C80
    from wmr_mj.figures import plots
    from wmr_mj.report.validate import write_report
    from wmr_mj.sim.config import build_reference

    folder = tmp_path_factory.mktemp("report")
    summary = json.loads(FIXTURES[request.param].read_text())
    summary["folder"] = str(folder)
    reference = build_reference("paper-circle", C80, dt=1e-3, duration=10.0)[0]
    C = np.asarray(reference.C_xy)
    wide = C + np.linspace(0.0, 1.0, len(C))[:, None] * (C - C[-1])  # a path that leaves the circle
    plots.save_figure(plots.figure_paths(reference, actual=[("the paper's design", wide),
                                                            ("the certified design", C + 0.005)]),
                      folder / "figures" / "fig4_trajectory")
    fig, ax = plots.new_figure(3.0, 2.0)
    ax.text(0.5, 0.5, "placeholder", ha="center")
    placeholder = plots.save_figure(fig, folder / "figures" / "placeholder")
    for stem, paths in summary["figures"].items():
        for rel in paths:
            if stem != "fig4_trajectory":
                shutil.copyfile(next(p for p in placeholder if p.suffix == Path(rel).suffix), folder / rel)
    write_report(summary, folder)
    return folder, summary


def test_the_answer_and_fig4_come_before_the_first_table(report):
    from wmr_mj.report.text import verdict_lines

    folder, summary = report
    text = (folder / "index.html").read_text()
    lines = verdict_lines(summary)
    answer = text.index("<section id='answer'")
    at = [text.index(f">{html.escape(line)}</p>") for line in lines]
    figure = text.index("<figure class='lead'>")
    assert answer < at[0] and at == sorted(at) and at[-1] < figure < text.index("<table")
    assert "figures/fig4_trajectory.png" in text[figure:text.index("</figure>", figure)]
    assert not re.search(r"<(table|h2)", text[:figure])  # nothing but the answer above the figure


@pytest.mark.browser
@needs_chromium
def test_chromium_shows_the_answer_and_fig4_in_the_first_screen(report, tmp_path):
    folder, _ = report
    shot = tmp_path / "first-screen.png"
    proc = _chromium(f"--screenshot={shot}", (folder / "index.html").as_uri())
    assert shot.is_file() and shot.stat().st_size > 0, proc.stderr[-2000:]
    pixels = mpimg.imread(shot)[..., :3]
    assert pixels.shape[:2] == (HEIGHT, WIDTH)
    dark = (pixels.mean(axis=2) < 0.5).mean()  # text and lines on a white page
    assert pixels.std() > 0.05 and 0.005 < dark < 0.5, f"a blank screenshot? std {pixels.std():.3g}, dark {dark:.3g}"
    lower = pixels[HEIGHT // 3:, : WIDTH // 2]  # the figure sits under the answer, on the left
    assert (lower.max(axis=2) - lower.min(axis=2) > 0.3).any(), "no coloured line under the answer: Fig. 4 missing?"

    # the layout: the answer and the whole figure above the fold, the first table below them
    probe = folder / "probe.html"
    probe.write_text((folder / "index.html").read_text().replace("</body>", PROBE + "</body>"))
    dom = _chromium("--virtual-time-budget=5000", "--dump-dom", probe.as_uri()).stdout
    found = re.search(r'data-probe="([^"]*)"', dom)
    assert found, "the probe did not run: " + dom[:500]
    box = json.loads(html.unescape(found.group(1)))
    assert box["image"][2] > 300, f"Fig. 4 is drawn {box['image'][2]:.0f} px high: not loaded?"
    assert 0 <= box["answer"][0] < box["answer"][1] <= box["figure"][0] < box["figure"][1] <= HEIGHT, box
    assert box["table"][0] >= box["figure"][1], box
    os.remove(probe)
