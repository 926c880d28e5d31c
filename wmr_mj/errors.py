"""Exception hierarchy of wmr-mj.

Every error a user can cause by bad input derives from :class:`WmrMjError`; the
CLI prints its message as one line and exits with status 2. Messages name the
culprit and what is accepted.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = [
    "WmrMjError",
    "ParameterError",
    "DurationError",
    "UnknownNameError",
    "ModelFileError",
    "InfeasiblePathError",
    "LogError",
    "SchedulerError",
    "OutputPathError",
    "NotEnoughMemoryError",
    "NoRenderBackendError",
]


class WmrMjError(Exception):
    """Base class of every user-facing wmr-mj error."""


class ParameterError(WmrMjError, ValueError):
    """A parameter value is out of its accepted range (non-positive, non-finite...)."""


class DurationError(ParameterError):
    """A run's duration is refused: the path, the control period or a delay does not fit in it. The command line
    says where a refused duration came from (the command's default where none was given)."""


class UnknownNameError(WmrMjError, KeyError):
    """A name (parameter, model source, controller, channel...) is not known.

    The message lists the valid names.
    """

    def __init__(self, kind: str, name: str, valid: Iterable[str]):
        self.kind = kind
        self.name = name
        self.valid = sorted(valid)
        super().__init__(
            f"unknown {kind} {name!r}; valid {kind}s: {', '.join(self.valid)}"
        )

    def __str__(self) -> str:  # KeyError would quote the message
        return self.args[0]


class ModelFileError(WmrMjError):
    """A model file is missing or MuJoCo cannot compile it."""


class InfeasiblePathError(WmrMjError, ValueError):
    """A reference path violates the steering range, rate or acceleration limit."""


class StiffReferenceError(InfeasiblePathError):
    """A reference whose integration would not end in bounded time (a wheelbase tiny against the path)."""


class LogError(WmrMjError):
    """An MCAP log is missing, not MCAP, corrupt, or of an unknown schema version."""


class SchedulerError(WmrMjError):
    """A Dask scheduler cannot be reached or used."""


class OutputPathError(WmrMjError):
    """An output file or folder cannot be created or written (missing permission, a file in
    the way, a read-only file system)."""


class NotEnoughMemoryError(WmrMjError):
    """A job would need more memory than the machine has available; refused before it starts."""


class NoRenderBackendError(WmrMjError):
    """No OpenGL backend (EGL, OSMesa) can render offscreen on this machine."""
