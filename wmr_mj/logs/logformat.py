"""The wmr-mj run-log format (schema version 2): channels, their schemas, and CDR encoding.

A run log is one MCAP file per run, written by :class:`wmr_mj.logs.writer.RunLogger` through
``mcap.writer.Writer`` and read by :func:`wmr_mj.logs.reader.load_log` through mcap's readers. This
module says what is in it; ``wmr_mj/schemas/wmr_mj.channels.json`` is the one description of
our channels, from which the ros2msg schema text stored in every file is generated.

==============  =================================  ==========  =================  ==================================
topic           schema (encoding)                  messages    rate               content
==============  =================================  ==========  =================  ==================================
/signals        wmr_mj/msg/SignalBlock (ros2msg)   cdr         one per block      every logged row: t, alpha, ... e,
                                                                                  e_dot, voltage..., heading, a_pos,
                                                                                  c_pos (NumPy-packed sequences)
/sim/state      wmr_mj/msg/SimStateBlock           cdr         one per block      every control step: t, qpos, qvel,
                                                                                  ctrl (replay --verify reads it)
/steering       wmr_mj/msg/Steering                cdr         plot rate (100 Hz) one row: t alpha ... e e_dot
/motor          wmr_mj/msg/Motor                   cdr         plot rate          one row: t voltage_cmd voltage ...
/pose           wmr_mj/msg/Pose2                   cdr         tf rate            one row: t a_x a_y c_x c_y heading
/path           wmr_mj/msg/PathError               cdr         plot rate          one row: t cross_track along_track
                                                                                  heading_error (C against its path)
/bounds         wmr_mj/msg/Bounds                  cdr         one per block      +-E_max, +-Edot_max, +-voltage limit
/measured       wmr_mj/msg/MeasuredBlock           cdr         one per block      sensed runs only: every control step:
                                                                                  t, alpha, alpha_dot as the law read
                                                                                  them (replay --verify regenerates)
/steering/      wmr_mj/msg/SteeringMeasured        cdr         plot rate          sensed runs only: one row: t alpha
  measured                                                                        alpha_dot as the law read them
/tf             foxglove_msgs/msg/FrameTransforms  cdr         tf rate (50 Hz)    world -> chassis -> ... -> wheels
/scene          foxglove.SceneUpdate (jsonschema)  json        once, at t = 0     the vehicle's shapes, desired path
==============  =================================  ==========  =================  ==================================

/signals and /steering hold the true state (alpha, alpha_dot, E, E_dot) whatever the sensing. Where the
run has a sensor (``RunConfig.sensing`` not ideal; :attr:`wmr_mj.sim.log_header.LogHeader.sensed`), what the
law read instead (:data:`SENSED_BLOCK_KEYS`) goes to the two channels marked ``sensed_only``
(:func:`sensed_only`); an ideal run's log has neither, and its bytes are what they were before them.

A *block* is what the runner hands the logger about once per simulated second; its rows are
packed into one message per block channel, so that the full-rate data costs a few messages a
second. The plot channels repeat a decimated copy, one message per row, which Foxglove's Plot
panel draws against time. Every CDR message is little-endian XCDR1 (ROS 2's encoding): a
4-byte encapsulation header, then the fields, each aligned to its size counted from the end
of the header. Log times are nanoseconds of run time.

Usage::

    from wmr_mj.logs import logformat as lf
    text = lf.ros2msg_text("/sim/state")                  # the schema text stored in the file
    payload = lf.encode_block("/sim/state", {"t": t, "qpos": q, "qvel": v, "ctrl": u})
    fields = lf.decode_cdr(text, payload)                 # {"rows": n, "nq": .., "t": (n,), "qpos": (n*nq,) ...}
    rows = lf.row_dtype(lf.ros2msg_text("/steering"))     # structured dtype of one /steering message
"""

from __future__ import annotations

import functools
import json
import re
import struct
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from typing import Any

import numpy as np

__all__ = [
    "SCHEMA_VERSION",
    "SUPPORTED_SCHEMA_VERSIONS",
    "CDR_LE_HEADER",
    "SIGNALS_TOPIC",
    "STATE_TOPIC",
    "PLOT_TOPICS",
    "BOUNDS_TOPIC",
    "MEASURED_TOPIC",
    "MEASURED_PLOT_TOPIC",
    "PACKED_TOPICS",
    "SENSED_BLOCK_KEYS",
    "sensed_only",
    "TF_TOPIC",
    "SCENE_TOPIC",
    "BLOCK_KEYS",
    "OPTIONAL_BLOCK_KEYS",
    "channel_layouts",
    "schema_text",
    "foxglove_schema",
    "ros2msg_text",
    "Field",
    "parse_ros2msg",
    "row_dtype",
    "encode_rows",
    "encode_block",
    "decode_cdr",
    "CdrTemplate",
]

SCHEMA_VERSION = "2"
SUPPORTED_SCHEMA_VERSIONS = ("2",)
CDR_LE_HEADER = b"\x00\x01\x00\x00"  # encapsulation: plain CDR, little endian

SIGNALS_TOPIC = "/signals"
STATE_TOPIC = "/sim/state"
PLOT_TOPICS = ("/steering", "/motor", "/pose", "/path")
BOUNDS_TOPIC = "/bounds"
MEASURED_TOPIC = "/measured"  # sensed runs only: what the law read, every control step
MEASURED_PLOT_TOPIC = "/steering/measured"  # sensed runs only: the same at the plot rate, for Foxglove
#: The block channels, one message per block (their chunks are CRC-checked when the log is loaded).
PACKED_TOPICS = (SIGNALS_TOPIC, STATE_TOPIC, MEASURED_TOPIC)
TF_TOPIC = "/tf"
SCENE_TOPIC = "/scene"

#: What the runner hands the logger: (N,) arrays, A_pos/C_pos (N, 2), qpos/qvel/ctrl (N, nq/nv/nu).
BLOCK_KEYS = (
    "t", "alpha", "alpha_dot", "alpha0", "alpha0_dot", "alpha0_ddot", "E", "E_dot",
    "voltage_cmd", "voltage", "current", "steer_torque", "A_pos", "C_pos", "heading",
    "qpos", "qvel", "ctrl",
)  # fmt: skip
#: What the runner may add to a block: C's path errors (NaN where absent), for the /path channel.
OPTIONAL_BLOCK_KEYS = ("path_cross_track", "path_along_track", "path_heading_error")
#: What the runner adds to a block where the run has a sensor (wmr_mj.sim.engine.SENSED_ROW_FIELDS): alpha
#: [rad] and alpha' [rad/s] as the law read them, (N,) each; required by a logger whose header says sensed.
SENSED_BLOCK_KEYS = ("alpha_measured", "alpha_dot_measured")

_PRIMITIVES = {
    "float64": "<f8", "float32": "<f4", "int8": "i1", "uint8": "u1", "int16": "<i2", "uint16": "<u2",
    "int32": "<i4", "uint32": "<u4", "int64": "<i8", "uint64": "<u8", "bool": "u1", "byte": "u1", "char": "u1",
}  # fmt: skip


# --------------------------------------------------------------------------- layout files


def schema_text(name: str) -> str:
    """A file of ``wmr_mj/schemas`` as text (works from a wheel too)."""
    return resources.files("wmr_mj").joinpath("schemas", name).read_text(encoding="utf-8")


@functools.lru_cache(maxsize=1)
def channel_layouts() -> dict[str, Any]:
    """``wmr_mj/schemas/wmr_mj.channels.json`` parsed (shared: do not modify it)."""
    return json.loads(schema_text("wmr_mj.channels.json"))


def foxglove_schema(name: str) -> dict[str, Any]:
    """A vendored Foxglove JSON schema, e.g. ``foxglove_schema("foxglove.SceneUpdate")``."""
    return json.loads(schema_text(f"{name}.json"))


def sensed_only(topic: str) -> bool:
    """True for a channel written only in the log of a run with a sensor (``"sensed_only"`` in its layout)."""
    return bool(channel_layouts()["channels"][topic].get("sensed_only", False))


@functools.cache
def ros2msg_text(topic: str) -> str:
    """The ros2msg schema text of one of our channels (/signals, /sim/state, plot channels, /bounds)."""
    spec = channel_layouts()["channels"][topic]
    kind = spec["kind"]
    lines = [f"# {topic} of a wmr-mj run log, schema version {SCHEMA_VERSION}: {spec['description']}"]
    if kind == "block":
        lines.append("# Each float64[] holds one value per row in row order, or `columns` values per row (row-major).")
        lines.append("uint32 rows  # rows in this message")
        for name in spec.get("counts", []):
            lines.append(f"uint32 {name}  # columns of the fields sized {name}")
    for f in spec["fields"]:
        unit = f" [{f['unit']}]" if f.get("unit") else ""
        cols = f.get("columns")
        per_row = f", {cols} per row" if cols is not None else ""
        typ = "float64[]" if kind == "block" else "float64"
        lines.append(f"{typ} {f['name']}  # {f['description']}{per_row}{unit}")
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- ros2msg


@dataclass(frozen=True)
class Field:
    """One top-level field of a ros2msg definition: ``length`` None (scalar), -1 (unbounded
    sequence ``T[]``) or n (fixed array ``T[n]``)."""

    type: str
    name: str
    length: int | None

    @property
    def dtype(self) -> np.dtype:
        return np.dtype(_PRIMITIVES[self.type])


_FIELD = re.compile(r"(\w+(?:/\w+)*)(?:\[(\d*)\])?\s+(\w+)(\s*=.*|\s+\S.*)?")


@functools.lru_cache(maxsize=64)
def parse_ros2msg(text: str) -> tuple[Field, ...] | None:
    """Top-level fields of a ros2msg text whose fields are all primitive numbers (scalars, fixed
    arrays or sequences); None when it has strings, nested types or bounded sequences."""
    fields: list[Field] = []
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        if line.startswith("==="):
            break  # definitions of nested types follow
        m = _FIELD.fullmatch(line)
        if not m or m.group(1) not in _PRIMITIVES:
            return None
        if m.group(4) and m.group(4).lstrip().startswith("="):
            continue  # a constant
        length = None if m.group(2) is None else (-1 if m.group(2) == "" else int(m.group(2)))
        fields.append(Field(m.group(1), m.group(3), length))
    return tuple(fields)


@functools.lru_cache(maxsize=64)
def row_dtype(text: str) -> np.dtype | None:
    """Structured dtype of a whole CDR message (header + fields) whose fields all have a fixed
    size; None otherwise. Messages of such a channel are decoded in bulk with it."""
    fields = parse_ros2msg(text)
    if fields is None or any(f.length == -1 for f in fields):
        return None
    spec: list[tuple] = [("__cdr", "u1", (4,))]
    offset = 0
    for f in fields:
        size = f.dtype.itemsize
        pad = (-offset) % size
        if pad:
            spec.append((f"__pad{offset}", "u1", (pad,)))
            offset += pad
        spec.append((f.name, f.dtype, (f.length,)) if f.length is not None else (f.name, f.dtype))
        offset += size * (f.length or 1)
    return np.dtype(spec)


def encode_rows(topic: str, block: Mapping[str, np.ndarray], rows: Any) -> np.ndarray:
    """The messages of a per-row channel for the given ``rows`` of a block: (n,) structured array
    (``.tobytes()`` holds them back to back, ``itemsize`` bytes each)."""
    spec = channel_layouts()["channels"][topic]
    dt = row_dtype(ros2msg_text(topic))
    t = block["t"][rows]
    out = np.zeros(len(t), dt)
    out["__cdr"] = np.frombuffer(CDR_LE_HEADER, np.uint8)
    for f in spec["fields"]:
        src = block[f["block"]]
        out[f["name"]] = src[rows, f["index"]] if "index" in f else src[rows]
    return out


def encode_block(topic: str, values: Mapping[str, Any]) -> bytes:
    """One message of a block channel: ``values`` maps field names (and the ``counts``, e.g.
    nq) to arrays; (n, k) arrays are written row-major; ``rows`` is taken from ``values["t"]``."""
    fields = parse_ros2msg(ros2msg_text(topic))
    assert fields is not None
    parts = [CDR_LE_HEADER]
    offset = 0
    rows = len(values["t"])
    for f in fields:
        size = f.dtype.itemsize
        if f.length is None:
            value = rows if f.name == "rows" else values[f.name]
            pad = (-offset) % size
            parts.append(b"\0" * pad + np.asarray(value, f.dtype).tobytes())
            offset += pad + size
            continue
        data = np.ascontiguousarray(values[f.name], f.dtype).tobytes()
        pad = (-offset) % 4
        offset += pad + 4
        pad2 = (-offset) % size
        parts.append(b"\0" * pad + struct.pack("<I", len(data) // size) + b"\0" * pad2 + data)
        offset += pad2 + len(data)
    return b"".join(parts)


def decode_cdr(text: str, payload: bytes) -> dict[str, Any]:
    """Decode one CDR message of a numbers-only ros2msg schema (see :func:`parse_ros2msg`):
    scalars as Python numbers, arrays and sequences as read-only NumPy views of ``payload``.
    Raises ValueError when the schema is not numbers-only or the payload does not fit it."""
    fields = parse_ros2msg(text)
    if fields is None:
        raise ValueError("the schema has strings or nested types")
    if len(payload) < 4 or payload[1] != 1:
        raise ValueError("the payload is not little-endian CDR")
    buf = memoryview(payload)[4:]
    offset = 0
    out: dict[str, Any] = {}
    for f in fields:
        size = f.dtype.itemsize
        count = 1 if f.length is None else f.length
        if f.length == -1:
            offset += (-offset) % 4
            (count,) = struct.unpack_from("<I", buf, offset)
            offset += 4
        offset += (-offset) % size
        end = offset + size * count
        if end > len(buf):
            raise ValueError(f"field {f.name} runs past the end of the {len(payload)}-byte payload")
        arr = np.frombuffer(buf[offset:end], f.dtype)
        out[f.name] = arr[0].item() if f.length is None else arr
        offset = end
    return out


# --------------------------------------------------------------------------- fixed-shape CDR messages


class CdrTemplate:
    """Byte layout of one CDR message whose shape is fixed (same strings, same sequence
    lengths), built field by field in order; the numbers are then written for N messages at
    once into copies of :attr:`template` at the byte offsets :attr:`slots` records.

    ``uint32``/``string`` write fixed content; ``slot(name, type)`` reserves an aligned number
    and returns its offset in the payload (header included).
    """

    def __init__(self) -> None:
        self._buf = bytearray(CDR_LE_HEADER)
        self.slots: dict[str, tuple[int, str]] = {}  # name -> (byte offset, dtype code)

    def _align(self, size: int) -> None:
        self._buf += b"\0" * ((-(len(self._buf) - 4)) % size)

    def uint32(self, value: int) -> None:
        self._align(4)
        self._buf += struct.pack("<I", value)

    def string(self, text: str) -> None:
        data = text.encode("utf-8") + b"\0"
        self.uint32(len(data))
        self._buf += data

    def slot(self, name: str, type_: str) -> int:
        code = _PRIMITIVES[type_]
        size = np.dtype(code).itemsize
        self._align(size)
        self.slots[name] = (len(self._buf), code)
        self._buf += b"\0" * size
        return self.slots[name][0]

    @property
    def template(self) -> bytes:
        return bytes(self._buf)

    def byte_index(self, names: list[str]) -> np.ndarray:
        """Byte positions of the slots ``names``, in order: where ``values.view(np.uint8)`` goes
        for a C-contiguous (N, len(names)) array of their (common) dtype."""
        return np.concatenate([self.slots[n][0] + np.arange(np.dtype(self.slots[n][1]).itemsize) for n in names])
