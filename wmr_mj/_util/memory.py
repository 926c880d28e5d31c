"""Refuse jobs whose arrays would not fit in memory, before they start.

A run keeps every control step's row (``simulate.ROW_FIELDS``) and its reference
(alpha0 and its rates, the path of A and C, the arc length, curvature...) as
float64 arrays, plus temporaries while the reference is built: measured peak
resident memory grows by 240-300 bytes per control step (paper circle 100 vs 800 s,
lane change 50 vs 400 s), so :data:`RUN_BYTES_PER_STEP` allows 40 float64.

Usage::

    from wmr_mj._util.memory import require_run_memory
    require_run_memory(duration_s=1e9, control_period_s=1e-3)  # raises NotEnoughMemoryError
"""

from __future__ import annotations

import os

from wmr_mj.errors import NotEnoughMemoryError

__all__ = ["RUN_BYTES_PER_STEP", "available_memory_bytes", "format_bytes", "require_memory", "require_run_memory"]

#: Memory one closed-loop run holds per control step, bytes (40 float64; measured 240-300).
RUN_BYTES_PER_STEP = 40 * 8


def available_memory_bytes() -> int | None:
    """Memory available to a new allocation, bytes: MemAvailable of /proc/meminfo, else the
    physical memory (sysconf); None where neither is known."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_PHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def format_bytes(n: float) -> str:
    """``n`` bytes as B, KiB ... EiB with three significant digits."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024:
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} EiB"


def require_memory(needed_bytes: float, *, what: str, hint: str = "") -> None:
    """Raise NotEnoughMemoryError if ``needed_bytes`` exceeds the memory available now.

    what: the job, as the message names it; hint: what the user can change.
    Does nothing where the available memory cannot be read.
    """
    available = available_memory_bytes()
    if available is None or needed_bytes <= available:
        return
    tail = f"; {hint}" if hint else ""
    raise NotEnoughMemoryError(f"{what} would need about {format_bytes(needed_bytes)} of memory, "
                               f"{format_bytes(available)} is available{tail}")


def require_run_memory(*, duration_s: float, control_period_s: float) -> None:
    """Refuse a closed-loop run of ``duration_s`` whose rows would not fit in memory."""
    steps = duration_s / control_period_s
    require_memory(steps * RUN_BYTES_PER_STEP,
                   what=f"a run of {duration_s:g} s ({steps:.3g} control steps of {control_period_s:g} s)",
                   hint="give a shorter --duration or a longer --control-period")
