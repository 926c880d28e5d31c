"""``wmr-mj run``: one headless closed-loop run on the MuJoCo plant, reported against the region."""

from __future__ import annotations

import argparse
import functools
import json
import sys
import time
from typing import TYPE_CHECKING, Any

from controllers.registry import parse_params
from wmr_mj._util.files import check_output_path
from wmr_mj._util.memory import require_run_memory
from wmr_mj.analysis.requirements import parse_requirement
from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE, format_measurement_cause, format_verdict
from wmr_mj.carts import load_cart
from wmr_mj.cli._common import CLAIM_BROKEN_EXIT, parse_assignments, print_json
from wmr_mj.cli.ranges import box_ranges_from_args
from wmr_mj.errors import ParameterError
from wmr_mj.hardware import Actuation, Sensing, Transmission, cart_line, is_ideal_cart
from wmr_mj.logs.writer import LogOptions, RunLogger, terminate_as_interrupt
from wmr_mj.params import M1_NOMINAL, M1_RANGE, uncertainty_ranges
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.reference.named import default_path, default_path_note
from wmr_mj.searches.design_search import (
    design_cart,
    design_cart_name,
    design_file_box,
    design_file_settings,
    read_design,
)
from wmr_mj.sim.closed_loop import MUJOCO_WITHOUT_WARNINGS, run_parts
from wmr_mj.sim.coerce import cart_file_of_record
from wmr_mj.sim.config import RunConfig, plugin_source
from wmr_mj.sim.engine import law_path
from wmr_mj.sim.parts import resolve_run
from wmr_mj.sim.run_report import measurement_cause
from wmr_mj.sim.signals import signals_from
from wmr_mj.sim.spec import LawChoice, law_fields, no_estimate_note

if TYPE_CHECKING:
    from wmr_mj.sim.summary import RunSummary


def hardware_from_args(args: argparse.Namespace) -> dict[str, Any]:
    """RunConfig's sensing, actuation and transmission from --sensing, --actuation, --backlash: each typed part
    (wmr_mj.hardware; ideal where the option is not given).

    Raises:
        ParameterError, UnknownNameError: a malformed spec, an unknown key or preset, a value out of range (a
            delay on the control period's grid is checked where RunConfig is built).
    """
    # an option not given stays None: the cart's default (RunConfig.cart; ideal on the C80)
    given: dict[str, tuple[Any, str]] = {"sensing": (Sensing, "sensing"), "actuation": (Actuation, "actuation"),
                                         "transmission": (Transmission, "backlash")}
    return {name: None if getattr(args, option, None) is None else cls.from_spec(getattr(args, option))
            for name, (cls, option) in given.items()}


def config_from_args(args: argparse.Namespace, **extra):
    """A RunConfig from the shared options (raises WmrMjError on bad input): the law's options merged with the
    preset by :func:`wmr_mj.sim.spec.law_fields`, the rest parsed here."""
    if getattr(args, "design", None) is not None:
        with_design_file(args)
    tracker = getattr(args, "tracker", None)
    if bool(getattr(args, "correction", False)) and tracker not in (None, "stanley-at-C"):
        raise ParameterError(f"--correction is the tracker stanley-at-C; give it or --tracker {tracker}, not both")

    # --cart: the cart's parameter set, boxes and defaults; --m1 and --m1-range not given (their defaults, the
    # very objects): the cart's m1 and m1 box
    cart = getattr(args, "cart", None)
    m1_range = getattr(args, "m1_range", M1_RANGE)
    choice = LawChoice(cart=cart, preset=args.preset, controller=args.controller,
                       controller_params=parse_params(getattr(args, "controller_param", None)), model=args.model,
                       kp=args.kp, kd=args.kd, omega_r=args.omega_r, friction_sign=args.friction_sign,
                       friction_width=args.friction_width, identified=args.identified,
                       coefficients=parse_assignments(args.coef) if args.coef else None, path=args.path)
    signals = signals_from_args(args)
    if signals is not None:
        extra.setdefault("signals", signals)
    tracker_params = parse_params(getattr(args, "tracker_param", None), option="--tracker-param")
    if extra.get("m1", None) is M1_NOMINAL:
        extra["m1"] = None  # --m1 not given: the cart's nominal m1
    given_range: Any = None if m1_range is M1_RANGE else tuple(m1_range)  # None: the cart's m1 box
    config = RunConfig.from_inputs(**law_fields(choice), cart=cart, tracker=tracker, tracker_params=tracker_params,
                                   duration=args.duration, control_period=args.control_period,
                                   path=args.path,  # None: the design's, else the cart's own (coerce)
                                   plant_overrides=parse_assignments(args.param), m1_inertia=args.m1_inertia,
                                   box=args.box, m1_range=given_range, steering_friction=args.steering_friction,
                                   tyre_contact=args.tyre_contact, box_ranges=box_ranges_from_args(args),
                                   correction=bool(getattr(args, "correction", False)),
                                   reference_bounds=getattr(args, "reference_bounds", None),
                                   **hardware_from_args(args), **extra)
    args.m1_range = config.m1_range  # --m1-range not given: the cart's m1 box, which the commands read from args
    return config


def with_design_file(args: argparse.Namespace) -> argparse.Namespace:
    """``args`` with each option that --design FILE sets and was not given taken from the file, in place (the
    command reads them from ``args`` after this): its settings
    (:func:`wmr_mj.searches.design_search.design_file_settings`) as a preset's are, its cart
    (:func:`~wmr_mj.searches.design_search.design_cart`), and what it was found on
    (:func:`~wmr_mj.searches.design_search.design_file_box`): its m1 box, reference bounds and path. --omega-r keeps
    the file's gains out. A --cart other than the design's runs the gains on that cart with the cart's own sensing,
    actuation and play; it, and an --m1-range beyond the design's box, print one note naming both.

    Raises:
        ParameterError: --design with --preset, a file that is not a design file, a design found on a cart
            file that is no longer there (and no --cart given).
    """
    if args.preset is not None:
        raise ParameterError("give --design FILE or --preset, not both (a design file is a preset of its own)")
    if getattr(args, "design_applied", None) == args.design:
        return args  # read once: a command that builds its config twice reads the same options
    data = read_design(args.design)
    settings = design_file_settings(args.design, data)
    found_on = design_file_box(args.design, data)
    notes = []
    if hasattr(args, "cart"):  # the cart the design was found on, unless --cart names one
        given = args.cart
        settings["cart"] = design_cart(args.design, given, data=data)
        if given is not None and not _same_cart(given, data.get("cart")):
            notes.append(f"--cart {given} is not the cart the design {args.design} was found on "
                         f"({design_cart_name(args.design, data)}): its gains run on {given} with that cart's own "
                         "sensing, actuation, play, m1 box and path")
            for name in ("sensing", "actuation", "backlash"):
                settings.pop(name)
            found_on.pop("m1_range", None)
            found_on.pop("path", None)  # the design's path may be one the given cart cannot steer
    if args.omega_r is not None:
        settings.pop("kp"), settings.pop("kd")
    for name, value in settings.items():
        if getattr(args, name, None) is None:
            setattr(args, name, value)
    box = found_on.get("m1_range")
    given_box = getattr(args, "m1_range", M1_RANGE)
    if box is not None and hasattr(args, "m1_range"):
        if given_box is M1_RANGE:  # --m1-range not given: the design's box
            args.m1_range = box
        elif not box[0] <= float(given_box[0]) <= float(given_box[1]) <= box[1]:
            notes.append(f"--m1-range {float(given_box[0]):g} {float(given_box[1]):g} goes beyond the m1 box the "
                         f"design {args.design} was found on ({box[0]:g}-{box[1]:g} kg): its certificate is "
                         "computed again on the box given")
    if getattr(args, "uncertainty", "given") is None and not getattr(args, "range", None) and "box_ranges" in found_on:
        args.uncertainty = _box_name(found_on["box_ranges"], args.cart)  # the design's box (None: no such box)
    if getattr(args, "reference_bounds", None) is None and "reference_bounds" in found_on:
        args.reference_bounds = found_on["reference_bounds"]
    if getattr(args, "path", None) is None and "path" in found_on:
        args.path = found_on["path"]
    for note in notes:
        print(f"wmr-mj: note: {note}", file=sys.stderr)
    args.design_applied = args.design
    return args


def default_path_note_of(args: argparse.Namespace, config: Any) -> str | None:
    """The line naming the config's path where it is the default derived from the cart's stops (no --path given,
    none from a design; :func:`wmr_mj.reference.named.default_path_note`); None otherwise."""
    if getattr(args, "path", None) is not None:
        return None
    cart = cart_file_of_record(config.cart)
    return default_path_note(cart) if config.path == default_path(cart) else None


def _box_name(ranges: dict[str, tuple[float, float]], cart: Any) -> str | None:
    """The name of the cart's uncertainty box (--uncertainty NAME) whose ranges besides m1 are ``ranges`` (a design
    file's box_ranges); None where no box of the cart is that."""
    if cart is not None:
        boxes = {name: dict(box) for name, box in load_cart(cart).uncertainty.items()}
    else:
        boxes = {name: uncertainty_ranges(name) for name in ("m1", "full")}
    for name, box in boxes.items():
        if {k: tuple(v) for k, v in box.items() if k != "m1"} == {k: tuple(v) for k, v in ranges.items()}:
            return name
    return None


def _same_cart(given: Any, recorded: Any) -> bool:
    """Whether the cart ``given`` (--cart) is the one a design file records (None: the C80): the same text, or
    both the C80's numbers."""
    record = RunConfig.from_inputs(cart=given).cart
    if record is None or not isinstance(recorded, dict):
        return record is None and not isinstance(recorded, dict)
    return record["text"] == recorded.get("text")


def requirements_from_args(args: argparse.Namespace, period: float) -> list:
    """The --require requirements, each checked (syntax, signal names, time bounds) before any run."""
    return [parse_requirement(text, period=period) for text in getattr(args, "require", None) or []]


def format_requirements(results: list[dict]) -> list[str]:
    """One line per requirement: formula, robustness, whether it holds."""
    lines = []
    for r in results:
        rob = r["robustness"]
        status = "no region" if rob is None else ("holds" if r["satisfied"] else "VIOLATED")
        rob_text = "n/a" if rob is None else f"{rob:+.5g}"
        name = r["formula"] if "requirement" not in r or r["formula"] == r["requirement"] else \
            f"{r['requirement']} = {r['formula']}"
        lines.append(f"requirement {name}: robustness {rob_text} ({status})"
                     + (f"  [{r['note']}]" if r.get("note") else ""))
    return lines


def _key_values(option: str, text: str) -> dict:
    """'k=v,k=v' -> {k: v}, numbers as numbers (seed an integer), kind as text."""
    out: dict = {}
    for item in text.split(","):
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not key or not value:
            raise ParameterError(f"{option} {text!r}: expected KEY=VALUE pairs separated by commas")
        if key == "kind":
            out[key] = value
            continue
        try:
            out[key] = int(value) if key == "seed" else float(value)
        except ValueError:
            raise ParameterError(f"{option} {text!r}: {key} = {value!r} is not a number") from None
    return out


def signals_from_args(args: argparse.Namespace):
    """The run's Signals from --signals, --disturbance, --load, --d-max (None without any)."""
    data: dict = {}
    if getattr(args, "signals", None):
        s = signals_from(args.signals)
        data = {} if s is None else s.to_dict()
    if getattr(args, "disturbance", None):
        if "disturbance" in data:
            raise ParameterError("give the disturbance by --signals or by --disturbance, not both")
        data["disturbance"] = _key_values("--disturbance", args.disturbance)
    if getattr(args, "load", None):
        if "loads" in data:
            raise ParameterError("give the loads by --signals or by --load, not both")
        data["loads"] = [{"kind": "step", **_key_values("--load", text)} for text in args.load]
    if getattr(args, "d_max", None) is not None:
        data["d_max"] = args.d_max
    return signals_from(data) if data else None


def default_log_path(config) -> str:
    """logs/run-<time>-<model>-m<m1>.mcap for a RunConfig or the run command's arguments."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    return f"logs/run-{stamp}-{config.model}-m{config.m1:g}.mcap"


def format_report(s: RunSummary, *, measurement: Any = None, cart: str | None = None) -> str:
    """Human-readable run report of the summary ``s`` (``measurement``: as :func:`measurement_cause` takes it).
    ``cart``: the name of the cart the run is on where it is not the paper's C80 (None: the C80): the paper's claim,
    which the paper makes for its C80 only, is then not printed (its numbers stay in --json, as the paper's)."""
    def ratio(x):
        return "n/a" if x is None else f"{x:.3f}"

    def num(x):
        return "n/a" if x is None else f"{x:.5g}"

    cert = s.certificate
    cert_E_max, cert_Edot_max = (None, None) if cert is None else (cert.E_max, cert.Edot_max)
    cert_E_ratio, cert_Edot_ratio = (None, None) if cert is None else (cert.E_ratio, cert.Edot_ratio)

    after = f"after {s.settle_s:.1f} s"
    if s.paper_law:
        who = f"controller {s.controller} ({s.model} model), plant m1 = {s.m1:g} kg, K_P = {s.kp:g}, K_D = {s.kd:g}"
    else:
        params = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                           for k, v in (s.controller_config or {}).items()
                           if k != "controller" and not isinstance(v, (dict, list)))
        who = f"controller {s.controller} ({params or 'no parameters'}), plant m1 = {s.m1:g} kg"
    rate = "" if s.realtime_factor is None else f" ({s.realtime_factor:.0f}x real time)"
    # a run that ended before the entry transient did has no samples after it: n/a, not the empty sup's 0
    settled = s.duration > s.settle_s
    paper_columns = s.paper_law and cart is None  # the paper's claim: the C80's, printed on the C80 only
    paper = (lambda bound, r: f" {bound:12.5g} {ratio(r):>8s}") if paper_columns else (lambda bound, r: "")
    verdict = format_verdict(s.to_dict())
    if cart is not None:  # the paper's claim is the C80's: never printed as if it were this cart's
        verdict = [line for line in verdict if not line.startswith("paper's claim:")]
    cause = measurement_cause(s, measurement)
    if cause is not None:  # beside the certificate's line: what it assumed the law reads, and what binds
        at = next((i + 1 for i, line in enumerate(verdict) if line.startswith("certificate:")), len(verdict))
        verdict.insert(at, format_measurement_cause(cause))
    lines = [
        f"{who}, {s.duration:g} s, {s.steps} steps in {s.wall_s:.2f} s{rate}",
        *verdict,
        f"{'':22s} {'whole run':>12s} {after:>12s} {'certificate':>12s} {'ratio':>8s}"
        + (f" {'paper':>12s} {'ratio':>8s}" if paper_columns else ""),
        f"{'sup|E|   [rad]':22s} {s.sup_E:12.5g} {num(s.sup_E_settled if settled else None):>12s} "
        f"{num(cert_E_max):>12s} {ratio(cert_E_ratio):>8s}" + paper(s.E_max, s.E_ratio),
        f"{'sup|E|dot [rad/s]':22s} {s.sup_Edot:12.5g} {num(s.sup_Edot_settled if settled else None):>12s} "
        f"{num(cert_Edot_max):>12s} {ratio(cert_Edot_ratio):>8s}" + paper(s.Edot_max, s.Edot_ratio),
        f"voltage saturated {100 * s.saturated_fraction:.1f}% of the time",
    ]
    return "\n".join(lines + _after_the_table(s))


def _after_the_table(s: RunSummary) -> list[str]:
    """The lines of a run's report below its table: MuJoCo's warnings, C's path and its verdict, a route not
    finished, the steering's stop, a run that did not complete (none where nothing of these happened)."""
    lines = []
    cert = s.certificate
    if s.mujoco_warnings:  # counted over the run and said once here (MuJoCo's console printing is held)
        said = next((a.note for a in (cert.assumptions if cert is not None else ())
                     if a.name == MUJOCO_WITHOUT_WARNINGS), "")
        lines.append(f"MuJoCo warned {s.mujoco_warnings} time(s) during the run; the run is not certified "
                     f"(its steps MuJoCo warned of are not the plant the claim is of){': ' + said if said else ''}")
    if s.path_error is not None:
        pe = s.path_error
        lines.append(f"path of C: cross-track max {pe.cross_track_max:.4g} m, rms {pe.cross_track_rms:.4g} m; "
                     f"along-track at the end {pe.along_track_final:+.4g} m; heading error max "
                     f"{pe.heading_error_max:.4g} rad")
    if s.path_verdict is not None:
        lines.append(f"path verdict: {s.path_verdict.verdict} ({s.path_verdict.text})")
    if s.route is not None and not s.route.finished:
        lines.append(f"route not finished: its reference covers {s.route.driven_m:.4g} m of the route's "
                     f"{s.route.length_m:.4g} m in {s.duration:g} s")
    if s.left_steering_range:
        lines.append(f"the steering reached its stop (+-range) at t = {s.left_steering_range_at_s:.3f} s")
    if s.status != "completed":
        lines.append(f"run {s.status}: report covers the simulated part only")
    return lines


def _law_note(result: Any, config: Any) -> str | None:
    """The stderr line on which law ran: the Python law's fallback, or a plug-in's compiled or Python path."""
    plugin = plugin_source(config) is not None
    if result.law_note:
        if not plugin:
            return f"the Python law ran ({result.law_note}); the numbers are the same, the run slower"
        return f"controller {result.summary.controller!r} runs {law_path(result.law)} ({result.law_note})"
    if result.law == "compiled" and plugin:  # a plug-in in the callback: its pure law function, compiled
        return (f"controller {result.summary.controller!r} compiled by numba into MuJoCo's control "
                "callback, no Python per control step")
    return None


def _print_text(result: Any, parts: Any, report: dict[str, Any], path: str | None) -> None:
    """The run's report as text (``--json`` prints ``report`` instead)."""
    config = result.config
    record = parts.config.cart  # None: the C80
    print(format_report(result.summary, measurement=parts.measurement,
                        cart=None if record is None else f"{record['name']} {record['version']}"))
    if not is_ideal_cart(config):
        print(cart_line(config))
    if report.get("requirements"):
        print("\n".join(format_requirements(report["requirements"])))
    if config.signals is not None:
        print(f"signals: {json.dumps(report['signals'], separators=(',', ':'))}")
        print(f"reproduce: add --signals '{json.dumps(report['signals'], separators=(',', ':'))}'")
    if path:
        print(f"log: {path}")


def run(args: argparse.Namespace) -> int:
    # refuse what cannot work before anything runs (an identification for --model identified)
    require_run_memory(duration_s=args.duration, control_period_s=args.control_period or TIMESTEP)
    path = None
    if not args.no_log:
        path = args.out or default_log_path(args)
        check_output_path(path, kind="file", option="--out")
    config = config_from_args(args, m1=args.m1)
    period = args.control_period or TIMESTEP
    requirements = requirements_from_args(args, period)
    factory = None
    if path is not None:
        factory = functools.partial(RunLogger, path, options=LogOptions(log_every=args.log_every, background=True))
    parts = resolve_run(config)  # the run's law, reference and claim, built once
    for note in (default_path_note_of(args, config), no_estimate_note(parts)):
        if note:
            print(f"wmr-mj: note: {note}", file=sys.stderr)
    with terminate_as_interrupt():
        result = run_parts(parts, logger_factory=factory, progress=args.progress)
    law_note = _law_note(result, config)
    if law_note:
        print(f"wmr-mj: {law_note}", file=sys.stderr)
    if result.summary.failure is not None:
        print(f"wmr-mj: the run failed: {result.summary.failure}", file=sys.stderr)
    report = result.to_dict(measurement=parts.measurement, log=path, requirements=requirements, period=period)
    if args.json:
        print_json(report)
    else:
        _print_text(result, parts, report, path)
    if result.status == "interrupted":
        print("wmr-mj: interrupted; the log holds what was simulated", file=sys.stderr)
        return 130
    if result.status == "failed":
        return 1  # the law failed mid-run: the report and the log hold what ran before it
    return CLAIM_BROKEN_EXIT if result.summary.verdict == CERTIFIED_OUTSIDE else 0
