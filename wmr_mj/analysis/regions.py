"""The regions a claim bounds the run's (sup|E|, sup|E'|) by: a :class:`Region` protocol and its shapes.

A claim (:class:`wmr_mj.analysis.claim_types.Certificate`) holds one region object; the verdict asks it
whether the run's point lies inside, how far (a ratio, <= 1 inside) and which polygon to draw. Code
asks the region, never a name: a third shape (a sampled-data certificate's) is one more class with
these members, and an object that is not a region is refused (:func:`check_region`).

* :class:`SmallGainRegion`: section 4's region (4.21), the points with
  ||E|| <= gamma1 (delta1 + delta2 ||E|| + delta3 ||E'||) and ||E'|| <= gamma2 (the same);
* :class:`BoxRegion`: |E| <= E_max and |E'| <= Edot_max (Edot_max = inf: |E| alone), the claim of a
  law with a simpler guarantee (:func:`wmr_mj.analysis.claim.box_claim`).

Usage::

    from wmr_mj.analysis.regions import BoxRegion, SmallGainRegion
    r = SmallGainRegion(gamma1=0.01, gamma2=0.1, delta1=2.0, delta2=5.0, delta3=0.5, E_max=0.02 / 0.9,
                        Edot_max=0.2 / 0.9)
    r.ratio(0.01, 0.1), r.contains(0.01, 0.1), r.vertices
    BoxRegion(E_max=0.04, Edot_max=0.4).ratio(0.02, 0.1)       # 0.5
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Protocol, runtime_checkable

__all__ = ["Region", "SmallGainRegion", "BoxRegion", "check_region", "CORNER_TOLERANCE"]

#: Relative slack of :meth:`Region.contains` on the ratio: the corner (E_max, Edot_max) of (4.21) lies on
#: both lines, and only rounding separates it from them.
CORNER_TOLERANCE = 1e-12


@runtime_checkable
class Region(Protocol):
    """A set of (sup|E| [rad], sup|E'| [rad/s]) a claim promises the run stays in.

    Attributes:
        kind: the region's name in the JSON ('small-gain', 'box'); written, never branched on.
        E_max: the largest |E| of the region [rad].
        Edot_max: the largest |E'| of the region [rad/s] (inf: not bounded).
    """

    kind: ClassVar[str]

    @property
    def E_max(self) -> float: ...

    @property
    def Edot_max(self) -> float: ...

    @property
    def vertices(self) -> tuple[tuple[float, float], ...]:
        """The polygon to draw in the (||E||, ||E'||) plane, from (0, 0) counter-clockwise."""
        ...

    def ratio(self, sup_E: float, sup_Edot: float) -> float:
        """How far the point is along the region's boundary [-]: <= 1 inside, > 1 outside."""
        ...

    def contains(self, sup_E: float, sup_Edot: float) -> bool:
        """The point (finite, >= 0) lies in the region."""
        ...


def _contains(region: Region, sup_E: float, sup_Edot: float) -> bool:
    """Below both maxima and ratio <= 1 (with :data:`CORNER_TOLERANCE`)."""
    return bool(sup_E <= region.E_max and sup_Edot <= region.Edot_max
                and region.ratio(sup_E, sup_Edot) <= 1.0 + CORNER_TOLERANCE)


@dataclass(frozen=True)
class SmallGainRegion:
    """Section 4's region (4.21): ||E|| <= gamma1 eta and ||E'|| <= gamma2 eta, eta = delta1 + delta2 ||E||
    + delta3 ||E'||, inside the rectangle E_max x Edot_max (its corner, where both hold with equality).

    Attributes:
        gamma1 [s^2], gamma2 [s]: the L-infinity gains of (4.14).
        delta1 [rad/s^2], delta2 [1/s^2], delta3 [1/s]: the bound (4.19) on ||eta||.
        E_max [rad], Edot_max [rad/s]: the corner, gamma1 delta1/(1 - condition) and gamma2 delta1/(1 -
            condition) (E_max as the fixed point on the reachable angle found it, to its tolerance 1e-13).
    """

    kind: ClassVar[str] = "small-gain"

    gamma1: float
    gamma2: float
    delta1: float
    delta2: float
    delta3: float
    E_max: float
    Edot_max: float

    @property
    def condition(self) -> float:
        """The left side of (4.23), gamma1 delta2 + gamma2 delta3 [-]: < 1 for a bounded region."""
        return self.gamma1 * self.delta2 + self.gamma2 * self.delta3

    @property
    def vertices(self) -> tuple[tuple[float, float], ...]:
        """(0, 0), the ||E||-axis end of the first line, the corner, the ||E'||-axis end of the second."""
        g1, g2, d1 = self.gamma1, self.gamma2, self.delta1
        return ((0.0, 0.0), (g1 * d1 / (1.0 - g1 * self.delta2), 0.0), (self.E_max, self.Edot_max),
                (0.0, g2 * d1 / (1.0 - g2 * self.delta3)))

    def ratio(self, sup_E: float, sup_Edot: float) -> float:
        """max of the two sides of (4.21): x/(gamma1 eta) and y/(gamma2 eta), eta at (x, y)."""
        x, y = float(sup_E), float(sup_Edot)
        eta = self.delta1 + self.delta2 * x + self.delta3 * y
        return max(x / (self.gamma1 * eta), y / (self.gamma2 * eta))

    def contains(self, sup_E: float, sup_Edot: float) -> bool:
        """Both inequalities of (4.21) hold at the point, and it lies below the corner."""
        return _contains(self, sup_E, sup_Edot)


@dataclass(frozen=True)
class BoxRegion:
    """|E| <= E_max and |E'| <= Edot_max.

    Attributes:
        E_max: the bound on |E| [rad], >= 0.
        Edot_max: the bound on |E'| [rad/s]; inf when the claim bounds |E| alone.
    """

    kind: ClassVar[str] = "box"

    E_max: float
    Edot_max: float = math.inf

    @property
    def vertices(self) -> tuple[tuple[float, float], ...]:
        """The rectangle; with |E'| unbounded, its edge on the ||E||-axis."""
        Ed = self.Edot_max if math.isfinite(self.Edot_max) else 0.0
        return ((0.0, 0.0), (self.E_max, 0.0), (self.E_max, Ed), (0.0, Ed))

    def ratio(self, sup_E: float, sup_Edot: float) -> float:
        """max(sup|E|/E_max, sup|E'|/Edot_max) (inf when E_max = 0; 0 for |E'| when Edot_max = inf)."""
        x, y = float(sup_E), float(sup_Edot)
        return max(x / self.E_max if self.E_max > 0 else math.inf, y / self.Edot_max)

    def contains(self, sup_E: float, sup_Edot: float) -> bool:
        """|E| <= E_max and |E'| <= Edot_max at the point."""
        return _contains(self, sup_E, sup_Edot)


def check_region(region: object) -> Region:
    """``region`` when it is a :class:`Region`.

    Raises:
        TypeError: anything else (a name such as 'box' included): a claim's region is an object
            with ``contains``, ``ratio`` and ``vertices``, not a tag.
    """
    if isinstance(region, str) or not isinstance(region, Region):
        raise TypeError(f"a claim's region must be a Region (SmallGainRegion, BoxRegion, ...), got "
                        f"{type(region).__name__} {region!r}")
    return region
