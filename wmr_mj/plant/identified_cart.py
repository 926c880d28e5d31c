"""The cart file identification writes: the start with every identified value replaced, each with its source.

Every parameter of :data:`wmr_mj.plant.output_error.IDENTIFIED_PARAMETERS` gets the identified value and the
source ``identified from FILE (SHA-256 ...), 95 % interval [lo, hi]``; the 'full' uncertainty box gets those
intervals as its ranges (m1's range stays the start's, widened to hold every recording's m1); ``defaults.sensing``
carries the measured encoder, delay and noise (the start's velocity estimate kept: a recording of the angle
does not say how the board differences it; 'exact' becomes 'difference', what a board with an encoder does).
The measured delay is the voltage-to-angle one, sensing and actuation together: ``defaults.sensing`` runs all of it
(the start's actuation delay, if any, set to 0) and ``[defaults.delay_split]`` is 'unknown', so that every
certificate on the file covers each split of it (:mod:`wmr_mj.analysis.delay_split`).
The file is checked as any cart file is (:func:`wmr_mj.carts.load_cart_text`) before it is returned.

Usage::

    from wmr_mj.plant.identified_cart import identified_cart_text
    text = identified_cart_text(start_cart, fit, recordings, date="2026-11-28")
"""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib
from collections.abc import Mapping, Sequence
from typing import Any

from wmr_mj.carts import PARAMETER_SECTIONS, CartFile, load_cart_text
from wmr_mj.hardware.actuation import Actuation
from wmr_mj.hardware.sensing import Sensing
from wmr_mj.params import parameters_of_cart
from wmr_mj.plant.output_error import IDENTIFIED_PARAMETERS, SteeringFit
from wmr_mj.plant.recordings import Recording

__all__ = ["identified_cart_text", "sensing_of_fit", "provenance"]


def provenance(recordings: Sequence[Recording]) -> str:
    """'FILE (SHA-256 abc...)' for each recording, joined by ' and '."""
    return " and ".join(f"{rec.name} (SHA-256 {rec.sha256})" for rec in recordings)


def sensing_of_fit(start: CartFile, fit: SteeringFit) -> Sensing:
    """The start's default sensing with the measured encoder (on the axis, rounding), delay and noise (the delay: the
    whole voltage-to-angle delay, or that less the actuation delay where ``u_applied_V`` measured it)."""
    base = Sensing.from_spec(start.defaults["sensing"])
    velocity = "difference" if base.velocity == "exact" else base.velocity
    noise = fit.noise_rad * math.sqrt(3.0)  # uniform on [-B, B) has the standard deviation B/sqrt(3)
    return dataclasses.replace(
        base, encoder_ticks=fit.encoder_ticks, encoder_side="axis", encoder_rounding="round", velocity=velocity,
        filter_tau=base.filter_tau if velocity == "filtered" else None, delay=fit.sensing_steps * fit.period,
        noise_kind="uniform" if noise > 0 else "none", noise=noise)


def _spec_text(sensing: Sensing) -> str:
    pairs = []
    for key, value in sensing.to_dict().items():
        if value is None or value == "none" or (key == "delay" and value == 0.0) or (key == "seed" and value == 0):
            continue
        pairs.append(f"{key}={value!r}" if isinstance(value, float) else f"{key}={value}")
    return ",".join(pairs) if pairs else "ideal"


def _write_actuation(document: dict[str, Any], start: CartFile, fit: SteeringFit, made_of: str) -> None:
    """defaults.actuation (the start's, its delay the measured one or 0) and [defaults.delay_split]."""
    actuation = Actuation.from_spec(start.defaults["actuation"])
    delay = (fit.actuation_steps or 0) * fit.period
    entry = document["defaults"]["actuation"]
    if actuation.delay != delay:  # measured, or held by the measured voltage-to-angle delay: not counted twice
        entry["value"] = _actuation_text(dataclasses.replace(actuation, delay=delay))
        entry["source"] = (f"delay {delay:g} s " + (
            "(the measured voltage-to-angle delay in defaults.sensing holds the start's)" if fit.actuation_steps is None
            else f"measured from u_applied_V in {made_of}") + f"; the rest the start's: {entry['source']}")
    if fit.actuation_steps is None:
        document["defaults"]["delay_split"] = {
            "value": "unknown",
            "source": (f"measured from {made_of}: the voltage the controller applied and the angle its encoder read "
                       f"fix only the sum of the sensing and actuation delays, {fit.delay_steps} control periods of "
                       f"{fit.period:g} s (a pure delay commutes with the plant); each lies in [0, {fit.delay.hi:g}] "
                       "s. A run simulates all of it as sensing (defaults.sensing); every certificate covers each "
                       "split of the sum in whole control periods, the worst claimed"),
        }
    else:
        a = fit.actuation_delay
        document["defaults"]["delay_split"] = {
            "value": "known",
            "source": (f"measured from {made_of}: the voltage at the motor (u_applied_V) follows the voltage the "
                       f"controller applied by {fit.actuation_steps} control periods, 95 % interval [{a.lo:g}, "
                       f"{a.hi:g}] s (the actuation delay, defaults.actuation); the rest of the {fit.delay_steps} "
                       "periods from the voltage to the angle is the sensing delay (defaults.sensing)"),
        }


def _actuation_text(actuation: Actuation) -> str:
    pairs = [f"{key}={value!r}" for key, value in actuation.to_dict().items() if value not in (None, 0.0)]
    return ",".join(pairs) if pairs else "ideal"


def _bump_minor(version: str) -> str:
    major, minor, _patch = (int(x) for x in version.split("."))
    return f"{major}.{minor + 1}.0"


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v))
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {v!r} to a cart file")


def _table(lines: list[str], name: str, entries: Mapping[str, Any]) -> None:
    lines.append(f"[{name}]")
    lines.extend(f"{key} = {_value(value)}" for key, value in entries.items())


def _dump(document: Mapping[str, Any], header: str) -> str:
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    lines.append("")
    lines.append(f"name = {_value(document['name'])}")
    lines.append(f"version = {_value(document['version'])}")
    lines.append("changelog = [")
    lines.extend(f"  {_value(line)}," for line in document["changelog"])
    lines.append("]")
    for section in PARAMETER_SECTIONS:
        lines.append("")
        for name, entry in document[section].items():
            _table(lines, f"{section}.{name}", entry)
    lines.append("")
    for box, ranges in document["uncertainty"].items():
        for name, entry in ranges.items():
            _table(lines, f"uncertainty.{box}.{name}", entry)
    lines.append("")
    for key, entry in document["defaults"].items():
        _table(lines, f"defaults.{key}", entry)
    return "\n".join(lines) + "\n"


def identified_cart_text(start: CartFile, fit: SteeringFit, recordings: Sequence[Recording], *, date: str,
                         command: str = "wmr-mj identify") -> str:
    """The identified cart file's text (checked).

    Args:
        start: the cart file identification started from.
        fit: what the recordings said.
        recordings: the recordings it was fitted to (their files and SHA-256 are named in every source).
        date: the changelog's date, YYYY-MM-DD.
        command: the command line, for the file's header.

    Raises:
        ParameterError: an identified value the cart file refuses (a negative front-beam mass: the steering's
            inertia below its wheels'; the message says which).
    """
    document = tomllib.loads(start.text)
    made_of = provenance(recordings)
    section_of = {name: s for s in PARAMETER_SECTIONS for name in document[s]}
    full = document["uncertainty"]["full"]
    for name in IDENTIFIED_PARAMETERS:
        iv = fit.physical[name]
        entry = document[section_of[name]][name]
        entry["value"] = iv.value
        entry["source"] = (f"identified from {made_of}, 95 % interval [{iv.lo:.6g}, {iv.hi:.6g}] {entry['unit']} "
                           f"(output error, block bootstrap over {fit.segments} segments of {fit.segment_steps} "
                           f"control periods; {IDENTIFIED_PARAMETERS[name]})")
        full[name] = {"range": [iv.lo, iv.hi], "unit": entry["unit"],
                      "source": f"the 95 % interval identified from {made_of}"}
    m1s = list(fit.m1)
    for box in document["uncertainty"].values():
        lo, hi = box["m1"]["range"]
        if min(m1s) < lo or max(m1s) > hi:
            box["m1"]["range"] = [min(lo, *m1s), max(hi, *m1s)]
            box["m1"]["source"] += f"; widened to hold the recordings' m1 ({', '.join(f'{m:g}' for m in m1s)} kg)"
    sensing = sensing_of_fit(start, fit)
    encoder = ("not readable (the angle is not on one grid)" if fit.encoder_ticks is None
               else f"{fit.encoder_ticks} ticks per revolution read from the angle's quantisation ("
                    + ("every reading a whole number of ticks)" if fit.noise_rad == 0.0
                       else "the readings concentrate on its grid through the noise)"))
    total = (f"{fit.delay_steps} control periods of {fit.period:g} s, 95 % interval [{fit.delay.lo:g}, "
             f"{fit.delay.hi:g}] s")
    if fit.actuation_steps is None:
        delay = (f"delay {total} (the voltage-to-angle delay, sensing and actuation together: run as sensing, its "
                 "split unknown, [defaults.delay_split])")
    else:
        s_iv = fit.sensing_delay
        delay = (f"delay {fit.sensing_steps} control periods, 95 % interval [{s_iv.lo:g}, {s_iv.hi:g}] s: the "
                 f"voltage-to-angle delay ({total}) less the actuation delay (defaults.actuation)")
    document["defaults"]["sensing"] = {
        "value": _spec_text(sensing),
        "source": (f"measured from {made_of}: encoder {encoder}; {delay}; noise {fit.noise_rad:.3g} rad standard "
                   "deviation beyond the quantisation (written as uniform of the same variance); the velocity "
                   "estimate is the start's (not in the recording)"),
    }
    _write_actuation(document, start, fit, made_of)
    version = _bump_minor(document["version"])
    document["version"] = version
    document["changelog"] = [f"{version} ({date}): identified by {command} from {made_of}: "
                             f"{', '.join(IDENTIFIED_PARAMETERS)} and the sensing; every other number the start's "
                             f"({start.name} {start.version})", *document["changelog"]]
    header = (f"{document['name']}: identified from recordings by {command} ({date}).\n"
              f"Started from {start.path} ({start.name} {start.version}); identified: "
              f"{', '.join(IDENTIFIED_PARAMETERS)}, the sensing delay, the encoder and the noise (each source says "
              "from what). Fixed from the start: the rest.")
    text = _dump(document, header)
    cart = load_cart_text(text, path="<identified cart>")
    parameters_of_cart(cart)
    return text
