"""Type aliases shared by camcad modules."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["ArrayLike", "FloatArray", "readonly"]

FloatArray = NDArray[np.float64]


def readonly(*arrays: FloatArray) -> None:
    """Mark arrays read-only before they leave a function (trimesh's habit)."""
    for arr in arrays:
        arr.flags.writeable = False
