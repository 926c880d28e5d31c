"""The figures of a result's ``.plot()``: each a :class:`ResultPlot` with the figure and its axes, drawn with
:mod:`wmr_mj.figures.plots` (the same figures the commands write).

- :func:`plot_run`: E and E' between the bounds the run is judged by, the voltage between the supply limits
  (:func:`wmr_mj.figures.plots.plot_time_history`), and C's path beside its reference.
- :func:`plot_sweep`: sup|E| of every run against each ranged parameter, with the certificate's E_max.
- :func:`figure_sweep_region`: a sweep's runs in the (sup|E|, sup|E'|) plane with the bounds they are judged by
  (``wmr-mj sweep``'s region.png).
- :func:`plot_falsify`: the search beside random (:func:`wmr_mj.figures.plots.falsify_history`).
- :func:`plot_compare`: compare's figure (:func:`figure_compare`, compare.png).
- :func:`plot_validate`: the ladder's verdicts (:func:`wmr_mj.figures.plots.figure_ladder`).
- :func:`plot_design`: each path's certificate of a design (E_max and the voltage bound), certified or not.
- :func:`plot_tightness`: each cart's certificate beside the worst sup|E| the adversary found, and their ratio.
- :func:`plot_cart_check`: each identified coefficient against the one the cart file implies, in its allowance.

The results (``RunResult``, ``SweepResult``, ``FalsifyResult``, ``CompareResult``, ``DesignResult``,
``CartTightness``, ``CartCheck`` in ``wmr_mj.sim``, ``ValidateSummary`` in ``wmr_mj.report``) import these in
their ``plot()``; this module is below them and imports none of them: each result is handed in and read by
attribute, and what only its layer knows (a sweep's axis labels, a search's words) it hands in too.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib.patches import Rectangle

from wmr_mj.analysis.verdicts import paper_region_name
from wmr_mj.figures import plots

__all__ = ["ResultPlot", "plot_run", "plot_sweep", "plot_falsify", "plot_compare", "plot_validate", "figure_compare",
           "plot_design", "plot_tightness", "plot_cart_check", "figure_sweep_region"]

#: a certified bar's colour and an uncertified one's (the verdicts' colours)
_CERTIFIED_COLOUR, _UNCERTIFIED_COLOUR = plots.VERDICT_COLORS["certified-inside"], "0.6"


@dataclass(frozen=True)
class ResultPlot:
    """A result's figure (``result.plot()``), as python-control's ``ControlPlot``.

    Attributes:
        figure: the matplotlib Figure (not attached to pyplot: a notebook shows it by ``figure`` or by this
            object's own display).
        axes: its axes, in the order the figure reads (a tuple).
    """

    figure: Any
    axes: tuple[Any, ...]

    def _repr_png_(self) -> bytes:  # a notebook shows the figure when the plot is a cell's value
        buf = io.BytesIO()
        self.figure.savefig(buf, format="png", dpi=100, bbox_inches="tight")
        return buf.getvalue()


def _plot(fig: Any) -> ResultPlot:
    return ResultPlot(figure=fig, axes=tuple(fig.axes))


def drawn_error_bounds(summary: Any, *, on_c80: bool = True) -> tuple[float | None, float | None, str]:
    """(E_max [rad], E'_max [rad/s], whose): the certificate's where it bounds E (said "uncertified" where an
    assumption is not met), else the paper's region where the run has one (named the paper's claim on the C80,
    ``on_c80``, else the (4.21)-(4.23) region on this cart: :func:`wmr_mj.analysis.verdicts.paper_region_name`),
    else none."""
    judged = summary.certificate
    if judged is not None and judged.E_max is not None:
        return judged.E_max, judged.Edot_max, "certificate" if judged.certified else "certificate, uncertified"
    if summary.paper_region is not None:
        return summary.E_max, summary.Edot_max, paper_region_name(on_c80).removeprefix("the ")
    return None, None, ""


def plot_run(result: Any, *, supply: float, title: str | None = None) -> ResultPlot:
    """A run (``RunResult``): E, E' and the voltage against time (axes 0-2, bounds dashed), C's path (axis 3).

    Args:
        result: the run.
        supply: the plant's supply limit, V (the run's parameter set: its cart's, with its overrides).
        title: the figure's title; default the law, m1 and the verdict.
    """
    s = result.summary
    E_max, Edot_max, whose = drawn_error_bounds(s, on_c80=getattr(result.config, "cart", None) is None)
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


def plot_sweep(result: Any, *, xlabels: Sequence[str] | None = None) -> ResultPlot:
    """A sweep (``SweepResult``): sup|E| of every run against each ranged parameter (one panel each, the
    value each run used), coloured by verdict, with the certificate's E_max: one dashed line where every run
    has the same, else each run's as a dash at its value (a ranged cart's axis changes the claim).

    Args:
        result: the sweep (read by attribute: ``spec.names``, ``rows``, ``summary.n``).
        xlabels: each panel's x label, one per ranged parameter in ``spec.names``' order (the sweep's table's
            column names, with units); default the bare names.
    """
    names = result.spec.names
    labels = tuple(names) if xlabels is None else tuple(xlabels)
    if len(labels) != len(names):
        raise ValueError(f"xlabels: {len(labels)} labels for {len(names)} ranged parameters")
    fig, axes = plots.new_figure(3.6 * len(names) + 0.6, 3.4, 1, len(names), sharey=True)
    axes = tuple(np.atleast_1d(axes))
    for ax, name, label in zip(axes, names, labels):
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
        ax.set_xlabel(label)
    axes[0].set_ylabel("sup |E| [rad]")
    axes[-1].legend(loc="best", fontsize=6.5)
    fig.suptitle(f"sweep of {result.summary.n} runs", fontsize=10)
    return ResultPlot(figure=fig, axes=axes)


def figure_sweep_region(result: Any, *, on_c80: bool) -> Any:
    """Fig.-7-style plot of a sweep's ``result`` (``SweepResult``, read by attribute: ``rows``, ``summary``): the
    bounds a run is judged by (sup|E| <= E_max and sup|E'| <= E'_max, the sweep's inside/outside) and every run's
    (sup|E|, sup|E'|), coloured by m1. The region (4.21)-(4.23) is labelled the paper's claim on the paper's C80
    only (``on_c80``: the sweep's base runs on no cart file; :func:`wmr_mj.analysis.verdicts.paper_region_name`)."""
    results, runs = result.rows, result.summary
    claim = paper_region_name(on_c80)
    fig, ax = plots.new_figure(5.0, 4.0)
    for (E_max, Ed_max), colour, label in (
            ((runs.certificate_E_max, runs.certificate_Edot_max), "C2", "certificate's bounds"),
            ((runs.paper_E_max, runs.paper_Edot_max), "C0", claim.removeprefix("the "))):
        if E_max is not None and Ed_max is not None and math.isfinite(E_max) and math.isfinite(Ed_max):
            ax.add_patch(Rectangle((0, 0), E_max, Ed_max, alpha=0.15, color=colour, label=label))
    sc = ax.scatter([r["sup_E"] for r in results], [r["sup_Edot"] for r in results], c=[r["m1"] for r in results],
                    s=12, label="runs")
    fig.colorbar(sc, ax=ax, label="m1 [kg]")
    ax.set_xlabel("sup |E| [rad]")
    ax.set_ylabel("sup |E'| [rad/s]")
    ax.legend(loc="best")  # the runs sit anywhere; keep the legend off them
    return fig


def plot_falsify(result: Any) -> ResultPlot:
    """A search (``FalsifyResult``): each run's objective and the running worst, the search beside random."""
    return _plot(plots.falsify_history(result))


def plot_compare(result: Any) -> ResultPlot:
    """A comparison (``CompareResult``): compare.png's figure (:func:`figure_compare`)."""
    return _plot(figure_compare(result))


def figure_compare(result: Any) -> Any:
    """compare.png: (a) the requirement checks each design held; (b) effort (RMS voltage) against the worst
    cross-track. ``result``: a ``CompareResult`` (read by attribute: each of ``rows``' ``label``,
    ``requirements_passed``, ``requirements_total``, ``rms_voltage`` [V], ``cross_track_max`` [m])."""
    fig, (a, b) = plots.new_figure(10.0, 3.6, ncols=2)
    labels = [r.label for r in result.rows]
    held = [r.requirements_passed / r.requirements_total if r.requirements_total else 0.0 for r in result.rows]
    y = range(len(labels))
    colours = [f"C{i % 10}" for i in range(len(labels))]  # one per design, the same in both panels
    a.barh(list(y), held, color=colours)
    a.set_yticks(list(y), labels, fontsize=8)
    a.invert_yaxis()
    a.set_xlim(0, 1)
    a.set_xlabel("fraction of requirement checks held")
    a.set_title("(a) requirements over the suite")
    for i, r in enumerate(result.rows):
        b.scatter(r.rms_voltage, r.cross_track_max if r.cross_track_max is not None else math.nan, color=colours[i],
                  label=r.label)
    b.set_xlabel("RMS voltage [V]")
    b.set_ylabel("worst |cross-track| [m]")
    b.set_title("(b) effort against C's path")
    b.legend(fontsize=7, frameon=False)
    return fig


def plot_validate(summary: Any) -> ResultPlot:
    """The validation (``ValidateSummary``): the verdicts of each rung of the ladder (and the user's designs)."""
    rungs = summary.rungs
    claim = paper_region_name(not summary.settings.get("cart"))  # the paper's claim on its C80 only
    return _plot(plots.figure_ladder([f"{r.index}. {r.label}" for r in rungs], [r.verdicts for r in rungs],
                                     [r.paper_inside for r in rungs], claim=claim.removeprefix("the ")))


def _bound(cert: Any, name: str) -> float:
    """A certificate's bound ``name`` (E_max [rad], voltage_max [V]); NaN where it has no valid one (no bar)."""
    value = getattr(cert, name, None) if cert is not None and cert.valid else None
    return math.nan if value is None else float(value)


def plot_design(result: Any) -> ResultPlot:
    """A design (``DesignResult``): each path's certificate at the design, (a) its E_max [rad] and (b) its
    voltage bound [V], one bar per path, green where certified and grey where not (no bar: no valid bound).

    Args:
        result: the design (read by attribute: ``certificates`` path -> certificate or None, ``certified``,
            ``E_max``, ``objective``).
    """
    paths = list(result.certificates)
    certs = [result.certificates[p] for p in paths]
    colours = [_CERTIFIED_COLOUR if c is not None and c.certified else _UNCERTIFIED_COLOUR for c in certs]
    fig, (a, b) = plots.new_figure(3.2 * 2 + 0.6, 3.4, ncols=2)
    for ax, name, label in ((a, "E_max", "E_max [rad]"), (b, "voltage_max", "voltage bound [V]")):
        ax.bar(range(len(paths)), [_bound(c, name) for c in certs], color=colours)
        ax.set_xticks(range(len(paths)), paths, fontsize=8)
        ax.set_ylabel(label)
    a.set_title("(a) the certificate's E_max, each path")
    b.set_title("(b) the certificate's voltage bound")
    worst = f"worst E_max {result.E_max:.4g} rad" if math.isfinite(result.E_max) else "no bound on some path"
    fig.suptitle(f"design ({result.objective}): {'certified' if result.certified else 'nothing certifies'}, "
                 f"{worst}", fontsize=10)
    return _plot(fig)


def plot_tightness(rows: Sequence[Any]) -> ResultPlot:
    """Carts' tightness (``CartTightness`` rows): (a) each row's certificate E_max beside the worst sup|E| the
    adversary found [rad], (b) their ratio, the tightness [-], against 1 (a ratio above 1 on a certified claim
    is a broken claim). A row without a bound has no E_max bar and no tightness bar.

    Args:
        rows: the rows, each read by attribute (``path``, ``certificate``, ``E_max``, ``worst_sup_E``,
            ``tightness``); labelled by their path (and certificate).
    """
    labels = [f"{r.path}\n{r.certificate or 'no certificate'}" for r in rows]
    x = np.arange(len(rows), dtype=float)
    fig, (a, b) = plots.new_figure(max(5.0, 1.6 * len(rows) + 3.0), 3.6, ncols=2)
    a.bar(x - 0.2, [math.nan if r.E_max is None else r.E_max for r in rows], width=0.4, color="#1b4f72",
          label="certificate's E_max (upper bound)")
    a.bar(x + 0.2, [r.worst_sup_E for r in rows], width=0.4, color="#c0392b",
          label="worst sup|E| found (lower bound)")
    a.set_ylabel("[rad]")
    a.set_title("(a) the bound and the worst found")
    a.legend(fontsize=7, frameon=False)
    b.bar(x, [math.nan if r.tightness is None else r.tightness for r in rows], color="0.35")
    b.axhline(1.0, color="#e00000", ls="--", lw=1.0, label="1: the bound reached")
    b.set_ylabel("tightness = worst sup|E| / E_max [-]")
    b.set_title("(b) the tightness")
    b.legend(fontsize=7, frameon=False)
    for ax in (a, b):
        ax.set_xticks(x, labels, fontsize=7)
    return _plot(fig)


def plot_cart_check(check: Any) -> ResultPlot:
    """A cart check (``CartCheck``): each coefficient identified from the simulated excitation (the plant)
    against the one the cart file implies (the model), as (identified - implied) / allowed: inside the shaded
    band |.| <= 1 a coefficient passes (its allowance, in its own unit, is the check's).

    Args:
        check: the check (read by attribute: ``identification.rows``, each with ``name``, ``identified``,
            ``implied``, ``allowed``; ``identification`` None: the fit was impossible, said on the
            axes with ``identification_error``; ``answer`` titles the figure).
    """
    fig, ax = plots.new_figure(5.6, 3.4)
    ident = check.identification
    rows = () if ident is None else ident.rows
    x = np.arange(len(rows), dtype=float)
    ax.axhspan(-1.0, 1.0, color="#d5f5e3", label="allowed (passes)")
    ax.axhline(0.0, color="0.55", lw=0.8)
    ax.plot(x, [(r.identified - r.implied) / r.allowed for r in rows], "o", color="C0",
            label="identified (the MuJoCo plant)")
    ax.set_xticks(x, [r.name for r in rows])
    ax.set_ylabel("(value - implied) / allowed [-]")
    if ident is None:
        ax.text(0.5, 0.5, f"no identification: {check.identification_error}", transform=ax.transAxes,
                ha="center", va="center", fontsize=8, wrap=True)
    ax.legend(fontsize=7, frameon=False, loc="best")
    cart = check.cart
    fig.suptitle(f"cart {cart.name} {cart.version}: {'passes' if check.passed else 'FAILS'}", fontsize=10)
    return _plot(fig)
