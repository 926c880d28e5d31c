"""Read wmr-mj run logs (MCAP) into NumPy arrays.

::

    from wmr_mj.logs import load_log
    log = load_log("logs/run.mcap")
    s = log.signals                      # t, alpha, E, E_dot, voltage, A_pos (N,2), ...
    st = log.state                       # t, qpos (N,nq), qvel (N,nv), ctrl (N,nu): every row
    steer = log.channel("/steering")     # one channel's fields (+ "log_time" in ns)
    log.config, log.summary, log.metadata, log.attachments, log.mjcf_xml, log.initial_state
    log.truncated                        # True when the run was killed before the footer

Fixed-layout channels (CDR, flat float64 fields) are decoded in bulk: the
payloads of each chunk are viewed with a structured dtype built from the
ros2msg schema text stored in the file, then concatenated. JSON channels
(``/tf``, ``/scene``) are parsed on demand by :meth:`RunLog.messages`.

Every problem a user can cause (missing file, not MCAP, a corrupt chunk, an
unknown schema version) raises :class:`wmr_mj.errors.LogError` with one line
naming the file. A file that ends early (abrupt kill, copy cut short) is read up
to its last complete chunk and flagged ``truncated``.
"""

from __future__ import annotations

import io
import json
import re
import struct
import zlib
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from .errors import LogError

__all__ = ["RunLog", "load_log", "SUPPORTED_SCHEMA_VERSIONS"]

SUPPORTED_SCHEMA_VERSIONS = ("1",)
MCAP_MAGIC = b"\x89MCAP0\r\n"
ACCEPTED = "wmr-mj replay accepts MCAP run logs written by `wmr-mj run`"

_PRIMS = {
    "float64": "<f8", "float32": "<f4", "int8": "i1", "uint8": "u1", "int16": "<i2", "uint16": "<u2",
    "int32": "<i4", "uint32": "<u4", "int64": "<i8", "uint64": "<u8", "bool": "u1", "byte": "u1", "char": "u1",
}  # fmt: skip

class _Truncated(Exception):
    pass


def _ros2msg_dtype(text: str) -> np.dtype | None:
    """Structured dtype (4-byte CDR header + fields) of a flat ros2msg schema, or None
    when the schema has nested types or variable-length fields (not fixed layout)."""
    fields: list[tuple] = [("__cdr", "u1", (4,))]
    offset = 0
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        if line.startswith("==="):
            break  # nested definitions follow: not a flat message
        m = re.fullmatch(r"(\w+)(?:\[(\d+)\])?\s+(\w+)(\s*=.*)?", line)
        if not m or m.group(1) not in _PRIMS:
            return None
        if m.group(4):  # constant
            continue
        code = _PRIMS[m.group(1)]
        size = np.dtype(code).itemsize
        pad = (-offset) % size  # CDR aligns each primitive to its size, relative to the payload
        if pad:
            fields.append((f"__pad{offset}", "u1", (pad,)))
            offset += pad
        count = int(m.group(2)) if m.group(2) else 1
        fields.append((m.group(3), code, (count,)) if m.group(2) else (m.group(3), code))
        offset += size * count
    return np.dtype(fields)


@dataclass
class _Channel:
    id: int
    topic: str
    encoding: str
    schema_name: str
    schema_encoding: str
    schema_data: bytes
    metadata: dict[str, str]
    log_times: list[np.ndarray] = field(default_factory=list)
    payloads: list[np.ndarray] = field(default_factory=list)  # (n, L) uint8 blocks
    loose: list[tuple[int, bytes]] = field(default_factory=list)  # variable-size messages


class RunLog:
    """A loaded run log; see the module docstring."""

    def __init__(self, path: Path):
        self.path = path
        self.metadata: dict[str, dict[str, str]] = {}
        self.attachments: dict[str, bytes] = {}
        self.attachment_types: dict[str, str] = {}
        self.truncated = False
        self.truncated_reason = ""
        self._channels: dict[int, _Channel] = {}
        self._by_topic: dict[str, _Channel] = {}
        self._decoded: dict[str, dict[str, np.ndarray]] = {}

    # ---- metadata
    def _json_record(self, name: str) -> dict[str, Any] | None:
        rec = self.metadata.get(name)
        if rec is None:
            return None
        out: dict[str, Any] = {}
        for k, v in rec.items():
            try:
                out[k] = json.loads(v)
            except ValueError:
                out[k] = v
        return out

    @cached_property
    def info(self) -> dict[str, str]:
        """The "wmr_mj" metadata record (schema_version, timestep, ...), as stored."""
        return dict(self.metadata.get("wmr_mj", {}))

    @cached_property
    def config(self) -> dict[str, Any]:
        return self._json_record("config") or {}

    @cached_property
    def summary(self) -> dict[str, Any] | None:
        """The summary written at close (with "status"), or None for a truncated log."""
        return self._json_record("summary")

    @property
    def status(self) -> str:
        if self.summary is not None and "status" in self.summary:
            return str(self.summary["status"])
        return "truncated" if self.truncated else "unknown"

    @cached_property
    def versions(self) -> dict[str, str]:
        return dict(self.metadata.get("versions", {}))

    @property
    def seed(self) -> Any:
        try:
            return json.loads(self.info.get("seed", "null"))
        except ValueError:
            return self.info.get("seed")

    @property
    def timestep(self) -> float:
        return float(self.info.get("timestep", "nan"))

    @property
    def control_substeps(self) -> int:
        return int(self.info.get("control_substeps", "1"))

    @property
    def log_every(self) -> int:
        return int(self.info.get("log_every", "1"))

    def _attachment_named(self, suffix: str, kind: str) -> bytes:
        for name, data in self.attachments.items():
            if name.endswith(suffix):
                return data
        raise LogError(f"{self.path}: the log has no {kind} attachment ({suffix}); it was cut before it was written")

    @property
    def mjcf_xml(self) -> str:
        """The exact MJCF the run simulated."""
        return self._attachment_named(".xml", "MJCF").decode("utf-8")

    @property
    def parameters(self) -> dict[str, Any]:
        return json.loads(self._attachment_named("parameters.json", "parameter set"))

    @property
    def initial_state(self) -> np.ndarray:
        """mjSTATE_INTEGRATION state at t = 0."""
        return np.load(io.BytesIO(self._attachment_named("initial_state.npy", "initial state")), allow_pickle=False)

    @property
    def reference_path(self) -> np.ndarray | None:
        data = self.attachments.get("reference_path.npy")
        return None if data is None else np.load(io.BytesIO(data), allow_pickle=False)

    # ---- channels
    @property
    def topics(self) -> list[str]:
        return list(self._by_topic)

    def message_count(self, topic: str) -> int:
        ch = self._get(topic)
        return sum(len(x) for x in ch.log_times) + len(ch.loose)

    def _get(self, topic: str) -> _Channel:
        ch = self._by_topic.get(topic)
        if ch is None:
            from .errors import UnknownNameError

            raise UnknownNameError("channel", topic, self._by_topic)
        return ch

    def channel(self, topic: str) -> dict[str, np.ndarray]:
        """Fields of a fixed-layout channel as arrays (one row per message), plus "log_time" [ns]."""
        if topic in self._decoded:
            return self._decoded[topic]
        ch = self._get(topic)
        if ch.encoding != "cdr" or ch.schema_encoding != "ros2msg":
            raise LogError(f"{self.path}: channel {topic} is {ch.encoding}, not a fixed-layout cdr channel; use messages()")
        dt = _ros2msg_dtype(ch.schema_data.decode("utf-8", "replace"))
        if dt is None:
            raise LogError(f"{self.path}: channel {topic} has a schema that is not a flat ros2msg message")
        blocks = list(ch.payloads)
        times = list(ch.log_times)
        if ch.loose:
            times.append(np.array([t for t, _ in ch.loose], np.uint64))
            sizes = {len(p) for _, p in ch.loose}
            if sizes != {dt.itemsize}:
                raise LogError(f"{self.path}: messages of {topic} do not match their schema ({sorted(sizes)} bytes, expected {dt.itemsize})")
            blocks.append(np.frombuffer(b"".join(p for _, p in ch.loose), np.uint8).reshape(-1, dt.itemsize))
        for blk in blocks:
            if blk.shape[1] != dt.itemsize:
                raise LogError(f"{self.path}: messages of {topic} are {blk.shape[1]} bytes, their schema needs {dt.itemsize}")
        raw = np.concatenate(blocks) if len(blocks) > 1 else (blocks[0] if blocks else np.empty((0, dt.itemsize), np.uint8))
        arr = np.frombuffer(np.ascontiguousarray(raw).data, dtype=dt) if raw.size else np.empty(0, dt)
        out: dict[str, np.ndarray] = {"log_time": np.concatenate(times) if times else np.empty(0, np.uint64)}
        for name in dt.names:
            if not name.startswith("__"):
                out[name] = np.ascontiguousarray(arr[name])
        order = np.argsort(out["log_time"], kind="stable")
        if order.size and np.any(order != np.arange(order.size)):
            out = {k: v[order] for k, v in out.items()}
        self._decoded[topic] = out
        return out

    def messages(self, topic: str) -> list[tuple[int, Any]]:
        """(log_time ns, decoded message) pairs of a JSON channel, in log-time order."""
        ch = self._get(topic)
        if ch.encoding != "json":
            raise LogError(f"{self.path}: channel {topic} is {ch.encoding}; use channel() for fixed-layout channels")
        out = []
        for times, blk in zip(ch.log_times, ch.payloads):
            for t, row in zip(times.tolist(), blk):
                out.append((t, json.loads(row.tobytes())))
        out += [(t, json.loads(p)) for t, p in ch.loose]
        out.sort(key=lambda x: x[0])
        return out

    def raw_messages(self, topic: str) -> list[tuple[int, bytes]]:
        """(log_time ns, payload bytes) pairs of any channel."""
        ch = self._get(topic)
        out = [(t, row.tobytes()) for times, blk in zip(ch.log_times, ch.payloads) for t, row in zip(times.tolist(), blk)]
        out += list(ch.loose)
        out.sort(key=lambda x: x[0])
        return out

    @cached_property
    def signals(self) -> dict[str, np.ndarray]:
        """The runner's block keys (every log_every-th row): t, alpha, ..., A_pos (N,2), C_pos (N,2), heading."""
        from .mcaplog import SIGNAL_TOPICS, channel_layouts

        out: dict[str, np.ndarray] = {}
        pairs: dict[str, list[tuple[int, np.ndarray]]] = {}
        for topic in SIGNAL_TOPICS:
            if topic not in self._by_topic:
                continue
            ch = self.channel(topic)
            for f in channel_layouts()["channels"][topic]["fields"]:
                if f["name"] not in ch or (f["block"] in out and "index" not in f):
                    continue
                if "index" in f:
                    pairs.setdefault(f["block"], []).append((f["index"], ch[f["name"]]))
                else:
                    out[f["block"]] = ch[f["name"]]
        for key, cols in pairs.items():
            out[key] = np.column_stack([c for _, c in sorted(cols, key=lambda x: x[0])])
        return out

    @cached_property
    def state(self) -> dict[str, np.ndarray]:
        """/sim/state: t, qpos (N,nq), qvel (N,nv), ctrl (N,nu) at every control step."""
        if "/sim/state" not in self._by_topic:
            return {}
        ch = self.channel("/sim/state")
        return {k: ch[k] for k in ("t", "qpos", "qvel", "ctrl") if k in ch}

    @property
    def rows(self) -> int:
        """Number of control steps logged (rows of /sim/state)."""
        return self.message_count("/sim/state") if "/sim/state" in self._by_topic else 0

    def __repr__(self) -> str:
        return f"RunLog({str(self.path)!r}, rows={self.rows}, status={self.status!r}, truncated={self.truncated})"


# --------------------------------------------------------------------------- parsing


def _str(buf: memoryview, pos: int, end: int) -> tuple[str, int]:
    if pos + 4 > end:
        raise _Truncated
    (n,) = struct.unpack_from("<I", buf, pos)
    pos += 4
    if pos + n > end:
        raise _Truncated
    return bytes(buf[pos : pos + n]).decode("utf-8"), pos + n


def _map(buf: memoryview, pos: int, end: int) -> tuple[dict[str, str], int]:
    if pos + 4 > end:
        raise _Truncated
    (n,) = struct.unpack_from("<I", buf, pos)
    pos += 4
    stop = pos + n
    if stop > end:
        raise _Truncated
    out = {}
    while pos < stop:
        k, pos = _str(buf, pos, stop)
        v, pos = _str(buf, pos, stop)
        out[k] = v
    return out, stop


class _Parser:
    def __init__(self, path: Path, log: RunLog):
        self.path = path
        self.log = log
        self.schemas: dict[int, tuple[str, str, bytes]] = {}

    def fail(self, what: str) -> LogError:
        return LogError(f"{self.path}: {what}; {ACCEPTED}")

    # records valid at top level and inside chunks
    def schema(self, buf: memoryview, p: int, end: int) -> None:
        (sid,) = struct.unpack_from("<H", buf, p)
        name, p = _str(buf, p + 2, end)
        enc, p = _str(buf, p, end)
        (n,) = struct.unpack_from("<I", buf, p)
        self.schemas[sid] = (name, enc, bytes(buf[p + 4 : p + 4 + n]))

    def channel(self, buf: memoryview, p: int, end: int) -> None:
        cid, sid = struct.unpack_from("<HH", buf, p)
        topic, p = _str(buf, p + 4, end)
        enc, p = _str(buf, p, end)
        meta, p = _map(buf, p, end)
        if cid in self.log._channels:
            return
        sname, senc, sdata = self.schemas.get(sid, ("", "", b""))
        ch = _Channel(cid, topic, enc, sname, senc, sdata, meta)
        self.log._channels[cid] = ch
        self.log._by_topic.setdefault(topic, ch)

    def message(self, buf: memoryview, p: int, end: int) -> None:
        cid, _seq, log_time, _pub = struct.unpack_from("<HIQQ", buf, p)
        ch = self.log._channels.get(cid)
        if ch is None:
            raise self.fail(f"message on undeclared channel {cid}")
        ch.loose.append((log_time, bytes(buf[p + 22 : end])))

    def chunk_records(self, data: bytes, where: int) -> None:
        """Records of one decompressed chunk; fixed-size runs of one channel in bulk."""
        n = len(data)
        if n >= 9 and data[0] == 0x05:
            (length,) = struct.unpack_from("<Q", data, 1)
            size = 9 + length
            if length >= 22 and n % size == 0:
                dt = np.dtype(
                    [("op", "u1"), ("len", "<u8"), ("channel", "<u2"), ("seq", "<u4"), ("log_time", "<u8"), ("pub", "<u8"), ("payload", "u1", (length - 22,))]
                )
                rec = np.frombuffer(data, dt)
                cid = int(rec["channel"][0])
                if np.all(rec["op"] == 5) and np.all(rec["len"] == length) and np.all(rec["channel"] == cid):
                    ch = self.log._channels.get(cid)
                    if ch is None:
                        raise self.fail(f"chunk at byte {where} holds messages of undeclared channel {cid}")
                    ch.log_times.append(rec["log_time"].copy())
                    ch.payloads.append(rec["payload"])
                    return
        buf = memoryview(data)
        p = 0
        while p < n:
            if p + 9 > n:
                raise self.fail(f"chunk at byte {where} is corrupt (record header cut at {p})")
            op, length = struct.unpack_from("<BQ", buf, p)
            body, end = p + 9, p + 9 + length
            if end > n:
                raise self.fail(f"chunk at byte {where} is corrupt (record runs past the chunk)")
            if op == 0x05:
                self.message(buf, body, end)
            elif op == 0x03:
                self.schema(buf, body, end)
            elif op == 0x04:
                self.channel(buf, body, end)
            p = end

    def decompress(self, comp: str, data: bytes, size: int, crc: int, where: int) -> bytes:
        try:
            if comp == "":
                out = bytes(data)
            elif comp == "zstd":
                import zstandard

                out = zstandard.ZstdDecompressor().decompress(bytes(data), max_output_size=size)
            elif comp == "lz4":
                import lz4.frame

                out = lz4.frame.decompress(bytes(data))
            else:
                raise self.fail(f"chunk at byte {where} uses unsupported compression {comp!r} (zstd, lz4 or none are read)")
        except LogError:
            raise
        except Exception as exc:
            raise self.fail(f"chunk at byte {where} is corrupt ({comp} decompression failed: {exc})") from None
        if len(out) != size:
            raise self.fail(f"chunk at byte {where} is corrupt (decompressed to {len(out)} bytes, expected {size})")
        if crc and zlib.crc32(out) != crc:
            raise self.fail(f"chunk at byte {where} is corrupt (CRC mismatch)")
        return out

    def parse(self, data: bytes) -> None:
        log = self.log
        if len(data) < 8 or data[:8] != MCAP_MAGIC:
            if len(data) < 8 and MCAP_MAGIC.startswith(data):
                raise self.fail("the file is empty or cut inside the MCAP magic")
            raise self.fail("not an MCAP file (bad magic bytes)")
        buf = memoryview(data)
        total = len(data)
        finished = total >= 16 and data[-8:] == MCAP_MAGIC
        p = 8
        data_end = False
        while True:
            if p == total:
                break
            if p + 9 > total:
                raise _Truncated(f"record header cut at byte {p}")
            op, length = struct.unpack_from("<BQ", buf, p)
            body, end = p + 9, p + 9 + length
            if end > total:
                raise _Truncated(f"record at byte {p} runs past the end of the file")
            try:
                if op == 0x06:  # chunk
                    t0, t1, usize, ucrc = struct.unpack_from("<QQQI", buf, body)
                    comp, q = _str(buf, body + 28, end)
                    (clen,) = struct.unpack_from("<Q", buf, q)
                    if q + 8 + clen != end:
                        raise self.fail(f"chunk at byte {p} is corrupt (inconsistent lengths)")
                    self.chunk_records(self.decompress(comp, buf[q + 8 : end], usize, ucrc, p), p)
                elif op == 0x05:
                    self.message(buf, body, end)
                elif op == 0x03:
                    self.schema(buf, body, end)
                elif op == 0x04:
                    self.channel(buf, body, end)
                elif op == 0x0C:  # metadata
                    name, q = _str(buf, body, end)
                    meta, q = _map(buf, q, end)
                    log.metadata[name] = meta
                elif op == 0x09:  # attachment
                    _lt, _ct = struct.unpack_from("<QQ", buf, body)
                    name, q = _str(buf, body + 16, end)
                    media, q = _str(buf, q, end)
                    (dlen,) = struct.unpack_from("<Q", buf, q)
                    payload = bytes(buf[q + 8 : q + 8 + dlen])
                    (crc,) = struct.unpack_from("<I", buf, q + 8 + dlen)
                    if crc and zlib.crc32(buf[body : q + 8 + dlen]) != crc:
                        raise self.fail(f"attachment {name!r} at byte {p} is corrupt (CRC mismatch)")
                    log.attachments[name] = payload
                    log.attachment_types[name] = media
                elif op == 0x0F:  # data end: the summary section follows
                    data_end = True
                    break
                elif op == 0x01 and p != 8:
                    raise self.fail(f"unexpected header record at byte {p}")
                elif op == 0x00 or (op > 0x0F and op < 0x80):
                    raise self.fail(f"invalid record opcode 0x{op:02x} at byte {p}")
            except (struct.error, UnicodeDecodeError, _Truncated):
                raise self.fail(f"record at byte {p} (opcode 0x{op:02x}) is corrupt") from None
            p = end
        if not data_end:
            raise _Truncated("no data-end record")
        if not finished:
            raise _Truncated("no footer")


def load_log(path: str | Path) -> RunLog:
    """Load a run log; raises LogError on a missing, non-MCAP, corrupt or unsupported file."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise LogError(f"{path}: no such file; {ACCEPTED}") from None
    except IsADirectoryError:
        raise LogError(f"{path}: is a directory; {ACCEPTED}") from None
    except OSError as exc:
        raise LogError(f"{path}: cannot be read ({exc.strerror}); {ACCEPTED}") from None
    log = RunLog(path)
    parser = _Parser(path, log)
    try:
        parser.parse(data)
    except _Truncated as exc:
        log.truncated = True
        log.truncated_reason = str(exc) or "the file ends early"
    except LogError:
        raise
    except Exception as exc:  # any other parse failure is corruption, reported in one line
        raise LogError(f"{path}: corrupt MCAP file ({type(exc).__name__}: {exc}); {ACCEPTED}") from None
    if data[-8:] == MCAP_MAGIC and log.truncated and len(data) > 16:
        # a finished file (footer magic present) that cannot be walked to its end is corrupt
        raise LogError(f"{path}: corrupt MCAP file ({log.truncated_reason} although the file has a footer); {ACCEPTED}")
    info = log.metadata.get("wmr_mj")
    if info is None:
        if log.truncated:
            raise LogError(f"{path}: the file was cut before its wmr_mj metadata record; nothing to read; {ACCEPTED}")
        raise LogError(f"{path}: MCAP file without a wmr_mj metadata record (not a wmr-mj run log); {ACCEPTED}")
    version = info.get("schema_version")
    if version not in SUPPORTED_SCHEMA_VERSIONS:
        raise LogError(
            f"{path}: unknown wmr-mj log schema version {version!r}; this wmr-mj reads schema version(s) "
            f"{', '.join(SUPPORTED_SCHEMA_VERSIONS)}"
        )
    # decode every fixed-layout channel now, so that a bad payload is reported here
    for topic, ch in log._by_topic.items():
        if ch.encoding == "cdr" and ch.schema_encoding == "ros2msg":
            log.channel(topic)
    return log
