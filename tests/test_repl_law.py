"""A law written in a REPL (a class of a ``__main__`` module without a file) runs and records no source hash.

``python -c``, the interactive interpreter and a pytest-xdist worker have such a ``__main__``:
``inspect.getsourcefile`` raises OSError there, not TypeError (docs/guides/plugins.md's example,
run by tests/test_docs.py under ``make test``'s two workers, defines its law so).
"""

from __future__ import annotations

import sys
import types

import pytest

from controllers import SteeringController
from controllers.registry import source_hash
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig, controller_source


@pytest.fixture
def repl_law(monkeypatch):
    """A law class whose module is a ``__main__`` without ``__file__``, as a REPL makes it."""
    monkeypatch.setitem(sys.modules, "__main__", types.ModuleType("__main__"))

    class ReplPD(SteeringController):
        name = "repl-pd"

        def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
            return 0.385 * (alpha0_ddot + 15.0 * (alpha0_dot - alpha_dot) + 50.0 * (alpha0 - alpha))

    ReplPD.__module__ = "__main__"
    return ReplPD


def test_a_law_made_in_a_repl_has_no_source_hash(repl_law):
    import inspect

    with pytest.raises(OSError):  # what the hash must not pass on
        inspect.getsourcefile(repl_law)
    assert source_hash(repl_law) is None


def test_a_law_made_in_a_repl_runs_and_says_it_has_no_source(repl_law):
    result = run_closed_loop(RunConfig(controller=repl_law(), path="lane-change", duration=2.5), progress=False)
    assert result.status == "completed" and result.summary.sup_E > 0.0
    source = controller_source(result.config)  # what the run's JSON and log record of the law
    assert source["name"] == "repl-pd" and source["source_sha256"] is None
