"""What ``wmr-mj validate`` runs (its settings and defaults) and the helpers its stages share.

Usage::

    from wmr_mj.report.settings import ValidateSettings
    settings = ValidateSettings(n=8, search_budget=10)
    print(settings.config(CERTIFIED))
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

from wmr_mj._util.checks import as_pair, integer_at_least, positive_number
from wmr_mj._util.progress import Stages
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.experiments.compare import FileDesign, design_token_changes, is_design_file
from wmr_mj.experiments.sweep import (
    SAMPLINGS,
    max_at,  # noqa: F401  (re-exported: the report reads runs.csv with it)
)
from wmr_mj.hardware.assembly import CART_PARTS, cart_dict
from wmr_mj.params import UNCERTAINTY_NAMES, uncertainty_ranges
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.report.defaults import DEFAULT_DURATION, DEFAULT_N, DEFAULT_SEARCH_BUDGET, FULL_BOX_FACTOR
from wmr_mj.searches.falsify import cma_population
from wmr_mj.sim.config import RunConfig, base_for, cart_file, estimate_parameters
from wmr_mj.sim.designs import DesignLike, design_changes, on_cart
from wmr_mj.sim.parts import resolve_run, run_reference

__all__ = [
    "DEFAULT_N",
    "DEFAULT_DURATION",
    "DEFAULT_SEARCH_BUDGET",
    "FULL_BOX_FACTOR",
    "LADDER_GROUPS",
    "ValidateSettings",
    "max_at",
    "certificate_summary",
    "reference_of",
    "stage_progress",
    "loud",
]

#: What a ladder rung may change, in groups of RunConfig fields: each rung changes exactly one.
LADDER_GROUPS = {"controller": ("controller",), "model source": ("model",),
                 "compensation": ("friction_sign", "friction_width"), "gains": ("kp", "kd")}
_MIN_POPULATION = 5  # the smallest generation (wmr_mj.searches.falsify.MIN_POPULATION)

# --------------------------------------------------------------------------- settings
@dataclass(frozen=True, kw_only=True)
class ValidateSettings:
    """What ``wmr-mj validate`` runs. Bad values raise ParameterError / UnknownNameError.

    n: runs per rung; duration [s] per run; identify_duration [s] of excitation;
    search_budget: simulations of each m1-box search (the full box gets FULL_BOX_FACTOR
    times as many; 0: no search); nthread: 0 = every core; m1_range, nominal_m1 [kg];
    uncertainty: the box the ladder samples and the certificates cover ('m1', the paper's,
    or 'full': wmr_mj.params.uncertainty_ranges), its m1 range replaced by m1_range.
    """

    n: int = DEFAULT_N
    seed: int = 0
    sampling: str = "lhs"
    duration: float = DEFAULT_DURATION
    identify_duration: float = 60.0
    search_budget: int = DEFAULT_SEARCH_BUDGET
    nthread: int = 0
    # None: the cart's m1 box and nominal m1 (the C80's 550-750 kg and 650 kg), resolved when checked
    m1_range: tuple[float, float] = None  # type: ignore[assignment]
    nominal_m1: float = None  # type: ignore[assignment]
    uncertainty: str = "m1"
    # C's path of every run; None: the cart's own (wmr_mj.reference.named.default_path; the paper circle on the C80),
    # resolved when checked, as validate takes it
    path: str = None  # type: ignore[assignment]
    designs: tuple[str, ...] = ()  # designs of the user's, each judged beside the ladder (validate --design)
    # the cart every run of the report runs on (wmr_mj.hardware parts or their specs, as RunConfig takes them;
    # validate --sensing/--actuation/--backlash); None: ideal (to_dict then has none of these keys)
    sensing: Any = None
    actuation: Any = None
    transmission: Any = None
    # the cart (RunConfig.cart: a shipped cart's name, a .toml file; validate --cart), kept as its record; None: the
    # C80 (to_dict then has no "cart" key). Its parameter set, boxes and defaults; the certified design's gains are
    # derived on it by their rule (wmr_mj.sim.designs.on_cart)
    cart: Any = None

    def __post_init__(self) -> None:
        on_cart = RunConfig.from_inputs(cart=self.cart)  # a missing file, an unknown name: one line, before any run
        object.__setattr__(self, "cart", on_cart.cart)
        if self.m1_range is None:
            object.__setattr__(self, "m1_range", on_cart.m1_range)
        if self.nominal_m1 is None:
            object.__setattr__(self, "nominal_m1", on_cart.m1)
        if self.path is None:
            object.__setattr__(self, "path", on_cart.path)

        integer_at_least("n", self.n, 1, "the number of runs per rung must be an integer >= 1")
        integer_at_least("seed", self.seed, 0, "an integer >= 0 is required")
        if self.sampling not in SAMPLINGS:
            raise UnknownNameError("sampling", str(self.sampling), SAMPLINGS)
        for name in ("duration", "identify_duration", "nominal_m1"):
            positive_number(name, getattr(self, name))
        integer_at_least("nthread", self.nthread, 0, "an integer >= 0 (0: all CPUs) is required")
        integer_at_least("search_budget", self.search_budget, 0,
                         f"give 0 (no search) or an integer >= {_MIN_POPULATION}")
        lo, hi = self.m1_range
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
            raise ParameterError(f"m1_range = {self.m1_range!r} must be (lo, hi) with 0 < lo < hi")

        if self.uncertainty not in UNCERTAINTY_NAMES:
            raise UnknownNameError("uncertainty box name", str(self.uncertainty), UNCERTAINTY_NAMES)
        # a named path or a route file, and the cart (a bad spec, a delay off the grid): refused as a run would
        probe = RunConfig.from_inputs(path=self.path, sensing=self.sensing, actuation=self.actuation,
                                      transmission=self.transmission, cart=self.cart)
        for name in ("sensing", "actuation", "transmission"):
            object.__setattr__(self, name, getattr(probe, name))  # the typed part

        object.__setattr__(self, "designs", tuple(str(t) for t in self.designs))

        for token in self.designs:  # an unknown law, a missing file, a bad setting: refused before any run
            # built once: a parameter the law does not take, a claim() that raises or returns no Certificate
            changes = design_token_changes(token, cart=self.cart) if is_design_file(token) else design_changes(token)
            resolve_run(RunConfig.from_inputs(**{"path": self.path, **changes}, cart=self.cart))  # the runs' path
        if 0 < self.search_budget < self.min_search_budget:
            raise ParameterError(f"search_budget = {self.search_budget} is below one generation of CMA-ES (the "
                                 f"searches' portfolio); give 0 (no search) or an integer >= {self.min_search_budget}")

    @property
    def min_search_budget(self) -> int:
        """One CMA-ES generation of each search (wmr_mj.report.search.search_plans): the ladder's box and,
        over the m1 box, the full box at FULL_BOX_FACTOR times the budget."""
        need = cma_population(1 + len(self.ranges))
        if self.uncertainty == "m1":
            need = max(need, -(-cma_population(1 + len(self.box_ranges("full"))) // FULL_BOX_FACTOR))
        return need

    @property
    def ranges(self) -> dict[str, tuple[float, float]]:
        """The ranged parameters of the uncertainty box other than m1, name -> (lo, hi)."""
        return self.box_ranges(self.uncertainty)

    def box_ranges(self, name: str) -> dict[str, tuple[float, float]]:
        """The ranged parameters of uncertainty box ``name`` ('m1', 'full') other than m1: the cart's own box of
        that name where the cart file declares one, else the C80's (:func:`wmr_mj.params.uncertainty_ranges`)."""
        box = uncertainty_ranges(name)
        if self.cart is not None:
            box = dict(cart_file(RunConfig(cart=self.cart)).uncertainty.get(name, box))
        return {k: v for k, v in box.items() if k != "m1"}

    @property
    def base(self):
        """The cart's parameter set (:class:`wmr_mj.params.C80Parameters`; the C80 without a cart)."""
        return base_for(RunConfig(cart=self.cart))

    def config(self, design: DesignLike) -> RunConfig:
        """The run of ``design`` these settings sweep (m1 at nominal; the sweep draws it), on the cart: the
        certified design's gains derived on it (:func:`wmr_mj.sim.designs.on_cart`). A design file
        (:class:`wmr_mj.experiments.compare.FileDesign`) keeps its gains and the parts of its own cart, but where these
        settings give a part that is not ideal (validate's --sensing, --actuation, --backlash), as ``run --design
        FILE`` keeps the options given."""
        changes = design.config_changes()
        if not isinstance(design, FileDesign):
            changes = on_cart(changes, self.cart)
        given = cart_dict(self)  # the parts these settings make non-ideal: they replace the design file's own
        hardware = {name: getattr(self, name) for name in CART_PARTS if name in given or name not in changes}
        changes = {k: v for k, v in changes.items() if k not in hardware}
        return RunConfig.from_inputs(**changes, duration=self.duration, m1=self.nominal_m1, path=self.path,
                                     m1_range=as_pair(self.m1_range), box_ranges=self.ranges, seed=self.seed,
                                     cart=self.cart, **hardware)

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["m1_range"] = list(self.m1_range)
        if not self.designs:
            del d["designs"]  # the settings written before designs existed, unchanged
        else:
            d["designs"] = list(self.designs)
        for name in CART_PARTS:  # likewise: only the parts of the cart that are not ideal
            del d[name]
        d.update(cart_dict(self))
        if self.cart is None:
            del d["cart"]  # likewise: the C80's settings as they always were
        return d


def certificate_summary(cert: Any) -> dict[str, Any]:
    """A certificate's numbers for the report: ``Certificate.to_dict()`` without the bulky
    inputs, plus the reference's max|alpha0|, the steering range, the supply and the box."""
    if cert is None:  # a law that states no claim
        return {"certified": False, "valid": False, "unmet": ["no claim (the law states none)"], "E_max": None,
                "Edot_max": None, "voltage_max": None, "reason": "the law states no claim"}
    d = {k: v for k, v in cert.to_dict().items() if k != "inputs"}
    inputs = cert.inputs
    d["alpha0_max"] = inputs.get("reference", {}).get("alpha0_max")
    d["steering_range"] = inputs.get("steering_range")
    d["voltage_limit"] = inputs.get("voltage_limit")
    d["m1_range"] = inputs.get("m1_range")
    d["box_ranges"] = inputs.get("box_ranges", {})
    return d


def reference_of(settings: ValidateSettings):
    """The reference of ``settings.path`` (the paper circle by default) for runs of ``settings.duration``
    on the 1 ms grid, built as :func:`wmr_mj.sim.parts.resolve_run` builds the runs' (on the cart's belief)."""
    return run_reference(settings.path, estimate_parameters(settings.base), period=TIMESTEP,
                         duration=settings.duration)[0]



def stage_progress(st: Stages) -> Callable[[float, int], None]:
    return lambda done, total: st.update(done, total)


def loud(count: int, where: str) -> str:
    return (f" !!! {count} CERTIFIED-OUTSIDE run(s) in {where}: a bug or a modelling gap !!!" if count else "")


