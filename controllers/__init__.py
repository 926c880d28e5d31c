"""Steering laws and path trackers for wmr-mj.

A steering law (:class:`SteeringController`): steering state, reference and time in, armature
voltage out, with an optional claim (a bound on |E| and |E'|) that every run is judged against. A
path tracker (:class:`PathTracker`): C's pose and speed in, the steering reference alpha0 out.
Built-ins are named in :mod:`controllers.registry`; a researcher's own are named ``FILE.py:Class``,
``module:Class`` or by an installed entry point.
"""

from controllers.adaptive import AdaptiveComputedTorque
from controllers.base import BuildContext, SteeringController, saturate
from controllers.computed_torque import (
    CONTROLLER_NAMES,
    FRICTION_SIGNS,
    MODEL_SOURCES,
    ComputedTorque,
    PDController,
    gains_from_omega_r,
    make_controller,
    model_from_source,
)
from controllers.pure_pursuit import PurePursuit
from controllers.registry import BUILTIN_CONTROLLERS, BUILTIN_TRACKERS, controller_names, resolve, tracker_names
from controllers.sliding_mode import SlidingMode
from controllers.tracking import PathTracker, RateLimitedFilter, StanleyAtC

__all__ = [
    "SteeringController",
    "PathTracker",
    "BuildContext",
    "saturate",
    "ComputedTorque",
    "PDController",
    "SlidingMode",
    "AdaptiveComputedTorque",
    "StanleyAtC",
    "PurePursuit",
    "RateLimitedFilter",
    "make_controller",
    "model_from_source",
    "gains_from_omega_r",
    "resolve",
    "controller_names",
    "tracker_names",
    "BUILTIN_CONTROLLERS",
    "BUILTIN_TRACKERS",
    "MODEL_SOURCES",
    "CONTROLLER_NAMES",
    "FRICTION_SIGNS",
]
