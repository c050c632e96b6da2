"""Plane-curve quantities from analytic derivatives: tangents, normals, curvature.

Every curve in camcad is a function of the cam angle φ. Its first and second
derivatives come from the motion law in closed form, so nothing here
differentiates sampled points.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly

__all__ = ["CurveSample", "curve_sample"]


@dataclass(frozen=True, slots=True, kw_only=True)
class CurveSample:
    """A plane curve of the cam frame sampled at cam angles.

    Attributes
    ----------
    phi
        (n,) cam angle φ [rad].
    point
        (n, 2) points [mm].
    d1
        (n, 2) dP/dφ [mm/rad].
    d2
        (n, 2) d²P/dφ² [mm/rad²].
    tangent
        (n, 2) unit tangent in the direction of increasing φ.
    normal
        (n, 2) unit normal pointing away from the cam axis (outward).
    rho
        (n,) signed radius of curvature [mm]: positive where the curve is
        convex (seen from outside), negative where concave, ``inf`` where
        straight.
    """

    phi: FloatArray
    point: FloatArray
    d1: FloatArray
    d2: FloatArray
    tangent: FloatArray
    normal: FloatArray
    rho: FloatArray


def curve_sample(
    phi: FloatArray, point: FloatArray, d1: FloatArray, d2: FloatArray, *, clockwise: bool
) -> CurveSample:
    """Build a :class:`CurveSample` from a point and its two φ-derivatives.

    Parameters
    ----------
    phi
        (n,) cam angle [rad].
    point, d1, d2
        (n, 2) P, dP/dφ [mm/rad] and d²P/dφ² [mm/rad²].
    clockwise
        True when the curve runs clockwise about the cam axis as φ grows
        (a counter-clockwise cam); fixes which side is outward.

    Notes
    -----
    ρ = |P'|³ / (x'y'' − y'x'') is the parametric radius of curvature
    (papers/README erratum to Quang & Hung 2015, eq. 5); its sign is flipped
    for clockwise curves so that convex is positive for both rotations.
    """
    speed = np.hypot(d1[:, 0], d1[:, 1])
    tangent = d1 / speed[:, None]
    left = np.column_stack((-tangent[:, 1], tangent[:, 0]))
    normal = -left if not clockwise else left
    # For a clockwise run the outward side is the left of the tangent.
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    sign = -1.0 if clockwise else 1.0
    with np.errstate(divide="ignore"):
        rho = sign * speed**3 / cross
    rho = np.where(cross == 0.0, np.inf, rho)
    out = CurveSample(
        phi=np.asarray(phi, dtype=float),
        point=point,
        d1=d1,
        d2=d2,
        tangent=tangent,
        normal=normal,
        rho=rho,
    )
    readonly(out.point, out.d1, out.d2, out.tangent, out.normal, out.rho)
    return out
