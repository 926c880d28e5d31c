"""``validate --design TOKEN``: a design of the user's (a plug-in law, a tracker, other gains) judged beside
the ladder: its rung (the same m1 sweep, its verdicts against its own claim), and its nominal run.

A token names a design as ``wmr-mj compare`` does (:func:`wmr_mj.sim.designs.design_changes`):
``sliding-mode``, ``my_law.py:MyLaw,k=2``, ``certified,tracker=pure-pursuit``. Each gets a row after the
ladder's (summary.json's ``designs``), numbered after the correction rung.

Usage::

    summary["designs"] = designs_stage(settings, folder, st, first_index=6)
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["TokenDesign", "designs_stage"]


@dataclass(frozen=True)
class TokenDesign:
    """A design named by a token, shaped as :class:`wmr_mj.sim.designs.Design` for the ladder's rung."""

    token: str

    @property
    def name(self) -> str:
        return re.sub(r"[^A-Za-z0-9_.-]+", "-", self.token).strip("-")[:60] or "design"

    @property
    def label(self) -> str:
        return self.token

    def config_changes(self) -> dict[str, Any]:
        from wmr_mj.sim.designs import design_changes

        return design_changes(self.token)

    def describe(self) -> str:
        from wmr_mj.sim.config import RunConfig, controller_for, estimate_parameters

        return controller_for(RunConfig(**self.config_changes()), estimate_parameters()).label()


def designs_stage(settings: Any, folder: Path, st: Any, *, first_index: int) -> list[dict[str, Any]]:
    """Each of ``settings.designs``: its rung (:func:`wmr_mj.report.validate.run_rung`) with its nominal run."""
    from wmr_mj.report.settings import reference_of
    from wmr_mj.report.validate import _nominal_summary, run_rung
    from wmr_mj.sim.closed_loop import run_closed_loop

    out = []
    for k, token in enumerate(settings.designs, start=first_index):
        design = TokenDesign(token)
        rung = run_rung(settings, k, design, folder, st, reference_of(settings), None)
        st.start(f"design-{k}", f"nominal run of {token} at m1 = {settings.nominal_m1:g} kg")
        nominal = run_closed_loop(settings.config(design), progress=False)
        st.done(f"sup|E| = {nominal.summary.sup_E:.3g} rad, {nominal.summary.verdict}")
        law = "no-claim: judged by requirements only" if nominal.summary.verdict == "no-claim" else ""
        rung.update(token=token, change="a design of the user's (validate --design)" + (f"; {law}" if law else ""),
                    nominal=_nominal_summary(nominal), paper_law=nominal.summary.paper_law)
        out.append(rung)
    return out
