"""The recordings a cart file rests on: the (file, SHA-256) pairs its identified sources name.

``wmr-mj identify --data`` writes each identified parameter's source as "identified from FILE (SHA-256 ...) and
FILE (SHA-256 ...), 95 % interval [lo, hi] ..." (:func:`wmr_mj.plant.identified_cart.provenance`); a design found on
such a cart records them (the design file's ``cart.identified_from``) and ``validate`` names them in its first
lines. Light on purpose (the standard library and the cart sections only): the design writer imports it.

Usage::

    from wmr_mj.carts.provenance import identified_from
    identified_from(Path("new.toml").read_text())   # (("lane.csv", "8ab8..."), ("eight.csv", "e180..."))
"""

from __future__ import annotations

import functools
import re
import tomllib
from collections.abc import Mapping

from wmr_mj.carts import PARAMETER_SECTIONS

__all__ = ["identified_from", "identified_from_line", "delay_split_unknown"]

#: 'FILE (SHA-256 HEX)' in a source, after the 'identified from ' or the ' and ' that joins it to the one before
_NAMED_FILE = re.compile(r"(?:identified from | and )(.+?) \(SHA-256 ([0-9a-f]{64})\)")


def identified_from(text: str) -> tuple[tuple[str, str], ...]:
    """(file, SHA-256) of each recording a cart file's text names as the data of an identified parameter, each
    once, in the order first named; () for a cart written by hand, or text that is no TOML."""
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        return ()
    named: dict[tuple[str, str], None] = {}
    for section in PARAMETER_SECTIONS:
        entries = document.get(section)
        for entry in entries.values() if isinstance(entries, Mapping) else ():
            source = entry.get("source") if isinstance(entry, Mapping) else None
            if isinstance(source, str) and source.startswith("identified from "):
                head = source.split(", 95 % interval", 1)[0]
                named.update(dict.fromkeys((m.group(1), m.group(2)) for m in _NAMED_FILE.finditer(head)))
    return tuple(named)


def identified_from_line(text: str, cart: str) -> str | None:
    """One line naming the data the cart ``cart`` (its name, as the outputs print it) rests on and what a
    certificate on it then assumes; None for a cart no recording identified."""
    named = identified_from(text)
    if not named:
        return None
    files = " and ".join(f"{name} (SHA-256 {sha[:12]}...)" for name, sha in named)
    split = ("; they cover the measured delay in any split between sensing and actuation (the data fix only its sum)"
             if delay_split_unknown(text) else "")
    return (f"the cart {cart} is identified from {files}: its certificates hold for the real cart if the real cart "
            f"lies inside the identified box, which those data support at 95 % per parameter{split}")


@functools.lru_cache(maxsize=16)  # read once per cart text: every resolution and design candidate asks
def delay_split_unknown(text: str) -> bool:
    """Whether a cart file's text says that only the sum of its sensing and actuation delays is known
    (``[defaults.delay_split]`` 'unknown': written by ``identify --data``): the one reader of that key (the
    certificates' ``wmr_mj.sim.certify.delay_split_of`` and the reports' words ask it)."""
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        return False
    entry = document.get("defaults", {}).get("delay_split")
    return isinstance(entry, Mapping) and entry.get("value") == "unknown"
