"""A sweep as one typed result: its spec, every run's row and what they add up to, for a notebook.

:func:`wmr_mj.experiments.sweep.run_sweep` returns the runs' rows (runs.csv's columns, a list of mappings), as the
CLI and validate read them; :func:`sweep` runs the same sweep and keeps the rows beside their
:class:`~wmr_mj.experiments.sweep.SweepSummary`, with a table (:meth:`SweepResult.to_pandas`), a figure
(:meth:`SweepResult.plot`) and a few lines for a notebook. It writes nothing that ``run_sweep`` does not.

Usage::

    import wmr_mj as wm

    result = wm.sweep(wm.SweepSpec(n=16, ranges={"sensing.delay": (0.0, 0.02)}, base=wm.RunConfig(duration=5.0)))
    result.summary.passes, result.to_pandas()["sup_E [rad]"].max()
"""

from __future__ import annotations

import dataclasses
import json
import os
import time
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from wmr_mj._util.checks import runs_of
from wmr_mj.experiments.sweep import SweepSpec, SweepSummary, run_sweep, spec_from_json, spec_to_json
from wmr_mj.hardware import cart_dict
from wmr_mj.searches.search_space import HARDWARE_AXES, parameter_units
from wmr_mj.sim import notebook
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.run_report import add_controller_source

__all__ = ["SweepResult", "sweep"]


@dataclass(frozen=True)
class SweepResult:
    """Every run of a sweep and what they add up to (:func:`sweep`).

    Attributes:
        spec: the sweep.
        rows: each run's row, in run order (runs.csv's columns: :func:`wmr_mj.sim.many_runs.flat_row`).
        summary: what the runs add up to.
        wall_s: the sweep's wall time, s (its steps per second; 0: not measured).
        folder: the sweep's folder (runs.csv, summary.json), where it wrote one.
    """

    spec: SweepSpec
    rows: tuple[Mapping[str, Any], ...]
    summary: SweepSummary
    wall_s: float = 0.0
    folder: str | None = None

    def to_dict(self, *, runs: bool = True) -> dict[str, Any]:
        """The sweep's JSON: ``wmr-mj sweep --json``'s keys (summary.json of the sweep's folder, before the CLI adds
        its figure's ``plot`` and ``mcap_dir``: :meth:`SweepSummary.sweep_dict`, then the sweep's folder, law, seed,
        sampling and ranges, its fixed m1, signals, the law's source, the cart and the cart's axes drawn per run),
        then, with ``runs``, the key ``runs``: the spec (as sweep.json and the workers read it: its base as
        ``RunConfig.to_dict``), each run's row (in run order) and the summary (:meth:`SweepSummary.to_dict`), which
        :meth:`from_dict` reads back.

        Args:
            runs: add ``runs``; False: sweep --json's object exactly (runs.csv holds the rows).
        """
        spec, base = self.spec, coerced(self.spec.base)  # a base built directly: the config its runs ran as
        out = self.summary.sweep_dict(self.wall_s)
        out.update({"folder": None if self.folder is None else str(self.folder), "model": base.model,
                    "controller": base.controller, "seed": spec.seed, "sampling": spec.sampling,
                    "ranges": {"m1": list(spec.m1_range), **{k: list(v) for k, v in spec.ranges.items()}}})
        if spec.m1 is not None:  # every run's m1 (ranges' m1: the certificate's box)
            out["fixed_m1"] = spec.m1
        if base.signals is not None:
            out["signals"] = base.signals.to_dict()  # every run's, with every parameter
        add_controller_source(out, base)
        out.update(cart_dict(base))  # the cart every run shares, where not ideal
        if spec.hardware_names:  # and the cart's axes each run draws, with what a drawn value becomes
            out["hardware_axes"] = {n: HARDWARE_AXES[n] for n in spec.hardware_names}
        if runs:
            out["runs"] = {"spec": json.loads(spec_to_json(self.spec)), "rows": [dict(row) for row in self.rows],
                           "summary": self.summary.to_dict()}
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> SweepResult:
        """The result of its JSON ``d`` (what :meth:`to_dict` wrote, with its ``runs``).

        Raises:
            ParameterError: ``d`` has no ``runs`` (sweep --json's object, summary.json): one line.
        """
        runs = runs_of(d, result="SweepResult", holds="sweep --json and summary.json hold the summary only")
        return cls(spec=spec_from_json(json.dumps(runs["spec"])), rows=tuple(dict(row) for row in runs["rows"]),
                   summary=SweepSummary.from_dict(runs["summary"]), wall_s=d["wall_s"], folder=d["folder"])

    def report(self, *, wall_s: float, folder: str | os.PathLike) -> dict[str, Any]:
        """Deprecated (kept one release): ``to_dict(runs=False)`` is sweep --json's object (the result carries its
        wall time and folder)."""
        warnings.warn("SweepResult.report() is deprecated: result.to_dict(runs=False) is sweep --json's object",
                      DeprecationWarning, stacklevel=2)
        return dataclasses.replace(self, wall_s=wall_s, folder=str(folder)).to_dict(runs=False)

    def to_pandas(self) -> Any:
        """One row per run: the values each run used (m1 and every ranged parameter, with units), its verdict,
        sup|E|, sup|E'|, the certificate's bounds and ratios (``certificate_E_max [rad]``), the paper's claim
        (``paper_E_max [rad]``), effort and C's path (:data:`wmr_mj.sim.notebook.RUN_COLUMNS`).

        Raises:
            WmrMjError: pandas is not installed (``pip install 'wmr-mj[notebook]'``).
        """
        return notebook.runs_frame(self.rows, parameters=self.spec.names, units=parameter_units(self.spec.names))

    def plot(self, **options: Any) -> Any:
        """sup|E| of every run against each ranged parameter, one panel each, with the certificate's E_max
        (:class:`wmr_mj.figures.results.ResultPlot`); each panel's x label is the parameter's column in
        :meth:`to_pandas` (with its unit)."""
        from wmr_mj.figures.results import plot_sweep  # matplotlib loads only when a figure is asked for

        units = parameter_units(self.spec.names)
        return plot_sweep(self, xlabels=[notebook.run_column(n, units) for n in self.spec.names], **options)

    def _repr_html_(self) -> str:
        s = self.summary
        lines = [f"{s.n} runs over {', '.join(self.spec.names)}: {notebook.verdict_counts_text(s.verdicts)}",
                 f"worst sup|E| {notebook.number(s.sup_E.value, 'rad')}; certificate's E_max "
                 f"{notebook.number(s.certificate_E_max, 'rad')}; worst sup|E|/E_max "
                 f"{notebook.number(s.certificate_E_ratio.value)}",
                 f"mean time at the voltage limit {notebook.number(100 * s.mean_saturated_fraction, spec='.3g')} %"]
        verdict = ("CERTIFIED-OUTSIDE in some run" if s.certified_outside else
                   f"{s.passes}/{s.n} certified-inside")
        return notebook.html_lines("sweep", verdict, lines)


def sweep(spec: SweepSpec, *, out_dir: str | os.PathLike | None = None, chunk: int = 128, nthread: int = 0,
          scheduler: str | None = None, progress: Callable[[float, int], None] | None = None) -> SweepResult:
    """:func:`wmr_mj.experiments.sweep.run_sweep` (the same runs, the same files with ``out_dir``), typed.

    Args:
        spec: the sweep.
        out_dir, chunk, nthread, scheduler, progress: as :func:`~wmr_mj.experiments.sweep.run_sweep`.

    Returns:
        SweepResult: the rows and their :class:`~wmr_mj.experiments.sweep.SweepSummary`, the wall time and the
        folder.
    """
    t0 = time.perf_counter()
    rows = run_sweep(spec, out_dir=out_dir, chunk=chunk, nthread=nthread, scheduler=scheduler, progress=progress)
    summary = SweepSummary.of(rows, spec.requirements, names=spec.names)
    return SweepResult(spec=spec, rows=tuple(rows), summary=summary, wall_s=time.perf_counter() - t0,
                       folder=None if out_dir is None else str(out_dir))
