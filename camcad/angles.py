"""Angles on the cam circle: the full turn, and runs of flagged samples.

``TWO_PI`` is defined here, once, for every layer above.
"""

from __future__ import annotations

import math

import numpy as np

from camcad._typing import FloatArray

__all__ = ["TWO_PI", "flagged_ranges", "format_ranges"]

TWO_PI: float = 2.0 * math.pi
"""One turn of the cam [rad]."""


def flagged_ranges(phi: FloatArray, mask: np.ndarray) -> list[tuple[float, float]]:
    """Contiguous runs of ``mask`` over the sorted cam angles ``phi`` [rad].

    A run that crosses 360° is merged with the one starting at 0°, so its
    start angle is larger than its end angle. Returns ``[(start, end), ...]``
    in radians.

    Examples
    --------
    Twelve samples 30° apart; the run flagged at 300°, 330° and 0° wraps
    through 360° and is one range:

    >>> phi = np.radians(np.arange(0.0, 360.0, 30.0))
    >>> mask = np.zeros(12, dtype=bool)
    >>> mask[[0, 3, 4, 10, 11]] = True
    >>> [tuple(round(math.degrees(a), 9) for a in run) for run in flagged_ranges(phi, mask)]
    [(300.0, 0.0), (90.0, 120.0)]
    """
    mask = np.asarray(mask, dtype=bool)
    if not mask.any():
        return []
    if mask.all():
        return [(float(phi[0]), float(phi[-1]))]
    edges = np.flatnonzero(np.diff(mask.astype(np.int8)))
    starts = list(edges[mask[edges + 1]] + 1)
    ends = list(edges[mask[edges]])
    if mask[0]:
        starts.insert(0, 0)
    if mask[-1]:
        ends.append(len(mask) - 1)
    runs = [(float(phi[a]), float(phi[b])) for a, b in zip(starts, ends, strict=True)]
    if mask[0] and mask[-1] and len(runs) > 1:
        first, last = runs[0], runs.pop()
        runs[0] = (last[0], first[1])
    return runs


def format_ranges(ranges: list[tuple[float, float]]) -> str:
    """``'12.3°–45.6°, 300.0°–10.0°'`` from ranges in radians.

    Examples
    --------
    >>> format_ranges([(math.pi / 6, math.pi / 4), (5 * math.pi / 3, TWO_PI)])
    '30.0°–45.0°, 300.0°–360.0°'
    """
    return ", ".join(f"{math.degrees(a):.1f}°–{math.degrees(b):.1f}°" for a, b in ranges)
