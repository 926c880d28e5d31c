"""Signals that act on the plant during a run: a steering disturbance torque and chassis load changes.

A run's :class:`Signals` (``RunConfig.signals``; ``wmr-mj run --signals FILE.json``,
``--disturbance``, ``--load``) is plain data: frozen, every parameter explicit (the noise's seed
included), and its :meth:`Signals.to_dict` is the JSON that :func:`signals_from` reads back, so a
reported signal reproduces its run to the bit. The forms::

    {"disturbance": {"kind": "step", "amplitude": 1.0, "t1": 5.0},     # N m on the steering joint
     "d_max": 1.5,                       # declared bound [N m] for the certificate (default: the signal's)
     "loads": [{"kind": "step", "t": 10.0, "m1": 600.0},                # chassis mass [kg] from t on
               {"kind": "ramp", "t1": 15.0, "t2": 20.0, "m1": 700.0, "every": 0.1}]}

Disturbance kinds (d in N m, positive turning the steering towards +alpha; the value at each
control step's start is held over that step, as the voltage is):

* ``constant``: d = amplitude throughout (t1 = 0);
* ``step``: amplitude from t1 on (until t2, when given);
* ``pulse``: amplitude for t1 <= t < t2;
* ``noise``: band-limited noise from t1 (until t2): knots every 1/(2 bandwidth) s, uniform in
  [-amplitude, amplitude] from ``numpy.random.default_rng(seed)``, joined by half-cosine
  segments, so |d| <= |amplitude| and the spectrum falls off above ``bandwidth`` [Hz].

Its bound, |d| <= |amplitude|, is the d_max the certificate declares unless ``d_max`` says a
larger one; a signal beyond the declared bound makes the run uncertified (an assumption
"disturbance within the bound" names value and limit).

Loads: ``step`` sets m1 from t on; ``ramp`` goes linearly from the m1 before t1 to ``m1`` at t2,
applied as steps every ``every`` s (the mass is piecewise constant; each change is applied at the
first control step at or after its time). The chassis mass and inertia change together as
:func:`wmr_mj.params.with_params` has them (``RunConfig.m1_inertia``); the front axle's normal
load, hence the steering's Coulomb friction, follows; the drive servo's gain does not (a payload
change does not retune it). The certificate covers every m1 inside its box (the module docstring
of :mod:`wmr_mj.analysis.certificate`); one outside makes the run uncertified ("load inside the box").
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from wmr_mj.errors import ParameterError

__all__ = ["Disturbance", "LoadChange", "Signals", "signals_from", "DISTURBANCE_KINDS", "LOAD_KINDS"]

DISTURBANCE_KINDS = ("constant", "step", "pulse", "noise")
LOAD_KINDS = ("step", "ramp")


def _num(where: str, name: str, value: Any, *, positive: bool = False, nonneg: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(f"{where}: {name} = {value!r} is not accepted: a number is required")
    v = float(value)
    if not math.isfinite(v) or (positive and v <= 0) or (nonneg and v < 0):
        need = " > 0" if positive else (" >= 0" if nonneg else "")
        raise ParameterError(f"{where}: {name} = {value!r} is not accepted: a finite number{need} is required")
    return v


def _keys(where: str, data: Mapping[str, Any], allowed: Sequence[str]) -> None:
    if not isinstance(data, Mapping):
        raise ParameterError(f"{where} must be a JSON object, got {data!r}")
    extra = sorted(set(data) - set(allowed))
    if extra:
        raise ParameterError(f"{where}: unknown key(s) {', '.join(map(repr, extra))}; accepted: {', '.join(allowed)}")


@dataclass(frozen=True)
class Disturbance:
    """A torque d(t) [N m] on the steering joint (module docstring); |d| <= |amplitude|."""

    kind: str
    amplitude: float
    t1: float = 0.0
    t2: float | None = None
    bandwidth: float | None = None  # Hz, noise only
    seed: int | None = None  # noise only

    def __post_init__(self) -> None:
        w = "disturbance"
        if self.kind not in DISTURBANCE_KINDS:
            raise ParameterError(f"{w}: kind = {self.kind!r} is not accepted; accepted: {', '.join(DISTURBANCE_KINDS)}")
        object.__setattr__(self, "amplitude", _num(w, "amplitude", self.amplitude))
        object.__setattr__(self, "t1", _num(w, "t1", self.t1, nonneg=True))
        if self.t2 is not None:
            object.__setattr__(self, "t2", _num(w, "t2", self.t2, nonneg=True))
            if self.t2 <= self.t1:
                raise ParameterError(f"{w}: t2 = {self.t2:g} s must be after t1 = {self.t1:g} s")
        if self.kind == "constant" and (self.t1 != 0.0 or self.t2 is not None):
            raise ParameterError(f"{w}: a constant disturbance has no t1/t2; use kind 'step' or 'pulse'")
        if self.kind == "pulse" and self.t2 is None:
            raise ParameterError(f"{w}: a pulse needs t2 (its end, s)")
        if self.kind == "noise":
            if self.bandwidth is None or self.seed is None:
                raise ParameterError(f"{w}: noise needs bandwidth (Hz, > 0) and seed (an integer >= 0)")
            object.__setattr__(self, "bandwidth", _num(w, "bandwidth", self.bandwidth, positive=True))
            if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
                raise ParameterError(f"{w}: seed = {self.seed!r} is not accepted: an integer >= 0 is required")
        elif self.bandwidth is not None or self.seed is not None:
            raise ParameterError(f"{w}: bandwidth and seed belong to kind 'noise', not {self.kind!r}")

    @property
    def bound(self) -> float:
        """max |d| [N m]."""
        return abs(self.amplitude)

    def samples(self, t: np.ndarray) -> np.ndarray:
        """d [N m] at times ``t`` [s] (the control steps' starts)."""
        t = np.asarray(t, dtype=float)
        on = t >= self.t1
        if self.t2 is not None:
            on &= t < self.t2
        if self.kind != "noise":
            return np.where(on, self.amplitude, 0.0)
        assert self.bandwidth is not None and self.seed is not None  # checked for noise at construction
        h = 0.5 / self.bandwidth  # knot spacing, s
        x = t / h
        j = np.floor(x).astype(np.int64)
        count = int(j.max()) + 2 if j.size else 2
        knots = self.amplitude * np.random.default_rng(self.seed).uniform(-1.0, 1.0, size=count)
        w = 0.5 * (1.0 - np.cos(math.pi * (x - j)))
        return np.where(on, knots[j] * (1.0 - w) + knots[j + 1] * w, 0.0)

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"kind": self.kind, "amplitude": self.amplitude, "t1": self.t1}
        for name in ("t2", "bandwidth", "seed"):
            if getattr(self, name) is not None:
                out[name] = getattr(self, name)
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Disturbance:
        _keys("disturbance", data, ("kind", "amplitude", "t1", "t2", "bandwidth", "seed"))
        if "kind" not in data or "amplitude" not in data:
            raise ParameterError("disturbance: kind and amplitude (N m) are required")
        return cls(**dict(data))


@dataclass(frozen=True)
class LoadChange:
    """A change of the chassis mass m1 [kg]: a step at ``t``, or a ramp over t1..t2 in steps of ``every``."""

    kind: str
    m1: float
    t: float | None = None  # step
    t1: float | None = None  # ramp
    t2: float | None = None
    every: float | None = None

    def __post_init__(self) -> None:
        w = "load"
        if self.kind not in LOAD_KINDS:
            raise ParameterError(f"{w}: kind = {self.kind!r} is not accepted; accepted: {', '.join(LOAD_KINDS)}")
        object.__setattr__(self, "m1", _num(w, "m1", self.m1, positive=True))
        if self.kind == "step":
            if self.t is None or any(v is not None for v in (self.t1, self.t2, self.every)):
                raise ParameterError(f"{w}: a step takes t (s) and m1 (kg) only")
            object.__setattr__(self, "t", _num(w, "t", self.t, nonneg=True))
        else:
            if self.t is not None or self.t1 is None or self.t2 is None:
                raise ParameterError(f"{w}: a ramp takes t1, t2 (s), m1 (kg) and optionally every (s)")
            object.__setattr__(self, "t1", _num(w, "t1", self.t1, nonneg=True))
            object.__setattr__(self, "t2", _num(w, "t2", self.t2, nonneg=True))
            object.__setattr__(self, "every", _num(w, "every", 0.1 if self.every is None else self.every,
                                                   positive=True))
            if self.t2 <= self.t1:
                raise ParameterError(f"{w}: ramp t2 = {self.t2:g} s must be after t1 = {self.t1:g} s")

    @property
    def start(self) -> float:
        return float(self.t if self.kind == "step" else self.t1)  # type: ignore[arg-type]

    def steps(self, m1_before: float) -> list[tuple[float, float]]:
        """(time [s], m1 [kg]) of the piecewise-constant mass this change applies."""
        if self.kind == "step":
            return [(float(self.t), self.m1)]  # type: ignore[arg-type]
        t1, t2, every = float(self.t1), float(self.t2), float(self.every)  # type: ignore[arg-type]
        n = max(1, int(math.ceil((t2 - t1) / every - 1e-9)))
        out = [(t1 + (t2 - t1) * i / n, m1_before + (self.m1 - m1_before) * i / n) for i in range(1, n)]
        return out + [(t2, self.m1)]

    def to_dict(self) -> dict[str, Any]:
        names = ("t",) if self.kind == "step" else ("t1", "t2", "every")
        return {"kind": self.kind, **{n: getattr(self, n) for n in names}, "m1": self.m1}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> LoadChange:
        _keys("load", data, ("kind", "t", "t1", "t2", "every", "m1"))
        if "kind" not in data or "m1" not in data:
            raise ParameterError("load: kind and m1 (kg) are required")
        return cls(**dict(data))


@dataclass(frozen=True)
class Signals:
    """What acts on the plant during a run besides the law: a disturbance, load changes, and the
    disturbance bound the certificate declares (``d_max`` [N m]; None: the disturbance's own)."""

    disturbance: Disturbance | None = None
    loads: tuple[LoadChange, ...] = ()
    d_max: float | None = None

    def __post_init__(self) -> None:
        if self.disturbance is not None and not isinstance(self.disturbance, Disturbance):
            raise ParameterError(f"signals: disturbance must be a Disturbance, got {type(self.disturbance).__name__}")
        loads = tuple(self.loads)
        for ld in loads:
            if not isinstance(ld, LoadChange):
                raise ParameterError(f"signals: loads must be LoadChange records, got {type(ld).__name__}")
        starts = [ld.start for ld in loads]
        if starts != sorted(starts):
            raise ParameterError("signals: loads must be in time order")
        for a, b in zip(loads, loads[1:]):
            if a.kind == "ramp" and b.start < float(a.t2):  # type: ignore[arg-type]
                raise ParameterError(f"signals: a load change at {b.start:g} s falls inside the ramp "
                                     f"{a.t1:g}..{a.t2:g} s")
        object.__setattr__(self, "loads", loads)
        if self.d_max is not None:
            object.__setattr__(self, "d_max", _num("signals", "d_max", self.d_max, nonneg=True))

    @property
    def empty(self) -> bool:
        return self.disturbance is None and not self.loads and self.d_max is None

    @property
    def declared_d_max(self) -> float:
        """The disturbance bound [N m] the certificate declares: d_max, else the signal's own, else 0."""
        if self.d_max is not None:
            return self.d_max
        return self.disturbance.bound if self.disturbance is not None else 0.0

    def load_steps(self, m1: float) -> list[tuple[float, float]]:
        """(time [s], m1 [kg]) of every mass change, from the run's initial m1."""
        out: list[tuple[float, float]] = []
        for ld in self.loads:
            out += ld.steps(out[-1][1] if out else m1)
        return out

    def m1_values(self, m1: float) -> list[float]:
        """Every chassis mass [kg] the run has: the initial one and each change's."""
        return [m1, *(m for _, m in self.load_steps(m1))]

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if self.disturbance is not None:
            out["disturbance"] = self.disturbance.to_dict()
        if self.d_max is not None:
            out["d_max"] = self.d_max
        if self.loads:
            out["loads"] = [ld.to_dict() for ld in self.loads]
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Signals:
        _keys("signals", data, ("disturbance", "d_max", "loads"))
        dist = data.get("disturbance")
        loads = data.get("loads") or []
        if not isinstance(loads, list):
            raise ParameterError(f"signals: loads must be a JSON list, got {loads!r}")
        return cls(disturbance=None if dist is None else Disturbance.from_dict(dist),
                   loads=tuple(LoadChange.from_dict(ld) for ld in loads), d_max=data.get("d_max"))


def signals_from(value: Any) -> Signals | None:
    """A :class:`Signals` from itself, a mapping, JSON text or a .json file; None for None or nothing."""
    if value is None or isinstance(value, Signals):
        return None if value is None or value.empty else value
    if isinstance(value, Mapping):
        s = Signals.from_dict(value)
        return None if s.empty else s
    if isinstance(value, (str, Path)):
        text = str(value)
        if not text.lstrip().startswith("{"):
            try:
                text = Path(value).read_text()
            except OSError as exc:
                raise ParameterError(f"signals file {str(value)!r} is not readable: {exc.strerror}") from None
        try:
            data = json.loads(text)
        except ValueError as exc:
            raise ParameterError(f"signals {str(value)[:60]!r} is not JSON: {exc}") from None
        return signals_from(data)
    raise ParameterError(f"signals = {value!r} is not accepted: a Signals, a JSON object or a .json file")
