"""A test law for identification (tests/test_identify_data.py): a PD on the angle read plus a seeded voltage
multisine, the way a lab excites its cart under its own loop (``wmr-mj excite`` writes such a dither).

    wmr-mj run --cart truth.toml --controller tests/data/identify_dithered_pd.py:DitheredPD \
        --controller-param amplitude=3 --sensing encoder_ticks=4096,velocity=difference,delay=0.005
"""

from __future__ import annotations

import numpy as np

from controllers import SteeringController


class DitheredPD(SteeringController):
    """u = kp (alpha0 - alpha) + kd (alpha0' - alpha') + a multisine of ``amplitude`` V (0.3 to 6 Hz)."""

    name = "dithered-pd"

    def __init__(self, kp: float = 40.0, kd: float = 4.0, amplitude: float = 3.0, seed: int = 0) -> None:
        self.kp, self.kd, self.amplitude, self.seed = float(kp), float(kd), float(amplitude), int(seed)
        rng = np.random.default_rng(self.seed)
        self._freqs = np.linspace(0.3, 6.0, 15)
        self._phases = rng.uniform(0.0, 2 * np.pi, self._freqs.size)
        self._t = 0.0

    def reset(self, *, control_period: float) -> None:
        self._t = 0.0

    def step(self, t: float, alpha: float, alpha_dot: float, alpha0: float, alpha0_dot: float,
             alpha0_ddot: float) -> float:
        dither = self.amplitude * float(np.mean(np.sin(2 * np.pi * self._freqs * t + self._phases))) * 2.5
        return self.kp * (alpha0 - alpha) + self.kd * (alpha0_dot - alpha_dot) + dither
