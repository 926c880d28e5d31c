"""MCAP run logs: :class:`RunLogger` writes one file per closed-loop run with ``mcap.writer.Writer``.

The runner hands the logger one *block* of rows about once per simulated second. Each block
becomes, through the official writer, two chunks that are flushed to the file at once:

1. the full-rate data, packed with NumPy into one message per channel (``/sim/state`` at every
   control step, ``/signals`` at every ``log_every``-th), so that it costs a few messages a second;
2. what Foxglove draws: one message per row at ``plot_rate_hz`` on ``/steering``, ``/motor``,
   ``/pose`` (Plot panel), ``/tf`` at ``tf_rate_hz`` (3D panel) and ``/bounds``.

Where the header says the run is sensed (``LogHeader.sensed``), each block also carries what the law read
(``logformat.SENSED_BLOCK_KEYS``): it goes to ``/measured`` (every control step, in the first chunk) and
``/steering/measured`` (plot rate, in the second); an ideal run's log has neither channel.

``close`` adds the summary as a metadata record, then the writer's index and footer. Channels
and encodings: :mod:`wmr_mj.logs.logformat`; frames and scene: :mod:`wmr_mj.logs.foxglove`; reading:
:func:`wmr_mj.logs.reader.load_log`.

Interruptions: SIGINT/SIGTERM are held while a block is written, so a chunk is never half
written; with :func:`terminate_as_interrupt` SIGTERM becomes KeyboardInterrupt, the runner closes
the log with status "interrupted" and the file is finished. After a hard kill (SIGKILL, power
loss with ``fsync=True``) the file holds every flushed block; mcap's stream reader recovers them.

Usage::

    header = LogHeader(mjcf_xml=xml, config=cfg, parameters=params, initial_state=s0,
                       timestep=m.opt.timestep, control_substeps=1,
                       bounds={"E_max": 0.02, "Edot_max": 0.1})
    with terminate_as_interrupt(), RunLogger("logs/run.mcap", header,
                                             options=LogOptions(compression="zstd")) as log:
        for block in blocks:            # dict of (N, ...) float64 arrays, see logformat.BLOCK_KEYS
            log.write_block(block)
        log.close({"sup_E": 0.01})
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import datetime as _dt
import functools
import io
import json
import math
import os
import signal
import statistics
import threading
import time
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from mcap.opcode import Opcode
from mcap.records import MessageIndex

from wmr_mj._util.files import json_safe, software_versions
from wmr_mj._version import __version__
from wmr_mj.errors import LogError, OutputPathError, ParameterError
from wmr_mj.logs import logformat as lf
from wmr_mj.logs.foxglove import (
    TF_SCHEMA_NAME,
    FrameTree,
    TfEncoder,
    scene_update,
    tf_schema_text,
    travelled_update,
)
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.log_header import LogHeader

if TYPE_CHECKING:
    from wmr_mj.sim.config import RunConfig
    from wmr_mj.sim.summary import RunSummary

__all__ = ["RunLogger", "LogHeader", "LogOptions", "run_logged", "terminate_as_interrupt", "measure_logging_overhead",
           "COMPRESSIONS", "STATUSES"]

STATUSES = ("completed", "interrupted", "error", "failed")  # failed: the law (a plug-in) failed mid-run
COMPRESSIONS = ("lz4", "zstd", "none")


#: The channel of a law's own signals (JSON, one message per block: {"t": [...], NAME: [...]}, NaN as null), and
#: the block keys it takes them from (engine.LAW_SIGNAL_PREFIX + NAME); only in the log of a law that logs any.
LAW_TOPIC = "/law"
LAW_PREFIX = "law_"


def _dumps(obj: Any) -> str:
    return json.dumps(json_safe(obj), allow_nan=False, separators=(",", ":"))


def _npy(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, array, allow_pickle=False)
    return buf.getvalue()


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
    """Hold SIGINT/SIGTERM while a block is written; a held signal is raised on leaving."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _block_signals() -> None:
    """In the writer thread: leave SIGINT/SIGTERM to the main thread, which defers them around writes."""
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})


# --------------------------------------------------------------------------- writer


class _MessageIndex(MessageIndex):
    """mcap's MessageIndex record, its (log time, offset) entries written with one NumPy call."""

    def write(self, stream: Any) -> None:
        stream.start_record(Opcode.MESSAGE_INDEX)
        stream.write2(self.channel_id)
        stream.write4(len(self.records) * 16)
        stream.write(np.asarray(self.records, dtype="<u8").reshape(-1, 2).tobytes())  # time, offset, time, ...
        stream.finish_record()


class _BulkMessages:
    """Many messages of one channel into the open chunk of an ``mcap.writer.Writer`` at once, with NumPy.

    The records, the chunk's message index and the file's statistics come out exactly as
    ``Writer.add_message`` called once per row would leave them (same bytes, same order), without
    its Python per message: a block's Foxglove channels are a few hundred messages a simulated
    second. It reaches into the writer's chunk builder and statistics (mcap 1.x); :meth:`attach`
    returns None where they are not as expected, and the writer then adds one message at a time.
    """

    _HEADER = 1 + 8 + 2 + 4 + 8 + 8  # opcode, record length, channel, sequence, log time, publish time

    def __init__(self, writer: Any, builder: Any, statistics: Any) -> None:
        self._w, self._builder, self._stats = writer, builder, statistics
        self._finalize = writer._Writer__maybe_finalize_chunk

    @classmethod
    def attach(cls, writer: Any) -> _BulkMessages | None:
        builder = getattr(writer, "_Writer__chunk_builder", None)
        stats = getattr(writer, "_Writer__statistics", None)
        needed = (hasattr(builder, "record_writer") and hasattr(builder, "message_indices")
                  and hasattr(builder, "num_messages") and hasattr(stats, "channel_message_counts")
                  and hasattr(writer, "_Writer__maybe_finalize_chunk"))
        return cls(writer, builder, stats) if needed else None

    def add(self, cid: int, log_times: np.ndarray, payloads: np.ndarray, seq: int) -> None:
        n = len(log_times)
        data = np.ascontiguousarray(payloads).view(np.uint8).reshape(n, -1)
        size = data.shape[1]
        rec = np.empty(n, np.dtype([("op", "u1"), ("len", "<u8"), ("ch", "<u2"), ("seq", "<u4"), ("log", "<u8"),
                                    ("pub", "<u8"), ("data", "u1", (size,))]))  # packed, as the records are
        rec["op"] = int(Opcode.MESSAGE)
        rec["len"] = self._HEADER - 9 + size
        rec["ch"] = cid
        rec["seq"] = (seq + np.arange(n, dtype=np.int64)) & 0xFFFFFFFF
        rec["log"] = log_times
        rec["pub"] = log_times
        rec["data"] = data
        b, st = self._builder, self._stats
        first = b.record_writer.count
        times = log_times.tolist()
        lo, hi = min(times), max(times)
        b.message_start_time = lo if b.num_messages == 0 else min(b.message_start_time, lo)
        b.message_end_time = max(b.message_end_time, hi)
        index = b.message_indices.get(cid)
        if not index:
            index = b.message_indices[cid] = _MessageIndex(channel_id=cid, records=[])
        index.records.extend(zip(times, range(first, first + n * rec.itemsize, rec.itemsize)))
        b.num_messages += n
        b.record_writer.write(rec.tobytes())
        st.message_start_time = lo if st.message_count == 0 else min(st.message_start_time, lo)
        st.message_end_time = max(st.message_end_time, hi)
        st.channel_message_counts[cid] += n
        st.message_count += n
        self._finalize()


@dataclass(frozen=True)
class LogOptions:
    """How a log is written (not what the run is: that is :class:`LogHeader`).

    Attributes:
        log_every: /signals keeps every k-th row (/sim/state keeps all), an integer >= 1.
        plot_rate_hz: rate of the Foxglove plot channels /steering, /motor, /pose [Hz].
        tf_rate_hz: rate of /tf (3D panel) [Hz].
        flush_period_s: simulated time per flush [s].
        compression: "lz4" (default: about 20 % smaller files than "none" for 2 % more run
            time), "zstd" (about 25 % smaller again, for some 6 % more run time;
            bench/bench_logging.py measures them) or "none".
        fsync: make each flush durable against power loss, not only against the process being
            killed.
        background: a writer thread encodes, compresses and writes each flushed second while the
            runner simulates the next (NumPy, lz4 and the file write release the GIL, as
            ``mujoco.batch`` does): ``write_block`` then returns once every second before the one
            it hands over is on disk, so a hard kill loses at most the second in flight; ``close``
            and ``flush`` wait for it.
    """

    log_every: int = 1  # rows per /signals row
    plot_rate_hz: float = 100.0  # [Hz]
    tf_rate_hz: float = 50.0  # [Hz]
    flush_period_s: float = 1.0  # simulated [s]
    compression: str = "lz4"  # one of COMPRESSIONS
    fsync: bool = False
    background: bool = False


class RunLogger:
    """Write one run to an MCAP file (see the module docstring).

    Args:
        path: the .mcap file to write (its folder is made).
        header: what the runner tells the log (:class:`LogHeader`: MJCF, config, parameters,
            initial state, timestep, control substeps, reference path, bounds, compiled model).
        options: how the log is written (:class:`LogOptions`: /signals decimation, Foxglove
            rates, flush period, compression, fsync, background writer thread).
    """

    def __init__(self, path: str | os.PathLike, header: LogHeader, *, options: LogOptions = LogOptions()):
        import mujoco
        from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer

        mjcf_xml, config, parameters = header.mjcf_xml, header.config, header.parameters
        initial_state, timestep, control_substeps = header.initial_state, header.timestep, header.control_substeps
        reference_path, bounds, model = header.reference_path, header.bounds, header.model
        self._path_errors = header.path_errors
        self._sensed = bool(header.sensed)  # /measured and /steering/measured, and their block keys
        self._keys = (*lf.BLOCK_KEYS, *lf.SENSED_BLOCK_KEYS) if self._sensed else lf.BLOCK_KEYS
        log_every, plot_rate_hz, tf_rate_hz = options.log_every, options.plot_rate_hz, options.tf_rate_hz
        flush_period_s, compression = options.flush_period_s, options.compression
        fsync, background = options.fsync, options.background
        if compression not in COMPRESSIONS:
            raise ParameterError(f"compression {compression!r} is not one of {', '.join(COMPRESSIONS)}")
        for name, value in (("log_every", log_every), ("control_substeps", control_substeps)):
            if int(value) != value or int(value) < 1:
                raise ParameterError(f"{name} = {value!r}; an integer >= 1 is accepted")
        for name, x in (("timestep", timestep), ("plot_rate_hz", plot_rate_hz), ("tf_rate_hz", tf_rate_hz),
                        ("flush_period_s", flush_period_s)):
            if not (isinstance(x, (int, float)) and math.isfinite(x) and x > 0):
                raise ParameterError(f"{name} = {x!r}; a finite number > 0 is accepted")
        self.path = Path(path)
        self.timestep = float(timestep)
        self.control_substeps = int(control_substeps)
        self.log_every = int(log_every)
        self.flush_period_s = float(flush_period_s)
        self.dt_row = self.timestep * self.control_substeps
        self.plot_every = max(1, round(1.0 / (plot_rate_hz * self.dt_row)))
        self.tf_every = max(1, round(1.0 / (tf_rate_hz * self.dt_row)))
        self.compression = compression
        self._fsync = bool(fsync)
        self._model = model if model is not None else mujoco.MjModel.from_xml_string(mjcf_xml)
        m = self._model
        self.nq, self.nv, self.nu = int(m.nq), int(m.nv), int(m.nu)
        init = np.ascontiguousarray(np.asarray(initial_state, dtype=np.float64).ravel())
        expected = mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION)
        if init.size != expected:
            raise ParameterError(f"initial_state has {init.size} values; mjSTATE_INTEGRATION of this model "
                                 f"has {expected}")
        self._voltage_limit = (parameters or {}).get("voltage_limit")
        self._bounds_given = bounds is not None
        self._bounds = self._bound_values(bounds or {}, parameters)
        self._closed = False
        self._rows = 0
        self._travelled_last = np.empty((0, 2))  # C's last xy drawn in the scene's travelled path
        self._travelled_pieces = 0
        self._last_t = 0.0
        self._pending: list[dict[str, np.ndarray]] = []
        self._pending_rows = 0
        self._taken_rows = 0  # rows handed to _write_rows, written or in flight
        self._background = bool(background)
        self._in_flight: Any = None  # the writer thread's job (concurrent.futures.Future), background only
        self._executor: Any = None
        self._seq: dict[int, int] = {}
        self._tf = TfEncoder(FrameTree(m))

        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._f = open(self.path, "wb")
        except OSError as exc:
            raise OutputPathError(f"{str(self.path)!r} cannot be written: {exc.strerror or exc}; "
                                  "give a log path in a writable folder") from None
        try:
            comp = {"lz4": CompressionType.LZ4, "zstd": CompressionType.ZSTD, "none": CompressionType.NONE}
            # chunks are cut by flush() only: one block of full-rate data, one of Foxglove data
            self._w = Writer(self._f, chunk_size=1 << 62, compression=comp[compression])
            self._bulk = _BulkMessages.attach(self._w)  # None: one add_message per row
            self._w.start(profile="", library=f"wmr-mj/{__version__}; {LIBRARY_IDENTIFIER}")
            self._start(mjcf_xml, config, parameters, init, reference_path)
        except BaseException:
            self._f.close()
            self.path.unlink(missing_ok=True)  # no partial file of a log that never started
            raise

    @staticmethod
    def _bound_values(bounds: Mapping[str, Any], parameters: Mapping[str, Any]) -> dict[str, float]:
        def finite(v: Any) -> float:
            try:
                x = float(v)
            except (TypeError, ValueError):
                return math.nan
            return x if math.isfinite(x) else math.nan

        src = {"E_max": bounds.get("E_max"), "Edot_max": bounds.get("Edot_max"),
               "voltage_limit": (parameters or {}).get("voltage_limit")}
        return {f["name"]: f["sign"] * finite(src[f["source"]])
                for f in lf.channel_layouts()["channels"][lf.BOUNDS_TOPIC]["fields"]}

    # ---- start
    def _start(self, mjcf_xml: str, config: Any, parameters: Mapping[str, Any], init: np.ndarray,
               reference_path: np.ndarray | None) -> None:
        w = self._w
        self._cid: dict[str, int] = {}
        for topic, spec in lf.channel_layouts()["channels"].items():
            if lf.sensed_only(topic) and not self._sensed:
                continue  # registered last, so that an ideal run's channel ids are what they were
            sid = w.register_schema(spec["schema"], "ros2msg", lf.ros2msg_text(topic).encode())
            units = {f["name"]: f.get("unit", "") for f in spec["fields"]}
            self._cid[topic] = w.register_channel(topic, "cdr", sid, {"units": json.dumps(units)})
        sid = w.register_schema(TF_SCHEMA_NAME, "ros2msg", tf_schema_text().encode())
        self._cid[lf.TF_TOPIC] = w.register_channel(lf.TF_TOPIC, "cdr", sid, {})
        scene_schema = lf.schema_text("foxglove.SceneUpdate.json").encode()
        sid = w.register_schema("foxglove.SceneUpdate", "jsonschema", scene_schema)
        self._cid[lf.SCENE_TOPIC] = w.register_channel(lf.SCENE_TOPIC, "json", sid, {})
        self._seq = dict.fromkeys(self._cid.values(), 0)

        cfg = config if isinstance(config, Mapping) else {"config": config}
        w.add_metadata("wmr_mj", {
            "schema_version": lf.SCHEMA_VERSION,
            "format": "wmr-mj run log",
            "timestep": repr(self.timestep),
            "control_substeps": str(self.control_substeps),
            "log_every": str(self.log_every),
            "plot_every": str(self.plot_every),
            "tf_every": str(self.tf_every),
            "nq": str(self.nq), "nv": str(self.nv), "nu": str(self.nu),
            "seed": _dumps(cfg.get("seed")),
            "compression": self.compression,
            "created_utc": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        })  # fmt: skip
        w.add_metadata("versions", software_versions())
        w.add_metadata("config", {str(k): _dumps(v) for k, v in cfg.items()})
        now = time.time_ns()
        w.add_attachment(now, 0, "c80.xml", "application/xml", mjcf_xml.encode("utf-8"))
        params = json.dumps(json_safe(parameters), indent=2, allow_nan=False).encode()
        w.add_attachment(now, 0, "parameters.json", "application/json", params)
        w.add_attachment(now, 0, "initial_state.npy", "application/x-npy", _npy(init))
        cart = cfg.get("cart")
        if isinstance(cart, Mapping) and isinstance(cart.get("text"), str):  # a run on a cart file: the file itself
            w.add_attachment(now, 0, "cart.toml", "application/toml", cart["text"].encode("utf-8"))
        if reference_path is not None:
            ref = np.asarray(reference_path, dtype=np.float64)
            w.add_attachment(now, 0, "reference_path.npy", "application/x-npy", _npy(ref))
        scene = scene_update(self._model, self._tf.tree.names, reference_path)
        try:  # built from finite floats; the slower sanitizer only when that fails
            text = json.dumps(scene, allow_nan=False, separators=(",", ":"))
        except (TypeError, ValueError):
            text = _dumps(scene)
        self._add(lf.SCENE_TOPIC, 0, text.encode())
        with _signals_deferred():
            w.flush()  # the first chunk holds the schemas and channels: a killed run's file starts readable

    def _add(self, topic: str, log_time: int, data: bytes) -> None:
        cid = self._cid[topic]
        seq = self._seq[cid]
        self._w.add_message(cid, log_time, data, log_time, seq & 0xFFFFFFFF)
        self._seq[cid] = seq + 1

    def _add_many(self, topic: str, log_times: np.ndarray, payloads: np.ndarray) -> None:
        """One message per row of ``payloads`` ((n, L) uint8 or (n,) structured)."""
        cid = self._cid[topic]
        seq = self._seq[cid]
        n = len(log_times)
        if n and self._bulk is not None:
            self._bulk.add(cid, np.asarray(log_times, dtype=np.int64), payloads, seq)
        else:
            raw = memoryview(payloads.tobytes())  # slices of it are not copied
            size = len(raw) // max(n, 1)
            add = self._w.add_message
            for i, t in enumerate(log_times.tolist()):
                # mcap annotates data as bytes; it takes any buffer, and a memoryview slice is not a copy
                add(cid, t, raw[i * size : (i + 1) * size], t, (seq + i) & 0xFFFFFFFF)  # type: ignore[arg-type]
        self._seq[cid] = seq + n

    # ---- blocks
    def write_block(self, block: Mapping[str, np.ndarray]) -> None:
        """Append N rows; written and flushed once ``flush_period_s`` of simulated time is pending
        (every block when the runner hands one per simulated second)."""
        with _signals_deferred():  # an interrupt is raised after the rows are taken, never half way
            self._write_block(block)

    def _write_block(self, block: Mapping[str, np.ndarray]) -> None:
        if self._closed:
            raise LogError(f"{self.path}: write_block after close")
        missing = [k for k in self._keys if k not in block]
        if missing:
            raise ParameterError(f"block lacks {', '.join(missing)}; a block has {', '.join(self._keys)}"
                                 + (" (the header says the run is sensed)" if self._sensed else ""))
        t = np.asarray(block["t"], np.float64).ravel()
        n = t.size
        if n == 0:
            return
        shapes = {"A_pos": (n, 2), "C_pos": (n, 2), "qpos": (n, self.nq), "qvel": (n, self.nv), "ctrl": (n, self.nu)}
        clean: dict[str, np.ndarray] = {}
        for k in self._keys:
            a = np.asarray(block[k], np.float64)
            want = shapes.get(k, (n,))
            if a.shape != want:
                if a.size != math.prod(want):
                    raise ParameterError(f"block[{k!r}] has shape {a.shape}; {want} is expected")
                a = a.reshape(want)
            clean[k] = np.array(a) if self._background else a  # the runner may reuse its buffers
        for k in lf.OPTIONAL_BLOCK_KEYS:  # C's path errors: NaN where the runner gave none
            given = block.get(k)
            a = np.full(n, np.nan) if given is None else np.array(given, np.float64).ravel()
            if a.shape != (n,):
                raise ParameterError(f"block[{k!r}] has shape {a.shape}; {(n,)} is expected")
            clean[k] = a
        for k in block:  # a law's own signals (rows law_NAME: controllers.SteeringController.signal_names)
            if k.startswith(LAW_PREFIX):
                clean[k] = np.array(block[k], np.float64).ravel()
        self._pending.append(clean)
        self._pending_rows += n
        if self._pending_rows * self.dt_row >= self.flush_period_s - 0.5 * self.dt_row:
            self.flush()

    def _take_pending(self) -> dict[str, np.ndarray]:
        self._taken_rows += self._pending_rows
        blocks, self._pending, self._pending_rows = self._pending, [], 0
        keys = (*self._keys, *lf.OPTIONAL_BLOCK_KEYS, *(k for k in blocks[0] if k.startswith(LAW_PREFIX)))
        return blocks[0] if len(blocks) == 1 else {k: np.concatenate([b[k] for b in blocks]) for k in keys}

    def flush(self) -> None:
        """Write the pending rows as two complete chunks and flush them to the file.

        In the background, hand them to the writer thread once the second before is on disk.
        """
        self._wait()
        if not self._pending:
            return
        if self._background:
            if self._executor is None:
                self._executor = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="wmr-mj-log",
                                                                       initializer=_block_signals)
            self._in_flight = self._executor.submit(self._write_and_flush, self._take_pending())
            return
        with _signals_deferred():  # a signal arriving now is raised after the chunks are out
            self._write_and_flush(self._take_pending())

    def _write_and_flush(self, rows: Mapping[str, np.ndarray]) -> None:
        if self._path_errors is not None:  # C's path errors for /path, here: on the writer's thread if any
            rows = {**rows, **self._path_errors(rows, self.plot_every)}
        self._write_rows(rows)
        self._w.flush()
        if self._fsync:
            os.fsync(self._f.fileno())

    def _wait(self) -> None:
        """Wait for the writer thread's second (re-raising its error); nothing in flight after it returns."""
        job = self._in_flight
        if job is not None:
            try:
                job.result()
            finally:
                if job.done():  # not when an interrupt ended the wait: close waits again
                    self._in_flight = None

    def _write_rows(self, b: Mapping[str, np.ndarray]) -> None:
        t = b["t"]
        n = t.size
        rows = np.arange(self._rows, self._rows + n, dtype=np.int64)
        tt = np.where(np.isfinite(t), t, rows * self.dt_row)  # a NaN time still gets a place
        lt = np.rint(np.clip(tt, 0.0, 9.2e9) * 1e9).astype(np.int64)
        # 1. full-rate data, packed: its own chunk, so that readers of it skip the rest
        counts = {"nq": self.nq, "nv": self.nv, "nu": self.nu}
        state = {f["name"]: b[f["block"]] for f in lf.channel_layouts()["channels"][lf.STATE_TOPIC]["fields"]}
        self._add(lf.STATE_TOPIC, int(lt[0]), lf.encode_block(lf.STATE_TOPIC, {**state, **counts}))
        sel = np.flatnonzero(rows % self.log_every == 0)
        if sel.size:
            fields = lf.channel_layouts()["channels"][lf.SIGNALS_TOPIC]["fields"]
            sig = {f["name"]: b[f["block"]][sel] for f in fields}
            self._add(lf.SIGNALS_TOPIC, int(lt[sel[0]]), lf.encode_block(lf.SIGNALS_TOPIC, sig))
        if self._sensed:  # what the law read, at every control step (replay --verify compares all of them)
            fields = lf.channel_layouts()["channels"][lf.MEASURED_TOPIC]["fields"]
            measured = {f["name"]: b[f["block"]] for f in fields}
            self._add(lf.MEASURED_TOPIC, int(lt[0]), lf.encode_block(lf.MEASURED_TOPIC, measured))
        law = [k for k in b if k.startswith(LAW_PREFIX)]
        if law and LAW_TOPIC not in self._cid:  # registered at its first block: other runs keep their channel ids
            self._cid[LAW_TOPIC] = cid = self._w.register_channel(LAW_TOPIC, "json", 0, {})
            self._seq[cid] = 0
        if law:  # the law's own signals at every control step: one JSON message per block on /law
            self._add(LAW_TOPIC, int(lt[0]), _dumps({"t": t, **{k[len(LAW_PREFIX):]: b[k] for k in law}}).encode())
        self._w.flush()
        # 2. what Foxglove draws, one message per row
        plot = np.flatnonzero(rows % self.plot_every == 0)
        tf = np.flatnonzero(rows % self.tf_every == 0)
        for topic in (*lf.PLOT_TOPICS, *((lf.MEASURED_PLOT_TOPIC,) if self._sensed else ())):
            sel = tf if lf.channel_layouts()["channels"][topic]["rate"] == "tf" else plot
            self._add_many(topic, lt[sel], lf.encode_rows(topic, b, sel))
        keep, payloads = self._tf.encode(lt[tf], b["qpos"][tf])
        self._add_many(lf.TF_TOPIC, lt[tf][keep], payloads)
        # the path C travelled, on the 3D panel: one piece per written block, joined to the one before
        C = b["C_pos"][tf]
        piece = np.concatenate([self._travelled_last, C[np.all(np.isfinite(C), axis=1)]])
        if len(piece) >= 2:
            scene = travelled_update(piece, int(lt[-1]), self._travelled_pieces)
            self._add(lf.SCENE_TOPIC, int(lt[-1]), json.dumps(scene, separators=(",", ":")).encode())
            self._travelled_pieces += 1
        if len(piece):
            self._travelled_last = piece[-1:]
        if self._bounds_given:
            self._add_bounds(int(lt[0]))
        self._rows += n
        self._last_t = float(tt[-1])

    def _add_bounds(self, log_time: int) -> None:
        spec = lf.channel_layouts()["channels"][lf.BOUNDS_TOPIC]
        msg = np.zeros(1, lf.row_dtype(lf.ros2msg_text(lf.BOUNDS_TOPIC)))
        msg["__cdr"] = np.frombuffer(lf.CDR_LE_HEADER, np.uint8)
        for f in spec["fields"]:
            msg[f["name"]] = self._bounds[f["name"]]
        self._add(lf.BOUNDS_TOPIC, log_time, msg.tobytes())

    # ---- close
    def close(self, summary: Mapping[str, Any] | None = None, *, status: str = "completed") -> None:
        """Write what is pending, the summary metadata record, the index and the footer; close the file."""
        if self._closed:
            return
        if status not in STATUSES:
            raise ParameterError(f"status {status!r} is not one of {', '.join(STATUSES)}")
        self._closed = True
        summary = dict(summary or {})
        try:
            with _signals_deferred():
                with contextlib.suppress(Exception):  # the second in flight; its error must not cost the footer
                    self._wait()
                if self._executor is not None:
                    self._executor.shutdown(wait=True)
                if self._pending:
                    with contextlib.suppress(Exception):  # never lose the footer because of one bad block
                        self._write_rows(self._take_pending())
                if not self._bounds_given and ("E_max" in summary or "Edot_max" in summary):
                    self._bounds = self._bound_values(summary, {"voltage_limit": self._voltage_limit})
                    self._add_bounds(0)
                if self._rows and (self._bounds_given or "E_max" in summary or "Edot_max" in summary):
                    self._add_bounds(int(round(self._last_t * 1e9)))  # the constant series reaches the end
                meta = {"status": _dumps(status), "rows": _dumps(self._rows), "last_t": _dumps(self._last_t)}
                for k, v in summary.items():
                    meta.setdefault(str(k), _dumps(v))
                self._w.add_metadata("summary", meta)
                self._w.finish()
                self._f.flush()
                if self._fsync:
                    os.fsync(self._f.fileno())
        finally:
            self._f.close()

    @property
    def rows(self) -> int:
        """Rows written so far (flushed, in flight or pending)."""
        return self._taken_rows + self._pending_rows

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
    """Time ``run(None)`` (no log) against ``run(log_path)`` (logged), alternating, median of ``repeats``.

    ``run`` is the runner's entry point taking the log path or None; returns
    {"unlogged_s", "logged_s", "ratio"}. Used by bench/bench_logging.py.
    """

    def timed(arg: Any) -> float:
        t0 = time.perf_counter()
        run(arg)
        return time.perf_counter() - t0

    unlogged, logged = [], []
    for _ in range(repeats):  # alternate, so that a slow spell of a shared machine hits both
        unlogged.append(timed(None))
        logged.append(timed(log_path))
    u, lg = statistics.median(unlogged), statistics.median(logged)
    return {"unlogged_s": u, "logged_s": lg, "ratio": lg / u}


def run_logged(config: RunConfig, path: str) -> RunSummary:
    """Re-run ``config`` serially (``run_closed_loop``) with an MCAP log at ``path``; its summary."""
    return run_closed_loop(config, logger_factory=functools.partial(RunLogger, path), progress=False).summary
