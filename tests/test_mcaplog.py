"""MCAP run logs: writer (wmr_mj.logs.writer), format (wmr_mj.logs.logformat), Foxglove encoders
(wmr_mj.logs.foxglove) and reader (wmr_mj.logs.reader).

A small cart model with the C80's body and joint names is compiled from a string, stepped
with some ctrl, and logged with the runner's block contract. What is written is checked
against independent readers: mcap's own reader, mcap-ros2-support's CDR decoder and
MuJoCo's kinematics.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import mujoco
import numpy as np
import pytest
from helpers import CONFIG, ROW_KEYS, TEST_MJCF, chunk_spans, ros2_decoded, synthetic_block, synthetic_run

from wmr_mj.errors import LogError, ParameterError
from wmr_mj.logs import logformat
from wmr_mj.logs.logformat import foxglove_schema
from wmr_mj.logs.reader import load_log
from wmr_mj.logs.writer import LogHeader, LogOptions, RunLogger, terminate_as_interrupt


@pytest.fixture(scope="module")
def logged(tmp_path_factory):
    path = tmp_path_factory.mktemp("log") / "run.mcap"
    rows = synthetic_run(path, 1.2, block_rows=500, nan_at=700, bounds={"E_max": 0.25, "Edot_max": math.inf})
    return path, rows


def test_round_trip_arrays(logged):
    path, rows = logged
    log = load_log(path)
    assert not log.truncated and log.status == "completed"
    assert log.rows == len(rows["t"]) == 1200
    for k in ROW_KEYS:  # the full-rate data, every row, bit for bit
        got = log.state[k] if k in ("qpos", "qvel", "ctrl") else log.signals[k]
        assert got.shape == rows[k].shape, k
        assert np.array_equal(got, rows[k], equal_nan=True), k
    assert np.array_equal(log.state["t"], rows["t"])
    steer = log.channel("/steering")  # the plot channel: every 10th row (100 Hz of a 1 kHz run)
    assert set(steer) == {"log_time", "t", "alpha", "alpha_dot", "alpha0", "alpha0_dot", "alpha0_ddot", "e", "e_dot"}
    assert np.array_equal(steer["t"], rows["t"][::10])
    assert np.array_equal(steer["e"], rows["E"][::10], equal_nan=True)
    assert np.array_equal(steer["log_time"], np.rint(rows["t"][::10] * 1e9).astype(np.uint64))
    pose = log.channel("/pose")  # the pose channel: at the tf rate, every 20th row
    assert np.array_equal(pose["c_y"], rows["C_pos"][::20, 1])


def test_metadata_and_attachments(logged):
    path, _ = logged
    log = load_log(path)
    assert log.info["schema_version"] == logformat.SCHEMA_VERSION
    assert log.config == CONFIG
    assert log.seed == 7
    assert log.timestep == 0.001 and log.control_substeps == 1 and log.log_every == 1
    assert set(log.versions) >= {"python", "mujoco", "numpy", "mcap", "wmr_mj"}
    assert log.mjcf_xml == TEST_MJCF
    assert log.parameters == {"m1": 650.0, "voltage_limit": 20.0}
    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    d = mujoco.MjData(m)
    s0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(m, d, s0, mujoco.mjtState.mjSTATE_INTEGRATION)
    assert np.array_equal(log.initial_state, s0)
    assert log.reference_path.shape == (50, 2)
    assert log.summary["status"] == "completed" and log.summary["sup_abs_E"] == 0.1
    assert log.summary["nan"] is None  # NaN in the summary becomes null
    assert {"c80.xml", "parameters.json", "initial_state.npy"} <= set(log.attachments)


def test_official_mcap_reader_and_schemas(logged):
    from mcap.reader import make_reader
    from mcap.stream_reader import StreamReader

    path, _ = logged
    with open(path, "rb") as f:
        reader = make_reader(f)
        summ = reader.get_summary()
        topics = {c.topic: c for c in summ.channels.values()}
        assert set(topics) == {"/signals", "/sim/state", "/steering", "/motor", "/pose", "/path", "/bounds", "/tf",
                               "/scene"}
        schemas = {t: summ.schemas[c.schema_id] for t, c in topics.items()}
        assert schemas["/tf"].name == "foxglove_msgs/msg/FrameTransforms" and schemas["/tf"].encoding == "ros2msg"
        assert schemas["/scene"].name == "foxglove.SceneUpdate" and schemas["/scene"].encoding == "jsonschema"
        assert json.loads(schemas["/scene"].data) == foxglove_schema("foxglove.SceneUpdate")
        cdr = [t for t in topics if t != "/scene"]
        assert all(schemas[t].encoding == "ros2msg" and topics[t].message_encoding == "cdr" for t in cdr)
        counts = {}
        for _, ch, _ in reader.iter_messages(log_time_order=True):
            counts[ch.topic] = counts.get(ch.topic, 0) + 1
        # 1.2 s at 1 kHz, flushed every simulated second: 2 packed messages; 100 Hz plot rows; /tf at 50 Hz
        assert counts["/sim/state"] == counts["/signals"] == 2
        assert counts["/steering"] == counts["/motor"] == counts["/path"] == 120
        assert counts["/pose"] == 60 and counts["/tf"] == 59  # the NaN pose row (700) is left out of /tf
        # /scene: the vehicle and the desired path at t = 0, then C's travelled path once per written block
        assert counts["/scene"] == 3 and counts["/bounds"] == 3  # one per flush, one at the end
        assert summ.statistics.message_count == sum(counts.values())
        assert {m.name for m in reader.iter_metadata()} == {"wmr_mj", "versions", "config", "summary"}
        assert {a.name for a in reader.iter_attachments()} >= {"c80.xml", "parameters.json", "initial_state.npy"}
        assert {ci.compression for ci in summ.chunk_indexes} == {"lz4"}
    with open(path, "rb") as f:  # CRCs of chunks and data section, read from the start
        assert sum(1 for _ in StreamReader(f, validate_crcs=True).records) > 10


def test_cdr_channels_decode_with_an_independent_decoder(logged):
    path, rows = logged
    log = load_log(path)
    dec = ros2_decoded(path, ["/signals", "/sim/state", "/steering", "/bounds"])
    state = dec["/sim/state"]
    assert [(t, m.rows) for t, m in state] == [(0, 1000), (1_000_000_000, 200)]
    qpos = np.concatenate([np.reshape(m.qpos, (m.rows, m.nq)) for _, m in state])
    assert np.array_equal(qpos, rows["qpos"], equal_nan=True)
    assert np.array_equal(np.concatenate([m.e for _, m in dec["/signals"]]), rows["E"], equal_nan=True)
    assert np.array_equal(np.concatenate([np.reshape(m.c_pos, (-1, 2)) for _, m in dec["/signals"]]), rows["C_pos"])
    steer = dec["/steering"]
    assert np.array_equal([m.alpha0_dot for _, m in steer], log.channel("/steering")["alpha0_dot"])
    bounds = dec["/bounds"]
    assert [(m.e_max, m.e_min, m.voltage_max, m.voltage_min) for _, m in bounds] == [(0.25, -0.25, 20.0, -20.0)] * 3
    assert all(math.isnan(m.e_dot_max) for _, m in bounds)  # an infinite bound is no line
    assert bounds[-1][0] == int(round(rows["t"][-1] * 1e9))  # the constant series reaches the end


def _compose(transforms):
    from wmr_mj.logs.foxglove import qmul, qrot

    world = {"world": (np.zeros(3), np.array([1.0, 0, 0, 0]))}
    for tr in transforms:
        p, q = world[tr.parent_frame_id]
        tl = np.array([tr.translation.x, tr.translation.y, tr.translation.z])
        r = np.array([tr.rotation.w, tr.rotation.x, tr.rotation.y, tr.rotation.z])
        world[tr.child_frame_id] = (p + qrot(q, tl), qmul(q, r))
    return world


def test_tf_matches_mujoco_kinematics(logged):
    path, rows = logged
    msgs = dict(ros2_decoded(path, ["/tf"])["/tf"])
    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    d = mujoco.MjData(m)
    for k in (0, 340, 1180):
        tf = msgs[int(round(rows["t"][k] * 1e9))]
        stamp = divmod(int(round(rows["t"][k] * 1e9)), 10**9)
        assert {(x.timestamp.sec, x.timestamp.nanosec) for x in tf.transforms} == {stamp}
        d.qpos[:] = rows["qpos"][k]
        mujoco.mj_kinematics(m, d)
        world = _compose(tf.transforms)
        # composed transforms against mj_kinematics of the same qpos: rounding of m-scale products
        for b in range(1, m.nbody):
            p, q = world[mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)]
            assert np.allclose(p, d.xpos[b], atol=1e-12)
            assert abs(abs(np.dot(q, d.xquat[b])) - 1) < 1e-12
    assert int(round(rows["t"][700] * 1e9)) not in msgs  # the NaN pose row


def test_scene_validates_and_shows_the_axles(logged):
    jsonschema = pytest.importorskip("jsonschema")
    path, _ = logged
    scene = load_log(path).messages("/scene")
    assert len(scene) == 3 and scene[0][0] == 0  # the vehicle, then the travelled path per written block
    msg = scene[0][1]
    for _, m in scene:
        jsonschema.validate(m, foxglove_schema("foxglove.SceneUpdate"))
    travelled = [m["entities"][0] for _, m in scene[1:]]
    assert [e["id"] for e in travelled] == ["travelled_path/0", "travelled_path/1"]
    first, second = (e["lines"][0]["points"] for e in travelled)
    assert first[-1] == second[0]  # the pieces join: each starts where the one before ended
    ents = {e["id"]: e for e in msg["entities"]}
    bodies = {"body:chassis", "body:steering_unit", "body:front_left_wheel", "body:rear_right_wheel"}
    assert bodies | {"reference_path"} <= set(ents)
    chassis = ents["body:chassis"]
    assert chassis["cubes"] and all(c["color"]["a"] <= 0.25 for c in chassis["cubes"])  # see-through
    assert len(chassis["lines"][0]["points"]) == 24  # its 12 edges outlined
    assert ents["body:front_left_wheel"]["cylinders"][0]["color"]["a"] == 1.0
    assert ents["body:steering_unit"]["cylinders"]  # the steered axle
    path_line = ents["reference_path"]["lines"][0]
    assert ents["reference_path"]["frame_id"] == "world" and len(path_line["points"]) == 50


def test_foxglove_layout_names_what_the_log_has(logged):
    from wmr_mj.logs.foxglove import LAYOUT_PATH

    path, _ = logged
    log = load_log(path)
    layout = json.loads(LAYOUT_PATH.read_text())
    plots = [v for k, v in layout["configById"].items() if k.startswith("Plot!")]
    series = [p["value"] for plot in plots for p in plot["paths"]]
    assert {"/steering.e", "/steering.e_dot", "/bounds.e_max", "/bounds.e_min", "/bounds.e_dot_max",
            "/motor.voltage", "/bounds.voltage_max"} <= set(series)  # fmt: skip
    for value in series:
        topic, field = value.split(".", 1)
        assert field in log.channel(topic), value
    (three_d,) = [v for k, v in layout["configById"].items() if k.startswith("3D!")]
    frames = {x.child_frame_id for x in ros2_decoded(path, ["/tf"])["/tf"][0][1].transforms}
    assert three_d["followTf"] in frames and three_d["topics"]["/scene"]["visible"]


def test_nan_survives_and_json_stays_valid(logged):
    path, rows = logged
    log = load_log(path)
    assert np.isnan(log.signals["E"][700]) and np.isposinf(log.signals["voltage"][700])
    assert np.isnan(log.state["qpos"][700, 0])
    for name in ("config", "summary", "wmr_mj"):
        for v in log.metadata[name].values():
            if name != "wmr_mj":
                json.loads(v, parse_constant=lambda c, name=name: pytest.fail(f"non-JSON constant {c} in {name}"))


def test_log_every_and_substeps(tmp_path):
    path = tmp_path / "every.mcap"
    rows = synthetic_run(path, 0.3, block_rows=64, log_every=3, substeps=2)
    log = load_log(path)
    assert log.rows == 150 and log.log_every == 3 and log.control_substeps == 2
    assert np.array_equal(log.signals["t"], rows["t"][::3])
    assert np.array_equal(log.signals["A_pos"], rows["A_pos"][::3])
    assert np.array_equal(log.state["qpos"], rows["qpos"])
    assert log.message_count("/steering") == 30  # 100 Hz of a 2 ms control step: every 5th row
    assert log.message_count("/tf") == 15


def test_small_blocks_that_miss_the_plot_rows(tmp_path):
    """Blocks of 7 rows flushed one by one: most hold no 100 Hz plot row and no 50 Hz /tf row."""
    path = tmp_path / "small.mcap"
    rows = synthetic_run(path, 0.1, block_rows=7, flush_period_s=0.005)
    log = load_log(path)
    assert np.array_equal(log.state["qpos"], rows["qpos"]) and np.array_equal(log.signals["E"], rows["E"])
    assert log.message_count("/sim/state") == 15  # 14 blocks of 7 rows and one of 2
    assert log.channel("/steering")["t"].tolist() == rows["t"][::10].tolist()
    assert log.message_count("/tf") == 5


@pytest.mark.parametrize("compression", ["zstd", "none"])
def test_other_compressions(tmp_path, compression):
    from mcap.reader import make_reader

    path = tmp_path / f"{compression}.mcap"
    rows = synthetic_run(path, 0.2, compression=compression)
    log = load_log(path)
    assert np.array_equal(log.state["qvel"], rows["qvel"])
    assert log.info["compression"] == compression
    with open(path, "rb") as f:
        chunks = make_reader(f).get_summary().chunk_indexes
        assert {ci.compression for ci in chunks} == {compression.replace("none", "")}


def test_bounds_from_the_summary_when_not_given(tmp_path):
    path = tmp_path / "b.mcap"
    rows = synthetic_run(path, 0.2, summary={"E_max": 0.125, "Edot_max": 0.5})
    b = load_log(path).channel("/bounds")
    assert b["log_time"].tolist() == [0, int(round(rows["t"][-1] * 1e9))]
    assert b["e_max"].tolist() == [0.125, 0.125] and b["e_dot_min"].tolist() == [-0.5, -0.5]


def test_each_block_is_on_disk(tmp_path):
    """After write_block returns, the file read as it is holds every row (complete chunks)."""
    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    d = mujoco.MjData(m)
    s0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(m, d, s0, mujoco.mjtState.mjSTATE_INTEGRATION)
    path = tmp_path / "open.mcap"
    log = RunLogger(path, LogHeader(mjcf_xml=TEST_MJCF, config={}, parameters={}, initial_state=s0, timestep=0.001,
                                    control_substeps=1))
    for b in range(3):
        log.write_block(synthetic_block(m, 1000, b))
        partial = load_log(path)
        assert partial.truncated and partial.summary is None
        assert partial.rows == 1000 * (b + 1)
    log.close({}, status="completed")
    assert not load_log(path).truncated
    with pytest.raises(LogError, match="after close"):
        log.write_block(synthetic_block(m, 10, 0))


def test_bad_blocks_and_options_are_refused(tmp_path):
    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    s0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(m, mujoco.MjData(m), s0, mujoco.mjtState.mjSTATE_INTEGRATION)
    header = LogHeader(mjcf_xml=TEST_MJCF, config={}, parameters={}, initial_state=s0, timestep=0.001,
                       control_substeps=1)
    with pytest.raises(ParameterError, match="compression 'gzip'"):
        RunLogger(tmp_path / "x.mcap", header, options=LogOptions(compression="gzip"))
    with pytest.raises(ParameterError, match="initial_state"):
        RunLogger(tmp_path / "x.mcap", dataclasses.replace(header, initial_state=s0[:-1]))
    with RunLogger(tmp_path / "x.mcap", header) as log:
        blk = synthetic_block(m, 10, 0)
        with pytest.raises(ParameterError, match="lacks qvel"):
            log.write_block({k: v for k, v in blk.items() if k != "qvel"})
        with pytest.raises(ParameterError, match=r"block\['qpos'\] has shape"):
            log.write_block({**blk, "qpos": blk["qpos"][:, :3]})


def test_unwritable_log_path_is_one_clear_error(tmp_path):
    from wmr_mj.errors import OutputPathError

    (tmp_path / "file").write_text("x")
    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    s0 = np.zeros(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    with pytest.raises(OutputPathError, match="cannot be written"):
        RunLogger(tmp_path / "file" / "run.mcap", LogHeader(mjcf_xml=TEST_MJCF, config={}, parameters={},
                                                             initial_state=s0, timestep=0.001, control_substeps=1,
                                                             model=m))


def test_context_manager_closes_on_error(tmp_path):
    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    s0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(m, mujoco.MjData(m), s0, mujoco.mjtState.mjSTATE_INTEGRATION)
    path = tmp_path / "err.mcap"
    with pytest.raises(ZeroDivisionError):
        with RunLogger(path, LogHeader(mjcf_xml=TEST_MJCF, config={}, parameters={}, initial_state=s0,
                                       timestep=0.001, control_substeps=1)) as log:
            log.write_block(synthetic_block(m, 200, 0))
            raise ZeroDivisionError("division by zero")
    log2 = load_log(path)
    assert log2.status == "error" and not log2.truncated and log2.rows == 200
    assert "ZeroDivisionError" in log2.summary["reason"]


# --------------------------------------------------------------------------- bad input


def _write_small(tmp_path, name="small.mcap", seconds=0.4, **kw):
    path = tmp_path / name
    synthetic_run(path, seconds, block_rows=100, flush_period_s=0.1, **kw)
    return path


def test_missing_and_not_mcap(tmp_path):
    with pytest.raises(LogError, match="no such file"):
        load_log(tmp_path / "missing.mcap")
    bad = tmp_path / "notes.mcap"
    bad.write_text("hello, this is not a log\n")
    with pytest.raises(LogError, match="not an MCAP file"):
        load_log(bad)
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(b"")
    with pytest.raises(LogError, match="not an MCAP file"):
        load_log(empty)
    with pytest.raises(LogError, match="is a directory"):
        load_log(tmp_path)


def test_mcap_that_is_not_a_run_log(tmp_path):
    from mcap.writer import Writer

    path = tmp_path / "other.mcap"
    with open(path, "wb") as f:
        w = Writer(f)
        w.start()
        w.add_metadata("something", {"a": "b"})
        w.finish()
    with pytest.raises(LogError, match="without a wmr_mj metadata record"):
        load_log(path)


def test_run_log_with_a_channel_of_unknown_schema(tmp_path):
    """A file that claims to be a run log but whose /sim/state schema is not ours: one clear line."""
    from mcap.writer import Writer

    path = tmp_path / "odd.mcap"
    with open(path, "wb") as f:
        w = Writer(f)
        w.start()
        w.add_metadata("wmr_mj", {"schema_version": logformat.SCHEMA_VERSION})
        sid = w.register_schema("other/msg/State", "ros2msg", b"string name\nfloat64[] qpos\n")
        cid = w.register_channel("/sim/state", "cdr", sid)
        w.add_message(cid, 0, b"\x00\x01\x00\x00" + bytes(12), 0)
        w.finish()
    with pytest.raises(LogError, match=r"/sim/state \(other/msg/State, cdr\) is not a numbers-only CDR channel"):
        load_log(path)


def test_corrupted_chunk(tmp_path):
    path = _write_small(tmp_path)
    data = bytearray(path.read_bytes())
    spans = chunk_spans(path)
    rng = np.random.default_rng(3)
    for i, (start, length) in enumerate(spans[1::2]):  # packed and Foxglove chunks alike
        bad = bytearray(data)
        at = start + length - 1 - int(rng.integers(0, max(1, length // 2)))
        bad[at] ^= 0xFF
        bad[at - 1] ^= 0x5A
        p = tmp_path / f"corrupt{i}.mcap"
        p.write_bytes(bytes(bad))
        with pytest.raises(LogError, match="corrupt") as exc:
            load_log(p)
        assert "\n" not in str(exc.value) and str(p) in str(exc.value)
        p.write_bytes(bytes(bad[: start + length + 40]))  # the same damage in a file that was cut later
        with pytest.raises(LogError, match="corrupt"):
            load_log(p)


def test_unknown_schema_version(tmp_path, monkeypatch):
    monkeypatch.setattr(logformat, "SCHEMA_VERSION", "99")
    path = _write_small(tmp_path, "v99.mcap", seconds=0.1)
    with pytest.raises(LogError, match="schema version '99'"):
        load_log(path)


def test_random_cuts(tmp_path):
    path = _write_small(tmp_path, seconds=0.6)
    data = path.read_bytes()
    full = load_log(path)
    rng = np.random.default_rng(20240611)
    offsets = sorted(set(rng.integers(0, len(data), 40).tolist()) | {0, 4, 8, 20, 200, len(data) - 1, len(data) - 8})
    read = failed = 0
    partial = set()
    for off in offsets:
        p = tmp_path / f"cut{off}.mcap"
        p.write_bytes(data[:off])
        try:
            log = load_log(p)
        except LogError as exc:
            assert "\n" not in str(exc)
            failed += 1
            continue
        read += 1
        assert log.truncated
        assert log.rows <= full.rows
        partial.add(log.rows)
        assert np.array_equal(log.state["qpos"], full.state["qpos"][: log.rows])
        n = len(log.signals.get("t", []))
        assert np.array_equal(log.signals.get("E", np.empty(0)), full.signals["E"][:n])
    assert read > 10 and failed >= 3
    assert len(partial) >= 4  # cuts at different places keep different numbers of flushed rows


# --------------------------------------------------------------------------- kills

_LOOP = textwrap.dedent(
    """
    import sys, time
    import numpy as np, mujoco
    sys.path.insert(0, {tests!r})
    from helpers import TEST_MJCF, synthetic_block
    from wmr_mj.logs.writer import LogHeader, RunLogger, terminate_as_interrupt
    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    s0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(m, mujoco.MjData(m), s0, mujoco.mjtState.mjSTATE_INTEGRATION)
    try:
        header = LogHeader(mjcf_xml=TEST_MJCF, config={{"seed": 1}}, parameters={{}}, initial_state=s0,
                           timestep=0.001, control_substeps=1, model=m)
        with terminate_as_interrupt(), RunLogger({path!r}, header) as log:
            b = 0
            while True:
                log.write_block(synthetic_block(m, 1000, b))
                b += 1
                print("block", b, flush=True)
                time.sleep(0.05)
    except KeyboardInterrupt:
        sys.exit(130)
    """
)


def _start_loop(tmp_path, name):
    path = tmp_path / name
    code = _LOOP.format(tests=str(Path(__file__).parent), path=str(path))
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    blocks = 0
    deadline = time.time() + 60
    while blocks < 3 and time.time() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        blocks += line.startswith("block")
    assert blocks >= 3, proc.stderr.read() if proc.poll() is not None else "no progress"
    return proc, path


def test_sigkill_leaves_readable_truncated_log(tmp_path):
    from mcap.records import Channel, Message
    from mcap.stream_reader import StreamReader

    proc, path = _start_loop(tmp_path, "killed.mcap")
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    log = load_log(path)
    assert log.truncated and log.summary is None and log.status == "truncated"
    assert log.rows >= 3000 and log.rows % 1000 == 0
    assert np.array_equal(log.state["t"], np.arange(log.rows) * 1e-3)
    # mcap's own stream reader recovers the same flushed blocks, up to where the file ends
    channels, rows = {}, 0
    with open(path, "rb") as f:
        try:
            for rec in StreamReader(f).records:
                if isinstance(rec, Channel):
                    channels[rec.id] = rec.topic
                elif isinstance(rec, Message) and channels[rec.channel_id] == "/sim/state":
                    rows += int(np.frombuffer(rec.data[4:8], "<u4")[0])
        except Exception:  # the end of a killed file: the reader stops at the last complete record
            pass
    assert rows == log.rows


@pytest.mark.slow
def test_sigterm_finishes_file_as_interrupted(tmp_path):
    proc, path = _start_loop(tmp_path, "termed.mcap")
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=30) == 130
    log = load_log(path)
    assert not log.truncated
    assert log.status == "interrupted"
    assert log.rows >= 3000 and log.summary["rows"] == log.rows


def test_terminate_as_interrupt_restores_handler():
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(KeyboardInterrupt):
        with terminate_as_interrupt():
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(1)
    assert signal.getsignal(signal.SIGTERM) == before


def test_bulk_messages_are_the_messages_added_one_by_one(tmp_path):
    """The writer's NumPy path for the Foxglove channels leaves what add_message per row leaves:
    every message (channel, times, sequence, bytes) in the same order, and the same statistics."""
    from mcap.reader import make_reader

    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    d = mujoco.MjData(m)
    s0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(m, d, s0, mujoco.mjtState.mjSTATE_INTEGRATION)
    files = {}
    for bulk in (True, False):
        path = files[bulk] = tmp_path / f"bulk-{bulk}.mcap"
        log = RunLogger(path, LogHeader(mjcf_xml=TEST_MJCF, config={}, parameters={}, initial_state=s0,
                                        timestep=0.001, control_substeps=1, bounds={"E_max": 0.1, "Edot_max": 0.2}))
        assert log._bulk is not None  # the fast path runs with this mcap
        if not bulk:
            log._bulk = None
        for b in range(3):
            log.write_block(synthetic_block(m, 1000 if b < 2 else 437, b))
        log.close({"sup_E": 0.01})

    def messages(path):
        with open(path, "rb") as f:
            reader = make_reader(f)
            stats = reader.get_summary().statistics
            msgs = [(c.topic, msg.log_time, msg.publish_time, msg.sequence, msg.data)
                    for _, c, msg in reader.iter_messages(log_time_order=False)]
        return msgs, (stats.message_count, dict(stats.channel_message_counts), stats.message_start_time,
                      stats.message_end_time, stats.chunk_count)

    def indexes(path):  # every message index record: (channel, [(log time, offset in the chunk)])
        from mcap.records import MessageIndex
        from mcap.stream_reader import StreamReader

        with open(path, "rb") as f:
            return [(r.channel_id, list(r.records)) for r in StreamReader(f).records if isinstance(r, MessageIndex)]

    fast, slow = messages(files[True]), messages(files[False])
    assert len(fast[0]) > 700 and fast == slow
    assert indexes(files[True]) == indexes(files[False]) != []
    assert load_log(files[True]).rows == 2437


def test_a_background_writer_writes_the_same_file_a_second_behind_at_most(tmp_path):
    """background=True: a writer thread writes each flushed second; when write_block returns, every
    second before the one it took is on disk; close waits; the messages are those written in line."""
    from mcap.reader import make_reader

    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    d = mujoco.MjData(m)
    s0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(m, d, s0, mujoco.mjtState.mjSTATE_INTEGRATION)
    files = {}
    for background in (False, True):
        path = files[background] = tmp_path / f"bg-{background}.mcap"
        log = RunLogger(path, LogHeader(mjcf_xml=TEST_MJCF, config={}, parameters={}, initial_state=s0,
                                        timestep=0.001, control_substeps=1, bounds={"E_max": 0.1, "Edot_max": 0.2}),
                        options=LogOptions(background=background))
        buffer = synthetic_block(m, 1000, 0)
        for b in range(4):
            block = synthetic_block(m, 1000, b)
            for k, v in block.items():  # the runner reuses its buffers: the writer must have copied them
                buffer[k][...] = v
            log.write_block(buffer)
            assert log.rows == 1000 * (b + 1)
            assert load_log(path).rows >= 1000 * b
        log.close({"sup_E": 0.01})

    def messages(path):
        with open(path, "rb") as f:
            return [(c.topic, msg.log_time, msg.sequence, msg.data)
                    for _, c, msg in make_reader(f).iter_messages(log_time_order=False)]

    assert messages(files[True]) == messages(files[False])
    log = load_log(files[True])
    assert log.rows == 4000 and log.status == "completed" and not log.truncated
