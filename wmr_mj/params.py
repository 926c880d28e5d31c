"""The C80 parameter set: the one source of every number in the plant.

The paper (Hendzel, "Robustness problem in control of wheeled mobile robot",
``../shared/seed/``) gives no dimensions of the C80. The values below describe a
plausible compact cart chosen so that the paper's own formulas (2.3), (2.7) and
(2.13) reproduce its numerical example (5.1); each field says where its value
comes from. All quantities are SI: m, kg, s, rad, V, A, Ohm, N m.

Geometry (top view, x forward, y left, z up)::

    A      rear-axle midpoint (point of the drive unit b); V_A is its speed
    l1     wheelbase: A to the steering pivot O, along the chassis axis
    l2     rear half-track: A to each rear wheel centre
    l3     A to the chassis centre of mass (unit a), along the axis
    l4     front half-track: pivot O to each front wheel centre (unit c)
    C      the tracked point: the centre of steering unit c, i.e. the pivot O

Usage::

    from wmr_mj import C80, with_params
    heavy = with_params(C80, m1=750.0)       # payload reading of m1 (default)
    p = heavy.coefficients()                 # P, C_V, F, K, gyro, ... in volts

Masses and inertias are per unit (the paper's (2.3) reads as if m2, m3, I_y2,
I_z2, I_y3, I_z3 were per side: see ``kinetic_energy_coefficients``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, fields
from typing import Any, Literal, get_args

from wmr_mj.errors import ParameterError, UnknownNameError

__all__ = [
    "C80Parameters",
    "C80",
    "Coefficients",
    "COEFFICIENT_NAMES",
    "CoefficientModel",
    "COEFFICIENT_MODELS",
    "with_params",
    "parameter_names",
    "PARAMETER_SOURCES",
    "PAPER_KP",
    "PAPER_KD",
    "M1_NOMINAL",
    "M1_RANGE",
    "UNCERTAINTY_NAMES",
    "UNCERTAINTY_SOURCES",
    "uncertainty_ranges",
]

# The paper's design and uncertainty (5.1): written here once, imported everywhere else.
PAPER_KP = 6.0  # K_P of (5.1), 1/s^2
PAPER_KD = 9.0  # K_D of (5.1), 1/s
M1_NOMINAL = 650.0  # kg, the centre of (5.1)'s 550-750 kg
M1_RANGE = (550.0, 750.0)  # kg, (5.1)

# Uncertainty boxes for model-mismatch experiments: parameter name -> (lo, hi) in its
# SI unit. 'm1' is the paper's; 'full' adds what a real C80 also varies in.
_UNCERTAINTY: dict[str, dict[str, tuple[float, float]]] = {
    "m1": {"m1": M1_RANGE},
    "full": {
        "m1": M1_RANGE,
        "mu": (0.0129, 0.0215),
        "ground_friction": (0.6, 1.0),
        "R_a": (1.0, 1.3),
        "V_A": (0.15, 0.25),
    },
}
UNCERTAINTY_NAMES = tuple(_UNCERTAINTY)
#: Where each range of the 'full' box comes from.
UNCERTAINTY_SOURCES: dict[str, str] = {
    "m1": "(5.1): chassis mass 550-750 kg",
    "mu": "chosen: steering Coulomb coefficient +-25% around 0.0172 (lubrication, wear and load spread of a king-pin bearing)",
    "ground_friction": "chosen: tyre-floor friction 0.6 (dusty or damp concrete) to 1.0 (dry rubber on concrete)",
    "R_a": "chosen: armature resistance 1.0-1.3 Ohm, copper at +0.39 %/K from 20 C to about 95 C winding temperature",
    "V_A": "chosen: forward speed 0.15-0.25 m/s, +-25% around (5.1)'s 0.2 m/s (drive speed loop, wheel wear)",
}


def uncertainty_ranges(name: str) -> dict[str, tuple[float, float]]:
    """The ranged parameters of uncertainty box ``name`` ('m1' or 'full'), name -> (lo, hi)."""
    if name not in _UNCERTAINTY:
        raise UnknownNameError("uncertainty box name", name, UNCERTAINTY_NAMES)
    return dict(_UNCERTAINTY[name])

# One line per field: where its value comes from.
PARAMETER_SOURCES: dict[str, str] = {
    "V_A": "(5.1): the experiment's forward speed of point A, 0.2 m/s",
    "g": "standard gravity",
    "m1": "(5.1): chassis (unit a) mass, nominal 650 kg = centre of the 550-750 kg range",
    "chassis_length": "chosen: 1.75 m platform; with chassis_width gives I_z1 = 205 kg m^2 so that K(650 kg) = 5.33 V, the centre of (5.1)'s (5.29, 5.38)",
    "chassis_width": "chosen: 0.85 m platform (see chassis_length)",
    "chassis_height": "chosen: 0.30 m platform depth (roll/pitch inertia only)",
    "chassis_inertia_mass": "chosen: the chassis inertia is that of a uniform box of 650 kg; m1 beyond it is a compact payload at the chassis centre of mass (the paper's (2.3) keeps I_z1 fixed while m1 varies)",
    "l1": "chosen: 0.612 m wheelbase, so that C (the pivot) on the R = 1 m circle needs alpha = 0.659 rad and sin/cos^3 = 1.24 as in (5.1)",
    "l2": "chosen: 0.30 m rear half-track",
    "l3": "chosen: 0.142 m from A to the chassis centre of mass, so that m1 over 550-750 kg spans K over (5.29, 5.38) as in (5.1)",
    "l4": "chosen: 0.25 m front half-track (pivot to front wheel centre)",
    "rear_axle_mass": "chosen: 40 kg rear beam, differential and drive motor (unit b without wheels)",
    "rear_wheel_mass": "chosen: 10 kg per rear wheel (solid rubber tyre on steel hub)",
    "r2": "chosen: 0.15 m rear wheel radius",
    "rear_wheel_width": "chosen: 0.08 m rear wheel width (inertia only)",
    "i1": "chosen: 20:1 drive gear (not used by the steering analysis)",
    "front_axle_mass": "chosen: 14 kg front beam with the steering gear; with the wheels gives P = 0.385 V s^2/rad, inside (5.1)'s (0.37, 0.4)",
    "front_wheel_mass": "chosen: 8 kg per front wheel",
    "r3": "chosen: 0.10 m front wheel radius",
    "front_wheel_width": "chosen: 0.06 m front wheel width (inertia only)",
    "R_a": "chosen: 1.0 Ohm armature resistance of a 24 V, ~250 W permanent-magnet motor",
    "k_i": "chosen: 0.0795 N m/A = C_V / i2, with C_V = 4.77 V s/rad, the centre of (5.1)'s (4.73, 4.81)",
    "k_b": "chosen: 0.0795 V s/rad, equal to k_i in SI units",
    "i2": "chosen: 60:1 steering gear",
    "voltage_limit": "chosen: 24 V supply of the steering motor",
    "steering_range": "chosen: +-0.9 rad mechanical stops, beyond the 0.66 rad the 1 m circle needs",
    "mu": "chosen: 0.0172 Coulomb friction coefficient of the steering, so that F(650 kg) = 1.52 V lies in (5.1)'s (1.5, 1.53)",
    "f2": "chosen: 0.5 mm rolling-resistance arm of the rear wheels (2.5); acts on the drive only",
    "f3": "chosen: 0.5 mm rolling-resistance arm of the front wheels (2.5); acts on the drive only",
    "ground_friction": "chosen: 1.0 tyre-floor friction coefficient (rubber on concrete)",
}


@dataclass(frozen=True)
class Coefficients:
    """Reduced steering-model coefficients in the voltage form (2.12)-(2.13).

    P alpha'' + C_V alpha' + F sgn(alpha') + K sin(alpha)/cos^3(alpha)
      + gyro V_A alpha'/cos^2(alpha) = u      [V]
    """

    P: float  # V s^2/rad
    C_V: float  # V s/rad
    F: float  # V
    K: float  # V, coefficient of sin/cos^3
    gyro: float  # V s/m, coefficient of V_A alpha'/cos^2

    def as_dict(self) -> dict[str, float]:
        return dataclasses.asdict(self)


#: The reduced model's coefficients, in (2.13)'s order: the fields of :class:`Coefficients`, what
#: identification fits and what an estimate names.
COEFFICIENT_NAMES: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(Coefficients))

#: The models :meth:`C80Parameters.coefficients` derives coefficients for: the paper's (2.13) and
#: the non-holonomic one (wmr_mj.plant.reduced adds 'paper-lagrange', a variant of the paper's).
CoefficientModel = Literal["paper", "nonholonomic"]
COEFFICIENT_MODELS: tuple[str, ...] = get_args(CoefficientModel)


@dataclass(frozen=True, kw_only=True)
class C80Parameters:
    """Physical parameters of the C80 cart (SI units). See PARAMETER_SOURCES."""

    V_A: float = 0.2
    g: float = 9.81
    # unit a: chassis
    m1: float = 650.0
    chassis_length: float = 1.75
    chassis_width: float = 0.85
    chassis_height: float = 0.30
    chassis_inertia_mass: float = 650.0
    # geometry
    l1: float = 0.612
    l2: float = 0.30
    l3: float = 0.142
    l4: float = 0.25
    # unit b: rear drive
    rear_axle_mass: float = 40.0
    rear_wheel_mass: float = 10.0
    r2: float = 0.15
    rear_wheel_width: float = 0.08
    i1: float = 20.0
    # unit c: front steering
    front_axle_mass: float = 14.0
    front_wheel_mass: float = 8.0
    r3: float = 0.10
    front_wheel_width: float = 0.06
    # steering motor (2.9)-(2.10)
    R_a: float = 1.0
    k_i: float = 0.0795
    k_b: float = 0.0795
    i2: float = 60.0
    voltage_limit: float = 24.0
    steering_range: float = 0.9
    # friction (2.5)
    mu: float = 0.0172
    f2: float = 0.0005
    f3: float = 0.0005
    ground_friction: float = 1.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterError(
                    f"parameter {f.name} must be a number, got {value!r}"
                )
            if not math.isfinite(value) or value <= 0.0:
                raise ParameterError(
                    f"parameter {f.name} = {value!r} is not accepted: "
                    "every C80 parameter must be finite and > 0"
                )
        if self.l3 >= self.l1:
            raise ParameterError(
                f"parameter l3 = {self.l3} must be below the wheelbase l1 = {self.l1}"
            )
        if self.steering_range >= math.pi / 2:
            raise ParameterError(
                f"parameter steering_range = {self.steering_range} rad must be below pi/2"
            )

    # -- units ---------------------------------------------------------------
    @property
    def m2(self) -> float:
        """Mass of the rear drive unit b (beam + two wheels), kg."""
        return self.rear_axle_mass + 2.0 * self.rear_wheel_mass

    @property
    def m3(self) -> float:
        """Mass of the front steering unit c (beam + two wheels), kg."""
        return self.front_axle_mass + 2.0 * self.front_wheel_mass

    @property
    def total_mass(self) -> float:
        return self.m1 + self.m2 + self.m3

    @property
    def Q(self) -> float:
        """Gravity force of the whole WMR, N (2.5)."""
        return self.total_mass * self.g

    @property
    def chassis_inertia(self) -> tuple[float, float, float]:
        """Principal inertia (I_x1, I_y1, I_z1) of the chassis about its CoM, kg m^2.

        A uniform box of ``chassis_inertia_mass``; m1 beyond it is a point-like
        payload at the centre of mass, which adds no inertia about it.
        """
        m = self.chassis_inertia_mass
        a, b, c = self.chassis_length, self.chassis_width, self.chassis_height
        return (m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12)

    @property
    def I_z1(self) -> float:
        return self.chassis_inertia[2]

    @staticmethod
    def _wheel_inertia(mass: float, radius: float, width: float) -> tuple[float, float]:
        """(spin, diametral) inertia of a solid disc wheel, kg m^2."""
        return 0.5 * mass * radius**2, mass * (3 * radius**2 + width**2) / 12

    @property
    def I_y2(self) -> float:
        """Spin inertia of one rear wheel about its axle, kg m^2."""
        return self._wheel_inertia(self.rear_wheel_mass, self.r2, self.rear_wheel_width)[0]

    @property
    def I_z2(self) -> float:
        """Diametral (yaw) inertia of one rear wheel, kg m^2."""
        return self._wheel_inertia(self.rear_wheel_mass, self.r2, self.rear_wheel_width)[1]

    @property
    def I_y3(self) -> float:
        """Spin inertia of one front wheel about its axle, kg m^2."""
        return self._wheel_inertia(self.front_wheel_mass, self.r3, self.front_wheel_width)[0]

    @property
    def I_z3(self) -> float:
        """Diametral (yaw) inertia of one front wheel, kg m^2."""
        return self._wheel_inertia(self.front_wheel_mass, self.r3, self.front_wheel_width)[1]

    @property
    def rear_axle_yaw_inertia(self) -> float:
        """Rear beam as a slender rod of length 2 l2, kg m^2."""
        return self.rear_axle_mass * (2 * self.l2) ** 2 / 12

    @property
    def front_axle_yaw_inertia(self) -> float:
        """Front beam as a slender rod of length 2 l4 centred on the pivot, kg m^2."""
        return self.front_axle_mass * (2 * self.l4) ** 2 / 12

    @property
    def steering_yaw_inertia(self) -> float:
        """Yaw inertia of steering unit c about the pivot (beam and wheels), kg m^2."""
        return self.front_axle_yaw_inertia + 2 * (self.I_z3 + self.front_wheel_mass * self.l4**2)

    @property
    def steering_inertia(self) -> float:
        """Effective steering inertia J = 2D about the pivot, kg m^2.

        The yaw inertia plus the spin inertia the rolling front wheels reflect:
        turning the unit by d alpha rolls each wheel by l4 d alpha / r3.
        """
        return self.steering_yaw_inertia + 2 * self.I_y3 * (self.l4 / self.r3) ** 2

    @property
    def steering_friction_torque(self) -> float:
        """Coulomb friction torque at the steering pivot, N m: (l3 l4 / l1) mu Q, (2.5)."""
        return self.l3 * self.l4 / self.l1 * self.mu * self.Q

    # -- the paper's coefficients ----------------------------------------------
    def kinetic_energy_coefficients(self) -> dict[str, float]:
        """A, B, C, D of E = A V^2 + B V^2 tan^2 a + C V a' tan a + D a'^2, (2.2).

        Derived from the geometry (``wmr_mj.plant.derivation`` regenerates them with
        sympy) with per-unit masses:

        A = (m1 + m2 + m3)/2 + I_y2/r2^2 + I_y3/r3^2
        B = [m1 l3^2/2 + I_z1/2 + I_b2/2 + m_w2 l2^2 + I_z2 + I_y2 l2^2/r2^2 + J/2]/l1^2
            + m_b3/2 + m_w3 + I_y3/r3^2
        C = J / l1,   D = J / 2,   J = steering_inertia
        (m_w, I_y, I_z per wheel; I_b2 the rear beam's yaw inertia; m_b3 the front beam.)
        """
        J = self.steering_inertia
        A = 0.5 * self.total_mass + self.I_y2 / self.r2**2 + self.I_y3 / self.r3**2
        B = (
            0.5 * self.m1 * self.l3**2
            + 0.5 * self.I_z1
            + 0.5 * self.rear_axle_yaw_inertia
            + self.rear_wheel_mass * self.l2**2
            + self.I_z2
            + self.I_y2 * self.l2**2 / self.r2**2
            + 0.5 * J
        ) / self.l1**2 + 0.5 * self.front_axle_mass + self.front_wheel_mass + self.I_y3 / self.r3**2
        return {"A": A, "B": B, "C": J / self.l1, "D": 0.5 * J}

    def steering_model_torque_form(self) -> dict[str, float]:
        """The paper's torque form (2.7)-(2.8) at the motor shaft: H, the V(alpha)
        coefficient 2 B V_A^2 / i2 (N m), the friction torque F(alpha') / sgn (N m)."""
        ke = self.kinetic_energy_coefficients()
        return {"H": 2 * ke["D"] / self.i2, "V": 2 * ke["B"] * self.V_A**2 / self.i2,
                "F": self.steering_friction_torque / self.i2}

    def coefficients(self, model: str = "paper") -> Coefficients:
        """Reduced-model coefficients in volts for ``model`` = 'paper' or 'nonholonomic'.

        paper (2.7), (2.13): P = (R_a/k_i) 2D/i2, C_V = k_b i2,
            F = (R_a/k_i) (l3 l4/(l1 i2)) mu Q, K = (R_a/k_i) 2 B V_A^2 / i2, gyro = 0.
        nonholonomic (see ``wmr_mj.plant.reduced``): same P, C_V, F; K = 0;
            gyro = P / l1 (the chassis yaw acceleration V_A alpha'/(l1 cos^2)
            acting on the steering inertia).
        """
        if model not in COEFFICIENT_MODELS:
            raise UnknownNameError("model", model, COEFFICIENT_MODELS)
        ke = self.kinetic_energy_coefficients()
        r = self.R_a / self.k_i
        P = r * 2 * ke["D"] / self.i2
        C_V = self.k_b * self.i2
        F = r * self.steering_friction_torque / self.i2
        if model == "paper":
            return Coefficients(P=P, C_V=C_V, F=F, K=r * 2 * ke["B"] * self.V_A**2 / self.i2, gyro=0.0)
        return Coefficients(P=P, C_V=C_V, F=F, K=0.0, gyro=P / self.l1)

    def steering_torque_voltage(self, torque: float) -> float:
        """The voltage [V] equivalent to a torque [N m] on the steering joint: R_a torque/(k_i i2).

        The dcmotor gives the joint i2 k_i (u - k_b i2 a')/R_a, so a joint torque d enters the
        voltage form (2.12) as u + R_a d/(k_i i2), the factor of P and F in :meth:`coefficients`.
        """
        return self.R_a * float(torque) / (self.k_i * self.i2)

    def as_dict(self) -> dict[str, float]:
        return dataclasses.asdict(self)


C80 = C80Parameters()


def parameter_names() -> tuple[str, ...]:
    return tuple(f.name for f in fields(C80Parameters))


def with_params(base: C80Parameters = C80, /, *, m1_inertia: str = "payload", **changes: Any) -> C80Parameters:
    """A copy of ``base`` with ``changes``; the one call that changes a parameter.

    m1_inertia: how a change of m1 moves the chassis inertia. 'payload' (default)
    keeps the chassis inertia about its centre of mass (a compact load at the
    CoM, as the paper's (2.3) treats m1); 'scale' scales it with m1 (uniform
    density). Unknown names raise UnknownNameError listing the valid ones.
    """
    names = parameter_names()
    for name in changes:
        if name not in names:
            raise UnknownNameError("parameter", name, names)
    if m1_inertia not in ("payload", "scale"):
        raise UnknownNameError("m1 inertia mode", m1_inertia, ("payload", "scale"))
    coerced: dict[str, Any] = {}
    for name, value in changes.items():
        try:
            coerced[name] = float(value)
        except (TypeError, ValueError):
            raise ParameterError(f"parameter {name} must be a number, got {value!r}") from None
    if m1_inertia == "scale" and "m1" in coerced and "chassis_inertia_mass" not in coerced:
        coerced["chassis_inertia_mass"] = base.chassis_inertia_mass * coerced["m1"] / base.m1
    return dataclasses.replace(base, **coerced)
