"""The gains a given cart can certify: a seeded search over a law's parameters whose objective is the run's own
certificate (``wmr-mj design``): the computed-torque law (the default) or the sliding-mode law (:data:`LAWS`).

The search space (for each control period of a given list): the natural frequency omega_n and the damping
ratio zeta of the error dynamics, K_P = omega_n^2, K_D = 2 zeta omega_n; the Coulomb sign's smoothing width w
(rad/s); and, where the cart's velocity estimate is ``filtered``, its time constant tau_f (s). The law is the
certified design's family (computed torque, the non-holonomic model, the measured sign, smoothed).

The sliding-mode family (``controller='sliding-mode'``, the non-holonomic model, the measured sign, smoothed):
the surface's slope lam (1/s), the layer phi (rad/s), the switching gain k (V) and the sliding condition's margin
eta (V), each searched in log, with the sign's width, tau_f and the period as above. Its certificate is the one a
run computes: on a sensed cart the better of the continuous boundary layer and the layer as a sampled loop
(:mod:`wmr_mj.analysis.sliding_sampled`); its start is the law's defaults (lam 5, phi 0.2, k 3, eta 0.2) with the
narrowest sign width of the range (the default's exact sign, width 0, lies outside a log range).

Each point is scored by :func:`wmr_mj.sim.certify.certificate_of` on the parts a run resolves
(:func:`wmr_mj.sim.parts.resolve_run`, once per period and path): the certificate of the design is the one
``wmr-mj run --design FILE`` computes, to the bit, and the found design is checked again through
``resolve_run`` itself. A point whose certificate is not certified on every path is infeasible: it scores a
penalty above every feasible point (ranked by how many assumptions it leaves unmet), never a value. The optimiser
(:data:`METHODS`) is CMA-ES (``cmaes``, seeded) started at :data:`START_POINT` (omega_n 10, zeta 1, w 0.01: the
certified preset until 2026-11-28, omega_r 20), which it scores first, or scipy's differential evolution (seeded,
one worker, no gradient polish) with that point in its first population: where the point lies in the space the
design is never worse than it. The start is a fixed point of the search, not the preset (now omega_r 30), so a
change of the preset moves no design.

The objective ``E_max-then-voltage`` (:data:`OBJECTIVES`) weighs the supply: a first search minimises E_max as
``E_max`` does (the same points, the same best E*), then a second, of the same budget, started at the first's best
point of each period, minimises the worst certified voltage over the points whose worst E_max is at most
(1 + :data:`E_MAX_SLACK`) E* (a point above that cap scores between :data:`PENALTY` and every uncertified point,
graded by how far above it is). The first's best point meets the cap, so the design is never above E* (1 + 0.1)
nor above the first's voltage; its score is its voltage. A lexicographic rule, not a weighted sum: it needs no
exchange rate between radians and volts, and the slack is the issue's own (within 10 % of the same E_max).

Usage::

    from wmr_mj.searches.design_search import DesignProblem, search_design
    result = search_design(DesignProblem(base=config, paths=("paper-circle",), periods=(0.001,)))
    result.settings            # {'controller': 'computed-torque', 'kp': ..., 'kd': ..., ...}
    write_design(result, "design.json"); design_file_settings("design.json")
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from wmr_mj._util.files import write_json_atomic
from wmr_mj.analysis.claim_types import Assumption
from wmr_mj.carts import cart_names, cart_path
from wmr_mj.carts.provenance import identified_from
from wmr_mj.errors import ParameterError
from wmr_mj.hardware import Actuation, Sensing, Transmission
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.searches.design_options import (
    DEFAULT_BUDGET,
    DEFAULT_OBJECTIVE,
    DEFAULT_SEED,
    E_MAX_SLACK,
    LAWS,
    METHODS,
    OBJECTIVES,
)
from wmr_mj.searches.optimisers import CMAES, Chain, DifferentialEvolution, Optimiser, Points, drive
from wmr_mj.sim import notebook
from wmr_mj.sim.certify import certificate_name, certificate_of, measurement_errors_of
from wmr_mj.sim.coerce import coerced, plant_parameters
from wmr_mj.sim.config import controller_and_settings
from wmr_mj.sim.designs import CERTIFIED
from wmr_mj.sim.notebook import number
from wmr_mj.sim.parts import resolve_run
from wmr_mj.sim.records import Record

__all__ = ["DesignProblem", "DesignResult", "OBJECTIVES", "METHODS", "LAWS", "DEFAULT_SEED", "DEFAULT_BUDGET",
           "DEFAULT_OBJECTIVE", "DESIGN_FIELDS", "law_changes", "uncovered", "search_design", "evaluate_design",
           "write_design", "read_design", "design_file_settings", "design_cart", "check_periods"]

#: the RunConfig settings a design file sets (``run --design FILE``), as a preset does
DESIGN_FIELDS = ("controller", "controller_params", "model", "kp", "kd", "friction_sign", "friction_width",
                 "control_period", "sensing", "actuation", "transmission")
#: the file's format tag and version
FORMAT = "wmr-mj design"
PENALTY = 1.0e6  # an uncertified point's score: above every feasible one (plus its number of unmet assumptions)


@dataclass(frozen=True, kw_only=True)
class DesignProblem:
    """What ``wmr-mj design`` searches.

    Attributes:
        base: the run's configuration: the cart (sensing, actuation, transmission), the plant box (m1_range,
            box_ranges, box), the duration; the law's fields are the search's.
        paths: the paths every certificate must hold on (the worst counts); empty: the base's own path (its
            ``path``, else its cart's: :func:`wmr_mj.reference.named.default_path`, the paper circle on the C80), as
            ``wmr-mj design`` takes it.
        periods: the control periods tried, s (each a whole number of physics steps).
        objective: one of :data:`OBJECTIVES` (default :data:`DEFAULT_OBJECTIVE`, the supply weighed).
        method: one of :data:`METHODS`.
        seed: the optimiser's seed (same seed, same design).
        budget: points scored per period, about (each point's certificate on every path): CMA-ES's generations
            until that many; differential evolution's generations are budget // (popsize * dimensions) - 1, at
            least 1.
        omega_n: natural frequency range, rad/s; zeta: damping ratio range; width: the sign's smoothing range,
            rad/s (searched in log); tau_f: the filter's time constant range, s (searched in log; only where the
            cart's velocity estimate is filtered).
        lam (1/s), phi (rad/s), k (V), eta (V): the sliding-mode law's ranges (``base.controller`` 'sliding-mode').
    """

    base: Any
    paths: tuple[str, ...] = ()
    periods: tuple[float, ...] = (0.001,)
    objective: str = DEFAULT_OBJECTIVE
    method: str = "cma"
    seed: int = DEFAULT_SEED
    budget: int = DEFAULT_BUDGET
    omega_n: tuple[float, float] = (2.0, 40.0)
    zeta: tuple[float, float] = (0.5, 3.0)
    width: tuple[float, float] = (1.0e-3, 1.0)
    tau_f: tuple[float, float] = (1.0e-3, 0.2)
    lam: tuple[float, float] = (1.0, 60.0)
    phi: tuple[float, float] = (0.05, 20.0)
    k: tuple[float, float] = (0.5, 24.0)
    eta: tuple[float, float] = (1.0e-3, 1.0)


@dataclass(frozen=True, kw_only=True)
class DesignCertificate(Record):
    """A path's certificate as the design file records it (:meth:`DesignResult.from_dict` reads it back in place
    of the live :class:`~wmr_mj.analysis.certificate.Certificate`; it answers the same attributes a design reads).

    Attributes:
        certified: every assumption met.
        E_max: the bound on |E| [rad]; None where the certificate has no valid bound.
        voltage_max: the bound on |u| [V]; None likewise.
        reason: why there is no valid bound ('' where there is one).
        certificate: which analysis gave it (:func:`wmr_mj.sim.certify.certificate_name`).
        assumptions: its assumptions, each with its value and limit.
    """

    certified: bool
    E_max: float | None
    voltage_max: float | None
    reason: str
    certificate: str
    assumptions: tuple[Assumption, ...] = ()

    @property
    def valid(self) -> bool:
        """The certificate has a bound (the file records E_max only then)."""
        return self.E_max is not None

    @property
    def Edot_max(self) -> None:
        """Not recorded in the design file: None."""
        return None

    @property
    def inputs(self) -> dict[str, str]:
        """What :func:`~wmr_mj.sim.certify.certificate_name` reads: the analysis that gave it."""
        return {"certificate": self.certificate}

    @property
    def analysis(self) -> str:
        """The analysis that gave it (as :attr:`inputs` says)."""
        return self.certificate

    @classmethod
    def of(cls, cert: Any) -> DesignCertificate:
        """The record of a live certificate (a record is itself)."""
        if isinstance(cert, DesignCertificate):
            return cert
        return cls(certified=cert.certified, E_max=cert.E_max if cert.valid else None,
                   voltage_max=cert.voltage_max if cert.valid else None, reason=cert.reason,
                   certificate=certificate_name(cert), assumptions=tuple(cert.assumptions))

    def to_dict(self) -> dict[str, Any]:
        """The design file's ``certificates[path]``."""
        return {"certified": self.certified, "E_max": self.E_max, "voltage_max": self.voltage_max,
                "reason": self.reason, "certificate": self.certificate,
                "assumptions": [a.to_dict() for a in self.assumptions]}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> DesignCertificate:
        """The record of ``certificates[path]`` (an assumption's None value or limit: NaN, as it was written)."""
        def number(value: Any) -> float:
            return math.nan if value is None else float(value)

        assumptions = tuple(Assumption(name=a["name"], equation=a["equation"], met=a["met"], value=number(a["value"]),
                                       limit=number(a["limit"]), note=a["note"], kind=a["kind"])
                            for a in d["assumptions"])
        return cls(certified=d["certified"], E_max=d["E_max"], voltage_max=d["voltage_max"], reason=d["reason"],
                   certificate=d["certificate"], assumptions=assumptions)


@dataclass(frozen=True, kw_only=True)
class DesignResult:
    """The design found.

    Attributes:
        settings: the RunConfig fields it sets (:data:`DESIGN_FIELDS`; the cart's parts as objects).
        certified: every path's certificate is certified.
        score: the objective at the design (:data:`PENALTY` and above where nothing certified).
        certificates: per path, the certificate ``run`` computes for the design (from ``resolve_run``).
        binding: where nothing certified: the assumption (or reason) unmet at the best point found; '' else.
        evaluations: certificate evaluations spent.
        box: what the certificates were computed for besides the design (m1_range, box_ranges, box,
            reference_bounds, duration): the run options a run needs to compute the same certificate.
        cart: the cart searched on, as its config records it (name, version, path, the file's text); None: the C80.
        law_parameters: the law's own parameters the search varied (``controllers.base.DesignParameter``, the
            law's ``design_parameters``); (): its gains K_P, K_D.
        objective, seed, periods, paths: the search's.
    """

    settings: Mapping[str, Any]
    certified: bool
    score: float
    certificates: Mapping[str, Any]
    binding: str = ""
    evaluations: int = 0
    objective: str = "E_max"
    seed: int = 0
    periods: tuple[float, ...] = ()
    paths: tuple[str, ...] = ()
    box: Mapping[str, Any] | None = None
    cart: Mapping[str, Any] | None = None
    law_parameters: tuple[Any, ...] = ()

    @property
    def E_max(self) -> float:
        """The worst E_max over the paths, rad (inf where a certificate has none)."""
        return max((c.E_max if c is not None and c.valid else math.inf) for c in self.certificates.values())

    def to_dict(self) -> dict[str, Any]:
        """The design file's content (:func:`design_dict`: what ``design --out`` writes and ``run --design``
        reads)."""
        return design_dict(self)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> DesignResult:
        """The design of its file's content ``d`` (:meth:`to_dict`): the settings as the run's parts, each path's
        certificate as the file records it (:class:`DesignCertificate`)."""
        settings = dict(d["settings"])
        law_parameters: tuple[Any, ...] = ()
        if "controller_params" in settings:  # the law's own parameters: the sign's shape among them, as a run has it
            law_parameters = tuple(settings["controller_params"])
            settings["controller_params"] = {**settings["controller_params"],
                                             "friction_sign": settings["friction_sign"],
                                             "friction_width": settings["friction_width"]}
        else:
            settings["controller_params"] = {}
        settings.update(sensing=Sensing.from_spec(settings["sensing"]),
                        actuation=Actuation.from_spec(settings["actuation"]),
                        transmission=Transmission(backlash=settings.pop("backlash")))
        search = d["search"]
        return cls(settings={k: settings[k] for k in DESIGN_FIELDS}, certified=d["certified"], score=search["score"],
                   certificates={p: None if c is None else DesignCertificate.from_dict(c)
                                 for p, c in d["certificates"].items()},
                   binding=d["binding"], evaluations=search["evaluations"], objective=search["objective"],
                   seed=search["seed"], periods=tuple(search["periods"]), paths=tuple(search["paths"]), box=d["box"],
                   cart=d.get("cart"), law_parameters=law_parameters)

    # -- in a notebook (wmr_mj.sim.notebook): each path's certificate as a table, the design in a few lines
    def to_pandas(self) -> Any:
        """One row per path: ``path``, ``certified``, ``certificate`` (which analysis gave it), ``E_max [rad]``,
        ``Edot_max [rad/s]``, ``voltage_max [V]`` and ``unmet`` (the assumptions not met, by name).

        Raises:
            WmrMjError: pandas is not installed (``pip install 'wmr-mj[notebook]'``).
        """
        rows = []
        for path, cert in self.certificates.items():
            valid = cert is not None and cert.valid
            rows.append({"path": path, "certified": bool(cert is not None and cert.certified),
                         "certificate": certificate_name(cert) if cert is not None else "",
                         "E_max [rad]": cert.E_max if valid else None,
                         "Edot_max [rad/s]": cert.Edot_max if valid else None,
                         "voltage_max [V]": cert.voltage_max if valid else None,
                         "unmet": ", ".join(a.name for a in cert.assumptions if not a.met) if cert else ""})
        return notebook.records_frame(rows)

    def plot(self) -> Any:
        """Each path's certificate at the design: its E_max and its voltage bound, one bar per path, green where
        certified (a :class:`wmr_mj.figures.results.ResultPlot`: ``.figure``, ``.axes``)."""
        from wmr_mj.figures.results import plot_design  # matplotlib loads only when a figure is asked for

        return plot_design(self)

    def _repr_html_(self) -> str:
        return notebook.html_lines("design", "certified" if self.certified else "nothing certifies",
                                   design_lines(self))


def law_changes(law: str) -> dict[str, Any]:
    """The RunConfig fields of the law a design searches, before the gains the search sets: computed torque as
    the certified preset has it (its model, its measured smoothed sign), sliding mode on the non-holonomic model.

    Raises:
        ParameterError: a law not in :data:`LAWS` (one line listing them).
    """
    _check_law(law)
    return CERTIFIED.config_changes() if law == "computed-torque" else {"controller": law, "model": "nonholonomic"}


def _check_law(law: Any) -> None:
    if law not in LAWS:
        raise ParameterError(f"--controller {law!r} is not accepted; one of {', '.join(LAWS)}")


def uncovered(base: Any) -> str:
    """Why no certificate can cover ``base``'s cart (its sensing, actuation and play on its parameter set), so that
    no design can certify it (e.g. "Gaussian noise has no bound"); '' where its errors are covered. What ``wmr-mj
    design`` refuses before any search and ``cart check`` reports as binding. The errors are derived as
    :func:`wmr_mj.sim.parts.resolve_run` derives a run's (:func:`wmr_mj.sim.certify.measurement_errors_of` on the
    run's plant), without building the run."""
    measurement = measurement_errors_of(base, plant_parameters(base))
    return "" if measurement.covered else str(measurement.why_not)


def check_periods(periods: Sequence[float], duration: float) -> tuple[float, ...]:
    """The period list, each checked: > 0, a whole number of 1 ms physics steps, and a divisor of the run.

    Raises:
        ParameterError: an empty list or a period that is not accepted (one line naming it).
    """
    out = []
    for p in periods:
        p = float(p)
        steps = p / TIMESTEP
        if not (math.isfinite(p) and p > 0 and abs(steps - round(steps)) < 1e-9 and round(steps) >= 1):
            raise ParameterError(f"--periods: {p!r} s is not a whole number of {TIMESTEP:g} s physics steps; "
                                 "periods such as 0.001,0.002 are accepted")
        runs = duration / p
        if abs(runs - round(runs)) > 1e-9 * max(1.0, runs):
            raise ParameterError(f"--periods: {p!r} s does not divide the run's {duration!r} s; a period that "
                                 "divides the run and the physics step's multiple is accepted")
        out.append(p)
    if not out:
        raise ParameterError("--periods is empty; one or more periods (s), e.g. 0.001,0.002, are accepted")
    return tuple(out)


def _gains(omega_n: float, zeta: float) -> tuple[float, float]:
    return omega_n * omega_n, 2.0 * zeta * omega_n


class _Scorer:
    """The certificate of a point on each path, on the parts ``resolve_run`` gives (resolved once per path)."""

    def __init__(self, problem: DesignProblem, period: float):
        self.problem = problem
        self.template = dataclasses.replace(problem.base, control_period=period)
        self.parts = {path: resolve_run(dataclasses.replace(self.template, path=path)) for path in problem.paths}
        self.filtered = self.template.sensing.velocity == "filtered"
        law = type(next(iter(self.parts.values())).controller)
        #: the law's own parameters searched (controllers.base.DesignParameter; (): its gains as omega_n, zeta),
        #: whether an uncertified point is graded, and the law's keyword defaults (the search's start)
        self.law_parameters: tuple[str, ...] = tuple(p.name for p in law.design_parameters)
        self.graded = bool(law.design_graded)
        self.law_defaults = law.__init__.__kwdefaults__ or {}
        self.evaluations = 0
        #: what this scorer minimises, and the cap on the worst E_max (rad) of the second search of
        #: 'E_max-then-voltage' (None: the first, which minimises E_max)
        self.objective = "E_max" if problem.objective == "E_max-then-voltage" else problem.objective
        self.e_max_cap: float | None = None

    def bounds(self, period: float) -> list[tuple[float, float]]:
        """The point's box: (log omega_n, zeta, log10 w) or (log lam, log phi, log k, log eta, log10 w), then
        log tau_f where the estimate is filtered."""
        p = self.problem
        width = (math.log10(p.width[0]), math.log10(p.width[1]))
        if self.law_parameters:
            out = [(math.log(lo), math.log(hi)) for lo, hi in (getattr(p, n) for n in self.law_parameters)] + [width]
        else:
            out = [(math.log(p.omega_n[0]), math.log(p.omega_n[1])), p.zeta, width]
        if self.filtered:
            out.append((math.log(max(p.tau_f[0], period)), math.log(p.tau_f[1])))
        return out

    def config(self, x: Any) -> Any:
        """The RunConfig of the point x (a sequence or an array; :meth:`bounds`)."""
        sensing = self.template.sensing
        if self.filtered:
            sensing = dataclasses.replace(sensing, filter_tau=math.exp(x[-1]))
        if self.law_parameters:
            params: dict[str, Any] = {n: math.exp(float(v)) for n, v in zip(self.law_parameters, x)}
            params.update(friction_sign="measured", friction_width=10.0 ** float(x[len(self.law_parameters)]))
            return dataclasses.replace(self.template, controller_params=params, sensing=sensing)
        kp, kd = _gains(math.exp(x[0]), float(x[1]))
        return dataclasses.replace(self.template, kp=kp, kd=kd, friction_width=10.0 ** float(x[2]), sensing=sensing)

    def certificates(self, config: Any) -> dict[str, Any]:
        out = {}
        for path, parts in self.parts.items():
            c = dataclasses.replace(config, path=path)
            controller, _ = controller_and_settings(c, parts.estimate)
            self.evaluations += 1
            out[path] = certificate_of(c, parts.reference, base=parts.base, estimate=parts.estimate,
                                       plant=parts.plant, controller=controller, tracker=parts.tracker)
        return out

    def __call__(self, x: Any) -> float:
        return score(self.certificates(self.config(x)), self.objective, graded=self.graded, e_max_cap=self.e_max_cap)


def _margin(cert: Any) -> float:
    """The smallest relative margin 1 - value/limit of the checked assumptions with a finite limit > 0."""
    margins = [1.0 - a.value / a.limit for a in cert.assumptions
               if a.kind == "checked" and math.isfinite(a.limit) and a.limit > 0 and math.isfinite(a.value)]
    return min(margins, default=0.0)


def score(certificates: Mapping[str, Any], objective: str, *, graded: bool = False,
          e_max_cap: float | None = None) -> float:
    """The objective over the paths' certificates: the worst one; :data:`PENALTY` plus the unmet assumptions'
    count where any certificate is missing or not certified. ``graded`` (the sliding-mode search, whose default
    start has its layer saturated: a flat plateau of one unmet assumption): plus x/(1 + x) < 1, x the sum of
    log(value/limit) over the unmet checked assumptions with a finite value and limit > 0, so the optimiser sees
    how far a point is from meeting them (the count still ranks first).

    ``E_max-then-voltage`` (its second search; ``e_max_cap`` the cap on the worst E_max, rad): the worst voltage
    where the worst E_max is at most the cap; above it, :data:`PENALTY` + (1 - cap/E_max), in (PENALTY, PENALTY + 1):
    above every point that meets the cap, below every uncertified one, graded by how far above the cap.

    Raises:
        ParameterError: ``E_max-then-voltage`` without ``e_max_cap`` on certified certificates.
    """
    unmet, excess = 0, 0.0
    for cert in certificates.values():
        if cert is None:
            unmet += 100
        elif not cert.certified:
            unmet += len(cert.unmet) + (0 if cert.valid else 1)
            excess += sum(math.log(a.value / a.limit) for a in cert.assumptions
                          if not a.met and a.kind == "checked" and math.isfinite(a.value) and a.value > a.limit > 0)
    if unmet:
        return PENALTY + unmet + (excess / (1.0 + excess) if graded else 0.0)
    certs = list(certificates.values())
    if objective == "E_max":
        return max(c.E_max for c in certs)
    if objective == "E_max-then-voltage":
        if e_max_cap is None:
            raise ParameterError("the objective E_max-then-voltage scores a point against a cap on E_max: none given")
        worst = max(c.E_max for c in certs)
        if worst > e_max_cap:
            return PENALTY + (1.0 - e_max_cap / worst)
        return max(c.voltage_max for c in certs)
    if objective == "voltage":
        return max(c.voltage_max for c in certs)
    return -min(_margin(c) for c in certs)


def binding_of(certificates: Mapping[str, Any]) -> str:
    """The first assumption unmet (or the reason there is no bound) over the paths, '' where all certify."""
    for path, cert in certificates.items():
        if cert is None:
            return f"the law states no claim on {path}"
        if not cert.certified:
            unmet = cert.unmet
            return f"the assumption {unmet[0]!r}" if unmet else f"no bound ({cert.reason or 'none derived'})"
    return ""


#: computed torque's start (omega_n 1/s, zeta, sign width w rad/s): critical damping at omega_r 20 (K_P 100, K_D 20),
#: the certified preset's gains until 2026-11-28, kept so that the designs found stay those of before
START_POINT = (10.0, 1.0, 0.01)


def _preset_point(scorer: _Scorer, bounds: list[tuple[float, float]]) -> list[float] | None:
    """The start point, :data:`START_POINT` (the cart's own tau_f beside it) where it is in bounds; for sliding
    mode the law's defaults with the narrowest width (module docstring)."""
    if scorer.law_parameters:
        own = scorer.law_parameters
        x = [math.log(float(scorer.law_defaults[n])) for n in own] + [bounds[len(own)][0]]
    else:
        omega_n, zeta, width = START_POINT
        x = [math.log(omega_n), zeta, math.log10(width)]
    if scorer.filtered:
        x.append(math.log(scorer.template.sensing.filter_tau))
    return x if all(lo <= v <= hi for v, (lo, hi) in zip(x, bounds)) else None


def search_design(problem: DesignProblem) -> DesignResult:
    """The design of ``problem`` (:class:`DesignResult`): the best point over the periods, its certificates
    computed again by ``resolve_run`` (what ``run`` computes for it).

    Raises:
        ParameterError: an unknown objective or method, a period list that is not accepted.
    """
    if problem.objective not in OBJECTIVES:
        raise ParameterError(f"--objective {problem.objective!r} is not accepted; one of {', '.join(OBJECTIVES)}")
    if problem.method not in METHODS:
        raise ParameterError(f"--method {problem.method!r} is not accepted; one of {', '.join(METHODS)}")
    base = coerced(problem.base)  # a base given directly: typed once, here (its path the cart's where it names none)
    problem = dataclasses.replace(problem, base=base, paths=problem.paths or (base.path,))
    periods = check_periods(problem.periods, problem.base.duration)
    _check_law(problem.base.controller)
    best: tuple[float, Any] | None = None
    firsts = []  # each period's scorer and best (score, point) of the first search
    for period in periods:
        scorer = _Scorer(problem, period)
        value, x = _search(scorer, scorer.bounds(period), problem)
        firsts.append((scorer, value, x))
        if best is None or value < best[0]:
            best = (value, scorer.config(x))
    assert best is not None
    cap = None
    if problem.objective == "E_max-then-voltage" and best[0] < PENALTY:  # the second search: the supply
        cap = (1.0 + E_MAX_SLACK) * best[0]
        best = None
        for (scorer, _, x), period in zip(firsts, periods):
            scorer.objective, scorer.e_max_cap = problem.objective, cap
            value, x = _search(scorer, scorer.bounds(period), problem, start=list(x))
            if best is None or value < best[0]:
                best = (value, scorer.config(x))
        assert best is not None
    evaluations = sum(scorer.evaluations for scorer, _, _ in firsts)
    return _finish(problem, best[1], best[0], evaluations, periods, e_max_cap=cap)


def _optimiser(scorer: _Scorer, bounds: list[tuple[float, float]], problem: DesignProblem,
               start: list[float] | None = None) -> Optimiser:
    """The optimiser of ``problem.method`` (:mod:`wmr_mj.searches.optimisers`), minimising the score.

    - ``cma``: CMA-ES (``cmaes``, falsify's optimiser: its own seeded generator, bounds kept by resampling),
      started at :data:`START_POINT`, which is scored first, or at the box's centre, with a step of 0.3 of the
      narrowest range; whole generations until ``budget`` points are scored.
    - ``de``: scipy's differential evolution (seeded, one worker, no gradient polish), START_POINT in its
      first population, popsize 10, budget // (10 dimensions) - 1 generations (at least 1), one point at a time.

    ``start``: the point started from in place of START_POINT (E_max-then-voltage's second search: the first's best).
    """
    x0 = _preset_point(scorer, bounds) if start is None else start
    if problem.method == "de":
        popsize = 10
        maxiter = max(1, problem.budget // (popsize * len(bounds)) - 1)
        return DifferentialEvolution(bounds, seed=problem.seed, popsize=popsize, maxiter=maxiter, polish=False,
                                     updating="immediate", workers=1, tol=0.0, init="sobol", x0=x0)
    box = np.array(bounds, dtype=float)
    mean = np.array(x0) if x0 is not None else box.mean(axis=1)
    return Chain(Points(mean), CMAES(mean=mean, sigma=0.3 * float(np.min(box[:, 1] - box[:, 0])), bounds=box,
                                     seed=problem.seed))


def _search(scorer: _Scorer, bounds: list[tuple[float, float]], problem: DesignProblem,
            start: list[float] | None = None) -> tuple[float, Any]:
    """The best (score, point) of one period's search (:func:`_optimiser`, driven by the one loop
    :func:`wmr_mj.searches.optimisers.drive`): differential evolution's own result; CMA-ES's first point of the
    smallest score."""
    optimiser = _optimiser(scorer, bounds, problem, start)
    budget = problem.budget if problem.method == "cma" else None
    trace = drive(optimiser, lambda points: [scorer(x) for x in points], budget=budget)
    if isinstance(optimiser, DifferentialEvolution):
        return float(optimiser.result.fun), optimiser.result.x
    best = 0
    for i, value in enumerate(trace.values):  # the first of the smallest, as scored in order
        if value < trace.values[best]:
            best = i
    return float(trace.values[best]), trace.points[best]


def evaluate_design(config: Any, paths: Sequence[str]) -> dict[str, Any]:
    """Each path's certificate of ``config`` as ``wmr-mj run`` computes it (``resolve_run(...).claim``)."""
    return {path: parts.claim for path, parts in _resolved(config, paths).items()}


def _resolved(config: Any, paths: Sequence[str]) -> dict[str, Any]:
    """Each path's :class:`~wmr_mj.sim.parts.RunParts` of ``config``, as ``wmr-mj run`` resolves it."""
    return {path: resolve_run(dataclasses.replace(config, path=path)) for path in paths}


def _finish(problem: DesignProblem, config: Any, found: float, evaluations: int,
            periods: tuple[float, ...], *, e_max_cap: float | None = None) -> DesignResult:
    resolved = _resolved(config, problem.paths)
    certificates = {path: parts.claim for path, parts in resolved.items()}
    law = type(next(iter(resolved.values())).controller)
    value = score(certificates, problem.objective, graded=law.design_graded, e_max_cap=e_max_cap)
    if value != found:  # the search's certificate is the run's: a difference is a bug, never rounded away
        raise RuntimeError(f"design: the search scored {found!r} but the run's certificate gives {value!r}")
    settings = {name: getattr(config, name) for name in DESIGN_FIELDS}
    bounds = config.reference_bounds
    box = {"m1_range": list(config.m1_range), "box_ranges": {k: list(v) for k, v in config.box_ranges.items()},
           "box": config.box, "reference_bounds": None if bounds is None else bounds.to_dict(),
           "duration": config.duration}
    return DesignResult(box=box, settings=settings, certified=value < PENALTY, score=value, certificates=certificates,
                        binding=binding_of(certificates), evaluations=evaluations, objective=problem.objective,
                        seed=problem.seed, periods=periods, paths=problem.paths, cart=config.cart,
                        law_parameters=law.design_parameters)


def design_lines(result: DesignResult) -> list[str]:
    """The design in a few lines: the law's parameters, then each path's certificate (or what binds)."""
    s = result.settings
    if result.law_parameters:  # the law's own parameters (controller_params), not the run's gains
        law = s["controller"].replace("-", " ") + " " + ", ".join(
            f"{k} = {number(v)}" for k, v in s["controller_params"].items() if isinstance(v, float))
    else:
        law = f"computed torque K_P = {number(s['kp'], '1/s^2')}, K_D = {number(s['kd'], '1/s')}, " \
              f"sign width {number(s['friction_width'], 'rad/s')}"
    lines = [f"{law}, period {number(s['control_period'] * 1e3, 'ms')} ({result.objective}, seed {result.seed}, "
             f"{result.evaluations} certificates)"]
    if not result.certified:
        lines.append(f"{result.binding} binds at the best point found")
    for path, cert in result.certificates.items():
        if cert is not None and cert.valid:
            lines.append(f"{path}: E_max {number(cert.E_max, 'rad')}, {number(cert.voltage_max, 'V')} "
                         f"({certificate_name(cert)}{'' if cert.certified else ', not certified'})")
    return lines


def _certificate_dict(cert: Any) -> dict[str, Any] | None:
    return None if cert is None else DesignCertificate.of(cert).to_dict()


def design_dict(result: DesignResult) -> dict[str, Any]:
    """The design file's content: the settings (the cart's parts as their spec mappings), the certificate of
    each path, the search."""
    s = dict(result.settings)
    if result.law_parameters:  # its parameters are the law's own (--controller-param), kp/kd unused
        params = dict(s["controller_params"])
        settings = {"controller": s["controller"], "model": s["model"], "kp": None, "kd": None,
                    "friction_sign": params.pop("friction_sign"), "friction_width": params.pop("friction_width"),
                    "controller_params": params, "control_period": s["control_period"]}
    else:
        settings = {k: s[k] for k in ("controller", "model", "kp", "kd", "friction_sign", "friction_width",
                                      "control_period")}
    settings.update(sensing=s["sensing"].to_dict(), actuation=s["actuation"].to_dict(),
                    backlash=s["transmission"].backlash)
    return {"format": FORMAT, "version": 1, "settings": settings, "certified": result.certified,
            "E_max": result.E_max if math.isfinite(result.E_max) else None, "binding": result.binding,
            "certificates": {p: _certificate_dict(c) for p, c in result.certificates.items()},
            "box": result.box, "search": {"objective": result.objective, "score": result.score, "seed": result.seed,
                       "periods": list(result.periods), "paths": list(result.paths),
                       "evaluations": result.evaluations},
            # the cart searched on (name, version, path, the file's text: design_cart finds it again; a cart
            # identified from recordings: identified_from, each file and its SHA-256); a C80 design's file has no
            # "cart" key, as a C80 config's record has none
            **({} if result.cart is None else {"cart": _cart_entry(result.cart)})}


def _cart_entry(record: Mapping[str, Any]) -> dict[str, Any]:
    """The design file's record of its cart: the config's record, with the recordings the cart file rests on
    (``identified_from``: [{"file", "sha256"}], where its sources name any: wmr-mj identify --data)."""
    named = identified_from(str(record.get("text", "")))
    data = [{"file": name, "sha256": sha} for name, sha in named]
    return {**record, **({"identified_from": data} if data else {})}


def write_design(result: DesignResult, path: str | os.PathLike) -> None:
    """Write the design file (JSON; floats at full precision, so ``run --design`` reads the same numbers)."""
    write_json_atomic(path, design_dict(result))


def read_design(path: str | os.PathLike) -> dict[str, Any]:
    """The design file's content.

    Raises:
        ParameterError: a file that cannot be read or is not a design file (one line naming it).
    """
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError) as exc:
        raise ParameterError(f"--design {os.fspath(path)!r} cannot be read as a design file: {exc}") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT or not isinstance(data.get("settings"), dict):
        raise ParameterError(f"--design {os.fspath(path)!r} is not a design file (one written by `wmr-mj design "
                             "--out FILE`)")
    return data


def design_file_settings(path: str | os.PathLike, data: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The settings of a design file, as the run options spell them (controller, model, kp, kd, friction_sign,
    friction_width, control_period, sensing, actuation, backlash, and a sliding-mode design's controller_param):
    ``run --design FILE`` fills each option not given explicitly from them, as a preset does. ``data``: the file's
    content where it was read already (:func:`read_design`)."""
    settings = (read_design(path) if data is None else data)["settings"]
    out = {k: settings.get(k) for k in ("controller", "model", "kp", "kd", "friction_sign", "friction_width",
                                        "control_period", "sensing", "actuation", "backlash")}
    if settings.get("controller_params"):
        out["controller_param"] = dict(settings["controller_params"])
    return out


def design_file_box(path: str | os.PathLike, data: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """What the design of file ``path`` was found on besides its settings: ``m1_range`` (kg, the m1 box its
    certificates were computed for), ``box_ranges`` (the other ranged parameters), ``reference_bounds`` (None:
    the run's own) and ``path`` (the first path it was certified on). A run of the design judges against these
    unless an option overrides one. A key the file lacks (a file written before it was recorded) is left out."""
    data = read_design(path) if data is None else data
    box, search = data.get("box") or {}, data.get("search") or {}
    out: dict[str, Any] = {}
    if isinstance(box.get("m1_range"), list) and len(box["m1_range"]) == 2:
        out["m1_range"] = (float(box["m1_range"][0]), float(box["m1_range"][1]))
    if isinstance(box.get("box_ranges"), Mapping):
        out["box_ranges"] = {k: (float(v[0]), float(v[1])) for k, v in box["box_ranges"].items()}
    if box.get("reference_bounds") is not None:
        out["reference_bounds"] = dict(box["reference_bounds"])
    if search.get("paths"):
        first = str(search["paths"][0])
        beside = os.path.join(os.path.dirname(os.fspath(path)), first)  # a route file found where the design is
        if first.lower().endswith((".toml", ".json")) and not os.path.isfile(first) and os.path.isfile(beside):
            first = beside
        out["path"] = first
    return out


def design_cart_name(path: str | os.PathLike, data: Mapping[str, Any] | None = None) -> str:
    """The cart the design of file ``path`` was found on, as its outputs name it ('C80' where it records none)."""
    recorded = (read_design(path) if data is None else data).get("cart")
    if not isinstance(recorded, Mapping):
        return "C80"
    return f"{recorded.get('name')} {recorded.get('version', '')}".strip()



def design_cart(path: str | os.PathLike, given: Any = None, *, data: Mapping[str, Any] | None = None) -> Any:
    """The cart a run of the design file ``path`` is on: ``given`` where a cart is named (an explicit --cart
    overrides the file, as every explicit option does); else the cart the design was found on, which the file
    records (``wmr-mj design --cart``): the file the record names, found where it was, beside the design file, or
    among the shipped carts, holding the very text the design was found on. A design found on the C80 records
    none: None.

    Without this a design found on another cart would run on the C80 with that cart's gains, and its certificate
    would silently be another cart's.

    ``data``: the file's content where it was read already (:func:`read_design`).

    Raises:
        ParameterError: the design's cart file is nowhere to be found with the text it had (moved or changed): one
            line naming it and what is accepted.
    """
    from pathlib import Path

    recorded = (read_design(path) if data is None else data).get("cart")
    if given is not None or not isinstance(recorded, Mapping):
        return given
    where = Path(str(recorded.get("path", "")))
    candidates = [where, Path(path).parent / where.name, *(cart_path(name) for name in cart_names())]
    for candidate in candidates:
        try:
            if candidate.is_file() and candidate.read_text(encoding="utf-8") == recorded.get("text"):
                return str(candidate)
        except OSError:
            continue
    raise ParameterError(f"--design {os.fspath(path)!r} was found on cart {recorded.get('name')!r} "
                         f"{recorded.get('version', '')} ({where}), which is no longer there with the same text; "
                         "give --cart FILE (the cart to run it on; --cart c80 for the C80)")
