"""``wmr-mj validate``: the headline report (``make demo``), the answer first (what it runs and writes: the command's
help page, :mod:`wmr_mj.cli.parsers.validate`; the report itself: :mod:`wmr_mj.report.validate`)."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from wmr_mj._util.files import check_output_path
from wmr_mj.carts.provenance import identified_from_line
from wmr_mj.cli._common import default_folder, print_json
from wmr_mj.cli.run import hardware_from_args, with_design_file
from wmr_mj.errors import ParameterError, WmrMjError
from wmr_mj.experiments.compare import is_design_file
from wmr_mj.hardware import cart_line, is_ideal_cart
from wmr_mj.params import M1_RANGE
from wmr_mj.reference.named import default_path, default_path_note
from wmr_mj.report.text import format_headline
from wmr_mj.report.validate import ValidateSettings, run_validate, write_pointer
from wmr_mj.sim.coerce import cart_file_of_record
from wmr_mj.sim.config import RunConfig


def _design_file_options(args: argparse.Namespace) -> tuple[float, float] | None:
    """The first design file among --design, read as ``run --design FILE`` reads it
    (:func:`wmr_mj.cli.run.with_design_file`): its cart, path, sensing, actuation and play fill --cart, --path,
    --sensing, --actuation, --backlash where not given (in ``args``), and its m1 box is returned (None: no design
    file, or a --cart other than the design's, which prints one note naming both and runs on that cart's box)."""
    files = [t.strip() for t in args.design or () if is_design_file(t) and "," not in t]
    if not files:
        return None

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
    t0 = time.perf_counter()
    m1_range = _design_file_options(args)  # a design file: its cart, m1 box, path and sensing, unless given
    if args.path is None:  # the cart's own path (the paper circle on the C80)
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

        # a cart identified from recordings (wmr-mj identify --data): the data it rests on, and what that assumes
        rests_on = identified_from_line(str(settings.cart.get("text", "")), str(settings.cart["path"]))
        if rests_on is not None:
            print(rests_on)

    if not is_ideal_cart(settings):
        print(f"every run on the {cart_line(settings)}")
    print()
    print(f"report: {out}/index.html (also index.md, summary.json, summary.csv); pointer: {pointer}")
    print(f"total wall time {wall:.1f} s")
    return 0
