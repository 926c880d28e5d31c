"""Robustness analysis of the computed-torque steering controller (paper section 4).

The controller (3.2)-(3.3) uses estimates P^, C_V^, F^, K^ of the plant
(2.12)-(2.13)::

    P a'' + C_V a' + F sgn(a') + K sin(a)/cos^3(a) = u                    (2.12)

and the servo error E = a0 - a then obeys the linear error equation

    E'' + K_D E' + K_P E = eta                                            (4.10)
    eta = N + (1 - P^-1 P^) K_D E' + (1 - P^-1 P^) K_P E
    N   = P^-1 [P~ a0'' + F~ sgn(a') + K~ sin/cos^3 + C~_V a0' - C~_V E']   (4.8)

with X~ = X - X^ (truth minus estimate) and P^-1 the inverse of the *true* P.

Operator gains (4.14): gamma1 = int_0^inf |h| dt, gamma2 = int_0^inf |g| dt, where h and
g are the impulse responses of 1/(s^2 + K_D s + K_P) (4.11) and s/(s^2 + K_D s + K_P)
(4.12). With a = K_D/2 and d = a^2 - K_P (this module's closed forms, exact for any
K_P, K_D > 0):

* all regimes: h peaks at t* = atanh(sqrt d / a)/sqrt d (d > 0), 1/a (d = 0),
  atan(sqrt(-d)/a)/sqrt(-d) (d < 0), with h(t*) = exp(-a t*)/sqrt(K_P).
* over-/critically damped (d >= 0): h >= 0, so gamma1 = 1/K_P; g = h' changes sign
  once (at t*), so gamma2 = 2 h(t*).
* under-damped (d < 0, v = sqrt(-d)): h = exp(-a t) sin(v t)/v changes sign every
  pi/v and each half-period's area is q = exp(-a pi/v) times the last one, so
  gamma1 = (1 + q) / ((1 - q) K_P) = coth(a pi/(2 v)) / K_P;
  the extrema of h alternate with |h(t_k)| = h(t*) q^k, so gamma2 = 2 h(t*)/(1 - q).

The paper's (4.15)-(4.16), gamma1 = 1/K_P and gamma2 = 4/(e K_D), are the
critically damped case (K_D = 2 sqrt(K_P)) only; its example K_D = 9, K_P = 6 is
over-damped (K_D^2 = 81 > 4 K_P = 24), where the exact gamma2 is 0.19132, not
4/(9 e) = 0.16350. :func:`paper_gammas` gives the printed forms for comparison.

Bound on eta (4.18)-(4.19)::

    ||eta|| <= delta1 + delta_E ||E|| + delta_Edot ||E'||                 (4.19)
    delta1     = sup |P^-1 [P~ a0'' + F~ + C~_V a0' + K~ sin/cos^3]|     (4.18)
    delta_E    = sup |1 - P^-1 P^| K_P                   ("corrected", from 4.10)
    delta_Edot = sup |(1 - P^-1 P^) K_D - P^-1 C~_V|     ("corrected", from 4.10)

The paper's (4.20) prints delta2 = |(1 - P^-1 P^) K_D - C~_V| and
delta3 = |(1 - P^-1 P^) K_P|, while (4.19), (4.21) and (4.23) use delta2 as the
coefficient of ||E|| and delta3 as that of ||E'||; (4.10) multiplies E by K_P, so
the labels of (4.20) are swapped ("corrected" reading, the default). In this
module ``delta2`` is *always* the coefficient of ||E|| (= ``delta_E``) and
``delta3`` that of ||E'|| (= ``delta_Edot``), as in (4.19)/(4.23); ``reading``
only changes what those coefficients are:

* ``"corrected"``: as above.
* ``"printed"``: (4.20)'s labels as printed, delta_E = |(1 - P^-1 P^) K_D - P^-1 C~_V|,
  delta_Edot = |1 - P^-1 P^| K_P (with the dimensionally required P^-1 on C~_V).
* ``"printed-literal"``: as "printed" but with C~_V (no P^-1), exactly as (4.20) reads.

Uncertainty (4.2): unless an explicit ``estimate`` is given, truth and estimate both
lie anywhere in the :class:`ParameterBox`, so |X~| <= X_max - X_min, and P, P^ are
taken at the box corners that make each sup largest (each delta is maximised on
its own, which is the paper's, conservative, procedure). With an ``estimate``
(numbers for some of P^, C_V^, F^, K^) the truth alone ranges over the box.

Closed region (4.21)-(4.23): with (4.17) ||E|| <= gamma1 ||eta||, ||E'|| <= gamma2 ||eta||::

    ||E||  <= gamma1 delta1/(1 - gamma1 delta2) + gamma1 delta3/(1 - gamma1 delta2) ||E'||   (4.21)
    ||E||  >= -delta1/delta2 + (1 - gamma2 delta3)/(gamma2 delta2) ||E'||
    condition = gamma1 delta2 + gamma2 delta3 < 1                                       (4.23)
    E_max     = gamma1 delta1 / (1 - condition),   Edot_max = gamma2 delta1 / (1 - condition)

This is the paper's analysis ("the paper's claim"). :mod:`wmr_mj.analysis.certificate` redoes it
for the controller actually run on the plant actually simulated (friction at rest by
compensation mode, the gyroscopic term, K~ over the reachable angle, the supply).

Usage::

    from wmr_mj.analysis.robustness import ParameterBox, analyse
    r = analyse(ParameterBox.paper(), kp=6.0, kd=9.0)      # the paper's (5.1) example
    r.condition     # 0.26204 (paper: 0.2613), r.stable -> True
    r.E_max, r.Edot_max, r.vertices                        # bounds and Fig. 7 polygon
    analyse(ParameterBox.paper(), reading="printed", gammas="paper").condition

    from wmr_mj import C80
    box = ParameterBox.from_parameters(C80, m1_range=(550.0, 750.0), ranges={"mu": (0.015, 0.02)})
"""

from __future__ import annotations

import itertools
import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Literal

from wmr_mj._util.checks import box_interval as _interval
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.params import M1_RANGE, PAPER_KD, PAPER_KP, parameter_names, with_params
from wmr_mj.reference.bounds import PAPER_BOUNDS, ReferenceBounds

__all__ = [
    "ParameterBox",
    "ReferenceBounds",
    "RobustnessResult",
    "analyse",
    "exact_gammas",
    "paper_gammas",
    "damping_regime",
    "impulse_responses",
    "gains_from_omega_r",
    "READINGS",
    "GAMMA_FORMS",
    "BOX_COEFFICIENTS",
    "PAPER_CONDITION",
]

READINGS = ("corrected", "printed", "printed-literal")
GAMMA_FORMS = ("exact", "paper")
#: The coefficients a ParameterBox bounds, the uncertainty set of (4.2): the paper's model has no
#: gyro term (wmr_mj.params.COEFFICIENT_NAMES has it too).
BOX_COEFFICIENTS = ("P", "C_V", "F", "K")
#: The left side of (4.23) the paper reports for its (5.1) example.
PAPER_CONDITION = 0.2613

Reading = Literal["corrected", "printed", "printed-literal"]
GammaForm = Literal["exact", "paper"]


# --------------------------------------------------------------------------- gains
def _check_gains(kp: float, kd: float) -> tuple[float, float]:
    out = []
    for name, value in (("K_P", kp), ("K_D", kd)):
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ParameterError(f"gain {name} must be a number, got {value!r}") from None
        if not math.isfinite(v) or v <= 0.0:
            raise ParameterError(f"gain {name} = {value!r} is not accepted: a finite number > 0 is required")
        if v < sys.float_info.min:  # subnormal: K_D/2 and the logs of the closed forms lose it
            raise ParameterError(f"gain {name} = {value!r} is not accepted: a number >= "
                                 f"{sys.float_info.min:.4g} (the smallest normal float) is required")
        out.append(v)
    return out[0], out[1]


def gains_from_omega_r(omega_r: float) -> tuple[float, float]:
    """(K_P, K_D) = (omega_r^2/4, omega_r) for critical damping, (3.6)."""
    try:
        w = float(omega_r)
    except (TypeError, ValueError):
        raise ParameterError(f"omega_r must be a number, got {omega_r!r}") from None
    if not math.isfinite(w) or w <= 0.0:
        raise ParameterError(f"omega_r = {omega_r!r} is not accepted: a finite number > 0 is required")
    return _check_gains(0.25 * w * w, w)


def _stiffness_ratio(kp: float, kd: float) -> float:
    """r = K_P / a^2 = 4 K_P / K_D^2 (a = K_D/2); < 1 over-damped, > 1 under-damped.

    Divided in two steps so that extreme but finite gains (1e308) do not overflow a^2.
    """
    a = 0.5 * kd
    return (kp / a) / a


def damping_regime(kp: float, kd: float) -> str:
    """'over-damped', 'critically damped' or 'under-damped' (K_D^2 vs 4 K_P).

    Critical within a relative 1e-12 (so that K_D = 2 sqrt(K_P) in floating point
    counts as critical); the gammas are continuous there anyway.
    """
    kp, kd = _check_gains(kp, kd)
    r = _stiffness_ratio(kp, kd)
    if abs(1.0 - r) <= 1e-12:
        return "critically damped"
    return "over-damped" if r < 1.0 else "under-damped"


def _peak_time_scaled(y: float, one_minus_y: float, log_r: float) -> float:
    """a t* as a function of y = d / a^2 = 1 - r (r = K_P/a^2), smooth through y = 0.

    atanh(sqrt y)/sqrt y for y > 0, atan(sqrt(-y))/sqrt(-y) for y < 0: both are the
    series 1 + y/3 + y^2/5 + ..., used near y = 0. ``one_minus_y`` (= r) and log r are
    passed separately: 1 - y loses r when r < 1e-16, and r may underflow.
    """
    if abs(y) < 1e-6:
        return 1.0 + y / 3.0 + y * y / 5.0
    if y > 0.0:
        x = math.sqrt(y)
        if one_minus_y > 1e-12:
            # atanh(x) = 0.5 log1p(2x/(1-x)), with 1 - x = (1 - y)/(1 + x) (no cancellation near x = 1)
            return 0.5 * math.log1p(2.0 * x * (1.0 + x) / one_minus_y) / x
        # strongly over-damped: atanh(x) = log1p(x) - log(r)/2, in logs (r may underflow)
        return (math.log1p(x) - 0.5 * log_r) / x
    x = math.sqrt(-y)
    return math.atan(x) / x


def exact_gammas(kp: float, kd: float) -> tuple[float, float]:
    """(gamma1, gamma2) = (int |h|, int |g|) exactly, for any K_P, K_D > 0 (4.14).

    Closed forms in the module docstring; no quadrature. Smooth through critical
    damping (no sqrt(d) cancellation). Extreme but finite gains (up to 1e308) are
    evaluated without overflow (in logs where a^2, K_P/a^2 or exp(-a t*) would leave
    the floating-point range); gains whose gammas themselves leave it raise
    ParameterError.
    """
    kp, kd = _check_gains(kp, kd)
    a = 0.5 * kd
    aa = a * a
    ordinary = 1e-300 < aa < 1e300 and 1e-300 < kp < 1e300
    # y = d / a^2 = 1 - 4 K_P / K_D^2; r = 1 - y, formed without a^2 when a^2 is extreme
    r = kp / aa if ordinary else _stiffness_ratio(kp, kd)
    y = 1.0 - r
    one_minus_y = 1.0 - y if ordinary else r
    log_r = math.log(kp) - 2.0 * math.log(a)
    at_peak = None
    if ordinary or y > -1e-6:
        at_peak = _peak_time_scaled(y, one_minus_y, log_r)
    if y >= 0.0:
        assert at_peak is not None  # y >= 0 > -1e-6: computed above
        # h_peak = exp(-a t*) / sqrt(K_P); in logs when exp(-a t*) would underflow
        h_peak = math.exp(-at_peak) / math.sqrt(kp) if at_peak < 700.0 else math.exp(-at_peak - 0.5 * math.log(kp))
        gamma1, gamma2 = 1.0 / kp, 2.0 * h_peak
    else:
        root_kp = math.sqrt(kp)
        if r < 1e300:
            v = a * math.sqrt(-y)  # damped frequency
        else:  # a^2 << K_P: v = sqrt(K_P) sqrt(1 - a^2/K_P), no overflow
            v = root_kp * math.sqrt(1.0 - (a / root_kp) ** 2)
        if at_peak is None:  # a^2 or K_P extreme: atan(v/a)/(v/a) without overflow
            at_peak = math.atan2(v, a) * (a / v)
        h_peak = math.exp(-at_peak) / root_kp
        z = a * math.pi / v  # q = exp(-z): decay per half-period
        with_z = kp * math.tanh(0.5 * z)
        gamma1 = 1.0 / with_z if with_z > 0.0 else math.inf
        decay = -math.expm1(-z)
        gamma2 = 2.0 * h_peak / decay if decay > 0.0 else math.inf
    for name, value in (("gamma1", gamma1), ("gamma2", gamma2)):
        if not (math.isfinite(value) and value > 0.0):
            raise ParameterError(
                f"gains K_P = {kp:g}, K_D = {kd:g}: the operator gain {name} = {value:g} is outside the "
                "floating-point range; gains with K_P, K_D and K_D^2/K_P between 1e-100 and 1e100 are always accepted"
            )
    return gamma1, gamma2


def paper_gammas(kp: float, kd: float) -> tuple[float, float]:
    """The paper's printed (4.16): (1/K_P, 4/(e K_D)); exact only for K_D = 2 sqrt(K_P)."""
    kp, kd = _check_gains(kp, kd)
    e_kd = math.e * kd
    return 1.0 / kp, (4.0 / e_kd if math.isfinite(e_kd) else (4.0 / math.e) / kd)


def impulse_responses(t: Any, kp: float, kd: float) -> tuple[Any, Any]:
    """h(t), g(t) of (4.11)-(4.12) as NumPy arrays (for plots and checks)."""
    import numpy as np

    kp, kd = _check_gains(kp, kd)
    t = np.asarray(t, dtype=float)
    a = 0.5 * kd
    d = a * a - kp
    env = np.exp(-a * t)
    if d > 0.0:
        w = math.sqrt(d)
        s, c = np.sinh(w * t) / w, np.cosh(w * t)
    elif d < 0.0:
        w = math.sqrt(-d)
        s, c = np.sin(w * t) / w, np.cos(w * t)
    else:
        s, c = t, np.ones_like(t)
    return env * s, env * (c - a * s)


# --------------------------------------------------------------------------- box
@dataclass(frozen=True)
class ParameterBox:
    """Intervals (lo, hi) of the plant coefficients of (2.12), the uncertainty set of (4.2).

    P [V s^2/rad], C_V [V s/rad], F [V] (Coulomb), K [V] (coefficient of sin/cos^3).
    lo == hi (a coefficient known exactly) is accepted; P must be > 0.
    """

    P: tuple[float, float]
    C_V: tuple[float, float]
    F: tuple[float, float]
    K: tuple[float, float]

    def __post_init__(self) -> None:
        for name in BOX_COEFFICIENTS:
            object.__setattr__(
                self, name, _interval(name, getattr(self, name), allow_degenerate=True, what="box interval")
            )
        if self.P[0] <= 0.0:
            raise ParameterError(f"box interval P = {self.P} is not accepted: P > 0 is required")

    @classmethod
    def paper(cls) -> ParameterBox:
        """The paper's (5.1): P (0.37, 0.4), C_V (4.73, 4.81), F (1.5, 1.53), K (5.29, 5.38)."""
        return cls(P=(0.37, 0.4), C_V=(4.73, 4.81), F=(1.5, 1.53), K=(5.29, 5.38))

    @classmethod
    def from_parameters(
        cls,
        params: Any,
        *,
        m1_range: tuple[float, float] | None = M1_RANGE,
        ranges: Mapping[str, tuple[float, float]] | None = None,
        model: str = "paper",
        m1_inertia: str = "payload",
        grid: int | None = None,
    ) -> ParameterBox:
        """The box spanned by ``params.coefficients(model)`` over physical parameter ranges.

        ``m1_range`` (None: m1 fixed) and ``ranges`` ({C80 field: (lo, hi)}; an
        'm1' entry replaces m1_range) are sampled on a grid that includes every
        corner and interior points (``grid`` points per ranged parameter; default
        5 for up to 5 parameters, then fewer so that at most ~4096 points are
        evaluated; at most 12 ranged parameters). Each coefficient's min/max over
        the grid gives its interval.
        """
        names = parameter_names()
        spans: dict[str, tuple[float, float]] = {}
        if m1_range is not None:
            spans["m1"] = _interval("m1", m1_range, allow_degenerate=False, what="range")
        for name, value in (ranges or {}).items():
            if name not in names:
                raise UnknownNameError("parameter", name, names)
            spans[name] = _interval(name, value, allow_degenerate=False, what="range")
        if len(spans) > 12:
            raise ParameterError(
                f"{len(spans)} ranged parameters ({', '.join(spans)}); at most 12 are accepted"
            )
        if grid is None:
            n = max(len(spans), 1)
            grid = 5 if n <= 5 else max(2, int(4096 ** (1.0 / n)))
        if isinstance(grid, bool) or not isinstance(grid, int) or grid < 2:
            raise ParameterError(f"grid = {grid!r} is not accepted: an integer >= 2 is required")
        axes = []
        for lo, hi in spans.values():
            axes.append(sorted({lo, hi, *(lo + (hi - lo) * k / (grid - 1) for k in range(grid))}))
        lo_v = {name: math.inf for name in BOX_COEFFICIENTS}
        hi_v = {name: -math.inf for name in BOX_COEFFICIENTS}
        for point in itertools.product(*axes):
            changes = dict(zip(spans, point))
            p = with_params(params, m1_inertia=m1_inertia, **changes) if changes else params
            c = p.coefficients(model)
            for name in BOX_COEFFICIENTS:
                v = float(getattr(c, name))
                lo_v[name] = min(lo_v[name], v)
                hi_v[name] = max(hi_v[name], v)
        return cls(**{name: (lo_v[name], hi_v[name]) for name in BOX_COEFFICIENTS})

    def width(self, name: str) -> float:
        lo, hi = getattr(self, name)
        return hi - lo

    def to_dict(self) -> dict[str, list[float]]:
        return {n: list(getattr(self, n)) for n in BOX_COEFFICIENTS}


# --------------------------------------------------------------------------- result
def _finite_or_none(x: float) -> float | None:
    return x if math.isfinite(x) else None


@dataclass(frozen=True)
class RobustnessResult:
    """Outcome of :func:`analyse`.

    delta_E / delta_Edot are the coefficients of ||E|| / ||E'|| in (4.19);
    ``delta2`` / ``delta3`` are aliases with the paper's names *as used in
    (4.19), (4.21), (4.23)* (its (4.20) prints the labels swapped). condition is
    the left side of (4.23); E_max, Edot_max are inf when it is >= 1.
    """

    gamma1: float
    gamma2: float
    delta1: float
    delta_E: float
    delta_Edot: float
    condition: float
    stable: bool
    E_max: float
    Edot_max: float
    kp: float
    kd: float
    reading: str = "corrected"
    gammas: str = "exact"
    box: ParameterBox | None = None
    bounds: ReferenceBounds | None = None
    estimate: Mapping[str, float] | None = None

    @property
    def delta2(self) -> float:
        """Paper's delta2: the coefficient of ||E|| in (4.19) (= delta_E)."""
        return self.delta_E

    @property
    def delta3(self) -> float:
        """Paper's delta3: the coefficient of ||E'|| in (4.19) (= delta_Edot)."""
        return self.delta_Edot

    @property
    def regime(self) -> str:
        return damping_regime(self.kp, self.kd)

    @property
    def vertices(self) -> tuple[tuple[float, float], ...]:
        """Polygon of the closed region in the (||E||, ||E'||) plane, counter-clockwise.

        (0, 0), (E-axis end of the first line of (4.21)), (E_max, Edot_max),
        (E'-axis end of the second line); () when (4.23) fails (unbounded region).
        """
        if not self.stable:
            return ()
        g1, g2, d1 = self.gamma1, self.gamma2, self.delta1
        x_axis = g1 * d1 / (1.0 - g1 * self.delta_E)
        y_axis = g2 * d1 / (1.0 - g2 * self.delta_Edot)
        return ((0.0, 0.0), (x_axis, 0.0), (self.E_max, self.Edot_max), (0.0, y_axis))

    def lines(self) -> dict[str, tuple[float, float] | None]:
        """The two lines of (4.21) as ||E|| = c0 + c1 ||E'|| ({'upper': (c0, c1), 'lower': ...}).

        'lower' is None when delta2 = 0 (the line is then ||E'|| = gamma2 delta1/(1 - gamma2 delta3)).
        'upper' is None when gamma1 delta2 >= 1.
        """
        g1, g2, d1, d2, d3 = self.gamma1, self.gamma2, self.delta1, self.delta_E, self.delta_Edot
        upper = None
        if g1 * d2 < 1.0:
            upper = (g1 * d1 / (1.0 - g1 * d2), g1 * d3 / (1.0 - g1 * d2))
        lower = None
        if d2 > 0.0:
            lower = (-d1 / d2, (1.0 - g2 * d3) / (g2 * d2))
        return {"upper": upper, "lower": lower}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (no NaN/inf: unbounded values are None)."""
        g1p, g2p = paper_gammas(self.kp, self.kd)
        out: dict[str, Any] = {
            "gamma1": self.gamma1,
            "gamma2": self.gamma2,
            "gamma1_paper_4_16": g1p,
            "gamma2_paper_4_16": g2p,
            "delta1": self.delta1,
            "delta_E": self.delta_E,
            "delta_Edot": self.delta_Edot,
            "delta2": self.delta2,
            "delta3": self.delta3,
            "condition": _finite_or_none(self.condition),
            "stable": bool(self.stable),
            "E_max": _finite_or_none(self.E_max),
            "Edot_max": _finite_or_none(self.Edot_max),
            "kp": self.kp,
            "kd": self.kd,
            "regime": self.regime,
            "reading": self.reading,
            "gammas": self.gammas,
            "paper_condition": PAPER_CONDITION,
            "relative_difference": (
                (self.condition - PAPER_CONDITION) / PAPER_CONDITION if math.isfinite(self.condition) else None
            ),
            "vertices": [list(v) for v in self.vertices],
        }
        if self.box is not None:
            out["box"] = self.box.to_dict()
        if self.bounds is not None:
            out["bounds"] = self.bounds.to_dict()
        out["estimate"] = dict(self.estimate) if self.estimate is not None else None
        return out


# --------------------------------------------------------------------------- analysis
def _normalise_estimate(estimate: Any) -> dict[str, float]:
    if estimate is None:
        return {}
    if hasattr(estimate, "to_dict") and not isinstance(estimate, Mapping):
        estimate = estimate.to_dict()
    if not isinstance(estimate, Mapping):
        raise ParameterError(
            f"estimate must be a mapping {{name: value}} of {', '.join(BOX_COEFFICIENTS)}, got {estimate!r}"
        )
    out: dict[str, float] = {}
    for name, value in estimate.items():
        if name not in BOX_COEFFICIENTS:
            if name == "gyro":  # Coefficients.to_dict() carries it; the analysis has no gyro term
                continue
            raise UnknownNameError("estimate name", name, BOX_COEFFICIENTS)
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ParameterError(f"estimate {name} must be a number, got {value!r}") from None
        if not math.isfinite(v):
            raise ParameterError(f"estimate {name} = {value!r} is not finite")
        if name == "P" and v <= 0.0:
            raise ParameterError(f"estimate P = {value!r} is not accepted: P^ > 0 is required")
        out[name] = v
    return out


def _candidates(box: ParameterBox, name: str, est: dict[str, float]) -> tuple[list[float], list[float]]:
    """Candidate truths and estimates for a coefficient: box corners (and a fixed estimate)."""
    lo, hi = getattr(box, name)
    truths = [lo, hi]
    if name in est:
        e = est[name]
        return truths, [e]
    return truths, [lo, hi]


def _max_tilde(box: ParameterBox, name: str, est: dict[str, float]) -> float:
    truths, ests = _candidates(box, name, est)
    return max(abs(t - e) for t in truths for e in ests)


def analyse(
    box: ParameterBox,
    *,
    kp: float = PAPER_KP,
    kd: float = PAPER_KD,
    bounds: ReferenceBounds = PAPER_BOUNDS,
    reading: Reading = "corrected",
    gammas: GammaForm = "exact",
    estimate: Mapping[str, float] | Any | None = None,
) -> RobustnessResult:
    """Robustness region of section 4 for ``box`` and gains K_P = kp, K_D = kd.

    reading: 'corrected' (default; coefficients settled from (4.10)), 'printed'
    ((4.20)'s labels as printed, P^-1 C~_V), 'printed-literal' ((4.20) verbatim, C~_V).
    gammas: 'exact' (default, :func:`exact_gammas`) or 'paper' ((4.16), :func:`paper_gammas`).
    estimate: optional {'P': P^, 'C_V': C_V^, 'F': F^, 'K': K^} (any subset, or a
    :class:`wmr_mj.params.Coefficients`); named coefficients use that estimate and
    the truth ranges over the box; the others are "anywhere in the box" (4.2).
    """
    _check_analysis_inputs(box, bounds, reading, gammas)
    kp, kd = _check_gains(kp, kd)
    est = _normalise_estimate(estimate)
    g1, g2 = exact_gammas(kp, kd) if gammas == "exact" else paper_gammas(kp, kd)
    pairs = _P_pairs(box, est)
    delta1 = _delta1(box, est, bounds, pairs)
    delta_E, delta_Edot = _error_coefficients(box, est, pairs, kp, kd, reading)
    condition = g1 * delta_E + g2 * delta_Edot  # (4.23)
    stable = condition < 1.0
    if stable:
        E_max = g1 * delta1 / (1.0 - condition)
        Edot_max = g2 * delta1 / (1.0 - condition)
    else:
        E_max = Edot_max = math.inf
    return RobustnessResult(
        gamma1=g1,
        gamma2=g2,
        delta1=delta1,
        delta_E=delta_E,
        delta_Edot=delta_Edot,
        condition=condition,
        stable=stable,
        E_max=E_max,
        Edot_max=Edot_max,
        kp=kp,
        kd=kd,
        reading=reading,
        gammas=gammas,
        box=box,
        bounds=bounds,
        estimate=dict(est) if est else None,
    )


def _check_analysis_inputs(box: Any, bounds: Any, reading: Any, gammas: Any) -> None:
    if not isinstance(box, ParameterBox):
        raise ParameterError(f"box must be a ParameterBox, got {type(box).__name__}")
    if not isinstance(bounds, ReferenceBounds):
        raise ParameterError(f"bounds must be a ReferenceBounds, got {type(bounds).__name__}")
    if reading not in READINGS:
        raise UnknownNameError("reading", str(reading), READINGS)
    if gammas not in GAMMA_FORMS:
        raise UnknownNameError("gamma form", str(gammas), GAMMA_FORMS)


def _P_pairs(box: ParameterBox, est: dict[str, float]) -> list[tuple[float, float]]:
    """The (P, P^) pairs the sups of (4.18)-(4.20) are taken over.

    Inside each sup the expression is monotone in P between kinks, so box corners (and
    P = P^ when an estimate lies in the box) suffice.
    """
    P_true, P_est = _candidates(box, "P", est)
    if "P" in est and box.P[0] < est["P"] < box.P[1]:
        P_true = P_true + [est["P"]]
    return [(p, ph) for p in P_true for ph in P_est]


def _delta1(box: ParameterBox, est: dict[str, float], bounds: ReferenceBounds,
            pairs: list[tuple[float, float]]) -> float:
    """delta1 of (4.18) [rad/s^2]: the worst cases of |X~| for the additive terms, over the P pairs."""
    dC = _max_tilde(box, "C_V", est)
    dF = _max_tilde(box, "F", est)
    dK = _max_tilde(box, "K", est)
    rest = dF + dC * bounds.alpha_dot_max + dK * bounds.sin_cos3_max
    return max((abs(p - ph) * bounds.alpha_ddot_max + rest) / p for p, ph in pairs)  # (4.18)


def _error_coefficients(box: ParameterBox, est: dict[str, float], pairs: list[tuple[float, float]], kp: float,
                        kd: float, reading: str) -> tuple[float, float]:
    """(coefficient of ||E|| [1/s^2], of ||E'|| [1/s]) in (4.19), as ``reading`` reads (4.20)."""

    def mis(p: float, ph: float) -> float:  # 1 - P^-1 P^
        return 1.0 - ph / p

    term_kp = max(abs(mis(p, ph)) * kp for p, ph in pairs)
    c_scale = (lambda p: 1.0) if reading == "printed-literal" else (lambda p: 1.0 / p)
    # C~_V = C_V - C_V^: both signs up to the box width, or truth-in-box minus a fixed estimate.
    dC = _max_tilde(box, "C_V", est)
    c_tilde = [box.C_V[0] - est["C_V"], box.C_V[1] - est["C_V"]] if "C_V" in est else [-dC, dC]
    term_kd = max(abs(mis(p, ph) * kd - ct * c_scale(p)) for p, ph in pairs for ct in c_tilde)
    if reading == "corrected":
        return term_kp, term_kd
    return term_kd, term_kp
