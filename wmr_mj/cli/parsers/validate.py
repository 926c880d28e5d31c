"""``wmr-mj validate``: the headline report (``make demo``), the answer first.

Runs the paper's design against the paper's claim and against its own certificate, the
ladder from the paper's design to the certified one (one change per rung, a sweep of m1
each), the worst-case search beside the Monte-Carlo worst and the certificate, the
plant's measured friction law, the certified design on real encoders and, beside it, the design
``wmr-mj design`` finds for the 12-bit axis encoder (its gains, certificate and runs), then
writes a report folder (index.html, index.md, summary.json, summary.csv, per-run CSVs, the
worst runs' MCAP logs, figures). Prints on stdout
a five-line verdict first (the question; the paper's design; why; the certified design; where
the report is: ``wmr_mj.report.text.verdict_lines``, the same lines that open index.md and
index.html), then the details, and one line per stage on stderr. See :mod:`wmr_mj.report.validate`.

Usage::

    wmr-mj validate                      # make demo: 32 runs per rung, about a minute on 2 cores
    wmr-mj validate --n 100 --out logs/full-counts
    wmr-mj validate --search-budget 0 --json
"""

from __future__ import annotations

import argparse

from wmr_mj.cli.command_options import add_command_options

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = ("headline report: the paper's design, the ladder to the certified design, the worst-case search, the "
        "plant's friction law; writes index.html")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("validate", help=HELP,
                       description=__doc__.split("\n\n")[1] if __doc__ else None)
    add_command_options(p, "validate")
