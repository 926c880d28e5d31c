"""Names a module keeps for one release with a warning: its ``__getattr__`` (PEP 562), one place for every module."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["deprecated_names"]


def deprecated_names(module: str, names: Mapping[str, tuple[Any, str]]) -> Callable[[str], Any]:
    """A module ``__getattr__`` that hands each deprecated name its value with a DeprecationWarning, every use.

    Args:
        module: the module's ``__name__`` (the warning names ``module.name``).
        names: deprecated name -> (its value, what to use instead, in words).

    Returns:
        The function to bind as the module's ``__getattr__``; any other name raises AttributeError.
    """
    def module_getattr(name: str) -> Any:
        if name in names:
            value, instead = names[name]
            warnings.warn(f"{module}.{name} is deprecated: {instead}", DeprecationWarning, stacklevel=2)
            return value
        raise AttributeError(f"module {module!r} has no attribute {name!r}")

    return module_getattr
