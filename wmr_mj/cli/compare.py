"""``wmr-mj compare DESIGN...``: every design on every scenario of a versioned suite, then the same adversary (what
a DESIGN may be, and how the cart options apply: the command's help page, :mod:`wmr_mj.cli.parsers.compare`)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

from wmr_mj._util.files import check_output_path
from wmr_mj._util.progress import counter_callback, progress_bar
from wmr_mj.cli._common import CLAIM_BROKEN_EXIT, print_json
from wmr_mj.cli.run import hardware_from_args, with_design_file
from wmr_mj.errors import ParameterError
from wmr_mj.experiments.compare import adversary_spec, compare, design_from_token, is_design_file
from wmr_mj.experiments.suite import load_suite
from wmr_mj.params import M1_RANGE
from wmr_mj.report.compare import markdown, write_report
from wmr_mj.sim.config import RunConfig


def _cart_options(args: argparse.Namespace) -> dict:
    """The parts of the cart that --sensing, --actuation, --backlash give (each overrides a design's own
    ``,sensing=...`` setting; a part not given stays the design's)."""
    parts = hardware_from_args(args)
    given = {"sensing": args.sensing, "actuation": args.actuation, "transmission": args.backlash}
    out = {name: part for name, part in parts.items() if given[name] is not None}
    if getattr(args, "cart", None) is not None:
        out["cart"] = args.cart  # the cart file: every design's parameter set, box and default parts
    return out


def design_files_found_on(args: argparse.Namespace) -> dict[str, dict[str, Any]]:
    """What each design file among ``args.designs`` was found on, read as ``run --design FILE`` reads it
    (:func:`wmr_mj.cli.run.with_design_file`): token -> {"m1_range": its m1 box (lo, hi) kg, "path": its path},
    returned as :func:`wmr_mj.experiments.compare.design_from_token` takes them; and the cart, which becomes
    ``args.cart`` where --cart is not given (compare runs every design on one cart). A --cart other than a design's
    prints one note naming both, and that design then takes the cart's own m1 box.

    Raises:
        ParameterError: design files found on different carts and no --cart (one line naming them).
    """
    found: dict[str, dict[str, Any]] = {}
    carts: dict[str, Any] = {}
    for token in args.designs:
        if not is_design_file(token) or "," in token:  # a file with settings is refused where it is read
            continue
        read = argparse.Namespace(preset=None, design=token.strip(), cart=args.cart, omega_r=None, path=None,
                                  m1_range=M1_RANGE, sensing=None, actuation=None, backlash=None)
        with_design_file(read)
        carts[token] = read.cart
        found[token] = {"path": read.path, "m1_range": None if read.m1_range is M1_RANGE
                        else (float(read.m1_range[0]), float(read.m1_range[1]))}
    if args.cart is None and carts:
        records = {token: RunConfig.from_inputs(cart=cart).cart for token, cart in carts.items()}
        texts = {None if r is None else r["text"] for r in records.values()}
        if len(texts) > 1:
            raise ParameterError("the design files were found on different carts ("
                                 + ", ".join(f"{t}: {'C80' if r is None else r['name']}" for t, r in records.items())
                                 + "); give --cart FILE to compare them on one cart")
        args.cart = next(iter(carts.values()))
    return found


def run(args: argparse.Namespace) -> int:
    if args.budget < 0:
        raise ParameterError(f"--budget {args.budget} is not accepted: a number of runs >= 0")
    suite = load_suite(args.suite)
    chosen = suite.select(args.scenarios or [])  # an unknown scenario: one line, before any run
    found_on = design_files_found_on(args)  # a design file's cart (where --cart is not given), m1 box and path
    cart = _cart_options(args)
    designs = [design_from_token(t, suite, cart=cart, **found_on.get(t, {})) for t in args.designs]
    labels = [d.label for d in designs]
    if len(set(labels)) != len(labels):
        twice = sorted({x for x in labels if labels.count(x) > 1})
        raise ParameterError(f"a design is named twice: {', '.join(twice)}; name each once")
    if args.budget:
        for d in designs:  # a budget below one generation, a requirement or box the design refuses: before any run
            adversary_spec(d, suite, budget=args.budget, seed=args.seed, method=args.method, scenarios=chosen)
    out = Path(check_output_path(args.out or f"logs/compare-{time.strftime('%Y%m%d-%H%M%S')}", kind="dir",
                                 option="--out"))
    with progress_bar(1, desc="compare", unit="runs", enabled=args.progress) as bar:
        result = compare(designs, suite, scenarios=args.scenarios or [], budget=args.budget, seed=args.seed,
                         nthread=args.nthread, scheduler=args.scheduler, method=args.method,
                         progress=counter_callback(bar))
    paths = write_report(result, out)
    status = CLAIM_BROKEN_EXIT if result.claims_broken else 0
    if args.json:
        print_json({**result.to_dict(runs=False), "files": paths})
        return status
    print(markdown(result).rstrip())  # compare.md: the banners, the table and what each column says
    print(f"\nreport: {paths['html']} (also {Path(paths['markdown']).name}, {Path(paths['csv']).name}, "
          f"{Path(paths['figure']).name}, {Path(paths['json']).name}, {Path(paths['runs']).name})")
    return status
