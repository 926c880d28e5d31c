"""A run's configuration resolved once into typed parts, before any step.

A :class:`~wmr_mj.sim.config.RunConfig` names what a run is; :func:`resolve_run` builds what it is made
of, once: the plant's parameters and the controller's belief, the steering law and the path tracker
(fresh instances: a run never shares a law's state), C's reference on the control grid, the signals,
the paper's analysis and the law's own claim. The runner, the batch and the report take these parts;
nothing below them reads the config's strings again.

Usage::

    from wmr_mj.sim.parts import resolve_run
    parts = resolve_run(RunConfig(controller="sliding-mode", model="nonholonomic"))
    parts.controller.name, parts.claim.E_max, parts.n, parts.period
    parts.claims[LAW_CLAIM]      # the same claim, by name: a further analysis is one more entry
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from controllers import PathTracker, SteeringController
from wmr_mj.analysis.certificate import Certificate
from wmr_mj.analysis.claim_types import LAW_CLAIM, Claims, claim_set
from wmr_mj.analysis.measurement import MeasurementErrors
from wmr_mj.errors import ParameterError
from wmr_mj.hardware import Actuation, Sensing, Transmission
from wmr_mj.params import C80, C80Parameters, with_params
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.reference.named import run_reference
from wmr_mj.sim import certify
from wmr_mj.sim.builders import (
    BoxSpec,
    LawSpec,
    analysis_of,
    estimate_of,
    estimate_parameters,
    laws_of,
    manoeuvre_length,
)
from wmr_mj.sim.coerce import (
    coerce_with_classes,
    coerced,
    controller_name,
    law_name,
    plant_parameters,
)
from wmr_mj.sim.engine import load_fields, plant_options
from wmr_mj.sim.run_config import RunConfig

__all__ = ["RunParts", "RunLabels", "resolve_run", "run_reference", "plant_and_claim", "control_substeps",
           "signal_inputs"]


@dataclass(frozen=True, kw_only=True)
class RunLabels:
    """What a run's summary calls its law, estimate, gains and path: read from the config once, by
    :func:`resolve_run`, so that nothing below it reads the config's strings (the summary's ``controller``,
    ``model``, ``kp``, ``kd``, ``path`` keys).

    Attributes:
        controller: the law's name (a built-in's name, a plug-in's ``name``).
        model: the estimate's model source. kp [1/s^2], kd [1/s]: the gains as given.
        path: C's path as the config names it (a path name, a route name or file, canonical route JSON).
    """

    controller: str
    model: str
    kp: float
    kd: float
    path: str

    @classmethod
    def of(cls, config: RunConfig, *, name: str | None = None) -> RunLabels:
        """The labels of ``config``; ``name``: the law's name where already known (else from the config)."""
        return cls.named(config, controller_name(config) if name is None else name)

    @classmethod
    def named(cls, config: RunConfig, name: str) -> RunLabels:
        """The labels of ``config``, whose law is called ``name``: read, nothing coerced."""
        return cls(controller=name, model=str(config.model), kp=config.kp, kd=config.kd, path=config.path)


def control_substeps(control_period: float | None, timestep: float = TIMESTEP) -> int:
    """Physics steps per control step for a control period [s] (``RunConfig.control_period``; None: every
    physics step, 1).

    Raises:
        ParameterError: a control period that is not a whole multiple of the physics step.
    """
    if control_period is None:
        return 1
    n = round(control_period / timestep)
    if n < 1 or abs(n * timestep - control_period) > 1e-9:
        raise ParameterError(f"control_period = {control_period} s must be a multiple of the "
                             f"physics step {timestep} s")
    return n


@dataclass(frozen=True)
class RunParts:
    """What a run is made of (:func:`resolve_run`).

    Attributes:
        config: the configuration it was resolved from.
        base: the base parameter set.
        plant: the plant's parameters (m1, the overrides).
        estimate: the controller's belief (the nominal parameter set).
        controller: a fresh instance of the steering law.
        controller_name: what every output calls it.
        tracker: a fresh instance of the path tracker, or None.
        reference: C's reference on the control grid (:class:`wmr_mj.reference.paths.Reference`).
        settle_s: when the entry transient ends [s].
        substeps: physics steps per control step; period: the control period [s]; n: control steps.
        options: the plant's laws (steering friction, tyre contact).
        analysis: the paper's analysis for the run's box, gains and reference bounds.
        claims: the claims the run is judged by, by name (:class:`~wmr_mj.analysis.claim_types.Claims`): the
            law's own under :data:`~wmr_mj.analysis.claim_types.LAW_CLAIM` (absent where it states none); a
            further analysis is one more entry, measured and judged by ``run_parts`` as the law's is. The
            run's verdict is the law's claim's (:attr:`claim`).
        paper_law: the law is the paper's family (computed torque, PD): the paper's region applies to it.
        law_settings: the RunConfig settings the law reads (``controller_and_settings``: model, kp, kd, ...).
        sensing, actuation, transmission: the cart as it is built (:mod:`wmr_mj.hardware`; ideal by default).
        reference_bounds: the reference bounds the claims are computed for
            (:class:`wmr_mj.reference.bounds.ReferenceBounds`): the declared ones, else the run's own reference's.
        signals: the run's signals (:class:`wmr_mj.sim.signals.Signals`), None without.
        disturbance: the disturbance torque at each control step [N m], None without one.
        loads: (control step, the plant's MuJoCo fields from then on) of each load change, in time order.
        route_length_m: the length of the route C follows [m] (one lap of a closed one), or of the manoeuvre a
            named path must drive to judge it whole (lane-change's: :func:`wmr_mj.sim.config.manoeuvre_length`);
            None on the other named paths.
        measurement: the error bounds on what the law reads, from the cart's parts
            (:func:`wmr_mj.sim.certify.measurement_errors_of`; exact on an ideal cart).
        labels: what the summary calls the law, estimate, gains and path (:class:`RunLabels`).
        record: the config as its log records it (``RunConfig.to_dict()``, taken once here).
    """

    config: RunConfig
    base: C80Parameters
    plant: C80Parameters
    estimate: C80Parameters
    controller: SteeringController
    controller_name: str
    tracker: PathTracker | None
    reference: Any
    settle_s: float
    substeps: int
    period: float
    n: int
    options: dict[str, Any]
    analysis: Any
    claims: Claims
    paper_law: bool = True
    law_settings: frozenset[str] | None = None
    sensing: Sensing = Sensing()
    actuation: Actuation = Actuation()
    transmission: Transmission = Transmission()
    reference_bounds: Any = None
    signals: Any = None
    disturbance: np.ndarray | None = None
    loads: tuple[tuple[int, Any], ...] = ()
    route_length_m: float | None = None
    measurement: MeasurementErrors = MeasurementErrors.exact()
    labels: RunLabels | None = None
    record: Mapping[str, Any] | None = None

    @property
    def claim(self) -> Certificate | None:
        """The law's own claim (``claims[LAW_CLAIM]``), None where it states none: the run's verdict is
        judged against it."""
        return self.claims.get(LAW_CLAIM)


def resolve_run(config: RunConfig, *, base: C80Parameters = C80) -> RunParts:
    """``config`` resolved once into its parts (:class:`RunParts`).

    The config is coerced first (:func:`wmr_mj.sim.coerce.coerce_with_classes`): a reference it holds (a cart's
    name or file, a plug-in by name, a route file) is read here, once, and ``RunParts.config`` is the typed config.
    It is then read once into typed values -- the control grid, the law's :class:`~wmr_mj.sim.builders.LawSpec`,
    the analysis' :class:`~wmr_mj.sim.builders.BoxSpec`, the cart's parts, the labels and the record -- and each
    part is built once from those, in layer order: the parameter sets, the law and the tracker, C's reference, the
    paper's analysis, the cart's measurement errors, the law's claim (:func:`wmr_mj.sim.certify.law_certificate`).
    No builder below is handed the config.

    base: the base parameter set; where it is the default (the C80) and the config names a cart
    (``RunConfig.cart``), the cart's (:func:`wmr_mj.sim.config.base_for`).

    Raises:
        WmrMjError: what the config cannot build (a plug-in, a path too short, a period that does not fit).
    """
    typed = coerce_with_classes(config, base=base)  # the one read of the config's files and plug-ins
    config, classes, base, plant, record = typed.config, typed.classes, typed.base, typed.plant, typed.record
    # the typed config read once, here in the sim layer, into what each part is built from
    substeps = control_substeps(config.control_period)
    period = substeps * TIMESTEP
    n = int(round(config.duration / period))
    claim_period = config.control_period if config.control_period is not None else TIMESTEP  # the law's, as given
    law, box, options = LawSpec.of(config), BoxSpec.of(config), plant_options(config)
    labels = RunLabels.named(config, law_name(config))
    route_length_m = (float(typed.route.path.length) if typed.route is not None
                      else manoeuvre_length(config.path))  # lane-change's
    disturbance, loads = signal_inputs(config.signals, plant, options, n=n, period=period,
                                       m1_inertia=config.m1_inertia)  # the signals' samples on the run's grid
    # then each part, built once and handed on in layer order: the parameter sets, the law and the tracker on the
    # belief, C's reference, the paper's analysis, the cart's measurement errors, the law's claim
    estimate = estimate_parameters(base)
    controller, law_settings, tracker = laws_of(law, estimate, classes=classes)
    if config.sensing.velocity == "none" and getattr(controller, "reads_velocity", True):
        raise ParameterError(f"controller {controller.name!r} reads alpha', which --sensing velocity=none does not "
                             "give it; accepted: a law that estimates alpha' from the angle (reads_velocity = False, "
                             "docs/guides/plugins.md), or a velocity estimate (exact, tachometer, difference, "
                             "filtered)")
    reference, settle_s = run_reference(config.path, estimate, period=period, duration=config.duration)
    # the reference bounds the claims are computed for: the declared ones, else the reference's own
    bounds = reference.bounds() if config.reference_bounds is None else config.reference_bounds
    paper_estimate = estimate_of(controller)  # None: not the paper's law, whose region then says nothing of it
    analysis = analysis_of(box, bounds, estimate, kp=law.kp, kd=law.kd, estimate=paper_estimate)
    # once: the claim and the run's parts share them (the typed parts: measurement_errors_of would check again
    # that the config is coerced, which it is here)
    measurement = certify.measurement_errors(config.sensing, config.actuation, config.transmission, plant,
                                             period=claim_period)
    law_claim = certify.law_certificate(reference, controller=controller, tracker=tracker, box=box, base=base,
                                estimate=estimate, plant=plant, period=claim_period, signals=config.signals,
                                declared_bounds=config.reference_bounds, sensing=config.sensing,
                                actuation=config.actuation, transmission=config.transmission,
                                steering_friction=config.steering_friction, measurement=measurement,
                                sampled_data=True, delay_split=typed.delay_split)
    claims = claim_set(**{LAW_CLAIM: law_claim})
    return RunParts(config=config, base=base, plant=plant, estimate=estimate, controller=controller,
                    controller_name=labels.controller, tracker=tracker, reference=reference,
                    settle_s=settle_s, substeps=substeps, period=period, n=n, options=options,
                    analysis=analysis, claims=claims,
                    paper_law=paper_estimate is not None, law_settings=law_settings, sensing=config.sensing,
                    actuation=config.actuation, transmission=config.transmission,
                    reference_bounds=bounds, signals=config.signals,
                    disturbance=disturbance, loads=loads, route_length_m=route_length_m,
                    measurement=measurement, labels=labels, record=record)


def plant_and_claim(config: RunConfig, shared: RunParts, *, base: C80Parameters = C80
                    ) -> tuple[C80Parameters, Certificate | None]:
    """A batch's further run: its own plant, and the claim of ``shared``'s law (the batch's parts, which it shares
    but for the plant: law, tracker, reference, belief) on that plant -- a plant outside the box fails its
    assumption. ``base``: the batch's base parameter set, as :func:`wmr_mj.sim.batch.run_batch` is given it."""
    config = coerced(config)
    plant = plant_parameters(config, base)
    claim = certify.certificate_of(config, shared.reference, base=base, estimate=shared.estimate, plant=plant,
                           controller=shared.controller, tracker=shared.tracker)
    return plant, claim


def signal_inputs(signals: Any, plant: C80Parameters, options: dict[str, Any], *, n: int, period: float,
                  m1_inertia: str) -> tuple[np.ndarray | None, tuple[tuple[int, Any], ...]]:
    """What the run's signals (:class:`wmr_mj.sim.signals.Signals`, None: none) do to its plant, on its grid.

    A load change at time t is applied at the first control step at or after t.

    Args:
        plant: the plant's parameters before any load change; options: its laws (``plant_options``).
        n: control steps; period: the control period [s]; m1_inertia: how m1 changes the chassis inertia.

    Returns:
        (the disturbance torque at each control step [N m] or None, ((control step, load fields), ...)).
    """
    if signals is None:
        return None, ()

    disturbance = None
    if signals.disturbance is not None:
        disturbance = signals.disturbance.samples(np.arange(n) * period)
    loads = []
    for t, m1 in signals.load_steps(plant.m1):
        k = int(np.ceil(t / period - 1e-9))
        if k < n:
            loads.append((k, load_fields(with_params(plant, m1_inertia=m1_inertia, m1=m1), **options)))
    return disturbance, tuple(loads)
