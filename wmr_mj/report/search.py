"""Stage 4 of ``wmr-mj validate``: the worst-case search beside the Monte-Carlo worst and the certificate.

Three searches (:func:`search_plans`), each falsify's default portfolio: the box's vertices, then
CMA-ES on whole generations (:func:`wmr_mj.searches.falsify.search_worst`, every batch one ``mujoco.batch``;
differential evolution until the portfolio replaced it):

- the paper's design over the m1 box, maximising sup|E|/E_max of the paper's claim (it has
  no certificate), beside the worst of rung 1's Monte-Carlo sweep (runs.csv ``E_ratio``);
- the certified design over the m1 box, maximising sup|E|/E_max of its certificate, beside
  the worst of the last rung's sweep (``cert_E_ratio``): how tight the certificate is;
- the certified design over the 'full' uncertainty box of :mod:`wmr_mj.params` (m1,
  steering friction, tyre friction, R_a, V_A), maximising sup|E|: its certificate over that
  box needs more than the supply, so every run there is uncertified, and the report says so.

The ladder's sweep is the random baseline, so no random sample is drawn here. Each search
lives in search-<key>/ (search.json, evaluations.csv, worst.mcap: the worst run re-run
serially with an MCAP log) and is read back when its spec has not changed.

Usage::

    from wmr_mj.report.settings import ValidateSettings
    from wmr_mj.report.search import search_plans
    [plan.key for plan in search_plans(ValidateSettings())]   # ['paper', 'certified', 'certified-full']
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from wmr_mj._util.checks import as_pair
from wmr_mj._util.files import write_json_atomic, write_text_atomic
from wmr_mj._util.progress import Stages
from wmr_mj.analysis.verdicts import count_verdicts, paper_region_name
from wmr_mj.experiments.sweep import read_runs
from wmr_mj.logs.writer import run_logged
from wmr_mj.report.settings import (
    FULL_BOX_FACTOR,
    ValidateSettings,
    certificate_summary,
    loud,
    max_at,
    stage_progress,
)
from wmr_mj.searches.falsify import FalsifySpec, objective_label, objective_value, search_worst
from wmr_mj.sim.designs import CERTIFIED, LADDER, PAPER, DesignPreset
from wmr_mj.sim.many_runs import run_configs
from wmr_mj.sim.parts import resolve_run

__all__ = ["SearchPlan", "search_plans", "run_search", "search_stage"]


@dataclass(frozen=True, kw_only=True)
class SearchPlan:
    """One worst-case search of the report.

    objective: of :data:`wmr_mj.searches.falsify.OBJECTIVES`; mc_rung / mc_column: the ladder rung
    (1-based) whose Monte-Carlo sweep is compared, and its runs.csv column holding the same
    objective (None: no Monte-Carlo sweep of this box).
    """

    key: str
    title: str
    design: DesignPreset
    box: str  # uncertainty box of wmr_mj.params: 'm1' or 'full'
    objective: str
    budget: int
    mc_rung: int | None = None
    mc_column: str | None = None


def search_plans(settings: ValidateSettings) -> tuple[SearchPlan, ...]:
    """The report's searches: two over the ladder's box, and the full box for the certified design when the
    ladder sampled m1 only (none when ``settings.search_budget`` is 0)."""
    b = settings.search_budget
    if b == 0:
        return ()
    box = settings.uncertainty  # the box the ladder sampled: the Monte-Carlo worst to compare with
    return (
        SearchPlan(key="paper", title=f"the paper's design against {paper_region_name(settings.cart is None)}, "
                                      f"{box} box", design=PAPER,
                   box=box, objective="paper", budget=b, mc_rung=1, mc_column="E_ratio"),
        SearchPlan(key="certified", title=f"the certified design against its certificate, {box} box",
                   design=CERTIFIED, box=box, objective="certificate", budget=b, mc_rung=len(LADDER),
                   mc_column="cert_E_ratio"),
    ) + ((SearchPlan(key="certified-full", title="the certified design over the full uncertainty box",
                     design=CERTIFIED, box="full", objective="sup-E", budget=FULL_BOX_FACTOR * b),)
         if box == "m1" else ())  # over the full box the search above already covers it


def _search_spec(plan: SearchPlan, settings: ValidateSettings):
    extra = settings.box_ranges(plan.box)  # the cart's own box of that name (the C80's without a cart)
    base = settings.config(plan.design).replace(box_ranges=extra)
    return FalsifySpec(base=base, box={"m1": as_pair(settings.m1_range), **extra}, objective=plan.objective,
                       budget=plan.budget, seed=settings.seed)  # falsify's default method: the portfolio


def _fingerprint(spec) -> str:
    obj = {"base": spec.base.to_dict(), "box": {k: list(v) for k, v in spec.box.items()}, "objective": spec.objective,
           "budget": spec.budget, "seed": spec.seed, "population": spec.population_size, "method": spec.method}
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]


def _evaluate_search(spec, *, nthread: int, progress: Callable[[float, int], None]) -> list[dict[str, Any]]:
    """Run the search of ``spec`` (no random sample: the ladder's sweep is the
    baseline); every evaluated run as {generation, params, objective, sup_E, sup_Edot, verdict}."""
    runs: list[dict[str, Any]] = []
    generation = [0]

    def evaluate(points: np.ndarray) -> np.ndarray:
        reports = run_configs([spec.config(p) for p in points], nthread=nthread,
                              progress=lambda k, n: progress(len(runs) + k, spec.budget))
        values = []
        for p, r in zip(points, reports):
            v = objective_value(r.to_dict(), spec.objective)
            values.append(np.nan if v is None else v)
            runs.append({"generation": generation[0], "params": {n: float(x) for n, x in zip(spec.names, p)},
                         "objective": None if v is None else float(v), "sup_E": float(r.sup_E),
                         "sup_Edot": float(r.sup_Edot), "verdict": str(r.verdict)})
        generation[0] += 1
        return np.array(values)

    search_worst(evaluate, spec.bounds, budget=spec.budget, seed=spec.seed, population=spec.population_size,
                 method=spec.method)
    return runs


def _worst_of(runs: Sequence[Mapping[str, Any]]) -> dict[str, Any] | None:
    best = None
    for r in runs:  # the first of equals
        if r["objective"] is not None and (best is None or r["objective"] > best["objective"]):
            best = r
    return None if best is None else dict(best)


def _evaluations_csv(names: Sequence[str], runs: Sequence[Mapping[str, Any]]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["index", "generation", *names, "objective", "sup_E", "sup_Edot", "verdict"])
    for i, r in enumerate(runs):
        w.writerow([i, r["generation"], *(repr(r["params"][n]) for n in names),
                    "" if r["objective"] is None else repr(r["objective"]), repr(r["sup_E"]), repr(r["sup_Edot"]),
                    r["verdict"]])
    return buf.getvalue()


def _compare(result: dict[str, Any], plan: SearchPlan, rungs: Sequence[Mapping[str, Any]], folder: Path) -> None:
    """Add the Monte-Carlo worst of the plan's rung (read from its runs.csv) beside the search's."""
    if plan.mc_rung is None or plan.mc_column is None:
        result["mc"] = None
        return
    rung = rungs[plan.mc_rung - 1]
    value, m1 = max_at(read_runs((folder / rung["runs_csv"]).parent), plan.mc_column)
    worst = (result["worst"] or {}).get("objective")
    result["mc"] = {"rung": plan.mc_rung, "n": rung["n"], "column": plan.mc_column, "worst_objective": value,
                    "worst_m1": m1, "runs_csv": rung["runs_csv"]}
    result["search_at_least_mc"] = None if worst is None or value is None else bool(worst >= value)


def _read_back(saved: Path, fingerprint: str) -> dict[str, Any] | None:
    """The saved search, when search.json and worst.mcap exist and the spec is the same."""
    if not (saved.is_file() and (saved.parent / "worst.mcap").is_file()):
        return None
    try:
        result = json.loads(saved.read_text())
    except json.JSONDecodeError:
        return None
    return result if isinstance(result, dict) and result.get("fingerprint") == fingerprint else None


def _result(plan: SearchPlan, spec, runs: Sequence[Mapping[str, Any]], worst: Mapping[str, Any] | None,
            reproduced: bool, certificate: Any, out: Path, folder: Path, label: str) -> dict[str, Any]:
    return {
        "key": plan.key, "title": plan.title, "fingerprint": _fingerprint(spec), "design": plan.design.name,
        "design_text": plan.design.describe(), "box_name": plan.box,
        "box": {k: list(v) for k, v in spec.box.items()}, "names": list(spec.names), "objective": plan.objective,
        "objective_label": label, "budget": spec.budget,
        "method": spec.method, "population": spec.population_size,
        "generations": 1 + max(r["generation"] for r in runs),
        "evaluations": len(runs), "seed": spec.seed, "worst": None if worst is None else dict(worst),
        "verdicts": count_verdicts(r["verdict"] for r in runs), "values": [r["objective"] for r in runs],
        "certificate": certificate_summary(certificate),
        "log": (out / "worst.mcap").relative_to(folder).as_posix() if worst else None, "reproduced": reproduced,
        "evaluations_csv": (out / "evaluations.csv").relative_to(folder).as_posix(),
    }


def run_search(plan: SearchPlan, settings: ValidateSettings, folder: Path, st: Stages,
               rungs: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """One search: read back when search-<key>/search.json matches its spec, else run it,
    re-run its worst run with an MCAP log (worst.mcap: is the serial run's sup|E| the
    batch's?) and write evaluations.csv and search.json; its certificate is the base run's claim
    (:func:`wmr_mj.sim.parts.resolve_run`)."""
    spec = _search_spec(plan, settings)
    out = folder / f"search-{plan.key}"
    st.start(f"search-{plan.key}", f"search: {plan.title} ({len(spec.names)} parameter(s), budget {spec.budget} runs)")
    result = _read_back(out / "search.json", _fingerprint(spec))
    if result is not None:
        _compare(result, plan, rungs, folder)  # the ladder's sweep may have changed since
        st.done(f"read back from search-{plan.key}/search.json")
        return result
    runs = _evaluate_search(spec, nthread=settings.nthread, progress=stage_progress(st))
    label = objective_label(plan.objective, on_c80=settings.cart is None)  # the paper's region: this cart's
    worst = _worst_of(runs)
    out.mkdir(parents=True, exist_ok=True)
    logged = None
    if worst:
        logged = run_logged(spec.config([worst["params"][n] for n in spec.names]), str(out / "worst.mcap"))
    result = _result(plan, spec, runs, worst, bool(worst and logged is not None and logged.sup_E == worst["sup_E"]),
                     resolve_run(spec.base).claim, out, folder, label)
    _compare(result, plan, rungs, folder)
    write_text_atomic(out / "evaluations.csv", _evaluations_csv(spec.names, runs))
    write_json_atomic(out / "search.json", result)
    st.done(f"worst {_num(worst and worst['objective'])} ({label})"
            + loud(result["verdicts"]["certified-outside"], f"search {plan.key}"))
    return result


def _num(x: Any) -> str:
    return "n/a" if x is None else f"{x:.4g}"


def search_stage(settings: ValidateSettings, folder: Path, st: Stages, rungs: Sequence[Mapping[str, Any]]
                 ) -> list[dict[str, Any]]:
    """Every search of :func:`search_plans`, in order ([] when the search is disabled)."""
    return [run_search(plan, settings, folder, st, rungs) for plan in search_plans(settings)]
