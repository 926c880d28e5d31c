"""``wmr-mj validate``'s defaults, apart from its settings (:mod:`wmr_mj.report.settings`, which gives them), so
that the command's parser reads them without importing the simulation (tests/test_cli_help.py).

Usage::

    from wmr_mj.report.defaults import DEFAULT_N
"""

from __future__ import annotations

__all__ = ["DEFAULT_N", "DEFAULT_DURATION", "DEFAULT_SEARCH_BUDGET", "FULL_BOX_FACTOR"]

#: Defaults of ``wmr-mj validate``: 4 rungs x 32 runs of 35 s and 3 searches (30 + 30 + 56 runs) take
#: about a minute on 2 cores, so ``make demo`` fits 3 minutes with the install; ``--n 100``: full counts.
DEFAULT_N = 32
DEFAULT_DURATION = 35.0
#: Simulations of each m1-box search; the 5-parameter full-box search gets FULL_BOX_FACTOR times as many.
DEFAULT_SEARCH_BUDGET = 30
FULL_BOX_FACTOR = 2
