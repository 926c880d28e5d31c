"""What follows from a run's configuration before any step: the controller's belief, the law and the tracker
(fresh instances), C's reference on the control grid, the paper's analysis for the run's box.

Each builder takes typed values, not the config: the law and tracker a :class:`LawSpec` (:func:`laws_of`, both in
one call; :func:`law_and_settings`, :func:`tracker_of`), the analysis a :class:`BoxSpec` and the reference bounds
(:func:`analysis_of`); the reference is built in its own layer from a path and the belief
(:func:`wmr_mj.reference.named.build_reference`, re-exported here). :func:`wmr_mj.sim.parts.resolve_run` reads a typed
:class:`~wmr_mj.sim.run_config.RunConfig` (:mod:`wmr_mj.sim.coerce`) into them once and calls each once per run;
the functions that take a config (:func:`controller_for`, :func:`controller_and_settings`, :func:`tracker_for`,
:func:`analysis_box`, :func:`analysis_for`) unpack it and call them. No builder reads a file of its own.

Usage::

    from wmr_mj.sim.builders import LawSpec, build_reference, controller_for, estimate_parameters, law_and_settings
    controller = controller_for(config, estimate_parameters())
    controller, settings = law_and_settings(LawSpec.of(config), estimate_parameters())   # a typed config's law
    reference, settle_s = build_reference("paper-circle", estimate_parameters(), dt=1e-3, duration=35.0)
"""

from __future__ import annotations

import inspect
import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from controllers import PathTracker, SteeringController, make_controller, model_from_source
from controllers.computed_torque import CONTROLLER_NAMES
from controllers.registry import build_plugin, resolve
from wmr_mj._util.checks import as_pair
from wmr_mj.analysis.plant_box import derived_box
from wmr_mj.analysis.robustness import ParameterBox, analyse
from wmr_mj.errors import ParameterError
from wmr_mj.params import C80, C80Parameters
from wmr_mj.reference.bounds import ReferenceBounds
from wmr_mj.reference.named import (
    LANE_CHANGE_LEAD_IN_M,
    LANE_CHANGE_LENGTH_M,
    REFERENCE_CACHE_SIZE,
    build_reference,
)
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.run_config import RunConfig

__all__ = ["BoxSpec", "LawSpec", "estimate_parameters", "build_reference", "REFERENCE_CACHE_SIZE", "manoeuvre_length",
           "analysis_box", "parameter_box", "analysis_for", "analysis_of", "reference_bounds_of", "run_bounds",
           "law_and_settings", "tracker_of", "laws_of", "controller_for", "controller_and_settings", "LAW_SETTINGS",
           "declared_parameters", "tracker_for", "has_tracker", "estimate_of", "config_from_dict"]


def estimate_parameters(base: C80Parameters = C80) -> C80Parameters:
    """The controller's belief: the nominal parameter set (m1 = 650 kg)."""
    return base


def manoeuvre_length(path: str) -> float | None:
    """The length [m] of C's reference a run of the named ``path`` must drive for its verdict to judge the whole
    manoeuvre: lane-change's lead-in and lane change (the line after it only fills the duration); None for a
    path that refuses a duration too short for it (paper-circle), a closed one (figure-eight) or a route (whose
    own length :func:`wmr_mj.reference.route.route_length` gives)."""
    if path == "lane-change":
        return LANE_CHANGE_LEAD_IN_M + LANE_CHANGE_LENGTH_M
    return None


@dataclass(frozen=True, kw_only=True)
class BoxSpec:
    """The parameter box a run's analyses are computed over, as its config declares it (the config's fields of
    the same names, read once by :meth:`of`): the paper's analysis (:func:`analysis_of`) and the law's claim
    (:func:`wmr_mj.sim.certify.law_certificate`) take this, not the config.

    Attributes:
        box: 'derived' (from the parameter set over the ranges) or 'paper' ((5.1)).
        model: the controller's model source: the derived box stands on the nonholonomic model for
            'nonholonomic' and 'identified', on the paper's otherwise; 'identified' hulls in its spread.
        identified: the identification (a path or mapping from ``wmr-mj identify``) for model 'identified'.
        m1_range: the m1 range [kg]; m1_inertia: how m1 changes the chassis inertia.
        box_ranges: the other ranged parameters, NAME -> (lo, hi), in the config's order.
        plant_overrides: the names of the parameters the run's plant overrides (at the base value in the box).
    """

    box: str
    model: str
    identified: Any
    m1_range: tuple[float, float]
    m1_inertia: str
    box_ranges: Mapping[str, tuple[float, float]]
    plant_overrides: tuple[str, ...]

    @classmethod
    def of(cls, config: RunConfig) -> BoxSpec:
        """The box of a typed config (:func:`wmr_mj.sim.coerce.coerced`)."""
        return cls(box=config.box, model=str(config.model), identified=config.identified,
                   m1_range=config.m1_range, m1_inertia=config.m1_inertia, box_ranges=config.box_ranges,
                   plant_overrides=tuple(config.plant_overrides))


def analysis_box(config: RunConfig, params: C80Parameters = C80):
    """The parameter box of the analysis (:func:`parameter_box` of the config's :class:`BoxSpec`)."""
    return parameter_box(BoxSpec.of(coerced(config)), params)


def parameter_box(box: BoxSpec, params: C80Parameters = C80):
    """The parameter box of the analysis: the paper's (5.1), or derived from ``params`` over
    the box's m1 range (and box ranges) with the model the controller's source stands on
    ('nonholonomic' for nonholonomic and identified, 'paper' otherwise)."""
    if box.box == "paper":
        return ParameterBox.paper()
    box_model = "nonholonomic" if box.model in ("nonholonomic", "identified") else "paper"
    return derived_box(params, as_pair(box.m1_range), box.m1_inertia,
                       tuple((k, as_pair(v)) for k, v in box.box_ranges.items()), model=box_model)


def analysis_for(config: RunConfig, reference, params: C80Parameters = C80, *, estimate=None):
    """The robustness analysis (4.17)-(4.23) for the run's box, gains and reference bounds
    (:func:`analysis_of` on the config's box, gains and :func:`reference_bounds_of`)."""
    config = coerced(config)
    return analysis_of(BoxSpec.of(config), reference_bounds_of(config, reference), params, kp=config.kp,
                       kd=config.kd, estimate=estimate)


def analysis_of(box: BoxSpec, bounds: ReferenceBounds, params: C80Parameters = C80, *, kp: float, kd: float,
                estimate=None):
    """The robustness analysis (4.17)-(4.23) over ``box`` (:func:`parameter_box` on ``params``), for the gains
    kp [1/s^2], kd [1/s] and the reference bounds the run's analyses take (:func:`reference_bounds_of`).

    estimate: the controller's coefficients (P^, C_V^, F^, K^); the parameter
    errors are then truth-anywhere-in-the-box minus this estimate. None: the
    estimate is anywhere in the box too, as in the paper's (4.2).
    """
    over = parameter_box(box, params)
    floored = ReferenceBounds(alpha_ddot_max=max(bounds.alpha_ddot_max, 1e-12),
                              alpha_dot_max=max(bounds.alpha_dot_max, 1e-12),
                              sin_cos3_max=max(bounds.sin_cos3_max, 1e-12))
    return analyse(over, kp=kp, kd=kd, bounds=floored, estimate=estimate)


def reference_bounds_of(config: RunConfig, reference):
    """:func:`run_bounds` of ``reference`` and the config's declared bounds (``config.reference_bounds``)."""
    return run_bounds(reference, config.reference_bounds)


def run_bounds(reference, declared: ReferenceBounds | None) -> ReferenceBounds:
    """The reference bounds the run's analyses are computed for: the ``declared`` ones, else the run's own
    reference's (``reference.bounds()``)."""
    return reference.bounds() if declared is None else declared


def controller_for(config: RunConfig, params: C80Parameters, *, classes: Mapping[str, type] | None = None
                   ) -> SteeringController:
    """A fresh instance of the controller ``config`` runs, built on ``params`` (the controller's belief,
    see :func:`estimate_parameters`): the computed-torque and PD laws from the config's fields, a plug-in
    from its name and ``controller_params`` (``from_context``), an object as a deep copy (a run never
    shares a law's state with another), a factory by calling it.

    Raises:
        UnknownNameError: an unknown controller or model source.
        ParameterError: a plug-in that cannot be built (a parameter it does not take, a factory that
            returns no SteeringController).
    """
    return controller_and_settings(config, params, classes=classes)[0]


#: The RunConfig fields that configure a steering law beside its own parameters (``--model``, ``--kp``,
#: ``--kd``, ``--friction-sign``, ``--friction-width``): the computed-torque law reads them all.
LAW_SETTINGS = ("model", "kp", "kd", "friction_sign", "friction_width")
#: The ones the PD law reads (it has no Coulomb compensation).
_PD_SETTINGS = ("model", "kp", "kd")


@dataclass(frozen=True, kw_only=True)
class LawSpec:
    """What a run's law and tracker are built from, as its config declares them (the config's fields of the same
    names, read once by :meth:`of`): :func:`law_and_settings` and :func:`tracker_of` take this, not the config.

    Attributes:
        controller: the law as given (a name, ``FILE.py:Class``, ``module:Class``, an object, a factory);
            controller_params: its parameters.
        model: the estimate's model source; identified, coefficients: its data ('identified', 'explicit').
        kp [1/s^2], kd [1/s], friction_sign, friction_width [rad/s]: the settings a law may read.
        tracker: the path tracker as given, "stanley-at-C" for the correction, None without one;
            tracker_params: its parameters.
    """

    controller: Any
    controller_params: Mapping[str, Any]
    model: str
    identified: Any
    coefficients: Mapping[str, float] | None
    kp: float
    kd: float
    friction_sign: str
    friction_width: float
    tracker: Any
    tracker_params: Mapping[str, Any]

    @classmethod
    def of(cls, config: RunConfig) -> LawSpec:
        """The law and tracker of a typed config (:func:`wmr_mj.sim.coerce.coerced`)."""
        return cls(controller=config.controller, controller_params=config.controller_params,
                   model=str(config.model), identified=config.identified, coefficients=config.coefficients,
                   kp=config.kp, kd=config.kd, friction_sign=config.friction_sign,
                   friction_width=config.friction_width,
                   tracker="stanley-at-C" if config.tracker is None and config.correction else config.tracker,
                   tracker_params=config.tracker_params)


def controller_and_settings(config: RunConfig, params: C80Parameters, *, classes: Mapping[str, type] | None = None
                            ) -> tuple[SteeringController, frozenset[str]]:
    """:func:`law_and_settings` of the config's :class:`LawSpec`."""
    return law_and_settings(LawSpec.of(coerced(config)), params, classes=classes)


def law_and_settings(law: LawSpec, params: C80Parameters, *, classes: Mapping[str, type] | None = None
                     ) -> tuple[SteeringController, frozenset[str]]:
    """:func:`controller_for`, and the names of :data:`LAW_SETTINGS` the law reads: all of them for the
    computed-torque law, model, kp and kd for PD; for a law built by name, those of its build context
    (``controllers.base.BuildContext``) its ``from_context`` read; none for an object or a factory.
    Only these describe the law in its outputs (the others' values were never used). ``classes``: the plug-ins'
    classes already found (``coerce_with_classes``), kind -> class; a plug-in not there is resolved by name."""
    given = law.controller
    model = model_from_source(law.model, params=params, identified=law.identified, coefficients=law.coefficients)
    if isinstance(given, str) and given in CONTROLLER_NAMES:
        built = make_controller(given, model, kp=law.kp, kd=law.kd, friction_sign=law.friction_sign,
                                friction_width=law.friction_width)
        return built, frozenset(_PD_SETTINGS if given == "pd" else LAW_SETTINGS)
    return build_plugin(given, law.controller_params, kind="controller", estimate=params, kp=law.kp, kd=law.kd,
                        model=model, cls=(classes or {}).get("controller"))


def laws_of(law: LawSpec, params: C80Parameters, *, classes: Mapping[str, type] | None = None
            ) -> tuple[SteeringController, frozenset[str], PathTracker | None]:
    """(law, the settings it reads, tracker): :func:`law_and_settings` and :func:`tracker_of` in one call, each a
    fresh instance on the belief ``params`` (:func:`wmr_mj.sim.parts.resolve_run` builds a run's two laws here)."""
    controller, settings = law_and_settings(law, params, classes=classes)
    tracker, _ = build_plugin(law.tracker, law.tracker_params, kind="tracker", estimate=params, kp=law.kp, kd=law.kd,
                              model_source=law.model, identified=law.identified, coefficients=law.coefficients,
                              cls=(classes or {}).get("tracker"))  # as tracker_of builds it
    return controller, settings, tracker


def declared_parameters(spec: str) -> frozenset[str]:
    """The keyword parameters the law named ``spec`` (a built-in name, FILE.py:Class, module:Class) declares
    in its constructor or its ``from_context`` (which a run's ``controller_params`` may set)."""
    cls, _ = resolve(spec, kind="controller")
    names: set[str] = set()
    for fn in (cls, getattr(cls, "from_context", cls)):
        try:
            sig = inspect.signature(fn)
        except (TypeError, ValueError):
            continue
        names.update(n for n, p in sig.parameters.items()
                     if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and n not in ("self", "cls", "context"))
    return frozenset(names)


def tracker_for(config: RunConfig, params: C80Parameters, *, classes: Mapping[str, type] | None = None):
    """:func:`tracker_of` the config's :class:`LawSpec`."""
    return tracker_of(LawSpec.of(coerced(config)), params, classes=classes)


def tracker_of(law: LawSpec, params: C80Parameters, *, classes: Mapping[str, type] | None = None):
    """A fresh instance of the run's path tracker (:class:`controllers.tracking.PathTracker`), None without one;
    built as :func:`controller_for` builds a plug-in (:func:`controllers.registry.build_plugin`)."""
    tracker, _ = build_plugin(law.tracker, law.tracker_params, kind="tracker", estimate=params, kp=law.kp, kd=law.kd,
                              model_source=law.model, identified=law.identified, coefficients=law.coefficients,
                              cls=(classes or {}).get("tracker"))
    return tracker


def has_tracker(config: RunConfig) -> bool:
    """Whether the run has an outer loop on C (a tracker, or the correction)."""
    return config.tracker is not None or bool(config.correction)


def estimate_of(controller: SteeringController) -> dict[str, float] | None:
    """The coefficients the paper's analysis takes as the law's estimate (P^, C_V^, F^, K^), where the law
    is the paper's family (:meth:`~controllers.computed_torque.ComputedTorque.paper_estimate`); None: the
    paper's (4.2), the estimate anywhere in the box."""
    method = getattr(controller, "paper_estimate", None)
    return method() if callable(method) else None


def config_from_dict(obj: Mapping[str, Any]) -> RunConfig:
    """The RunConfig of ``RunConfig.to_dict()`` (after a JSON round trip: lists back to tuples).

    A plug-in (``controller_plugin``, ``tracker_plugin``) is found again by its name, else by the
    absolute import path the record holds (a file named relative to another folder), and its source
    must be the one recorded.

    Raises:
        ParameterError: a plug-in given as an object (it cannot be rebuilt from JSON), one whose file
            or module is gone, or whose source has changed since the record was written (its SHA-256).
    """
    d = dict(obj)
    d["m1_range"] = tuple(d["m1_range"])  # a record always holds m1 and m1_range, the cart's where not given
    d["box_ranges"] = {k: tuple(v) for k, v in d.get("box_ranges", {}).items()}
    for kind in ("controller", "tracker"):
        record = d.pop(f"{kind}_plugin", None)
        if record is not None:
            d[kind] = _plugin_again(kind, record)
    return RunConfig.from_inputs(**d)


def _plugin_again(kind: str, record: Mapping[str, Any]) -> str:
    """The name a recorded plug-in is found by now, its source checked against the record."""
    if record.get("origin") == "instance":
        raise ParameterError(f"the {kind} {record.get('name')!r} was given as an object "
                             f"({record.get('import_path')}); it cannot be rebuilt from the record: give it by "
                             "name, FILE.py:Class or module:Class to make runs that can be replayed and resumed")
    spec = str(record.get("spec"))
    if record.get("origin") == "file":
        where = spec.rpartition(":")[0]
        if not os.path.isfile(where):
            spec = str(record.get("import_path"))  # the absolute path it was imported from
    params = record.get("params") or {}
    _, now = resolve(spec, params, kind=kind)
    if record.get("source_sha256") and now.source_sha256 != record["source_sha256"]:
        raise ParameterError(f"the {kind} {record.get('name')!r} ({now.import_path}) has changed since it ran: its "
                             f"source's SHA-256 is {str(now.source_sha256)[:12]}..., the record's "
                             f"{str(record['source_sha256'])[:12]}...; restore that source to reproduce the run")
    return spec
