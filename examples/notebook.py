# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3 (ipykernel)
#     language: python
#     name: python3
# ---

# %% [markdown]
# # wmr-mj in a notebook
#
# A run, its figure and its table; a sweep over the sensor's delay; your own law; the worst-case search and a
# comparison as tables. Every result has `.to_pandas()` (columns named with their units), `.plot()` (a
# `ResultPlot` with `.figure` and `.axes`) and shows its verdict when it is a cell's value.
#
# Install: `pip install -e '.[notebook]'` from the repository (pandas, Jupyter's kernel and runner).
# `WMR_MJ_NOTEBOOK_QUICK=1` shortens every run and budget (the tests run this notebook so).

# %%
import dataclasses
import os

import wmr_mj as wm

QUICK = os.environ.get("WMR_MJ_NOTEBOOK_QUICK") == "1"
DURATION = 9.0 if QUICK else 35.0  # [s] of each run (the paper's circle needs 8.1 s to enter)
RUNS = 4 if QUICK else 16  # a sweep's runs
BUDGET = 6 if QUICK else 32  # the search's simulations (and as many at random)

# %% [markdown]
# ## A run
# The certified design on the paper's circle at m1 = 700 kg: its verdict, E and E' between the certificate's
# bounds, the voltage between the supply limits, C's path.

# %%
run = wm.run_closed_loop(wm.RunConfig(**wm.CERTIFIED.config_changes(), m1=700.0, duration=DURATION), progress=False)
run

# %%
run.plot()  # a ResultPlot: .figure, .axes; shown as its figure

# %%
table = run.to_pandas()  # one row per control step: t [s], E [rad], E_dot [rad/s], voltage [V], ...
table[["t [s]", "E [rad]", "E_dot [rad/s]", "voltage [V]"]].describe()

# %% [markdown]
# ## A sweep over the sensor's delay
# m1 is fixed at 700 kg (`SweepSpec(m1=...)`; the certificate's box stays the default 550-750 kg), so the delay
# is the only axis drawn. Each row holds the values its run used, and the certificate's bound is
# `certificate_E_max [rad]` (the paper's is `paper_E_max [rad]`).

# %%
sweep = wm.sweep(wm.SweepSpec(n=RUNS, m1=700.0, ranges={"sensing.delay": (0.0, 0.02)},
                              base=wm.RunConfig(**wm.CERTIFIED.config_changes(), duration=DURATION)))
sweep

# %%
sweep.to_pandas()[["sensing.delay [s]", "verdict", "sup_E [rad]", "certificate_E_max [rad]"]]

# %%
sweep.plot()

# %% [markdown]
# ## Your own law
# `my_pid.py` beside this notebook: a PID that states no claim, so its verdict is `no-claim`.

# %%
mine = wm.run_closed_loop(wm.RunConfig(controller="my_pid.py:MyPID", controller_params={"ki": 10.0},
                                       duration=DURATION), progress=False)
mine

# %% [markdown]
# ## The worst-case search, as a table
# The certificate's ratio sup|E|/E_max searched over m1, beside a random sample of the same budget.

# %%
search = wm.falsify(wm.FalsifySpec(base=wm.RunConfig(**wm.CERTIFIED.config_changes(), duration=DURATION),
                                   box={"m1": (600.0, 800.0)}, budget=BUDGET))
search.to_pandas()[["phase", "m1 [kg]", "objective", "verdict", "sup_E [rad]", "certificate_E_max [rad]"]]

# %%
search.plot()

# %% [markdown]
# ## A comparison, as a table
# The certified design and the PID on the suite's nominal circle: one row per design and scenario.

# %%
suite = wm.load_suite("standard-v1")
if QUICK:
    suite = dataclasses.replace(suite, duration=DURATION)
designs = [wm.design_from_token(token, suite) for token in ("certified", "my_pid.py:MyPID,ki=10")]
comparison = wm.compare(designs, suite, scenarios=["circle/nominal/none"], budget=0 if QUICK else 16)
comparison.to_pandas()[["design", "scenario", "verdict", "sup_E [rad]", "rms_voltage [V]", "cross_track_max [m]"]]

# %%
comparison

# %% [markdown]
# ## A design for your cart, attacked
# `wmr-mj design` as a function: the gains whose certificate on the second shipped cart, with a 12-bit encoder on
# the steering axis, is the smallest (the certified preset has none there), then the adversary over the m1 box.

# %%
cart_base = wm.RunConfig(**wm.CERTIFIED.config_changes(), cart="c80-magmotor", duration=DURATION,
                         sensing=wm.Sensing.from_spec("magnetic-12bit-axis"))
found = wm.search_design(wm.DesignProblem(base=cart_base, budget=24 if QUICK else 600))
found.to_pandas()

# %%
wm.cart_tightness(cart_base.replace(**found.settings), budget=5 if QUICK else 64)
