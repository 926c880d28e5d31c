"""The certified design on the cart as it is built: one run per sensing, actuation and play, with its verdict.

Each row is one 35 s run of the certified design (``--preset certified``) on the paper's circle at
m1 = 750 kg, the worst mass of the box: sup|E|, the claim's bound E_max for this cart (none where the
extended certificate does not close), sup|E| over the ideal cart's bound (0.0408 rad for the certified design
since 2026-11-28, omega_r 30; the sampled-data one since issue 44), the verdict, the unmet assumptions, and
the voltage's activity (RMS u, total variation of u per second).

Usage::

    python examples/cart_as_built.py            # about 20 s with the compiled law
"""

from __future__ import annotations

import numpy as np

import wmr_mj as wm
from wmr_mj.analysis.verdicts import unmet_assumptions

DURATION_S = 35.0
CASES = (
    ("ideal", {}),
    ("12-bit axis encoder, differenced", {"sensing": "magnetic-12bit-axis"}),
    ("14-bit axis encoder, filtered difference", {"sensing": "magnetic-14bit-axis"}),
    ("500-line motor encoder, differenced", {"sensing": "incremental-500-motor"}),
    ("12-bit axis encoder, tachometer", {"sensing": "encoder_ticks=4096,velocity=tachometer"}),
    ("uniform noise 0.5 mrad, tachometer", {"sensing": "noise=uniform:0.0005,velocity=tachometer,seed=1"}),
    ("Gaussian noise 0.5 mrad", {"sensing": "noise=gaussian:0.0005,seed=1"}),
    ("sensing delay 1 ms", {"sensing": "delay=0.001"}),
    ("sensing delay 20 ms", {"sensing": "delay=0.02"}),
    ("actuation delay 5 ms", {"actuation": "delay=0.005"}),
    ("inductance 2 mH", {"actuation": "inductance=0.002"}),
    ("current limit 5 A", {"actuation": "current_limit=5"}),
    ("play 2 mrad, axis encoder", {"transmission": 0.002}),
    ("play 2 mrad, motor encoder", {"transmission": 0.002, "sensing": "incremental-500-motor"}),
)


def main() -> None:
    base = wm.RunConfig(**wm.CERTIFIED.config_changes(), m1=750.0, duration=DURATION_S)
    ideal_bound = None
    print("| cart | sup\\|E\\| [rad] | E_max [rad] | sup\\|E\\| / ideal E_max | verdict | not met | RMS u [V] "
          "| TV u [V/s] |")
    print("|---|---|---|---|---|---|---|---|")
    for name, changes in CASES:
        result = wm.run_closed_loop(base.replace(**changes), progress=False)
        s = result.summary
        cert = s.certificate.to_dict()
        if ideal_bound is None:
            ideal_bound = cert["E_max"]
        u = result.rows["voltage"]
        rms = float(np.sqrt(np.mean(u * u)))
        tv = float(np.sum(np.abs(np.diff(u))) / DURATION_S)
        bound = "none" if cert.get("E_max") is None else f"{cert['E_max']:.4f}"
        unmet = ", ".join(a["name"] for a in unmet_assumptions(cert)) or "-"
        print(f"| {name} | {s.sup_E:.4f} | {bound} | {s.sup_E / ideal_bound:.3f} | {s.verdict} | {unmet} | "
              f"{rms:.2f} | {tv:.1f} |", flush=True)


if __name__ == "__main__":
    main()
