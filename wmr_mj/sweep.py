"""Model-mismatch sweeps: many closed-loop runs at once on ``mujoco.batch``.

The plant's m1 (and any other named parameter) is drawn over its range; each
simulation runs on its own compiled model (mass and inertia consistent, as
``wmr_mj.params.with_params``), the controller acts on all simulations in one
vectorised call per control step, and each run is reported exactly as a single
``wmr_mj.simulate.run_closed_loop`` would report it (a test keeps them
bit-identical).

Usage::

    from wmr_mj.simulate import RunConfig
    from wmr_mj.sweep import SweepSpec, run_sweep
    spec = SweepSpec(n=64, seed=1, sampling="lhs", base=RunConfig(model="nonholonomic", duration=20.0))
    results = run_sweep(spec)             # list of per-run report dicts, in run order

``run_sweep(spec, out_dir=...)`` writes ``runs.csv`` after every chunk and
resumes from it; ``scheduler="tcp://host:8786"`` runs the chunks on a Dask
cluster with the same results.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from .errors import ParameterError, SchedulerError, UnknownNameError
from .params import C80, C80Parameters, parameter_names
from .plant import compile_model
from .simulate import (
    RunConfig,
    _controller,
    _estimate_of,
    _substeps,
    analysis_for,
    build_reference,
    estimate_parameters,
    plant_parameters,
    report,
)

__all__ = [
    "SweepSpec",
    "draw_samples",
    "run_batch",
    "run_sweep",
    "SAMPLINGS",
    "RESULT_COLUMNS",
    "read_results",
]

SAMPLINGS = ("uniform", "lhs", "grid")
RESULT_COLUMNS = ("run", "m1", "sup_E", "sup_Edot", "sup_E_settled", "sup_Edot_settled", "E_max", "Edot_max",
                  "E_ratio", "Edot_ratio", "inside", "saturated_fraction", "left_steering_range", "final_alpha")


def _check_range(name: str, lo: float, hi: float) -> tuple[float, float]:
    lo, hi = float(lo), float(hi)
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ParameterError(f"range of {name} = ({lo}, {hi}) must be finite")
    if lo >= hi:
        raise ParameterError(f"range of {name} = ({lo}, {hi}) is empty or inverted; give LO < HI")
    if lo <= 0:
        raise ParameterError(f"range of {name} = ({lo}, {hi}) must be > 0 (every C80 parameter is positive)")
    return lo, hi


@dataclass(frozen=True, kw_only=True)
class SweepSpec:
    """n runs of ``base`` with the plant's m1 (and ``ranges``) drawn by ``sampling``."""

    n: int = 200
    seed: int = 0
    sampling: str = "lhs"
    m1_range: tuple[float, float] = (550.0, 750.0)
    ranges: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    base: RunConfig = field(default_factory=RunConfig)

    def __post_init__(self) -> None:
        if not isinstance(self.n, int) or self.n < 1:
            raise ParameterError(f"n = {self.n!r} is not accepted; the number of runs must be an integer >= 1")
        if self.sampling not in SAMPLINGS:
            raise UnknownNameError("sampling", self.sampling, SAMPLINGS)
        _check_range("m1", *self.m1_range)
        names = set(parameter_names()) - {"m1"}
        for name, (lo, hi) in self.ranges.items():
            if name not in names:
                raise UnknownNameError("parameter", name, names)
            _check_range(name, lo, hi)
        if self.sampling == "grid":
            d = 1 + len(self.ranges)
            k = round(self.n ** (1.0 / d))
            if k**d != self.n:
                raise ParameterError(f"grid sampling of {d} parameter(s) needs n = k^{d}; n = {self.n} is not")

    @property
    def names(self) -> tuple[str, ...]:
        return ("m1", *self.ranges.keys())

    @property
    def bounds(self) -> np.ndarray:
        return np.array([self.m1_range, *self.ranges.values()], dtype=float)

    def base_for_box(self) -> RunConfig:
        return self.base.replace(m1_range=tuple(self.m1_range), box_ranges=dict(self.ranges))

    def fingerprint(self) -> str:
        """Identifies the sweep, so that resuming never mixes two different sweeps."""
        obj = {"n": self.n, "seed": self.seed, "sampling": self.sampling, "m1_range": list(self.m1_range),
               "ranges": {k: list(v) for k, v in self.ranges.items()}, "base": self.base.as_dict()}
        return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]


def draw_samples(spec: SweepSpec) -> np.ndarray:
    """(n, d) parameter values: m1 first, then ``spec.ranges`` in order. Seeded."""
    bounds = spec.bounds
    d = len(bounds)
    rng = np.random.default_rng(spec.seed)
    if spec.sampling == "uniform":
        unit = rng.random((spec.n, d))
    elif spec.sampling == "lhs":
        from scipy.stats import qmc

        unit = qmc.LatinHypercube(d=d, rng=rng).random(spec.n)
    else:
        k = round(spec.n ** (1.0 / d))
        axes = [np.linspace(0.0, 1.0, k)] if k > 1 else [np.array([0.5])]
        unit = np.stack(np.meshgrid(*(axes * d), indexing="ij"), axis=-1).reshape(-1, d)
    return bounds[:, 0] + unit * (bounds[:, 1] - bounds[:, 0])


def _run_configs(spec: SweepSpec, samples: np.ndarray) -> list[RunConfig]:
    base = spec.base_for_box()
    out = []
    for row in samples:
        overrides = dict(base.plant_overrides)
        overrides.update({name: float(v) for name, v in zip(spec.names[1:], row[1:])})
        out.append(base.replace(m1=float(row[0]), plant_overrides=overrides))
    return out


def run_batch(configs: Sequence[RunConfig], *, nthread: int = 0, base: C80Parameters = C80,
              progress: Callable[[int, int], None] | None = None) -> list[dict[str, Any]]:
    """Run closed-loop configs that differ only in their plant parameters, all at once.

    One ``mujoco.batch.Batch`` with one compiled model per simulation; one
    vectorised controller call per control step. Returns per-run reports.
    """
    from mujoco.batch import Batch

    if not configs:
        return []
    first = configs[0]
    shared = first.replace(m1=650.0, plant_overrides={})
    for c in configs[1:]:
        if c.replace(m1=650.0, plant_overrides={}) != shared:
            raise ParameterError("run_batch needs configs that differ only in m1 and plant_overrides")
    estimate = estimate_parameters(base)
    controller = _controller(first, estimate)
    plants = [plant_parameters(c, base) for c in configs]
    models = [compile_model(p)[0] for p in plants]
    model = models[0]
    nsim = len(configs)
    dt = model.opt.timestep
    substeps = _substeps(first, dt)
    period = substeps * dt
    n = int(round(first.duration / period))
    reference, settle_s = build_reference(first.path, estimate, dt=period, duration=n * period)
    analysis = analysis_for(first, reference, estimate, estimate=_estimate_of(controller))
    a0_all, a0d_all, a0dd_all = reference.alpha0, reference.alpha0_dot, reference.alpha0_ddot

    batch = Batch(model, nsim=nsim, nthread=nthread)
    batch.set_models(models)
    batch.reset(keyframe=model.key("home").id)
    qpos, qvel, ctrl = batch.bind("qpos"), batch.bind("qvel"), batch.bind("ctrl")
    qa = model.jnt_qposadr[model.joint("steer").id]
    dv = model.jnt_dofadr[model.joint("steer").id]
    act = model.actuator("steering_motor").id
    limits = np.array([p.voltage_limit for p in plants])
    range_limits = np.array([p.steering_range for p in plants]) - 1e-3
    sup_E = np.zeros(nsim)
    sup_Ed = np.zeros(nsim)
    sup_E_s = np.zeros(nsim)
    sup_Ed_s = np.zeros(nsim)
    saturated = np.zeros(nsim, dtype=np.int64)
    left_at = np.full(nsim, np.nan)
    settle_k = int(math.ceil(settle_s / period - 1e-9))
    law = controller.voltage
    # per-step work is only the law and the voltage limit; the statistics of a block of
    # steps are computed in bulk (the same numbers as step by step: max and count are exact)
    block = min(n, 1000)
    a_buf, ad_buf = np.empty((block, nsim)), np.empty((block, nsim))
    ucmd_buf, u_buf = np.empty((block, nsim)), np.empty((block, nsim))
    lo, hi = -limits, limits

    def block_stats(k0: int, rows: int) -> None:
        ks = np.arange(k0, k0 + rows)
        E = np.abs(a0_all[ks, None] - a_buf[:rows])
        Ed = np.abs(a0d_all[ks, None] - ad_buf[:rows])
        np.maximum(sup_E, E.max(axis=0), out=sup_E)
        np.maximum(sup_Ed, Ed.max(axis=0), out=sup_Ed)
        after = ks >= settle_k
        if after.any():
            np.maximum(sup_E_s, E[after].max(axis=0), out=sup_E_s)
            np.maximum(sup_Ed_s, Ed[after].max(axis=0), out=sup_Ed_s)
        saturated[:] += (u_buf[:rows] != ucmd_buf[:rows]).sum(axis=0)
        hit = np.abs(a_buf[:rows]) >= range_limits
        first = np.where(hit.any(axis=0), hit.argmax(axis=0), -1)
        new = np.isnan(left_at) & (first >= 0)
        left_at[new] = (k0 + first[new]) * period

    wall0 = time.perf_counter()
    j = 0
    k0 = 0
    for k in range(n):
        alpha = a_buf[j]
        alpha_dot = ad_buf[j]
        alpha[:] = qpos[:, qa]
        alpha_dot[:] = qvel[:, dv]
        u_cmd = law(alpha, alpha_dot, a0_all[k], a0d_all[k], a0dd_all[k])
        ucmd_buf[j] = u_cmd
        u = np.clip(u_cmd, lo, hi, out=u_buf[j])
        np.nan_to_num(u, copy=False, nan=0.0)  # a diverged law applies nothing, as in the serial loop
        ctrl[:, act] = u
        batch.step(nstep=substeps)
        j += 1
        if j == block:
            block_stats(k0, j)
            k0, j = k + 1, 0
            if progress is not None:
                progress(k + 1, n)
    if j:
        block_stats(k0, j)
    alpha = a_buf[j - 1] if j else a_buf[block - 1]
    wall = time.perf_counter() - wall0
    final_alpha = qpos[:, qa].copy()  # state after the last step; the serial run reports the last control row
    reports = []
    for i, (c, p) in enumerate(zip(configs, plants)):
        r = report(c, analysis=analysis, params=p, settle_s=settle_s, sup_E=sup_E[i], sup_Edot=sup_Ed[i],
                   sup_E_settled=sup_E_s[i], sup_Edot_settled=sup_Ed_s[i], saturated_fraction=saturated[i] / n,
                   left_range_at=None if np.isnan(left_at[i]) else float(left_at[i]), final_alpha=alpha[i],
                   control_steps=n, steps=n * substeps, wall_s=wall / nsim, status="completed")
        r["final_alpha_after_step"] = float(final_alpha[i])
        r["mujoco_warnings"] = 0
        reports.append(r)
    # batch-level figures for benchmarks
    for r in reports:
        r["batch_wall_s"] = wall
        r["batch_steps_per_s"] = nsim * n * substeps / wall if wall > 0 else None
    return reports


# -- sweeps: chunks, resume, Dask ---------------------------------------------------------

def _run_chunk(spec_json: str, indices: list[int], nthread: int,
               progress: Callable[[int, int], None] | None = None) -> list[dict[str, Any]]:
    """Run the sweep's runs ``indices`` (a Dask task: arguments and result are plain data)."""
    spec = spec_from_json(spec_json)
    samples = draw_samples(spec)
    configs = _run_configs(spec, samples[indices])
    reports = run_batch(configs, nthread=nthread, progress=progress)
    for i, r in zip(indices, reports):
        r["run"] = int(i)
        for name, value in zip(spec.names[1:], samples[i][1:]):
            r[name] = float(value)
    return reports


def spec_to_json(spec: SweepSpec) -> str:
    base = spec.base.as_dict()
    return json.dumps({"n": spec.n, "seed": spec.seed, "sampling": spec.sampling, "m1_range": list(spec.m1_range),
                       "ranges": {k: list(v) for k, v in spec.ranges.items()}, "base": base}, sort_keys=True)


def spec_from_json(text: str) -> SweepSpec:
    obj = json.loads(text)
    base = dict(obj["base"])
    base["m1_range"] = tuple(base["m1_range"])
    base["box_ranges"] = {k: tuple(v) for k, v in base.get("box_ranges", {}).items()}
    return SweepSpec(n=obj["n"], seed=obj["seed"], sampling=obj["sampling"], m1_range=tuple(obj["m1_range"]),
                     ranges={k: tuple(v) for k, v in obj["ranges"].items()}, base=RunConfig(**base))


def _csv_text(rows: list[dict[str, Any]], extra: Sequence[str]) -> str:
    buf = io.StringIO()
    cols = list(RESULT_COLUMNS[:2]) + list(extra) + list(RESULT_COLUMNS[2:])
    w = csv.DictWriter(buf, fieldnames=cols, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for r in sorted(rows, key=lambda r: r["run"]):
        w.writerow({k: _cell(r.get(k)) for k in cols})
    return buf.getvalue()


def _cell(value: Any) -> Any:
    """CSV text of a value: floats round-trip exactly (repr), None is empty."""
    if value is None:
        return ""
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    return value


def read_results(path: str | os.PathLike) -> list[dict[str, Any]]:
    """Rows of a sweep's runs.csv, numbers parsed."""
    out = []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            parsed: dict[str, Any] = {}
            for k, v in row.items():
                if v == "":
                    parsed[k] = None
                elif v in ("True", "False"):
                    parsed[k] = v == "True"
                else:
                    try:
                        parsed[k] = int(v) if k == "run" else float(v)
                    except ValueError:
                        parsed[k] = v
            out.append(parsed)
    return out


def _connect(scheduler: str):
    try:
        from distributed import Client
    except ImportError:
        raise SchedulerError("--scheduler needs the Dask extra: pip install 'wmr-mj[dask]'") from None
    try:
        return Client(scheduler, timeout="5s", set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SchedulerError(f"cannot reach the Dask scheduler at {scheduler!r} ({type(exc).__name__}); "
                             "give the address of a running scheduler, e.g. tcp://127.0.0.1:8786") from None


def run_sweep(spec: SweepSpec, *, out_dir: str | os.PathLike | None = None, chunk: int = 128, nthread: int = 0,
              scheduler: str | None = None, progress: Callable[[int, int], None] | None = None) -> list[dict[str, Any]]:
    """All runs of ``spec``, in run order. With ``out_dir``: runs.csv (atomic, after every chunk) and resume.

    progress(done, total) is called as runs finish and, locally, as a chunk steps (done
    is then fractional).
    """
    from .io import write_json_atomic, write_text_atomic

    if chunk < 1:
        raise ParameterError(f"chunk = {chunk} must be >= 1")
    done: dict[int, dict[str, Any]] = {}
    out = Path(out_dir) if out_dir is not None else None
    extra = list(spec.names[1:])
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        state_path, csv_path = out / "sweep.json", out / "runs.csv"
        fp = spec.fingerprint()
        if state_path.is_file() and csv_path.is_file():
            try:
                state = json.loads(state_path.read_text())
            except json.JSONDecodeError:
                state = {}
            if state.get("fingerprint") == fp:
                for r in read_results(csv_path):
                    done[int(r["run"])] = r
        write_json_atomic(state_path, {"fingerprint": fp, "spec": json.loads(spec_to_json(spec))})
    todo = [i for i in range(spec.n) if i not in done]
    chunks = [todo[i:i + chunk] for i in range(0, len(todo), chunk)]
    spec_json = spec_to_json(spec)

    def record(reports: list[dict[str, Any]]) -> None:
        for r in reports:
            done[r["run"]] = r
        if out is not None:
            write_text_atomic(out / "runs.csv", _csv_text(list(done.values()), extra))
        if progress is not None:
            progress(len(done), spec.n)

    if progress is not None:
        progress(len(done), spec.n)
    if scheduler is not None:
        client = _connect(scheduler)
        try:
            futures = [client.submit(_run_chunk, spec_json, c, 1, pure=False) for c in chunks]
            for fut in futures:  # in order; each finished chunk is saved before the next is awaited
                record(fut.result())
        finally:
            client.close()
    else:
        for c in chunks:
            base_done = len(done)
            step_progress = None
            if progress is not None:
                def step_progress(k: int, n: int, base_done=base_done, size=len(c)) -> None:
                    progress(base_done + size * k / n, spec.n)  # fractional runs while a chunk steps
            record(_run_chunk(spec_json, c, nthread, step_progress))
    return [done[i] for i in range(spec.n)]
