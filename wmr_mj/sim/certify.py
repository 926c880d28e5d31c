"""The certificate of a configured run: :func:`wmr_mj.analysis.certificate.certify` on the plant
box, estimate, gains and reference bounds that a :class:`wmr_mj.sim.config.RunConfig` implies.

Usage::

    from wmr_mj.sim.certify import certificate_for
    from wmr_mj.sim.config import RunConfig, build_reference
    from wmr_mj import C80
    cfg = RunConfig(model="nonholonomic", kp=100.0, kd=20.0, friction_width=0.01)
    cert = certificate_for(cfg, build_reference("paper-circle", C80, dt=1e-3, duration=35.0)[0])
    print(cert.E_max, cert.valid)
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

from controllers.sampled_claim import MAX_SAMPLED_DELAY_PERIODS
from wmr_mj._util.checks import finite_number, interval
from wmr_mj.analysis.certificate import (
    GYRO_BAND,
    GYRO_MEASURED_RATIOS,
    PLANT_K_BAND,
    PLANT_K_MEASURED,
    Assumption,
    Certificate,
    PlantBox,
    PlantLimits,
    derived_box,
    friction_over_P_max,
    replace_inputs,
)
from wmr_mj.analysis.claim import ClaimContext, covers_measurement
from wmr_mj.analysis.delay_split import covers_delay_split
from wmr_mj.analysis.measurement import MeasurementErrors
from wmr_mj.analysis.plant_box import F_OVER_P_NOT_MONOTONE, box_corners
from wmr_mj.analysis.plant_box import hull as _hull
from wmr_mj.analysis.regions import SmallGainRegion
from wmr_mj.analysis.robustness import ParameterBox
from wmr_mj.analysis.verdicts import OUTSIDE_THE_BOX
from wmr_mj.errors import ParameterError
from wmr_mj.hardware import Actuation, Sensing, Transmission
from wmr_mj.params import C80, COEFFICIENT_NAMES, C80Parameters
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.sim.builders import BoxSpec, run_bounds
from wmr_mj.sim.coerce import coerced, delay_split_of
from wmr_mj.sim.config import (
    base_for,
    controller_and_settings,
    controller_for,
    estimate_parameters,
    plant_parameters,
    tracker_for,
)

__all__ = ["certificate_for", "certificate_of", "law_certificate", "measurement_errors", "outside_of",
           "claim_on_estimate", "identified_spread",
           "box_spans", "outside_the_box", "reference_within", "certificate_name",
           "MAX_SAMPLED_DELAY_PERIODS", "section_4_beside"]


def identified_spread(identified: Any) -> dict[str, tuple[float, float]]:
    """{name: (x - 2 sigma, x + 2 sigma)} from `wmr-mj identify` output (path or mapping)."""
    import json
    from pathlib import Path

    data = identified
    if not isinstance(data, Mapping):
        path = Path(identified)
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError):
            raise ParameterError(f"identified-model file {str(path)!r} is not readable JSON from "
                                 "wmr-mj identify") from None
    values = data.get("identified", data)
    se = (data.get("diagnostics") or {}).get("std_error") or {}
    out = {}
    for name in COEFFICIENT_NAMES:
        if name in values:
            x, s = float(values[name]), 2.0 * abs(float(se.get(name, 0.0)))
            out[name] = (x - s, x + s)
    return out


def box_spans(config: Any, base: C80Parameters = C80) -> dict[str, tuple[float, float]]:
    """The box the certificate covers, per plant parameter that the run sets or ranges: m1 over
    config.m1_range, each of config.box_ranges over its range, every other parameter the run
    overrides (--param) at the base value only (the box does not range it). ``config``: a config or its
    :class:`~wmr_mj.sim.builders.BoxSpec`."""
    spans = {"m1": (float(config.m1_range[0]), float(config.m1_range[1]))}
    spans.update({k: (float(v[0]), float(v[1])) for k, v in config.box_ranges.items()})
    for name in config.plant_overrides:
        if name not in spans:
            value = float(getattr(base, name))
            spans[name] = (value, value)
    return spans


def _widen_hint(name: str, value: float, lo: float, hi: float) -> str:
    new_lo, new_hi = min(lo, value), max(hi, value)
    if name == "m1":
        return f"--m1-range {new_lo:g} {new_hi:g}"
    return f"--range {name}={new_lo!r}:{new_hi!r}"


def outside_the_box(config: Any, plant: C80Parameters, base: C80Parameters = C80) -> tuple[Assumption, ...]:
    """:func:`outside_of` the config's box (:class:`~wmr_mj.sim.builders.BoxSpec`)."""
    return outside_of(BoxSpec.of(coerced(config)), plant, base)


def outside_of(box: BoxSpec, plant: C80Parameters, base: C80Parameters = C80) -> tuple[Assumption, ...]:
    """A failed assumption 'plant inside the box' per parameter of the run's plant that lies
    outside the box the certificate covers (:func:`box_spans`); () when the plant is inside.

    The certificate is computed over the declared box only: a run outside it is not covered.
    (Listed only when failed, so the assumptions of a run inside the box are unchanged.)
    """
    out = []
    for name, (lo, hi) in box_spans(box, base).items():
        value = float(getattr(plant, name))
        if lo <= value <= hi:
            continue
        limit = hi if value > hi else lo
        span = f"{lo:g}-{hi:g}" if lo != hi else f"fixed at {lo:g} (not ranged)"
        out.append(Assumption(
            f"{OUTSIDE_THE_BOX}: {name}", f"{name} = {value:g} within the box's {name} {span}", False,
            value, limit, f"the certificate covers the declared box only; to cover this plant, widen the box: "
                          f"{_widen_hint(name, value, lo, hi)}", kind="checked"))
    return tuple(out)


def reference_within(measured: Any, declared: Any) -> Assumption:
    """The assumption "reference within the declared bounds": the run's reference (``measured``,
    its grid's maxima) against the declared :class:`~wmr_mj.reference.bounds.ReferenceBounds`.

    Value and limit are the largest ratio measured/declared over max|alpha0'|, max|alpha0''|,
    max sin/cos^3 and max|alpha0|, against 1 (a declared bound of 0 with a measured one above
    it: inf).
    """
    pairs = (("max|alpha0'|", measured.alpha_dot_max, declared.alpha_dot_max),
             ("max|alpha0''|", measured.alpha_ddot_max, declared.alpha_ddot_max),
             ("max sin/cos^3", measured.sin_cos3_max, declared.sin_cos3_max),
             ("max|alpha0|", measured.angle_max, declared.angle_max))
    ratios = [(m / d if d > 0 else (math.inf if m > 0 else 0.0), name, m, d) for name, m, d in pairs]
    worst, name, m, d = max(ratios)
    return Assumption("reference within the declared bounds",
                      "max|alpha0'|, max|alpha0''|, max sin/cos^3, max|alpha0| of the run's reference <= declared",
                      worst <= 1.0, worst, 1.0,
                      f"largest ratio {name}: {m:.6g} against {d:.6g} declared; the certificate covers every "
                      "reference within the declared bounds", kind="checked")


def certificate_for(config: Any, reference: Any, *, params: C80Parameters = C80,
                    k_band: float = PLANT_K_BAND, gyro_band: tuple[float, float] = GYRO_BAND,
                    measurement: MeasurementErrors | None = None) -> Certificate | None:
    """The certificate of a :class:`wmr_mj.sim.closed_loop.RunConfig` run on ``reference``.

    Plant box: P, C_V, F by the rule of ``simulate.analysis_box``: derived from ``params``
    over config.m1_range and config.box_ranges (both reduced models share P, C_V, F), and
    for config.box = 'paper' hulled with the (5.1) intervals (whose F does not cover the
    simulated m1 range); for model 'identified' hulled with its +-2 sigma. The run's own plant
    is not hulled in: a plant outside the declared box (m1 outside config.m1_range, a ranged
    parameter outside its range, a --param override of a parameter the box does not range)
    fails the assumption 'plant inside the box' (:func:`outside_the_box`), so the run is
    uncertified. The plant's K is not the
    paper's (2.7) prediction (the plant has none): |K| <= k_band (:data:`PLANT_K_BAND`,
    measured). gyro: gyro_band x P/l1 over the box (:data:`GYRO_BAND`, measured), V_A
    over the box's range. Estimate: the controller as ``simulate`` builds it (the same
    ``controller_for`` on ``estimate_parameters(params)``). params: the base parameter set.

    Reference: the declared bounds (config.reference_bounds) where given, with the assumption
    "reference within the declared bounds" (:func:`reference_within`) checked on ``reference``;
    else ``reference.bounds()``, the run's own (a certificate for that reference alone).

    Signals (config.signals, :mod:`wmr_mj.sim.signals`): the declared disturbance bound d_max
    [N m] enters delta1 as d_V,max = d_max max(R_a)/min(k_i i2) over the box and the run's plant
    (:func:`disturbance_voltage`); the assumption "disturbance within the bound" (the signal's
    max|d| against d_max) is added, and with load changes "load inside the box" (every m1 they
    set against the box's m1 range; the initial m1 is the plant's, checked as every run's by
    :func:`outside_the_box`). A run without signals gets neither.

    Tracker (config.tracker, or config.correction): the claim is computed for the bounds the tracker
    declares for the reference it writes (measured on every run: ``controllers.tracking.within_declared``),
    with the assumptions it states.

    Measurement (``measurement``, :class:`~wmr_mj.analysis.measurement.MeasurementErrors`): None, the cart's own
    (:func:`measurement_errors_of` on config.sensing, actuation and transmission; exact on the ideal cart, every
    number as before), and then, on a cart that is not ideal, a law with a sampled-data analysis (the computed-torque
    and sliding-mode laws and their subclasses) computes it beside its own claim and takes the certified one with the
    smaller E_max (``ClaimContext.sampled_data``; it is derived from the cart's parts, not from summed bounds);
    given, those bounds in place of the cart's (a what-if), and the law's continuous claim alone. Handed
    to the claim as ``ClaimContext.measurement``; the computed-torque, PD and sliding-mode claims absorb the
    bounds, and a claim that does not state the assumption 'sensing and actuation covered' gets it unmet
    (:func:`wmr_mj.analysis.claim.covers_measurement`).

    Returns:
        The controller's claim (``SteeringController.claim``: the section-4 certificate for the
        computed-torque and PD laws) with the run's inputs recorded; None where the law states none.
    """
    config = coerced(config)  # a config given directly: its references read here
    params = base_for(config, params)  # the config's cart, where it names one
    estimate_params = estimate_parameters(params)
    return certificate_of(config, reference, base=params, estimate=estimate_params,
                          plant=plant_parameters(config, params), controller=controller_for(config, estimate_params),
                          tracker=tracker_for(config, estimate_params), k_band=k_band, gyro_band=gyro_band,
                          measurement=measurement)


def claim_on_estimate(parts: Any, model: str) -> Certificate | None:
    """The claim the run's law would state on another estimate: the law of ``parts`` (a resolved run,
    :class:`wmr_mj.sim.parts.RunParts`) built on the model source ``model`` (one new law, built once), its
    claim computed on the run's reference, plant, belief and tracker.

    Raises:
        WmrMjError: what the law on that estimate cannot build or claim.
    """
    config = parts.config.replace(model=model)
    controller, _ = controller_and_settings(config, parts.estimate)
    return certificate_of(config, parts.reference, base=parts.base, estimate=parts.estimate, plant=parts.plant,
                          controller=controller, tracker=parts.tracker)


def measurement_errors_of(config: Any, plant: C80Parameters) -> MeasurementErrors:
    """What the run's law reads instead of the true state, as the certificates take it:
    :func:`measurement_errors` of the config's cart parts (sensing, actuation, transmission) and control period."""
    config = coerced(config)  # a config given directly: its parts typed here
    return measurement_errors(config.sensing, config.actuation, config.transmission, plant,
                              period=config.control_period if config.control_period is not None else TIMESTEP)


def measurement_errors(sensing: Sensing, actuation: Actuation, transmission: Transmission, plant: C80Parameters, *,
                       period: float) -> MeasurementErrors:
    """What the run's law reads instead of the true state, as the certificates take it
    (:mod:`wmr_mj.analysis.measurement`),
    from the cart as it is built: the sum of each part's own coverage (``sensing.coverage``,
    ``transmission.coverage``, ``actuation.coverage``; :class:`wmr_mj.hardware.Coverage`); ``period``: the
    control period [s].

    Bounded, and so covered: the encoder's quantisation, a uniform noise, a differenced or filtered velocity's
    error (:func:`wmr_mj.hardware.sensing.measurement_error_bounds`); its lag, the sensing delay and the
    actuation delay are charged together as one delay (a lag on alpha' alone is within a delay of both).
    Not covered (the certificate is then uncertified, saying why): Gaussian noise, the play with the encoder
    on the steering axis (it lies between the motor and the measured angle, on the actuator's side), the
    play with the encoder on the motor side (the motor angle / i2 would be within b of alpha with a rigid
    stop, but MuJoCo's stop is a soft limit pressed in under torque: measured 0.00554 rad against b +
    Delta/i2 = 0.005013 rad, docs/guides/hardware.md, and no sound bound of its penetration is derived), the
    current limit (the proof's motor has none). The armature inductance (the actuation's, else the plant's L_a) is
    bounded: its L_a/R_a is ``electrical_time_constant_s``, which only the sampled-data certificate holds.

    Returns:
        :meth:`MeasurementErrors.exact` for an ideal cart (every number as before).
    """
    actuation = actuation.on_motor(L_a=plant.L_a)  # the cart's armature inductance where the run sets none
    if sensing.is_ideal and actuation.is_ideal and transmission.is_ideal:
        return MeasurementErrors.exact()
    # each part declares its coverage (wmr_mj.hardware.coverage); the play's rigid-stop b enters the sensor's
    # bounds where the encoder reads the motor shaft
    play = transmission.coverage(encoder_on_motor=sensing.reads_motor_side)
    sensed = sensing.coverage(control_period=period, gear_ratio=plant.i2, play=play.alpha_error)
    driven = actuation.coverage(R_a=plant.R_a)
    why = sensed.why_not + play.why_not + driven.why_not
    return MeasurementErrors(alpha_error_max=sensed.alpha_error, alpha_dot_error_max=sensed.alpha_dot_error,
                             delay_s=sensed.delay + driven.delay + sensed.lag,  # in this order: the same double
                             covered=not why, why_not="; ".join(why) or None,
                             electrical_time_constant_s=driven.electrical_time_constant)


def certificate_of(config: Any, reference: Any, *, base: C80Parameters, estimate: C80Parameters,
                   plant: C80Parameters, controller: Any, tracker: Any, k_band: float = PLANT_K_BAND,
                   gyro_band: tuple[float, float] = GYRO_BAND,
                   measurement: MeasurementErrors | None = None,
                   cart_measurement: MeasurementErrors | None = None) -> Certificate | None:
    """:func:`certificate_for` on parts already resolved (:func:`wmr_mj.sim.parts.resolve_run`): the plant's
    parameters, the controller's belief, the law and the tracker of the run. ``cart_measurement``: the cart's own
    errors (:func:`measurement_errors_of`), already derived: taken as ``measurement`` None takes them.
    :func:`law_certificate` on the config's box, period, signals, declared bounds and cart parts."""
    config = coerced(config)  # a config given directly (a batch's further runs): typed here
    derived = measurement is None
    if measurement is None:  # cart_measurement: the cart's own, already derived (resolve_run's), not derived again
        measurement = measurement_errors_of(config, plant) if cart_measurement is None else cart_measurement
    return law_certificate(reference, controller=controller, tracker=tracker, box=BoxSpec.of(config), base=base,
                           estimate=estimate, plant=plant,
                           period=config.control_period if config.control_period is not None else TIMESTEP,
                           signals=getattr(config, "signals", None), declared_bounds=config.reference_bounds,
                           sensing=config.sensing, actuation=config.actuation, transmission=config.transmission,
                           steering_friction=getattr(config, "steering_friction", None), measurement=measurement,
                           sampled_data=derived, k_band=k_band, gyro_band=gyro_band,
                           delay_split=delay_split_of(config.cart))


def law_certificate(reference: Any, *, controller: Any, tracker: Any, box: BoxSpec, base: C80Parameters,
                    estimate: C80Parameters, plant: C80Parameters, period: float, signals: Any,
                    declared_bounds: Any, sensing: Sensing, actuation: Actuation, transmission: Transmission,
                    steering_friction: str | None, measurement: MeasurementErrors, sampled_data: bool,
                    k_band: float = PLANT_K_BAND, gyro_band: tuple[float, float] = GYRO_BAND,
                    delay_split: str = "known") -> Certificate | None:
    """The law's claim (``controller.claim``) on the run's typed parts, with the run's inputs recorded: what
    :func:`certificate_for` computes, from what :func:`wmr_mj.sim.parts.resolve_run` resolved once.

    Args:
        reference: C's reference on the control grid; declared_bounds: the reference bounds the run declares
            (None: the reference's own).
        controller, tracker: the run's law and path tracker (None without one).
        box: the declared parameter box (:class:`~wmr_mj.sim.builders.BoxSpec`); base, estimate, plant: the
            base parameter set, the controller's belief and the run's plant.
        period: the control period [s]; signals: the run's :class:`~wmr_mj.sim.signals.Signals` or None.
        sensing, actuation, transmission: the cart's parts; measurement: the bounds the claim takes
            (:func:`measurement_errors`); sampled_data: they are the cart's own, derived from those parts.
        steering_friction: the plant's steering friction law, as the inputs record it.
        k_band [V], gyro_band: the plant K and gyro bands (:data:`PLANT_K_BAND`, :data:`GYRO_BAND`).
        delay_split: how the sensing and actuation delays divide (:func:`delay_split_of` the run's cart): 'unknown'
            makes a sampled-data certificate cover every split of their sum.
    """
    k_band = finite_number("k_band", k_band, minimum=0.0)
    gyro_band = interval("gyro_band", gyro_band, positive=True)
    ranges = {k: (float(v[0]), float(v[1])) for k, v in box.box_ranges.items()}
    m1_range = (float(box.m1_range[0]), float(box.m1_range[1]))
    # what the run states, read from its own parts first; then the box the claim covers, down in the analysis
    stated = _stated_assumptions(k_band, gyro_band) + outside_of(box, plant, base)
    if signals is not None:
        stated = stated + tuple(_signal_assumptions(signals, plant.m1, m1_range))
    bounds = run_bounds(reference, declared_bounds)
    if declared_bounds is not None:
        stated = stated + (reference_within(reference.bounds(), declared_bounds),)
    if tracker is not None:
        # the reference the law receives is the tracker's: the claim is computed for the bounds it
        # declares, which every run measures (controllers.tracking.within_declared)
        bounds = tracker.declared_bounds(bounds)
        stated = stated + tracker.stated_assumptions()
    initial = (float(reference.alpha0[0]), float(reference.alpha0_dot[0]))  # the plant starts at alpha = alpha' = 0
    plant_box, notes = _plant_box(box, base, estimate, ranges, k_band, gyro_band)
    if signals is not None:
        plant_box = _with_disturbance(box, signals, plant_box, estimate, plant, ranges)
    context = ClaimContext(plant=plant_box, reference=bounds,
                           limits=PlantLimits(steering_range=plant.steering_range, voltage_limit=plant.voltage_limit),
                           control_period=period, initial_error=initial, stated=stated, estimate=estimate,
                           measurement=measurement, sensing=sensing, actuation_delay=actuation.delay,
                           gear_ratio=plant.i2, play=transmission.backlash, delay_split=delay_split,
                           sampled_data=sampled_data)
    try:
        cert = controller.claim(context)
    except Exception as exc:  # noqa: BLE001  (any error of a law's own claim: one line naming the law, before any step)
        raise ParameterError(f"controller {controller.name!r}: claim() raised {type(exc).__name__}: {exc}; a claim "
                             "returns a Certificate (see wmr_mj.analysis.claim.box_claim) or None") from None
    if cert is None:
        return None
    if not isinstance(cert, Certificate):
        raise ParameterError(f"controller {controller.name!r}: claim() returned {type(cert).__name__}, not a "
                             "Certificate (see wmr_mj.analysis.claim.box_claim) or None")
    cert = covers_measurement(cert, measurement)
    if delay_split == "unknown" and sampled_data:  # the cart's own delay, known as its sum: every split, or unmet
        total = round((sensing.delay + actuation.delay) / period)
        cert = covers_delay_split(cert, total_periods=total, control_period=period)
    inputs = dict(cert.inputs)
    inputs.update(model=box.model, controller=controller.name, box_rule=box.box,
                  m1_range=list(box.m1_range), box_ranges={k: list(v) for k, v in ranges.items()},
                  plant_m1=plant.m1, notes=notes, steering_friction=steering_friction)
    if signals is not None:
        inputs.update(signals=signals.to_dict(), d_max=signals.declared_d_max)
    return replace_inputs(cert, inputs)


def certificate_name(cert: Certificate) -> str:
    """Which analysis gave ``cert``: ``inputs['certificate']`` where the run computed two (the law's claim beside
    the sampled-data certificate, :func:`controllers.sampled_claim.with_sampled_data`), else the analysis the law
    named (:attr:`Certificate.analysis`: 'section-4', 'boundary-layer'), 'section-4' where it named none."""
    return str(cert.inputs.get("certificate", cert.analysis or "section-4"))


def _plant_box(spec: BoxSpec, base: C80Parameters, estimate_params: C80Parameters,
               ranges: Mapping[str, tuple[float, float]], k_band: float,
               gyro_band: tuple[float, float]) -> tuple[PlantBox, list[str]]:
    """The plant box of :func:`law_certificate` (no disturbance yet) and its notes."""
    # an identified model's +-2 sigma, read before the box is derived down in the analysis
    spread: dict[str, Any] = identified_spread(spec.identified) if spec.model == "identified" else {}
    derived = derived_box(estimate_params, tuple(float(v) for v in spec.m1_range), spec.m1_inertia,
                          tuple(sorted(ranges.items())))
    box = ParameterBox.paper() if spec.box == "paper" else derived
    P = _hull(box.P, *derived.P)
    C_V = _hull(box.C_V, *derived.C_V)
    F = _hull(box.F, *derived.F)
    K = (-k_band, k_band)
    l1_lo, l1_hi = ranges.get("l1", (base.l1, base.l1))
    gyro = (gyro_band[0] * P[0] / l1_hi, gyro_band[1] * P[1] / l1_lo)
    V_A = ranges.get("V_A", (base.V_A, base.V_A))
    notes = []
    if spec.model == "identified":
        P = _hull(P, *spread.get("P", P))
        C_V = _hull(C_V, *spread.get("C_V", C_V))
        F = _hull(F, *spread.get("F", F))
        K = _hull(K, *spread.get("K", K))
        gyro = _hull(gyro, *spread.get("gyro", gyro))
        notes.append("identified +-2 sigma hulled in")
    plant_box = ParameterBox(P=P, C_V=C_V, F=(max(F[0], 0.0), F[1]), K=K)
    # F and P both scale with R_a: bound F/P over the same plants
    ratio = friction_over_P_max(estimate_params, tuple(float(v) for v in spec.m1_range), spec.m1_inertia,
                                tuple(sorted(ranges.items())))
    if ratio is not None:
        if spec.model == "identified" and "F" in spread and "P" in spread:
            ratio = max(ratio, spread["F"][1] / spread["P"][0])
        if spec.box == "paper":
            ratio = None  # (5.1)'s printed intervals come with no such relation
    return PlantBox(box=plant_box, gyro=gyro, V_A=V_A, friction_over_P=ratio, disturbance=0.0,
                    disturbance_over_P=None), notes


def _stated_assumptions(k_band: float, gyro_band: tuple[float, float]) -> tuple[Assumption, ...]:
    """The measured plant K and gyro bands, each against the data behind it."""
    k_seen = max(abs(v) for v in PLANT_K_MEASURED)
    g_lo, g_hi = GYRO_MEASURED_RATIOS
    g_used = max((1.0 - g_lo) / (1.0 - gyro_band[0]) if gyro_band[0] < 1.0 else math.inf,
                 (g_hi - 1.0) / (gyro_band[1] - 1.0) if gyro_band[1] > 1.0 else math.inf)
    return (
        Assumption("plant K band", f"|K_plant| <= {k_band:g} V (non-holonomic plant: K = 0)",
                   k_seen <= k_band, k_seen, k_band,
                   "MuJoCo identify K = -0.0052 +- 0.0016 V; Drake 0.018 V at 1e7 N/m (physics.md section 6)",
                   kind="stated"),
        Assumption("plant gyro band", f"{gyro_band[0]:g} P/l1 <= gyro <= {gyro_band[1]:g} P/l1",
                   g_used <= 1.0, g_used, 1.0,
                   "fraction of the band used by measurements: MuJoCo identify seeds 0-5 0.492-0.704 V s/m "
                   "(0.78-1.12 P/l1), Drake 0.621-0.644 (physics.md section 6)", kind="stated"),
    )


def _with_disturbance(box: BoxSpec, signals: Any, plant_box: PlantBox, estimate_params: C80Parameters,
                      plant: C80Parameters, ranges: Mapping[str, tuple[float, float]]) -> PlantBox:
    """The plant box with the signals' declared disturbance bound in it."""
    d_V = disturbance_voltage(signals.declared_d_max, plant, ranges)
    d_over_P = None
    m1_range = (float(box.m1_range[0]), float(box.m1_range[1]))
    if d_V and box.box != "paper":  # (5.1)'s printed P interval comes with no inertia behind it
        d_over_P = disturbance_over_P_max(signals.declared_d_max, estimate_params, plant, m1_range,
                                          box.m1_inertia, tuple(sorted(ranges.items())))
    return dataclasses.replace(plant_box, disturbance=d_V, disturbance_over_P=d_over_P)


def disturbance_voltage(d_max: float, plant: C80Parameters, ranges: Mapping[str, tuple[float, float]]) -> float:
    """d_V,max [V] = d_max max(R_a)/min(k_i i2): a steering torque bound [N m] as a voltage, over the box.

    R_a, k_i, i2 over their box ranges, hulled with the run's plant (``plant``); the factor of
    :meth:`wmr_mj.params.C80Parameters.steering_torque_voltage`.
    """
    if not d_max:
        return 0.0
    R_a = _hull(ranges.get("R_a", (plant.R_a, plant.R_a)), plant.R_a)[1]
    k_i = _hull(ranges.get("k_i", (plant.k_i, plant.k_i)), plant.k_i)[0]
    i2 = _hull(ranges.get("i2", (plant.i2, plant.i2)), plant.i2)[0]
    if k_i <= 0 or i2 <= 0:
        raise ParameterError(f"k_i = {k_i:g}, i2 = {i2:g}: the disturbance bound needs k_i, i2 > 0 over the box")
    return float(d_max) * R_a / (k_i * i2)


def disturbance_over_P_max(d_max: float, params: C80Parameters, plant: C80Parameters, m1_range: tuple[float, float],
                           m1_inertia: str, ranges: tuple[tuple[str, tuple[float, float]], ...]) -> float | None:
    """max d_V/P [rad/s^2] = d_max/min(2D) over the box's plants and the run's ``plant``.

    d_V/P = (R_a d/(k_i i2)) / ((R_a/k_i) 2D/i2) = d/(2D): R_a, k_i, i2 cancel and 2D, the steering's
    inertia, does not depend on m1 or any other parameter but the geometry and masses of
    :data:`wmr_mj.analysis.plant_box.F_OVER_P_NOT_MONOTONE`; with one of those ranged, None.
    """
    if any(name in F_OVER_P_NOT_MONOTONE for name, _ in ranges):
        return None
    corners = list(box_corners(params, m1_range, m1_inertia, ranges))
    worst = plant.steering_torque_voltage(d_max) / plant.coefficients("nonholonomic").P
    for p in corners:
        worst = max(worst, p.steering_torque_voltage(d_max) / p.coefficients("nonholonomic").P)
    return worst


def _signal_assumptions(signals: Any, m1: float, m1_box: tuple[float, float]) -> tuple[Assumption, ...]:
    """The assumptions a run with signals adds: its disturbance within d_max; with load changes, every
    m1 they set inside the box's m1 range (the initial m1, the plant's, is :func:`outside_the_box`'s)."""
    d_max = signals.declared_d_max
    d = signals.disturbance.bound if signals.disturbance is not None else 0.0
    out = [Assumption("disturbance within the bound", "max|d| <= d_max (declared; enters delta1 as R_a d_max/(k_i i2))",
                      d <= d_max, d, d_max, "N m on the steering joint", kind="checked")]
    values = [v for _, v in signals.load_steps(m1)]
    if values:
        lo, hi = m1_box
        # the value farthest outside the box (else the one nearest an edge), with that edge
        worst = max(values, key=lambda v: max(lo - v, v - hi))
        edge = lo if (lo - worst) > (worst - hi) else hi
        out.append(Assumption("load inside the box", f"{lo:g} <= m1 <= {hi:g} kg at every load change",
                              all(lo <= v <= hi for v in values), worst, edge,
                              f"m1 from {m1:g} kg, then " + ", ".join(f"{v:g}" for v in values) + " kg",
                              kind="checked"))
    return tuple(out)


def section_4_beside(parts: Any, cert: Certificate) -> Certificate | None:
    """Section 4's certificate of a run whose claim taken, ``cert``, is the sampled-data certificate and records
    section 4's beside it (issue 44: the paper's analysis, a second opinion): the law's continuous claim alone, as
    :func:`certificate_of` gives it for the cart's own measurement as a what-if; else None.

    Args:
        parts: the run's resolved parts (:class:`wmr_mj.sim.parts.RunParts`): its config, reference, parameter
            sets, law and tracker.
    """
    if "section-4" not in (cert.inputs.get("certificates") or {}):
        return None
    config = parts.config
    alone = certificate_of(config, parts.reference, base=parts.base, estimate=parts.estimate, plant=parts.plant,
                           controller=parts.controller, tracker=parts.tracker,
                           measurement=measurement_errors_of(config, parts.plant))
    return alone if alone is not None and isinstance(alone.region, SmallGainRegion) else None
