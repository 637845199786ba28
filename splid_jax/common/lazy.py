"""A package that offers its modules' names but imports each module only on first use, so that a
command can install its signal handlers before JAX loads."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable


def lazy_names(package: str, homes: dict[str, tuple[str, ...]]) -> tuple[Callable, Callable, list[str]]:
    """``__getattr__``, ``__dir__`` and ``__all__`` for ``package``, whose names live in the modules
    ``homes`` maps to them."""
    home_of = {name: module for module, names in homes.items() for name in names}
    offered = sorted(home_of)

    def __getattr__(name: str):
        if name not in home_of:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(home_of[name]), name)

    def __dir__() -> list[str]:
        return sorted({*vars(sys.modules[package]), *offered})

    return __getattr__, __dir__, offered
