"""Integrals and means over one cam turn of quantities sampled at cam angles.

Used by the life, film and drive analyses: each needs a mean of some power
of a per-angle quantity over the turn, weighted by the cam angle or by a
roller's revolutions.
"""

from __future__ import annotations

import numpy as np

from camcad._typing import ArrayLike, FloatArray
from camcad.angles import TWO_PI

__all__ = ["cycle_integral", "cycle_mean", "cycle_weights"]


def cycle_weights(phi: ArrayLike) -> FloatArray:
    """Periodic trapezoid weights of sorted samples over one turn [rad].

    Parameters
    ----------
    phi
        (n,) sorted cam angles in [0, 2π) [rad]; the turn closes from the last
        sample back to the first plus 2π.

    Returns
    -------
    FloatArray
        (n,) w with Σ w·f ≈ ∫₀^{2π} f dφ; Σ w = 2π. The rule is second-order
        on each smooth piece; the grid should hold every joint, where f may
        jump (the error there is then O(h·jump) of one interval).

    Raises
    ------
    ValueError
        If ``phi`` is empty or not sorted within one turn.
    """
    p = np.asarray(phi, dtype=float).ravel()
    if p.size == 0:
        raise ValueError("no samples")
    gaps = np.diff(np.append(p, p[0] + TWO_PI))
    if np.any(gaps < 0.0):
        raise ValueError("cam angles must be sorted within one turn")
    out: FloatArray = 0.5 * (gaps + np.roll(gaps, 1))  # trapezoid: half of each adjacent interval
    return out


def cycle_integral(phi: ArrayLike, values: ArrayLike) -> float:
    """∫₀^{2π} f(φ) dφ by the periodic trapezoid rule on the samples (see :func:`cycle_weights`)."""
    return float(np.dot(cycle_weights(phi), np.asarray(values, dtype=float).ravel()))


def cycle_mean(phi: ArrayLike, values: ArrayLike) -> float:
    """Mean of f over the turn, (1/2π)∫f dφ: at constant cam speed, the mean over time."""
    return cycle_integral(phi, values) / TWO_PI
