"""Worst-case search: the plant in the uncertainty box that the controller tracks worst.

A robustness claim is only as credible as the worst case anyone looked for. Sweeps
sample the box; ``falsify`` searches it, as falsification tools (S-TaLiRo, Breach) do,
maximising an objective of the closed-loop run over the ranged plant parameters, and the
same number of simulations is spent on a seeded Latin-hypercube sample beside it, so the
search can be judged against chance (``bench/bench_falsify.py`` does so over seeds).

Methods (:data:`METHODS`):

- ``portfolio`` (the default, of ``falsify`` and of ``validate``'s searches): the box's vertices
  first, as one batch: all 2^d where they fit half the budget (:data:`PORTFOLIO_VERTEX_SHARE`) and
  number at most 32 (:data:`PORTFOLIO_MAX_VERTICES`), so that a monotone worst case (a vertex) is
  found exactly (the full box, d = 5: its worst vertex, 0.3927 of E_max, within the first 32 runs of
  any budget >= 64), else a seeded fractional-factorial covering of at most an eighth of the budget
  (:data:`PORTFOLIO_COVER_SHARE`); then CMA-ES (``cmaes``) from the box's centre, moved a quarter of
  a range towards the worse side of each parameter whose main effect over the vertices is
  significant (:func:`screened_start`: the two-level screening of a designed experiment), a
  generation per batch, restarted with twice the population when it stops (IPOP), in whole
  generations up to the local phase; from 200 runs on, that global phase is two independent CMA-ES
  runs from the same start, equal in generations (:func:`portfolio_global_runs`); then a local
  CMA-ES from the worst point found (:func:`portfolio_local_phase`): the last fifth of the budget,
  step 0.05 of each range, below 200 runs, the last three tenths, step 0.02, from 200 on, where the
  second half of it (:func:`portfolio_coordinate_runs`) is coordinate moves of the worst point found
  instead: each parameter moved with probability 1/d (at least one), by a normal step of 0.05 of its
  range (:data:`PORTFOLIO_COORDINATE_STEP`), a generation's worth per batch, the worst found taken
  anew before each batch. Over C's path the high values lie on thin ridges (two adjacent curvature
  knots about 0.075 1/m apart), which a move of the coordinates off a ridge's normal stays on.
  How each part was measured and chosen, on synthetic objectives with known worst cases and on C's
  path with tuning seeds other than the bench's, and what else was tried: the benchmarks guide
  (``docs/guides/benchmarks.md``, "How the portfolio was chosen").
- ``cma``: CMA-ES alone, from the box's centre (the portfolio without the vertices).
- ``vertices-polish``: the box's 2^d vertices first, as one batch, where the budget allows them
  (else a fractional-factorial covering of them, :func:`covering_design`), then scipy's
  Nelder-Mead with bounds from the worst point found, restarted from the next-worst while budget
  is left. At a budget of 48 on the full box, differential evolution was beaten by random sampling
  in 3 of 6 seeds and never reached the worst vertex (0.3927 of E_max), which this finds in 27 runs.
- ``lhs-polish``: a seeded Latin hypercube of half the budget, then the same polish. Over C's path
  (3 knots, the hold, m1; budget 48) the vertices' worst was 0.68 of E_max and random sampling beat
  vertices-polish in 6 of 10 seeds, lhs-polish in 5 of 10.
- ``de``: scipy's differential evolution, a generation per batch (``vectorized=True``).

Each batch of points runs as one batch of simulations (``wmr_mj.sim.many_runs.run_configs``:
``mujoco.batch``, or Dask chunks); the polish asks for one point at a time. A budget below one
generation (differential evolution's or CMA-ES's population) is refused before any run.

Where the objective is the certificate's ratio, :attr:`FalsifyResult.tightness` sets the worst
found (a lower bound on the worst case) beside the certificate's E_max (an upper bound): "the worst
found is X of the certificate's bound: the certificate is 1/X times the worst case found"; where X
exceeds 1, "the worst run is X times the claimed bound: the claim is exceeded". Whatever the objective, the
worst run carries its certificate: :attr:`WorstRun.E_max`, :attr:`WorstRun.binding_term` (the largest part of
its delta1) and the tightness of that run's certificate (for another objective, the worst run is that
objective's, and the sentence says so).

Whatever the objective, a run of either phase that is ``certified-outside`` breaks the law's claim:
:attr:`FalsifyResult.claim_broken` names the one that breaks it most (its parameters), and
:attr:`FalsifyResult.falsified` is then True (``wmr-mj falsify`` prints the banner ``run`` prints and
exits with :data:`wmr_mj.cli._common.CLAIM_BROKEN_EXIT`).

Objectives (:data:`OBJECTIVES`), read from a run's summary by :func:`objective_value`:

- ``certificate``: sup|E| / E_max of the run's certificate (the default);
- ``paper``: sup|E| / E_max of the paper's region;
- ``sup-E``: sup|E| itself, rad;
- ``requirement``: minus the robustness of an STL requirement (``FalsifySpec.requirement``,
  :mod:`wmr_mj.analysis.requirements`): > 0 falsified. These runs go one by one on the engine,
  ``nthread`` at a time (the batch keeps no per-step signals to monitor).

The box (``FalsifySpec.box``) ranges plant parameters and, where the base config has signals
(:mod:`wmr_mj.sim.signals`), their parameters: ``disturbance.amplitude``, ``disturbance.t1``,
``load0.m1``, ... (:mod:`wmr_mj.searches.search_space`). A ranged disturbance amplitude with no
declared ``d_max`` declares the box's largest |amplitude|, one certificate for the whole search.
Runs with signals do not share a batch: they run one by one, ``nthread`` at a time.

Usage::

    from wmr_mj.searches.falsify import FalsifySpec, falsify
    from wmr_mj.params import uncertainty_ranges
    from wmr_mj.sim.closed_loop import RunConfig
    box = uncertainty_ranges("full")  # the certificate covers the declared box: give the base the same ranges
    base = RunConfig.from_inputs(model="nonholonomic", box_ranges={k: v for k, v in box.items() if k != "m1"})
    spec = FalsifySpec(base=base, box=box, budget=256)
    result = falsify(spec)
    print(result.worst.params, result.worst.objective, result.random_worst.objective)

Every evaluation is a run that ``run_closed_loop`` reproduces bit for bit, so the worst
run's parameters (kept at full precision) given back to ``wmr-mj run --m1 X --param
NAME=VALUE ...`` give the same sup|E|; the same seed gives the same search.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from wmr_mj._util.checks import positive_range, runs_of
from wmr_mj._util.deprecation import deprecated_names
from wmr_mj.analysis.requirements import parse_requirement
from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE, VERDICTS, unmet_assumptions
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.params import parameter_names, tie_motor_constant
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.searches.falsify_objectives import (
    OBJECTIVE_LABELS,
    OBJECTIVES,
    binding_term,
    certificate_E_max,
    check_objective_applies,
    check_objective_defined,
    objective_label,
    objective_source,
    objective_value,
    shares_the_base_certificate,
    verdict_of,
)
from wmr_mj.searches.search_methods import (
    METHOD_LABELS,
    METHODS,
    MIN_POPULATION,
    PORTFOLIO_COORDINATE_STEP,
    Trace,
    check_budget,
    cma_population,
    covering_design,
    population_size,
    portfolio_coordinate_runs,
    portfolio_global_runs,
    portfolio_local_phase,
    portfolio_phases,
    portfolio_vertices,
    random_worst,
    screened_start,
    search_worst,
)
from wmr_mj.searches.search_space import (
    check_hardware_range,
    config_for,
    hardware_axis,
    hardware_values,
    parameter_units,
    path_axis,
    signal_axis,
)
from wmr_mj.sim import notebook
from wmr_mj.sim.config import RunConfig, config_from_dict
from wmr_mj.sim.many_runs import connect, flat_row, run_configs
from wmr_mj.sim.parts import resolve_run
from wmr_mj.sim.records import BrokenRun, Record, UnmetAssumption

__all__ = [
    "OBJECTIVES",
    "METHODS",
    "METHOD_LABELS",
    "covering_design",
    "OBJECTIVE_LABELS",
    "objective_label",
    "FalsifySpec",
    "FalsifyResult",
    "WorstRun",
    "RandomWorst",
    "Tightness",
    "BindingTerm",
    "BrokenRun",
    "Evaluation",
    "Trace",
    "objective_value",
    "objective_source",
    "population_size",
    "cma_population",
    "portfolio_vertices",
    "portfolio_global_runs",
    "portfolio_coordinate_runs",
    "search_worst",
    "random_worst",
    "falsify",
    "check_runnable",
    "worst_config",
    "portfolio_start",
    # re-exported from wmr_mj.searches.falsify_objectives and wmr_mj.searches.search_methods, where they live
    "MIN_POPULATION",
    "PORTFOLIO_COORDINATE_STEP",
    "check_budget",
    "check_objective_applies",
    "check_objective_defined",
    "shares_the_base_certificate",
    "undefined_objective_warning",
    "portfolio_local_phase",
    "portfolio_phases",
    "screened_start",
]

_POPULATION_OF = {"de": "differential evolution", "cma": "CMA-ES", "portfolio": "CMA-ES"}  # methods with generations


def undefined_objective_warning(result: FalsifyResult) -> str | None:
    """The warning of a search some of whose runs have no objective (left blank, never the worst): how many
    of each phase, which objective, and what to search where no certificate exists; None when every run
    has one."""
    blank = {phase: sum(e.objective is None for e in evals)
             for phase, evals in (("search", result.search), ("random", result.random))}
    if not any(blank.values()):
        return None
    counts = ", ".join(f"{blank[p]} of {len(evals)} {p} runs" for p, evals in
                       (("search", result.search), ("random", result.random)) if evals)
    objective = result.spec.objective
    text = (f"WARNING: {counts} have no {OBJECTIVE_LABELS[objective]} (left blank: the worst is over the "
            "others only)")
    if objective in ("certificate", "paper"):
        region = "certificate" if objective == "certificate" else "paper's region"
        text += (f"; a run without a {region} (its bound does not exist for that run) may be the worst: "
                 "--objective sup-E searches sup|E| on every run")
    return text


# -- falsify: the search on closed-loop runs ------------------------------------------------

@dataclass(frozen=True, kw_only=True)
class FalsifySpec:
    """Search ``box`` (parameter name -> (lo, hi), m1 included or fixed at base.m1) for the
    run of ``base`` that maximises ``objective``, spending ``budget`` simulations (and as
    many on the random sample)."""

    base: RunConfig = field(default_factory=RunConfig)
    box: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    objective: str = "certificate"
    budget: int = 256
    seed: int = 0
    population: int | None = None  # members per generation of differential evolution or CMA-ES
    method: str = "portfolio"  # one of METHODS
    requirement: str | None = None  # objective 'requirement': an STL formula (wmr_mj.analysis.requirements)

    def __post_init__(self) -> None:
        if self.objective not in OBJECTIVES:
            raise UnknownNameError("objective", self.objective, OBJECTIVES)
        if self.method not in METHODS:
            raise UnknownNameError("search method", self.method, METHODS)
        if (self.objective == "requirement") != (self.requirement is not None):
            raise ParameterError("the objective 'requirement' goes with a requirement (an STL formula), and only it")
        if self.requirement is not None:
            self.parsed_requirement  # noqa: B018  (refused here, before any run, when malformed)
        if not self.box:
            raise ParameterError("the box is empty; give at least one ranged parameter (e.g. --uncertainty m1)")
        names = parameter_names()
        for name, (lo, hi) in self.box.items():
            if hardware_axis(name):  # the cart's: searched, each run's claim covering its own cart
                check_hardware_range(self.base, name, lo, hi)
                continue
            if signal_axis(name) or path_axis(name):
                if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
                    raise ParameterError(f"range of {name} = {lo!r}:{hi!r} is not accepted: finite LO <= HI")
                continue
            if name not in names:
                raise UnknownNameError("parameter", name, names)
            positive_range(name, lo, hi)
        amplitude = self.box.get("disturbance.amplitude")
        signals = self.base.signals
        if amplitude is not None and signals is not None and signals.d_max is None:
            # the certificate declares one bound for the whole search: the largest amplitude of the box
            declared = dataclasses.replace(signals, d_max=max(abs(float(amplitude[0])), abs(float(amplitude[1]))))
            object.__setattr__(self, "base", self.base.replace(signals=declared))
        self.config([lo for lo, _ in self.box.values()])  # a bad axis, or k_b's range not holding k_i's, fails here
        if isinstance(self.seed, bool) or not isinstance(self.seed, int):
            raise ParameterError(f"seed = {self.seed!r} is not accepted; give an integer")
        check_budget(self.budget, self.population_size if self.population_size is not None else MIN_POPULATION,
                      what=_POPULATION_OF.get(self.method, "the search"))

    @property
    def parsed_requirement(self):
        period = TIMESTEP if self.base.control_period is None else self.base.control_period
        return parse_requirement(self.requirement, period=period)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.box)

    @property
    def bounds(self) -> np.ndarray:
        return np.array([self.box[n] for n in self.names], dtype=float)

    @property
    def population_size(self) -> int | None:
        """Members per generation: differential evolution's or CMA-ES's (its first; None for the polish methods)."""
        if self.method not in _POPULATION_OF:
            return None
        if self.population is not None:
            return self.population
        d = len(self.box)
        return population_size(self.budget, d) if self.method == "de" else cma_population(d)

    def recorded_values(self, point: Sequence[float]) -> dict[str, float]:
        """Each ranged parameter -> the value its run used (what the search's tables record): as proposed, but a
        hardware axis rounded as the run has it (:func:`wmr_mj.searches.search_space.hardware_values`)."""
        out = tie_motor_constant({n: float(v) for n, v in zip(self.names, point)}, self.box)
        out.update(hardware_values(self.base, {n: v for n, v in out.items() if hardware_axis(n)}))
        return out

    def config(self, point: Sequence[float]) -> RunConfig:
        """The run at ``point`` (values in ``names`` order): m1, the plant overrides and the signals'
        parameters set (:func:`wmr_mj.searches.search_space.config_for`); k_b as k_i where the box ranges both
        (:func:`wmr_mj.params.tie_motor_constant`)."""
        tied = tie_motor_constant({n: float(v) for n, v in zip(self.names, point)}, self.box)
        return config_for(self.base, self.names, [tied[n] for n in self.names])

    def to_dict(self) -> dict[str, Any]:
        """The search's JSON: its base (``RunConfig.to_dict``), the box (name -> [lo, hi]) and its settings."""
        return {"base": self.base.to_dict(), "box": {k: [float(lo), float(hi)] for k, (lo, hi) in self.box.items()},
                "objective": self.objective, "budget": self.budget, "seed": self.seed,
                "population": self.population, "method": self.method, "requirement": self.requirement}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> FalsifySpec:
        """The search of its JSON ``d`` (:meth:`to_dict`), checked as a new one is; its base read by
        :func:`~wmr_mj.sim.builders.config_from_dict` (coerced, as a command's base is)."""
        box = {k: (float(lo), float(hi)) for k, (lo, hi) in d["box"].items()}
        return cls(base=config_from_dict(d["base"]), box=box, objective=d["objective"], budget=d["budget"],
                   seed=d["seed"], population=d["population"], method=d["method"], requirement=d["requirement"])


@dataclass(frozen=True)
class Evaluation:
    """One simulated run of the search or the random sample."""

    phase: str  # "search" or "random"
    index: int  # in its phase, in evaluation order
    generation: int
    # every ranged parameter, full precision, as the run used it: a hardware axis rounded as its run had it
    # (sensing.encoder_bits = 12.0 where the search proposed 11.533: the run had 4096 ticks)
    params: dict[str, float]
    objective: float | None
    summary: dict[str, Any]  # the run's report
    point: tuple[float, ...] = ()  # the point the search proposed (FalsifySpec.names order); () where unknown

    @property
    def sup_E(self) -> float:
        return float(self.summary["sup_E"])

    @property
    def sup_Edot(self) -> float:
        return float(self.summary["sup_Edot"])

    @property
    def verdict(self) -> str:
        return verdict_of(self.summary)

    @property
    def E_max(self) -> float | None:
        """Its certificate's E_max [rad], whatever the objective; None where the run has none."""
        return certificate_E_max(self.summary)

    @property
    def unmet(self) -> tuple[UnmetAssumption, ...]:
        """The claim's assumptions the run does not meet (its certificate's)."""
        return tuple(UnmetAssumption.from_dict(a) for a in unmet_assumptions(self.summary.get("certificate")))

    @property
    def binding_term(self) -> BindingTerm | None:
        """The largest term of its certificate's delta1 (:class:`BindingTerm`); None where it has none."""
        binding = binding_term(self.summary)
        return None if binding is None else BindingTerm(name=binding[0], value=binding[1])

    def to_dict(self) -> dict[str, Any]:
        """The run's JSON: its phase, index, generation, parameters, objective, summary and proposed point."""
        return {"phase": self.phase, "index": self.index, "generation": self.generation, "params": dict(self.params),
                "objective": self.objective, "summary": self.summary, "point": list(self.point)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Evaluation:
        """The run of its JSON ``d`` (:meth:`to_dict`)."""
        return cls(phase=d["phase"], index=d["index"], generation=d["generation"], params=dict(d["params"]),
                   objective=d["objective"], summary=dict(d["summary"]), point=tuple(d["point"]))


@dataclass(frozen=True, kw_only=True)
class BindingTerm(Record):
    """The largest part of delta1 of a run's certificate, the term that binds its E_max most
    (:func:`wmr_mj.searches.falsify_objectives.binding_term`).

    Attributes:
        name: the term's name in the certificate's JSON (``friction_term``, ``gyro_term``, ``K_term``, ...).
        value: its value [rad/s^2].
    """

    name: str
    value: float


@dataclass(frozen=True, kw_only=True)
class Tightness(Record):
    """How tight the certificate is (:attr:`FalsifyResult.tightness`).

    Attributes:
        ratio: sup|E|/E_max of the worst run's certificate [-] (where the objective is that ratio, the worst
            objective found: a lower bound on the worst case).
        factor: 1/ratio, how many times the worst case found the certificate is (inf where ratio <= 0).
        found_sup_E: the worst run's sup|E| [rad].
        E_max: the certificate's E_max [rad] (an upper bound); None where the run has none.
        text: the sentence ``wmr-mj falsify`` prints.
    """

    ratio: float | None
    factor: float
    found_sup_E: float
    E_max: float | None
    text: str


@dataclass(frozen=True, kw_only=True)
class WorstRun(Record):
    """The search's worst run (``falsify --json``'s ``worst``): its parameters, objective, sup|E| [rad],
    sup|E'| [rad/s], verdict, generation and index (0-based in the search), the claim's assumptions it
    does not meet, and its certificate, whatever the objective: its E_max [rad] (None where the run has none)
    and the largest term of its delta1 (:class:`BindingTerm`; None where it has none)."""

    _records = {"unmet": UnmetAssumption, "binding_term": BindingTerm}

    params: Mapping[str, float]
    objective: float | None
    sup_E: float
    sup_Edot: float
    verdict: str
    generation: int
    index: int
    unmet: tuple[UnmetAssumption, ...]
    E_max: float | None = None
    binding_term: BindingTerm | None = None


@dataclass(frozen=True, kw_only=True)
class RandomWorst(Record):
    """The random sample's worst run (``falsify --json``'s ``random``): its objective and parameters, the
    sample's size, the run's sup|E| [rad] and verdict."""

    worst_objective: float | None
    worst_params: Mapping[str, float]
    evaluations: int
    sup_E: float
    verdict: str


@dataclass(frozen=True, kw_only=True)
class _FalsifyRecord(Record):
    """``wmr-mj falsify --json``'s object, typed (:meth:`FalsifyResult.to_dict` with ``runs=False`` writes it
    before the command adds its files, cart and reproduce line). Not a result of its own: :class:`FalsifyResult`
    answers each of these by attribute (``worst`` and ``random_worst`` as the runs themselves); the deprecated
    name ``FalsifyReport`` still reads an old script's falsify.json with :meth:`from_dict`.

    Attributes:
        objective: one of :data:`OBJECTIVES`.
        objective_label: its words (:data:`OBJECTIVE_LABELS`).
        objective_source: where the objective's bound comes from (:func:`objective_source`).
        budget: the search's simulations asked.
        evaluations: the search's simulations run.
        seed: the search's seed.
        method: one of :data:`METHODS`.
        population: members per generation; None for the polish methods.
        generations: the search's generations.
        requirement: the STL requirement of the objective 'requirement'; None otherwise.
        falsified: :attr:`FalsifyResult.falsified`.
        claim_broken: the run that breaks the claim most; None when none does.
        box: each ranged parameter -> (lo, hi).
        worst: the search's worst run.
        tightness: how tight the worst run's certificate is, whatever the objective; None where the objective is
            not the certificate's ratio and that run has no certificate.
        random: the random sample's worst run.
        log: the MCAP log of the worst run's re-run; None where not written.
    """

    _records = {"claim_broken": BrokenRun, "worst": WorstRun, "tightness": Tightness, "random": RandomWorst}

    objective: str
    objective_label: str
    objective_source: str
    budget: int
    evaluations: int
    seed: int
    method: str
    population: int | None
    generations: int
    requirement: str | None
    falsified: bool | None
    claim_broken: BrokenRun | None
    box: Mapping[str, tuple[float, float]]
    worst: WorstRun
    tightness: Tightness | None
    random: RandomWorst
    log: str | None = None

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> _FalsifyRecord:
        report = super().from_dict(d)
        return dataclasses.replace(report, box={k: (float(lo), float(hi)) for k, (lo, hi) in report.box.items()})


@dataclass(frozen=True)
class FalsifyResult:
    """A search's one result (:func:`falsify`): every run of the search and of its random sample, and what they
    add up to, read by attribute (:attr:`worst`, :attr:`random_worst`, :attr:`tightness`, :attr:`claim_broken`,
    :attr:`falsified`, ...).

    :meth:`to_dict` is its JSON with every run (``runs``), which :meth:`from_dict` reads back; with
    ``runs=False`` it is ``wmr-mj falsify --json``'s object before the command adds its files.

    Attributes:
        spec: the search.
        search: the search's runs, in evaluation order.
        random: the random sample's runs, in evaluation order.
        objective_source: where the objective's bound comes from (:func:`objective_source`).
        log: the MCAP log of the worst run's re-run (the command writes it); None where not written.
    """

    spec: FalsifySpec
    search: list[Evaluation]
    random: list[Evaluation]
    objective_source: str
    log: str | None = None

    @staticmethod
    def _worst(evals: list[Evaluation]) -> Evaluation:
        best, value = None, -math.inf
        for e in evals:  # the first of equals
            if e.objective is not None and e.objective > value:
                best, value = e, e.objective
        if best is None:
            raise ParameterError("the objective is undefined for every run: the design has no certificate over "
                                 "this box (an assumption fails: see wmr-mj robustness --certificate) or the "
                                 "region does not exist; search --objective sup-E or --against paper instead")
        return best

    @property
    def worst(self) -> Evaluation:
        return self._worst(self.search)

    @property
    def random_worst(self) -> Evaluation:
        """The random sample's run of the largest objective; where none of its runs has the objective (each
        left blank: :func:`undefined_objective_warning` says so), its run of the largest sup|E|, whose
        objective is None: the search's worst is still the answer, not an error."""
        if self.random and all(e.objective is None for e in self.random):
            return max(self.random, key=lambda e: e.sup_E)  # max keeps the first of equals
        return self._worst(self.random)

    @property
    def generations(self) -> int:
        return 1 + max((e.generation for e in self.search), default=-1)

    # -- the search's settings, as its JSON names them
    @property
    def objective(self) -> str:
        """One of :data:`OBJECTIVES`."""
        return self.spec.objective

    @property
    def budget(self) -> int:
        """The search's simulations asked."""
        return self.spec.budget

    @property
    def evaluations(self) -> int:
        """The search's simulations run."""
        return len(self.search)

    @property
    def seed(self) -> int:
        return self.spec.seed

    @property
    def method(self) -> str:
        """One of :data:`METHODS`."""
        return self.spec.method

    @property
    def population(self) -> int | None:
        """Members per generation; None for the polish methods."""
        return self.spec.population_size

    @property
    def requirement(self) -> str | None:
        """The STL requirement of the objective 'requirement'; None otherwise."""
        return self.spec.requirement

    @property
    def box(self) -> dict[str, tuple[float, float]]:
        """Each ranged parameter -> (lo, hi)."""
        return {k: (float(lo), float(hi)) for k, (lo, hi) in self.spec.box.items()}

    @property
    def method_label(self) -> str:
        """The search's method in words (:data:`METHOD_LABELS`: ``vertices, then CMA-ES``), as its figure says it."""
        return METHOD_LABELS[self.spec.method]

    @property
    def objective_label(self) -> str:
        """The objective in words (:func:`objective_label`: ``sup|E|/E_max of the certificate``; the paper's region
        named as this cart's on another cart than the C80)."""
        return objective_label(self.spec.objective, on_c80=getattr(self.spec.base, "cart", None) is None)

    @property
    def tightness(self) -> Tightness | None:
        """How tight the certificate is, whatever the objective: the worst run's sup|E| (where the objective is
        the certificate's ratio, the worst found: a lower bound on the worst case, a run reached it) beside its
        certificate's E_max (an upper bound), their ratio X and 1/X, and the sentence falsify prints. Where the
        objective is another, the worst run is that objective's, and the sentence says so; None where that run
        has no certificate."""
        w = self.worst
        e_max = certificate_E_max(w.summary)
        if self.spec.objective == "certificate":
            x = w.objective
        elif e_max is None:
            return None
        else:
            x = objective_value(w.summary, "certificate")
        factor = 1.0 / x if x is not None and x > 0 else math.inf
        bound = "n/a" if e_max is None else f"{e_max:.4g}"
        if x is not None and x > 1.0:  # exceeded: said as such, never as a fraction of the worst case
            text = (f"the worst run is {x:.3g} times the claimed bound (sup|E| = {w.sup_E:.4g} rad found, <= "
                    f"{bound} rad claimed): the claim is exceeded"
                    + (" and its assumptions hold: CERTIFIED-OUTSIDE" if w.verdict == CERTIFIED_OUTSIDE else
                       f" where its assumptions are not all met ({w.verdict}): not a broken claim"))
        else:
            text = (f"the worst found is {_number(x, '.4g')} of the certificate's bound: the certificate is "
                    f"{factor:.3g} times the worst case found (sup|E| >= {w.sup_E:.4g} rad found, <= {bound} rad "
                    "certified)")
        if self.spec.objective != "certificate":
            text += f" (the worst run by {self.objective_label})"
        return Tightness(ratio=x, factor=factor, found_sup_E=w.sup_E, E_max=e_max, text=text)

    @property
    def claim_broken(self) -> BrokenRun | None:
        """The run (of the search or the random sample) that breaks the law's claim most, whatever the
        objective: the ``certified-outside`` run of the largest sup|E|/E_max (the first of equals, the
        search's first); None when no run breaks it."""
        broken = [e for e in (*self.search, *self.random) if e.verdict == CERTIFIED_OUTSIDE]
        if not broken:
            return None

        def ratio(e: Evaluation) -> float:
            value = (e.summary.get("certificate") or {}).get("E_ratio")
            return -math.inf if value is None else float(value)

        e = max(broken, key=ratio)  # max keeps the first of equals
        e_max = (e.summary.get("certificate") or {}).get("E_max")
        return BrokenRun(phase=e.phase, run=e.index + 1, params=dict(e.params), sup_E=e.sup_E, sup_Edot=e.sup_Edot,
                         E_max=None if e_max is None else float(e_max),
                         ratio=None if ratio(e) == -math.inf else ratio(e), count=len(broken))

    @property
    def falsified(self) -> bool | None:
        """True when a run breaks the law's claim (:attr:`claim_broken`) or, for the objective
        'requirement', when the worst run falsifies it; False when neither, where there is a claim or a
        requirement to falsify; None when there is neither (every run without a claim)."""
        if self.claim_broken is not None:
            return True
        if self.spec.objective == "requirement":
            w = self.worst
            return w.objective is not None and w.objective > 0.0
        judged = any(e.verdict in VERDICTS for e in (*self.search, *self.random))
        return False if judged else None

    def _record(self, log: str | None) -> _FalsifyRecord:
        """``falsify --json``'s object, typed (``log``: the worst run's MCAP log, where written)."""
        w, r = self.worst, self.random_worst
        return _FalsifyRecord(
            objective=self.objective, objective_label=self.objective_label, objective_source=self.objective_source,
            budget=self.budget, evaluations=self.evaluations, seed=self.seed, method=self.method,
            population=self.population, generations=self.generations, requirement=self.requirement,
            falsified=self.falsified, claim_broken=self.claim_broken, box=self.box,
            worst=WorstRun(params=dict(w.params), objective=w.objective, sup_E=w.sup_E, sup_Edot=w.sup_Edot,
                           verdict=w.verdict, generation=w.generation, index=w.index, unmet=w.unmet, E_max=w.E_max,
                           binding_term=w.binding_term),
            tightness=self.tightness,
            random=RandomWorst(worst_objective=r.objective, worst_params=dict(r.params), evaluations=len(self.random),
                               sup_E=r.sup_E, verdict=r.verdict),
            log=log)

    def report(self, *, log: str | None = None) -> _FalsifyRecord:
        """Deprecated (kept one release): the result answers each of these by attribute, and
        ``to_dict(runs=False)`` is their JSON."""
        warnings.warn("FalsifyResult.report() is deprecated: read the result by attribute (result.worst, "
                      "result.tightness, result.claim_broken); result.to_dict(runs=False) is falsify --json's object",
                      DeprecationWarning, stacklevel=2)
        return self._record(self.log if log is None else log)

    def to_dict(self, *, log: str | None = None, runs: bool = True) -> dict[str, Any]:
        """The search's JSON: ``wmr-mj falsify --json``'s keys (the worst run, the random sample's worst, the
        tightness, the claim broken, the log), then, with ``runs``, ``runs``: the spec (``FalsifySpec.to_dict``)
        and every run of both phases (``Evaluation.to_dict``), which :meth:`from_dict` reads back.

        Args:
            log: the worst run's MCAP log, in place of :attr:`log` (None: :attr:`log`).
            runs: add ``runs``; False: falsify --json's object exactly.
        """
        out = self._record(self.log if log is None else log).to_dict()
        if runs:
            out["runs"] = {"spec": self.spec.to_dict(), "search": [e.to_dict() for e in self.search],
                           "random": [e.to_dict() for e in self.random]}
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> FalsifyResult:
        """The result of its JSON ``d`` (:meth:`to_dict`, with its ``runs``): equal to the result written where its
        spec's base was coerced (a command's, or ``RunConfig.from_inputs``); a base built directly reads back as
        the coerced config it ran as (the same JSON).

        Raises:
            ParameterError: ``d`` has no ``runs`` (falsify --json's object, falsify.json): one line.
        """
        runs = runs_of(d, result="FalsifyResult", holds="falsify --json and falsify.json hold the worst run only")
        return cls(spec=FalsifySpec.from_dict(runs["spec"]), search=[Evaluation.from_dict(e) for e in runs["search"]],
                   random=[Evaluation.from_dict(e) for e in runs["random"]], objective_source=d["objective_source"],
                   log=d.get("log"))

    # -- in a notebook (wmr_mj.sim.notebook): every run as a table, the search beside random, a few lines
    def to_pandas(self) -> Any:
        """One row per run, the search's then the random sample's: ``phase``, ``index``, ``generation``, the
        values the run used (each ranged parameter, with units), ``objective``, then the run's verdict, sup|E|,
        the certificate's bounds (``certificate_E_max [rad]``) and the paper's claim as a sweep's table.

        Raises:
            WmrMjError: pandas is not installed (``pip install 'wmr-mj[notebook]'``).
        """
        names = self.spec.names
        rows = [{"phase": e.phase, "index": e.index, "generation": e.generation, **e.params,
                 "objective": e.objective, **{k: v for k, v in flat_row(e.summary).items() if k not in e.params}}
                for e in (*self.search, *self.random)]
        return notebook.runs_frame(rows, parameters=names, units=parameter_units(names),
                                   first=("phase", "index", "generation", "objective"))

    def plot(self, **options: Any) -> Any:
        """The search beside random: each run's objective and the running worst of each
        (a :class:`wmr_mj.figures.results.ResultPlot`)."""
        from wmr_mj.figures.results import plot_falsify  # matplotlib loads only when a figure is asked for

        return plot_falsify(self, **options)

    def _repr_html_(self) -> str:
        return notebook.falsify_html(self)



# deprecated alias: keep one release (FalsifyResult is falsify's one result)
__getattr__ = deprecated_names(__name__, {"FalsifyReport": (
    _FalsifyRecord, "FalsifyResult is the search's one result (read it by attribute; to_dict(runs=False) is "
    "falsify --json's object)")})


def falsify(spec: FalsifySpec, *, chunk: int = 128, nthread: int = 0, scheduler: str | None = None,
            progress: Callable[[int, int], None] | None = None,
            checkpoint: Callable[[FalsifyResult], object] | None = None, parts: Any = None) -> FalsifyResult:
    """Search ``spec.box`` for the worst run, then spend as many runs on a random sample.

    ``parts``: ``spec.base`` already resolved (:func:`check_runnable`); None: resolved here.

    Each generation runs as one batch (locally in chunks of ``chunk`` on ``nthread``
    threads, or on the Dask ``scheduler``). progress(done, total) counts finished runs of
    both phases. checkpoint(partial result) is called after every generation (and the
    random batch), so an interrupted search can leave what it evaluated on disk.
    """
    parts = check_runnable(spec.base) if parts is None else parts  # a bad duration or path: one line, here
    check_objective_applies(parts.controller, spec.objective)
    check_objective_defined(parts, spec)  # undefined for every run: refused before any step
    client = connect(scheduler) if scheduler is not None else None
    evaluations: dict[str, list[Evaluation]] = {"search": [], "random": []}
    total = 2 * spec.budget  # refined once the search has run
    done = 0

    def evaluator(phase: str, generation_of: Callable[[], int]) -> Callable[[np.ndarray], np.ndarray]:
        def evaluate(points: np.ndarray) -> np.ndarray:
            nonlocal done
            configs = [spec.config(p) for p in points]
            base_done = done

            def chunk_progress(k: int, n: int) -> None:
                if progress is not None:
                    progress(base_done + k, total)

            requirements = () if spec.requirement is None else (spec.requirement,)
            reports = [s.to_dict() for s in  # the summaries' JSON, what a search writes and reads back
                       run_configs(configs, chunk=chunk, nthread=nthread, client=client, progress=chunk_progress,
                                   requirements=requirements)]
            done += len(reports)
            out = np.full(len(points), np.nan)
            generation = generation_of()
            for i, (p, r) in enumerate(zip(points, reports)):
                value = objective_value(r, spec.objective)
                out[i] = np.nan if value is None else value
                evaluations[phase].append(Evaluation(
                    phase=phase, index=len(evaluations[phase]), generation=generation,
                    params=spec.recorded_values(p), point=tuple(float(v) for v in p),
                    objective=None if value is None else float(value), summary=r))
            if checkpoint is not None:
                checkpoint(FalsifyResult(spec=spec, search=list(evaluations["search"]),
                                         random=list(evaluations["random"]),
                                         objective_source=objective_source(reports[0], spec.objective)))
            return out

        return evaluate

    generations = 0

    def next_generation() -> int:
        nonlocal generations
        generations += 1
        return generations - 1

    try:
        search_worst(evaluator("search", next_generation), spec.bounds, budget=spec.budget, seed=spec.seed,
                     population=spec.population_size, method=spec.method)
        total = 2 * len(evaluations["search"])
        random_worst(evaluator("random", lambda: 0), spec.bounds, n=len(evaluations["search"]), seed=spec.seed)
    finally:
        if client is not None:
            client.close()
    first = evaluations["search"][0].summary
    return FalsifyResult(spec=spec, search=evaluations["search"], random=evaluations["random"],
                         objective_source=objective_source(first, spec.objective))


def check_runnable(base: RunConfig) -> Any:
    """Raise what the first batch would raise for ``base`` (a duration too short for the path,
    a control period that does not fit), before any search starts: the reference every
    evaluation shares depends on the base configuration only (path, duration, period), and a law's
    claim() that raises or returns what is not a claim (:func:`wmr_mj.sim.certify.certificate_of`).

    Returns:
        RunParts: ``base`` resolved (:func:`wmr_mj.sim.parts.resolve_run`), for :func:`falsify`'s ``parts``.
    """
    return resolve_run(base)


def _number(x: float | None, spec: str) -> str:
    return "n/a" if x is None else format(x, spec)


def worst_config(result: FalsifyResult) -> RunConfig:
    """The worst run's config, rebuilt from its reported parameters."""
    w = result.worst
    return result.spec.config(w.point or [w.params[n] for n in result.spec.names])


def portfolio_start(spec: FalsifySpec, first: Sequence[Evaluation]) -> np.ndarray:
    """Where the portfolio's CMA-ES started (d,) in the unit box: :func:`screened_start` of its vertices ``first``
    (the runs of generation 0), each at its point as searched (unrounded) scaled to [0, 1] per range (a range of
    zero width at 0), their objectives the values (a run without one left out)."""
    lo, hi = spec.bounds[:, 0], spec.bounds[:, 1]
    corners = np.array([e.point or [e.params[n] for n in spec.names] for e in first])  # as searched, unrounded
    corners = np.where(hi > lo, (corners - lo) / np.where(hi > lo, hi - lo, 1.0), 0.0)
    values = np.array([np.nan if e.objective is None else e.objective for e in first])
    return screened_start(corners, values)
