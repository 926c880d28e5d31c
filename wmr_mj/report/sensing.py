"""The certified design on realistic sensing: a section of ``wmr-mj validate`` (summary.json's ``sensing``).

The certified design runs at the top of the m1 box (the worst mass for it) on the report's path, once with
the simulator's exact alpha and alpha' and once on each sensing preset of :data:`REALISTIC_SENSING`
(:mod:`wmr_mj.hardware.presets`: a 12-bit and a 14-bit absolute magnetic encoder on the steering axis, an
incremental 500-line encoder on the motor shaft). For each run it records:

- the verdict against the run's own certificate (which covers the run's measurement errors or names the
  assumption it lacks) and the unmet assumptions with value and limit;
- sup|E| against the ideal certificate's E_max (the bound of exact measurement);
- the voltage activity: RMS u [V] and the total variation of u per second [V/s] (as ``wmr-mj compare``);
- the dead band: the settled |E| plateau (the mean of |E| over the run's last :data:`SETTLED_WINDOW_S`
  seconds, with its spread), beside F^ / (P^ K_P), the error at which the PD part alone supplies the
  Coulomb voltage (../shared/notes/mismatch.md: with a quantised angle the differenced velocity reads 0,
  the Coulomb compensation switches off, and the steering stays stuck until P^ K_P |E| overcomes F).

Usage::

    from wmr_mj.report.sensing import sensing_stage
    section = sensing_stage(settings, st)   # 1 + len(REALISTIC_SENSING) runs of settings.duration
    section["runs"][1]["verdict"], section["runs"][1]["tv_voltage"]
"""

from __future__ import annotations

from typing import Any

import numpy as np

from wmr_mj._util.progress import Stages
from wmr_mj.analysis.verdicts import CERTIFIED_OUTSIDE, unmet_assumptions
from wmr_mj.report.settings import ValidateSettings
from wmr_mj.sim.closed_loop import run_parts
from wmr_mj.sim.coerce import coerce
from wmr_mj.sim.designs import CERTIFIED
from wmr_mj.sim.parts import resolve_run

__all__ = ["REALISTIC_SENSING", "SETTLED_WINDOW_S", "sensing_stage", "voltage_activity", "settled_plateau"]

#: The sensing presets the section runs the certified design on, beside the exact measurement ('ideal').
REALISTIC_SENSING = ("magnetic-12bit-axis", "magnetic-14bit-axis", "incremental-500-motor")
#: [s] the window at the run's end over which the settled |E| plateau is measured (half the run if shorter).
SETTLED_WINDOW_S = 5.0


def voltage_activity(voltage: np.ndarray, control_period: float) -> tuple[float, float]:
    """RMS u [V] and the total variation of u per second [V/s] (sum |u[k+1] - u[k]| / duration), as
    ``wmr-mj compare`` computes them (:func:`wmr_mj.experiments.compare.run_scenario`).

    Args:
        voltage: the applied voltage at each control step [V], shape (n,).
        control_period: s between samples.
    """
    u = np.asarray(voltage, float)
    if u.size == 0:
        return float("nan"), 0.0
    duration = u.size * control_period
    return float(np.sqrt(np.mean(u * u))), float(np.sum(np.abs(np.diff(u))) / duration)


def settled_plateau(E: np.ndarray, control_period: float, window_s: float = SETTLED_WINDOW_S) -> dict[str, float]:
    """The settled |E| plateau: mean, min and max of |E| [rad] over the last ``window_s`` seconds (half the
    samples where the run is shorter than twice that).

    Args:
        E: the tracking error at each control step [rad], shape (n,), n >= 1.
        control_period: s between samples.
    """
    a = np.abs(np.asarray(E, float))
    n = max(1, min(int(round(window_s / control_period)), a.size // 2))
    tail = a[-n:]
    return {"mean": float(tail.mean()), "min": float(tail.min()), "max": float(tail.max()),
            "window_s": n * control_period}


def _one_run(parts, name: str, ideal_E_max: float | None) -> dict[str, Any]:
    """The run of ``parts`` (resolved: :func:`wmr_mj.sim.parts.resolve_run`) under the sensing called ``name``."""
    config = parts.config
    run = run_parts(parts, progress=False)
    s = run.summary
    cert = s.to_dict().get("certificate") or {}
    period = 1e-3 if config.control_period is None else config.control_period
    rms, tv = voltage_activity(run.rows["voltage"], period)
    return {"sensing": name, "label": config.sensing.label(), "verdict": s.verdict,
            "certificate_E_max": cert.get("E_max"), "unmet": unmet_assumptions(cert), "sup_E": s.sup_E,
            "sup_E_over_ideal_E_max": None if not ideal_E_max else s.sup_E / ideal_E_max,
            "rms_voltage": rms, "tv_voltage": tv, "settled_E": settled_plateau(run.rows["E"], period),
            "max_abs_voltage": float(np.max(np.abs(run.rows["voltage"]))) if len(run.rows["voltage"]) else None}


def _dead_band_prediction(parts) -> dict[str, float]:
    """F^ / (P^ K_P) [rad] from the certified design's law (its estimate's F and P, its K_P) and the E_max of the
    certificate its run is judged by (the sampled-data one since issue 44): the run resolved (``parts``,
    :func:`wmr_mj.sim.parts.resolve_run`)."""
    cert = parts.claim
    if cert is None:  # the certified design's computed-torque law always states one
        raise RuntimeError("the certified design states no certificate")
    law = parts.controller
    est = law.model.coefficients
    return {"F_estimate": float(est.F), "P_estimate": float(est.P), "kp": float(law.kp),
            "dead_band": float(est.F) / (float(est.P) * float(law.kp)),
            "ideal_E_max": float(cert.E_max) if cert.valid else float("nan")}


def sensing_stage(settings: ValidateSettings, st: Stages, *,
                  presets: tuple[str, ...] = REALISTIC_SENSING) -> dict[str, Any]:
    """Run the certified design at m1 = the box's upper end on exact sensing and on each of ``presets``.

    Returns:
        summary.json's ``sensing``: ``m1`` [kg], ``design``, ``duration`` [s], the prediction
        (``F_estimate`` [V], ``P_estimate`` [V s^2/rad], ``kp`` [1/s^2], ``dead_band`` [rad], ``ideal_E_max``
        [rad]), ``runs`` (one per sensing, 'ideal' first: see the module docstring), ``certified_outside``.
    """
    m1 = float(settings.m1_range[1])
    st.start("sensing", f"the certified design on realistic sensing ({', '.join(presets)}; m1 = {m1:g} kg, "
                        f"{settings.duration:g} s each)")
    base = settings.config(CERTIFIED).replace(m1=m1, sensing="ideal")  # exact sensing, whatever the cart's default
    base_parts = resolve_run(base)
    prediction = _dead_band_prediction(base_parts)
    runs = []
    for name in ("ideal", *presets):
        config = coerce(base.replace(sensing=name))  # the preset typed, so that 'ideal' is the base itself
        parts = base_parts if config == base else resolve_run(config)  # the base run resolved once
        runs.append(_one_run(parts, name, prediction["ideal_E_max"]))
    n_out = sum(r["verdict"] == CERTIFIED_OUTSIDE for r in runs)
    st.done(", ".join(f"{r['sensing']}: {r['verdict']}, TV u {r['tv_voltage']:.3g} V/s" for r in runs))
    return {"m1": m1, "design": CERTIFIED.label, "duration": settings.duration, **prediction, "runs": runs,
            "certified_outside": n_out}

