"""Argument helpers shared by the subcommands (the shared options and --range: :mod:`wmr_mj.cli.options`, whose
argparse types and range readers are also importable from here)."""

from __future__ import annotations

import json
import sys
from typing import Any

from wmr_mj.cli.options import (  # noqa: F401  (importable from here, as before)
    box_ranges_from_args,
    hardware_ranges_from_args,
    int_at_least,
    parse_range,
    positive_float,
    positive_int,
)

#: Exit status of ``run``, ``sweep``, ``compare`` and ``falsify`` when a run breaks its law's claim (a
#: ``certified-outside`` run), and of ``falsify`` when it falsifies its ``--require``: a CI job can gate on
#: it. Distinct from bad input's 2 and from a failed or irreproducible run's 1 (docs/reference/commands.md).
CLAIM_BROKEN_EXIT = 3


def parse_assignments(items: list[str] | None, *, option: str = "--param",
                      example: str = "mu=0.02") -> dict[str, Any]:
    """``NAME=VALUE`` pairs (``--param l3=0.15``) into a dict; bad syntax raises ParameterError."""
    from wmr_mj.errors import ParameterError

    out: dict[str, float] = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise ParameterError(f"{option} {item!r} is not NAME=VALUE (e.g. {option} {example})")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise ParameterError(f"{option} {item!r}: {value!r} is not a number") from None
    return out


def print_json(obj: Any) -> None:
    """One JSON object on stdout; non-finite numbers become null."""
    from wmr_mj._util.files import json_safe

    json.dump(json_safe(obj), sys.stdout, indent=2, sort_keys=True, allow_nan=False, default=float)
    sys.stdout.write("\n")
