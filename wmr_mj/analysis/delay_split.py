"""A certificate over every split of a delay known only as its total (issue 43: the sensing and actuation delays).

Recordings taken at the controller (the voltage it commanded, the angle its encoder read) fix the whole
voltage-to-angle delay d = d_s + d_a, not how it divides: a pure delay commutes with a time-invariant plant. The
sampled-data certificate treats the two differently (the feedforward is delayed by d_a only; measured on the
identified cart of ``tests/test_identify_walk.py``, E_max 0.0430 rad with d = 5 periods all in sensing against
0.0347 rad all in actuation), so a certificate on such a cart is computed for each split of the whole periods,
d_s = d, d - 1, ..., 0, and the worst is claimed: certified only where every split is, each split's own
assumptions checked (``docs/guides/certificates.md``, "A delay known only as its total").

Usage::

    from wmr_mj.analysis.delay_split import delay_splits, worst_over_splits
    splits = delay_splits(5)                          # ((5, 0), (4, 1), ..., (0, 5)): (d_s, d_a) in periods
    cert = worst_over_splits({s: certify(s) for s in splits}, control_period=0.001, simulated=(5, 0))
    cert.E_max                                        # the largest E_max of the six; the inputs list each
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping

from wmr_mj.analysis.claim_types import Assumption, Certificate
from wmr_mj.analysis.regions import BoxRegion
from wmr_mj.errors import ParameterError

__all__ = ["DELAY_SPLIT_COVERED", "DELAY_SPLITS", "delay_splits", "worst_over_splits", "split_label",
           "covered_split", "covers_delay_split"]

#: The assumption a certificate over every split adds: every split of the total certified.
DELAY_SPLIT_COVERED = "delay split covered"
#: How a cart file says how its delay divides (``[defaults.delay_split]``, ``docs/reference/cart.md``): 'known' (the
#: sensing and actuation delays as written, the default where the file has none), 'unknown' (only their sum).
DELAY_SPLITS = ("known", "unknown")

Split = tuple[int, int]


def delay_splits(total_periods: int) -> tuple[Split, ...]:
    """Every split (d_s, d_a) of ``total_periods`` whole control periods, all sensing first.

    Raises:
        ParameterError: a total that is not a whole number >= 0.
    """
    if isinstance(total_periods, bool) or not isinstance(total_periods, int) or total_periods < 0:
        raise ParameterError(f"delay split: a total of {total_periods!r} control periods is not accepted; a whole "
                             "number >= 0 is required")
    return tuple((d_s, total_periods - d_s) for d_s in range(total_periods, -1, -1))


def split_label(total_periods: int, control_period: float) -> str:
    """'delay 5 ms, any split sensing/actuation' (the words a verdict carries)."""
    return f"delay {total_periods * control_period * 1e3:g} ms, any split sensing/actuation"


def covered_split(assumptions: Iterable[Assumption]) -> str | None:
    """'delay 5 ms, any split sensing/actuation' where the assumptions (a certificate's, or a design file's) hold
    :data:`DELAY_SPLIT_COVERED` met; None where the certificate was not computed over the splits or one failed."""
    for a in assumptions:
        if a.name == DELAY_SPLIT_COVERED and a.met:
            return a.equation.split(": ", 1)[1]
    return None


def _split_assumption(total_periods: int, control_period: float, *, met: bool, value: float, limit: float,
                      note: str) -> Assumption:
    return Assumption(DELAY_SPLIT_COVERED,
                      f"every split d_s + d_a = {total_periods} control periods certified: "
                      f"{split_label(total_periods, control_period)}", met, value, limit, note, kind="checked")


def covers_delay_split(cert: Certificate, *, total_periods: int, control_period: float) -> Certificate:
    """``cert`` on a cart whose delay split is unknown: unchanged where the delay is 0 or the claim states
    :data:`DELAY_SPLIT_COVERED` itself; else with it unmet (a plug-in's claim computed on the split the run
    simulates covers that split only), as :func:`wmr_mj.analysis.claim.covers_measurement` does for sensing."""
    if total_periods == 0 or any(a.name == DELAY_SPLIT_COVERED for a in cert.assumptions):
        return cert
    note = (f"{cert.claimant or 'the claim'} does not state that it covers every split of the delay (only its sum "
            "is known); a claim computed on each split, or on the sum as one delay, states it")
    return dataclasses.replace(cert, assumptions=(*cert.assumptions, _split_assumption(
        total_periods, control_period, met=False, value=0.0, limit=float(total_periods + 1), note=note)))


def _severity(cert: Certificate) -> tuple[bool, bool, float]:
    """The order of 'worse': no bound, then not certified, then the larger E_max."""
    return (not cert.valid, not cert.certified, cert.E_max)


def worst_over_splits(certificates: Mapping[Split, Certificate], *, control_period: float,
                      simulated: Split | None = None) -> Certificate:
    """The certificate over every split: the worst split's, its region the box of the largest E_max and Edot_max.

    Worst: a split with no bound, else one not certified, else the largest E_max (the first of equals, all
    sensing first). Its assumptions are kept (its split's own checks) and :data:`DELAY_SPLIT_COVERED` added: met
    where every split is certified, its note listing each split's E_max. ``alpha_max`` and ``voltage_max`` are the
    largest over the splits. ``inputs['delay_split']`` records the total, the split the run simulates and each
    split's E_max, voltage bound and verdict.

    Args:
        certificates: (d_s, d_a) -> the certificate on that split; every split of one total (:func:`delay_splits`).
        control_period: T, s (the label's milliseconds).
        simulated: the split the run's plant runs (None: not said).

    Raises:
        ParameterError: no certificate, or splits of different totals.
    """
    if not certificates:
        raise ParameterError("delay split: no certificate to take the worst of")
    totals = {d_s + d_a for d_s, d_a in certificates}
    if len(totals) != 1:
        raise ParameterError(f"delay split: the splits {sorted(certificates)} are not of one total")
    (total,) = totals
    splits = sorted(certificates, reverse=True)  # all sensing first, as delay_splits orders them
    worst_split = max(splits, key=lambda s: _severity(certificates[s]))  # max: the first of equals
    worst = certificates[worst_split]
    valid = all(certificates[s].valid for s in splits)
    label = split_label(total, control_period)
    failed = [s for s in splits if not certificates[s].certified]
    each = "; ".join(f"{d_s}+{d_a}: " + (f"E_max {certificates[(d_s, d_a)].E_max:.4g} rad"
                                          if certificates[(d_s, d_a)].valid else "no bound")
                     + ("" if certificates[(d_s, d_a)].certified else " (not certified: "
                        + ", ".join(certificates[(d_s, d_a)].unmet or ("no bound",)) + ")")
                     for d_s, d_a in splits)
    covered = _split_assumption(
        total, control_period, met=not failed, value=float(len(splits) - len(failed)), limit=float(len(splits)),
        note=f"sensing+actuation periods: {each}; the worst {worst_split[0]}+{worst_split[1]} is claimed"
        + ("" if simulated is None else f"; the run simulates {simulated[0]}+{simulated[1]}")
        + "; only their sum is known")
    region = worst.region
    if valid and all(isinstance(certificates[s].region, BoxRegion) for s in splits):  # the box of the boxes
        region = BoxRegion(E_max=max(certificates[s].E_max for s in splits),
                           Edot_max=max(certificates[s].Edot_max for s in splits))
    record = {"total_periods": total, "control_period_s": control_period, "label": label,
              "worst": list(worst_split), "simulated": None if simulated is None else list(simulated),
              "splits": [{"sensing_periods": d_s, "actuation_periods": d_a,
                          "E_max": certificates[(d_s, d_a)].E_max if certificates[(d_s, d_a)].valid else None,
                          "voltage_max": (certificates[(d_s, d_a)].voltage_max if certificates[(d_s, d_a)].valid
                                          else None),
                          "certified": certificates[(d_s, d_a)].certified} for d_s, d_a in splits]}
    return dataclasses.replace(
        worst, region=region, valid=valid, assumptions=(*worst.assumptions, covered),
        alpha_max=max(certificates[s].alpha_max for s in splits),
        voltage_max=max(certificates[s].voltage_max for s in splits),
        inputs=worst.inputs.with_record({**worst.inputs.to_dict(), "delay_split": record}))
