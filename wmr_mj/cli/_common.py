"""Argument helpers shared by the subcommands."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

#: Exit status of ``run``, ``sweep``, ``compare`` and ``falsify`` when a run breaks its law's claim (a
#: ``certified-outside`` run), and of ``falsify`` when it falsifies its ``--require``: a CI job can gate on
#: it. Distinct from bad input's 2 and from a failed or irreproducible run's 1 (docs/reference/commands.md).
CLAIM_BROKEN_EXIT = 3


def add_controller_source(out: dict[str, Any], config: Any) -> dict[str, Any]:
    """``out`` with ``controller_source``: where the run's law comes from, as its MCAP log records it
    (:class:`controllers.registry.PluginSource`: spec, name, origin, import path of the file or module and
    class, parameters, the SHA-256 of its source), for every law but those built from the config's fields
    (computed-torque, pd), whose JSON keeps the keys it always had. The JSON of run, sweep and falsify."""
    from wmr_mj.sim.config import controller_source

    source = controller_source(config)
    if source is not None:
        out["controller_source"] = source
    return out


def positive_float(text: str) -> float:
    """argparse type: a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number; a finite number > 0 is accepted") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not accepted; a finite number > 0 is required")
    return value


def int_at_least(minimum: int):
    """argparse type factory: an integer >= minimum."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not an integer; an integer >= {minimum} is accepted") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"{text!r} is not accepted; an integer >= {minimum} is required")
        return value

    parse.__name__ = f"integer >= {minimum}"
    return parse


positive_int = int_at_least(1)


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


def parse_range(item: str) -> tuple[str, tuple[float, float]]:
    """``NAME=LO:HI`` (``--range mu=0.015:0.02``) into (name, (lo, hi)); bad syntax raises ParameterError."""
    from wmr_mj.errors import ParameterError

    name, sep, span = item.partition("=")
    lo_s, sep2, hi_s = span.partition(":")
    name = name.strip()
    if not sep or not sep2 or not name or not lo_s.strip() or not hi_s.strip():
        raise ParameterError(f"--range {item!r} is not NAME=LO:HI (e.g. --range mu=0.015:0.02)")
    try:
        lo, hi = float(lo_s), float(hi_s)
    except ValueError:
        raise ParameterError(f"--range {item!r}: LO and HI must be numbers") from None
    return name, (lo, hi)


def box_ranges_from_args(args: argparse.Namespace) -> dict[str, tuple[float, float]]:
    """The ranged plant parameters besides m1 (whose range is --m1-range): those of the
    --uncertainty box (``wmr_mj.params.uncertainty_ranges``; 'm1' when not given), then each
    --range NAME=LO:HI, which adds a parameter or replaces its range. The cart's axes
    (sensing.*, actuation.*, transmission.*: :func:`hardware_ranges_from_args`) are drawn or
    searched, never part of the certificate's plant box: they are left out here."""
    from wmr_mj.errors import ParameterError
    from wmr_mj.params import uncertainty_ranges
    from wmr_mj.sim.search_space import hardware_axis

    ranges = {k: v for k, v in uncertainty_ranges(getattr(args, "uncertainty", None) or "m1").items() if k != "m1"}
    for item in getattr(args, "range", None) or []:
        name, span = parse_range(item)
        if hardware_axis(name):
            continue
        if name == "m1":
            raise ParameterError("give m1's range with --m1-range LO HI, not --range m1=...")
        ranges[name] = span
    return ranges


def hardware_ranges_from_args(args: argparse.Namespace) -> dict[str, tuple[float, float]]:
    """The cart's axes among the --range NAME=LO:HI items (``sensing.delay``, ``sensing.encoder_ticks``, ...:
    :data:`wmr_mj.sim.search_space.HARDWARE_AXES`), in the order given; each is checked where the sweep
    or the search is built."""
    from wmr_mj.sim.search_space import hardware_axis

    spans = (parse_range(item) for item in getattr(args, "range", None) or [])
    return {name: span for name, span in spans if hardware_axis(name)}
