"""Packages whose public names load their modules on first use (PEP 562).

``camcad.design`` reads the small ``spec`` modules of every stage for every
design; a package ``__init__`` that imported its whole stage would load SciPy,
the FE solver or the planner for a design that needs none of them.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping

__all__ = ["lazy_names"]


def lazy_names(package: str, home: Mapping[str, str]) -> Callable[[str], object]:
    """A module ``__getattr__`` that imports ``home[name]`` when ``package.name`` is first used."""

    def __getattr__(name: str) -> object:
        if name in home:
            return getattr(importlib.import_module(home[name]), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
