"""The Pareto front of two objectives, both minimised.

A design dominates another when it is no worse in both objectives and
better in one; the front is the set of designs no other design dominates.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from camcad._typing import FloatArray

__all__ = ["pareto_mask"]


def pareto_mask(first: Sequence[float] | FloatArray, second: Sequence[float] | FloatArray) -> np.ndarray:
    """Which points are on the Pareto front of (first, second), both minimised.

    Points with a NaN in either objective are never on the front. Equal
    points do not dominate each other, so all copies of a front point are on
    it. One sort and one pass, O(n log n): after sorting by (first, second),
    a point is on the front exactly when its second objective is below that
    of every earlier distinct point.

    Examples
    --------
    >>> pareto_mask([1.0, 2.0, 3.0, 2.0], [3.0, 1.0, 0.5, 2.0]).tolist()
    [True, True, True, False]
    """
    f1 = np.asarray(first, dtype=float)
    f2 = np.asarray(second, dtype=float)
    mask = np.zeros(f1.shape, dtype=bool)
    ok = np.flatnonzero(~(np.isnan(f1) | np.isnan(f2)))
    order = ok[np.lexsort((f2[ok], f1[ok]))]
    best = np.inf  # smallest second objective among the earlier distinct points
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and f1[order[j + 1]] == f1[order[i]] and f2[order[j + 1]] == f2[order[i]]:
            j += 1
        if f2[order[i]] < best:
            mask[order[i : j + 1]] = True
            best = f2[order[i]]
        i = j + 1
    return mask
