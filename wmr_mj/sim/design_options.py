"""The design search's names and defaults, in a module of their own: ``wmr-mj design``'s parser reads them
without importing the search (and scipy with it), so that ``wmr-mj --help`` stays light (tests/test_cli_help.py).
:mod:`wmr_mj.sim.design_search` re-exports them."""

from __future__ import annotations

__all__ = ["OBJECTIVES", "METHODS", "LAWS", "DEFAULT_SEED", "DEFAULT_BUDGET"]

#: what the search minimises: the worst certified E_max over the paths (rad), the worst certified voltage (V),
#: or minus the smallest relative margin 1 - value/limit of the certificate's checked assumptions
OBJECTIVES = ("E_max", "voltage", "margin")
#: the optimisers: CMA-ES (``cmaes``; the default: at 640 points on the 12-bit cart it found 0.018894 rad on
#: seeds 0 and 1 where differential evolution found 0.019517 rad, bench/bench_design.py) or scipy's
#: differential evolution
METHODS = ("cma", "de")
#: the laws searched: their families are in the module docstring
LAWS = ("computed-torque", "sliding-mode")
#: the search's seed and budget (certificates per period and path, about) where none is given: ``wmr-mj design``'s,
#: and what validate's section (e) and ``cart check`` search with, so that the command finds the same design
DEFAULT_SEED = 0
DEFAULT_BUDGET = 600
