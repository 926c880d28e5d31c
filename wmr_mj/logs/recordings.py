"""A wmr-mj run's MCAP log as a recording for identification (``wmr-mj identify --data run.mcap``).

The log carries what identification needs: the time and the applied voltage at every logged row (/signals),
the angle the law read at every control step (/measured, a sensed run; an ideal run's law read the exact
angle of /signals), and the chassis mass m1 of the run (its parameters). A log written with ``--log-every``
above 1 has the voltage of every k-th step only: refused, in one line.

A ROS 2 bag in MCAP (``--data bag.mcap --topics u=/steer/voltage,alpha=/steer/angle[,speed=/odom/speed]``) is
read through mcap's own ROS 2 support (``mcap-ros2-support``): each topic's messages carry one number, the field
``data`` (std_msgs/Float64) or the field named after the topic (``/joint_states.position[0]``); the recording's
times are the angle's log times, the voltage and speed held from their last message (zero-order hold).

Usage::

    from wmr_mj.logs.recordings import read_run_log, read_ros2_bag
    rec = read_run_log("logs/run.mcap")          # rec.m1: the run's chassis mass
    rec = read_ros2_bag("bag.mcap", {"u": "/steer/voltage", "alpha": "/steer/angle"}, m1=112.0)
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from wmr_mj.errors import ParameterError
from wmr_mj.logs.reader import load_log
from wmr_mj.plant.recordings import Recording, file_sha256

__all__ = ["read_run_log", "read_ros2_bag", "parse_topics", "TOPIC_KEYS"]

#: The keys of ``--topics``: the voltage applied, the angle read, the speed (optional).
TOPIC_KEYS = ("u", "alpha", "speed")
_FIELD = re.compile(r"^(?P<topic>/[^.\[]*)(?:\.(?P<field>\w+)(?:\[(?P<index>\d+)\])?)?$")


def parse_topics(text: str | None) -> dict[str, str]:
    """``u=/a,alpha=/b.position[0]`` -> {"u": "/a", "alpha": "/b.position[0]"}.

    Raises:
        ParameterError: a pair without '=', an unknown key, or u or alpha missing.
    """
    out: dict[str, str] = {}
    for pair in (text or "").split(","):
        key, sep, value = pair.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or key not in TOPIC_KEYS or not _FIELD.match(value):
            raise ParameterError(f"--topics: {pair!r} is not accepted; accepted: u=/TOPIC,alpha=/TOPIC"
                                 "[,speed=/TOPIC], a topic with an optional .field or .field[i] (default field: data)")
        out[key] = value
    for key in ("u", "alpha"):
        if key not in out:
            raise ParameterError(f"--topics names no {key}=/TOPIC; accepted: u=/TOPIC,alpha=/TOPIC[,speed=/TOPIC]")
    return out


def _series(path: Path, spec: str) -> tuple[np.ndarray, np.ndarray]:
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory  # optional: mcap-ros2-support, needed for ROS 2 bags only

    m = _FIELD.match(spec)
    assert m is not None  # parse_topics checked it
    topic, field, index = m["topic"], m["field"] or "data", m["index"]
    times, values = [], []
    try:
        with open(path, "rb") as f:
            reader = make_reader(f, decoder_factories=[DecoderFactory()])
            for _schema, _channel, message, ros_msg in reader.iter_decoded_messages(topics=[topic]):
                value = getattr(ros_msg, field)
                values.append(float(value[int(index)] if index is not None else value))
                times.append(message.log_time * 1e-9)
    except (AttributeError, IndexError, TypeError, ValueError) as exc:
        raise ParameterError(f"recording {str(path)!r}: topic {topic} has no number at {spec!r}: {exc}") from None
    except Exception as exc:  # mcap's readers raise their own errors for a corrupt file
        raise ParameterError(f"recording {str(path)!r} cannot be read as a ROS 2 bag: {exc}") from None
    if not times:
        raise ParameterError(f"recording {str(path)!r}: topic {topic} is missing or empty; accepted: a topic of the "
                             "bag")
    return np.asarray(times), np.asarray(values)


def read_ros2_bag(path: str | Path, topics: dict[str, str], *, m1: float | None = None) -> Recording:
    """A recording from a ROS 2 bag in MCAP: the angle's times, the voltage (and speed) held from their last
    message before each.

    Raises:
        ParameterError: a missing or empty topic, a field that is not a number, a voltage that starts after the
            angle (no voltage to hold at the first angle).
    """
    path = Path(path)
    t, alpha = _series(path, topics["alpha"])
    tu, u = _series(path, topics["u"])
    held = np.searchsorted(tu, t, side="right") - 1
    keep = held >= 0
    if not keep.any():
        raise ParameterError(f"recording {str(path)!r}: the voltage topic {topics['u']} starts after the angle's last "
                             "message; accepted: a bag in which both overlap")
    speed = None
    if "speed" in topics:
        ts, v = _series(path, topics["speed"])
        speed = v[np.clip(np.searchsorted(ts, t[keep], side="right") - 1, 0, v.size - 1)]
    return Recording(name=str(path), sha256=file_sha256(path), t=t[keep], voltage=u[held[keep]], alpha=alpha[keep],
                     speed=speed, m1=m1)


def read_run_log(path: str | Path, *, m1: float | None = None) -> Recording:
    """The recording a run's log holds: t, the applied voltage, the angle the law read; m1 the run's.

    Args:
        path: the MCAP log of a ``wmr-mj run``.
        m1: chassis mass, kg (None: the run's, from the log's parameters).

    Raises:
        ParameterError: a log that cannot be read, or one logged every k-th step (k > 1).
        wmr_mj.errors.LogError: a corrupt or unsupported file.
    """
    log = load_log(path)
    if log.log_every != 1:
        raise ParameterError(f"recording {str(path)!r}: the run logged every {log.log_every}th step; accepted: a log "
                             "of every control step (wmr-mj run --log-every 1, the default)")
    signals = log.signals
    measured = log.measured
    alpha = measured["alpha_measured"] if measured is not None else signals["alpha"]
    n = min(signals["t"].size, alpha.size)
    mass = float(log.parameters["m1"]) if m1 is None else m1
    return Recording(name=str(path), sha256=file_sha256(path), t=np.asarray(signals["t"][:n], float),
                     voltage=np.asarray(signals["voltage"][:n], float), alpha=np.asarray(alpha[:n], float),
                     speed=None, m1=mass)
