"""Versioned scenario suites: one yardstick for every controller (``wmr-mj compare``).

A suite (``wmr_mj/data/suites/<name>.toml``, e.g. ``standard-v1``) is data: scenarios, each a path of
C x a plant x signals on the plant (x, from ``standard-v2``, the cart as it is built: its sensing, actuation
and gear play, a ``[hardware.<name>]`` table; ideal where a scenario names none) with a stable identifier;
requirements in STL that every run is judged by; and the adversary's box, over which ``compare`` falsifies
every controller at the same budget and seed. Changing any of it makes a new suite version; results name the
suite's name and version with the wmr-mj and MuJoCo versions (:func:`versions`).

Usage::

    from wmr_mj.experiments.suite import load_suite
    suite = load_suite("standard-v1")
    [s.id for s in suite.scenarios][:2]      # ['circle/nominal/none', 'circle/nominal/pulse']
    config = suite.scenarios[0].config(base)  # the RunConfig of that scenario for a design's base config
    load_suite("standard-v2").scenario("circle/nominal/none/magnetic-12bit").sensing   # Sensing(4096 ticks, ...)
"""

from __future__ import annotations

import hashlib
import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from wmr_mj._version import __version__
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware import Actuation, Sensing, Transmission
from wmr_mj.params import parameter_names
from wmr_mj.sim.coerce import coerce
from wmr_mj.sim.config import RunConfig

__all__ = ["Suite", "Scenario", "Adversary", "load_suite", "suite_names", "SUITES_DIR", "versions"]

SUITES_DIR = Path(__file__).resolve().parents[1] / "data" / "suites"


@dataclass(frozen=True)
class Scenario:
    """One scenario: its stable ``id``, C's ``path`` (None where the suite names none: the design's own, a design
    file's path or its cart's), the plant's parameters (``plant``: name and overrides, m1 among them where set) and
    the run's ``signals`` (JSON form, None: none)."""

    id: str
    path: str | None
    plant: str
    plant_params: Mapping[str, float]
    signals_name: str
    signals: Mapping[str, Any] | None
    duration: float
    reference_bounds: str | None
    #: the cart as it is built (``[hardware.<name>]``): None where the scenario names none (the design's own,
    #: ideal by default; every scenario of standard-v1), else the typed parts the run gets
    hardware: str | None = None
    sensing: Any = None  # wmr_mj.hardware.Sensing
    actuation: Any = None  # wmr_mj.hardware.Actuation
    transmission: Any = None  # wmr_mj.hardware.Transmission

    def config(self, base: RunConfig) -> RunConfig:
        """``base`` (a design: its controller, tracker, gains, model) on this scenario: on the scenario's path where it
        names one, else the design's own (``base.path``: a design file's, else its cart's); on the scenario's
        hardware where it names one (its sensing, actuation and transmission replace the design's)."""
        params = dict(self.plant_params)
        m1 = params.pop("m1", None)
        changes: dict[str, Any] = {"path": base.path if self.path is None else self.path, "duration": self.duration,
                                   "plant_overrides": {**base.plant_overrides, **params},
                                   "signals": None if self.signals is None else dict(self.signals),
                                   "reference_bounds": self.reference_bounds}
        if m1 is not None:
            changes["m1"] = float(m1)
        if self.hardware is not None:
            changes.update(sensing=self.sensing, actuation=self.actuation, transmission=self.transmission)
        return coerce(base.replace(**changes))  # the scenario's signals, route and parts typed (wmr_mj.sim.coerce)


@dataclass(frozen=True)
class Adversary:
    """The box ``compare`` falsifies every controller over: the plant's uncertainty box, C's path (knots and
    hold within the declared bounds; ``path`` the base path, None where the suite names none: the design's own)
    and a disturbance pulse (start and amplitude), against one requirement."""

    requirement: str
    path: str | None
    uncertainty: str
    path_knots: int
    hold_range: tuple[float, float]
    pulse_t1: tuple[float, float]
    pulse_amplitude: tuple[float, float]
    pulse_width: float


@dataclass(frozen=True)
class Suite:
    """A loaded suite: name, version, scenarios in order, requirements (name -> STL) and the adversary."""

    name: str
    version: int
    duration: float
    d_max: float
    reference_bounds: str | None
    scenarios: tuple[Scenario, ...]
    requirements: Mapping[str, str]
    adversary: Adversary
    source: str
    sha256: str = field(default="")

    def scenario(self, scenario_id: str) -> Scenario:
        for s in self.scenarios:
            if s.id == scenario_id:
                return s
        raise UnknownNameError("scenario", scenario_id, tuple(s.id for s in self.scenarios))

    def select(self, patterns: Sequence[str]) -> tuple[Scenario, ...]:
        """The scenarios whose id matches any of the shell-style ``patterns`` (all where none is given).

        Raises:
            UnknownNameError: a pattern that matches no scenario (the valid ids listed).
        """
        from fnmatch import fnmatchcase

        if not patterns:
            return self.scenarios
        out: list[Scenario] = []
        for p in patterns:
            hits = [s for s in self.scenarios if fnmatchcase(s.id, p)]
            if not hits:
                raise UnknownNameError("scenario", p, tuple(s.id for s in self.scenarios))
            out.extend(h for h in hits if h not in out)
        return tuple(out)

    def to_dict(self) -> dict[str, Any]:
        """JSON form; ``hardware`` (scenario id -> its sensing, actuation and transmission labels) only where a
        scenario names hardware (a suite without, standard-v1, gives the keys it always gave)."""
        out = {"name": self.name, "version": self.version, "sha256": self.sha256, "duration": self.duration,
               "d_max": self.d_max, "reference_bounds": self.reference_bounds,
               "requirements": dict(self.requirements), "scenarios": [s.id for s in self.scenarios]}
        built = {s.id: {"hardware": s.hardware, "sensing": s.sensing.label(), "actuation": s.actuation.label(),
                        "transmission": s.transmission.label()} for s in self.scenarios if s.hardware is not None}
        if built:
            out["hardware"] = built
        return out


def suite_names() -> tuple[str, ...]:
    """The packaged suites (``wmr_mj/data/suites/*.toml``)."""
    return tuple(sorted(p.stem for p in SUITES_DIR.glob("*.toml")))


def versions() -> dict[str, str]:
    """The versions results name beside the suite's: wmr-mj's and MuJoCo's."""
    import mujoco

    return {"wmr_mj": __version__, "mujoco": mujoco.__version__}


def load_suite(name: str) -> Suite:
    """A packaged suite by name (:func:`suite_names`) or a suite file (``.toml``).

    Raises:
        UnknownNameError: an unknown suite name.
        ParameterError: a malformed suite (naming the table and what is accepted), a duplicate scenario id,
            an unknown plant parameter, signals set or requirement name.
    """
    path = Path(name)
    if not (name.endswith(".toml") and path.is_file()):
        if name not in suite_names():
            raise UnknownNameError("suite", name, suite_names() + ("<suite file .toml>",))
        path = SUITES_DIR / f"{name}.toml"
    raw = path.read_bytes()
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ParameterError(f"suite {name!r}: not TOML ({exc})") from None
    where = f"suite {name!r}"
    try:
        return _build(data, where, str(path), hashlib.sha256(raw).hexdigest())
    except (ParameterError, UnknownNameError):
        raise  # already one line naming the table and what is accepted
    except (KeyError, TypeError, ValueError) as exc:
        raise ParameterError(f"{where}: malformed ({type(exc).__name__}: {exc}); see "
                             "wmr_mj/data/suites/standard-v1.toml for the format") from None


_HARDWARE_KEYS = ("sensing", "actuation", "backlash")


def _hardware(name: str, spec: Mapping[str, Any], where: str) -> dict[str, Any]:
    """A ``[hardware.<name>]`` table as typed parts: ``sensing`` and ``actuation`` in the spec forms of
    :meth:`wmr_mj.hardware.Sensing.from_spec` / :meth:`~wmr_mj.hardware.Actuation.from_spec` (a preset name,
    ``"KEY=VALUE,..."`` or an inline table), ``backlash`` in rad at the steering axis; each ideal where absent.

    Raises:
        UnknownNameError: an unknown key of the table (or of a spec).
        ParameterError: a bad value (the part's message, prefixed with the table).
    """
    for key in spec:
        if key not in _HARDWARE_KEYS:
            raise UnknownNameError(f"{where}: [hardware.{name}] key", str(key), _HARDWARE_KEYS)
    try:
        return {"sensing": Sensing.from_spec(spec.get("sensing")),
                "actuation": Actuation.from_spec(spec.get("actuation")),
                "transmission": Transmission.from_spec(spec.get("backlash", 0.0))}
    except ParameterError as exc:
        raise ParameterError(f"{where}: [hardware.{name}] {exc}") from None


def _build(data: Mapping[str, Any], where: str, source: str, sha256: str) -> Suite:
    head = data["suite"]
    duration, d_max = float(head["duration"]), float(head.get("d_max", 0.0))
    if not (math.isfinite(duration) and duration > 0):
        raise ParameterError(f"{where}: [suite] duration = {duration!r} must be > 0 s")
    bounds = head.get("reference_bounds")
    names = parameter_names()
    plants = {}
    for plant, params in data["plants"].items():
        for key in params:
            if key not in names:
                raise UnknownNameError(f"{where}: [plants.{plant}] parameter", key, names)
        plants[plant] = {k: float(v) for k, v in params.items()}
    signal_sets = {}
    for sig, content in data["signals"].items():
        signal_sets[sig] = ({**content, "d_max": d_max} if content else None)
    requirements = {str(k): str(v) for k, v in data["requirements"].items()}
    hardware = {str(name): _hardware(name, spec, where) for name, spec in data.get("hardware", {}).items()}
    scenarios, seen = [], set()
    for s in data["scenario"]:
        sid = str(s["id"])
        if sid in seen:
            raise ParameterError(f"{where}: scenario id {sid!r} is given twice (ids must be unique and stable)")
        seen.add(sid)
        if s["plant"] not in plants:
            raise UnknownNameError(f"{where}: scenario {sid!r} plant", s["plant"], tuple(plants))
        if s["signals"] not in signal_sets:
            raise UnknownNameError(f"{where}: scenario {sid!r} signals", s["signals"], tuple(signal_sets))
        built: dict[str, Any] = {}
        if "hardware" in s:
            if s["hardware"] not in hardware:
                raise UnknownNameError(f"{where}: scenario {sid!r} hardware", s["hardware"], tuple(hardware))
            built = {"hardware": str(s["hardware"]), **hardware[s["hardware"]]}
        path = None if s.get("path") is None else str(s["path"])  # none: the design's own
        scenarios.append(Scenario(id=sid, path=path, plant=str(s["plant"]), plant_params=plants[s["plant"]],
                                  signals_name=str(s["signals"]), signals=signal_sets[s["signals"]],
                                  duration=duration, reference_bounds=bounds, **built))
    adv = data["adversary"]
    if adv["requirement"] not in requirements:
        raise UnknownNameError(f"{where}: [adversary] requirement", adv["requirement"], tuple(requirements))
    pulse = adv["disturbance"]
    adv_path = None if adv.get("path") is None else str(adv["path"])  # none: the design's own
    adversary = Adversary(requirement=str(adv["requirement"]), path=adv_path,
                          uncertainty=str(adv["uncertainty"]), path_knots=int(adv.get("path_knots", 0)),
                          hold_range=(float(adv["hold_range"][0]), float(adv["hold_range"][1])),
                          pulse_t1=(float(pulse["t1"][0]), float(pulse["t1"][1])),
                          pulse_amplitude=(float(pulse["amplitude"][0]), float(pulse["amplitude"][1])),
                          pulse_width=float(pulse["width"]))
    return Suite(name=str(head["name"]), version=int(head["version"]), duration=duration, d_max=d_max,
                 reference_bounds=bounds, scenarios=tuple(scenarios), requirements=requirements,
                 adversary=adversary, source=source, sha256=sha256)
