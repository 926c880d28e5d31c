"""How tight the claim is on every covered cart: E_max beside the worst sup|E| an adversary finds.

For each cart of ``examples/cart_as_built.py`` whose claim certifies the certified design (``--preset
certified``), on each path: section 4's E_max, the sampled-data certificate's E_max, the one the run takes, the
worst sup|E| that ``falsify`` finds over the m1 box (550-750 kg) at the given budget (its search and as many
random runs, both counted; objective sup-E), tightness = worst found / E_max taken, the guide's old tightness
of the error term alone where one applies (``docs/guides/certificates.md``, "Tightness": 0.076 for a delay,
0.071 for an encoder's quantised angle), and the verdicts of every run. The carts no claim covers are listed
below the table with what is unmet. Built on :func:`wmr_mj.experiments.tightness.cart_tightness`.

With ``--binding`` it runs nothing: per cart and path, the certificate the run takes and which term of it binds
(the Coulomb sign's charge, its share of W0 and of E_max, the largest other term; ``docs/guides/certificates.md``,
"Sampling bounded on every cart").

Usage::

    python examples/tightness_table.py                       # budget 64, 35 s, 2 paths: about 15 min on 1 core
    python examples/tightness_table.py --budget 5 --duration 10 --cart ideal --json out.json   # seconds
    python examples/tightness_table.py --binding             # the binding terms, no run: about a minute
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import wmr_mj as wm
from wmr_mj.experiments.tightness import CartTightness, cart_tightness
from wmr_mj.sim.parts import resolve_run

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cart_as_built import CASES  # noqa: E402  (the hardware guide's table of carts, one list)

#: the guide's old tightness of the error term alone (certificates.md, "Tightness", 2026-11-26): the delay term's
#: (a PD loop with a 2 ms sensing delay) and the quantised angle's (4 ticks of 12 bits on the reduced model)
OLD_TIGHTNESS = {"delay": 0.076, "encoder": 0.071}
HEADER = ("| cart | path | E_max today (section 4) [rad] | E_max sampled-data [rad] | E_max taken [rad] | "
          "worst sup\\|E\\| found [rad] (m1 [kg]) | tightness | old (error term) | verdicts |")


def old_tightness(changes: dict) -> float | None:
    """The guide's old tightness of the error term this cart adds, or None where none applies."""
    spec = f"{changes.get('sensing', '')},{changes.get('actuation', '')}"
    if "delay" in spec:
        return OLD_TIGHTNESS["delay"]
    if "encoder" in spec or "bit" in spec or "motor" in spec:
        return OLD_TIGHTNESS["encoder"]
    return None


def _rad(value: float | None) -> str:
    return "none" if value is None else f"{value:.4f}"


def row(name: str, t: CartTightness, old: float | None) -> str:
    """The table's markdown row of one cart on one path."""
    verdicts = ", ".join(f"{k} {v}" for k, v in sorted(t.verdicts.items()))
    where = ", ".join(f"{v:.0f}" for v in t.worst_params.values())
    tight = "-" if t.tightness is None else f"{t.tightness:.2f}"
    return (f"| {name} | {t.path} | {_rad(t.E_max_section4)} | {_rad(t.E_max_sampled)} | {_rad(t.E_max)} "
            f"({t.certificate}) | {t.worst_sup_E:.5f} ({where}) | {tight} | {'-' if old is None else old} | "
            f"{verdicts} |")


#: the parts of the sampled-data certificate's W0 (SampledDataTerms), rad/s^2
W0_PARTS = ("friction_term", "P_term", "feedforward_hold_term", "C_V_term", "K_term", "gyro_term", "disturbance_term")
BINDING_HEADER = ("| cart | path | E_max taken [rad] | certified | friction term [rad/s^2] | share of W0 | "
                  "friction's part of E_max [rad] | the largest other term of W0 [rad/s^2] |")


def binding_row(name: str, path: str, claim) -> str:
    """The markdown row of one cart on one path: which term of the claim taken binds. The friction's part of E_max
    is g_E,w x friction term / (1 - lambda): what the Coulomb sign's charge alone drives through the sampled loop."""
    terms = claim.inputs.get("terms") if claim is not None else None
    if terms is None:
        reason = claim.reason if claim is not None else "no claim"
        return f"| {name} | {path} | none | no | - | - | - | {reason} |"
    t = terms.to_dict() if hasattr(terms, "to_dict") else dict(terms)
    parts = {k: t[k] or 0.0 for k in W0_PARTS}
    other = max((k for k in W0_PARTS if k != "friction_term"), key=lambda k: parts[k])
    friction = t["gain_E_w"] * t["friction_term"] / (1.0 - t["loop_gain"])
    return (f"| {name} | {path} | {claim.E_max:.4f} | {'yes' if claim.certified else 'no'} | "
            f"{t['friction_term']:.3f} | {t['friction_term'] / sum(parts.values()):.2f} | {friction:.4f} "
            f"({friction / claim.E_max:.2f} of E_max) | {other.removesuffix('_term')} {parts[other]:.3f} |")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=int, default=64, help="falsify's budget per cart and path (default 64)")
    ap.add_argument("--duration", type=float, default=35.0, help="each run's length, s (default 35)")
    ap.add_argument("--paths", default="paper-circle,lane-change", help="comma-separated paths")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--nthread", type=int, default=1)
    ap.add_argument("--cart", action="append", help="only this cart of the table (repeatable; default: all)")
    ap.add_argument("--json", metavar="FILE", help="also write every number to FILE")
    ap.add_argument("--binding", action="store_true", help="run nothing: which term of each certificate binds")
    args = ap.parse_args(argv)
    cases = [c for c in CASES if args.cart is None or c[0] in args.cart]
    if args.cart is not None and len(cases) != len(set(args.cart)):
        known = ", ".join(repr(c[0]) for c in CASES)
        ap.error(f"--cart: {sorted(set(args.cart) - {c[0] for c in cases})} not in the table; one of {known}")
    base = wm.RunConfig(**wm.CERTIFIED.config_changes(), duration=args.duration)
    if args.binding:
        print(BINDING_HEADER)
        print("|---|---|---|---|---|---|---|---|")
        for name, changes in cases:
            for path in args.paths.split(","):
                print(binding_row(name, path, resolve_run(base.replace(**changes, path=path)).claim), flush=True)
        return
    print(HEADER)
    print("|---|---|---|---|---|---|---|---|---|", flush=True)
    out, uncovered = [], []
    for name, changes in cases:
        for path in args.paths.split(","):
            config = base.replace(**changes, path=path)
            claim = resolve_run(config).claim
            if claim is None or not claim.certified:
                unmet = ", ".join(claim.unmet) if claim is not None else "no claim"
                uncovered.append((name, path, unmet or (claim.reason if claim is not None else "")))
                continue
            t = cart_tightness(config, budget=args.budget, seed=args.seed, nthread=args.nthread)
            old = old_tightness(changes)
            print(row(name, t, old), flush=True)
            out.append({"cart": name, "changes": {k: str(v) for k, v in changes.items()}, "old_tightness": old,
                        "tightness": t.tightness, **{k: getattr(t, k) for k in (
                            "path", "certificate", "certified", "E_max", "E_max_section4", "E_max_sampled",
                            "worst_sup_E", "search_sup_E", "random_sup_E", "runs", "budget", "seed")},
                        "worst_params": dict(t.worst_params), "verdicts": dict(t.verdicts)})
    print()
    for name, path, unmet in uncovered:
        print(f"not covered: {name} on {path}: {unmet}")
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": out, "uncovered": [list(u) for u in uncovered],
                                               "duration": args.duration, "budget": args.budget}, indent=1))


if __name__ == "__main__":
    main()
