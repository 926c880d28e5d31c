"""The steering law compiled into MuJoCo's control callback, for batches of closed-loop runs.

A batch of closed-loop runs (``wmr_mj.sim.batch.run_batch``) steps every simulation by one
control period, then evaluates the law for all of them in NumPy: about 20 small ufunc calls a
step whose cost does not shrink with the batch. This module moves the law into C instead:
``wmr_mj/sim/_compiled_law.c`` holds ``ComputedTorque.voltage_scalar`` and
``PDController.voltage_scalar`` of ``controllers.computed_torque``, operation for operation,
as ``mjcb_control``, so that ``mujoco.batch.Batch.rollout`` runs a whole block of closed-loop
steps with no Python in between. The law's constants and the reference travel in each model
(two ``numeric`` fields), its outputs in ``userdata``::

    from wmr_mj.sim import compiled_law

    if compiled_law.unavailable_reason() is None:
        compiled_law.install()                       # once per process; inert for other models
        law = compiled_law.law_vector(controller, voltage_limit=24.0, substeps=1, nstep=n,
                                      qpos_adr=qa, dof_adr=dv, actuator=act)
        compiled_law.attach(spec, law, reference_rows)    # before spec.compile()
        # Batch.rollout(..., record=("userdata",)) then records USERDATA_FIELDS every step

The callback acts only on models that carry the law (``attach``); every other model of the
process (the Python-law engine's included) steps as before. Per control step it computes, with
E = alpha0 - alpha (3.2)-(3.3)::

    u = P^ (alpha0'' + K_D E' + K_P E) + K^ sin(alpha)/cos^3(alpha) + C_V^ alpha'
        + F^ s + gyro^ V_A alpha'/cos^2(alpha)                         (computed torque)
    u = P^ (K_D E' + K_P E)                                            (PD)

and applies clip(u, +-voltage_limit), 0 V where u is NaN, as the Python law of
``wmr_mj.sim.engine`` does; a single run (``wmr_mj.sim.engine.run_engine``) reads its rows from
the userdata too (alpha', the applied voltage, the chassis heading). tests/test_compiled_law.py
checks the callback against ``voltage_scalar`` and whole batches against single runs, to the bit.

A plug-in law (a :class:`controllers.SteeringController` of one's own) runs in the same callback
where it offers its law as a pure function of floats (the *external* law, kind 2)::

    class FastPD(SteeringController):
        def law_parameters(self):              # the law's constants, a float64 array p
            return [self.P_hat, self.kp, self.kd]
        @staticmethod
        def law(p, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
            return p[0] * (alpha0_ddot + p[2] * (alpha0_dot - alpha_dot) + p[1] * (alpha0 - alpha))

:func:`external_law` compiles ``law`` with numba (``numba.njit`` inside a ``numba.cfunc`` of the C
signature ``double (const double *p, int n, double alpha, ..., double alpha0_ddot)``; fastmath
off, so no contraction into fused multiply-adds and the same libm calls as Python's ``math``),
registers the function pointer in a table of the C library (``wmr_mj_register_law``: the model
names a slot of that table, never an address, and the compiled function is kept for the life of
the process) and appends ``p`` to the law numeric. The callback then calls it at every control
step, with the voltage limit and the userdata of the built-in laws; a value that is not finite is
applied as NaN, so that MuJoCo warns and the engine re-runs the block with the Python law, which
fails the run at that step as the Python path of a plug-in does. The Python path of the same law
(``SteeringController.voltage_scalar`` calls ``law(p, ...)``) gives the same bits
(tests/test_fast_law.py). Only a stateless law (``controller.stateful`` False) takes this path;
where numba is not installed, the law offers no ``law``, or numba cannot compile it,
:func:`external_reason` says why and the law runs in Python.

It is built by ``pip install`` (setup.py, with the MuJoCo headers of the mujoco wheel) where a
C compiler is found; without it, or with ``WMR_MJ_COMPILED_LAW=0`` in the environment,
``unavailable_reason`` says why and the batch uses the NumPy law.
"""

from __future__ import annotations

import ctypes
import inspect
import os
import threading
from collections.abc import Sequence
from functools import cache
from typing import Any

import mujoco
import numpy as np

from controllers import ComputedTorque, PDController
from wmr_mj.errors import ParameterError
from wmr_mj.hardware.sensing import _VELOCITY_CODES, N_PARAMETERS, S_RING

__all__ = ["LAW_FIELDS", "USERDATA_FIELDS", "SENSING_USERDATA_FIELDS", "SENSING_STATE_ADR", "sensing_numeric",
            "unavailable_reason", "install", "supports", "law_vector", "attach",
           "external_reason", "external_law", "compiles"]

#: The numeric "wmr_mj_law", in order (the enum of _compiled_law.c).
LAW_FIELDS = ("kind", "P", "K_P", "K_D", "C_V", "F", "K", "gyro_V", "friction_width", "friction_sign",
              "voltage_limit", "substeps", "nstep", "qpos_adr", "dof_adr", "actuator", "chassis", "function", "nparam")
#: LAW_FIELDS "kind" of a plug-in's law compiled by numba (0: computed torque, 1: PD)
EXTERNAL_KIND = 2
#: userdata of a model with the law, written at every control step (heading: at every physics step,
#: where the law names the chassis body).
USERDATA_FIELDS = ("alpha", "E", "E_dot", "voltage_cmd", "alpha_dot", "voltage", "heading")
LAW_NUMERIC, REFERENCE_NUMERIC, DISTURBANCE_NUMERIC = "wmr_mj_law", "wmr_mj_reference", "wmr_mj_disturbance"
#: the numeric of the steering sensor (wmr_mj.hardware.sensing.SensingChain): SENSE_FIELDS, the chain's
#: parameters, then its noise on alpha and on alpha' per control step
SENSING_NUMERIC = "wmr_mj_sensing"
SENSE_FIELDS = ("motor_qpos_adr", "nstep")
#: userdata after USERDATA_FIELDS where the run has a sensor: what the law read; the chain's state follows
SENSING_USERDATA_FIELDS = ("alpha_measured", "alpha_dot_measured")
SENSING_STATE_ADR = len(USERDATA_FIELDS) + len(SENSING_USERDATA_FIELDS)
_ENV = "WMR_MJ_COMPILED_LAW"
_install_lock = threading.Lock()


@cache
def _library() -> tuple[ctypes.CDLL | None, str | None]:
    """(the loaded library, None) or (None, why not)."""
    try:
        from wmr_mj.sim import _compiled_law  # type: ignore[attr-defined]  # a C extension, built in place
    except ImportError as exc:
        return None, f"wmr_mj.sim._compiled_law is not built ({exc}); install with a C compiler to build it"
    lib = ctypes.CDLL(_compiled_law.__file__)
    built_for, running = int(lib.wmr_mj_mujoco_version()), int(mujoco.mj_version())
    if built_for != running:
        return None, f"wmr_mj.sim._compiled_law was built for MuJoCo {built_for}, this is {running}; reinstall wmr-mj"
    if (int(lib.wmr_mj_law_size()) != len(LAW_FIELDS) or not hasattr(lib, "wmr_mj_disturbance_numeric")
            or not hasattr(lib, "wmr_mj_register_law") or not hasattr(lib, "wmr_mj_sensing_layout")
            or int(lib.wmr_mj_sensing_layout()) != _sensing_layout()):
        return None, "wmr_mj.sim._compiled_law does not match wmr_mj.sim.compiled_law (LAW_FIELDS); reinstall wmr-mj"
    return lib, None


def _sensing_layout() -> int:
    """The sensing layout's sizes as the C file encodes them (wmr_mj_sensing_layout), and the number of velocity
    codes it knows (a library built before velocity=none would difference where the chain gives NaN)."""
    return 100000 * len(_VELOCITY_CODES) + 1000 * len(SENSE_FIELDS) + 10 * N_PARAMETERS + S_RING


def sensing_numeric(chain: Any, *, motor_qpos_adr: int) -> np.ndarray:
    """The numeric "wmr_mj_sensing" of ``chain`` (a :class:`wmr_mj.hardware.sensing.SensingChain`):
    SENSE_FIELDS, its parameters, its noise on alpha and on alpha' (n_steps each)."""
    return np.concatenate([np.array([float(motor_qpos_adr), float(chain.n_steps)]), chain.parameters,
                           chain.alpha_noise, chain.alpha_dot_noise])


def _address(fn: Any) -> int | None:
    return None if fn is None else ctypes.cast(fn, ctypes.c_void_p).value


def unavailable_reason() -> str | None:
    """None where the compiled law can run in this process, else one line saying why not."""
    if os.environ.get(_ENV, "1") == "0":
        return f"the compiled law is switched off ({_ENV}=0)"
    lib, why = _library()
    if lib is None:
        return why
    installed = _address(mujoco.get_mjcb_control())
    if installed is not None and installed != _address(lib.wmr_mj_control):
        return "another mjcb_control is installed in this process; the batch leaves it in place"
    return None


def install() -> None:
    """Install the law as mjcb_control (idempotent; raises ParameterError, saying why, where it cannot run).

    It stays installed: it returns at once for models without the law, and uninstalling it
    while another thread's batch runs would stop that batch's control.
    """
    with _install_lock:
        why = unavailable_reason()
        if why is not None:
            raise ParameterError(f"the compiled law cannot run: {why}")
        lib, _ = _library()
        assert lib is not None  # unavailable_reason() is None only when the library loaded
        if mujoco.get_mjcb_control() is None:
            mujoco.set_mjcb_control(lib.wmr_mj_control)


def supports(controller: Any) -> bool:
    """Whether the C law implements ``controller``: ComputedTorque and PDController themselves.

    A subclass may change the law, so it keeps the NumPy path.
    """
    return type(controller) in (ComputedTorque, PDController)


def compiles(controller: Any) -> bool:
    """Whether the callback runs ``controller``'s law: a built-in law (:func:`supports`) or a plug-in's
    pure function that numba compiles (:func:`external_reason` None)."""
    return supports(controller) or external_reason(controller) is None


_external_lock = threading.Lock()
_external: dict[Any, tuple[Any, int] | str] = {}  # law function -> (numba cfunc, kept alive; its slot) or why not


def _law_function(controller: Any) -> Any:
    return getattr(type(controller), "law", None)


def external_reason(controller: Any) -> str | None:
    """None where ``controller``'s law runs compiled by numba in the callback, else one line saying why not.

    It needs a stateless law (``controller.stateful`` False) that offers ``law(p, alpha, alpha',
    alpha0, alpha0', alpha0'')`` (a staticmethod, plain float arithmetic and ``math``) and
    ``law_parameters()`` (p), and numba to compile it (``pip install 'wmr-mj[fast]'``); compiling
    happens here, once per law function and process.
    """
    name = type(controller).__name__
    if supports(controller):
        return f"{name} is a built-in law of the callback, not an external one"
    if getattr(controller, "stateful", False):
        return f"{name} keeps state (it overrides step or reset), which the compiled law does not hold"
    fn = _law_function(controller)
    if fn is None or not callable(fn):
        return (f"the compiled law implements ComputedTorque and PDController; {name} offers no pure law "
                "function to compile (a staticmethod law(p, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot) "
                "with law_parameters(); controllers.base)")
    if not isinstance(inspect.getattr_static(type(controller), "law"), staticmethod):
        return f"{name}.law is not a staticmethod: the compiled law calls law(p, alpha, ...) without the object"
    try:
        _parameters(controller)
    except (TypeError, ValueError) as exc:
        return f"{name}.law_parameters() is not a sequence of floats ({exc})"
    return _compile(fn, name)[1]


def _parameters(controller: Any) -> np.ndarray:
    p = np.asarray(controller.law_parameters(), dtype=np.float64)
    if p.ndim != 1:
        raise ValueError(f"shape {p.shape}, not one axis")
    return p


def _compile(fn: Any, name: str) -> tuple[int | None, str | None]:
    """(slot of fn's compiled function in the C table, None) or (None, why not); cached per function."""
    with _external_lock:
        done = _external.get(fn)
        if done is None:
            done = _external[fn] = _compile_new(fn, name)
    return (None, done) if isinstance(done, str) else (done[1], None)


def _compile_new(fn: Any, name: str) -> tuple[Any, int] | str:
    lib, why = _library()
    if lib is None:
        return why or "the compiled law is not built"
    try:
        import numba
        from numba import types
    except ImportError as exc:
        return f"numba is not installed ({exc}); pip install 'wmr-mj[fast]' compiles {name}.law"
    try:
        inner = numba.njit(error_model="numpy")(fn)
        signature = types.float64(types.CPointer(types.float64), types.intc, types.float64, types.float64,
                                  types.float64, types.float64, types.float64)

        def entry(p, n, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):  # pragma: no cover  (numba compiles it)
            return inner(numba.carray(p, (n,)), alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)

        compiled = numba.cfunc(signature, error_model="numpy")(entry)
    except Exception as exc:  # noqa: BLE001  (numba's typing and lowering errors, whatever their class)
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        return f"numba could not compile {name}.law ({type(exc).__name__}: {first})"
    slot = int(lib.wmr_mj_register_law(ctypes.c_void_p(compiled.address)))
    if slot < 0:
        return "the compiled law's table of law functions is full"
    return compiled, slot


def external_law(controller: Any) -> tuple[int, np.ndarray]:
    """(slot, constants p) of ``controller``'s law compiled by numba; ParameterError, saying why, where it is not."""
    why = external_reason(controller)
    if why is not None:
        raise ParameterError(f"the compiled law cannot run {type(controller).__name__}: {why}")
    slot, _ = _compile(_law_function(controller), type(controller).__name__)
    assert slot is not None
    return slot, _parameters(controller)


def law_vector(controller: Any, *, voltage_limit: float, substeps: int, nstep: int, qpos_adr: int, dof_adr: int,
               actuator: int, chassis: int = -1) -> np.ndarray | None:
    """The numeric "wmr_mj_law" for ``controller``; None where :func:`compiles` is False.

    ``chassis``: the chassis body, whose heading the callback then writes at every physics step
    (-1: none, as in a batch, which does not record it). A plug-in's law (kind 2) has its
    constants appended after the :data:`LAW_FIELDS`.
    """
    if not supports(controller):
        if external_reason(controller) is not None:
            return None
        slot, p = external_law(controller)
        fixed = dict.fromkeys(LAW_FIELDS, 0.0)
        fixed.update(kind=float(EXTERNAL_KIND), voltage_limit=voltage_limit, substeps=substeps, nstep=nstep,
                     qpos_adr=qpos_adr, dof_adr=dof_adr, actuator=actuator, chassis=chassis, function=slot,
                     nparam=len(p))
        return np.concatenate([np.array([float(fixed[name]) for name in LAW_FIELDS]), p])

    values: dict[str, Any] = {"C_V": 0.0, "F": 0.0, "K": 0.0, "gyro_V": 0.0, "friction_width": 0.0,
                              "friction_sign": "measured"}
    values.update(controller.law_constants())
    values.update(kind=0.0 if type(controller) is ComputedTorque else 1.0, function=0.0, nparam=0.0,
                  friction_sign=2.0 if values["friction_sign"] == "reference" else 1.0,
                  voltage_limit=voltage_limit, substeps=substeps, nstep=nstep, qpos_adr=qpos_adr,
                  dof_adr=dof_adr, actuator=actuator, chassis=chassis)
    return np.array([float(values[name]) for name in LAW_FIELDS])


def attach(spec: mujoco.MjSpec, law: np.ndarray, reference: Sequence[np.ndarray],
           disturbance: np.ndarray | None = None, sensing: tuple[np.ndarray, int] | None = None) -> None:
    """Give the model of ``spec`` the law: the numerics the callback reads, and its userdata.

    ``reference`` is (alpha0, alpha0', alpha0'') on the control grid, nstep samples each;
    ``disturbance``, where given, a torque on the steering joint per control step [N m] (nstep
    samples), the third numeric, which the callback writes to qfrc_applied at every physics step;
    ``sensing``, where given, (the numeric of :func:`sensing_numeric`, the chain's state size): the
    law then reads the measured state, and userdata holds SENSING_USERDATA_FIELDS and the chain's state.
    """
    if len(spec.numerics):
        raise ParameterError("attach needs a spec without numerics: the law must be the model's first numeric")
    if spec.nuserdata:
        raise ParameterError("attach needs a spec without userdata: the law writes userdata")
    law = np.asarray(law, dtype=float)
    if law.ndim != 1 or len(law) < len(LAW_FIELDS) or len(law) != len(LAW_FIELDS) + law[LAW_FIELDS.index("nparam")]:
        raise ParameterError(f"law must have the {len(LAW_FIELDS)} values of LAW_FIELDS (and its nparam constants)")
    nstep = int(law[LAW_FIELDS.index("nstep")])
    rows = np.stack([np.asarray(r, dtype=float)[:nstep] for r in reference], axis=1)
    if rows.shape != (nstep, 3):
        raise ParameterError(f"reference must be three rows of at least {nstep} samples")
    spec.add_numeric(name=LAW_NUMERIC, data=law.tolist())
    spec.add_numeric(name=REFERENCE_NUMERIC, data=rows.ravel().tolist())
    if disturbance is not None:
        torque = np.asarray(disturbance, dtype=float)[:nstep]
        if torque.shape != (nstep,) or not np.all(np.isfinite(torque)):
            raise ParameterError(f"disturbance must be {nstep} finite samples")
        spec.add_numeric(name=DISTURBANCE_NUMERIC, data=torque.tolist())
    spec.nuserdata = len(USERDATA_FIELDS)
    if sensing is not None:
        values, state_size = sensing
        spec.add_numeric(name=SENSING_NUMERIC, data=np.asarray(values, dtype=float).tolist())
        spec.nuserdata = SENSING_STATE_ADR + int(state_size)
