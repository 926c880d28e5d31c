"""One run, one resolution: ``wmr-mj run`` builds each law once and computes each claim once.

The counter wraps each law class's constructor and its ``claim`` (a deep copy does not call the
constructor, so only a build counts), keyed by the law's class and its estimate's model source: a run of
the paper's design builds the computed-torque law on the paper's model once; where the run's note asks
what the law would claim on the other estimate (``no_estimate_note``), that other law is built once too.
"""

from __future__ import annotations

import collections
from pathlib import Path

import pytest

from controllers.adaptive import AdaptiveComputedTorque
from controllers.computed_torque import ComputedTorque, PDController
from controllers.registry import resolve
from controllers.sliding_mode import SlidingMode
from wmr_mj.cli.app import main

REPO = Path(__file__).resolve().parents[1]
MY_PID = f"{REPO / 'examples' / 'my_pid.py'}:MyPID"


def _key(law) -> tuple[str, str | None]:
    model = getattr(law, "model", None)
    return type(law).__name__, getattr(model, "name", None)


@pytest.fixture
def counted(monkeypatch):
    """(builds, claims): Counters of (law class, model source) filled by every law built and claim computed."""
    builds: collections.Counter = collections.Counter()
    claims: collections.Counter = collections.Counter()
    classes = [ComputedTorque, PDController, SlidingMode, AdaptiveComputedTorque, resolve(MY_PID)[0]]
    for cls in classes:
        def init(self, *args, __init=cls.__init__, __cls=cls, **kwargs):
            __init(self, *args, **kwargs)
            if type(self) is __cls:
                builds[_key(self)] += 1

        monkeypatch.setattr(cls, "__init__", init)
        if "claim" in vars(cls):
            def claim(self, context, __claim=cls.claim):
                claims[_key(self)] += 1
                return __claim(self, context)

            monkeypatch.setattr(cls, "claim", claim)
    return builds, claims


@pytest.mark.slow
@pytest.mark.parametrize("options", [
    [],  # the paper's design
    ["--preset", "certified"],
    ["--controller", "sliding-mode"],
    ["--controller", "adaptive-computed-torque"],
    ["--controller", "pd"],
    ["--controller", MY_PID],
], ids=["paper", "certified", "sliding-mode", "adaptive", "pd", "plug-in"])
def test_a_run_builds_each_law_once_and_computes_each_claim_once(counted, options, capsys):
    builds, claims = counted
    assert main(["run", "--no-log", "--duration", "10", "--json", *options]) in (0, 3)
    assert builds, "no law was built: the counter missed the run's law"
    assert set(builds.values()) == {1}, f"a law built more than once: {dict(builds)}"
    assert set(claims.values()) <= {1}, f"a claim computed more than once: {dict(claims)}"
    assert set(claims) <= set(builds), f"a claim of a law never built: {dict(claims)}"


def test_a_plugin_is_imported_and_hashed_once_per_resolution(monkeypatch):
    """A plug-in given by name is a reference: constructing its config hashes nothing, resolve_run finds it once
    (imported, its source hashed), and to_dict, controller_name and the run's record read what was found; the
    record is the one a fresh resolution gives."""
    import controllers.registry as registry
    from wmr_mj.sim.config import RunConfig, controller_name, controller_source
    from wmr_mj.sim.parts import resolve_run

    hashed: list[type] = []
    real = registry.source_hash

    def counting(cls):
        hashed.append(cls)
        return real(cls)

    monkeypatch.setattr(registry, "source_hash", counting)
    config = RunConfig(controller=MY_PID, controller_params={"ki": 20.0}, duration=10.0)
    assert hashed == []
    parts = resolve_run(config)
    assert len(hashed) == 1, f"hashed again: {hashed}"
    first = parts.config.to_dict()
    assert first == parts.record and controller_name(parts.config) == "my-pid"
    assert len(hashed) == 1, f"hashed again: {hashed}"
    _, fresh = resolve(MY_PID, {"ki": 20.0})
    assert first["controller_plugin"] == fresh.to_dict() == controller_source(parts.config)


class _Reads:
    """A RunConfig that records which of its fields are read (and hands them out)."""

    def __init__(self, config) -> None:
        object.__setattr__(self, "_config", config)
        object.__setattr__(self, "read", set())

    def __getattr__(self, name):
        self.read.add(name)
        return getattr(self._config, name)


class _Header:
    """A logger that keeps the run's header (what the log would record) and drops the rows."""

    last: object = None

    def __init__(self, header) -> None:
        _Header.last = header

    def write_block(self, *args, **kwargs) -> None:
        pass

    def close(self, *args, **kwargs) -> None:
        pass


#: what run_parts may read of the config: nothing (its labels and its record, ``to_dict``, are read once by
#: resolve_run: RunParts.labels, RunParts.record)
RECORDED: set[str] = set()


@pytest.mark.slow
def test_below_resolve_run_the_config_is_only_recorded():
    """run_parts reads the typed parts (sensing, signals, reference bounds, route, labels, the config's record,
    ...) and no field of the config, nor its to_dict; the run's numbers are the same as run_closed_loop's."""
    import dataclasses

    import numpy as np

    from wmr_mj.sim.closed_loop import run_closed_loop, run_parts
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED
    from wmr_mj.sim.parts import resolve_run

    config = RunConfig(**CERTIFIED.config_changes(), path="lane-change", duration=5.0, sensing="magnetic-12bit-axis",
                       signals={"disturbance": {"kind": "step", "amplitude": 0.5, "t1": 1.0},
                                "loads": [{"kind": "step", "t": 2.0, "m1": 700.0}]},
                       reference_bounds="paper", correction=True)
    parts = resolve_run(config)
    spy = _Reads(config)
    seen = run_parts(dataclasses.replace(parts, config=spy), progress=False, logger_factory=_Header)
    assert spy.read <= RECORDED, f"read below resolve_run: {sorted(spy.read - RECORDED)}"
    assert _Header.last.config == config.to_dict()  # the log's record of the config, taken by resolve_run
    plain = run_closed_loop(config, progress=False)
    timing = ("wall_s", "realtime_factor")  # the two runs' clocks, the only keys that differ

    def numbers(result):
        return {k: v for k, v in result.summary.to_dict().items() if k not in timing}

    assert numbers(seen) == numbers(plain)
    assert all(np.array_equal(seen.rows[k], plain.rows[k], equal_nan=True) for k in plain.rows)


def test_the_coercer_hands_resolve_run_what_it_read():
    """coerce_with_classes reads each reference once and hands on what it read: the plug-in's class, the route, the
    cart's parameter set and the plant's, and the record to_dict writes -- each what the package that owns it
    gives on its own; resolve_run's parts are built from them."""
    from wmr_mj.carts import load_cart
    from wmr_mj.params import parameters_of_cart, with_params
    from wmr_mj.reference.route import load_route
    from wmr_mj.sim.coerce import coerce_with_classes
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.parts import resolve_run

    given = {"cart": "c80-magmotor", "path": "agv-loop", "controller": MY_PID, "controller_params": {"ki": 20.0},
             "m1": 700.0, "duration": 5.0}
    typed = coerce_with_classes(RunConfig(**given))
    assert typed.classes["controller"] is resolve(MY_PID)[0]
    assert typed.route.text == load_route("agv-loop").text
    assert typed.base == parameters_of_cart(load_cart("c80-magmotor"))
    assert typed.plant == with_params(typed.base, m1=700.0)
    assert typed.record == RunConfig.from_inputs(**given).to_dict()
    parts = resolve_run(RunConfig(**given))
    assert (parts.base, parts.plant, parts.record) == (typed.base, typed.plant, typed.record)
    assert parts.route_length_m == float(load_route("agv-loop").path.length)
