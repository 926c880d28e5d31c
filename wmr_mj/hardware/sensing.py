"""The steering sensor between the plant and every law: encoder, velocity estimate, noise and delay.

Usage::

    from wmr_mj.hardware import Sensing, SensingChain, measurement_error_bounds

    s = Sensing.from_spec("encoder_ticks=4096,encoder_side=axis,velocity=difference,delay=0.005,"
                          "noise=uniform:0.0005,seed=3")
    chain = SensingChain(s, control_period=0.001, n_steps=35_000, gear_ratio=60.0)
    for k in range(n):                                   # once per control step, k = 0, 1, 2, ...
        alpha_m, alpha_dot_m = chain.step(k, alpha, alpha_dot, motor_angle)
    bounds = measurement_error_bounds(s, control_period=0.001, gear_ratio=60.0)

:class:`Sensing` is the typed specification (frozen, checked when built); :class:`SensingChain` runs it.

The pipeline, once per control step k at t_k = k T (T the control period), in this order:

(a) **delay** (Drake's ``DiscreteTimeDelay``): the true samples (alpha, alpha', motor angle) of step
    k - d, d = ``delay / T`` (a whole number, :meth:`Sensing.delay_steps`), from a ring buffer of d + 1 slots;
    before d steps have passed, the first sample (the state at t = 0).
(b) **encoder**: the delayed angle theta (alpha on the ``axis``; the motor angle on the ``motor`` side) is
    quantised to N ticks per revolution: with c = N / (2 pi) ticks per rad (one double, computed once),
    ``round``: rint(theta c) / c, ``floor``: floor(theta c) / c. rint rounds half to even (IEEE
    roundTiesToEven): numpy.rint, Python's ``round`` on a float, C's ``nearbyint`` under the default rounding
    mode. On the motor side the result is divided by the gear ratio i2, so the steering angle's resolution is
    Delta / i2 with Delta = 2 pi / N. Without an encoder (``encoder_ticks=None``) theta passes unquantised
    (divided by i2 on the motor side).
(c) **noise on alpha**: ``alpha_m[k] = alpha_q + n_alpha[k]`` where set.
(d) **velocity**: ``exact``: the delayed true alpha'; ``tachometer``: the same (its noise is the velocity
    noise); ``difference``: (alpha_m[k] - alpha_m[k-1]) / T, 0 at k = 0; ``filtered``: that difference x_k
    through y_k = a y_{k-1} + (1 - a) x_k, a = exp(-T / tau_f), y_{-1} = 0 (the exact discretisation of
    1/(tau_f s + 1) for an input held over each period); ``none``: no velocity is read, alpha'_m[k] is NaN (the
    law reads the measured angle only and estimates alpha' itself; no velocity noise is accepted). Then
    ``alpha'_m[k] = v_k + n_alpha'[k]`` where set. Each estimate (and the delay of (a)) is defined once, as a
    discrete linear system, in :mod:`wmr_mj.hardware.estimators`: the step performs the operations of its
    stages (:meth:`~wmr_mj.hardware.estimators.VelocityEstimator.step`: the difference, / T, the low-pass) with
    the coefficients a and 1 - a of its :class:`~wmr_mj.hardware.estimators.VelocityEstimator`
    (:attr:`SensingChain.estimator`), to the bit; the certificate's loop reads the stages in series
    (``tests/test_estimators.py``).

Noise, drawn up front: ``rng = numpy.random.default_rng(seed)``; first the n_steps noise values on alpha
(``rng.uniform(-B, B, n_steps)`` or ``rng.normal(0.0, sigma, n_steps)``), only where noise on alpha is set;
then the n_steps values on alpha' the same way, only where velocity noise is set. The arrays are
:attr:`SensingChain.alpha_noise` and :attr:`SensingChain.alpha_dot_noise` (zeros where not set; a zero is
never added, so the ideal chain returns its inputs to the bit).

For a port to C (the state lives in MuJoCo's userdata; the parameters and the noise arrays are passed in):
every operation of :meth:`SensingChain.step` is one IEEE-754 double operation in the order written (no
fused multiply-add: compile with ``-ffp-contract=off``; no reduction; a division stays a division); the
coefficients c, a and 1 - a are computed once (a and 1 - a by the estimator) and read from
:attr:`SensingChain.parameters`, so the C step calls no ``exp``. The layouts (index constants of this module):

- parameters (float64): ``P_TICKS_PER_RAD`` c (0 without an encoder), ``P_GEAR_RATIO`` i2, ``P_PERIOD`` T (s),
  ``P_FILTER_A`` a, ``P_FILTER_ONE_MINUS_A`` 1 - a, ``P_DELAY_STEPS`` d, ``P_ENCODER_SIDE`` (0 axis, 1 motor;
  the angle is quantised where c != 0), ``P_ROUNDING`` (0 rint, 1 floor), ``P_VELOCITY`` (0 exact,
  1 tachometer, 2 difference, 3 filtered, 4 none), ``P_ALPHA_NOISE_ON``, ``P_ALPHA_DOT_NOISE_ON`` (0 or 1);
  ``N_PARAMETERS`` in all.
- state (float64, ``STATE_HEADER + 3 (d + 1)``): ``S_NEXT_STEP`` the k the next call must pass,
  ``S_PREVIOUS_ALPHA`` alpha_m[k-1] (rad), ``S_FILTER`` y_{k-1} (rad/s), then the ring: slot j at
  ``S_RING + 3 j`` holds (alpha rad, alpha' rad/s, motor angle rad) of the last step k with k mod (d+1) = j.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Literal, get_args

import numpy as np

from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware.coverage import Coverage
from wmr_mj.hardware.estimators import velocity_estimator
from wmr_mj.hardware.presets import SENSING_PRESETS
from wmr_mj.hardware.spec import (
    Converter,
    SpecSource,
    field_converters,
    parse_spec,
    to_float,
    to_int,
    whole_periods,
)

__all__ = [
    "Sensing",
    "SensingChain",
    "MeasurementBounds",
    "measurement_error_bounds",
    "sensing_preset",
    "EncoderSide",
    "EncoderRounding",
    "VelocityEstimate",
    "NoiseKind",
    "SENSING_SPEC_KEYS",
]

EncoderSide = Literal["axis", "motor"]
EncoderRounding = Literal["round", "floor"]
VelocityEstimate = Literal["exact", "tachometer", "difference", "filtered", "none"]
NoiseKind = Literal["none", "uniform", "gaussian"]

# parameter layout (see the module docstring)
P_TICKS_PER_RAD, P_GEAR_RATIO, P_PERIOD, P_FILTER_A, P_FILTER_ONE_MINUS_A, P_DELAY_STEPS = range(6)
P_ENCODER_SIDE, P_ROUNDING, P_VELOCITY, P_ALPHA_NOISE_ON, P_ALPHA_DOT_NOISE_ON = range(6, 11)
N_PARAMETERS = 11
# state layout
S_NEXT_STEP, S_PREVIOUS_ALPHA, S_FILTER, S_RING = range(4)
STATE_HEADER = S_RING

_SIDE_CODES = {"axis": 0, "motor": 1}
_ROUNDING_CODES = {"round": 0, "floor": 1}
_VELOCITY_CODES = {"exact": 0, "tachometer": 1, "difference": 2, "filtered": 3, "none": 4}
_NOISE_FORMS = "'none', 'uniform:BOUND' or 'gaussian:SIGMA'"
#: The finest encoder accepted, in bits: 2**48 ticks keep angle x ticks / (2 pi) below 2**53 (where a double
#: holds every integer) for a motor-shaft angle up to 2**53 / 2**48 x 2 pi = 201 rad (i2 = 60: 3.3 rad of steering).
MAX_ENCODER_BITS = 48


def _check_choice(key: str, value: object, choices: tuple[str, ...]) -> None:
    if value not in choices:
        raise UnknownNameError(f"sensing {key} value", str(value), choices)


def _check_noise(kind_key: str, kind: object, magnitude_key: str, magnitude: object, unit: str) -> float:
    _check_choice(kind_key, kind, get_args(NoiseKind))
    m = to_float("sensing", magnitude_key, magnitude)
    if m < 0.0:
        raise ParameterError(f"sensing: {magnitude_key} = {magnitude!r} {unit} is not accepted; a bound or a "
                             f"standard deviation >= 0 {unit} is required")
    if kind == "none" and m != 0.0:
        raise ParameterError(f"sensing: {magnitude_key} = {magnitude!r} {unit} needs a noise kind "
                             f"('uniform' or 'gaussian'); {kind_key} is 'none'")
    return m


@dataclass(frozen=True, kw_only=True)
class Sensing:
    """How the law sees the steering angle alpha and its rate alpha'. The default is exact (``is_ideal``).

    Built directly (``Sensing(encoder_ticks=4096, velocity="difference")``) or from a spec
    (:meth:`from_spec`); either way checked here. A noise of magnitude 0 is stored as no noise. Each quantity has
    one name in Python, a spec, a file and an axis (``noise``: ``Sensing(noise_kind="uniform", noise=5e-4)``,
    ``noise=uniform:0.0005``, ``sensing.noise``); the encoder's resolution has a second spec form,
    ``encoder_bits`` (2**bits ticks).

    Raises:
        ParameterError: zero, negative or more than 2**48 ticks, a negative delay or noise magnitude, a filter
            time constant that is missing (``velocity='filtered'``), not > 0, or given for another velocity
            estimate, a negative seed. The limits that need the plant and the run (a delay against the duration,
            a reading against the steering stops) are :func:`wmr_mj.hardware.assembly.check_cart`'s.
        UnknownNameError: an unknown side, rounding, velocity estimate or noise kind.
    """

    encoder_ticks: int | None = None  # ticks per revolution of the shaft the encoder sits on; None: exact
    encoder_side: EncoderSide = "axis"  # 'motor': on the motor shaft, angle = i2 * alpha (no play)
    encoder_rounding: EncoderRounding = "round"  # 'round': rint (ties to even); 'floor': truncation down
    velocity: VelocityEstimate = "exact"  # how alpha' is obtained; 'none': not at all (NaN, the law estimates it)
    filter_tau: float | None = None  # s, the low-pass time constant tau_f of velocity='filtered'
    noise_kind: NoiseKind = "none"  # noise added to the quantised alpha
    noise: float = 0.0  # rad: the bound B (uniform on [-B, B)) or the standard deviation (gaussian)
    velocity_noise_kind: NoiseKind = "none"  # noise added to the measured alpha'
    velocity_noise: float = 0.0  # rad/s: its bound or standard deviation
    delay: float = 0.0  # s, the sensing delay, a whole number of control periods when run
    seed: int = 0  # numpy.random.default_rng seed of the noise

    def __post_init__(self) -> None:
        ticks = self.encoder_ticks
        if ticks is not None and (isinstance(ticks, bool) or not isinstance(ticks, int)
                                  or not 1 <= ticks <= 2 ** MAX_ENCODER_BITS):
            raise ParameterError(f"sensing: encoder_ticks = {ticks!r} is not accepted; an integer >= 1 and <= "
                                 f"2**{MAX_ENCODER_BITS} (ticks per revolution; the step rounds angle x ticks / 2 pi "
                                 "in doubles, exact below 2**53) or none (the exact angle) is required")
        _check_choice("encoder_side", self.encoder_side, get_args(EncoderSide))
        _check_choice("encoder_rounding", self.encoder_rounding, get_args(EncoderRounding))
        _check_choice("velocity", self.velocity, get_args(VelocityEstimate))
        self._check_filter()
        for kind_key, mag_key, unit in (("noise_kind", "noise", "rad"),
                                        ("velocity_noise_kind", "velocity_noise", "rad/s")):
            m = _check_noise(kind_key, getattr(self, kind_key), mag_key, getattr(self, mag_key), unit)
            object.__setattr__(self, mag_key, m)
            if m == 0.0:
                object.__setattr__(self, kind_key, "none")
        if self.velocity == "none" and self.velocity_noise_kind != "none":
            raise ParameterError("sensing: velocity_noise needs a velocity reading; velocity is 'none' (the law reads "
                                 "the angle only)")
        delay = to_float("sensing", "delay", self.delay)
        if delay < 0.0:
            raise ParameterError(f"sensing: delay = {self.delay!r} s is not accepted; a delay >= 0 s is required")
        object.__setattr__(self, "delay", delay)
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise ParameterError(f"sensing: seed = {self.seed!r} is not accepted; an integer >= 0 is required")

    def _check_filter(self) -> None:
        tau = self.filter_tau
        if self.velocity != "filtered":
            if tau is not None:
                raise ParameterError(f"sensing: filter_tau = {tau!r} s applies to velocity=filtered only "
                                     f"(velocity is {self.velocity!r})")
            return
        if tau is None:
            raise ParameterError("sensing: velocity=filtered needs filter_tau (s, > 0), the low-pass time constant")
        t = to_float("sensing", "filter_tau", tau)
        if t <= 0.0:
            raise ParameterError(f"sensing: filter_tau = {tau!r} s is not accepted; a time constant > 0 s is "
                                 "required")
        object.__setattr__(self, "filter_tau", t)

    @property
    def is_ideal(self) -> bool:
        """True where the law reads the exact alpha and alpha' now: no encoder (on the axis), exact velocity,
        no noise, no delay (the seed and the rounding then change nothing)."""
        return (self.encoder_ticks is None and self.encoder_side == "axis" and self.velocity == "exact"
                and self.noise_kind == "none" and self.velocity_noise_kind == "none" and self.delay == 0.0)

    def delay_steps(self, control_period: float) -> int:
        """The delay as a whole number d of control periods (s), as Drake's ``DiscreteTimeDelay`` counts it.

        Raises:
            ParameterError: a period that is not > 0, or a delay that is not a whole multiple of it within
                1e-9 relative (the message names both).
        """
        return whole_periods("sensing delay", self.delay, control_period)

    # ---- each stage's bound (measurement_error_bounds sums them; mismatch.md item 4); (a) the delay is its
    # own bound: the reading stands for the truth ``delay`` earlier
    def encoder_step(self, gear_ratio: float) -> float:
        """(b) Delta, rad at the steering axis: 2 pi / N on the axis, 2 pi / (N i2) on the motor side; 0 without
        an encoder."""
        if self.encoder_ticks is None:
            return 0.0
        return 2.0 * math.pi / self.encoder_ticks / (gear_ratio if self.encoder_side == "motor" else 1.0)

    def encoder_bound(self, gear_ratio: float) -> float:
        """(b) |quantised - theta| <= Delta/2 (round) or Delta (floor: the error lies in [0, Delta)), rad, padded
        for the float operations of the step (_ROUNDING_PAD)."""
        return self.encoder_step(gear_ratio) * _ROUNDING_PAD * (0.5 if self.encoder_rounding == "round" else 1.0)

    def encoder_spread(self, gear_ratio: float) -> float:
        """(b) the largest change of the quantisation error between two readings, rad: Delta (round and floor
        alike), padded; what a differenced velocity divides by T."""
        return self.encoder_step(gear_ratio) * _ROUNDING_PAD

    def noise_bound(self) -> float:
        """(c) |noise on alpha| <= this, rad: 0 (none), B (uniform on [-B, B)), inf (Gaussian: no bound)."""
        return {"none": 0.0, "uniform": self.noise, "gaussian": math.inf}[self.noise_kind]

    def velocity_noise_bound(self) -> float:
        """(d) |noise on alpha'| <= this, rad/s: 0, its bound B, or inf (Gaussian)."""
        return {"none": 0.0, "uniform": self.velocity_noise,
                "gaussian": math.inf}[self.velocity_noise_kind]

    def estimate_bound(self, control_period: float, *, angle_spread: float) -> tuple[float, float]:
        """(d) the velocity estimate's error bound (rad/s) and its lag (s, times sup|alpha''| in the bound).

        exact and tachometer: the velocity noise's bound, no lag. none: (0, 0): no alpha' is read (NaN), so no
        reading's error and no difference's T/2 lag is charged; a law that estimates alpha' itself charges its
        estimate in its own claim (:func:`wmr_mj.analysis.linear_part_bounds`). difference: the angle's error
        changes by at most ``angle_spread`` (rad) in a period T, so ``angle_spread / T`` plus the velocity noise,
        with the lag T/2 of a mean over the period; filtered: the same error (the filter's weights are >= 0 and sum
        to at most 1) and the lag tau_f + T/2 (:func:`measurement_error_bounds`).
        """
        if self.velocity in ("exact", "tachometer"):
            return self.velocity_noise_bound(), 0.0
        if self.velocity == "none":
            return 0.0, 0.0
        dot_error = angle_spread / control_period + self.velocity_noise_bound()
        return dot_error, control_period / 2.0 + (self.filter_tau or 0.0)  # filter_tau is set for 'filtered' only

    @property
    def reads_motor_side(self) -> bool:
        """True where the sensor reads the motor shaft, through an encoder or exactly (``encoder_side='motor'``,
        ``encoder_ticks`` any): the gear's play then lies between the reading and alpha. The side, not the
        ticks, says where the play sits."""
        return self.encoder_side == "motor"

    def model_options(self) -> dict[str, Any]:
        """The model keywords this part sets: none (the sensor runs in the control callback, not the model)."""
        return {}

    def coverage(self, *, control_period: float, gear_ratio: float, play: float = 0.0) -> Coverage:
        """The stages' bounds summed (:func:`measurement_error_bounds`), as a :class:`Coverage`; not covered
        where a noise is Gaussian: the error it enters is then unbounded, math.inf (a claim that reads only
        the numbers cannot cover it), the reason in ``why_not``.

        Args:
            control_period: T, s (> 0).
            gear_ratio: i2 (> 0).
            play: rad at the steering axis, what the gear's play adds where the sensor reads the motor side.
        """
        bounds = measurement_error_bounds(self, control_period=control_period, gear_ratio=gear_ratio, backlash=play)
        return Coverage(alpha_error=bounds.alpha_error_max, alpha_dot_error=bounds.alpha_dot_error_max,
                        delay=bounds.delay, lag=bounds.alpha_dot_lag,
                        why_not=() if bounds.covered else (str(bounds.why_not),))

    def to_dict(self) -> dict[str, Any]:
        """The spec form (JSON-ready; :meth:`from_spec` reads it back to an equal Sensing)."""
        return {"encoder_ticks": self.encoder_ticks, "encoder_side": self.encoder_side,
                "encoder_rounding": self.encoder_rounding, "velocity": self.velocity,
                "filter_tau": self.filter_tau,
                "noise": _noise_text(self.noise_kind, self.noise),
                "velocity_noise": _noise_text(self.velocity_noise_kind, self.velocity_noise),
                "delay": self.delay, "seed": self.seed}

    def label(self) -> str:
        """One short line: 'ideal', or e.g. 'encoder 4096/rev axis round, alpha' difference, delay 5 ms'."""
        if self.is_ideal:
            return "ideal"
        parts = []
        if self.encoder_ticks is None:
            parts.append("exact angle" + (" (motor side)" if self.encoder_side == "motor" else ""))
        else:
            parts.append(f"encoder {self.encoder_ticks}/rev {self.encoder_side} {self.encoder_rounding}")
        parts.append(f"alpha' {self.velocity}"
                     + (f" tau_f {self.filter_tau * 1e3:g} ms" if self.filter_tau is not None else ""))
        if self.noise_kind != "none":
            parts.append(f"noise {self.noise_kind} {self.noise:g} rad")
        if self.velocity_noise_kind != "none":
            parts.append(f"alpha' noise {self.velocity_noise_kind} {self.velocity_noise:g} rad/s")
        if self.delay:
            parts.append(f"delay {self.delay * 1e3:g} ms")
        if self.noise_kind != "none" or self.velocity_noise_kind != "none":
            parts.append(f"seed {self.seed}")
        return ", ".join(parts)

    @classmethod
    def from_spec(cls, spec: SpecSource) -> Sensing:
        """A Sensing from ``"KEY=VALUE,..."`` (keys :data:`SENSING_SPEC_KEYS`, noise as 'none',
        'uniform:BOUND' or 'gaussian:SIGMA'), a mapping of the same, a ``.json``/``.toml`` file (which sets at
        least one key), a preset name (:func:`~wmr_mj.hardware.presets.sensing_preset_names`), a preset or a file
        with changes (``preset=magnetic-14bit-axis,delay=0.003``, ``preset=my.toml,delay=0.003``), or None
        (ideal).

        Raises:
            UnknownNameError: an unknown key, preset or choice.
            ParameterError: a malformed value or a range refused (see the class).
        """
        return parse_spec(spec, cls, what="sensing", keys=_SPEC_KEYS, presets=_presets())


def _noise_text(kind: str, magnitude: float) -> str:
    return "none" if kind == "none" else f"{kind}:{magnitude!r}"


def _noise_key(kind_field: str, magnitude_field: str, unit: str) -> Converter:
    def convert(what: str, key: str, value: object) -> dict[str, object]:
        text = value.strip() if isinstance(value, str) else None
        if text == "none":
            return {kind_field: "none", magnitude_field: 0.0}
        kind, sep, magnitude = (text or "").partition(":")
        if text is None or not sep or kind not in ("uniform", "gaussian"):
            raise ParameterError(f"{what}: {key} = {value!r} is not accepted; accepted: {_NOISE_FORMS} ({unit})")
        return {kind_field: kind, magnitude_field: to_float(what, key, magnitude)}
    return convert


def _encoder_bits(what: str, key: str, value: object) -> dict[str, object]:
    """``encoder_bits=B``: an encoder of 2**B ticks per revolution (B an integer >= 0; the ticks' range is the
    part's)."""
    bits = to_int(what, key, value)
    if not 0 <= bits <= MAX_ENCODER_BITS:
        raise ParameterError(f"{what}: {key} = {value!r} is not accepted; an integer number of bits from 0 to "
                             f"{MAX_ENCODER_BITS} is required (encoder_ticks = 2**bits)")
    return {"encoder_ticks": 2 ** bits}


_SPEC_KEYS: dict[str, Converter] = {
    **field_converters(Sensing, exclude=("noise_kind", "noise", "velocity_noise_kind",
                                         "velocity_noise")),
    "encoder_bits": _encoder_bits,
    "noise": _noise_key("noise_kind", "noise", "rad"),
    "velocity_noise": _noise_key("velocity_noise_kind", "velocity_noise", "rad/s"),
}
#: The keys of the spec form, in :meth:`Sensing.to_dict`'s order, with ``encoder_bits`` (a second way to give
#: ``encoder_ticks``: 2**bits) after ``encoder_ticks``.
SENSING_SPEC_KEYS: tuple[str, ...] = tuple(k for key in Sensing().to_dict()
                                           for k in ((key, "encoder_bits") if key == "encoder_ticks" else (key,)))
assert set(SENSING_SPEC_KEYS) == set(_SPEC_KEYS)  # the two lists are one list

_PRESET_CACHE: dict[str, Sensing] = {}


def _presets() -> Mapping[str, Sensing]:
    if not _PRESET_CACHE:
        for name, spec in SENSING_PRESETS.items():
            _PRESET_CACHE[name] = parse_spec(dict(spec), Sensing, what=f"sensing preset {name!r}", keys=_SPEC_KEYS)
    return _PRESET_CACHE


def sensing_preset(name: str) -> Sensing:
    """The named preset (:func:`~wmr_mj.hardware.presets.sensing_preset_names`).

    Raises:
        UnknownNameError: an unknown name (the message lists the presets).
    """
    presets = _presets()
    if name not in presets:
        raise UnknownNameError("sensing preset", name, presets)
    return presets[name]


def _draw(rng: np.random.Generator, kind: str, magnitude: float, n: int) -> np.ndarray:
    if kind == "uniform":
        return rng.uniform(-magnitude, magnitude, n)  # [-B, B): the bound is never exceeded
    if kind == "gaussian":
        return rng.normal(0.0, magnitude, n)
    return np.zeros(n)


class SensingChain:
    """The sensing pipeline of one run (module docstring: steps (a)-(d), the layouts, the draw order).

    Args:
        sensing: the specification.
        control_period: T, s (> 0); the delay must be a whole number of it.
        n_steps: how many control steps the run has (>= 1): the noise arrays' length.
        gear_ratio: i2 (> 0), motor shaft angle / steering angle.

    Raises:
        ParameterError: a period, step count or gear ratio out of range, or a delay that is not a whole
            number of periods.

    Attributes:
        parameters: float64 (N_PARAMETERS,), read only by the step.
        state: float64 (STATE_HEADER + 3 (d + 1),), all the chain's memory.
        alpha_noise: float64 (n_steps,), rad, added to alpha at step k (zeros where no noise).
        alpha_dot_noise: float64 (n_steps,), rad/s, added to alpha' at step k.
    """

    def __init__(self, sensing: Sensing, *, control_period: float, n_steps: int, gear_ratio: float):
        d = sensing.delay_steps(control_period)
        if isinstance(n_steps, bool) or not isinstance(n_steps, int) or n_steps < 1:
            raise ParameterError(f"sensing chain: n_steps = {n_steps!r} is not accepted; an integer >= 1 is required")
        i2 = to_float("sensing chain", "gear_ratio", gear_ratio)
        if i2 <= 0.0:
            raise ParameterError(f"sensing chain: gear_ratio = {gear_ratio!r} is not accepted; i2 > 0 is required")
        self.sensing = sensing
        self.control_period = float(control_period)
        self.n_steps = n_steps
        self.delay_steps = d
        p = np.zeros(N_PARAMETERS)
        if sensing.encoder_ticks is not None:
            p[P_TICKS_PER_RAD] = sensing.encoder_ticks / (2.0 * math.pi)
        p[P_GEAR_RATIO] = i2
        p[P_PERIOD] = self.control_period
        #: the velocity estimate's coefficients (a, 1 - a), defined once (:mod:`wmr_mj.hardware.estimators`); None
        #: where no velocity is read
        self.estimator = (None if sensing.velocity == "none" else
                          velocity_estimator(sensing.velocity, control_period=self.control_period,
                                             filter_tau=sensing.filter_tau))
        if self.estimator is not None:
            p[P_FILTER_A], p[P_FILTER_ONE_MINUS_A] = self.estimator.a, self.estimator.one_minus_a
        p[P_DELAY_STEPS] = d
        p[P_ENCODER_SIDE] = _SIDE_CODES[sensing.encoder_side]
        p[P_ROUNDING] = _ROUNDING_CODES[sensing.encoder_rounding]
        p[P_VELOCITY] = _VELOCITY_CODES[sensing.velocity]
        p[P_ALPHA_NOISE_ON] = sensing.noise_kind != "none"
        p[P_ALPHA_DOT_NOISE_ON] = sensing.velocity_noise_kind != "none"
        self.parameters = p
        self.parameters.flags.writeable = False
        rng = np.random.default_rng(sensing.seed)
        self.alpha_noise = _draw(rng, sensing.noise_kind, sensing.noise, n_steps)
        self.alpha_dot_noise = _draw(rng, sensing.velocity_noise_kind, sensing.velocity_noise, n_steps)
        self.state = np.zeros(STATE_HEADER + 3 * (d + 1))
        # the step reads these as Python numbers (IEEE doubles, the same operations as numpy's, faster)
        self._ticks_per_rad = float(p[P_TICKS_PER_RAD])
        self._i2 = i2
        self._floor = sensing.encoder_rounding == "floor"
        self._motor = sensing.encoder_side == "motor"
        self._velocity = _VELOCITY_CODES[sensing.velocity]
        self._a, self._one_minus_a = float(p[P_FILTER_A]), float(p[P_FILTER_ONE_MINUS_A])
        self._noise_on = bool(p[P_ALPHA_NOISE_ON])
        self._dot_noise_on = bool(p[P_ALPHA_DOT_NOISE_ON])

    def reset(self) -> None:
        """Back to before step 0 (the noise arrays stay: a rerun reads the same numbers)."""
        self.state[:] = 0.0

    def step(self, k: int, alpha: float, alpha_dot: float, motor_angle: float) -> tuple[float, float]:
        """One control step: the measured (alpha rad, alpha' rad/s) from the true values at t_k = k T.

        Args:
            k: the step, 0, 1, 2, ... in turn (0 <= k < n_steps).
            alpha: the true steering angle, rad.
            alpha_dot: its true rate, rad/s.
            motor_angle: the motor shaft's angle at the motor, rad (i2 alpha without play); read where the
                encoder is on the motor side.

        Returns:
            (alpha_m rad, alpha'_m rad/s), Python floats.

        Raises:
            ValueError: k out of turn (the chain holds state from step k - 1) or k >= n_steps.
        """
        s = self.state
        if k != s[S_NEXT_STEP] or k >= self.n_steps:
            raise ValueError(f"sensing chain: step {k} called where step {int(s[S_NEXT_STEP])} is next "
                             f"(of {self.n_steps})")
        slots = self.delay_steps + 1
        j = S_RING + 3 * (k % slots)
        s[j], s[j + 1], s[j + 2] = alpha, alpha_dot, motor_angle
        if k == 0:  # before d steps have passed, every slot holds the state at t = 0
            for i in range(S_RING, S_RING + 3 * slots, 3):
                s[i], s[i + 1], s[i + 2] = alpha, alpha_dot, motor_angle
        r = S_RING + 3 * ((k + 1) % slots)  # slot of step k - d (k - d = k + 1 mod d + 1)
        theta = s.item(r + 2) if self._motor else s.item(r)
        c = self._ticks_per_rad
        if c != 0.0:
            x = theta * c
            theta = (math.floor(x) if self._floor else round(x)) / c  # ints < 2**53 convert exactly
        alpha_m = theta / self._i2 if self._motor else theta
        if self._noise_on:
            alpha_m = alpha_m + self.alpha_noise.item(k)
        if self._velocity <= 1:  # exact, tachometer
            v = s.item(r + 1)
        elif self._velocity == 4:  # none: the law reads the angle only
            v = math.nan
        else:
            v = 0.0 if k == 0 else (alpha_m - s.item(S_PREVIOUS_ALPHA)) / self.control_period
            if self._velocity == 3:
                v = self._a * s.item(S_FILTER) + self._one_minus_a * v
                s[S_FILTER] = v
        if self._dot_noise_on:
            v = v + self.alpha_dot_noise.item(k)
        s[S_PREVIOUS_ALPHA] = alpha_m
        s[S_NEXT_STEP] = k + 1
        return alpha_m, v

    def run(self, alpha: np.ndarray, alpha_dot: np.ndarray,
            motor_angle: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`step` over whole signals from step 0 (after a :meth:`reset`).

        Args:
            alpha: (n,) rad, n <= n_steps.
            alpha_dot: (n,) rad/s.
            motor_angle: (n,) rad; default i2 alpha (a gear without play).

        Returns:
            (alpha_m, alpha'_m), each (n,).
        """
        a = np.asarray(alpha, dtype=float)
        ad = np.asarray(alpha_dot, dtype=float)
        m = a * float(self.parameters[P_GEAR_RATIO]) if motor_angle is None else np.asarray(motor_angle, dtype=float)
        self.reset()
        out = np.array([self.step(k, a[k], ad[k], m[k]) for k in range(a.size)]).reshape(-1, 2)
        return out[:, 0], out[:, 1]


@dataclass(frozen=True)
class MeasurementBounds:
    """What the sensing's measurement error is bounded by, for the certificate's terms.

    With alpha_d(t_k) = alpha(t_k - delay) the delayed true angle, at every control step k:

    - |alpha_m[k] - alpha_d(t_k)| <= ``alpha_error_max``;
    - |alpha'_m[k] - alpha_d'(t_k)| <= ``alpha_dot_error_max`` + ``alpha_dot_lag`` sup|alpha''|;
    - the delay itself: |alpha(t - delay) - alpha(t)| <= ``delay`` sup|alpha'| (the certificate's term).

    ``covered`` is False where no bound exists (``why_not`` says why; the bound is then inf).
    """

    alpha_error_max: float  # rad
    alpha_dot_error_max: float  # rad/s
    alpha_dot_lag: float  # s: the velocity estimate's lag, times sup|alpha''| in the bound
    delay: float  # s
    covered: bool
    why_not: str | None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (inf stays a float: JSON writers spell it Infinity)."""
        return {"alpha_error_max": self.alpha_error_max, "alpha_dot_error_max": self.alpha_dot_error_max,
                "alpha_dot_lag": self.alpha_dot_lag, "delay": self.delay, "covered": self.covered,
                "why_not": self.why_not}


# quantisation bounds hold in real arithmetic; the float operations of step (b) add a few ulp of the angle:
# 1e-9 relative covers angles up to ~1e3 rad at the shaft (4 ulp of 1e3 rad = 1e-12 rad < 1e-9 * 2 pi / 2**24)
_ROUNDING_PAD = 1.0 + 1e-9


def measurement_error_bounds(sensing: Sensing, *, control_period: float, gear_ratio: float,
                             backlash: float = 0.0) -> MeasurementBounds:
    """The bounds of :class:`MeasurementBounds` for ``sensing`` (mismatch.md item 4).

    On alpha, the sum of:
      - quantisation: Delta/2 (round) or Delta (floor; the error lies in [0, Delta)), Delta = 2 pi / N at the
        axis, 2 pi / (N i2) on the motor side;
      - uniform noise: its bound B;
      - backlash b (rad at the steering axis), where the encoder is on the motor side: the motor angle / i2
        is within b of alpha.
    On alpha', by the estimate:
      - exact, tachometer: the velocity noise's bound; no lag;
      - difference: (alpha_m[k] - alpha_m[k-1]) / T = (alpha_d(t_k) - alpha_d(t_{k-1})) / T + (eta_k - eta_{k-1})
        / T. The first term is the mean of alpha_d' over [t_{k-1}, t_k], within (T/2) sup|alpha''| of
        alpha_d'(t_k): the lag T/2. The second is at most the spread of eta over T: Delta (round and floor
        alike), 2 B, 2 b, summed;
      - filtered: the filter's weights (1 - a) a^j are >= 0 and sum to at most 1, so the error part keeps the
        difference's bound; the signal part is a weighted mean of the differences, each (j + 1/2) T old,
        whose mean age is T a/(1 - a) + T/2 <= tau_f + T/2 (a/(1 - a) = 1/(e^{T/tau_f} - 1) <= tau_f/T): the lag
        tau_f + T/2;
      - plus the velocity noise's bound.
    The difference and the filter start from 0 (y_{-1} = 0, alpha'_m[0] = 0): the bounds assume the steering
    at rest at t = 0 (alpha'(0) = 0); otherwise add |alpha'(0)| a^(k+1) at step k.

    Args:
        sensing: the specification.
        control_period: T, s (> 0).
        gear_ratio: i2 (> 0).
        backlash: b, rad at the steering axis, the gear's half-width (>= 0).

    Returns:
        The bounds; Gaussian noise (on alpha or alpha') gives covered False, why_not "Gaussian noise has no
        bound", and inf in the bound it enters.

    Raises:
        ParameterError: a period, gear ratio or backlash out of range, or a delay that is not a whole number
            of periods.
    """
    sensing.delay_steps(control_period)
    T = float(control_period)
    i2 = to_float("measurement bounds", "gear_ratio", gear_ratio)
    b = to_float("measurement bounds", "backlash", backlash)
    if i2 <= 0.0 or b < 0.0:
        raise ParameterError(f"measurement bounds: gear_ratio = {gear_ratio!r} (> 0 required) or backlash = "
                             f"{backlash!r} rad (>= 0 required) is not accepted")
    play = b if sensing.encoder_side == "motor" else 0.0
    noise = sensing.noise_bound()
    alpha_error = sensing.encoder_bound(i2) + noise + play
    spread = sensing.encoder_spread(i2) + 2.0 * noise + 2.0 * play
    dot_error, lag = sensing.estimate_bound(T, angle_spread=spread)
    gaussian = "gaussian" in (sensing.noise_kind, sensing.velocity_noise_kind)
    return MeasurementBounds(alpha_error_max=alpha_error, alpha_dot_error_max=dot_error, alpha_dot_lag=lag,
                             delay=sensing.delay, covered=not gaussian,
                             why_not="Gaussian noise has no bound" if gaussian else None)
