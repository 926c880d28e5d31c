"""The steering-controller interface.

A controller maps the steering state and the reference to an armature voltage,
vectorised over a leading batch axis so that one call controls many
simulations::

    u = controller.voltage(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)   # arrays (B,) -> (B,)

``voltage_scalar`` is the same law on Python floats, for the single-run loop
where NumPy's per-call overhead would dominate, and ``batch_law(n)`` the same
law for the batched loop of ``wmr_mj.sim.sweep``: a callable that writes into
buffers it owns, so that a control step allocates nothing (tests keep all three
bit-identical)::

    law = controller.batch_law(n)
    u = law(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot, E, E_dot, u_out)

The motor's voltage limit is applied outside the law by :func:`saturate`.
"""

from __future__ import annotations

import abc
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    from wmr_mj.plant.reduced import SteeringModel

__all__ = ["SteeringController", "BatchLaw", "saturate"]

#: law(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot, E, E_dot, u) -> u: alpha, alpha_dot (n,) arrays
#: (rad, rad/s; strided views are fine); the reference as floats; E = alpha0 - alpha and
#: E_dot = alpha0_dot - alpha_dot are written into the (n,) arrays E, E_dot; the unsaturated
#: voltage (V) into u, which is returned.
BatchLaw = Callable[[np.ndarray, np.ndarray, float, float, float, np.ndarray, np.ndarray, np.ndarray], np.ndarray]


class SteeringController(abc.ABC):
    """Steering state and reference in (rad, rad/s, rad/s^2), armature voltage out (V)."""

    name: str = "controller"
    #: the reduced model the law stands on (its estimate P^, C_V^, F^, K^); the certificate reads it
    model: SteeringModel

    @abc.abstractmethod
    def voltage(
        self,
        alpha: ArrayLike,
        alpha_dot: ArrayLike,
        alpha0: ArrayLike,
        alpha0_dot: ArrayLike,
        alpha0_ddot: ArrayLike,
    ) -> np.ndarray:
        """Unsaturated armature voltage for each simulation of the batch, V."""

    def voltage_scalar(
        self, alpha: float, alpha_dot: float, alpha0: float, alpha0_dot: float, alpha0_ddot: float
    ) -> float:
        """The same law on floats (override for speed)."""
        return float(self.voltage(np.array([alpha]), np.array([alpha_dot]), np.array([alpha0]),
                                  np.array([alpha0_dot]), np.array([alpha0_ddot]))[0])

    def batch_law(self, n: int) -> BatchLaw:
        """The law for a batch of ``n`` simulations, writing into the caller's buffers.

        This default calls :meth:`voltage` (which allocates); controllers override it
        with a law that allocates nothing per call.
        """

        def law(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot, E, E_dot, u):
            np.subtract(alpha0, alpha, out=E)
            np.subtract(alpha0_dot, alpha_dot, out=E_dot)
            u[...] = self.voltage(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)
            return u

        return law

    def describe(self) -> dict:
        """JSON-able description for logs and reports."""
        return {"controller": self.name}


def saturate(u: ArrayLike, limit: float) -> tuple[np.ndarray, np.ndarray]:
    """(clip(u, -limit, limit), mask of saturated entries)."""
    u = np.asarray(u, dtype=float)
    clipped = np.clip(u, -limit, limit)
    return clipped, clipped != u
