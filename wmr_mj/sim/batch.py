"""Many closed-loop runs at once on ``mujoco.batch``: the engine of sweeps and searches.

``run_batch`` runs configs that differ only in their plant parameters (m1 and any other
named parameter), each simulation on its own compiled model, and reports each run exactly
as a single ``wmr_mj.sim.closed_loop.run_closed_loop`` would (tests keep them bit-identical).

How a batch runs at the speed of open-loop ``mujoco.rollout`` (bench/bench_sweep.py):

- the law runs in C, inside every ``mj_step``, as MuJoCo's control callback
  (:mod:`wmr_mj.sim.compiled_law`: ``voltage_scalar`` operation for operation, bit-identical);
  ``mujoco.batch.Batch.rollout`` then runs a block of 1000 closed-loop steps of every
  simulation per call, on every thread, with no Python in between;
- where the compiled law cannot run (not built, ``WMR_MJ_COMPILED_LAW=0``, a controller
  subclass), the NumPy law: the simulations are split into groups, each a ``Batch``
  stepped on its own thread with its own vectorised law (``controller.batch_law``: NumPy
  ``out=`` buffers, nothing allocated per step), one group's law overlapping the others'
  physics; ``run_batch(law=...)`` chooses;
- statistics are folded in blocks of 1000 steps, not step by step;
- models are compiled without the scene's sky texture (95% of compiling it).

Usage::

    from wmr_mj.sim.batch import run_batch
    from wmr_mj.sim.config import RunConfig
    base = RunConfig(model="nonholonomic", duration=20.0)
    reports = run_batch([base.replace(m1=m) for m in (550.0, 650.0, 750.0)], nthread=2)
    [r.sup_E for r in reports]           # each a RunSummary, as run_closed_loop(config).summary
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import math
import os
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

from wmr_mj._util.memory import require_memory
from wmr_mj.analysis.requirements import parse_requirement
from wmr_mj.analysis.verdicts import drift, drift_window_steps
from wmr_mj.errors import ParameterError
from wmr_mj.params import C80, M1_NOMINAL, C80Parameters
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.reference.route import RouteProgress
from wmr_mj.sim import compiled_law
from wmr_mj.sim.closed_loop import (
    PathJudgement,
    RunMeasures,
    judge_path,
    judge_requirements,
    path_sample_index,
    report,
    run_closed_loop,
)
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.config import RunConfig, has_tracker
from wmr_mj.sim.engine import LAW_BACKENDS, _heading, batch_law_backend, batch_model, held_mujoco_warnings
from wmr_mj.sim.parts import RunLabels, RunParts, plant_and_claim, resolve_run
from wmr_mj.sim.summary import BatchFigures, RunSummary, voltage_effort

__all__ = ["run_batch", "shares_one_batch", "batch_model", "batch_law_backend", "LAW_BACKENDS", "thread_count",
           "batch_groups"]

def thread_count(nthread: int, nsim: int) -> int:
    """Threads for nsim simulations: nthread, or every core this process may use when 0."""
    if nthread < 0:
        raise ParameterError(f"nthread = {nthread} is not accepted; give 0 (all cores) or a count >= 1")
    if nthread == 0:
        nthread = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    return max(1, min(nthread, nsim))


def batch_groups(nsim: int, threads: int) -> list[tuple[np.ndarray, int]]:
    """(simulation indices, batch threads) of each group: one Python thread per group.

    min(threads, nsim // 32) groups, at least one: each law call costs about 5 us whatever
    the group's size, under the GIL, so small groups pay it too often; the threads left
    over step inside the groups' batches. Measured (2 threads, 10 s runs, run_batch wall):
    16 simulations ran at 232.6k steps/s in one group against 216.2k in two, 32 at 247.2k
    against 244.7k, 64 at 262.5k against 262.9k.
    """
    ngroups = max(1, min(threads, nsim // 32))
    per_group = np.array_split(np.arange(threads), ngroups)
    return [(idx, len(t)) for idx, t in zip(np.array_split(np.arange(nsim), ngroups), per_group)]


@dataclass
class _BatchStats:
    """Per-simulation statistics of a batch, written by the group loops at their indices."""

    nsim: int
    sup_E: np.ndarray = field(init=False)
    sup_Ed: np.ndarray = field(init=False)
    sup_E_s: np.ndarray = field(init=False)
    sup_Ed_s: np.ndarray = field(init=False)
    saturated: np.ndarray = field(init=False)
    left_at: np.ndarray = field(init=False)
    final_alpha: np.ndarray = field(init=False)
    final_alpha_after_step: np.ndarray = field(init=False)
    warnings: np.ndarray = field(init=False)
    law_nan: np.ndarray = field(init=False)  # the law gave NaN: re-run as a single run
    drift_prev: np.ndarray = field(init=False)  # max |E| over the window before the last (wmr_mj.analysis.verdicts)
    drift_last: np.ndarray = field(init=False)  # max |E| over the last window
    drift_halves: np.ndarray = field(init=False)  # (nsim, 2) max |E| over the first and second half of the last
    control_steps: int = 0  # the runs' control steps (the rows of ``voltage``)
    voltage: np.ndarray = field(init=False)  # (control_steps, nsim) the applied voltage [V] (its effort)
    final_alpha_dot: np.ndarray = field(init=False)  # alpha0' - E' of the last control step
    path_samples: int = 0  # control steps at which C is sampled (closed_loop.path_sample_index)
    C_xy: np.ndarray = field(init=False)  # (nsim, path_samples, 2) C's xy there [m]
    heading: np.ndarray = field(init=False)  # (nsim, path_samples) the chassis heading there [rad]
    cpu_s: list[float] = field(default_factory=list)  # CPU time of each group's thread

    def __post_init__(self) -> None:
        n = self.nsim
        self.law_nan = np.zeros(n, dtype=bool)
        self.sup_E, self.sup_Ed, self.sup_E_s, self.sup_Ed_s = (np.zeros(n) for _ in range(4))
        self.saturated, self.warnings = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
        self.left_at, self.final_alpha, self.final_alpha_after_step = (np.full(n, np.nan) for _ in range(3))
        self.drift_prev, self.drift_last = np.zeros(n), np.zeros(n)
        self.drift_halves = np.zeros((n, 2))
        self.voltage = np.full((self.control_steps, n), np.nan)
        self.final_alpha_dot = np.full(n, np.nan)
        self.C_xy = np.full((n, self.path_samples, 2), np.nan)
        self.heading = np.full((n, self.path_samples), np.nan)


@dataclass(frozen=True, kw_only=True)
class _Loop:
    """What every group's control loop shares: reference, timing, limits, indices."""

    alpha0: np.ndarray
    alpha0_dot: np.ndarray
    alpha0_ddot: np.ndarray
    n: int  # control steps
    substeps: int
    period: float
    settle_k: int
    drift_k: int  # control steps per drift window (wmr_mj.analysis.verdicts.drift_window_steps)
    block: int
    qpos_adr: int
    dof_adr: int
    actuator: int
    keyframe: int
    voltage_limit: np.ndarray  # (nsim,)
    range_limit: np.ndarray  # (nsim,)
    path_at: np.ndarray  # control steps at which C's xy and the heading are kept (closed_loop.path_sample_index)
    chassis: int  # the chassis body (its heading)
    site_C: int  # site C (its xy)


def _run_group(loop: _Loop, models: Sequence[mujoco.MjModel], idx: np.ndarray, threads: int, law,
               stats: _BatchStats, stop: threading.Event, progress: Callable[[int, int], None] | None) -> None:
    """The closed loop of simulations ``idx`` on one thread, from the home keyframe to the end.

    Groups share nothing but the GIL, held only while the law runs: while one thread
    computes its law, the others step (mujoco.batch releases the GIL), and no thread
    waits for another at the end of a step. The loop body is what a control step costs
    beyond the physics (bench/bench_sweep.py): a copy, the law, two clips, the step call.
    """
    from mujoco.batch import Batch

    g = len(idx)
    batch = Batch(models[0], nsim=g, nthread=threads)
    batch.set_models(list(models))
    batch.reset(keyframe=loop.keyframe)
    alpha_now = batch.bind("qpos")[:, loop.qpos_adr]  # views of the state rows: no copy
    alpha_dot_now = batch.bind("qvel")[:, loop.dof_adr]
    ctrl_now = batch.bind("ctrl")[:, loop.actuator]
    C_now = batch.bind("site_xpos")[:, loop.site_C, :2]  # after a step: of the state it started from
    quat_now = batch.bind("xquat")[:, loop.chassis]
    block = loop.block
    C_buf, q_buf = np.empty((block, g, 2)), np.empty((block, g, 4))
    bufs = a_buf, E_buf, Ed_buf, u_buf = tuple(np.empty((block, g)) for _ in range(4))
    rows = [list(buf) for buf in bufs]  # row views made once, not at every step
    clipped = np.empty(g)
    lo, hi = -loop.voltage_limit[idx], loop.voltage_limit[idx]
    range_limit = loop.range_limit[idx]
    step, nstep = batch.step, loop.substeps
    maximum, minimum = np.maximum, np.minimum
    for k0 in range(0, loop.n, block):
        count = min(block, loop.n - k0)
        reference = (loop.alpha0[k0:k0 + count].tolist(), loop.alpha0_dot[k0:k0 + count].tolist(),
                     loop.alpha0_ddot[k0:k0 + count].tolist())
        for j, (alpha, E, E_dot, u, a0, a0d, a0dd) in enumerate(zip(*rows, *reference)):
            alpha[:] = alpha_now  # recorded: the state row changes with the step
            law(alpha, alpha_dot_now, a0, a0d, a0dd, E, E_dot, u)
            # the voltage limit; a NaN passes through to MuJoCo, which then warns (BADCTRL), and
            # the simulation is re-run serially (run_batch), where NaN applies nothing
            maximum(u, lo, out=clipped)
            minimum(clipped, hi, out=ctrl_now)
            step(nstep=nstep)
            C_buf[j] = C_now
            q_buf[j] = quat_now
        _path_stats(loop, stats, idx, k0, count, C_buf, q_buf)
        _block_stats(loop, stats, idx, k0, count, a_buf, E_buf, Ed_buf, u_buf, lo, hi, range_limit)
        if _stopped(loop, k0 + count, stop, progress):
            return
    _final_stats(loop, stats, idx, batch, a_buf[count - 1], Ed_buf[count - 1], alpha_now)


def _stopped(loop: _Loop, done: int, stop: threading.Event, progress: Callable[[int, int], None] | None) -> bool:
    """Report ``done`` control steps; whether the group must stop (another group failed, Ctrl-C)."""
    if progress is not None:
        progress(done, loop.n)
    return stop.is_set()


def _final_stats(loop: _Loop, stats: _BatchStats, idx: np.ndarray, batch, last_alpha: np.ndarray,
                 last_E_dot: np.ndarray, alpha_now: np.ndarray) -> None:
    """The end-of-run figures of a group from its last control step and its final state."""
    stats.final_alpha[idx] = last_alpha
    stats.final_alpha_dot[idx] = loop.alpha0_dot[loop.n - 1] - last_E_dot  # as the serial run computes it
    stats.final_alpha_after_step[idx] = alpha_now
    stats.warnings[idx] = batch.warning[:, :, 1].sum(axis=1)  # (nsim, mjNWARNING, (lastinfo, number))


def _run_group_compiled(loop: _Loop, models: Sequence[mujoco.MjModel], idx: np.ndarray, threads: int,
                        stats: _BatchStats, stop: threading.Event,
                        progress: Callable[[int, int], None] | None) -> None:
    """The closed loop of simulations ``idx`` with the compiled law, a block of steps per call.

    The law runs inside every mj_step (``wmr_mj.sim.compiled_law``: mjcb_control), so
    ``Batch.rollout`` runs a whole block of control steps in C on ``threads`` threads; the
    block's userdata (alpha, E, E', the law's voltage at every control step) is then folded
    into the statistics as the NumPy loop folds its buffers. Rollout stops a simulation whose
    warning counters rise; run_batch re-runs those as single runs (run_closed_loop).
    """
    from mujoco.batch import Batch

    g = len(idx)
    batch = Batch(models[0], nsim=g, nthread=threads)
    batch.set_models(list(models))
    batch.reset(keyframe=loop.keyframe)
    alpha_now = batch.bind("qpos")[:, loop.qpos_adr]
    lo, hi = -loop.voltage_limit[idx], loop.voltage_limit[idx]
    range_limit = loop.range_limit[idx]
    substeps = loop.substeps
    heading_field = compiled_law.USERDATA_FIELDS.index("heading")
    records: dict[int, dict[str, np.ndarray]] = {}  # one output buffer per block length, reused
    for k0 in range(0, loop.n, loop.block):
        count = min(loop.block, loop.n - k0)
        out = records.setdefault(count, {})
        # the record after each physics step; a control step's values hold over its substeps
        with held_mujoco_warnings():  # not printed per step: the run re-run alone counts and reports them
            rec = batch.rollout(count * substeps, record=("userdata", "site_xpos"), out=out)
        out.update(rec)
        userdata = rec["userdata"][:, ::substeps]
        a_buf, E_buf, Ed_buf, u_buf = (userdata[:, :, j].T for j in range(4))  # (count, g) views
        # C and the heading after each control step's last substep, as the single run records them
        end = slice(substeps - 1, None, substeps)
        sites = rec["site_xpos"][:, end].reshape(g, count, -1, 3)
        _path_stats(loop, stats, idx, k0, count, sites[:, :, loop.site_C, :2].transpose(1, 0, 2),
                    heading=rec["userdata"][:, end, heading_field].T)
        _block_stats(loop, stats, idx, k0, count, a_buf, E_buf, Ed_buf, u_buf, lo, hi, range_limit)
        if _stopped(loop, k0 + count, stop, progress):
            return
    _final_stats(loop, stats, idx, batch, a_buf[count - 1], Ed_buf[count - 1], alpha_now)


def _path_stats(loop: _Loop, stats: _BatchStats, idx: np.ndarray, k0: int, rows: int, C_buf: np.ndarray,
                quat: np.ndarray | None = None, heading: np.ndarray | None = None) -> None:
    """Keep C's xy and the heading (or the chassis quaternion's yaw) of control steps k0 .. k0+rows-1
    that are path samples; (rows, g, ...) buffers."""
    lo, hi = np.searchsorted(loop.path_at, [k0, k0 + rows])
    if lo == hi:
        return
    local = loop.path_at[lo:hi] - k0
    stats.C_xy[idx, lo:hi] = C_buf[local].transpose(1, 0, 2)
    if heading is None:
        if quat is None:
            raise ParameterError("_path_stats needs the heading or the chassis quaternions")
        q = quat[local].reshape(-1, 4)
        heading = _heading(q).reshape(len(local), -1)
        stats.heading[idx, lo:hi] = heading.T
    else:
        stats.heading[idx, lo:hi] = heading[local].T


def _block_stats(loop: _Loop, stats: _BatchStats, idx: np.ndarray, k0: int, rows: int, a_buf, E_buf, Ed_buf,
                 u_buf, lo, hi, range_limit) -> None:
    """Fold control steps k0 .. k0+rows-1 into the statistics (max and count are exact in bulk)."""
    E = np.abs(E_buf[:rows])
    Ed = np.abs(Ed_buf[:rows])
    stats.sup_E[idx] = np.maximum(stats.sup_E[idx], E.max(axis=0))
    stats.sup_Ed[idx] = np.maximum(stats.sup_Ed[idx], Ed.max(axis=0))
    first_settled = max(loop.settle_k - k0, 0)
    if first_settled < rows:
        stats.sup_E_s[idx] = np.maximum(stats.sup_E_s[idx], E[first_settled:].max(axis=0))
        stats.sup_Ed_s[idx] = np.maximum(stats.sup_Ed_s[idx], Ed[first_settled:].max(axis=0))
    u = u_buf[:rows]
    # saturated as in the serial loop: the applied voltage differs from the law's (NaN included)
    stats.saturated[idx] += (~((u >= lo) & (u <= hi))).sum(axis=0)
    # the applied voltage, clipped as the step applied it (its effort: wmr_mj.sim.summary.voltage_effort)
    stats.voltage[k0:k0 + rows, idx] = np.minimum(np.maximum(u, lo), hi)
    stats.law_nan[idx] |= np.isnan(u).any(axis=0)
    hit = np.abs(a_buf[:rows]) >= range_limit
    first = np.where(hit.any(axis=0), hit.argmax(axis=0), -1)
    new = np.isnan(stats.left_at[idx]) & (first >= 0)
    stats.left_at[idx[new]] = (k0 + first[new]) * loop.period
    w = loop.drift_k
    for lo_k, hi_k, out in ((loop.n - 2 * w, loop.n - w, stats.drift_prev), (loop.n - w, loop.n, stats.drift_last)):
        a, b = max(lo_k - k0, 0), min(hi_k - k0, rows)
        if a < b:
            out[idx] = np.maximum(out[idx], E[a:b].max(axis=0))
    half = loop.n - w + w // 2  # the last window's halves (wmr_mj.sim.closed_loop._drift_of)
    for j, (lo_k, hi_k) in enumerate(((loop.n - w, half), (half, loop.n))):
        a, b = max(lo_k - k0, 0), min(hi_k - k0, rows)
        if a < b:
            stats.drift_halves[idx, j] = np.maximum(stats.drift_halves[idx, j], E[a:b].max(axis=0))


def run_batch(configs: Sequence[RunConfig], *, nthread: int = 0, base: C80Parameters = C80,
              progress: Callable[[int, int], None] | None = None, law: str = "auto",
              requirements: Sequence[str] = ()) -> list[RunSummary]:
    """Run closed-loop configs, all at once where they share one batch.

    Configs that differ only in their plant parameters (m1, plant_overrides) and have no
    signals and no path tracker share one batch (:func:`shares_one_batch`). ``law``
    (:data:`LAW_BACKENDS`, :func:`batch_law_backend`): 'compiled' runs one
    ``mujoco.batch.Batch`` of every simulation on ``nthread`` threads (0: every core) with
    the law in MuJoCo's control callback, a block of steps per ``Batch.rollout`` call;
    'numpy' splits the simulations into groups (:func:`batch_groups`), each a ``Batch`` on
    its own Python thread with its own vectorised law (``controller.batch_law``), so that
    the law of one group runs while the others step; 'auto' (the default) takes the
    compiled law where it can run. Each simulation has its own compiled model.

    Configs that cannot share a batch (each its own reference, signals or tracker; a law with state) and runs
    with ``requirements`` (STL formulas or presets, :mod:`wmr_mj.analysis.requirements`, whose
    monitor needs every control step's signals, which a batch does not keep) run one by one on
    the engine (``run_closed_loop``), ``nthread`` at a time on threads (each engine call
    releases the GIL while MuJoCo steps).

    Returns per-run :class:`RunSummary` records, each bit-identical to ``run_closed_loop`` of
    the same config, whichever the law. Their ``batch.cpu_s`` is the CPU time of the group
    threads (a figure for benchmarks on a shared machine; batch-internal threads excluded),
    ``batch.law`` the law that ran; ``requirements`` holds each requirement judged.
    """
    if not configs:
        return []
    configs = [coerced(c) for c in configs]  # each config's references read once, here (a config already typed: none)
    first = configs[0]
    if requirements or not shares_one_batch(configs):
        return _run_one_by_one(configs, base=base, progress=progress, law=law, nthread=nthread,
                               requirements=tuple(requirements))
    parts = resolve_run(first, base=base)  # the batch's shared parts: law, reference, grid, analysis
    controller = parts.controller
    if controller.stateful:  # a law with state (or time) has no batch form: each run on the engine
        return _run_one_by_one(configs, base=base, progress=progress, law=law, nthread=nthread)
    backend = batch_law_backend(controller, law)
    # each further run's plant and the shared law's claim on it (parts.plant_and_claim), the first's from its parts
    further = [plant_and_claim(c, parts, base=base) for c in configs[1:]]
    plants = [parts.plant] + [plant for plant, _ in further]
    claims = [parts.claim] + [claim for _, claim in further]
    options = parts.options
    model = batch_model(plants[0], **options)
    nsim = len(configs)
    substeps, period, n = parts.substeps, parts.period, parts.n
    reference, settle_s = parts.reference, parts.settle_s
    rows = (np.asarray(reference.alpha0), np.asarray(reference.alpha0_dot), np.asarray(reference.alpha0_ddot))
    steer = model.joint("steer").id
    where = dict(qpos_adr=int(model.jnt_qposadr[steer]), dof_adr=int(model.jnt_dofadr[steer]),
                 actuator=model.actuator("steering_motor").id,
                 chassis=model.body("chassis").id)  # the same in every simulation's model; the law writes the heading
    models = _simulation_models(backend, controller, plants, options, model, (substeps, n), rows, where)
    analysis = parts.analysis
    path_at = path_sample_index(n, period)
    require_memory(nsim * len(path_at) * 3 * 8, what=f"C's path samples of a batch of {nsim} runs",
                   hint="run fewer at once (a smaller chunk)")
    loop = _Loop(alpha0=rows[0], alpha0_dot=rows[1], alpha0_ddot=rows[2], n=n, substeps=substeps, period=period,
                 settle_k=int(math.ceil(settle_s / period - 1e-9)), drift_k=drift_window_steps(n, period),
                 block=min(n, 1000), **where, keyframe=model.key("home").id,
                 voltage_limit=np.array([p.voltage_limit for p in plants]),
                 range_limit=np.array([p.steering_range for p in plants]) - 1e-3,
                 path_at=path_at, site_C=model.site("C").id)
    stats = _BatchStats(nsim, path_samples=len(path_at), control_steps=n)
    threads = thread_count(nthread, nsim)
    # the compiled law holds no GIL: one batch on every thread
    groups = [(np.arange(nsim), threads)] if backend == "compiled" else batch_groups(nsim, threads)
    stop = threading.Event()
    errors: list[BaseException] = []

    def work(idx: np.ndarray, threads: int, report_progress) -> None:
        try:
            cpu0 = time.thread_time()
            group_models = [models[i] for i in idx]
            if backend == "compiled":
                _run_group_compiled(loop, group_models, idx, threads, stats, stop, report_progress)
            else:
                _run_group(loop, group_models, idx, threads, controller.batch_law(len(idx)), stats, stop,
                           report_progress)
            stats.cpu_s.append(time.thread_time() - cpu0)
        except BaseException as exc:  # noqa: BLE001  (re-raised on the calling thread)
            errors.append(exc)
            stop.set()

    # The groups' threads run here in one piece: each group's block loop (_run_group*) is the hot
    # loop, one Batch.rollout call per block and no Python per step; this only starts, joins and
    # stops them.
    wall0 = time.perf_counter()
    workers = [threading.Thread(target=work, args=(idx, threads, None), daemon=True) for idx, threads in groups[1:]]
    for w in workers:
        w.start()
    try:
        idx0, threads0 = groups[0]
        work(idx0, threads0, progress)  # the calling thread runs the first group and reports progress
    finally:
        for w in workers:
            while w.is_alive():
                try:
                    w.join()
                except KeyboardInterrupt:  # stop the groups at their next block, then re-raise
                    stop.set()
                    raise
    if errors:
        raise errors[0]
    wall = time.perf_counter() - wall0
    return _summaries(configs, plants, stats, _BatchRun(base=base, reference=reference, settle_s=settle_s,
                                                       analysis=analysis, loop=loop, backend=backend, wall=wall,
                                                       threads=threads, parts=parts, claims=tuple(claims)))


def shares_one_batch(configs: Sequence[RunConfig]) -> bool:
    """Whether ``configs`` run as one batch: no signals, no tracker, an ideal cart (no sensor, actuation or
    play: the batch's loops read the state and drive the axle), and nothing but m1 and plant_overrides differs
    (the batch's simulations share one reference and one law)."""
    configs = [coerced(c) for c in configs]  # typed parts to compare (a config already typed: itself)
    if any(c.signals is not None or has_tracker(c) or not _ideal_cart(c) for c in configs):
        return False
    shared = configs[0].replace(m1=M1_NOMINAL, plant_overrides={})
    return all(c.replace(m1=M1_NOMINAL, plant_overrides={}) == shared for c in configs[1:])


def _ideal_cart(config: RunConfig) -> bool:
    return config.sensing.is_ideal and config.actuation.is_ideal and config.transmission.is_ideal


def _simulation_models(backend: str, controller: Any, plants: Sequence[C80Parameters], options: dict[str, Any],
                       model: mujoco.MjModel, grid: tuple[int, int], rows: tuple[np.ndarray, ...],
                       where: dict[str, int]) -> list[mujoco.MjModel]:
    """One model per simulation (``model`` is the first plant's, without the law); with the compiled
    law each carries the law and the reference. grid: (substeps, n)."""
    substeps, n = grid
    nsim = len(plants)
    if backend == "compiled":
        # each model carries the reference (3 float64 per control step), for the callback
        require_memory(nsim * n * 3 * 8, what=f"a batch of {nsim} runs of {n} control steps with the compiled law",
                       hint="run fewer at once (a smaller chunk) or the NumPy law (WMR_MJ_COMPILED_LAW=0)")
        compiled_law.install()
        # law_vector is None only for a law compiles() refuses (neither built in nor compiled by numba), and
        # then the backend is not 'compiled'
        return [batch_model(p, law=(compiled_law.law_vector(controller, voltage_limit=p.voltage_limit,
                                                            substeps=substeps, nstep=n, **where), rows),
                            **options) for p in plants]
    return [model] + [batch_model(p, **options) for p in plants[1:]]


@dataclass(frozen=True)
class _BatchRun:
    """What :func:`_summaries` needs of a finished batch besides its statistics."""

    base: C80Parameters
    reference: Any
    settle_s: float
    analysis: Any
    loop: _Loop
    backend: str
    wall: float
    threads: int  # the batch's threads, which also judge C's paths
    parts: RunParts  # the first config's, which the batch's simulations share but for the plant
    claims: tuple[Any, ...]  # each simulation's claim: the shared law on its own plant (plant_and_claim)


def _summaries(configs: Sequence[RunConfig], plants: Sequence[C80Parameters], stats: _BatchStats,
               run: _BatchRun) -> list[RunSummary]:
    """Each simulation's :class:`RunSummary` from the batch's statistics (a serial re-run where the
    batch's law gave NaN or MuJoCo warned), with the batch-level figures."""
    base, reference, settle_s, analysis = run.base, run.reference, run.settle_s, run.analysis
    n, substeps, period, path_at = run.loop.n, run.loop.substeps, run.loop.period, run.loop.path_at
    backend, wall, nsim = run.backend, run.wall, len(configs)
    parts = run.parts
    certificates = run.claims  # each simulation's claim: the shared law on its own plant (plant_and_claim)

    def path_of(i: int) -> PathJudgement | None:
        return judge_path(reference, path_at * period, stats.C_xy[i], stats.heading[i], settle_s=settle_s,
                          certificate=certificates[i], steering_range=plants[i].steering_range)

    # C's projections are NumPy work that releases the GIL: judged on the batch's threads, each run alone
    with concurrent.futures.ThreadPoolExecutor(max(1, min(run.threads, nsim))) as pool:
        paths = list(pool.map(path_of, range(nsim)))

    progress = (None if parts.route_length_m is None  # one path: one progress
                else RouteProgress.along(parts.route_length_m, reference, n * substeps * TIMESTEP))
    reports = []
    # the configs differ only in their plants (shares_one_batch): the first's labels are every run's
    labels = parts.labels if parts.labels is not None else RunLabels.of(configs[0], name=parts.controller_name)
    for i, (c, p) in enumerate(zip(configs, plants)):
        certificate = certificates[i]
        measured = RunMeasures(status="completed", settle_s=settle_s, sup_E=stats.sup_E[i], sup_Edot=stats.sup_Ed[i],
                               sup_E_settled=stats.sup_E_s[i], sup_Edot_settled=stats.sup_Ed_s[i],
                               saturated_fraction=stats.saturated[i] / n,
                               left_range_at=None if np.isnan(stats.left_at[i]) else float(stats.left_at[i]),
                               final_alpha=stats.final_alpha[i], control_steps=n, steps=n * substeps,
                               wall_s=wall / nsim, effort=voltage_effort(stats.voltage[:, i], period))
        r = report(labels, measured, analysis=analysis, params=p, certificate=certificate,
                   claims_nothing=certificate is None,
                   drift=drift(prev_window=float(stats.drift_prev[i]), last_window=float(stats.drift_last[i]),
                               final_alpha_dot=float(stats.final_alpha_dot[i]),
                               last_halves=((float(stats.drift_halves[i, 0]), float(stats.drift_halves[i, 1]))
                                            if run.loop.drift_k >= 2 else None)),
                   path=paths[i])
        if stats.law_nan[i] if backend == "numpy" else stats.warnings[i]:
            # NumPy law: NaN from the law, where the serial loop applies 0 V and MuJoCo would zero
            # every control of the step (BADCTRL); compiled law (which applies 0 V as the serial
            # loop does): a warning, after which rollout stopped the simulation. The serial run
            # is the truth
            serial = run_closed_loop(c, progress=False, base=base).summary
            r = dataclasses.replace(serial, analysis=None, controller_config=None)  # report's fields and the warnings
        else:
            r = dataclasses.replace(r, mujoco_warnings=int(stats.warnings[i]), paper_law=run.parts.paper_law,
                                    law_settings=run.parts.law_settings, route=progress)
        r = dataclasses.replace(r, batch=BatchFigures(
            final_alpha_after_step=float(stats.final_alpha_after_step[i]),  # the serial run reports the last row
            # batch-level figures for benchmarks
            wall_s=wall, steps_per_s=nsim * n * substeps / wall if wall > 0 else None,
            cpu_s=sum(stats.cpu_s),  # robust to a shared machine, unlike the wall time
            law=backend))
        reports.append(r)
    return reports


def _run_one_by_one(configs: Sequence[RunConfig], *, base: C80Parameters, progress: Callable[[int, int], None] | None,
                    law: str, nthread: int = 1, requirements: tuple[str, ...] = ()) -> list[RunSummary]:
    """Runs that do not share a batch, each a single run on the engine, ``nthread`` at a time.

    A run with a path tracker (``controllers.tracking``) rewrites its own reference
    from its state between blocks; a run with signals, or on its own path, has inputs of its
    own; and a requirement's monitor needs every control step's signals: the batch's loops
    share one reference and keep statistics only. Each summary is run_closed_loop's (the
    requirements judged on its rows); ``batch.final_alpha_after_step`` is NaN: a single run
    does not keep the state after its last step. ``batch.wall_s`` is the wall time of them
    all, ``batch.cpu_s`` the sum of the threads' CPU time.
    """
    def period_of(config: RunConfig) -> float:
        return TIMESTEP if config.control_period is None else config.control_period

    # parsed here, on the calling thread: a bad formula fails before any run, and rtamt is imported
    # once (its modules deadlock when two threads import them at once)
    parsed = {p: [parse_requirement(text, period=p) for text in requirements] for p in {period_of(c) for c in configs}}
    monitor = threading.Lock()  # rtamt is pure Python and toggles process-wide logging: one run at a time

    def one(config: RunConfig) -> tuple[RunSummary, str, float]:
        cpu0 = time.thread_time()
        result = run_closed_loop(config, progress=False, base=base, law=law)
        summary = result.summary
        if requirements:
            period = period_of(config)
            judged = judge_requirements(result, parsed[period], period=period, base=base, monitor=monitor)
            summary = dataclasses.replace(summary, requirements=tuple(judged))
        return summary, result.law, time.thread_time() - cpu0

    threads = thread_count(nthread, len(configs))
    wall0 = time.perf_counter()
    done: list[tuple[RunSummary, str, float]] = []
    if threads == 1:
        for c in configs:
            done.append(one(c))
            if progress is not None:
                progress(len(done), len(configs))
    else:
        with concurrent.futures.ThreadPoolExecutor(threads) as pool:
            futures = [pool.submit(one, c) for c in configs]
            try:
                for k, fut in enumerate(concurrent.futures.as_completed(futures)):
                    fut.result()  # the first failure, raised here
                    if progress is not None:
                        progress(k + 1, len(configs))
            except BaseException:
                for fut in futures:
                    fut.cancel()
                raise
            done = [fut.result() for fut in futures]
    wall = time.perf_counter() - wall0
    cpu = sum(c for _, _, c in done)
    steps = sum(s.steps for s, _, _ in done)
    return [dataclasses.replace(s, analysis=None, controller_config=None, batch=BatchFigures(
        final_alpha_after_step=math.nan, wall_s=wall, steps_per_s=steps / wall if wall > 0 else None, cpu_s=cpu,
        law=used)) for s, used, _ in done]  # 'compiled' or 'python': one by one on the engine, as run


# -- sweeps: chunks, resume, Dask ---------------------------------------------------------
