"""Model-mismatch sweeps: many closed-loop runs at once on ``mujoco.batch``.

The plant's m1 (and any other named parameter) is drawn over its range; each
simulation runs on its own compiled model (mass and inertia consistent, as
``wmr_mj.params.with_params``), and each run is reported exactly as a single
``wmr_mj.sim.closed_loop.run_closed_loop`` would report it (a test keeps them
bit-identical).

Each chunk of runs is one ``wmr_mj.sim.batch.run_batch`` (all at once on ``mujoco.batch``,
the law compiled into MuJoCo's control callback); a run's row is :func:`wmr_mj.sim.many_runs.flat_row`.

Usage::

    from wmr_mj.sim.closed_loop import RunConfig
    from wmr_mj.experiments.sweep import SweepSpec, run_sweep
    spec = SweepSpec(n=64, seed=1, sampling="lhs", base=RunConfig(model="nonholonomic", duration=20.0))
    results = run_sweep(spec)             # per-run rows (a summary's JSON, flat), in run order

``run_sweep(spec, out_dir=...)`` writes ``runs.csv`` after every chunk and
resumes from it; ``scheduler="tcp://host:8786"`` runs the chunks on a Dask
cluster with the same results. ``wmr_mj.sim.many_runs.run_configs`` runs any list of configs that
differ in plant parameters only (what ``wmr_mj.searches.falsify`` evaluates).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from wmr_mj._util.checks import positive_range
from wmr_mj._util.files import write_json_atomic, write_text_atomic
from wmr_mj.analysis.path_bound import PATH_VERDICTS
from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE, PASS, count_unmet, count_verdicts, unmet_assumptions
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.params import parameter_names, tie_motor_constant
from wmr_mj.searches.search_space import (
    HARDWARE_AXES,
    check_hardware_range,
    hardware_axis,
    hardware_values,
    with_hardware,
)
from wmr_mj.sim.batch import run_batch
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.config import RunConfig, config_from_dict
from wmr_mj.sim.many_runs import RESULT_COLUMNS, connect, csv_number, flat_row, latin_hypercube, requirement_column
from wmr_mj.sim.records import BrokenRun, Record, UnmetAssumption

__all__ = [
    "SweepSpec",
    "draw_samples",
    "run_sweep",
    "SAMPLINGS",
    "read_results",
    "read_runs",
    "max_at",
    "Worst",
    "BrokenRun",
    "SweepSummary",
    "config_from_dict",
    "RequirementSweep",
    "Effort",
    "EffortLevel",
    "AxisEffort",
    "sweep_over_box",
]

SAMPLINGS = ("uniform", "lhs", "grid")


def _count_path_verdicts(rows: Sequence[Mapping[str, Any]]) -> dict[str, int] | None:
    """The count of each path verdict in ``rows`` (zeros included); None when no row has one."""
    seen = [str(r["path_verdict"]) for r in rows if r.get("path_verdict")]
    if not seen:
        return None
    return {v: seen.count(v) for v in (*PATH_VERDICTS, *sorted(set(seen) - set(PATH_VERDICTS)))}


@dataclass(frozen=True, kw_only=True)
class SweepSpec:
    """n runs of ``base`` with the plant's m1 (and ``ranges``) drawn by ``sampling``; with ``m1``, every run's
    m1 is that (the other axes swept alone) and ``m1_range`` stays the certificate's box."""

    n: int = 200
    seed: int = 0
    sampling: str = "lhs"
    # the m1 box, kg: drawn over (m1 not fixed) and the certificate's; None: the base's (its cart's m1 box, the C80's
    # 550-750 kg where it names none)
    m1_range: tuple[float, float] = None  # type: ignore[assignment]
    m1: float | None = None  # a fixed m1 [kg]: every run's; None: drawn over m1_range
    ranges: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    base: RunConfig = field(default_factory=RunConfig)
    # STL requirements (formulas or presets, wmr_mj.analysis.requirements) judged on every run: such
    # sweeps run one by one on the engine (the batch keeps no per-step signals to monitor)
    requirements: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "requirements", tuple(self.requirements))
        if self.m1_range is None:  # the base's box: its cart's (RunConfig(cart=...)), read where the base names one
            object.__setattr__(self, "m1_range", tuple(coerced(self.base).m1_range))
        if not isinstance(self.n, int) or self.n < 1:
            raise ParameterError(f"n = {self.n!r} is not accepted; the number of runs must be an integer >= 1")
        if self.sampling not in SAMPLINGS:
            raise UnknownNameError("sampling", self.sampling, SAMPLINGS)
        positive_range("m1", *self.m1_range)
        if self.m1 is not None and (isinstance(self.m1, bool) or not isinstance(self.m1, (int, float))
                                    or not (math.isfinite(self.m1) and self.m1 > 0)):
            raise ParameterError(f"m1 = {self.m1!r} is not accepted; a fixed m1 is a finite number of kg > 0")

        names = set(parameter_names()) - {"m1"}
        for name, (lo, hi) in self.ranges.items():
            if hardware_axis(name):
                check_hardware_range(self.base, name, lo, hi)
                continue
            if name not in names:
                raise UnknownNameError("axis name", name, [*sorted(names), *HARDWARE_AXES])
            positive_range(name, lo, hi)
        # k_i and k_b both ranged: each run takes k_b = k_i, so k_b's range must hold k_i's (refused before any run)
        tie_motor_constant({name: lo for name, (lo, _hi) in self.ranges.items()}, self.ranges)
        if self.sampling == "grid":
            d = self.grid_dimensions
            if d == 0:
                raise ParameterError("grid sampling with a fixed m1 needs a ranged parameter (--range NAME=LO:HI)")
            k = round(self.n ** (1.0 / d))
            if k**d != self.n:
                raise ParameterError(f"grid sampling of {d} parameter(s) needs n = k^{d}; n = {self.n} is not")

    @property
    def grid_dimensions(self) -> int:
        """The axes a grid spans: the ranged parameters, and m1 unless it is fixed."""
        return len(self.ranges) + (0 if self.m1 is not None else 1)

    @property
    def names(self) -> tuple[str, ...]:
        return ("m1", *self.ranges.keys())

    @property
    def bounds(self) -> np.ndarray:
        m1 = self.m1_range if self.m1 is None else (self.m1, self.m1)  # a fixed m1: a zero-width draw
        return np.array([m1, *self.ranges.values()], dtype=float)

    @property
    def hardware_names(self) -> tuple[str, ...]:
        """The ranged axes of the cart (:data:`wmr_mj.searches.search_space.HARDWARE_AXES`), in order: drawn per run,
        never part of the certificate's plant box (each run's claim covers its own cart)."""
        return tuple(n for n in self.ranges if hardware_axis(n))

    def base_for_box(self) -> RunConfig:
        plant = {k: v for k, v in self.ranges.items() if k not in self.hardware_names}
        return self.base.replace(m1_range=tuple(self.m1_range), box_ranges=plant)

    def config_at(self, values: Sequence[float]) -> RunConfig:
        """The run of one draw (``values`` in :attr:`names` order: m1 first): m1 and the plant parameters set,
        the cart's axes set in its parts (rounded to what a run can have)."""
        base = self.base_for_box()
        hardware = set(self.hardware_names)
        overrides = dict(base.plant_overrides)
        overrides.update(tie_motor_constant({n: float(v) for n, v in zip(self.names[1:], values[1:])
                                             if n not in hardware}, self.ranges))
        config = base.replace(m1=float(values[0]), plant_overrides=overrides)
        return with_hardware(config, {n: float(v) for n, v in zip(self.names[1:], values[1:]) if n in hardware})

    def recorded_values(self, values: Sequence[float]) -> dict[str, float]:
        """Each ranged axis but m1 -> the value its run used (runs.csv's columns): a plant parameter as drawn
        (k_b as k_i where both are ranged: :func:`wmr_mj.params.tie_motor_constant`), a hardware axis as rounded
        (:func:`wmr_mj.searches.search_space.hardware_values`)."""
        out = tie_motor_constant({n: float(v) for n, v in zip(self.names[1:], values[1:])}, self.ranges)
        out.update(hardware_values(self.base, {n: out[n] for n in self.hardware_names}))
        return out

    @property
    def requirement_columns(self) -> tuple[str, ...]:
        """runs.csv's robustness column of each requirement, in order."""
        return tuple(requirement_column(i) for i in range(len(self.requirements)))

    def fingerprint(self) -> str:
        """Identifies the sweep, so that resuming never mixes two different sweeps."""
        obj = {"n": self.n, "seed": self.seed, "sampling": self.sampling, "m1_range": list(self.m1_range),
               "ranges": {k: list(v) for k, v in self.ranges.items()}, "base": self.base.to_dict()}
        if self.requirements:  # a sweep without requirements keeps the fingerprint it always had
            obj["requirements"] = list(self.requirements)
        if self.m1 is not None:  # and one with m1 drawn too
            obj["m1"] = self.m1
        return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]


#: the paper's deprecated aliases of a sweep summary, which sit under its ``paper`` key (never at the top
#: level, where a reader took them for the certificate's), and the top-level keys of the same numbers
SWEEP_KEYS_DEPRECATED = {"inside": "paper_inside", "outside": "paper_outside", "worst_E_ratio": "worst_paper_E_ratio",
                         "worst_Edot_ratio": "worst_paper_Edot_ratio", "E_max": "paper_E_max",
                         "Edot_max": "paper_Edot_max"}


def draw_samples(spec: SweepSpec) -> np.ndarray:
    """(n, d) parameter values: m1 first, then ``spec.ranges`` in order. Seeded."""
    bounds = spec.bounds
    d = len(bounds)
    rng = np.random.default_rng(spec.seed)
    if spec.sampling == "uniform":
        unit = rng.random((spec.n, d))
    elif spec.sampling == "lhs":
        unit = latin_hypercube(spec.n, d, rng.spawn(1)[0])  # scipy's qmc draws from a spawned child
    elif spec.m1 is not None:  # a grid over the ranged axes only; m1's column is fixed
        g = spec.grid_dimensions
        k = round(spec.n ** (1.0 / g))
        axes = [np.linspace(0.0, 1.0, k)] if k > 1 else [np.array([0.5])]
        grid = np.stack(np.meshgrid(*(axes * g), indexing="ij"), axis=-1).reshape(-1, g)
        unit = np.hstack([np.zeros((len(grid), 1)), grid])
    else:
        k = round(spec.n ** (1.0 / d))
        axes = [np.linspace(0.0, 1.0, k)] if k > 1 else [np.array([0.5])]
        unit = np.stack(np.meshgrid(*(axes * d), indexing="ij"), axis=-1).reshape(-1, d)
    return bounds[:, 0] + unit * (bounds[:, 1] - bounds[:, 0])


def _run_configs(spec: SweepSpec, samples: np.ndarray) -> list[RunConfig]:
    return [spec.config_at(row) for row in samples]


def _run_chunk(spec_json: str, indices: list[int], nthread: int,
               progress: Callable[[int, int], None] | None = None) -> list[dict[str, Any]]:
    """Run the sweep's runs ``indices`` (a Dask task: arguments and result are plain data).

    Returns:
        One row per run: its summary's JSON (``RunSummary.to_dict()``) with ``run`` (its index)
        and the value of each ranged parameter added.
    """
    spec = spec_from_json(spec_json)
    samples = draw_samples(spec)
    configs = _run_configs(spec, samples[indices])
    rows = []
    for i, summary in zip(indices, run_batch(configs, nthread=nthread, progress=progress,
                                             requirements=spec.requirements)):
        r = summary.to_dict()
        r["run"] = int(i)
        r.update(spec.recorded_values(samples[i]))
        rows.append(r)
    return rows


def _other_law(state: Mapping[str, Any], spec: SweepSpec) -> str | None:
    """How a sweep folder's recorded law (controller, tracker, their parameters and sources) differs from
    ``spec``'s, in a few words; None where it is the same law (another n or seed starts afresh, as always)."""
    old_base = (state.get("spec") or {}).get("base") or {}
    new_base = json.loads(spec_to_json(spec))["base"]
    for key in ("controller", "controller_params", "controller_plugin", "tracker", "tracker_params",
                "tracker_plugin", "correction"):
        if old_base.get(key) != new_base.get(key):
            return f"its {key} is {old_base.get(key)!r}, this sweep's {new_base.get(key)!r}"
    return None


def spec_to_json(spec: SweepSpec) -> str:
    base = spec.base.to_dict()
    obj = {"n": spec.n, "seed": spec.seed, "sampling": spec.sampling, "m1_range": list(spec.m1_range),
           "ranges": {k: list(v) for k, v in spec.ranges.items()}, "base": base}
    if spec.requirements:
        obj["requirements"] = list(spec.requirements)
    if spec.m1 is not None:
        obj["m1"] = spec.m1
    return json.dumps(obj, sort_keys=True)


def spec_from_json(text: str) -> SweepSpec:
    obj = json.loads(text)
    return SweepSpec(n=obj["n"], seed=obj["seed"], sampling=obj["sampling"], m1_range=tuple(obj["m1_range"]),
                     ranges={k: tuple(v) for k, v in obj["ranges"].items()}, base=config_from_dict(obj["base"]),
                     requirements=tuple(obj.get("requirements", ())), m1=obj.get("m1"))


#: the sweep folder's file of every runs.csv row at full precision (JSON: floats round-trip exactly), which
#: a resumed sweep and validate's rungs read (:func:`read_runs`), so that no number they report is rounded
PRECISE_ROWS = "runs-full-precision.json"


def _columns(extra: Sequence[str], tail: Sequence[str] = ()) -> list[str]:
    return list(RESULT_COLUMNS[:2]) + list(extra) + list(RESULT_COLUMNS[2:]) + list(tail)


def _csv_text(rows: list[dict[str, Any]], extra: Sequence[str], tail: Sequence[str] = ()) -> str:
    buf = io.StringIO()
    cols = _columns(extra, tail)
    w = csv.DictWriter(buf, fieldnames=cols, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for r in sorted(rows, key=lambda r: r["run"]):
        w.writerow({k: _cell(r.get(k)) for k in cols})
    return buf.getvalue()


def _cell(value: Any) -> Any:
    """CSV text of a value: floats to :data:`~wmr_mj.sim.many_runs.CSV_SIGNIFICANT_DIGITS` digits
    (:func:`~wmr_mj.sim.many_runs.csv_number`), None is empty."""
    if value is None:
        return ""
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, (float, np.floating)):
        return csv_number(float(value))
    return value


def _precise(value: Any) -> Any:
    """A runs.csv cell at full precision, typed as :func:`read_results` parses the cell (numbers as float)."""
    if value is None or isinstance(value, (bool, np.bool_)):
        return None if value is None else bool(value)
    if isinstance(value, (int, float, np.integer, np.floating)):
        return float(value)
    try:
        return float(value)
    except (TypeError, ValueError):
        return value


def _precise_rows(rows: list[dict[str, Any]], extra: Sequence[str], tail: Sequence[str] = ()) -> list[dict]:
    cols = _columns(extra, tail)
    return [{k: int(r["run"]) if k == "run" else _precise(r.get(k)) for k in cols}
            for r in sorted(rows, key=lambda r: r["run"])]


def read_results(path: str | os.PathLike) -> list[dict[str, Any]]:
    """Rows of a sweep's runs.csv, numbers parsed (as the CSV holds them:
    :data:`~wmr_mj.sim.many_runs.CSV_SIGNIFICANT_DIGITS` digits; :func:`read_runs` reads a folder's rows at full
    precision)."""
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


def read_runs(folder: str | os.PathLike) -> list[dict[str, Any]]:
    """Rows of a sweep folder's runs.csv, each at full precision where :data:`PRECISE_ROWS` holds its run
    (written before runs.csv after every chunk, so it holds every run the CSV does; a folder written before
    that file: the CSV's rows), typed as :func:`read_results` types them."""
    rows = read_results(Path(folder) / "runs.csv")
    path = Path(folder) / PRECISE_ROWS
    if not path.is_file():
        return rows
    try:
        precise = {int(r["run"]): r for r in json.loads(path.read_text())}
    except (json.JSONDecodeError, KeyError, TypeError, ValueError):
        return rows  # unreadable: the CSV's rows, as before that file existed
    return [dict(precise.get(int(r["run"]), r)) for r in rows]


def _chunk_progress(progress: Callable[[float, int], None] | None, done: int, size: int,
                    total: int) -> Callable[[int, int], None] | None:
    """A chunk's step progress as fractional runs of the sweep."""
    if progress is None:
        return None
    return lambda k, n: progress(done + size * k / n, total)


def run_sweep(spec: SweepSpec, *, out_dir: str | os.PathLike | None = None, chunk: int = 128, nthread: int = 0,
              scheduler: str | None = None,
              progress: Callable[[float, int], None] | None = None) -> list[dict[str, Any]]:
    """All runs of ``spec``, in run order. With ``out_dir``: runs.csv (atomic, after every chunk) and resume.

    progress(done, total) is called as runs finish and, locally, as a chunk steps (done
    is then fractional).
    """
    if chunk < 1:
        raise ParameterError(f"chunk = {chunk} must be >= 1")
    # an unreachable scheduler is refused before anything is written (the folder, sweep.json)
    client = connect(scheduler) if scheduler is not None else None
    try:
        return _run_sweep(spec, out_dir, chunk, nthread, client, progress)
    finally:
        if client is not None:
            client.close()


def _run_sweep(spec: SweepSpec, out_dir: str | os.PathLike | None, chunk: int, nthread: int, client: Any,
               progress: Callable[[float, int], None] | None) -> list[dict[str, Any]]:
    """:func:`run_sweep` once its inputs are checked: locally, or on ``client`` (a Dask client) where given."""
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
                for r in read_runs(out):
                    done[int(r["run"])] = r
            elif (other := _other_law(state, spec)) and read_results(csv_path):
                # another law's runs are never taken for this one's, nor written over
                raise ParameterError(f"--out {str(out)!r} holds the runs of another controller ({other}); they "
                                     "are not resumed: give another --out, or remove that folder to start afresh")
        write_json_atomic(state_path, {"fingerprint": fp, "spec": json.loads(spec_to_json(spec))})
    todo = [i for i in range(spec.n) if i not in done]
    chunks = [todo[i:i + chunk] for i in range(0, len(todo), chunk)]
    spec_json = spec_to_json(spec)

    def record(reports: list[dict[str, Any]]) -> None:
        for r in reports:
            done[r["run"]] = flat_row(r)
        if out is not None:
            rows = list(done.values())
            # NaN and inf as Python's json writes them: read back as the same floats (json_safe would null them)
            write_text_atomic(out / PRECISE_ROWS, json.dumps(_precise_rows(rows, extra, spec.requirement_columns)))
            write_text_atomic(out / "runs.csv", _csv_text(rows, extra, spec.requirement_columns))
        if progress is not None:
            progress(len(done), spec.n)

    if progress is not None:
        progress(len(done), spec.n)
    if client is not None:
        futures = [client.submit(_run_chunk, spec_json, c, 1, pure=False) for c in chunks]
        for fut in futures:  # in order; each finished chunk is saved before the next is awaited
            record(fut.result())
    else:
        for c in chunks:
            record(_run_chunk(spec_json, c, nthread, _chunk_progress(progress, len(done), len(c), spec.n)))
    return [done[i] for i in range(spec.n)]


# -- the summary of a sweep's runs (sweep --json and validate's rungs) ------------------------

def max_at(rows: Sequence[Mapping[str, Any]], column: str) -> tuple[float | None, float | None]:
    """The largest value of ``column`` and the m1 of its run (the first of equals).

    Args:
        rows: runs (rows of runs.csv or of :func:`run_sweep`).
        column: the column to maximise; rows where it is None are skipped.

    Returns:
        (value, m1 [kg]); (None, None) when the column is empty.
    """
    best, m1 = None, None
    for r in rows:
        v = r.get(column)
        if v is not None and (best is None or float(v) > best):
            best, m1 = float(v), float(r["m1"])
    return best, m1


@dataclass(frozen=True)
class Worst(Record):
    """The largest value of one quantity over a sweep's runs, and where.

    Attributes:
        value: the largest value (units of the quantity); None when no run has one.
        m1: the m1 of its run [kg]; None with the value.
    """

    value: float | None
    m1: float | None


@dataclass(frozen=True)
class RequirementSweep(Record):
    """One STL requirement over a sweep's runs (``wmr-mj sweep --require``).

    Attributes:
        requirement: the formula or preset as given.
        min_robustness: the least robustness over the runs (< 0: violated by that much); None when
            no run has one (a preset whose region no run has).
        run: the run of that robustness (the first of equals); None with it.
        m1: that run's m1 [kg]; None with it.
        satisfied: runs with robustness >= 0.
        violated: runs with robustness < 0.
        undefined: runs without a robustness.
    """

    requirement: str
    min_robustness: float | None
    run: int | None
    m1: float | None
    satisfied: int
    violated: int
    undefined: int

    @classmethod
    def of(cls, rows: Sequence[Mapping[str, Any]], index: int, requirement: str) -> RequirementSweep:
        column = requirement_column(index)
        values = [(float(r[column]), r) for r in rows if r.get(column) is not None]
        least = min(values, key=lambda vr: vr[0], default=None)
        return cls(requirement=requirement, min_robustness=None if least is None else least[0],
                   run=None if least is None else int(least[1]["run"]),
                   m1=None if least is None else float(least[1]["m1"]),
                   satisfied=sum(v >= 0.0 for v, _ in values), violated=sum(v < 0.0 for v, _ in values),
                   undefined=len(rows) - len(values))


def _claim_broken(rows: Sequence[Mapping[str, Any]], names: Sequence[str]) -> BrokenRun | None:
    """SweepSummary.claim_broken of ``rows``: the certified-outside run of the largest cert_E_ratio."""
    broken = [r for r in rows if r.get("verdict") == CERTIFIED_OUTSIDE]
    if not broken:
        return None

    def ratio(r: Mapping[str, Any]) -> float:
        return -math.inf if r.get("cert_E_ratio") is None else float(r["cert_E_ratio"])

    r = max(broken, key=ratio)  # max keeps the first of equals
    return BrokenRun(run=int(r["run"]) if r.get("run") is not None else None,
                     params={n: float(r[n]) for n in names if r.get(n) is not None}, sup_E=float(r["sup_E"]),
                     sup_Edot=float(r["sup_Edot"]),
                     E_max=None if r.get("cert_E_max") is None else float(r["cert_E_max"]),
                     ratio=None if ratio(r) == -math.inf else ratio(r), count=len(broken))


def _unmet_over(rows: Sequence[Mapping[str, Any]]) -> tuple[UnmetAssumption, ...]:
    """SweepSummary.unmet of ``rows``: each unmet assumption once, its first run's value and limit, and
    the number of runs that do not meet it."""
    certificates = (r.get("certificate") for r in rows)
    counted = count_unmet(unmet_assumptions(c if isinstance(c, Mapping) else None) for c in certificates)
    return tuple(UnmetAssumption.from_dict(a) for a in counted)


#: a ranged axis has levels (and its effort per level) where its runs take at most this many distinct values:
#: a grid, or a hardware axis rounded to whole periods, ticks or bits; a continuous draw has none
MAX_EFFORT_LEVELS = 16
_EFFORT_COLUMNS = ("saturated_fraction", "peak_voltage", "rms_voltage", "tv_voltage")


@dataclass(frozen=True, kw_only=True)
class Effort(Record):
    """What runs asked of the motor (:attr:`SweepSummary.effort`), from runs.csv's effort columns.

    Attributes:
        runs: how many runs.
        mean_saturated_fraction: the mean fraction of control steps at the voltage limit [-].
        max_saturated_fraction: the largest [-].
        peak_voltage: the largest |u| of any run [V].
        mean_rms_voltage: the mean of the runs' RMS u [V].
        mean_tv_voltage: the mean of the runs' total variation of u per second [V/s] (voltage activity).
        max_tv_voltage: the largest [V/s].
    """

    runs: int
    mean_saturated_fraction: float
    max_saturated_fraction: float
    peak_voltage: float
    mean_rms_voltage: float
    mean_tv_voltage: float
    max_tv_voltage: float

    @classmethod
    def of(cls, rows: Sequence[Mapping[str, Any]]) -> Effort | None:
        """The effort of ``rows``; None where a row lacks an effort column (a runs.csv written before them)."""
        if not rows or any(r.get(c) is None for r in rows for c in _EFFORT_COLUMNS):
            return None
        col = {c: [float(r[c]) for r in rows] for c in _EFFORT_COLUMNS}
        return cls(runs=len(rows), mean_saturated_fraction=sum(col["saturated_fraction"]) / len(rows),
                   max_saturated_fraction=max(col["saturated_fraction"]), peak_voltage=max(col["peak_voltage"]),
                   mean_rms_voltage=sum(col["rms_voltage"]) / len(rows),
                   mean_tv_voltage=sum(col["tv_voltage"]) / len(rows), max_tv_voltage=max(col["tv_voltage"]))


@dataclass(frozen=True, kw_only=True)
class EffortLevel(Record):
    """The effort of the runs at one level of a ranged axis: ``value`` (the axis's units) and their effort."""

    _records = {"effort": Effort}

    value: float
    effort: Effort


@dataclass(frozen=True, kw_only=True)
class AxisEffort(Record):
    """The effort per level of one ranged axis (:attr:`SweepSummary.effort_by_level`), levels ascending."""

    _records = {"levels": EffortLevel}

    axis: str
    levels: tuple[EffortLevel, ...]


def _effort_by_level(rows: Sequence[Mapping[str, Any]], names: Sequence[str]) -> tuple[AxisEffort, ...]:
    """Each ranged axis of ``names`` whose runs take 2 to :data:`MAX_EFFORT_LEVELS` distinct values, some value
    shared by several runs (a grid of two axes or more, a rounded hardware axis), with the effort of the runs
    at each value; none where the rows have no effort columns."""
    out = []
    for name in names:
        values = sorted({float(r[name]) for r in rows if r.get(name) is not None})
        if not 2 <= len(values) <= MAX_EFFORT_LEVELS or len(values) == len(rows):
            continue  # one level, a continuous draw, or one run per level (runs.csv has each run's)
        levels = []
        for v in values:
            effort = Effort.of([r for r in rows if r.get(name) is not None and float(r[name]) == v])
            if effort is None:
                return ()
            levels.append(EffortLevel(value=v, effort=effort))
        out.append(AxisEffort(axis=name, levels=tuple(levels)))
    return tuple(out)


@dataclass(frozen=True)
class SweepSummary(Record):
    """What a sweep's runs add up to: the one aggregator of ``wmr-mj sweep`` and validate's rungs.

    :meth:`of` reads rows of runs.csv (or of :func:`run_sweep`, which carry the same columns);
    :meth:`sweep_dict` writes ``wmr-mj sweep --json``'s keys, :meth:`rung_dict` validate's;
    :meth:`to_dict` every field and :meth:`from_dict` reads it back (:class:`wmr_mj.sim.records.Record`).

    Attributes:
        n: number of runs.
        verdicts: the count of each verdict (``wmr_mj.analysis.verdicts.VERDICTS``, zeros included).
        paper_inside: runs inside the paper's claim; None where no run has the paper's region (a law
            outside the paper's family).
        sup_E: the worst sup|E| [rad].
        sup_Edot: the worst sup|E'| [rad/s].
        certificate_E_ratio: the worst sup|E|/E_max of the certificate [-].
        certificate_Edot_ratio: the worst sup|E'|/Edot_max of the certificate [-].
        paper_E_ratio: the worst sup|E|/E_max of the paper's claim [-].
        paper_Edot_ratio: the worst sup|E'|/Edot_max of the paper's claim [-].
        certificate_E_max: the certificate's E_max of the first run [rad]; None where it has none.
        certificate_Edot_max: its Edot_max [rad/s].
        paper_E_max: the paper's E_max of the first run [rad] (inf or None where (4.23) fails).
        paper_Edot_max: its Edot_max [rad/s].
        hit_stop: runs that reached the steering stop.
        growing: runs whose |E| still grows at the end.
        mean_saturated_fraction: the mean fraction of control steps at the voltage limit [-].
        m1_min: the smallest m1 [kg].
        m1_max: the largest m1 [kg].
        steps: physics steps of the runs simulated by this call (resumed runs have none).
        batch_law: how this call's batches evaluated the law (``wmr_mj.sim.batch.LAW_BACKENDS``).
        path_cross_track: the worst sup|cross-track| of C [m] (None for rows without it).
        path_verdicts: the count of each path verdict ('within-bound', 'beyond-bound', 'no-guarantee').
        requirements: each STL requirement over the runs.
        claim_broken: the ``certified-outside`` run of the largest sup|E|/E_max (the first of equals), the
            run that breaks the law's claim most; None when no run breaks it.
        unmet: the claim's assumptions not met in some run: value and limit of the first such run (the
            assumption's units), runs: how many; from rows that carry their certificate (a resumed sweep's
            rows, read from runs.csv, do not).
        effort: what the runs asked of the motor: saturation, peak voltage, voltage activity (:class:`Effort`);
            None where the rows have no effort columns.
        effort_by_level: the effort per level of each ranged axis with levels (:func:`_effort_by_level`).
    """

    _records = {"sup_E": Worst, "sup_Edot": Worst, "certificate_E_ratio": Worst, "certificate_Edot_ratio": Worst,
                "paper_E_ratio": Worst, "paper_Edot_ratio": Worst, "path_cross_track": Worst,
                "requirements": RequirementSweep, "claim_broken": BrokenRun, "unmet": UnmetAssumption,
                "effort": Effort, "effort_by_level": AxisEffort}

    n: int
    verdicts: Mapping[str, int]
    paper_inside: int | None
    sup_E: Worst
    sup_Edot: Worst
    certificate_E_ratio: Worst
    certificate_Edot_ratio: Worst
    paper_E_ratio: Worst
    paper_Edot_ratio: Worst
    certificate_E_max: float | None
    certificate_Edot_max: float | None
    paper_E_max: float | None
    paper_Edot_max: float | None
    hit_stop: int
    growing: int
    mean_saturated_fraction: float
    m1_min: float
    m1_max: float
    steps: int
    batch_law: tuple[str, ...]
    path_cross_track: Worst = Worst(None, None)
    path_verdicts: Mapping[str, int] | None = None
    requirements: tuple[RequirementSweep, ...] = ()
    claim_broken: BrokenRun | None = None
    unmet: tuple[UnmetAssumption, ...] = ()
    effort: Effort | None = None
    effort_by_level: tuple[AxisEffort, ...] = ()

    @classmethod
    def of(cls, rows: Sequence[Mapping[str, Any]], requirements: Sequence[str] = (), *,
           names: Sequence[str] = ("m1",)) -> SweepSummary:
        """Summarise ``rows`` (runs.csv columns: :data:`RESULT_COLUMNS`; ``requirements``: the sweep's,
        whose robustness columns the rows carry, :func:`requirement_column`; ``names``: the drawn
        parameters, m1 first, that name the run that breaks the claim).

        Raises:
            ParameterError: no rows.
        """
        if not rows:
            raise ParameterError("no runs to summarise")
        first = rows[0]
        return cls(
            n=len(rows),
            verdicts=count_verdicts(str(r["verdict"]) for r in rows if r.get("verdict")),
            # None: no run has the paper's region (a law outside the paper's family), so nothing to count
            paper_inside=(sum(bool(r["inside"]) for r in rows) if any(r.get("inside") is not None for r in rows)
                          else None),
            sup_E=Worst(*max_at(rows, "sup_E")),
            sup_Edot=Worst(*max_at(rows, "sup_Edot")),
            certificate_E_ratio=Worst(*max_at(rows, "cert_E_ratio")),
            certificate_Edot_ratio=Worst(*max_at(rows, "cert_Edot_ratio")),
            paper_E_ratio=Worst(*max_at(rows, "E_ratio")),
            paper_Edot_ratio=Worst(*max_at(rows, "Edot_ratio")),
            certificate_E_max=first.get("cert_E_max"),
            certificate_Edot_max=first.get("cert_Edot_max"),
            paper_E_max=first.get("E_max"),
            paper_Edot_max=first.get("Edot_max"),
            hit_stop=sum(bool(r["left_steering_range"]) for r in rows),
            growing=sum(bool(r.get("drift_growing")) for r in rows),
            mean_saturated_fraction=sum(float(r["saturated_fraction"]) for r in rows) / len(rows),
            m1_min=min(float(r["m1"]) for r in rows),
            m1_max=max(float(r["m1"]) for r in rows),
            steps=sum(int(r["steps"]) for r in rows if r.get("steps") is not None),
            batch_law=tuple(sorted({r["batch_law"] for r in rows if r.get("batch_law")})),
            path_cross_track=Worst(*max_at(rows, "path_cross_track_max")),
            path_verdicts=_count_path_verdicts(rows),
            requirements=tuple(RequirementSweep.of(rows, i, text) for i, text in enumerate(requirements)),
            claim_broken=_claim_broken(rows, names),
            unmet=_unmet_over(rows),
            effort=Effort.of(rows),
            effort_by_level=_effort_by_level(rows, names),
        )

    @property
    def passes(self) -> int:
        """Runs ``certified-inside``, the only pass."""
        return self.verdicts[PASS]

    @property
    def certified_outside(self) -> int:
        """Runs ``certified-outside``: a bug or a modelling gap."""
        return self.verdicts["certified-outside"]

    def sweep_dict(self, wall_s: float) -> dict[str, Any]:
        """``wmr-mj sweep --json``'s keys (summary.json of a sweep folder); ``wall_s``: the sweep's wall time [s]."""
        out: dict[str, Any] = {
            "n": self.n,
            "verdicts": dict(self.verdicts),
            "worst_certificate_ratio": self.certificate_E_ratio.value,
            "worst_certificate_Edot_ratio": self.certificate_Edot_ratio.value,
            "certificate_E_max": self.certificate_E_max,
            "certificate_Edot_max": self.certificate_Edot_max,
            "drift_growing": self.growing,
            "paper_inside": self.paper_inside,
            "paper_outside": None if self.paper_inside is None else self.n - self.paper_inside,
            "worst_paper_E_ratio": self.paper_E_ratio.value,
            "worst_paper_Edot_ratio": self.paper_Edot_ratio.value,
            "worst_sup_E": self.sup_E.value,
            "worst_sup_Edot": self.sup_Edot.value,
            "paper_E_max": self.paper_E_max,
            "paper_Edot_max": self.paper_Edot_max,
            "hit_steering_stop": self.hit_stop,
            "steps": self.steps,
            "wall_s": wall_s,
            "steps_per_s": self.steps / wall_s if wall_s > 0 and math.isfinite(wall_s) else None,
            # how the runs of this call evaluated the law (wmr_mj.sim.batch.LAW_BACKENDS; resumed runs: none)
            "batch_law": list(self.batch_law),
            # C's path (wmr_mj.analysis.path_error): the worst sup|cross-track| [m] and the path verdicts
            "worst_path_cross_track": self.path_cross_track.value,
            "worst_path_cross_track_m1": self.path_cross_track.m1,
            "path_verdicts": None if self.path_verdicts is None else dict(self.path_verdicts),
            **({"requirements": [{**r.to_dict(), "column": requirement_column(i)}
                                 for i, r in enumerate(self.requirements)]} if self.requirements else {}),
            # a broken claim, whatever else the sweep measured (None: no run is certified-outside)
            "claim_broken": None if self.claim_broken is None else self.claim_broken.to_dict(),
            "unmet": [a.to_dict() for a in self.unmet],
            # what the runs asked of the motor, overall and per level of each ranged axis that has levels
            "effort": None if self.effort is None else self.effort.to_dict(),
            "effort_by_level": {a.axis: [{"value": lv.value, **lv.effort.to_dict()} for lv in a.levels]
                                for a in self.effort_by_level},
        }
        # the paper's deprecated aliases, under ``paper`` only: at the top level they read as the certificate's
        out["paper"] = {old: out[new] for old, new in SWEEP_KEYS_DEPRECATED.items()}
        if self.paper_inside is None:
            out["paper_claim_applies"] = False
            out["not_applicable"] = {"paper_inside": "the paper's region is for its computed-torque law "
                                                     "(computed-torque, pd), not this one: no run was judged by it"}
        return out

    def rung_dict(self) -> dict[str, Any]:
        """The keys of one rung of ``wmr-mj validate``'s ladder (summary.json's ``ladder``)."""
        return {
            "n": self.n,
            "verdicts": dict(self.verdicts),
            "passes": self.passes,
            "certified_outside": self.certified_outside,
            "paper_inside": self.paper_inside,
            "worst_sup_E": self.sup_E.value, "worst_sup_E_m1": self.sup_E.m1,
            "worst_sup_Edot": self.sup_Edot.value,
            "worst_certificate_ratio": self.certificate_E_ratio.value,
            "worst_certificate_ratio_m1": self.certificate_E_ratio.m1,
            "worst_paper_ratio": self.paper_E_ratio.value, "worst_paper_ratio_m1": self.paper_E_ratio.m1,
            "hit_stop": self.hit_stop,
            "growing": self.growing,
            "mean_saturated_fraction": self.mean_saturated_fraction,
            "m1_min": self.m1_min, "m1_max": self.m1_max,
            "worst_path_cross_track": self.path_cross_track.value,
            "worst_path_cross_track_m1": self.path_cross_track.m1,
            "path_verdicts": None if self.path_verdicts is None else dict(self.path_verdicts),
        }


def sweep_over_box(base: RunConfig, n: int, *, seed: int) -> SweepSummary:
    """``n`` runs of ``base`` drawn over its own box (its m1 range and its box ranges) by a Latin hypercube of
    ``seed``: their summary (``wmr-mj design --check``: the verdicts at the design found)."""
    (lo, hi) = base.m1_range
    spec = SweepSpec(n=n, seed=seed, sampling="lhs", m1_range=(lo, hi),
                     ranges={k: (a, b) for k, (a, b) in base.box_ranges.items()}, base=base)
    return SweepSummary.of(run_sweep(spec), spec.requirements, names=spec.names)
