"""What the cart costs: the certified E_max against the encoder's bits and against the sensing delay.

Two axes of the cart, each from the ideal sensor: an encoder on the steering axis of 10-16 bits (rounded, alpha'
a backward difference over the 1 ms period), and an exact sensor read 0-50 ms late. At each point, for (a) the
certified design (``--preset certified``) and (b) the design ``wmr-mj design`` finds for that cart
(:func:`wmr_mj.searches.design_search.search_design`, CMA-ES from its START_POINT, omega_n 10, seed 0; not
the preset's point since the preset became omega_r 30): the certified E_max on
the paper's circle over the m1 box (550-750 kg; none where the claim does not certify, with what binds), and the
worst sup|E| that ``falsify`` finds over the m1 box at a small budget (its search and as many random runs;
:func:`wmr_mj.experiments.tightness.cart_tightness`), with the verdicts of its runs.

Writes the figure (PNG) and its numbers (JSON) beside it.

Usage::

    python examples/design_tradeoff.py                         # docs/img/design_tradeoff.{png,json}; ~6 min (2 cores)
    python examples/design_tradeoff.py --quick --out /tmp/t    # 2 + 2 carts, tiny budgets: seconds
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path
from typing import Any

import wmr_mj as wm
from wmr_mj.experiments.tightness import cart_tightness
from wmr_mj.searches.design_search import DesignProblem, search_design
from wmr_mj.sim.parts import resolve_run

ROOT = Path(__file__).resolve().parents[1]
BITS = (10, 11, 12, 13, 14, 15, 16)
DELAYS_S = (0.0, 0.005, 0.01, 0.02, 0.03, 0.04, 0.05)


def sensing_of(axis: str, value: float) -> str:
    """The --sensing spec of a point: 'bits' (an axis encoder, differenced) or 'delay' (an exact sensor, s)."""
    if axis == "bits":
        return f"encoder_ticks={2 ** int(value)},encoder_side=axis,encoder_rounding=round,velocity=difference"
    return f"delay={value:g}"


def _claimed(config: Any, falsify_budget: int) -> dict[str, Any]:
    """The run's certificate of ``config`` and, where it certifies, the worst falsify finds."""
    claim = resolve_run(config).claim
    out: dict[str, Any] = {"certified": bool(claim is not None and claim.certified),
                           "E_max": claim.E_max if claim is not None and claim.certified else None,
                           "binding": "" if claim is None or claim.certified else
                           (", ".join(claim.unmet) or claim.reason or "no bound"),
                           "worst_sup_E": None, "verdicts": {}}
    if out["certified"]:
        t = cart_tightness(config, budget=falsify_budget)
        out.update(worst_sup_E=t.worst_sup_E, worst_params=dict(t.worst_params), verdicts=dict(t.verdicts),
                   E_max_falsify=t.E_max)
    return out


def point(axis: str, value: float, *, duration: float, design_budget: int, falsify_budget: int) -> dict[str, Any]:
    """One cart of the figure: the preset's and the design's certificates and worst found."""
    base = wm.RunConfig(**wm.CERTIFIED.config_changes(), duration=duration, path="paper-circle")
    config = base.replace(sensing=sensing_of(axis, value))
    t0 = time.perf_counter()
    # the E_max design (the objective the figure was measured with, 2026-11-27; the default weighs the supply since)
    found = search_design(DesignProblem(base=config, budget=design_budget, objective="E_max"))
    design_s = time.perf_counter() - t0
    design = _claimed(config.replace(**found.settings), falsify_budget) if found.certified else {
        "certified": False, "E_max": None, "binding": found.binding, "worst_sup_E": None, "verdicts": {}}
    s = found.settings
    design.update(kp=s["kp"], kd=s["kd"], friction_width=s["friction_width"], evaluations=found.evaluations,
                  search_s=round(design_s, 1))
    return {"axis": axis, "value": value, "sensing": sensing_of(axis, value),
            "preset": _claimed(config, falsify_budget), "design": design}


def plot(points: list[dict[str, Any]], path: Path, *, title: str) -> None:
    """The two panels: E_max and the worst found against bits and against delay (log scale)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), sharey=True)
    for ax, axis, label in ((axes[0], "bits", "axis encoder, bits (differenced alpha')"),
                            (axes[1], "delay", "sensing delay, ms (exact sensor)")):
        pts = [p for p in points if p["axis"] == axis]
        xs = [p["value"] * (1e3 if axis == "delay" else 1) for p in pts]
        for who, color, name in (("preset", "tab:blue", "certified preset"), ("design", "tab:orange", "design")):
            e_max = [p[who]["E_max"] if p[who]["E_max"] is not None else math.nan for p in pts]
            worst = [p[who]["worst_sup_E"] if p[who]["worst_sup_E"] is not None else math.nan for p in pts]
            ax.plot(xs, e_max, "o-", color=color, label=f"{name}: certified E_max")
            ax.plot(xs, worst, "s--", color=color, mfc="none", label=f"{name}: worst sup|E| found")
            for x, e in zip(xs, e_max):
                if math.isnan(e):
                    ax.plot([x], [0.0], "x", color=color, transform=ax.get_xaxis_transform(), clip_on=False)
        ax.set_xlabel(label)
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("rad")
    axes[0].xaxis.get_major_locator().set_params(integer=True)
    handles, labels = axes[0].get_legend_handles_labels()
    handles.append(axes[0].plot([], [], "x", color="gray")[0])
    labels.append("no certificate (x on the axis)")
    fig.legend(handles, labels, fontsize=7, loc="lower center", ncol=5)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def title_of(meta: dict[str, Any]) -> str:
    """The figure's title: what was run."""
    return (f"certified preset and wmr-mj design (budget {meta['design_budget']}), paper circle, "
            f"{meta['duration']:g} s, m1 box 550-750 kg; worst found: falsify budget {meta['falsify_budget']}")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "img" / "design_tradeoff"),
                    help="path without suffix: writes OUT.png and OUT.json (default docs/img/design_tradeoff)")
    ap.add_argument("--design-budget", type=int, default=600, help="search_design's budget (default 600, the CLI's)")
    ap.add_argument("--falsify-budget", type=int, default=16, help="falsify's budget per point (default 16)")
    ap.add_argument("--duration", type=float, default=35.0, help="each run's length, s (default 35)")
    ap.add_argument("--quick", action="store_true",
                    help="bits 10 and 14, delays 0 and 20 ms, design budget 12, falsify budget 5, 10 s runs")
    ap.add_argument("--from-json", metavar="FILE", help="draw the figure again from a JSON this script wrote")
    args = ap.parse_args(argv)
    out = Path(args.out)
    if args.from_json:
        data = json.loads(Path(args.from_json).read_text())
        plot(data["points"], out.with_suffix(".png"), title=title_of(data["settings"]))
        print(f"wrote {out.with_suffix('.png')}")
        return
    bits, delays = BITS, DELAYS_S
    if args.quick:
        bits, delays = (10, 14), (0.0, 0.02)
        args.design_budget, args.falsify_budget, args.duration = 12, 5, 10.0
    points = []
    for axis, values in (("bits", bits), ("delay", delays)):
        for value in values:
            p = point(axis, value, duration=args.duration, design_budget=args.design_budget,
                      falsify_budget=args.falsify_budget)
            points.append(p)
            pre, des = p["preset"], p["design"]
            print(f"{axis} {value:g}: preset E_max {pre['E_max']} worst {pre['worst_sup_E']} {pre['binding']}; "
                  f"design E_max {des['E_max']} worst {des['worst_sup_E']} {des['binding']}", flush=True)
    out.parent.mkdir(parents=True, exist_ok=True)
    meta = {"duration": args.duration, "design_budget": args.design_budget, "falsify_budget": args.falsify_budget,
            "path": "paper-circle", "box": "m1 550-750 kg", "seed": 0}
    out.with_suffix(".json").write_text(json.dumps({"settings": meta, "points": points}, indent=1))
    plot(points, out.with_suffix(".png"), title=title_of(meta))
    print(f"wrote {out.with_suffix('.png')} and {out.with_suffix('.json')}")


if __name__ == "__main__":
    main()
