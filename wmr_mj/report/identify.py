"""The identification's report: recorded against simulated angle, the residuals and the table of intervals,
as HTML beside PNG; the result a notebook reads (``.plot()``, ``.to_pandas()``).

Usage::

    from wmr_mj.report.identify import IdentifyReport
    report = IdentifyReport.of(fit, recordings, params, holdout=holdout_recording)
    report.plot()                 # ResultPlot: the figure
    report.to_pandas()            # one row per quantity: value, lo, hi, unit, how
    report.write("identify-report")   # identify.html, identify.png
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from wmr_mj._util.files import write_text_atomic
from wmr_mj.figures.identify import figure_identify
from wmr_mj.figures.plots import save_figure
from wmr_mj.figures.results import ResultPlot
from wmr_mj.params import C80Parameters
from wmr_mj.plant.output_error import (
    HOLDOUT_NRMSE_MAX,
    IDENTIFIED_PARAMETERS,
    SteeringFit,
    holdout_error,
    simulate_recording,
)
from wmr_mj.plant.recordings import Recording

__all__ = ["IdentifyReport", "UNITS"]

#: The unit of each quantity of the table.
UNITS = {"P": "V s^2/rad", "C_V": "V s/rad", "F": "V", "K": "V", "gyro": "V s/m", "front_axle_mass": "kg",
         "k_i": "N m/A", "k_b": "V s/rad", "mu": "-", "sensing_delay": "s"}


@dataclass(frozen=True)
class IdentifyReport:
    """What identification found and how well it predicts.

    Attributes:
        fit: the :class:`~wmr_mj.plant.output_error.SteeringFit`.
        shown: the recording drawn (the hold-out where given, else the first), its name.
        t, recorded, simulated: its angle over the segments, recorded and simulated (rad), against t (s).
        holdout_nrmse: the hold-out's normalised RMS error, or None without one.
    """

    fit: SteeringFit
    shown: str
    t: np.ndarray
    recorded: np.ndarray
    simulated: np.ndarray
    holdout_nrmse: float | None

    @classmethod
    def of(cls, fit: SteeringFit, recordings: Sequence[Recording], params: C80Parameters, *,
           holdout: Recording | None = None) -> IdentifyReport:
        rec = holdout if holdout is not None else recordings[0]
        recorded, simulated = simulate_recording(fit, rec, params)
        nrmse = holdout_error(fit, holdout, params) if holdout is not None else None
        return cls(fit=fit, shown=rec.name, t=np.arange(recorded.size) * fit.period, recorded=recorded,
                   simulated=simulated, holdout_nrmse=nrmse)

    def rows(self) -> list[dict[str, Any]]:
        """One row per quantity: name, value, lo, hi, unit, how (identified, or fixed and why)."""
        how = {"K": "fixed: 0 (non-holonomic model)", "gyro": "fixed: P / l1 (moves with C_V at constant speed)"}
        out = [{"name": k, "value": iv.value, "lo": iv.lo, "hi": iv.hi, "unit": UNITS[k],
                "how": how.get(k, "identified (reduced model)")} for k, iv in self.fit.coefficients.items()]
        out += [{"name": k, "value": iv.value, "lo": iv.lo, "hi": iv.hi, "unit": UNITS[k],
                 "how": IDENTIFIED_PARAMETERS[k]} for k, iv in self.fit.physical.items()]
        d = self.fit.delay
        out.append({"name": "delay", "value": d.value, "lo": d.lo, "hi": d.hi, "unit": "s",
                    "how": "identified: voltage to angle (sensing and actuation together), whole control periods"})
        split = ("not identifiable alone (only the sum is): run as all sensing, certified over every split"
               if self.fit.actuation_steps is None else
               "identified: the actuation delay from u_V to u_applied_V (the voltage at the motor), the sensing "
               "delay the rest")
        for name, iv in (("sensing_delay", self.fit.sensing_delay), ("actuation_delay", self.fit.actuation_delay)):
            out.append({"name": name, "value": iv.value, "lo": iv.lo, "hi": iv.hi, "unit": "s", "how": split})
        return out

    def to_pandas(self) -> Any:
        """The table as a pandas DataFrame, indexed by name (pandas is imported here: an optional dependency)."""
        import pandas as pd

        return pd.DataFrame(self.rows()).set_index("name")

    def plot(self) -> ResultPlot:
        """Recorded against simulated angle and their difference (:class:`ResultPlot`)."""
        fig = figure_identify(self.t, self.recorded, self.simulated, title=self._title())
        return ResultPlot(figure=fig, axes=tuple(fig.axes))

    def _title(self) -> str:
        where = f"hold-out {Path(self.shown).name}" if self.holdout_nrmse is not None else Path(self.shown).name
        extra = f", NRMSE {self.holdout_nrmse:.3g}" if self.holdout_nrmse is not None else ""
        return f"{where}{extra}"

    def write(self, folder: str | Path) -> list[Path]:
        """identify.png and identify.html (the table, the figure, the hold-out's check) in ``folder``."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        paths = save_figure(self.plot().figure, folder / "identify", ("png",))
        head = "".join(f"<th>{c}</th>" for c in ("quantity", "value", "95 % interval", "unit", "how"))
        body = "".join(
            f"<tr><td>{html.escape(r['name'])}</td><td>{r['value']:.6g}</td><td>[{r['lo']:.6g}, {r['hi']:.6g}]</td>"
            f"<td>{html.escape(r['unit'])}</td><td>{html.escape(r['how'])}</td></tr>" for r in self.rows())
        fit = self.fit
        check = ("" if self.holdout_nrmse is None else
                 f"<p>Hold-out {html.escape(self.shown)}: normalised RMS error {self.holdout_nrmse:.3g} (at most "
                 f"{HOLDOUT_NRMSE_MAX:g} passes): {'passes' if self.holdout_nrmse <= HOLDOUT_NRMSE_MAX else 'FAILS'}"
                 "</p>")
        enc = "not readable" if fit.encoder_ticks is None else f"{fit.encoder_ticks} ticks per revolution"
        text = (f"<!doctype html><html><head><meta charset='utf-8'><title>wmr-mj identify</title></head><body>"
                f"<h1>wmr-mj identify</h1><p>{fit.segments} segments of {fit.segment_steps} control periods; residual "
                f"{fit.residual_rms_rad:.3g} rad rms; encoder {enc}; noise {fit.noise_rad:.3g} rad.</p>{check}"
                f"<table border='1'><tr>{head}</tr>{body}</table>"
                f"<p><img src='identify.png' alt='recorded against simulated angle'></p></body></html>\n")
        paths.append(write_text_atomic(folder / "identify.html", text))
        return paths
