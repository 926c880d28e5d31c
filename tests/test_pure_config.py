"""RunConfig as data (issue 41 item 1): constructing or ``replace``-ing a RunConfig opens no file and imports no
module -- for built-in names and typed parts, and for a cart name, a cart file, a plug-in and a route file, which
it keeps as references. ``RunConfig.from_inputs`` (``wmr_mj.sim.coerce.coerce``) reads them; ``resolve_run``
coerces a config given directly, once, and the run is the one ``from_inputs`` gives."""

import dataclasses
import json
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.reference.route import ROUTES_DIR
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.coerce import coerce, is_coerced
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.parts import resolve_run

ROOT = Path(__file__).resolve().parents[1]
CART_TOML = ROOT / "wmr_mj" / "carts" / "c80-magmotor.toml"
PLUGIN = "examples/my_pid.py:MyPID"

#: run in a fresh interpreter (an audit hook cannot be removed, and what the construction would import must not be
#: imported already by other tests). After the imports, an audit hook records every ``open`` (any file opened,
#: by Python or by a C extension through the audit API) and every ``import`` event while the configs named by
#: CONFIGS are constructed and replaced; the modules loaded are compared before and after.
_PROBE = textwrap.dedent('''
    import json, sys
    from wmr_mj.hardware import Sensing
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED
    from wmr_mj.sim.signals import Signals

    events = []
    watching = False

    def hook(event, args):
        if watching and event in ("open", "import"):
            events.append(event + " " + repr(args[0]))

    sys.addaudithook(hook)
    before = set(sys.modules)
    watching = True
    configs = [CONFIGS]
    replaced = [c.replace(duration=20.0, kp=120.0) for c in configs]
    watching = False
    print(json.dumps({"events": events, "new_modules": sorted(set(sys.modules) - before),
                      "models": [c.model for c in configs], "n": len(replaced)}))
''')

#: the configs of the Done-when line, and of issue 34 (built-in names, typed parts, spec strings)
_CONFIGS = ", ".join([
    "RunConfig()",
    "RunConfig(controller='sliding-mode', model='nonholonomic')",
    "RunConfig(controller='pd', model='nonholonomic', path='lane-change')",
    "RunConfig(**CERTIFIED.config_changes(), path='figure-eight', tracker='pure-pursuit')",
    "RunConfig(**CERTIFIED.config_changes(), correction=True, reference_bounds='paper')",
    "RunConfig(sensing='magnetic-12bit-axis', actuation='delay=0.002', transmission=0.002)",
    "RunConfig(sensing=Sensing(), signals=Signals.from_dict({'disturbance': {'kind': 'step', 'amplitude': 0.5, "
    "'t1': 1.0}}))",
    "RunConfig(signals={'loads': [{'kind': 'step', 't': 2.0, 'm1': 700.0}]})",
    "RunConfig(cart='c80-magmotor')",                      # a cart name
    f"RunConfig(cart={str(CART_TOML)!r})",                 # a cart file
    f"RunConfig(controller={PLUGIN!r})",                   # a plug-in
    "RunConfig(path='agv-loop')",                          # a packaged route
    f"RunConfig(path={str(ROUTES_DIR / 'agv-loop.toml')!r})",  # a route file
])


def _probe(configs: str) -> dict:
    out = subprocess.run([sys.executable, "-c", _PROBE.replace("CONFIGS", configs)], capture_output=True, text=True,
                         check=True, cwd=ROOT)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_constructing_and_replacing_opens_no_file_and_imports_no_module():
    seen = _probe(_CONFIGS)
    assert seen["events"] == []
    assert seen["new_modules"] == []
    assert seen["n"] == 13
    # a model not given is left to the law: None until coerced (the law's default is its class's, which a plug-in
    # would have to import); a given one is kept
    assert seen["models"][:2] == [None, "nonholonomic"]


def test_the_probe_can_fail():
    """The same probe sees from_inputs open the cart file, import the plug-in and read the route (a probe that
    cannot fail proves nothing)."""
    seen = _probe("RunConfig.from_inputs(cart='c80-magmotor')")
    assert any(e.startswith("open") and "c80-magmotor.toml" in e for e in seen["events"])
    seen = _probe(f"RunConfig.from_inputs(controller={PLUGIN!r})")
    assert any("my_pid.py" in e for e in seen["events"])
    assert any(m.startswith("wmr_mj_plugin_") for m in seen["new_modules"])
    seen = _probe("RunConfig.from_inputs(path='agv-loop')")
    assert any("agv-loop.toml" in e for e in seen["events"])


def test_a_config_has_no_mutable_cache():
    """Frozen data: every field is an init field (no cache written behind the dataclass's back)."""
    fields = dataclasses.fields(RunConfig)
    assert all(f.init for f in fields)
    assert not hasattr(RunConfig(), "__dict__") or set(vars(RunConfig())) == {f.name for f in fields}


def test_from_inputs_is_the_coerced_config(tmp_path):
    """from_inputs reads a cart, a plug-in, a route and a signals file; coerce of the same config given directly
    is the same config, and coercing it again changes nothing."""
    signals = {"disturbance": {"kind": "step", "amplitude": 0.5, "t1": 1.0}}
    (tmp_path / "signals.json").write_text(json.dumps(signals))
    inputs = {"controller": PLUGIN, "signals": str(tmp_path / "signals.json"), "duration": 20.0,
              "cart": "c80-magmotor", "path": "agv-loop"}
    given = RunConfig(**inputs)
    assert not is_coerced(given) and given.cart == "c80-magmotor" and given.m1 is None
    coerced = RunConfig.from_inputs(**inputs)
    assert is_coerced(coerced)
    assert coerce(given) == coerced
    assert coerce(coerced) == coerced
    assert coerced.signals == RunConfig.from_inputs(signals=signals).signals
    assert coerced.cart["name"] == "C80 with a Magmotor C40-A-200FX and a Beckhoff NP045 32:1"
    assert coerced.controller_plugin.name == "my-pid"
    assert given.to_dict() == coerced.to_dict()  # to_dict of a direct config coerces it first


def test_a_replaced_plug_in_is_found_again():
    """A coerced config replaced with another law holds that law's source after coercion (no stale record)."""
    coerced = RunConfig.from_inputs(controller=PLUGIN)
    back = coerce(coerced.replace(controller="sliding-mode", model="nonholonomic"))
    assert back.controller_plugin.name == "sliding-mode"
    assert coerce(back.replace(controller="computed-torque")).controller_plugin is None


@pytest.mark.parametrize("inputs, error", [({"controller": "no-such-law"}, UnknownNameError),
                                           ({"path": "nowhere"}, UnknownNameError),
                                           ({"signals": "/no/such/signals.json"}, ParameterError),
                                           ({"cart": "/no/such/cart.toml"}, ParameterError)])
def test_bad_references_are_refused_where_they_are_read(inputs, error):
    """A reference is checked where it is read: by from_inputs (the commands, before any run) and by resolve_run
    (a config given directly); a bad value that needs no file is refused at construction."""
    with pytest.raises(error):
        RunConfig.from_inputs(**inputs)
    with pytest.raises(error):
        resolve_run(RunConfig(**inputs))


@pytest.mark.parametrize("inputs", [{"kp": -1.0}, {"model": "nope"}, {"m1_range": (700.0, 600.0)},
                                    {"controller": "pd", "controller_params": {"x": 1}}])
def test_bad_values_are_refused_at_construction(inputs):
    with pytest.raises((ParameterError, UnknownNameError)):
        RunConfig(**inputs)


def test_a_run_from_a_direct_config_is_the_run_from_inputs(tmp_path):
    """resolve_run reads a direct config's references once, and the run gives the numbers from_inputs gives: a cart
    file, a plug-in and a route file, with the route given by a copy of the packaged file."""
    route = tmp_path / "loop.toml"
    shutil.copy(ROUTES_DIR / "agv-loop.toml", route)
    inputs = {"controller": PLUGIN, "cart": str(CART_TOML), "path": str(route), "duration": 2.0}
    direct, coerced = resolve_run(RunConfig(**inputs)), resolve_run(RunConfig.from_inputs(**inputs))
    assert direct.config == coerced.config
    assert direct.record == coerced.record
    assert direct.plant == coerced.plant and direct.estimate == coerced.estimate
    np.testing.assert_array_equal(direct.reference.alpha0, coerced.reference.alpha0)
    assert direct.controller_name == "my-pid" and direct.measurement == coerced.measurement
    a = run_closed_loop(RunConfig(**inputs), progress=False)
    b = run_closed_loop(RunConfig.from_inputs(**inputs), progress=False)
    timing = ("wall_s", "realtime_factor")  # the machine's clock, not the run's numbers
    assert ({k: v for k, v in a.summary.to_dict().items() if k not in timing}
            == {k: v for k, v in b.summary.to_dict().items() if k not in timing})


def test_measurement_errors_are_derived_once_per_resolution(monkeypatch):
    """resolve_run derives the cart's measurement errors once and hands them to the law's claim (issue 41 item 3);
    the claim is the one certificate_for derives alone (which computes the errors itself)."""
    import wmr_mj.sim.certify as certify
    from wmr_mj.analysis.measurement import MeasurementErrors

    config = RunConfig(sensing="magnetic-12bit-axis", actuation="delay=0.002", path="lane-change", duration=5.0)
    calls = []
    real = certify.measurement_errors  # the typed core that measurement_errors_of unpacks a config into

    def counting(*args, **kwargs):
        calls.append(args[0])
        return real(*args, **kwargs)

    monkeypatch.setattr(certify, "measurement_errors", counting)
    parts = resolve_run(config)
    assert len(calls) == 1
    assert parts.measurement != MeasurementErrors.exact()
    alone = certify.certificate_for(config, parts.reference)
    assert len(calls) == 2  # certificate_for derives its own
    assert parts.claim.E_max == alone.E_max and parts.claim.inputs == alone.inputs
