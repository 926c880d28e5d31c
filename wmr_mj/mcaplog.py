"""MCAP run logs: one file per closed-loop run, written in bulk with NumPy.

The runner hands :class:`RunLogger` one *block* of rows about once per simulated
second; every block is encoded with vectorised NumPy (no per-message Python
work), written as complete zstd chunks and flushed, so that a killed run leaves a
readable file. ``close`` appends the summary metadata, the index and the footer.

Channels (schema version 1, see ``wmr_mj/schemas/wmr_mj.channels.json``):

==============  =========================  ==========  ==========================
topic           schema                     encoding    content
==============  =========================  ==========  ==========================
/steering       wmr_mj/msg/Steering        cdr         t alpha alpha_dot alpha0
                (ros2msg)                              alpha0_dot alpha0_ddot e e_dot
/motor          wmr_mj/msg/Motor           cdr         t voltage_cmd voltage current
                                                       steer_torque
/pose           wmr_mj/msg/Pose2           cdr         t a_x a_y c_x c_y heading
/sim/state      wmr_mj/msg/SimState        cdr         t qpos[nq] qvel[nv] ctrl[nu],
                                                       every control step
/tf             foxglove.FrameTransforms   json        world -> chassis -> ... frames
/scene          foxglove.SceneUpdate       json        vehicle shapes + desired path
==============  =========================  ==========  ==========================

Field names follow ROS 2 rules (lower case: ``e`` is the block's ``E``, ``a_x``
and ``a_y`` its ``A_pos``...); ``wmr_mj.logs.RunLog.signals`` maps them back.
Signal channels are written every ``log_every``-th row, ``/sim/state`` at every
row (``wmr-mj replay --verify`` re-simulates from it). Log times are nanoseconds
of run time. The MCAP records are produced here rather than by ``mcap.Writer``
(whose per-message cost is several microseconds); the files are plain MCAP and
open with the ``mcap`` reader and Foxglove.

Usage::

    with terminate_as_interrupt(), RunLogger("logs/run.mcap", mjcf_xml=xml, config=cfg,
            parameters=params, initial_state=s0, timestep=m.opt.timestep,
            control_substeps=1) as log:
        for block in blocks:            # dict of (N,...) float64 arrays
            log.write_block(block)
        log.close({"sup_abs_E": 0.01})
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime as _dt
import functools
import io
import json
import math
import os
import platform
import signal
import struct
import sys
import threading
import time
import zlib
from collections.abc import Iterator, Mapping
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "SCHEMA_VERSION",
    "RunLogger",
    "terminate_as_interrupt",
    "json_safe",
    "channel_layouts",
    "foxglove_schema",
    "software_versions",
    "measure_logging_overhead",
]

SCHEMA_VERSION = "1"
MCAP_MAGIC = b"\x89MCAP0\r\n"
CDR_LE_HEADER = b"\x00\x01\x00\x00"

# MCAP opcodes
OP_HEADER, OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_MESSAGE, OP_CHUNK = 0x01, 0x02, 0x03, 0x04, 0x05, 0x06
OP_MESSAGE_INDEX, OP_CHUNK_INDEX, OP_ATTACHMENT, OP_ATTACHMENT_INDEX = 0x07, 0x08, 0x09, 0x0A
OP_STATISTICS, OP_METADATA, OP_METADATA_INDEX, OP_SUMMARY_OFFSET, OP_DATA_END = 0x0B, 0x0C, 0x0D, 0x0E, 0x0F

SIGNAL_TOPICS = ("/steering", "/motor", "/pose")
STATE_TOPIC = "/sim/state"
TF_TOPIC = "/tf"
SCENE_TOPIC = "/scene"
BLOCK_KEYS = (
    "t", "alpha", "alpha_dot", "alpha0", "alpha0_dot", "alpha0_ddot", "E", "E_dot",
    "voltage_cmd", "voltage", "current", "steer_torque", "A_pos", "C_pos", "heading",
    "qpos", "qvel", "ctrl",
)  # fmt: skip
STATUSES = ("completed", "interrupted", "error")
MAX_CHUNK_BYTES = 8 << 20  # split a block's channel data into chunks of at most ~8 MiB


# --------------------------------------------------------------------------- schemas


def _schema_text(name: str) -> str:
    return resources.files("wmr_mj").joinpath("schemas", name).read_text(encoding="utf-8")


_LAYOUTS: dict[str, Any] | None = None


def channel_layouts() -> dict[str, Any]:
    """Our channel layout file ``wmr_mj/schemas/wmr_mj.channels.json`` (parsed)."""
    global _LAYOUTS
    if _LAYOUTS is None:
        _LAYOUTS = json.loads(_schema_text("wmr_mj.channels.json"))
    return _LAYOUTS


def foxglove_schema(name: str) -> dict[str, Any]:
    """A vendored Foxglove JSON schema, e.g. ``foxglove_schema("foxglove.SceneUpdate")``."""
    return json.loads(_schema_text(f"{name}.json"))


def _ros2msg(topic: str, sizes: Mapping[str, int]) -> tuple[str, str, list[tuple[str, int]]]:
    """(schema name, ros2msg text, [(field, count)]) of one of our signal channels."""
    spec = channel_layouts()["channels"][topic]
    lines = [f"# {topic} of a wmr-mj run log, schema version {SCHEMA_VERSION}"]
    fields: list[tuple[str, int]] = []
    for f in spec["fields"]:
        unit = f" [{f['unit']}]" if f.get("unit") else ""
        if "length" in f:
            n = int(sizes[f["length"]])
            lines.append(f"float64[{n}] {f['name']}  # {f['description']}{unit}")
            fields.append((f["name"], n))
        else:
            lines.append(f"float64 {f['name']}  # {f['description']}{unit}")
            fields.append((f["name"], 1))
    return spec["schema"], "\n".join(lines) + "\n", fields


# --------------------------------------------------------------------------- helpers


def json_safe(obj: Any) -> Any:
    """``obj`` with NumPy values made plain and NaN/inf replaced by None (valid JSON)."""
    if isinstance(obj, Mapping):
        return {str(k): json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, set, frozenset)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_safe(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if obj is None or isinstance(obj, str):
        return obj
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    if hasattr(obj, "as_dict"):
        return json_safe(obj.as_dict())
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return json_safe(dataclasses.asdict(obj))
    return str(obj)


def _dumps(obj: Any) -> str:
    return json.dumps(json_safe(obj), allow_nan=False, separators=(",", ":"))


@functools.lru_cache(maxsize=1)
def _software_versions() -> tuple[tuple[str, str], ...]:
    return tuple(_collect_versions().items())


def software_versions() -> dict[str, str]:
    """Versions of python, numpy, mujoco, mcap, zstandard and wmr_mj."""
    return dict(_software_versions())


def _collect_versions() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version(), "numpy": np.__version__}
    for dist in ("mujoco", "mcap", "zstandard", "wmr-mj"):
        try:
            out[dist.replace("-", "_")] = version(dist)
        except PackageNotFoundError:
            out[dist.replace("-", "_")] = "unknown"
    try:
        import wmr_mj

        out["wmr_mj"] = getattr(wmr_mj, "__version__", out["wmr_mj"])
    except Exception:  # pragma: no cover
        pass
    return out


def _s(text: str) -> bytes:
    b = text.encode("utf-8")
    return struct.pack("<I", len(b)) + b


def _m(mapping: Mapping[str, str]) -> bytes:
    body = b"".join(_s(str(k)) + _s(str(v)) for k, v in mapping.items())
    return struct.pack("<I", len(body)) + body


def _rec(op: int, body: bytes) -> bytes:
    return struct.pack("<BQ", op, len(body)) + body


class _Compressor:
    def __init__(self, name: str):
        self.name = ""
        self._fn = None
        for cand in [name] + [c for c in ("zstd", "lz4") if c != name]:
            if cand == "zstd":
                try:
                    import zstandard

                    comp = zstandard.ZstdCompressor(level=1)
                    self.name, self._fn = "zstd", comp.compress
                    return
                except ImportError:
                    continue
            if cand == "lz4":
                try:
                    import lz4.frame

                    self.name, self._fn = "lz4", lz4.frame.compress
                    return
                except ImportError:
                    continue
            if cand in ("", "none"):
                break

    def __call__(self, data: bytes) -> bytes:
        return self._fn(data) if self._fn else data


# --------------------------------------------------------------------------- fixed-width ASCII


_LUT4 = np.frombuffer("".join(f"{i:04d}" for i in range(10000)).encode("ascii"), "<u4").copy()


def _ascii_numbers(x: np.ndarray, int_digits: int, decimals: int) -> np.ndarray:
    """Vectorised fixed-width formatting: (n,) -> (n, W) uint8, W = 1 + int_digits (+ 1 + decimals).

    Each row is a valid JSON number right-aligned with leading spaces (JSON allows
    whitespace before a value). The caller guarantees finite |x| < 10**int_digits - 1.
    Digits are produced four at a time from a lookup table of 4-byte strings.
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    width = 1 + int_digits + (1 + decimals if decimals else 0)
    scaled = (np.abs(x) * (10.0**decimals) + 0.5).astype(np.int64)
    ndig = int_digits + decimals
    groups = -(-ndig // 4)
    quads = np.empty((n, groups), "<u4")
    rest = scaled
    for j in range(groups - 1, -1, -1):
        q = rest // 10000
        quads[:, j] = _LUT4[rest - q * 10000]
        rest = q
    digits = quads.view(np.uint8).reshape(n, 4 * groups)
    digits = digits[:, 4 * groups - ndig :]
    out = np.empty((n, width), np.uint8)
    out[:, 0] = 32
    out[:, 1 : 1 + int_digits] = digits[:, :int_digits]
    if int_digits > 1:  # leading zeros of the integer part become spaces
        lz = np.logical_and.accumulate(digits[:, : int_digits - 1] == 48, axis=1)
        out[:, 1:int_digits][lz] = 32
        lead = lz.sum(axis=1)
    else:
        lead = np.zeros(n, np.int64)
    if decimals:
        out[:, 1 + int_digits] = 46  # '.'
        out[:, 2 + int_digits :] = digits[:, int_digits:]
    neg = np.flatnonzero((x < 0) & (scaled > 0))
    if neg.size:
        out[neg, lead[neg]] = 45  # '-'
    return out


class _FixedJson:
    """A JSON message template with fixed-width numeric holes, filled for N rows at once."""

    def __init__(self) -> None:
        self._parts: list[bytes] = []
        self._holes: list[tuple[int, str, int]] = []  # (offset, group, column)
        self._len = 0

    def lit(self, text: str) -> None:
        b = text.encode("ascii")
        self._parts.append(b)
        self._len += len(b)

    def hole(self, group: str, column: int, width: int) -> None:
        self._holes.append((self._len, group, column))
        self._parts.append(b" " * width)
        self._len += width

    def compile(self, widths: Mapping[str, int]) -> None:
        self.base = np.frombuffer(b"".join(self._parts), np.uint8)
        self.length = self._len
        self.index: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        for group, w in widths.items():
            dst = [off + k for off, g, c in self._holes if g == group for k in range(w)]
            src = [c * w + k for off, g, c in self._holes if g == group for k in range(w)]
            self.index[group] = (np.asarray(dst, np.intp), np.asarray(src, np.intp))

    def fill(self, n: int, formatted: Mapping[str, np.ndarray]) -> np.ndarray:
        out = np.empty((n, self.length), np.uint8)
        out[:] = self.base
        for group, (dst, src) in self.index.items():
            if dst.size:
                out[:, dst] = formatted[group].reshape(n, -1)[:, src]
        return out


# --------------------------------------------------------------------------- kinematics


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Quaternion product (wxyz), broadcasting over leading axes."""
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def _qrot(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors v (...,3) by quaternions q (...,4, wxyz)."""
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    vx, vy, vz = v[..., 0], v[..., 1], v[..., 2]
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return np.stack(
        [vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz), vz + w * tz + (x * ty - y * tx)], axis=-1
    )


class FrameTree:
    """Frames of a compiled model (one per body) and their parent-relative poses from qpos.

    Frame names are body names ("world" for body 0). A body with a free joint is
    given directly in "world"; other bodies in their parent body's frame, with
    hinge/slide/ball joints applied as in ``mj_kinematics``.
    """

    def __init__(self, model: Any):
        import mujoco

        m = model
        self.names = []
        for b in range(m.nbody):
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)
            self.names.append(name if name else ("world" if b == 0 else f"body{b}"))
        self.frames: list[dict[str, Any]] = []
        for b in range(1, m.nbody):
            jadr, jnum = int(m.body_jntadr[b]), int(m.body_jntnum[b])
            joints = []
            free = False
            for j in range(jadr, jadr + jnum) if jnum > 0 else []:
                jt = int(m.jnt_type[j])
                qa = int(m.jnt_qposadr[j])
                if jt == int(mujoco.mjtJoint.mjJNT_FREE):
                    free = True
                    joints = [("free", qa, None, None, 0.0)]
                    break
                kind = {
                    int(mujoco.mjtJoint.mjJNT_BALL): "ball",
                    int(mujoco.mjtJoint.mjJNT_SLIDE): "slide",
                    int(mujoco.mjtJoint.mjJNT_HINGE): "hinge",
                }[jt]
                joints.append(
                    (kind, qa, np.array(m.jnt_axis[j], float), np.array(m.jnt_pos[j], float), float(m.qpos0[qa]))
                )
            parent = "world" if free else self.names[int(m.body_parentid[b])]
            self.frames.append(
                {
                    "child": self.names[b],
                    "parent": parent,
                    "pos0": np.array(m.body_pos[b], float),
                    "quat0": np.array(m.body_quat[b], float),
                    "joints": joints,
                }
            )

    def local_poses(self, qpos: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """Per frame: translation (N,3) and quaternion (N,4, wxyz) in the parent frame."""
        qpos = np.asarray(qpos, np.float64)
        n = qpos.shape[0]
        out = []
        for fr in self.frames:
            pos = np.broadcast_to(fr["pos0"], (n, 3)).copy()
            quat = np.broadcast_to(fr["quat0"], (n, 4)).copy()
            for kind, qa, axis, jpos, ref in fr["joints"]:
                if kind == "free":
                    pos = qpos[:, qa : qa + 3].copy()
                    quat = qpos[:, qa + 3 : qa + 7].copy()
                    with np.errstate(invalid="ignore", divide="ignore"):
                        quat /= np.linalg.norm(quat, axis=1, keepdims=True)
                    continue
                off = bool(np.any(jpos != 0))
                anchor = pos + _qrot(quat, np.broadcast_to(jpos, (n, 3))) if off else pos
                if kind == "slide":
                    pos = pos + _qrot(quat, np.broadcast_to(axis, (n, 3))) * (qpos[:, qa] - ref)[:, None]
                    continue
                if kind == "ball":
                    qloc = qpos[:, qa : qa + 4].copy()
                    with np.errstate(invalid="ignore", divide="ignore"):
                        qloc /= np.linalg.norm(qloc, axis=1, keepdims=True)
                else:
                    half = 0.5 * (qpos[:, qa] - ref)
                    an = axis / np.linalg.norm(axis)
                    qloc = np.column_stack([np.cos(half), np.sin(half)[:, None] * an])
                quat = _qmul(quat, qloc)
                if off:
                    pos = anchor - _qrot(quat, np.broadcast_to(jpos, (n, 3)))
            out.append((pos, quat))
        return out


class _TfEncoder:
    """foxglove.FrameTransforms JSON for N rows at once, as fixed-length ASCII rows.

    Components that no joint can change (found by evaluating the frames at random
    joint values) are written as literals; the others are fixed-width holes.
    """

    POS_INT, POS_DEC = 6, 6  # |x| < 999999 m, micrometres
    QUAT_INT, QUAT_DEC = 1, 8

    def __init__(self, tree: FrameTree, model: Any):
        self.tree = tree
        samples = self._random_qpos(model, 16)
        poses = tree.local_poses(samples)
        wpos = 1 + self.POS_INT + 1 + self.POS_DEC
        wq = 1 + self.QUAT_INT + 1 + self.QUAT_DEC
        self.pos_cols: list[tuple[int, int]] = []  # (frame, component) of variable translations
        self.quat_cols: list[tuple[int, int]] = []  # (frame, component wxyz) of variable rotations
        tpl = _FixedJson()
        tpl.lit('{"transforms":[')
        for i, fr in enumerate(tree.frames):
            pos, quat = poses[i]
            tpl.lit("," if i else "")
            tpl.lit('{"timestamp":{"sec":')
            tpl.hole("sec", 0, 11)
            tpl.lit(',"nsec":')
            tpl.hole("nsec", 0, 10)
            tpl.lit(f'}},"parent_frame_id":{json.dumps(fr["parent"])},"child_frame_id":{json.dumps(fr["child"])},"translation":{{')
            for c, key in enumerate("xyz"):
                tpl.lit(("," if c else "") + f'"{key}":')
                if np.all(pos[:, c] == pos[0, c]):
                    tpl.lit(json.dumps(float(pos[0, c])))
                else:
                    tpl.hole("pos", len(self.pos_cols), wpos)
                    self.pos_cols.append((i, c))
            tpl.lit('},"rotation":{')
            for k, (c, key) in enumerate(zip((1, 2, 3, 0), "xyzw")):
                tpl.lit(("," if k else "") + f'"{key}":')
                if np.all(quat[:, c] == quat[0, c]):
                    tpl.lit(json.dumps(float(quat[0, c])))
                else:
                    tpl.hole("quat", len(self.quat_cols), wq)
                    self.quat_cols.append((i, c))
            tpl.lit("}}")
        tpl.lit("]}")
        tpl.compile({"sec": 11, "nsec": 10, "pos": wpos, "quat": wq})
        self.tpl = tpl
        self.length = tpl.length

    @staticmethod
    def _random_qpos(model: Any, n: int) -> np.ndarray:
        import mujoco

        rng = np.random.default_rng(12345)
        q = np.tile(np.asarray(model.qpos0, float), (n, 1))
        for j in range(model.njnt):
            a = int(model.jnt_qposadr[j])
            jt = int(model.jnt_type[j])
            if jt == int(mujoco.mjtJoint.mjJNT_FREE):
                q[:, a : a + 3] = rng.uniform(-5, 5, (n, 3))
                u = rng.normal(size=(n, 4))
                q[:, a + 3 : a + 7] = u / np.linalg.norm(u, axis=1, keepdims=True)
            elif jt == int(mujoco.mjtJoint.mjJNT_BALL):
                u = rng.normal(size=(n, 4))
                q[:, a : a + 4] = u / np.linalg.norm(u, axis=1, keepdims=True)
            else:
                q[:, a] = rng.uniform(-3, 3, n)
        return q

    def encode(self, log_time: np.ndarray, qpos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(rows kept, (n_kept, length) uint8 payloads); rows with non-finite poses are left out."""
        poses = self.tree.local_poses(qpos)
        n = qpos.shape[0]
        pos = np.empty((n, len(self.pos_cols)))
        for k, (i, c) in enumerate(self.pos_cols):
            pos[:, k] = poses[i][0][:, c]
        quat = np.empty((n, len(self.quat_cols)))
        for k, (i, c) in enumerate(self.quat_cols):
            quat[:, k] = poses[i][1][:, c]
        with np.errstate(invalid="ignore"):
            ok = np.all(np.abs(pos) < 10.0**self.POS_INT - 1, axis=1) & np.all(np.abs(quat) <= 1.0 + 1e-9, axis=1)
        keep = np.flatnonzero(ok)
        if keep.size < n:
            pos, quat, log_time = pos[keep], quat[keep], log_time[keep]
        k = keep.size
        quat = np.clip(quat, -1.0, 1.0)
        fmt = {
            "sec": _ascii_numbers((log_time // 1_000_000_000).astype(np.float64), 10, 0),
            "nsec": _ascii_numbers((log_time % 1_000_000_000).astype(np.float64), 9, 0),
            "pos": _ascii_numbers(pos.ravel(), self.POS_INT, self.POS_DEC),
            "quat": _ascii_numbers(quat.ravel(), self.QUAT_INT, self.QUAT_DEC),
        }
        return keep, self.tpl.fill(k, fmt)


# --------------------------------------------------------------------------- scene


def _geom_color(m: Any, g: int) -> dict[str, float]:
    rgba = np.array(m.geom_rgba[g], float)
    mat = int(m.geom_matid[g])
    if mat >= 0 and np.allclose(rgba, [0.5, 0.5, 0.5, 1.0]):
        rgba = np.array(m.mat_rgba[mat], float)
    r, gg, b, a = (float(np.clip(v, 0.0, 1.0)) for v in rgba)
    return {"r": r, "g": gg, "b": b, "a": a}


def _pose(pos: Any, quat_wxyz: Any) -> dict[str, Any]:
    w, x, y, z = (float(v) for v in quat_wxyz)
    return {
        "position": {"x": float(pos[0]), "y": float(pos[1]), "z": float(pos[2])},
        "orientation": {"x": x, "y": y, "z": z, "w": w},
    }


def scene_update(model: Any, frame_names: list[str], reference_path: np.ndarray | None) -> dict[str, Any]:
    """foxglove.SceneUpdate: one entity per body with geoms (frame-locked), plus the path."""
    import mujoco

    m = model
    T = mujoco.mjtGeom
    stamp = {"sec": 0, "nsec": 0}

    def entity(frame: str, ident: str) -> dict[str, Any]:
        return {
            "timestamp": stamp, "frame_id": frame, "id": ident, "lifetime": {"sec": 0, "nsec": 0},
            "frame_locked": True, "metadata": [], "arrows": [], "cubes": [], "spheres": [],
            "cylinders": [], "lines": [], "triangles": [], "texts": [], "models": [],
        }  # fmt: skip

    entities: dict[int, dict[str, Any]] = {}
    for g in range(m.ngeom):
        b = int(m.geom_bodyid[g])
        gt = int(m.geom_type[g])
        size = np.array(m.geom_size[g], float)
        pos, quat = np.array(m.geom_pos[g], float), np.array(m.geom_quat[g], float)
        color = _geom_color(m, g)
        if color["a"] <= 0.0:
            continue
        ent = entities.get(b)
        if ent is None:
            ent = entities[b] = entity(frame_names[b], f"body:{frame_names[b]}")
        if gt == int(T.mjGEOM_BOX):
            ent["cubes"].append({"pose": _pose(pos, quat), "size": dict(zip("xyz", map(float, 2 * size))), "color": color})
        elif gt == int(T.mjGEOM_SPHERE):
            d = float(2 * size[0])
            ent["spheres"].append({"pose": _pose(pos, quat), "size": {"x": d, "y": d, "z": d}, "color": color})
        elif gt == int(T.mjGEOM_ELLIPSOID):
            ent["spheres"].append({"pose": _pose(pos, quat), "size": dict(zip("xyz", map(float, 2 * size))), "color": color})
        elif gt in (int(T.mjGEOM_CYLINDER), int(T.mjGEOM_CAPSULE)):
            d, h = float(2 * size[0]), float(2 * size[1])
            ent["cylinders"].append(
                {"pose": _pose(pos, quat), "size": {"x": d, "y": d, "z": h}, "bottom_scale": 1.0, "top_scale": 1.0, "color": color}
            )
            if gt == int(T.mjGEOM_CAPSULE):
                for sgn in (-1.0, 1.0):
                    c = pos + _qrot(quat, np.array([0.0, 0.0, sgn * size[1]]))
                    ent["spheres"].append({"pose": _pose(c, quat), "size": {"x": d, "y": d, "z": d}, "color": color})
        else:  # planes, meshes, height fields, SDFs: not drawn
            if not any(ent[k] for k in ("cubes", "spheres", "cylinders")):
                del entities[b]
            continue
    out = [entities[b] for b in sorted(entities)]
    if reference_path is not None:
        path = np.asarray(reference_path, float).reshape(-1, 2)
        path = path[np.all(np.isfinite(path), axis=1)]
        if len(path) >= 2:
            if len(path) > 20000:  # keep the scene message small
                path = path[np.linspace(0, len(path) - 1, 20000).round().astype(int)]
            ent = entity("world", "reference_path")
            ent["frame_locked"] = False
            ent["lines"].append(
                {
                    "type": 0,
                    "pose": _pose([0, 0, 0], [1, 0, 0, 0]),
                    "thickness": 3.0,
                    "scale_invariant": True,
                    "points": [{"x": float(x), "y": float(y), "z": 0.002} for x, y in path],
                    "color": {"r": 0.9, "g": 0.2, "b": 0.1, "a": 1.0},
                    "colors": [],
                    "indices": [],
                }
            )
            out.append(ent)
    return {"deletions": [], "entities": out}


# --------------------------------------------------------------------------- signals


@contextlib.contextmanager
def terminate_as_interrupt() -> Iterator[None]:
    """While active, SIGTERM raises KeyboardInterrupt (so a run is closed as "interrupted").

    A no-op outside the main thread, where Python cannot install signal handlers.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def _handler(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt(f"signal {signum} (SIGTERM)")

    previous = signal.signal(signal.SIGTERM, _handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextlib.contextmanager
def _signals_deferred() -> Iterator[None]:
    """Hold SIGINT/SIGTERM while a block is written, so that a chunk is never half written."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "pthread_sigmask"):
        yield
        return
    sigs = {signal.SIGINT, signal.SIGTERM}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, sigs)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


# --------------------------------------------------------------------------- writer


def _fixed_dtype(payload: np.dtype | int) -> np.dtype:
    """Packed dtype of one MCAP Message record with a fixed-size payload."""
    pl = ("payload", payload) if isinstance(payload, np.dtype) else ("payload", "u1", (int(payload),))
    return np.dtype(
        [("op", "u1"), ("len", "<u8"), ("channel", "<u2"), ("sequence", "<u4"), ("log_time", "<u8"), ("publish_time", "<u8"), pl]
    )


class RunLogger:
    """Write one run to an MCAP file (see the module docstring for channels and usage).

    Parameters follow the runner contract; ``model`` (a compiled MjModel of
    ``mjcf_xml``) may be passed to skip recompiling it, ``compression`` is "zstd"
    (default; falls back to lz4, then none), and ``fsync`` makes every flush
    durable against power loss, not just against the process being killed.
    """

    def __init__(
        self,
        path: str | os.PathLike,
        *,
        mjcf_xml: str,
        config: dict,
        parameters: dict,
        initial_state: np.ndarray,
        timestep: float,
        control_substeps: int,
        reference_path: np.ndarray | None = None,
        log_every: int = 1,
        flush_period_s: float = 1.0,
        model: Any = None,
        compression: str = "zstd",
        fsync: bool = False,
    ):
        import mujoco

        if int(log_every) < 1:
            raise ValueError(f"log_every must be an integer >= 1, got {log_every!r}")
        if int(control_substeps) < 1:
            raise ValueError(f"control_substeps must be an integer >= 1, got {control_substeps!r}")
        self.path = Path(path)
        self.timestep = float(timestep)
        self.control_substeps = int(control_substeps)
        self.log_every = int(log_every)
        self.flush_period_s = float(flush_period_s)
        self.dt_row = self.timestep * self.control_substeps
        self._fsync = bool(fsync)
        self._model = model if model is not None else mujoco.MjModel.from_xml_string(mjcf_xml)
        m = self._model
        self.nq, self.nv, self.nu = int(m.nq), int(m.nv), int(m.nu)
        self._comp = _Compressor(compression)
        self._closed = False
        self._rows = 0
        self._pending: list[dict[str, np.ndarray]] = []
        self._pending_rows = 0
        self._offset = 0
        self._dirty_from: int | None = None
        self._data_crc = 0
        self._schemas: list[bytes] = []
        self._channels: list[bytes] = []
        self._chunk_indexes: list[bytes] = []
        self._attachment_indexes: list[bytes] = []
        self._metadata_indexes: list[bytes] = []
        self._msg_counts: dict[int, int] = {}
        self._t_min: int | None = None
        self._t_max = 0
        self._n_metadata = self._n_attachments = self._n_chunks = 0
        self._last_t = 0.0

        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._f = open(self.path, "wb")
        try:
            self._start(mjcf_xml, config, parameters, initial_state, reference_path)
        except BaseException:
            self._f.close()
            raise

    # ---- low level
    def _write(self, data: bytes, *, flush: bool = True) -> None:
        self._dirty_from = self._offset
        self._f.write(data)
        if flush:
            self._f.flush()
            if self._fsync:
                os.fsync(self._f.fileno())
        self._data_crc = zlib.crc32(data, self._data_crc)
        self._offset += len(data)
        self._dirty_from = None

    def _add_schema(self, name: str, encoding: str, data: bytes) -> int:
        sid = len(self._schemas) + 1
        self._schemas.append(_rec(OP_SCHEMA, struct.pack("<H", sid) + _s(name) + _s(encoding) + struct.pack("<I", len(data)) + data))
        return sid

    def _add_channel(self, topic: str, encoding: str, schema_id: int, meta: Mapping[str, str]) -> int:
        cid = len(self._channels) + 1
        self._channels.append(_rec(OP_CHANNEL, struct.pack("<HH", cid, schema_id) + _s(topic) + _s(encoding) + _m(meta)))
        self._msg_counts[cid] = 0
        return cid

    def _metadata(self, name: str, data: Mapping[str, str]) -> bytes:
        rec = _rec(OP_METADATA, _s(name) + _m(data))
        self._metadata_indexes.append(_rec(OP_METADATA_INDEX, struct.pack("<QQ", self._offset_pending, len(rec)) + _s(name)))
        self._offset_pending += len(rec)
        self._n_metadata += 1
        return rec

    def _attachment(self, name: str, media_type: str, data: bytes) -> bytes:
        create = time.time_ns()
        body = struct.pack("<QQ", 0, create) + _s(name) + _s(media_type) + struct.pack("<Q", len(data)) + data
        rec = _rec(OP_ATTACHMENT, body + struct.pack("<I", zlib.crc32(body)))
        self._attachment_indexes.append(
            _rec(OP_ATTACHMENT_INDEX, struct.pack("<QQQQQ", self._offset_pending, len(rec), 0, create, len(data)) + _s(name) + _s(media_type))
        )
        self._offset_pending += len(rec)
        self._n_attachments += 1
        return rec

    def _chunk(self, cid: int, records: bytes, log_times: np.ndarray, offsets: np.ndarray) -> bytes:
        """A Chunk record holding ``records`` (messages of channel ``cid``) + its MessageIndex."""
        t0, t1 = int(log_times.min()), int(log_times.max())
        comp = self._comp(records)
        body = struct.pack("<QQQI", t0, t1, len(records), zlib.crc32(records)) + _s(self._comp.name) + struct.pack("<Q", len(comp))
        chunk = struct.pack("<BQ", OP_CHUNK, len(body) + len(comp)) + body + comp
        pairs = np.empty((len(log_times), 2), "<u8")
        pairs[:, 0] = log_times
        pairs[:, 1] = offsets
        pb = pairs.tobytes()
        index = _rec(OP_MESSAGE_INDEX, struct.pack("<HI", cid, len(pb)) + pb)
        start = self._offset_pending
        self._offset_pending += len(chunk) + len(index)
        self._chunk_indexes.append(
            _rec(
                OP_CHUNK_INDEX,
                struct.pack("<QQQQ", t0, t1, start, len(chunk))
                + struct.pack("<I", 10)
                + struct.pack("<HQ", cid, start + len(chunk))
                + struct.pack("<Q", len(index))
                + _s(self._comp.name)
                + struct.pack("<QQ", len(comp), len(records)),
            )
        )
        self._n_chunks += 1
        self._msg_counts[cid] += len(log_times)
        self._t_min = t0 if self._t_min is None else min(self._t_min, t0)
        self._t_max = max(self._t_max, t1)
        return chunk + index

    def _fixed_chunks(self, cid: int, seq: np.ndarray, log_time: np.ndarray, payload: np.ndarray) -> list[bytes]:
        """Chunks of fixed-size messages; ``payload`` is a structured (N,) or (N, L) uint8 array."""
        n = len(log_time)
        if n == 0:
            return []
        pdt = payload.dtype if payload.dtype.names else int(payload.shape[1])
        dt = _fixed_dtype(pdt)
        rec = np.empty(n, dt)
        rec["op"] = OP_MESSAGE
        rec["len"] = dt.itemsize - 9
        rec["channel"] = cid
        rec["sequence"] = seq
        rec["log_time"] = log_time
        rec["publish_time"] = log_time
        rec["payload"] = payload
        per = max(1, MAX_CHUNK_BYTES // dt.itemsize)
        out = []
        for a in range(0, n, per):
            part = rec[a : a + per]
            out.append(self._chunk(cid, part.tobytes(), part["log_time"], np.arange(len(part), dtype=np.uint64) * dt.itemsize))
        return out

    # ---- start
    def _start(self, mjcf_xml: str, config: dict, parameters: dict, initial_state: np.ndarray, reference_path: Any) -> None:
        import mujoco

        sizes = {"nq": self.nq, "nv": self.nv, "nu": self.nu}
        self._sig: dict[str, tuple[int, np.dtype, list[tuple[str, int]]]] = {}
        for topic in SIGNAL_TOPICS + (STATE_TOPIC,):
            name, text, fields = _ros2msg(topic, sizes)
            sid = self._add_schema(name, "ros2msg", text.encode())
            units = {f["name"]: f.get("unit", "") for f in channel_layouts()["channels"][topic]["fields"]}
            cid = self._add_channel(topic, "cdr", sid, {"units": json.dumps(units)})
            dt = np.dtype([("cdr", "u1", (4,))] + [(f, "<f8") if k == 1 else (f, "<f8", (k,)) for f, k in fields])
            self._sig[topic] = (cid, dt, fields)
        tf_sid = self._add_schema("foxglove.FrameTransforms", "jsonschema", _schema_text("foxglove.FrameTransforms.json").encode())
        self._tf_cid = self._add_channel(TF_TOPIC, "json", tf_sid, {})
        sc_sid = self._add_schema("foxglove.SceneUpdate", "jsonschema", _schema_text("foxglove.SceneUpdate.json").encode())
        self._scene_cid = self._add_channel(SCENE_TOPIC, "json", sc_sid, {})

        self._tree = FrameTree(self._model)
        self._tf = _TfEncoder(self._tree, self._model)

        init = np.ascontiguousarray(np.asarray(initial_state, dtype=np.float64).ravel())
        expected = mujoco.mj_stateSize(self._model, mujoco.mjtState.mjSTATE_INTEGRATION)
        if init.size != expected:
            raise ValueError(f"initial_state has {init.size} values; mjSTATE_INTEGRATION of this model has {expected}")
        seed = config.get("seed") if isinstance(config, Mapping) else None
        head = MCAP_MAGIC + _rec(OP_HEADER, _s("") + _s(f"wmr-mj/{software_versions()['wmr_mj']} numpy bulk writer"))
        self._offset_pending = len(head)
        parts = [head]
        # schemas and channels in the data section, so that a truncated file still declares them
        for r in self._schemas + self._channels:
            parts.append(r)
            self._offset_pending += len(r)
        info = {
            "schema_version": SCHEMA_VERSION,
            "format": "wmr-mj run log",
            "timestep": repr(self.timestep),
            "control_substeps": str(self.control_substeps),
            "log_every": str(self.log_every),
            "nq": str(self.nq),
            "nv": str(self.nv),
            "nu": str(self.nu),
            "seed": _dumps(seed),
            "compression": self._comp.name or "none",
            "created_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        }
        parts.append(self._metadata("wmr_mj", info))
        parts.append(self._metadata("versions", software_versions()))
        cfg = config if isinstance(config, Mapping) else {"config": config}
        parts.append(self._metadata("config", {str(k): _dumps(v) for k, v in cfg.items()}))
        parts.append(self._attachment("c80.xml", "application/xml", mjcf_xml.encode("utf-8")))
        parts.append(self._attachment("parameters.json", "application/json", json.dumps(json_safe(parameters), indent=2, allow_nan=False).encode()))
        buf = io.BytesIO()
        np.save(buf, init, allow_pickle=False)
        parts.append(self._attachment("initial_state.npy", "application/x-npy", buf.getvalue()))
        if reference_path is not None:
            buf = io.BytesIO()
            np.save(buf, np.asarray(reference_path, dtype=np.float64), allow_pickle=False)
            parts.append(self._attachment("reference_path.npy", "application/x-npy", buf.getvalue()))
        scene_obj = scene_update(self._model, self._tree.names, reference_path)
        try:  # built from finite floats: no need for the slower json_safe walk
            scene = json.dumps(scene_obj, allow_nan=False, separators=(",", ":")).encode()
        except (TypeError, ValueError):
            scene = _dumps(scene_obj).encode()
        msg = _rec(OP_MESSAGE, struct.pack("<HIQQ", self._scene_cid, 0, 0, 0) + scene)
        parts.append(self._chunk(self._scene_cid, msg, np.zeros(1, np.uint64), np.zeros(1, np.uint64)))
        self._write(b"".join(parts))

    # ---- blocks
    def write_block(self, block: Mapping[str, np.ndarray]) -> None:
        """Append N rows (see the runner contract); written and flushed once at least
        ``flush_period_s`` of simulated time is pending (every block when the runner
        hands one per simulated second)."""
        if self._closed:
            raise RuntimeError(f"{self.path}: write_block after close")
        missing = [k for k in BLOCK_KEYS if k not in block]
        if missing:
            raise ValueError(f"block lacks {', '.join(missing)}")
        t = np.asarray(block["t"], np.float64).ravel()
        n = t.size
        if n == 0:
            return
        shapes = {"A_pos": (n, 2), "C_pos": (n, 2), "qpos": (n, self.nq), "qvel": (n, self.nv), "ctrl": (n, self.nu)}
        clean: dict[str, np.ndarray] = {}
        for k in BLOCK_KEYS:
            a = np.asarray(block[k], np.float64)
            want = shapes.get(k, (n,))
            if a.shape != want:
                if a.size == int(np.prod(want)):
                    a = a.reshape(want)
                else:
                    raise ValueError(f"block[{k!r}] has shape {a.shape}, expected {want}")
            clean[k] = a
        self._pending.append(clean)
        self._pending_rows += n
        if self._pending_rows * self.dt_row >= self.flush_period_s - 0.5 * self.dt_row:
            self.flush()

    def flush(self) -> None:
        """Encode the pending rows as complete chunks, write and flush them to the file."""
        if not self._pending:
            return
        blocks, self._pending, self._pending_rows = self._pending, [], 0
        snap = self._snapshot()
        written = False
        try:
            b = blocks[0] if len(blocks) == 1 else {k: np.concatenate([x[k] for x in blocks]) for k in BLOCK_KEYS}
            data = self._encode(b)
            with _signals_deferred():  # a signal held here is raised on leaving, after the write
                self._write(data)
                self._rows += len(b["t"])
                written = True
        except BaseException:
            if not written:  # keep the index consistent with the file; close() retries the rows
                self._restore(snap)
                self._pending = blocks + self._pending
                self._pending_rows = sum(len(x["t"]) for x in self._pending)
            raise

    def _snapshot(self) -> tuple:
        return (len(self._chunk_indexes), dict(self._msg_counts), self._t_min, self._t_max, self._n_chunks, self._last_t)

    def _restore(self, snap: tuple) -> None:
        n, counts, self._t_min, self._t_max, self._n_chunks, self._last_t = snap
        del self._chunk_indexes[n:]
        self._msg_counts = counts

    def _encode(self, b: Mapping[str, np.ndarray]) -> bytes:
        self._offset_pending = self._offset
        t = b["t"]
        n = t.size
        k0 = self._rows
        rows = np.arange(k0, k0 + n, dtype=np.int64)
        fallback = rows * self.dt_row
        tt = np.where(np.isfinite(t), t, fallback)
        lt = np.rint(np.clip(tt, 0.0, 1.8e10) * 1e9).astype(np.uint64)
        seq = (rows % (1 << 32)).astype(np.uint32)
        parts: list[bytes] = []
        # /sim/state: every row
        cid, dt, _ = self._sig[STATE_TOPIC]
        p = np.zeros(n, dt)
        p["cdr"] = np.frombuffer(CDR_LE_HEADER, np.uint8)
        p["t"], p["qpos"], p["qvel"], p["ctrl"] = t, b["qpos"], b["qvel"], b["ctrl"]
        parts += self._fixed_chunks(cid, seq, lt, p)
        sel = np.flatnonzero(rows % self.log_every == 0) if self.log_every > 1 else slice(None)
        lts, seqs = lt[sel], seq[sel]
        m = len(lts)
        for topic in SIGNAL_TOPICS:
            cid, dt, fields = self._sig[topic]
            p = np.zeros(m, dt)
            p["cdr"] = np.frombuffer(CDR_LE_HEADER, np.uint8)
            for f in channel_layouts()["channels"][topic]["fields"]:
                src = b[f["block"]]
                p[f["name"]] = src[sel, f["index"]] if "index" in f else src[sel]
            parts += self._fixed_chunks(cid, seqs, lts, p)
        keep, payload = self._tf.encode(lts, b["qpos"][sel])
        if keep.size:
            parts += self._fixed_chunks(self._tf_cid, seqs[keep], lts[keep], payload)
        self._last_t = float(tt[-1])
        return b"".join(parts)

    # ---- close
    def close(self, summary: Mapping[str, Any] | None = None, *, status: str = "completed") -> None:
        """Flush, write the summary metadata record, the index and the footer; close the file."""
        if self._closed:
            return
        if status not in STATUSES:
            raise ValueError(f"status {status!r} is not one of {', '.join(STATUSES)}")
        self._closed = True
        try:
            with _signals_deferred():
                if self._dirty_from is not None:  # a write was cut short: drop its partial bytes
                    self._f.seek(self._dirty_from)
                    self._f.truncate()
                    self._offset = self._dirty_from
                    self._dirty_from = None
                if self._pending:
                    blocks, self._pending, self._pending_rows = self._pending, [], 0
                    snap = self._snapshot()
                    try:  # never lose the footer because of one bad block
                        b = blocks[0] if len(blocks) == 1 else {k: np.concatenate([x[k] for x in blocks]) for k in BLOCK_KEYS}
                        self._write(self._encode(b), flush=False)
                        self._rows += len(b["t"])
                    except Exception:
                        self._restore(snap)
                self._offset_pending = self._offset
                meta = {"status": _dumps(status), "rows": _dumps(self._rows), "last_t": _dumps(self._last_t)}
                for k, v in (summary or {}).items():
                    if str(k) not in meta:
                        meta[str(k)] = _dumps(v)
                self._write(self._metadata("summary", meta), flush=False)
                self._write(_rec(OP_DATA_END, struct.pack("<I", self._data_crc)), flush=False)
                self._f.write(self._summary_section())
                self._f.flush()
                if self._fsync:
                    os.fsync(self._f.fileno())
        finally:
            self._f.close()

    def _summary_section(self) -> bytes:
        start = self._offset
        groups: list[tuple[int, bytes]] = [
            (OP_SCHEMA, b"".join(self._schemas)),
            (OP_CHANNEL, b"".join(self._channels)),
        ]
        counts = b"".join(struct.pack("<HQ", cid, c) for cid, c in self._msg_counts.items())
        stats = struct.pack(
            "<QHIIIIQQ",
            sum(self._msg_counts.values()), len(self._schemas), len(self._channels), self._n_attachments,
            self._n_metadata, self._n_chunks, self._t_min or 0, self._t_max,
        ) + struct.pack("<I", len(counts)) + counts  # fmt: skip
        groups.append((OP_STATISTICS, _rec(OP_STATISTICS, stats)))
        groups.append((OP_CHUNK_INDEX, b"".join(self._chunk_indexes)))
        groups.append((OP_ATTACHMENT_INDEX, b"".join(self._attachment_indexes)))
        groups.append((OP_METADATA_INDEX, b"".join(self._metadata_indexes)))
        body = b""
        offsets = b""
        for op, data in groups:
            if data:
                offsets += _rec(OP_SUMMARY_OFFSET, struct.pack("<BQQ", op, start + len(body), len(data)))
                body += data
        offsets_start = start + len(body)
        summary = body + offsets
        footer_head = struct.pack("<BQQQ", OP_FOOTER, 20, start, offsets_start)
        crc = zlib.crc32(footer_head, zlib.crc32(summary))
        return summary + footer_head + struct.pack("<I", crc) + MCAP_MAGIC

    @property
    def rows(self) -> int:
        """Rows written so far (flushed or pending)."""
        return self._rows + self._pending_rows

    def __enter__(self) -> RunLogger:
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        if self._closed:
            return
        if exc_type is None:
            self.close({}, status="completed")
        elif issubclass(exc_type, (KeyboardInterrupt, SystemExit)):
            self.close({"reason": str(exc) or exc_type.__name__}, status="interrupted")
        else:
            self.close({"reason": f"{exc_type.__name__}: {exc}"}, status="error")


# --------------------------------------------------------------------------- bench helper


def measure_logging_overhead(run: Any, log_path: str | os.PathLike, *, repeats: int = 3) -> dict[str, float]:
    """Time ``run(None)`` (no log) against ``run(log_path)`` (logged), median of ``repeats``.

    ``run`` is the runner's entry point taking the log path or None; returns
    {"unlogged_s", "logged_s", "ratio"}. Used by bench/bench_logging.py.
    """
    import statistics

    def timed(arg: Any) -> float:
        t0 = time.perf_counter()
        run(arg)
        return time.perf_counter() - t0

    unlogged = statistics.median(timed(None) for _ in range(repeats))
    logged = statistics.median(timed(log_path) for _ in range(repeats))
    return {"unlogged_s": unlogged, "logged_s": logged, "ratio": logged / unlogged}


if __name__ == "__main__":  # pragma: no cover
    sys.exit("wmr_mj.mcaplog is a library; see `wmr-mj run` and `wmr-mj replay`")
