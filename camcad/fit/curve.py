"""The B-spline curve value type shared by the fit and the exporters."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import BSpline

from camcad._typing import FloatArray

__all__ = ["BSplineCurve"]


@dataclass(frozen=True, slots=True, kw_only=True)
class BSplineCurve:
    """A non-rational B-spline plane curve (all weights 1).

    Attributes
    ----------
    degree
        Polynomial degree p (3 for the cam profile).
    knots
        (m + p + 1,) full knot vector. For ``periodic=False`` the ends are
        clamped (p + 1 equal knots); for ``periodic=True`` it is the extended
        knot vector of a periodic spline over ``[knots[p], knots[-p-1]]``.
    control_points
        (m, 2) control points [mm]. For a periodic curve the last p points
        repeat the first p; for a closed clamped curve the last point equals
        the first.
    periodic
        Whether the curve is the periodic form (C^{p-1} across the seam).
    """

    degree: int
    knots: FloatArray
    control_points: FloatArray
    periodic: bool = False

    @property
    def domain(self) -> tuple[float, float]:
        """Parameter interval ``(u_start, u_end)`` of the curve."""
        p = self.degree
        return float(self.knots[p]), float(self.knots[-p - 1])

    def evaluate(self, u: FloatArray, der: int = 0) -> FloatArray:
        """Points (or the ``der``-th derivative) at parameters ``u``; (n, 2) [mm].

        Periodic curves wrap ``u`` into the domain.
        """
        u = np.asarray(u, dtype=float)
        spline = BSpline(
            self.knots,
            self.control_points,
            self.degree,
            extrapolate="periodic" if self.periodic else False,
        )
        if der:
            spline = spline.derivative(der)
        return np.asarray(spline(u), dtype=float)
