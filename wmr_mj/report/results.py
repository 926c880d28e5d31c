"""The headline validation's result, read by attribute: :class:`ValidateSummary` and its :class:`Rung`.

:func:`wmr_mj.report.validate.run_validate` returns a :class:`ValidateSummary`; summary.json is its
``to_dict()`` (the keys it always had) and :meth:`ValidateSummary.from_dict` reads a summary.json back, so
that :mod:`wmr_mj.report.text` renders a fresh report and a saved one alike. The sections other modules
write (the settings, the searches, the friction law, the identification, realistic sensing, the
certificate of each rung) stay their JSON mappings here: their shapes are their modules'.

Usage::

    import json
    from wmr_mj.report.results import ValidateSummary
    summary = ValidateSummary.from_dict(json.loads(open("logs/validate-latest/summary.json").read()))
    rung = summary.ladder[-1]
    rung.passes, rung.n, rung.worst_certificate_ratio
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from wmr_mj.figures.results import plot_validate
from wmr_mj.report.cart_design import CartDesign
from wmr_mj.sim import notebook
from wmr_mj.sim.records import Record

__all__ = ["Rung", "CertifiedRule", "PathSummary", "ValidateSummary"]


@dataclass(frozen=True, kw_only=True)
class Rung(Record):
    """One rung of validate's ladder (a sweep over m1 of one design), or the correction rung, or a design of
    the user's (``validate --design``): summary.json's ``ladder[k]``, ``correction_rung``, ``designs[k]``.

    The counts and worst values are :meth:`wmr_mj.experiments.sweep.SweepSummary.rung_dict`'s (sup|E| [rad],
    sup|E'| [rad/s], ratios [-], m1 [kg], cross-track [m]); then the design's place and words.

    Attributes:
        index: the rung's number, 1-based.
        name: the design's name.
        label: the design's label.
        design: the design's description.
        config: the RunConfig fields the design sets.
        changed: the groups changed from the rung before.
        change: the change in words ("" on the first rung).
        certificate: the rung's certificate (``wmr_mj.report.settings.certificate_summary``: a mapping).
        paper_region: the paper's claim for the rung ({E_max, Edot_max, condition, stable, vertices}).
        runs_csv: the rung's runs.csv, relative to the report folder.
        token: a user's design as given (``validate --design``); None on the ladder (no ``token`` key).
        nominal: that design's nominal run (a mapping); None on the ladder.
        paper_law: False where that design's law is not the paper's family (its paper column says n/a).
    """

    n: int
    verdicts: Mapping[str, int]
    passes: int
    certified_outside: int
    paper_inside: int | None
    worst_sup_E: float | None
    worst_sup_E_m1: float | None
    worst_sup_Edot: float | None
    worst_certificate_ratio: float | None
    worst_certificate_ratio_m1: float | None
    worst_paper_ratio: float | None
    worst_paper_ratio_m1: float | None
    hit_stop: int
    growing: int
    mean_saturated_fraction: float
    m1_min: float
    m1_max: float
    worst_path_cross_track: float | None = None
    worst_path_cross_track_m1: float | None = None
    path_verdicts: Mapping[str, int] | None = None
    index: int
    name: str
    label: str
    design: str
    config: Mapping[str, Any]
    changed: tuple[str, ...]
    change: str
    certificate: Mapping[str, Any]
    paper_region: Mapping[str, Any]
    runs_csv: str
    token: str | None = None
    nominal: Mapping[str, Any] | None = None
    paper_law: bool = True

    def to_dict(self) -> dict[str, Any]:
        """The rung's JSON; a ladder rung has no ``token``, ``nominal`` nor ``paper_law`` (only a user's design)."""
        out = super().to_dict()
        if self.token is None:
            for key in ("token", "nominal", "paper_law"):
                del out[key]
        return out


@dataclass(frozen=True, kw_only=True)
class CertifiedRule(Record):
    """The certified design's rule as designs.py writes it (``text``), its error spec E_max [rad], the step of
    its omega_r grid [rad/s], the omega_r the rule gives now (None: no omega_r of the grid meets it) and the one
    the design uses [rad/s]."""

    text: str
    error_spec: float
    omega_r_grid_step: float
    omega_r_rule: float | None
    omega_r_design: float


@dataclass(frozen=True, kw_only=True)
class PathSummary(Record):
    """The runs' path of C: its name and, on the paper circle, the circle's radius [m] (else None)."""

    name: str
    circle_radius: float | None


@dataclass(frozen=True, kw_only=True)
class ValidateSummary(Record):
    """What ``wmr-mj validate`` found: summary.json, read by attribute.

    Attributes:
        folder: the report's folder.
        created: when (local time, with its offset).
        settings: the settings (``ValidateSettings.to_dict()``).
        seed: the settings' seed.
        ladder: the rungs from the paper's design to the certified design, in order.
        certified_rule: how the certified design was chosen.
        searches: the worst-case searches (:mod:`wmr_mj.report.search`'s mappings), in order.
        nominal: the paper's and the certified design's run at the nominal m1, by name (mappings).
        friction: the steering joint's measured friction law, by friction model (mappings).
        identification: the plant identified at the nominal m1 (a mapping, with its verdict).
        paper_example: the section-5 example of the paper (Fig. 7).
        figures: stem -> the files written.
        correction_rung: the certified design with the Cartesian correction; None in reports before it.
        path: the runs' path of C; None in reports before it.
        designs: the user's designs (``validate --design``), each as a rung; () when none (no ``designs`` key).
        certified_outside: certified-outside runs of every rung, design, search and sensing run.
        sensing: the certified design on realistic sensing (:mod:`wmr_mj.report.sensing`); None in reports
            before it (no ``sensing`` key).
        cart_design: the design ``wmr-mj design`` finds for the 12-bit axis encoder beside the certified design
            on it (:mod:`wmr_mj.report.cart_design`); None in reports before it (no ``cart_design`` key).
        versions: the software's.
        findings: the report's findings, in sentences.
        timings_s: each stage's wall time [s].
        wall_s: the whole validation's wall time [s].
    """

    _records = {"ladder": Rung, "certified_rule": CertifiedRule, "correction_rung": Rung, "path": PathSummary,
                "designs": Rung, "cart_design": CartDesign}

    folder: str
    created: str
    settings: Mapping[str, Any]
    seed: int
    ladder: tuple[Rung, ...]
    certified_rule: CertifiedRule
    searches: tuple[Mapping[str, Any], ...]
    nominal: Mapping[str, Mapping[str, Any]]
    friction: Mapping[str, Mapping[str, Any]]
    identification: Mapping[str, Any]
    paper_example: Mapping[str, Any]
    figures: Mapping[str, Any]
    correction_rung: Rung | None = None
    path: PathSummary | None = None
    designs: tuple[Rung, ...] = ()
    certified_outside: int
    sensing: Mapping[str, Any] | None = None
    cart_design: CartDesign | None = None
    versions: Mapping[str, str]
    findings: tuple[str, ...] = ()
    timings_s: Mapping[str, float] = field(default_factory=dict)
    wall_s: float = math.nan

    def to_dict(self) -> dict[str, Any]:
        """summary.json's object: ``designs`` only where there are some, ``sensing``, ``cart_design``, ``path``
        and ``correction_rung`` only where the report has them."""
        out = super().to_dict()
        if not self.designs:
            del out["designs"]
        for key in ("sensing", "cart_design", "path", "correction_rung"):
            if out[key] is None:
                del out[key]
        return out

    @classmethod
    def of(cls, summary: ValidateSummary | Mapping[str, Any]) -> ValidateSummary:
        """``summary`` itself, or the summary of its JSON (a summary.json read back)."""
        return summary if isinstance(summary, ValidateSummary) else cls.from_dict(summary)

    # -- in a notebook (wmr_mj.sim.notebook): one row per rung, the ladder's figure, the verdict in a few lines
    @property
    def rungs(self) -> tuple[Rung, ...]:
        """The ladder, the correction rung where there is one, then the user's designs."""
        return (*self.ladder, *((self.correction_rung,) if self.correction_rung else ()), *self.designs)

    def to_pandas(self) -> Any:
        """One row per rung (:attr:`rungs`): its runs, each verdict's count, the certificate's bounds, the worst
        sup|E| (and its m1), the worst ratios, effort, m1's range; units in the column names.

        Raises:
            WmrMjError: pandas is not installed (``pip install 'wmr-mj[notebook]'``).
        """
        return notebook.validate_frame(self.rungs)

    def plot(self) -> Any:
        """The verdicts of each rung (the report's ladder figure), as a :class:`wmr_mj.figures.results.ResultPlot`."""
        return plot_validate(self)

    def _repr_html_(self) -> str:
        return notebook.validate_html(self)
