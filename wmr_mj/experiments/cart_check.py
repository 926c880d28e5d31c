"""``wmr-mj cart check``'s answer as one frozen result: is a cart file sound, what does the certified design
certify on it, can the design search certify it (:func:`cart_check`; the CLI prints it).

The checks of the file itself (compile and step with random controls, identify the reduced model) are
:mod:`wmr_mj.plant.cartcheck`'s; this module, above the run, adds the certified design's certificate on the cart
(:mod:`wmr_mj.sim.designs`) and the design search's answer (:mod:`wmr_mj.searches.design_search`).

Usage::

    from wmr_mj.carts import load_cart
    from wmr_mj.experiments.cart_check import cart_check

    check = cart_check(load_cart("c80"), seed=0)
    check.passed, check.answer, check.to_dict()["design"]["certified"]
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from wmr_mj.errors import InfeasiblePathError, ParameterError, StiffReferenceError, WmrMjError
from wmr_mj.hardware import Actuation, Sensing, Transmission
from wmr_mj.params import parameters_of_cart
from wmr_mj.plant.cartcheck import (
    COEFFICIENT_UNITS,
    IdentificationCheck,
    RandomStepCheck,
    check_identification,
    step_with_random_controls,
)
from wmr_mj.plant.mjcf import TIMESTEP
from wmr_mj.reference.named import default_path, default_path_note
from wmr_mj.reference.route import path_name
from wmr_mj.searches.design_search import (
    DEFAULT_BUDGET,
    DEFAULT_SEED,
    DesignProblem,
    law_changes,
    search_design,
    uncovered,
)
from wmr_mj.sim import notebook
from wmr_mj.sim.config import RunConfig, estimate_parameters
from wmr_mj.sim.designs import certified_design
from wmr_mj.sim.parts import resolve_run, run_reference

__all__ = ["CartCheck", "NamedCart", "cart_check", "default_parts", "certified_on_cart", "design_on_cart"]


@dataclass(frozen=True, kw_only=True)
class NamedCart:
    """A cart file as a cart check's JSON names it (:meth:`CartCheck.from_dict`): the file is named, not read.

    Attributes:
        name, version: the file's name and version.
        path: the file checked, as the JSON wrote it.
    """

    name: str
    version: str
    path: str


@dataclass(frozen=True, kw_only=True)
class CartCheck:
    """``wmr-mj cart check``'s answer (:func:`cart_check`).

    Attributes:
        cart: the checked cart file (:class:`wmr_mj.carts.CartFile`).
        defaults: its default sensing, actuation and play, each as its part's label.
        steps: 1 s of random controls (:func:`wmr_mj.plant.cartcheck.step_with_random_controls`).
        identification: the identification against what the file implies
            (:func:`wmr_mj.plant.cartcheck.check_identification`); None where the fit was impossible.
        identification_error: why it was impossible; None otherwise.
        certified_design: the certified design's certificate on the cart (:func:`certified_on_cart`).
        design: whether the design search certifies the cart (:func:`design_on_cart`).
        design_wall_s: the design search's wall time [s] (not in the JSON).
        path_note: the line naming the default path derived from the cart's stops where it answers on it
            (:func:`wmr_mj.reference.named.default_path_note`); None otherwise.
    """

    cart: Any
    defaults: Mapping[str, str]
    steps: Any
    identification: Any
    identification_error: str | None
    certified_design: Mapping[str, Any]
    design: Mapping[str, Any]
    design_wall_s: float = 0.0
    path_note: str | None = None

    @property
    def passed(self) -> bool:
        """Every check of the file passes (the certificate and the design are reports, not checks)."""
        return self.steps.passed and self.identification is not None and self.identification.passed

    @property
    def answer(self) -> str:
        """The first line: passes, or what failed."""
        return _answer(self.cart, self.steps, self.identification, self.identification_error)

    def to_dict(self) -> dict[str, Any]:
        """``wmr-mj cart check --json``."""
        cart, ident = self.cart, self.identification
        return {"answer": self.answer, "passed": self.passed, "cart": cart.name, "version": cart.version,
                "path": str(cart.path), "defaults": dict(self.defaults), "steps": self.steps.to_dict(),
                "identification": None if ident is None else ident.to_dict(),
                "identification_error": self.identification_error,
                "certified_design": dict(self.certified_design), "design": dict(self.design),
                **({} if self.path_note is None else {"path_note": self.path_note})}  # only where the path is derived

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> CartCheck:
        """The check of its JSON ``d`` (what :meth:`to_dict` wrote, ``wmr-mj cart check --json``), such that
        ``to_dict()`` writes ``d`` again (``answer`` and ``passed`` are derived).

        Not in the JSON, so not restored: the cart file itself (a :class:`NamedCart`: its name, version and path;
        the file is not read), the identification's other diagnostics and m1
        (:meth:`wmr_mj.plant.cartcheck.IdentificationCheck.from_dict`), and the design search's wall time
        (``design_wall_s``: 0).
        """
        ident = d["identification"]
        return cls(cart=NamedCart(name=d["cart"], version=d["version"], path=d["path"]), defaults=dict(d["defaults"]),
                   steps=RandomStepCheck.from_dict(d["steps"]),
                   identification=None if ident is None else IdentificationCheck.from_dict(ident),
                   identification_error=d["identification_error"], certified_design=dict(d["certified_design"]),
                   design=dict(d["design"]), path_note=d.get("path_note"))

    # -- in a notebook (wmr_mj.sim.notebook): one row per coefficient, the coefficients' figure, a few lines
    def to_pandas(self) -> Any:
        """One row per identified coefficient (``P``, ``C_V``, ``F``, ``K``, ``gyro``): ``coefficient``, ``unit``,
        ``identified`` (the MuJoCo plant's, least squares), ``implied`` (the cart file's non-holonomic model),
        ``paper`` (the paper's (2.13)), ``allowed`` (the largest |identified - implied| accepted) and ``passed``;
        no row where the fit was impossible.

        Raises:
            WmrMjError: pandas is not installed (``pip install 'wmr-mj[notebook]'``).
        """
        rows = () if self.identification is None else self.identification.rows
        return notebook.records_frame([
            {"coefficient": r.name, "unit": COEFFICIENT_UNITS[r.name], "identified": r.identified,
             "implied": r.implied, "paper": r.paper, "allowed": r.allowed, "passed": r.passed} for r in rows])

    def plot(self) -> Any:
        """Each identified coefficient against the one the file implies, in its allowance
        (:func:`wmr_mj.figures.results.plot_cart_check`, a :class:`~wmr_mj.figures.results.ResultPlot`)."""
        from wmr_mj.figures.results import plot_cart_check  # matplotlib loads only when a figure is asked for

        return plot_cart_check(self)

    def _repr_html_(self) -> str:
        """The answer's verdict, the default parts, the certified design's E_max and whether design certifies."""
        cert, design = self.certified_design, self.design
        lines = [self.answer,
                 "defaults: " + ", ".join(f"{k} {v}" for k, v in self.defaults.items()),
                 (f"the certified design (omega_r {notebook.number(cert['omega_r'], 'rad/s')}) on {cert['path']}: "
                  f"E_max {notebook.number(cert['E_max'], 'rad')}, "
                  f"{'certified' if cert['certified'] else 'not certified'}")
                 if cert.get("omega_r") is not None else f"the certified design: {cert.get('reason')}",
                 (f"design certifies it: E_max {notebook.number(design.get('E_max'), 'rad')}" if design.get("certified")
                  else f"design certifies nothing: {design.get('binding')} binds")]
        return notebook.html_lines("cart check", "passes" if self.passed else "FAILS", lines)


def cart_check(cart: Any, *, seed: int = 0, duration: float = 20.0, path: str | None = None) -> CartCheck:
    """Check ``cart`` (a :class:`wmr_mj.carts.CartFile`): its default parts, the certified design's certificate
    on it, the design search, 1 s of random controls, and the identification over a ``duration`` s excitation,
    each seeded with ``seed``. ``path``: the path the certified design and the design search answer for (None: the
    cart's own, :func:`wmr_mj.reference.named.default_path`; named in the answer).

    Raises:
        ParameterError: a default part that cannot be built, or a reference that cannot be built in bounded time
            (an absurd cart), before any step: one line naming the file.
    """
    params = parameters_of_cart(cart)
    parts = default_parts(cart)
    path = default_path(cart) if path is None else path
    try:  # a reference that cannot be built in bounded time is an absurd cart: refused before any step
        run_reference(path, estimate_parameters(params), period=TIMESTEP, duration=35.0)  # a 35 s run's, as resolved
    except StiffReferenceError as exc:
        raise ParameterError(f"cart file {str(cart.path)!r}: {exc}") from None
    except InfeasiblePathError:  # a circle the cart cannot steer: the cart's answer, reported below
        pass
    certified = certified_on_cart(cart, path)
    t0 = time.perf_counter()
    design = design_on_cart(cart, seed=seed, path=path)
    design_wall = time.perf_counter() - t0
    steps = step_with_random_controls(params, seed=seed)
    ident, ident_error = None, None
    try:
        ident = check_identification(params, duration=duration, seed=seed)
    except ParameterError as exc:  # too few sliding samples: the cart's answer, not the user's input
        ident_error = str(exc)
    note = default_path_note(cart) if path == default_path(cart) else None
    return CartCheck(cart=cart, defaults=parts, steps=steps, identification=ident, identification_error=ident_error,
                     certified_design=certified, design=design, design_wall_s=design_wall, path_note=note)


def default_parts(cart: Any) -> dict[str, str]:
    """The cart's default sensing, actuation and play built as their parts (a bad spec raises one line)."""

    built = {}
    for key, cls in (("sensing", Sensing), ("actuation", Actuation), ("backlash", Transmission)):
        value = cart.defaults[key]
        try:
            part = cls(backlash=value) if cls is Transmission else cls.from_spec(value)
        except WmrMjError as exc:
            raise ParameterError(f"cart file {str(cart.path)!r}: defaults.{key}.value = {value!r}: {exc}") from None
        built[key] = part.label()
    return built


def _answer(cart: Any, steps: Any, ident: Any, ident_error: str | None) -> str:
    """The first line: passes, or what failed (``ident`` None: the fit was impossible, ``ident_error`` says why)."""
    where = f"cart {cart.name} {cart.version} ({cart.path})"
    failed = []
    if not steps.passed:
        what = ", ".join(f"{name} x{n}" for name, n in steps.warnings.items()) or "no warning"
        failed.append(f"1 s of random controls: {what}" + ("" if steps.finite else ", a non-finite state"))
    if ident is None:
        failed.append(f"no identification: {ident_error}")
    elif ident.warnings:
        failed.append(f"{ident.warnings} MuJoCo warnings in the excitation")
    if ident is not None:
        failed += [f"{row.name} identified {row.identified:.4g}, implied {row.implied:.4g} +- {row.allowed:.2g}"
                   for row in ident.rows if not row.passed]
    if failed:
        return f"{where}: FAILS: " + "; ".join(failed)
    return (f"{where}: passes: compiles and steps 1 s of random controls with no MuJoCo warning; the identified "
            "P, C_V, F, K, gyro are those the file implies")


def certified_on_cart(cart: Any, path: str | None = None) -> dict[str, Any]:
    """The certified design on ``cart`` (a checked CartFile) and its certificate on ``path`` (None: the cart's own,
    :func:`wmr_mj.reference.named.default_path`) with the cart's default sensing, actuation and play: omega_r [rad/s],
    kp, kd, certified, E_max [rad], Edot_max [rad/s],
    voltage_max [V], voltage_limit [V], met, unmet (assumption names); or omega_r None and 'reason' where the rule
    finds no omega_r on its grid."""

    path = default_path(cart) if path is None else path
    try:  # a paper circle the cart's supply or stops cannot follow: the cart's answer, not the user's input
        design = certified_design(cart, path=path)
        claim = resolve_run(RunConfig(**design.config_changes(), cart=cart, path=path)).claim
    except (ParameterError, InfeasiblePathError) as exc:
        return {"omega_r": None, "reason": str(exc), "path": path}
    assert claim is not None  # the computed-torque law always states its certificate
    return {"omega_r": design.kd, "kp": design.kp, "kd": design.kd, "certified": claim.certified,
            "E_max": claim.E_max, "Edot_max": claim.Edot_max, "voltage_max": claim.voltage_max,
            "voltage_limit": float(cart.parameters["voltage_limit"]),
            "met": [a.name for a in claim.assumptions if a.met], "unmet": list(claim.unmet), "path": path}


def design_on_cart(cart: Any, *, seed: int | None = None, budget: int | None = None,
                   path: str | None = None) -> dict[str, Any]:
    """Can ``wmr-mj design`` certify ``cart`` (a checked CartFile) on its default sensing, actuation and play? The
    design search on ``path`` (None: the cart's own, :func:`wmr_mj.reference.named.default_path`) over the cart's m1
    box, computed-torque law, 1 ms period, E_max minimised.

    Returns:
        certified; where certified: E_max [rad], voltage_max [V], kp [1/s^2], kd [1/s], friction_width [rad/s];
        else binding (the assumption, or why no certificate covers the cart's sensing); budget, seed, evaluations,
        and the ``wmr-mj design`` command that runs the same search. seed, budget: None, design's defaults
        (:data:`~wmr_mj.searches.design_search.DEFAULT_SEED`, :data:`~wmr_mj.searches.design_search.DEFAULT_BUDGET`).
    """

    seed = DEFAULT_SEED if seed is None else seed
    budget = DEFAULT_BUDGET if budget is None else budget
    path = default_path(cart) if path is None else path
    command = (f"wmr-mj design --cart {cart.path} --seed {seed}"
               + ("" if budget == DEFAULT_BUDGET else f" --budget {budget}")
               + ("" if path == default_path(cart) else f" --path {path}"))
    out: dict[str, Any] = {"budget": budget, "seed": seed, "command": command, "path": path}
    base = RunConfig.from_inputs(**law_changes("computed-torque"), cart=cart)
    why_not = uncovered(base)
    if why_not:  # design refuses such a cart's sensing (no certificate can cover it)
        return {**out, "certified": False, "evaluations": 0,
                "binding": f"the default sensing ({why_not}: no certificate covers it)"}
    try:
        result = search_design(DesignProblem(base=base, seed=seed, budget=budget, paths=(path,)))
    except InfeasiblePathError as exc:  # the cart cannot follow the path: no gains certify it
        return {**out, "certified": False, "evaluations": 0,
                "binding": f"the path {path_name(path)}'s feasibility ({exc})"}
    out.update(certified=result.certified, evaluations=result.evaluations)
    if not result.certified:
        return {**out, "binding": result.binding}
    s = result.settings
    return {**out, "E_max": result.E_max, "voltage_max": result.certificates[path].voltage_max,
            "kp": s["kp"], "kd": s["kd"], "friction_width": s["friction_width"]}
