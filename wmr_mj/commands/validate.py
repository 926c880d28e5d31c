"""``wmr-mj validate``: the headline report (``make demo``).

Identifies the MuJoCo plant, sweeps the plant's m1 for each model source of the
controller ('paper', 'nonholonomic', 'identified'), judges the robustness
analysis against the runs and writes a report folder (index.html, index.md,
summary.json, summary.csv, per-run CSVs, figures). See :mod:`wmr_mj.report`.
"""

from __future__ import annotations

import argparse

from ._common import int_at_least, positive_float, positive_int

_nonneg_int = int_at_least(0)


def register(sub: argparse._SubParsersAction) -> None:
    from ..report import DEFAULT_DURATION, DEFAULT_N
    from ..sweep import SAMPLINGS

    p = sub.add_parser("validate", help="headline report: identify the plant, sweep m1 per model source, judge "
                                        "the robustness analysis, write index.html",
                       description=__doc__.split("\n\n")[1] if __doc__ else None)
    p.add_argument("--n", type=positive_int, default=DEFAULT_N, help=f"runs per model source (default {DEFAULT_N})")
    p.add_argument("--seed", type=int, default=0, help="seed of the m1 samples and the identification (default 0)")
    p.add_argument("--sampling", choices=SAMPLINGS, default="lhs", help="sampling of m1 (default lhs)")
    p.add_argument("--duration", type=positive_float, default=DEFAULT_DURATION,
                   help=f"simulated time per run, s (default {DEFAULT_DURATION:g}; >= ~10 s reaches the circle)")
    p.add_argument("--identify-duration", type=positive_float, default=60.0,
                   help="excitation length of the identification, s (default 60)")
    p.add_argument("--nthread", type=_nonneg_int, default=0, help="simulation threads (default 0: all CPUs)")
    p.add_argument("--out", metavar="DIR",
                   help="report folder (default logs/validate-<timestamp>/; an existing folder resumes its sweeps)")
    p.add_argument("--json", action="store_true", help="print one JSON summary object on stdout")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import sys
    import time

    from ..io import check_output_path
    from ..report import (
        ValidateSettings,
        format_identification_table,
        format_verdict_table,
        json_summary,
        run_validate,
        write_pointer,
    )
    from ._common import print_json
    from .figures import default_folder

    t0 = time.perf_counter()
    settings = ValidateSettings(n=args.n, seed=args.seed, sampling=args.sampling, duration=args.duration,
                                identify_duration=args.identify_duration, nthread=args.nthread)
    out = args.out or default_folder("validate")
    check_output_path(out, kind="dir", option="--out")
    summary = run_validate(settings, out)
    pointer = write_pointer(out)
    wall = time.perf_counter() - t0
    summary["wall_s"] = wall
    if args.json:
        obj = json_summary(summary)
        obj["pointer"] = str(pointer)
        print_json(obj)
        print(f"validate: total wall time {wall:.1f} s; report {out}/index.html", file=sys.stderr)
        return 0
    print(f"Verdict ({settings.n} runs per source, m1 {settings.m1_range[0]:g}-{settings.m1_range[1]:g} kg, "
          f"{settings.duration:g} s each):")
    print(format_verdict_table(summary))
    print()
    print(f"Identification at m1 = {summary['identification']['m1']:g} kg:")
    print(format_identification_table(summary))
    print()
    for line in summary["findings"]:
        print(f"- {line}")
    print()
    print(f"report: {out}/index.html (also index.md, summary.json, summary.csv); pointer: {pointer}")
    print(f"total wall time {wall:.1f} s")
    return 0
