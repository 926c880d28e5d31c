"""The analysis: the paper's section 4, the certificate for the controller actually run, verdicts.

A law's own claim analyses its linear part on the run's cart with :func:`linear_part_bounds` (or
:func:`sampled_loop_of` and :func:`~wmr_mj.analysis.sampled_data.peak_gains`), from
:mod:`wmr_mj.analysis.linear_part`; they load on first use (numpy and scipy are not imported with the package).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

__all__ = ["linear_part_bounds", "sampled_loop_of", "LinearPartBounds", "discrete_controller"]

if TYPE_CHECKING:
    from wmr_mj.analysis.linear_part import LinearPartBounds, discrete_controller, linear_part_bounds, sampled_loop_of
else:
    def __getattr__(name: str) -> Any:
        if name in __all__:
            from wmr_mj.analysis import linear_part  # on first use (PEP 562): numpy and scipy stay unimported

            return getattr(linear_part, name)
        raise AttributeError(f"module 'wmr_mj.analysis' has no attribute {name!r}")
