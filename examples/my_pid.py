"""A steering law of one's own, run through the testbed's plant, adversary, requirements and logs.

A PID on the steering error with the reference's feedforward, in volts::

    u = P_hat (alpha0'' + K_D E' + K_P E + K_I integral(E))        E = alpha0 - alpha

It states no claim, so its runs are judged by their requirements only (verdict ``no-claim``,
never a pass without one). Run it from the repository root::

    wmr-mj run --controller examples/my_pid.py:MyPID --controller-param ki=20 \\
        --require 'always[10,35](abs(E) <= 0.02)' --out logs/my-pid.mcap
    wmr-mj replay logs/my-pid.mcap --verify        # re-imports this file, checks its SHA-256, re-runs it
    wmr-mj sweep --controller examples/my_pid.py:MyPID --n 8 --duration 20 --require 'always(abs(E) <= 0.1)'
    wmr-mj falsify --controller examples/my_pid.py:MyPID --objective sup_E --budget 16 --duration 20

or from Python: ``RunConfig(controller="examples/my_pid.py:MyPID", controller_params={"ki": 20.0})``,
or ``RunConfig(controller=MyPID(ki=20.0))`` (an object runs, but a sweep or a replay needs it by name).
"""

from controllers import SteeringController


class MyPID(SteeringController):
    """PID with feedforward; the integral is the law's state, cleared by ``reset`` before every run."""

    name = "my-pid"

    def __init__(self, kp: float = 100.0, kd: float = 20.0, ki: float = 0.0, P_hat: float = 0.385) -> None:
        self.kp, self.kd, self.ki, self.P_hat = float(kp), float(kd), float(ki), float(P_hat)
        self.integral, self.period = 0.0, 0.001

    def reset(self, *, control_period: float) -> None:
        self.integral, self.period = 0.0, control_period

    def step(self, t, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        E = alpha0 - alpha
        u = self.P_hat * (alpha0_ddot + self.kd * (alpha0_dot - alpha_dot) + self.kp * E + self.ki * self.integral)
        self.integral += E * self.period  # the integral over this control period, for the next step
        return u

    def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        """The law at the current integral, without advancing it."""
        return self.P_hat * (alpha0_ddot + self.kd * (alpha0_dot - alpha_dot) + self.kp * (alpha0 - alpha)
                             + self.ki * self.integral)

    def describe(self) -> dict:
        return {"controller": self.name, "kp": self.kp, "kd": self.kd, "ki": self.ki, "P_hat": self.P_hat}
