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
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from controllers import PathTracker, SteeringController
from wmr_mj.analysis.certificate import Certificate
from wmr_mj.errors import ParameterError
from wmr_mj.hardware import Actuation, Sensing, Transmission
from wmr_mj.params import C80, C80Parameters
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.sim.config import (
    RunConfig,
    analysis_for,
    build_reference,
    controller_and_settings,
    controller_name,
    estimate_of,
    estimate_parameters,
    plant_parameters,
    tracker_for,
)

__all__ = ["RunParts", "resolve_run", "control_substeps"]


def control_substeps(config: RunConfig, timestep: float = TIMESTEP) -> int:
    """Physics steps per control step of ``config`` (1 where it sets no control period).

    Raises:
        ParameterError: a control period that is not a whole multiple of the physics step.
    """
    if config.control_period is None:
        return 1
    n = round(config.control_period / timestep)
    if n < 1 or abs(n * timestep - config.control_period) > 1e-9:
        raise ParameterError(f"control_period = {config.control_period} s must be a multiple of the "
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
        claim: the law's own claim (a Certificate), None where it states none.
        paper_law: the law is the paper's family (computed torque, PD): the paper's region applies to it.
        law_settings: the RunConfig settings the law reads (``controller_and_settings``: model, kp, kd, ...).
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
    claim: Certificate | None
    paper_law: bool = True
    law_settings: frozenset[str] | None = None
    sensing: Sensing = Sensing()
    actuation: Actuation = Actuation()
    transmission: Transmission = Transmission()


def resolve_run(config: RunConfig, *, base: C80Parameters = C80) -> RunParts:
    """``config`` resolved once into its parts (:class:`RunParts`).

    Raises:
        WmrMjError: what the config cannot build (a plug-in, a path too short, a period that does not fit).
    """
    from wmr_mj.sim.certify import certificate_of
    from wmr_mj.sim.engine import plant_options

    plant = plant_parameters(config, base)
    estimate = estimate_parameters(base)
    controller, law_settings = controller_and_settings(config, estimate)
    tracker = tracker_for(config, estimate)
    substeps = control_substeps(config)
    period = substeps * TIMESTEP
    n = int(round(config.duration / period))
    reference, settle_s = build_reference(config.path, estimate, dt=period, duration=n * period)
    paper_estimate = estimate_of(controller)  # None: not the paper's law, whose region then says nothing of it
    analysis = analysis_for(config, reference, estimate, estimate=paper_estimate)
    claim = certificate_of(config, reference, base=base, estimate=estimate, plant=plant,
                           controller=controller, tracker=tracker)
    return RunParts(config=config, base=base, plant=plant, estimate=estimate, controller=controller,
                    controller_name=controller_name(config), tracker=tracker, reference=reference,
                    settle_s=settle_s, substeps=substeps, period=period, n=n, options=plant_options(config),
                    analysis=analysis, claim=claim, paper_law=paper_estimate is not None,
                    law_settings=law_settings, sensing=config.sensing, actuation=config.actuation,
                    transmission=config.transmission)
