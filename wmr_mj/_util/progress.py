"""Progress display on stderr through tqdm; silent when stderr is not a terminal.

Three shapes cover the package's long jobs:

- :func:`progress_bar`: a tqdm bar (a run's steps);
- :func:`counter_callback`: a ``progress(done, total)`` callback, as ``run_sweep`` calls it
  (``done`` may be fractional while a chunk steps; the first call reports resumed runs);
- :class:`Stages`: named stages of a job, one log line each with its wall time, and a
  live bar while a stage runs (``wmr-mj validate``).

Usage::

    from wmr_mj._util.progress import counter_callback, progress_bar
    with progress_bar(35_000, desc="run", unit="step") as bar:
        for k in range(35_000):
            bar.update(1)
    with progress_bar(200, desc="sweep", unit="runs", fractional=True) as bar:
        run_sweep(spec, progress=counter_callback(bar))
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable
from typing import IO, Any

from tqdm import tqdm

__all__ = ["progress_bar", "counter_callback", "Stages", "is_terminal"]

# a bar whose count may be fractional (runs of a sweep while a chunk steps)
_FRACTIONAL_FORMAT = "{desc}: {percentage:3.0f}%|{bar}| {n:.1f}/{total_fmt} {unit} [{elapsed}<{remaining}]"
_NO_TOTAL_FORMAT = "{desc} [{elapsed}]"


def is_terminal(stream: IO[str] | None = None) -> bool:
    """Whether ``stream`` (default stderr) is a terminal."""
    stream = sys.stderr if stream is None else stream
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty()) if isatty is not None else False
    except (ValueError, OSError):  # closed or detached stream
        return False


class _Bar(tqdm):
    """tqdm that can also redraw itself every ``tick_s`` seconds, so the elapsed time moves
    while a stage makes no countable progress (an identification, the figures)."""

    def __init__(self, *args: Any, tick_s: float | None = None, **kwargs: Any):
        self._stop_ticking = threading.Event()
        self._ticker: threading.Thread | None = None
        super().__init__(*args, **kwargs)
        if tick_s and not self.disable:
            self._ticker = threading.Thread(target=self._tick, args=(tick_s,), daemon=True)
            self._ticker.start()

    def _tick(self, tick_s: float) -> None:
        while not self._stop_ticking.wait(tick_s):
            self.refresh()

    def close(self) -> None:
        self._stop_ticking.set()
        if self._ticker is not None and self._ticker is not threading.current_thread():
            self._ticker.join()
            self._ticker = None
        super().close()


def progress_bar(total: float | None = None, *, desc: str | None = None, unit: str = "it",
                 enabled: bool | None = None, stream: IO[str] | None = None, fractional: bool = False,
                 tick_s: float | None = None, leave: bool = False, **tqdm_options: Any) -> tqdm:
    """A tqdm bar on ``stream`` (default stderr); ``enabled=None`` shows it only on a terminal.

    fractional: the count may be fractional (shown with one decimal). tick_s: redraw every
    tick_s seconds even without updates. leave: keep the finished bar on screen (default:
    erase it, so the command's report starts on a clean line). Other options go to tqdm.
    """
    stream = sys.stderr if stream is None else stream
    show = is_terminal(stream) if enabled is None else bool(enabled)
    if fractional:
        tqdm_options.setdefault("bar_format", _FRACTIONAL_FORMAT)
    elif total is None:
        tqdm_options.setdefault("bar_format", _NO_TOTAL_FORMAT)
    return _Bar(total=total, desc=desc, unit=unit, file=stream, disable=not show, leave=leave,
                dynamic_ncols=True, tick_s=tick_s, **tqdm_options)


def counter_callback(bar: tqdm) -> Callable[[float, int], None]:
    """A ``progress(done, total)`` callback that moves ``bar`` to ``done`` of ``total``.

    The first call's ``done`` (runs found in a resumed sweep's runs.csv) counts as the
    bar's initial value, so the rate and the time left are those of the runs done now.
    """
    first = True

    def progress(done: float, total: int) -> None:
        nonlocal first
        if bar.total != total:
            bar.total = total
        if first:
            first = False
            bar.initial = bar.n = done
            bar.refresh()
            return
        bar.update(done - bar.n)

    return progress


class Stages:
    """Named stages of a long job on ``stream`` (default stderr).

    Each finished stage writes one line ``<prefix>: <label> ... <s> s: <result>`` (when
    ``enabled``, terminal or not); while a stage runs, a live tqdm line shows its elapsed
    time and, after :meth:`update`, its count (only on a terminal; ``tty`` forces or
    suppresses it). ``timings`` maps each stage's key to its wall time in seconds.
    """

    def __init__(self, prefix: str, *, stream: IO[str] | None = None, enabled: bool = True,
                 tty: bool | None = None):
        self.prefix = prefix
        self.stream = sys.stderr if stream is None else stream
        self.enabled = enabled
        self.live = enabled and (is_terminal(self.stream) if tty is None else tty)
        self.timings: dict[str, float] = {}
        self._key = ""
        self._label = ""
        self._t0 = time.perf_counter()
        self._bar: tqdm | None = None
        self._count: Callable[[float, int], None] | None = None

    def start(self, key: str, label: str) -> None:
        self._close_bar()
        self._key, self._label = key, label
        self._t0 = time.perf_counter()
        if self.live:
            self._bar = progress_bar(desc=f"{self.prefix}: {label}", stream=self.stream, enabled=True, tick_s=0.5)
            self._count = None

    def update(self, done: float, total: int, unit: str = "runs") -> None:
        """The running stage has done ``done`` of ``total`` (fractional allowed)."""
        if self._bar is None:
            return
        if self._count is None:
            self._bar.unit = unit
            self._bar.bar_format = _FRACTIONAL_FORMAT
            self._count = counter_callback(self._bar)
        self._count(done, total)

    def done(self, result: str = "") -> float:
        """End the running stage: record and (when enabled) write its line; returns its wall time, s."""
        elapsed = time.perf_counter() - self._t0
        self.timings[self._key] = elapsed
        self._close_bar()
        if self.enabled:
            tail = f": {result}" if result else ""
            self.stream.write(f"{self.prefix}: {self._label} ... {elapsed:.1f} s{tail}\n")
            self.stream.flush()
        return elapsed

    def _close_bar(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
