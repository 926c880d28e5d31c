"""Helpers shared by the test files: test files import from here, never from one another.

- :func:`one_error_line` and :func:`files_under`: the bad-input contract (one line on stderr, nothing left).
- :data:`TEST_MJCF`, :func:`synthetic_run`, :func:`synthetic_block`: a small cart logged through the
  runner's block contract, without the closed loop (the log tests).
- :func:`ros2_decoded`, :func:`chunk_spans`, :func:`foxglove_read`: independent readers of a log.
- :class:`StopAfter3000Rows`: a logger that stops a run with Ctrl-C after its third simulated second.
- :func:`example_module`: an example script of ``examples/`` imported as a module (it is no package).

The runs that many files repeat are session fixtures in ``tests/conftest.py``, not here.

Usage::

    from helpers import files_under, one_error_line

    def test_an_unknown_path_is_one_line(tmp_path, capsys):
        assert main(["sweep", "--n", "1", "--path", "no-such-path", "--out", str(tmp_path / "sweep")]) == 2
        assert "no-such-path" in one_error_line(capsys)
        assert files_under(tmp_path) == []
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import mujoco
import numpy as np
import pytest

from wmr_mj.logs.writer import LogHeader, LogOptions, RunLogger

TESTS = Path(__file__).resolve().parent
EXAMPLES = TESTS.parent / "examples"


def example_module(name: str):
    """``examples/NAME.py`` imported as a module (examples are scripts, not a package), run once per call.

    Args:
        name: the script's stem, e.g. ``"observer_law"``.
    """
    import importlib.util

    spec = importlib.util.spec_from_file_location(f"{name}_example", EXAMPLES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# --------------------------------------------------------------------------- bad input


def one_error_line(capsys) -> str:
    """The one line a refused command wrote on stderr, asserted to be the only one and no traceback.

    Args:
        capsys: pytest's capture fixture of the test that ran the command in process.

    Returns:
        The line, ``wmr-mj: error: ...``.
    """
    return _the_one_line(capsys.readouterr().err)


def refused_line(capsys, argv: list[str]) -> str:
    """Runs ``wmr-mj ARGV`` in process and returns its one error line, asserting exit status 2, nothing on
    stdout, one line on stderr and no traceback (:func:`one_error_line`).

    Args:
        capsys: pytest's capture fixture; argv: the command's arguments, without ``wmr-mj``.
    """
    from wmr_mj.cli.app import main

    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == "", captured.out
    return _the_one_line(captured.err)


def _the_one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("wmr-mj: error: ") and "Traceback" not in err
    return lines[0]


def files_under(folder: Path) -> list[str]:
    """Every file and folder below ``folder``, as sorted POSIX paths relative to it (to see what a command left)."""
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


# --------------------------------------------------------------------------- a synthetic log

TEST_MJCF = """
<mujoco model="c80_test">
  <option timestep="0.001" integrator="implicitfast"/>
  <worldbody>
    <light pos="0 0 4" dir="0 0 -1"/>
    <geom name="floor" type="plane" size="0 0 0.1" rgba=".8 .8 .8 1"/>
    <body name="chassis" pos="0 0 0.2">
      <freejoint name="chassis_free"/>
      <geom type="box" size="0.6 0.3 0.05" pos="0.3 0 0.1" rgba="0.2 0.4 0.8 1" mass="50"/>
      <geom type="sphere" size="0.05" pos="0.8 0 0.2" rgba="1 1 0 1" mass="0.1"/>
      <geom type="ellipsoid" size="0.1 0.05 0.03" pos="0 0 0.2" rgba="0 1 0 1" mass="0.1"/>
      <body name="drive_unit">
        <geom type="box" size="0.04 0.3 0.03" rgba=".3 .3 .3 1" mass="5"/>
        <body name="rear_left_wheel" pos="0 0.35 -0.05">
          <joint name="rear_left_spin" type="hinge" axis="0 1 0" damping="0.01"/>
          <geom type="cylinder" size="0.15 0.04" euler="90 0 0" rgba=".1 .1 .1 1" mass="2"/>
        </body>
        <body name="rear_right_wheel" pos="0 -0.35 -0.05">
          <joint name="rear_right_spin" type="hinge" axis="0 1 0" damping="0.01"/>
          <geom type="cylinder" size="0.15 0.04" euler="90 0 0" rgba=".1 .1 .1 1" mass="2"/>
        </body>
      </body>
      <body name="steering_unit" pos="0.612 0 0">
        <joint name="steer" type="hinge" axis="0 0 1" range="-0.9 0.9" damping="0.5"/>
        <geom type="capsule" size="0.03 0.2" euler="90 0 0" rgba=".6 .2 .2 1" mass="3"/>
        <body name="front_left_wheel" pos="0 0.25 -0.1">
          <joint name="front_left_spin" type="hinge" axis="0 1 0"/>
          <geom type="cylinder" size="0.1 0.03" euler="90 0 0" rgba=".1 .1 .1 1" mass="1"/>
        </body>
        <body name="front_right_wheel" pos="0 -0.25 -0.1">
          <joint name="front_right_spin" type="hinge" axis="0 1 0"/>
          <geom type="cylinder" size="0.1 0.03" euler="90 0 0" rgba=".1 .1 .1 1" mass="1"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="steer_motor" joint="steer" gear="1" ctrlrange="-20 20"/>
    <motor name="drive_left" joint="rear_left_spin" gear="1"/>
    <motor name="drive_right" joint="rear_right_spin" gear="1"/>
  </actuator>
</mujoco>
"""

ROW_KEYS = (
    "t", "alpha", "alpha_dot", "alpha0", "alpha0_dot", "alpha0_ddot", "E", "E_dot", "voltage_cmd",
    "voltage", "current", "steer_torque", "A_pos", "C_pos", "heading", "qpos", "qvel", "ctrl",
)  # fmt: skip
CONFIG = {"seed": 7, "controller": "test", "settle_s": 0.5, "E_max": 0.5, "Edot_max": 2.0, "gains": {"kp": 6.0}}


def synthetic_run(path, seconds=1.0, *, block_rows=1000, log_every=1, substeps=1, nan_at=None,
                  tamper_at=None, summary=None, bounds=None, **options):  # fmt: skip
    """Simulate TEST_MJCF under a simple steering law and log it; returns the rows logged."""
    m = mujoco.MjModel.from_xml_string(TEST_MJCF)
    d = mujoco.MjData(m)
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    s0 = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, s0, spec)
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "steer")
    qa, va = m.jnt_qposadr[jid], m.jnt_dofadr[jid]
    cb = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "steering_unit")
    ab = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "drive_unit")
    n = int(round(seconds / (m.opt.timestep * substeps)))
    ref = np.column_stack([np.linspace(0, 2, 50), 0.2 * np.sin(np.linspace(0, 3, 50))])
    header = LogHeader(mjcf_xml=TEST_MJCF, config=CONFIG, parameters={"m1": 650.0, "voltage_limit": 20.0},
                       initial_state=s0, timestep=m.opt.timestep, control_substeps=substeps, reference_path=ref,
                       bounds=bounds)
    log = RunLogger(path, header, options=LogOptions(log_every=log_every, **options))
    rows = {k: [] for k in ROW_KEYS}
    out = {k: [] for k in ROW_KEYS}
    for k in range(n):
        t = d.time
        a0, a0d = 0.3 * np.sin(2 * t), 0.6 * np.cos(2 * t)
        u = 40 * (a0 - d.qpos[qa]) - 2 * d.qvel[va]
        ctrl = np.array([np.clip(u, -20, 20), 1.0, 1.0])
        row = {
            "t": t, "alpha": d.qpos[qa], "alpha_dot": d.qvel[va], "alpha0": a0, "alpha0_dot": a0d,
            "alpha0_ddot": -1.2 * np.sin(2 * t), "E": a0 - d.qpos[qa], "E_dot": a0d - d.qvel[va],
            "voltage_cmd": u, "voltage": np.clip(u, -20, 20), "current": 0.1 * u, "steer_torque": ctrl[0],
            "A_pos": d.xpos[ab][:2].copy(), "C_pos": d.xpos[cb][:2].copy(),
            "heading": 2 * np.arctan2(d.qpos[6], d.qpos[3]), "qpos": d.qpos.copy(), "qvel": d.qvel.copy(), "ctrl": ctrl,
        }  # fmt: skip
        if nan_at is not None and k == nan_at:
            row["E"] = np.nan
            row["voltage"] = np.inf
            row["qpos"][0] = np.nan  # a NaN pose: /tf leaves the row out, /sim/state keeps it
        if tamper_at is not None and k == tamper_at:
            row["qpos"][2] += 1e-12
        for key in ROW_KEYS:
            rows[key].append(row[key])
        d.ctrl[:] = ctrl
        for _ in range(substeps):
            mujoco.mj_step(m, d)
        if len(rows["t"]) == block_rows or k == n - 1:
            blk = {key: np.array(v) for key, v in rows.items()}
            for key in ROW_KEYS:
                out[key].append(blk[key])
            log.write_block(blk)
            rows = {key: [] for key in ROW_KEYS}
    log.close(summary if summary is not None else {"sup_abs_E": 0.1, "nan": float("nan")})
    return {k: np.concatenate(v) for k, v in out.items()}


def synthetic_block(m, n, b):
    """Block ``b`` of ``n`` rows of smooth made-up signals for model ``m`` (TEST_MJCF compiled), 1 ms apart."""
    t = (np.arange(n) + b * n) * 1e-3
    blk = {k: np.sin(t + i) for i, k in enumerate(ROW_KEYS) if k not in ("A_pos", "C_pos", "qpos", "qvel", "ctrl")}
    blk["t"] = t
    blk["A_pos"] = np.column_stack([t, 0 * t])
    blk["C_pos"] = np.column_stack([t + 0.6, 0 * t])
    blk["qpos"] = np.tile(m.qpos0, (n, 1))
    blk["qvel"] = np.zeros((n, m.nv))
    blk["ctrl"] = np.zeros((n, m.nu))
    return blk


class StopAfter3000Rows(RunLogger):
    """A run's logger that stops it as Ctrl-C would once 3000 rows (the third simulated second at 1 ms) are written."""

    def write_block(self, block):
        super().write_block(block)
        if self.rows >= 3000:
            raise KeyboardInterrupt


# --------------------------------------------------------------------------- independent readers


def ros2_decoded(path, topics):
    """{topic: [(log_time, message)]} decoded by mcap-ros2-support, a CDR decoder independent of ours."""
    decoder = pytest.importorskip("mcap_ros2.decoder")
    from mcap.reader import make_reader

    out = {t: [] for t in topics}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[decoder.DecoderFactory()])
        for _, channel, message, msg in reader.iter_decoded_messages(topics=topics):
            out[channel.topic].append((message.log_time, msg))
    return out


def chunk_spans(path):
    """[(start byte, length in bytes)] of each chunk of an MCAP file, from mcap's own reader."""
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        return [(ci.chunk_start_offset, ci.chunk_length) for ci in make_reader(f).get_summary().chunk_indexes]


FOXGLOVE_CHECK = TESTS / "foxglove_reader" / "check.mjs"


def foxglove_read(path: Path) -> dict:
    """What Foxglove's own reader (@mcap/core, via node) decodes from a log; skips the test without node or it."""
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed")
    if not (FOXGLOVE_CHECK.parent / "node_modules" / "@mcap" / "core").is_dir():
        pytest.skip("Foxglove's reader packages are not installed: npm ci --prefix tests/foxglove_reader")
    proc = subprocess.run([node, str(FOXGLOVE_CHECK), str(path)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)
