"""A cart's own recordings of its steering: read, checked, ready for identification.

A recording is what a real cart's controller saw and did at each control step: the time t (s), the armature
voltage u it applied (V), the steering angle alpha its encoder read (rad) and, where measured, the forward
speed of A (m/s); and the chassis mass m1 (kg) during it. :func:`read_csv` reads one from a CSV file whose
header names each column and its unit (``t_s,u_V,alpha_rad[,speed_m_per_s]``; other names mapped with
``columns``); :func:`check_recording` refuses what identification cannot use, in one line
(:class:`wmr_mj.errors.ParameterError`, exit status 2 at the command line).

Usage::

    from wmr_mj.plant.recordings import read_csv, check_recording

    rec = read_csv("lab-run-1.csv", m1=112.0)                     # header t_s,u_V,alpha_rad
    rec = read_csv("bag.csv", columns={"t_s": "time", "u_V": "volts", "alpha_rad": "steer"})
    check_recording(rec, voltage_limit=24.0, steering_range=0.9)  # raises ParameterError on bad data
    rec.period, rec.duration, rec.sha256
"""

from __future__ import annotations

import csv
import hashlib
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from wmr_mj.errors import ParameterError

__all__ = ["Recording", "COLUMNS", "REQUIRED_COLUMNS", "read_csv", "write_csv", "check_recording", "parse_columns",
           "MIN_RECORDING_S", "GAP_TOLERANCE", "SUPPLY_TOLERANCE"]

#: The CSV columns, by the name the header must give (quantity and unit in one): what each holds.
COLUMNS: Mapping[str, str] = {
    "t_s": "time, s",
    "u_V": "armature voltage applied to the steering motor, V",
    "alpha_rad": "steering angle as the encoder read it, rad",
    "speed_m_per_s": "forward speed of A, m/s (optional: the cart's V_A where absent)",
    "u_applied_V": ("the voltage at the motor's terminals as the driver applied it, after the bus, V (optional: with "
                    "it the actuation delay, from u_V to it, is identified apart from the sensing delay)"),
}
REQUIRED_COLUMNS: tuple[str, ...] = ("t_s", "u_V", "alpha_rad")
#: A column named with another unit of a known quantity: the header disagrees with the units read.
_OTHER_UNITS: Mapping[str, str] = {"t_ms": "t_s", "t_us": "t_s", "t_ns": "t_s", "u_mV": "u_V", "alpha_deg": "alpha_rad",
                                   "speed_km_per_h": "speed_m_per_s", "speed_mm_per_s": "speed_m_per_s"}
#: The shortest recording identification accepts, s: the slowest time constant of a steering (P/C_V is tens of
#: ms, the friction's stick-slip cycles under a PD law a few hundred ms) must be seen many times over; 2 s gives
#: two segments of the output-error fit (wmr_mj.plant.output_error.SEGMENT_S = 1 s).
MIN_RECORDING_S = 2.0
#: A time step more than this times the median step is a gap (a dropped sample of a 1 kHz log is 2x).
GAP_TOLERANCE = 1.5
#: A voltage beyond the supply by more than this (relative) is refused: a float written with 6 digits rounds by
#: 5e-7 relative; 1e-6 keeps a recording of the limit itself.
SUPPLY_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Recording:
    """One recording of a cart's steering (arrays of equal length, one row per control step).

    Attributes:
        name: where it was read from (a file's path).
        sha256: SHA-256 of the file's bytes (hex), named by every value identified from it.
        t: time, s, (N,).
        voltage: armature voltage applied, V, (N,).
        alpha: steering angle as read, rad, (N,).
        speed: forward speed of A, m/s, (N,), or None where not recorded.
        m1: chassis mass during the recording, kg, or None: the cart's.
        applied: the voltage at the motor's terminals, V, (N,), or None where not recorded (an actuator-side
            signal: the delay from ``voltage`` to it is the actuation delay).
    """

    name: str
    sha256: str
    t: np.ndarray
    voltage: np.ndarray
    alpha: np.ndarray
    speed: np.ndarray | None = None
    m1: float | None = None
    applied: np.ndarray | None = None

    @property
    def samples(self) -> int:
        return int(self.t.size)

    @property
    def period(self) -> float:
        """The median time step, s, to 9 significant digits (times written as 0.001 k differ from k ms in the last
        bits; the delay, a whole number of periods, is then written as the cart file's 0.005 and not 0.00499...)."""
        return float(f"{float(np.median(np.diff(self.t))):.9g}") if self.t.size > 1 else math.nan

    @property
    def duration(self) -> float:
        """Last time minus first, s."""
        return float(self.t[-1] - self.t[0]) if self.t.size else 0.0

    def with_m1(self, m1: float) -> Recording:
        return Recording(self.name, self.sha256, self.t, self.voltage, self.alpha, self.speed, m1, self.applied)


def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file's bytes, hex."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def parse_columns(text: str | None) -> dict[str, str]:
    """``--columns t_s=time,u_V=volts,alpha_rad=steer`` -> {"t_s": "time", ...}.

    Raises:
        ParameterError: a pair without '=', or a key that is not one of :data:`COLUMNS`.
    """
    out: dict[str, str] = {}
    if not text:
        return out
    for pair in text.split(","):
        key, sep, value = pair.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not value:
            raise ParameterError(f"--columns: {pair!r} is not KEY=NAME; accepted: {', '.join(COLUMNS)} = the "
                                 "recording's column name, e.g. t_s=time,u_V=volts,alpha_rad=steer")
        if key not in COLUMNS:
            raise ParameterError(f"--columns: {key!r} is not a column of a recording; accepted: {', '.join(COLUMNS)}")
        out[key] = value
    return out


def write_csv(path: str | Path, columns: Mapping[str, np.ndarray]) -> Path:
    """Write a recording as :func:`read_csv` reads it: a header of ``columns``' names (:data:`COLUMNS`, in the
    order given), then one row per sample, each number as Python's ``repr`` of the float (read back to the bit).

    Args:
        path: the file written.
        columns: our column name -> its samples, all of one length (``t_s``, ``u_V`` and ``alpha_rad`` at least).

    Returns:
        ``path``, as a Path.

    Raises:
        ParameterError: a name that is not one of :data:`COLUMNS`, a required column missing, or columns of
            different lengths (one line).
    """
    unknown = [name for name in columns if name not in COLUMNS]
    missing = [name for name in REQUIRED_COLUMNS if name not in columns]
    if unknown or missing:
        raise ParameterError(f"a recording's columns: {', '.join(unknown + missing)} "
                             f"{'not known' if unknown else 'missing'}; accepted: {', '.join(COLUMNS)}, with "
                             f"{', '.join(REQUIRED_COLUMNS)} required")
    samples = [np.asarray(v, dtype=float) for v in columns.values()]
    if len({len(v) for v in samples}) != 1:
        raise ParameterError(f"a recording's columns differ in length: {[len(v) for v in samples]}")
    path = Path(path)
    with open(path, "w", encoding="utf-8") as f:
        f.write(",".join(columns) + "\n")
        for row in zip(*samples):
            f.write(",".join(repr(float(x)) for x in row) + "\n")
    return path


def read_csv(path: str | Path, *, m1: float | None = None, columns: Mapping[str, str] | None = None) -> Recording:
    """Read a recording from a CSV file with a header row.

    Args:
        path: the file.
        m1: chassis mass during the recording, kg (None: the cart's).
        columns: our column name (:data:`COLUMNS`) -> the file's header name, for files that name them otherwise.

    Returns:
        The :class:`Recording` (not yet checked: :func:`check_recording`).

    Raises:
        ParameterError: an unreadable file, a missing column, a header in other units than ours, a cell that is
            not a number (one line naming the file, the row and the column).
    """
    path = Path(path)
    mapping = {key: key for key in COLUMNS}
    mapping.update(columns or {})
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
    except (OSError, UnicodeDecodeError) as exc:
        raise ParameterError(f"recording {str(path)!r} cannot be read: {exc}") from None
    if not rows:
        raise ParameterError(f"recording {str(path)!r} is empty; accepted: a CSV file with the header "
                             f"{','.join(REQUIRED_COLUMNS)}[,speed_m_per_s] and one row per control step")
    header = [h.strip() for h in rows[0]]
    for name in header:
        if name in _OTHER_UNITS and mapping.get(_OTHER_UNITS[name]) not in header:
            raise ParameterError(f"recording {str(path)!r}: column {name!r} is in other units than accepted; accepted: "
                                 f"{_OTHER_UNITS[name]!r} ({COLUMNS[_OTHER_UNITS[name]]}): convert it to SI units")
    index: dict[str, int] = {}
    for key in COLUMNS:
        name = mapping[key]
        if name in header:
            index[key] = header.index(name)
        elif key in REQUIRED_COLUMNS:
            raise ParameterError(f"recording {str(path)!r}: column {name!r} ({COLUMNS[key]}) is missing; the header "
                                 f"is {','.join(header)!r}; accepted: {','.join(REQUIRED_COLUMNS)}[,speed_m_per_s], "
                                 "or --columns to map other names")
    data = np.full((len(rows) - 1, len(index)), np.nan)
    keys = list(index)
    for i, row in enumerate(rows[1:]):
        for j, key in enumerate(keys):
            cell = row[index[key]].strip() if index[key] < len(row) else ""
            try:
                data[i, j] = float(cell) if cell else math.nan
            except ValueError:
                raise ParameterError(f"recording {str(path)!r}: row {i + 2}, column {mapping[key]!r} = {cell!r} is not "
                                     "a number") from None
    col = {key: data[:, j].copy() for j, key in enumerate(keys)}
    return Recording(name=str(path), sha256=file_sha256(path), t=col["t_s"], voltage=col["u_V"],
                     alpha=col["alpha_rad"], speed=col.get("speed_m_per_s"), m1=m1, applied=col.get("u_applied_V"))


def check_recording(rec: Recording, *, voltage_limit: float, steering_range: float,
                    min_duration: float = MIN_RECORDING_S) -> None:
    """Refuse what identification cannot use, in one line.

    Args:
        rec: the recording.
        voltage_limit: the cart's supply, V: |u| beyond it (by more than :data:`SUPPLY_TOLERANCE`) is refused.
        steering_range: the cart's stops, rad: |alpha| beyond them is refused.
        min_duration: the shortest recording accepted, s.

    Raises:
        ParameterError: a row with NaN, time not increasing, a gap (a step above :data:`GAP_TOLERANCE` times the
            median), a constant voltage or angle, a recording shorter than ``min_duration``, an angle beyond the
            stops, a voltage beyond the supply.
    """
    name = rec.name
    arrays = {"t_s": rec.t, "u_V": rec.voltage, "alpha_rad": rec.alpha}
    if rec.speed is not None:
        arrays["speed_m_per_s"] = rec.speed
    if rec.applied is not None:
        arrays["u_applied_V"] = rec.applied
    for key, values in arrays.items():
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise ParameterError(f"recording {name!r}: {bad.size} rows with {key} not a number (NaN or empty), the "
                                 f"first at data row {int(bad[0]) + 1}; accepted: every cell a finite number (drop or "
                                 "repair those rows)")
    if rec.samples < 3:
        raise ParameterError(f"recording {name!r} has {rec.samples} rows; accepted: at least {min_duration:g} s of "
                             "rows at the control rate")
    dt = np.diff(rec.t)
    back = np.flatnonzero(dt <= 0.0)
    if back.size:
        k = int(back[0])
        raise ParameterError(f"recording {name!r}: time goes backwards or stands still at data row {k + 2} "
                             f"(t = {rec.t[k]:.9g} s, then {rec.t[k + 1]:.9g} s); accepted: t_s strictly increasing")
    period = float(np.median(dt))
    gaps = np.flatnonzero(dt > GAP_TOLERANCE * period)
    if gaps.size:
        k = int(gaps[0])
        raise ParameterError(f"recording {name!r}: a gap of {dt[k]:.6g} s after t = {rec.t[k]:.9g} s ({gaps.size} "
                             f"gaps in all), the control period being {period:.6g} s; accepted: one row per control "
                             f"step, no step above {GAP_TOLERANCE:g} periods (split the recording at its gaps)")
    if rec.duration < min_duration:
        raise ParameterError(f"recording {name!r} is {rec.duration:.6g} s long; accepted: at least {min_duration:g} s "
                             "(identification compares simulated and recorded angles over 1 s segments)")
    for key, values in (("u_V", rec.voltage), ("alpha_rad", rec.alpha)):
        if float(np.ptp(values)) == 0.0:
            raise ParameterError(f"recording {name!r}: {key} is constant ({values[0]:.6g}); accepted: a recording in "
                                 "which the steering moves under a varying voltage (wmr-mj excite writes one to play)")
    worst = int(np.argmax(np.abs(rec.alpha)))
    if abs(rec.alpha[worst]) > steering_range:
        raise ParameterError(f"recording {name!r}: alpha_rad = {rec.alpha[worst]:.6g} rad at t = {rec.t[worst]:.9g} s "
                             f"is beyond the cart's stops +-{steering_range:g} rad; accepted: |alpha| <= "
                             "steering_range (a wrong unit, zero or sign, or the wrong cart file)")
    worst = int(np.argmax(np.abs(rec.voltage)))
    if abs(rec.voltage[worst]) > voltage_limit * (1.0 + SUPPLY_TOLERANCE):
        raise ParameterError(f"recording {name!r}: u_V = {rec.voltage[worst]:.6g} V at t = {rec.t[worst]:.9g} s is "
                             f"beyond the cart's supply +-{voltage_limit:g} V; accepted: |u| <= voltage_limit (the "
                             "voltage applied after the limit, not the controller's command)")
    if rec.m1 is not None and not (math.isfinite(rec.m1) and rec.m1 > 0):
        raise ParameterError(f"recording {name!r}: m1 = {rec.m1!r} kg; accepted: a finite mass > 0")
