"""Sweeps: batch == one by one, sampling, resume, Dask == local, bad input."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from wmr_mj import ParameterError, SchedulerError, UnknownNameError
from wmr_mj.simulate import RunConfig, run_closed_loop
from wmr_mj.sweep import SweepSpec, draw_samples, read_results, run_batch, run_sweep

BASE = RunConfig(model="nonholonomic", duration=10.0)
KEYS = ("sup_E", "sup_Edot", "sup_E_settled", "sup_Edot_settled", "E_max", "Edot_max", "saturated_fraction",
        "final_alpha", "inside", "left_steering_range", "left_steering_range_at_s")


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


def test_paper_model_batch_matches_serial_including_steering_stop():
    configs = [RunConfig(model="paper", duration=10.0, m1=m) for m in (560.0, 740.0)]
    for cfg, b in zip(configs, run_batch(configs, nthread=1)):
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
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        remote = run_sweep(spec, out_dir=tmp_path, chunk=2, scheduler=cluster.scheduler_address)
    for a, b in zip(local, remote):
        for key in KEYS + ("m1", "run"):
            assert a[key] == b[key]


def test_unreachable_scheduler_is_a_clear_error():
    with pytest.raises(SchedulerError, match="cannot reach"):
        run_sweep(SweepSpec(n=1, base=BASE), scheduler="tcp://127.0.0.1:9")


@pytest.mark.parametrize("kwargs,error", [({"n": 0}, ParameterError), ({"m1_range": (700.0, 600.0)}, ParameterError),
                                           ({"m1_range": (600.0, 600.0)}, ParameterError),
                                           ({"ranges": {"wheelbase": (1.0, 2.0)}}, UnknownNameError),
                                           ({"sampling": "sobol"}, UnknownNameError),
                                           ({"n": 10, "sampling": "grid", "ranges": {"mu": (0.01, 0.02)}}, ParameterError)])
def test_bad_spec_raises(kwargs, error):
    with pytest.raises(error):
        SweepSpec(base=BASE, **kwargs)


def test_cli_sweep_json_and_files(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "sweep", "--n", "3", "--model", "nonholonomic",
                           "--duration", "10", "--out", str(tmp_path), "--json"], capture_output=True, text=True, check=True)
    obj = json.loads(proc.stdout)
    for key in ("n", "inside", "outside", "worst_E_ratio", "worst_Edot_ratio", "steps_per_s"):
        assert key in obj
    rows = read_results(tmp_path / "runs.csv")
    assert obj["n"] == 3 and obj["inside"] + obj["outside"] == 3
    assert obj["inside"] == sum(r["inside"] for r in rows)
    assert obj["worst_E_ratio"] == max(r["E_ratio"] for r in rows)
    assert (tmp_path / "region.png").stat().st_size > 1000


@pytest.mark.parametrize("argv", [["--n", "0"], ["--m1-range", "750", "550"], ["--range", "nope=1:2"],
                                  ["--range", "mu=0.03:0.01"], ["--sampling", "sobol"],
                                  ["--scheduler", "tcp://127.0.0.1:9"], ["--range", "mu=abc"]])
def test_cli_sweep_bad_input_exits_2(argv, tmp_path):
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "sweep", "--duration", "10", "--out", str(tmp_path), *argv],
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
