"""Type aliases shared by camcad modules, and two small helpers (read-only arrays, a tree copy)."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["ArrayLike", "FloatArray", "readonly", "tree_copy"]

FloatArray = NDArray[np.float64]


def readonly(*arrays: FloatArray) -> None:
    """Mark arrays read-only before they leave a function (trimesh's habit)."""
    for arr in arrays:
        arr.flags.writeable = False


_ATOMS = (str, int, float, bool, type(None))


def tree_copy(value: Any) -> Any:
    """``copy.deepcopy`` of a TOML-like value: dicts and lists copied, str, numbers, bool, None shared.

    The same copy for the tables a design file parses into, at a fraction of
    deepcopy's cost (no memo, no per-object dispatch): a sweep copies its
    design mapping once per variant, an analysis its motion summary once per
    summary. Any other object is deep-copied.
    """
    kind = type(value)
    if kind is dict:
        return {k: tree_copy(v) for k, v in value.items()}
    if kind is list:
        return [tree_copy(v) for v in value]
    if kind in _ATOMS:
        return value
    return copy.deepcopy(value)
