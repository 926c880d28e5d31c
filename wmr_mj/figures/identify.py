"""The identification's figure: the recorded angle beside the identified model's on a recording (the hold-out
where there is one), and their difference. Handed the arrays; computes nothing.

Usage::

    from wmr_mj.figures.identify import figure_identify
    fig = figure_identify(t, recorded, simulated, title="hold-out run3.csv")
"""

from __future__ import annotations

from typing import Any

import numpy as np

from wmr_mj.figures.plots import new_figure

__all__ = ["figure_identify"]


def figure_identify(t: np.ndarray, recorded: np.ndarray, simulated: np.ndarray, *, title: str) -> Any:
    """Two panels against t (s): recorded and simulated alpha (rad); recorded - simulated (mrad).

    The simulated angle is each 1 s segment's simulation from its recorded state (segment offsets fitted), so
    the curves meet at each segment's start."""
    fig, (ax_a, ax_r) = new_figure(7.0, 5.0, nrows=2, sharex=True)
    ax_a.plot(t, recorded, lw=0.8, label="recorded (as read)")
    ax_a.plot(t, simulated, lw=0.8, ls="--", label="identified model")
    ax_a.set_ylabel("alpha [rad]")
    ax_a.set_title(title)
    ax_a.legend(loc="best")
    ax_r.plot(t, 1e3 * (recorded - simulated), lw=0.6)
    ax_r.set_ylabel("recorded - model [mrad]")
    ax_r.set_xlabel("t within the segments [s]")
    return fig
