"""Headless figures: the paper's Figs. 4-7 and the validation plots (PNG + SVG).

Everything draws on ``matplotlib.figure.Figure`` objects with the Agg canvas
(no pyplot, no display), so it runs on servers and in tests. SVG text stays
text (``svg.fonttype = 'none'``), lines stay vectors.

Each function is handed its data (a reference, a summary, a search, the paper's example) and reads it by
attribute: this module sits below ``wmr_mj.sim`` (its layer, ``wmr_mj.figures``) and imports nothing of the
layers that make those results, so the results of ``wmr_mj.sim`` can draw with it.

Axes-level functions (reusable by ``validate`` and ``replay``)::

    plot_paths(ax, reference)                    # Fig. 4: paths of A and C, equal aspect
    plot_alpha0(ax, reference)                   # Fig. 5
    plot_alpha0_rate(ax, reference, bound=0.23)  # Fig. 6 (alpha0')
    plot_alpha0_accel(ax, reference, bound=0.4)  # alpha0''
    plot_region(ax, result, points=..., values=..., trajectory=(E, Edot), label=...)
    plot_error_trajectory(ax, E, E_dot, label=...)
    plot_time_history(axes3, rows, E_max=..., Edot_max=..., voltage_limit=...)

Figure-level functions return a Figure: ``figure_paths``, ``figure_alpha0``,
``figure_alpha0_rates``, ``figure_region`` (region + trajectories/points, with a
second full-range panel and a note when data leave the region's scale),
``figure_time_history``. ``save_figure(fig, stem)`` writes stem.png and
stem.svg atomically.

The validation's figures (``wmr-mj validate``)::

    figure_verdict_plane(sup_E, sup_Edot, verdicts, [DrawnRegion("certificate", cert.vertices,
                         gid=CERTIFICATE_GID)])      # every run of a sweep, by verdict, with regions
    figure_ladder(labels, counts, paper_inside)      # verdict counts per rung, stacked bars
    figure_search_history([SearchHistory(title, ylabel, values, mc_worst=..., bound=1.0)])

The paper's figures::

    from wmr_mj.report.paper_example import paper_example   # computes (runs the simulations)
    from wmr_mj.figures.plots import paper_figures, write_figures  # only draws
    example = paper_example()                 # reference, (5.1) analysis, reduced + MuJoCo runs
    paths = write_figures(paper_figures(example), "logs/figures")

Fig. 7 draws the region (4.21)-(4.23) of the paper's (5.1) example
(ParameterBox.paper(), K_P = 6, K_D = 9, bounds (5.1)) with the error
trajectories (|E(t)|, |E'(t)|) of (a) the same computed-torque law on the
reduced paper model as the plant (estimate and plant at opposite corners of
the box, both pairings; the paper's view) and (b) the MuJoCo plant with the
controller built from the paper model.
"""

from __future__ import annotations

import io
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib

matplotlib.use("Agg", force=False)  # headless; a no-op when Agg is already selected

import numpy as np  # noqa: E402
from matplotlib import rc_context  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Patch, Polygon  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from wmr_mj._util.files import write_bytes_atomic
from wmr_mj.params import M1_NOMINAL  # noqa: E402
from wmr_mj.reference.bounds import PAPER_BOUNDS

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType

__all__ = [
    "STYLE",
    "new_figure",
    "falsify_history",
    "save_figure",
    "write_figures",
    "plot_paths",
    "plot_alpha0",
    "plot_alpha0_rate",
    "plot_alpha0_accel",
    "plot_region",
    "RegionStyle",
    "plot_error_trajectory",
    "plot_region_points",
    "plot_time_history",
    "Series",
    "figure_paths",
    "figure_alpha0",
    "figure_alpha0_rates",
    "figure_region",
    "figure_time_history",
    "paper_figures",
    "PAPER_FIGURE_NAMES",
    "REGION_GID",
    "CERTIFICATE_GID",
    "VERDICT_COLORS",
    "PAPER_CLAIM_COLOR",
    "DrawnRegion",
    "plot_region_polygon",
    "plot_verdict_points",
    "figure_verdict_plane",
    "figure_ladder",
    "SearchHistory",
    "figure_search_history",
]

#: Style for paper-quality output: readable at a single-column width, text kept as text in SVG.
STYLE: dict[RcKeyType, Any] = {
    "font.size": 9.0,
    "axes.titlesize": 9.5,
    "axes.labelsize": 9.0,
    "legend.fontsize": 7.5,
    "xtick.labelsize": 8.0,
    "ytick.labelsize": 8.0,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.5,
    "lines.linewidth": 1.3,
    "axes.linewidth": 0.7,
    "savefig.dpi": 200,
    "savefig.bbox": "tight",
    "savefig.pad_inches": 0.03,
    "svg.fonttype": "none",
    "svg.hashsalt": "wmr-mj",  # reproducible SVG ids
    "figure.constrained_layout.use": True,
}

#: gid of the region polygon drawn by :func:`plot_region` (find it with ``patch.get_gid()``).
REGION_GID = "robustness-region"
#: gid of a certificate's region polygon in :func:`figure_verdict_plane`.
CERTIFICATE_GID = "certificate-region"

#: File stems of the paper's figures written by :func:`paper_figures`.
PAPER_FIGURE_NAMES = ("fig4_trajectory", "fig5_alpha0", "fig6_alpha0_rates", "fig7_region")

_COLORS = {"C": "#1f4e9c", "A": "#c0392b", "region": "#7fb3d5", "bound": "0.35",
           "reduced": "#1e8449", "reduced2": "#7d3c98", "mujoco": "#d35400", "voltage": "#2c3e50",
           "paper": "#d35400"}
#: Colour of the paper's claim (its region, drawn as a dashed outline beside a certificate's).
PAPER_CLAIM_COLOR = _COLORS["paper"]
#: Colour of each verdict of wmr_mj.analysis.verdicts (certified-outside: a bug or a modelling gap, in red).
VERDICT_COLORS = {"certified-inside": "#1e8449", "certified-outside": "#e00000",
                  "uncertified-inside": "#f0b000", "uncertified-outside": "#8c8c8c"}
_VERDICT_MARKERS = {"certified-inside": "o", "certified-outside": "X", "uncertified-inside": "s",
                    "uncertified-outside": "^"}
# region extent above which data count as "leaving the region's scale" (drawn in a second panel)
_ZOOM_FACTOR = 3.0


# --------------------------------------------------------------------------- figures and files
def new_figure(width: float = 5.0, height: float = 3.4, nrows: int = 1, ncols: int = 1, **kw: Any):
    """(Figure, axes) in :data:`STYLE`, on the Agg canvas. ``kw`` goes to ``Figure.subplots``."""
    with rc_context(STYLE):
        fig = Figure(figsize=(width, height))
        axes = fig.subplots(nrows, ncols, squeeze=True, **kw)
    return fig, axes


def _figure_bytes(fig: Figure, fmt: str) -> bytes:
    buf = io.BytesIO()
    with rc_context(STYLE):
        fig.savefig(buf, format=fmt, metadata=_metadata(fmt))
    return buf.getvalue()


def _metadata(fmt: str) -> dict[str, Any] | None:
    if fmt == "svg":
        return {"Date": None, "Creator": "wmr-mj"}
    if fmt == "png":
        return {"Software": "wmr-mj (matplotlib Agg)"}
    return None


def save_figure(fig: Figure, stem: str | Path, formats: Sequence[str] = ("png", "svg")) -> list[Path]:
    """Write ``stem.<fmt>`` for each format (atomic: temporary file, then rename). Returns the paths."""
    stem = Path(stem)
    out = []
    for fmt in formats:
        out.append(write_bytes_atomic(stem.with_name(f"{stem.name}.{fmt}"), _figure_bytes(fig, fmt)))
    return out


def write_figures(figures: Mapping[str, Figure], out_dir: str | Path,
                  formats: Sequence[str] = ("png", "svg")) -> list[Path]:
    """Save {stem: Figure} into ``out_dir`` as PNG and SVG; the written paths, in order."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    for stem, fig in figures.items():
        paths.extend(save_figure(fig, out_dir / stem, formats))
    return paths


# --------------------------------------------------------------------------- Figs. 4-6
def plot_paths(ax, reference, *, vehicle_every: float | None = 5.0) -> None:
    """Fig. 4: paths of C (tracked point, steering pivot) and A (rear-axle midpoint), equal aspect.

    vehicle_every: draw the wheelbase A-C every so many seconds (None: not at all).
    """
    A, C = np.asarray(reference.A_xy), np.asarray(reference.C_xy)
    t = np.asarray(reference.t)
    ax.plot(C[:, 0], C[:, 1], color=_COLORS["C"], label="C, tracked point (steering pivot)")
    ax.plot(A[:, 0], A[:, 1], color=_COLORS["A"], ls="--", label="A, rear-axle midpoint")
    if vehicle_every:
        for ts in np.arange(0.0, t[-1] + 1e-9, vehicle_every):
            i = int(np.searchsorted(t, ts))
            i = min(i, len(t) - 1)
            ax.plot([A[i, 0], C[i, 0]], [A[i, 1], C[i, 1]], color="0.55", lw=0.8, zorder=1)
            ax.plot(C[i, 0], C[i, 1], "o", ms=2.5, color=_COLORS["C"], zorder=3)
        ax.plot([], [], color="0.55", lw=0.8, label=f"wheelbase A-C every {vehicle_every:g} s")
    ax.plot(C[0, 0], C[0, 1], "o", ms=5, mfc="white", mec=_COLORS["C"], zorder=4, label="start (t = 0)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def _steady_angle(reference) -> float | None:
    k = float(np.asarray(reference.kappa)[-1])
    if k == 0 or abs(reference.l1 * k) >= 1:
        return None
    return math.asin(reference.l1 * k)


def plot_alpha0(ax, reference) -> None:
    """Fig. 5: the reference steering angle alpha0(t)."""
    ax.plot(reference.t, reference.alpha0, color=_COLORS["C"], label=r"$\alpha_0(t)$")
    steady = _steady_angle(reference)
    if steady is not None:
        ax.axhline(steady, color=_COLORS["bound"], ls=":", lw=1.0,
                   label=rf"steady angle $\arcsin(l_1 \kappa)$ = {steady:.3f} rad")
    ax.set_xlabel("t [s]")
    ax.set_ylabel(r"$\alpha_0$ [rad]")
    ax.set_xlim(0.0, float(reference.t[-1]))


def _bound_lines(ax, bound: float | None, label: str) -> None:
    if bound is None:
        return
    ax.axhline(bound, color=_COLORS["bound"], ls="--", lw=0.9, label=label)
    ax.axhline(-bound, color=_COLORS["bound"], ls="--", lw=0.9)


def plot_alpha0_rate(ax, reference, *, bound: float | None = None) -> None:
    """Fig. 6: alpha0'(t), with +-bound (the (5.1) value ||alpha0'|| = 0.23 rad/s) when given."""
    ax.plot(reference.t, reference.alpha0_dot, color=_COLORS["C"], label=r"$\dot\alpha_0(t)$")
    _bound_lines(ax, bound, rf"$\pm\|\dot\alpha_0\|$ = {bound:g} rad/s (5.1)" if bound is not None else "")
    ax.set_xlabel("t [s]")
    ax.set_ylabel(r"$\dot\alpha_0$ [rad/s]")
    ax.set_xlim(0.0, float(reference.t[-1]))


def plot_alpha0_accel(ax, reference, *, bound: float | None = None) -> None:
    """alpha0''(t), with +-bound (the (5.1) value ||alpha0''|| = 0.4 rad/s^2) when given."""
    ax.plot(reference.t, reference.alpha0_ddot, color=_COLORS["C"], label=r"$\ddot\alpha_0(t)$")
    _bound_lines(ax, bound, rf"$\pm\|\ddot\alpha_0\|$ = {bound:g} rad/s$^2$ (5.1)" if bound is not None else "")
    ax.set_xlabel("t [s]")
    ax.set_ylabel(r"$\ddot\alpha_0$ [rad/s$^2$]")
    ax.set_xlim(0.0, float(reference.t[-1]))


def figure_paths(reference, *, title: str | None = None,
                 actual: Sequence[tuple[str, np.ndarray]] = ()) -> Figure:
    """Fig. 4; ``actual``: (label, C's xy (n, 2) [m]) of runs, the paths C travelled, drawn over it."""
    fig, ax = new_figure(5.0, 5.0)
    plot_paths(ax, reference)
    for (label, xy), color in zip(actual, ("#d35400", "#1e8449", "#7d3c98", "#f0b000")):
        xy = np.asarray(xy, dtype=float)
        # wide and under the desired path (zorder 1.5 < 2), so a path that follows it shows as a halo around it
        ax.plot(xy[:, 0], xy[:, 1], color=color, lw=2.6, alpha=0.75, zorder=1.5, label=f"C travelled: {label}")
    _legend_below(fig, ax, ncols=2)
    default = rf"Fig. 4  Desired trajectory: C on the circle, $V_A$ = {reference.V_A:g} m/s"
    if actual:
        default = "Fig. 4  C's desired path and the paths C travelled (MuJoCo plant)"
    ax.set_title(title or default)
    return fig


def figure_alpha0(reference, *, title: str | None = None) -> Figure:
    fig, ax = new_figure(5.0, 3.0)
    plot_alpha0(ax, reference)
    ax.legend(loc="lower right")
    ax.set_title(title or r"Fig. 5  Reference steering angle $\alpha_0(t)$")
    return fig


def figure_alpha0_rates(reference, *, rate_bound: float | None = 0.23, accel_bound: float | None = 0.4,
                        title: str | None = None) -> Figure:
    """Fig. 6 (alpha0') with alpha0'' below it; bounds of (5.1) dashed."""
    fig, (a1, a2) = new_figure(5.0, 4.4, 2, 1, sharex=True)
    plot_alpha0_rate(a1, reference, bound=rate_bound)
    plot_alpha0_accel(a2, reference, bound=accel_bound)
    a1.set_xlabel("")
    for ax in (a1, a2):
        ax.legend(loc="center right")
    a1.set_title(title or r"Fig. 6  Reference steering rate $\dot\alpha_0(t)$ and acceleration $\ddot\alpha_0(t)$")
    return fig


# --------------------------------------------------------------------------- Fig. 7: the region
def _region_extent(result) -> tuple[float, float]:
    v = np.asarray(result.vertices, dtype=float)
    if v.size == 0:
        return 0.0, 0.0
    return float(v[:, 0].max()), float(v[:, 1].max())


@dataclass(frozen=True)
class RegionStyle:
    """How :func:`plot_region` draws: labels, the points' colour map and colorbar, the (4.21) lines.

    region_label: the polygon's legend entry (default: the region's bounds). value_label: the
    colorbar's label. point_label: the points' legend entry. lines: also draw the two lines of (4.21).
    """

    region_label: str | None = None
    value_label: str = "plant m1 [kg]"
    cmap: str = "viridis"
    lines: bool = True
    colorbar: bool = True
    point_label: str | None = None


def plot_region(ax, result, *, points=None, values=None, trajectory=None, label: str | None = None,
                style: RegionStyle = RegionStyle()) -> dict[str, Any]:
    """The region (4.21)-(4.23) of ``result`` (a RobustnessResult) in the (||E||, ||E'||) plane.

    points: (N, 2) array of (sup|E|, sup|E'|) (one per run), coloured by ``values`` (e.g. m1)
    with a colorbar labelled ``style.value_label``. trajectory: (|E(t)|, |E'(t)|) arrays drawn as a
    line labelled ``label``. ``style`` (:class:`RegionStyle`): labels, colour map, colorbar and
    whether the lines of (4.21) are drawn. Returns the artists
    {'region': Polygon or None, 'scatter': ..., 'trajectory': ..., 'colorbar': ...}.
    The polygon's vertices are exactly ``result.vertices`` (gid :data:`REGION_GID`).
    """
    out: dict[str, Any] = {"region": None, "scatter": None, "trajectory": None, "colorbar": None}
    verts = tuple(result.vertices)
    if verts:
        poly = Polygon(np.asarray(verts, dtype=float), closed=True, facecolor=_COLORS["region"], alpha=0.45,
                       edgecolor="#1b4f72", lw=1.0, zorder=1,
                       label=style.region_label or (f"region (4.21)-(4.23): ||E|| <= {result.E_max:.3g} rad, "
                                              f"||E'|| <= {result.Edot_max:.3g} rad/s"))
        poly.set_gid(REGION_GID)
        ax.add_patch(poly)
        out["region"] = poly
        ax.plot([result.E_max], [result.Edot_max], "s", ms=3.5, color="#1b4f72", zorder=2)
        if style.lines:
            _draw_4_21_lines(ax, result)
    else:
        ax.text(0.03, 0.97, f"(4.23) fails: condition = {result.condition:.3g} >= 1;\nno bounded region",
                transform=ax.transAxes, va="top", ha="left", fontsize=8,
                bbox=dict(boxstyle="round", fc="#fdebd0", ec="#d35400"))
    if trajectory is not None:
        E, Ed = (np.abs(np.asarray(x, dtype=float)) for x in trajectory)
        out["trajectory"] = plot_error_trajectory(ax, E, Ed, label=label or "error trajectory")
    if points is not None:
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        s = Series(label=style.point_label or "runs: (sup|E|, sup|E'|)", E=pts[:, 0], E_dot=pts[:, 1], kind="points",
                   values=None if values is None else np.asarray(values, dtype=float))
        out["scatter"], out["colorbar"] = plot_region_points(ax, s, value_label=style.value_label,
                                                             colorbar=style.colorbar, cmap=style.cmap)
    ax.set_xlabel(r"$\|E\|$ = sup$|E|$ [rad]")
    ax.set_ylabel(r"$\|\dot E\|$ = sup$|\dot E|$ [rad/s]")
    return out


def _draw_4_21_lines(ax, result) -> None:
    """The two lines of (4.21), as far as the region's corner times 1.6, dotted."""
    lines = result.lines()
    x_end, y_end = _region_extent(result)
    ys = np.linspace(0.0, 1.6 * max(y_end, 1e-12), 50)
    up = lines.get("upper")
    if up is not None:
        ax.plot(up[0] + up[1] * ys, ys, ":", color="#1b4f72", lw=0.8, zorder=1)
    low = lines.get("lower")
    if low is not None:
        ax.plot(low[0] + low[1] * ys, ys, ":", color="#1b4f72", lw=0.8, zorder=1)
    ax.plot([], [], ":", color="#1b4f72", lw=0.8, label="lines of (4.21)")


def plot_error_trajectory(ax, E, E_dot, *, label: str, color: str | None = None, ls: str = "-",
                          lw: float = 1.0, mark_end: bool = True):
    """(|E(t)|, |E'(t)|) as a line in the magnitude plane; marks the start (o) and end (x)."""
    E = np.abs(np.asarray(E, dtype=float))
    Ed = np.abs(np.asarray(E_dot, dtype=float))
    (line,) = ax.plot(E, Ed, ls=ls, lw=lw, color=color, label=label, zorder=3)
    if mark_end and E.size:
        ax.plot(E[-1], Ed[-1], "x", ms=5, color=line.get_color(), zorder=5)
    return line


@dataclass
class Series:
    """One data set for :func:`figure_region`: a trajectory or a point cloud."""

    label: str
    E: np.ndarray
    E_dot: np.ndarray
    kind: str = "trajectory"  # or 'points'
    values: np.ndarray | None = None  # colours of points
    color: str | None = None
    ls: str = "-"
    tag: str | None = None  # short name for notes, e.g. "(b)"

    @property
    def sup(self) -> tuple[float, float]:
        E, Ed = np.abs(self.E), np.abs(self.E_dot)
        return (float(np.max(E)) if E.size else 0.0, float(np.max(Ed)) if Ed.size else 0.0)


def _draw_series(ax, result, series: Sequence[Series], *, value_label: str, colorbar: bool,
                 region_label: str | None) -> dict[str, Any]:
    arts = plot_region(ax, result, style=RegionStyle(region_label=region_label))
    for s in series:
        if s.kind == "points":
            plot_region_points(ax, s, value_label=value_label, colorbar=colorbar)
        else:
            plot_error_trajectory(ax, s.E, s.E_dot, label=s.label, color=s.color, ls=s.ls)
    return arts


def plot_region_points(ax, s: Series, *, value_label: str = "plant m1 [kg]", colorbar: bool = True,
                       cmap: str = "viridis"):
    """A point cloud (one point per run); coloured by ``s.values`` with a colorbar. (scatter, colorbar)."""
    kw: dict[str, Any] = dict(s=14, zorder=4, edgecolors="k", linewidths=0.3, label=s.label)
    cbar = None
    if s.values is not None:
        sc = ax.scatter(s.E, s.E_dot, c=s.values, cmap=cmap, **kw)
        if colorbar:
            cbar = ax.figure.colorbar(sc, ax=ax, label=value_label, pad=0.01)
    else:
        sc = ax.scatter(s.E, s.E_dot, color=s.color or _COLORS["mujoco"], **kw)
    return sc, cbar


def _legend_below(fig, ax, ncols: int = 1) -> None:
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="outside lower center", ncols=ncols, framealpha=0.9)



def _full_range_frame(af: Any, *, xm: float, ym: float, xz: float, yz: float) -> None:
    """Limits of the full-range panel and the dashed outline of the zoomed (left) panel."""
    af.set_xlim(0.0, 1.08 * xm)
    af.set_ylim(0.0, 1.08 * ym)
    af.add_patch(Polygon([(0, 0), (xz, 0), (xz, yz), (0, yz)], closed=True, fill=False, ls="--", lw=0.8,
                         ec="0.3", zorder=6))
    af.annotate("left panel", (xz, yz), xytext=(4, 4), textcoords="offset points", fontsize=7, color="0.3")
    af.set_title("Full range")

def figure_region(result, series: Sequence[Series] = (), *, title: str | None = None,
                  value_label: str = "plant m1 [kg]", region_label: str | None = None,
                  zoom_factor: float = _ZOOM_FACTOR) -> Figure:
    """The region of ``result`` with trajectories and/or run points; legend below the axes.

    When every series stays within ``zoom_factor`` times the region's extent, one
    panel shows all. Otherwise the left panel shows the region at its own scale and
    its title says which series leave it (with their sup values and multiples of
    E_max, E'_max); a right panel shows the full range with the region and the
    left panel's window (dashed) marked.
    """
    xr, yr = _region_extent(result)
    sups = [(s, *s.sup) for s in series]
    if xr > 0 and yr > 0:
        leaving = [(s, e, ed) for s, e, ed in sups if e > zoom_factor * xr or ed > zoom_factor * yr]
    else:  # no bounded region (or a point): show everything in one panel
        leaving = []
    has_cbar = any(s.kind == "points" and s.values is not None for s in series)
    if not leaving:
        fig, ax = new_figure(5.6 if has_cbar else 5.0, 5.0)
        _draw_series(ax, result, series, value_label=value_label, colorbar=has_cbar, region_label=region_label)
        xm = max([xr] + [e for _, e, _ in sups] + [1e-9])
        ym = max([yr] + [ed for _, _, ed in sups] + [1e-9])
        ax.set_xlim(0.0, 1.12 * xm)
        ax.set_ylim(0.0, 1.12 * ym)
        _legend_below(fig, ax)
        ax.set_title(title or "Robustness region in the error-magnitude plane")
        return fig

    fig, (az, af) = new_figure(9.6 if has_cbar else 9.0, 5.0, 1, 2)
    # zoom panel: the region at its own scale (plus the series that stay near it)
    _draw_series(az, result, series, value_label=value_label, colorbar=False, region_label=region_label)
    leaving_ids = {id(s) for s, _, _ in leaving}
    near = [(e, ed) for s, e, ed in sups if id(s) not in leaving_ids]
    xz = 1.35 * max([xr] + [e for e, _ in near])
    yz = 1.35 * max([yr] + [ed for _, ed in near])
    az.set_xlim(0.0, xz)
    az.set_ylim(0.0, yz)
    note = []
    for s, e, ed in leaving:
        if s.kind == "points":
            out_of_view = int(np.sum((np.abs(s.E) > xz) | (np.abs(s.E_dot) > yz)))
            note.append(f"{out_of_view} of {np.size(s.E)} {s.tag or 'points'} lie beyond this range: up to "
                        f"sup|E| = {e:.3g} rad ({e / xr:.1f} E_max), sup|E'| = {ed:.3g} rad/s ({ed / yr:.1f} E'_max)")
        else:
            note.append(f"{s.tag or s.label} leaves this range: sup|E| = {e:.3g} rad ({e / xr:.1f} E_max), "
                        f"sup|E'| = {ed:.3g} rad/s ({ed / yr:.1f} E'_max)")
    az.set_title("Region scale\n" + "\n".join(note), fontsize=7.5, color="#a04000")
    # full panel
    _draw_series(af, result, series, value_label=value_label, colorbar=has_cbar, region_label=region_label)
    xm = max([xr] + [e for _, e, _ in sups])
    ym = max([yr] + [ed for _, _, ed in sups])
    _full_range_frame(af, xm=xm, ym=ym, xz=xz, yz=yz)
    _legend_below(fig, az)
    fig.suptitle(title or "Robustness region in the error-magnitude plane", fontsize=10)
    return fig


# --------------------------------------------------------------------------- time histories
def plot_time_history(axes, rows: Mapping[str, np.ndarray], *, E_max: float | None = None,
                      Edot_max: float | None = None, voltage_limit: float | None = None,
                      settle_s: float | None = None, stop_at: float | None = None,
                      bound_name: str | None = None) -> None:
    """E(t), E'(t) and the armature voltage on three axes (bounds dashed, entry end dotted).

    bound_name: whose bounds E_max, Edot_max are (e.g. "certificate"), shown in the legend.
    """
    whose = f" ({bound_name})" if bound_name else ""
    a1, a2, a3 = axes
    t = np.asarray(rows["t"])
    a1.plot(t, rows["E"], color=_COLORS["C"], label=r"$E = \alpha_0 - \alpha$")
    a2.plot(t, rows["E_dot"], color=_COLORS["C"], label=r"$\dot E$")
    if "voltage_cmd" in rows:
        a3.plot(t, rows["voltage_cmd"], color="0.6", lw=0.8, label="commanded")
    a3.plot(t, rows["voltage"], color=_COLORS["voltage"], label="applied")
    if E_max is not None and math.isfinite(E_max):
        _bound_lines(a1, E_max, rf"$\pm E_{{max}}${whose} = {E_max:.3g} rad")
    if Edot_max is not None and math.isfinite(Edot_max):
        _bound_lines(a2, Edot_max, rf"$\pm \dot E_{{max}}${whose} = {Edot_max:.3g} rad/s")
    if voltage_limit is not None:
        _bound_lines(a3, voltage_limit, rf"$\pm$ {voltage_limit:g} V supply")
    for ax in axes:
        if settle_s:
            ax.axvline(settle_s, color="0.4", ls=":", lw=0.9)
        if stop_at is not None:
            ax.axvline(stop_at, color="#c0392b", ls="-.", lw=0.9)
        ax.set_xlim(float(t[0]), float(t[-1]))
    if settle_s:
        a1.plot([], [], color="0.4", ls=":", lw=0.9, label=f"C enters the circle ({settle_s:.1f} s)")
    if stop_at is not None:
        a1.plot([], [], color="#c0392b", ls="-.", lw=0.9, label=f"steering stop reached ({stop_at:.2f} s)")
    a1.set_ylabel("E [rad]")
    a2.set_ylabel(r"$\dot E$ [rad/s]")
    a3.set_ylabel("u [V]")
    a3.set_xlabel("t [s]")
    for ax in axes:
        ax.legend(loc="upper right", fontsize=6.5, framealpha=0.9)


def figure_time_history(rows: Mapping[str, np.ndarray], summary: Any, *,
                        voltage_limit: float | None = None, title: str | None = None,
                        bounds: tuple[float | None, float | None] | None = None,
                        bound_name: str | None = None) -> Figure:
    """Three-panel time history of one run.

    Args:
        rows: the run's rows (``RunResult.rows``).
        summary: the run's summary (``RunSummary``, read by attribute).
        voltage_limit: the supply to draw [V]; None: none.
        title: the figure's title; default the model and m1.
        bounds: (E_max [rad], Edot_max [rad/s]) to draw, named ``bound_name``; default the
            summary's E_max, Edot_max (the paper's claim).
        bound_name: the legend's name of ``bounds``.
    """
    fig, axes = new_figure(5.6, 5.6, 3, 1, sharex=True)
    E_max, Ed_max = bounds if bounds is not None else (summary.E_max, summary.Edot_max)
    plot_time_history(axes, rows, E_max=None if E_max is None else float(E_max),
                      Edot_max=None if Ed_max is None else float(Ed_max), voltage_limit=voltage_limit,
                      settle_s=summary.settle_s, stop_at=summary.left_steering_range_at_s,
                      bound_name=bound_name)
    axes[0].set_title(title or f"{summary.model} model, plant m1 = {summary.m1:g} kg")
    return fig


# --------------------------------------------------------------------------- the validation's figures
@dataclass(frozen=True)
class DrawnRegion:
    """A region of the (||E||, ||E'||) plane as drawn (a patch): its polygon and how; the claim's region itself is
    a :class:`wmr_mj.analysis.regions.Region`.

    vertices: the polygon (e.g. ``Certificate.vertices``, ``RobustnessResult.vertices``);
    empty when the region does not exist. filled: a filled patch (else a dashed outline).
    """

    label: str
    vertices: Sequence[tuple[float, float]]
    color: str = _COLORS["region"]
    filled: bool = True
    gid: str | None = None

    @property
    def extent(self) -> tuple[float, float]:
        """(max ||E||, max ||E'||) over the vertices; (0, 0) when empty."""
        v = np.asarray(self.vertices, dtype=float).reshape(-1, 2)
        return (float(v[:, 0].max()), float(v[:, 1].max())) if v.size else (0.0, 0.0)


def plot_region_polygon(ax, region: DrawnRegion):
    """Draw ``region`` (its vertices exactly); the Polygon, or None when the region is empty."""
    if not len(region.vertices):
        return None
    xy = np.asarray(region.vertices, dtype=float)
    if region.filled:
        poly = Polygon(xy, closed=True, facecolor=region.color, alpha=0.4, edgecolor=region.color, lw=1.0,
                       zorder=1, label=region.label)
    else:
        poly = Polygon(xy, closed=True, fill=False, edgecolor=region.color, lw=1.3, ls="--", zorder=2,
                       label=region.label)
    if region.gid:
        poly.set_gid(region.gid)
    ax.add_patch(poly)
    return poly


def plot_verdict_points(ax, sup_E: Sequence[float], sup_Edot: Sequence[float], verdicts: Sequence[str]
                        ) -> dict[str, Any]:
    """One point per run at (sup|E|, sup|E'|), coloured and shaped by its verdict; the legend
    label carries the count. certified-outside points are drawn large, on top. {verdict: scatter}."""
    E = np.asarray(sup_E, dtype=float)
    Ed = np.asarray(sup_Edot, dtype=float)
    names = np.asarray(list(verdicts), dtype=object)
    out = {}
    for verdict, color in VERDICT_COLORS.items():
        mask = names == verdict
        if not mask.any():
            continue
        loud = verdict == "certified-outside"
        out[verdict] = ax.scatter(E[mask], Ed[mask], s=60 if loud else 16, color=color, edgecolors="k",
                                  linewidths=0.8 if loud else 0.3, marker=_VERDICT_MARKERS[verdict],
                                  zorder=6 if loud else 4,
                                  label=f"{verdict.upper() if loud else verdict}: {int(mask.sum())} runs")
    return out


def _plane_panel(ax, E, Ed, verdicts, regions: Sequence[DrawnRegion], note: str | None) -> None:
    for region in regions:
        plot_region_polygon(ax, region)
    plot_verdict_points(ax, E, Ed, verdicts)
    ax.set_xlabel(r"$\|E\|$ = sup$|E|$ [rad]")
    ax.set_ylabel(r"$\|\dot E\|$ = sup$|\dot E|$ [rad/s]")
    if note:
        ax.text(0.98, 0.97, note, transform=ax.transAxes, va="top", ha="right", multialignment="left",
                fontsize=7, bbox=dict(boxstyle="round", fc="#fdebd0", ec="#d35400"), zorder=7)


def figure_verdict_plane(sup_E: Sequence[float], sup_Edot: Sequence[float], verdicts: Sequence[str],
                         regions: Sequence[DrawnRegion] = (), *, title: str | None = None, note: str | None = None,
                         zoom_factor: float = _ZOOM_FACTOR) -> Figure:
    """Every run of a sweep at (sup|E|, sup|E'|) by verdict, with ``regions`` (e.g. the
    certificate's, filled, and the paper's claim, dashed); ``note`` in a box (e.g. why there
    is no certificate); legend below.

    When runs lie beyond ``zoom_factor`` times the regions' extent, a left panel shows the
    regions at their own scale (its title counts the runs beyond it) and a right panel the
    full range with the left panel's window dashed.
    """
    E = np.asarray(sup_E, dtype=float)
    Ed = np.asarray(sup_Edot, dtype=float)
    extents = [r.extent for r in regions if len(r.vertices)]
    xr = max((x for x, _ in extents), default=0.0)
    yr = max((y for _, y in extents), default=0.0)
    xm = max([xr, *E.tolist(), 1e-9])
    ym = max([yr, *Ed.tolist(), 1e-9])
    beyond = (E > zoom_factor * xr) | (Ed > zoom_factor * yr)
    if not (xr > 0 and yr > 0 and beyond.any()):
        fig, ax = new_figure(5.4, 5.0)
        _plane_panel(ax, E, Ed, verdicts, regions, note)
        ax.set_xlim(0.0, 1.12 * xm)
        ax.set_ylim(0.0, 1.12 * ym)
        _legend_below(fig, ax)
        ax.set_title(title or "Runs by verdict in the error-magnitude plane")
        return fig
    fig, (az, af) = new_figure(9.6, 5.0, 1, 2)
    near = ~beyond
    xz = 1.35 * max([xr, *E[near].tolist()])
    yz = 1.35 * max([yr, *Ed[near].tolist()])
    _plane_panel(az, E, Ed, verdicts, regions, None)
    az.set_xlim(0.0, xz)
    az.set_ylim(0.0, yz)
    out_of_view = int(np.sum((E > xz) | (Ed > yz)))
    az.set_title(f"Region scale: {out_of_view} of {E.size} runs lie beyond it, up to sup|E| = {E.max():.3g} rad "
                 f"({E.max() / xr:.1f}x), sup|E'| = {Ed.max():.3g} rad/s ({Ed.max() / yr:.1f}x)",
                 fontsize=7.5, color="#a04000")
    _plane_panel(af, E, Ed, verdicts, regions, note)
    _full_range_frame(af, xm=xm, ym=ym, xz=xz, yz=yz)
    _legend_below(fig, az, ncols=2)
    fig.suptitle(title or "Runs by verdict in the error-magnitude plane", fontsize=10)
    return fig


def figure_ladder(labels: Sequence[str], counts: Sequence[Mapping[str, int]], paper_inside: Sequence[int | None], *,
                  title: str | None = None, claim: str = "paper's claim") -> Figure:
    """Verdict counts per rung as stacked horizontal bars (first rung on top), each with its
    count, and the runs inside the paper's claim (``claim``: its name, the paper's on the C80 only) beside each bar."""
    fig, ax = new_figure(7.0, 0.55 * len(labels) + 1.6)
    y = np.arange(len(labels))[::-1]
    n = [sum(c.values()) for c in counts]
    left = np.zeros(len(labels))
    handles = []
    for verdict, color in VERDICT_COLORS.items():
        widths = np.array([c.get(verdict, 0) for c in counts], dtype=float)
        handles.append(Patch(facecolor=color, edgecolor="k", lw=0.4, label=f"{verdict}: {int(widths.sum())}"))
        bars = ax.barh(y, widths, left=left, color=color, edgecolor="k", lw=0.4)
        for bar, w in zip(bars, widths):
            if w:
                ax.text(bar.get_x() + w / 2, bar.get_y() + bar.get_height() / 2, f"{int(w)}", ha="center",
                        va="center", fontsize=7)
        left += widths
    for yi, k, total in zip(y, paper_inside, n):
        if k is None:  # a law outside the paper's family: its region says nothing of the rung
            continue
        ax.text(1.01 * max(n), yi, f"{claim}: {k}/{total} inside", va="center", fontsize=7, color="#a04000")
    ax.set_yticks(y, labels)
    ax.set_xlim(0.0, 1.45 * max(n))
    ax.set_xlabel("runs")
    ax.grid(False)
    fig.legend(handles=handles, loc="outside lower center", ncols=2, framealpha=0.9)
    ax.set_title(title or "Verdicts per rung of the ladder")
    return fig


@dataclass
class SearchHistory:
    """One worst-case search for :func:`figure_search_history`: the objective of each run in
    evaluation order (None: undefined), and the lines to compare with."""

    title: str
    ylabel: str
    values: Sequence[float | None]
    mc_worst: float | None = None  # worst of the Monte-Carlo sweep of the same design
    mc_label: str = "Monte-Carlo worst"
    bound: float | None = None  # e.g. 1.0 for a ratio to a region, or a certificate's E_max
    bound_label: str = "bound"


def figure_search_history(histories: Sequence[SearchHistory], *, title: str | None = None) -> Figure:
    """One panel per search: each run's objective, the search's running worst, the
    Monte-Carlo worst (dashed) and the bound (dotted)."""
    fig, axes = new_figure(3.6 * len(histories) + 0.4, 3.6, 1, len(histories))
    for ax, h in zip(np.atleast_1d(axes), histories):
        v = np.array([np.nan if x is None else float(x) for x in h.values])
        x = np.arange(1, v.size + 1)
        ax.scatter(x, v, s=9, color="C3", alpha=0.55, linewidths=0)
        running = np.fmax.accumulate(np.where(np.isnan(v), -np.inf, v)) if v.size else v
        if v.size and np.isfinite(v).any():
            ax.step(x, np.where(np.isfinite(running), running, np.nan), where="post", color="C3",
                    label=f"search: worst {np.nanmax(v):.4g}")
        if h.mc_worst is not None:
            ax.axhline(h.mc_worst, color="0.35", ls="--", lw=1.0, label=f"{h.mc_label}: {h.mc_worst:.4g}")
        if h.bound is not None:
            ax.axhline(h.bound, color="#1b4f72", ls=":", lw=1.2, label=f"{h.bound_label}: {h.bound:.4g}")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_xlabel("simulations of the search")
        ax.set_ylabel(h.ylabel)
        ax.set_title(h.title, fontsize=8.5)
        ax.legend(loc="best", fontsize=6.5)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


# --------------------------------------------------------------------------- the paper's example
def fig7_series(example: Any) -> list[Series]:
    series = []
    styles = [(_COLORS["reduced"], "-"), (_COLORS["reduced2"], "--")]
    for (name, rows), (color, ls) in zip(example.reduced, styles):
        series.append(Series(label=f"(a) paper's view, reduced paper model as plant: {name}",
                             E=np.abs(rows["E"]), E_dot=np.abs(rows["E_dot"]), color=color, ls=ls, tag="(a)"))
    if example.mujoco_rows is not None:
        m1 = example.mujoco_summary.m1 if example.mujoco_summary else M1_NOMINAL
        series.append(Series(label=f"(b) MuJoCo plant (m1 = {m1:g} kg), paper-model controller",
                             E=np.abs(example.mujoco_rows["E"]), E_dot=np.abs(example.mujoco_rows["E_dot"]),
                             color=_COLORS["mujoco"], ls="-", tag="(b) MuJoCo"))
    return series


def paper_figures(example: Any) -> dict[str, Figure]:
    """{stem: Figure} of Figs. 4-7 (stems :data:`PAPER_FIGURE_NAMES`) of ``example``
    (:class:`wmr_mj.report.paper_example.PaperExample`, read by attribute)."""
    ref = example.reference
    r = example.result
    figs = {
        "fig4_trajectory": figure_paths(ref, actual=example.actual_paths),
        "fig5_alpha0": figure_alpha0(ref),
        "fig6_alpha0_rates": figure_alpha0_rates(ref, rate_bound=PAPER_BOUNDS.alpha_dot_max,
                                                 accel_bound=PAPER_BOUNDS.alpha_ddot_max),
        "fig7_region": figure_region(
            r, fig7_series(example),
            title=(f"Fig. 7  Region of the (5.1) example (paper box, K_P = {r.kp:g}, K_D = {r.kd:g}): "
                   f"(4.23) = {r.condition:.4f}"),
            region_label=(f"region (4.21)-(4.23), (5.1): ||E|| <= {r.E_max:.3g} rad, "
                          f"||E'|| <= {r.Edot_max:.3g} rad/s")),
    }
    return figs


def close_all(figures: Iterable[Figure]) -> None:
    """Drop the figures' canvases' caches (Figures without pyplot are freed by GC)."""
    for fig in figures:
        fig.clear()


def falsify_history(result: Any):
    """The search's history: each run's objective in evaluation order, and the running worst
    of the search and of the random sample (same budget).

    Args:
        result: the search (``FalsifyResult``, read by attribute: ``spec``, ``search``, ``random``, and the
            words of its method and objective, ``method_label`` and ``objective_label``).
    """
    fig, ax = new_figure(6.0, 3.6)
    search_label = result.method_label
    for evals, color, label in ((result.search, "C3", search_label),
                                (result.random, "0.45", "random (Latin hypercube)")):
        x = np.arange(1, len(evals) + 1)
        y = np.array([np.nan if e.objective is None else e.objective for e in evals])
        ax.scatter(x, y, s=8, color=color, alpha=0.45, linewidths=0)
        running = np.fmax.accumulate(np.where(np.isnan(y), -np.inf, y))
        ax.step(x, np.where(np.isfinite(running), running, np.nan), where="post", color=color,
                label=f"{label}: worst {np.nanmax(y):.4g}" if np.isfinite(y).any() else label)
    worst = max((e.objective for e in (*result.search, *result.random) if e.objective is not None), default=0.0)
    if result.spec.objective != "sup-E" and worst >= 0.5:  # in view without squashing the data
        ax.axhline(1.0, color="0.2", lw=0.8, ls="--", label="region boundary (ratio 1)")
    ax.set_xlabel("simulations")
    ax.set_ylabel(result.objective_label)
    ax.set_title(f"worst-case search, {len(result.spec.box)} parameters, budget {result.spec.budget}, "
                 f"seed {result.spec.seed}", fontsize=9)
    ax.legend(loc="best", fontsize=8)
    return fig
