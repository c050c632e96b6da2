"""The error certificate: true point-to-curve distances and seam continuity.

The least-squares residual |C(t_i) − D_i| mixes a tangential slip of the
parameter with the geometric error; what a machinist needs is the distance
from the profile to the curve. Each check point is projected onto the curve
by Newton's method on the foot-point condition (C(u) − P)·C'(u) = 0
(Piegl & Tiller 1997, §6.1), vectorised over all points.

References
----------
.. [1] Piegl & Tiller (1997), The NURBS Book, 2nd ed., Springer.
   doi:10.1007/978-3-642-59223-2
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.fit.bspline import curve_derivatives
from camcad.fit.curve import BSplineCurve

__all__ = ["Certificate", "certify", "normal_distance", "project", "seam_jumps"]


@dataclass(frozen=True, slots=True, kw_only=True)
class Certificate:
    """Distances from check points to a curve.

    Attributes
    ----------
    foot
        (n,) parameter of the foot point of each check point.
    distance
        (n,) distance from each check point to its foot point [mm].
    """

    foot: FloatArray
    distance: FloatArray

    @property
    def max_error(self) -> float:
        """Largest distance [mm]."""
        return float(np.max(self.distance))

    @property
    def rms_error(self) -> float:
        """Root-mean-square distance [mm]."""
        return float(np.sqrt(np.mean(self.distance**2)))


def normal_distance(at_params: FloatArray, tangent: FloatArray, points: FloatArray) -> FloatArray:
    """First-order distance of points to a curve from their fit parameters.

    Parameters
    ----------
    at_params
        (n, 2) curve points C(t_i) [mm].
    tangent
        (n, 2) derivatives C'(t_i).
    points
        (n, 2) the points D_i [mm].

    Returns
    -------
    FloatArray
        (n,) |r × C'| / |C'| with r = C(t_i) − D_i [mm]: the normal part of
        the residual, equal to the foot-point distance up to O(|r|² κ).
        Cheap; it steers the knot search and is never the certificate.
    """
    r = at_params - points
    cross = r[:, 0] * tangent[:, 1] - r[:, 1] * tangent[:, 0]
    return np.abs(cross) / np.hypot(tangent[:, 0], tangent[:, 1])


def project(
    curve: BSplineCurve, points: FloatArray, u0: FloatArray, *, max_iter: int = 20, tol: float = 1e-10
) -> Certificate:
    """Foot points of ``points`` on ``curve`` by vectorised Newton iteration.

    Parameters
    ----------
    curve
        The curve (periodic curves wrap the parameter, clamped ones clip it).
    points
        (n, 2) points [mm].
    u0
        (n,) starting parameters, close to the foot points.
    max_iter
        Newton iterations at most.
    tol
        Stop when every step moves the foot point less than this [mm].

    Returns
    -------
    Certificate
        Foot parameters (unwrapped for periodic curves) and distances [mm].

    Notes
    -----
    f(u) = (C − P)·C', f'(u) = |C'|² + (C − P)·C'' and u ← u − f / f'
    (Piegl & Tiller 1997, §6.1). Where f' <= 0 the Gauss–Newton
    denominator |C'|² is used instead. A step that would increase a
    distance is rejected and that point's next step halved.
    """
    a, b = curve.domain
    pts = np.asarray(points, dtype=float)
    u = np.asarray(u0, dtype=float).copy()
    c, d1, d2 = curve_derivatives(curve, u, 2)
    dist = np.hypot(*(c - pts).T)
    damp = np.ones_like(u)
    for _ in range(max_iter):
        r = c - pts
        speed2 = np.einsum("ij,ij->i", d1, d1)
        f = np.einsum("ij,ij->i", r, d1)
        fp = speed2 + np.einsum("ij,ij->i", r, d2)
        step = damp * f / np.where(fp > 0.0, fp, speed2)  # Newton step, Piegl & Tiller 1997, §6.1
        if not curve.periodic:
            step = u - np.clip(u - step, a, b)
        if np.max(np.abs(step) * np.sqrt(speed2), initial=0.0) < tol:
            break
        trial = u - step
        ct, d1t, d2t = curve_derivatives(curve, trial, 2)
        dt = np.hypot(*(ct - pts).T)
        ok = dt <= dist * (1.0 + 1e-12) + 1e-15
        damp = np.where(ok, 1.0, 0.5 * damp)
        u = np.where(ok, trial, u)
        dist = np.where(ok, dt, dist)
        c = np.where(ok[:, None], ct, c)
        d1 = np.where(ok[:, None], d1t, d1)
        d2 = np.where(ok[:, None], d2t, d2)
    readonly(u, dist)
    return Certificate(foot=u, distance=dist)


def certify(
    curve: BSplineCurve,
    samples: FloatArray,
    params: FloatArray,
    between: FloatArray | None = None,
) -> tuple[Certificate, Certificate | None]:
    """Certify a fitted curve against its samples and points between them.

    Parameters
    ----------
    curve
        Fitted curve.
    samples
        (n, 2) samples the curve was fitted to [mm].
    params
        (n,) their fit parameters (starting guesses for the foot points).
    between
        (n, 2) exact profile points between consecutive samples [mm]
        (closed: the last lies between sample n−1 and sample 0; open:
        (n − 1, 2)), or None when no exact profile is known.

    Returns
    -------
    tuple
        (certificate of the samples, certificate of the between points or
        None). The certified error is the max over both.
    """
    at_samples = project(curve, samples, params)
    if between is None:
        return at_samples, None
    ends = np.append(params, params[0] + 1.0) if curve.periodic else params
    mids = 0.5 * (ends[1:] + ends[:-1])[: len(between)]
    return at_samples, project(curve, between, mids)


def _curvature(d1: FloatArray, d2: FloatArray) -> FloatArray:
    """Signed curvature κ = (x'y'' − y'x'') / |C'|³ [1/mm]."""
    return (d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]) / np.hypot(d1[..., 0], d1[..., 1]) ** 3


def seam_jumps(clamped: BSplineCurve) -> tuple[float, float]:
    """Tangent-angle and curvature jumps across the seam of a closed clamped curve.

    Parameters
    ----------
    clamped
        Clamped closed curve (first control point equals the last).

    Returns
    -------
    tuple of float
        (angle between the end and start tangents [rad],
        |κ(start) − κ(end)| [1/mm]).
    """
    a, b = clamped.domain
    d = curve_derivatives(clamped, np.array([a, b]), 2)
    t0, t1 = d[1, 0], d[1, 1]
    cross = t1[0] * t0[1] - t1[1] * t0[0]
    angle = float(np.arctan2(abs(cross), float(np.dot(t0, t1))))
    kappa = _curvature(d[1], d[2])
    return angle, float(abs(kappa[0] - kappa[1]))
