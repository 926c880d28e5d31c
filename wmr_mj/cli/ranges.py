"""The one reader of ``--range``, and the boxes and the cart that a command's options give: what a command reads
from its parsed options when it runs (the parser's options themselves: :mod:`wmr_mj.cli.options`).

* :func:`parse_ranges`: ``--range NAME=LO:HI`` as every command reads it (:data:`RANGE_RULE`);
  :func:`command_ranges`: a command's, with the kinds it varies (:data:`RANGE_ACCEPTS`).
* :func:`box_ranges_from_args`, :func:`hardware_ranges_from_args`: the certificate's plant box and the cart's
  searched or drawn axes (the parameter set of ``--cart``: :func:`wmr_mj.cli._common.cart_parameters`).

Usage::

    from wmr_mj.cli.ranges import parse_ranges
    ranges = parse_ranges(args.range, command="sweep", accepts=("plant", "cart"))
    ranges.plant, ranges.cart
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Collection, Iterable
from dataclasses import dataclass, field

from wmr_mj.carts import load_cart
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.params import parameter_names, uncertainty_ranges
from wmr_mj.searches.search_space import hardware_axis, path_axis, signal_axis

__all__ = ["parse_range", "RANGE_RULE", "RANGE_KINDS", "RANGE_ACCEPTS", "Ranges", "parse_ranges", "command_ranges",
           "range_kind", "box_ranges_from_args", "hardware_ranges_from_args"]


def parse_range(item: str) -> tuple[str, tuple[float, float]]:
    """``NAME=LO:HI`` (``--range mu=0.015:0.02``) into (name, (lo, hi)); bad syntax raises ParameterError."""
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


#: What a --range name may be, by kind: what each kind is, for the line that refuses it.
RANGE_KINDS = {
    "plant": "plant parameters (wmr_mj.params; m1's range is --m1-range)",
    "cart": "the cart's axes (sensing.*, actuation.*, transmission.*)",
    "signal": "the signals' parameters (d_max, disturbance.*, load<i>.*)",
    "path": "the path's knots (path.k<i>, path.hold)",
}


#: The one rule of ``--range`` (sweep, falsify, run, robustness, robustness --certificate; compare's box is its
#: suite's): ``NAME=LO:HI``, repeatable, each NAME once, LO and HI finite numbers. NAME is a plant parameter
#: (``wmr_mj.params.parameter_names()``: LO < HI; it adds the parameter to the --uncertainty box or replaces its
#: range there), a cart axis, a signal's parameter or a path knot (their values are checked where the draw or
#: the search is built). m1 is never a --range: its range is --m1-range LO HI, the one place every command
#: reads it. A command refuses, in one line, a kind it does not vary.
#: The kinds of --range each command varies: a run's and the certificate's box is the plant's; sweep draws the
#: cart's axes too; falsify searches every kind.
RANGE_ACCEPTS = {"run": ("plant",), "robustness": ("plant",), "sweep": ("plant", "cart"),
                 "falsify": ("plant", "cart", "signal", "path")}


RANGE_RULE = ("--range NAME=LO:HI: NAME a plant parameter (LO < HI; m1's range is --m1-range), a cart axis "
              "(sensing.*, actuation.*, transmission.*), a signal's parameter or a path knot, each once")


@dataclass(frozen=True)
class Ranges:
    """The --range items of a command, by kind, each name -> (lo, hi) in the order given.

    Attributes:
        plant: plant parameters besides m1 (the certificate's box).
        cart: the cart's axes (drawn or searched per run, never in the box).
        signal: the signals' parameters; path: the path's knots (searched by falsify).
    """

    plant: dict[str, tuple[float, float]] = field(default_factory=dict)
    cart: dict[str, tuple[float, float]] = field(default_factory=dict)
    signal: dict[str, tuple[float, float]] = field(default_factory=dict)
    path: dict[str, tuple[float, float]] = field(default_factory=dict)
    order: tuple[str, ...] = ()  # every name, in the order given

    @property
    def searched(self) -> dict[str, tuple[float, float]]:
        """The axes that are varied but not certified over (the cart's, the signals', the path's), in the order
        given: a search's axes keep the order the user gave them."""
        others = {**self.signal, **self.path, **self.cart}
        return {name: others[name] for name in self.order if name in others}


def range_kind(name: str) -> str:
    """The kind of a --range name (:data:`RANGE_KINDS`): 'cart', 'signal', 'path', else 'plant'."""
    if hardware_axis(name):
        return "cart"
    if signal_axis(name):
        return "signal"
    if path_axis(name):
        return "path"
    return "plant"


def parse_ranges(items: Iterable[str] | None, *, command: str, accepts: Collection[str]) -> Ranges:
    """``--range NAME=LO:HI`` items read by :data:`RANGE_RULE`, the same for every command.

    Args:
        items: the --range values as given (None: none).
        command: the command's name, for the line that refuses a kind (e.g. 'sweep').
        accepts: the kinds of :data:`RANGE_KINDS` the command varies.

    Returns:
        Ranges: the items by kind, in the order given.

    Raises:
        ParameterError: bad syntax, a number that is not finite, a name given twice, m1, an inverted plant
            range, a kind the command does not vary (one line each).
        UnknownNameError: a plant parameter that does not exist.
    """
    out: dict[str, dict[str, tuple[float, float]]] = {kind: {} for kind in RANGE_KINDS}
    seen: set[str] = set()
    seen_order: list[str] = []
    for item in items or []:
        name, (lo, hi) = parse_range(item)
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise ParameterError(f"--range {item!r}: LO and HI must be finite numbers")
        if name in seen:
            raise ParameterError(f"--range {name} given twice; give each parameter once")
        seen.add(name)
        seen_order.append(name)
        if name == "m1":
            raise ParameterError("give m1's range with --m1-range LO HI, not --range m1=...")
        kind = range_kind(name)
        if kind not in accepts:
            takes = "; ".join(RANGE_KINDS[k] for k in RANGE_KINDS if k in accepts)
            raise ParameterError(f"--range {name}: {command} does not vary {RANGE_KINDS[kind]}; it ranges {takes}")
        if kind == "plant":
            if name not in parameter_names():
                raise UnknownNameError("parameter", name, parameter_names())
            if not lo < hi:
                raise ParameterError(f"--range {item!r}: the range of {name} is empty or inverted; LO < HI is "
                                     "required")
        out[kind][name] = (lo, hi)
    return Ranges(**out, order=tuple(seen_order))


def command_ranges(args: argparse.Namespace, command: str | None = None) -> Ranges:
    """``args.range`` read by :func:`parse_ranges` for ``command`` (default: ``args.command``, else 'run'), with
    the kinds it varies (:data:`RANGE_ACCEPTS`)."""
    command = command or getattr(args, "command", None) or "run"
    return parse_ranges(getattr(args, "range", None), command=command,
                        accepts=RANGE_ACCEPTS.get(command, tuple(RANGE_KINDS)))


def box_ranges_from_args(args: argparse.Namespace) -> dict[str, tuple[float, float]]:
    """The ranged plant parameters besides m1 (whose range is --m1-range): those of the
    --uncertainty box (``wmr_mj.params.uncertainty_ranges``; 'm1' when not given), then each plant
    parameter of --range NAME=LO:HI (read by :func:`parse_ranges`, the one rule of every
    command), which adds a parameter or replaces its range. The cart's axes (:func:`hardware_ranges_from_args`)
    and the other searched axes are never part of the certificate's plant box: they are left out here.

    Raises:
        ParameterError, UnknownNameError: a --range the command does not accept (one line).
    """
    box = getattr(args, "uncertainty", None) or "m1"
    ranges = {k: v for k, v in uncertainty_ranges(box).items() if k != "m1"}
    if getattr(args, "cart", None) is not None:  # the cart's own box (--cart)
        boxes = load_cart(args.cart).uncertainty
        if box in boxes:
            ranges = {k: v for k, v in boxes[box].items() if k != "m1"}
    ranges.update(command_ranges(args).plant)
    return ranges


def hardware_ranges_from_args(args: argparse.Namespace) -> dict[str, tuple[float, float]]:
    """The cart's axes among the --range NAME=LO:HI items (``sensing.delay``, ``sensing.encoder_ticks``, ...:
    :data:`wmr_mj.searches.search_space.HARDWARE_AXES`), in the order given; each is checked where the sweep
    or the search is built."""
    return command_ranges(args).cart

