"""wmr-mj: a MuJoCo validation testbed for computed-torque steering control of the C80 cart.

The top level is the library's public API, enough for a notebook::

    import wmr_mj as wm

    result = wm.run_closed_loop(wm.RunConfig(**wm.CERTIFIED.config_changes(), m1=700.0))
    result.plot().figure    # E, E' and the voltage between their bounds, C's path (docs/guides/notebook.md)
    result.summary.verdict  # 'certified-inside': the summary is a frozen record, read by attribute

``result.to_pandas()`` is its rows, one per control step, with units (``pip install 'wmr-mj[notebook]'``).

The parameter set and the errors are imported at once; everything else (the simulation, sweeps,
the search, logs, the certificate) on first use (PEP 562), because ``controllers`` imports
``wmr_mj.params`` and an eager import of ``wmr_mj.sim`` from here would be circular.
"""

from __future__ import annotations

import importlib
import warnings
from typing import TYPE_CHECKING, Any

from wmr_mj.errors import (
    DurationError,
    InfeasiblePathError,
    LogError,
    ModelFileError,
    NoRenderBackendError,
    NotEnoughMemoryError,
    OutputPathError,
    ParameterError,
    SchedulerError,
    UnknownNameError,
    WmrMjError,
)
from wmr_mj.hardware import Actuation, Sensing, SensingChain, Transmission, sensing_preset_names
from wmr_mj.params import C80, C80Parameters, Coefficients, parameter_names, with_params

from ._version import __version__ as __version__

if TYPE_CHECKING:
    from wmr_mj.carts import CartFile, load_cart
    from wmr_mj.experiments.compare import CompareResult, Design, DesignRow, compare, design_from_token
    from wmr_mj.experiments.suite import load_suite
    from wmr_mj.experiments.sweep import SweepSpec, SweepSummary
    from wmr_mj.experiments.sweep_result import SweepResult, sweep
    from wmr_mj.experiments.tightness import CartTightness, cart_tightness
    from wmr_mj.figures.results import ResultPlot
    from wmr_mj.logs.reader import load_log
    from wmr_mj.logs.writer import LogOptions, RunLogger
    from wmr_mj.report.results import ValidateSummary
    from wmr_mj.searches.design_search import DesignProblem, DesignResult, search_design, write_design
    from wmr_mj.searches.falsify import FalsifyResult, FalsifySpec, falsify
    from wmr_mj.sim.certify import certificate_for
    from wmr_mj.sim.closed_loop import RunResult, run_closed_loop
    from wmr_mj.sim.config import RunConfig, controller_for
    from wmr_mj.sim.designs import CERTIFIED, CERTIFIED_C80, PAPER, PRESETS, preset
    from wmr_mj.sim.log_header import LogHeader
    from wmr_mj.sim.parts import RunParts, resolve_run
    from wmr_mj.sim.signals import Disturbance, LoadChange, Signals

#: name -> the module that defines it, imported on first access (PEP 562, :func:`__getattr__`). Deliberately lazy,
#: not an oversight of "imports at module top": ``import wmr_mj`` runs first for every ``wmr-mj`` command, so an
#: eager import here would load MuJoCo, scipy and the laws before ``wmr-mj --help`` answers (tests/test_cli_help.py),
#: and ``controllers`` imports ``wmr_mj.params``, so importing ``wmr_mj.sim`` from here would be circular
_LAZY: dict[str, str] = {
    "RunConfig": "wmr_mj.sim.config",
    "controller_for": "wmr_mj.sim.config",
    "run_closed_loop": "wmr_mj.sim.closed_loop",
    "RunResult": "wmr_mj.sim.closed_loop",
    "certificate_for": "wmr_mj.sim.certify",
    "SweepSpec": "wmr_mj.experiments.sweep",
    "SweepSummary": "wmr_mj.experiments.sweep",
    "sweep": "wmr_mj.experiments.sweep_result",
    "SweepResult": "wmr_mj.experiments.sweep_result",
    "FalsifySpec": "wmr_mj.searches.falsify",
    "falsify": "wmr_mj.searches.falsify",
    "FalsifyResult": "wmr_mj.searches.falsify",
    "ValidateSummary": "wmr_mj.report.results",
    "PAPER": "wmr_mj.sim.designs",
    "CERTIFIED": "wmr_mj.sim.designs",
    "CERTIFIED_C80": "wmr_mj.sim.designs",
    "PRESETS": "wmr_mj.sim.designs",
    "preset": "wmr_mj.sim.designs",
    "load_log": "wmr_mj.logs.reader",
    "Signals": "wmr_mj.sim.signals",
    "Disturbance": "wmr_mj.sim.signals",
    "LoadChange": "wmr_mj.sim.signals",
    "RunLogger": "wmr_mj.logs.writer",
    "LogHeader": "wmr_mj.sim.log_header",
    "LogOptions": "wmr_mj.logs.writer",
    "resolve_run": "wmr_mj.sim.parts",
    "RunParts": "wmr_mj.sim.parts",
    "load_suite": "wmr_mj.experiments.suite",
    "compare": "wmr_mj.experiments.compare",
    "CompareResult": "wmr_mj.experiments.compare",
    "DesignRow": "wmr_mj.experiments.compare",
    "Design": "wmr_mj.experiments.compare",
    "design_from_token": "wmr_mj.experiments.compare",
    "ResultPlot": "wmr_mj.figures.results",
    "load_cart": "wmr_mj.carts",
    "CartFile": "wmr_mj.carts",
    "DesignProblem": "wmr_mj.searches.design_search",
    "DesignResult": "wmr_mj.searches.design_search",
    "search_design": "wmr_mj.searches.design_search",
    "write_design": "wmr_mj.searches.design_search",
    "cart_tightness": "wmr_mj.experiments.tightness",
    "CartTightness": "wmr_mj.experiments.tightness",
}

__all__ = [
    # parameters
    "C80",
    "C80Parameters",
    "Coefficients",
    "parameter_names",
    "with_params",
    # one run, its controller and its certificate
    "RunConfig",
    "run_closed_loop",
    "RunResult",
    "controller_for",
    "certificate_for",
    "resolve_run",
    "RunParts",
    # the cart as it is built: the steering sensor, the motor's actuation, the gear's play
    "Sensing",
    "SensingChain",
    "Actuation",
    "Transmission",
    "sensing_preset_names",
    # a cart of your own (a TOML file: wmr_mj/carts/c80.toml to copy; RunConfig(cart=...))
    "load_cart",
    "CartFile",
    # the gains a given cart can certify (wmr-mj design), and how tight a cart's claim is against the adversary
    "DesignProblem",
    "DesignResult",
    "search_design",
    "write_design",
    "cart_tightness",
    "CartTightness",
    # what acts on the plant during a run: a steering disturbance, load changes
    "Signals",
    "Disturbance",
    "LoadChange",
    # the design presets
    "PAPER",
    "CERTIFIED",
    "CERTIFIED_C80",
    "PRESETS",
    "preset",
    # many runs and the search for the worst, and what they add up to (frozen, read by attribute; to_dict/from_dict)
    "SweepSpec",
    "SweepSummary",
    "sweep",
    "SweepResult",
    "FalsifySpec",
    "falsify",
    "FalsifyResult",
    # one yardstick for every controller
    "load_suite",
    "compare",
    "CompareResult",
    "DesignRow",
    "Design",
    "design_from_token",
    # a result in a notebook: .to_pandas() (pip install 'wmr-mj[notebook]'), .plot() -> ResultPlot, _repr_html_
    "ResultPlot",
    # the headline validation's summary (wmr-mj validate; summary.json is its to_dict())
    "ValidateSummary",
    # logs
    "RunLogger",
    "LogHeader",
    "LogOptions",
    "load_log",
    # errors
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


#: names kept at the top level for one release, each with its module and what to use instead: a warning on use
_DEPRECATED = {
    "run_sweep": ("wmr_mj.experiments.sweep",
                  "wm.sweep(spec), whose .rows are these rows (or wmr_mj.experiments.sweep.run_sweep)"),
    # one result per command: the search's and the comparison's records are their results' to_dict(runs=False)
    "FalsifyReport": ("wmr_mj.searches.falsify",
                      "wm.FalsifyResult, read by attribute (to_dict(runs=False) is its JSON)"),
    "CompareReport": ("wmr_mj.experiments.compare",
                      "wm.CompareResult, read by attribute (to_dict(runs=False) is its JSON)"),
}


def __getattr__(name: str) -> Any:
    """A public name of :data:`_LAZY`, its module imported on this first access (lazy on purpose: see
    :data:`_LAZY`); a name of :data:`_DEPRECATED`, with a warning at every use."""
    if name in _DEPRECATED:  # not cached: every use warns
        where, instead = _DEPRECATED[name]
        warnings.warn(f"wmr_mj.{name} is deprecated and leaves the top level in the next release; use {instead}",
                      DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(where), name)
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'wmr_mj' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # the next access skips this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
