"""The figures of a result's ``.plot()`` (:data:`wmr_mj.sim.notebook.PLOT_BACKEND`): each a
:class:`~wmr_mj.sim.notebook.ResultPlot` with the figure and its axes, drawn with :mod:`wmr_mj.report.plots`
and :func:`wmr_mj.report.compare.figure` (the same figures the commands write).

- :func:`plot_run`: E and E' between the bounds the run is judged by, the voltage between the supply limits
  (:func:`wmr_mj.report.plots.plot_time_history`), and C's path beside its reference.
- :func:`plot_sweep`: sup|E| of every run against each ranged parameter, with the certificate's E_max.
- :func:`plot_falsify`: the search beside random (:func:`wmr_mj.report.plots.falsify_history`).
- :func:`plot_compare`: compare's figure (:func:`wmr_mj.report.compare.figure`).
- :func:`plot_validate`: the ladder's verdicts (:func:`wmr_mj.report.plots.figure_ladder`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from wmr_mj.params import C80
from wmr_mj.report import plots
from wmr_mj.sim.notebook import ResultPlot, run_column
from wmr_mj.sim.sweep_result import parameter_units

__all__ = ["plot_run", "plot_sweep", "plot_falsify", "plot_compare", "plot_validate"]


def _plot(fig: Any) -> ResultPlot:
    return ResultPlot(figure=fig, axes=tuple(fig.axes))


def run_bounds(summary: Any) -> tuple[float | None, float | None, str]:
    """(E_max [rad], E'_max [rad/s], whose): the certificate's where it bounds E (said "uncertified" where an
    assumption is not met), else the paper's claim where the run has one, else none."""
    judged = summary.certificate
    if judged is not None and judged.E_max is not None:
        return judged.E_max, judged.Edot_max, "certificate" if judged.certified else "certificate, uncertified"
    if summary.paper_region is not None:
        return summary.E_max, summary.Edot_max, "paper's claim"
    return None, None, ""


def plot_run(result: Any, *, title: str | None = None) -> ResultPlot:
    """A run (``RunResult``): E, E' and the voltage against time (axes 0-2, bounds dashed), C's path (axis 3).

    Args:
        result: the run.
        title: the figure's title; default the law, m1 and the verdict.
    """
    s = result.summary
    E_max, Edot_max, whose = run_bounds(s)
    supply = float(result.config.plant_overrides.get("voltage_limit", C80.voltage_limit))
    with plots.rc_context(plots.STYLE):
        fig = plots.Figure(figsize=(10.0, 5.6))
        grid = fig.add_gridspec(3, 2, width_ratios=(1.5, 1.0))
        a1 = fig.add_subplot(grid[0, 0])
        a2, a3 = fig.add_subplot(grid[1, 0], sharex=a1), fig.add_subplot(grid[2, 0], sharex=a1)
        path = fig.add_subplot(grid[:, 1])
    plots.plot_time_history((a1, a2, a3), result.rows, E_max=_finite(E_max), Edot_max=_finite(Edot_max),
                            voltage_limit=supply, settle_s=s.settle_s, stop_at=s.left_steering_range_at_s,
                            bound_name=whose or None)
    reference = getattr(result.reference, "C_xy", None)
    if reference is not None:
        ref = np.asarray(reference)
        path.plot(ref[:, 0], ref[:, 1], color="0.55", ls="--", lw=1.0, label="C's reference path")
    if result.C_xy is not None:
        c = np.asarray(result.C_xy)
        path.plot(c[:, 0], c[:, 1], color="C0", lw=1.2, label="C (MuJoCo)")
        path.plot(c[0, 0], c[0, 1], "o", ms=4, mfc="white", mec="C0", label="start")
    path.set_aspect("equal", adjustable="datalim")
    path.set_xlabel("x [m]")
    path.set_ylabel("y [m]")
    path.legend(loc="best", fontsize=6.5)
    fig.suptitle(title or f"{s.controller}, m1 = {s.m1:g} kg: {s.verdict}", fontsize=10)
    return ResultPlot(figure=fig, axes=(a1, a2, a3, path))


def _finite(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(float(x)) else float(x)


def plot_sweep(result: Any) -> ResultPlot:
    """A sweep (``SweepResult``): sup|E| of every run against each ranged parameter (one panel each, the
    value each run used), coloured by verdict, with the certificate's E_max: one dashed line where every run
    has the same, else each run's as a dash at its value (a ranged cart's axis changes the claim)."""
    names = result.spec.names
    fig, axes = plots.new_figure(3.6 * len(names) + 0.6, 3.4, 1, len(names), sharey=True)
    axes = tuple(np.atleast_1d(axes))
    units = parameter_units(names)
    for ax, name in zip(axes, names):
        groups: dict[str, list[Any]] = {}
        for r in result.rows:  # by verdict, in the verdicts' order; any other word (no-claim, failed) as "other"
            verdict = r.get("verdict")
            groups.setdefault(verdict if verdict in plots.VERDICT_COLORS else "other", []).append(r)
        for verdict, colour in (*plots.VERDICT_COLORS.items(), ("other", "0.5")):
            runs = groups.get(verdict, [])
            if runs:
                ax.scatter([float(r[name]) for r in runs], [float(r["sup_E"]) for r in runs], s=14, color=colour,
                           label=verdict, zorder=3)
        bounds = [(float(r[name]), float(r["cert_E_max"])) for r in result.rows if _finite(r.get("cert_E_max"))]
        if bounds and all(b == bounds[0][1] for _, b in bounds):  # one certificate for every run: one line
            ax.axhline(bounds[0][1], color="#1b4f72", ls="--", lw=1.0,
                       label=f"certificate's E_max = {bounds[0][1]:.3g} rad")
        elif bounds:  # each run's cart has its own claim (a cart's axis ranged): each run's bound, a dash
            ax.scatter(*zip(*bounds), marker="_", s=160, color="#1b4f72", label="certificate's E_max, each run's",
                       zorder=2)
        ax.set_xlabel(run_column(name, units))
    axes[0].set_ylabel("sup |E| [rad]")
    axes[-1].legend(loc="best", fontsize=6.5)
    fig.suptitle(f"sweep of {result.summary.n} runs", fontsize=10)
    return ResultPlot(figure=fig, axes=axes)


def plot_falsify(result: Any) -> ResultPlot:
    """A search (``FalsifyResult``): each run's objective and the running worst, the search beside random."""
    return _plot(plots.falsify_history(result))


def plot_compare(result: Any) -> ResultPlot:
    """A comparison (``CompareResult``): compare.png's figure."""
    from wmr_mj.report.compare import figure

    return _plot(figure(result))


def plot_validate(summary: Any) -> ResultPlot:
    """The validation (``ValidateSummary``): the verdicts of each rung of the ladder (and the user's designs)."""
    rungs = summary.rungs
    return _plot(plots.figure_ladder([f"{r.index}. {r.label}" for r in rungs], [r.verdicts for r in rungs],
                                     [r.paper_inside for r in rungs]))
