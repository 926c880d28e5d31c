"""The closed-loop batch (wmr_mj.sim.batch): bit-identical to serial runs, the laws, the models, the groups."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmr_mj.sim.batch import batch_model, run_batch
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig

BASE = RunConfig(model="nonholonomic", duration=10.0)
KEYS = ("sup_E", "sup_Edot", "sup_E_settled", "sup_Edot_settled", "E_max", "Edot_max", "saturated_fraction",
        "final_alpha", "inside", "left_steering_range", "left_steering_range_at_s",
        "verdict", "certificate", "paper_region", "drift")


@pytest.mark.slow
def test_batch_is_bit_identical_to_runs_one_by_one():
    configs = [BASE.replace(m1=m) for m in (552.5, 650.0, 749.0)]
    configs.append(BASE.replace(m1=600.0, plant_overrides={"mu": 0.03, "l4": 0.27}))
    configs.append(BASE.replace(m1=700.0, plant_overrides={"mu": 0.001}))
    batch = run_batch(configs, nthread=2)
    for cfg, b in zip(configs, batch):
        serial, b = run_closed_loop(cfg, progress=False).summary.to_dict(), b.to_dict()
        for key in KEYS:
            assert serial[key] == b[key], (cfg.m1, key, serial[key], b[key])
    # the runs really differ: the comparison is not between copies
    assert len({b.sup_E for b in batch}) == len(batch)



LAW_INPUTS = (np.array([0.0, 0.31, -0.62, 0.05, 0.8, -0.1, 0.2, 0.0]),  # alpha, rad
              np.array([0.0, 0.4, -0.03, 0.0, -1.5, 2e-3, -2e-3, 0.1]))  # alpha', rad/s (exact zeros included)


@pytest.mark.parametrize("options", [dict(model="paper"), dict(model="nonholonomic"), dict(model="paper-lagrange"),
                                     dict(model="paper", friction_sign="reference"),
                                     dict(model="nonholonomic", friction_sign="none"),
                                     dict(model="paper", friction_width=0.01),
                                     dict(model="nonholonomic", friction_sign="reference", friction_width=0.01),
                                     dict(controller="pd", model="paper")])
def test_batch_law_is_bit_identical_to_the_scalar_and_array_laws(options):
    from wmr_mj.sim.config import controller_for, estimate_parameters

    controller = controller_for(RunConfig(**options), estimate_parameters())
    alpha, alpha_dot = LAW_INPUTS
    law = controller.batch_law(len(alpha))
    E, E_dot, u = np.empty(len(alpha)), np.empty(len(alpha)), np.empty(len(alpha))
    state = np.zeros((len(alpha), 3))  # the law reads strided views of state rows in the batch
    state[:, 0], state[:, 2] = alpha, alpha_dot
    for ref in ((0.3, 0.1, -0.2), (-0.5, 0.0, 0.4), (0.0, -0.2, 0.0)):
        out = law(state[:, 0], state[:, 2], *ref, E, E_dot, u)
        scalar = [controller.voltage_scalar(a, ad, *ref) for a, ad in zip(alpha, alpha_dot)]
        assert out is u and u.tolist() == scalar
        assert controller.voltage(alpha, alpha_dot, *ref).tolist() == scalar
        assert E.tolist() == [ref[0] - a for a in alpha] and E_dot.tolist() == [ref[1] - ad for ad in alpha_dot]



def test_batch_model_is_the_serial_model_but_for_the_sky():
    import mujoco

    from wmr_mj.plant.mjcf import compile_model
    from wmr_mj.sim.config import plant_parameters

    cfg = BASE.replace(m1=612.3456789, plant_overrides={"mu": 0.0191234567, "V_A": 0.23})
    serial, _ = compile_model(plant_parameters(cfg), steering_friction=cfg.steering_friction)
    batch = batch_model(plant_parameters(cfg), steering_friction=cfg.steering_friction)
    assert batch.ntex == serial.ntex - 1
    skip = ("tex", "name", "mat_texid", "paths")
    compared = 0
    for name in dir(serial):
        value = getattr(serial, name)
        if name.startswith("_") or name.startswith(skip) or not isinstance(value, np.ndarray):
            continue
        assert np.array_equal(value, getattr(batch, name), equal_nan=True), name
        compared += 1
    for name in dir(serial.opt):
        if not name.startswith("_") and not callable(getattr(serial.opt, name)):
            assert np.array_equal(getattr(serial.opt, name), getattr(batch.opt, name)), name
    assert compared > 100 and isinstance(serial, mujoco.MjModel)



def test_a_nan_voltage_from_a_plug_in_fails_its_run_in_the_batch_as_in_the_serial_run():
    from controllers import ComputedTorque, model_from_source
    from wmr_mj.params import C80

    class NanWhileTurning(ComputedTorque):
        """The law of the paper, but NaN while the reference turns fast (a law with a bug)."""

        name = "nan-while-turning"

        def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
            return math.nan if alpha0_dot > 0.002 else super().voltage_scalar(alpha, alpha_dot, alpha0, alpha0_dot,
                                                                              alpha0_ddot)

        def batch_law(self, n):
            law = super().batch_law(n)

            def nan_law(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot, E, E_dot, u):
                law(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot, E, E_dot, u)
                if alpha0_dot > 0.002:
                    u[:] = math.nan
                return u

            return nan_law

    law = NanWhileTurning(model_from_source(BASE.model, params=C80), kp=BASE.kp, kd=BASE.kd)
    configs = [BASE.replace(controller=law, path="lane-change", duration=4.0, m1=m) for m in (560.0, 720.0)]
    for cfg, b in zip(configs, run_batch(configs, nthread=1)):
        s, b = run_closed_loop(cfg, progress=False).summary.to_dict(), b.to_dict()
        # the batch's NaN step sends the run to the serial engine, which stops it there, naming the law
        assert s["status"] == b["status"] == "failed" and s["verdict"] == "failed"
        assert "nan-while-turning" in s["failure"] and "nan" in s["failure"].lower()
        assert s["controller"] == "nan-while-turning"
        assert 0 < s["control_steps"] < 4000  # stopped at the first NaN, with what ran before it
        for key in ("sup_E", "sup_Edot", "final_alpha", "failure", "control_steps"):
            assert s[key] == b[key], key


def test_paper_model_batch_matches_serial_including_steering_stop():
    configs = [RunConfig(model="paper", duration=10.0, m1=m) for m in (560.0, 740.0)]
    # two runs on two threads: one group whose batch steps on both threads (batch.batch_groups)
    for cfg, b in zip(configs, run_batch(configs, nthread=2)):
        s = run_closed_loop(cfg, progress=False).summary
        assert b.left_steering_range and b.left_steering_range_at_s == s.left_steering_range_at_s
        assert b.sup_Edot == s.sup_Edot



@pytest.mark.slow
def test_batch_split_into_groups_is_bit_identical_to_one_group(monkeypatch):
    """Several groups on their own threads (what run_batch uses for large batches) give the same numbers."""
    import wmr_mj.sim.batch as batch_module

    configs = [BASE.replace(m1=m) for m in (560.0, 610.0, 680.0, 745.0)]
    one = run_batch(configs, nthread=2, law="numpy")  # groups are the NumPy law's (the compiled law runs one)
    monkeypatch.setattr(batch_module, "batch_groups",
                        lambda nsim, threads: [(np.array([0, 1]), 1), (np.array([2, 3]), 1)])
    two = run_batch(configs, nthread=2, law="numpy")
    for a, b in zip(one, two):
        a, b = a.to_dict(), b.to_dict()
        for key in KEYS:
            assert a[key] == b[key], key
