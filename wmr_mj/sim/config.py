"""What defines a closed-loop run, and what follows from it before any step: one import for the three modules
that hold them.

- :mod:`wmr_mj.sim.run_config`: :class:`RunConfig`, data (constructing or replacing one reads nothing);
- :mod:`wmr_mj.sim.coerce`: the coercer, the one place a config reads a file or imports user code
  (``RunConfig.from_inputs``, ``resolve_run``), and what a typed config's cart and plug-ins give;
- :mod:`wmr_mj.sim.builders`: the controller's belief, the law, the tracker, the reference, the analysis.

Usage::

    from wmr_mj.sim.config import RunConfig, build_reference, coerce, controller_for, estimate_parameters
    config = RunConfig(model="nonholonomic", kp=100.0, kd=20.0, m1=700.0)
    controller = controller_for(config, estimate_parameters())
    reference, settle_s = build_reference(coerce(config).path, estimate_parameters(), dt=1e-3, duration=35.0)
"""

from __future__ import annotations

from wmr_mj.sim.builders import (
    LAW_SETTINGS,
    REFERENCE_CACHE_SIZE,
    analysis_box,
    analysis_for,
    build_reference,
    config_from_dict,
    controller_and_settings,
    controller_for,
    declared_parameters,
    estimate_of,
    estimate_parameters,
    has_tracker,
    manoeuvre_length,
    reference_bounds_of,
    tracker_for,
)
from wmr_mj.sim.coerce import (
    PATH_NAMES,
    base_for,
    cart_file,
    check_motor_constant,
    coerce,
    controller_name,
    controller_source,
    default_model,
    plant_parameters,
    plugin_source,
)
from wmr_mj.sim.run_config import RunConfig

__all__ = [
    "PATH_NAMES",
    "RunConfig",
    "coerce",
    "plant_parameters",
    "estimate_parameters",
    "controller_for",
    "controller_and_settings",
    "declared_parameters",
    "LAW_SETTINGS",
    "REFERENCE_CACHE_SIZE",
    "tracker_for",
    "has_tracker",
    "plugin_source",
    "controller_name",
    "controller_source",
    "default_model",
    "config_from_dict",
    "estimate_of",
    "build_reference",
    "manoeuvre_length",
    "analysis_box",
    "analysis_for",
    "reference_bounds_of",
    "base_for",
    "cart_file",
    "check_motor_constant",
]
