"""The cart file's checks, driven by its JSON Schema (``cart.schema.json``): one line per violation.

The schema is the one statement of the file's keys, units and accepted ranges; this module walks it over a
parsed file with the Python standard library only. jsonschema, a test dependency, validates the same files
with the same schema in the tests (a second method); it is not a dependency of the package, and one line
naming the key, its value, its unit and what is accepted is more than its messages say.

Only the keywords in :data:`SUPPORTED_KEYWORDS` may appear in the schema (a test checks it), so the schema
cannot say something these checks would skip.

Usage::

    from wmr_mj.carts.schema import load_schema, check_against_schema

    check_against_schema(document, load_schema())   # raises ParameterError('chassis.l1.value = 0.0 m ...')
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from functools import cache
from pathlib import Path
from typing import Any

from wmr_mj.errors import ParameterError

__all__ = ["SCHEMA_PATH", "SUPPORTED_KEYWORDS", "load_schema", "check_against_schema", "resolve_ref", "schema_table"]

#: The cart file's JSON Schema (draft 2020-12), shipped beside the carts.
SCHEMA_PATH = Path(__file__).resolve().parent / "cart.schema.json"

#: The JSON Schema keywords these checks enforce (annotations included); no other may appear in the schema.
SUPPORTED_KEYWORDS = frozenset({
    "$schema", "$id", "$defs", "$ref", "title", "description",  # identification, references and annotations
    "type", "properties", "required", "additionalProperties",  # objects
    "items", "minItems", "maxItems",  # arrays
    "const", "enum", "minLength", "pattern",  # strings and constants
    "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum",  # numbers
})

_TYPE_WORDS = {"object": "a table", "array": "an array", "string": "a string", "number": "a number"}


@cache
def load_schema() -> Mapping[str, Any]:
    """The cart file's schema, read once from :data:`SCHEMA_PATH`."""
    return json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))


def resolve_ref(schema: Mapping[str, Any], root: Mapping[str, Any]) -> dict[str, Any]:
    """``schema`` with its local ``$ref`` ('#/$defs/NAME') replaced by the definition; the referring schema's
    own keywords (a description) win over the definition's."""
    if "$ref" not in schema:
        return dict(schema)
    ref = schema["$ref"]
    prefix = "#/$defs/"
    if not ref.startswith(prefix) or ref[len(prefix):] not in root.get("$defs", {}):
        raise ParameterError(f"cart schema: $ref {ref!r} is not a local definition ('#/$defs/NAME')")
    base = resolve_ref(root["$defs"][ref[len(prefix):]], root)
    return {**base, **{k: v for k, v in schema.items() if k != "$ref"}}


def _number_text(x: float) -> str:
    return "pi/2" if x == math.pi / 2 else f"{x:g}"


def _accepted_number(schema: Mapping[str, Any], unit: str) -> str:
    """'a number > 0 and < pi/2 rad' from the schema's bounds."""
    bounds = [f"{op} {_number_text(schema[key])}" for key, op in
              (("exclusiveMinimum", ">"), ("minimum", ">="), ("exclusiveMaximum", "<"), ("maximum", "<="))
              if key in schema]
    return "a number" + (" " + " and ".join(bounds) if bounds else "") + (f" {unit}" if unit and unit != "-" else "")


def _where(path: tuple[str | int, ...]) -> str:
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "the file"


def _section(path: tuple[str | int, ...]) -> str:
    return f"[{_where(path)}]" if path else "the file's top level"


def _check_type(value: Any, schema: Mapping[str, Any], path: tuple[str | int, ...], unit: str) -> None:
    kind = schema.get("type")
    if kind is not None and kind not in _TYPE_WORDS:
        raise ParameterError(f"cart schema: type {kind!r} at {_where(path)} is not supported; supported: "
                             + ", ".join(_TYPE_WORDS))
    ok = {
        None: True,
        "object": isinstance(value, dict),
        "array": isinstance(value, list),
        "string": isinstance(value, str),
        "number": isinstance(value, (int, float)) and not isinstance(value, bool),
    }[kind]
    if ok:
        return
    accepted = _accepted_number(schema, unit) if kind == "number" else _TYPE_WORDS[str(kind)]
    if kind == "object" and "required" in schema:
        accepted += " with the keys " + ", ".join(schema["required"])
    raise ParameterError(f"{_where(path)} = {value!r} is not accepted; accepted: {accepted}")


def _check_object(value: dict, schema: Mapping[str, Any], root: Mapping[str, Any],
                  path: tuple[str | int, ...]) -> None:
    properties = schema.get("properties", {})
    for key in schema.get("required", ()):
        if key not in value:
            sub = resolve_ref(properties.get(key, {}), root)
            what = f" ({sub['description']})" if "description" in sub else ""
            raise ParameterError(f"{_where((*path, key))} is missing{what}; required in {_section(path)}: "
                                 + ", ".join(schema["required"]))
    if schema.get("additionalProperties", True) is False:
        for key in value:
            if key not in properties:
                raise ParameterError(f"{_where((*path, key))} = {value[key]!r} is not a known key; accepted in "
                                     f"{_section(path)}: " + ", ".join(properties))
    unit_schema = properties.get("unit", {})
    unit = unit_schema.get("const", "") if isinstance(unit_schema, Mapping) else ""
    # the unit first: a value written in degrees is refused for its unit, not shown as radians
    for key in sorted(value, key=lambda k: k != "unit"):
        if key in properties:
            check_against_schema(value[key], properties[key], root=root, path=(*path, key), unit=unit)


def _check_array(value: list, schema: Mapping[str, Any], root: Mapping[str, Any],
                 path: tuple[str | int, ...], unit: str) -> None:
    lo, hi = schema.get("minItems", 0), schema.get("maxItems", math.inf)
    if not lo <= len(value) <= hi:
        count = f"{lo}" if lo == hi else f"at least {lo}" + ("" if hi == math.inf else f" and at most {hi}")
        raise ParameterError(f"{_where(path)} = {value!r} has {len(value)} items; accepted: {count} items")
    if "items" in schema:
        for i, item in enumerate(value):
            check_against_schema(item, schema["items"], root=root, path=(*path, i), unit=unit)


def _check_scalar(value: Any, schema: Mapping[str, Any], path: tuple[str | int, ...], unit: str) -> None:
    where = _where(path)
    if "const" in schema and value != schema["const"]:
        why = " (every value is in SI units)" if path and path[-1] == "unit" else ""
        raise ParameterError(f"{where} = {value!r} is not accepted; accepted: {schema['const']!r} only{why}")
    if "enum" in schema and value not in schema["enum"]:
        raise ParameterError(f"{where} = {value!r} is not accepted; accepted: "
                             + " or ".join(repr(v) for v in schema["enum"]))
    if isinstance(value, str):
        if len(value) < schema.get("minLength", 0):
            raise ParameterError(f"{where} = {value!r} is empty; accepted: a non-empty string")
        if "pattern" in schema and re.search(schema["pattern"], value) is None:
            what = schema.get("description", f"a string matching {schema['pattern']}")
            raise ParameterError(f"{where} = {value!r} is not accepted; accepted: {what}")
    elif isinstance(value, (int, float)):
        bad = (not math.isfinite(value)
               or ("exclusiveMinimum" in schema and not value > schema["exclusiveMinimum"])
               or ("minimum" in schema and not value >= schema["minimum"])
               or ("exclusiveMaximum" in schema and not value < schema["exclusiveMaximum"])
               or ("maximum" in schema and not value <= schema["maximum"]))
        if bad:
            shown = f"{value!r} {unit}" if unit and unit != "-" else repr(value)
            raise ParameterError(f"{where} = {shown} is not accepted; accepted: {_accepted_number(schema, unit)}")


def check_against_schema(value: Any, schema: Mapping[str, Any], *, root: Mapping[str, Any] | None = None,
                         path: tuple[str | int, ...] = (), unit: str = "") -> None:
    """Check ``value`` (a parsed TOML document, or a part of it at ``path``) against ``schema``.

    Args:
        value: the parsed file (tomllib's dicts, lists, strings, numbers) or a part of it.
        schema: the schema, or the part of it that applies at ``path``.
        root: the whole schema, for ``$ref`` (default: ``schema``).
        path: the keys leading to ``value``, for the message.
        unit: the unit of a number at ``path`` (the ``unit`` const beside it), for the message.

    Raises:
        ParameterError: the first violation, in one line naming the key, the value, its unit and what is
            accepted. Keys are checked in the file's order (a table's unit before its value); a missing key
            before an unknown one.
    """
    root = schema if root is None else root
    schema = resolve_ref(schema, root)
    _check_type(value, schema, path, unit)
    if isinstance(value, dict):
        _check_object(value, schema, root, path)
    elif isinstance(value, list):
        _check_array(value, schema, root, path, unit)
    else:
        _check_scalar(value, schema, path, unit)


def _accepted_value(value_schema: Mapping[str, Any]) -> str:
    if value_schema.get("type") == "number":
        return _accepted_number(value_schema, "")
    if "enum" in value_schema:
        return " or ".join(f"`{v!r}`" for v in value_schema["enum"])
    return "a non-empty string" if value_schema.get("minLength") else "a string"


def schema_table(schema: Mapping[str, Any] | None = None) -> str:
    """The cart file's keys as a Markdown table (key, unit, accepted, what), rendered from the schema: the
    documentation's table (``docs/reference/cart.md``), kept equal to a fresh rendering by a test."""
    root = load_schema() if schema is None else schema
    rows = ["| key | unit | accepted | what |", "|---|---|---|---|"]
    for key in ("name", "version", "changelog"):
        entry = root["properties"][key]
        accepted = f"a string matching `{entry['pattern']}`" if "pattern" in entry else (
            "an array of strings, at least one" if entry["type"] == "array" else "a non-empty string")
        rows.append(f"| `{key}` | | {accepted} | {entry['description']} |")
    for section, section_schema in root["properties"].items():
        if section in ("name", "version", "changelog"):
            continue
        if section == "paths":  # optional: a table of strings, not of entries
            rows.append(f"| `paths.default` | | a non-empty string (and its `paths.source`); optional | "
                        f"{section_schema['description']} |")
            continue
        for name, sub in section_schema["properties"].items():
            entry = resolve_ref(sub, root)
            props = entry.get("properties", {})
            unit = props.get("unit", {}).get("const", "")
            if "value" in props:
                accepted = _accepted_value(props["value"])
            else:  # an uncertainty box: parameter -> range
                required = ", ".join(entry.get("required", ()))
                accepted = (f"a table of `NAME = {{range = [lo, hi], unit, source}}`, lo < hi, each bound accepted as "
                            f"NAME's value; requires {required}")
            rows.append(f"| `{section}.{name}` | {unit} | {accepted} | {entry.get('description', '')} |")
    return "\n".join(rows) + "\n"
