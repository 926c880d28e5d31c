"""A sampled steering law on the reduced model, integrated independently of the testbed's engine.

The plant is the reduced model of wmr_mj.plant.reduced written out again here (not imported), for
a batch of B plants at once::

    P a'' + C_V a' + F sigma(a') + K sin(a)/cos^3(a) + Gam a'/cos^2(a) = u + d

with sigma(x) = x/sqrt(x^2 + w^2) (a smoothed Coulomb sign of width w [rad/s]; |F sigma| <= F as
the stiction plant's friction). The law is called once per control period T with the state at the
sample and its voltage held (zero-order hold) over the period, which is integrated by classical
RK4 in ``substeps`` equal steps. Every substep is recorded, so a sup over the rows includes the
inter-sample motion.

Usage::

    rows = simulate_zoh(law, plant, reference_fn, T=1e-3, n=10000, substeps=4)
    rows["E"]      # (n * substeps + 1, B)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Plant:
    """B reduced-model plants: coefficient arrays (B,) in volts (Gam = gyro V_A [V s/rad]);
    w: the Coulomb sign's smoothing [rad/s]; d: a constant voltage disturbance [V]."""

    P: np.ndarray
    C_V: np.ndarray
    F: np.ndarray
    K: np.ndarray
    Gam: np.ndarray
    w: float = 0.01
    d: float = 0.0

    @classmethod
    def of(cls, *, P, C_V, F, K=0.0, Gam=0.0, w: float = 0.01, d: float = 0.0) -> Plant:
        arrs = np.broadcast_arrays(*(np.atleast_1d(np.asarray(x, dtype=float)) for x in (P, C_V, F, K, Gam)))
        return cls(*(a.copy() for a in arrs), w=w, d=d)

    def acceleration(self, a: np.ndarray, ad: np.ndarray, u: np.ndarray) -> np.ndarray:
        c = np.cos(a)
        sigma = ad / np.sqrt(ad * ad + self.w * self.w)
        rest = self.C_V * ad + self.F * sigma + self.K * np.sin(a) / (c * c * c) + self.Gam * ad / (c * c)
        return (u + self.d - rest) / self.P


def simulate_zoh(law: Callable[[int, float, np.ndarray, np.ndarray, float, float, float], np.ndarray],
                 plant: Plant, reference: Callable[[float], tuple[float, float, float]], *, T: float, n: int,
                 substeps: int = 4, alpha_init: float = 0.0) -> dict[str, np.ndarray]:
    """Run ``n`` control periods of ``law(k, t, a, a', alpha0, alpha0', alpha0'')`` -> u (B,) on ``plant``.

    reference(t) -> (alpha0, alpha0', alpha0'') at any t; the plant starts at a = alpha_init, a' = 0.
    Returns rows t (m,), a, ad, E, E_dot (m, B) at every substep (m = n substeps + 1), and u (n, B)
    the voltage held over each period.
    """
    B = plant.P.size
    h = T / substeps
    a = np.full(B, float(alpha_init))
    ad = np.zeros(B)
    m = n * substeps + 1
    ts = np.arange(m) * h
    A, AD = np.empty((m, B)), np.empty((m, B))
    U = np.empty((n, B))
    A[0], AD[0] = a, ad
    j = 0
    for k in range(n):
        t = k * T
        r0, r1, r2 = reference(t)
        u = np.broadcast_to(np.asarray(law(k, t, a.copy(), ad.copy(), r0, r1, r2), dtype=float), (B,))
        U[k] = u
        for _ in range(substeps):
            k1a, k1v = ad, plant.acceleration(a, ad, u)
            k2a, k2v = ad + 0.5 * h * k1v, plant.acceleration(a + 0.5 * h * k1a, ad + 0.5 * h * k1v, u)
            k3a, k3v = ad + 0.5 * h * k2v, plant.acceleration(a + 0.5 * h * k2a, ad + 0.5 * h * k2v, u)
            k4a, k4v = ad + h * k3v, plant.acceleration(a + h * k3a, ad + h * k3v, u)
            a = a + h / 6.0 * (k1a + 2 * k2a + 2 * k3a + k4a)
            ad = ad + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
            j += 1
            A[j], AD[j] = a, ad
    ref = np.array([reference(float(t)) for t in ts])
    return {"t": ts, "a": A, "ad": AD, "E": ref[:, :1] - A, "E_dot": ref[:, 1:2] - AD, "u": U,
            "alpha0": ref[:, 0], "alpha0_dot": ref[:, 1]}
