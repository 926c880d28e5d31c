"""The plants a claim covers and the limits it must respect: :class:`PlantBox`, :class:`PlantLimits`, and
the box a run's parameter ranges span (:func:`derived_box`, :func:`friction_over_P_max`).

F and P move together. In volts F = (R_a/(k_i i2)) tau_f and P = (R_a/k_i) 2D/i2, so F/P = tau_f/(2D)
does not depend on R_a: a box where R_a is uncertain holds no plant with F_max and P_min at once. With
r >= F/P over the box (:func:`friction_over_P_max`) the friction level at P is min(F_max, r P).

Usage::

    from wmr_mj import C80
    from wmr_mj.analysis.plant_box import derived_box, friction_over_P_max
    box = derived_box(C80, (550.0, 750.0), "payload", ())            # cached: a sweep asks once per run
    r = friction_over_P_max(C80, (550.0, 750.0), "payload", ())        # max F/P [rad/s^2] over the corners
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Iterator
from dataclasses import dataclass

from wmr_mj._util.checks import finite_number as _number
from wmr_mj._util.checks import interval as _interval
from wmr_mj.analysis.robustness import ParameterBox
from wmr_mj.errors import ParameterError
from wmr_mj.params import C80Parameters, with_params

__all__ = [
    "PlantBox",
    "PlantLimits",
    "PLANT_K_BAND",
    "PLANT_K_MEASURED",
    "GYRO_BAND",
    "GYRO_MEASURED_RATIOS",
    "F_OVER_P_NOT_MONOTONE",
    "hull",
    "derived_box",
    "box_corners",
    "friction_over_P_max",
]

#: The plant's sin/cos^3 coefficient, V: |K| <= 0.02. Measured: MuJoCo identification
#: K = -0.0052 +- 0.0016 V (model card, seed 0); Drake 0.018 V at 1e7 N/m contacts
#: (physics.md section 6). The non-holonomic model has K = 0.
PLANT_K_BAND = 0.02
PLANT_K_MEASURED = (-0.0052 - 2 * 0.0016, 0.018)
#: The plant's gyro coefficient relative to P/l1 (the non-holonomic prediction).
#: The band covers every plant variant the testbed runs and both engines: this plant
#: (stiction, stiff tyre contacts) identifies 0.616-0.624 V s/m over seeds 0-5 (model
#: card, 0.98-0.99 x P/l1 = 0.6291); with soft tyre contacts 0.575 (0.91 x); the earlier
#: soft-friction plant scattered 0.492-0.704 over seeds 0-5 (0.78-1.12 x, physics.md
#: section 6); Drake 0.621-0.644.
GYRO_BAND = (0.75, 1.15)
GYRO_MEASURED_RATIOS = (0.492 / 0.6291, 0.704 / 0.6291)


@dataclass(frozen=True)
class PlantBox:
    """The plants the certificate covers.

    Attributes:
        box: the plant's P [V s^2/rad], C_V [V s/rad], F [V] (Coulomb, break-away = sliding;
            F >= 0) and K [V] (sin/cos^3) ranges.
        gyro: (lo, hi) of the plant's gyroscopic coefficient [V s/m] (Gam = gyro V_A).
        V_A: (lo, hi) of the forward speed [m/s].
        friction_over_P: an upper bound on F/P over the plants of the box [rad/s^2] (F and P
            both scale with R_a, so F/P does not move with it; see :func:`friction_over_P_max`).
            With it the friction level at each P is min(F_max, friction_over_P P) rather than
            F_max at every P; None: F and P independent, as the box alone says.
        disturbance: d_V,max [V], the bound on a steering disturbance torque at the motor's voltage,
            R_a d_max/(k_i i2) maximised over the box (:mod:`wmr_mj.analysis.small_gain`); 0: none.
        disturbance_over_P: an upper bound on d_V/P = d_max/(2D) over the plants of the box
            [rad/s^2] (R_a cancels, as in F/P); the term at each P is then min(d_V,max, r_d P)/P.
            None: d_V,max/P at every P.

    Raises:
        ParameterError: a box that is not a ParameterBox, F < 0, a range that is not finite lo <= hi,
            friction_over_P <= 0, disturbance < 0.
    """

    box: ParameterBox
    gyro: tuple[float, float]
    V_A: tuple[float, float]
    friction_over_P: float | None = None
    disturbance: float = 0.0
    disturbance_over_P: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.box, ParameterBox):
            raise ParameterError(f"box must be a ParameterBox, got {type(self.box).__name__}")
        object.__setattr__(self, "gyro", _interval("gyro range", self.gyro))
        object.__setattr__(self, "V_A", _interval("V_A range", self.V_A))
        if self.box.F[0] < 0.0:
            raise ParameterError(f"box F = {self.box.F} is not accepted: a Coulomb level F >= 0 is required")
        if self.friction_over_P is not None:
            object.__setattr__(self, "friction_over_P",
                               _number("friction_over_P", self.friction_over_P, minimum=0.0, strict=True))
        object.__setattr__(self, "disturbance", _number("disturbance", self.disturbance, minimum=0.0))
        if self.disturbance_over_P is not None:
            object.__setattr__(self, "disturbance_over_P",
                               _number("disturbance_over_P", self.disturbance_over_P, minimum=0.0, strict=True))


@dataclass(frozen=True)
class PlantLimits:
    """The plant's limits the certified region must respect.

    Attributes:
        steering_range: the steering stops, |alpha| [rad], > 0.
        voltage_limit: the supply [V], > 0.

    Raises:
        ParameterError: a limit that is not a finite number > 0.
    """

    steering_range: float
    voltage_limit: float

    def __post_init__(self) -> None:
        for name in ("steering_range", "voltage_limit"):
            object.__setattr__(self, name, _number(name, getattr(self, name), minimum=0.0, strict=True))


def hull(a: tuple[float, float], *values: float) -> tuple[float, float]:
    """The smallest interval holding ``a`` and ``values``."""
    return min(a[0], *values), max(a[1], *values)


@functools.lru_cache(maxsize=64)  # the two caches it replaces held 32 each
def derived_box(params: C80Parameters, m1_range: tuple[float, float], m1_inertia: str,
                ranges: tuple[tuple[str, tuple[float, float]], ...], model: str = "nonholonomic") -> ParameterBox:
    """The box of ``params.coefficients(model)`` over m1 in ``m1_range`` and the ranged parameters.

    Cached: every run of a sweep or a comparison over a box of several ranged parameters asks for the
    same one (its corners cost 0.4 s for the full box). :meth:`ParameterBox.from_parameters` on a grid.

    Args:
        params: the parameter set the box is around.
        m1_range: (lo, hi) of the chassis mass [kg].
        m1_inertia: how m1 moves the inertia ('payload', ...).
        ranges: ((name, (lo, hi)), ...) of the other ranged parameters, sorted (a hashable key).
        model: the coefficients' model ('nonholonomic' for the certificate).
    """
    return ParameterBox.from_parameters(params, m1_range=m1_range, model=model, m1_inertia=m1_inertia,
                                        ranges=dict(ranges) or None)


#: Parameters F/P = (l3 l4/l1) mu Q / (2D) is not monotone in (they enter D, or Q and D), and the
#: steering's inertia 2D depends on: with one of them ranged, :func:`friction_over_P_max` gives no bound.
F_OVER_P_NOT_MONOTONE = frozenset({"l4", "front_axle_mass", "front_wheel_mass", "r3", "front_wheel_width"})


def box_corners(params: C80Parameters, m1_range: tuple[float, float], m1_inertia: str,
                ranges: tuple[tuple[str, tuple[float, float]], ...]) -> Iterator[C80Parameters]:
    """Each corner of the box: ``params`` with m1 and every ranged parameter at one end of its range.

    The corners come in :func:`itertools.product` order over (m1, *ranges).
    """
    axes = [("m1", m1_range), *ranges]
    names = [n for n, _ in axes]
    for corner in itertools.product(*(span for _, span in axes)):
        yield with_params(params, m1_inertia=m1_inertia, **dict(zip(names, corner)))


@functools.lru_cache(maxsize=32)
def friction_over_P_max(params: C80Parameters, m1_range: tuple[float, float], m1_inertia: str,
                        ranges: tuple[tuple[str, tuple[float, float]], ...]) -> float | None:
    """max F/P [rad/s^2] over the box's plants: m1 over m1_range and the ranged parameters.

    F/P = (R_a/(k_i i2)) tau_f / ((R_a/k_i) 2D/i2) = tau_f/(2D), tau_f = (l3 l4/l1) mu Q: it
    does not depend on R_a, k_i, i2, V_A or the tyres, and is monotone in every other
    parameter but those of :data:`F_OVER_P_NOT_MONOTONE`, so its maximum is at a corner of
    the box (all corners are evaluated: :func:`box_corners`). None when a non-monotone parameter is ranged.
    """
    if any(name in F_OVER_P_NOT_MONOTONE for name, _ in ranges):
        return None
    best = 0.0
    for p in box_corners(params, m1_range, m1_inertia, ranges):
        c = p.coefficients("nonholonomic")
        best = max(best, c.F / c.P)
    return best
