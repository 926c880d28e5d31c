"""Steering controllers for wmr-mj: steering state and reference in, armature voltage out."""

from controllers.base import SteeringController, saturate
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

__all__ = [
    "SteeringController",
    "saturate",
    "ComputedTorque",
    "PDController",
    "make_controller",
    "model_from_source",
    "gains_from_omega_r",
    "MODEL_SOURCES",
    "CONTROLLER_NAMES",
    "FRICTION_SIGNS",
]
