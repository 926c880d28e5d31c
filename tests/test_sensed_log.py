"""The MCAP log and replay of a cart as it is built (issue 31): a run with a sensor logs what its law read on
/measured and /steering/measured beside the true state, replay --verify regenerates it from the header's
sensing and seed to the bit, and a run with actuation or backlash carries the model it simulated.

The truth each test holds the log to: the rows the engine recorded (result.rows), an independent CDR decoder
(mcap-ros2-support), the model compiled from the keywords the run was given, and logs altered by one ulp
or one seed."""

from __future__ import annotations

import dataclasses
import functools
import json

import mujoco
import numpy as np
import pytest
from helpers import StopAfter3000Rows, chunk_spans, foxglove_read, ros2_decoded

from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError
from wmr_mj.hardware import Actuation, Sensing, Transmission
from wmr_mj.logs import logformat as lf
from wmr_mj.logs.reader import load_log
from wmr_mj.logs.replay import (
    format_summary,
    format_verify,
    hardware_labels,
    replay_figure,
    summarize,
    verify,
    verify_controller,
)
from wmr_mj.logs.writer import RunLogger
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.designs import CERTIFIED

#: the brief's sensing: a 10-bit encoder on the axis, a filtered difference, a delay and both noises
SPEC = ("encoder_ticks=1024,velocity=filtered,filter_tau=0.002,delay=0.005,noise=uniform:0.0005,"
        "velocity_noise=gaussian:0.01,seed=3")
SENSED = RunConfig(path="lane-change", duration=6.0, sensing=SPEC, **CERTIFIED.config_changes())
IDEAL = RunConfig(path="lane-change", duration=6.0, **CERTIFIED.config_changes())
ORIGINAL_TOPICS = ["/signals", "/sim/state", "/steering", "/motor", "/pose", "/path", "/bounds", "/tf", "/scene"]


def _run(config, path, logger=RunLogger):
    return run_closed_loop(config, logger_factory=functools.partial(logger, path), progress=False)


@pytest.fixture(scope="module")
def sensed(tmp_path_factory):
    path = tmp_path_factory.mktemp("sensed") / "sensed.mcap"
    result = _run(SENSED, path)
    return path, result


def _messages(path):
    """{topic: [(log_time, publish_time, sequence, payload)]} through mcap's own reader, with channel ids."""
    from mcap.reader import make_reader

    out: dict[str, list] = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for _, ch, m in reader.iter_messages(log_time_order=False):
            out.setdefault(ch.topic, []).append((ch.id, m.log_time, m.publish_time, m.sequence, bytes(m.data)))
    return out


def test_sensed_keys_are_the_engines():
    from wmr_mj.sim.engine import SENSED_ROW_FIELDS

    assert lf.SENSED_BLOCK_KEYS == SENSED_ROW_FIELDS
    assert [t for t in lf.channel_layouts()["channels"] if lf.sensed_only(t)] == [lf.MEASURED_TOPIC,
                                                                                  lf.MEASURED_PLOT_TOPIC]


def test_the_log_holds_what_the_law_read_beside_the_true_state(sensed):
    path, result = sensed
    log = load_log(path)
    assert log.sensed and log.topics == ORIGINAL_TOPICS[:7] + ["/measured", "/steering/measured"] + ORIGINAL_TOPICS[7:]
    rows = result.rows
    ms = log.measured
    for key in ("t", "alpha_measured", "alpha_dot_measured"):  # every control step, bit for bit
        assert ms[key].tobytes() == rows[key].tobytes(), key
    # /signals keeps the true state, which differs from what the law read (encoder, noise, delay)
    assert log.signals["alpha"].tobytes() == rows["alpha"].tobytes()
    assert np.count_nonzero(ms["alpha_measured"] != log.signals["alpha"]) > 0.99 * len(ms["t"])
    # Foxglove's plot channel: every plot_every-th row (100 Hz of 1 kHz), decoded by an independent decoder
    dec = ros2_decoded(path, ["/measured", "/steering/measured"])
    plot = dec["/steering/measured"]
    assert len(plot) == 600
    assert np.array_equal([m.alpha for _, m in plot], rows["alpha_measured"][::10])
    assert np.array_equal([m.alpha_dot for _, m in plot], rows["alpha_dot_measured"][::10])
    assert [t for t, _ in plot] == [int(round(t * 1e9)) for t in rows["t"][::10]]
    packed = dec["/measured"]
    assert [m.rows for _, m in packed] == [1000] * 6  # one message per simulated second
    assert np.array_equal(np.concatenate([m.alpha for _, m in packed]), rows["alpha_measured"])
    units = {c: json.loads(log._channels[c].metadata["units"]) for c in ("/measured", "/steering/measured")}
    assert units["/measured"] == units["/steering/measured"] == {"t": "s", "alpha": "rad", "alpha_dot": "rad/s"}


def test_an_ideal_run_writes_no_sensed_channel_and_the_same_messages(tmp_path):
    """The sensed channels are added only: the same blocks logged with and without them hold the same
    messages on every other channel (ids, times, sequence numbers, bytes); an ideal run's log has none of them.
    (Also checked against the log /work/main wrote before the channels existed: same channels and messages.)"""
    ideal = tmp_path / "ideal.mcap"
    _run(IDEAL, ideal)
    log = load_log(ideal)
    assert log.topics == ORIGINAL_TOPICS and not log.sensed and log.measured is None
    blocks = []

    class Keep(RunLogger):
        def write_block(self, block):
            blocks.append({k: np.array(v) for k, v in block.items()})
            super().write_block(block)

    _run(SENSED, tmp_path / "sensed.mcap", Keep)
    from wmr_mj.sim.log_header import LogHeader

    header = LogHeader(mjcf_xml=log.mjcf_xml, config=log.config, parameters=log.parameters,
                       initial_state=log.initial_state, timestep=log.timestep, control_substeps=1,
                       bounds={"E_max": 0.2, "Edot_max": 1.6})
    written = {}
    for sensed_flag in (False, True):
        path = tmp_path / f"same-blocks-{sensed_flag}.mcap"
        with RunLogger(path, dataclasses.replace(header, sensed=sensed_flag)) as out:
            for b in blocks:
                out.write_block(b)
        written[sensed_flag] = _messages(path)
    plain, with_measured = written[False], written[True]
    assert set(with_measured) - set(plain) == {"/measured", "/steering/measured"}
    assert set(plain) == set(ORIGINAL_TOPICS)
    for topic in plain:
        ids = {m[0] for m in plain[topic]}
        same_bytes = [m[1:] for m in plain[topic]] == [m[1:] for m in with_measured[topic]]
        assert same_bytes, topic
        if topic not in ("/tf", "/scene"):  # the channels registered before the sensed ones keep their ids
            assert ids == {m[0] for m in with_measured[topic]}, topic


def test_a_sensed_block_without_what_the_law_read_is_refused(tmp_path, sensed):
    log = load_log(sensed[0])
    from wmr_mj.sim.log_header import LogHeader

    header = LogHeader(mjcf_xml=log.mjcf_xml, config=log.config, parameters=log.parameters,
                       initial_state=log.initial_state, timestep=log.timestep, control_substeps=1, sensed=True)
    block = {k: np.zeros((3, 2)) if k in ("A_pos", "C_pos") else np.zeros(3) for k in lf.BLOCK_KEYS}
    block.update(qpos=np.zeros((3, 13 - 1)), qvel=np.zeros((3, 12 - 1)), ctrl=np.zeros((3, 2)))
    with RunLogger(tmp_path / "x.mcap", header) as out:
        with pytest.raises(ParameterError, match="block lacks alpha_measured, alpha_dot_measured; .*sensed"):
            out.write_block(block)


def test_replay_verify_regenerates_what_the_law_read(sensed, capsys):
    path, _ = sensed
    log = load_log(path)
    ver = verify(log)
    assert ver["identical"] and ver["state_identical"]
    assert ver["measured"] == {"identical": True, "rows": 6000, "sensing": Sensing.from_spec(SPEC).label()}
    ctrl = verify_controller(log)
    assert ctrl["identical"] and ctrl["rows"] == 6000
    assert main(["replay", str(path), "--verify"]) == 0
    out = capsys.readouterr().out
    assert "bit-identical: what the law read (/measured" in out and "seed 3" in out


def _tampered(tmp_path, row):
    """The sensed run, logged with alpha_measured one ulp off at control step ``row`` (the rest honest)."""

    class OneUlpOff(RunLogger):
        def write_block(self, block):
            block = dict(block)
            t = np.asarray(block["t"])
            hit = np.flatnonzero(np.rint(t * 1000) == row)
            if hit.size:
                block["alpha_measured"] = a = np.array(block["alpha_measured"])
                a[hit] = np.nextafter(a[hit], np.inf)
            super().write_block(block)

    path = tmp_path / "tampered.mcap"
    _run(SENSED, path, OneUlpOff)
    return path


def test_a_tampered_measured_channel_fails_verify(tmp_path, capsys):
    path = _tampered(tmp_path, 2500)
    log = load_log(path)
    ver = verify(log)
    assert ver["state_identical"] and not ver["identical"]  # the physics is honest; what the law read is not
    ms = ver["measured"]
    assert not ms["identical"] and ms["mismatched_rows"] == 1 and ms["first_mismatch_t"] == 2.5
    assert ms["max_deviation_in"] == "alpha_measured" and 0 < ms["max_deviation"] < 1e-15
    assert "MISMATCH in what the law read" in format_verify(ver)
    ctrl = verify_controller(log)  # the re-run's law read the honest value
    assert not ctrl["identical"] and ctrl["first_mismatch_t"] == 2.5
    assert main(["replay", str(path), "--verify"]) == 1
    capsys.readouterr()


def test_another_seed_in_the_header_fails_verify(tmp_path):
    def reseeded(header):
        config = dict(header.config)
        config["sensing"] = {**config["sensing"], "seed": 4}
        return RunLogger(tmp_path / "reseeded.mcap", dataclasses.replace(header, config=config))

    run_closed_loop(SENSED, logger_factory=reseeded, progress=False)
    log = load_log(tmp_path / "reseeded.mcap")
    ver = verify(log)
    assert ver["state_identical"] and not ver["identical"]
    assert ver["measured"]["first_mismatch_t"] == 0.0  # the noise at step 0 is already another draw
    assert ver["measured"]["mismatched_rows"] == 6000
    assert not verify_controller(log)["identical"]  # the law re-run on seed 4's noise applies other voltages


def test_a_log_whose_config_lost_its_sensing_fails_verify(tmp_path):
    def unsensed(header):
        config = {k: v for k, v in header.config.items() if k != "sensing"}
        return RunLogger(tmp_path / "lost.mcap", dataclasses.replace(header, config=config))

    run_closed_loop(SENSED, logger_factory=unsensed, progress=False)
    ver = verify(load_log(tmp_path / "lost.mcap"))
    assert not ver["identical"] and "names no sensing" in ver["measured"]["reason"]


def test_actuation_and_backlash_the_header_model_is_the_one_simulated(tmp_path):
    from wmr_mj.plant.mjcf import compile_model, steering_joint_addresses
    from wmr_mj.sim.config import plant_parameters

    config = IDEAL.replace(actuation="inductance=0.001", transmission=0.002)
    path = tmp_path / "built.mcap"
    result = _run(config, path)
    log = load_log(path)
    header_model = mujoco.MjModel.from_xml_string(log.mjcf_xml)
    built, _ = compile_model(plant_parameters(config), inductance_H=0.001, backlash_rad=0.002)
    ideal, _ = compile_model(plant_parameters(config))
    compared = 0
    for name in dir(built):
        value = getattr(built, name)
        if name.startswith("_") or name.startswith(("tex", "name", "mat_texid", "paths")):
            continue
        if isinstance(value, np.ndarray):
            assert np.array_equal(value, getattr(header_model, name), equal_nan=True), name
            compared += 1
    assert compared > 100
    assert (header_model.na, ideal.na) == (1, 0)  # the armature current is a state of the built cart only
    assert steering_joint_addresses(header_model).play_tendon is not None
    assert not log.sensed and result.status == "completed"
    assert verify(log) == {"rows": 6000, "mj_steps": 6000, "identical": True}
    assert verify_controller(log)["identical"]
    rep = summarize(log)
    assert rep["hardware"] == {"sensing": "ideal", "actuation": Actuation.from_spec("inductance=0.001").label(),
                               "gear": Transmission.from_spec(0.002).label()}
    assert "actuation: L_a 1 mH | gear: backlash +-2 mrad" in format_summary(rep)


def test_an_interrupted_sensed_run_leaves_a_readable_log_that_verifies(tmp_path):
    path = tmp_path / "stopped.mcap"

    result = _run(SENSED.replace(duration=12.0), path, StopAfter3000Rows)
    assert result.status == "interrupted"
    log = load_log(path)
    assert log.status == "interrupted" and not log.truncated and log.rows == 3000
    assert log.measured["alpha_measured"].tobytes() == result.rows["alpha_measured"].tobytes()
    ver = verify(log)  # the noise is drawn for the 12 s the run was to last, as the run drew it
    assert ver["identical"] and ver["measured"]["rows"] == 3000
    # the file cut inside its last chunks (a killed run) still reads, its measured rows a prefix of the run's
    data = path.read_bytes()
    start, length = chunk_spans(path)[-3]
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: start + length // 2])
    short = load_log(cut)
    k = len(short.measured["t"])
    assert short.truncated and short.sensed and 0 < k <= 3000
    assert np.array_equal(short.measured["alpha_measured"], result.rows["alpha_measured"][:k])


def test_summary_and_figure_name_the_cart_and_draw_what_the_law_read(sensed, tmp_path):
    path, result = sensed
    log = load_log(path)
    rep = summarize(log)
    label = Sensing.from_spec(SPEC).label()
    assert rep["hardware"] == {"sensing": label, "actuation": "ideal", "gear": "ideal"} and rep["sensed"]
    assert f"cart       sensing: {label} | actuation: ideal | gear: ideal" in format_summary(rep)
    fig = replay_figure(log, rep)
    steering = fig.axes[0]
    (line,) = [ln for ln in steering.get_lines() if ln.get_label() == "measured (what the law read)"]
    rows = result.rows
    assert np.array_equal(line.get_ydata(), rows["alpha0"] - rows["alpha_measured"])
    assert label in fig._suptitle.get_text()
    ideal = tmp_path / "ideal.mcap"
    _run(IDEAL.replace(duration=2.0), ideal)
    log = load_log(ideal)
    fig = replay_figure(log, summarize(log))
    assert not [ln for ln in fig.axes[0].get_lines() if ln.get_label().startswith("measured")]
    assert "sensing:" not in fig._suptitle.get_text()  # an ideal cart's title as it was


def test_hardware_labels_of_a_config_wmr_mj_does_not_accept():
    labels = hardware_labels({"sensing": {"encoder_ticks": 0}, "transmission": {"backlash": -1.0}})
    assert labels["sensing"].startswith("not read (") and labels["gear"].startswith("not read (")
    assert labels["actuation"] == "ideal" and hardware_labels(None) == dict.fromkeys(labels, "ideal")


@pytest.mark.npm  # Foxglove's reader from npm (tests/foxglove_reader): skipped where it is not installed
def test_foxglove_reader_decodes_the_sensed_channels(sensed):

    path, result = sensed
    fox = foxglove_read(path)
    log = load_log(path)
    assert set(fox["topics"]) == set(log.topics)
    for topic, entry in fox["topics"].items():
        assert entry["count"] == log.message_count(topic), topic
    rows = result.rows
    packed = fox["topics"]["/measured"]["messages"][0]
    assert packed["rows"] == 1000
    assert packed["alpha"] == {"length": 1000, "first": rows["alpha_measured"][0], "last": rows["alpha_measured"][999]}
    plot = log.channel("/steering/measured")
    for k, msg in enumerate(fox["topics"]["/steering/measured"]["messages"]):
        assert msg == {name: float(plot[name][k]) for name in msg}


def test_a_motor_side_encoder_through_the_play_verifies(tmp_path):
    """The regenerated chain reads the motor shaft's joint (i2 times its angle) where the encoder is on the motor
    side of a gear with play, at a 2 ms control period (two physics steps per row), with an actuator delay."""
    config = IDEAL.replace(sensing="encoder_ticks=2000,encoder_side=motor,velocity=difference,noise=gaussian:0.0001,"
                                   "seed=1", transmission=0.002, actuation="delay=0.002", control_period=0.002)
    path = tmp_path / "motor.mcap"
    result = _run(config, path)
    log = load_log(path)
    ver = verify(log)
    assert ver["identical"] and ver["mj_steps"] == 6000 and ver["measured"]["rows"] == 3000
    # the motor-side reading leaves the axle's quantised angle by more than 1 mrad somewhere: the play (half-width
    # 2 mrad), not the noise (sd 0.1 mrad), so the chain above must have read the motor's joint
    axle = np.rint(result.rows["alpha"] * 60 * 2000 / (2 * np.pi)) / (60 * 2000 / (2 * np.pi))
    assert np.count_nonzero(np.abs(log.measured["alpha_measured"] - axle) > 1e-3) > 0
