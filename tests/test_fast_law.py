"""A plug-in's pure law function compiled by numba into the control callback (wmr_mj.sim.compiled_law, kind 2):
the same bits as its Python path (single runs and a batch), a NaN failing the run as in Python, and the Python
path, saying why, where numba is missing, the law offers no function, numba cannot compile it or the law has state."""

from __future__ import annotations

import decimal
import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from controllers import SteeringController
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError
from wmr_mj.sim import compiled_law
from wmr_mj.sim.batch import batch_law_backend, run_batch
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig

REPO = Path(__file__).resolve().parents[1]
HAS_NUMBA = importlib.util.find_spec("numba") is not None
needs_numba = pytest.mark.skipif(not HAS_NUMBA, reason="numba is not installed (pip install 'wmr-mj[fast]')")
needs_compiled = pytest.mark.skipif(compiled_law.unavailable_reason() is not None,
                                    reason=f"the compiled law cannot run: {compiled_law.unavailable_reason()}")
KEYS = ("sup_E", "sup_Edot", "sup_E_settled", "sup_Edot_settled", "E_max", "Edot_max", "saturated_fraction",
        "final_alpha", "inside", "left_steering_range", "left_steering_range_at_s", "drift", "mujoco_warnings")


class FastLaw(SteeringController):
    """A computed-torque-like law as a pure function: feedforward, gravity-like sin/cos^3, a smoothed sign."""

    name = "fast-law"

    def __init__(self, kp: float = 100.0, kd: float = 20.0) -> None:
        self.kp, self.kd = kp, kd

    def law_parameters(self):
        return [0.385, self.kp, self.kd, 0.6, 0.9, 0.05]

    @staticmethod
    def law(p, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        c = math.cos(alpha)
        u = p[0] * (alpha0_ddot + p[2] * (alpha0_dot - alpha_dot) + p[1] * (alpha0 - alpha))
        u = u + p[3] * math.sin(alpha) / (c * c * c)
        return u + p[4] * alpha_dot / math.sqrt(alpha_dot * alpha_dot + p[5] * p[5])


class SlowLaw(SteeringController):
    """The same law written as voltage_scalar (the Python path only: no pure function)."""

    name = "slow-law"

    def __init__(self, kp: float = 100.0, kd: float = 20.0) -> None:
        self.kp, self.kd = kp, kd

    def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        c = math.cos(alpha)
        u = 0.385 * (alpha0_ddot + self.kd * (alpha0_dot - alpha_dot) + self.kp * (alpha0 - alpha))
        u = u + 0.6 * math.sin(alpha) / (c * c * c)
        return u + 0.9 * alpha_dot / math.sqrt(alpha_dot * alpha_dot + 0.05 * 0.05)


class StatefulLaw(FastLaw):
    """A pure function, but state beside it (an overridden reset): never compiled."""

    name = "stateful-law"

    def reset(self, *, control_period: float) -> None:
        self.period = control_period


class Uncompilable(FastLaw):
    name = "uncompilable"

    @staticmethod
    def law(p, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        return float(decimal.Decimal(alpha))  # a Python object numba does not know


class MethodLaw(FastLaw):
    name = "method-law"

    def law(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):  # type: ignore[override]
        return 0.0


class NaNLaw(FastLaw):
    name = "nan-law"

    @staticmethod
    def law(p, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        if alpha0 > 0.05:  # once the reference has turned far enough
            return math.nan
        return p[0] * (alpha0_ddot + p[2] * (alpha0_dot - alpha_dot) + p[1] * (alpha0 - alpha))


def _run(controller, law="auto", **options):
    return run_closed_loop(RunConfig(model="nonholonomic", duration=10.0, controller=controller, **options),
                           progress=False, law=law)


@needs_compiled
@needs_numba
@pytest.mark.slow
@pytest.mark.parametrize("options", [dict(), dict(control_period=0.005), dict(m1=700.0)])
def test_the_numba_path_gives_the_python_paths_bits(options):
    fast, python = _run(FastLaw(), **options), _run(FastLaw(), "numpy", **options)
    written = _run(SlowLaw(), **options)
    assert (fast.law, fast.law_note) == ("compiled", None)
    assert python.law == written.law == "python" and "asked for" in python.law_note
    assert "no pure law function" in written.law_note
    assert fast.rows.keys() == python.rows.keys() and len(fast.rows["t"]) > 1000
    for key in fast.rows:
        assert np.array_equal(fast.rows[key], python.rows[key]), key
        assert np.array_equal(fast.rows[key], written.rows[key]), key
    assert np.array_equal(fast.C_xy, python.C_xy)
    assert np.abs(fast.rows["voltage_cmd"]).max() > 1.0  # a law that does something


@needs_compiled
@needs_numba
@pytest.mark.slow
def test_a_batch_runs_the_numba_law_in_the_callback_bit_identical_to_python():
    configs = [RunConfig(model="nonholonomic", duration=10.0, controller=FastLaw(), m1=m) for m in (556.0, 690.0)]
    configs.append(configs[0].replace(m1=640.0, plant_overrides={"mu": 0.03}))
    assert batch_law_backend(FastLaw()) == "compiled"
    compiled = run_batch(configs, nthread=2)
    numpy_law = run_batch(configs, nthread=2, law="numpy")
    # the configs carry law objects (one each), so they run one by one on the engine: the Python law when asked
    # for 'numpy', named as run names it (engine.law_path)
    assert {r.batch.law for r in compiled} == {"compiled"} and {r.batch.law for r in numpy_law} == {"python"}
    for cfg, c, n in zip(configs, compiled, numpy_law):
        single = run_closed_loop(cfg.replace(controller=SlowLaw()), progress=False)
        assert single.law == "python"
        serial, c, n = single.summary.to_dict(), c.to_dict(), n.to_dict()
        for key in KEYS:
            assert c[key] == serial[key] == n[key], (cfg.m1, key)
    assert len({r.sup_E for r in compiled}) == len(configs)


@needs_compiled
@needs_numba
@pytest.mark.slow
def test_a_nan_fails_the_compiled_run_where_the_python_run_fails():
    fast, python = _run(NaNLaw()), _run(NaNLaw(), "numpy")
    assert fast.status == python.status == "failed"
    assert fast.summary.failure == python.summary.failure and "returned nan V" in fast.summary.failure
    assert fast.summary.steps == python.summary.steps > 0
    for key in fast.rows:
        assert np.array_equal(fast.rows[key], python.rows[key]), key


@needs_compiled
def test_without_numba_the_python_path_runs_and_says_why(monkeypatch):
    monkeypatch.setitem(sys.modules, "numba", None)  # import numba raises ImportError
    monkeypatch.setattr(compiled_law, "_external", {})  # nothing compiled yet in this process
    why = compiled_law.external_reason(FastLaw())
    assert why is not None and "numba is not installed" in why and "wmr-mj[fast]" in why
    assert batch_law_backend(FastLaw()) == "numpy"
    with pytest.raises(ParameterError, match="numba is not installed"):
        batch_law_backend(FastLaw(), "compiled")
    assert compiled_law.law_vector(FastLaw(), voltage_limit=24.0, substeps=1, nstep=3, qpos_adr=0, dof_adr=0,
                                   actuator=0) is None


@needs_compiled
@pytest.mark.slow
def test_without_numba_a_run_takes_the_python_path_and_says_so(monkeypatch):
    monkeypatch.setitem(sys.modules, "numba", None)
    monkeypatch.setattr(compiled_law, "_external", {})
    run = _run(FastLaw())
    assert run.law == "python" and "numba is not installed" in run.law_note and run.status == "completed"


@needs_compiled
def test_a_law_without_a_pure_function_or_with_state_is_never_compiled():
    why = compiled_law.external_reason(SlowLaw())
    assert why is not None and "SlowLaw offers no pure law function" in why
    assert StatefulLaw().stateful and not FastLaw().stateful
    why = compiled_law.external_reason(StatefulLaw())
    assert why is not None and "keeps state" in why
    for law in (SlowLaw(), StatefulLaw()):
        assert batch_law_backend(law) == "numpy" and not compiled_law.compiles(law)
        with pytest.raises(ParameterError, match="cannot run"):
            batch_law_backend(law, "compiled")


@needs_compiled
@pytest.mark.slow
def test_a_stateful_law_runs_in_python_single_and_in_a_batch():
    run = _run(StatefulLaw())
    assert run.law == "python" and "keeps state" in run.law_note
    configs = [RunConfig(model="nonholonomic", duration=10.0, controller=StatefulLaw(), m1=m) for m in (556.0, 690.0)]
    assert {r.batch.law for r in run_batch(configs, nthread=1)} == {"python"}  # one by one, as run names it


@needs_compiled
@needs_numba
def test_a_law_numba_cannot_compile_runs_in_python_and_says_why():
    why = compiled_law.external_reason(Uncompilable())
    assert why is not None and why.startswith("numba could not compile Uncompilable.law")
    assert "\n" not in why
    assert compiled_law.external_reason(Uncompilable()) == why  # cached: compiled (or refused) once per function
    assert "not a staticmethod" in compiled_law.external_reason(MethodLaw())


@needs_compiled
@needs_numba
def test_the_law_numeric_carries_a_slot_and_the_constants():
    vector = compiled_law.law_vector(FastLaw(kp=7.0), voltage_limit=24.0, substeps=2, nstep=5, qpos_adr=1, dof_adr=2,
                                     actuator=3)
    fields = dict(zip(compiled_law.LAW_FIELDS, vector))
    assert fields["kind"] == compiled_law.EXTERNAL_KIND and fields["nparam"] == 6 and fields["function"] >= 0
    assert vector[len(compiled_law.LAW_FIELDS):].tolist() == FastLaw(kp=7.0).law_parameters()
    # the same law function: the same slot, whatever the constants
    again = compiled_law.law_vector(FastLaw(kp=1.0), voltage_limit=24.0, substeps=2, nstep=5, qpos_adr=1, dof_adr=2,
                                    actuator=3)
    assert again[compiled_law.LAW_FIELDS.index("function")] == fields["function"]


def test_voltage_scalar_and_voltage_derive_from_law():
    law = FastLaw()
    state = (0.1, -0.2, 0.15, 0.05, 0.3)
    assert law.voltage_scalar(*state) == SlowLaw().voltage_scalar(*state)
    assert law.voltage(*(np.array([x, x]) for x in state)).tolist() == [law.voltage_scalar(*state)] * 2


@needs_compiled
@needs_numba
@pytest.mark.slow
def test_the_command_says_which_path_it_took(capsys, tmp_path):
    assert main(["run", "--controller", f"{REPO / 'examples' / 'fast_pd.py'}:FastPD", "--duration", "10",
                 "--no-log"]) == 0
    assert "'fast-pd' compiled by numba" in capsys.readouterr().err
    assert main(["run", "--controller", f"{REPO / 'examples' / 'my_pid.py'}:MyPID", "--duration", "10",
                 "--no-log"]) == 0
    err = capsys.readouterr().err
    assert "runs in Python" in err and "keeps state" in err
