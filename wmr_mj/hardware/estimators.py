"""The velocity estimators and the delay of the steering sensor, each defined once as a discrete linear system.

Usage::

    from wmr_mj.hardware.estimators import velocity_estimator, delay_line

    est = velocity_estimator("filtered", control_period=0.001, filter_tau=0.005)
    est.system.A, est.system.B, est.system.C, est.system.D     # x[k+1] = A x + B u, y = C x + D u
    est.a, est.one_minus_a                                   # the filter's coefficients, computed once here
    delay_line(5).A                                          # the 5-period shift register

Drake keeps a ``DiscreteTimeDelay`` as one small system that simulation and analysis both use, and
python-control keeps one ``StateSpace`` per system; so does this module, for what sits between the steering
angle the encoder reads and the velocity the law reads. Its users:

- :class:`wmr_mj.hardware.sensing.SensingChain` (and the C of the compiled law, ``sense()`` in
  ``wmr_mj/sim/_compiled_law.c``, which reads the chain's parameter vector) run the estimator in its factored
  form, ``v = (alpha_m[k] - alpha_m[k-1]) / T`` then ``y = a y + (1 - a) v``, with the coefficients T, a and
  1 - a of :class:`VelocityEstimator` (the chain computes no ``exp`` of its own);
- :func:`wmr_mj.analysis.sampled_data.sampled_loop` and :func:`wmr_mj.analysis.linear_part.sampled_loop_of`
  build the certificate's loop from :attr:`VelocityEstimator.system` and :func:`delay_line`;
- ``tests/test_estimators.py`` drives the compiled C and the Python chain on random inputs and checks them
  against these matrices: the delay to the bit, the estimate within the rounding bound it states (the
  factored form and the product C x + D u round differently; each is within a few ulp of the exact value).

Each estimator, with T the control period (s), u = (alpha_m[k] rad, the delayed true rate rad/s) its input and
y its estimate of the rate (rad/s):

- ``exact`` and ``tachometer``: no state; y = the delayed true rate (D = [0, 1]; a tachometer's error is the
  velocity noise, added after the estimate);
- ``difference``: x = alpha_m[k-1]; y = (alpha_m[k] - alpha_m[k-1]) / T, so A = [0], B = [1, 0],
  C = [-1/T], D = [1/T, 0];
- ``filtered``: x = (alpha_m[k-1], y[k-1]); y = a y[k-1] + (1 - a)(alpha_m[k] - alpha_m[k-1]) / T, a =
  exp(-T / tau_f) (the exact discretisation of 1/(tau_f s + 1) for an input held over the period), so with
  g = (1 - a)(1/T): A = [[0, 0], [-g, a]], B = [[1, 0], [g, 0]], C = [-g, a], D = [g, 0].

Each entry is one IEEE operation on the coefficients (1/T, then (1 - a) times it), so the rows the certificate
builds from these matrices are the bits it built before they were defined here.

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
    def system(self) -> DiscreteSystem:
        """The estimate's (A, B, C, D) (module docstring)."""
        if not self.differences:
            return DiscreteSystem(A=np.zeros((0, 0)), B=np.zeros((0, 2)), C=np.zeros((1, 0)), D=np.array([[0.0, 1.0]]))
        inv_T = 1.0 / self.control_period
        if not self.filters:
            return DiscreteSystem(A=np.array([[0.0]]), B=np.array([[1.0, 0.0]]), C=np.array([[-inv_T]]),
                                  D=np.array([[inv_T, 0.0]]))
        g = self.one_minus_a * inv_T
        return DiscreteSystem(A=np.array([[0.0, 0.0], [-g, self.a]]), B=np.array([[1.0, 0.0], [g, 0.0]]),
                              C=np.array([[-g, self.a]]), D=np.array([[g, 0.0]]))


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
