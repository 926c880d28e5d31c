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

from wmr_mj.cli.options import (
    add_argument_with_help_of,
    add_json,
    add_out,
    add_seed,
    add_threads,
    int_at_least,
    names_in,
    positive_float,
    positive_int,
)
from wmr_mj.cli.parsers.run import add_hardware_options
from wmr_mj.report.defaults import DEFAULT_DURATION, DEFAULT_N, DEFAULT_SEARCH_BUDGET, FULL_BOX_FACTOR

_nonneg_int = int_at_least(0)


#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = ("headline report: the paper's design, the ladder to the certified design, the worst-case search, the "
        "plant's friction law; writes index.html")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("validate", help=HELP,
                       description=__doc__.split("\n\n")[1] if __doc__ else None)
    p.add_argument("--n", type=positive_int, default=DEFAULT_N,
                   help=f"runs per rung of the ladder (default {DEFAULT_N}; --n 100 for the full counts)")
    add_seed(p, help="seed of the m1 samples, the searches and the identification (default 0)")
    add_argument_with_help_of(p, "--sampling", _sampling_help, default="lhs")  # the names checked by the settings
    p.add_argument("--duration", type=positive_float, default=DEFAULT_DURATION,
                   help=f"simulated time per run, s (default {DEFAULT_DURATION:g}; >= ~10 s reaches the circle)")
    p.add_argument("--identify-duration", type=positive_float, default=60.0,
                   help="excitation length of the identification, s (default 60)")
    p.add_argument("--search-budget", type=_nonneg_int, default=DEFAULT_SEARCH_BUDGET,
                   help=f"simulations of each m1-box search (default {DEFAULT_SEARCH_BUDGET}; the full-box search "
                        f"gets {FULL_BOX_FACTOR}x; 0: no search; else >= 5, one generation)")
    p.add_argument("--uncertainty", default="m1",
                   help="uncertainty box the ladder samples and its certificates cover: m1 (the paper's, default) or "
                        "full (m1, steering and tyre friction, R_a, V_A; see wmr_mj/params.py)")
    p.add_argument("--path", default=None, metavar="NAME|FILE",
                   help="path of C every run follows: a named path (paper-circle), a packaged route (agv-loop) or a "
                        "route file, as for wmr-mj run (default: the cart's own, [paths] default in its file, else "
                        "paper-circle)")
    p.add_argument("--design", action="append", metavar="DESIGN", default=None,
                   help="a design of your own, judged beside the ladder (its rung and its nominal run): a preset, "
                        "a law's name, FILE.py:Class or module:Class, with ,key=value settings as for wmr-mj "
                        "compare, e.g. 'sliding-mode' or 'my_law.py:MyLaw,k=2', or a design file FILE.json "
                        "(wmr-mj design --out: its gains; the first design file's cart, m1 box, path and sensing are "
                        "every run's where --cart, --path, --sensing, --actuation, --backlash are not given, and a "
                        "--cart other than the design's prints one note) (repeatable)")
    add_threads(p, help="simulation threads (default 0: all CPUs)")
    add_out(p, help="report folder (default logs/validate-<timestamp>/; an existing folder resumes its sweeps)")
    add_json(p, help="print the summary object (summary.json) on stdout")

    add_hardware_options(p)  # the cart of every run of the report (summary.json's settings record it)


def _sampling_help() -> str:
    return f"sampling of m1: one of {names_in('wmr_mj.experiments.sweep', 'SAMPLINGS')} (default lhs)"
