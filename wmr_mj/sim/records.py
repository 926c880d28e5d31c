"""Frozen result records read by attribute, with their JSON: ``to_dict`` and ``from_dict``.

The results above one run (a sweep's summary, a search's report, a comparison's rows) are frozen
dataclasses; a dict appears only where JSON, CSV or MCAP is written or read. :class:`Record` gives each
its two conversions from its fields, in field order (the order of the JSON keys it writes):

- ``to_dict()``: nested records become their ``to_dict()``, tuples lists, mappings dicts;
- ``from_dict(d)``: the fields named in the class's ``_records`` (field -> record type) are rebuilt as
  that record (a list as a tuple of them), other lists become tuples, mappings stay as read;

so that ``X.from_dict(x.to_dict()).to_dict() == x.to_dict()`` (a test checks each result type).

Usage::

    from wmr_mj.sim.records import UnmetAssumption
    a = UnmetAssumption.from_dict({"name": "within the supply", "value": 24.1, "limit": 24.0, "runs": 3})
    a.runs, a.to_dict()
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any, ClassVar, TypeVar

__all__ = ["Record", "plain", "UnmetAssumption", "BrokenRun"]

R = TypeVar("R", bound="Record")


def plain(value: Any) -> Any:
    """``value`` as JSON writes it: a record as its ``to_dict()``, a tuple or list as a list, a mapping as a
    dict (each item likewise); anything else as it is."""
    if isinstance(value, Record):
        return value.to_dict()
    if isinstance(value, (tuple, list)):
        return [plain(v) for v in value]
    if isinstance(value, Mapping):
        return {k: plain(v) for k, v in value.items()}
    return value


class Record:
    """The mixin of a frozen dataclass whose JSON is its fields in order (see the module)."""

    #: field -> the record type it holds (one, or a tuple of them where the JSON has a list)
    _records: ClassVar[Mapping[str, type[Record]]] = {}

    def to_dict(self) -> dict[str, Any]:
        """The record's JSON: each field, in order (nested records, tuples and mappings made plain)."""
        return {f.name: plain(getattr(self, f.name)) for f in dataclasses.fields(self)}  # type: ignore[arg-type]

    @classmethod
    def from_dict(cls: type[R], d: Mapping[str, Any]) -> R:
        """The record of its JSON ``d`` (what :meth:`to_dict` wrote; a key left out takes its field's default)."""
        kwargs: dict[str, Any] = {}
        for f in dataclasses.fields(cls):  # type: ignore[arg-type]
            if f.name not in d:
                continue
            value = d[f.name]
            kind = cls._records.get(f.name)
            if kind is not None and value is not None:
                value = (tuple(kind.from_dict(v) for v in value) if isinstance(value, (list, tuple))
                         else kind.from_dict(value))
            elif isinstance(value, list):
                value = tuple(value)
            kwargs[f.name] = value
        return cls(**kwargs)


@dataclasses.dataclass(frozen=True, kw_only=True)
class UnmetAssumption(Record):
    """An assumption of a claim that a run (or some runs) does not meet
    (:func:`wmr_mj.analysis.verdicts.unmet_assumptions`, :func:`~wmr_mj.analysis.verdicts.count_unmet`).

    Attributes:
        name: the assumption's name.
        value: its value in the (first) run that does not meet it, in the assumption's units; None where
            not finite.
        limit: the limit it is held to, in the same units; None where not finite.
        note: why it is not met, for an assumption about the cart (``CART_ASSUMPTIONS``); None otherwise
            (the JSON then has no ``note``).
        runs: how many runs do not meet it, where counted over runs; None for one run's (no ``runs`` key).
        value_range: (lo, hi) of its finite values over the runs that do not meet it, where counted over
            runs and they differ; None otherwise (the JSON then has no ``value_range``).
    """

    name: str
    value: float | None
    limit: float | None
    note: str | None = None
    runs: int | None = None
    value_range: tuple[float, float] | None = None

    def to_dict(self) -> dict[str, Any]:
        """{name, value, limit} with ``note``, ``runs`` and ``value_range`` only where set: the keys the verdicts
        module writes."""
        out: dict[str, Any] = {"name": self.name, "value": self.value, "limit": self.limit}
        if self.note is not None:
            out["note"] = self.note
        if self.runs is not None:
            out["runs"] = self.runs
        if self.value_range is not None:
            out["value_range"] = list(self.value_range)
        return out


@dataclasses.dataclass(frozen=True, kw_only=True)
class BrokenRun(Record):
    """The run that breaks the law's claim most: a sweep's (:attr:`wmr_mj.experiments.sweep.SweepSummary.claim_broken`)
    or a search's (:attr:`wmr_mj.searches.falsify.FalsifyResult.claim_broken`), one record for both.

    Attributes:
        run: a sweep's run index, or its place in its search phase (1-based); None where a sweep's row has none.
        params: the run's ranged parameters (a sweep's m1 among them), full precision.
        sup_E: its sup|E| [rad].
        sup_Edot: its sup|E'| [rad/s].
        E_max: the certificate's E_max [rad]; None where it has none.
        ratio: sup|E|/E_max of the certificate [-]; None where undefined.
        count: the certified-outside runs (a sweep's, or both phases of a search).
        phase: a search's phase, "search" or "random"; None for a sweep (its JSON then has no ``phase``).
    """

    run: int | None
    params: Mapping[str, float]
    sup_E: float
    sup_Edot: float
    E_max: float | None
    ratio: float | None
    count: int
    phase: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """A search's JSON begins with ``phase`` (falsify --json's order); a sweep's has none."""
        out = super().to_dict()
        phase = out.pop("phase")
        return out if phase is None else {"phase": phase, **out}
