"""What an options table is made of, and the argparse pieces every command's parser uses.

* :class:`Option`: one row of an options table (its flag, argparse settings and help), which adds itself to a parser;
  the run options (:mod:`wmr_mj.cli.run_options`) and each command's own (:mod:`wmr_mj.cli.command_options`) are
  tables of them.
* :class:`OneLineParser`: a parser that refuses bad arguments in one line, exit status 2.
* :func:`positive_float`, :func:`non_negative_float`, :func:`int_at_least`, :func:`positive_int`,
  :func:`non_negative_int`: argparse types.
* :func:`add_argument_with_help_of`: an option whose help names what a heavy module holds (the laws, the paths),
  computed when the help is shown, so that building a parser imports no simulation (``wmr-mj --help`` and a bad
  option answer at once; ``bench/bench_cli_help.py``); such a help reads the names by :func:`names_in`, which
  imports their module by name when the help is formatted (the one place a help imports).

The reader of ``--range`` and of the boxes an option gives, used when a command runs: :mod:`wmr_mj.cli.ranges`.

Usage::

    from wmr_mj.cli.options import Option, non_negative_int
    SEED = Option(flag="--seed", settings=dict(type=non_negative_int, default=0), help="seed (default 0)")
    SEED.with_help("seed of the draw (default 0)").add_to(parser)
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

__all__ = ["Option", "add_argument_with_help_of", "positive_float", "non_negative_float", "int_at_least",
           "positive_int", "non_negative_int", "names_in", "OneLineParser"]


class OneLineParser(argparse.ArgumentParser):
    """Argument errors as one line (no usage dump), exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


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


#: argparse type of a seed and of a thread count: an integer >= 0 (0 threads: every core)
non_negative_int = int_at_least(0)


def non_negative_float(text: str) -> float:
    """argparse type: a finite number >= 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number; a finite number >= 0 is accepted") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not accepted; a finite number >= 0 is required")
    return value


@dataclass(frozen=True, kw_only=True)
class Option:
    """One row of an options table: an option (or a positional argument) as argparse adds it.

    Attributes:
        flag: its name on the command line (``--kp``), or a positional argument's name (``action``).
        settings: argparse's keywords (type, default, metavar, action, nargs, choices, required).
        help: its help, or a function of nothing giving it (names a heavy module holds: called for --help only,
            :func:`add_argument_with_help_of`).
    """

    flag: str
    settings: Mapping[str, Any] = field(default_factory=dict)
    help: str | Callable[[], str] = ""

    def add_to(self, p: argparse.ArgumentParser | argparse._ArgumentGroup) -> None:
        """Add this option to the parser (or argument group) ``p``."""
        if callable(self.help):
            add_argument_with_help_of(p, self.flag, self.help, **self.settings)
        else:
            p.add_argument(self.flag, help=self.help, **self.settings)

    def with_help(self, help: str | Callable[[], str], **settings: Any) -> Option:
        """This row as a command words it: its own ``help``, and any of ``settings`` it gives otherwise (its
        default, its metavar), the other settings kept."""
        return dataclasses.replace(self, help=help, settings={**self.settings, **settings})


class _HelpOnRead:
    """An argparse action's ``help`` computed the first time it is read (by the help formatter), then kept."""

    _help_text: str | Callable[[], str] | None

    @property
    def help(self) -> str | None:
        if callable(self._help_text):
            self._help_text = self._help_text()
        return self._help_text

    @help.setter
    def help(self, value: str | Callable[[], str] | None) -> None:
        self._help_text = value


_HELP_ON_READ: dict[type, type] = {}


def _help_on_read(action_class: type) -> type:
    """``action_class`` with its ``help`` read on demand (one subclass per argparse action class)."""
    if action_class not in _HELP_ON_READ:
        _HELP_ON_READ[action_class] = type(action_class.__name__, (_HelpOnRead, action_class), {})
    return _HELP_ON_READ[action_class]


def add_argument_with_help_of(p: argparse.ArgumentParser | argparse._ArgumentGroup, flag: str,
                              help_of: Callable[[], str], **settings) -> argparse.Action:
    """``p.add_argument(flag, **settings)`` with the help ``help_of()``, called only when a help page is formatted.

    A help that lists names held by a heavy module (the laws of ``controllers``, the paths of ``wmr_mj.sim``)
    would import it while the parser is built, for every command line; here it is imported for ``--help`` alone.
    The action is argparse's own (``settings['action']``), its class given a ``help`` read on demand.
    """
    action = p.add_argument(flag, **settings)
    action.__class__ = _help_on_read(type(action))
    action.help = help_of  # type: ignore[assignment]  # the property's setter: a function, called when read
    return action


def names_in(module: str, attribute: str) -> str:
    """The names ``module.attribute`` holds (a sequence, or a function of nothing returning one), joined by ', ': what
    a help computed when shown (:func:`add_argument_with_help_of`) lists, e.g. ``names_in('controllers.registry',
    'controller_names')``. ``module`` is imported here, by name, when the help is formatted: it is one that building a
    parser must not import (the laws, the simulation; tests/test_cli_help.py)."""
    held = getattr(importlib.import_module(module), attribute)
    return ", ".join(held() if callable(held) else held)
