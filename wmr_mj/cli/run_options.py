"""The run options, declared once: each one's flag, argparse settings, help, the RunConfig field it sets and how
that field is written back as the option.

The table (:func:`run_options`) drives both ways:

* argparse: :func:`add_options` adds a group of rows (``wmr-mj run``'s options, the cart's, the signals', the
  requirement) to a command's parser, as the command's table (:mod:`wmr_mj.cli.command_options`) names them; a row
  a command words its own way is :func:`run_option`'s, with the command's help (:meth:`RunOption.with_help`);
* the reproduce line: :func:`wmr_mj.cli.falsify.command_line` writes a RunConfig back as the ``wmr-mj run`` line
  that builds it,
  each row writing its own field (``wmr-mj falsify``'s reproduce line), so a field read by one row's parser is
  written by the same row, and a test parses the line back into an equal config (``tests/test_spine2.py``).

Usage::

    from wmr_mj.cli.falsify import command_line
    from wmr_mj.cli.run_options import Replay
    command_line(config, Replay(preset="certified", law_settings=parts.law_settings))
"""

from __future__ import annotations

import argparse
import functools
import json
import shlex
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from wmr_mj.cli.options import Option, names_in, positive_float
from wmr_mj.hardware.spec import spec_string
from wmr_mj.params import M1_NOMINAL, M1_RANGE, UNCERTAINTY_NAMES, uncertainty_ranges

__all__ = ["RunOption", "Replay", "run_options", "run_option", "add_options", "GROUPS", "SECTIONS"]

#: --duration's default, s: the very object argparse keeps where --duration is not given (a message about the
#: duration then says that it is the default: wmr_mj.cli.app)
DEFAULT_DURATION = 35.0


@dataclass(frozen=True, kw_only=True)
class Replay:
    """What a reproduce line needs beside the RunConfig: what the config does not record.

    Attributes:
        preset: the design the law options were merged with (None: paper), which gives the fields the law does
            not read (those the line does not write).
        law_settings: the RunConfig settings the law reads (``RunParts.law_settings``): only those law options
            are written (another one is refused by ``wmr-mj run``).
        path_file: a file holding the run's path (a searched path's canonical route), written in its place.
        signals_file: a file holding the run's signals, written in their place.
        require: the requirements (STL) the run is judged by.
    """

    preset: str | None = None
    law_settings: frozenset[str] = frozenset()
    path_file: str | None = None
    signals_file: str | None = None
    require: tuple[str, ...] = ()


def _nothing(config: Any, replay: Replay) -> list[str]:
    return []


@dataclass(frozen=True, kw_only=True)
class RunOption(Option):
    """One run option: an :class:`~wmr_mj.cli.options.Option` (flag, argparse settings, help) that sets a RunConfig
    field and writes it back.

    Attributes:
        group: which group of rows it is added with (:data:`GROUPS`): 'run', 'cart', 'signals', 'require', or
            'command' (each command adds it from its own table, with its own help: ``--m1``, ``--range``).
        sets: the RunConfig field it sets ('' where it sets none directly: ``--preset``, ``--omega-r``).
        write: ``write(config, replay)``: the words that give ``config``'s field back ([] where nothing needs
            writing: a default, an option another row writes, the same field written by another row).
    """

    group: str
    sets: str
    write: Callable[[Any, Replay], list[str]] = _nothing


#: the groups of the table's rows (:attr:`RunOption.group`)
GROUPS = ("run", "cart", "signals", "require", "command")

#: the groups a help page shows under a heading of their own (an argparse argument group), by group
SECTIONS = {
    "cart": "the cart as it is built (wmr_mj/hardware; default ideal: the exact alpha and alpha', no delay, no "
            "inductance, no play); shown in every summary and JSON where not ideal",
    "signals": "signals on the plant during the run (wmr_mj/sim/signals.py); reported under 'signals' in --json, "
               "which --signals takes back to reproduce the run to the bit",
}


def _law(name: str) -> Callable[[Any, Replay], list[str]]:
    """The writer of a law option: written only where the law reads the setting (``Replay.law_settings``)."""

    def write(config: Any, replay: Replay) -> list[str]:
        if name not in replay.law_settings:
            return []
        value = getattr(config, name)
        return [f"--{name.replace('_', '-')}", repr(value) if isinstance(value, float) else str(value)]

    return write


def _each(flag: str, pairs: Callable[[Any], Mapping[str, Any]], text: Callable[[Any], str] = repr):
    """The writer of a repeatable NAME=VALUE option: one per pair of ``pairs(config)``."""

    def write(config: Any, replay: Replay) -> list[str]:
        return [w for name, value in (pairs(config) or {}).items()
                for w in (flag, shlex.quote(f"{name}={text(value)}"))]

    return write


def _uncertainty_box(config: Any) -> tuple[str, dict[str, tuple[float, float]]]:
    """The --uncertainty box and the --range items that give ``config.box_ranges`` back: the named box whose
    ranges (besides m1, which is --m1-range) all stay in it, with the fewest items to add or replace."""
    best: tuple[str, dict[str, tuple[float, float]]] | None = None
    ranges = {k: tuple(v) for k, v in config.box_ranges.items()}
    for name in UNCERTAINTY_NAMES:
        box = {k: v for k, v in uncertainty_ranges(name).items() if k != "m1"}
        if not set(box) <= set(ranges):
            continue  # --range adds or replaces; it cannot remove a range of the box
        extra = {k: v for k, v in ranges.items() if box.get(k) != v}
        if best is None or len(extra) < len(best[1]):
            best = (name, extra)
    assert best is not None  # the 'm1' box has no range besides m1: it always fits
    return best


def _write_uncertainty(config: Any, replay: Replay) -> list[str]:
    return ["--uncertainty", _uncertainty_box(config)[0]]


def _write_ranges(config: Any, replay: Replay) -> list[str]:
    return [w for name, (lo, hi) in _uncertainty_box(config)[1].items()
            for w in ("--range", shlex.quote(f"{name}={lo!r}:{hi!r}"))]


def _write_part(option: str, part: str) -> Callable[[Any, Replay], list[str]]:
    """The writer of --sensing or --actuation: every field of the part, at full precision, where not ideal."""

    def write(config: Any, replay: Replay) -> list[str]:
        value = getattr(config, part)
        if value.is_ideal:
            return []
        spec = {k: repr(v) if isinstance(v, float) else v for k, v in value.to_dict().items()}
        return [option, shlex.quote(spec_string(spec))]

    return write


def _if(condition: Callable[[Any, Replay], bool], words: Callable[[Any, Replay], list[str]]):
    return lambda config, replay: words(config, replay) if condition(config, replay) else []


@functools.cache
def run_options() -> tuple[RunOption, ...]:
    """The run options, in the order the reproduce line writes them (and the help lists them): the law and the
    run's length, then the plant and its analysis box, then the outer loop, the signals and the cart."""
    return _law_rows() + _plant_rows() + _outer_signal_and_cart_rows()


def _law_rows() -> tuple[RunOption, ...]:
    R = RunOption
    return (
        R(flag="--preset", group="run", sets="", settings=dict(default=None), help=_preset_help,
          write=_if(lambda c, r: r.preset is not None, lambda c, r: ["--preset", str(r.preset)])),
        # its settings are written by their own rows (the law's, --control-period, the cart's): read, never written
        R(flag="--design", group="run", sets="", settings=dict(default=None, metavar="FILE"),
          help="a design file written by `wmr-mj design --out FILE`: its law, gains, control period and cart "
               "(sensing, actuation, backlash) merged like a preset; explicit options override it"),
        R(flag="--controller", group="run", sets="controller",
          settings=dict(default=None, metavar="NAME|FILE.py:Class|module:Class"), help=_controller_help,
          write=lambda c, r: ["--controller", shlex.quote(str(c.controller))]),
        R(flag="--model", group="run", sets="model", settings=dict(default=None), help=_model_help,
          write=_law("model")),
        R(flag="--kp", group="run", sets="kp", settings=dict(type=positive_float, default=None),
          help="K_P, 1/s^2 (default: the preset's)", write=_law("kp")),
        R(flag="--kd", group="run", sets="kd", settings=dict(type=positive_float, default=None),
          help="K_D, 1/s (default: the preset's)", write=_law("kd")),
        R(flag="--friction-sign", group="run", sets="friction_sign", settings=dict(default=None),
          help=_friction_sign_help, write=_law("friction_sign")),
        R(flag="--friction-width", group="run", sets="friction_width", settings=dict(type=float, default=None),
          help="smoothing of that sign, rad/s: x/sqrt(x^2+w^2) (0: exact sign; default: the preset's)",
          write=_law("friction_width")),
        R(flag="--path", group="run", sets="path", settings=dict(default=None, metavar="NAME|FILE"),
          help=_path_help, write=lambda c, r: ["--path", shlex.quote(r.path_file or c.path)]),
        R(flag="--duration", group="run", sets="duration", settings=dict(type=positive_float, default=DEFAULT_DURATION),
          help="simulated time, s (default 35)", write=lambda c, r: ["--duration", repr(c.duration)]),
        R(flag="--m1", group="command", sets="m1", settings=dict(type=positive_float, default=M1_NOMINAL),
          write=lambda c, r: ["--m1", repr(c.m1)]),
        R(flag="--identified", group="run", sets="identified", settings=dict(metavar="PATH"),
          help="JSON from `wmr-mj identify --out` for --model identified (default: identify the nominal plant now)",
          write=_if(lambda c, r: isinstance(c.identified, str),
                    lambda c, r: ["--identified", shlex.quote(c.identified)])),
        R(flag="--coef", group="run", sets="coefficients", settings=dict(action="append", metavar="NAME=VALUE"),
          help="coefficient for --model explicit (P, C_V, F, K, gyro)",
          write=_each("--coef", lambda c: c.coefficients)),
        R(flag="--control-period", group="run", sets="control_period",
          settings=dict(type=positive_float, default=None),
          help="controller period, s, a multiple of the 1 ms physics step (default: every step)",
          write=_if(lambda c, r: c.control_period is not None,
                    lambda c, r: ["--control-period", repr(c.control_period)])),
        R(flag="--param", group="run", sets="plant_overrides", settings=dict(action="append", metavar="NAME=VALUE"),
          help="override a plant parameter (repeatable)", write=_each("--param", lambda c: c.plant_overrides)),
    )


def _plant_rows() -> tuple[RunOption, ...]:
    R = RunOption
    return (
        R(flag="--steering-friction", group="run", sets="steering_friction", settings=dict(default="stiction"),
          help=_steering_friction_help, write=lambda c, r: ["--steering-friction", c.steering_friction]),
        R(flag="--tyre-contact", group="run", sets="tyre_contact", settings=dict(default="stiff"),
          help=_tyre_contact_help, write=lambda c, r: ["--tyre-contact", c.tyre_contact]),
        R(flag="--require", group="require", sets="", settings=dict(action="append", metavar="STL"),
          help=_require_help, write=lambda c, r: [w for text in r.require for w in ("--require", shlex.quote(text))]),
        R(flag="--m1-inertia", group="run", sets="m1_inertia",
          settings=dict(default="payload", choices=("payload", "scale")),
          help="m1 changes as a compact payload at the CoM (default) or scales the chassis inertia",
          write=lambda c, r: ["--m1-inertia", c.m1_inertia]),
        R(flag="--box", group="run", sets="box", settings=dict(default="derived"),
          help="parameter box of the analysis: derived (from the parameter set over --m1-range) or paper (5.1)",
          write=lambda c, r: ["--box", c.box]),
        R(flag="--m1-range", group="run", sets="m1_range",
          settings=dict(nargs=2, type=positive_float, metavar=("LO", "HI"), default=M1_RANGE),
          help="m1 range of the analysis box, kg (default: the cart's m1 box, 550 750 on the C80)",
          write=lambda c, r: ["--m1-range", repr(c.m1_range[0]), repr(c.m1_range[1])]),
        R(flag="--uncertainty", group="run", sets="box_ranges", settings=dict(default=None), help=_uncertainty_help,
          write=_write_uncertainty),
        R(flag="--range", group="command", sets="box_ranges", settings=dict(action="append", metavar="NAME=LO:HI"),
          write=_write_ranges),
    )


def _outer_signal_and_cart_rows() -> tuple[RunOption, ...]:
    R = RunOption
    return (
        R(flag="--correction", group="run", sets="correction", settings=dict(action="store_true"),
          help="Cartesian correction: an outer loop at C (Stanley-like, from C's cross-track and heading errors) "
               "corrects alpha0 within declared rate and acceleration limits, which the certificate then assumes "
               "(controllers/tracking.py)",
          write=_if(lambda c, r: bool(c.correction), lambda c, r: ["--correction"])),
        R(flag="--controller-param", group="run", sets="controller_params",
          settings=dict(action="append", metavar="NAME=VALUE", default=None),
          help="a parameter of a --controller given by name or file (repeatable; VALUE read as JSON where it "
               "parses, e.g. lam=5, else as text)",
          write=_each("--controller-param", lambda c: c.controller_params, json.dumps)),
        R(flag="--tracker", group="run", sets="tracker",
          settings=dict(default=None, metavar="NAME|FILE.py:Class|module:Class"), help=_tracker_help,
          write=_if(lambda c, r: isinstance(c.tracker, str), lambda c, r: ["--tracker", shlex.quote(c.tracker)])),
        R(flag="--tracker-param", group="run", sets="tracker_params",
          settings=dict(action="append", metavar="NAME=VALUE", default=None),
          help="a parameter of the --tracker (repeatable)",
          write=_each("--tracker-param", lambda c: c.tracker_params, json.dumps)),
        R(flag="--signals", group="signals", sets="signals", settings=dict(metavar="FILE|JSON"),
          help="a .json file or JSON text: {\"disturbance\": {...}, \"d_max\": N m, \"loads\": [...]}",
          write=_if(lambda c, r: c.signals is not None, lambda c, r: [
              "--signals", shlex.quote(r.signals_file or json.dumps(c.signals.to_dict()))])),
        R(flag="--reference-bounds", group="run", sets="reference_bounds",
          settings=dict(metavar="paper|KEY=VALUE,...", default=None), help=_reference_bounds_help,
          write=_if(lambda c, r: c.reference_bounds is not None, lambda c, r: [
              "--reference-bounds", ",".join(f"{k}={v!r}" for k, v in c.reference_bounds.to_dict().items())])),
        R(flag="--sensing", group="cart", sets="sensing", settings=dict(metavar="KEY=VALUE,...|PRESET|FILE",
                                                                          default=None),
          help=_sensing_help, write=_write_part("--sensing", "sensing")),
        R(flag="--actuation", group="cart", sets="actuation",
          settings=dict(metavar="KEY=VALUE,...|FILE", default=None),
          help="the motor's actuation: delay (s, whole 1 ms physics steps), inductance (H), current_limit (A), e.g. "
               "delay=0.002,inductance=0.0005,current_limit=20, or a .json/.toml file",
          write=_write_part("--actuation", "actuation")),
        R(flag="--backlash", group="cart", sets="transmission", settings=dict(metavar="RAD", default=None),
          help="the gear's play: half-width b >= 0, rad at the steering axis (e.g. 0.002)",
          write=_if(lambda c, r: not c.transmission.is_ideal,
                    lambda c, r: ["--backlash", repr(c.transmission.backlash)])),
        R(flag="--cart", group="cart", sets="cart", settings=dict(metavar="FILE|NAME", default=None),
          help=_cart_help, write=_if(lambda c, r: c.cart is not None,
                                     lambda c, r: ["--cart", shlex.quote(c.cart["path"])])),
        # written as kp and kd, or within --signals: read, never written
        R(flag="--omega-r", group="run", sets="", settings=dict(type=positive_float, default=None),
          help="gains by (3.6): K_P = omega_r^2/4, K_D = omega_r"),
        R(flag="--disturbance", group="signals", sets="signals", settings=dict(metavar="KEY=VALUE,..."),
          help="torque on the steering joint, N m: kind=constant|step|pulse|noise,amplitude=A [,t1=S][,t2=S]"
               "[,bandwidth=HZ,seed=N for noise], e.g. kind=step,amplitude=1,t1=5"),
        R(flag="--load", group="signals", sets="signals", settings=dict(action="append", metavar="KEY=VALUE,..."),
          help="chassis mass change (repeatable, in time order): t=S,m1=KG (a step) or "
               "kind=ramp,t1=S,t2=S,m1=KG[,every=S]"),
        R(flag="--d-max", group="signals", sets="signals", settings=dict(type=float, default=None, metavar="NM"),
          help="disturbance bound the certificate declares, N m (default: the disturbance's amplitude)"),
    )


def add_options(p: argparse.ArgumentParser | Any, group: str) -> None:
    """Add the rows of ``group`` (:data:`GROUPS`) to the parser ``p``, in the table's order: under their heading
    where the group has one (:data:`SECTIONS`)."""
    where = p.add_argument_group(SECTIONS[group]) if group in SECTIONS else p
    for row in run_options():
        if row.group == group:
            row.add_to(where)


def run_option(flag: str) -> RunOption:
    """The row of ``flag`` (``run_option("--cart")``): a command adds it alone, or words it its own way
    (:meth:`RunOption.with_help`)."""
    return next(r for r in run_options() if r.flag == flag)


def _preset_help() -> str:
    return (f"controller design: one of {names_in('wmr_mj.sim.designs', 'PRESET_NAMES')} (default paper: paper "
            "model, K_P = 6, K_D = 9, exact sign; certified: see wmr_mj/sim/designs.py); explicit options override "
            "it. With --controller and no --preset, the law's estimate is its own default model (as "
            "RunConfig(controller=NAME) and wmr-mj compare NAME: non-holonomic for sliding-mode)")


def _controller_help() -> str:
    return (f"the steering law: one of {names_in('controllers.registry', 'controller_names')}, a class in a file of "
            "your own (FILE.py:Class), or of an importable module (module:Class) (default: the preset's; see "
            "controllers/base.py)")


def _tracker_help() -> str:
    return ("a path tracker, the outer loop on C that writes alpha0: one of "
            f"{names_in('controllers.registry', 'tracker_names')}, "
            "FILE.py:Class or module:Class (default: none, the path's own alpha0; see controllers/tracking.py)")


def _model_help() -> str:
    return (f"model source of the estimate: one of {names_in('controllers.computed_torque', 'MODEL_SOURCES')} "
            "(default: the preset's)")


def _friction_sign_help() -> str:
    return (f"Coulomb compensation sign: one of {names_in('controllers.computed_torque', 'FRICTION_SIGNS')} "
            "(default: the preset's)")


def _path_help() -> str:
    return (f"reference path of point C: one of {names_in('wmr_mj.sim.config', 'PATH_NAMES')}, a packaged route "
            "(agv-loop), or a route file (.toml/.json: segments or waypoints; see wmr_mj/reference/route.py); "
            "default: the --design file's path, else the cart's own ([paths] default in its file), else "
            "paper-circle where the cart steers it within 85%% of its stops, else a loop of turns it steers")


def _steering_friction_help() -> str:
    return (f"plant's steering friction law: one of {names_in('wmr_mj.plant.mjcf', 'STEERING_FRICTION_MODELS')} "
            "(default stiction: holds below break-away; soft: MuJoCo's default frictionloss, creeps at mrad/s)")


def _tyre_contact_help() -> str:
    return (f"plant's tyre-floor contacts: one of {names_in('wmr_mj.plant.mjcf', 'TYRE_CONTACT_MODELS')} (default "
            "stiff; soft: MuJoCo's default solref, see models/README.md)")


def _uncertainty_help() -> str:
    return (f"uncertainty box: one of {', '.join(UNCERTAINTY_NAMES)} (m1: the paper's 550-750 kg, the default of run "
            "and sweep; full: also steering and tyre friction, R_a and V_A, the default of falsify; sources in "
            "wmr_mj/params.py). A run draws nothing: the box is what its analysis covers; m1's range is --m1-range")


def _reference_bounds_help() -> str:
    return ("declared bounds on the reference alpha0: 'paper' ((5.1): alpha0' 0.23 rad/s, alpha0'' 0.4 rad/s^2, "
            "sin/cos^3 1.24) or alpha_dot_max=..,alpha_ddot_max=..,alpha_max=.. (others: the paper's). The "
            "certificate then covers every reference within them, and the run's own reference is checked against "
            "them (default: the certificate is for this path alone)")


def _sensing_help() -> str:
    return ("the steering sensor between the plant and the law: a preset "
            f"({names_in('wmr_mj.hardware', 'sensing_preset_names')}), KEY=VALUE pairs "
            f"({names_in('wmr_mj.hardware', 'SENSING_SPEC_KEYS')}, preset; e.g. "
            "encoder_ticks=4096,velocity=difference,delay=0.005,noise=uniform:0.0005,seed=3; the delay a whole number "
            "of control periods) or a .json/.toml file of the same")


def _cart_help() -> str:
    return ("the cart: a cart file (.toml, see wmr_mj/carts/c80.toml and docs/reference/cart.md) or a shipped cart "
            f"({names_in('wmr_mj.carts', 'cart_names')}); it gives the parameter set, the m1 box, the supply and "
            "stops, the default sensing, actuation and play, and the certified preset's gains (its rule run on the "
            "cart) (default: c80)")


def _require_help() -> str:
    return ("a requirement in Signal Temporal Logic, monitored by rtamt on the run's signals "
            f"({names_in('wmr_mj.analysis.requirements', 'SIGNALS')}; time bounds in s), e.g. "
            "'always[8,35](abs(E) <= 0.05)', or a preset: "
            f"{names_in('wmr_mj.analysis.requirements', 'PRESETS')} (the certificate's or the paper's |E|, |E'| "
            "bounds for the whole run); repeatable. Its robustness (> 0: held with that margin) is reported")
