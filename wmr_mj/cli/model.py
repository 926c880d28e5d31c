"""``wmr-mj model``: write or check models/c80.xml and models/scene.xml, render models/c80.png, write the model
card, or print a parameter table."""

from __future__ import annotations

import argparse
from typing import Any

from wmr_mj._util.files import write_text_atomic
from wmr_mj._util.resources import MODELS_IN_CHECKOUT
from wmr_mj.carts import load_cart
from wmr_mj.cli._common import cart_parameters, parse_assignments, print_json
from wmr_mj.errors import ParameterError
from wmr_mj.params import COEFFICIENT_NAMES, PARAMETER_SOURCES, check_motor_constant, with_params
from wmr_mj.plant.friction import measure_friction_law
from wmr_mj.plant.image import write_model_image
from wmr_mj.plant.mjcf import (
    MODELS_DIR,
    STEERING_FRICTION_MODELS,
    measure_side_slip,
    robot_xml,
    scene_file_xml,
    write_model_files,
)
from wmr_mj.plant.modelcard import render_model_card


def run(args: argparse.Namespace) -> int:
    if getattr(args, "cart", None) is not None and args.action in ("write", "check", "card", "image"):
        raise ParameterError(f"model {args.action} is for the C80's files in models/; it takes no --cart (a cart's "
                             "model card: wmr-mj cart card FILE); accepted with --cart: params, slip, friction")
    overrides = parse_assignments(args.param)
    params = with_params(cart_parameters(args), **overrides)
    if "k_i" in overrides or "k_b" in overrides:
        check_motor_constant(params.k_i, params.k_b)
    if args.action == "write":
        for path in write_model_files(params):
            print(f"wrote {path}")
        return 0
    action = {"check": _check, "card": _card, "image": _image, "friction": _friction, "slip": _slip}.get(
        args.action, _params)
    return action(args, params)


def _check(args: argparse.Namespace, params: Any) -> int:
    """model check: are models/c80.xml and scene.xml those of the parameter set?"""
    stale = [name for name, text in (("c80.xml", robot_xml(params)), ("scene.xml", scene_file_xml(params)))
             if not (MODELS_DIR / name).is_file() or (MODELS_DIR / name).read_text() != text]
    where = f"{MODELS_DIR} ({'checkout' if MODELS_IN_CHECKOUT else 'copy installed with the package'})"
    if stale:
        print(f"out of date in {where}: {', '.join(stale)} (run: wmr-mj model write)")
        return 1
    print(f"c80.xml and scene.xml in {where} match the parameter set")
    return 0


def _card(args: argparse.Namespace, params: Any) -> int:
    """model card: models/README.md."""
    path = write_text_atomic(MODELS_DIR / "README.md", render_model_card(params))
    print(f"wrote {path}")
    return 0


def _image(args: argparse.Namespace, params: Any) -> int:
    """model image: the C80's picture in models/."""
    if args.param:
        raise ParameterError("model image renders the C80 parameter set of models/; it takes no --param")
    print(f"wrote {write_model_image(MODELS_DIR)}")
    return 0


def _friction(args: argparse.Namespace, params: Any) -> int:
    """model friction: each steering friction law measured on the plant."""
    laws = {name: measure_friction_law(params, steering_friction=name) for name in STEERING_FRICTION_MODELS}
    if args.json:
        print_json({name: law.to_dict() for name, law in laws.items()})
        return 0
    any_law = laws["stiction"]
    print(f"steering friction: F = {any_law.friction_voltage:.5g} V "
          f"({any_law.friction_torque:.5g} N m at the joint); constant voltage from the home keyframe, "
          f"cart driving, rate over the last second of {any_law.duration:g} s; "
          f"holds = rate <= {any_law.hold_rate:g} rad/s")
    for name, law in laws.items():
        lo = law.breakaway_voltage - law.breakaway_resolution
        print(f"  {name:9s} break-away ({lo:.5g}, {law.breakaway_voltage:.5g}] V "
              f"= {law.breakaway_voltage / law.friction_voltage:.4f} F ({law.breakaway_torque:.4g} N m); "
              f"creep {law.creep_rates[0.5]:.3g} rad/s at 0.5 F, {law.creep_rates[0.9]:.3g} rad/s at 0.9 F; "
              f"{law.slide_rates[1.3]:.3g} rad/s at 1.3 F ((2.13): {law.predicted_slide_rates[1.3]:.3g}, "
              f"with gyro: {law.predicted_slide_rates_gyro[1.3]:.3g}); "
              f"{'holds below, slides above' if law.holds() else 'does NOT hold below break-away'}; "
              f"{law.mujoco_warnings} MuJoCo warnings")
    return 0


def _slip(args: argparse.Namespace, params: Any) -> int:
    """model slip: the side slip on the 1 m circle."""
    slip = measure_side_slip(params)
    if args.json:
        print_json(slip)
    else:
        print(f"side slip on the 1 m circle at V_A = {params.V_A:g} m/s: "
              f"max {1e3 * slip['max_slip_m_s']:.3f} mm/s ({100 * slip['max_slip_fraction']:.2f}% of V_A, "
              f"slip angle {1e3 * slip['max_slip_angle_rad']:.2f} mrad), rms {1e3 * slip['rms_slip_m_s']:.3f} mm/s")
    return 0


def _params(args: argparse.Namespace, params: Any) -> int:
    """model params: the parameter set with its sources, and the reduced model's coefficients."""
    paper, nonholonomic = params.coefficients("paper"), params.coefficients("nonholonomic")
    if args.json:
        print_json({"parameters": params.to_dict(), "paper": paper.to_dict(), "nonholonomic": nonholonomic.to_dict(),
                    "kinetic_energy": params.kinetic_energy_coefficients()})
        return 0
    sources = PARAMETER_SOURCES
    if getattr(args, "cart", None) is not None:
        sources = dict(load_cart(args.cart).sources)
    for name, value in params.to_dict().items():
        print(f"{name:22s} {value:12.6g}  {sources[name]}")
    print()
    for key in COEFFICIENT_NAMES:
        print(f"{key:5s} paper {getattr(paper, key):10.5g}   nonholonomic {getattr(nonholonomic, key):10.5g}")
    return 0
