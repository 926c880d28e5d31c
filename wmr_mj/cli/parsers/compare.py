"""``wmr-mj compare DESIGN...``: every design on every scenario of a versioned suite, then the same adversary.

Each DESIGN is a preset (``paper``, ``certified``), a built-in law (``sliding-mode``,
``adaptive-computed-torque``, ``computed-torque``, ``pd``), or a law of one's own (``FILE.py:Class``,
``module:Class``), with ``,key=value`` settings: ``tracker=NAME`` (``stanley-at-C``, ``pure-pursuit``,
FILE.py:Class), ``correction=true``, ``model=...``, ``kp=...``, ``kd=...``, ``omega_r=...``, or the law's
own parameters (``sliding-mode,k=5``). A law's name means what ``wmr-mj run --controller NAME`` means: the
law with its own defaults (``computed-torque`` and ``pd`` with the paper's model and gains, so
``computed-torque`` is the ``paper`` preset; ``sliding-mode`` and ``adaptive-computed-torque`` on the
non-holonomic model); ``certified`` names the certified design. A DESIGN ending in ``.json`` is a design file
(``wmr-mj design --out FILE.json``): its law, gains, period, cart and m1 box, as ``wmr-mj run --design FILE``
reads them (a bad file: one line, exit status 2); without ``--cart`` every design runs on the design's cart, and a
``--cart`` other than the design's prints one note naming both. Example::

    wmr-mj compare paper certified certified,correction=true sliding-mode adaptive-computed-torque \\
        sliding-mode,tracker=pure-pursuit --scenarios 'circle/*' --budget 32

The cart (``--sensing``, ``--actuation``, ``--backlash``, as for ``wmr-mj run``) applies to every design: to
each scenario's run and to the adversary's. A scenario that names its own sensing, actuation or backlash
(the suite's hardware scenarios) runs with its own: the suite's scenario is the condition compared, the
option the cart of every other run. An option overrides a design's own ``,sensing=PRESET`` setting.
"""

from __future__ import annotations

import argparse

from wmr_mj.cli._common import CLAIM_BROKEN_EXIT
from wmr_mj.cli.command_options import add_command_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = ("every design on every scenario of a versioned suite, then the same adversary: one table (Markdown, "
        "CSV, HTML) and a figure")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("compare", help=HELP,
                       description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter,
                       epilog=f"exit status: 0; {CLAIM_BROKEN_EXIT} when a run of a design (a scenario's or the "
                              "adversary's) is certified-outside: it breaks that design's claim (a banner above "
                              "the table names the run); 2 bad input")
    add_command_options(p, "compare")
