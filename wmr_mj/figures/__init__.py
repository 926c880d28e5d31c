"""Figures, headless (matplotlib's Agg canvas): the drawing primitives (:mod:`wmr_mj.figures.plots`) and the
figure of each result's ``.plot()`` (:mod:`wmr_mj.figures.results`).

A layer of its own, below ``wmr_mj.sim``: it is handed its data and reads it by attribute, so the results of
``wmr_mj.sim`` and the reports of ``wmr_mj.report`` both import it, downwards.
"""
