"""The design ``wmr-mj design`` finds for a real encoder, beside the certified design on it: the second part of
``wmr-mj validate``'s section (e) (summary.json's ``cart_design``).

On the 12-bit absolute magnetic encoder on the steering axis (:data:`DESIGN_SENSING`, ``magnetic-12bit-axis``:
the ams AS5045, its velocity the backward difference), the stage

1. searches the computed-torque gains this cart certifies, as ``wmr-mj design --sensing magnetic-12bit-axis``
   does (:func:`wmr_mj.searches.design_search.search_design`, CMA-ES, :data:`DESIGN_SEED`, :data:`DESIGN_BUDGET`
   certificates: a few seconds), for the report's box, path and duration; writes the design file into the
   report folder and reads it back as ``wmr-mj run --design FILE`` reads it;
2. sweeps the certified design and the found design on that cart over the same m1 draws
   (:func:`wmr_mj.experiments.sweep.run_sweep`: min(n, :data:`DESIGN_RUNS`) runs, the report's seed and sampling;
   resumable in cart-design-<name>/), each judged against its own certificate.

For each design it records the gains, the certificate (E_max, the voltage it needs, which certificate:
section 4's or the sampled-data one), the verdict counts, the worst sup|E|/E_max of its own certificate and
the voltage's total variation per second (what the gains cost on a quantised angle).

Usage::

    from wmr_mj.report.cart_design import cart_design_stage
    section = cart_design_stage(settings, folder, st)
    section.designs[1].E_max, section.designs[1].verdicts   # the found design's
"""

from __future__ import annotations

import math
import shlex
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from wmr_mj._util.checks import as_pair
from wmr_mj._util.progress import Stages
from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE
from wmr_mj.experiments.compare import design_file_changes
from wmr_mj.experiments.sweep import SweepSpec, SweepSummary, read_runs, run_sweep
from wmr_mj.hardware import Sensing
from wmr_mj.params import M1_RANGE
from wmr_mj.report.settings import ValidateSettings, loud, stage_progress
from wmr_mj.searches.design_search import DEFAULT_BUDGET, DEFAULT_SEED, DesignProblem, search_design, write_design
from wmr_mj.sim.certify import certificate_name
from wmr_mj.sim.coerce import coerce
from wmr_mj.sim.designs import CERTIFIED
from wmr_mj.sim.parts import resolve_run
from wmr_mj.sim.records import Record

__all__ = ["DESIGN_SENSING", "DESIGN_SEED", "DESIGN_BUDGET", "DESIGN_RUNS", "DesignOnCart", "CartDesign",
           "design_problem", "design_command", "cart_design_stage"]

#: The cart the section designs for: the 12-bit axis encoder (ams AS5045), its velocity differenced.
DESIGN_SENSING = "magnetic-12bit-axis"
#: The search's seed and budget: ``wmr-mj design``'s defaults, so that its command finds the same design.
DESIGN_SEED = DEFAULT_SEED
DESIGN_BUDGET = DEFAULT_BUDGET
#: The runs of each design on the cart, at most (the report's n where smaller): issue 35's 16-run sweep.
DESIGN_RUNS = 16


@dataclass(frozen=True, kw_only=True)
class DesignOnCart(Record):
    """One design on the section's cart: its gains, its certificate, its runs.

    Attributes:
        name: 'certified' (the certified design) or 'designed' (the design ``wmr-mj design`` found).
        label: the design in words.
        kp: K_P [1/s^2]; kd: K_D [1/s]; friction_sign, friction_width [rad/s]: the Coulomb compensation;
            control_period [s]; filter_tau: the velocity filter's time constant [s] (None: unfiltered).
        certified: its certificate holds on the cart (every assumption met).
        certificate: which certificate gives its bound: 'section-4' or 'sampled-data' (None: no valid one).
        E_max: the certificate's bound on |E| [rad] (None: no valid certificate); voltage_max: the voltage it
            needs [V] (None likewise).
        unmet: the certificate's unmet assumptions (their names).
        n: runs; verdicts: each verdict's count; certified_outside: those runs.
        worst_sup_E: the worst sup|E| [rad] and its m1 [kg]; worst_certificate_ratio: the worst sup|E|/E_max of
            its own certificate and its m1 [kg] (None where no run has a certificate).
        mean_tv_voltage: the total variation of the voltage per second [V/s], the mean over its runs (as
            section (e)'s TV u: the price of the gains on a quantised angle).
        runs_csv: its runs.csv, relative to the report folder.
    """

    name: str
    label: str
    kp: float
    kd: float
    friction_sign: str
    friction_width: float
    control_period: float | None
    filter_tau: float | None
    certified: bool
    certificate: str | None
    E_max: float | None
    voltage_max: float | None
    unmet: tuple[str, ...]
    n: int
    verdicts: Mapping[str, int]
    certified_outside: int
    worst_sup_E: float | None
    worst_sup_E_m1: float | None
    worst_certificate_ratio: float | None
    worst_certificate_ratio_m1: float | None
    mean_tv_voltage: float | None
    runs_csv: str


@dataclass(frozen=True, kw_only=True)
class CartDesign(Record):
    """Section (e)'s design for a real encoder (summary.json's ``cart_design``).

    Attributes:
        sensing: the cart's sensing preset; label: its label.
        m1_range: the box's m1 [kg]; n: runs of each design; seed, sampling: of the m1 draws (the report's);
            duration [s] and path: of each run.
        search: the search's objective, method, seed, budget, certificate evaluations and periods [s].
        binding: where nothing certified, the assumption that binds; '' else.
        design_file: the design file written, relative to the report folder (``wmr-mj run --design FILE``).
        command: the ``wmr-mj design`` command that finds the same design.
        designs: the certified design, then the found design, on the cart.
        certified_outside: certified-outside runs of both.
    """

    _records = {"designs": DesignOnCart}

    sensing: str
    label: str
    m1_range: tuple[float, float]
    n: int
    seed: int
    sampling: str
    duration: float
    path: str
    search: Mapping[str, Any]
    binding: str
    design_file: str
    command: str
    designs: tuple[DesignOnCart, ...]
    certified_outside: int


def design_problem(settings: ValidateSettings, *, sensing: str = DESIGN_SENSING, seed: int = DESIGN_SEED,
                   budget: int = DESIGN_BUDGET) -> Any:
    """The :class:`~wmr_mj.searches.design_search.DesignProblem` of the section: the certified design's run of these
    settings (their box, path, duration and cart) on ``sensing``, searched as ``wmr-mj design`` searches
    (the 1 ms period, the default objective: E_max, then the supply within 10 % of it; CMA-ES)."""
    base = coerce(settings.config(CERTIFIED).replace(sensing=sensing))  # the sensing's spec typed
    return DesignProblem(base=base, paths=(settings.path,), seed=seed, budget=budget)


def design_command(settings: ValidateSettings, problem: Any) -> str:
    """The ``wmr-mj design`` command that searches ``problem`` (its options where they are not its defaults)."""
    sensing = problem.base.sensing
    words = ["wmr-mj", "design", "--sensing", shlex.quote(DESIGN_SENSING if sensing == _preset(DESIGN_SENSING)
                                                          else _spec(sensing.to_dict()))]
    if not problem.base.actuation.is_ideal:
        words += ["--actuation", shlex.quote(_spec(problem.base.actuation.to_dict()))]
    if problem.base.transmission.backlash:
        words += ["--backlash", repr(problem.base.transmission.backlash)]
    if settings.cart is not None:  # the cart file the search ran on (its parameter set, box and stops)
        words += ["--cart", shlex.quote(str(settings.cart["path"]))]
    if settings.path != "paper-circle":
        words += ["--path", shlex.quote(settings.path)]
    if settings.uncertainty != "m1":
        words += ["--uncertainty", settings.uncertainty]
    if tuple(settings.m1_range) != tuple(M1_RANGE):
        words += ["--m1-range", *(f"{v:g}" for v in settings.m1_range)]
    if settings.duration != 35.0:
        words += ["--duration", f"{settings.duration:g}"]
    if problem.seed != DESIGN_SEED:
        words += ["--seed", str(problem.seed)]
    if problem.budget != DESIGN_BUDGET:
        words += ["--budget", str(problem.budget)]
    return " ".join(words)


def _preset(name: str) -> Any:
    return Sensing.from_spec(name)


def _spec(d: Mapping[str, Any]) -> str:
    return ",".join(f"{k}={v}" for k, v in d.items() if v is not None)


def _design_on_cart(name: str, label: str, base: Any, settings: ValidateSettings, folder: Path, st: Stages,
                    n: int) -> DesignOnCart:
    """Sweep ``base`` over the m1 draws (resumable in cart-design-<name>/) and summarise it with its certificate."""
    cert = resolve_run(base).claim  # the certificate of the design on the cart, over the box (a run's own)
    spec = SweepSpec(n=n, seed=settings.seed, sampling=settings.sampling, m1_range=as_pair(settings.m1_range),
                     ranges=settings.ranges, base=base)
    sweep_dir = folder / f"cart-design-{name}"
    run_sweep(spec, out_dir=sweep_dir, nthread=settings.nthread, progress=stage_progress(st))
    rows = read_runs(sweep_dir)  # full precision: runs.csv is rounded
    runs = SweepSummary.of(rows).rung_dict()
    tv = [float(r["tv_voltage"]) for r in rows if r.get("tv_voltage") is not None]
    valid = cert if cert is not None and cert.valid else None
    return DesignOnCart(
        name=name, label=label, kp=float(base.kp), kd=float(base.kd), friction_sign=str(base.friction_sign),
        friction_width=float(base.friction_width), control_period=base.control_period,
        filter_tau=base.sensing.filter_tau, certified=bool(cert is not None and cert.certified),
        certificate=None if valid is None else certificate_name(valid),
        E_max=None if valid is None else float(valid.E_max),
        voltage_max=None if valid is None else float(valid.voltage_max),
        unmet=tuple(cert.unmet) if cert is not None else ("no claim (the law states none)",), n=runs["n"],
        verdicts=runs["verdicts"], certified_outside=int(runs["verdicts"].get(CERTIFIED_OUTSIDE, 0)),
        worst_sup_E=runs["worst_sup_E"], worst_sup_E_m1=runs["worst_sup_E_m1"],
        worst_certificate_ratio=runs["worst_certificate_ratio"],
        worst_certificate_ratio_m1=runs["worst_certificate_ratio_m1"],
        mean_tv_voltage=sum(tv) / len(tv) if tv else None,
        runs_csv=(sweep_dir / "runs.csv").relative_to(folder).as_posix())


def cart_design_stage(settings: ValidateSettings, folder: Path, st: Stages, *, sensing: str = DESIGN_SENSING,
                      seed: int = DESIGN_SEED, budget: int = DESIGN_BUDGET) -> CartDesign:
    """Search the design for ``sensing`` and sweep it beside the certified design on that cart (the module).

    Args:
        settings: the report's (box, path, duration, m1 draws, threads, cart).
        folder: the report folder (the design file and both sweeps go there).
        st: the report's stage lines.
        sensing: the cart's sensing preset; seed, budget: the search's (:data:`DESIGN_SEED`,
            :data:`DESIGN_BUDGET`: ``wmr-mj design``'s defaults).

    Returns:
        summary.json's ``cart_design``.
    """
    problem = design_problem(settings, sensing=sensing, seed=seed, budget=budget)
    n = min(settings.n, DESIGN_RUNS)
    st.start("cart-design", f"the design wmr-mj design finds for {sensing} ({budget} certificates), then it and the "
                            f"certified design on that cart: {n} runs each over m1 {settings.m1_range[0]:g}-"
                            f"{settings.m1_range[1]:g} kg")
    t0 = time.perf_counter()
    result = search_design(problem)
    search_s = time.perf_counter() - t0
    file = folder / f"design-{sensing}.json"
    write_design(result, file)
    certified_base = problem.base
    # the found design as `run --design FILE` reads it back: the file, not the search's objects
    designed_base = certified_base.replace(**design_file_changes(str(file), cart=settings.cart))
    rows = []
    for name, base in (("certified", certified_base), ("designed", designed_base)):
        label = "the certified design" if name == "certified" else f"the design for {sensing} (wmr-mj design)"
        rows.append(_design_on_cart(name, label, base, settings, folder, st, n))
    n_out = sum(d.certified_outside for d in rows)
    st.done("; ".join(f"{d.name}: " + (f"E_max {d.E_max:.3g} rad ({d.certificate})" if d.E_max is not None
                                        else "no certificate") + f", {d.verdicts.get('certified-inside', 0)}/{d.n} "
                      "certified-inside" for d in rows) + f" (search {search_s:.1f} s)"
            + loud(n_out, "the design section"))
    return CartDesign(
        sensing=sensing, label=certified_base.sensing.label(), m1_range=as_pair(settings.m1_range), n=n,
        seed=settings.seed, sampling=settings.sampling, duration=settings.duration, path=settings.path,
        search={"objective": result.objective, "method": problem.method, "seed": result.seed, "budget": budget,
                "evaluations": result.evaluations, "periods": list(result.periods),
                "score": result.score if math.isfinite(result.score) else None},
        binding=result.binding, design_file=file.relative_to(folder).as_posix(),
        command=design_command(settings, problem), designs=tuple(rows), certified_outside=n_out)
