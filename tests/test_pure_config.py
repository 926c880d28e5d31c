"""RunConfig as data (issue 34 item 1): constructing it from built-in names, named paths, typed parts and spec
strings reads no file and imports no module; what needs either (a plug-in by name, a route or signals file) is
coerced by ``RunConfig.from_inputs``, and ``RunConfig(...)`` given such input coerces it the same way."""

import json
import subprocess
import sys
import textwrap

import pytest

from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.sim.config import RunConfig

#: run in a fresh interpreter, so that what the construction would import is not already imported by other tests:
#: after the module is imported, every way to open or list a file and to import a module fails, and the modules
#: loaded are compared before and after
_NO_IO = textwrap.dedent('''
    import builtins, importlib, io, json, os, sys
    from wmr_mj.hardware import Sensing
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED
    from wmr_mj.sim.signals import Signals

    calls = []

    def refuse(name):
        def refused(*args, **kwargs):
            calls.append(name + repr(args[:1]))
            raise AssertionError(name + " called while constructing a RunConfig: " + repr(args[:1]))
        return refused

    before = set(sys.modules)
    saved = {}
    for owner, name in ((builtins, "open"), (io, "open"), (os, "open"), (os, "stat"), (os, "listdir"),
                        (os, "scandir"), (importlib, "import_module"), (builtins, "__import__")):
        saved[owner, name] = getattr(owner, name)
    real_import = builtins.__import__

    def no_new_import(name, globals=None, locals=None, fromlist=(), level=0):
        if name not in sys.modules:
            calls.append("import " + name)
        return real_import(name, globals, locals, fromlist, level)

    try:
        for owner, name in saved:
            setattr(owner, name, no_new_import if name == "__import__" else refuse(name))
        configs = [
            RunConfig(),
            RunConfig(controller="sliding-mode"),
            RunConfig(controller="adaptive-computed-torque", duration=20.0),
            RunConfig(controller="pd", model="nonholonomic", path="lane-change"),
            RunConfig(**CERTIFIED.config_changes(), path="figure-eight", tracker="pure-pursuit"),
            RunConfig(**CERTIFIED.config_changes(), correction=True, reference_bounds="paper"),
            RunConfig(sensing="magnetic-12bit-axis", actuation="delay=0.002", transmission=0.002),
            RunConfig(sensing=Sensing(), signals=Signals.from_dict({"disturbance": {"kind": "step", "amplitude": 0.5,
                                                                                     "t1": 1.0}})),
            RunConfig(signals={"loads": [{"kind": "step", "t": 2.0, "m1": 700.0}]}),
        ]
    finally:
        for (owner, name), value in saved.items():
            setattr(owner, name, value)
    print(json.dumps({"calls": calls, "new_modules": sorted(set(sys.modules) - before),
                      "models": [c.model for c in configs]}))
''')


def test_built_in_names_read_no_file_and_import_no_module():
    out = subprocess.run([sys.executable, "-c", _NO_IO], capture_output=True, text=True, check=True)
    seen = json.loads(out.stdout.strip().splitlines()[-1])
    assert seen["calls"] == []
    assert seen["new_modules"] == []
    # the laws' own default models, read from the registry's classes (controllers.base.SteeringController)
    assert seen["models"][:4] == ["paper", "nonholonomic", "nonholonomic", "nonholonomic"]


def test_the_probe_can_fail():
    """The same probe sees a plug-in's import and a route file's read (a probe that cannot fail proves nothing)."""
    probe = _NO_IO.replace("configs = [", "configs = [RunConfig(controller='examples/my_pid.py:MyPID'), ")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert out.returncode != 0 and "called while constructing a RunConfig" in out.stderr
    probe = _NO_IO.replace("configs = [", "configs = [RunConfig(path='agv-loop'), ")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert out.returncode != 0 and "called while constructing a RunConfig" in out.stderr


def test_from_inputs_coerces_what_needs_a_file_or_an_import(tmp_path):
    """The coercer reads a signals file and imports a plug-in; RunConfig(...) given the same coerces it alike."""
    signals = {"disturbance": {"kind": "step", "amplitude": 0.5, "t1": 1.0}}
    (tmp_path / "signals.json").write_text(json.dumps(signals))
    inputs = {"controller": "examples/my_pid.py:MyPID", "signals": str(tmp_path / "signals.json"), "duration": 20.0}
    coerced = RunConfig.from_inputs(**inputs)
    assert coerced == RunConfig(**inputs)
    assert coerced.signals == RunConfig(signals=signals).signals
    assert coerced.as_dict()["controller_plugin"]["name"] == RunConfig(**inputs).as_dict()["controller_plugin"]["name"]


@pytest.mark.parametrize("inputs, error", [({"controller": "no-such-law"}, UnknownNameError),
                                           ({"path": "nowhere"}, UnknownNameError),
                                           ({"signals": "/no/such/signals.json"}, ParameterError)])
def test_bad_input_is_refused_at_construction(inputs, error):
    with pytest.raises(error):
        RunConfig(**inputs)
    with pytest.raises(error):
        RunConfig.from_inputs(**inputs)
