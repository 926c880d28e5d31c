"""Many runs of the run layer, for whatever asks for them (a sweep, a search, a comparison, a report).

- :func:`run_configs`: the summaries of any list of configs, in order: locally in ``run_batch`` chunks, or one
  Dask task per chunk on a client (:func:`connect`), the same numbers;
- each run's row: a summary flattened to runs.csv's columns (:data:`RESULT_COLUMNS`, :func:`flat_row`), and a
  number as a CSV table writes it (:func:`csv_number`);
- :func:`latin_hypercube`: points spread over the unit box, one in each stratum of every axis.

Usage::

    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.many_runs import flat_row, run_configs
    base = RunConfig(model="nonholonomic", duration=10.0)
    rows = [flat_row(s.to_dict()) for s in run_configs([base.replace(m1=m) for m in (550.0, 750.0)])]
"""

from __future__ import annotations

import socket
from collections.abc import Callable, Mapping, Sequence
from typing import Any
from urllib.parse import urlsplit

import numpy as np

from wmr_mj.errors import ParameterError, SchedulerError
from wmr_mj.sim.batch import run_batch
from wmr_mj.sim.config import RunConfig, config_from_dict
from wmr_mj.sim.summary import RunSummary

__all__ = [
    "run_configs",
    "connect",
    "RESULT_COLUMNS",
    "flat_row",
    "requirement_column",
    "CSV_SIGNIFICANT_DIGITS",
    "csv_number",
    "latin_hypercube",
]

#: runs.csv's columns, in order (a sweep puts its ranged parameters after m1 and its requirements' columns last)
RESULT_COLUMNS = ("run", "m1", "verdict", "cert_valid", "cert_E_max", "cert_Edot_max", "cert_E_ratio",
                  "cert_Edot_ratio", "cert_inside", "sup_E", "sup_Edot", "sup_E_settled", "sup_Edot_settled",
                  "E_max", "Edot_max", "E_ratio", "Edot_ratio", "inside", "saturated_fraction",
                  # the applied voltage's effort (wmr_mj.sim.summary.VoltageEffort): [V], [V], [V/s]
                  "peak_voltage", "rms_voltage", "tv_voltage",
                  "left_steering_range", "final_alpha", "final_alpha_dot", "drift_growing",
                  # C's path (wmr_mj.analysis.path_error, path_bound): [m], [m], [rad], verdict, [m]
                  "path_cross_track_max", "path_along_track_final", "path_heading_error_max", "path_verdict",
                  "path_cross_track_bound")
#: runs.csv columns taken from a run summary's nested certificate, drift and path (see flat_row)
_FLAT = {"cert_valid": ("certificate", "certified"), "cert_E_max": ("certificate", "E_max"),
         "cert_Edot_max": ("certificate", "Edot_max"), "cert_E_ratio": ("certificate", "E_ratio"),
         "cert_Edot_ratio": ("certificate", "Edot_ratio"), "cert_inside": ("certificate", "inside"),
         "final_alpha_dot": ("drift", "final_alpha_dot"), "drift_growing": ("drift", "growing"),
         "path_cross_track_max": ("path_error", "cross_track_max"),
         "path_along_track_final": ("path_error", "along_track_final"),
         "path_heading_error_max": ("path_error", "heading_error_max"),
         "path_verdict": ("path_verdict", "verdict"), "path_cross_track_bound": ("path_verdict", "cross_track_bound")}


def requirement_column(index: int) -> str:
    """runs.csv's column of the robustness of requirement ``index`` (0-based): requirement_1_robustness, ..."""
    return f"requirement_{index + 1}_robustness"


def flat_row(summary: Mapping[str, Any]) -> dict[str, Any]:
    """A run summary with the runs.csv columns of its certificate, drift, path and requirements added at
    the top level (cert_valid, cert_E_max, ..., path_cross_track_max, ..., requirement_1_robustness, ...)."""
    out = dict(summary)
    for col, (outer, inner) in _FLAT.items():
        # path_verdict: the summary's is the whole judgement (a mapping); the column is its word
        if col not in out or isinstance(out[col], Mapping):
            out[col] = (summary.get(outer) or {}).get(inner)
    for i, judged in enumerate(summary.get("requirements") or ()):
        out.setdefault(requirement_column(i), judged.get("robustness"))
    return out


#: significant digits of a number in a CSV table (runs.csv, falsify's evaluations.csv): 0.009 where the float
#: is 0.009000000000000001. Full precision is kept in the JSON (summary.json, a sweep's
#: :data:`wmr_mj.experiments.sweep.PRECISE_ROWS`).
CSV_SIGNIFICANT_DIGITS = 12


def csv_number(value: float) -> str:
    """CSV text of a float: rounded to :data:`CSV_SIGNIFICANT_DIGITS` significant digits, then the shortest
    text of that float (repr): '0.009' for 0.009000000000000001, 'nan', 'inf'."""
    return repr(float(f"{float(value):.{CSV_SIGNIFICANT_DIGITS}g}"))


def _run_config_chunk(config_dicts: list[dict[str, Any]], nthread: int,
                      requirements: Sequence[str] = ()) -> list[RunSummary]:
    """Summaries of configs given as ``to_dict()`` (a Dask task: plain data in, frozen records out)."""
    return run_batch([config_from_dict(d) for d in config_dicts], nthread=nthread, requirements=requirements)


def run_configs(configs: Sequence[RunConfig], *, chunk: int = 128, nthread: int = 0, client: Any = None,
                progress: Callable[[int, int], None] | None = None,
                requirements: Sequence[str] = ()) -> list[RunSummary]:
    """Summaries of ``configs``, in order (``requirements``: STL formulas judged on every run).

    Locally: ``run_batch`` calls of at most ``chunk`` simulations (one batch where they share
    one, else one by one on ``nthread`` threads). With a Dask ``client`` (see :func:`connect`):
    one task per chunk, the same numbers. progress(done, total) is called as chunks finish.
    """
    if chunk < 1:
        raise ParameterError(f"chunk = {chunk} must be >= 1")
    requirements = tuple(requirements)
    parts = [list(configs[i:i + chunk]) for i in range(0, len(configs), chunk)]
    reports: list[RunSummary] = []
    if client is not None:
        futures = [client.submit(_run_config_chunk, [c.to_dict() for c in part], 1, requirements, pure=False)
                   for part in parts]
        for fut in futures:
            reports.extend(fut.result())
            if progress is not None:
                progress(len(reports), len(configs))
        return reports
    for part in parts:
        reports.extend(run_batch(part, nthread=nthread, requirements=requirements))
        if progress is not None:
            progress(len(reports), len(configs))
    return reports


def connect(scheduler: str):
    """A ``distributed.Client`` of the Dask scheduler at ``scheduler`` (SchedulerError if unreachable)."""
    return _connect(scheduler)


def _connect(scheduler: str):
    try:
        from distributed import Client
    except ImportError:
        raise SchedulerError("--scheduler needs the Dask extra: pip install 'wmr-mj[dask]'") from None
    if _refused(scheduler):
        raise SchedulerError(f"cannot reach the Dask scheduler at {scheduler!r} (ConnectionRefusedError); give the "
                             "address of a running scheduler, e.g. tcp://127.0.0.1:8786")
    try:
        return Client(scheduler, timeout="5s", set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SchedulerError(f"cannot reach the Dask scheduler at {scheduler!r} ({type(exc).__name__}); "
                             "give the address of a running scheduler, e.g. tcp://127.0.0.1:8786") from None


def _refused(scheduler: str) -> bool:
    """True where nothing listens at a ``tcp://HOST:PORT`` address: the host refuses the connection at once,
    where a ``Client`` would retry until its timeout. False for another scheme, or any other answer (the
    ``Client`` then says what is wrong)."""
    address = urlsplit(scheduler)
    try:
        port = address.port
    except ValueError:
        return False
    if address.scheme != "tcp" or address.hostname is None or port is None:
        return False
    try:
        with socket.create_connection((address.hostname, port), timeout=5.0):
            return False
    except ConnectionRefusedError:
        return True
    except OSError:
        return False


def latin_hypercube(n: int, d: int, rng: np.random.Generator) -> np.ndarray:
    """(n, d) points in [0, 1)^d, one in each of the n strata of every axis (scrambled LHS).

    The algorithm of ``scipy.stats.qmc.LatinHypercube(d, rng=parent).random(n)`` (scipy 1.17)
    with ``rng = parent.spawn(1)[0]``, the child generator scipy draws from: the same
    numbers (a test compares the two). Written out here because importing scipy.stats
    costs 0.6-0.8 s, a seventh of a 32-run sweep.
    """
    jitter = rng.uniform(size=(n, d))
    strata = np.tile(np.arange(1, n + 1), (d, 1))
    for axis in range(d):
        rng.shuffle(strata[axis, :])
    return (strata.T - jitter) / n
