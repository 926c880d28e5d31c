"""Identification from 150 s of 1 kHz recordings: ``identify --data``'s fit beside today's reduced regression and
one MuJoCo rollout of the same length (what each evaluation of ``mujoco.sysid`` costs).

    .venv/bin/python bench/bench_identify.py [--duration 150] [--cart tests/data/identify_truth.toml]

Recordings: the testbed's own sensed run of the cart (12-bit encoder, 5 ms delay) under the dithered PD of
tests/data/identify_dithered_pd.py, on lane-change, ``--duration`` s. Timed (wall, one process):

  fit:        wmr_mj.plant.output_error.fit_recordings (the delay's search, the fit, 2000 bootstrap draws);
  regression: wmr_mj.plant.identify.fit_steering_model on the same number of samples of the MuJoCo plant's
              exact states (today's identify without its excitation run: it needs alpha'' and alpha', which a
              real recording does not have);
  rollout:    one mujoco.rollout of the plant model over the recording's steps, open loop with its voltage:
              what mujoco.sysid's optimiser pays per residual column (sysid_rollout calls mujoco.rollout);
  sysid:      with the sysid extra (pip install 'wmr-mj[sysid]'): mujoco.sysid.optimize refitting the MJCF's
              front_axle_mass, k_i = k_b and mu by rollouts of 1 s segments of the first --sysid-seconds of the
              recording (wmr_mj.plant.mjcf_rollouts.fit_mjcf), from the start cart, its Jacobian intervals
              (calculate_intervals); and one check of the identified cart's MJCF (identify --sysid) on them.
Target: the fit under 60 s on 2 cores.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=150.0)
    ap.add_argument("--cart", default=str(ROOT / "tests/data/identify_truth.toml"))
    ap.add_argument("--start", default=str(ROOT / "tests/data/identify_start.toml"),
                    help="the cart mujoco.sysid's refit starts from")
    ap.add_argument("--sysid-seconds", type=float, default=20.0,
                    help="s of the recording mujoco.sysid refits on (its cost grows with it: ~12 s per s of data)")
    args = ap.parse_args()

    import mujoco
    from mujoco import rollout

    from wmr_mj.carts import load_cart
    from wmr_mj.errors import ParameterError
    from wmr_mj.params import parameters_of_cart, with_params
    from wmr_mj.plant.identify import fit_steering_model
    from wmr_mj.plant.mjcf import Plant
    from wmr_mj.plant.output_error import fit_recordings
    from wmr_mj.plant.recordings import Recording
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig

    params = parameters_of_cart(load_cart(args.cart))
    cfg = RunConfig.from_inputs(cart=args.cart, sensing="encoder_ticks=4096,velocity=difference,delay=0.005",
                                path="lane-change", duration=args.duration,
                                controller=f"{ROOT / 'tests/data/identify_dithered_pd.py'}:DitheredPD")
    t0 = time.perf_counter()
    rows = run_closed_loop(cfg, progress=False).rows
    record_s = time.perf_counter() - t0
    rec = Recording("bench", "", rows["t"], rows["voltage"], rows["alpha_measured"], m1=params.m1)
    t0 = time.perf_counter()
    fit = fit_recordings([rec], params)
    fit_s = time.perf_counter() - t0
    n = rows["t"].size
    acc = np.gradient(rows["alpha_dot"], rows["t"])
    t0 = time.perf_counter()
    fit_steering_model(rows["alpha"], rows["alpha_dot"], acc, rows["voltage"], np.full(n, params.V_A))
    regression_s = time.perf_counter() - t0
    plant = Plant(params)
    m, d = plant.model, plant.data
    state = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS))
    mujoco.mj_getState(m, d, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    ctrl = np.zeros((1, n, m.nu))
    ctrl[0, :, plant.steer_actuator] = rows["voltage"]
    t0 = time.perf_counter()
    rollout.rollout(m, d, state[None, :], ctrl)
    rollout_s = time.perf_counter() - t0
    sysid_half, mjcf = None, None
    try:
        from wmr_mj.plant.mjcf_rollouts import fit_mjcf, import_sysid, mjcf_rollout_nrmse

        sysid = import_sysid()
        sysid_note = "importable"
    except ParameterError as exc:
        sysid, sysid_note = None, f"not usable: {exc}"
    if sysid is not None:  # its intervals on our residuals and Jacobian at the fit (the numbers it would be handed)
        from wmr_mj.plant import output_error as oe

        seg = oe._segments([rec], params, period=fit.period, steps=fit.segment_steps, max_delay=fit.delay_steps)
        theta = np.array([fit.coefficients[k].value for k in ("P", "C_V", "F")])
        r, J = oe._segment_jacobian(theta, seg, fit.delay_steps, period=fit.period, inv_l1=1.0 / params.l1)
        sysid_half = sysid.calculate_intervals([r.ravel()], J.reshape(-1, 3))[1]
        keep = min(n, int(round(args.sysid_seconds / fit.period)))
        short = dataclasses.replace(rec, t=rec.t[:keep], voltage=rec.voltage[:keep], alpha=rec.alpha[:keep])
        start = parameters_of_cart(load_cart(args.start))
        mjcf = fit_mjcf(start, [short], delay_steps=fit.delay_steps, m1=params.m1)
        identified = with_params(start, front_axle_mass=fit.physical["front_axle_mass"].value,
                                 k_i=fit.physical["k_i"].value, k_b=fit.physical["k_b"].value,
                                 mu=fit.physical["mu"].value)
        t0 = time.perf_counter()
        check = mjcf_rollout_nrmse(identified, [short], delay_steps=fit.delay_steps, m1=params.m1)
        check_s = time.perf_counter() - t0
    print(f"{args.duration:g} s of 1 kHz recording ({n} samples; recorded in {record_s:.2f} s)")
    print(f"fit (identify --data):        {fit_s:7.2f} s  (delay {fit.delay_steps} periods, encoder "
          f"{fit.encoder_ticks}, P {fit.coefficients['P'].value:.5g})")
    print(f"regression (today's identify): {regression_s:7.3f} s")
    print(f"one MuJoCo rollout:            {rollout_s:7.2f} s  (x ~40 evaluations per fit: ~{40 * rollout_s:.0f} s); "
          f"mujoco.sysid {sysid_note}")
    print("95 % intervals of P, C_V, F: ours (block bootstrap, 2 % model floor) | the Jacobian's (s^2)"
          + (" | mujoco.sysid.calculate_intervals" if sysid_half is not None else ""))
    for i, name in enumerate(("P", "C_V", "F")):
        iv = fit.coefficients[name]
        cells = f"{name:4s} {iv.value:.5g} [{iv.lo:.5g}, {iv.hi:.5g}] | +-{fit.jacobian_half_width[name]:.2g}"
        if sysid_half is not None:
            cells += f" | +-{float(sysid_half[i]):.2g}"
        print(cells)
    truth = params.coefficients("nonholonomic")
    print(f"truth: P {truth.P:.5g}, C_V {truth.C_V:.5g}, F {truth.F:.5g}")
    if mjcf is not None:
        print(f"mujoco.sysid.optimize on the MJCF, {args.sysid_seconds:g} s of the recording from "
              f"{Path(args.start).name}: {mjcf.wall_s:.1f} s, {mjcf.rollouts} rollouts of a 1 s segment, "
              f"NRMSE {mjcf.nrmse:.3g} at its fit")
        ours = {"front_axle_mass": fit.physical["front_axle_mass"], "k": fit.physical["k_i"], "mu": fit.physical["mu"]}
        true = {"front_axle_mass": params.front_axle_mass, "k": params.k_i, "mu": params.mu}
        print(f"cart parameters: ours ({args.duration:g} s, block bootstrap) | mujoco.sysid (rollouts, "
              "calculate_intervals) | truth")
        for name, v in mjcf.values.items():
            iv = ours[name]
            print(f"{name:16s} {iv.value:.5g} [{iv.lo:.5g}, {iv.hi:.5g}] | {v:.5g} +-{mjcf.half_width[name]:.2g} | "
                  f"{true[name]:.5g}")
        print(f"identify --sysid (the identified cart's MJCF rolled out on the same {args.sysid_seconds:g} s): "
              f"{check_s:.2f} s, NRMSE {check:.3g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
