"""The C80 parameter set: the one source of every number in the plant.

The paper (Hendzel, "Robustness problem in control of wheeled mobile robot",
``../shared/seed/``) gives no dimensions of the C80. The values below describe a
plausible compact cart chosen so that the paper's own formulas (2.3), (2.7) and
(2.13) reproduce its numerical example (5.1); each field says where its value
comes from. All quantities are SI: m, kg, s, rad, V, A, Ohm, N m.

Every number and source of the C80 is read from its cart file, ``wmr_mj/carts/c80.toml``
(:data:`C80_CART`): the parameter set's defaults, the m1 range and the uncertainty boxes. The
dataclass below fixes the fields, their order and the formulas; the file fixes the values.

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
import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any, Literal, get_args

from wmr_mj.carts import CartFile, cart_of_text, load_cart
from wmr_mj.carts.cartfile import MAX_ELECTRICAL_TIME_CONSTANT_S, MOTOR_CONSTANT_RTOL
from wmr_mj.errors import ParameterError, UnknownNameError

__all__ = [
    "C80Parameters",
    "C80",
    "C80_CART",
    "parameters_of_cart",
    "parameters_of_cart_text",
    "check_physical_sense",
    "check_motor_constant",
    "Coefficients",
    "COEFFICIENT_NAMES",
    "CoefficientModel",
    "COEFFICIENT_MODELS",
    "with_params",
    "parameter_names",
    "tie_motor_constant",
    "PARAMETER_SOURCES",
    "PAPER_KP",
    "PAPER_KD",
    "M1_NOMINAL",
    "M1_RANGE",
    "UNCERTAINTY_NAMES",
    "UNCERTAINTY_SOURCES",
    "uncertainty_ranges",
]

#: The C80's cart file: the one source of every number below (values, sources, ranges).
C80_CART: CartFile = load_cart("c80")
_C80_VALUES = C80_CART.parameters

# The paper's design (5.1), a controller's gains and not a fact of the cart: written here once.
PAPER_KP = 6.0  # K_P of (5.1), 1/s^2
PAPER_KD = 9.0  # K_D of (5.1), 1/s
M1_NOMINAL = _C80_VALUES["m1"]  # kg, the centre of (5.1)'s 550-750 kg: the C80's m1
M1_RANGE: tuple[float, float] = C80_CART.uncertainty["m1"]["m1"]  # kg, (5.1)

# Uncertainty boxes for model-mismatch experiments: parameter name -> (lo, hi) in its
# SI unit. 'm1' is the paper's; 'full' adds what a real C80 also varies in.
_UNCERTAINTY: dict[str, dict[str, tuple[float, float]]] = {box: dict(r) for box, r in C80_CART.uncertainty.items()}
UNCERTAINTY_NAMES = tuple(_UNCERTAINTY)
#: Where each range of the 'full' box comes from.
UNCERTAINTY_SOURCES: dict[str, str] = dict(C80_CART.uncertainty_sources["full"])


def uncertainty_ranges(name: str) -> dict[str, tuple[float, float]]:
    """The ranged parameters of uncertainty box ``name`` ('m1' or 'full'), name -> (lo, hi)."""
    if name not in _UNCERTAINTY:
        raise UnknownNameError("uncertainty box name", name, UNCERTAINTY_NAMES)
    return dict(_UNCERTAINTY[name])

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

    def to_dict(self) -> dict[str, float]:
        return dataclasses.asdict(self)


#: The reduced model's coefficients, in (2.13)'s order: the fields of :class:`Coefficients`, what
#: identification fits and what an estimate names.
COEFFICIENT_NAMES: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(Coefficients))

#: The models :meth:`C80Parameters.coefficients` derives coefficients for: the paper's (2.13) and
#: the non-holonomic one (wmr_mj.plant.reduced adds 'paper-lagrange', a variant of the paper's).
CoefficientModel = Literal["paper", "nonholonomic"]
COEFFICIENT_MODELS: tuple[str, ...] = get_args(CoefficientModel)


#: The parameters that may be 0 (every other one is > 0): the armature inductance L_a (0: no electrical lag).
NONNEGATIVE_PARAMETERS: frozenset[str] = frozenset({"L_a"})


@dataclass(frozen=True, kw_only=True)
class C80Parameters:
    """Physical parameters of the C80 cart (SI units). The defaults are the C80's, read from its cart file
    (``wmr_mj/carts/c80.toml``); see PARAMETER_SOURCES."""

    V_A: float = _C80_VALUES["V_A"]
    g: float = _C80_VALUES["g"]
    # unit a: chassis
    m1: float = _C80_VALUES["m1"]
    chassis_length: float = _C80_VALUES["chassis_length"]
    chassis_width: float = _C80_VALUES["chassis_width"]
    chassis_height: float = _C80_VALUES["chassis_height"]
    chassis_inertia_mass: float = _C80_VALUES["chassis_inertia_mass"]
    # geometry
    l1: float = _C80_VALUES["l1"]
    l2: float = _C80_VALUES["l2"]
    l3: float = _C80_VALUES["l3"]
    l4: float = _C80_VALUES["l4"]
    # unit b: rear drive
    rear_axle_mass: float = _C80_VALUES["rear_axle_mass"]
    rear_wheel_mass: float = _C80_VALUES["rear_wheel_mass"]
    r2: float = _C80_VALUES["r2"]
    rear_wheel_width: float = _C80_VALUES["rear_wheel_width"]
    i1: float = _C80_VALUES["i1"]
    # unit c: front steering
    front_axle_mass: float = _C80_VALUES["front_axle_mass"]
    front_wheel_mass: float = _C80_VALUES["front_wheel_mass"]
    r3: float = _C80_VALUES["r3"]
    front_wheel_width: float = _C80_VALUES["front_wheel_width"]
    # steering motor (2.9)-(2.10)
    R_a: float = _C80_VALUES["R_a"]
    # the armature inductance L_a, H (>= 0; 0: the current follows the voltage at once, the paper's (2.10)); the
    # default inductance of the dcmotor (wmr_mj.plant.mjcf), which ``--actuation inductance=`` overrides
    L_a: float = _C80_VALUES["L_a"]
    k_i: float = _C80_VALUES["k_i"]
    k_b: float = _C80_VALUES["k_b"]
    i2: float = _C80_VALUES["i2"]
    voltage_limit: float = _C80_VALUES["voltage_limit"]
    steering_range: float = _C80_VALUES["steering_range"]
    # friction (2.5)
    mu: float = _C80_VALUES["mu"]
    f2: float = _C80_VALUES["f2"]
    f3: float = _C80_VALUES["f3"]
    ground_friction: float = _C80_VALUES["ground_friction"]

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterError(
                    f"parameter {f.name} must be a number, got {value!r}"
                )
            if f.name in NONNEGATIVE_PARAMETERS:
                if not math.isfinite(value) or value < 0.0:
                    raise ParameterError(f"parameter {f.name} = {value!r} is not accepted: it must be finite and >= 0")
            elif not math.isfinite(value) or value <= 0.0:
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

    def to_dict(self) -> dict[str, float]:
        return dataclasses.asdict(self)


C80 = C80Parameters()


def parameter_names() -> tuple[str, ...]:
    return tuple(f.name for f in fields(C80Parameters))


def tie_motor_constant(drawn: Mapping[str, float],
                       ranges: Mapping[str, tuple[float, float]]) -> dict[str, float]:
    """A draw of a box's plant parameters with the motor's one constant tied: k_b = k_i where the box ranges both.

    In SI units the torque constant k_i [N m/A] and the back-EMF constant k_b [V s/rad] are one flux (a cart file
    must have them equal, :mod:`wmr_mj.carts.cartfile`), so a box that ranges both (an identified cart's does, over
    one interval) names one axis twice. A run takes k_b = k_i: the point (k_i, k_i) lies inside the box whenever
    k_b's range holds k_i's, so the run stays inside what its certificate covers (the certificate's hull is taken
    over the box's corners, which hold that diagonal).

    Args:
        drawn: parameter name -> drawn value (SI units).
        ranges: parameter name -> its range (lo, hi) in the box the draw came from.

    Returns:
        A copy of ``drawn``, with k_b set to k_i where both are drawn.

    Raises:
        ParameterError: both are drawn and k_b's range does not hold k_i's (no run could have k_b = k_i inside).
    """
    tied = dict(drawn)
    if "k_i" in tied and "k_b" in tied:
        (i_lo, i_hi), (b_lo, b_hi) = ranges["k_i"], ranges["k_b"]
        if not (b_lo <= i_lo and i_hi <= b_hi):
            raise ParameterError(f"the box ranges k_i over [{i_lo:g}, {i_hi:g}] N m/A and k_b over [{b_lo:g}, "
                                 f"{b_hi:g}] V s/rad; accepted: k_b's range holding k_i's (one flux in SI units: "
                                 "a run has k_b = k_i)")
        tied["k_b"] = tied["k_i"]
    return tied


def check_motor_constant(k_i: float, k_b: float) -> None:
    """k_b equal to k_i, as a cart file must have them (:mod:`wmr_mj.carts.cartfile`): one flux in SI units, and
    MuJoCo's dcmotor has one constant (it would silently use their geometric mean). Every command that takes
    ``--param`` checks it after its overrides.

    Args:
        k_i: the torque constant, N m/A. k_b: the back-EMF constant, V s/rad.

    Raises:
        ParameterError: they differ by more than a rounding (one line naming both and what is accepted).
    """
    if abs(k_b - k_i) > MOTOR_CONSTANT_RTOL * abs(k_i):
        raise ParameterError(f"--param: k_b = {k_b!r} V s/rad and k_i = {k_i!r} N m/A differ; accepted: k_b equal to "
                             "k_i (one flux in SI units; MuJoCo's dcmotor has one constant), e.g. --param "
                             f"k_i={k_i!r} --param k_b={k_i!r}")


#: One line per field: where its value comes from (the C80 cart file's sources, in the fields' order).
PARAMETER_SOURCES: dict[str, str] = {name: C80_CART.sources[name] for name in parameter_names()}


#: The largest ratio of two body masses of the multibody model a parameter set may ask for. Measured on the C80's
#: bodies (2026-11-28, MuJoCo 4.0, 1 s of random steering voltages at the 1 ms step): m1 = 10^7.5 kg (a ratio of
#: 4.0e6 to the 8 kg front wheel) stepped with no warning, m1 = 1e8 kg (1.25e7) warned at once that the inertia
#: matrix is too close to singular; 1e6 keeps a factor of 4 from the first warning.
MAX_BODY_MASS_RATIO = 1e6


def check_physical_sense(p: C80Parameters) -> None:
    """Refuses a parameter set whose plant is absurd, before any step: what a cart file's schema cannot say.

    Checked: the reduced coefficients of both models are finite (P, C_V > 0; F, K, gyro >= 0); the supply breaks
    the steering's friction (F, the voltage whose stall torque equals the steering's Coulomb torque, below
    voltage_limit: otherwise the motor cannot move the steering at all); the body masses within
    :data:`MAX_BODY_MASS_RATIO` of each other (beyond it MuJoCo warns of a singular inertia matrix); the armature's
    L_a/R_a at most :data:`wmr_mj.carts.cartfile.MAX_ELECTRICAL_TIME_CONSTANT_S`.

    Raises:
        ParameterError: one line naming the culprit, its value and what is accepted.
    """
    masses = {"m1": p.m1, "rear_axle_mass": p.rear_axle_mass, "rear_wheel_mass": p.rear_wheel_mass,
              "front_axle_mass": p.front_axle_mass, "front_wheel_mass": p.front_wheel_mass}
    heavy, light = max(masses, key=masses.__getitem__), min(masses, key=masses.__getitem__)
    if masses[heavy] > MAX_BODY_MASS_RATIO * masses[light]:
        raise ParameterError(
            f"{heavy} = {masses[heavy]:.4g} kg is {masses[heavy] / masses[light]:.3g} times {light} = "
            f"{masses[light]:.4g} kg; accepted: a ratio of at most {MAX_BODY_MASS_RATIO:.0e} (beyond it MuJoCo "
            "warns that the inertia matrix is singular)")
    for model in COEFFICIENT_MODELS:
        c = p.coefficients(model)
        for name, value in c.to_dict().items():
            positive = name in ("P", "C_V")
            if not math.isfinite(value) or (value <= 0.0 if positive else value < 0.0):
                raise ParameterError(
                    f"the reduced coefficient {name} = {value!r} ({model} model) is not accepted; accepted: finite and "
                    f"{'> 0' if positive else '>= 0'} (check R_a, k_i, i2, the masses and the geometry it is made of)")
    if not p.L_a / p.R_a <= MAX_ELECTRICAL_TIME_CONSTANT_S:
        raise ParameterError(
            f"L_a = {p.L_a:.4g} H is not accepted: its electrical time constant L_a/R_a = {p.L_a / p.R_a:.3g} s (R_a = "
            f"{p.R_a:.4g} Ohm) exceeds {MAX_ELECTRICAL_TIME_CONSTANT_S:g} s; accepted: L_a <= "
            f"{MAX_ELECTRICAL_TIME_CONSTANT_S * p.R_a:.4g} H")
    F = p.coefficients("paper").F
    if not F < p.voltage_limit:
        raise ParameterError(
            f"the motor cannot move the steering: its Coulomb friction needs F = {F:.4g} V at stall "
            f"((R_a/k_i) (l3 l4/(l1 i2)) mu Q, from R_a = {p.R_a:.4g} Ohm, k_i = {p.k_i:.4g} N m/A, i2 = {p.i2:.4g}, "
            f"mu = {p.mu:.4g}) and the supply gives voltage_limit = {p.voltage_limit:.4g} V; accepted: F below the "
            "supply")


def parameters_of_cart(cart: CartFile) -> C80Parameters:
    """The parameter set of a checked cart file (:func:`wmr_mj.carts.load_cart`).

    Raises:
        ParameterError: the file's keys are not the parameter set's fields, or a value the parameter set
            refuses (the message names the file).
    """
    names = parameter_names()
    if set(cart.parameters) != set(names):
        odd = sorted(set(cart.parameters) ^ set(names))
        raise ParameterError(f"cart file {str(cart.path)!r}: its parameters differ from the parameter set's in "
                             f"{', '.join(odd)}; accepted: exactly {', '.join(names)}")
    try:
        params = C80Parameters(**{name: cart.parameters[name] for name in names})
        check_physical_sense(params)
        return params
    except ParameterError as exc:
        raise ParameterError(f"cart file {str(cart.path)!r}: {exc}") from None


@functools.lru_cache(maxsize=8)  # once per cart text: each coercion of a config on the cart, and its default path, ask
def parameters_of_cart_text(text: str, path: str) -> C80Parameters:
    """:func:`parameters_of_cart` of a run's cart record (its text and path, :func:`wmr_mj.carts.cart_of_text`),
    the last few kept.

    Raises:
        ParameterError: as :func:`parameters_of_cart`, or a text the cart file's schema refuses.
    """
    return parameters_of_cart(cart_of_text(text, path))


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
