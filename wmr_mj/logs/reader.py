"""Read wmr-mj run logs (MCAP) into NumPy arrays, with mcap's own readers.

::

    from wmr_mj.logs.reader import load_log
    log = load_log("logs/run.mcap")
    s = log.signals                      # t, alpha, E, E_dot, voltage, A_pos (N, 2), ... every logged row
    st = log.state                       # t, qpos (N, nq), qvel (N, nv), ctrl (N, nu): every control step
    ms = log.measured                    # a sensed run: t, alpha_measured, alpha_dot_measured (what the law
                                         # read) at every control step; None for an ideal run (log.sensed)
    steer = log.channel("/steering")     # one channel's fields as arrays (+ "log_time" [ns] for per-row channels)
    log.config, log.summary, log.metadata, log.attachments, log.mjcf_xml, log.initial_state
    log.truncated                        # True when the run was killed before the footer

A finished file is read through its index (``mcap.reader.make_reader``): the summary, the
metadata and attachments, and only the chunks of the channels asked for; every chunk's CRC is
checked once. A file without its footer (a killed run, a copy cut short) is read from the start
with ``mcap.stream_reader.StreamReader`` up to its last complete chunk and flagged ``truncated``.
The messages are decoded from the ros2msg schema text stored in the file
(:mod:`wmr_mj.logs.logformat`): the packed channels (/signals, /sim/state) a few messages a second,
the per-row channels in bulk with a structured dtype.

Every problem a user can cause (missing file, not MCAP, a corrupt chunk, an unknown schema
version) raises :class:`wmr_mj.errors.LogError` with one line naming the file.
"""

from __future__ import annotations

import io
import json
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from wmr_mj.errors import LogError, UnknownNameError
from wmr_mj.logs import logformat as lf

__all__ = ["RunLog", "load_log", "SUPPORTED_SCHEMA_VERSIONS"]

SUPPORTED_SCHEMA_VERSIONS = lf.SUPPORTED_SCHEMA_VERSIONS
ACCEPTED = "wmr-mj replay accepts MCAP run logs written by `wmr-mj run`"


@dataclass(frozen=True)
class _Channel:
    id: int
    topic: str
    encoding: str
    schema_name: str
    schema_encoding: str
    schema_text: str
    metadata: dict[str, str]


class _Truncated(Exception):
    pass


class RunLog:
    """A loaded run log; see the module docstring. Made by :func:`load_log`."""

    def __init__(self, path: Path):
        self.path = path
        self.metadata: dict[str, dict[str, str]] = {}
        self.attachments: dict[str, bytes] = {}
        self.attachment_types: dict[str, str] = {}
        self.truncated = False
        self.truncated_reason = ""
        self._channels: dict[str, _Channel] = {}
        self._messages: dict[str, list[tuple[int, bytes]]] = {}  # topic -> (log_time, payload), once read
        self._counts: dict[str, int] = {}
        self._indexed = False  # True: unread topics come from the file's index
        self._decoded: dict[str, dict[str, np.ndarray]] = {}

    def _fail(self, what: str) -> LogError:
        return LogError(f"{self.path}: {what}; {ACCEPTED}")

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
        """The summary written at close (with "status"), or None for a log cut before it."""
        return self._json_record("summary")

    @property
    def status(self) -> str:
        """"completed", "interrupted", "error", "failed" (from the summary), or "truncated"."""
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

    def _info_number(self, key: str, kind: type, default: str) -> Any:
        try:
            return kind(self.info.get(key, default))
        except ValueError:
            raise self._fail(f"the wmr_mj metadata record has {key} = {self.info.get(key)!r}") from None

    @property
    def timestep(self) -> float:
        return self._info_number("timestep", float, "nan")

    @property
    def control_substeps(self) -> int:
        return self._info_number("control_substeps", int, "1")

    @property
    def log_every(self) -> int:
        return self._info_number("log_every", int, "1")

    def _attachment_named(self, name: str, kind: str) -> bytes:
        data = self.attachments.get(name)
        if data is None:
            raise LogError(f"{self.path}: the log has no {kind} attachment ({name}); it was cut before it was written")
        return data

    @property
    def mjcf_xml(self) -> str:
        """The exact MJCF the run simulated."""
        return self._attachment_named("c80.xml", "MJCF").decode("utf-8")

    @property
    def parameters(self) -> dict[str, Any]:
        return json.loads(self._attachment_named("parameters.json", "parameter set"))

    @property
    def initial_state(self) -> np.ndarray:
        """mjSTATE_INTEGRATION state at t = 0."""
        return np.load(io.BytesIO(self._attachment_named("initial_state.npy", "initial state")), allow_pickle=False)

    @property
    def reference_path(self) -> np.ndarray | None:
        """Desired path of C, (M, 2) world xy, when the run had one."""
        data = self.attachments.get("reference_path.npy")
        return None if data is None else np.load(io.BytesIO(data), allow_pickle=False)

    # ---- channels
    @property
    def topics(self) -> list[str]:
        return list(self._channels)

    def _get(self, topic: str) -> _Channel:
        ch = self._channels.get(topic)
        if ch is None:
            raise UnknownNameError("channel", topic, self._channels)
        return ch

    def message_count(self, topic: str) -> int:
        self._get(topic)
        if topic in self._counts:
            return self._counts[topic]
        return len(self.raw_messages(topic))

    def raw_messages(self, topic: str) -> list[tuple[int, bytes]]:
        """(log_time ns, payload bytes) pairs of any channel, in log-time order."""
        self._get(topic)
        if topic not in self._messages:
            self._read_indexed([topic])
        return self._messages[topic]

    def _read_indexed(self, topics: list[str], *, validate_crcs: bool = False) -> None:
        """Messages of ``topics`` through the file's index (finished files)."""
        from mcap.reader import make_reader

        got: dict[str, list[tuple[int, bytes]]] = {t: [] for t in topics}
        if self._indexed:
            try:
                with open(self.path, "rb") as f:
                    for _, channel, message in make_reader(f, validate_crcs=validate_crcs).iter_messages(topics=topics):
                        got[channel.topic].append((message.log_time, message.data))
            except OSError as exc:
                raise LogError(f"{self.path}: cannot be read ({exc.strerror or exc}); {ACCEPTED}") from None
            except Exception as exc:  # the library's parse and CRC errors
                raise self._fail(f"corrupt MCAP file ({type(exc).__name__}: {exc})") from None
        self._messages.update(got)

    def channel(self, topic: str) -> dict[str, np.ndarray]:
        """A numbers-only CDR channel as arrays: one row per message plus "log_time" [ns] for
        per-row channels; the rows of all messages concatenated for packed channels (a field
        with k values per row is (rows, k))."""
        if topic in self._decoded:
            return self._decoded[topic]
        ch = self._get(topic)
        if ch.encoding != "cdr" or ch.schema_encoding != "ros2msg" or lf.parse_ros2msg(ch.schema_text) is None:
            raise LogError(f"{self.path}: channel {topic} ({ch.schema_name}, {ch.encoding}) is not a numbers-only "
                           "CDR channel; use messages() or raw_messages()")
        msgs = self.raw_messages(topic)
        dt = lf.row_dtype(ch.schema_text)
        if dt is not None:
            out = self._rows_in_bulk(topic, dt, msgs)
        else:
            out = self._packed(topic, ch, msgs)
        self._decoded[topic] = out
        return out

    def _rows_in_bulk(self, topic: str, dt: np.dtype, msgs: list[tuple[int, bytes]]) -> dict[str, np.ndarray]:
        sizes = {len(p) for _, p in msgs}
        if sizes - {dt.itemsize}:
            raise self._fail(f"messages of {topic} are {sorted(sizes)} bytes; their schema needs {dt.itemsize}")
        arr = np.frombuffer(b"".join(p for _, p in msgs), dt)
        out = {"log_time": np.fromiter((t for t, _ in msgs), np.uint64, len(msgs))}
        for name in dt.names or ():
            if not name.startswith("__"):
                out[name] = np.ascontiguousarray(arr[name])
        return out

    def _packed(self, topic: str, ch: _Channel, msgs: list[tuple[int, bytes]]) -> dict[str, np.ndarray]:
        fields = lf.parse_ros2msg(ch.schema_text) or ()
        seqs = [f.name for f in fields if f.length == -1]
        parts: dict[str, list[np.ndarray]] = {name: [] for name in seqs}
        for _, payload in msgs:
            try:
                msg = lf.decode_cdr(ch.schema_text, payload)
            except ValueError as exc:
                raise self._fail(f"a message of {topic} does not fit its schema ({exc})") from None
            rows = int(msg.get("rows", len(msg[seqs[0]]) if seqs else 0))
            for name in seqs:
                a = msg[name]
                if rows == 0 or a.size % rows:
                    raise self._fail(f"field {name} of {topic} has {a.size} values for {rows} rows")
                parts[name].append(a if a.size == rows else a.reshape(rows, -1))
        out = {}
        for name, blocks in parts.items():
            out[name] = np.concatenate(blocks) if blocks else np.empty(0)
        return out

    def messages(self, topic: str) -> list[tuple[int, Any]]:
        """(log_time ns, decoded message) pairs of a JSON channel or a numbers-only CDR channel
        (a dict per message). Other CDR channels (/tf): decode ``raw_messages`` with a ROS 2
        decoder such as mcap-ros2-support."""
        ch = self._get(topic)
        msgs = self.raw_messages(topic)
        if ch.encoding == "json":
            return [(t, json.loads(p)) for t, p in msgs]
        if ch.encoding == "cdr" and lf.parse_ros2msg(ch.schema_text) is not None:
            return [(t, {k: (v.copy() if isinstance(v, np.ndarray) else v)
                         for k, v in lf.decode_cdr(ch.schema_text, p).items()}) for t, p in msgs]
        raise LogError(f"{self.path}: channel {topic} ({ch.schema_name}) has strings or nested types; decode "
                       "raw_messages() with a ROS 2 decoder (e.g. mcap-ros2-support)")

    @cached_property
    def signals(self) -> dict[str, np.ndarray]:
        """The runner's block keys at every logged row: t, alpha, ..., E, E_dot, ..., A_pos (N, 2), C_pos (N, 2),
        heading."""
        fields = lf.channel_layouts()["channels"][lf.SIGNALS_TOPIC]["fields"]
        if lf.SIGNALS_TOPIC not in self._channels:  # a file cut before its first block
            return {f["block"]: np.empty((0, f["columns"]) if "columns" in f else 0) for f in fields}
        ch = self.channel(lf.SIGNALS_TOPIC)
        return {f["block"]: ch[f["name"]] for f in fields if f["name"] in ch}

    @cached_property
    def state(self) -> dict[str, np.ndarray]:
        """/sim/state: t, qpos (N, nq), qvel (N, nv), ctrl (N, nu) at every control step."""
        widths = {"qpos": "nq", "qvel": "nv", "ctrl": "nu"}
        if lf.STATE_TOPIC not in self._channels:  # a file cut before its first block
            return {"t": np.empty(0), **{k: np.empty((0, self._info_number(w, int, "0"))) for k, w in widths.items()}}
        ch = self.channel(lf.STATE_TOPIC)
        out = {k: ch[k] for k in ("t", *widths) if k in ch}
        for k, w in widths.items():  # a model with one coordinate, or no rows, still gets (N, n)
            if k in out and out[k].ndim == 1:
                out[k] = out[k].reshape(out["t"].size, self._info_number(w, int, "0"))
        return out

    @property
    def sensed(self) -> bool:
        """True for the log of a run with a sensor between the plant and the law (it has /measured)."""
        return lf.MEASURED_TOPIC in self._channels

    @cached_property
    def measured(self) -> dict[str, np.ndarray] | None:
        """/measured of a sensed run: t [s], alpha_measured [rad], alpha_dot_measured [rad/s], what the law read
        at every control step (whatever log_every), (N,) each, keyed as the runner's block; None for the log of
        an ideal run, where the law read the state that /signals holds."""
        if not self.sensed:
            return None
        fields = lf.channel_layouts()["channels"][lf.MEASURED_TOPIC]["fields"]
        ch = self.channel(lf.MEASURED_TOPIC)
        return {f["block"]: ch.get(f["name"], np.empty(0)) for f in fields}

    @property
    def rows(self) -> int:
        """Number of control steps logged (rows of /sim/state)."""
        return int(self.state["t"].size)

    def __repr__(self) -> str:
        return f"RunLog({str(self.path)!r}, rows={self.rows}, status={self.status!r}, truncated={self.truncated})"


# --------------------------------------------------------------------------- loading


def _channel_of(channel: Any, schemas: dict[int, Any]) -> _Channel:
    schema = schemas.get(channel.schema_id)
    return _Channel(
        id=channel.id, topic=channel.topic, encoding=channel.message_encoding,
        schema_name=schema.name if schema else "", schema_encoding=schema.encoding if schema else "",
        schema_text=bytes(schema.data).decode("utf-8", "replace") if schema else "", metadata=dict(channel.metadata),
    )  # fmt: skip


def _load_indexed(log: RunLog, f: Any) -> None:
    """A finished file: summary, metadata, attachments and the packed channels through the index;
    every chunk's CRC checked."""
    from mcap.data_stream import ReadDataStream
    from mcap.reader import make_reader
    from mcap.records import Chunk
    from mcap.stream_reader import get_chunk_data_stream

    reader = make_reader(f)
    summary = reader.get_summary()
    if summary is None:
        raise log._fail("MCAP file without a summary section (not written by wmr-mj)")
    for ch in summary.channels.values():
        log._channels.setdefault(ch.topic, _channel_of(ch, summary.schemas))
    if summary.statistics is not None:
        for cid, n in summary.statistics.channel_message_counts.items():
            if cid in summary.channels:
                log._counts[summary.channels[cid].topic] = int(n)
    for rec in reader.iter_metadata():
        log.metadata[rec.name] = dict(rec.metadata)
    for att in reader.iter_attachments():
        log.attachments[att.name] = bytes(att.data)
        log.attachment_types[att.name] = att.media_type
    log._indexed = True
    packed = {c.id for c in summary.channels.values() if c.topic in lf.PACKED_TOPICS}
    for ci in summary.chunk_indexes:  # chunks that the packed read below does not check
        if not packed & set(ci.message_index_offsets):
            f.seek(ci.chunk_start_offset + 9)  # past the record's opcode and length
            get_chunk_data_stream(Chunk.read(ReadDataStream(f)), validate_crc=True)


def _load_stream(log: RunLog, f: Any, size: int) -> None:
    """A file without footer: every record from the start, up to the last complete chunk."""
    from mcap.records import Attachment, Channel, Chunk, DataEnd, Footer, Message, Metadata, Schema
    from mcap.stream_reader import StreamReader, breakup_chunk

    schemas: dict[int, Any] = {}
    channels: dict[int, _Channel] = {}
    messages: dict[str, list[tuple[int, bytes]]] = {}
    records = StreamReader(f, emit_chunks=True).records
    reason = "the writer stopped after a complete block"
    data_end = False

    def take(rec: Any) -> None:
        if isinstance(rec, Schema):
            schemas[rec.id] = rec
        elif isinstance(rec, Channel):
            channels[rec.id] = _channel_of(rec, schemas)
            log._channels.setdefault(rec.topic, channels[rec.id])
            messages.setdefault(rec.topic, [])
        elif isinstance(rec, Message):
            ch = channels.get(rec.channel_id)
            if ch is None:
                raise log._fail(f"message on undeclared channel {rec.channel_id}")
            messages[ch.topic].append((rec.log_time, rec.data))

    try:
        while True:
            start = f.tell()
            try:
                rec = next(records)
            except StopIteration:
                break
            except Exception as exc:
                if data_end:
                    raise _Truncated("the file ends in its summary section, after all its data") from None
                if start >= size:  # a killed writer: everything flushed is complete
                    raise _Truncated("the writer stopped after a complete block") from None
                if f.tell() >= size:  # the cut: a record runs past the end of the file
                    raise _Truncated("the file ends inside a record") from None
                raise log._fail(f"corrupt MCAP file ({type(exc).__name__}: {exc})") from None
            if isinstance(rec, Chunk):
                try:
                    inner = breakup_chunk(rec, validate_crc=True)
                except Exception as exc:
                    if f.tell() >= size:
                        raise _Truncated("the file ends inside a chunk") from None
                    raise log._fail(f"corrupt MCAP file (a chunk: {type(exc).__name__}: {exc})") from None
                for r in inner:
                    take(r)
            elif isinstance(rec, Metadata):
                log.metadata[rec.name] = dict(rec.metadata)
            elif isinstance(rec, Attachment):
                log.attachments[rec.name] = bytes(rec.data)
                log.attachment_types[rec.name] = rec.media_type
            elif isinstance(rec, DataEnd):
                data_end = True
            elif isinstance(rec, Footer):  # read this way only when the closing magic is missing
                reason = "the file ends after its footer, without the closing MCAP magic"
                break
            else:
                take(rec)
    except _Truncated as exc:
        reason = str(exc)
    for msgs in messages.values():
        msgs.sort(key=lambda x: x[0])
    log._messages.update(messages)
    log.truncated = bool(reason)
    log.truncated_reason = reason


def load_log(path: str | Path) -> RunLog:
    """Load a run log; raises LogError on a missing, non-MCAP, corrupt or unsupported file."""
    from mcap.writer import MCAP0_MAGIC

    path = Path(path)
    log = RunLog(path)
    try:
        with open(path, "rb") as f:
            size = f.seek(0, 2)
            f.seek(0)
            head = f.read(8)
            if head != MCAP0_MAGIC:
                what = "an empty file" if not head else "it does not start with the MCAP magic"
                raise LogError(f"{path}: not an MCAP file ({what}); {ACCEPTED}")
            f.seek(max(size - 8, 8))
            finished = size >= 16 and f.read(8) == MCAP0_MAGIC  # a closed file ends with the magic too
            f.seek(0)
            try:
                if finished:
                    _load_indexed(log, f)
                else:
                    _load_stream(log, f, size)
            except LogError:
                raise
            except Exception as exc:  # the library's parse and CRC errors: corruption, in one line
                raise log._fail(f"corrupt MCAP file ({type(exc).__name__}: {exc})") from None
    except FileNotFoundError:
        raise LogError(f"{path}: no such file; {ACCEPTED}") from None
    except IsADirectoryError:
        raise LogError(f"{path}: is a directory; {ACCEPTED}") from None
    except OSError as exc:
        raise LogError(f"{path}: cannot be read ({exc.strerror or exc}); {ACCEPTED}") from None
    info = log.metadata.get("wmr_mj")
    if info is None:
        if log.truncated:
            raise LogError(f"{path}: the file was cut before its wmr_mj metadata record; nothing to read; {ACCEPTED}")
        raise LogError(f"{path}: MCAP file without a wmr_mj metadata record (not a wmr-mj run log); {ACCEPTED}")
    version = info.get("schema_version")
    if version not in SUPPORTED_SCHEMA_VERSIONS:
        raise LogError(
            f"{path}: unknown wmr-mj log schema version {version!r}; this wmr-mj reads schema version(s) "
            f"{', '.join(SUPPORTED_SCHEMA_VERSIONS)} (write the log again with `wmr-mj run`)"
        )
    # the full-rate channels now (their chunks' CRCs checked), so that a bad file is reported here
    packed = [t for t in lf.PACKED_TOPICS if t in log._channels and t not in log._messages]
    if packed:
        log._read_indexed(packed, validate_crcs=True)
    _ = log.signals, log.state, log.measured
    return log
