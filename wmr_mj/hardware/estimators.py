"""The velocity estimators and the delay of the steering sensor, each defined once as a discrete linear system.

Usage::

    from wmr_mj.hardware.estimators import velocity_estimator, delay_line

    est = velocity_estimator("filtered", control_period=0.001, filter_tau=0.005)
    est.difference.A, est.low_pass.A                         # its stages (below), each a DiscreteSystem
    x_next, y = est.step(x, u)                               # one step, in the sensing chain's operations
    est.system.A, est.system.B, est.system.C, est.system.D     # the stages in series: x[k+1] = A x + B u, y = C x + D u
    delay_line(5).A                                          # the 5-period shift register

Drake keeps a ``DiscreteTimeDelay`` as one small system that simulation and analysis both use, and
python-control keeps one ``StateSpace`` per system; so does this module, for what sits between the steering
angle the encoder reads and the velocity the law reads.

Each estimator, with T the control period (s), u = (alpha_m[k] rad, the delayed true rate rad/s) its input and
y its estimate of the rate (rad/s):

- ``exact`` and ``tachometer``: no state; y = the delayed true rate (D = [0, 1]; a tachometer's error is the
  velocity noise, added after the estimate);
- ``difference``: the stage :attr:`VelocityEstimator.difference` Delta (x = alpha_m[k-1]; its output the
  increment alpha_m[k] - alpha_m[k-1], rad: A = [0], B = [1], C = [-1], D = [1]), then the division by T;
- ``filtered``: Delta, the division by T, then the stage :attr:`VelocityEstimator.low_pass` L (x = y[k-1];
  y = a y[k-1] + (1 - a) v: A = [a], B = [1 - a], C = [a], D = [1 - a]), a = exp(-T / tau_f) (the exact
  discretisation of 1/(tau_f s + 1) for an input held over the period).

The stages are the definition; :attr:`VelocityEstimator.system` is their series connection, the one linear
system the certificate's loop reads: with g = (1 - a)(1/T), the difference's A = [0], B = [1, 0], C = [-1/T],
D = [1/T, 0], and the filter's (x = (alpha_m[k-1], y[k-1])) A = [[0, 0], [-g, a]], B = [[1, 0], [g, 0]],
C = [-g, a], D = [g, 0]. Each entry is one IEEE operation on the stages' coefficients (1/T, then (1 - a) times
it), so the rows the certificate builds are the bits it built before these were defined here.

The division by T is kept as a division: v / T is not v (1/T) for every double v (at T = 0.001 s about one in
seven differ by an ulp), so no matrix entry reproduces it, and the plant divides. :meth:`VelocityEstimator.step`
runs the stages, each with :meth:`DiscreteSystem.step` (each row summed over its nonzero entries, state before
input, in index order), and the division between them: the operations of
:class:`wmr_mj.hardware.sensing.SensingChain` and of ``sense()`` in the compiled law's C
(``wmr_mj/sim/_compiled_law.c``), which read the coefficients T, a and 1 - a from here (the chain computes no
``exp`` of its own). ``tests/test_estimators.py`` drives the C on seeded random inputs against :meth:`step` and
:func:`delay_line` to the last bit, and the series connection against the stages.

The delay of d periods (:func:`delay_line`): x = (u[k-1], ..., u[k-d]), y = u[k-d]; A shifts, B = e_1, C = e_d,
D = 0 (d = 0: no state, D = 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np

from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware.spec import whole_period_count

__all__ = ["DiscreteSystem", "VelocityEstimator", "LinearVelocityEstimate", "LINEAR_VELOCITY_ESTIMATES",
           "velocity_estimator", "delay_line"]

#: The estimates that are linear systems (the sensing's ``velocity`` but 'none', which reads no velocity).
LinearVelocityEstimate = Literal["exact", "tachometer", "difference", "filtered"]
LINEAR_VELOCITY_ESTIMATES: tuple[str, ...] = get_args(LinearVelocityEstimate)


@dataclass(frozen=True, eq=False)
class DiscreteSystem:
    """x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k]; the arrays read-only.

    Attributes:
        A: (n, n). B: (n, m). C: (p, n). D: (p, m).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray

    def __post_init__(self) -> None:
        for name in ("A", "B", "C", "D"):
            x = np.array(getattr(self, name), dtype=float)
            x.flags.writeable = False
            object.__setattr__(self, name, x)

    @property
    def n_states(self) -> int:
        """n, the state's dimension."""
        return int(self.A.shape[0])

    def step(self, x: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One step: (x[k+1] = A x + B u, y[k] = C x + D u) from the state x (n,) and the input u (m,).

        Each row is summed over its nonzero entries only, the state's terms before the input's, in index order,
        from its first term (no 0.0 to start from, which would turn a -0 into +0): the operations a hand-written
        step performs (a structural zero is no operation; 1 and -1 give the operand and its negation exactly).
        A row with no nonzero entry is 0.0.
        """
        x, u = np.asarray(x, dtype=float), np.asarray(u, dtype=float)
        return (np.array([_row(self.A[i], x, self.B[i], u) for i in range(self.A.shape[0])]),
                np.array([_row(self.C[i], x, self.D[i], u) for i in range(self.C.shape[0])]))


def _row(state_row: np.ndarray, x: np.ndarray, input_row: np.ndarray, u: np.ndarray) -> float:
    """sum_j state_row[j] x[j] + sum_j input_row[j] u[j] over the nonzero coefficients, left to right."""
    total: float | None = None
    for coefficients, values in ((state_row, x), (input_row, u)):
        for c, v in zip(coefficients.tolist(), values.tolist()):
            if c != 0.0:
                term = c * v
                total = term if total is None else total + term
    return 0.0 if total is None else total


@dataclass(frozen=True, kw_only=True)
class VelocityEstimator:
    """One velocity estimate at the control period T (module docstring: the systems).

    Build with :func:`velocity_estimator` (checked). The state is (alpha_m[k-1] rad where the estimate differences,
    y[k-1] rad/s where it filters); the inputs (alpha_m[k] rad, the delayed true rate rad/s); the output the
    estimate, rad/s (before the velocity noise).

    Attributes:
        kind: the estimate. control_period: T, s. filter_tau: tau_f, s ('filtered' only, else None).
        a: exp(-T / tau_f) (0 unless filtered). one_minus_a: 1 - a (0 unless filtered).
    """

    kind: LinearVelocityEstimate
    control_period: float
    filter_tau: float | None = None
    a: float = 0.0
    one_minus_a: float = 0.0

    @property
    def differences(self) -> bool:
        """True where the estimate differences the measured angle (it holds alpha_m[k-1])."""
        return self.kind in ("difference", "filtered")

    @property
    def filters(self) -> bool:
        """True where the difference runs through the low-pass (it holds y[k-1])."""
        return self.kind == "filtered"

    @property
    def difference(self) -> DiscreteSystem:
        """Delta: x = alpha_m[k-1] rad, u = alpha_m[k] rad, y = alpha_m[k] - alpha_m[k-1] rad (the increment over
        the period, before the division by T). Raises ValueError where the estimate does not difference."""
        if not self.differences:
            raise ValueError(f"velocity estimate {self.kind!r} does not difference the measured angle")
        return DiscreteSystem(A=np.array([[0.0]]), B=np.array([[1.0]]), C=np.array([[-1.0]]), D=np.array([[1.0]]))

    @property
    def low_pass(self) -> DiscreteSystem:
        """L: x = y[k-1] rad/s, u = v, the difference over T (rad/s), y = a y[k-1] + (1 - a) v rad/s. Raises
        ValueError unless filtered."""
        if not self.filters:
            raise ValueError(f"velocity estimate {self.kind!r} has no low-pass")
        a, b = self.a, self.one_minus_a
        return DiscreteSystem(A=np.array([[a]]), B=np.array([[b]]), C=np.array([[a]]), D=np.array([[b]]))

    def step(self, x: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One step of the estimate in the stages' operations (module docstring): Delta, v / T, then L.

        Args:
            x: the state of :attr:`system`, (alpha_m[k-1] rad, y[k-1] rad/s) as far as the estimate holds them.
            u: (alpha_m[k] rad, the delayed true rate rad/s).

        Returns:
            (x[k+1], y[k]): the next state, as :attr:`system`'s, and the estimate (1,), rad/s.
        """
        x, u = np.asarray(x, dtype=float), np.asarray(u, dtype=float)
        if not self.differences:
            return self.system.step(x, u)
        previous_alpha, increment = self.difference.step(x[:1], u[:1])
        rate = increment / self.control_period
        if not self.filters:
            return previous_alpha, rate
        filtered, estimate = self.low_pass.step(x[1:], rate)
        return np.concatenate([previous_alpha, filtered]), estimate

    @property
    def system(self) -> DiscreteSystem:
        """The stages in series as one system (module docstring): its inputs (alpha_m[k], the delayed rate)."""
        if not self.differences:
            return DiscreteSystem(A=np.zeros((0, 0)), B=np.zeros((0, 2)), C=np.zeros((1, 0)), D=np.array([[0.0, 1.0]]))
        inv_T = 1.0 / self.control_period
        delta = self.difference
        (dA,), (dB,), (dC,), (dD,) = delta.A[0], delta.B[0], delta.C[0], delta.D[0]
        if not self.filters:
            return DiscreteSystem(A=np.array([[dA]]), B=np.array([[dB, 0.0]]), C=np.array([[inv_T * dC]]),
                                  D=np.array([[inv_T * dD, 0.0]]))
        low = self.low_pass
        gB, gD = low.B[0, 0] * inv_T, low.D[0, 0] * inv_T  # g = (1 - a)(1/T), the input's path through 1/T and L
        return DiscreteSystem(A=np.array([[dA, 0.0], [gB * dC, low.A[0, 0]]]), B=np.array([[dB, 0.0], [gB * dD, 0.0]]),
                              C=np.array([[gD * dC, low.C[0, 0]]]), D=np.array([[gD * dD, 0.0]]))


def velocity_estimator(kind: str, *, control_period: float, filter_tau: float | None = None) -> VelocityEstimator:
    """The estimate ``kind`` at the control period, its coefficients computed once (a = exp(-T / tau_f), then 1 - a).

    Args:
        kind: 'exact', 'tachometer', 'difference' or 'filtered' (:data:`LINEAR_VELOCITY_ESTIMATES`).
        control_period: T, s (finite, > 0).
        filter_tau: tau_f, s (finite, > 0), for 'filtered' only.

    Raises:
        UnknownNameError: an unknown estimate.
        ParameterError: a period not finite and > 0, filter_tau missing for 'filtered', not finite and > 0, or
            given for another estimate.
    """
    if kind not in LINEAR_VELOCITY_ESTIMATES:
        raise UnknownNameError("velocity estimate", kind, LINEAR_VELOCITY_ESTIMATES)
    T = float(control_period)
    if not (math.isfinite(T) and T > 0.0):
        raise ParameterError(f"control_period = {control_period!r} s is not accepted: it must be finite and > 0")
    if kind != "filtered":
        if filter_tau is not None:
            raise ParameterError(f"filter_tau = {filter_tau!r} s applies to velocity='filtered' only "
                                 f"(velocity is {kind!r})")
        return VelocityEstimator(kind=kind, control_period=T)  # type: ignore[arg-type]
    if filter_tau is None:
        raise ParameterError("velocity='filtered' needs filter_tau (s, > 0), the low-pass time constant")
    tau = float(filter_tau)
    if not (math.isfinite(tau) and tau > 0.0):
        raise ParameterError(f"filter_tau = {filter_tau!r} s is not accepted: it must be finite and > 0")
    a = math.exp(-T / tau)
    return VelocityEstimator(kind="filtered", control_period=T, filter_tau=tau, a=a, one_minus_a=1.0 - a)


def delay_line(periods: int) -> DiscreteSystem:
    """The delay of ``periods`` control periods as a shift register (Drake's ``DiscreteTimeDelay``): y[k] = u[k-d].

    State (u[k-1], ..., u[k-d]); d = 0: no state, y = u.

    Raises:
        ParameterError: d not a whole number >= 0.
    """
    d = whole_period_count("delay", periods)
    A = np.eye(d, k=-1)
    B = np.zeros((d, 1))
    C = np.zeros((1, d))
    if d:
        B[0, 0], C[0, d - 1] = 1.0, 1.0
    return DiscreteSystem(A=A, B=B, C=C, D=np.array([[0.0 if d else 1.0]]))
