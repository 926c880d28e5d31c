"""The top level is the public API a notebook uses: every name in ``wmr_mj.__all__`` imports from it."""

from __future__ import annotations

import subprocess
import sys

import pytest

import wmr_mj


@pytest.mark.parametrize("name", wmr_mj.__all__)
def test_every_public_name_imports_from_the_top_level(name):
    namespace: dict[str, object] = {}
    exec(f"from wmr_mj import {name}", namespace)  # the statement a notebook writes
    assert namespace[name] is getattr(wmr_mj, name)
    assert name in dir(wmr_mj)


def test_the_lazy_names_are_the_defining_modules_own():
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.designs import CERTIFIED

    assert wmr_mj.run_closed_loop is run_closed_loop and wmr_mj.CERTIFIED is CERTIFIED


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        wmr_mj.nope  # noqa: B018
    with pytest.raises(ImportError):
        exec("from wmr_mj import nope", {})


def test_run_sweep_at_the_top_level_is_a_deprecated_alias():
    """The list-of-rows ``run_sweep`` leaves the top level (issue 41): kept one release, it warns on every use and
    names what replaces it; ``wm.sweep`` and the module's own ``run_sweep`` do not warn."""
    import warnings

    from wmr_mj.experiments.sweep import run_sweep

    assert "run_sweep" not in wmr_mj.__all__ and "sweep" in wmr_mj.__all__
    for _ in range(2):  # not cached: the second use warns too
        with pytest.warns(DeprecationWarning, match=r"wmr_mj\.run_sweep is deprecated.*wm\.sweep\(spec\)"):
            assert wmr_mj.run_sweep is run_sweep
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert wmr_mj.sweep is not None


def test_run_configs_old_name_for_to_dict_warns_and_returns_the_same():
    """RunConfig's dict had another name, documented in the api reference: kept one release with a warning."""
    config = wmr_mj.RunConfig(duration=5.0)
    with pytest.warns(DeprecationWarning, match=r"RunConfig\..*is deprecated.*use to_dict\(\)"):
        old = config.as_dict()  # deprecated alias: keep
    assert old == config.to_dict() and old["duration"] == 5.0


@pytest.mark.parametrize("first", ["import controllers", "import wmr_mj.params", "pass"])
def test_controllers_first_then_wmr_mj_in_a_fresh_interpreter(first):
    code = f"{first}\nimport wmr_mj\nprint(wmr_mj.RunConfig.__name__, wmr_mj.controller_for.__module__)"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["RunConfig", "wmr_mj.sim.builders"]  # where the law is built (sim/builders.py)


def test_importing_wmr_mj_loads_no_simulation():
    layers = ("wmr_mj.sim", "wmr_mj.searches", "wmr_mj.experiments", "wmr_mj.logs")
    code = f"import sys, wmr_mj; print(sorted(m for m in sys.modules if m.startswith({layers!r})))"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"
