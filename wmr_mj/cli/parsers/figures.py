"""``wmr-mj figures``: the paper's Figs. 4-7 regenerated headless as PNG and SVG.

Fig. 4 desired trajectory (paths of A and C), Fig. 5 alpha0(t), Fig. 6
alpha0'(t) and alpha0''(t), Fig. 7 the region (4.21)-(4.23) of the (5.1) example
with the error trajectories of the paper's view (reduced paper model as the
plant) and of the MuJoCo plant. See :mod:`wmr_mj.figures.plots`.
"""

from __future__ import annotations

import argparse

from wmr_mj.cli.command_options import add_command_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "regenerate the paper's Figs. 4-7 (PNG and SVG, headless)"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("figures", help=HELP,
                       description=__doc__.split("\n\n")[1] if __doc__ else None)
    add_command_options(p, "figures")
