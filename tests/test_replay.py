"""`wmr-mj replay` and wmr_mj.logs.replay: summary, --json, --plot, --verify (bit for bit, on a
synthetic log and on a real closed-loop run), --video and bad input."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from helpers import StopAfter3000Rows, chunk_spans, synthetic_run

from wmr_mj.cli.app import main


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("replay")
    honest = d / "honest.mcap"
    synthetic_run(honest, 1.0, block_rows=100, substeps=2, flush_period_s=0.2, summary={"sup_E": 0.3})
    tampered = d / "tampered.mcap"
    synthetic_run(tampered, 1.0, block_rows=100, substeps=2, flush_period_s=0.2, tamper_at=300)
    return {"dir": d, "honest": honest, "tampered": tampered}


def _run(capsys, *argv):
    code = main(["replay", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


def test_summary_text(logs, capsys):
    code, out, err = _run(capsys, logs["honest"])
    assert code == 0 and err == ""
    assert "completed" in out and "sup|E|" in out and "sup|E'|" in out
    assert "t >= 0.5 s" in out  # settle_s from the config
    assert "E_max = 0.5 rad" in out and ("INSIDE" in out or "OUTSIDE" in out)
    assert "controller=test" in out


def test_summary_json(logs, capsys):
    code, out, _ = _run(capsys, logs["honest"], "--json")
    assert code == 0
    rep = json.loads(out)
    assert rep["status"] == "completed" and rep["truncated"] is False
    assert rep["rows"] == 500 and rep["control_substeps"] == 2
    assert rep["E_max"] == 0.5 and rep["Edot_max"] == 2.0 and rep["settle_s"] == 0.5
    assert isinstance(rep["inside"], bool) and isinstance(rep["inside_after_settle"], bool)
    assert rep["sup_abs_E"] >= rep["sup_abs_E_after_settle"] > 0
    assert rep["summary"]["sup_E"] == 0.3


def test_verify_honest_log_is_bit_identical(logs, capsys):
    code, out, _ = _run(capsys, logs["honest"], "--verify")
    assert code == 0
    assert "bit-identical" in out and "1000 mj_step" in out


def test_verify_tampered_log_fails(logs, capsys):
    code, out, _ = _run(capsys, logs["tampered"], "--verify", "--json")
    assert code == 1
    ver = json.loads(out)["verify"]
    assert ver["identical"] is False
    assert ver["first_mismatch_row"] == 300 and ver["max_deviation_in"] == "qpos"
    assert ver["max_deviation"] > 0 and ver["max_deviation_t"] == pytest.approx(0.6)
    code, out, _ = _run(capsys, logs["tampered"], "--verify")
    assert code == 1 and "MISMATCH: largest deviation" in out and "t = 0.6" in out


@pytest.mark.slow
def test_plot(logs, capsys):
    png = logs["dir"] / "fig" / "honest.png"
    code, out, _ = _run(capsys, logs["honest"], "--plot", png)
    assert code == 0 and str(png) in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20000


def test_video_renders_or_says_why(logs, capsys):
    mp4 = logs["dir"] / "honest.mp4"
    code, out, err = _run(capsys, logs["honest"], "--video", mp4, "--fps", "5", "--size", "160x120")
    if code == 0:
        assert mp4.stat().st_size > 0
    else:
        assert code == 2
        assert err.count("\n") == 1 and err.startswith("wmr-mj: error: ")
        assert "no OpenGL backend (EGL/OSMesa) available" in err or "no mp4 writer" in err


def test_truncated_log_replays(logs, capsys):
    data = logs["honest"].read_bytes()
    start, length = chunk_spans(logs["honest"])[-3]
    cut = logs["dir"] / "cut.mcap"
    cut.write_bytes(data[: start + length // 2])
    code, out, _ = _run(capsys, cut)
    assert code == 0 and "TRUNCATED" in out
    code, out, _ = _run(capsys, cut, "--json", "--verify")
    rep = json.loads(out)
    assert rep["truncated"] is True and rep["status"] == "truncated"
    assert code == 0 and rep["verify"]["identical"] is True and 0 < rep["rows"] < 500


@pytest.mark.parametrize("case", ["missing", "not_mcap", "corrupt_chunk", "unknown_version", "cut_header"])
def test_bad_input_exit_2_one_line(logs, capsys, monkeypatch, case):
    d = logs["dir"]
    path = d / f"{case}.mcap"
    if case == "not_mcap":
        path.write_bytes(b"PK\x03\x04 definitely not an MCAP file" * 10)
    elif case == "corrupt_chunk":
        data = bytearray(logs["honest"].read_bytes())
        start, length = chunk_spans(logs["honest"])[2]
        for k in range(8):
            data[start + length - 20 - k] ^= 0xA5
        path.write_bytes(bytes(data))
    elif case == "unknown_version":
        import wmr_mj.logs.logformat as logformat

        monkeypatch.setattr(logformat, "SCHEMA_VERSION", "1")  # what the hand-written writer made
        synthetic_run(path, 0.05)
    elif case == "cut_header":
        path.write_bytes(logs["honest"].read_bytes()[:100])
    code, out, err = _run(capsys, path)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("wmr-mj: error: ") and str(path) in err
    assert "Traceback" not in err


@pytest.mark.slow
def test_bad_input_subprocess_no_traceback(logs):
    bad = logs["dir"] / "junk.mcap"
    bad.write_bytes(np.random.default_rng(0).bytes(4096))
    for path in (bad, logs["dir"] / "nowhere.mcap"):
        proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "replay", str(path)], capture_output=True, text=True)
        assert proc.returncode == 2
        assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr and str(path) in proc.stderr


def test_video_without_gl_backend_says_so(logs, capsys, monkeypatch):
    import wmr_mj.logs.video as video

    monkeypatch.delenv("MUJOCO_GL", raising=False)
    monkeypatch.setattr(video, "BACKENDS", ("no-such-backend",))  # MuJoCo refuses this MUJOCO_GL
    code, out, err = _run(capsys, logs["honest"], "--video", logs["dir"] / "x.mp4")
    assert code == 2 and out == ""
    assert err.count("\n") == 1
    assert "no OpenGL backend (EGL/OSMesa) available: no-such-backend: " in err


def test_real_run_replays_bit_for_bit(tmp_path, capsys):
    """The closed-loop runner's own log (C80 plant, paper circle, interrupted after 3 s) verifies."""
    from wmr_mj.logs.reader import load_log
    from wmr_mj.logs.replay import summarize, verify
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig

    path = tmp_path / "run.mcap"

    result = run_closed_loop(RunConfig(duration=12.0), logger_factory=lambda header: StopAfter3000Rows(path, header),
                             progress=False)
    assert result.status == "interrupted"
    log = load_log(path)
    assert log.status == "interrupted" and not log.truncated and log.rows == 3000
    assert np.array_equal(log.signals["E"], result.rows["E"])
    rep = summarize(log)
    assert rep["E_max"] == result.summary.E_max and rep["sup_abs_E"] == result.summary.sup_E
    assert rep["region_polygon"] == result.summary.analysis["vertices"]
    ver = verify(log)
    assert ver == {"rows": 3000, "mj_steps": 3000, "identical": True}
    bounds = log.channel("/bounds")  # the certificate's bound (NaN where it has none: no line drawn)
    cert_E_max = result.summary.certificate.E_max
    expected = np.nan if cert_E_max is None else cert_E_max
    np.testing.assert_array_equal(bounds["e_max"], np.full(len(bounds["e_max"]), expected))
