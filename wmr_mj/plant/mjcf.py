"""The C80 MJCF model, built with ``mujoco.MjSpec`` from one parameter set.

``robot_spec(params)`` builds the cart, ``scene_spec(params)`` adds the floor and
light; ``robot_xml`` / ``scene_xml`` are their ``MjSpec.to_xml()`` texts.
``models/c80.xml`` is ``robot_xml(C80)`` written out (a test keeps them equal),
``models/scene.xml`` includes it and adds the floor and light. Simulations run on
``scene_xml(params)``: the same robot with the floor in one string, compiled from
that string, so a log can attach exactly what was simulated.

Every number enters the spec rounded to 6 significant digits
(:func:`round_sig`): ``to_xml`` writes 6 digits, so the model compiled from the
written file equals the one compiled from the spec, and no 17-digit numbers.

Units (``wmr_mj.params``): chassis a on a free joint, origin at point A (rear
axle midpoint) at axle height; drive unit b fixed to it, two rear wheels holding
V_A through an open differential (a fixed tendon, mean of the wheel angles,
driven by a velocity servo through gear i1); steering unit c on the vertical
hinge ``steer`` at the pivot O = C, two free-rolling front wheels. The steering
joint is driven by MuJoCo's ``dcmotor`` in voltage mode (2.9)-(2.10) with R_a,
k_i, k_b, gear i2 and the voltage limit, and carries the Coulomb friction
(l3 l4 / l1) mu Q of (2.5) as ``frictionloss``. Wheels touch the floor with a
sphere each (one contact point, as the rolling-disc model assumes).

Steering friction law (``steering_friction``, one of ``STEERING_FRICTION_MODELS``):

- ``"stiction"`` (default): the frictionloss constraint made stiff with
  ``STICTION_SOLREF`` / ``STICTION_SOLIMP`` so the joint holds below break-away
  (creep of a few µrad/s, measured by ``wmr_mj.plant.friction``);
- ``"soft"``: MuJoCo's default friction softness, under which the joint creeps
  at mrad/s below break-away (kept to reproduce that finding).

Tyre-floor contacts (``tyre_contact``, one of ``TYRE_CONTACT_MODELS``): ``"stiff"``
(default, ``TYRE_CONTACT_SOLREF`` on the wheel spheres and the floor: side slip of
a rubber tyre's order) or ``"soft"`` (MuJoCo's default solref). models/README.md
gives the measured numbers of both.

Usage::

    from wmr_mj import C80, with_params
    from wmr_mj.plant.mjcf import compile_model, Plant
    model, xml = compile_model(with_params(C80, m1=700.0))
    plant = Plant(with_params(C80, m1=700.0))      # model + data at the home keyframe
    soft = Plant(C80, steering_friction="soft")     # MuJoCo's default soft friction
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal, get_args

import mujoco
import numpy as np

from wmr_mj.errors import ModelFileError, ParameterError, UnknownNameError
from wmr_mj.hardware.actuation import Actuation
from wmr_mj.hardware.spec import whole_periods
from wmr_mj.hardware.transmission import Transmission
from wmr_mj.params import C80, C80Parameters

__all__ = [
    "robot_spec",
    "scene_spec",
    "robot_xml",
    "scene_file_xml",
    "scene_xml",
    "compile_model",
    "load_model_file",
    "write_model_files",
    "round_sig",
    "Plant",
    "MODELS_DIR",
    "TIMESTEP",
    "BEAM_PITCH_RATIO",
    "SteeringFriction",
    "STEERING_FRICTION_MODELS",
    "STICTION_SOLREF",
    "STICTION_SOLIMP",
    "TYRE_CONTACT_MODELS",
    "TYRE_CONTACT_SOLREF",
    "STEERING_JOINT",
    "MOTOR_JOINT",
    "GEAR_PLAY_TENDON",
    "MOTOR_ARMATURE",
    "GEAR_PLAY_SOLREF",
    "GEAR_PLAY_SOLIMP",
    "SteeringAddresses",
    "steering_joint_addresses",
]

from wmr_mj._util.resources import MODELS_DIR  # noqa: E402  (re-exported)

TIMESTEP = 1e-3  # s, physics step (the paper's controller runs at every step)
# Beams are slender rods: their inertia about their own axis is set to this
# fraction of the transverse one (MuJoCo needs it > 0; it never matters here).
BEAM_PITCH_RATIO = 0.01
# Drive servo: velocity-loop time constant of the rear wheels' speed, s.
DRIVE_TIME_CONSTANT = 0.02
# Significant digits of every number written into the MJCF (MjSpec.to_xml writes 6).
SIGNIFICANT_DIGITS = 6

#: Steering friction laws a plant can be built with (see the module docstring); the report
#: measures each of them.
SteeringFriction = Literal["stiction", "soft"]
STEERING_FRICTION_MODELS: tuple[str, ...] = get_args(SteeringFriction)
# "stiction": solver parameters of the steering joint's frictionloss constraint.
# Below break-away a frictionloss constraint creeps at v = (1-d)/d * tau/J * d_w*timeconst/2
# (MuJoCo's friction dynamics, modeling.rst "Friction"); MuJoCo's defaults (d = 0.9,
# d_w = 0.95, timeconst 0.02 s) give mrad/s. timeconst = 2 steps is the least MuJoCo uses
# at 1 ms (smaller values are clamped, refsafe); d = 0.999 brings the creep to a few µrad/s
# (d = 0.9999, MuJoCo's largest, gave 10x less; not needed for the 1e-4 rad/s bound).
# Measured by wmr_mj.plant.friction.measure_friction_law on C80 (home keyframe, cart driving,
# constant voltage): creep 2.6 µrad/s at 0.5 F and 4.7 µrad/s at 0.9 F, 0.092 rad/s at 1.3 F,
# no MuJoCo warning at the 1 ms step; the soft default creeps 2.8 and 5.1 mrad/s.
STICTION_SOLREF = (0.002, 1.0)  # (timeconst s, dampratio)
STICTION_SOLIMP = (0.999, 0.9999, 0.001, 0.5, 2.0)  # (d0, d_width, width, midpoint, power)

#: Tyre-floor contact laws a plant can be built with: "stiff" (default) or MuJoCo's default "soft".
TYRE_CONTACT_MODELS = ("stiff", "soft")
# "stiff": solref of the wheel spheres and the floor. Contact friction is soft like frictionloss:
# a wheel under side force slips sideways at a rate proportional to it. MuJoCo's default
# (timeconst 0.02 s) gave 2.6 mrad slip angle on the 1 m circle and lowered the identified
# gyroscopic coefficient by 9% (0.575 against P/l1 = 0.629); a rubber tyre's cornering stiffness
# (C_alpha/F_z of order 10-20 /rad) puts its slip angle at that side force near 0.3 mrad.
# timeconst = 2 steps (the least MuJoCo takes at 1 ms) gave 0.29 mrad and gyro 0.619; the
# normal direction becomes stiffer than a tyre (µm instead of 0.3-0.5 mm), which moves only
# the tilt-induced K (0.0096 -> 0.0010 V, both < 0.2% of the paper's K). Measured by
# wmr_mj.plant.friction.measure_contact_softness; numbers in models/README.md.
TYRE_CONTACT_SOLREF = (0.002, 1.0)  # (timeconst s, dampratio)

#: The steering joint: the axle's angle alpha (the law, the engine and the certificate read it).
STEERING_JOINT = "steer"
#: With backlash: the motor side of the gear play, a hinge coaxial with STEERING_JOINT, its angle
#: at the steering axis (the motor shaft turns i2 times it).
MOTOR_JOINT = "steer_motor"
#: With backlash: the fixed tendon steer - steer_motor, limited to +-b (the play of the gear).
GEAR_PLAY_TENDON = "gear_play"
# Motor side of the play, kg m^2 at the steering axis. The paper's model has no rotor inertia
# (P = J R_a / (i2 k_i) with J the load alone), but inside the play the motor side must have
# some, or the joint-space inertia matrix is singular (modeling.rst, "Backlash"). 0.01 kg m^2
# (0.5% of J = 1.836; a rotor of 2.8e-6 kg m^2 through i2 = 60) keeps P within 0.6% of the
# paper's; larger values are a real motor's and a keyword of the builders.
MOTOR_ARMATURE = 0.01
# The play's end stops (the tendon's limit constraint): timeconst = 2 steps, the least MuJoCo
# takes at 1 ms (as STICTION_SOLREF), so a stop behaves as a tooth contact, not a spring.
GEAR_PLAY_SOLREF = (0.002, 1.0)  # (timeconst s, dampratio)
# and impedance 0.999 (STICTION_SOLIMP's). A stop is still compliant: its stiffness is about
# motor_armature / timeconst^2 = 2500 N m/rad at MOTOR_ARMATURE, so pushing the axle against its
# friction (7.24 N m) presses it 2.37 mrad (2.52 with MuJoCo's default impedance 0.9); measured
# by tests/test_backlash_model.py. A larger motor_armature_kgm2 stiffens it in proportion.
GEAR_PLAY_SOLIMP = STICTION_SOLIMP


def round_sig(x: float, digits: int = SIGNIFICANT_DIGITS) -> float:
    """``x`` rounded to ``digits`` significant digits (what the MJCF text can carry)."""
    return float(f"{float(x):.{digits}g}")


def _r(values: Sequence[float]) -> list[float]:
    return [round_sig(v) for v in values]


def _check_models(steering_friction: str, tyre_contact: str) -> None:
    if steering_friction not in STEERING_FRICTION_MODELS:
        raise UnknownNameError("steering friction model", steering_friction, STEERING_FRICTION_MODELS)
    if tyre_contact not in TYRE_CONTACT_MODELS:
        raise UnknownNameError("tyre contact model", tyre_contact, TYRE_CONTACT_MODELS)


@dataclass(frozen=True)
class _DriveTrain:
    """The steering motor's actuation and the gear's play, as the cart's parts declare them
    (:class:`wmr_mj.hardware.Actuation`, :class:`wmr_mj.hardware.Transmission`), with what only the model
    adds: the motor side's inertia inside the play. The defaults are today's plant.
    """

    actuation: Actuation = Actuation()
    transmission: Transmission = Transmission()
    motor_armature_kgm2: float = MOTOR_ARMATURE  # kg m^2 at the steering axis, motor side (with play)

    @property
    def has_play(self) -> bool:
        return not self.transmission.is_ideal

    @property
    def delay_steps(self) -> int:
        return int(round(self.actuation.delay / TIMESTEP))

    def comment(self) -> str:
        """The non-default options, for the scene's comment ('' for today's plant)."""
        options = {**self.actuation.model_options(), **self.transmission.model_options()}
        changed = [f"{name}={value!r}" for name, value in options.items() if value != _IDEAL_OPTIONS[name]]
        if changed and self.has_play:
            changed.append(f"motor_armature_kgm2={self.motor_armature_kgm2!r}")
        return ", ".join(changed)


#: The builders' actuation and play keywords at today's plant (what an ideal part leaves out).
_IDEAL_OPTIONS = {"actuation_delay_s": 0.0, "inductance_H": 0.0, "current_limit_A": None, "backlash_rad": 0.0}


def _drive_train(*, actuation_delay_s: float = 0.0, inductance_H: float = 0.0, current_limit_A: float | None = None,
                 backlash_rad: float = 0.0, motor_armature_kgm2: float = MOTOR_ARMATURE,
                 cart_inductance_H: float = 0.0) -> _DriveTrain:
    """The builders' keywords as the parts (each part checks its own values, the message naming the keyword),
    and what the model alone requires: a delay of whole physics steps, inertia on the motor side of a play.
    ``cart_inductance_H`` is the cart's armature inductance (``params.L_a``, H): the motor's where ``inductance_H``
    is 0 (an inductance given, e.g. by ``--actuation inductance=``, overrides it:
    :meth:`wmr_mj.hardware.Actuation.on_motor`)."""
    actuation = Actuation.from_model_options(actuation_delay_s=actuation_delay_s, inductance_H=inductance_H,
                                             current_limit_A=current_limit_A).on_motor(L_a=cart_inductance_H)
    whole_periods("actuation_delay_s", actuation.delay, TIMESTEP, periods="physics steps",
                  why=" (MuJoCo reads a delayed ctrl at whole steps)")
    transmission = Transmission.from_model_options(backlash_rad=backlash_rad)
    armature = motor_armature_kgm2
    if isinstance(armature, bool) or not isinstance(armature, (int, float)) or not math.isfinite(armature) \
            or armature < 0:
        raise ParameterError(f"motor_armature_kgm2 must be a finite number >= 0 kg m^2, got {armature!r}")
    if not transmission.is_ideal and armature == 0:
        raise ParameterError("motor_armature_kgm2 must be > 0 kg m^2 with backlash_rad > 0 (the motor side "
                             "of the play needs inertia)")
    return _DriveTrain(actuation=actuation, transmission=transmission, motor_armature_kgm2=float(armature))


_HINGE = mujoco.mjtJoint.mjJNT_HINGE
_SPHERE, _CYLINDER, _BOX, _CAPSULE, _PLANE = (mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_CYLINDER,
                                              mujoco.mjtGeom.mjGEOM_BOX, mujoco.mjtGeom.mjGEOM_CAPSULE,
                                              mujoco.mjtGeom.mjGEOM_PLANE)
# Cylinders and capsules lie along their z axis; this turns z onto the axle (y). Written
# with 6 digits, the same numbers the file carries, so file and spec compile alike.
_AXLE_QUAT = _r((math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0))
_TYRE_RGBA = (0.15, 0.15, 0.15, 1.0)
_SITE_SIZE = [0.02, 0.005, 0.005]  # a sphere uses the first; the rest are MJCF's defaults


def _add_defaults(spec: mujoco.MjSpec, params: C80Parameters, steering_friction: str, tyre_contact: str) -> None:
    """Default classes (Menagerie style): c80 > wheel, steer, visual, collision."""
    c80 = spec.add_default("c80", spec.default)
    wheel = spec.add_default("wheel", c80)
    wheel.joint.type = _HINGE
    wheel.joint.axis = [0.0, 1.0, 0.0]
    # no damping, frictionloss or armature (MuJoCo's defaults, 0): free-rolling bearings
    steer = spec.add_default("steer", c80)
    steer.joint.type = _HINGE
    steer.joint.axis = [0.0, 0.0, 1.0]
    # no damping or armature: the motor's back-EMF is the steering's only viscous term (2.13)
    if steering_friction == "stiction":
        steer.joint.solref_friction = list(STICTION_SOLREF)
        steer.joint.solimp_friction = list(STICTION_SOLIMP)
    visual = spec.add_default("visual", c80)
    visual.geom.contype = 0
    visual.geom.conaffinity = 0
    visual.geom.group = 2
    visual.geom.mass = 0.0
    visual.geom.density = 0.0
    collision = spec.add_default("collision", c80)
    collision.geom.contype = 1
    collision.geom.conaffinity = 0
    collision.geom.group = 3
    collision.geom.condim = 3
    collision.geom.friction = _r((params.ground_friction, 0.0, 0.0))
    collision.geom.mass = 0.0
    collision.geom.density = 0.0
    collision.geom.rgba = [0.8, 0.2, 0.2, 0.3]
    if tyre_contact == "stiff":
        collision.geom.solref = list(TYRE_CONTACT_SOLREF)


def _add_wheel(parent: mujoco.MjsBody, spec: mujoco.MjSpec, name: str, *, y: float, mass: float, radius: float,
               width: float, spin: float, diametral: float) -> None:
    body = parent.add_body(name=f"{name}_wheel", pos=_r((0.0, y, 0.0)))
    _inertial(body, mass=mass, inertia=(diametral, spin, diametral))
    body.add_joint(name=f"{name}_spin", default=spec.find_default("wheel"))
    body.add_geom(name=f"{name}_contact", default=spec.find_default("collision"), type=_SPHERE,
                  size=[round_sig(radius), 0.0, 0.0])
    body.add_geom(name=f"{name}_tyre", default=spec.find_default("visual"), type=_CYLINDER,
                  size=_r((radius, width / 2, 0.0)), quat=_AXLE_QUAT, rgba=list(_TYRE_RGBA))


def _inertial(body: mujoco.MjsBody, *, mass: float, inertia: Sequence[float], pos=(0.0, 0.0, 0.0)) -> None:
    body.explicitinertial = True
    body.ipos = _r(pos)
    body.mass = round_sig(mass)
    body.inertia = _r(inertia)


def robot_spec(params: C80Parameters = C80, *, steering_friction: str = "stiction",
               tyre_contact: str = "stiff", actuation_delay_s: float = 0.0,
               inductance_H: float = 0.0, current_limit_A: float | None = None, backlash_rad: float = 0.0,
               motor_armature_kgm2: float = MOTOR_ARMATURE) -> mujoco.MjSpec:
    """The C80 alone (no floor) as an MjSpec; every number comes from ``params``.

    With every actuation and backlash option at its default the spec is today's, byte for byte.

    Args:
        params: the parameter set.
        steering_friction: one of STEERING_FRICTION_MODELS.
        tyre_contact: one of TYRE_CONTACT_MODELS.
        actuation_delay_s: s, the steering motor reads its voltage this long ago (MuJoCo's actuator
            ``delay`` with ``nsample``, zero-order hold); a whole number of physics steps.
        inductance_H: H, the armature inductance L_a of the ``dcmotor`` (one activation, the current;
            electrical time constant L_a / R_a); 0: the cart's ``params.L_a`` (0 for the C80: the current is
            algebraic, today's).
        current_limit_A: A, the driver's current limit (the ``dcmotor``'s ``saturation`` current:
            a force range of +-k I_max); None: no limit.
        backlash_rad: rad at the steering axis, half-width b of the gear's play: a motor-side hinge
            ``steer_motor`` carrying the motor and its armature, and the tendon ``gear_play`` =
            steer - steer_motor limited to +-b; 0: no play, one steering joint (today's).
        motor_armature_kgm2: kg m^2 at the steering axis, the motor side's inertia (used with play only).

    Returns:
        The spec: chassis (unit a), drive unit (b), steering unit (c), actuators, sensors and the ``home`` key.

    Raises:
        UnknownNameError: an unknown friction or contact model.
        ParameterError: a negative or non-finite option, a delay that is not a whole number of steps.
    """
    _check_models(steering_friction, tyre_contact)
    drive = _drive_train(actuation_delay_s=actuation_delay_s, inductance_H=inductance_H,
                      current_limit_A=current_limit_A, backlash_rad=backlash_rad,
                      motor_armature_kgm2=motor_armature_kgm2, cart_inductance_H=params.L_a)
    p = params
    spec = mujoco.MjSpec()
    spec.modelname = "c80"
    spec.comment = (" C80 cart, generated by wmr_mj.plant.mjcf.robot_spec from wmr_mj.params; do not edit by hand. "
                    "Regenerate: wmr-mj model write ")
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    spec.option.timestep = TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = _r((0.0, 0.0, -p.g))
    _add_defaults(spec, p, steering_friction, tyre_contact)
    chassis = _add_chassis(spec, p)
    _add_drive_unit(spec, chassis, p)
    _add_steering_unit(spec, chassis, p)
    if drive.has_play:
        _add_gear_play(spec, chassis, p, drive)
    _add_actuators(spec, p, drive)
    _add_sensors(spec, drive)
    _add_home_key(spec, p, drive)
    return spec


def _add_chassis(spec: mujoco.MjSpec, p: C80Parameters) -> mujoco.MjsBody:
    """Unit a: the chassis on a free joint, with site A (the rear-axle midpoint)."""
    chassis = spec.worldbody.add_body(name="chassis", pos=_r((0.0, 0.0, p.r2)), childclass="c80")
    chassis.add_freejoint(name="chassis_free")
    zc = p.chassis_height / 2
    _inertial(chassis, mass=p.m1, inertia=p.chassis_inertia, pos=(p.l3, 0.0, zc))
    chassis.add_geom(name="chassis_body", default=spec.find_default("visual"), type=_BOX, pos=_r((p.l3, 0.0, zc)),
                     size=_r((p.chassis_length / 2, p.chassis_width / 2, p.chassis_height / 2)),
                     rgba=[0.85, 0.55, 0.1, 0.6])
    chassis.add_site(name="A", pos=[0.0, 0.0, 0.0], size=_SITE_SIZE, rgba=[0.0, 0.0, 1.0, 1.0])
    return chassis


def _add_drive_unit(spec: mujoco.MjSpec, chassis: mujoco.MjsBody, p: C80Parameters) -> None:
    """Unit b: rear beam, differential and two driven wheels."""
    drive = chassis.add_body(name="drive_unit", pos=[0.0, 0.0, 0.0])
    beam = p.rear_axle_yaw_inertia
    _inertial(drive, mass=p.rear_axle_mass, inertia=(beam, BEAM_PITCH_RATIO * beam, beam))
    drive.add_geom(name="rear_beam", default=spec.find_default("visual"), type=_CAPSULE, quat=_AXLE_QUAT,
                   size=_r((0.03, p.l2, 0.0)), rgba=[0.3, 0.3, 0.35, 1.0])
    for side, y in (("rear_left", p.l2), ("rear_right", -p.l2)):
        _add_wheel(drive, spec, side, y=y, mass=p.rear_wheel_mass, radius=p.r2, width=p.rear_wheel_width,
                   spin=p.I_y2, diametral=p.I_z2)


def _add_steering_unit(spec: mujoco.MjSpec, chassis: mujoco.MjsBody, p: C80Parameters) -> None:
    """Unit c: the steered front axle on the pivot O = C, with site C."""
    steering = chassis.add_body(name="steering_unit", pos=_r((p.l1, 0.0, p.r3 - p.r2)))
    steering.add_joint(name="steer", default=spec.find_default("steer"),
                       range=_r((-p.steering_range, p.steering_range)),
                       frictionloss=round_sig(p.steering_friction_torque))
    beam = p.front_axle_yaw_inertia
    _inertial(steering, mass=p.front_axle_mass, inertia=(beam, BEAM_PITCH_RATIO * beam, beam))
    steering.add_geom(name="front_beam", default=spec.find_default("visual"), type=_CAPSULE, quat=_AXLE_QUAT,
                      size=_r((0.025, p.l4, 0.0)), rgba=[0.2, 0.4, 0.8, 1.0])
    steering.add_site(name="C", pos=[0.0, 0.0, 0.0], size=_SITE_SIZE, rgba=[1.0, 0.0, 0.0, 1.0])
    for side, y in (("front_left", p.l4), ("front_right", -p.l4)):
        _add_wheel(steering, spec, side, y=y, mass=p.front_wheel_mass, radius=p.r3, width=p.front_wheel_width,
                   spin=p.I_y3, diametral=p.I_z3)


# The motor side's body only carries its hinge: MuJoCo's compiler refuses a moving body without
# mass; these are far below anything the dynamics sees (the armature is the motor's inertia).
_SHAFT_MASS, _SHAFT_INERTIA = 1e-6, 1e-9  # kg, kg m^2


def _add_gear_play(spec: mujoco.MjSpec, chassis: mujoco.MjsBody, p: C80Parameters, drive: _DriveTrain) -> None:
    """The gear's play: the motor side's hinge and the tendon limiting steer - steer_motor to +-b.

    The motor side is a shaft body coaxial with the steering pivot, added after the steering unit
    so that every address of today's model (steer's qpos 9 and dof 8, the wheels') is kept and
    steer_motor's come last. Its hinge carries the motor's armature and no friction: the Coulomb
    torque (l3 l4 / l1) mu Q of (2.5) is the front tyres' scrub on the floor, a load on the axle,
    so it stays on ``steer`` (the axle's bearing side of the play). The steering range (the
    axle's stops) stays on ``steer`` too; the motor side is unlimited.
    """
    shaft = chassis.add_body(name="steer_motor_shaft", pos=_r((p.l1, 0.0, p.r3 - p.r2)))
    _inertial(shaft, mass=_SHAFT_MASS, inertia=(_SHAFT_INERTIA, _SHAFT_INERTIA, _SHAFT_INERTIA))
    shaft.add_joint(name=MOTOR_JOINT, type=_HINGE, axis=[0.0, 0.0, 1.0],
                    armature=round_sig(drive.motor_armature_kgm2))
    b = drive.transmission.backlash
    play = spec.add_tendon(name=GEAR_PLAY_TENDON, range=_r((-b, b)))
    play.solref_limit = list(GEAR_PLAY_SOLREF)
    play.solimp_limit = list(GEAR_PLAY_SOLIMP)
    play.wrap_joint(STEERING_JOINT, 1.0)
    play.wrap_joint(MOTOR_JOINT, -1.0)


def _add_actuators(spec: mujoco.MjSpec, p: C80Parameters, drive: _DriveTrain) -> None:
    """The open differential, the DC steering motor (2.9)-(2.11) and the drive's velocity servo.

    The motor drives ``steer`` (no play) or the motor side ``steer_motor`` (play); its delay,
    inductance and current limit are MuJoCo's (``nsample``/``delay``, ``inductance``,
    ``saturation``), set only where they differ from today's so the default text is unchanged.
    """
    # open differential: the drive acts on the mean rear-wheel angle, equal torque to each wheel
    differential = spec.add_tendon(name="differential")
    differential.wrap_joint("rear_left_spin", 0.5)
    differential.wrap_joint("rear_right_spin", 0.5)

    target = MOTOR_JOINT if drive.has_play else STEERING_JOINT
    motor = spec.add_actuator(name="steering_motor", target=target, trntype=mujoco.mjtTrn.mjTRN_JOINT)
    electrical: dict[str, list[float]] = {}
    actuation = drive.actuation
    if actuation.inductance > 0:
        electrical["inductance"] = [round_sig(actuation.inductance), 0.0]
    if actuation.current_limit is not None:
        electrical["saturation"] = [0.0, round_sig(actuation.current_limit), 0.0]
    motor.set_to_dcmotor(motorconst=_r((p.k_i, p.k_b)), resistance=round_sig(p.R_a), **electrical)
    if drive.delay_steps > 0:
        # the ring buffer holds exactly the delay: MuJoCo reads ctrl at time - delay (zoh)
        motor.nsample = drive.delay_steps
        motor.delay = round_sig(drive.delay_steps * TIMESTEP)
    motor.gear = [round_sig(p.i2), 0.0, 0.0, 0.0, 0.0, 0.0]
    motor.ctrlrange = _r((-p.voltage_limit, p.voltage_limit))
    # drive servo gain at the motor, N m s/rad: time constant of the vehicle's speed
    inertia_at_wheels = p.total_mass * p.r2**2 + 2 * p.I_y2 + 2 * p.I_y3 * (p.r2 / p.r3) ** 2
    drive_kv = inertia_at_wheels / DRIVE_TIME_CONSTANT / p.i1**2
    servo = spec.add_actuator(name="drive", target="differential", trntype=mujoco.mjtTrn.mjTRN_TENDON)
    servo.set_to_velocity(kv=round_sig(drive_kv))
    servo.gear = [round_sig(p.i1), 0.0, 0.0, 0.0, 0.0, 0.0]


def _add_sensors(spec: mujoco.MjSpec, drive: _DriveTrain) -> None:
    """Steering angle, rate and torques; positions of A and C; the chassis's attitude; A's velocity.

    With play, ``steer_joint_torque`` is the motor's torque at its side of the play (the only
    joint the motor acts on) and ``steer_motor_angle`` is added last.
    """
    sens, obj_t = mujoco.mjtSensor, mujoco.mjtObj
    motor_joint = MOTOR_JOINT if drive.has_play else STEERING_JOINT
    for name, kind, objtype, obj in (
        ("steer_angle", sens.mjSENS_JOINTPOS, obj_t.mjOBJ_JOINT, "steer"),
        ("steer_rate", sens.mjSENS_JOINTVEL, obj_t.mjOBJ_JOINT, "steer"),
        ("steer_motor_torque", sens.mjSENS_ACTUATORFRC, obj_t.mjOBJ_ACTUATOR, "steering_motor"),
        ("steer_joint_torque", sens.mjSENS_JOINTACTFRC, obj_t.mjOBJ_JOINT, motor_joint),
        ("A_pos", sens.mjSENS_FRAMEPOS, obj_t.mjOBJ_SITE, "A"),
        ("C_pos", sens.mjSENS_FRAMEPOS, obj_t.mjOBJ_SITE, "C"),
        ("chassis_quat", sens.mjSENS_FRAMEQUAT, obj_t.mjOBJ_BODY, "chassis"),
        ("A_vel", sens.mjSENS_FRAMELINVEL, obj_t.mjOBJ_SITE, "A"),
    ):
        spec.add_sensor(name=name, type=kind, objtype=objtype, objname=obj)
    if drive.has_play:
        spec.add_sensor(name="steer_motor_angle", type=sens.mjSENS_JOINTPOS, objtype=obj_t.mjOBJ_JOINT,
                        objname=MOTOR_JOINT)


def _add_home_key(spec: mujoco.MjSpec, p: C80Parameters, drive: _DriveTrain) -> None:
    """The ``home`` key: rolling straight ahead at V_A, the drive commanding i1 V_A / r2."""
    # qpos order: free joint (7), rear_left, rear_right, steer, front_left, front_right[, steer_motor]
    w2, w3 = p.V_A / p.r2, p.V_A / p.r3
    extra = (0.0,) if drive.has_play else ()
    spec.add_key(name="home",
                 qpos=_r((0.0, 0.0, p.r2, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0) + extra),
                 qvel=_r((p.V_A, 0.0, 0.0, 0.0, 0.0, 0.0, w2, w2, 0.0, w3, w3) + extra),
                 ctrl=_r((0.0, p.i1 * w2)))


def _add_world(spec: mujoco.MjSpec, params: C80Parameters, tyre_contact: str = "stiff") -> None:
    """Floor, light, sky and the viewer's defaults (what scene.xml adds to the robot)."""
    spec.visual.headlight.diffuse = [0.6, 0.6, 0.6]
    spec.visual.headlight.ambient = [0.3, 0.3, 0.3]
    spec.visual.headlight.specular = [0.0, 0.0, 0.0]
    spec.visual.global_.azimuth = 150.0
    spec.visual.global_.elevation = -25.0
    T = mujoco.mjtTexture
    spec.add_texture(type=T.mjTEXTURE_SKYBOX, builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
                     rgb1=[0.3, 0.5, 0.7], rgb2=[0.0, 0.0, 0.0], width=512, height=3072)
    spec.add_texture(name="groundplane", type=T.mjTEXTURE_2D, builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
                     mark=mujoco.mjtMark.mjMARK_EDGE, rgb1=[0.2, 0.3, 0.4], rgb2=[0.1, 0.2, 0.3],
                     markrgb=[0.8, 0.8, 0.8], width=300, height=300)
    material = spec.add_material(name="groundplane", texuniform=True, texrepeat=[5.0, 5.0], reflectance=0.2)
    material.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "groundplane"
    spec.worldbody.add_light(pos=[0.0, 0.0, 3.5], dir=[0.0, 0.0, -1.0], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
    spec.worldbody.add_geom(name="floor", type=_PLANE, size=[0.0, 0.0, 0.05], material="groundplane", contype=0,
                            conaffinity=1, condim=3, friction=_r((params.ground_friction, 0.0, 0.0)))
    if tyre_contact == "stiff":  # the same as the wheels: MuJoCo averages the two geoms' solref
        spec.geom("floor").solref = list(TYRE_CONTACT_SOLREF)


def scene_spec(params: C80Parameters = C80, *, steering_friction: str = "stiction",
               tyre_contact: str = "stiff", actuation_delay_s: float = 0.0,
               inductance_H: float = 0.0, current_limit_A: float | None = None, backlash_rad: float = 0.0,
               motor_armature_kgm2: float = MOTOR_ARMATURE) -> mujoco.MjSpec:
    """The robot and the floor in one MjSpec (what runs simulate); options as :func:`robot_spec`."""
    spec = robot_spec(params, steering_friction=steering_friction, tyre_contact=tyre_contact,
                      actuation_delay_s=actuation_delay_s, inductance_H=inductance_H,
                      current_limit_A=current_limit_A, backlash_rad=backlash_rad,
                      motor_armature_kgm2=motor_armature_kgm2)
    spec.modelname = "c80 scene"
    options = _drive_train(actuation_delay_s=actuation_delay_s, inductance_H=inductance_H,
                      current_limit_A=current_limit_A, backlash_rad=backlash_rad,
                      motor_armature_kgm2=motor_armature_kgm2, cart_inductance_H=params.L_a).comment()
    spec.comment = (" C80 scene (robot and floor), generated by wmr_mj.plant.mjcf.scene_spec from wmr_mj.params "
                    f"with steering_friction={steering_friction!r}, tyre_contact={tyre_contact!r}"
                    + (f", {options}" if options else "") + ". ")
    _add_world(spec, params, tyre_contact)
    return spec


def robot_xml(params: C80Parameters = C80, *, steering_friction: str = "stiction", tyre_contact: str = "stiff",
              actuation_delay_s: float = 0.0,
               inductance_H: float = 0.0, current_limit_A: float | None = None, backlash_rad: float = 0.0,
               motor_armature_kgm2: float = MOTOR_ARMATURE) -> str:
    """MJCF of the C80 alone (no floor): ``robot_spec(params, ...).to_xml()``."""
    return robot_spec(params, steering_friction=steering_friction, tyre_contact=tyre_contact,
                      actuation_delay_s=actuation_delay_s, inductance_H=inductance_H,
                      current_limit_A=current_limit_A, backlash_rad=backlash_rad,
                      motor_armature_kgm2=motor_armature_kgm2).to_xml()


#: The comment scene.xml carries above its floor.
FLOOR_COMMENT = ("<!-- The floor's contact settings (friction = ground_friction, solref) are physics, not "
                 "rendering: every wheel contact uses them (MuJoCo takes the larger friction of the two geoms "
                 "and averages their solref). -->")


def scene_file_xml(params: C80Parameters = C80) -> str:
    """``models/scene.xml``: includes c80.xml, adds floor and light.

    MjSpec has no include element, so the world-only spec's text gets the one
    ``<include>`` line after its opening tag and comment. MjSpec always writes a
    ``<compiler>`` element; c80.xml has the one the model needs (angles in radians,
    and the scene has none), so the scene's is left out, and the floor gets
    :data:`FLOOR_COMMENT`.
    """
    spec = mujoco.MjSpec()
    spec.modelname = "c80 scene"
    spec.comment = " C80 scene, generated by wmr_mj.plant.mjcf.scene_file_xml; do not edit by hand. "
    spec.compiler.degree = False
    _add_world(spec, params)
    head, sep, tail = spec.to_xml().partition("-->\n")
    compiler = '  <compiler angle="radian"/>\n\n'
    floor = '    <geom name="floor"'
    if not tail.startswith(compiler) or tail.count(floor) != 1:
        raise ModelFileError("MjSpec.to_xml wrote the scene in an unexpected form; update scene_file_xml")
    tail = tail[len(compiler):].replace(floor, f"    {FLOOR_COMMENT}\n{floor}")
    return head + sep + '  <include file="c80.xml"/>\n\n' + tail


def scene_xml(params: C80Parameters = C80, *, steering_friction: str = "stiction", tyre_contact: str = "stiff",
              actuation_delay_s: float = 0.0,
               inductance_H: float = 0.0, current_limit_A: float | None = None, backlash_rad: float = 0.0,
               motor_armature_kgm2: float = MOTOR_ARMATURE) -> str:
    """One self-contained MJCF string: the robot and the floor (what runs simulate)."""
    return spec_xml(scene_spec(params, steering_friction=steering_friction, tyre_contact=tyre_contact,
                               actuation_delay_s=actuation_delay_s, inductance_H=inductance_H,
                      current_limit_A=current_limit_A, backlash_rad=backlash_rad,
                      motor_armature_kgm2=motor_armature_kgm2))


def spec_xml(spec: mujoco.MjSpec) -> str:
    """``spec.to_xml()``, the same text, without generating the sky's pixels.

    to_xml compiles the spec, and the 512x3072 sky gradient is 95% of compiling the scene
    (about 67 of 75 ms): the spec is written with a 1x6 sky and the size put back in that
    element's text (tests/test_plant.py compares with to_xml).
    """
    sky = [t for t in spec.textures if t.type == mujoco.mjtTexture.mjTEXTURE_SKYBOX]
    if len(sky) != 1:
        return spec.to_xml()
    texture = sky[0]
    width, height = int(texture.width), int(texture.height)
    small, full = 'width="1" height="6"', f'width="{width}" height="{height}"'
    texture.width, texture.height = 1, 6
    try:
        xml = spec.to_xml()
    finally:
        texture.width, texture.height = width, height
    lines = xml.split("\n")
    at = [i for i, line in enumerate(lines) if 'type="skybox"' in line and small in line]
    if len(at) != 1:
        return spec.to_xml()
    lines[at[0]] = lines[at[0]].replace(small, full)
    return "\n".join(lines)


def _compile(xml: str, source: str) -> mujoco.MjModel:
    try:
        return mujoco.MjModel.from_xml_string(xml)
    except ValueError as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else "compile error"
        raise ModelFileError(f"{source}: MuJoCo cannot compile it: {first}") from None


def compile_model(params: C80Parameters = C80, *, steering_friction: str = "stiction",
                  tyre_contact: str = "stiff", actuation_delay_s: float = 0.0,
               inductance_H: float = 0.0, current_limit_A: float | None = None, backlash_rad: float = 0.0,
               motor_armature_kgm2: float = MOTOR_ARMATURE) -> tuple[mujoco.MjModel, str]:
    """(model, xml) of the C80 scene for ``params``; xml is exactly what was compiled.

    steering_friction: one of STEERING_FRICTION_MODELS; tyre_contact: one of TYRE_CONTACT_MODELS;
    the actuation and backlash options as :func:`robot_spec` (their defaults: today's model).
    """
    xml = scene_xml(params, steering_friction=steering_friction, tyre_contact=tyre_contact,
                    actuation_delay_s=actuation_delay_s, inductance_H=inductance_H,
                      current_limit_A=current_limit_A, backlash_rad=backlash_rad,
                      motor_armature_kgm2=motor_armature_kgm2)
    return _compile(xml, "generated C80 scene"), xml


def load_model_file(path: str | Path) -> mujoco.MjModel:
    """Compile an MJCF file; a missing or malformed file raises ModelFileError."""
    path = Path(path)
    if not path.is_file():
        raise ModelFileError(f"model file {str(path)!r} does not exist; give a path to an MJCF (.xml) file")
    try:
        return mujoco.MjModel.from_xml_path(str(path))
    except ValueError as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else "compile error"
        raise ModelFileError(f"model file {str(path)!r} is not a valid MJCF model: {first}") from None


@dataclass(frozen=True)
class SteeringAddresses:
    """Where a compiled C80 keeps its steering: the axle (alpha), the motor side, the current.

    Without play the motor side is the axle (``motor_qpos == axle_qpos``). The motor shaft's
    angle is ``i2 * data.qpos[motor_qpos]`` (an encoder on the motor shaft reads it); the
    armature current is ``data.act[current_act]`` A where the motor has inductance, else it is
    algebraic and equals ``data.actuator_force[actuator] / sqrt(k_i k_b)``.
    """

    axle_qpos: int  # qpos address of ``steer``: alpha, rad
    axle_dof: int  # dof address of ``steer``: alpha', rad/s
    motor_qpos: int  # qpos address of the motor side at the steering axis, rad
    motor_dof: int  # dof address of the motor side (where the motor's torque acts)
    actuator: int  # id of ``steering_motor``
    current_act: int | None  # index into data.act of the armature current, A; None: no inductance
    play_tendon: int | None  # id of the ``gear_play`` tendon (steer - steer_motor, rad); None: no play

    @property
    def has_play(self) -> bool:
        return self.play_tendon is not None


def steering_joint_addresses(model: mujoco.MjModel) -> SteeringAddresses:
    """The steering's addresses in ``model`` (any C80 built here, with or without play).

    Raises:
        ModelFileError: the model has no ``steer`` joint or ``steering_motor`` actuator.
    """
    try:
        axle = model.joint(STEERING_JOINT).id
        actuator = model.actuator("steering_motor").id
    except KeyError:
        raise ModelFileError("the model has no 'steer' joint or 'steering_motor' actuator; "
                             "give a C80 model built by wmr_mj.plant.mjcf") from None
    motor = int(model.actuator_trnid[actuator, 0])
    play = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TENDON, GEAR_PLAY_TENDON)
    current = int(model.actuator_actadr[actuator]) if model.actuator_actnum[actuator] > 0 else None
    return SteeringAddresses(axle_qpos=int(model.jnt_qposadr[axle]), axle_dof=int(model.jnt_dofadr[axle]),
                             motor_qpos=int(model.jnt_qposadr[motor]), motor_dof=int(model.jnt_dofadr[motor]),
                             actuator=int(actuator), current_act=current, play_tendon=play if play >= 0 else None)


@dataclass
class Plant:
    """A compiled C80 scene with MjData at the home keyframe and named indices.

    All indices are resolved once here so the control loop reads arrays only.
    """

    params: C80Parameters = C80
    steering_friction: str = field(default="stiction", kw_only=True)  # one of STEERING_FRICTION_MODELS
    tyre_contact: str = field(default="stiff", kw_only=True)  # one of TYRE_CONTACT_MODELS
    actuation_delay_s: float = field(default=0.0, kw_only=True)  # s, see robot_spec
    inductance_H: float = field(default=0.0, kw_only=True)  # H
    current_limit_A: float | None = field(default=None, kw_only=True)  # A, None: no limit
    backlash_rad: float = field(default=0.0, kw_only=True)  # rad at the steering axis
    motor_armature_kgm2: float = field(default=MOTOR_ARMATURE, kw_only=True)  # kg m^2, with play only
    model: mujoco.MjModel = field(init=False)
    data: mujoco.MjData = field(init=False)
    xml: str = field(init=False)

    def __post_init__(self) -> None:
        self.model, self.xml = compile_model(
            self.params, steering_friction=self.steering_friction, tyre_contact=self.tyre_contact,
            actuation_delay_s=self.actuation_delay_s, inductance_H=self.inductance_H,
            current_limit_A=self.current_limit_A, backlash_rad=self.backlash_rad,
            motor_armature_kgm2=self.motor_armature_kgm2)
        self.data = mujoco.MjData(self.model)
        m = self.model
        self.steering = steering_joint_addresses(m)
        self.steer_qpos = m.jnt_qposadr[m.joint("steer").id]
        self.steer_dof = m.jnt_dofadr[m.joint("steer").id]
        self.steer_actuator = m.actuator("steering_motor").id
        self.drive_actuator = m.actuator("drive").id
        self.site_A = m.site("A").id
        self.site_C = m.site("C").id
        self.chassis_body = m.body("chassis").id
        self.home = m.key("home").id
        self.reset()

    def reset(self) -> None:
        mujoco.mj_resetDataKeyframe(self.model, self.data, self.home)
        mujoco.mj_forward(self.model, self.data)

    @property
    def motor_constant(self) -> float:
        """Effective dcmotor constant MuJoCo uses, sqrt(k_i k_b), N m/A."""
        return math.sqrt(self.params.k_i * self.params.k_b)

    def steering_state(self) -> tuple[float, float]:
        d = self.data
        return float(d.qpos[self.steer_qpos]), float(d.qvel[self.steer_dof])

    def heading(self) -> float:
        q = self.data.xquat[self.chassis_body]
        return math.atan2(2 * (q[0] * q[3] + q[1] * q[2]), 1 - 2 * (q[2] ** 2 + q[3] ** 2))

    def motor_current(self) -> float:
        """Armature current, A: motor torque (actuator force) / k_i."""
        return float(self.data.actuator_force[self.steer_actuator]) / self.params.k_i

    def steer_torque(self) -> float:
        """Torque of the motor at the steering joint (after the gear; with play, at its motor side), N m."""
        return float(self.data.qfrc_actuator[self.steering.motor_dof])


def write_model_files(params: C80Parameters = C80, directory: Path = MODELS_DIR) -> list[Path]:
    """Write models/c80.xml and models/scene.xml from ``params``."""
    directory.mkdir(parents=True, exist_ok=True)
    out = []
    for name, text in (("c80.xml", robot_xml(params)), ("scene.xml", scene_file_xml(params))):
        path = directory / name
        path.write_text(text)
        out.append(path)
    return out


WHEELS = ("rear_left", "rear_right", "front_left", "front_right")


def wheel_contact_slip(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Side-slip speed of each wheel's contact point, m/s (lateral velocity of the
    material point of the wheel at the contact, in the wheel's lateral direction)."""
    out = []
    for name in WHEELS:
        body = model.body(f"{name}_wheel").id
        geom = model.geom(f"{name}_contact").id
        radius = model.geom_size[geom][0]
        centre = data.xpos[body]
        point = centre - np.array([0.0, 0.0, radius])
        # velocity of the wheel body's material point at the contact
        jacp = np.zeros((3, model.nv))
        mujoco.mj_jac(model, data, jacp, None, point, body)
        v = jacp @ data.qvel
        lateral = data.xmat[body].reshape(3, 3)[:, 1]  # wheel axle direction
        out.append(float(v @ lateral))
    return np.asarray(out)


def wheel_side_force_ratio(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """|side force| / normal force at each wheel's contact (side: along the wheel's axle)."""
    out = np.zeros(len(WHEELS))
    wheel_of = {model.geom(f"{name}_contact").id: i for i, name in enumerate(WHEELS)}
    force = np.zeros(6)
    for i in range(data.ncon):
        c = data.contact[i]
        geom = c.geom1 if c.geom1 in wheel_of else c.geom2
        if geom not in wheel_of:
            continue
        mujoco.mj_contactForce(model, data, i, force)  # contact frame: normal, then two tangents
        world = c.frame.reshape(3, 3).T @ force[:3]
        lateral = data.xmat[model.geom_bodyid[geom]].reshape(3, 3)[:, 1]
        out[wheel_of[geom]] = abs(world @ lateral) / force[0] if force[0] > 0 else 0.0
    return out


def measure_side_slip(params: C80Parameters = C80, *, radius: float = 1.0, duration: float = 30.0,
                      settle: float = 10.0, steering_friction: str = "stiction",
                      tyre_contact: str = "stiff") -> dict[str, float]:
    """Drive the scene on the steady circle of C (alpha = asin(l1/R), held by a stiff PD on the
    dcmotor, within F/300 rad) and measure each wheel's side slip after ``settle`` s.

    Returns the largest and rms side-slip speed over the wheels (m/s), the same as a
    fraction of V_A, the slip angle atan(slip / V_A) in rad, the largest side/normal force
    ratio of a wheel, and the range over the wheels of the contact's cornering coefficient
    (side/normal force ratio per rad of slip angle, time means; a tyre's C_alpha / F_z).
    """
    plant = Plant(params, steering_friction=steering_friction, tyre_contact=tyre_contact)
    m, d = plant.model, plant.data
    alpha_ss = math.asin(params.l1 / radius)
    n = int(round(duration / m.opt.timestep))
    k_settle = int(round(settle / m.opt.timestep))
    samples, ratios = [], []
    for k in range(n):
        a, ad = d.qpos[plant.steer_qpos], d.qvel[plant.steer_dof]
        # stiff PD (V/rad, V s/rad): stiction leaves a dead band F / 300 = 5 mrad around the circle's angle
        d.ctrl[plant.steer_actuator] = min(max(300.0 * (alpha_ss - a) - 10.0 * ad, -params.voltage_limit),
                                           params.voltage_limit)
        mujoco.mj_step(m, d)
        if k >= k_settle and k % 20 == 0:
            mujoco.mj_forward(m, d)
            samples.append(wheel_contact_slip(m, d))
            ratios.append(wheel_side_force_ratio(m, d))
    s = np.abs(np.asarray(samples))
    worst = float(s.max())
    cornering = np.mean(ratios, axis=0) / np.arctan2(s.mean(axis=0), params.V_A)
    return {"max_slip_m_s": worst, "rms_slip_m_s": float(np.sqrt((s**2).mean())),
            "max_slip_fraction": worst / params.V_A, "max_slip_angle_rad": math.atan2(worst, params.V_A),
            "max_side_force_ratio": float(np.max(np.mean(ratios, axis=0))),
            "cornering_coefficient_min": float(cornering.min()), "cornering_coefficient_max": float(cornering.max()),
            "alpha": float(d.qpos[plant.steer_qpos]), "alpha_target": alpha_ss}
