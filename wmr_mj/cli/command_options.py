"""Every command's options, declared once: one tuple of rows per command, in the order its help lists them.

A command's table (:data:`COMMAND_OPTIONS`) holds its own rows (:class:`~wmr_mj.cli.options.Option`: flag,
argparse settings, help) and the groups of the table of run options it takes (:class:`RunRows`: ``run``'s law
and plant, the cart's, the signals', the requirement; :mod:`wmr_mj.cli.run_options`). An option several commands
share is one row, used by each (:data:`JSON`, :data:`OUT`, :data:`SEED`, :data:`THREADS`, ...; the run options'
``--path``, ``--duration``, ``--m1-range``, ``--range``, ``--cart`` ...): a command that words it its own way, or
gives it another default or metavar, says so with :meth:`~wmr_mj.cli.options.Option.with_help`. A command's parser
(:mod:`wmr_mj.cli.parsers`) is its description and epilog and :func:`add_command_options`;
tests/test_cli_options.py checks that every option of every parser is a row of its command's table.

Like the parsers, this module imports argparse-level modules only: a help that names what a heavy module holds is a
function, called when the help is shown (tests/test_cli_help.py).

Usage::

    from wmr_mj.cli.command_options import add_command_options
    p = sub.add_parser("sweep", help=HELP)
    add_command_options(p, "sweep")
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from wmr_mj.cli.options import (
    Option,
    names_in,
    non_negative_float,
    non_negative_int,
    positive_float,
    positive_int,
)
from wmr_mj.cli.run_options import RunOption, add_options, run_option, run_options
from wmr_mj.params import COEFFICIENT_MODELS
from wmr_mj.report.defaults import DEFAULT_DURATION as VALIDATE_DURATION
from wmr_mj.report.defaults import DEFAULT_N, DEFAULT_SEARCH_BUDGET, FULL_BOX_FACTOR
from wmr_mj.searches.design_options import (
    DEFAULT_BUDGET,
    DEFAULT_OBJECTIVE,
    DEFAULT_SEED,
    METHODS,
    OBJECTIVE_WORDS,
)

__all__ = ["RunRows", "COMMAND_OPTIONS", "add_command_options", "rows_of", "JSON", "OUT", "SEED", "THREADS",
           "CHUNK", "SCHEDULER", "PROGRESS"]


@dataclass(frozen=True)
class RunRows:
    """The rows of one group of the table of run options (:data:`wmr_mj.cli.run_options.GROUPS`), added in the
    table's order, under their heading where the group has one."""

    group: str

    def add_to(self, p: argparse.ArgumentParser) -> None:
        add_options(p, self.group)

    def rows(self) -> tuple[RunOption, ...]:
        return tuple(row for row in run_options() if row.group == self.group)


#: ``wmr-mj run``'s law, path, plant and analysis box (the 'run' rows)
RUN_ROWS = RunRows("run")
#: --sensing, --actuation, --backlash, --cart: the cart as it is built (under their heading)
CART_ROWS = RunRows("cart")
#: --signals, --disturbance, --load, --d-max (under their heading)
SIGNAL_ROWS = RunRows("signals")
#: --require STL, repeatable
REQUIRE_ROWS = RunRows("require")

# --------------------------------------------------------------------------- options several commands share
JSON = Option(flag="--json", settings=dict(action="store_true"), help="print one JSON object")
#: where the command writes: each command names it (a folder, a file) and its default
OUT = Option(flag="--out", settings=dict(metavar="DIR"))
#: each command says what it seeds
SEED = Option(flag="--seed", settings=dict(type=non_negative_int, default=0))
THREADS = Option(flag="--nthread", settings=dict(type=non_negative_int, default=0),
                 help="threads of the batch (default 0: all cores)")
CHUNK = Option(flag="--chunk", settings=dict(type=positive_int, default=128),
               help="simulations per batch (default 128)")
SCHEDULER = Option(flag="--scheduler", settings=dict(metavar="ADDRESS"))
PROGRESS = Option(flag="--progress", settings=dict(action=argparse.BooleanOptionalAction, default=None),
                  help="progress bar (default: only on a terminal)")
SAMPLING = Option(flag="--sampling", settings=dict(default="lhs"),
                  help="uniform, lhs (Latin hypercube, default) or grid")
#: falsify's search method (compare's adversary is falsify's search)
SEARCH_METHOD = Option(
    flag="--method", settings=dict(default="portfolio"),
    help="search: portfolio (default: the box's 2^d vertices where they fit half the budget, else a "
         "fractional-factorial covering of at most an eighth of it, then CMA-ES from the box's centre "
         "moved to the worse side of significant main effects, a generation per batch, then a local "
         "CMA-ES around the worst found), cma (CMA-ES alone), vertices-polish (the vertices, then "
         "scipy's Nelder-Mead from the worst), lhs-polish (a Latin hypercube of half the budget, then "
         "the same polish) or de (differential evolution)")

# the run options other commands take, in their own words
M1 = run_option("--m1")
RANGE = run_option("--range")
PATH = run_option("--path")
DURATION = run_option("--duration")
M1_RANGE = run_option("--m1-range")
PARAM = run_option("--param")
CART = run_option("--cart")
UNCERTAINTY = run_option("--uncertainty")
REFERENCE_BOUNDS = run_option("--reference-bounds")

#: sweep's and falsify's --m1: a fixed m1, so that the other axes are swept or searched alone
FIXED_M1 = M1.with_help("fix every run's m1 at KG (the other ranges swept alone; the certificate's box stays "
                        "--m1-range); a zero-width --m1-range KG KG is the same, the box then the default 550-750 kg",
                        default=None, metavar="KG")


# --------------------------------------------------------------------------- each command's table
RUN = (
    RUN_ROWS,
    CART_ROWS,
    M1.with_help("plant chassis mass, kg (default: the cart's, 650 on the C80)"),
    RANGE.with_help("another ranged plant parameter of the analysis box (repeatable; it adds the parameter to "
                    "the --uncertainty box or replaces its range, e.g. R_a=1.0:1.3); a run draws nothing"),
    OUT.with_help("MCAP log path (default logs/run-<time>-<model>-m<m1>.mcap)", metavar="PATH"),
    Option(flag="--no-log", settings=dict(action="store_true"), help="do not write an MCAP log"),
    Option(flag="--log-every", settings=dict(type=positive_int, default=1),
           help="log signals every k-th control step (default 1)"),
    PROGRESS,
    REQUIRE_ROWS,
    JSON,
    SIGNAL_ROWS,
)

SWEEP = (
    RUN_ROWS,
    CART_ROWS,
    FIXED_M1,
    Option(flag="--n", settings=dict(type=int, default=200), help="number of runs (default 200)"),
    SEED.with_help("seed of the draw (default 0)"),
    SAMPLING,
    RANGE.with_help("draw another plant parameter over a range too (repeatable); the box includes it. Or a "
                    "hardware axis of the cart, drawn per run but not in the certificate's box (each run's claim "
                    "covers its own cart): sensing.delay (rounded to whole control periods), "
                    "sensing.encoder_ticks (rounded to whole ticks), sensing.encoder_bits (2**round(bits) "
                    "ticks), sensing.noise, sensing.velocity_noise, sensing.filter_tau, "
                    "actuation.delay (whole 1 ms steps), actuation.inductance, actuation.current_limit, "
                    "transmission.backlash; runs.csv records the value each run used"),
    OUT.with_help("output folder (default logs/sweep-<time>); rerun to resume"),
    CHUNK,
    THREADS,
    SCHEDULER.with_help("run the chunks on a Dask cluster (e.g. tcp://127.0.0.1:8786)"),
    Option(flag="--log", settings=dict(action="store_true"),
           help="also write an MCAP log per run (re-run one by one; bit-identical)"),
    JSON.with_help("print one summary JSON object"),
    REQUIRE_ROWS,
    SIGNAL_ROWS,
)

FALSIFY = (
    RUN_ROWS,
    CART_ROWS,
    FIXED_M1,
    RANGE.with_help("add a plant parameter to the box or replace its range (repeatable); with --disturbance "
                    "or --load, also their parameters: disturbance.amplitude, disturbance.t1, ..., load0.m1, "
                    "load0.t, ..., d_max (a ranged amplitude without --d-max declares the box's largest); "
                    "and the cart's axes, searched but not in the certificate's box (each run's claim covers its "
                    "own cart): sensing.delay (whole control periods), sensing.encoder_ticks (whole ticks), "
                    "sensing.encoder_bits (2**round(bits) ticks), sensing.noise, "
                    "sensing.velocity_noise, sensing.filter_tau, actuation.delay (whole 1 ms steps), "
                    "actuation.inductance, actuation.current_limit, transmission.backlash"),
    Option(flag="--path-knots", settings=dict(type=int, default=0, metavar="N"),
           help="search C's path too: N curvature knots (path.k1..path.kN, each within +-kappa_max of the "
                "declared reference bounds) and the hold time at each (path.hold, 0-3 s), every path "
                "feasible for those bounds (wmr_mj/reference/knots.py); declares --reference-bounds paper "
                "unless given (default 0: the --path given)"),
    Option(flag="--against", settings=dict(default="certificate"),
           help="the region of the ratio sup|E|/E_max: certificate (default) or paper (the paper's region)"),
    Option(flag="--objective", settings=dict(default="ratio"),
           help="what is maximised: ratio (default, see --against) or sup-E"),
    SEARCH_METHOD,
    # one requirement, falsified (run's --require is repeatable: each one monitored)
    run_option("--require").with_help(
        "falsify an STL requirement (e.g. 'always(abs(E) <= 0.05)', signals as for wmr-mj run "
        "--require): maximise minus its robustness (> 0: falsified); runs one by one, the batch "
        "keeps no per-step signals", action="store"),
    Option(flag="--budget", settings=dict(type=positive_int, default=256),
           help="simulations of the search (default 256); the random sample gets as many"),
    Option(flag="--population", settings=dict(type=int, default=None),
           help="members per generation: CMA-ES's (default 4 + 3 ln d) or differential evolution's "
                "(default: 10 per parameter, at most budget/8, at least 5)"),
    SEED.with_help("seed of the search and of the random sample (default 0)"),
    CHUNK,
    THREADS,
    SCHEDULER.with_help("run the batches on a Dask cluster (e.g. tcp://127.0.0.1:8786)"),
    OUT.with_help("output folder (default logs/falsify-<time>)"),
    JSON,
    SIGNAL_ROWS,
)


def _suite_help() -> str:
    return f"the scenario suite: one of {names_in('wmr_mj.experiments.suite', 'suite_names')} or a suite file (.toml)"


COMPARE = (
    Option(flag="designs", settings=dict(nargs="+", metavar="DESIGN"),
           help="a preset, a law's name, FILE.py:Class or module:Class, with ,key=value settings; or a design file "
                "FILE.json (wmr-mj design --out)"),
    Option(flag="--suite", settings=dict(default="standard-v1"), help=_suite_help),
    Option(flag="--scenarios", settings=dict(action="append", metavar="PATTERN"),
           help="only the scenarios whose id matches (shell pattern, e.g. 'circle/*'; repeatable)"),
    Option(flag="--budget", settings=dict(type=int, default=32),
           help="the adversary's simulations per design, and as many random ones (default 32; 0: none)"),
    SEED.with_help("the adversary's seed, the same for every design (default 0)"),
    SEARCH_METHOD.with_help("the adversary's search method (default: falsify's)", default=None),
    THREADS.with_help("threads (default 0: every core)"),
    SCHEDULER.with_help("run on a Dask cluster (e.g. tcp://127.0.0.1:8786)"),
    OUT.with_help("output folder (default logs/compare-<time>)"),
    JSON,
    PROGRESS,
    CART_ROWS,  # every design's cart: its scenarios (but one that names its own) and its adversary
)


def _sampling_help() -> str:
    return f"sampling of m1: one of {names_in('wmr_mj.experiments.sweep', 'SAMPLINGS')} (default lhs)"


VALIDATE = (
    Option(flag="--n", settings=dict(type=positive_int, default=DEFAULT_N),
           help=f"runs per rung of the ladder (default {DEFAULT_N}; --n 100 for the full counts)"),
    SEED.with_help("seed of the m1 samples, the searches and the identification (default 0)"),
    SAMPLING.with_help(_sampling_help),  # the names checked by the settings
    DURATION.with_help(f"simulated time per run, s (default {VALIDATE_DURATION:g}; >= ~10 s reaches the circle)",
                       default=VALIDATE_DURATION),
    Option(flag="--identify-duration", settings=dict(type=positive_float, default=60.0),
           help="excitation length of the identification, s (default 60)"),
    Option(flag="--search-budget", settings=dict(type=non_negative_int, default=DEFAULT_SEARCH_BUDGET),
           help=f"simulations of each m1-box search (default {DEFAULT_SEARCH_BUDGET}; the full-box search "
                f"gets {FULL_BOX_FACTOR}x; 0: no search; else >= 5, one generation)"),
    UNCERTAINTY.with_help("uncertainty box the ladder samples and its certificates cover: m1 (the paper's, default) "
                          "or full (m1, steering and tyre friction, R_a, V_A; see wmr_mj/params.py)", default="m1"),
    PATH.with_help("path of C every run follows: a named path (paper-circle), a packaged route (agv-loop) or a "
                   "route file, as for wmr-mj run (default: the cart's own, [paths] default in its file, else "
                   "paper-circle where the cart steers it within 85%% of its stops, else a loop of turns it steers)"),
    Option(flag="--design", settings=dict(action="append", metavar="DESIGN", default=None),
           help="a design of your own, judged beside the ladder (its rung and its nominal run): a preset, "
                "a law's name, FILE.py:Class or module:Class, with ,key=value settings as for wmr-mj "
                "compare, e.g. 'sliding-mode' or 'my_law.py:MyLaw,k=2', or a design file FILE.json "
                "(wmr-mj design --out: its gains; the first design file's cart, m1 box, path and sensing are "
                "every run's where --cart, --path, --sensing, --actuation, --backlash are not given, and a "
                "--cart other than the design's prints one note) (repeatable)"),
    THREADS.with_help("simulation threads (default 0: all CPUs)"),
    OUT.with_help("report folder (default logs/validate-<timestamp>/; an existing folder resumes its sweeps)"),
    JSON.with_help("print the summary object (summary.json) on stdout"),
    CART_ROWS,  # the cart of every run of the report (summary.json's settings record it)
)

DESIGN = (
    CART_ROWS,
    run_option("--controller").with_help(
        "the law searched: computed-torque (default: omega_n, zeta) or sliding-mode (lam, phi, k, eta "
        "on the non-holonomic model); both with the sign's width, tau_f and the period",
        default="computed-torque", metavar="LAW"),
    PATH.with_help("a path every certificate must hold on (repeatable; default: the cart's own, [paths] default "
                   "in its file, else paper-circle where the cart steers it within 85%% of its stops, else a loop of "
                   "turns it steers)", action="append"),
    UNCERTAINTY.with_help("the plant box: m1 (default) or full (wmr_mj/params.py)"),
    # type=float, not run's positive_float: argparse lets a bound <= 0 through here (as before the table)
    M1_RANGE.with_help("m1 range of the box, kg (default: the cart's m1 box, 550 750 on the C80)", type=float),
    RANGE.with_help("another ranged parameter of the box"),
    REFERENCE_BOUNDS.with_help("declared reference bounds the certificates cover (default: each path's own)"),
    # 35.0 and not run's DEFAULT_DURATION object: the note that a refused duration is the default one is run's
    # (wmr_mj.cli.app compares the very object)
    DURATION.with_help("the run's length, s (default 35, run's)", default=35.0),
    Option(flag="--periods", settings=dict(default="0.001", metavar="T1,T2,..."),
           help="control periods to try, s, each a whole number of 1 ms physics steps dividing the run "
                "(default 0.001)"),
    Option(flag="--objective", settings=dict(default=DEFAULT_OBJECTIVE),
           help=f"what is minimised (default {DEFAULT_OBJECTIVE}): " + "; ".join(
               f"{name}: {words}" for name, words in OBJECTIVE_WORDS.items()).replace("%", "%%")),
    Option(flag="--method", settings=dict(default="cma", choices=METHODS),
           help="the optimiser: cma (CMA-ES, the default: the better of the two in bench/bench_design.py) "
                "or de (scipy's differential evolution)"),
    SEED.with_help(f"the optimiser's seed (same seed, same design; default {DEFAULT_SEED})", type=int,
                   default=DEFAULT_SEED),
    Option(flag="--budget", settings=dict(type=positive_int, default=DEFAULT_BUDGET),
           help=f"certificate evaluations per period and path, about (default {DEFAULT_BUDGET})"),
    Option(flag="--check", settings=dict(type=int, default=0, metavar="N"),
           help="then sweep N runs over the box at the design and count the verdicts (default 0: none)"),
    OUT.with_help("the design file (default design.json)", default="design.json", metavar="FILE"),
    JSON,
)

ROBUSTNESS = (
    run_option("--kp").with_help("K_P [1/s^2] (default 6)"),
    run_option("--kd").with_help("K_D [1/s] (default 9)"),
    run_option("--omega-r").with_help("critical damping (3.6): K_P = omega_r^2/4, K_D = omega_r (not with --kp/--kd)"),
    # the box of the analysis: the paper's, or derived from a cart over ranges, by a reduced model
    run_option("--box").with_help(
        "uncertainty box: the paper's (5.1) intervals (default), or derived from the C80 parameter set (the "
        "default with --cart: from the cart's)",
        choices=("paper", "derived"), default=None),
    M1_RANGE.with_help("chassis mass range [kg] for --box derived (default 550 750)", default=None),
    RANGE.with_help("extra C80 parameter range for --box derived (repeatable), e.g. mu=0.015:0.02"),
    CART.with_help("for --box derived: the cart whose parameter set and m1 box span it (a cart file or a "
                   "shipped cart's name; default the C80)"),
    Option(flag="--model", settings=dict(choices=COEFFICIENT_MODELS, default=None),
           help="reduced model whose coefficients span --box derived (default paper)"),
    Option(flag="--estimate", settings=dict(action="append", default=None, metavar="NAME=VALUE"),
           help="fixed estimate of P, C_V, F or K (repeatable); others are anywhere in the box (4.2)"),
    # the reading of (4.19)-(4.20) and the operator gains
    Option(flag="--reading", settings=dict(choices=("corrected", "printed", "printed-literal"), default=None),
           help="reading of (4.19)-(4.20): corrected from (4.10) (default), printed labels, or (4.20) verbatim"),
    Option(flag="--gammas", settings=dict(choices=("exact", "paper"), default=None),
           help="operator gains: exact integrals (default) or the paper's (4.16) 1/K_P, 4/(e K_D)"),
    Option(flag="--alpha-ddot", settings=dict(type=non_negative_float, default=None),
           help="||alpha0''|| [rad/s^2] (default 0.4)"),
    Option(flag="--alpha-dot", settings=dict(type=non_negative_float, default=None),
           help="||alpha0'|| [rad/s] (default 0.23)"),
    Option(flag="--sin-cos3", settings=dict(type=non_negative_float, default=None),
           help="||sin/cos^3|| (default 1.24)"),
    JSON,
    Option(flag="--certificate", settings=dict(nargs=argparse.REMAINDER, default=None, metavar="RUN-OPTIONS"),
           help="print the certificate for a controller as `wmr-mj run` would run it; every option after "
                "--certificate is one of run's (--model, --controller, --kp/--kd/--omega-r, --friction-sign, "
                "--friction-width, --control-period, --m1, --box, --m1-range, --param) or --range NAME=LO:HI, "
                "--uncertainty m1|full, --json (see: wmr-mj robustness --certificate --help)"),
)

#: the options read after ``wmr-mj robustness --certificate``: run's, the cart's, and the box's
ROBUSTNESS_CERTIFICATE = (
    RUN_ROWS,
    CART_ROWS,
    M1.with_help("plant chassis mass, kg (default 650); the certificate's box includes it"),
    RANGE.with_help("another ranged plant parameter of the box (repeatable), e.g. R_a=1.0:1.3"),
    run_option("--d-max").with_help("a steering disturbance torque bound, N m: its term R_a d_max/(k_i i2)/P enters "
                                    "delta1 (wmr-mj run --disturbance)"),
    JSON,
)

IDENTIFY = (
    M1.with_help("chassis mass of the plant, kg (default: the cart's, 650 on the C80)"),
    DURATION.with_help("excitation length, s (default 60)", default=60.0),
    SEED.with_help("seed of the excitation signal (default 0)"),
    PARAM,
    OUT.with_help("also write the result as JSON (used by --model identified); with --data: the identified cart "
                  "file NEW.toml", metavar="PATH"),
    Option(flag="--data", settings=dict(action="append", metavar="FILE[:m1=KG]"),
           help="a recording of the cart (CSV with the header t_s,u_V,alpha_rad[,speed_m_per_s][,u_applied_V]: "
                "u_applied_V, the voltage at the motor, separates the actuation delay from the sensing one; or a "
                "wmr-mj run's MCAP log); :m1= gives the chassis mass during it (default: the cart's); "
                "repeatable. Identifies P, C_V, F (as front_axle_mass, k_i = k_b, mu), the delay, the "
                "encoder and the noise, and writes --out NEW.toml"),
    Option(flag="--holdout", settings=dict(metavar="FILE[:m1=KG]"),
           help="a recording the fit never sees: the identified model must predict it (normalised RMS error "
                "at most 0.1, else exit 1)"),
    Option(flag="--report", settings=dict(metavar="DIR"),
           help="with --data: write identify.html and identify.png (recorded against simulated angle on the "
                "hold-out, or the first recording; residuals; the table of intervals) into DIR"),
    Option(flag="--topics", settings=dict(metavar="u=/T,alpha=/T[,speed=/T]"),
           help="with --data BAG.mcap: a ROS 2 bag's topics of the voltage, the angle and the speed (a topic "
                "with .field or .field[i]; default field data), read through mcap-ros2-support"),
    Option(flag="--columns", settings=dict(metavar="KEY=NAME,..."),
           help="CSV column names of another header: t_s=...,u_V=...,alpha_rad=...,speed_m_per_s=..."),
    Option(flag="--sysid", settings=dict(action="store_true"),
           help="with --data: also roll out the identified cart file's MJCF with mujoco.sysid on each segment "
                "of the hold-out (else of each recording) against the recorded angle and report its normalised "
                "RMS error (the hold-out's limit applies); needs the sysid extra: pip install 'wmr-mj[sysid]'"),
    JSON,
    CART,
)

MODEL = (
    Option(flag="action", settings=dict(choices=("write", "check", "params", "slip", "friction", "card", "image")),
           help="write: regenerate models/*.xml; check: exit 1 if they differ from the parameter set; "
                "params: print the parameter set with sources and the derived coefficients; "
                "slip: measure the wheels' side slip on the 1 m circle; friction: measure the steering "
                "joint's friction law (break-away, creep, sliding) for each friction model; "
                "card: write models/README.md; image: render models/c80.png (the scene at its home "
                "keyframe, offscreen: EGL or OSMesa)"),
    PARAM.with_help("override a parameter (repeatable)"),
    JSON.with_help("with 'params', 'slip' or 'friction': print one JSON object"),
    CART,  # params, slip, friction on the cart (its card: wmr-mj cart card FILE)
)

CART_COMMAND = (
    Option(flag="action", settings=dict(choices=("check", "card")),
           help="check: read the file against its schema, compile and step the generated model for 1 s "
                "with random controls (no MuJoCo warning), identify P, C_V, F, K, gyro from a simulated "
                "excitation and compare them with what the file implies, and report the certified design's "
                "certificate on the cart; exit 1 if a check fails. card: write the cart's model card "
                "(Markdown, as models/README.md is the C80's; about a minute of measurements)"),
    Option(flag="cart", settings=dict(metavar="FILE|NAME"),
           help="a cart file (.toml, see wmr_mj/carts/c80.toml) or a shipped cart's name (c80)"),
    DURATION.with_help("length of the identification's excitation, s (default 20)", default=20.0),
    # type=int: a negative seed is accepted here, as in design (the others: an integer >= 0)
    SEED.with_help("seed of the random controls and the excitation (default 0)", type=int),
    JSON,
    PATH.with_help("check: the path the certified design and the design search answer for (a path name, a "
                   "packaged route or a route file; default: the cart's own, [paths] default in its file, "
                   "else paper-circle where the cart steers it within 85%% of its stops, else a loop of turns it "
                   "steers)"),
    OUT.with_help("card: the Markdown file to write (default: logs/<cart file's stem>-card.md)", metavar="PATH"),
)

EXCITE = (
    CART.with_help("the cart file (or a shipped cart's name), default c80", default="c80", metavar=None),
    DURATION.with_help("plan length, s (default 60)", default=60.0),
    OUT.with_help("the plan: t_s,alpha0_rad,u_dither_V", required=True, metavar="PLAN.csv"),
    SEED.with_help("seed of the multisines (default 0)"),
)

REPLAY = (
    Option(flag="log", settings=dict(metavar="LOG"), help="MCAP run log written by `wmr-mj run`"),
    JSON.with_help("print the summary as one JSON object"),
    Option(flag="--plot", settings=dict(metavar="PATH.png"),
           help="write a figure: E, E', voltage over time and the (|E|,|E'|) plane"),
    Option(flag="--verify", settings=dict(action="store_true"),
           help="re-simulate from the attached MJCF and initial state, and re-run the law (a plug-in's file "
                "is checked against its SHA-256 before it is imported and run; exit 2 if changed or gone); "
                "exit 1 unless bit-identical"),
    Option(flag="--video", settings=dict(metavar="PATH.mp4"),
           help="render the run offscreen to MP4 (needs EGL or OSMesa)"),
    Option(flag="--settle", settings=dict(type=positive_float, metavar="S"),
           help="settling time for the sup after settling [s] (default: the log's settle_s)"),
    Option(flag="--fps", settings=dict(type=positive_int, default=30), help="video frame rate (default 30)"),
    Option(flag="--size", settings=dict(default="640x360", metavar="WxH"),
           help="video size in pixels (default 640x360)"),
)

FIGURES = (
    OUT.with_help("output folder (default logs/figures-<timestamp>/)"),
    DURATION.with_help("length of the paper circle run, s (default 35; >= ~10 s reaches the circle)", default=35.0),
)

#: each command's table, by the command's name (and ``robustness --certificate``'s, the parser of the options
#: after it)
COMMAND_OPTIONS: Mapping[str, tuple[Option | RunRows, ...]] = {
    "identify": IDENTIFY, "robustness": ROBUSTNESS, "robustness --certificate": ROBUSTNESS_CERTIFICATE,
    "run": RUN, "replay": REPLAY, "sweep": SWEEP, "falsify": FALSIFY, "compare": COMPARE, "validate": VALIDATE,
    "figures": FIGURES, "model": MODEL, "cart": CART_COMMAND, "design": DESIGN, "excite": EXCITE,
}


def add_command_options(p: Any, command: str) -> None:
    """Add ``command``'s options (:data:`COMMAND_OPTIONS`) to its parser ``p``, in its table's order."""
    for entry in COMMAND_OPTIONS[command]:
        entry.add_to(p)


def rows_of(command: str) -> tuple[Option, ...]:
    """``command``'s rows, each group of run options taken in its rows, in the order they are added."""
    return tuple(row for entry in COMMAND_OPTIONS[command]
                 for row in (entry.rows() if isinstance(entry, RunRows) else (entry,)))
