"""wmr-mj: a MuJoCo validation testbed for computed-torque steering control of the C80 cart."""

from .errors import (
    InfeasiblePathError,
    LogError,
    ModelFileError,
    ParameterError,
    SchedulerError,
    UnknownNameError,
    WmrMjError,
)
from .params import C80, C80Parameters, Coefficients, parameter_names, with_params

__version__ = "0.1.0"

__all__ = [
    "C80",
    "C80Parameters",
    "Coefficients",
    "parameter_names",
    "with_params",
    "WmrMjError",
    "ParameterError",
    "UnknownNameError",
    "ModelFileError",
    "InfeasiblePathError",
    "LogError",
    "SchedulerError",
]
