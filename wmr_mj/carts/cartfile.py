"""A cart file: a front-steered cart's parameters in SI units, each with its source, read from TOML.

The C80 is ``c80.toml`` beside this module (shipped with the package); :mod:`wmr_mj.params` builds the C80
parameter set from it. A file is checked against ``cart.schema.json`` (:mod:`wmr_mj.carts.schema`), then
against the rules a schema cannot say: l3 below the wheelbase l1, k_b equal to k_i (one flux in SI units, and
MuJoCo's dcmotor has one motor constant: it would silently use their geometric mean), each range's lo below
its hi, the newest changelog line beginning with the version. Every failure is one line naming the file, the
key, the value, its unit and what is accepted (:class:`wmr_mj.errors.ParameterError`; the CLI exits with 2).

The file's layout (``c80.toml`` is the example to copy)::

    name = "C80"
    version = "1.0.0"
    changelog = ["1.0.0 (2026-11-27): ..."]          # newest first, each line beginning with its version
    [chassis.l1]                                      # one table per parameter, in its section
    value = 0.612
    unit = "m"                                        # must be the schema's SI unit: a check, not a conversion
    source = "chosen: 0.612 m wheelbase, ..."
    [uncertainty.full.mu]                             # the boxes: 'm1' (the paper's) and 'full'
    range = [0.0129, 0.0215]
    unit = "-"
    source = "..."
    [defaults.sensing]                                # the default sensing, actuation and play
    value = "ideal"
    source = "..."

Usage::

    from wmr_mj.carts import load_cart

    cart = load_cart("c80")                  # a shipped cart by name, or a path to a .toml file
    cart.parameters["l1"], cart.units["l1"], cart.sources["l1"]     # 0.612, 'm', 'chosen: ...'
    cart.uncertainty["full"]["mu"]           # (0.0129, 0.0215)
"""

from __future__ import annotations

import functools
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

from wmr_mj.carts.schema import check_against_schema, load_schema
from wmr_mj.errors import ParameterError

__all__ = ["CARTS_DIR", "CartFile", "cart_names", "cart_path", "load_cart", "load_cart_text", "cart_of",
           "cart_of_text", "PARAMETER_SECTIONS", "DEFAULT_KEYS"]

#: The shipped carts (``NAME.toml``), inside the package: found from any folder and by an installed wheel.
CARTS_DIR = Path(__file__).resolve().parent
#: The sections holding the parameters, in the file's order (the schema's 'required' keys minus the others).
PARAMETER_SECTIONS: tuple[str, ...] = tuple(
    key for key in load_schema()["required"] if key not in ("name", "version", "changelog", "uncertainty", "defaults"))
#: How far k_b may differ from k_i, relative: a rounding, not a second constant (see _check_rules).
MOTOR_CONSTANT_RTOL = 1e-9
#: The largest armature electrical time constant L_a / R_a accepted in a cart file's motor.L_a, s: the limit of
#: --actuation inductance=, :data:`wmr_mj.hardware.assembly.MAX_ELECTRICAL_TIME_CONSTANT_S` (its source there; the
#: carts sit below the hardware layer, so it is written twice and a test holds the two equal).
MAX_ELECTRICAL_TIME_CONSTANT_S = 0.1
#: The keys of the [defaults] section: the default sensing, actuation and play of a run on the cart.
DEFAULT_KEYS: tuple[str, ...] = tuple(load_schema()["properties"]["defaults"]["required"])


def _frozen(mapping: Mapping[str, Any]) -> Mapping[str, Any]:
    return MappingProxyType(dict(mapping))


@dataclass(frozen=True)
class CartFile:
    """A checked cart file. Parameters are floats in SI units, by name (the C80Parameters field names).

    Attributes:
        name, version: the file's name and version (MAJOR.MINOR.PATCH).
        changelog: one line per version, newest first.
        path: the file read.
        parameters: parameter name -> value in its SI unit, in the file's section order.
        units: parameter name -> unit ('m', 'kg', 'rad', '-' for a ratio, ...).
        sources: parameter name -> where its value comes from.
        sections: section name -> its parameters' names.
        uncertainty: box name ('m1', 'full') -> parameter name -> (lo, hi) in its unit.
        uncertainty_sources: box name -> parameter name -> where the range comes from.
        defaults: 'sensing', 'actuation' (a preset name or KEY=VALUE spec), 'backlash' (rad) -> value.
        default_sources: the same keys -> where the default comes from.
        text: the file's text as read (a run's record and its log carry it; :func:`load_cart_text` reads it back).
        default_path: the path the cart declares its own (``[paths] default``): a path or packaged route's name as
            written, a route file as its path beside the cart file; None: the cart declares none.
    """

    name: str
    version: str
    changelog: tuple[str, ...]
    path: Path
    parameters: Mapping[str, float]
    units: Mapping[str, str]
    sources: Mapping[str, str]
    sections: Mapping[str, tuple[str, ...]]
    uncertainty: Mapping[str, Mapping[str, tuple[float, float]]]
    uncertainty_sources: Mapping[str, Mapping[str, str]]
    defaults: Mapping[str, Any]
    default_sources: Mapping[str, str]
    text: str = ""
    default_path: str | None = None

    def numbers(self) -> tuple[dict, dict, dict, str | None]:
        """What a run reads of the cart: its parameters, its boxes, its defaults and its default path (two carts
        of the same numbers run alike, whatever their names)."""
        return (dict(self.parameters), {k: dict(v) for k, v in self.uncertainty.items()}, dict(self.defaults),
                self.default_path)

    def __reduce__(self) -> tuple[Any, ...]:
        # the mappings are read-only proxies, which pickle refuses: a copy (a sweep's worker) reads the text again
        return (_cart_again, (self.text, str(self.path)))


def _cart_again(text: str, path: str) -> CartFile:
    return load_cart_text(text, path=path)


def cart_names() -> tuple[str, ...]:
    """The shipped carts' names (``NAME.toml`` in :data:`CARTS_DIR`), sorted."""
    return tuple(sorted(p.stem for p in CARTS_DIR.glob("*.toml")))


def cart_path(source: str | os.PathLike[str]) -> Path:
    """The file ``source`` names: a path to a file, or the name of a shipped cart ('c80').

    Raises:
        ParameterError: neither an existing file nor a shipped cart's name.
    """
    path = Path(source)
    if path.is_file():
        return path
    if isinstance(source, str) and source in cart_names():
        return CARTS_DIR / f"{source}.toml"
    raise ParameterError(f"cart {str(source)!r} is neither a file nor a shipped cart; accepted: a path to a .toml "
                         f"cart file or one of {', '.join(cart_names())}")


def _read_text(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ParameterError(f"cart file {str(path)!r} cannot be read: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise ParameterError(f"cart file {str(path)!r} is not UTF-8 text: {exc}") from None


def _parse(text: str, path: Path) -> dict[str, Any]:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"cart file {str(path)!r} is not valid TOML: {exc}") from None


def _check_rules(document: Mapping[str, Any]) -> None:
    """The rules the schema cannot say; raises ParameterError (without the file's name)."""
    l1, l3 = document["chassis"]["l1"]["value"], document["chassis"]["l3"]["value"]
    if not l3 < l1:
        raise ParameterError(f"chassis.l3.value = {l3!r} m is not accepted; accepted: a number below the wheelbase "
                             f"chassis.l1.value = {l1!r} m (the centre of mass lies between the axles)")
    k_i, k_b = document["motor"]["k_i"]["value"], document["motor"]["k_b"]["value"]
    if abs(k_b - k_i) > MOTOR_CONSTANT_RTOL * abs(k_i):
        raise ParameterError(f"motor.k_b.value = {k_b!r} V s/rad is not accepted; accepted: equal to motor.k_i.value = "
                             f"{k_i!r} N m/A (in SI units the back-EMF and torque constants are one flux; MuJoCo's "
                             "dcmotor has one constant and would use their geometric mean)")
    for box, ranges in document["uncertainty"].items():
        for name, entry in ranges.items():
            lo, hi = entry["range"]
            if not lo < hi:
                raise ParameterError(f"uncertainty.{box}.{name}.range = {entry['range']!r} {entry['unit']} is not "
                                     "accepted; accepted: [lo, hi] with lo < hi")
    R_a, L_a = document["motor"]["R_a"]["value"], document["motor"].get("L_a", {"value": 0.0})["value"]
    if not L_a / R_a <= MAX_ELECTRICAL_TIME_CONSTANT_S:
        raise ParameterError(f"motor.L_a.value = {L_a!r} H is not accepted; accepted: an electrical time constant "
                             f"L_a/R_a of at most {MAX_ELECTRICAL_TIME_CONSTANT_S:g} s (R_a = {R_a!r} Ohm: L_a <= "
                             f"{MAX_ELECTRICAL_TIME_CONSTANT_S * R_a:.4g} H), as --actuation inductance= accepts")
    m1, inertia_mass = document["chassis"]["m1"]["value"], document["chassis"]["chassis_inertia_mass"]["value"]
    if m1 < inertia_mass:
        raise ParameterError(f"chassis.m1.value = {m1!r} kg is not accepted; accepted: at least chassis."
                             f"chassis_inertia_mass.value = {inertia_mass!r} kg (m1 beyond the chassis' own mass is "
                             "its payload, which cannot be negative)")
    for box, ranges in document["uncertainty"].items():
        if "m1" in ranges and not ranges["m1"]["range"][0] <= m1 <= ranges["m1"]["range"][1]:
            raise ParameterError(f"chassis.m1.value = {m1!r} kg is not accepted; accepted: inside its own box "
                                 f"uncertainty.{box}.m1.range = {ranges['m1']['range']!r} kg")
    version, newest = document["version"], document["changelog"][0]
    if not newest.startswith(version):
        raise ParameterError(f"changelog[0] = {newest!r} is not accepted; accepted: the newest line first, beginning "
                             f"with the version {version!r}")


#: The optional parameters and the entry a file that omits one gets: the armature inductance, 0 H (the paper's motor).
OPTIONAL_PARAMETERS: Mapping[str, tuple[str, Mapping[str, Any]]] = {
    "L_a": ("motor", {"value": 0.0, "unit": "H",
                      "source": "not given in the file: 0 H, the current follows the voltage at once (the paper's "
                                "motor (2.9)-(2.10))"}),
}


def _with_optional(document: Mapping[str, Any]) -> dict[str, Any]:
    """``document`` with every optional parameter it omits at its default (:data:`OPTIONAL_PARAMETERS`)."""
    filled = {section: dict(entries) if isinstance(entries, Mapping) else entries
              for section, entries in document.items()}
    for name, (section, entry) in OPTIONAL_PARAMETERS.items():
        filled[section].setdefault(name, dict(entry))
    return filled


def _cart_of(document: Mapping[str, Any], path: Path, text: str) -> CartFile:
    document = _with_optional(document)
    sections = {s: tuple(document[s]) for s in PARAMETER_SECTIONS}
    entries = {name: document[s][name] for s, names in sections.items() for name in names}
    boxes = document["uncertainty"]
    return CartFile(
        name=document["name"], version=document["version"], changelog=tuple(document["changelog"]), path=path,
        parameters=_frozen({n: float(e["value"]) for n, e in entries.items()}),
        units=_frozen({n: e["unit"] for n, e in entries.items()}),
        sources=_frozen({n: e["source"] for n, e in entries.items()}),
        sections=_frozen(sections),
        uncertainty=_frozen({box: _frozen({n: (float(e["range"][0]), float(e["range"][1])) for n, e in r.items()})
                             for box, r in boxes.items()}),
        uncertainty_sources=_frozen({box: _frozen({n: e["source"] for n, e in r.items()}) for box, r in boxes.items()}),
        defaults=_frozen({k: (float(e["value"]) if "unit" in e else e["value"])
                          for k, e in document["defaults"].items()}),
        default_sources=_frozen({k: e["source"] for k, e in document["defaults"].items()}),
        text=text,
        default_path=None if "paths" not in document else _declared_path(document["paths"]["default"], path),
    )


def _declared_path(declared: str, path: Path) -> str:
    """The cart's declared default path: a route file (a name ending .toml/.json) as its path beside the cart file
    where it is there (else as written: a route file's own check then names it); any other name as written."""
    if declared.lower().endswith((".toml", ".json")) and not Path(declared).is_absolute():
        beside = path.parent / declared
        if beside.is_file():
            return str(beside)
    return declared


def load_cart(source: str | os.PathLike[str]) -> CartFile:
    """Read and check a cart file.

    Args:
        source: a path to a TOML cart file, or a shipped cart's name (:func:`cart_names`).

    Returns:
        The checked :class:`CartFile`.

    Raises:
        ParameterError: a missing or unreadable file, invalid TOML, or a violation of the schema or of the
            rules beside it: one line naming the file, the key, the value, its unit and what is accepted.
    """
    path = cart_path(source)
    return load_cart_text(_read_text(path), path=path)


def load_cart_text(text: str, *, path: str | os.PathLike[str] = "<text>") -> CartFile:
    """Read and check a cart file's text (as :func:`load_cart` reads a file; a run's record carries the text).

    Args:
        text: the TOML text of a cart file.
        path: where it was read from, for the messages and :attr:`CartFile.path`.

    Returns:
        The checked :class:`CartFile`.

    Raises:
        ParameterError: invalid TOML, or a violation of the schema or of the rules beside it (one line).
    """
    path = Path(path)
    document = _parse(text, path)
    try:
        check_against_schema(document, load_schema())
        _check_rules(document)
    except ParameterError as exc:
        raise ParameterError(f"cart file {str(path)!r}: {exc}") from None
    return _cart_of(document, path, text)


@functools.lru_cache(maxsize=8)
def cart_of_text(text: str, path: str) -> CartFile:
    """:func:`load_cart_text` of a run's cart record (its text and path), the last few kept: a typed config's cart
    is read back from its record each time it is coerced again."""
    return load_cart_text(text, path=path)


def cart_of(given: Any) -> CartFile | None:
    """The cart a run's config names (``RunConfig.cart``), read and checked: None for none; a :class:`CartFile` as
    it is; a cart record (the mapping a run's record holds: its ``text`` and ``path``) read back from its text; a
    shipped cart's name or a .toml file read (:func:`load_cart`).

    Raises:
        ParameterError: a missing file, an unknown name, a file its schema or rules refuse, another type (one line).
    """
    if given is None or isinstance(given, CartFile):
        return given
    if isinstance(given, Mapping):
        if not isinstance(given.get("text"), str):
            raise ParameterError(f"cart = {dict(given)!r} is not accepted: a cart record holds the file's 'text'")
        return cart_of_text(given["text"], str(given.get("path", "<text>")))
    if isinstance(given, (str, os.PathLike)):
        return load_cart(given)
    raise ParameterError(f"cart = {given!r} is not accepted: a shipped cart's name, a .toml cart file or a "
                         "wmr_mj.carts.CartFile")
