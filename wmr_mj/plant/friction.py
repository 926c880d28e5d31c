"""The plant's friction laws, measured: steering stiction and tyre-contact softness.

The steering joint carries the Coulomb torque (l3 l4 / l1) mu Q of (2.5) as a
MuJoCo ``frictionloss``, a constraint solved softly. What it does is measured
here, from the ``home`` keyframe with the cart driving at V_A, under constant
steering voltages u (the motor at rest gives the joint i2 k u / R_a, (2.9)-(2.10)):

- the creep rate below break-away (u = 0.5 F and 0.9 F, F = (R_a/(k_i i2)) tau_f
  the friction voltage of (2.13)): the rate over the last second of the run;
- the rate above break-away (u = 1.3 F), beside what (2.13) predicts for steady
  sliding, (u - F)/C_V, and what the non-holonomic model predicts, whose gyroscopic
  term adds gyro V_A / cos^2(alpha) to C_V: (u - F)/(C_V + gyro V_A) near alpha = 0;
- the break-away voltage itself: the least constant voltage whose rate exceeds
  ``HOLD_RATE``, found by a grid search on constant voltages (each a rollout),
  refined round by round.

``measure_contact_softness`` measures the tyre contacts the same way a user would
see them in the steering: wheel penetration, side slip on the 1 m circle and the
identified gyroscopic coefficient.

Usage::

    from wmr_mj import C80
    from wmr_mj.plant.friction import measure_friction_law
    law = measure_friction_law(C80, steering_friction="stiction")
    print(law.breakaway_voltage, law.creep_rates, law.holds())
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import mujoco
import numpy as np
from mujoco import rollout

from wmr_mj.errors import ParameterError
from wmr_mj.params import C80, C80Parameters
from wmr_mj.plant.identify import identify_plant
from wmr_mj.plant.mjcf import Plant, measure_side_slip

__all__ = [
    "HOLD_RATE",
    "CREEP_FRACTIONS",
    "SLIDE_FRACTION",
    "FrictionLaw",
    "ContactSoftness",
    "constant_voltage_rates",
    "measure_friction_law",
    "measure_contact_softness",
    "wheel_penetration",
    "contact_softness_of",
]

#: rad/s: a joint whose rate stays at or below this under a constant voltage holds (issue 8's bound).
HOLD_RATE = 1e-4
#: Fractions of F below break-away at which the creep is measured.
CREEP_FRACTIONS = (0.5, 0.9)
#: Fraction of F above break-away at which the sliding rate is measured.
SLIDE_FRACTION = 1.3


@dataclass(frozen=True)
class FrictionLaw:
    """The steering joint's measured friction law under one friction model (SI units)."""

    steering_friction: str  # the plant's friction model (wmr_mj.plant.mjcf.STEERING_FRICTION_MODELS)
    friction_torque: float  # N m, the joint's frictionloss (l3 l4/l1) mu Q of (2.5)
    friction_voltage: float  # V, F = (R_a/(k_i i2)) friction_torque, (2.13)
    breakaway_voltage: float  # V, measured: least constant voltage whose rate exceeds hold_rate
    breakaway_torque: float  # N m, the motor torque at the joint at that voltage, at rest
    breakaway_resolution: float  # V, width of the last bracket of the search
    hold_rate: float  # rad/s, the rate that counts as holding
    creep_rates: dict[float, float]  # fraction of F -> steady rate, rad/s
    slide_rates: dict[float, float]  # fraction of F -> steady rate, rad/s
    predicted_slide_rates: dict[float, float]  # fraction of F -> (u - F)/C_V, rad/s (2.13)
    predicted_slide_rates_gyro: dict[float, float]  # fraction -> (u - F)/(C_V + gyro V_A), non-holonomic model
    duration: float  # s, length of each constant-voltage run
    mujoco_warnings: int

    def holds(self) -> bool:
        """True when every creep rate is within hold_rate and the joint slides above F."""
        return (all(abs(r) <= self.hold_rate for r in self.creep_rates.values())
                and all(r > self.hold_rate for r in self.slide_rates.values()))

    def to_dict(self) -> dict:
        d = asdict(self)
        for key in ("creep_rates", "slide_rates", "predicted_slide_rates", "predicted_slide_rates_gyro"):
            d[key] = {f"{k:g}": v for k, v in d[key].items()}
        d["holds"] = self.holds()
        return d


def _check_duration(duration: float) -> None:
    if not math.isfinite(duration) or duration < 2.0:
        raise ParameterError(f"duration = {duration!r} s is not accepted; give a finite number >= 2 s "
                             "(the rate is read over the last second)")


def constant_voltage_rates(params: C80Parameters, voltages: np.ndarray, *, steering_friction: str = "stiction",
                           tyre_contact: str = "stiff", duration: float = 2.0) -> tuple[np.ndarray, int]:
    """Steering rate (rad/s, over the last second) under each constant voltage, from ``home``.

    One ``mujoco.rollout`` of the plant per voltage, the drive holding V_A. Returns the rates
    and the number of MuJoCo warnings raised.
    """
    _check_duration(duration)
    plant = Plant(params, steering_friction=steering_friction, tyre_contact=tyre_contact)
    m, d = plant.model, plant.data
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, state0, spec)
    nstep = int(round(duration / m.opt.timestep))
    window = int(round(1.0 / m.opt.timestep))
    voltages = np.atleast_1d(np.asarray(voltages, dtype=float))
    control = np.empty((voltages.size, nstep, m.nu))
    control[:] = d.ctrl  # the drive's command from the keyframe
    control[:, :, plant.steer_actuator] = voltages[:, None]
    _, sensordata = rollout.rollout(m, d, state0, control)
    adr = m.sensor("steer_angle").adr[0]
    angle = sensordata[:, :, adr]
    rates = (angle[:, -1] - angle[:, -1 - window]) / (window * m.opt.timestep)
    return rates, int(sum(w.number for w in d.warning))


def measure_friction_law(params: C80Parameters = C80, *, steering_friction: str = "stiction",
                         tyre_contact: str = "stiff", duration: float = 2.0, hold_rate: float = HOLD_RATE,
                         rounds: int = 3, grid: int = 8) -> FrictionLaw:
    """Measure break-away, creep below it and sliding above it (see the module docstring).

    The break-away search starts from the bracket [0, 2 F] and, ``rounds`` times, runs
    ``grid`` voltages evenly inside it and keeps the interval where the rate first exceeds
    ``hold_rate``: the resolution is 2 F / (grid + 1)**rounds.
    """
    coeffs = params.coefficients("nonholonomic")
    F, C_V, gyro = coeffs.F, coeffs.C_V, coeffs.gyro
    torque_per_volt = params.i2 * math.sqrt(params.k_i * params.k_b) / params.R_a  # at rest, (2.9)-(2.10)
    def rates_at(voltages: np.ndarray) -> tuple[np.ndarray, int]:
        return constant_voltage_rates(params, voltages, steering_friction=steering_friction,
                                      tyre_contact=tyre_contact, duration=duration)

    fractions = (*CREEP_FRACTIONS, SLIDE_FRACTION)
    rates, warnings = rates_at(np.array(fractions) * F)
    lo, hi = 0.0, 2.0 * F
    for _ in range(rounds):
        trial = np.linspace(lo, hi, grid + 2)[1:-1]
        r, w = rates_at(trial)
        warnings += w
        moving = np.flatnonzero(np.abs(r) > hold_rate)
        if moving.size:
            first = int(moving[0])
            hi = float(trial[first])
            lo = float(trial[first - 1]) if first > 0 else lo
        else:
            lo = float(trial[-1])
    return FrictionLaw(
        steering_friction=steering_friction,
        friction_torque=params.steering_friction_torque,
        friction_voltage=F,
        breakaway_voltage=hi,
        breakaway_torque=hi * torque_per_volt,
        breakaway_resolution=hi - lo,
        hold_rate=hold_rate,
        creep_rates={f: float(x) for f, x in zip(CREEP_FRACTIONS, rates[:len(CREEP_FRACTIONS)])},
        slide_rates={SLIDE_FRACTION: float(rates[-1])},
        predicted_slide_rates={SLIDE_FRACTION: (SLIDE_FRACTION - 1.0) * F / C_V},
        predicted_slide_rates_gyro={SLIDE_FRACTION: (SLIDE_FRACTION - 1.0) * F / (C_V + gyro * params.V_A)},
        duration=duration,
        mujoco_warnings=warnings,
    )


@dataclass(frozen=True)
class ContactSoftness:
    """What the tyre contacts do where the steering sees them (one contact model)."""

    tyre_contact: str  # wmr_mj.plant.mjcf.TYRE_CONTACT_MODELS
    penetration_rear: float  # m, each rear wheel's sphere into the floor, driving straight
    penetration_front: float  # m, the same for a front wheel
    max_slip_angle: float  # rad, largest wheel side slip / V_A on the 1 m circle
    side_force_ratio: float  # largest side/normal force of a wheel there
    cornering_coefficient: tuple[float, float]  # 1/rad, (min, max) over the wheels: side/normal force per slip angle
    gyro: float  # V s/m, identified coefficient of V_A alpha'/cos^2 alpha
    gyro_std_error: float
    K: float  # V, identified coefficient of sin/cos^3
    P: float  # V s^2/rad, identified
    mujoco_warnings: int  # raised during the identification

    def to_dict(self) -> dict:
        return asdict(self)


def wheel_penetration(params: C80Parameters = C80, *, tyre_contact: str = "stiff",
                      duration: float = 2.0) -> dict[str, float]:
    """Depth (m) of each wheel sphere in the floor after ``duration`` s driving straight from ``home``."""
    plant = Plant(params, tyre_contact=tyre_contact)
    m, d = plant.model, plant.data
    for _ in range(int(round(duration / m.opt.timestep))):
        mujoco.mj_step(m, d)
    depth = {}
    for i in range(d.ncon):
        c = d.contact[i]
        for g in (c.geom1, c.geom2):
            name = m.geom(g).name
            if name.endswith("_contact"):
                depth[name.removesuffix("_contact")] = -float(c.dist)
    return depth


def measure_contact_softness(params: C80Parameters = C80, *, tyre_contact: str = "stiff",
                             identify_duration: float = 60.0, seed: int = 0) -> ContactSoftness:
    """Penetration (``wheel_penetration``), side slip on the 1 m circle (``measure_side_slip``) and
    the identified gyro, K, P (``identify_plant``, ``identify_duration`` s, ``seed``) for one
    contact model."""
    depth = wheel_penetration(params, tyre_contact=tyre_contact)
    slip = measure_side_slip(params, tyre_contact=tyre_contact)
    ident = identify_plant(params, duration=identify_duration, seed=seed, tyre_contact=tyre_contact)
    return contact_softness_of(tyre_contact, depth, slip, ident)


def contact_softness_of(tyre_contact: str, depth: dict[str, float], slip: dict[str, float],
                        ident) -> ContactSoftness:
    """A ContactSoftness from measurements already made (penetration, side slip, identification)."""
    return ContactSoftness(
        tyre_contact=tyre_contact,
        penetration_rear=max(depth.get("rear_left", math.nan), depth.get("rear_right", math.nan)),
        penetration_front=max(depth.get("front_left", math.nan), depth.get("front_right", math.nan)),
        max_slip_angle=slip["max_slip_angle_rad"],
        side_force_ratio=slip["max_side_force_ratio"],
        cornering_coefficient=(slip["cornering_coefficient_min"], slip["cornering_coefficient_max"]),
        gyro=ident.identified.gyro,
        gyro_std_error=ident.diagnostics["std_error"]["gyro"],
        K=ident.identified.K,
        P=ident.identified.P,
        mujoco_warnings=int(ident.diagnostics["mujoco_warnings"]),
    )
