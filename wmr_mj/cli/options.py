"""The options every command shares: what a command's parser (:mod:`wmr_mj.cli.parsers`) is built from.

* :func:`add_seed`, :func:`add_threads`, :func:`add_out`, :func:`add_json`: the shared options (``--seed``,
  ``--nthread``, ``--out``, ``--json``), one type and one rule each, with the help the command gives.
* :class:`OneLineParser`: a parser that refuses bad arguments in one line, exit status 2.
* :func:`positive_float`, :func:`int_at_least`, :func:`positive_int`, :func:`non_negative_int`: argparse types.
* :func:`add_argument_with_help_of`: an option whose help names what a heavy module holds (the laws, the paths),
  computed when the help is shown, so that building a parser imports no simulation (``wmr-mj --help`` and a bad
  option answer at once; ``bench/bench_cli_help.py``); such a help reads the names by :func:`names_in`, which
  imports their module by name when the help is formatted (the one place a help imports).

The reader of ``--range`` and of the boxes an option gives, used when a command runs: :mod:`wmr_mj.cli.ranges`.

Usage::

    from wmr_mj.cli.options import add_json, add_seed
    add_seed(p, help="seed of the draw (default 0)")
    add_json(p)
"""

from __future__ import annotations

import argparse
import importlib
import math
from collections.abc import Callable

__all__ = ["add_argument_with_help_of", "positive_float", "int_at_least", "positive_int", "non_negative_int",
           "add_seed", "add_threads", "add_out", "add_json", "names_in", "OneLineParser"]


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


def add_seed(p: argparse.ArgumentParser, *, help: str) -> None:
    """``--seed N``: an integer >= 0, default 0 (``help`` says what it seeds)."""
    p.add_argument("--seed", type=non_negative_int, default=0, help=help)


def add_threads(p: argparse.ArgumentParser, *, help: str = "threads of the batch (default 0: all cores)") -> None:
    """``--nthread N``: the simulation threads, an integer >= 0, default 0 (every core)."""
    p.add_argument("--nthread", type=non_negative_int, default=0, help=help)


def add_out(p: argparse.ArgumentParser, *, help: str, metavar: str = "DIR") -> None:
    """``--out PATH``: where the command writes (``help`` names the default, a folder or a file)."""
    p.add_argument("--out", metavar=metavar, help=help)


def add_json(p: argparse.ArgumentParser, *, help: str = "print one JSON object") -> None:
    """``--json``: print one JSON object on stdout instead of the text report."""
    p.add_argument("--json", action="store_true", help=help)


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
