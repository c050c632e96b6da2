"""Points measured on a made cam, fitted onto its design: rotation, centre, normal deviations, pass/fail.

The points (x, y) [mm] may be in any frame (a CMM's): the fit finds the turn
θ and the centre c that carry the design's frame into it, x_meas = R(θ)·x + c,
by least squares on the signed normal distances to the exact profile (each
point's foot found by Newton's method on the profile's closed form, not on a
polygon). Start: the area centroids of the measured polygon and the design
profile, and the best of 360 turns by the median distance to a dense design
polygon. The fit is robust: ``scipy.optimize.least_squares`` with the
``soft_l1`` loss, then points beyond ``reject_sigmas`` robust standard
deviations (1.4826·MAD) of the residuals are rejected and the rest refitted
by ordinary least squares (Huber 1981, §7; Rousseeuw & Leroy 1987).

Bad input is refused with a one-line :class:`~camcad.errors.DesignError`
naming ``measured`` and the point (0-based row; the caller adds the file and
line): too few points, a value that is not finite, two points at the same
place, a scan that leaves a gap in the profile, a point cloud whose size is
not the design's (millimetres taken for inches), a profile that repeats
itself (the turn cannot be told), and a best fit whose residuals are far
beyond the band (the wrong cam). Nothing is ever fitted silently.

References
----------
.. [1] Huber (1981), Robust Statistics, Wiley. doi:10.1002/0471725250
.. [2] Rousseeuw & Leroy (1987), Robust Regression and Outlier Detection, Wiley.
   doi:10.1002/0471725382
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial import cKDTree

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.errors import DesignError
from camcad.geometry.cam import Cam

__all__ = [
    "MIN_POINTS",
    "Inspection",
    "foot_points",
    "inspect_points",
    "points_from_polar",
]

MIN_POINTS = 24
"""Fewest measured points: three unknowns and enough to see the whole profile."""
MAX_GAP_DEG = 30.0
"""Largest gap in the scan around the profile [°] by default."""
MISFIT_BANDS = 5.0
"""A fit whose robust residual spread exceeds this many band widths is the wrong cam."""
_MAD = 1.482602218505602  # σ of a normal spread per median absolute deviation


def points_from_polar(angle_deg: ArrayLike, radius: ArrayLike) -> FloatArray:
    """(m, 2) points [mm] from polar angles [°] and radii [mm], as CMM software exports them."""
    a = np.radians(np.asarray(angle_deg, dtype=float))
    r = np.asarray(radius, dtype=float)
    out: FloatArray = np.column_stack((r * np.cos(a), r * np.sin(a)))
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class Inspection:
    """A made cam's measured points against its design.

    Attributes
    ----------
    rotation
        θ [rad]: the design frame turned by θ (ccw) and moved to ``centre`` is
        the measurement frame, x_meas = R(θ)·x_design + centre.
    centre
        (2,) the cam axis in the measurement frame [mm].
    rotation_sigma, centre_sigma
        One standard deviation of each [rad, mm] (least-squares covariance).
    points
        (m, 2) the points in the design frame [mm].
    angle
        (m,) cam angle u of each point's foot on the design profile [rad].
    deviation
        (m,) signed normal deviation [mm]: + where the made cam has more material.
    band
        (lower, upper) tolerance band on the deviation [mm].
    outside
        (m,) whether each point lies outside the band.
    inlier
        (m,) whether the point was kept by the final fit.
    noise
        Robust standard deviation of the inliers' deviations [mm].
    """

    rotation: float
    centre: FloatArray
    rotation_sigma: float
    centre_sigma: FloatArray
    points: FloatArray
    angle: FloatArray
    deviation: FloatArray
    band: tuple[float, float]
    outside: np.ndarray
    inlier: np.ndarray
    noise: float

    @property
    def passed(self) -> bool:
        """Whether every point lies inside the band."""
        return not bool(np.any(self.outside))


def _bad(message: str) -> DesignError:
    return DesignError("measured", message)


def _validated(points: ArrayLike) -> FloatArray:
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise _bad(f"points of shape {pts.shape}; allowed: (m, 2) x, y in mm")
    if pts.shape[0] < MIN_POINTS:
        raise _bad(f"{pts.shape[0]} points; allowed: at least {MIN_POINTS} around the whole profile")
    finite = np.isfinite(pts).all(axis=1)
    if not finite.all():
        i = int(np.argmin(finite))
        raise _bad(f"point {i}: {pts[i].tolist()} is not finite; allowed: numbers in mm")
    scale = float(np.max(np.abs(pts - pts.mean(axis=0))))
    pairs = cKDTree(pts).query_pairs(1e-9 * max(scale, 1.0), output_type="ndarray")
    if len(pairs):
        i, j = sorted(int(k) for k in pairs[0])
        raise _bad(f"points {i} and {j} are the same point {pts[i].tolist()}; allowed: each point once")
    return pts


def _area_centroid(polygon: FloatArray) -> FloatArray:
    """Area centroid of a closed polygon (m, 2), first vertex not repeated."""
    x, y = polygon[:, 0], polygon[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * np.sum(cross)
    out: FloatArray = np.array([np.sum((x + xn) * cross), np.sum((y + yn) * cross)]) / (6.0 * area)
    return out


def _around(points: FloatArray, centre: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Points sorted by polar angle about ``centre``, and those angles [rad]."""
    d = points - centre
    angle = np.arctan2(d[:, 1], d[:, 0])
    order = np.argsort(angle)
    return points[order], angle[order]


def _largest_gap(angles: FloatArray) -> tuple[float, float]:
    """(size, start) of the largest gap between sorted angles on the circle [rad]."""
    a = np.sort(np.mod(angles, 2.0 * np.pi))
    gaps = np.diff(np.append(a, a[0] + 2.0 * np.pi))
    i = int(np.argmax(gaps))
    return float(gaps[i]), float(a[i])


def foot_points(cam: Cam, points: FloatArray, start: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Cam angles u (m,) of the feet of ``points`` (design frame) on the exact profile, and signed distances.

    Newton's method on (P(u) − x)·P′(u) = 0 from ``start`` (the nearest
    vertex of a dense polygon); the distance is (x − P)·N, N outward.
    """
    u = np.array(start, dtype=float)
    for _ in range(8):
        prof = cam.profile(u)
        r = prof.point - points
        f = np.einsum("ij,ij->i", r, prof.d1)
        df = np.einsum("ij,ij->i", prof.d1, prof.d1) + np.einsum("ij,ij->i", r, prof.d2)
        step = np.clip(f / df, -0.02, 0.02)
        u -= step
        if np.max(np.abs(step)) < 1e-14:
            break
    prof = cam.profile(u)
    dist = np.einsum("ij,ij->i", points - prof.point, prof.normal)
    return np.mod(u, 2.0 * np.pi), dist


class _Design:
    """The design's dense profile, its k-d tree, area centroid and RMS radius about it."""

    def __init__(self, cam: Cam) -> None:
        self.cam = cam
        self.phi = cam.sample_phi(math.radians(0.1))
        self.polygon = np.array(cam.profile(self.phi).point)
        self.tree = cKDTree(self.polygon)
        self.centroid = _area_centroid(self.polygon)
        self.size = float(np.sqrt(np.mean(np.sum((self.polygon - self.centroid) ** 2, axis=1))))

    def residuals(self, params: FloatArray, pts: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Signed distances of the points taken into the design frame, their feet, and the points there."""
        theta, cx, cy = params
        c, s = math.cos(theta), math.sin(theta)
        d = pts - np.array([cx, cy])
        x = np.column_stack((c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]))  # R(−θ)(p − c)
        _, nearest = self.tree.query(x)
        u, dist = foot_points(self.cam, x, self.phi[nearest])
        return dist, u, x

    def jacobian(self, params: FloatArray, pts: FloatArray, u: FloatArray) -> FloatArray:
        """∂(signed distance)/∂(θ, cx, cy): the normal N·∂x/∂params (the foot moves along the tangent)."""
        theta, cx, cy = params
        c, s = math.cos(theta), math.sin(theta)
        d = pts - np.array([cx, cy])
        normal = self.cam.profile(u).normal
        dx_dtheta = np.column_stack((-s * d[:, 0] + c * d[:, 1], -c * d[:, 0] - s * d[:, 1]))
        jac = np.column_stack(
            (
                np.einsum("ij,ij->i", normal, dx_dtheta),
                -(normal[:, 0] * c - normal[:, 1] * s),
                -(normal[:, 0] * s + normal[:, 1] * c),
            )
        )
        return jac


def _start(design: _Design, pts: FloatArray, max_gap: float) -> tuple[float, FloatArray]:
    """Coarse turn and centre: centroids matched, the best of 360 turns; refuses partial or foreign scans."""
    centroid0 = pts.mean(axis=0)
    ordered, angle = _around(pts, centroid0)
    gap, at = _largest_gap(angle)
    if gap > max_gap:
        raise _bad(
            f"the scan covers only {360.0 - math.degrees(gap):.0f}° of the profile (no point from "
            f"{math.degrees(at):.0f}° to {math.degrees(at + gap):.0f}° about its centre); allowed: "
            f"gaps up to {math.degrees(max_gap):g}°"
        )
    centroid = _area_centroid(ordered)
    size = float(np.sqrt(np.mean(np.sum((pts - centroid) ** 2, axis=1))))
    ratio = size / design.size
    if not 0.8 < ratio < 1.25:
        hint = ""
        if abs(ratio * 25.4 - 1.0) < 0.1:
            hint = "; they look like inches: multiply by 25.4"
        elif abs(ratio / 25.4 - 1.0) < 0.1:
            hint = "; they look like mm read as inches: divide by 25.4"
        raise _bad(
            f"the points are {ratio:.3g} times the size of the design ({size:.4g} mm against "
            f"{design.size:.4g} mm about the centroid){hint}; allowed: the cam itself, in mm"
        )
    turns = np.radians(np.arange(360.0))
    rel = (pts - centroid)[:: max(1, pts.shape[0] // 120)]  # a coarse search needs few points
    c, s = np.cos(turns)[:, None], np.sin(turns)[:, None]
    x = np.stack((c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]), axis=-1) + design.centroid
    cost = np.median(design.tree.query(x.reshape(-1, 2))[0].reshape(turns.size, -1), axis=1)
    best = int(np.argmin(cost))
    far = np.abs((np.arange(360) - best + 180) % 360 - 180) > 15
    rival = int(np.argmin(np.where(far, cost, np.inf)))
    if cost[rival] < 1.5 * cost[best] + 1e-9:
        raise _bad(
            f"the profile fits the points turned by {best}° and by {rival}° alike: the design repeats "
            "itself, so the turn cannot be told from the points; allowed: a profile without that symmetry"
        )
    theta = float(turns[best])
    gx, gy = design.centroid
    ct, st = math.cos(theta), math.sin(theta)
    centre = centroid - np.array([ct * gx - st * gy, st * gx + ct * gy])
    return theta, centre


def inspect_points(
    cam: Cam,
    points: ArrayLike,
    *,
    band: float | tuple[float, float],
    reject_sigmas: float = 3.0,
    max_gap: float = math.radians(MAX_GAP_DEG),
) -> Inspection:
    """Fit measured points onto the design and judge them against the tolerance band.

    Parameters
    ----------
    cam
        The design.
    points
        (m, 2) measured x, y [mm] in any frame, any order (see :func:`points_from_polar`).
    band
        ±t, or (lower, upper) with lower < 0 < upper, on the normal deviation [mm].
    reject_sigmas
        Points beyond this many robust standard deviations of the residuals
        are left out of the final fit (they are still judged).
    max_gap
        Largest gap allowed in the scan around the profile [rad].
    """
    lower, upper = (-float(band), float(band)) if np.isscalar(band) else (float(band[0]), float(band[1]))  # type: ignore[index, arg-type]
    if not (lower < 0.0 < upper) or not (math.isfinite(lower) and math.isfinite(upper)):
        raise DesignError("band", f"({lower:g}, {upper:g}) mm; allowed: lower < 0 < upper, finite")
    pts = _validated(points)
    design = _Design(cam)
    theta0, centre0 = _start(design, pts, max_gap)
    width = upper - lower

    memo: dict[bytes, tuple[FloatArray, FloatArray, FloatArray]] = {}

    def evaluate(p: FloatArray, sub: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        key = p.tobytes() + sub.shape[0].to_bytes(8, "little")
        if key not in memo:
            memo.clear()  # fun and jac ask for the same parameters in turn
            memo[key] = design.residuals(p, sub)
        return memo[key]

    def fun(p: FloatArray, sub: FloatArray) -> FloatArray:
        return evaluate(p, sub)[0]

    def jac(p: FloatArray, sub: FloatArray) -> FloatArray:
        return design.jacobian(p, sub, evaluate(p, sub)[1])

    x0 = np.array([theta0, centre0[0], centre0[1]])
    robust = least_squares(fun, x0, jac=jac, args=(pts,), loss="soft_l1", f_scale=0.25 * width, x_scale="jac")
    dist = fun(robust.x, pts)
    med = float(np.median(dist))
    spread = _MAD * float(np.median(np.abs(dist - med)))
    inlier = np.abs(dist - med) <= max(reject_sigmas * spread, 1e-12)
    if np.count_nonzero(inlier) < MIN_POINTS:
        raise _bad(
            f"only {np.count_nonzero(inlier)} points agree with the fit; allowed: at least {MIN_POINTS}"
        )
    final = least_squares(fun, robust.x, jac=jac, args=(pts[inlier],), x_scale="jac", xtol=1e-15, ftol=1e-15)
    dist, u, x = design.residuals(final.x, pts)
    noise = _MAD * float(np.median(np.abs(dist[inlier] - np.median(dist[inlier]))))
    if noise > MISFIT_BANDS * width:
        raise _bad(
            f"after the best fit the points scatter {noise:.4g} mm about the profile, "
            f"{noise / width:.0f} times the band {width:g} mm: they are not this cam (or not in mm)"
        )
    gap, at = _largest_gap(u[inlier])
    if gap > max_gap:
        raise _bad(
            f"no point on the profile from cam angle {math.degrees(at):.1f}° to "
            f"{math.degrees(at + gap):.1f}°; allowed: gaps up to {math.degrees(max_gap):g}°"
        )
    jm = final.jac
    dof = max(int(np.count_nonzero(inlier)) - 3, 1)
    s2 = float(np.sum(final.fun**2)) / dof
    cov = s2 * np.linalg.inv(jm.T @ jm)
    theta = float(np.mod(final.x[0] + math.pi, 2.0 * math.pi) - math.pi)
    outside = (dist < lower) | (dist > upper)
    out = Inspection(
        rotation=theta,
        centre=np.array(final.x[1:], dtype=float),
        rotation_sigma=float(math.sqrt(cov[0, 0])),
        centre_sigma=np.sqrt(np.diag(cov)[1:]),
        points=x,
        angle=u,
        deviation=dist,
        band=(lower, upper),
        outside=outside,
        inlier=inlier,
        noise=noise,
    )
    readonly(out.centre, out.centre_sigma, out.points, out.angle, out.deviation)
    return out
