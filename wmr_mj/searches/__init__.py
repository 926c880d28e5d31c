"""Searches: what asks the run layer (:mod:`wmr_mj.sim`) for runs or certificates to find a point.

- :mod:`~wmr_mj.searches.falsify`: the worst run in a box (``wmr-mj falsify``), on its objectives
  (:mod:`~wmr_mj.searches.falsify_objectives`), its axes (:mod:`~wmr_mj.searches.search_space`) and its methods
  (:mod:`~wmr_mj.searches.search_methods`);
- :mod:`~wmr_mj.searches.design_search`: the gains a cart certifies best (``wmr-mj design``), its names and
  defaults in :mod:`~wmr_mj.searches.design_options` (which ``wmr-mj design --help`` reads alone);
- :mod:`~wmr_mj.searches.optimisers`: the one ask/tell optimiser layer both drive.

A search imports the run layer and never an experiment (:mod:`wmr_mj.experiments`), which may run searches.
"""
