"""A run log opens in Foxglove's own reader, with every message decoding.

tests/foxglove_reader/check.mjs reads the log with @mcap/core's indexed reader (the MCAP reader
of Foxglove) and decodes each channel with @foxglove/rosmsg2-serialization (ros2msg/CDR) or
JSON.parse, from the schemas stored in the file. Needs node and the pinned packages:
``npm ci --prefix tests/foxglove_reader`` (make foxglove-reader); skipped without node.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from helpers import TEST_MJCF, foxglove_read, synthetic_run

from wmr_mj.logs.foxglove import qmul, qrot
from wmr_mj.logs.reader import load_log

pytestmark = pytest.mark.npm  # Foxglove's reader from npm: `make test-fast` leaves it out

@pytest.mark.parametrize("compression", ["lz4", "zstd"])
def test_foxglove_reader_decodes_every_channel(tmp_path, compression):
    path = tmp_path / f"{compression}.mcap"
    rows = synthetic_run(path, 0.5, block_rows=250, compression=compression, bounds={"E_max": 0.25, "Edot_max": 1.5})
    fox = foxglove_read(path)
    log = load_log(path)
    assert set(fox["topics"]) == set(log.topics)
    for topic, entry in fox["topics"].items():
        assert entry["count"] == log.message_count(topic), topic
    assert fox["message_count"] == sum(e["count"] for e in fox["topics"].values())
    # packed full-rate data: what Foxglove decodes is what load_log returns
    state = fox["topics"]["/sim/state"]["messages"][0]
    assert state["rows"] == 500 and state["nq"] == log.state["qpos"].shape[1]
    assert state["qpos"] == {"length": 500 * state["nq"], "first": rows["qpos"][0, 0], "last": rows["qpos"][499, -1]}
    sig = fox["topics"]["/signals"]["messages"][0]
    assert sig["e"]["last"] == rows["E"][499] and sig["c_pos"]["length"] == 1000
    # per-row plot channels
    steer = log.channel("/steering")
    for k, msg in enumerate(fox["topics"]["/steering"]["messages"]):
        assert msg == {name: float(steer[name][k]) for name in msg}
    assert fox["topics"]["/bounds"]["messages"][0] == {"e_max": 0.25, "e_min": -0.25, "e_dot_max": 1.5,
                                                        "e_dot_min": -1.5, "voltage_max": 20, "voltage_min": -20}
    assert "reference_path" in fox["topics"]["/scene"]["messages"][0]["entities"]
    # /tf: the frames Foxglove composes are MuJoCo's body poses
    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    d = mujoco.MjData(m)
    for k, transforms in zip((0, 20, 40), fox["topics"]["/tf"]["messages"]):
        d.qpos[:] = rows["qpos"][k]
        mujoco.mj_kinematics(m, d)
        world = {"world": (np.zeros(3), np.array([1.0, 0, 0, 0]))}
        for tr in transforms:
            assert tr["sec"] * 10**9 + tr["nsec"] == round(rows["t"][k] * 1e9)
            p, q = world[tr["parent"]]
            x, y, z, w = tr["rotation"]
            world[tr["child"]] = (p + qrot(q, np.array(tr["translation"])), qmul(q, np.array([w, x, y, z])))
        # the logged transforms composed again against mj_kinematics of the same qpos: rounding of a
        # chain of products of m-scale poses, no simulation in it
        for b in range(1, m.nbody):
            p, q = world[mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)]
            assert np.allclose(p, d.xpos[b], atol=1e-12) and abs(abs(np.dot(q, d.xquat[b])) - 1) < 1e-12
