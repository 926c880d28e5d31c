"""``wmr-mj figures``: the paper's Figs. 4-7 regenerated headless as PNG and SVG (which figures: the command's help
page, :mod:`wmr_mj.cli.parsers.figures`; the drawing: :mod:`wmr_mj.figures.plots`)."""

from __future__ import annotations

import argparse

from wmr_mj._util.files import check_output_path
from wmr_mj.cli._common import default_folder
from wmr_mj.figures.plots import paper_figures, write_figures
from wmr_mj.report.paper_example import paper_example


def run(args: argparse.Namespace) -> int:
    out = check_output_path(args.out or default_folder("figures"), kind="dir", option="--out")
    example = paper_example(duration=args.duration)
    paths = write_figures(paper_figures(example), out)
    for path in paths:
        print(path)
    return 0
