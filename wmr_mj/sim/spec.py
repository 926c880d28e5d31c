"""A run's specification from what a user chose: a preset merged with the law options given explicitly.

The commands (``run``, ``sweep``, ``falsify``, ``robustness --certificate``) parse their options and hand the
law's to :func:`law_fields` as a :class:`LawChoice`; what a run is made of is then resolved once
(:func:`wmr_mj.sim.parts.resolve_run`), and :func:`no_estimate_note` reads the resolved run.

Usage::

    from wmr_mj.sim.spec import LawChoice, law_fields
    from wmr_mj.sim.config import RunConfig
    config = RunConfig(**law_fields(LawChoice(preset="certified", kp=150.0)), m1=700.0)
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from controllers import gains_from_omega_r
from controllers.computed_torque import CONTROLLER_NAMES
from controllers.registry import is_builtin
from wmr_mj.errors import ParameterError
from wmr_mj.hardware.assembly import is_ideal_cart
from wmr_mj.params import C80
from wmr_mj.plant.identify import identify_plant
from wmr_mj.sim.certify import claim_on_estimate
from wmr_mj.sim.config import RunConfig, base_for, controller_and_settings, declared_parameters, estimate_parameters
from wmr_mj.sim.designs import CERTIFIED, preset
from wmr_mj.sim.parts import resolve_run

__all__ = ["LawChoice", "law_fields", "no_estimate_note", "LAW_OPTIONS"]

#: the law options (as the commands spell them) and the RunConfig fields each sets
LAW_OPTIONS = {"--model": ("model",), "--kp": ("kp",), "--kd": ("kd",), "--omega-r": ("kp", "kd"),
               "--friction-sign": ("friction_sign",), "--friction-width": ("friction_width",)}


@dataclass(frozen=True, kw_only=True)
class LawChoice:
    """The steering law as a user chose it; each None where not given (the preset's, or the law's own, then).

    Attributes:
        preset: a design of :data:`wmr_mj.sim.designs.PRESET_NAMES` (None: 'paper').
        controller: a law's name, ``FILE.py:Class`` or ``module:Class`` (None: the preset's).
        controller_params: a plug-in's parameters, NAME -> value.
        model: the estimate's model source; kp [1/s^2], kd [1/s]: the gains; omega_r [rad/s]: the gains by (3.6)
            instead; friction_sign, friction_width [rad/s]: the Coulomb compensation.
        identified: ``wmr-mj identify`` output (a path or a mapping) for model 'identified'; None: identify the
            nominal plant now.
        coefficients: the estimate's coefficients for model 'explicit'.
        cart: the cart the preset is derived for (``RunConfig.cart``; None: the C80): the certified design's
            rule run on it (:func:`wmr_mj.sim.designs.preset`), the identification done on it.
        path: the run's path where given: the certified design's rule runs on it (None: the cart's own path).
    """

    preset: str | None = None
    controller: str | None = None
    controller_params: Mapping[str, Any] = field(default_factory=dict)
    model: str | None = None
    kp: float | None = None
    kd: float | None = None
    omega_r: float | None = None
    friction_sign: str | None = None
    friction_width: float | None = None
    identified: Any = None
    coefficients: Mapping[str, float] | None = None
    cart: Any = None
    path: str | None = None  # the run's path, where given: the certified design's rule runs on it (None: the cart's)

    def given(self) -> dict[str, tuple[str, ...]]:
        """The law options given explicitly (:data:`LAW_OPTIONS`' keys) and the fields each sets."""
        return {option: fields for option, fields in LAW_OPTIONS.items()
                if getattr(self, option[2:].replace("-", "_")) is not None}


def law_fields(choice: LawChoice) -> dict[str, Any]:
    """The RunConfig fields of the law ``choice`` names: controller, controller_params, model, kp, kd,
    friction_sign, friction_width, identified, coefficients. The preset gives what is not given; with a
    controller and no preset, the model is the law's own default (None: RunConfig resolves it).

    Raises:
        ParameterError, UnknownNameError: an unknown preset, both omega_r and kp/kd, a bad friction width, a
            law option the law neither declares nor reads (:func:`_route_law_options`).
    """
    design = preset("paper" if choice.preset is None else choice.preset, cart=choice.cart, path=choice.path)
    if choice.omega_r is not None and (choice.kp is not None or choice.kd is not None):
        raise ParameterError("give either --omega-r or --kp/--kd, not both")
    if choice.omega_r is not None:
        kp, kd = gains_from_omega_r(choice.omega_r)
    else:
        kp = design.kp if choice.kp is None else choice.kp
        kd = design.kd if choice.kd is None else choice.kd
    controller = design.controller if choice.controller is None else choice.controller
    model = choice.model
    if model is None and (choice.preset is not None or choice.controller is None):
        model = design.model  # else None: the law's own default (RunConfig resolves it)
    friction_sign = design.friction_sign if choice.friction_sign is None else choice.friction_sign
    friction_width = design.friction_width if choice.friction_width is None else choice.friction_width
    if not math.isfinite(friction_width) or friction_width < 0:
        raise ParameterError(f"--friction-width {friction_width} must be finite and >= 0 (rad/s)")
    identified = choice.identified
    if model == "identified" and identified is None:
        identified = identify_plant(base_for(RunConfig(cart=choice.cart)), duration=30.0, seed=0).to_dict()
    settings: dict[str, Any] = {"model": model, "kp": kp, "kd": kd, "friction_sign": friction_sign,
                                "friction_width": friction_width}
    params = _route_law_options(choice, controller, dict(choice.controller_params), settings, design)
    return {"controller": controller, "controller_params": params, **settings, "identified": identified,
            "coefficients": choice.coefficients}


def _route_law_options(choice: LawChoice, controller: str, params: dict, settings: dict, design: Any) -> dict:
    """The explicit law options (--model, --kp, --kd, --omega-r, --friction-sign, --friction-width) of a law
    other than computed-torque: each goes to the law as the parameter of that name where it declares one
    (its constructor or from_context: moved from ``settings`` into the returned parameters, ``settings``
    keeping the preset's value), stays a RunConfig setting where its build reads it from the context
    (``BuildContext``: model, kp, kd), and is refused otherwise. A preset's own values are never refused.

    Raises:
        ParameterError: an option the law neither declares nor reads (one line naming what it takes), or
            one given both as an option and as --controller-param.
    """
    given = choice.given()
    if not given or controller == "computed-torque":
        return params
    if controller in CONTROLLER_NAMES:  # pd: fields, as computed-torque, but no Coulomb compensation
        declared: frozenset[str] = frozenset()
        reads = frozenset({"model", "kp", "kd"})
    else:
        declared = declared_parameters(controller) - {"model"}  # a model is the context's, never a parameter
        preset_values = {k: getattr(design, k) for k in settings}
        model = preset_values["model"] if preset_values["model"] != "identified" else "paper"
        probe = RunConfig.from_inputs(controller=controller, controller_params=params, model=model, kp=design.kp,
                                      kd=design.kd)
        reads = controller_and_settings(probe, estimate_parameters(C80))[1]
    out = dict(params)
    for option, fields in given.items():
        passed = [f for f in fields if f in declared]
        if passed and len(passed) == len(fields):
            for f in fields:
                if f in out:
                    raise ParameterError(f"{option} and --controller-param {f}=... both set {f}; give one")
                out[f] = settings[f]
                settings[f] = getattr(design, f)  # the RunConfig field the law does not read keeps the preset's
            continue
        if all(f in reads for f in fields):
            continue
        takes = sorted(declared - {"self"})
        raise ParameterError(
            f"{option} does not apply to controller {controller!r}: it reads no {'/'.join(fields)}; give its own "
            f"parameters with --controller-param NAME=VALUE (it takes: {', '.join(takes) or 'none'})")
    return out


#: the model sources whose estimate needs no data (identified and explicit need the user's)
_ESTIMATES = ("paper", "nonholonomic")


def no_estimate_note(parts: Any) -> str | None:
    """One line where a built-in law's claim holds under none of the estimates :data:`_ESTIMATES` at the
    run's other settings (gains, box, path): which assumptions fail under each; None where it can hold,
    states no claim, or the law is not built in.

    Args:
        parts: the run resolved (:func:`wmr_mj.sim.parts.resolve_run`): its own claim is read, not computed
            again; the law on the other estimate is built once, and its claim computed once. A RunConfig is
            resolved here first.
    """
    if isinstance(parts, RunConfig):
        parts = resolve_run(parts)
    config = parts.config
    if not is_builtin(config.controller) or config.model not in _ESTIMATES:
        return None
    if parts.claim is None or parts.claim.certified:
        return None
    claims = {model: parts.claim if model == config.model else claim_on_estimate(parts, model)
              for model in _ESTIMATES}
    unmet = {}
    for model, cert in claims.items():
        if cert is None or cert.certified:
            return None
        unmet[model] = ", ".join(cert.unmet) or "no finite bound"
    label = parts.controller.label()
    hint = ""
    if is_ideal_cart(config) and config.replace(**CERTIFIED.config_changes()) != config:
        hint = "; --preset certified is a computed-torque design whose claim holds"
    elif not is_ideal_cart(config):
        hint = " on this cart (its sensing, actuation or play: see the assumptions not met)"
    return (f"the claim of controller {config.controller!r} ({label}) holds under no estimate at these settings (" +
            "; ".join(f"{m} model: {u} not met" for m, u in unmet.items()) +
            "): its runs are uncertified whatever they do" + hint)
