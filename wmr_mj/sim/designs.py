"""Controller designs: the paper's, a certified one chosen by a rule, and the ladder between them.

A design is what ``--preset`` sets for ``run``, ``sweep``, ``falsify`` and
``robustness --certificate``: controller, model source of the estimate, gains and
Coulomb compensation. Explicit options override a preset. ``validate`` runs both
designs and the ladder between them.

``paper``: the paper's design (5.1): the paper model (2.7), K_P = 6, K_D = 9, exact
sign of alpha' in the compensation F^ sgn(alpha') (3.3).

``certified``: chosen by a rule written down before any run (it uses the certificate,
an analytic bound, never a simulation):

1. model source ``nonholonomic``: the reduced model the multibody derivation gives
   (K = 0, the gyroscopic term gyro V_A alpha'/cos^2 alpha), which needs no identification;
2. compensation: sign of alpha', smoothed, x/sqrt(x^2 + w^2) with w = 0.01 rad/s: it
   vanishes at rest, so under stiction the friction mismatch stays F_max
   (:func:`wmr_mj.analysis.certificate.friction_term`), and it does not chatter on a 1 ms loop;
3. gains: critical damping (3.6), K_P = omega_r^2/4, K_D = omega_r, with omega_r the
   smallest value on a grid of 5 rad/s whose certificate over the cart's m1 box and path
   (the C80's: 550-750 kg, the paper circle) is valid (every assumption met) and bounds the steering
   error by :data:`ERROR_SPEC` = 0.05 rad (about 3 cm of lateral offset of C at the C80's
   0.612 m wheelbase). The smallest such gain leaves the most room to what the plant
   model leaves out (sampling, unmodelled motor dynamics, sensor noise).

:func:`certified_omega_r` evaluates the rule; a test keeps :data:`CERTIFIED` equal to it.

The ladder (``LADDER``) goes from ``paper`` to ``certified`` changing one thing per
rung: the model source, then the compensation, then the gains. Its verdict counts show
what each of the paper's omissions costs.

Usage::

    from wmr_mj.sim.designs import PRESETS, LADDER, certified_omega_r
    PRESETS["certified"].config_changes()     # {'model': 'nonholonomic', 'kp': 225.0, ...}
    [rung.name for rung in LADDER]
    certified_omega_r()                         # 30.0 (from certificates only)
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from typing import Any, Protocol

from controllers import CONTROLLER_NAMES, gains_from_omega_r
from controllers.registry import parse_params
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.params import PAPER_KD, PAPER_KP
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.reference.named import default_path
from wmr_mj.reference.route import path_name
from wmr_mj.sim.certify import certificate_for
from wmr_mj.sim.coerce import cart_file_of_record
from wmr_mj.sim.config import RunConfig, base_for, controller_for, estimate_parameters
from wmr_mj.sim.parts import run_reference

__all__ = [
    "DesignPreset",
    "PAPER",
    "CERTIFIED",
    "PRESETS",
    "PRESET_NAMES",
    "LADDER",
    "CORRECTION_RUNG",
    "ERROR_SPEC",
    "OMEGA_R_GRID",
    "certified_omega_r",
    "certified_design",
    "CERTIFIED_C80",
    "on_cart",
    "preset",
]

#: The certified design's tracking specification: |E| <= 0.05 rad, set before any run.
ERROR_SPEC = 0.05
#: The words of the rule (the module docstring) that are the C80's: a report of another cart writes its own there.
RULE_C80_BOX = "the C80's: 550-750 kg, the paper circle"
RULE_C80_OFFSET = "about 3 cm of lateral offset of C at the C80's 0.612 m wheelbase"
#: The grid of omega_r (rad/s) the rule searches, smallest first.
OMEGA_R_GRID = tuple(float(w) for w in range(5, 105, 5))
SMOOTHING_WIDTH = 0.01  # rad/s, the certified design's sign smoothing w


@dataclass(frozen=True, kw_only=True)
class DesignPreset:
    """A controller configuration: what a preset or a ladder rung sets (a design to compare, a label and a whole
    RunConfig, is :class:`wmr_mj.experiments.compare.Design`)."""

    name: str
    label: str
    controller: str = "computed-torque"
    model: str = "paper"
    kp: float = PAPER_KP  # 1/s^2
    kd: float = PAPER_KD  # 1/s
    friction_sign: str = "measured"
    friction_width: float = 0.0  # rad/s; 0: exact sign
    correction: bool = False  # the Cartesian correction at C (controllers.tracking.StanleyAtC)

    def config_changes(self) -> dict[str, Any]:
        """The RunConfig fields this design sets (``correction`` only where it is on)."""
        out = {"controller": self.controller, "model": self.model, "kp": self.kp, "kd": self.kd,
               "friction_sign": self.friction_sign, "friction_width": self.friction_width}
        if self.correction:
            out["correction"] = True
        return out

    def on(self, cart: Any = None, *, path: str | None = None) -> DesignPreset:
        """This design on ``cart`` (anything ``RunConfig(cart=...)`` takes; None: the C80): the certified design's
        gain rule run on the cart (and ``path``; None: the cart's own default path) for :data:`CERTIFIED`, as
        ``--preset certified --cart`` runs it; any other design as it is (its gains are the cart's as given)."""
        if self.name != "certified":
            return self
        return certified_design(cart, path=path)

    def describe(self) -> str:
        sign = "exact sign" if self.friction_width == 0 else f"sign smoothed w = {self.friction_width:g} rad/s"
        if self.friction_sign == "reference":
            sign = "sign of alpha0'"
        elif self.friction_sign == "none":
            sign = "no compensation"
        return f"{self.model} model, K_P = {self.kp:g}, K_D = {self.kd:g}, {sign}" + (
            ", Cartesian correction" if self.correction else "")


PAPER = DesignPreset(name="paper", label="the paper's design")
#: the certified design: the gain rule (:func:`certified_omega_r`) on a cart -- ``CERTIFIED.on(cart)`` runs it on
#: ``cart`` (``--preset certified --cart``); as a value, CERTIFIED is the rule's answer on the C80
#: (:data:`CERTIFIED_C80`, omega_r = 30 rad/s: K_P = 225, K_D = 30, the rule on the sampled-data certificate,
#: issue 44), never another cart's; a test keeps it equal to :func:`certified_omega_r`
CERTIFIED = DesignPreset(name="certified", label="certified design", model="nonholonomic", kp=225.0, kd=30.0,
                   friction_sign="measured", friction_width=SMOOTHING_WIDTH)
#: the certified design's gains on the C80 (the rule on the C80 and the paper circle), by its C80 name
CERTIFIED_C80 = CERTIFIED
PRESETS: dict[str, DesignPreset] = {"paper": PAPER, "certified": CERTIFIED}
PRESET_NAMES = tuple(PRESETS)

LADDER: tuple[DesignPreset, ...] = (
    PAPER,
    DesignPreset(name="model", label="+ non-holonomic model", model="nonholonomic"),
    DesignPreset(name="compensation", label="+ smoothed compensation", model="nonholonomic",
           friction_width=SMOOTHING_WIDTH),
    DesignPreset(name="gains", label=f"+ gains omega_r = {CERTIFIED.kd:g} (= certified)", model=CERTIFIED.model,
           kp=CERTIFIED.kp, kd=CERTIFIED.kd, friction_sign=CERTIFIED.friction_sign,
           friction_width=CERTIFIED.friction_width),
)

#: validate's rung after the ladder: the certified design with the Cartesian correction at C
#: (not in LADDER, whose last rung is the certified design)
CORRECTION_RUNG = DesignPreset(name="correction", label="+ Cartesian correction", model=CERTIFIED.model,
                               kp=CERTIFIED.kp, kd=CERTIFIED.kd, friction_sign=CERTIFIED.friction_sign,
                               friction_width=CERTIFIED.friction_width, correction=True)


def preset(name: str, *, cart: Any = None, path: str | None = None) -> DesignPreset:
    """The design called ``name``; unknown names raise UnknownNameError listing the valid ones.

    cart: the cart the design is for (anything ``RunConfig(cart=...)`` takes; None: the C80). The paper's
    design is the paper's gains on any cart; the certified design is derived for the cart by its rule
    (:func:`certified_design`), never copied from the C80's.

    Raises:
        UnknownNameError: an unknown name.
        ParameterError: no omega_r of the rule's grid is certified on the cart.
    """
    if name not in PRESETS:
        raise UnknownNameError("preset", name, PRESET_NAMES)
    if name == "certified" and cart is not None:
        return certified_design(cart, path=path)
    return PRESETS[name]


def _cart_record(cart: Any) -> dict[str, Any] | None:
    """The cart's record as RunConfig keeps it (None: the C80)."""
    return RunConfig.from_inputs(cart=cart).cart


def certified_design(cart: Any = None, *, path: str | None = None) -> DesignPreset:
    """The certified design on ``cart`` (None, or the C80's numbers: the C80, :data:`CERTIFIED_C80`): the rule run
    on the cart and on ``path`` (None: the cart's own default path, :func:`wmr_mj.reference.named.default_path`).

    Raises:
        ParameterError: no omega_r of :data:`OMEGA_R_GRID` gives a valid certificate within
            :data:`ERROR_SPEC` on the cart (one line naming the cart and the path).
        InfeasiblePathError: the cart cannot steer the path (one line naming the path, the stops and --path).
    """
    record = _cart_record(cart)
    if record is None:
        return CERTIFIED_C80
    return _certified_on(record["text"], record["path"], path)


@functools.lru_cache(maxsize=8)
def _certified_on(text: str, cart_path: str, path: str | None) -> DesignPreset:
    record = {"text": text, "path": cart_path}
    w = certified_omega_r(cart=record, path=path)
    if w is None:
        raise ParameterError(f"cart file {cart_path!r}: the certified design's rule finds no omega_r in "
                             f"{OMEGA_R_GRID[0]:g}-{OMEGA_R_GRID[-1]:g} rad/s whose certificate is valid with "
                             f"E_max <= {ERROR_SPEC:g} rad on this cart and path "
                             f"{path_name(_path_of(record, path))}; give the gains with --kp/--kd or --omega-r, or "
                             "another --path")
    return dataclasses.replace(CERTIFIED, kp=w * w / 4.0, kd=w)


def _path_of(cart: Any, path: str | None) -> str:
    """The path the rule runs on: ``path``, else the cart's own default."""
    return path if path is not None else default_path(cart_file_of_record(RunConfig.from_inputs(cart=cart).cart))


def on_cart(changes: dict[str, Any], cart: Any) -> dict[str, Any]:
    """A design's RunConfig fields (``DesignPreset.config_changes``) on ``cart``: where they carry the certified
    design's gains (:data:`CERTIFIED`'s K_P and K_D: the certified preset, the ladder's gains rung, the correction
    rung), the gains the rule gives on the cart (:func:`certified_design`); the rest as given. None: the C80,
    unchanged."""
    if cart is None or (changes.get("kp"), changes.get("kd")) != (CERTIFIED.kp, CERTIFIED.kd):
        return changes
    derived = certified_design(cart)
    return {**changes, "kp": derived.kp, "kd": derived.kd}


def certified_omega_r(*, error_spec: float = ERROR_SPEC, grid: tuple[float, ...] = OMEGA_R_GRID,
                      cart: Any = None, path: str | None = None) -> float | None:
    """The rule of the certified design: the smallest omega_r of ``grid`` whose certificate
    (non-holonomic model, smoothed sign, paper circle, m1 over the cart's m1 box: 550-750 kg on the C80)
    is valid with E_max <= error_spec. None when no grid point qualifies. No simulation is run.

    cart: the cart (anything ``RunConfig(cart=...)`` takes; None: the C80): its parameter set, its m1 box, its
    stops and supply."""
    on_cart = RunConfig.from_inputs(cart=cart)
    # the reference of a 35 s run on the 1 ms grid, built as resolve_run builds a run's (on the cart's belief)
    reference, _ = run_reference(_path_of(cart, path), estimate_parameters(base_for(on_cart)), period=TIMESTEP,
                                 duration=35.0)
    for w in grid:
        config = RunConfig(model=CERTIFIED.model, kp=w * w / 4.0, kd=w, friction_sign=CERTIFIED.friction_sign,
                           friction_width=CERTIFIED.friction_width, cart=on_cart.cart)
        cert = certificate_for(config, reference)
        if cert is not None and cert.certified and cert.E_max <= error_spec:
            return w
    return None


class DesignLike(Protocol):
    """What a rung of validate's ladder needs of a design: :class:`DesignPreset`, or a token's
    (:class:`TokenDesign`)."""

    @property
    def name(self) -> str: ...

    @property
    def label(self) -> str: ...

    def config_changes(self) -> dict[str, Any]: ...

    def describe(self) -> str: ...


#: The RunConfig settings a design token may carry beside a law's own parameters.
TOKEN_FIELDS = ("model", "kp", "kd", "omega_r", "friction_sign", "friction_width", "tracker", "correction")


def design_changes(token: str) -> dict[str, Any]:
    """The RunConfig fields of a design named by one token, ``NAME[,key=value...]``: NAME a preset
    (:data:`PRESET_NAMES`) or a law (a built-in name, ``FILE.py:Class``, ``module:Class``); a key one of
    :data:`TOKEN_FIELDS` (``omega_r`` gives K_P, K_D by (3.6)) or, for a plug-in, one of its parameters.
    A law's name means what ``RunConfig(controller=NAME)`` and ``wmr-mj run --controller NAME`` mean: the
    law with its own defaults (its estimate the law's ``default_model``: the paper's model for
    computed-torque and pd, whose defaults are the paper's gains, so ``computed-torque`` is the ``paper``
    preset; the non-holonomic model for sliding-mode). A preset's name means the preset.

    Raises:
        UnknownNameError: an unknown preset or law (from RunConfig, naming the valid ones).
        ParameterError: an empty name, a setting the design does not take.
    """
    name, _, rest = str(token).partition(",")
    name = name.strip()
    if not name:
        raise ParameterError(f"design {token!r} is not accepted: NAME[,key=value...]")
    settings = parse_params([s for s in rest.split(",") if s.strip()] if rest else [], option=f"design {name}")
    fields = {k: settings.pop(k) for k in list(settings) if k in TOKEN_FIELDS}
    if "omega_r" in fields:
        fields["kp"], fields["kd"] = gains_from_omega_r(float(fields.pop("omega_r")))
    if "correction" in fields:
        fields["correction"] = bool(fields["correction"])
    if name in PRESET_NAMES:
        if settings:
            raise ParameterError(f"design {token!r}: a preset takes RunConfig settings ({', '.join(TOKEN_FIELDS)}), "
                                 f"not {sorted(settings)}")
        return {**preset(name).config_changes(), **fields}
    changes: dict[str, Any] = {"controller": name, **fields}
    if name in CONTROLLER_NAMES:  # the laws configured by RunConfig fields
        if settings:
            raise ParameterError(f"design {token!r}: {name} takes RunConfig settings, not {sorted(settings)}")
    else:
        changes["controller_params"] = settings
    return changes


@dataclass(frozen=True)
class TokenDesign:
    """A design named by a token (:func:`design_changes`), shaped as :class:`DesignPreset` for validate's ladder
    (``validate --design``)."""

    token: str

    @property
    def name(self) -> str:
        import re

        return re.sub(r"[^A-Za-z0-9_.-]+", "-", self.token).strip("-")[:60] or "design"

    @property
    def label(self) -> str:
        return self.token

    def config_changes(self) -> dict[str, Any]:
        return design_changes(self.token)

    def describe(self) -> str:
        return controller_for(RunConfig(**self.config_changes()), estimate_parameters()).label()
