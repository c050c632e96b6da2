"""Certified tensor-product B-spline surfaces of a barrel cam's groove walls.

Each wall W(φ, t) (:func:`camcad.geometry.barrel.barrel_faces`: motion angle
φ × station t along the roller's axis; a rib's two faces likewise) is fitted by a bicubic B-spline
S(u, v), periodic in u = φ/2π and clamped in v = (t − t₀)/(t₁ − t₀), with the
plate profile's least-squares kernels (:func:`~camcad.fit.bspline.lsq_periodic`,
:func:`~camcad.fit.bspline.lsq_clamped`): one periodic solve in u fits every
station's row at once (the same knots, so the normal matrix is shared), then
one clamped solve in v fits the columns of u-control points (Piegl & Tiller
1997, §9.4.1 for each direction; tensor-product fitting, §9.2.5). Knots in u
sit at the motion's joints with the multiplicity their smoothness asks for
(s of class C^k gives a wall of class C^(k−1) in φ, so multiplicity p − k + 1)
and are added by bisecting every span whose error exceeds half the
tolerance.

The certificate
---------------
The surface keeps the exact wall's parameters, so the parametric error
e(φ, t) = S(u, v) − W(φ, t) bounds the distance both ways: every exact point
is within |e| of the surface and every surface point within |e| of the exact
wall. On a grid of cells h_φ × h_t, |e| at any point of a cell is at most the
largest |e| at its corners plus the bilinear-interpolation remainder
(h_φ²/8)·max|e_φφ| + (h_t²/8)·max|e_tt| (the tensor-product linear
interpolation error, de Boor 2001, ch. XVII); the second derivatives are
estimated by the grid's second differences times the plate certificate's
safety factor 1.5 (:data:`camcad.fit.certify.CERT_SAFETY`), so the bound is
(max corner |e|) + 1.5·(max|Δ²_φ e| + max|Δ²_t e|)/8.

References
----------
.. [1] Piegl & Tiller (1997), The NURBS Book, 2nd ed., Springer.
   doi:10.1007/978-3-642-59223-2
.. [2] de Boor (2001), A Practical Guide to Splines, rev. ed., Springer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.errors import FitError
from camcad.fit.bspline import lsq_clamped, lsq_periodic, periodic_curve
from camcad.fit.certify import CERT_SAFETY
from camcad.fit.curve import BSplineCurve
from camcad.geometry.barrel import BarrelFollower, BarrelOptions, WallSide, barrel_faces, face_rollers
from camcad.knobs import Knob
from camcad.motion.program import MotionProgram

__all__ = [
    "BSplineSurface",
    "BarrelWallFit",
    "SurfaceCertificate",
    "WallFitOptions",
    "certify_surface",
    "fit_barrel_walls",
    "wall_station_range",
]

_DEGREE = 3


@dataclass(frozen=True, slots=True, kw_only=True)
class BSplineSurface:
    """A non-rational tensor-product B-spline surface, periodic in u.

    Attributes
    ----------
    degree_u, degree_v
        Degrees p, q.
    knots_u
        Extended periodic knot vector (domain [0, 1], u = φ/2π).
    knots_v
        Clamped knot vector on [0, 1].
    control_points
        (K_u + p, K_v, 3) [mm]: the last p rows repeat the first p.
    station_range
        (t₀, t₁) [mm]: v = (t − t₀)/(t₁ − t₀).
    """

    degree_u: int
    degree_v: int
    knots_u: FloatArray
    knots_v: FloatArray
    control_points: FloatArray
    station_range: tuple[float, float]

    @property
    def distinct_u(self) -> int:
        """K_u: the distinct control points round the barrel."""
        return int(self.control_points.shape[0] - self.degree_u)

    def v_of(self, station: FloatArray) -> FloatArray:
        """The parameter v = (t − t₀)/(t₁ − t₀) of stations t [mm]."""
        t0, t1 = self.station_range
        out: FloatArray = (np.asarray(station, dtype=float) - t0) / (t1 - t0)
        return out

    def evaluate(self, u: FloatArray, v: FloatArray) -> FloatArray:
        """S on the grid u (n,) × v (m,): (n, m, 3) [mm]."""
        u = np.asarray(u, dtype=float).ravel()
        v = np.asarray(v, dtype=float).ravel()
        ku, kv = self.control_points.shape[:2]
        cols = BSplineCurve(
            degree=self.degree_v,
            knots=self.knots_v,
            control_points=np.ascontiguousarray(self.control_points.transpose(1, 0, 2).reshape(kv, ku * 3)),
        )
        along_v = cols.evaluate(v).reshape(len(v), ku, 3).transpose(1, 0, 2).reshape(ku, len(v) * 3)
        rows = BSplineCurve(
            degree=self.degree_u,
            knots=self.knots_u,
            control_points=np.ascontiguousarray(along_v),
            periodic=True,
        )
        out: FloatArray = rows.evaluate(u).reshape(len(u), len(v), 3)
        return out

    def at(self, phi: FloatArray, station: FloatArray) -> FloatArray:
        """S at motion angles φ (n,) [rad] × stations t (m,) [mm]: (n, m, 3) [mm]."""
        return self.evaluate(np.asarray(phi, dtype=float) / TWO_PI, self.v_of(station))


@dataclass(frozen=True, slots=True, kw_only=True)
class SurfaceCertificate:
    """The certified error of one wall's surface [mm].

    ``node_max``: the largest |S − W| on the check grid; ``bound``: the bound
    between the grid's nodes (module notes), ≥ ``node_max``; ``grid``: the
    check grid's (n_φ, n_t).
    """

    node_max: float
    bound: float
    grid: tuple[int, int]

    @property
    def max_error(self) -> float:
        """The certified maximum distance between the surface and the exact wall [mm]."""
        return max(self.node_max, self.bound)


@dataclass(frozen=True, slots=True, kw_only=True)
class WallFitOptions:
    """How closely the walls are fitted.

    ``tolerance`` [mm]: the certified maximum error; ``margin`` [mm]: how far the
    fitted stations reach below the groove's bottom and above the barrel's
    surface (so that the walls cut both cylinders cleanly); ``max_spans``:
    the budget of knot spans round the barrel.
    """

    tolerance: float = 0.005
    margin: float = 1.0
    max_spans: int = 2000


@dataclass(frozen=True, slots=True, kw_only=True)
class BarrelWallFit:
    """Both walls' surfaces and their certificates; ``tolerance`` [mm] as asked."""

    upper: BSplineSurface
    lower: BSplineSurface
    upper_certificate: SurfaceCertificate
    lower_certificate: SurfaceCertificate
    tolerance: float

    @property
    def max_error(self) -> float:
        """The larger certified error of the two walls [mm]."""
        return max(self.upper_certificate.max_error, self.lower_certificate.max_error)

    def summary(self) -> dict[str, Any]:
        """The ``fit`` section of a barrel's summary.json: each wall's surface and its certificate [mm]."""

        def wall(surface: BSplineSurface, cert: SurfaceCertificate) -> dict[str, Any]:
            return {
                "control_points": [surface.distinct_u, int(surface.control_points.shape[1])],
                "degree": [surface.degree_u, surface.degree_v],
                "stations_mm": list(surface.station_range),
                "max_error_mm": cert.max_error,
                "node_max_error_mm": cert.node_max,
                "check_grid": list(cert.grid),
            }

        return {
            "kind": "barrel walls (bicubic B-spline surfaces, periodic round the barrel)",
            "tolerance_mm": self.tolerance,
            "max_error_mm": self.max_error,
            "certified": self.max_error <= self.tolerance,
            "control_points": sum(
                s.distinct_u * int(s.control_points.shape[1]) for s in (self.upper, self.lower)
            ),
            "upper_wall": wall(self.upper, self.upper_certificate),
            "lower_wall": wall(self.lower, self.lower_certificate),
        }


def wall_station_range(
    program: MotionProgram, follower: BarrelFollower, options: BarrelOptions, margin: float
) -> tuple[float, float]:
    """(t₀, t₁) [mm]: stations whose wall points lie inside the bottom cylinder, and outside the barrel.

    A wall point at station t lies √(t² + (y + r cos γ)²) from the barrel's
    axis, between t and √(t² + (|y| + r)²); so t₀ = √(b² − (|y|max + r)²) − margin
    (b the bottom radius) and t₁ = R + margin; |y| over a rib's two rollers.
    """
    phi = program.sample_phi(math.radians(1.0))
    motion = program.evaluate(phi)
    y = max(float(np.max(np.abs(src.centre(motion).m0[:, 0]))) for src, _ in face_rollers(follower, options))
    r = float(options.roller_at(options.bottom_radius, clearance=True))
    bottom = options.bottom_radius
    reach = y + r
    if reach >= bottom:
        raise FitError(
            f"the walls reach {reach:.3f} mm across the roller's axis, more than the groove's bottom "
            f"radius {bottom:g} mm",
            best_error=math.inf,
            control_point_count=0,
        )
    return math.sqrt(bottom * bottom - reach * reach) - margin, options.barrel_radius + margin


def _stations(t0: float, t1: float, count: int) -> FloatArray:
    """Chebyshev–Lobatto stations on [t₀, t₁] (ends included)."""
    k = np.arange(count)
    out: FloatArray = t0 + 0.5 * (t1 - t0) * (1.0 - np.cos(np.pi * k / (count - 1)))
    return out


def _joint_knots(program: MotionProgram, degree: int) -> tuple[FloatArray, FloatArray]:
    """Distinct joint parameters u and their multiplicities (p − k + 1, at least 1, at most p)."""
    marks: dict[float, int] = {0.0: 1}
    for bp in program.breakpoints:
        u = float(np.mod(bp.phi, TWO_PI) / TWO_PI)
        u = 0.0 if u > 1.0 - 1e-12 else u
        marks[u] = max(marks.get(u, 1), min(degree, max(1, degree - bp.continuity + 1)))
    keys = sorted(marks)
    return np.array(keys), np.array([marks[k] for k in keys], dtype=float)


def _tau(simple: FloatArray, joints: FloatArray, mult: FloatArray) -> FloatArray:
    """One period's knots: the joints with their multiplicities and the simple knots between."""
    free = simple[np.all(np.abs(simple[:, None] - joints[None, :]) > 1e-9, axis=1)]
    out = np.concatenate([np.repeat(joints, mult.astype(int)), free])
    out.sort(kind="stable")
    return out


def _exact(
    program: MotionProgram,
    follower: BarrelFollower,
    options: BarrelOptions,
    phi: FloatArray,
    stations: FloatArray,
    side: WallSide,
) -> FloatArray:
    """W (n, m, 3) [mm], taking each joint's right-hand limit (the surface's knots are there too)."""
    walls = barrel_faces(program.evaluate(phi), follower, options, stations)
    return walls.upper.point if side is WallSide.UPPER else walls.lower.point


def _fit_once(
    u: FloatArray,
    v: FloatArray,
    data: FloatArray,
    tau: FloatArray,
    interior_v: FloatArray,
    span: tuple[float, float],
) -> BSplineSurface:
    n, m = data.shape[:2]
    across_u = lsq_periodic(u, data.reshape(n, m * 3), tau, _DEGREE).curve.control_points[: len(tau)]
    ku = len(tau)
    cols = across_u.reshape(ku, m, 3).transpose(1, 0, 2).reshape(m, ku * 3)
    fit_v = lsq_clamped(v, np.ascontiguousarray(cols), interior_v, _DEGREE).curve
    kv = fit_v.control_points.shape[0]
    ctrl = fit_v.control_points.reshape(kv, ku, 3).transpose(1, 0, 2)
    full = periodic_curve(tau, ctrl.reshape(ku, kv * 3), _DEGREE)
    cps = np.ascontiguousarray(full.control_points.reshape(ku + _DEGREE, kv, 3))
    readonly(cps)
    return BSplineSurface(
        degree_u=_DEGREE,
        degree_v=_DEGREE,
        knots_u=full.knots,
        knots_v=fit_v.knots,
        control_points=cps,
        station_range=span,
    )


def _certify(
    surface: BSplineSurface,
    program: MotionProgram,
    follower: BarrelFollower,
    options: BarrelOptions,
    side: WallSide,
    *,
    step: float = math.radians(0.1),
    stations: int = 41,
) -> tuple[SurfaceCertificate, FloatArray, FloatArray]:
    """The certificate, the |S − W| grid (n_φ, n_t) and its angles φ (n_φ,) [rad].

    See :func:`certify_surface`.
    """
    phi = program.sample_phi(step)
    t = np.linspace(*surface.station_range, stations)
    err = surface.at(phi, t) - _exact(program, follower, options, phi, t, side)
    # the left-hand limit at each joint too (the surface is continuous there, the exact wall may not be)
    joints = np.array([bp.phi for bp in program.breakpoints])
    node = float(np.max(np.linalg.norm(err, axis=-1)))
    if joints.size:
        left = barrel_faces(program.evaluate(joints, side="left"), follower, options, t)
        w_left = left.upper.point if side is WallSide.UPPER else left.lower.point
        node = max(node, float(np.max(np.linalg.norm(surface.at(joints, t) - w_left, axis=-1))))
    wrapped = np.concatenate((err[-1:], err, err[:1]), axis=0)  # periodic in φ
    d2_phi = np.linalg.norm(wrapped[2:] - 2.0 * wrapped[1:-1] + wrapped[:-2], axis=-1)
    # across a joint two cells meet; the second difference there straddles it, which is what we want
    d2_t = np.linalg.norm(err[:, 2:] - 2.0 * err[:, 1:-1] + err[:, :-2], axis=-1)
    bound = node + CERT_SAFETY * (float(np.max(d2_phi)) + float(np.max(d2_t))) / 8.0
    cert = SurfaceCertificate(node_max=node, bound=bound, grid=(len(phi), stations))
    return cert, np.linalg.norm(err, axis=-1), phi


def certify_surface(
    surface: BSplineSurface,
    program: MotionProgram,
    follower: BarrelFollower,
    options: BarrelOptions,
    side: WallSide,
    *,
    step: float = math.radians(0.1),
    stations: int = 41,
) -> SurfaceCertificate:
    """Bound max |S − W| over the whole parameter rectangle (module notes).

    ``step`` [rad]: the check grid in φ (every joint added); ``stations``: the
    check grid's stations, uniform over the fitted range.
    """
    return _certify(surface, program, follower, options, side, step=step, stations=stations)[0]


def _fit_wall(
    program: MotionProgram,
    follower: BarrelFollower,
    options: BarrelOptions,
    side: WallSide,
    fit: WallFitOptions,
    span: tuple[float, float],
) -> tuple[BSplineSurface, SurfaceCertificate]:
    joints, mult = _joint_knots(program, _DEGREE)
    simple = np.linspace(0.0, 1.0, 73, endpoint=False)
    interior_v = np.array([0.25, 0.5, 0.75])
    m = 13
    best: tuple[BSplineSurface, SurfaceCertificate] | None = None
    for _ in range(12):
        tau = _tau(simple, joints, mult)
        gaps = np.diff(np.r_[np.unique(tau), 1.0])
        step = min(math.radians(0.25), 0.2 * TWO_PI * float(np.min(gaps)))
        phi = program.sample_phi(step)
        t = _stations(*span, m)
        data = _exact(program, follower, options, phi, t, side)
        v = (t - span[0]) / (span[1] - span[0])
        surface = _fit_once(phi / TWO_PI, v, data, tau, interior_v, span)
        cert, err, phi_c = _certify(surface, program, follower, options, side)
        if best is None or cert.max_error < best[1].max_error:
            best = (surface, cert)
        if cert.max_error <= fit.tolerance:
            return surface, cert
        # where the error lives: at the check grid's stations (worst over φ) and angles (worst over t)
        along_t = err.max(axis=0)
        along_u = err.max(axis=1)
        if float(np.max(along_t)) > 0.5 * fit.tolerance and float(np.ptp(along_t)) > 0.5 * float(
            np.max(along_t)
        ):
            interior_v = np.linspace(0.0, 1.0, len(interior_v) + 3)[1:-1]
            m = 2 * len(interior_v) + 9
        edges = np.r_[np.unique(tau), 1.0]
        which = np.searchsorted(edges, phi_c / TWO_PI, side="right") - 1
        worst = np.zeros(len(edges) - 1)
        np.maximum.at(worst, np.clip(which, 0, len(worst) - 1), along_u)
        split = worst > 0.5 * fit.tolerance
        if not split.any():
            split = worst >= float(np.max(worst))
        mids = 0.5 * (edges[:-1] + edges[1:])[split]
        simple = np.union1d(simple, mids)
        if len(simple) + int(mult.sum()) > fit.max_spans:
            break
    assert best is not None
    raise FitError(
        f"the {side.name.lower()} wall's surface cannot meet {fit.tolerance:g} mm within "
        f"{fit.max_spans} knot spans (best {best[1].max_error:.4g} mm); loosen the tolerance",
        best_error=best[1].max_error,
        control_point_count=best[0].distinct_u * best[0].control_points.shape[1],
        field=Knob.FIT_TOLERANCE,
    )


def fit_barrel_walls(
    program: MotionProgram,
    follower: BarrelFollower,
    options: BarrelOptions,
    fit: WallFitOptions | None = None,
) -> BarrelWallFit:
    """Fit both groove walls within ``fit.tolerance`` [mm], certified (module notes).

    The surfaces span φ over the whole turn and stations t from just inside
    the groove's bottom cylinder to just outside the barrel
    (:func:`wall_station_range`), so a solid modeller can trim them with both
    cylinders.

    Raises
    ------
    FitError
        The tolerance cannot be met within ``fit.max_spans`` (exit 3).
    """
    fit = fit or WallFitOptions()
    span = wall_station_range(program, follower, options, fit.margin)
    upper, cu = _fit_wall(program, follower, options, WallSide.UPPER, fit, span)
    lower, cl = _fit_wall(program, follower, options, WallSide.LOWER, fit, span)
    return BarrelWallFit(
        upper=upper, lower=lower, upper_certificate=cu, lower_certificate=cl, tolerance=fit.tolerance
    )
