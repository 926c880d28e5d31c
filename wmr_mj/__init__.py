"""wmr-mj: a MuJoCo validation testbed for computed-torque steering control of the C80 cart."""

from wmr_mj.errors import (
    InfeasiblePathError,
    LogError,
    ModelFileError,
    ParameterError,
    SchedulerError,
    UnknownNameError,
    WmrMjError,
)
from wmr_mj.params import C80, C80Parameters, Coefficients, parameter_names, with_params

from ._version import __version__ as __version__

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
