"""Experiments: many runs, and searches, asked for and added up into one answer.

- :mod:`~wmr_mj.experiments.sweep`: n runs with parameters drawn (``wmr-mj sweep``), typed as
  :mod:`~wmr_mj.experiments.sweep_result`;
- :mod:`~wmr_mj.experiments.compare`: every design on every scenario of a suite
  (:mod:`~wmr_mj.experiments.suite`), then the adversary on each (``wmr-mj compare``);
- :mod:`~wmr_mj.experiments.tightness`: a cart's certificate beside the worst run the adversary finds;
- :mod:`~wmr_mj.experiments.cart_check`: ``wmr-mj cart check``: a cart file's parts, certificate, design search
  and identification.

An experiment imports the run layer (:mod:`wmr_mj.sim`) and the searches (:mod:`wmr_mj.searches`); neither
imports an experiment.
"""
