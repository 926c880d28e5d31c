"""Recordings against rollouts of the cart's MJCF itself, through ``mujoco.sysid`` (the ``sysid`` extra).

``identify --data`` fits the reduced model (:mod:`wmr_mj.plant.output_error`): fast, and its intervals sound for
coloured residuals. This module puts the identified cart back on the MuJoCo plant: each recording is cut into
segments (as the fit cuts it), each rolled out on the MJCF of a parameter set from the recorded angle and rate
(the rest of the state the ``home`` key's: rolling straight at V_A), driven by the recorded voltage, and compared
with the recorded angle by ``mujoco.sysid``'s own residual (its ``ModelSequences``, ``build_residual_fn``,
``sysid_rollout``). :func:`mjcf_rollout_nrmse` is ``identify --sysid``'s check of the identified cart file on
the plant; :func:`fit_mjcf` is ``mujoco.sysid.optimize`` refitting the steering's parameters by rollouts
(``bench/bench_identify.py`` times it beside the fit: docs/guides/identify.md says why it is not the fit).

The delay: the voltage drives the rollout undelayed and the recorded angle is compared ``delay_steps`` later
(the whole voltage-to-angle delay, as the fit measures it). Each segment's first :data:`SKIP_S` (the initial
state's transient: a rate read through ticks, a chassis not yet turning with the wheels) and its mean offset (the
initial angle's half tick) are left out, as the fit leaves them out.

Usage::

    from wmr_mj.plant.mjcf_rollouts import mjcf_rollout_nrmse
    nrmse = mjcf_rollout_nrmse(parameters_of_cart(load_cart("new.toml")), [read_csv("lane.csv")], delay_steps=5)
"""

from __future__ import annotations

import importlib
import io
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import mujoco
import numpy as np

from wmr_mj.errors import ParameterError
from wmr_mj.params import C80Parameters, with_params
from wmr_mj.plant.mjcf import Plant
from wmr_mj.plant.recordings import Recording

__all__ = ["SYSID_EXTRA", "SKIP_S", "RATE_HALF_WINDOW_S", "import_sysid", "mjcf_rollout_nrmse", "fit_mjcf",
           "MjcfFit", "FITTED"]

#: the extra that installs mujoco.sysid's dependencies (absl-py, plotly, tabulate, ...): pip install 'wmr-mj[sysid]'
SYSID_EXTRA = "sysid"
#: s left out at each segment's start (the fit's burn-in, wmr_mj.plant.output_error)
SKIP_S = 0.1
#: s each side of a segment's start over which the recorded angle's slope gives the initial rate (a tick per
#: control period is ~1.5 rad/s of rate noise on a 12-bit encoder; +-10 ms brings it to ~0.08 rad/s)
RATE_HALF_WINDOW_S = 0.01
#: the cart-file parameters fit_mjcf refits: the steering's inertia (the beam's mass), the motor constant
#: (k_i = k_b, one flux) and the Coulomb coefficient; each as a factor of its start value
FITTED = ("front_axle_mass", "k", "mu")
#: relative finite-difference step of fit_mjcf (the MJCF carries 6 significant digits: a step below 1e-6 is
#: rounded away, and the stiff frictionloss constraint is not smooth on a finer scale)
FD_STEP = 1e-3


def import_sysid() -> ModuleType:
    """``mujoco.sysid``, with its dependencies.

    Raises:
        ParameterError: the extra is not installed (one line naming it).
    """
    try:  # the optional extra: imported only where it is asked for (by name: mypy would follow mujoco.sysid's
        # py.typed into the untyped mujoco package)
        sysid: ModuleType | None = importlib.import_module("mujoco.sysid")
    except ImportError:
        sysid = None
    if sysid is None or not hasattr(sysid, "optimize"):  # mujoco.sysid imports empty without its dependencies
        raise ParameterError(f"--sysid needs mujoco.sysid and its dependencies: pip install 'wmr-mj[{SYSID_EXTRA}]' "
                             "(the mujoco[sysid] extra: absl-py, plotly, tabulate, ...)")
    logging.getLogger("absl").setLevel(logging.ERROR)  # its optimiser's table and warnings: not ours to print
    return sysid


def _model(params: C80Parameters) -> Any:
    return Plant(params).model


def _sequences(sysid: ModuleType, params: C80Parameters, recordings: Sequence[Recording], delay_steps: int,
               segment_steps: int) -> Any:
    """The recordings as ``mujoco.sysid.ModelSequences``: one sequence per segment."""
    plant = Plant(params)
    model = plant.model
    key = model.key("home")
    period = recordings[0].period
    skip, half = int(round(SKIP_S / period)), int(round(RATE_HALF_WINDOW_S / period))
    lags = np.arange(-half, half + 1) * period
    inits, controls, sensors, names = [], [], [], []
    for rec in recordings:
        for k0 in range(half, rec.samples - segment_steps - delay_steps - half, segment_steps):
            i = k0 + delay_steps  # the recorded angle at step i is the plant's at step k0
            qpos, qvel = key.qpos.copy(), key.qvel.copy()
            qpos[plant.steer_qpos] = rec.alpha[i]
            qvel[plant.steer_dof] = np.polyfit(lags, rec.alpha[i - half:i + half + 1], 1)[0]
            inits.append(sysid.create_initial_state(model, qpos, qvel))
            t = np.arange(segment_steps) * period
            drive = np.full(segment_steps, key.ctrl[plant.drive_actuator])
            ctrl = np.empty((segment_steps, model.nu))
            ctrl[:, plant.steer_actuator], ctrl[:, plant.drive_actuator] = rec.voltage[k0:k0 + segment_steps], drive
            controls.append(sysid.TimeSeries(t, ctrl))
            angle = rec.alpha[i + skip:i + segment_steps][:, None]
            sensors.append(sysid.TimeSeries.from_names(t[skip:], angle, model, names=["steer_angle"]))
            names.append(f"{rec.name}@{rec.t[k0]:.3f}s")
    if not inits:
        raise ParameterError(f"the recordings are shorter than one segment of {segment_steps * period:g} s: no "
                             "rollout to compare")
    spec = mujoco.MjSpec.from_string(plant.xml)
    return sysid.ModelSequences("cart", spec, names, inits, controls, sensors, allow_missing_sensors=True)


def _segment_nrmse(measured: Sequence[Sequence[Any]], predicted: Sequence[Sequence[Any]]) -> float:
    """RMS(recorded - rolled out, each segment's mean removed) over the RMS of the recorded angle's motion
    within the segments (the hold-out's normalised error, wmr_mj.plant.output_error.holdout_error); the series as
    ``mujoco.sysid.residual`` returns them (per model group, per segment)."""
    err2 = motion2 = count = 0.0
    for m, p in zip((s for group in measured for s in group), (s for group in predicted for s in group)):
        e = m.data[:, 0] - p.data[:, 0]
        e = e - e.mean()
        a = m.data[:, 0] - m.data[:, 0].mean()
        err2, motion2, count = err2 + float(e @ e), motion2 + float(a @ a), count + e.size
    return float(np.sqrt(err2 / count) / max(np.sqrt(motion2 / count), 1e-300))


def mjcf_rollout_nrmse(params: C80Parameters, recordings: Sequence[Recording], *, delay_steps: int,
                       segment_steps: int = 1000, m1: float | None = None) -> float:
    """The normalised RMS error of the MJCF of ``params`` (at chassis mass ``m1``; None: its own) rolled out by
    ``mujoco.sysid`` on each segment of ``recordings`` against the recorded angle.

    Raises:
        ParameterError: mujoco.sysid is not installed (one line naming the extra), or the recordings are shorter
            than a segment.
    """
    sysid = import_sysid()
    p = params if m1 is None else with_params(params, m1=m1)
    sequences = _sequences(sysid, p, recordings, delay_steps, segment_steps)
    empty = sysid.ParameterDict()
    _res, predicted, measured = sysid.residual(np.zeros(0), empty, [sequences], build_model=lambda _p, _s: _model(p),
                                               return_pred_all=True)
    return _segment_nrmse(measured, predicted)


@dataclass(frozen=True)
class MjcfFit:
    """What ``mujoco.sysid.optimize`` found by rollouts of the MJCF.

    values: each of :data:`FITTED` (``k`` is k_i = k_b) in the cart file's units. half_width: its 95 %
    half-width from ``mujoco.sysid.calculate_intervals`` (the Jacobian's, from s^2 of the residuals).
    rollouts: rollouts of one segment (mujoco.sysid rolls each segment out alone, for each residual column).
    nrmse: the rollouts' normalised RMS error at the fit. wall_s: the optimiser's wall time.
    """

    values: dict[str, float]
    half_width: dict[str, float]
    rollouts: int
    nrmse: float
    wall_s: float


def fit_mjcf(params: C80Parameters, recordings: Sequence[Recording], *, delay_steps: int,
             segment_steps: int = 1000, m1: float | None = None, max_iters: int = 20,
             clock: Callable[[], float] | None = None) -> MjcfFit:
    """Refit the steering's beam mass, motor constant and Coulomb coefficient by ``mujoco.sysid.optimize`` on
    rollouts of the MJCF (its own Levenberg-Marquardt, finite differences of :data:`FD_STEP`), from ``params``.

    Raises:
        ParameterError: mujoco.sysid is not installed, or the recordings are shorter than a segment.
    """
    import time

    sysid = import_sysid()
    clock = clock or time.perf_counter
    base = params if m1 is None else with_params(params, m1=m1)
    start = {"front_axle_mass": base.front_axle_mass, "k": base.k_i, "mu": base.mu}
    sequences = _sequences(sysid, base, recordings, delay_steps, segment_steps)
    factors = sysid.ParameterDict()
    for name in FITTED:
        factors.add(sysid.Parameter(name, 1.0, 0.1, 5.0))
    rollouts, compiled = [0], {}  # type: list[int], dict[tuple[float, ...], Any]

    def build(p: Any, _spec: Any) -> Any:
        # mujoco.sysid builds the model once per segment and residual column: the MJCF is compiled once per
        # parameter vector (the last few kept), which is most of a rollout's cost otherwise
        rollouts[0] += 1
        x = tuple(float(p[name].value[0]) for name in FITTED)
        if x not in compiled:
            v = {name: start[name] * x[i] for i, name in enumerate(FITTED)}
            if len(compiled) >= 8:
                compiled.pop(next(iter(compiled)))
            compiled[x] = _model(with_params(base, front_axle_mass=v["front_axle_mass"], k_i=v["k"], k_b=v["k"],
                                             mu=v["mu"]))
        return compiled[x]

    residual_fn = sysid.build_residual_fn(models_sequences=[sequences], build_model=build)
    t0 = clock()
    # output: its optimiser's per-iteration lines (printed whatever optimize's verbose says) kept off stdout
    opt, result = sysid.optimize(initial_params=factors, residual_fn=residual_fn, optimizer="mujoco", verbose=False,
                                 eps=FD_STEP, max_iters=max_iters, output=io.StringIO())
    wall = clock() - t0
    x = opt.as_vector()
    residuals, predicted, measured = residual_fn(x, opt, return_pred_all=True)
    _cov, half = sysid.calculate_intervals(residuals, result.jac)
    return MjcfFit(values={n: start[n] * float(x[i]) for i, n in enumerate(FITTED)},
                   half_width={n: start[n] * float(half[i]) for i, n in enumerate(FITTED)},
                   rollouts=rollouts[0], nrmse=_segment_nrmse(measured, predicted), wall_s=wall)
