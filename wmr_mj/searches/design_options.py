"""The design search's names and defaults, in a module of their own: ``wmr-mj design``'s parser reads them
without importing the search (and scipy with it), so that ``wmr-mj --help`` stays light (tests/test_cli_help.py).
:mod:`wmr_mj.searches.design_search` re-exports them."""

from __future__ import annotations

__all__ = ["OBJECTIVES", "OBJECTIVE_WORDS", "DEFAULT_OBJECTIVE", "E_MAX_SLACK", "METHODS", "LAWS", "DEFAULT_SEED",
           "DEFAULT_BUDGET"]

#: what the search minimises: the worst certified E_max over the paths (rad), the worst certified voltage (V),
#: minus the smallest relative margin 1 - value/limit of the certificate's checked assumptions, or the supply
#: within E_MAX_SLACK of the best E_max: first the E_max search, then the worst certified voltage (V) among the
#: points whose worst E_max is at most (1 + E_MAX_SLACK) times the best E_max found (a second search of the same
#: budget, from that best point): the least supply that certifies within 10 % of the same E_max
OBJECTIVES = ("E_max", "voltage", "margin", "E_max-then-voltage")
#: each objective in words (``wmr-mj design --help``)
OBJECTIVE_WORDS = {"E_max": "the worst certified E_max", "voltage": "the worst certified voltage",
                   "margin": "minus the smallest relative margin of the checked assumptions",
                   "E_max-then-voltage": "the worst certified voltage within 10 % of the best E_max found"}
#: the E_max-then-voltage objective's slack: a design may give up this share of the best E_max for a lower supply
#: (issue 44's target: no design needs the full supply where a lower voltage certifies within 10 % of its E_max)
E_MAX_SLACK = 0.10
#: the objective where none is given (``wmr-mj design``, validate's section (e), ``cart check``, DesignProblem):
#: the supply weighed, since the E_max objective alone buys the last few per cent of E_max with the whole supply,
#: because the Coulomb sign's term does not shrink with the gains (on the 12-bit cart, 2026-11-28: E_max 0.018894
#: rad at 24.00 V, where 0.020723 rad, 9.7 % more, certifies at 22.61 V). E_max alone: ``--objective E_max``
DEFAULT_OBJECTIVE = "E_max-then-voltage"
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
