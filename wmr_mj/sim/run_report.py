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

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from wmr_mj.analysis.claim_types import MeasurementCause
from wmr_mj.hardware import cart_dict
from wmr_mj.sim.coerce import controller_source

if TYPE_CHECKING:
    from wmr_mj.sim.summary import RunSummary

__all__ = ["run_report", "measurement_cause", "add_controller_source"]


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
