"""The result of a profile fit: the curve, its export form and its certificate."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.fit.curve import BSplineCurve

__all__ = ["ProfileFit"]


@dataclass(frozen=True, slots=True, kw_only=True)
class ProfileFit:
    """A B-spline fitted to a profile, with its error certificate.

    Attributes
    ----------
    curve
        Periodic curve (closed input) or clamped open curve (open input);
        parameter domain [0, 1] in normalised chord length.
    clamped
        Clamped export form of the same curve. For closed input it opens at
        ``seam`` and its domain is [0, 1] again: ``clamped.evaluate(v)``
        equals ``curve.evaluate(v + seam)``; and
        ``control_points[-1] == control_points[0]``. For open input it is
        ``curve``.
    params
        (n,) increasing foot-point parameter of each input sample on
        ``curve``: the curve point nearest the sample is
        ``curve.evaluate(params)``. For closed input the first may lie a hair
        below 0 (its foot point precedes u = 0); ``curve`` wraps it. On
        ``clamped`` use :attr:`clamped_params`.
    tolerance
        Requested tolerance [mm].
    max_error
        Certified max distance from the exact profile to the curve [mm]:
        an upper bound over the whole turn (within 0.1 % of the largest
        distance found), whatever the sample step; for :func:`fit_points`,
        the max over the given points.
    rms_error
        RMS distance of the samples to the curve [mm].
    control_points
        Number of control points of the clamped form.
    degree
        Degree p.
    seam_tangent_jump
        Angle between the tangents either side of the seam of the clamped
        form [rad] (0 for open input).
    seam_curvature_jump
        |Δκ| across the seam of the clamped form [1/mm] (0 for open input).
    seam
        Parameter u_s of ``curve`` where ``clamped`` starts: inside the
        longest stretch between motion breakpoints (:mod:`camcad.fit.seam`),
        so the seam adds no tangent or curvature jump and the exported spline
        does not start at a joint; 0 without breakpoints and for open input.
    """

    curve: BSplineCurve
    clamped: BSplineCurve
    params: FloatArray
    tolerance: float
    max_error: float
    rms_error: float
    control_point_count: int
    degree: int
    seam_tangent_jump: float
    seam_curvature_jump: float
    seam: float = 0.0

    @property
    def clamped_params(self) -> FloatArray:
        """(n,) ``params`` on ``clamped``: ``np.mod(params − seam, 1)``.

        ``clamped.evaluate(clamped_params)`` equals ``curve.evaluate(params)``;
        for closed input they increase from the first sample past the seam
        and drop by one period once.
        """
        if self.curve.periodic:
            out = np.mod(np.asarray(self.params) - self.seam, 1.0)
        else:
            out = np.array(self.params)
        readonly(out)
        return out

    def summary(self) -> dict[str, float | int]:
        """Tolerance, errors [mm], control points and degree for the report."""
        return {
            "tolerance_mm": self.tolerance,
            "max_error_mm": self.max_error,
            "rms_error_mm": self.rms_error,
            "control_points": self.control_point_count,
            "degree": self.degree,
        }
