"""Sweeps: sampling, resume, Dask == local, the command line, bad input."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from wmr_mj import ParameterError, SchedulerError, UnknownNameError
from wmr_mj.experiments.sweep import (
    SweepSpec,
    draw_samples,
    read_results,
    read_runs,
    run_sweep,
)
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.many_runs import connect, latin_hypercube, run_configs

BASE = RunConfig(model="nonholonomic", duration=10.0)
KEYS = ("sup_E", "sup_Edot", "sup_E_settled", "sup_Edot_settled", "E_max", "Edot_max", "saturated_fraction",
        "final_alpha", "inside", "left_steering_range", "left_steering_range_at_s",
        "verdict", "certificate", "paper_region", "drift")

def test_latin_hypercube_is_scipys():
    from scipy.stats import qmc

    for n, d, seed in ((1, 1, 0), (7, 3, 5), (50, 5, 1)):
        expected = qmc.LatinHypercube(d=d, rng=np.random.default_rng(seed)).random(n)
        assert np.array_equal(latin_hypercube(n, d, np.random.default_rng(seed).spawn(1)[0]), expected)


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


@pytest.mark.slow
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


@pytest.mark.slow
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
        a, b = a.to_dict(), b.to_dict()
        for key in KEYS + ("m1",):
            assert a[key] == b[key]


@pytest.mark.slow
def test_unreachable_scheduler_is_a_clear_error(tmp_path):
    with pytest.raises(SchedulerError, match="cannot reach"):
        run_sweep(SweepSpec(n=1, base=BASE), out_dir=tmp_path / "sweep", scheduler="tcp://127.0.0.1:9")
    assert not (tmp_path / "sweep").exists()  # refused before the folder and its sweep.json are written


@pytest.mark.parametrize("kwargs,error", [({"n": 0}, ParameterError), ({"m1_range": (700.0, 600.0)}, ParameterError),
                                           ({"m1_range": (600.0, 600.0)}, ParameterError),
                                           ({"ranges": {"wheelbase": (1.0, 2.0)}}, UnknownNameError),
                                           ({"sampling": "sobol"}, UnknownNameError),
                                           ({"n": 10, "sampling": "grid", "ranges": {"mu": (0.01, 0.02)}},
                                            ParameterError)])
def test_bad_spec_raises(kwargs, error):
    with pytest.raises(error):
        SweepSpec(base=BASE, **kwargs)


@pytest.mark.slow
def test_cli_sweep_json_and_files(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "sweep", "--n", "3", "--model", "nonholonomic",
                           "--duration", "10", "--out", str(tmp_path), "--json"],
                          capture_output=True, text=True, check=True)
    obj = json.loads(proc.stdout)
    for key in ("n", "paper_inside", "paper_outside", "worst_paper_E_ratio", "worst_paper_Edot_ratio", "steps_per_s"):
        assert key in obj
    rows = read_runs(tmp_path)  # full precision (runs.csv rounds)
    assert obj["n"] == 3 and obj["paper_inside"] + obj["paper_outside"] == 3
    assert obj["batch_law"] == ["compiled"]  # the default where the compiled law is built (tests/test_compiled_law.py)
    assert obj["paper_inside"] == sum(r["inside"] for r in rows)
    assert obj["worst_paper_E_ratio"] == max(r["E_ratio"] for r in rows)
    assert (tmp_path / "region.png").stat().st_size > 1000


def test_uncertainty_box_and_ranges_from_the_command_line():
    import argparse

    from wmr_mj.cli.ranges import box_ranges_from_args
    from wmr_mj.params import uncertainty_ranges

    full = uncertainty_ranges("full")
    assert box_ranges_from_args(argparse.Namespace(uncertainty=None, range=None)) == {}
    args = argparse.Namespace(uncertainty="full", range=["mu=0.015:0.02", "l4=0.2:0.3"])
    got = box_ranges_from_args(args)
    assert got == {**{k: v for k, v in full.items() if k != "m1"}, "mu": (0.015, 0.02), "l4": (0.2, 0.3)}


@pytest.mark.slow
@pytest.mark.parametrize("argv", [["--n", "0"], ["--m1-range", "750", "550"], ["--range", "nope=1:2"],
                                  ["--uncertainty", "nope"],
                                  ["--range", "mu=0.03:0.01"], ["--sampling", "sobol"],
                                  ["--scheduler", "tcp://127.0.0.1:9"], ["--range", "mu=abc"]])
def test_cli_sweep_bad_input_exits_2(argv, tmp_path):
    out = tmp_path / "sweep"
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "sweep", "--duration", "10", "--out", str(out),
                           *argv],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "Traceback" not in proc.stderr
    assert not out.exists()  # refused before anything is written


@pytest.mark.slow
def test_cli_sweep_log_writes_replayable_mcap_per_run(tmp_path):
    from wmr_mj.logs.reader import load_log

    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "sweep", "--n", "2", "--model", "nonholonomic",
                           "--duration", "10", "--out", str(tmp_path), "--log", "--json"],
                          capture_output=True, text=True, check=True)
    obj = json.loads(proc.stdout)
    rows = read_runs(tmp_path)  # full precision (runs.csv rounds)
    logs = sorted((tmp_path / "mcap").glob("*.mcap"))
    assert len(logs) == 2 and obj["mcap_dir"] == str(tmp_path / "mcap")
    for path, row in zip(logs, rows):
        log = load_log(path)
        assert log.summary["sup_E"] == row["sup_E"]  # the logged re-run is the swept run, bit for bit
        assert float(np.max(np.abs(log.signals["E"]))) == row["sup_E"]


@pytest.mark.slow
def test_certified_design_sweep_over_m1_is_certified_inside_for_every_run(tmp_path):
    """Issue 8: a sweep of the certified design over m1 550-750 kg has no run outside certified-inside."""
    from wmr_mj.analysis.verdicts import count_verdicts
    from wmr_mj.params import M1_RANGE
    from wmr_mj.sim.designs import CERTIFIED

    base = RunConfig(**CERTIFIED.config_changes(), duration=35.0)
    spec = SweepSpec(n=8, seed=0, sampling="lhs", m1_range=M1_RANGE, base=base)
    rows = run_sweep(spec, out_dir=tmp_path)
    counts = count_verdicts(r["verdict"] for r in rows)
    assert counts["certified-inside"] == 8, counts
    assert max(r["cert_E_ratio"] for r in rows) < 1.0
    assert min(r["m1"] for r in rows) < 575.0 and max(r["m1"] for r in rows) > 725.0  # the range is covered
    saved = read_runs(tmp_path)  # the verdict columns survive the CSV (its numbers: at full precision)
    assert [r["verdict"] for r in saved] == [r["verdict"] for r in rows]
    assert [r["cert_E_ratio"] for r in saved] == [r["cert_E_ratio"] for r in rows]



def test_cli_sweep_reports_each_requirement_and_the_signals(tmp_path, capsys):
    """sweep --require: each run's robustness (runs.csv) is `wmr-mj run --require`'s for that plant,
    bit for bit, and the summary's least robustness is the least of the rows; --disturbance applies
    to every run and is reported with every parameter."""
    from wmr_mj.cli.app import main

    common = ["--preset", "certified", "--path", "lane-change", "--duration", "3",
              "--disturbance", "kind=step,amplitude=2,t1=1"]
    requirements = ["always[1,3](abs(E) <= 0.01)", "certificate"]
    argv = ["sweep", *common, "--n", "3", "--out", str(tmp_path / "s"), "--json"]
    for text in requirements:
        argv += ["--require", text]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    rows = read_runs(tmp_path / "s")  # full precision (runs.csv rounds)
    assert summary["signals"]["disturbance"] == {"kind": "step", "amplitude": 2.0, "t1": 1.0}
    for i, (text, judged) in enumerate(zip(requirements, summary["requirements"])):
        column = f"requirement_{i + 1}_robustness"
        values = [r[column] for r in rows]
        assert judged["requirement"] == text and judged["column"] == column
        assert judged["min_robustness"] == min(values)
        assert judged["satisfied"] + judged["violated"] == 3 and judged["satisfied"] == sum(v >= 0 for v in values)
    row = rows[int(summary["requirements"][0]["run"])]
    assert main(["run", *common, "--m1", repr(row["m1"]), "--no-log", "--json",
                 *[x for text in requirements for x in ("--require", text)]]) == 0
    single = json.loads(capsys.readouterr().out)
    assert [r["robustness"] for r in single["requirements"]] == [row["requirement_1_robustness"],
                                                                 row["requirement_2_robustness"]]
    assert single["sup_E"] == row["sup_E"]


def test_bench_sweep_refuses_an_unknown_projection_in_one_line():
    """bench/bench_sweep.py --projections: only C and NumPy; anything else is named, exit 2, before any run."""
    from pathlib import Path

    bench = Path(__file__).resolve().parent.parent / "bench" / "bench_sweep.py"
    out = subprocess.run([sys.executable, str(bench), "--projections", "C,numba"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert "--projections takes C, NumPy or both (got 'C,numba')" in out.stderr.splitlines()[-1]


def test_bench_sweep_refuses_the_c_projection_where_it_is_not_built_in_one_line():
    """--projections C where wmr_mj.analysis._nearest_chord cannot be imported (here: blocked in sys.modules):
    one line naming the way out, exit 2, before any run."""
    from pathlib import Path

    bench = Path(__file__).resolve().parent.parent / "bench" / "bench_sweep.py"
    code = ("import runpy, sys; sys.modules['wmr_mj.analysis._nearest_chord'] = None; "
            f"sys.argv = [{str(bench)!r}, '--projections', 'C']; runpy.run_path(sys.argv[0], run_name='__main__')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert out.stderr.splitlines()[-1].endswith("--projections C: the C projection is not built here "
                                                "(wmr_mj.analysis._nearest_chord); give NumPy")
