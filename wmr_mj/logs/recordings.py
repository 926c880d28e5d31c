"""A wmr-mj run's MCAP log as a recording for identification (``wmr-mj identify --data run.mcap``).

The log carries what identification needs: the time and the applied voltage at every logged row (/signals),
the angle the law read at every control step (/measured, a sensed run; an ideal run's law read the exact
angle of /signals), and the chassis mass m1 of the run (its parameters). A log written with ``--log-every``
above 1 has the voltage of every k-th step only: refused, in one line.

Usage::

    from wmr_mj.logs.recordings import read_run_log
    rec = read_run_log("logs/run.mcap")          # rec.m1: the run's chassis mass
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from wmr_mj.errors import ParameterError
from wmr_mj.logs.reader import load_log
from wmr_mj.plant.recordings import Recording, file_sha256

__all__ = ["read_run_log"]


def read_run_log(path: str | Path, *, m1: float | None = None) -> Recording:
    """The recording a run's log holds: t, the applied voltage, the angle the law read; m1 the run's.

    Args:
        path: the MCAP log of a ``wmr-mj run``.
        m1: chassis mass, kg (None: the run's, from the log's parameters).

    Raises:
        ParameterError: a log that cannot be read, or one logged every k-th step (k > 1).
        wmr_mj.errors.LogError: a corrupt or unsupported file.
    """
    log = load_log(path)
    if log.log_every != 1:
        raise ParameterError(f"recording {str(path)!r}: the run logged every {log.log_every}th step; accepted: a log "
                             "of every control step (wmr-mj run --log-every 1, the default)")
    signals = log.signals
    measured = log.measured
    alpha = measured["alpha_measured"] if measured is not None else signals["alpha"]
    n = min(signals["t"].size, alpha.size)
    mass = float(log.parameters["m1"]) if m1 is None else m1
    return Recording(name=str(path), sha256=file_sha256(path), t=np.asarray(signals["t"][:n], float),
                     voltage=np.asarray(signals["voltage"][:n], float), alpha=np.asarray(alpha[:n], float),
                     speed=None, m1=mass)
