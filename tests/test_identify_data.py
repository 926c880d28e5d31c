"""``wmr-mj identify --data``: a cart's recordings to a cart file with intervals, against a known truth.

The truth is a cart file the tests hold (tests/data/identify_truth.toml: ~100 kg chassis, 50:1 gear) that identify
never sees; its recordings are made by the testbed's own run with a sensed cart (a 12-bit axis encoder, a 5 ms
delay) under a dithered PD law (tests/data/identify_dithered_pd.py), the angle being what the law read and the
voltage what was applied. identify starts from tests/data/identify_start.toml (the truth with the steering beam's
mass, the motor constant and the friction written wrong) and must find the truth inside its 95 % intervals, the
delay to one control period, the encoder exactly.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from wmr_mj.carts import load_cart
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError
from wmr_mj.logs.recordings import read_run_log
from wmr_mj.params import parameters_of_cart
from wmr_mj.plant.output_error import MODEL_ERROR_FLOOR, POORLY_DETERMINED, Interval, fit_recordings
from wmr_mj.plant.recordings import Recording, check_recording, read_csv, write_csv
from wmr_mj.report.identify import IdentifyReport

DATA = Path(__file__).resolve().parent / "data"
TRUTH = DATA / "identify_truth.toml"
START = DATA / "identify_start.toml"
LAW = DATA / "identify_dithered_pd.py"
SENSING = "encoder_ticks=4096,velocity=difference,delay=0.005"  # the truth's sensor: 12 bits, 5 ms
TICKS, DELAY_S, PERIOD_S = 4096, 0.005, 0.001


def _record(path: str, seed: int, duration: float) -> dict[str, np.ndarray]:
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig

    cfg = RunConfig.from_inputs(cart=str(TRUTH), sensing=SENSING, path=path, duration=duration,
                                controller=f"{LAW}:DitheredPD", controller_params={"seed": seed})
    return dict(run_closed_loop(cfg, progress=False).rows)


def _write_csv(rows: dict[str, np.ndarray], path: Path, n: int | None = None) -> Path:
    sl = slice(0, n)
    return write_csv(path, {"t_s": rows["t"][sl], "u_V": rows["voltage"][sl], "alpha_rad": rows["alpha_measured"][sl]})


@pytest.fixture(scope="module")
def recordings(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("identify")
    lane = _record("lane-change", 0, 30.0)
    eight = _record("figure-eight", 1, 20.0)
    hold = _record("lane-change", 2, 10.0)
    return {"lane": _write_csv(lane, folder / "lane.csv", 20_000), "eight": _write_csv(eight, folder / "eight.csv"),
            "hold": _write_csv(hold, folder / "hold.csv"), "lane_short": _write_csv(lane, folder / "short.csv", 8_000),
            "lane_long": _write_csv(lane, folder / "long.csv"), "folder": folder}


@pytest.fixture(scope="module")
def identified(recordings: dict[str, Path]) -> tuple[dict, Path, int]:
    out = recordings["folder"] / "new.toml"
    code, printed = _main_json(["identify", "--cart", str(START), "--data", f"{recordings['lane']}:m1=100",
                                "--data", str(recordings["eight"]), "--holdout", str(recordings["hold"]),
                                "--out", str(out), "--json", "--report", str(recordings["folder"] / "report")])
    return printed, out, code


def _main_json(argv: list[str]) -> tuple[int, dict]:
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(argv)
    return code, json.loads(buf.getvalue())


def test_identify_recovers_the_truth_within_its_intervals(identified):
    obj, _out, code = identified
    truth = parameters_of_cart(load_cart(TRUTH))
    coefficients = truth.coefficients("nonholonomic")
    assert code == 0
    for name in ("P", "C_V", "F", "gyro"):
        lo, hi = obj["coefficients"][name]["interval"]
        assert lo <= getattr(coefficients, name) <= hi, (name, lo, hi, getattr(coefficients, name))
    for name in ("front_axle_mass", "k_i", "mu"):
        lo, hi = obj["physical"][name]["interval"]
        assert lo <= getattr(truth, name) <= hi, (name, lo, hi, getattr(truth, name))
    start = parameters_of_cart(load_cart(START))
    for name in ("front_axle_mass", "k_i", "mu"):  # the start is outside: the intervals were found, not copied
        lo, hi = obj["physical"][name]["interval"]
        assert not lo <= getattr(start, name) <= hi


def test_delay_to_one_period_and_encoder_exactly(identified):
    obj, _out, _code = identified
    assert abs(obj["sensing_delay_s"]["value"] - DELAY_S) <= PERIOD_S + 1e-12
    lo, hi = obj["sensing_delay_s"]["interval"]
    assert lo - 1e-12 <= DELAY_S <= hi + 1e-12
    assert obj["encoder_ticks"] == TICKS
    assert obj["noise_rad"] == 0.0  # every reading on the encoder's grid: no noise beyond it


def test_the_new_cart_file_names_its_data_and_passes_the_checks(identified, recordings):
    obj, out, _code = identified
    cart = load_cart(out)
    params = parameters_of_cart(cart)  # the parameter set accepts it (check_physical_sense)
    assert cart.version == "1.1.0"
    for name in ("front_axle_mass", "k_i", "k_b", "mu"):
        src = cart.sources[name]
        assert src.startswith("identified from ") and "SHA-256 " in src and "95 % interval [" in src
        lo, hi = cart.uncertainty["full"][name]
        assert lo <= cart.parameters[name] <= hi
        assert [lo, hi] == pytest.approx(obj["physical"][name]["interval"], rel=0, abs=0)
    assert "encoder_ticks=4096" in cart.defaults["sensing"] and "delay=0.005" in cart.defaults["sensing"]
    assert params.k_i == params.k_b
    assert obj["cart"] == str(out)
    assert main(["cart", "check", str(out)]) == 0


def test_holdout_predicted_and_a_wrong_model_fails_it(identified, recordings):
    from wmr_mj.plant.output_error import HOLDOUT_NRMSE_MAX, holdout_error

    obj, _out, _code = identified
    assert obj["holdout"]["passed"] and obj["holdout"]["nrmse"] < HOLDOUT_NRMSE_MAX
    start = parameters_of_cart(load_cart(START))
    rec = read_csv(recordings["hold"])
    fit = fit_recordings([read_csv(recordings["lane_short"])], start, draws=50)
    assert holdout_error(fit, rec, start) < HOLDOUT_NRMSE_MAX
    off = {k: Interval(v.value * (0.5 if k in ("P", "C_V") else 1.6), v.lo, v.hi) for k, v in fit.coefficients.items()}
    wrong = dataclasses.replace(fit, coefficients=off)  # P, C_V halved, F 60 % up
    assert holdout_error(wrong, rec, start) > HOLDOUT_NRMSE_MAX


def test_intervals_shrink_as_the_recording_lengthens(recordings):
    start = parameters_of_cart(load_cart(START))
    short = fit_recordings([read_csv(recordings["lane_short"])], start)
    long = fit_recordings([read_csv(recordings["lane_long"])], start)
    # the bootstrap's spread (the data's part of each interval) shrinks with 8 s -> 30 s of recording
    assert np.all(np.std(long.draws, axis=0) < np.std(short.draws, axis=0))
    # and no interval widens; each holds at least the model-error floor (MODEL_ERROR_FLOOR), which a longer
    # recording cannot shrink
    for name in ("P", "C_V", "F"):
        short_width, long_width = (fit.coefficients[name].hi - fit.coefficients[name].lo for fit in (short, long))
        assert long_width <= short_width * (1 + 1e-9), name
        assert long_width >= 2 * MODEL_ERROR_FLOOR * long.coefficients[name].value * (1 - 1e-9)


# ----------------------------------------------------------------------------------------------- bad data


def _rec(**changes) -> Recording:
    t = np.arange(3000) * 0.001
    base = {"name": "r.csv", "sha256": "0", "t": t, "voltage": np.sin(t), "alpha": 0.1 * np.sin(2 * t)}
    base.update(changes)
    return Recording(**base)


@pytest.mark.parametrize("changes, words", [
    ({"t": np.r_[np.arange(1500), np.arange(1499, 2999)] * 0.001}, "time goes backwards"),
    ({"t": np.r_[np.arange(1500), np.arange(1510, 3010)] * 0.001}, "a gap"),
    ({"voltage": np.r_[np.sin(np.arange(10)), np.nan, np.zeros(2989)]}, "not a number"),
    ({"voltage": np.full(3000, 1.0)}, "u_V is constant"),
    ({"alpha": np.zeros(3000)}, "alpha_rad is constant"),
    ({"t": np.arange(1000) * 0.001, "voltage": np.sin(np.arange(1000.0)), "alpha": np.sin(np.arange(1000.0)) * 0.1},
     "long; accepted: at least"),
    ({"alpha": 2.0 * np.sin(np.arange(3000) * 0.001)}, "beyond the cart's stops"),
    ({"voltage": 30.0 * np.sin(np.arange(3000) * 0.001)}, "beyond the cart's supply"),
])
def test_bad_data_one_line(changes, words):
    with pytest.raises(ParameterError) as err:
        check_recording(_rec(**changes), voltage_limit=24.0, steering_range=0.9)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_bad_csv_exit_2(tmp_path, capsys):
    missing = tmp_path / "missing.csv"
    missing.write_text("t_s,u_V\n0,1\n0.001,2\n", encoding="utf-8")
    degrees = tmp_path / "deg.csv"
    degrees.write_text("t_s,u_V,alpha_deg\n0,1,2\n", encoding="utf-8")
    for path, words in ((missing, "column 'alpha_rad'"), (degrees, "other units")):
        code = main(["identify", "--cart", str(START), "--data", str(path), "--out", str(tmp_path / "x.toml")])
        err = capsys.readouterr().err.strip()
        assert code == 2 and words in err and "\n" not in err
    assert not (tmp_path / "x.toml").exists()


def test_columns_map_other_names(tmp_path):
    path = tmp_path / "named.csv"
    path.write_text("time,volts,steer\n0,1,0.1\n0.001,2,0.2\n", encoding="utf-8")
    rec = read_csv(path, columns={"t_s": "time", "u_V": "volts", "alpha_rad": "steer"})
    assert rec.voltage.tolist() == [1.0, 2.0] and rec.alpha.tolist() == [0.1, 0.2]


def test_excite_writes_a_plan_within_the_stops_and_the_supply(tmp_path, capsys):
    out = tmp_path / "plan.csv"
    assert main(["excite", "--cart", str(TRUTH), "--duration", "6", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    plan = np.loadtxt(out, delimiter=",", skiprows=1)
    truth = parameters_of_cart(load_cart(TRUTH))
    assert out.read_text(encoding="utf-8").startswith("t_s,alpha0_rad,u_dither_V\n") and plan.shape == (6000, 3)
    assert np.max(np.abs(plan[:, 1])) <= truth.steering_range and np.max(np.abs(plan[:, 2])) <= truth.voltage_limit
    assert "front_axle_mass" in printed and "mu" in printed
    assert "poorly determined" in printed or "every identified parameter within" in printed


def test_report_html_beside_png_and_the_result_reads(identified, recordings):
    obj, _out, _code = identified
    folder = recordings["folder"] / "report"
    assert sorted(Path(p).name for p in obj["report"]) == ["identify.html", "identify.png"]
    assert (folder / "identify.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    page = (folder / "identify.html").read_text(encoding="utf-8")
    assert "95 % interval" in page and "identify.png" in page and "Hold-out" in page
    start = parameters_of_cart(load_cart(START))
    fit = fit_recordings([read_csv(recordings["lane_short"])], start, draws=50)
    report = IdentifyReport.of(fit, [read_csv(recordings["lane_short"])], start)
    table = report.to_pandas()
    assert table.loc["P", "value"] == fit.coefficients["P"].value and table.loc["mu", "unit"] == "-"
    assert len(report.plot().axes) == 2


def test_a_run_log_is_a_recording_with_its_m1(tmp_path):
    log = tmp_path / "run.mcap"
    code = main(["run", "--cart", str(TRUTH), "--controller", f"{LAW}:DitheredPD", "--sensing", SENSING,
                 "--path", "lane-change", "--duration", "4", "--m1", "110", "--out", str(log), "--no-progress"])
    assert code == 0
    rec = read_run_log(log)
    assert rec.m1 == 110.0 and rec.samples == 4000 and rec.sha256
    counts = rec.alpha * TICKS / (2 * np.pi)
    assert np.max(np.abs(counts - np.rint(counts))) < 1e-6  # the angle the law read, on the encoder's grid


def test_the_jacobians_intervals_are_far_narrower_than_the_bootstraps(recordings):
    """What mujoco.sysid.calculate_intervals computes (s^2 and the Jacobian) on a quantised closed-loop recording,
    beside the block bootstrap: the data's own part of the bootstrap's interval (the model floor aside) is wider."""
    start = parameters_of_cart(load_cart(START))
    fit = fit_recordings([read_csv(recordings["lane_long"])], start)
    for i, name in enumerate(("P", "C_V", "F")):
        lo, hi = np.percentile(fit.draws[:, i], [2.5, 97.5])
        assert 0 < fit.jacobian_half_width[name] < 0.5 * (hi - lo) / 2, name


def test_a_recording_that_does_not_excite_the_inertia_leaves_it_wide(tmp_path):
    """No dither: a PD tracking a smooth lane change hides P alpha'' (a few per cent of the voltage): the
    inertia's interval comes out wide, never a confident wrong number."""
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig

    truth = parameters_of_cart(load_cart(TRUTH))
    cfg = RunConfig.from_inputs(cart=str(TRUTH), sensing=SENSING, path="lane-change", duration=12.0,
                                controller=f"{LAW}:DitheredPD", controller_params={"amplitude": 0.0})
    rec = read_csv(_write_csv(dict(run_closed_loop(cfg, progress=False).rows), tmp_path / "smooth.csv"))
    fit = fit_recordings([rec], parameters_of_cart(load_cart(START)))
    iv = fit.physical["front_axle_mass"]
    assert iv.contains(truth.front_axle_mass) or iv.relative_half_width > 0.5
    assert iv.relative_half_width > POORLY_DETERMINED  # identify warns
    assert fit.delay.contains(DELAY_S)  # the delay, which trades with the inertia, is left open too


def test_a_ros2_bag_with_topics(recordings, tmp_path, capsys):
    """A ROS 2 bag (std_msgs/Float64 on two topics, written by mcap-ros2-support) identifies as its CSV does."""
    from mcap_ros2.writer import Writer

    rec = read_csv(recordings["lane_short"])
    bag = tmp_path / "bag.mcap"
    with open(bag, "wb") as f:
        writer = Writer(f)
        schema = writer.register_msgdef("std_msgs/Float64", "float64 data")
        for t, u, a in zip(rec.t, rec.voltage, rec.alpha):
            ns = int(round(t * 1e9)) + 1_000_000_000
            writer.write_message("/steer/voltage", schema, {"data": float(u)}, log_time=ns)
            writer.write_message("/steer/angle", schema, {"data": float(a)}, log_time=ns)
        writer.finish()
    argv = ["identify", "--cart", str(START), "--data", f"{bag}:m1=100", "--topics",
            "u=/steer/voltage,alpha=/steer/angle", "--out", str(tmp_path / "bag.toml"), "--json"]
    code, obj = _main_json(argv)
    assert code == 0 and obj["encoder_ticks"] == TICKS and obj["m1_kg"] == [100.0]
    missing = ["identify", "--cart", str(START), "--data", str(bag), "--topics", "u=/steer/voltage,alpha=/nope",
               "--out", str(tmp_path / "x.toml")]
    assert main(missing) == 2 and "topic /nope is missing" in capsys.readouterr().err


def test_encoder_and_noise_read_through_noise(tmp_path):
    """Uniform noise of 0.5 mrad after a 12-bit quantisation (a third of a tick): no reading on the grid, yet the
    readings concentrate on it; the noise is their distance to it, standard deviation B/sqrt(3)."""
    log = tmp_path / "noisy.mcap"
    assert main(["run", "--cart", str(TRUTH), "--controller", f"{LAW}:DitheredPD", "--sensing",
                 SENSING + ",noise=uniform:0.0005,seed=4", "--path", "lane-change", "--duration", "6",
                 "--out", str(log), "--no-progress"]) == 0
    code, obj = _main_json(["identify", "--cart", str(START), "--data", str(log), "--out", str(tmp_path / "n.toml"),
                            "--json"])
    assert code == 0 and obj["encoder_ticks"] == TICKS
    assert obj["noise_rad"] == pytest.approx(0.0005 / np.sqrt(3), rel=0.03)  # 6000 draws: 1 % standard error
    assert "noise=uniform:" in load_cart(tmp_path / "n.toml").defaults["sensing"]


def test_a_speed_column_is_the_speed_the_gyro_term_sees(recordings, tmp_path):
    """speed_m_per_s, where recorded, enters gyro V alpha'/cos^2: the cart's V_A written as a column gives the fit
    without it, to rounding; twice V_A another fit."""
    start = parameters_of_cart(load_cart(START))
    rec = read_csv(recordings["lane_short"])
    same = dataclasses.replace(rec, speed=np.full(rec.samples, start.V_A))
    double = dataclasses.replace(rec, speed=np.full(rec.samples, 2 * start.V_A))
    fits = [fit_recordings([r], start, draws=20) for r in (rec, same, double)]
    values = [np.array([f.coefficients[k].value for k in ("P", "C_V", "F")]) for f in fits]
    np.testing.assert_allclose(values[1], values[0], rtol=1e-9)
    assert not np.allclose(values[2], values[0], rtol=1e-3)
    path = tmp_path / "speed.csv"
    path.write_text("t_s,u_V,alpha_rad,speed_m_per_s\n0,1,0.1,0.2\n0.001,2,0.2,0.3\n", encoding="utf-8")
    assert read_csv(path).speed.tolist() == [0.2, 0.3]


# ----------------------------------------------------------------------------------------------- mujoco.sysid


def _sysid_installed() -> bool:
    from wmr_mj.plant.mjcf_rollouts import import_sysid

    try:
        import_sysid()
    except ParameterError:
        return False
    return True


@pytest.mark.slow
@pytest.mark.skipif(not _sysid_installed(), reason="the sysid extra (pip install 'wmr-mj[sysid]') is not installed")
def test_sysid_rolls_out_the_identified_mjcf_on_the_holdout(recordings, tmp_path):
    """identify --sysid: the identified cart file's MJCF, rolled out by mujoco.sysid from each segment's recorded
    state, predicts the hold-out as the reduced model does; the start's MJCF does not (the same rollouts)."""
    from wmr_mj.plant.mjcf_rollouts import mjcf_rollout_nrmse
    from wmr_mj.plant.output_error import HOLDOUT_NRMSE_MAX

    out = tmp_path / "s.toml"
    code, obj = _main_json(["identify", "--cart", str(START), "--data", f"{recordings['lane_short']}:m1=100",
                            "--holdout", str(recordings["hold"]), "--out", str(out), "--json", "--sysid"])
    hold = str(recordings["hold"])
    assert code == 0 and obj["mjcf_rollouts"]["nrmse"][hold] < HOLDOUT_NRMSE_MAX
    rec = read_csv(recordings["hold"])
    truth = mjcf_rollout_nrmse(parameters_of_cart(load_cart(TRUTH)), [rec], delay_steps=5)
    start = mjcf_rollout_nrmse(parameters_of_cart(load_cart(START)), [rec], delay_steps=5)
    assert truth < HOLDOUT_NRMSE_MAX < start  # the rollouts tell the true cart from the start
    assert obj["mjcf_rollouts"]["nrmse"][hold] == pytest.approx(truth, rel=0.25)  # within the fit's spread


def test_sysid_without_the_extra_is_one_line_exit_2(tmp_path, capsys, monkeypatch):
    import importlib

    real = importlib.import_module

    def without_sysid(name, *args, **kwargs):
        if name == "mujoco.sysid":
            raise ImportError("No module named 'absl'")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(importlib, "import_module", without_sysid)
    path = tmp_path / "r.csv"
    path.write_text("t_s,u_V,alpha_rad\n0,1,0.1\n0.001,2,0.2\n", encoding="utf-8")
    code = main(["identify", "--cart", str(START), "--data", str(path), "--out", str(tmp_path / "x.toml"), "--sysid"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "pip install 'wmr-mj[sysid]'" in err and "\n" not in err
    assert not (tmp_path / "x.toml").exists()
    assert main(["identify", "--sysid"]) == 2  # the simulated plant's identify has no recording to roll out
    assert "--sysid need --data" in capsys.readouterr().err


def test_identified_from_reads_the_files_and_hashes_a_cart_names(tmp_path):
    """wmr_mj.carts.provenance: the recordings an identified cart's sources name, each once; none for a cart written
    by hand. A file name with ' and ' in it stays whole."""
    from wmr_mj.carts.provenance import identified_from, identified_from_line

    a, b = "0" * 64, "ab" * 32
    text = START.read_text(encoding="utf-8")
    assert identified_from(text) == () and identified_from_line(text, "lab cart") is None
    source = f"identified from runs/lane and turn.csv (SHA-256 {a}) and eight.csv (SHA-256 {b}), 95 % interval [1, 2]"
    named = text.replace('source = "the start the tests give identify (the truth\'s structure; front_axle_mass, k_i, '
                          'k_b, mu written wrong), chosen"', f'source = "{source}"')
    assert identified_from(named) == (("runs/lane and turn.csv", a), ("eight.csv", b))
    line = identified_from_line(named, "lab cart")
    assert line is not None and "runs/lane and turn.csv (SHA-256 000000000000...)" in line
    assert identified_from("not = [toml") == ()


def test_a_recording_written_by_write_csv_reads_back_to_the_bit(tmp_path):
    """write_csv is read_csv's format written: every sample back bit for bit (repr of a float is exact), the
    optional column kept, and a column the reader does not know refused in one line."""
    rng = np.random.default_rng(3)
    t = np.arange(2500) * 1e-3
    u, alpha, applied = rng.normal(0, 5, t.size), rng.normal(0, 0.3, t.size), rng.normal(0, 5, t.size)
    rec = read_csv(write_csv(tmp_path / "r.csv", {"t_s": t, "u_V": u, "alpha_rad": alpha, "u_applied_V": applied}))
    for got, want in ((rec.t, t), (rec.voltage, u), (rec.alpha, alpha), (rec.applied, applied)):
        assert np.asarray(got).tobytes() == want.tobytes()
    with pytest.raises(ParameterError, match="volts not known"):
        write_csv(tmp_path / "bad.csv", {"t_s": t, "u_V": u, "alpha_rad": alpha, "volts": u})
    with pytest.raises(ParameterError, match="differ in length"):
        write_csv(tmp_path / "bad.csv", {"t_s": t, "u_V": u[:-1], "alpha_rad": alpha})
