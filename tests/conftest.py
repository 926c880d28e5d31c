"""Session fixtures: what several test files need alike is built once per test process.

Under pytest-xdist each worker is a process of its own, so each builds them once (``make test``
runs two workers). They are shared: treat them as read-only. A Reference's arrays are read-only
already; :func:`certified_run_10s` makes its row arrays read-only too, so a test that writes one
fails at once instead of changing the next test's input (copy the array first).

Helpers that are functions, not results, are in ``tests/helpers.py``.
"""

import os

import numpy as np
import pytest

os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture(scope="session")
def paper_reference():
    """C's reference on the paper's circle as a default run builds it: the nominal C80, a 1 ms grid,
    35 s (RunConfig's default duration)."""
    from wmr_mj import C80
    from wmr_mj.sim.config import build_reference

    return build_reference("paper-circle", C80, dt=1e-3, duration=35.0)[0]


@pytest.fixture(scope="session")
def certified_run_10s():
    """The certified design (``RunConfig(**CERTIFIED.config_changes())``) on the paper's circle for 10 s,
    its RunResult with read-only rows."""
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED

    result = run_closed_loop(RunConfig(**CERTIFIED.config_changes(), duration=10.0), progress=False)
    for array in (*result.rows.values(), result.C_xy):
        if isinstance(array, np.ndarray):
            array.flags.writeable = False
    return result
