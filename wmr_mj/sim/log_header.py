"""What a run tells its log: :class:`LogHeader`, built by the runner, read by ``wmr_mj.logs.writer``.

It lives in the sim layer so that the runner (``wmr_mj.sim.closed_loop``) builds it without
importing ``wmr_mj.logs`` (the logs layer sits above sim); ``wmr_mj.logs.writer`` imports it from
here and re-exports it.

Usage::

    header = LogHeader(mjcf_xml=xml, config=cfg, parameters=params, initial_state=s0,
                       timestep=m.opt.timestep, control_substeps=1,
                       bounds={"E_max": 0.02, "Edot_max": 0.1})
    logger = logger_factory(header)       # e.g. functools.partial(RunLogger, "logs/run.mcap")
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["LogHeader"]


@dataclass(frozen=True, eq=False)
class LogHeader:
    """The runner's description of a run, written once at the start of its log.

    Attributes:
        mjcf_xml: the scene's MJCF as the plant compiles it (attached as c80.xml).
        config: the run's configuration, ``RunConfig.to_dict()`` (any other value is stored
            under the key "config").
        parameters: the plant parameters, ``C80Parameters.to_dict()`` (SI units; its
            "voltage_limit" [V] feeds /bounds).
        initial_state: mjSTATE_INTEGRATION of the model at t = 0, (mj_stateSize,) float64.
        timestep: the physics timestep [s].
        control_substeps: physics steps per control step (>= 1); one logged row per control step.
        reference_path: (M, 2) world xy of C along the reference [m]; None for none.
        bounds: E_max [rad], Edot_max [rad/s] drawn on /bounds; None: taken from the summary at close.
        model: the compiled ``mjcf_xml`` (``mujoco.MjModel``), to skip compiling it again; None
            compiles it.
        path_errors: path_errors(rows, every) -> the log's /path columns (path_cross_track [m],
            path_along_track [m], path_heading_error [rad], NaN between plotted rows) of the rows'
            C_pos, heading and t, every ``every``-th control step; called once per written chunk of
            rows, in order (it keeps the projection's continuity), on the writer's thread when it
            has one; None: the rows' own columns (NaN where the runner gave none).
        sensed: True where the run has a sensor between the plant and the law (``RunConfig.sensing`` not
            ideal): its blocks then carry alpha_measured [rad] and alpha_dot_measured [rad/s], what the law
            read, and the log gains the channels /measured and /steering/measured; False (an ideal run) writes
            neither.
    """

    mjcf_xml: str
    config: Mapping[str, Any] | Any
    parameters: Mapping[str, Any]
    initial_state: np.ndarray  # mjSTATE_INTEGRATION at t = 0
    timestep: float  # [s]
    control_substeps: int  # physics steps per control step
    reference_path: np.ndarray | None = None  # (M, 2) world xy of C [m]
    bounds: Mapping[str, float] | None = None  # E_max [rad], Edot_max [rad/s]
    model: Any = None  # mujoco.MjModel compiled from mjcf_xml, or None
    path_errors: Any = None  # Callable[[Mapping[str, np.ndarray], int], Mapping[str, np.ndarray]] | None
    sensed: bool = False  # blocks carry what the law read (engine.SENSED_ROW_FIELDS)
