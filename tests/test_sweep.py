"""Sweeps: batch == one by one, sampling, resume, Dask == local, bad input."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from wmr_mj import ParameterError, SchedulerError, UnknownNameError
from wmr_mj.simulate import RunConfig, run_closed_loop
from wmr_mj.sweep import (
    SweepSpec,
    batch_model,
    connect,
    draw_samples,
    latin_hypercube,
    read_results,
    run_batch,
    run_configs,
    run_sweep,
)

BASE = RunConfig(model="nonholonomic", duration=10.0)
KEYS = ("sup_E", "sup_Edot", "sup_E_settled", "sup_Edot_settled", "E_max", "Edot_max", "saturated_fraction",
        "final_alpha", "inside", "left_steering_range", "left_steering_range_at_s",
        "verdict", "certificate", "paper_region", "drift")


def test_batch_is_bit_identical_to_runs_one_by_one():
    configs = [BASE.replace(m1=m) for m in (552.5, 650.0, 749.0)]
    configs.append(BASE.replace(m1=600.0, plant_overrides={"mu": 0.03, "l4": 0.27}))
    configs.append(BASE.replace(m1=700.0, plant_overrides={"mu": 0.001}))
    batch = run_batch(configs, nthread=2)
    for cfg, b in zip(configs, batch):
        serial = run_closed_loop(cfg, progress=False).summary
        for key in KEYS:
            assert serial[key] == b[key], (cfg.m1, key, serial[key], b[key])
    # the runs really differ: the comparison is not between copies
    assert len({b["sup_E"] for b in batch}) == len(batch)


LAW_INPUTS = (np.array([0.0, 0.31, -0.62, 0.05, 0.8, -0.1, 0.2, 0.0]),  # alpha, rad
              np.array([0.0, 0.4, -0.03, 0.0, -1.5, 2e-3, -2e-3, 0.1]))  # alpha', rad/s (exact zeros included)


@pytest.mark.parametrize("options", [dict(model="paper"), dict(model="nonholonomic"), dict(model="paper-lagrange"),
                                     dict(model="paper", friction_sign="reference"),
                                     dict(model="nonholonomic", friction_sign="none"),
                                     dict(model="paper", friction_width=0.01),
                                     dict(model="nonholonomic", friction_sign="reference", friction_width=0.01),
                                     dict(controller="pd", model="paper")])
def test_batch_law_is_bit_identical_to_the_scalar_and_array_laws(options):
    from wmr_mj.simulate import _controller, estimate_parameters

    controller = _controller(RunConfig(**options), estimate_parameters())
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

    from wmr_mj.plant import compile_model
    from wmr_mj.simulate import plant_parameters

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


def test_a_nan_voltage_applies_nothing_as_in_the_serial_run(monkeypatch):
    from controllers import ComputedTorque
    from wmr_mj import simulate, sweep

    class NanWhileTurning(ComputedTorque):
        """The law of the paper, but NaN while the reference turns fast (a diverged law)."""

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

    def controller(config, params):
        c = original(config, params)
        return NanWhileTurning(c.model, kp=c.kp, kd=c.kd)

    original = simulate._controller
    monkeypatch.setattr(simulate, "_controller", controller)
    monkeypatch.setattr(sweep, "_controller", controller)
    configs = [BASE.replace(path="lane-change", duration=4.0, m1=m) for m in (560.0, 720.0)]
    for cfg, b in zip(configs, run_batch(configs, nthread=1)):
        s = run_closed_loop(cfg, progress=False).summary
        assert s["saturated_fraction"] > 0  # the NaN steps happened (counted as saturated)
        for key in KEYS:
            assert s[key] == b[key], key


def test_latin_hypercube_is_scipys():
    from scipy.stats import qmc

    for n, d, seed in ((1, 1, 0), (7, 3, 5), (50, 5, 1)):
        expected = qmc.LatinHypercube(d=d, rng=np.random.default_rng(seed)).random(n)
        assert np.array_equal(latin_hypercube(n, d, np.random.default_rng(seed).spawn(1)[0]), expected)


def test_paper_model_batch_matches_serial_including_steering_stop():
    configs = [RunConfig(model="paper", duration=10.0, m1=m) for m in (560.0, 740.0)]
    # two runs on two threads: one group whose batch steps on both threads (sweep.batch_groups)
    for cfg, b in zip(configs, run_batch(configs, nthread=2)):
        s = run_closed_loop(cfg, progress=False).summary
        assert b["left_steering_range"] and b["left_steering_range_at_s"] == s["left_steering_range_at_s"]
        assert b["sup_Edot"] == s["sup_Edot"]


def test_sampling_is_seeded_and_covers_the_range():
    lhs = SweepSpec(n=50, seed=3, sampling="lhs", base=BASE)
    a, b = draw_samples(lhs), draw_samples(lhs)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, draw_samples(SweepSpec(n=50, seed=4, sampling="lhs", base=BASE)))
    # Latin hypercube: exactly one sample in each of the 50 strata of 550-750 kg
    strata = np.floor((a[:, 0] - 550.0) / 4.0).astype(int)
    assert sorted(strata) == list(range(50))
    grid = draw_samples(SweepSpec(n=5, sampling="grid", base=BASE))
    assert np.allclose(grid[:, 0], [550, 600, 650, 700, 750])
    two = draw_samples(SweepSpec(n=9, sampling="grid", ranges={"mu": (0.01, 0.03)}, base=BASE))
    assert sorted(set(np.round(two[:, 1], 12))) == [0.01, 0.02, 0.03]
    uni = draw_samples(SweepSpec(n=400, seed=0, sampling="uniform", base=BASE))
    assert 550 <= uni[:, 0].min() and uni[:, 0].max() <= 750 and abs(uni[:, 0].mean() - 650) < 10


def test_resume_keeps_finished_runs(tmp_path):
    spec = SweepSpec(n=6, seed=1, sampling="lhs", base=BASE)
    full = run_sweep(spec, out_dir=tmp_path / "a", chunk=2, nthread=1)
    # an interrupted sweep: only the first chunk finished
    calls = []
    part = tmp_path / "b"
    run_sweep(SweepSpec(n=6, seed=1, sampling="lhs", base=BASE), out_dir=part, chunk=2, nthread=1,
              progress=lambda done, total: calls.append(done))
    rows = read_results(part / "runs.csv")
    (part / "runs.csv").write_text("".join((part / "runs.csv").read_text().splitlines(True)[:3]))  # keep 2 runs
    seen = []
    resumed = run_sweep(spec, out_dir=part, chunk=2, nthread=1, progress=lambda done, total: seen.append(done))
    assert seen[0] == 2  # two runs were already there and were not repeated
    assert [r["sup_E"] for r in resumed] == [r["sup_E"] for r in full]
    assert len(read_results(part / "runs.csv")) == 6 and len(rows) == 6
    # a different sweep in the same folder starts afresh
    other = run_sweep(SweepSpec(n=2, seed=9, sampling="lhs", base=BASE), out_dir=part, chunk=2, nthread=1)
    assert len(other) == 2


def test_dask_gives_the_same_numbers_as_local(tmp_path):
    distributed = pytest.importorskip("distributed")
    spec = SweepSpec(n=4, seed=2, sampling="uniform", base=BASE)
    local = run_sweep(spec, chunk=2, nthread=1)
    configs = [BASE.replace(duration=3.0, path="lane-change", m1=m, plant_overrides={"mu": mu})
               for m, mu in ((560.0, 0.012), (700.0, 0.02), (640.0, 0.03))]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        remote = run_sweep(spec, out_dir=tmp_path, chunk=2, scheduler=cluster.scheduler_address)
        client = connect(cluster.scheduler_address)
        try:
            remote_configs = run_configs(configs, chunk=2, client=client)  # what falsify sends, chunk by chunk
        finally:
            client.close()
    for a, b in zip(local, remote):
        for key in KEYS + ("m1", "run"):
            assert a[key] == b[key]
    for a, b in zip(run_configs(configs, chunk=2, nthread=1), remote_configs):
        for key in KEYS + ("m1",):
            assert a[key] == b[key]


def test_unreachable_scheduler_is_a_clear_error():
    with pytest.raises(SchedulerError, match="cannot reach"):
        run_sweep(SweepSpec(n=1, base=BASE), scheduler="tcp://127.0.0.1:9")


@pytest.mark.parametrize("kwargs,error", [({"n": 0}, ParameterError), ({"m1_range": (700.0, 600.0)}, ParameterError),
                                           ({"m1_range": (600.0, 600.0)}, ParameterError),
                                           ({"ranges": {"wheelbase": (1.0, 2.0)}}, UnknownNameError),
                                           ({"sampling": "sobol"}, UnknownNameError),
                                           ({"n": 10, "sampling": "grid", "ranges": {"mu": (0.01, 0.02)}},
                                            ParameterError)])
def test_bad_spec_raises(kwargs, error):
    with pytest.raises(error):
        SweepSpec(base=BASE, **kwargs)


def test_cli_sweep_json_and_files(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "sweep", "--n", "3", "--model", "nonholonomic",
                           "--duration", "10", "--out", str(tmp_path), "--json"],
                          capture_output=True, text=True, check=True)
    obj = json.loads(proc.stdout)
    for key in ("n", "inside", "outside", "worst_E_ratio", "worst_Edot_ratio", "steps_per_s"):
        assert key in obj
    rows = read_results(tmp_path / "runs.csv")
    assert obj["n"] == 3 and obj["inside"] + obj["outside"] == 3
    assert obj["batch_law"] == ["compiled"]  # the default where the compiled law is built (tests/test_compiled_law.py)
    assert obj["inside"] == sum(r["inside"] for r in rows)
    assert obj["worst_E_ratio"] == max(r["E_ratio"] for r in rows)
    assert (tmp_path / "region.png").stat().st_size > 1000


def test_uncertainty_box_and_ranges_from_the_command_line():
    import argparse

    from wmr_mj.commands._common import box_ranges_from_args
    from wmr_mj.params import uncertainty_ranges

    full = uncertainty_ranges("full")
    assert box_ranges_from_args(argparse.Namespace(uncertainty=None, range=None)) == {}
    args = argparse.Namespace(uncertainty="full", range=["mu=0.015:0.02", "l4=0.2:0.3"])
    got = box_ranges_from_args(args)
    assert got == {**{k: v for k, v in full.items() if k != "m1"}, "mu": (0.015, 0.02), "l4": (0.2, 0.3)}


@pytest.mark.parametrize("argv", [["--n", "0"], ["--m1-range", "750", "550"], ["--range", "nope=1:2"],
                                  ["--uncertainty", "nope"],
                                  ["--range", "mu=0.03:0.01"], ["--sampling", "sobol"],
                                  ["--scheduler", "tcp://127.0.0.1:9"], ["--range", "mu=abc"]])
def test_cli_sweep_bad_input_exits_2(argv, tmp_path):
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "sweep", "--duration", "10", "--out", str(tmp_path),
                           *argv],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "Traceback" not in proc.stderr


def test_cli_sweep_log_writes_replayable_mcap_per_run(tmp_path):
    from wmr_mj.logs import load_log

    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "sweep", "--n", "2", "--model", "nonholonomic",
                           "--duration", "10", "--out", str(tmp_path), "--log", "--json"],
                          capture_output=True, text=True, check=True)
    obj = json.loads(proc.stdout)
    rows = read_results(tmp_path / "runs.csv")
    logs = sorted((tmp_path / "mcap").glob("*.mcap"))
    assert len(logs) == 2 and obj["mcap_dir"] == str(tmp_path / "mcap")
    for path, row in zip(logs, rows):
        log = load_log(path)
        assert log.summary["sup_E"] == row["sup_E"]  # the logged re-run is the swept run, bit for bit
        assert float(np.max(np.abs(log.signals["E"]))) == row["sup_E"]


def test_certified_design_sweep_over_m1_is_certified_inside_for_every_run(tmp_path):
    """Issue 8: a sweep of the certified design over m1 550-750 kg has no run outside certified-inside."""
    from wmr_mj.designs import CERTIFIED
    from wmr_mj.params import M1_RANGE
    from wmr_mj.verdicts import count_verdicts

    base = RunConfig(**CERTIFIED.config_changes(), duration=35.0)
    spec = SweepSpec(n=8, seed=0, sampling="lhs", m1_range=M1_RANGE, base=base)
    rows = run_sweep(spec, out_dir=tmp_path)
    counts = count_verdicts(r["verdict"] for r in rows)
    assert counts["certified-inside"] == 8, counts
    assert max(r["cert_E_ratio"] for r in rows) < 1.0
    assert min(r["m1"] for r in rows) < 575.0 and max(r["m1"] for r in rows) > 725.0  # the range is covered
    saved = read_results(tmp_path / "runs.csv")  # the verdict columns survive the CSV
    assert [r["verdict"] for r in saved] == [r["verdict"] for r in rows]
    assert [r["cert_E_ratio"] for r in saved] == [r["cert_E_ratio"] for r in rows]


def test_batch_split_into_groups_is_bit_identical_to_one_group(monkeypatch):
    """Several groups on their own threads (what run_batch uses for large batches) give the same numbers."""
    import wmr_mj.sweep as sweep_module

    configs = [BASE.replace(m1=m) for m in (560.0, 610.0, 680.0, 745.0)]
    one = run_batch(configs, nthread=2, law="numpy")  # groups are the NumPy law's (the compiled law runs one)
    monkeypatch.setattr(sweep_module, "batch_groups",
                        lambda nsim, threads: [(np.array([0, 1]), 1), (np.array([2, 3]), 1)])
    two = run_batch(configs, nthread=2, law="numpy")
    for a, b in zip(one, two):
        for key in KEYS:
            assert a[key] == b[key], key
