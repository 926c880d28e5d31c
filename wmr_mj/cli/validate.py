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

from wmr_mj.cli._common import int_at_least, positive_float, positive_int
from wmr_mj.cli.options import add_argument_with_help_of, add_json, add_out, add_seed, add_threads
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
    from wmr_mj.cli.run import add_hardware_options

    add_hardware_options(p)  # the cart of every run of the report (summary.json's settings record it)
    p.set_defaults(func=run)


def _sampling_help() -> str:
    from wmr_mj.experiments.sweep import SAMPLINGS

    return f"sampling of m1: one of {', '.join(SAMPLINGS)} (default lhs)"


def _design_file_options(args: argparse.Namespace) -> tuple[float, float] | None:
    """The first design file among --design, read as ``run --design FILE`` reads it
    (:func:`wmr_mj.cli.run.with_design_file`): its cart, path, sensing, actuation and play fill --cart, --path,
    --sensing, --actuation, --backlash where not given (in ``args``), and its m1 box is returned (None: no design
    file, or a --cart other than the design's, which prints one note naming both and runs on that cart's box)."""
    from wmr_mj.experiments.compare import is_design_file
    from wmr_mj.params import M1_RANGE

    files = [t.strip() for t in args.design or () if is_design_file(t) and "," not in t]
    if not files:
        return None
    from wmr_mj.cli.run import hardware_from_args, with_design_file
    from wmr_mj.errors import ParameterError, WmrMjError

    read = argparse.Namespace(preset=None, design=files[0], cart=args.cart, omega_r=None, path=args.path,
                              m1_range=M1_RANGE, sensing=args.sensing, actuation=args.actuation,
                              backlash=args.backlash)
    with_design_file(read)
    taken = {name: None if getattr(args, name) is not None else getattr(read, name)
             for name in ("sensing", "actuation", "backlash")}  # the parts the file gives
    try:  # refused naming the file, as a design token's parts are
        hardware_from_args(argparse.Namespace(**taken))
    except (WmrMjError, ValueError, TypeError) as exc:
        raise ParameterError(f"design {files[0]!r}: its sensing, actuation or play is not accepted: {exc}") from None
    args.cart, args.path = read.cart, read.path
    args.sensing, args.actuation, args.backlash = read.sensing, read.actuation, read.backlash
    return None if read.m1_range is M1_RANGE else (float(read.m1_range[0]), float(read.m1_range[1]))


def run(args: argparse.Namespace) -> int:
    import json
    import sys
    import time
    from pathlib import Path

    from wmr_mj._util.files import check_output_path
    from wmr_mj.cli._common import print_json
    from wmr_mj.cli.figures import default_folder
    from wmr_mj.cli.run import hardware_from_args
    from wmr_mj.report.text import format_headline
    from wmr_mj.report.validate import ValidateSettings, run_validate, write_pointer

    t0 = time.perf_counter()
    m1_range = _design_file_options(args)  # a design file: its cart, m1 box, path and sensing, unless given
    if args.path is None:  # the cart's own path (the paper circle on the C80)
        from wmr_mj.sim.coerce import cart_file_of_record, default_path, default_path_note
        from wmr_mj.sim.config import RunConfig

        cart = cart_file_of_record(RunConfig.from_inputs(cart=getattr(args, "cart", None)).cart)
        args.path = default_path(cart)
        note = default_path_note(cart)  # a path derived from the cart's stops, named
        if note is not None:
            print(f"wmr-mj: note: {note}", file=sys.stderr)
    settings = ValidateSettings(n=args.n, seed=args.seed, sampling=args.sampling, duration=args.duration,
                                identify_duration=args.identify_duration, search_budget=args.search_budget,
                                nthread=args.nthread, uncertainty=args.uncertainty, path=args.path,
                                designs=tuple(args.design or ()), cart=getattr(args, "cart", None),
                                m1_range=m1_range,  # type: ignore[arg-type]  # None: the cart's box, as the field
                                **hardware_from_args(args))
    out = check_output_path(args.out or default_folder("validate"), kind="dir", option="--out")
    summary = run_validate(settings, out)
    pointer = write_pointer(out)
    wall = time.perf_counter() - t0
    if args.json:
        print_json(json.loads(Path(out, "summary.json").read_text()))
        print(f"validate: total wall time {wall:.1f} s; report {out}/index.html", file=sys.stderr)
        return 0
    print(format_headline(summary))
    if settings.cart is not None:
        print(f"every run on the cart file {settings.cart['path']}")
        from wmr_mj.plant.cart_data import identified_from_line

        # a cart identified from recordings (wmr-mj identify --data): the data it rests on, and what that assumes
        rests_on = identified_from_line(str(settings.cart.get("text", "")), str(settings.cart["path"]))
        if rests_on is not None:
            print(rests_on)
    from wmr_mj.hardware import cart_line, is_ideal_cart

    if not is_ideal_cart(settings):
        print(f"every run on the {cart_line(settings)}")
    print()
    print(f"report: {out}/index.html (also index.md, summary.json, summary.csv); pointer: {pointer}")
    print(f"total wall time {wall:.1f} s")
    return 0
