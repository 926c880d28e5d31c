"""The one closed-loop engine: a single run is a batch of one, stepped in blocks through the compiled law.

``wmr_mj.sim.closed_loop.run_closed_loop`` (``wmr-mj run``, replay's re-runs, ``identify``,
``validate``) hands a run to :func:`run_engine`, which steps it one simulated second at a time:

- with the compiled law (:mod:`wmr_mj.sim.compiled_law`: the law in MuJoCo's control callback),
  one ``mujoco.batch.Batch.rollout`` call per block runs every physics step of that second in C
  and records, after each step, what the rows and the log need (userdata: alpha, E, E', the law's
  voltage, alpha', the applied voltage and the chassis's heading; the steering actuator's force and
  qfrc_actuator; for a log also qpos, qvel, ctrl and the site positions); the rows are then made
  from these arrays with NumPy, bit for bit what one ``mj_step`` at a time gives
  (tests/test_engine.py against tests/reference_loop.py);
- a plug-in law that offers a pure function of floats (``law(p, ...)``, :mod:`controllers.base`)
  runs in the same callback, compiled by numba (:func:`wmr_mj.sim.compiled_law.external_reason`);
- where the compiled law cannot run (not built, ``WMR_MJ_COMPILED_LAW=0``, a controller
  subclass, a plug-in without ``law``, with state, or without numba), the same engine steps the
  block with the Python law (``step``), one ``mj_step`` per physics step, into the same record
  arrays, and says so (``EngineRun.law_note``);
- a block in which MuJoCo warns (rollout stops a simulation whose warnings rise) is stepped again
  from its first state with the Python law, which, as ``mj_step`` does, goes on after a warning;
  the rest of the run keeps the Python law.

Signals (:mod:`wmr_mj.sim.signals`): a disturbance torque on the steering joint, one value per
control step, is written to qfrc_applied at every physics step (by the compiled law's callback from
a third numeric of the model, or by the Python stepper before its mj_step calls); a load change
sets the chassis's model fields (:data:`LOAD_FIELDS`, as the model compiled for the new m1 has
them) at its control step, then mj_setConst, the block being stepped in parts around it. A run
without signals steps exactly as before.

A sensor (``Schedule.sensing``, :class:`wmr_mj.hardware.SensingChain`) sits between the plant and the law in
both steppers: in the compiled callback (a numeric of the model, its state in userdata) and in the Python
stepper (``SensingChain.step``), the same bits; the rows gain what the law read (:data:`SENSED_ROW_FIELDS`).
The block loop (:class:`_BlockLoop`) knows nothing of it, and chooses its other hooks (the tracker, the
fall-back, load changes) once, before the first block.

Each block is handed to ``on_block`` (the MCAP logger) as arrays: the rows plus qpos, qvel, ctrl
at every control step's start and the positions of sites A and C.

The models: :func:`batch_model` (the scene without its sky texture, with the law attached or
not), shared with ``wmr_mj.sim.batch``; :func:`batch_law_backend` chooses the law.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import math
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, cast

import mujoco
import numpy as np

from wmr_mj.errors import ParameterError, UnknownNameError, WmrMjError
from wmr_mj.hardware.assembly import CART_PARTS
from wmr_mj.hardware.sensing import P_GEAR_RATIO, SensingChain
from wmr_mj.params import C80Parameters
from wmr_mj.plant.mjcf import scene_spec, steering_joint_addresses
from wmr_mj.sim import compiled_law

__all__ = ["run_engine", "Schedule", "EngineRun", "batch_model", "batch_law_backend", "LAW_BACKENDS", "LAW_PATHS",
           "law_path", "plant_options",
           "ROW_FIELDS", "LOAD_FIELDS", "load_fields", "ControllerFailure"]

# scalar fields recorded for every control step (see wmr_mj.sim.closed_loop.RunResult.rows)
ROW_FIELDS = ("t", "alpha", "alpha_dot", "alpha0", "alpha0_dot", "alpha0_ddot", "E", "E_dot",
              "voltage_cmd", "voltage", "current", "steer_torque", "heading")
#: recorded besides where the run has a sensor (wmr_mj.hardware.sensing): what the law read [rad, rad/s];
#: alpha, alpha_dot, E and E_dot stay the true state's
SENSED_ROW_FIELDS = ("alpha_measured", "alpha_dot_measured")
#: the rows' prefix of a law's own signals (``SteeringController.signal_names``: row ``law_NAME`` per name)
LAW_SIGNAL_PREFIX = "law_"

#: how a run evaluates the law: "compiled" (C, in MuJoCo's control callback), "numpy"
#: (Python: the vectorised law of a batch, ``voltage_scalar`` of a single run), "auto"
#: (compiled where it can run)
LAW_BACKENDS = ("auto", "compiled", "numpy")

_PLANT_OPTIONS = ("steering_friction", "tyre_contact")  # RunConfig fields that choose the plant's laws

#: The model fields a change of the chassis mass m1 sets (mass and inertia of the bodies, and the
#: steering's Coulomb friction through the front axle's load); mj_setConst derives the rest. The
#: drive servo's gain, which the model scales with the mass, is left as it was (a payload change
#: does not retune it).
LOAD_FIELDS = ("body_mass", "body_inertia", "body_ipos", "body_iquat", "dof_frictionloss")


def load_fields(params: C80Parameters, **plant_options: Any) -> dict[str, np.ndarray]:
    """:data:`LOAD_FIELDS` of the plant of ``params`` (give it the changed m1, as with_params makes it)."""
    model = batch_model(params, **plant_options)
    return {name: getattr(model, name).copy() for name in LOAD_FIELDS}


def plant_options(config: Any) -> dict[str, Any]:
    """The plant-law keywords the config carries (compile_model and Plant take them): the steering friction
    and tyre contact laws, and each cart part's own ``model_options()`` (:mod:`wmr_mj.hardware.coverage`: the
    actuation's delay, inductance and current limit, the gear's play; the sensor none); an ideal part adds no
    keyword, so an ideal cart's model is today's."""
    options = {name: getattr(config, name) for name in _PLANT_OPTIONS if hasattr(config, name)}
    for name in CART_PARTS:  # each part declares its own model change ({} where ideal)
        part = getattr(config, name, None)
        if part is not None:
            options.update(part.model_options())
    return options


def batch_model(params: C80Parameters, *, law: tuple[Any, ...] | None = None,
                **plant_options: Any) -> mujoco.MjModel:
    """The plant of ``compile_model(params, ...)`` without its sky texture, for the engine and the batch.

    Generating the 512x3072 sky gradient is 95% of compiling the scene (11.6 of 12 ms
    measured); a texture touches no physics, and a test checks that every other model
    field equals the serial run's. ``law`` = (law vector, reference rows[, disturbance]) attaches the
    compiled law (:func:`wmr_mj.sim.compiled_law.attach`: two numerics and userdata, no physics; a
    third numeric with the disturbance torque).
    """
    spec = scene_spec(params, **plant_options)
    for texture in list(spec.textures):
        if texture.type == mujoco.mjtTexture.mjTEXTURE_SKYBOX:
            spec.delete(texture)
    if law is not None:
        compiled_law.attach(spec, *law)
    return spec.compile()


#: How a run's law was evaluated, in the words every output uses (``run``'s note, ``sweep``'s last line):
#: 'compiled' (a batch or a run), 'numpy' (a batch's vectorised law), 'python' (one call per control step).
LAW_PATHS = {"compiled": "compiled in MuJoCo's control callback",
             "numpy": "in Python, vectorised with NumPy over the batch",
             "python": "in Python in the engine, one call per control step"}


def law_path(used: str) -> str:
    """The words for how a law ran (:data:`LAW_PATHS`: 'compiled', 'numpy' or 'python'; else ``used``)."""
    return LAW_PATHS.get(used, used)


def batch_law_backend(controller: Any, law: str = "auto") -> str:
    """'compiled' or 'numpy': how a run evaluates ``controller``'s law when asked for ``law``.

    'auto' takes the compiled law where it can run (:mod:`wmr_mj.sim.compiled_law`), else NumPy;
    'compiled' raises ParameterError, saying why, where it cannot.
    """
    return _backend(controller, law)[0]


def law_signal_names(controller: Any) -> tuple[str, ...]:
    """The names of the signals ``controller`` logs beside the rows (``signal_names``; () for most laws).

    Raises:
        ParameterError: names that are not a tuple of distinct identifiers.
    """
    names = getattr(controller, "signal_names", ())
    if names == ():
        return ()
    if (not isinstance(names, (tuple, list)) or not all(isinstance(x, str) and x.isidentifier() for x in names)
            or len(set(names)) != len(names)):
        raise ParameterError(f"controller {getattr(controller, 'name', controller)!r}: signal_names = {names!r} is "
                             "not accepted; a tuple of distinct identifiers (e.g. ('alpha_dot_est',)) is required")
    return tuple(names)


def _backend(controller: Any, law: str) -> tuple[str, str | None]:
    """(backend, why the compiled law does not run or None)."""
    if law not in LAW_BACKENDS:
        raise UnknownNameError("law backend", law, LAW_BACKENDS)
    if law == "numpy":
        return "numpy", "the Python law was asked for"
    why = compiled_law.unavailable_reason()
    if why is None and law_signal_names(controller):
        why = (f"{type(controller).__name__} logs its own signals (signal_names), which the compiled law does not "
               "call")
    if why is None and not compiled_law.supports(controller):
        # a plug-in: compiled by numba where it offers a pure law function (compiled_law.external_reason)
        why = compiled_law.external_reason(controller)
    if why is None:
        return "compiled", None
    if law == "compiled":
        raise ParameterError(f"the compiled law cannot run: {why}")
    return "numpy", why


@dataclass
class EngineRun:
    """What :func:`run_engine` simulated: ``steps`` control steps of rows, and how."""

    rows: dict[str, np.ndarray]  # ROW_FIELDS, the first `steps` control steps
    steps: int
    status: str  # "completed" or "interrupted"
    warnings: int  # MuJoCo's warning counters, summed
    law: str  # "compiled" or "python"
    law_note: str | None  # why the Python law ran, None with the compiled law
    wall_s: float  # the block loop's wall time: stepping, recording, rows, hand-over (models built before)
    cpu_s: float  # the block loop's CPU time on the calling thread (the batch of one steps on it)
    C_xy: np.ndarray = field(default_factory=lambda: np.empty((0, 2)))  # (steps, 2) xy of site C [m], as C_pos
    failure: str | None = None  # status 'failed': why (the law or tracker raised, returned NaN or a bad shape)
    warning_text: str | None = None  # MuJoCo's first warning of the run, as it words it (None: it warned not)


@contextlib.contextmanager
def held_mujoco_warnings() -> Iterator[list[str]]:
    """MuJoCo's warnings (its C warning callback, ``mju_user_warning``) collected in the list this yields
    instead of printed on the console; the handler before restored on leaving. A run counts its warnings
    from ``mjData.warning`` and reports them once (:class:`EngineRun`), never once per step."""
    texts: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(texts.append)
    try:
        yield texts
    finally:
        mujoco.set_mju_user_warning(previous)


class _Plant:
    """Indices and constants the engine reads, from a compiled model."""

    def __init__(self, m: mujoco.MjModel) -> None:
        steering = steering_joint_addresses(m)
        self.qpos, self.dof = steering.axle_qpos, steering.axle_dof  # alpha, alpha'
        # the motor side (the axle's joint itself where the gear has no play): the motor's torque acts on its
        # dof, and an encoder on the motor shaft reads i2 times its angle
        self.motor_qpos, self.motor_dof = steering.motor_qpos, steering.motor_dof
        self.actuator = steering.actuator
        self.chassis = int(m.body("chassis").id)
        self.site_A, self.site_C = int(m.site("A").id), int(m.site("C").id)
        self.keyframe = int(m.key("home").id)


class _Block:
    """One block's records, (count, ...) per control step, as both steppers fill them.

    alpha, alpha_dot, voltage_cmd, voltage: at the control step's start (what the law saw, what
    it applied); force (the steering actuator's), torque (qfrc_actuator at the steering dof),
    heading (of the chassis), sites: after the control step's last mj_step, i.e. of the state
    that step started from, as the serial loop read them; qpos, qvel, ctrl: at the control
    step's start, ctrl as applied (logs only: without a log they have no rows).
    """

    def __init__(self, count: int, m: mujoco.MjModel, log: bool, sensing: bool = False, n_signals: int = 0) -> None:
        self.alpha, self.alpha_dot, self.voltage_cmd, self.voltage, self.force, self.torque, self.heading = (
            np.empty(count) for _ in range(7))
        rows = count if log else 0
        self.qpos = np.empty((rows, m.nq))
        self.qvel = np.empty((rows, m.nv))
        self.ctrl = np.empty((rows, m.nu))
        self.sites = np.empty((rows, m.nsite, 3))
        self.C_xy = np.empty((count, 2))  # always: the run's path errors (wmr_mj.analysis.path_error)
        # what the law read where the run has a sensor (wmr_mj.hardware.sensing); else no rows
        sensed = count if sensing else 0
        self.alpha_measured, self.alpha_dot_measured = np.empty(sensed), np.empty(sensed)
        # the law's own signals (signal_names), one column each; no rows where it logs none
        self.law_signals = np.empty((count if n_signals else 0, n_signals))

    @classmethod
    def head(cls, block: _Block, count: int) -> _Block:
        """The first ``count`` control steps of ``block`` (views of its arrays; a log's arrays where it has them)."""
        out = cls.__new__(cls)
        for name, value in vars(block).items():
            setattr(out, name, value[:count] if len(value) else value)
        return out


def _heading(quat: np.ndarray) -> np.ndarray:
    """Yaw of unit quaternions (w, x, y, z), element for element the serial loop's math.atan2."""
    w, x, y, z = quat[:, 0], quat[:, 1], quat[:, 2], quat[:, 3]
    num = 2.0 * (w * z + x * y)
    den = 1.0 - 2.0 * (y * y + z * z)
    return np.fromiter(map(math.atan2, num.tolist(), den.tolist()), dtype=np.float64, count=len(num))


class _CompiledStepper:
    """A batch of one with the law in MuJoCo's control callback: one rollout call per block.

    The callback writes what the rows need into userdata (:data:`compiled_law.USERDATA_FIELDS`:
    alpha, E, E', the law's and the applied voltage, alpha' at each control step, the heading at
    each physics step); the rollout records it after every physics step, with the steering
    actuator's force and qfrc_actuator (computed after the callback), and for a log the state.
    """

    def __init__(self, model: mujoco.MjModel, where: _Plant, substeps: int, log: bool, own_model: bool = False,
                 sensing: bool = False) -> None:
        from mujoco.batch import Batch

        self.model, self.where, self.substeps, self.log = model, where, substeps, log
        self.batch = Batch(model, nsim=1, nthread=1)
        self.own_model = own_model
        if own_model:  # the simulation runs on ``model`` itself: edits of its reference numeric reach the law
            self.batch.set_models([model])
        self.batch.reset(keyframe=where.keyframe)
        self.record = ["userdata", "actuator_force", "qfrc_actuator", "site_xpos"]  # sites: C's path, always
        if log:
            self.record += ["qpos", "qvel", "ctrl"]
            # the state at the next control step's start (the rollout records the state after each step)
            self._qpos, self._qvel = self.batch.qpos[0].copy(), self.batch.qvel[0].copy()
        self._out: dict[int, dict[Any, np.ndarray]] = {}  # record buffers per block length, reused
        self._fields = {name: i for i, name in enumerate(compiled_law.USERDATA_FIELDS
                                                         + compiled_law.SENSING_USERDATA_FIELDS * sensing)}

    def warnings(self) -> int:
        return int(self.batch.warning[0, :, 1].sum())  # (nsim, mjNWARNING, (lastinfo, number))

    def set_fields(self, fields: Mapping[str, np.ndarray]) -> None:
        """A load change: the model's fields for the batch's simulation, then mj_setConst."""
        if self.own_model:  # the batch runs on this run's own model: set its fields, as the Python stepper does
            _set_model_fields(self.model, fields)
            return
        for name, value in fields.items():
            self.batch.expand(name)[0] = value
        self.batch.set_const()

    def state(self) -> np.ndarray:
        return self.batch.state[0].copy()  # mjSTATE_INTEGRATION of the model with the law

    def step(self, block: _Block, k0: int, count: int) -> None:
        S, w, f = self.substeps, self.where, self._fields
        out = self._out.setdefault(count, {})
        rec = self.batch.rollout(count * S, record=self.record, out=out)
        out.update(rec)
        end = {key: rec[key][0, S - 1::S] for key in self.record}  # after each control step's last substep
        ud = end["userdata"]  # written at a control step's first substep, held over the others
        block.alpha[:] = ud[:, f["alpha"]]
        block.alpha_dot[:] = ud[:, f["alpha_dot"]]
        block.voltage_cmd[:] = ud[:, f["voltage_cmd"]]
        block.voltage[:] = ud[:, f["voltage"]]
        block.heading[:] = ud[:, f["heading"]]  # written at every substep: the last one's
        if len(block.alpha_measured):
            block.alpha_measured[:] = ud[:, f["alpha_measured"]]
            block.alpha_dot_measured[:] = ud[:, f["alpha_dot_measured"]]
        block.force[:] = end["actuator_force"][:, w.actuator]
        block.torque[:] = end["qfrc_actuator"][:, w.motor_dof]
        sites = end["site_xpos"].reshape(count, -1, 3)
        block.C_xy[:] = sites[:, w.site_C, :2]
        if self.log:
            block.qpos[0], block.qpos[1:] = self._qpos, end["qpos"][:-1]
            block.qvel[0], block.qvel[1:] = self._qvel, end["qvel"][:-1]
            block.ctrl[:] = end["ctrl"]
            block.sites[:] = sites
            self._qpos, self._qvel = end["qpos"][-1].copy(), end["qvel"][-1].copy()


def _set_model_fields(model: mujoco.MjModel, fields: Mapping[str, np.ndarray]) -> None:
    """A load change on ``model`` itself: its fields, then mj_setConst (scratch data: the run's state stays)."""
    for name, value in fields.items():
        getattr(model, name)[...] = value
    mujoco.mj_setConst(model, mujoco.MjData(model))


class ControllerFailure(WmrMjError):
    """A law (or tracker) of the user's raised, returned NaN or returned something that is not one voltage:
    the run stops there, as 'failed', with this message."""

    steps_done: int = 0  # the control steps of the failing block that ran before the failure


def _checked_call(law: Callable[..., Any], t: float, *state: float) -> float:
    """``law(t, *state)`` as one finite float, else :class:`ControllerFailure` naming the law, the time and why."""
    name = getattr(getattr(law, "__self__", None), "name", getattr(law, "__qualname__", "the law"))
    try:
        out = law(t, *state)
    except Exception as exc:  # noqa: BLE001  (the user's law: its message, naming it and the time)
        raise ControllerFailure(f"controller {name!r} raised {type(exc).__name__} at t = {t:.6g} s: {exc}") from None
    try:
        u = float(out)
    except (TypeError, ValueError):
        shape = getattr(out, "shape", None)
        raise ControllerFailure(f"controller {name!r} returned {type(out).__name__}"
                                f"{'' if shape is None else f' of shape {shape}'} at t = {t:.6g} s; one voltage "
                                "(a float, V) is required") from None
    if not math.isfinite(u):
        raise ControllerFailure(f"controller {name!r} returned {u} V at t = {t:.6g} s (a finite voltage is required)")
    return u


def _read_signals(signals: Callable[[], Mapping[str, float]], names: tuple[str, ...], out: np.ndarray,
                  t: float) -> None:
    """The law's signals of this step into ``out`` (one per name), else :class:`ControllerFailure` saying why."""
    try:
        values = signals()
        for i, name in enumerate(names):
            out[i] = float(values[name])
    except Exception as exc:  # noqa: BLE001  (the user's hook: its message, naming the time)
        raise ControllerFailure(f"the law's signals() at t = {t:.6g} s: {type(exc).__name__}: {exc}; a dict of a "
                                f"float per name of signal_names {names} is required") from None


class _PythonStepper:
    """The same closed loop with the Python law, one mj_step at a time (no compiled law, or after a warning).

    ``law(t, alpha, alpha', alpha0, alpha0', alpha0'')`` is the controller's ``step``; ``strict``: a law the
    testbed does not compile (a plug-in) fails the run on an exception, a NaN or a value that is not one
    voltage (:class:`ControllerFailure`); the built-in laws apply 0 V for a NaN, as the compiled law does.
    """

    def __init__(self, model: mujoco.MjModel, where: _Plant, substeps: int, log: bool, law: Callable[..., float],
                 reference: tuple[np.ndarray, np.ndarray, np.ndarray], voltage_limit: float,
                 disturbance: np.ndarray | None = None, fields: Mapping[str, np.ndarray] | None = None, *,
                 period: float = 1.0, strict: bool = False, chain: Any = None,
                 signals: Callable[[], Mapping[str, float]] | None = None, signal_names: tuple[str, ...] = ()) -> None:
        self.model, self.where, self.substeps, self.log = model, where, substeps, log
        self.signals, self.signal_names = (signals, signal_names) if signal_names else (None, ())
        self.chain = chain  # the sensor between the plant and the law (wmr_mj.hardware.SensingChain), or None
        self.period, self.strict = period, strict
        self._own = False  # whether self.model is this stepper's own copy (made at the first load change)
        if fields:
            self.set_fields(fields)
        self.data = mujoco.MjData(self.model)
        mujoco.mj_resetDataKeyframe(self.model, self.data, where.keyframe)
        mujoco.mj_forward(self.model, self.data)
        self.law, self.reference, self.limit = law, reference, voltage_limit
        self.disturbance = disturbance

    def set_fields(self, fields: Mapping[str, np.ndarray]) -> None:
        """A load change: the fields in this stepper's own copy of the model, then mj_setConst."""
        if not self._own:
            self.model, self._own = copy.copy(self.model), True
        _set_model_fields(self.model, fields)

    def warnings(self) -> int:
        return int(sum(w.number for w in self.data.warning))

    def set_state(self, model: mujoco.MjModel, state: np.ndarray) -> None:
        """Continue from ``state`` (mjSTATE_INTEGRATION of ``model``, which may carry the law's userdata)."""
        spec = int(mujoco.mjtState.mjSTATE_INTEGRATION) & ~int(mujoco.mjtState.mjSTATE_USERDATA)
        full = mujoco.MjData(model)
        mujoco.mj_setState(model, full, state, mujoco.mjtState.mjSTATE_INTEGRATION)
        values = np.empty(mujoco.mj_stateSize(model, spec))
        mujoco.mj_getState(model, full, values, spec)
        mujoco.mj_setState(self.model, self.data, values, spec)
        if self.chain is not None:  # the sensor's memory, where the compiled law kept it
            adr = compiled_law.SENSING_STATE_ADR
            self.chain.state[:] = full.userdata[adr:adr + len(self.chain.state)]

    def step(self, block: _Block, k0: int, count: int) -> None:
        m, d, w = self.model, self.data, self.where
        qpos, qvel, ctrl = d.qpos, d.qvel, d.ctrl
        qa, dv, act, chassis, site_C, motor_dof = w.qpos, w.dof, w.actuator, w.chassis, w.site_C, w.motor_dof
        xquat, site_xpos, act_force, qfrc_act = d.xquat, d.site_xpos, d.actuator_force, d.qfrc_actuator
        limit, law, substeps, log, step = self.limit, self.law, self.substeps, self.log, mujoco.mj_step
        a0_all, a0d_all, a0dd_all = (r[k0:k0 + count].tolist() for r in self.reference)
        dist = None if self.disturbance is None else self.disturbance[k0:k0 + count].tolist()
        qfrc_applied = d.qfrc_applied
        quat = np.empty((count, 4))
        period, strict = self.period, self.strict
        chain, motor_qpos = self.chain, w.motor_qpos
        signals, names = self.signals, self.signal_names
        i2 = 0.0 if chain is None else float(chain.parameters[P_GEAR_RATIO])  # as the callback reads it
        for j in range(count):
            if dist is not None:
                qfrc_applied[dv] = dist[j]  # held over the control step's physics steps, as the callback does
            a = float(qpos[qa])
            ad = float(qvel[dv])
            am, adm = a, ad  # what the law reads: the state, or where the run has a sensor what it measures
            if chain is not None:
                am, adm = chain.step(k0 + j, a, ad, i2 * float(qpos[motor_qpos]))
                block.alpha_measured[j], block.alpha_dot_measured[j] = am, adm
            if strict:
                try:
                    u_cmd = _checked_call(law, (k0 + j) * period, am, adm, a0_all[j], a0d_all[j], a0dd_all[j])
                except ControllerFailure as exc:
                    exc.steps_done = j  # the control steps of this block recorded before the failing one
                    block.heading[:j] = _heading(quat[:j])
                    raise
            else:
                u_cmd = law((k0 + j) * period, am, adm, a0_all[j], a0d_all[j], a0dd_all[j])
            if signals is not None:
                try:
                    _read_signals(signals, names, block.law_signals[j], (k0 + j) * period)
                except ControllerFailure as exc:
                    exc.steps_done = j
                    block.heading[:j] = _heading(quat[:j])
                    raise
            if u_cmd != u_cmd:  # NaN from a diverged law: apply nothing, keep the record
                u = 0.0
            else:
                u = limit if u_cmd > limit else (-limit if u_cmd < -limit else u_cmd)
            ctrl[act] = u
            if log:
                block.qpos[j] = qpos
                block.qvel[j] = qvel
            for _ in range(substeps):
                step(m, d)
            # after mj_step, forces and kinematics belong to the state the step started from
            block.alpha[j] = a
            block.alpha_dot[j] = ad
            block.voltage_cmd[j] = u_cmd
            block.voltage[j] = u
            block.force[j] = act_force[act]
            block.torque[j] = qfrc_act[motor_dof]
            quat[j] = xquat[chassis]
            block.C_xy[j] = site_xpos[site_C, :2]
            if log:
                block.ctrl[j] = ctrl
                block.sites[j] = site_xpos
        block.heading[:] = _heading(quat)


@dataclass(frozen=True)
class Schedule:
    """What a run of :func:`run_engine` follows, control step by control step.

    ``reference`` = (alpha0, alpha0', alpha0'') on the control grid (at least n samples); ``n``
    control steps of ``substeps`` physics steps, ``period`` [s] each. ``disturbance``: a torque on
    the steering joint [N m] per control step (at least n samples); ``loads``: (control step, model
    fields) of each load change (:func:`load_fields`), in step order. ``tracker``: a
    :class:`controllers.tracking.PathTracker` (reset with ``path_reference``), whose outer loop writes the
    next block's reference before each block of its period, from C's position, the heading and C's
    speed of the control step before; the rows' alpha0 are then the tracker's.
    """

    reference: tuple[np.ndarray, np.ndarray, np.ndarray]
    n: int
    substeps: int
    period: float
    disturbance: np.ndarray | None = None
    loads: Sequence[tuple[int, Mapping[str, np.ndarray]]] = ()
    tracker: Any = None  # a controllers.tracking.PathTracker
    path_reference: Any = None  # the path's Reference, which the tracker is reset with
    sensing: Any = None  # the steering sensor (wmr_mj.hardware.Sensing); None or ideal: the law reads the state


def run_engine(*, params: C80Parameters, controller: Any, options: dict[str, Any], schedule: Schedule,
               law: str = "auto", on_block: Callable[[dict[str, np.ndarray]], None] | None = None,
               on_progress: Callable[[int], None] | None = None, model: mujoco.MjModel | None = None) -> EngineRun:
    """Run ``schedule.n`` control steps of ``controller`` on the plant of ``params``; rows of every control step.

    ``schedule`` (:class:`Schedule`): the reference, the control grid, the signals, the tracker and the
    sensor. ``on_block(block)``, where given, receives the rows of every simulated second with qpos,
    qvel, ctrl (at each control step's start, ctrl as applied), A_pos and C_pos (xy of sites A
    and C); ``on_progress(steps)`` the control steps of each block. KeyboardInterrupt (Ctrl-C,
    SIGTERM made one) ends the run as "interrupted" with the blocks simulated so far; a block
    committed but not yet handed to ``on_block`` is handed over before returning. ``model``:
    ``batch_model(params, **options)`` where the caller has it already.

    The steps: resolve the backend and the plant's indices, check the inputs, reset the law (and the
    tracker), build the first stepper (:func:`_first_stepper`), then :class:`_BlockLoop` steps the blocks.
    """
    backend, note = _backend(controller, law)
    plain = batch_model(params, **options) if model is None else model
    where = _Plant(plain)
    reference, disturbance, loads = _checked_inputs(schedule)
    strict = not compiled_law.supports(controller)
    chain = _sensing_chain(schedule, params)
    names = law_signal_names(controller)
    controller.reset(control_period=schedule.period)
    if schedule.tracker is not None:
        schedule.tracker.reset(schedule.path_reference, control_period=schedule.period)

    def python_stepper(fields: Mapping[str, np.ndarray] | None = None) -> _PythonStepper:
        return _PythonStepper(plain, where, schedule.substeps, on_block is not None, controller.step, reference,
                              params.voltage_limit, disturbance, fields, period=schedule.period, strict=strict,
                              chain=chain, signals=controller.signals if names else None, signal_names=names)

    if backend == "compiled":
        first: _CompiledStepper | _PythonStepper
        first, lawful, ref_adr = _compiled_stepper(params, controller, options, where, schedule, reference,
                                                   disturbance, on_block is not None, chain)
    else:
        first, lawful, ref_adr = python_stepper(), None, 0
    loop = _BlockLoop(first, python_stepper, schedule=schedule, plain=plain, where=where, reference=reference,
                      loads=loads, sensed=chain is not None, k_i=params.k_i, on_block=on_block, lawful=lawful,
                      ref_adr=ref_adr, note=note, signal_names=names)
    with held_mujoco_warnings() as texts:  # counted and reported once (EngineRun), never printed per step
        run = loop.run(on_progress)
    return dataclasses.replace(run, warning_text=texts[0]) if texts else run


class _BlockLoop:
    """The block loop of :func:`run_engine` and the state its steps share: the stepper (which may fall back to
    the Python law), the reference (which a tracker rewrites), the rows, the load fields in effect and the
    rows handed over so far.

    Every feature of a run is chosen once, here, never per block: the tracker's outer loop is the hook run
    before each block (:meth:`_track`, else nothing), the fall-back is the compiled stepper's way of stepping
    (:meth:`_step_watching`, else :meth:`_step_plain`), load changes are cut into the block by
    :meth:`_step_block`, and the sensor lives in the steppers.
    """

    def __init__(self, stepper: _CompiledStepper | _PythonStepper,
                 python_stepper: Callable[[Mapping[str, np.ndarray] | None], _PythonStepper], *, schedule: Schedule,
                 plain: mujoco.MjModel, where: _Plant, reference: tuple[np.ndarray, np.ndarray, np.ndarray],
                 loads: list[tuple[int, dict[str, np.ndarray]]], sensed: bool, k_i: float,
                 on_block: Callable[[dict[str, np.ndarray]], None] | None, lawful: mujoco.MjModel | None,
                 ref_adr: int, note: str | None, signal_names: tuple[str, ...] = ()) -> None:
        self.stepper, self.python_stepper = stepper, python_stepper
        self.n, self.period, self.tracker = schedule.n, schedule.period, schedule.tracker
        self.plain, self.where, self.reference, self.loads = plain, where, reference, loads
        self.sensed, self.k_i, self.on_block = sensed, k_i, on_block
        self.lawful, self.ref_adr = lawful, ref_adr  # the compiled law's model and its reference's address
        self.log = on_block is not None
        self.used = "compiled" if isinstance(stepper, _CompiledStepper) else "python"
        self.note = note
        self.signal_keys = tuple(LAW_SIGNAL_PREFIX + name for name in signal_names)
        self.rows = {key: np.empty(self.n) for key in ROW_FIELDS + SENSED_ROW_FIELDS * sensed + self.signal_keys}
        self.C_xy = np.empty((self.n, 2))
        self.block_len = max(1, int(round(1.0 / self.period)))  # one simulated second per block
        if self.tracker is not None:
            self.block_len = self.tracker.block_steps  # the outer loop's period
        self.blocks: dict[int, _Block] = {}
        self.in_effect: dict[str, np.ndarray] = {}  # the load fields set so far (a later Python stepper starts so)
        self.warned = 0  # warnings counted by a stepper left behind
        self.k0 = self.cnt = self.k = self.sent = 0  # the block being stepped, the steps done, the rows handed over
        self.before_block: Callable[[int, int], None] = self._track if self.tracker is not None else _nothing
        self.advance: Callable[[_Block, int, int], None] = (
            self._step_watching if isinstance(stepper, _CompiledStepper) else self._step_plain)

    def run(self, on_progress: Callable[[int], None] | None) -> EngineRun:
        """Step every block; an interrupt or a law's failure ends the run with the steps done before it."""
        status, failure = "completed", None
        wall0, cpu0 = time.perf_counter(), time.thread_time()
        try:
            # The hot loop: one rollout call, or one Python stepper call, per block of control steps and no
            # Python per physics step; no branch per feature (the hooks were chosen in __init__).
            for k0 in range(0, self.n, self.block_len):
                self.k0 = k0
                self.cnt = cnt = min(self.block_len, self.n - k0)
                b = self.blocks.get(cnt)
                if b is None:
                    b = self.blocks[cnt] = _Block(cnt, self.plain, self.log, self.sensed, len(self.signal_keys))
                self.before_block(k0, cnt)
                self.advance(b, k0, cnt)
                _record_block(self.rows, self.C_xy, b, k0, self.period, self.reference, self.k_i, self.signal_keys)
                self.k = k0 + cnt
                self.hand_over(self.k)
                if on_progress is not None:
                    on_progress(cnt)
        except KeyboardInterrupt:
            status = "interrupted"
        except ControllerFailure as exc:  # the run stops at the failing step; what was simulated before it stays
            status, failure = "failed", str(exc)
            self._keep_steps_before(exc.steps_done)
        if self.k:
            self.hand_over(self.k)  # a block interrupted between its rows and its hand-over
        wall, cpu = time.perf_counter() - wall0, time.thread_time() - cpu0
        k = self.k
        return EngineRun(rows={key: v[:k] for key, v in self.rows.items()}, steps=k, status=status,
                         warnings=self.warned + self.stepper.warnings(), law=self.used, law_note=self.note,
                         wall_s=wall, cpu_s=cpu, C_xy=self.C_xy[:k], failure=failure)

    def _keep_steps_before(self, done_in_block: int) -> None:
        """A law failed in the block at k0: its ``done_in_block`` steps before the failure become rows."""
        if done_in_block and self.k == self.k0:
            part = self.blocks[done_in_block] = _Block.head(self.blocks[self.cnt], done_in_block)
            self.cnt = done_in_block
            _record_block(self.rows, self.C_xy, part, self.k0, self.period, self.reference, self.k_i,
                          self.signal_keys)
            self.k = self.k0 + done_in_block

    def hand_over(self, upto: int) -> None:
        """The rows up to control step ``upto`` not handed to ``on_block`` yet, with the block's log arrays."""
        if self.on_block is None or upto <= self.sent:
            return
        rows, b, where = self.rows, self.blocks[self.cnt], self.where
        block = {key: rows[key][self.sent:upto] for key in rows}
        lo = self.sent - self.k0  # the rows of this block not handed over yet
        block.update(qpos=b.qpos[lo:], qvel=b.qvel[lo:], ctrl=b.ctrl[lo:],
                     A_pos=b.sites[lo:, where.site_A, :2], C_pos=b.sites[lo:, where.site_C, :2])
        self.sent = upto  # first: an interrupt raised as the block is written must not send it twice
        self.on_block(block)

    def _track(self, k0: int, cnt: int) -> None:
        """The tracker's outer loop: it measures C after the last block, then writes this block's reference."""
        tracker, C_xy, rows, period = self.tracker, self.C_xy, self.rows, self.period
        if k0:
            # C's speed over the control step before (NaN until two samples exist)
            speed = (math.hypot(*(C_xy[k0 - 1] - C_xy[k0 - 2])) / period) if k0 >= 2 else math.nan
            tracker.measure(rows["t"][k0 - 1], C_xy[k0 - 1], rows["heading"][k0 - 1], speed)
        sl = slice(k0, k0 + cnt)
        a0_all, a0d_all, a0dd_all = self.reference
        a0_all[sl], a0d_all[sl], a0dd_all[sl] = _tracker_block(tracker, k0, cnt)
        if self.lawful is not None:  # the compiled law reads its reference from the model
            self.lawful.numeric_data[self.ref_adr + 3 * k0:self.ref_adr + 3 * (k0 + cnt)] = np.stack(
                [a0_all[sl], a0d_all[sl], a0dd_all[sl]], axis=1).ravel()

    def _step_plain(self, b: _Block, k0: int, cnt: int) -> None:
        self._step_block(self.stepper, b, k0, cnt)

    def _step_watching(self, b: _Block, k0: int, cnt: int) -> None:
        """A block on the compiled law; where MuJoCo warns (rollout stops a simulation whose warnings rise), the
        block again from its first state with the Python law, which goes on after a warning as mj_step does,
        and the rest of the run with it (the sensor's memory carried over: :meth:`_PythonStepper.set_state`)."""
        stepper = cast(_CompiledStepper, self.stepper)  # this way of stepping is chosen for the compiled stepper
        before, start, fields_before = stepper.warnings(), stepper.state(), dict(self.in_effect)
        self._step_block(stepper, b, k0, cnt)
        if stepper.warnings() == before:
            return
        python = self.python_stepper(fields_before)
        python.set_state(self.lawful, start)
        self.warned, self.stepper, self.used, self.advance = before, python, "python", self._step_plain
        self.note = "MuJoCo warned; the run went on from that block with the Python law"
        self.in_effect.clear()
        self.in_effect.update(fields_before)
        self._step_block(python, b, k0, cnt)

    def _step_block(self, st: _CompiledStepper | _PythonStepper, b: _Block, k0: int, cnt: int) -> None:
        """Step one block; with load changes in it, in parts, each change set at its control step."""
        due = [(kc, f) for kc, f in self.loads if k0 <= kc < k0 + cnt]
        if not due:
            st.step(b, k0, cnt)
            return
        edges = sorted({k0, *(kc for kc, _ in due), k0 + cnt})
        for s0, s1 in zip(edges, edges[1:]):
            for kc, f in due:
                if kc == s0:
                    st.set_fields(f)
                    self.in_effect.update(f)
            part = _Block(s1 - s0, self.plain, self.log, len(b.alpha_measured) > 0)
            st.step(part, s0, s1 - s0)
            sl = slice(s0 - k0, s1 - k0)
            for name, value in vars(part).items():  # every record the part has rows of (C_xy included)
                if len(value):
                    getattr(b, name)[sl] = value


def _nothing(k0: int, cnt: int) -> None:
    """No hook before a block (a run without a tracker)."""


def _tracker_block(tracker: Any, k0: int, cnt: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The tracker's reference for control steps k0 .. k0 + cnt, checked: three finite arrays of cnt values."""
    try:
        out = tracker.block(k0, cnt)
        a0, a0d, a0dd = (np.asarray(x, dtype=np.float64) for x in out)
    except (TypeError, ValueError) as exc:
        raise ControllerFailure(f"tracker {getattr(tracker, 'name', type(tracker).__name__)!r}: block() must "
                                f"return (alpha0, alpha0', alpha0'') of {cnt} values each ({exc})") from None
    except Exception as exc:  # noqa: BLE001  (the user's tracker: its message, naming it)
        raise ControllerFailure(f"tracker {getattr(tracker, 'name', type(tracker).__name__)!r} raised "
                                f"{type(exc).__name__}: {exc}") from None
    for x in (a0, a0d, a0dd):
        if x.shape != (cnt,) or not np.all(np.isfinite(x)):
            raise ControllerFailure(f"tracker {getattr(tracker, 'name', type(tracker).__name__)!r}: block() must "
                                    f"return three arrays of {cnt} finite values, got shape {x.shape}")
    return a0, a0d, a0dd


def _checked_inputs(schedule: Schedule) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], np.ndarray | None,
                                                 list[tuple[int, dict[str, np.ndarray]]]]:
    """The schedule's reference (a copy where the tracker rewrites it), disturbance and load
    changes (sorted by step), each checked against the run's length."""
    n, tracker = schedule.n, schedule.tracker
    a0_all, a0d_all, a0dd_all = (np.array(r, dtype=np.float64) if tracker is not None
                                 else np.asarray(r, dtype=np.float64) for r in schedule.reference)
    if len(a0_all) < n:
        raise ParameterError(f"reference shorter than the run: {len(a0_all)} < {n} samples")
    disturbance, loads = schedule.disturbance, schedule.loads
    if disturbance is not None:
        disturbance = np.asarray(disturbance, dtype=np.float64)
        if len(disturbance) < n:
            raise ParameterError(f"disturbance shorter than the run: {len(disturbance)} < {n} samples")
    ordered = sorted(((int(k), dict(f)) for k, f in loads), key=lambda kf: kf[0])
    return (a0_all, a0d_all, a0dd_all), disturbance, ordered


def _sensing_chain(schedule: Schedule, params: C80Parameters) -> SensingChain | None:
    """The run's sensor as a chain over its control steps; None where the law reads the state itself."""
    sensing = schedule.sensing
    if sensing is None or sensing.is_ideal:
        return None
    return SensingChain(sensing, control_period=schedule.period, n_steps=schedule.n, gear_ratio=params.i2)


def _compiled_stepper(params: C80Parameters, controller: Any, options: dict[str, Any], where: _Plant,
                      schedule: Schedule, reference: tuple[np.ndarray, np.ndarray, np.ndarray],
                      disturbance: np.ndarray | None, log: bool,
                      chain: SensingChain | None = None) -> tuple[_CompiledStepper, mujoco.MjModel, int]:
    """The compiled law's stepper, its model (which carries the reference and the sensor) and the reference's
    address in it."""
    n, substeps = schedule.n, schedule.substeps
    compiled_law.install()
    vector = compiled_law.law_vector(controller, voltage_limit=params.voltage_limit, substeps=substeps, nstep=n,
                                     qpos_adr=where.qpos, dof_adr=where.dof, actuator=where.actuator,
                                     chassis=where.chassis)
    assert vector is not None  # the backend is 'compiled' only where compiled_law.compiles(controller)
    sensing = None if chain is None else (compiled_law.sensing_numeric(chain, motor_qpos_adr=where.motor_qpos),
                                          len(chain.state))
    carried = (vector, reference, None if disturbance is None else disturbance[:n], sensing)
    lawful = batch_model(params, law=carried, **options)
    stepper = _CompiledStepper(lawful, where, substeps, log, own_model=schedule.tracker is not None,
                               sensing=chain is not None)
    ref_numeric = lawful.numeric(compiled_law.REFERENCE_NUMERIC)
    return stepper, lawful, int(lawful.numeric_adr[ref_numeric.id])


def _record_block(rows: dict[str, np.ndarray], C_xy: np.ndarray, b: _Block, k0: int, period: float,
                  reference: tuple[np.ndarray, np.ndarray, np.ndarray], k_i: float,
                  signal_keys: tuple[str, ...] = ()) -> None:
    """The rows of one stepped block (control steps k0 .. k0 + len(b)), and C's xy (and the law's signals)."""
    a0_all, a0d_all, a0dd_all = reference
    cnt = len(b.alpha)
    sl = slice(k0, k0 + cnt)
    rows["t"][sl] = np.arange(k0, k0 + cnt) * period
    rows["alpha"][sl] = b.alpha
    rows["alpha_dot"][sl] = b.alpha_dot
    rows["alpha0"][sl] = a0_all[sl]
    rows["alpha0_dot"][sl] = a0d_all[sl]
    rows["alpha0_ddot"][sl] = a0dd_all[sl]
    np.subtract(a0_all[sl], b.alpha, out=rows["E"][sl])
    np.subtract(a0d_all[sl], b.alpha_dot, out=rows["E_dot"][sl])
    rows["voltage_cmd"][sl] = b.voltage_cmd
    rows["voltage"][sl] = b.voltage
    np.divide(b.force, k_i, out=rows["current"][sl])
    rows["steer_torque"][sl] = b.torque
    rows["heading"][sl] = b.heading
    C_xy[sl] = b.C_xy
    if len(b.alpha_measured):
        rows["alpha_measured"][sl] = b.alpha_measured
        rows["alpha_dot_measured"][sl] = b.alpha_dot_measured
    for i, key in enumerate(signal_keys):
        rows[key][sl] = b.law_signals[:, i]
