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

It is built by ``pip install`` (setup.py, with the MuJoCo headers of the mujoco wheel) where a
C compiler is found; without it, or with ``WMR_MJ_COMPILED_LAW=0`` in the environment,
``unavailable_reason`` says why and the batch uses the NumPy law.
"""

from __future__ import annotations

import ctypes
import os
import threading
from collections.abc import Sequence
from functools import cache
from typing import Any

import mujoco
import numpy as np

from wmr_mj.errors import ParameterError

__all__ = ["LAW_FIELDS", "USERDATA_FIELDS", "unavailable_reason", "install", "supports", "law_vector", "attach"]

#: The numeric "wmr_mj_law", in order (the enum of _compiled_law.c).
LAW_FIELDS = ("kind", "P", "K_P", "K_D", "C_V", "F", "K", "gyro_V", "friction_width", "friction_sign",
              "voltage_limit", "substeps", "nstep", "qpos_adr", "dof_adr", "actuator", "chassis")
#: userdata of a model with the law, written at every control step (heading: at every physics step,
#: where the law names the chassis body).
USERDATA_FIELDS = ("alpha", "E", "E_dot", "voltage_cmd", "alpha_dot", "voltage", "heading")
LAW_NUMERIC, REFERENCE_NUMERIC, DISTURBANCE_NUMERIC = "wmr_mj_law", "wmr_mj_reference", "wmr_mj_disturbance"
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
    if int(lib.wmr_mj_law_size()) != len(LAW_FIELDS) or not hasattr(lib, "wmr_mj_disturbance_numeric"):
        return None, "wmr_mj.sim._compiled_law does not match wmr_mj.sim.compiled_law (LAW_FIELDS); reinstall wmr-mj"
    return lib, None


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
    from controllers import ComputedTorque, PDController

    return type(controller) in (ComputedTorque, PDController)


def law_vector(controller: Any, *, voltage_limit: float, substeps: int, nstep: int, qpos_adr: int, dof_adr: int,
               actuator: int, chassis: int = -1) -> np.ndarray | None:
    """The numeric "wmr_mj_law" for ``controller``; None where :func:`supports` is False.

    ``chassis``: the chassis body, whose heading the callback then writes at every physics step
    (-1: none, as in a batch, which does not record it).
    """
    if not supports(controller):
        return None
    from controllers import ComputedTorque

    values: dict[str, Any] = {"C_V": 0.0, "F": 0.0, "K": 0.0, "gyro_V": 0.0, "friction_width": 0.0,
                              "friction_sign": "measured"}
    values.update(controller.law_constants())
    values.update(kind=0.0 if type(controller) is ComputedTorque else 1.0,
                  friction_sign=2.0 if values["friction_sign"] == "reference" else 1.0,
                  voltage_limit=voltage_limit, substeps=substeps, nstep=nstep, qpos_adr=qpos_adr,
                  dof_adr=dof_adr, actuator=actuator, chassis=chassis)
    return np.array([float(values[name]) for name in LAW_FIELDS])


def attach(spec: mujoco.MjSpec, law: np.ndarray, reference: Sequence[np.ndarray],
           disturbance: np.ndarray | None = None) -> None:
    """Give the model of ``spec`` the law: the numerics the callback reads, and its userdata.

    ``reference`` is (alpha0, alpha0', alpha0'') on the control grid, nstep samples each;
    ``disturbance``, where given, a torque on the steering joint per control step [N m] (nstep
    samples), the third numeric, which the callback writes to qfrc_applied at every physics step.
    """
    if len(spec.numerics):
        raise ParameterError("attach needs a spec without numerics: the law must be the model's first numeric")
    if spec.nuserdata:
        raise ParameterError("attach needs a spec without userdata: the law writes userdata")
    law = np.asarray(law, dtype=float)
    if law.shape != (len(LAW_FIELDS),):
        raise ParameterError(f"law must have the {len(LAW_FIELDS)} values of LAW_FIELDS")
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
