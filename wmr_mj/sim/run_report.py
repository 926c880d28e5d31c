"""A run's JSON: what ``wmr-mj run --json`` prints, assembled from its result (:meth:`RunResult.to_dict`).

The summary's keys (:meth:`wmr_mj.sim.summary.RunSummary.to_dict`), then ``log``, the requirements judged on the
run where any were given, the measurement errors its claim assumed, the signals that acted on the plant (every
parameter: ``--signals`` takes them back), where the law comes from (a plug-in's source) and the cart's parts that
are not ideal. The CLI prints it; a notebook gets the same dict.

Usage::

    from wmr_mj.sim.closed_loop import run_parts
    from wmr_mj.sim.parts import resolve_run

    parts = resolve_run(config)
    report = run_parts(parts).to_dict(measurement=parts.measurement)  # calls run_report
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from controllers.registry import PluginSource
from wmr_mj.analysis.claim_types import MeasurementCause
from wmr_mj.hardware import CART_PARTS, Actuation, Sensing, Transmission, cart_dict
from wmr_mj.sim.coerce import controller_source
from wmr_mj.sim.run_config import RunConfig
from wmr_mj.sim.signals import Signals
from wmr_mj.sim.summary import RunSummary

__all__ = ["run_report", "measurement_cause", "add_controller_source", "summary_of_report", "config_of_report"]

#: Each cart part's type, by its key in a run's JSON (:func:`wmr_mj.hardware.cart_dict`).
_PART_TYPES: Mapping[str, Any] = {"sensing": Sensing, "actuation": Actuation, "transmission": Transmission}


def measurement_cause(s: RunSummary, measurement: Any = None) -> MeasurementCause | None:
    """The measurement errors the run's certificate assumed, and which binds
    (:class:`~wmr_mj.analysis.claim_types.MeasurementCause`); None on an ideal cart or for another claim.

    Args:
        s: the run's summary.
        measurement: the run's :class:`~wmr_mj.analysis.measurement.MeasurementErrors` (``RunParts.measurement``):
            where the claim taken is the sampled-data certificate (it has a bound, so nothing binds), the errors it
            assumed are these.
    """
    judged = s.certificate
    terms = None if judged is None else judged.certificate.terms
    if terms is not None:
        return terms.measurement_cause
    sampled = judged is not None and judged.certificate.inputs.get("certificate") == "sampled-data"
    if not sampled or measurement is None or measurement.is_exact:
        return None
    return MeasurementCause(e_a=measurement.alpha_error_max, e_v=measurement.alpha_dot_error_max,
                            tau=measurement.delay_s)


def add_controller_source(out: dict[str, Any], config: Any) -> dict[str, Any]:
    """``out`` with ``controller_source``: where the run's law comes from, as its MCAP log records it
    (:class:`controllers.registry.PluginSource`: spec, name, origin, import path of the file or module and
    class, parameters, the SHA-256 of its source), for every law but those built from the config's fields
    (computed-torque, pd), whose JSON keeps the keys it always had. The JSON of run, sweep and falsify."""
    source = controller_source(config)
    if source is not None:
        out["controller_source"] = source
    return out


def run_report(result: Any, *, measurement: Any = None, log: str | None = None,
               judged: Sequence[Any] = ()) -> dict[str, Any]:
    """The run's JSON (``wmr-mj run --json``; :meth:`wmr_mj.sim.closed_loop.RunResult.to_dict` judges the
    requirements and calls this).

    Args:
        result: the run (:class:`~wmr_mj.sim.closed_loop.RunResult`, which imports this module).
        measurement: the run's measurement errors (``RunParts.measurement``), as :func:`measurement_cause` takes them.
        log: the run's MCAP log, or None (the JSON's ``log``).
        judged: the requirements judged on the run (:func:`wmr_mj.sim.closed_loop.judge_requirements`); none: no
            ``requirements`` key.

    Returns:
        dict: the summary's keys, ``log``, then ``requirements``, ``measurement_errors``, ``signals``,
        ``controller_source`` and the cart's parts where each applies.
    """
    config = result.config
    rows = [r.to_dict() for r in judged]
    report = {**result.summary.to_dict(), "log": log, **({"requirements": rows} if rows else {})}
    cause = measurement_cause(result.summary, measurement)
    if cause is not None:  # the errors the claim assumed, and which keeps its fixed point open (an ideal cart: none)
        report["measurement_errors"] = cause.to_dict()
    if config.signals is not None:
        report["signals"] = config.signals.to_dict()  # every parameter: --signals takes it back
    add_controller_source(report, config)
    report.update(cart_dict(config))  # the parts that are not ideal: an ideal run's JSON keeps its keys
    return report


def summary_of_report(report: Mapping[str, Any]) -> RunSummary:
    """The run's summary of its JSON ``report`` (:func:`run_report`): :meth:`RunSummary.from_dict`, with the
    measurement errors its section-4 certificate assumed (``measurement_errors``) given back to its terms (a
    claim without those terms, the sampled-data certificate, took them from the run's measurement errors, which
    the JSON does not hold whole: they are not restored there)."""
    certificate = report.get("certificate")
    errors = report.get("measurement_errors")
    with_terms = certificate is not None and "friction_term" in certificate
    cause = MeasurementCause.from_dict(errors) if errors is not None and with_terms else None
    return RunSummary.from_dict(report, measurement_cause=cause)


def config_of_report(report: Mapping[str, Any]) -> RunConfig:
    """What a run's JSON ``report`` (:func:`run_report`) records of its config, as a RunConfig (plain data:
    nothing read, nothing imported): the law (a plug-in's spec, parameters and source record), model, m1, K_P,
    K_D, path, duration, signals and the cart's parts that are not ideal. Every other field (the cart, the
    control period, the box, the plant's overrides, ...) is not in the JSON and takes its default; a setting the
    law does not read (null in the JSON) too."""
    source = report.get("controller_source")
    plugin = None if source is None else PluginSource(**source)
    fields: dict[str, Any] = {"controller": report["controller"] if plugin is None else plugin.spec,
                              "controller_params": {} if plugin is None else dict(plugin.params),
                              "controller_plugin": plugin, "model": report["model"], "m1": report["m1"],
                              "path": report["path"], "duration": report["duration"]}
    fields.update({k: report[k] for k in ("kp", "kd") if report[k] is not None})
    if report.get("signals") is not None:
        fields["signals"] = Signals.from_dict(report["signals"])
    fields.update({name: _PART_TYPES[name].from_spec(report.get(name)) for name in CART_PARTS})  # absent: ideal
    return RunConfig(**fields)
