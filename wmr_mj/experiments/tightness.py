"""How tight a claim is on a cart: the certificate a run takes beside the worst sup|E| an adversary finds.

The certificate's E_max is an upper bound on sup|E| over its box; the worst sup|E| that :func:`falsify` finds
over the same box (its search and its random sample, both counted) is a lower bound on the worst case. Their
ratio, the tightness, says how much of the bound the plant can be made to use: 1 would be exact, and a ratio
above 1 on a certified run would be a broken claim (``certified-outside``, counted in :attr:`verdicts`).

Usage::

    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.designs import CERTIFIED
    from wmr_mj.experiments.tightness import cart_tightness
    base = RunConfig(**CERTIFIED.config_changes(), sensing="magnetic-12bit-axis", path="lane-change")
    t = cart_tightness(base, budget=64)          # the m1 box by default: 128 runs
    t.E_max, t.worst_sup_E, t.tightness, t.verdicts
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

from wmr_mj.searches.falsify import FalsifySpec, check_runnable, falsify
from wmr_mj.sim import notebook
from wmr_mj.sim.certify import certificate_name
from wmr_mj.sim.coerce import coerced
from wmr_mj.sim.notebook import html_lines, number, verdict_counts_text
from wmr_mj.sim.records import Record

__all__ = ["CartTightness", "cart_tightness", "certificate_columns"]


@dataclass(frozen=True, kw_only=True)
class CartTightness(Record):
    """One cart on one path: the run's certificate and the worst the adversary found.

    Attributes:
        path: the reference path.
        certificate: the certificate the run takes, 'section-4' or 'sampled-data' ('' where there is none).
        certified: the claim is certified (every assumption met).
        E_max: the run's certificate's E_max, rad (None: no valid bound).
        E_max_section4: section 4's certificate's E_max, rad (None: it has none).
        E_max_sampled: the sampled-data certificate's E_max, rad (None: none, or not computed, as on the
            ideal cart, where section 4's is the claim).
        worst_sup_E: the largest sup|E| of every run, search and random sample, rad.
        worst_params: that run's ranged parameters (e.g. {'m1': 750.0}).
        search_sup_E: the search's worst sup|E|, rad; random_sup_E: the random sample's, rad.
        verdicts: verdict -> number of runs (both phases).
        runs: runs simulated; budget: falsify's budget; seed: its seed; box: the ranges searched.
    """

    path: str
    certificate: str
    certified: bool
    E_max: float | None
    E_max_section4: float | None
    E_max_sampled: float | None
    worst_sup_E: float
    worst_params: Mapping[str, float]
    search_sup_E: float
    random_sup_E: float
    verdicts: Mapping[str, int]
    runs: int
    budget: int
    seed: int
    box: Mapping[str, tuple[float, float]]

    @property
    def tightness(self) -> float | None:
        """worst_sup_E / E_max (None where there is no E_max)."""
        return None if self.E_max is None else self.worst_sup_E / self.E_max

    def to_dict(self) -> dict[str, Any]:
        """Its fields in order (the box's ranges as lists), then ``tightness``."""
        return {**super().to_dict(), "tightness": self.tightness}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> CartTightness:
        """The row of its JSON ``d`` (:meth:`to_dict`'s; ``tightness`` is computed again, not read)."""
        row = super().from_dict(d)
        return replace(row, box={k: (float(lo), float(hi)) for k, (lo, hi) in row.box.items()})

    # -- in a notebook (wmr_mj.sim.notebook): a one-row table (rows of several carts concatenate), a few lines
    def to_pandas(self) -> Any:
        """One row: ``path``, ``certificate``, ``certified``, the three E_max columns [rad], ``worst_sup_E [rad]``,
        ``tightness [-]``, ``runs`` and the verdict counts (one column each).

        Raises:
            WmrMjError: pandas is not installed (``pip install 'wmr-mj[notebook]'``).
        """
        return notebook.records_frame([{
            "path": self.path, "certificate": self.certificate, "certified": self.certified,
            "E_max [rad]": self.E_max, "E_max_section4 [rad]": self.E_max_section4,
            "E_max_sampled [rad]": self.E_max_sampled, "worst_sup_E [rad]": self.worst_sup_E,
            "tightness [-]": self.tightness, "runs": self.runs, **dict(self.verdicts)}])

    def plot(self) -> Any:
        """The certificate's E_max beside the worst sup|E| found, and their ratio against 1
        (:func:`wmr_mj.figures.results.plot_tightness` of this row; pass several rows there for several carts)."""
        from wmr_mj.figures.results import plot_tightness  # matplotlib loads only when a figure is asked for

        return plot_tightness([self])

    def _repr_html_(self) -> str:
        where = ", ".join(f"{k} = {v:.6g}" for k, v in self.worst_params.items())
        return html_lines("tightness", number(self.tightness), [
            f"{self.path}: E_max {number(self.E_max, 'rad')} ({self.certificate or 'no certificate'}; section 4 "
            f"{number(self.E_max_section4, 'rad')}, sampled-data {number(self.E_max_sampled, 'rad')})",
            f"worst sup|E| found {number(self.worst_sup_E, 'rad')} at {where} (search {number(self.search_sup_E)}, "
            f"random {number(self.random_sup_E)}; falsify budget {self.budget}, seed {self.seed})",
            f"{self.runs} runs: {verdict_counts_text(self.verdicts)}"])


def certificate_columns(cert: Any) -> dict[str, Any]:
    """The E_max columns of a run's certificate (:class:`wmr_mj.analysis.certificate.Certificate` or None).

    Returns:
        {'certificate', 'certified', 'E_max', 'E_max_section4', 'E_max_sampled'} (rad, None where none); on the
        ideal cart, where no sampled-data certificate is computed, section 4's is the one taken.
    """
    if cert is None:
        return {"certificate": "", "certified": False, "E_max": None, "E_max_section4": None, "E_max_sampled": None}

    e_max = float(cert.E_max) if cert.valid and math.isfinite(cert.E_max) else None
    both = cert.inputs.get("certificates")
    if both is None:  # the law's own claim alone (the ideal cart, or a law with no sampled-data certificate)
        return {"certificate": certificate_name(cert), "certified": bool(cert.certified), "E_max": e_max,
                "E_max_section4": e_max, "E_max_sampled": None}
    # the law's own (section 4's, or sliding mode's boundary layer): the one beside the sampled-data certificate
    own: dict[str, Any] = next((record for name, record in both.items() if name != "sampled-data"), {})
    return {"certificate": certificate_name(cert), "certified": bool(cert.certified), "E_max": e_max,
            "E_max_section4": own.get("E_max", e_max),
            "E_max_sampled": both.get("sampled-data", {}).get("E_max")}


def cart_tightness(base: Any, *, box: Mapping[str, tuple[float, float]] | None = None, budget: int = 64,
                   seed: int = 0, method: str = "portfolio", nthread: int = 1) -> CartTightness:
    """The run's certificate on ``base`` and the worst sup|E| that falsify finds over ``box``.

    Args:
        base: the run (:class:`wmr_mj.sim.config.RunConfig`): the law, the cart, the path, the duration.
        box: the ranges searched (None: m1 over the certificate's ``base.m1_range``, kg).
        budget: falsify's budget (as many runs again on its random sample).
        seed: falsify's seed; method: its search (:data:`wmr_mj.searches.falsify.METHODS`).
        nthread: threads of the batch.

    Returns:
        :class:`CartTightness`; its E_max columns are the certificate ``run`` computes for ``base``
        (``resolve_run(base).claim``), the one every run of the search shares.

    Raises:
        ParameterError: what falsify refuses (a budget below one population, a bad range or path).
    """
    base = coerced(base)  # a base given directly: its cart's m1 box read here
    if box is None:
        box = {"m1": (float(base.m1_range[0]), float(base.m1_range[1]))}
    spec = FalsifySpec(base=base, box=dict(box), objective="sup-E", budget=budget, seed=seed, method=method)
    parts = check_runnable(base)
    result = falsify(spec, nthread=nthread, parts=parts)
    runs = list(result.search) + list(result.random)
    worst = max(runs, key=lambda e: e.sup_E)
    return CartTightness(path=str(base.path), **certificate_columns(parts.claim), worst_sup_E=worst.sup_E,
                         worst_params=dict(worst.params), search_sup_E=max(e.sup_E for e in result.search),
                         random_sup_E=max(e.sup_E for e in result.random),
                         verdicts=dict(Counter(e.verdict for e in runs)), runs=len(runs), budget=budget, seed=seed,
                         box={k: (float(v[0]), float(v[1])) for k, v in box.items()})
