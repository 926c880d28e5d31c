"""A controller's claim: what a steering law promises about |E| and |E'|, and what the run gives it to work with.

Every controller may state a claim: a bound on the tracking error with the assumptions it rests
on (:meth:`controllers.base.SteeringController.claim`). The testbed hands it a
:class:`ClaimContext` (the plant box the run declares, the bounds of the reference the law will
receive, the plant's limits, the control period, the initial error, and the assumptions the run
itself brings: plant inside the box, signals within their bounds, reference within the declared
bounds, a tracker within its declared limits) and judges the run against what comes back, a
:class:`~wmr_mj.analysis.certificate.Certificate`, exactly as it judges the computed-torque law's
section-4 certificate:

* ``certified-inside``: every assumption holds and (sup|E|, sup|E'|) lies in the claimed region;
* ``certified-outside``: the assumptions hold and the run is outside (the claim is wrong for this
  plant, or the plant is not what the claim assumes: printed loudly);
* ``uncertified-*``: an assumption fails; never a pass;
* no claim at all (the law states none): the run has no verdict, only its requirements
  (``--require``); it is never a pass.

The computed-torque and PD laws claim the section-4 certificate
(:func:`wmr_mj.analysis.certificate.certify`). A law with a simpler guarantee, such as a
sliding-mode law's boundary layer |E| <= phi/lambda, states it with :func:`box_claim`: a
:class:`~wmr_mj.analysis.regions.BoxRegion` |E| <= E_max, |E'| <= Edot_max, with its own assumptions
beside the run's. Both share this module's :func:`fixed_point` (the reachable angle) and the four
assumptions of :func:`shared_assumptions`, each worded by the claim that states it.

Usage::

    from wmr_mj.analysis.claim import box_claim, run_assumptions
    def claim(self, context):
        E_max = self.phi / self.lam
        return box_claim(claimant=self.name, E_max=E_max, Edot_max=2 * self.phi, context=context,
                         alpha_max=context.reference.alpha_max + E_max, voltage_max=..., own=(...))
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple

from wmr_mj.analysis.claim_types import Assumption, Certificate, ClaimInputs
from wmr_mj.analysis.delay_split import DELAY_SPLITS
from wmr_mj.analysis.measurement import MEASUREMENT_COVERED, MeasurementErrors, coverage_assumption_fields
from wmr_mj.analysis.plant_box import PlantBox, PlantLimits
from wmr_mj.analysis.regions import BoxRegion
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware.sensing import Sensing
from wmr_mj.params import C80Parameters
from wmr_mj.reference.bounds import ReferenceBounds

__all__ = ["ClaimContext", "box_claim", "run_assumptions", "RunAssumptions", "shared_assumptions", "fixed_point",
           "with_measured", "covers_measurement", "best_certificate", "replace_inputs", "SAMPLED_DATA_NAME",
           "INITIAL_TOLERANCE", "least_fixed_point", "tangent_reason", "SAMPLING_BOUNDED"]

#: The tolerance on |E(0)|, |E'(0)| of the assumption 'zero initial error' (the reference's rounding at t = 0).
INITIAL_TOLERANCE = 1e-9
_FIXED_POINT_ITERATIONS = 10000
#: The sampled-data certificate's name in a run's ``inputs['certificate']`` and ``inputs['certificates']``.
SAMPLED_DATA_NAME = "sampled-data"
#: The assumption a sampled law's continuous claim carries, unmet, where no sampled-data certificate was computed.
SAMPLING_BOUNDED = "sampling bounded"


@dataclass(frozen=True, kw_only=True)
class ClaimContext:
    """What a run gives a controller's claim (:meth:`controllers.base.SteeringController.claim`).

    Attributes:
        plant: the plants the run declares (P [V s^2/rad], C_V [V s/rad], F [V], K [V] ranges,
            gyro [V s/m], V_A [m/s], the disturbance bound d_V,max [V]): the box the claim must cover.
        reference: bounds of the reference the law receives (max|alpha0| [rad], max|alpha0'|
            [rad/s], max|alpha0''| [rad/s^2], max sin/cos^3): the declared ones where the run
            declares them, widened by a tracker's declared limits where one runs.
        limits: the plant's steering stops [rad] and supply [V].
        control_period: the law's period [s].
        initial_error: (E(0) [rad], E'(0) [rad/s]) of the run.
        stated: the assumptions the run brings (each checked against the run, or stated with its
            source); a claim appends them to its own.
        estimate: the controller's belief, the nominal parameter set.
        measurement: bounds on what the law reads instead of the true state and its delay
            (:class:`~wmr_mj.analysis.measurement.MeasurementErrors`; default exact, today's runs). A claim
            that does not absorb them must not cover the run: :func:`covers_measurement`.
        sensing: the sensor itself (:class:`~wmr_mj.hardware.Sensing`: encoder ticks, side, rounding, noise,
            the velocity estimate, its delay [s]), whose stages ``measurement`` sums; a claim that analyses
            its own loop reads it (:func:`wmr_mj.analysis.linear_part_bounds`). Default: ideal.
        actuation_delay: the actuator's delay [s] (:class:`~wmr_mj.hardware.Actuation`), between the law's
            voltage and the motor.
        gear_ratio: i2 of the run's plant (a motor-side encoder's step at the axis is 2 pi / (N i2)); None:
            the estimate's.
        play: the gear's play b [rad at the axis] (0 without play; never covered today: see ``measurement``).
        delay_split: how the sensing delay and ``actuation_delay`` divide: 'known' (as given), or 'unknown' (a
            cart identified from controller-side recordings: only their sum is measured), and then a sampled-data
            certificate covers every split of the whole periods (:mod:`wmr_mj.analysis.delay_split`).
        sampled_data: whether ``measurement`` is the cart's own, derived from its parts (``sensing``,
            ``actuation_delay``, ``play``): a law with a sampled-data analysis then computes it beside its
            continuous claim and is judged by it (:func:`best_certificate`), on the ideal cart too (exact
            sensing, no delay, the run's control period: the zero-order hold is bounded, not assumed away);
            False where the bounds are a what-if that the parts do not describe (or the run computes no such
            analysis).
    """

    plant: PlantBox
    reference: ReferenceBounds
    limits: PlantLimits
    control_period: float
    initial_error: tuple[float, float]
    stated: tuple[Assumption, ...] = ()
    estimate: C80Parameters
    notes: Mapping[str, Any] = field(default_factory=dict)
    measurement: MeasurementErrors = field(default_factory=MeasurementErrors.exact)
    sensing: Sensing = field(default_factory=Sensing)
    actuation_delay: float = 0.0
    gear_ratio: float | None = None
    play: float = 0.0
    delay_split: str = "known"
    sampled_data: bool = False

    @property
    def wants_sampled_data(self) -> bool:
        """Whether a law with a sampled-data analysis computes it for this run: the cart's own measurement
        (``sampled_data``), the ideal cart's (exact) included (issue 44 item 1)."""
        return self.sampled_data

    def __post_init__(self) -> None:
        if not isinstance(self.measurement, MeasurementErrors):
            raise ParameterError(f"measurement must be a MeasurementErrors, got {type(self.measurement).__name__}")
        if not isinstance(self.sensing, Sensing):
            raise ParameterError(f"sensing must be a wmr_mj.hardware.Sensing, got {type(self.sensing).__name__}")
        if self.gear_ratio is None:
            object.__setattr__(self, "gear_ratio", float(self.estimate.i2))
        if self.delay_split not in DELAY_SPLITS:
            raise UnknownNameError("delay split", str(self.delay_split), DELAY_SPLITS)


class RunAssumptions(NamedTuple):
    """The four assumptions every claim of a bounded |E| shares (:func:`shared_assumptions`), by name."""

    reachable: Assumption
    stops: Assumption
    supply: Assumption
    initial: Assumption


def shared_assumptions(*, alpha_max: float, voltage_max: float, limits: PlantLimits,
                       initial_error: tuple[float, float], initial_tolerance: float = INITIAL_TOLERANCE,
                       angle_equation: str = "alpha_max = max|alpha0| + E_max < pi/2",
                       angle_met: bool | None = None, angle_note: str = "",
                       supply_equation: str = "the law's |u| bound <= voltage_limit",
                       initial_equation: str = "E(0) = E'(0) = 0") -> RunAssumptions:
    """The reachable angle, the steering stops, the supply and the zero initial error, checked; written once.

    Args:
        alpha_max: max|alpha0| + E_max [rad], the reachable angle.
        voltage_max: the claim's bound on the law's |u| [V].
        limits: the plant's steering stops [rad] and supply [V].
        initial_error: (E(0) [rad], E'(0) [rad/s]).
        initial_tolerance: the tolerance on them [rad, rad/s].
        angle_equation, supply_equation, initial_equation: how the claim words each (section 4 names its
            fixed point, its voltage bound and (4.17)); angle_met: whether the angle's bound exists
            (None: alpha_max < pi/2); angle_note: its note.

    Returns:
        RunAssumptions: the four, each an :class:`Assumption`.
    """
    E0, Ed0 = initial_error
    init = max(abs(E0), abs(Ed0))
    return RunAssumptions(
        Assumption("reachable angle", angle_equation, alpha_max < 0.5 * math.pi if angle_met is None else angle_met,
                   alpha_max, 0.5 * math.pi, angle_note),
        Assumption("inside the steering stops", "max|alpha0| + E_max < steering_range",
                   alpha_max < limits.steering_range, alpha_max, limits.steering_range,
                   "the stop's torque is not in the model"),
        Assumption("within the supply", supply_equation, voltage_max <= limits.voltage_limit,
                   voltage_max, limits.voltage_limit, "the analysis has no saturation"),
        Assumption("zero initial error", initial_equation, init <= initial_tolerance, init, initial_tolerance,
                   f"E(0) = {E0:g} rad, E'(0) = {Ed0:g} rad/s"),
    )


def run_assumptions(*, alpha_max: float, voltage_max: float, context: ClaimContext,
                    initial_tolerance: float = INITIAL_TOLERANCE) -> tuple[Assumption, ...]:
    """The assumptions every claim of a bounded |E| shares, checked: the reachable angle below pi/2
    (``alpha_max`` = max|alpha0| + E_max [rad]), inside the steering stops, the law's voltage within
    the supply (``voltage_max`` [V], the claim's bound on |u|), zero initial error (within
    ``initial_tolerance``, the reference's rounding at t = 0). :func:`shared_assumptions` on the context."""
    return tuple(shared_assumptions(alpha_max=alpha_max, voltage_max=voltage_max, limits=context.limits,
                                    initial_error=context.initial_error, initial_tolerance=initial_tolerance))


def least_fixed_point(step: Callable[[tuple[float, ...]], tuple[tuple[float, ...], str]], dimension: int, *,
                      tangent: Callable[[tuple[float, ...], tuple[float, ...]], str], max_iterations: int,
                      what: str = "no fixed point") -> tuple[tuple[float, ...] | None, int, str]:
    """The least point v >= 0 with v = step(v), iterated from 0: the one fixed-point iteration of the claims.

    Each iterate is the componentwise max of the last and its step (``step`` is increasing in every coordinate,
    so the iterates rise); it has settled where no coordinate of the step exceeds the iterate by more than 1e-13
    relative (1e-300 absolute). :func:`fixed_point` (section 4's E_max) and the sampled-data certificate's
    (E_max, Edot_max) (:mod:`wmr_mj.analysis.sampled_certificate`) both iterate here.

    Args:
        step: v -> (step(v), "" or the complete reason no bound exists there, which ends the iteration).
        dimension: the number of coordinates.
        tangent: (the last iterate, the settled point) -> "" where the step confines the point (it lies below
            a point just above it), else the reason (a tangent fixed point: the bound does not confine the error).
        max_iterations: the most steps.
        what: the start of the reason where it does not settle ('no fixed point').

    Returns:
        (the settled point, iterations, "") or (None, iterations, the reason).
    """
    x = (0.0,) * dimension
    for k in range(1, max_iterations + 1):
        nxt, failure = step(x)
        if failure:
            return None, k, failure
        settled = all(n <= v * (1.0 + 1e-13) + 1e-300 for n, v in zip(nxt, x))
        previous, x = x, tuple(max(v, n) for v, n in zip(x, nxt))
        if settled:
            reason = tangent(previous, x)
            return (None, k, reason) if reason else (x, k, "")
    return None, max_iterations, f"{what}: E_max did not settle in {max_iterations} iterations"


def tangent_reason(E_max: float) -> str:
    """The reason of a tangent fixed point at ``E_max`` [rad] (:func:`least_fixed_point`)."""
    return f"tangent fixed point at E_max = {E_max:.4g} rad: the bound does not confine the error"


def fixed_point(phi: Callable[[float], float], alpha0_max: float, *,
                max_iterations: int = _FIXED_POINT_ITERATIONS) -> tuple[float, int, str]:
    """Least x >= 0 with x = phi(x), alpha = alpha0_max + x staying in (-pi/2, pi/2) (:func:`least_fixed_point`).

    phi(x) is the bound at alpha_max = alpha0_max + x (increasing; inf where (4.23)
    fails). Returns (x*, iterations, reason); x* = inf with the reason when the
    iteration leaves (-pi/2, pi/2), (4.23) fails on the way, the fixed point is tangent
    (phi(x) >= x just above it), or it does not settle.
    """
    def step(v: tuple[float, ...]) -> tuple[tuple[float, ...], str]:
        x = v[0]
        if alpha0_max + x >= 0.5 * math.pi:
            return v, (f"no fixed point: the bound on |alpha| = max|alpha0| + E_max reaches pi/2 "
                       f"(iterate E_max = {x:.4g} rad), where sin/cos^3 and 1/cos^2 are unbounded")
        nxt = phi(x)
        if not math.isfinite(nxt):
            return v, (f"no fixed point: (4.23) fails at alpha_max = {alpha0_max + x:.4g} rad "
                       f"(iterate E_max = {x:.4g} rad)")
        return (nxt,), ""

    def tangent(_previous: tuple[float, ...], settled: tuple[float, ...]) -> str:
        x = settled[0]
        h = max(1e-6 * x, 1e-12)
        if alpha0_max + x + h < 0.5 * math.pi and not phi(x + h) < x + h:
            return tangent_reason(x)
        return ""

    point, k, reason = least_fixed_point(step, 1, tangent=tangent, max_iterations=max_iterations)
    return (math.inf, k, reason) if point is None else (point[0], k, "")


def box_claim(*, claimant: str, E_max: float, Edot_max: float = math.inf, context: ClaimContext, alpha_max: float,
              voltage_max: float, own: Sequence[Assumption] = (), reason: str = "",
              inputs: Mapping[str, Any] | None = None) -> Certificate:
    """A claim |E| <= E_max [rad] and |E'| <= Edot_max [rad/s] (inf: |E| alone): a :class:`BoxRegion`.

    Its assumptions: :func:`run_assumptions` (reachable angle, stops, supply, initial error), then
    the claim's ``own`` (e.g. a gain above an uncertainty bound), then the run's
    (``context.stated``). ``valid`` is False (E_max inf) where E_max is not a finite number >= 0 or
    the reachable angle reaches pi/2. ``inputs``: the law's own record (its JSON ``inputs``).

    Raises:
        ParameterError: an assumption that is not an :class:`Assumption`.
    """
    for a in own:
        if not isinstance(a, Assumption):
            raise ParameterError(f"a claim's assumptions must be Assumption records, got {type(a).__name__}")
    E_max, Edot_max = float(E_max), float(Edot_max)
    valid = math.isfinite(E_max) and E_max >= 0.0 and not math.isnan(Edot_max) and alpha_max < 0.5 * math.pi
    if not valid:
        E_max, Edot_max = math.inf, math.inf
        reason = reason or "no finite bound"
    assumptions = (*run_assumptions(alpha_max=alpha_max, voltage_max=voltage_max, context=context), *own,
                   *context.stated)
    return Certificate(region=BoxRegion(E_max=E_max, Edot_max=Edot_max), valid=valid, assumptions=assumptions,
                       alpha_max=alpha_max, voltage_max=voltage_max, reason=reason,
                       inputs=ClaimInputs(law=dict(inputs or {})), claimant=claimant)


def with_measured(cert: Certificate, assumption: Assumption) -> Certificate:
    """``cert`` with ``assumption``, measured on the run, in place of the one of the same name (else appended)."""
    kept = tuple(a for a in cert.assumptions if a.name != assumption.name)
    return dataclasses.replace(cert, assumptions=(*kept, assumption))


def covers_measurement(cert: Certificate, measurement: MeasurementErrors) -> Certificate:
    """``cert`` as it covers ``measurement``: unchanged where the measurement is exact or the claim states
    the assumption :data:`~wmr_mj.analysis.measurement.MEASUREMENT_COVERED` itself (it absorbed the
    errors); else with that assumption unmet: a claim that says nothing about sensing covers exact
    measurement only, so the run is uncertified."""
    if measurement.is_exact or any(a.name == MEASUREMENT_COVERED for a in cert.assumptions):
        return cert
    fields = coverage_assumption_fields(measurement, cert.claimant)
    fields.update(met=False, value=1.0, note=(f"{cert.claimant or 'the claim'} states nothing about sensing or "
                                              "actuation: it covers exact measurement only"))
    return dataclasses.replace(cert, assumptions=(*cert.assumptions, Assumption(**fields)))


def best_certificate(own: Certificate, own_name: str, sampled: Certificate | str) -> Certificate:
    """A sampled law's claim: its sampled-data certificate ``sampled``, with its continuous claim ``own`` (named
    ``own_name``: 'section-4', 'boundary-layer') beside it as a second opinion (issue 44 item 1).

    The law runs sampled: its command is held over each control period. ``own`` bounds the continuous law, with
    the hold assumed away; it could count only with a proven bound on what the hold adds, and no sound one
    smaller than the sampled-data certificate's is known (the held sign of alpha' alone is charged
    F_max + F^, as there: ``docs/guides/certificates.md``, "Sampling bounded on every cart"). So ``sampled``
    is taken, certified or not, whichever E_max is the smaller; where it was not computed (``sampled`` is the
    reason), ``own`` is taken with the assumption :data:`SAMPLING_BOUNDED` unmet: never certified by a bound
    that assumes sampling away. Both E_max, whether each is certified and its reason are recorded under
    ``inputs['certificates']``, and ``inputs['certificate']`` names the one taken.

    Args:
        own: the law's continuous claim, as it covers the run's measurement (:func:`covers_measurement`).
        own_name: its name.
        sampled: the sampled-data certificate, or why it was not computed (one line).
    """
    if isinstance(sampled, str):
        unbounded = Assumption(SAMPLING_BOUNDED, "the sampled-data certificate is computed (a continuous-time "
                               "bound alone assumes the zero-order hold away)", False, 1.0, 0.0, sampled,
                               kind="checked")
        own = dataclasses.replace(own, assumptions=(*own.assumptions, unbounded))
        return replace_inputs(own, {**dict(own.inputs), "certificate": own_name,
                                  "certificates": {SAMPLED_DATA_NAME: {"E_max": None, "reason": sampled}}})
    record = {own_name if c is own else SAMPLED_DATA_NAME: {"E_max": c.E_max if c.valid else None,
                                                             "certified": c.certified, "reason": c.reason}
              for c in (own, sampled)}
    return replace_inputs(sampled, {**dict(sampled.inputs), "certificate": SAMPLED_DATA_NAME,
                                    "certificates": record})


def replace_inputs(cert: Certificate, inputs: Mapping[str, Any]) -> Certificate:
    """``cert`` with ``inputs`` (a copy of ``cert.inputs``, updated) as its inputs: the law's stay typed, the
    keys that are new or changed become the run's (:meth:`ClaimInputs.with_record`)."""
    return dataclasses.replace(cert, inputs=cert.inputs.with_record(inputs))
