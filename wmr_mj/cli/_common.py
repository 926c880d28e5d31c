"""Helpers shared by the commands, light enough for their parsers (:mod:`wmr_mj.cli.parsers`): the exit status of
a broken claim, ``NAME=VALUE`` options, ``--param m1=``, the parameter set of ``--cart``, one JSON object on stdout,
a default output folder (the
shared options: :mod:`wmr_mj.cli.options`, whose argparse types are also importable from here; --range:
:mod:`wmr_mj.cli.ranges`)."""

from __future__ import annotations

import json
import math
import sys
import time
from typing import Any

from wmr_mj._util.files import json_safe
from wmr_mj.carts import load_cart
from wmr_mj.cli.options import (  # noqa: F401  (importable from here, as before)
    int_at_least,
    positive_float,
    positive_int,
)
from wmr_mj.errors import ParameterError
from wmr_mj.params import C80, M1_NOMINAL, C80Parameters, parameters_of_cart

#: Exit status of ``run``, ``sweep``, ``compare`` and ``falsify`` when a run breaks its law's claim (a
#: ``certified-outside`` run), and of ``falsify`` when it falsifies its ``--require``: a CI job can gate on
#: it. Distinct from bad input's 2 and from a failed or irreproducible run's 1 (docs/reference/commands.md).
CLAIM_BROKEN_EXIT = 3


def parse_assignments(items: list[str] | None, *, option: str = "--param",
                      example: str = "mu=0.02") -> dict[str, Any]:
    """``NAME=VALUE`` pairs (``--param l3=0.15``) into a dict; bad syntax raises ParameterError."""
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


def m1_of_param(args: Any) -> Any:
    """``args`` with ``--param m1=KG`` taken as ``--m1 KG`` (the one mass of the run; ``with_params`` takes m1 once),
    for every command that has both options; ``--m1`` and ``--param m1=`` given with different masses is refused.

    Raises:
        ParameterError: two different masses, or a malformed --param (one line).
    """
    items = getattr(args, "param", None)
    if not items or not hasattr(args, "m1"):
        return args
    masses = [item for item in items if item.partition("=")[0].strip() == "m1"]
    if not masses:
        return args
    values = {parse_assignments([item])["m1"] for item in masses}
    given = args.m1 if args.m1 is not None and args.m1 is not M1_NOMINAL else None  # --m1 as given (its default: not)
    if given is not None:
        values.add(float(given))
    if len(values) > 1:
        shown = " and ".join(f"{v:g} kg" for v in sorted(values))
        raise ParameterError(f"--m1 and --param m1= give two masses ({shown}); give one of them")
    (mass,) = values
    if not (math.isfinite(mass) and mass > 0):
        raise ParameterError(f"--param m1={mass!r} is not accepted; a finite mass > 0 kg is required")
    args.m1 = mass
    args.param = [item for item in items if item not in masses]
    return args


def print_json(obj: Any) -> None:
    """One JSON object on stdout; non-finite numbers become null."""
    json.dump(json_safe(obj), sys.stdout, indent=2, sort_keys=True, allow_nan=False, default=float)
    sys.stdout.write("\n")


def default_folder(prefix: str) -> str:
    """``logs/<prefix>-<local time>``: a command's output folder where --out is not given."""
    return f"logs/{prefix}-{time.strftime('%Y%m%d-%H%M%S')}"


def cart_parameters(args: Any) -> C80Parameters:
    """The parameter set of ``--cart`` (:class:`wmr_mj.params.C80Parameters`; the C80 where not given).

    Raises:
        ParameterError: a missing file, an unknown name, a file its schema or rules refuse (one line).
    """
    if getattr(args, "cart", None) is None:
        return C80
    return parameters_of_cart(load_cart(args.cart))
