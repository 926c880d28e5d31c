"""The paper's (5.1) example computed for Figs. 4-7: the reference, the analysis and the runs.

This module computes (reference, (5.1) analysis, reduced-model and MuJoCo runs);
:mod:`wmr_mj.figures.plots` only draws the result::

    from wmr_mj.report.paper_example import paper_example
    from wmr_mj.figures.plots import paper_figures, write_figures
    paths = write_figures(paper_figures(paper_example()), "logs/figures")
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from controllers import ComputedTorque
from wmr_mj.analysis.robustness import BOX_COEFFICIENTS, ParameterBox, analyse
from wmr_mj.errors import DurationError
from wmr_mj.params import C80, PAPER_KD, PAPER_KP
from wmr_mj.plant.reduced import SteeringModel
from wmr_mj.reference.bounds import ReferenceBounds
from wmr_mj.sim.closed_loop import run_closed_loop, run_on_reduced_model
from wmr_mj.sim.config import RunConfig, build_reference
from wmr_mj.sim.designs import CERTIFIED

if TYPE_CHECKING:
    from wmr_mj.sim.summary import RunSummary

__all__ = ["PaperExample", "paper_example"]


@dataclass
class PaperExample:
    """Data of the paper's Figs. 4-7 (see :func:`paper_example`; drawn by
    :func:`wmr_mj.figures.plots.paper_figures`)."""

    reference: Any
    settle_s: float
    result: Any  # RobustnessResult of (5.1)
    reduced: list[tuple[str, dict[str, np.ndarray]]] = field(default_factory=list)
    mujoco_rows: dict[str, np.ndarray] | None = None
    mujoco_summary: RunSummary | None = None
    actual_paths: list[tuple[str, np.ndarray]] = field(default_factory=list)  # (label, C's xy) for Fig. 4


def paper_example(*, duration: float = 35.0, friction_width: float = 1e-3, mujoco: bool = True) -> PaperExample:
    """Reference of the paper circle, the (5.1) analysis and the error trajectories of Fig. 7.

    (a) the computed-torque law on the reduced paper model as the plant: estimate at
    the box's lower corner and plant at its upper corner, and the reverse; the
    Coulomb sign smoothed as x/sqrt(x^2 + w^2), w = ``friction_width``, identically in
    law and plant (so the mismatch is (F - F^) s, as the analysis assumes).
    (b) ``run_closed_loop(RunConfig(model='paper'))`` on the MuJoCo plant.
    """
    if not (isinstance(duration, (int, float)) and math.isfinite(duration) and duration > 0):
        raise DurationError(f"duration = {duration!r} s is not accepted; a finite number > 0 is required")
    box = ParameterBox.paper()
    kp, kd = PAPER_KP, PAPER_KD
    result = analyse(box, kp=kp, kd=kd, bounds=ReferenceBounds())
    reference, settle_s = build_reference("paper-circle", C80, dt=1e-3, duration=float(duration))
    lo = {n: getattr(box, n)[0] for n in BOX_COEFFICIENTS}
    hi = {n: getattr(box, n)[1] for n in BOX_COEFFICIENTS}
    reduced = []
    for est, plant, name in ((lo, hi, "estimate at box min, plant at box max"),
                             (hi, lo, "estimate at box max, plant at box min")):
        law = ComputedTorque(SteeringModel(**est, gyro=0.0, V_A=C80.V_A, name="estimate"), kp=kp, kd=kd,
                             friction_width=friction_width)
        rows = run_on_reduced_model(law, SteeringModel(**plant, gyro=0.0, V_A=C80.V_A, name="plant"), reference,
                                    friction_width=friction_width)
        reduced.append((name, rows))
    ex = PaperExample(reference=reference, settle_s=settle_s, result=result, reduced=reduced)
    if mujoco:
        run = run_closed_loop(RunConfig(model="paper", duration=float(duration), kp=kp, kd=kd), progress=False)
        ex.mujoco_rows = run.rows
        ex.mujoco_summary = run.summary

        certified = run_closed_loop(RunConfig(**CERTIFIED.config_changes(), duration=float(duration)), progress=False)
        for label, r in (("the paper's design", run), ("the certified design", certified)):
            if r.C_xy is not None and r.summary.path_error is not None:
                ex.actual_paths.append((f"{label}, cross-track max {r.summary.path_error.cross_track_max:.3g} m",
                                        r.C_xy))
    return ex
