"""One parser for the hardware parts' specifications: a ``KEY=VALUE,KEY=VALUE`` string, a mapping, a
``.json`` or ``.toml`` file, or a preset name, into a frozen dataclass of the caller's choosing.

Usage::

    from wmr_mj.hardware.spec import parse_spec, field_converters

    keys = field_converters(Actuation)                 # one converter per dataclass field, from its type
    a = parse_spec("delay=0.002,inductance=0.001", Actuation, what="actuation", keys=keys)
    a = parse_spec({"delay": 0.002}, Actuation, what="actuation", keys=keys)
    a = parse_spec("actuation.toml", Actuation, what="actuation", keys=keys)

A converter takes ``(what, key, value)`` and returns the dataclass fields it sets (a key may set several:
``noise=uniform:0.0005`` sets ``noise_kind`` and ``noise``). The dataclass's ``__post_init__`` checks
ranges, so a part built directly is checked the same way. The key ``preset`` (where presets exist) names
the part the other keys change, a preset or a file: ``preset=magnetic-12bit-axis,delay=0.005``,
``preset=my-encoder.toml,delay=0.003`` (a file's own ``preset`` names a preset, not another file).

Every bad input raises one line naming the culprit and what is accepted: :class:`UnknownNameError` for an
unknown key or preset, :class:`ParameterError` for a value that is not of its key's type, a key given twice,
two keys that set the same field (``encoder_bits`` and ``encoder_ticks``), an unreadable file, or a file that
sets no key (an empty file is refused, never read as the ideal part).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import tomllib
import types
import typing
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, Literal, TypeVar, Union, get_args, get_origin

import numpy as np

from wmr_mj.errors import ParameterError, UnknownNameError

__all__ = [
    "Converter",
    "SpecSource",
    "parse_spec",
    "field_converters",
    "to_float",
    "to_int",
    "to_optional_int",
    "to_optional_float",
    "to_choice",
    "whole_periods",
    "whole_period_count",
    "spec_string",
]

T = TypeVar("T")
#: (what, key, value) -> the dataclass fields this key sets.
Converter = Callable[[str, str, object], dict[str, object]]
#: What a part's ``from_spec`` takes: a string (KEY=VALUE list, preset name or file name), a mapping, a path.
SpecSource = str | Mapping[str, Any] | os.PathLike[str] | None

_NONE_WORDS = ("none", "null", "")
_FILE_SUFFIXES = (".json", ".toml")


def to_float(what: str, key: str, value: object) -> float:
    """A finite real number from a number or a string (bool refused); range checks are the part's."""
    if isinstance(value, bool):
        raise ParameterError(f"{what}: {key} = {value!r} is not a number; a finite real number is accepted")
    try:
        x = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParameterError(f"{what}: {key} = {value!r} is not a number; a finite real number is accepted") from None
    if not math.isfinite(x):
        raise ParameterError(f"{what}: {key} = {value!r} is not finite; a finite real number is accepted")
    return x


def to_int(what: str, key: str, value: object) -> int:
    """An integer from an int, an integral float (TOML and JSON writers) or a string of digits."""
    if isinstance(value, bool):
        raise ParameterError(f"{what}: {key} = {value!r} is not an integer; an integer is accepted")
    if isinstance(value, int):
        return value
    if isinstance(value, float) and math.isfinite(value) and value == int(value):
        return int(value)
    if isinstance(value, str):
        try:
            return int(value.strip())
        except ValueError:
            pass
    raise ParameterError(f"{what}: {key} = {value!r} is not an integer; an integer is accepted")


def to_optional_int(what: str, key: str, value: object) -> int | None:
    """:func:`to_int`, or None for None, 'none' or 'null'."""
    if value is None or (isinstance(value, str) and value.strip().lower() in _NONE_WORDS):
        return None
    try:
        return to_int(what, key, value)
    except ParameterError:
        raise ParameterError(f"{what}: {key} = {value!r} is not an integer; an integer or 'none' is accepted") from None


def to_optional_float(what: str, key: str, value: object) -> float | None:
    """:func:`to_float`, or None for None, 'none' or 'null'."""
    if value is None or (isinstance(value, str) and value.strip().lower() in _NONE_WORDS):
        return None
    try:
        return to_float(what, key, value)
    except ParameterError:
        raise ParameterError(f"{what}: {key} = {value!r} is not a number; a finite real number or 'none' "
                             "is accepted") from None


def to_choice(what: str, key: str, value: object, choices: tuple[str, ...]) -> str:
    """One of ``choices`` (a string); anything else raises UnknownNameError listing them."""
    if not isinstance(value, str) or value.strip() not in choices:
        raise UnknownNameError(f"{what} {key} value", str(value), choices)
    return value.strip()


def _converter_for(hint: Any) -> Callable[[str, str, object], object]:
    """The converter of one field type: float, int, int | None, float | None, str, Literal[...]."""
    if get_origin(hint) is Literal:
        choices = tuple(str(c) for c in get_args(hint))
        return lambda what, key, value: to_choice(what, key, value, choices)
    if get_origin(hint) in (Union, types.UnionType):
        args = set(get_args(hint))
        if args == {int, type(None)}:
            return to_optional_int
        if args == {float, type(None)}:
            return to_optional_float
    if hint is float:
        return to_float
    if hint is int:
        return to_int
    if hint is str:
        return lambda what, key, value: str(value)
    raise TypeError(f"no spec converter for a field of type {hint!r}")


def field_converters(cls: type, *, exclude: tuple[str, ...] = ()) -> dict[str, Converter]:
    """One converter per init field of the dataclass ``cls`` (but ``exclude``), from its type annotation.

    Args:
        cls: a dataclass whose fields are typed float, int, str, ``int | None``, ``float | None`` or a Literal.
        exclude: fields set through other keys (e.g. ``noise_kind``, set by ``noise``).

    Returns:
        key -> converter returning ``{key: converted value}``.
    """
    hints = typing.get_type_hints(cls)
    out: dict[str, Converter] = {}
    for f in dataclasses.fields(cls):
        if not f.init or f.name in exclude:
            continue
        convert = _converter_for(hints[f.name])
        out[f.name] = (lambda c, name: lambda what, key, value: {name: c(what, key, value)})(convert, f.name)
    return out


def _split_pairs(text: str, what: str, accepted: list[str]) -> dict[str, str]:
    out: dict[str, str] = {}
    for item in text.split(","):
        item = item.strip()
        if "=" not in item:
            raise ParameterError(f"{what}: {item!r} is not KEY=VALUE; the form is KEY=VALUE,KEY=VALUE with "
                                 f"keys {', '.join(accepted)}")
        key, _, value = item.partition("=")
        key = key.strip()
        if key in out:
            raise ParameterError(f"{what}: key {key!r} is given twice")
        out[key] = value.strip()
    return out


def _read_file(path: Path, what: str) -> Mapping[str, Any]:
    if path.suffix.lower() not in _FILE_SUFFIXES:
        raise ParameterError(f"{what}: file {str(path)!r} is neither .json nor .toml")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ParameterError(f"{what}: cannot read {str(path)!r} ({exc.strerror or exc})") from None
    try:
        text = raw.decode("utf-8")
        data = json.loads(text) if path.suffix.lower() == ".json" else tomllib.loads(text)
    except (UnicodeDecodeError, json.JSONDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ParameterError(f"{what}: {str(path)!r} is not valid {path.suffix.lower()[1:].upper()} ({exc})") from None
    if not isinstance(data, dict):
        raise ParameterError(f"{what}: {str(path)!r} holds a {type(data).__name__}; a table of KEY = VALUE is "
                             "accepted")
    return data


def _read_spec_file(path: Path, what: str, accepted: list[str]) -> Mapping[str, Any]:
    """A file's table, refused where it sets no key: an empty file is a mistake, not the ideal part."""
    data = _read_file(path, what)
    if not data:
        raise ParameterError(f"{what}: {str(path)!r} sets no key; a file sets at least one of {', '.join(accepted)}")
    return data


def _is_file_name(value: object) -> bool:
    return isinstance(value, os.PathLike) or (isinstance(value, str) and value.strip().lower().endswith(_FILE_SUFFIXES))


def _as_mapping(spec: str | Mapping[str, Any] | os.PathLike[str], what: str, accepted: list[str],
                presets: Mapping[str, Any]) -> Mapping[str, Any]:
    """The spec as a mapping of keys to raw values; a preset name becomes ``{'preset': name}``."""
    if isinstance(spec, Mapping):
        return spec
    if isinstance(spec, os.PathLike):
        return _read_spec_file(Path(spec), what, accepted)
    if not isinstance(spec, str):
        raise ParameterError(f"{what}: {spec!r} is not a specification; a KEY=VALUE,... string, a mapping, a "
                             ".json/.toml file or a preset name is accepted")
    text = spec.strip()
    if "=" in text:
        return _split_pairs(text, what, accepted)
    if text.lower().endswith(_FILE_SUFFIXES):
        return _read_spec_file(Path(text), what, accepted)
    if text in presets:
        return {"preset": text}
    forms = ["<KEY=VALUE,...>", "<file .json/.toml>"]
    raise UnknownNameError(f"{what} preset", text, [*presets, *forms] if presets else forms)


def parse_spec(spec: SpecSource, cls: type[T], *, what: str, keys: Mapping[str, Converter],
               presets: Mapping[str, T] | None = None) -> T:
    """Build ``cls`` from a specification.

    Args:
        spec: None (the dataclass's defaults); a preset name; ``"KEY=VALUE,KEY=VALUE"``; a mapping (values
            typed or strings); a path or a file name ending in ``.json`` or ``.toml`` holding one table that
            sets at least one key.
        cls: the frozen dataclass to build; its ``__post_init__`` checks the ranges.
        what: the part's name in messages ('sensing', 'actuation').
        keys: accepted key -> converter (:func:`field_converters`, plus keys that set several fields).
        presets: name -> instance; the key ``preset`` picks the base that the other keys change: one of these,
            or (outside a file) a ``.json``/``.toml`` file.

    Returns:
        The instance.

    Raises:
        UnknownNameError: an unknown key, preset or choice (the message lists the accepted ones).
        ParameterError: a malformed string, a value of the wrong type, a field set twice (by one key given
            twice or by two keys), an unreadable file or one that sets no key, or a range the part refuses.
    """
    presets = presets or {}
    accepted = [*keys, *(["preset"] if presets else [])]
    if spec is None:
        return cls()
    raw = _as_mapping(spec, what, accepted, presets)
    base: T = cls()
    fields: dict[str, object] = {}
    set_by: dict[str, str] = {}  # field -> the key that set it
    for key, value in raw.items():
        if key == "preset" and presets:
            base = _preset_base(value, cls, what=what, keys=keys, presets=presets, in_file=_is_file_name(spec))
            continue
        if key not in keys:
            error = UnknownNameError(f"{what} key", str(key), accepted)
            if _is_file_name(spec):  # name the file too: its keys are not on the command line
                error.args = (f"{error.args[0]} (in {str(spec)!r})",)
            raise error
        for name, converted in keys[key](what, key, value).items():
            if name in fields:
                raise ParameterError(f"{what}: {set_by[name]!r} and {key!r} both set {name}; give one of them")
            fields[name], set_by[name] = converted, key
    return dataclasses.replace(base, **fields)  # type: ignore[type-var]


def _preset_base(value: object, cls: type[T], *, what: str, keys: Mapping[str, Converter],
                 presets: Mapping[str, T], in_file: bool) -> T:
    """The part that ``preset=VALUE`` names: a preset, or a .json/.toml file (which the other keys then
    change, as they change a preset). A file's own ``preset`` names a preset, not another file (no chain)."""
    if _is_file_name(value) and not in_file:
        return parse_spec(value if isinstance(value, os.PathLike) else str(value).strip(), cls, what=what,
                          keys=keys, presets=presets)
    if _is_file_name(value):
        raise ParameterError(f"{what}: a file's preset = {str(value)!r} names another file; a file's preset names "
                             f"one of the presets {', '.join(presets)}")
    name = value if isinstance(value, str) else repr(value)
    if name not in presets:
        raise UnknownNameError(f"{what} preset", name, presets)
    return presets[name]


def spec_string(spec: Mapping[str, object]) -> str:
    """A mapping of spec keys back as ``KEY=VALUE,...`` (None as 'none'), the inverse of the string form."""
    return ",".join(f"{k}={'none' if v is None else v}" for k, v in spec.items())


def whole_periods(what: str, duration: float, period: float, *, periods: str = "periods", why: str = "") -> int:
    """``duration`` as a whole number of ``period`` (both s), within 1e-9 relative; else ParameterError.

    The one check that a duration (a sensing or actuation delay) is a whole number of periods (control periods,
    physics steps); :func:`whole_period_count` checks a count already in periods.

    Args:
        what: the duration's name in the message ('sensing delay').
        duration: s, >= 0.
        period: s, > 0.
        periods: what the periods are called in the message ('physics steps').
        why: a reason the message gives after the period (' (MuJoCo reads ...)').

    Returns:
        n >= 0 with |duration - n period| <= 1e-9 max(duration, period).

    Raises:
        ParameterError: a period that is not finite and > 0, or a duration that is not a whole multiple.
    """
    if isinstance(period, bool) or not isinstance(period, (int, float)) or not (math.isfinite(period) and period > 0):
        raise ParameterError(f"{what}: the period {period!r} s is not accepted; a finite period > 0 s is required")
    n = round(duration / period)
    below, above = math.floor(duration / period) * period, math.ceil(duration / period) * period
    # 1e-9 relative: a delay typed in decimal (0.005) is rarely an exact double multiple of 0.001
    if abs(duration - n * period) > 1e-9 * max(abs(duration), period):
        raise ParameterError(f"{what} = {duration!r} s is not a whole number of {periods} of {period!r} s{why} "
                             f"({duration / period:.6g} {periods}); accepted: a multiple such as "
                             f"{below:g} s or {above:g} s")
    return int(n)


def whole_period_count(what: str, value: object) -> int:
    """``value``, a count of control periods, as an int >= 0 (a NumPy integer accepted, bool refused).

    Raises:
        ParameterError: anything else (the message names ``what``).
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ParameterError(f"{what} = {value!r} is not accepted; a whole number of control periods >= 0 "
                             "is required")
    return int(value)
