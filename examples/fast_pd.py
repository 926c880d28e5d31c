"""A steering law of one's own that runs compiled, at the speed of the built-in laws: a pure function of floats.

A PD on the steering error with the reference's feedforward, in volts (examples/my_pid.py without
its integral, so without state)::

    u = P_hat (alpha0'' + K_D E' + K_P E)        E = alpha0 - alpha

It offers the law as ``law(p, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)``, a staticmethod
of plain float arithmetic with its constants in ``p = law_parameters()``: with numba installed
(``pip install 'wmr-mj[fast]'``) the testbed compiles it into MuJoCo's control callback
(:mod:`wmr_mj.sim.compiled_law`), no Python per control step; without numba the same function
runs in Python, to the same bits, and the run says why on stderr. ``voltage`` is the same law on
arrays, for a batch that runs in NumPy (``run_batch(law="numpy")``). Run it from the repository root::

    wmr-mj run --controller examples/fast_pd.py:FastPD --controller-param kp=100 --no-log
    python bench/bench_plugins.py                   # beside the built-in PD and the Python path
"""

import numpy as np

from controllers import SteeringController


class FastPD(SteeringController):
    """PD with feedforward; stateless, so numba may compile it."""

    name = "fast-pd"

    def __init__(self, kp: float = 100.0, kd: float = 20.0, P_hat: float = 0.385) -> None:
        self.kp, self.kd, self.P_hat = float(kp), float(kd), float(P_hat)

    def law_parameters(self):
        return [self.P_hat, self.kp, self.kd]

    @staticmethod
    def law(p, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        return p[0] * (alpha0_ddot + p[2] * (alpha0_dot - alpha_dot) + p[1] * (alpha0 - alpha))

    def voltage(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        """The same operations on arrays (a batch in NumPy)."""
        alpha, alpha_dot = np.asarray(alpha, dtype=float), np.asarray(alpha_dot, dtype=float)
        return self.P_hat * (alpha0_ddot + self.kd * (alpha0_dot - alpha_dot) + self.kp * (alpha0 - alpha))

    def describe(self) -> dict:
        return {"controller": self.name, "kp": self.kp, "kd": self.kd, "P_hat": self.P_hat}
