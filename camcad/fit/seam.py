"""Where the closed clamped export form of a periodic profile opens (its seam).

The periodic fit has no seam; its clamped export form must start somewhere.
Opening at u = 0 (cam angle φ = 0) lands on a motion breakpoint in most
programs, where the profile itself is only C¹ or C² (a harmonic or VAP law's
acceleration jumps there, and with it the profile's curvature). The seam
then reports the profile's jump, and a CAD user sees the spline start at a
joint. So the clamped form opens inside the longest stretch between motion
breakpoints (in φ), where the profile is analytic:

- at the knot nearest the middle of the stretch's middle half (in φ), if one
  lies in that half and has multiplicity μ <= p − 2 (the spline is C² there,
  so curvature is continuous, Piegl & Tiller 1997, §2.2). The knot is
  inserted p − μ times instead of p, so the clamped form keeps one control
  point fewer than at a parameter inside a span;
- otherwise at the middle of that half (inside a span the spline is C^∞).

Either way the seam is at least a quarter of the longest stretch (in φ) from
every breakpoint, and the periodic curve is C² there, so the clamped form's
seam adds no tangent or curvature jump (rounding only).

References
----------
.. [1] Piegl & Tiller (1997), The NURBS Book, 2nd ed., Springer.
   doi:10.1007/978-3-642-59223-2
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from camcad.angles import TWO_PI
from camcad.fit.curve import BSplineCurve

__all__ = ["longest_stretch", "seam_parameter"]


def longest_stretch(breakpoint_phi: Sequence[float]) -> tuple[float, float] | None:
    """The longest cam-angle interval between consecutive breakpoints.

    Parameters
    ----------
    breakpoint_phi
        Breakpoint angles φ_k [rad], any order, any turn.

    Returns
    -------
    tuple of float or None
        ``(φ_lo, φ_hi)`` [rad] with φ_lo in [0, 2π) and φ_lo < φ_hi <= φ_lo + 2π
        (the stretch may wrap past 2π); the first of equally long stretches.
        None without breakpoints (every point is smooth).

    Examples
    --------
    >>> lo, hi = longest_stretch(np.radians([0.0, 150.0, 240.0]))
    >>> float(np.degrees(lo)), float(np.degrees(hi))
    (0.0, 150.0)
    """
    if len(breakpoint_phi) == 0:
        return None
    phi = np.unique(np.mod(np.asarray(breakpoint_phi, dtype=float), TWO_PI))
    ends = np.append(phi, phi[0] + TWO_PI)
    i = int(np.argmax(np.diff(ends)))
    return float(ends[i]), float(ends[i + 1])


def seam_parameter(curve: BSplineCurve, lo: float, hi: float) -> float:
    """Parameter in the window ``[lo, hi]`` where the clamped form of ``curve`` should open.

    Parameters
    ----------
    curve
        Periodic curve.
    lo, hi
        The window on ``curve``, ``lo < hi < lo + period``, either end possibly
        outside the domain (it may wrap): the middle half of the longest
        stretch between breakpoints. It should hold no knot of multiplicity
        > p − 2 (between motion breakpoints every knot is a simple free knot).

    Returns
    -------
    float
        The knot of multiplicity <= p − 2 in the window nearest its middle
        ``(lo + hi) / 2``, else the middle; wrapped into the domain ``[a, b)``.
    """
    p = curve.degree
    a, b = curve.domain
    period = b - a
    tau = np.asarray(curve.knots[p : len(curve.control_points)], dtype=float)  # one period
    values, counts = np.unique(tau, return_counts=True)
    smooth = values[counts <= p - 2]  # C² at a knot of multiplicity μ <= p − 2, P&T 1997, §2.2
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    dist = np.abs(np.mod(smooth - mid + 0.5 * period, period) - 0.5 * period)  # circular: may wrap
    if dist.size and dist.min() <= half:
        return float(smooth[np.argmin(dist)])
    return a + float(np.mod(mid - a, period))
