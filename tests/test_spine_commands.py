"""Every command builds its laws and references through the spine, each once per resolution (issue 41: "resolve_run
builds everything ... a test counts constructions over run, sweep, falsify, compare, design and validate").

The counter wraps each built-in law's constructor and ``claim``. At each call it looks up the Python stack:

- a law must be built by the spine's one builder, ``wmr_mj.sim.builders.law_and_settings`` (which
  ``resolve_run`` calls, and a design search calls on the parts resolve_run resolved, once per candidate law);
- a claim must be computed by the spine's one caller of claims, ``wmr_mj.sim.certify.law_certificate``;
- within one ``resolve_run`` call, each (law class, estimate's model) is built once and claims once.

Likewise C's reference: ``wmr_mj.reference.named.build_reference`` is wrapped where every module holds it, and each
call must come from the spine's one builder of a run's reference, ``wmr_mj.reference.named.run_reference`` (which
``resolve_run`` calls once per resolution; a log's replay, the certified design's rule, validate's path summary and
cart check's feasibility probe call it for a 35 s or the run's own reference on the 1 ms grid, as a run builds it).

``resolve_run`` is counted by wrapping it where every imported module holds it (the modules import it by name),
after importing every command's implementation, so each call is one numbered resolution.

The one law and the one reference built past the spine, named here: the paper's view in ``validate``
(``report/paper_example.py``), the law run on the reduced paper model with its estimate at a corner of the paper's
(5.1) box and the plant at the other, on its own reference of the paper circle: no MuJoCo run and no RunConfig's.
"""

from __future__ import annotations

import collections
import functools
import importlib
import itertools
import sys
import threading
from pathlib import Path

import pytest

from controllers.adaptive import AdaptiveComputedTorque
from controllers.computed_torque import ComputedTorque, PDController
from controllers.sliding_mode import SlidingMode
from wmr_mj.cli.app import COMMANDS as CLI_COMMANDS
from wmr_mj.cli.app import main
from wmr_mj.params import C80
from wmr_mj.reference import named
from wmr_mj.sim import config, parts

PACKAGE = Path(parts.__file__).parents[1]
#: the spine's one builder of laws, its one caller of a law's claim, and the law built past it on purpose
BUILDER = ("law_and_settings", str(PACKAGE / "sim" / "builders.py"))
CLAIMER = ("law_certificate", str(PACKAGE / "sim" / "certify.py"))
#: the spine's one builder of a run's reference (resolve_run's, and where a reference is needed without a run)
REFERENCER = ("run_reference", str(PACKAGE / "reference" / "named.py"))
PAPER_VIEW = ("paper_example", str(PACKAGE / "report" / "paper_example.py"))


def _above(*functions: tuple[str, str]) -> bool:
    """Whether a frame of one of ``functions`` (name, file) is on the stack above the caller."""
    frame = sys._getframe(2)
    while frame is not None:
        if (frame.f_code.co_name, frame.f_code.co_filename) in functions:
            return True
        frame = frame.f_back
    return False


@pytest.fixture
def counted(monkeypatch):
    """(builds, claims, references, outside): Counters of (resolution number or None, law class, model source),
    a Counter of the references built by resolution number (or None), and the laws built, claims computed or
    references built past the spine."""
    for name in CLI_COMMANDS:  # every command's implementation imported, so it holds resolve_run before the wrap
        importlib.import_module(f"wmr_mj.cli.{name}")
    # each thread's own stack of the resolutions under way (compare runs its scenarios in threads: a shared stack
    # would count one thread's reference against the other's resolution)
    local = threading.local()

    def stack() -> list[int]:
        if not hasattr(local, "resolving"):
            local.resolving = []
        return local.resolving

    numbers = itertools.count()
    original = parts.resolve_run

    @functools.wraps(original)
    def resolve_run(*args, **kwargs):
        stack().append(next(numbers))
        try:
            return original(*args, **kwargs)
        finally:
            stack().pop()

    holders = [m for m in list(sys.modules.values()) if getattr(m, "resolve_run", None) is original]
    assert len(holders) > 10  # the spine's users: run, sweep, falsify, compare, design, validate, ...
    for module in holders:
        monkeypatch.setattr(module, "resolve_run", resolve_run)

    builds: collections.Counter = collections.Counter()
    claims: collections.Counter = collections.Counter()
    references: collections.Counter = collections.Counter()
    outside: list[str] = []

    original_reference = named.build_reference

    @functools.wraps(original_reference)
    def build_reference(path, *args, **kwargs):
        if not _above(REFERENCER, PAPER_VIEW):
            outside.append(f"reference of {path!r}")
        references[stack()[-1] if stack() else None] += 1
        return original_reference(path, *args, **kwargs)

    holders = [m for m in list(sys.modules.values()) if getattr(m, "build_reference", None) is original_reference]
    assert named in holders  # where run_reference finds it
    for module in holders:
        monkeypatch.setattr(module, "build_reference", build_reference)

    def key(law) -> tuple:
        return (stack()[-1] if stack() else None, type(law).__name__,
                getattr(getattr(law, "model", None), "name", None))

    for cls in (ComputedTorque, PDController, SlidingMode, AdaptiveComputedTorque):
        def init(self, *args, __init=cls.__init__, __cls=cls, **kwargs):
            __init(self, *args, **kwargs)
            if type(self) is __cls:
                if not _above(BUILDER, PAPER_VIEW):
                    outside.append(f"built {key(self)[1:]}")
                builds[key(self)] += 1

        monkeypatch.setattr(cls, "__init__", init)
        if "claim" in vars(cls):
            def claim(self, context, __claim=cls.claim):
                if not _above(CLAIMER):
                    outside.append(f"claim of {key(self)[1:]}")
                claims[key(self)] += 1
                return __claim(self, context)

            monkeypatch.setattr(cls, "claim", claim)
    return builds, claims, references, outside


COMMANDS = {
    "run": ["run", "--no-log", "--duration", "10", "--preset", "certified"],
    "sweep": ["sweep", "--n", "2", "--duration", "10", "--preset", "certified", "--nthread", "1"],
    "falsify": ["falsify", "--preset", "certified", "--duration", "10", "--budget", "5", "--uncertainty", "m1"],
    "compare": ["compare", "paper", "certified", "--budget", "0", "--scenarios", "lane/nominal/none"],
    "design": ["design", "--budget", "4", "--duration", "10"],
    "validate": ["validate", "--n", "1", "--duration", "10", "--search-budget", "0", "--identify-duration", "2"],
}


@pytest.mark.slow
@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_law_a_command_builds_is_built_by_the_spine_once_per_resolution(command, counted, tmp_path,
                                                                              monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    builds, claims, references, outside = counted
    argv = COMMANDS[command]
    if command != "run":
        argv = [*argv, "--out", str(tmp_path / ("design.json" if command == "design" else "out"))]
    assert main(argv) in (0, 1, 3), capsys.readouterr().err
    assert any(key[0] is not None for key in builds), "no law was built by a resolution: the counter missed it"
    assert outside == [], f"{command}: built or claimed past the spine: {outside}"
    resolved = {key: n for key, n in builds.items() if key[0] is not None}
    assert set(resolved.values()) == {1}, f"{command}: a law built twice in one resolution: {resolved}"
    resolved = {key: n for key, n in claims.items() if key[0] is not None}
    assert set(resolved.values()) <= {1}, f"{command}: a claim computed twice in one resolution: {resolved}"
    resolved = {key: n for key, n in references.items() if key is not None}
    assert resolved and set(resolved.values()) == {1}, f"{command}: references by resolution: {resolved}"


def test_the_counter_sees_a_reference_built_past_the_spine(counted):
    """The reference counter itself: a reference built by ``build_reference`` where a module holds it (as a
    command's module would, importing it from the config) is counted outside; the spine's builder's is not."""
    _, _, references, outside = counted
    parts.run_reference("lane-change", C80, period=1e-3, duration=2.0)
    assert outside == [] and references[None] == 1
    config.build_reference("lane-change", C80, dt=1e-3, duration=2.0)
    assert outside == ["reference of 'lane-change'"] and references[None] == 2
