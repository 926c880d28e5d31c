"""One yardstick for every controller: each design runs every scenario of a versioned suite, then the same
adversary falsifies each at the same budget and seed (``wmr-mj compare``).

A design is named by one token (:func:`design_from_token`): a preset (``paper``, ``certified``), a
built-in law, ``FILE.py:Class`` or ``module:Class``, with ``,key=value`` settings: RunConfig fields
(``tracker=pure-pursuit``, ``model=...``, ``kp=...``, ``correction=true``) or the law's parameters
(``lam=5``). A law's name means the law with its own defaults, as ``wmr-mj run --controller NAME`` and
``RunConfig(controller=NAME)`` mean it (:func:`wmr_mj.sim.designs.design_changes`): ``computed-torque`` is the
paper's design (the ``paper`` preset: paper model, K_P = 6, K_D = 9), ``sliding-mode`` runs on the non-holonomic
model, its default estimate, under which its claim can hold. ``certified`` is the certified design. A token
ending in ``.json`` is a design file (:func:`is_design_file`: the file ``wmr-mj design --out FILE.json`` writes),
read as ``wmr-mj run --design FILE`` reads it (:func:`design_file_changes`): its law, gains, period and cart.
Every design declares the suite's uncertainty box, so a claim covers the plants the suite runs.

Usage::

    from wmr_mj.experiments.compare import compare, design_from_token
    from wmr_mj.experiments.suite import load_suite
    suite = load_suite("standard-v1")
    designs = [design_from_token(t, suite) for t in ("paper", "certified", "sliding-mode")]
    result = compare(designs, suite, scenarios=["circle/*"], budget=32, seed=0)
    result.rows[1].requirements_passed, result.rows[1].tightness
"""

from __future__ import annotations

import concurrent.futures
import json
import math
import re
import threading
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from wmr_mj._util.checks import runs_of
from wmr_mj._util.deprecation import deprecated_names
from wmr_mj.analysis.requirements import parse_requirement
from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE, count_unmet, unmet_assumptions
from wmr_mj.errors import InfeasiblePathError, ParameterError
from wmr_mj.experiments.suite import Scenario, Suite, load_suite, versions
from wmr_mj.hardware import Actuation, Sensing, Transmission, cart_dict
from wmr_mj.params import uncertainty_ranges
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.reference.knots import KnotSpace
from wmr_mj.reference.named import PATH_OPTION_HINT
from wmr_mj.searches.design_search import design_file_settings, read_design
from wmr_mj.searches.falsify import FalsifySpec, check_runnable, falsify
from wmr_mj.sim import notebook
from wmr_mj.sim.batch import thread_count
from wmr_mj.sim.closed_loop import judge_requirements, run_closed_loop
from wmr_mj.sim.config import (
    RunConfig,
    cart_file,
    coerce,
    config_from_dict,
    controller_for,
    controller_name,
    controller_source,
    estimate_parameters,
)
from wmr_mj.sim.designs import design_changes, on_cart
from wmr_mj.sim.many_runs import connect
from wmr_mj.sim.parts import resolve_run
from wmr_mj.sim.records import Record, plain
from wmr_mj.sim.spec import LawChoice, law_fields

__all__ = ["Design", "design_from_token", "is_design_file", "design_file_changes", "design_token_changes",
           "FileDesign", "ScenarioRun", "DesignRow", "CompareResult", "compare",
           "run_scenario", "adversary_spec", "adversary_cart_box", "ADVERSARY_CART_AXES"]


@dataclass(frozen=True)
class Design:
    """A design to compare: its ``label`` (the token as given) and its base RunConfig."""

    label: str
    config: RunConfig


def design_from_token(token: str, suite: Suite, *, cart: Mapping[str, Any] | None = None,
                      m1_range: tuple[float, float] | None = None, path: str | None = None) -> Design:
    """A design from ``NAME[,key=value...]`` (:func:`wmr_mj.sim.designs.design_changes`) or a design file
    ``FILE.json`` (:func:`design_file_changes`), declaring the suite's uncertainty box and running the suite's
    duration.

    Args:
        token: the design as named.
        suite: the suite it runs.
        cart: RunConfig's sensing, actuation, transmission for this design (``wmr-mj compare --sensing``, ...;
            each overrides the token's own setting of it): its runs and its adversary's run on that cart,
            but for a scenario that names its own; and ``cart`` (``compare --cart``): the cart file, whose box
            the design declares and on which the certified design's gains are derived.
        m1_range: the m1 box [kg] the design declares (a design file's own, ``wmr-mj compare``); None: the box of
            the suite's uncertainty on the cart.
        path: the design's own path (a design file's, ``wmr-mj compare``): a scenario (or the adversary) that
            names no path runs on it, one that names its own runs that; None: the cart's own
            (:func:`wmr_mj.reference.named.default_path`, the paper circle on the C80).

    Raises:
        UnknownNameError, ParameterError: an unknown preset or law, a bad setting (one line each).
    """
    box = uncertainty_ranges(suite.adversary.uncertainty)
    on = (cart or {}).get("cart")  # a cart file (compare --cart): its box, the certified gains derived on it
    if on is not None:
        box = dict(cart_file(RunConfig(cart=on)).uncertainty.get(suite.adversary.uncertainty, box))
    suite_m1 = box.pop("m1")
    m1_range = suite_m1 if m1_range is None else (float(m1_range[0]), float(m1_range[1]))
    changes = {**design_token_changes(token, cart=on), **(cart or {})}
    changes.setdefault("path", path)  # None: the cart's own
    config = RunConfig.from_inputs(**changes, m1_range=m1_range, box_ranges=box, duration=suite.duration)

    resolve_run(config)  # built once: a parameter the law does not take, a claim() that raises, before any run
    return Design(label=str(token), config=config)


#: the one rule that tells a design file from a design's name: the token ends in this suffix
DESIGN_FILE_SUFFIX = ".json"


def is_design_file(token: str) -> bool:
    """True where ``token`` names a design file: its name (before any ``,key=value``) ends in ``.json``
    (:data:`DESIGN_FILE_SUFFIX`); no preset, law, ``FILE.py:Class`` nor ``module:Class`` does."""
    return str(token).partition(",")[0].strip().lower().endswith(DESIGN_FILE_SUFFIX)


def design_file_changes(path: str, *, cart: Any = None) -> dict[str, Any]:
    """The RunConfig fields a design file sets, as ``wmr-mj run --design FILE`` sets them: the law's through
    :func:`wmr_mj.sim.spec.law_fields` (the file's controller, model, K_P, K_D, sign and width, none left to a
    preset), its control period, and the parts of its cart (sensing, actuation, backlash) as typed parts.

    Args:
        path: the design file (``wmr-mj design --out FILE.json``).
        cart: the cart file the law is built on (``RunConfig.cart``; None: the C80); the file's gains are kept.

    Raises:
        ParameterError: a file that cannot be read or is not a design file, a setting a run refuses, a design
            found on another cart where ``cart`` is None (one line naming the file).
    """
    try:
        data = read_design(path)
    except ParameterError as exc:  # read_design names the run option; here the file is a design's name
        raise ParameterError(str(exc).replace("--design ", "design ", 1)) from None
    s, found_on = design_file_settings(path, data), data.get("cart")
    if cart is None and isinstance(found_on, dict):  # every design here runs on the command's one cart
        raise ParameterError(f"design {str(path)!r} was found on cart {found_on.get('name')!r} "
                             f"({found_on.get('path')}); give --cart FILE to run every design on that cart (the "
                             "C80 is the default)")
    law = law_fields(LawChoice(cart=cart, controller=s["controller"], model=s["model"], kp=s["kp"], kd=s["kd"],
                               friction_sign=s["friction_sign"], friction_width=s["friction_width"],
                               controller_params=s.get("controller_param") or {}))
    law = {k: v for k, v in law.items() if v or k not in ("controller_params", "identified", "coefficients")}
    out = {**law, "control_period": s["control_period"]}
    parts: dict[str, tuple[Any, str]] = {"sensing": (Sensing, "sensing"), "actuation": (Actuation, "actuation"),
                                         "transmission": (Transmission, "backlash")}
    for name, (cls, key) in parts.items():
        if s.get(key) is not None:
            try:
                out[name] = cls.from_spec(s[key])
            except (ParameterError, ValueError, TypeError) as exc:
                raise ParameterError(f"design {str(path)!r}: its {key} is not accepted: {exc}") from None
    return out


def design_token_changes(token: str, *, cart: Any = None) -> dict[str, Any]:
    """The RunConfig fields of the design ``token`` names: a design file's (:func:`design_file_changes`, where
    :func:`is_design_file`), else the preset's or law's (:func:`wmr_mj.sim.designs.design_changes`), the
    certified design's gains derived on ``cart`` (:func:`wmr_mj.sim.designs.on_cart`).

    Raises:
        UnknownNameError, ParameterError: an unknown preset or law, a bad setting, a bad design file (one line).
    """
    if is_design_file(token):
        if "," in str(token):
            raise ParameterError(f"design {token!r}: a design file takes no ,key=value settings (the file is the "
                                 "design); give the file alone")
        return design_file_changes(str(token).strip(), cart=cart)
    return on_cart(design_changes(token), cart)


@dataclass(frozen=True)
class FileDesign:
    """A design file named as a design (``validate --design FILE.json``), shaped as
    :class:`wmr_mj.sim.designs.DesignLike` for validate's rungs; ``cart``: the cart file the law is built on."""

    path: str
    cart: Any = None

    @property
    def name(self) -> str:
        from pathlib import Path

        return re.sub(r"[^A-Za-z0-9_.-]+", "-", Path(self.path).stem).strip("-")[:60] or "design"

    @property
    def label(self) -> str:
        return self.path

    def config_changes(self) -> dict[str, Any]:
        return design_file_changes(self.path, cart=self.cart)

    def describe(self) -> str:
        return (f"{controller_for(RunConfig(**self.config_changes()), estimate_parameters()).label()} "
                f"(the design file {self.path})")


@dataclass(frozen=True)
class ScenarioRun(Record):
    """One design on one scenario: the run's summary (JSON), what the requirements gave, the effort (its JSON,
    ``to_dict``, is a line of runs.jsonl)."""

    design: str
    scenario: str
    summary: Mapping[str, Any]
    requirements: Mapping[str, Mapping[str, Any]]  # name -> robustness, satisfied, normalised (robustness/threshold)
    rms_voltage: float  # [V] of the applied voltage
    tv_voltage: float  # [V/s] total variation of the applied voltage per second: chattering
    cpu_us_per_step: float  # [us] CPU time of the run's loop per control step
    law: str  # compiled or python

    @property
    def verdict(self) -> str | None:
        return self.summary.get("verdict")


def _threshold(text: str) -> float | None:
    """The number an ``abs(x) <= c`` requirement bounds by (for the robustness in units of it)."""
    m = re.search(r"<=\s*([0-9.eE+-]+)\s*\)", text)
    return float(m.group(1)) if m else None


def run_scenario(config: RunConfig, requirements: Mapping[str, str], *, parsed: Sequence[Any] | None = None,
                 monitor: threading.Lock | None = None) -> dict[str, Any]:
    """One run of ``config`` judged by ``requirements`` (name -> STL): plain data (a Dask task's result).

    ``parsed``: the requirements already parsed (rtamt imports on the calling thread: two threads importing
    it at once deadlock); ``monitor``: a lock around rtamt's monitor (pure Python, process-wide logging).
    """
    period = TIMESTEP if config.control_period is None else config.control_period
    if parsed is None:
        parsed = [parse_requirement(text, period=period) for text in requirements.values()]
    result = run_closed_loop(config, progress=False)
    summary = result.summary.to_dict()
    judged = judge_requirements(result, parsed, period=period, monitor=monitor)
    reqs = {}
    for (name, text), r in zip(requirements.items(), judged):
        c = _threshold(text)
        rob = r.robustness
        reqs[name] = {"robustness": rob, "satisfied": r.satisfied,
                      "normalised": None if rob is None or not c else rob / c}
    u = np.asarray(result.rows["voltage"], float)
    duration = len(u) * period
    return {"summary": _slim(summary), "requirements": reqs,
            "rms_voltage": float(np.sqrt(np.mean(u * u))) if u.size else math.nan,
            "tv_voltage": float(np.sum(np.abs(np.diff(u))) / duration) if u.size > 1 else 0.0,
            "cpu_us_per_step": 1e6 * float(result.cpu_s or 0.0) / max(1, len(u)), "law": result.law}


def _slim(summary: Mapping[str, Any]) -> dict[str, Any]:
    """The summary's keys the comparison reads (the full summaries stay in runs.json)."""
    keys = ("status", "controller", "m1", "path", "sup_E", "sup_Edot", "verdict", "failure", "control_steps", "steps",
            "left_steering_range", "saturated_fraction", "wall_s")
    out = {k: summary.get(k) for k in keys}
    cert = summary.get("certificate") or {}
    slim: dict[str, Any] = {k: cert.get(k) for k in ("E_max", "Edot_max", "E_ratio", "valid", "certified", "unmet")}
    slim["unmet_assumptions"] = unmet_assumptions(cert)  # why, beside the verdict: value and limit
    out["certificate"] = slim
    pe = summary.get("path_error") or {}
    out["cross_track_max"] = pe.get("cross_track_max")
    return out


#: what changes a scenario's path that a cart cannot steer: compare has no --path (the suite names the paths)
SCENARIO_PATH_HINT = ("the suite names the scenario's path, not an option: --scenarios leaves the scenario out, and a "
                      "scenario of a suite of your own that names no path runs each design on its own (its cart's "
                      "[paths] default, a design file's path)")


def _scenario_refused(scenario: Scenario, exc: InfeasiblePathError) -> InfeasiblePathError:
    """``exc`` (a scenario's path the cart cannot steer) as one line naming the scenario and what changes it."""
    return type(exc)(f"scenario {scenario.id!r}: {str(exc).replace(PATH_OPTION_HINT, SCENARIO_PATH_HINT)}")


def _scenario_task(config_dict: Mapping[str, Any], requirements: Mapping[str, str]) -> dict[str, Any]:
    """A Dask task: plain data in, plain data out."""
    return run_scenario(config_from_dict(config_dict), requirements)


#: the cart's axes the adversary searches where a compared scenario's cart has them: each zero on an ideal cart,
#: so that [0, the largest a scenario declares] holds the ideal cart and every scenario's value. An encoder's
#: resolution is not among them: its shaft and velocity estimate are the scenario's, not one axis; nor is noise
#: (no suite's hardware declares any, and its kind is the scenario's too).
ADVERSARY_CART_AXES = {"sensing.delay": ("sensing", "delay"), "actuation.delay": ("actuation", "delay"),
                       "actuation.inductance": ("actuation", "inductance"),
                       "transmission.backlash": ("transmission", "backlash")}


def adversary_cart_box(base: RunConfig, scenarios: Sequence[Any]) -> dict[str, tuple[float, float]]:
    """The cart's axes of the adversary's box: each of :data:`ADVERSARY_CART_AXES` that a scenario's cart (one
    that names hardware, ``[hardware.<name>]``) sets above zero, over [0, the largest such value, or the
    design's own where larger]; none where no scenario names a non-ideal cart (the box is the plant's).

    Args:
        base: the adversary's base run (the design's cart).
        scenarios: the compared scenarios (:meth:`wmr_mj.experiments.suite.Suite.select`).
    """
    box: dict[str, tuple[float, float]] = {}
    for axis, (part, key) in ADVERSARY_CART_AXES.items():
        declared = [float(getattr(getattr(s, part), key)) for s in scenarios
                    if s.hardware is not None and getattr(s, part) is not None]
        top = max(declared, default=0.0)
        if top > 0.0:
            box[axis] = (0.0, max(top, float(getattr(getattr(base, part), key))))
    return box


def adversary_spec(design: Design, suite: Suite, *, budget: int, seed: int, method: str | None = None,
                   scenarios: Sequence[Any] = ()):
    """The FalsifySpec of the suite's adversary for ``design``: its plant box, C's knot path within the declared
    bounds and a disturbance pulse (start, amplitude within +-d_max), against the suite's requirement; and the
    cart's axes where a compared scenario (``scenarios``) declares a non-ideal cart (:func:`adversary_cart_box`)."""
    adv = suite.adversary
    width = adv.pulse_width
    t1 = adv.pulse_t1[0]
    signals = {"disturbance": {"kind": "pulse", "amplitude": adv.pulse_amplitude[1], "t1": t1, "t2": t1 + width},
               "d_max": suite.d_max}
    path = design.config.path if adv.path is None else adv.path  # none named: the design's own
    base = coerce(design.config.replace(path=path, signals=signals, reference_bounds=suite.reference_bounds))
    box: dict[str, tuple[float, float]] = {"m1": (float(base.m1_range[0]), float(base.m1_range[1])),
                                           **{k: (float(v[0]), float(v[1])) for k, v in base.box_ranges.items()}}
    if adv.path_knots:
        box.update(KnotSpace(adv.path_knots, hold_range=adv.hold_range).ranges(base.reference_bounds))
    box.update({"disturbance.t1": adv.pulse_t1, "disturbance.amplitude": adv.pulse_amplitude})
    box.update(adversary_cart_box(base, scenarios))  # searched, each run's claim covering its own cart
    kwargs: dict[str, Any] = {} if method is None else {"method": method}
    return FalsifySpec(base=base, box=box, objective="requirement", budget=budget, seed=seed,
                       requirement=suite.requirements[adv.requirement], **kwargs)


@dataclass(frozen=True)
class DesignRow(Record):
    """A design's line of the comparison (every figure over the suite's scenarios, then the adversary's)."""

    label: str
    controller: str
    tracker: str | None
    runs: int
    requirements_passed: int
    requirements_total: int
    least_normalised: float | None  # the least robustness / threshold over every requirement and scenario
    least_at: str  # "requirement @ scenario"
    certified_inside: int
    certified_outside: int
    uncertified: int
    no_claim: int
    failed: int
    claim_E_max: float | None  # [rad] the claim's bound on the adversary's base (None: no claim or no bound)
    adversary_worst: float | None  # the worst objective found (-robustness of the requirement; > 0 falsified)
    adversary_falsified: bool
    adversary_runs_to_falsify: int | None
    adversary_where: Mapping[str, float]
    adversary_worst_sup_E: float | None  # [rad]
    random_worst: float | None  # the random sample's worst objective at the same budget
    random_runs_to_falsify: int | None  # the random sample's first run that falsified (None: none did)
    tightness: float | None  # worst sup|E| found (certified runs of the adversary) / claim_E_max
    rms_voltage: float  # [V] mean over scenarios
    tv_voltage: float  # [V/s] mean over scenarios
    cross_track_max: float | None  # [m] worst over scenarios
    cpu_us_per_step: float  # [us] median over scenarios
    law: str
    # where the law comes from, as its log records it (controllers.registry.PluginSource.to_dict: file or
    # module, class, parameters, source SHA-256); None for the laws built from RunConfig fields
    controller_source: Mapping[str, Any] | None = None
    # the run that breaks the law's claim most (a certified-outside run of a scenario or of the adversary,
    # of the largest sup|E|/E_max): {where, scenario, params, sup_E [rad], E_max [rad], ratio, count}; None: none
    claim_broken: Mapping[str, Any] | None = None
    # the claim's assumptions not met over the scenarios: {name, value, limit, runs} (value and limit of the first)
    unmet: tuple[Mapping[str, Any], ...] = ()
    # the design's cart where not ideal (wmr_mj.hardware.cart_dict: sensing, actuation, transmission in spec
    # form); a scenario that names its own cart runs with that one. {}: ideal (to_dict then has no "cart")
    cart: Mapping[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The row's JSON (compare.json's ``rows``): every field, in order (:meth:`from_dict` reads it back)."""
        out = super().to_dict()
        if not self.cart:
            del out["cart"]  # a comparison on the ideal cart keeps the keys it always had
        return out



@dataclass(frozen=True)
class CompareResult:
    """A comparison's one result (:func:`compare`): one row per design, every scenario run, the suite and the
    versions, read by attribute.

    :meth:`to_dict` is its JSON with every scenario run (``runs``), which :meth:`from_dict` reads back; with
    ``runs=False`` it is compare.json's object (``wmr-mj compare --json`` without its files).
    """

    suite: Suite
    scenarios: tuple[Scenario, ...]
    rows: tuple[DesignRow, ...]
    runs: tuple[ScenarioRun, ...]
    budget: int
    seed: int
    versions: Mapping[str, str] = field(default_factory=dict)
    wall_s: float = 0.0
    steps: int = 0  # physics steps simulated: every scenario run's and every adversary run's

    @property
    def steps_per_s(self) -> float | None:
        """Physics steps per second of wall time, the whole comparison (runs, judging, the adversary)."""
        return self.steps / self.wall_s if self.wall_s > 0 else None

    @property
    def claims_broken(self) -> list[str]:
        """The designs one of whose runs (a scenario's or the adversary's) breaks its claim, in order."""
        return [r.label for r in self.rows if r.claim_broken is not None]

    def _record(self) -> _CompareRecord:
        """compare.json's object, typed (the suite as its JSON, scenarios by id)."""
        return _CompareRecord(suite=self.suite.to_dict(), versions=dict(self.versions), budget=self.budget,
                              seed=self.seed, scenarios=tuple(s.id for s in self.scenarios), rows=self.rows,
                              claims_broken=tuple(self.claims_broken), wall_s=self.wall_s, steps=self.steps)

    def report(self) -> _CompareRecord:
        """Deprecated (kept one release): the result answers each of these by attribute, and
        ``to_dict(runs=False)`` is their JSON."""
        warnings.warn("CompareResult.report() is deprecated: read the result by attribute (result.rows, "
                      "result.claims_broken); result.to_dict(runs=False) is compare.json's object",
                      DeprecationWarning, stacklevel=2)
        return self._record()

    def to_dict(self, *, runs: bool = True) -> dict[str, Any]:
        """The comparison's JSON: compare.json's keys (the suite, the versions, the adversary's budget and seed,
        the scenario ids, each design's row, the claims broken, wall time and steps), then, with ``runs``,
        ``runs``: the suite's file (``suite_source``) and every scenario run (``ScenarioRun.to_dict``), which
        :meth:`from_dict` reads back.

        Args:
            runs: add ``runs``; False: compare.json's object exactly.
        """
        out = self._record().to_dict()
        if runs:
            out["runs"] = {"suite_source": self.suite.source, "scenarios": [r.to_dict() for r in self.runs]}
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> CompareResult:
        """The result of its JSON ``d`` (:meth:`to_dict`, with its ``runs``): the suite read again from its file
        and checked against the SHA-256 the JSON records, the scenarios by id, the rows and the runs.

        Raises:
            ParameterError: ``d`` has no ``runs`` (compare.json), or the suite's file has changed: one line.
        """
        runs = runs_of(d, result="CompareResult", holds="compare.json and compare --json hold the rows only")
        suite = load_suite(runs["suite_source"])
        if suite.sha256 != d["suite"]["sha256"]:
            raise ParameterError(f"suite {runs['suite_source']!r} has changed since the comparison (SHA-256 "
                                 f"{suite.sha256[:12]}..., the comparison's {str(d['suite']['sha256'])[:12]}...)")
        record = _CompareRecord.from_dict(d)
        return cls(suite=suite, scenarios=tuple(suite.scenario(i) for i in record.scenarios), rows=record.rows,
                   runs=tuple(ScenarioRun.from_dict(r) for r in runs["scenarios"]), budget=record.budget,
                   seed=record.seed, versions=dict(record.versions), wall_s=record.wall_s, steps=record.steps)


    # -- in a notebook (wmr_mj.sim.notebook): one row per design and scenario, the table's figure, a few lines
    def to_pandas(self) -> Any:
        """One row per design and scenario, plain columns (no mapping in a cell): the run's verdict, sup|E|,
        the certificate's E_max, each requirement's robustness and whether it held, effort and C's path;
        then the design's adversary (the same on each of its rows).

        Raises:
            WmrMjError: pandas is not installed (``pip install 'wmr-mj[notebook]'``).
        """
        return notebook.compare_frame(self.runs, self.rows)

    def plot(self, **options: Any) -> Any:
        """The comparison's figure (compare.png: the requirement checks held, effort against C's path), as a
        :class:`wmr_mj.figures.results.ResultPlot`."""
        from wmr_mj.figures.results import plot_compare  # matplotlib loads only when a figure is asked for

        return plot_compare(self, **options)

    def _repr_html_(self) -> str:
        return notebook.compare_html(self.rows, self.claims_broken)


@dataclass(frozen=True, kw_only=True)
class _CompareRecord(Record):
    """compare.json's object, typed (:meth:`CompareResult.to_dict` with ``runs=False`` writes it). Not a result of
    its own: :class:`CompareResult` answers each of these by attribute; the deprecated name ``CompareReport``
    still reads an old script's compare.json with :meth:`from_dict`.

    Attributes:
        suite: the suite's JSON (``Suite.to_dict()``).
        versions: the software's.
        budget: the adversary's simulations per design.
        seed: the adversary's seed.
        scenarios: the ids of the scenarios run.
        rows: one per design, in order.
        claims_broken: the designs one of whose runs breaks its claim, in order.
        wall_s: the comparison's wall time [s].
        steps: physics steps simulated.
    """

    _records = {"rows": DesignRow}

    suite: Mapping[str, Any]
    versions: Mapping[str, str]
    budget: int
    seed: int
    scenarios: tuple[str, ...]
    rows: tuple[DesignRow, ...]
    claims_broken: tuple[str, ...]
    wall_s: float
    steps: int


# deprecated alias: keep one release (CompareResult is compare's one result)
__getattr__ = deprecated_names(__name__, {"CompareReport": (
    _CompareRecord, "CompareResult is the comparison's one result (read it by attribute; to_dict(runs=False) is "
    "compare.json's object)")})


def compare(designs: Sequence[Design], suite: Suite, *, scenarios: Sequence[str] = (), budget: int = 32,
            seed: int = 0, nthread: int = 0, scheduler: str | None = None, method: str | None = None,
            progress: Callable[[int, int], None] | None = None) -> CompareResult:
    """Every design on every (selected) scenario, then the adversary on each design.

    Args:
        designs: from :func:`design_from_token`.
        suite: the suite (:func:`wmr_mj.experiments.suite.load_suite`).
        scenarios: shell-style patterns of scenario ids (none: all).
        budget: the adversary's simulations per design (and as many for its random sample); 0: no adversary.
        seed: the adversary's seed, the same for every design.
        nthread: threads for the runs (0: every core); scheduler: a Dask scheduler address instead.
        method: the adversary's search method (None: falsify's default).

    Returns:
        CompareResult: one :class:`DesignRow` per design, in order.

    Raises:
        ParameterError: no design, a budget below one generation (before any run), a design that cannot run.
    """
    if not designs:
        raise ParameterError("compare needs at least one design")
    chosen = suite.select(scenarios)
    specs = ([adversary_spec(d, suite, budget=budget, seed=seed, method=method, scenarios=chosen) for d in designs]
             if budget else [])
    wall0 = time.perf_counter()
    jobs = [(d, s, s.config(d.config)) for d in designs for s in chosen]
    total = len(jobs) + 2 * budget * len(designs)
    done = 0

    def tick(k: int = 1) -> None:
        nonlocal done
        done += k
        if progress is not None:
            progress(done, total)

    results: list[dict[str, Any]]
    if scheduler is not None:
        client = connect(scheduler)
        try:
            futures = [client.submit(_scenario_task, cfg.to_dict(), dict(suite.requirements), pure=False)
                       for _, _, cfg in jobs]
            results = []
            for fut, (_, scenario, _) in zip(futures, jobs):
                try:
                    results.append(fut.result())
                except InfeasiblePathError as exc:
                    raise _scenario_refused(scenario, exc) from None
                tick()
        finally:
            client.close()
    else:
        periods = {TIMESTEP if c.control_period is None else c.control_period for _, _, c in jobs}
        parsed = {p: [parse_requirement(t, period=p) for t in suite.requirements.values()] for p in periods}
        monitor = threading.Lock()

        def one(job: tuple[Design, Scenario, RunConfig]) -> dict[str, Any]:
            _, scenario, cfg = job
            p = TIMESTEP if cfg.control_period is None else cfg.control_period
            try:
                out = run_scenario(cfg, suite.requirements, parsed=parsed[p], monitor=monitor)
            except InfeasiblePathError as exc:
                raise _scenario_refused(scenario, exc) from None
            tick()
            return out

        with concurrent.futures.ThreadPoolExecutor(thread_count(nthread, len(jobs))) as pool:
            results = list(pool.map(one, jobs))
    runs = tuple(ScenarioRun(design=d.label, scenario=s.id, summary=r["summary"], requirements=r["requirements"],
                             rms_voltage=r["rms_voltage"], tv_voltage=r["tv_voltage"],
                             cpu_us_per_step=r["cpu_us_per_step"], law=r["law"])
                 for (d, s, _), r in zip(jobs, results))
    rows = []
    steps = sum(int(r.summary.get("steps") or 0) for r in runs)
    for i, d in enumerate(designs):
        mine = [r for r in runs if r.design == d.label]
        adversary = claim = None
        if specs:
            parts = check_runnable(specs[i].base)  # the adversary's base run, resolved once: its claim is the row's
            claim = parts.claim
            adversary = falsify(specs[i], nthread=nthread, scheduler=scheduler,
                                progress=lambda k, n: None, parts=parts)
            steps += sum(int(e.summary.get("steps") or 0) for e in [*adversary.search, *adversary.random])
            tick(2 * budget)
        rows.append(_row(d, mine, adversary, claim))
    return CompareResult(suite=suite, scenarios=chosen, rows=tuple(rows), runs=runs, budget=budget, seed=seed,
                         versions=versions(), wall_s=time.perf_counter() - wall0, steps=steps)


def _row(design: Design, runs: Sequence[ScenarioRun], adversary: Any, cert: Any) -> DesignRow:
    """A design's line from its scenario runs and the adversary's result (``cert``: the claim of its base run)."""
    passed = total = 0
    least, least_at = None, ""
    for r in runs:
        for name, q in r.requirements.items():
            total += 1
            passed += bool(q["satisfied"])
            n = q["normalised"]
            if n is not None and (least is None or n < least):
                least, least_at = n, f"{name} @ {r.scenario}"
    verdicts = [r.verdict for r in runs]
    cross = [float(r.summary["cross_track_max"]) for r in runs if r.summary.get("cross_track_max") is not None]
    claim_E_max = worst = random_worst = worst_sup_E = tightness = None
    falsified, runs_to, random_runs_to, where = False, None, None, {}
    if adversary is not None:
        if cert is not None and cert.valid:
            claim_E_max = float(cert.E_max)
        evals = list(adversary.search) + list(adversary.random)
        w = adversary.worst
        worst, where, worst_sup_E = w.objective, dict(w.params), w.sup_E
        random_worst = adversary.random_worst.objective
        hits = [e.index + 1 for e in adversary.search if e.objective is not None and e.objective > 0]
        falsified, runs_to = bool(hits), (hits[0] if hits else None)
        random_hits = [e.index + 1 for e in adversary.random if e.objective is not None and e.objective > 0]
        random_runs_to = random_hits[0] if random_hits else None
        certified = [e.sup_E for e in evals if str(e.verdict).startswith("certified-")]
        if claim_E_max and certified:
            tightness = max(certified) / claim_E_max
    return DesignRow(
        label=design.label, controller=controller_name(design.config),
        tracker=None if design.config.tracker is None and not design.config.correction else str(
            design.config.tracker or "stanley-at-C"),
        runs=len(runs), requirements_passed=passed, requirements_total=total, least_normalised=least,
        least_at=least_at, certified_inside=verdicts.count("certified-inside"),
        certified_outside=verdicts.count("certified-outside"),
        uncertified=sum(1 for v in verdicts if str(v).startswith("uncertified")),
        no_claim=verdicts.count("no-claim"), failed=verdicts.count("failed"), claim_E_max=claim_E_max,
        adversary_worst=worst, adversary_falsified=falsified, adversary_runs_to_falsify=runs_to,
        adversary_where=where, adversary_worst_sup_E=worst_sup_E, random_worst=random_worst,
        random_runs_to_falsify=random_runs_to, tightness=tightness,
        rms_voltage=float(np.mean([r.rms_voltage for r in runs])) if runs else math.nan,
        tv_voltage=float(np.mean([r.tv_voltage for r in runs])) if runs else math.nan,
        cross_track_max=max(cross) if cross else None,
        cpu_us_per_step=float(np.median([r.cpu_us_per_step for r in runs])) if runs else math.nan,
        law="/".join(sorted({r.law for r in runs})), controller_source=controller_source(design.config),
        claim_broken=_claim_broken(runs, adversary),
        unmet=tuple(count_unmet((r.summary.get("certificate") or {}).get("unmet_assumptions") or [] for r in runs)),
        cart=cart_dict(design.config))


def _claim_broken(runs: Sequence[ScenarioRun], adversary: Any) -> dict[str, Any] | None:
    """DesignRow.claim_broken: of the certified-outside scenario runs and the adversary's
    (:attr:`~wmr_mj.searches.falsify.FalsifyResult.claim_broken`), the one of the largest sup|E|/E_max
    (scenarios first among equals)."""
    found: list[dict[str, Any]] = []
    for r in runs:
        if r.verdict == CERTIFIED_OUTSIDE:
            cert = r.summary.get("certificate") or {}
            found.append({"where": "scenario", "scenario": r.scenario, "params": {"m1": r.summary.get("m1")},
                          "sup_E": r.summary.get("sup_E"), "E_max": cert.get("E_max"), "ratio": cert.get("E_ratio")})
    # falsify's BrokenRun as the JSON this row writes (a mapping: compare's report reads it so)
    broken = None if adversary is None else plain(adversary.claim_broken)
    if broken is not None:
        found.append({"where": f"adversary {broken['phase']} run {broken['run']}", "scenario": None,
                      "params": broken["params"], "sup_E": broken["sup_E"], "E_max": broken["E_max"],
                      "ratio": broken["ratio"]})
    if not found:
        return None
    count = len(found) - (broken is not None) + (0 if broken is None else int(broken["count"]))
    worst = max(found, key=lambda f: -math.inf if f["ratio"] is None else float(f["ratio"]))
    return {**worst, "count": count}


def runs_json(result: CompareResult) -> str:
    """Every scenario run of the comparison as JSON lines (design, scenario, slim summary, requirements, effort)."""
    lines = []
    for r in result.runs:
        lines.append(json.dumps({"design": r.design, "scenario": r.scenario, "summary": r.summary,
                                 "requirements": r.requirements, "rms_voltage": r.rms_voltage,
                                 "tv_voltage": r.tv_voltage, "cpu_us_per_step": r.cpu_us_per_step, "law": r.law},
                                default=lambda x: None if isinstance(x, float) and not math.isfinite(x) else str(x)))
    return "\n".join(lines) + "\n"
