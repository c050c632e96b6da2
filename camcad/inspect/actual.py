"""What a measured cam does: its form error smoothed, the follower motion it gives, and a compensation.

The normal deviations of an :class:`~camcad.inspect.measure.Inspection`
(inliers only) are smoothed as a function of the cam angle u by least
squares on a Fourier series c0 + Σ (a_k cos ku + b_k sin ku), k ≤ H, plus
the three rigid modes of the fit (N·JP for a turn, N_x and N_y for a shift;
P the design profile, N its outward normal): the best fit has removed from
the form error its projection on those modes, which no short Fourier series
holds. The order H minimises the generalised cross-validation score
m·RSS/(m − p)², p = 2H + 4 (Craven & Wahba 1979): a linear smoother whose
hat-matrix trace is exactly p, periodic by construction, with derivatives
in closed form (the modes' from the exact profile: N′ = P′/ρ,
N″ = P″/ρ − P′ρ′/ρ²). Its coefficient covariance σ²(AᵀA)⁻¹, σ² = RSS/(m − p),
gives the standard deviation of e, e′ and e″ at any angle (the smoothing's
bias is not included: GCV balances it against this variance).

The actual motion is the follower re-solved on the made cam (design + e(u)
along the normal; :func:`~camcad.geometry.made.made_motion`), in the fitted
frame (the measurement's turn is not a keying error unless the CMM frame is
the shaft's). Its uncertainty: δq = L·e and δv = L·e′ + V·e exactly to first
order (L, V the form sensitivities of :mod:`camcad.geometry.sensitivity`);
for the acceleration the leading term L·e″ (the terms in L′, L″ multiply the
much smaller e and e′).

The compensation is the design offset by −e(u): a tool path cut to it
removes the measured systematic error. It is refused where |e| exceeds the
stock, or where the corrected profile is concave more tightly than the tool.

References
----------
.. [1] Craven & Wahba (1979), Smoothing noisy data with spline functions,
   Numerische Mathematik 31, 377–403. doi:10.1007/BF01404567
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import cholesky, solve_triangular

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.angles import flagged_ranges, format_ranges
from camcad.errors import DesignError, DesignLimitError, GougeError
from camcad.geometry.cam import Cam
from camcad.geometry.envelope import PointElement, line_envelope, offset_curve, point_envelope
from camcad.geometry.made import made_curve, made_motion
from camcad.geometry.sensitivity import Tol, sensitivities
from camcad.inspect.measure import Inspection

__all__ = [
    "MAX_ORDER",
    "ActualMotion",
    "Compensation",
    "FormFit",
    "actual_motion",
    "compensate",
    "smooth_deviation",
]


MAX_ORDER = 90
"""Highest harmonic of the smoothed form error by default (finer lobes are roughness, not form)."""


def _rigid_modes(cam: Cam, u: FloatArray, derivative: int) -> FloatArray:
    """(n, 3) the turn and shift modes N·JP, N_x, N_y of the design profile, or a u-derivative of them."""
    m = cam.motion(u)
    element = cam.follower.element(m)
    if isinstance(element, PointElement):
        base, drho = point_envelope(m.phi, element, cam.sigma)
        prof = offset_curve(base, drho, -cam.roller_radius)
    else:
        prof, drho = line_envelope(m.phi, element, cam.sigma)
    p0, p1, p2 = prof.point, prof.d1, prof.d2
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(np.isinf(prof.rho), 0.0, 1.0 / prof.rho)[:, None]
        dk = np.where(np.isinf(prof.rho), 0.0, -drho / prof.rho**2)[:, None]
    n0 = prof.normal
    n1 = p1 * k  # N′ = P′/ρ
    n2 = p2 * k + p1 * dk  # N″
    ns, ps = (n0, n1, n2), (p0, p1, p2)

    def dot(a: FloatArray, b: FloatArray) -> FloatArray:
        out: FloatArray = np.einsum("ij,ij->i", a, np.column_stack((-b[:, 1], b[:, 0])))
        return out

    binom = ((1,), (1, 1), (1, 2, 1))[derivative]
    turn = sum(c * dot(ns[i], ps[derivative - i]) for i, c in enumerate(binom))
    out: FloatArray = np.column_stack((turn, ns[derivative]))
    return out


def _basis(u: FloatArray, order: int, derivative: int = 0, cam: Cam | None = None) -> FloatArray:
    """(n, 2H + 1) columns 1, cos u, sin u, …, cos Hu, sin Hu (or their u-derivative of that order)."""
    k = np.arange(1, order + 1)
    ku = np.outer(u, k)
    c, s = np.cos(ku), np.sin(ku)
    if derivative == 0:
        cols = (c, s)
        const = np.ones((u.size, 1))
    elif derivative == 1:
        cols = (-k * s, k * c)
        const = np.zeros((u.size, 1))
    else:
        cols = (-(k**2) * c, -(k**2) * s)
        const = np.zeros((u.size, 1))
    inter = np.empty((u.size, 2 * order))
    inter[:, 0::2], inter[:, 1::2] = cols
    parts = [const, inter] if cam is None else [_rigid_modes(cam, u, derivative), const, inter]
    out: FloatArray = np.hstack(parts)
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class FormFit:
    """The smoothed form error e(u) [mm]: Fourier order H, coefficients, covariance, noise σ [mm].

    ``cam`` set: the first three coefficients are those of the design's rigid modes.
    """

    order: int
    coefficients: FloatArray
    covariance: FloatArray
    noise: float
    cam: Cam | None = None

    def __call__(self, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """e, de/du, d²e/du² at cam angles u [rad] (a :data:`~camcad.geometry.made.FormError`)."""
        ua = np.asarray(u, dtype=float)
        return tuple(_basis(ua, self.order, d, self.cam) @ self.coefficients for d in range(3))  # type: ignore[return-value]

    def std(self, u: ArrayLike, derivative: int = 0) -> FloatArray:
        """Standard deviation of e (or its u-derivative) at cam angles u [mm/radᵏ]."""
        a = _basis(np.asarray(u, dtype=float), self.order, derivative, self.cam)
        out: FloatArray = np.sqrt(np.einsum("ij,jk,ik->i", a, self.covariance, a))
        return out


def smooth_deviation(
    angle: ArrayLike, deviation: ArrayLike, *, max_order: int | None = None, cam: Cam | None = None
) -> FormFit:
    """The GCV Fourier smoothing of deviations (m,) [mm] at cam angles (m,) [rad]; see the module notes.

    With ``cam`` the design's three rigid modes join the basis (deviations after a best fit).
    """
    u = np.asarray(angle, dtype=float)
    y = np.asarray(deviation, dtype=float)
    m = u.size
    top = min(m // 4, MAX_ORDER) if max_order is None else max_order
    if m < 8 or top < 0:
        raise DesignError("measured", f"{m} deviations; allowed: at least 8 to smooth")
    a = _basis(u, top, 0, cam)
    # Nested bases: the fit of order H uses the first p columns. With the Gram matrix G = AᵀA = LLᵀ
    # (Cholesky, itself nested) and z = L⁻¹Aᵀy, the residual of the first p columns is |y|² − Σ_{i<p} zᵢ².
    # (A Householder QR would do the same; on this shared machine it was 100 times slower.)
    low = cholesky(a.T @ a, lower=True)
    z = solve_triangular(low, a.T @ y, lower=True)
    total = float(y @ y)
    p = 2 * np.arange(top + 1) + 1 + (0 if cam is None else 3)
    rss = total - np.cumsum(z**2)[p - 1]
    gcv = m * np.maximum(rss, 0.0) / (m - p) ** 2
    h = int(np.argmin(gcv))
    k = int(p[h])
    lk = low[:k, :k]
    coef = solve_triangular(lk.T, z[:k], lower=False)
    sigma2 = max(float(rss[h]), 0.0) / (m - k)
    linv = solve_triangular(lk, np.eye(k), lower=True)
    cov = sigma2 * (linv.T @ linv)  # σ²(AᵀA)⁻¹
    readonly(coef, cov)
    return FormFit(order=h, coefficients=coef, covariance=cov, noise=math.sqrt(sigma2), cam=cam)


@dataclass(frozen=True, slots=True, kw_only=True)
class ActualMotion:
    """The follower motion of the measured cam and one standard deviation of each (n,) arrays.

    Lift in the program's unit, velocity per rad, acceleration per rad²
    (NaN for a face on an arm); ``form`` the smoothed form error.
    """

    phi: FloatArray
    lift: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    lift_std: FloatArray
    velocity_std: FloatArray
    acceleration_std: FloatArray
    form: FormFit


def actual_motion(cam: Cam, inspection: Inspection, phi: ArrayLike | None = None) -> ActualMotion:
    """The motion the measured cam gives at cam angles φ [rad] (default: the design's samples)."""
    ph = cam.sample_phi() if phi is None else np.asarray(phi, dtype=float).ravel()
    keep = inspection.inlier
    form = smooth_deviation(inspection.angle[keep], inspection.deviation[keep], cam=cam)
    made = made_motion(cam, ph, form=form)
    sens = sensitivities(cam, ph)
    lift_k, vel_k = sens.lift[sens.row(Tol.FORM)], sens.velocity[sens.row(Tol.FORM)]
    a0, a1, a2 = (_basis(ph, form.order, d, cam) for d in range(3))
    cov = form.covariance

    def spread(rows: FloatArray) -> FloatArray:
        out: FloatArray = np.sqrt(np.einsum("ij,jk,ik->i", rows, cov, rows))
        return out

    out = ActualMotion(
        phi=ph,
        lift=made.lift,
        velocity=made.velocity,
        acceleration=made.acceleration,
        lift_std=spread(lift_k[:, None] * a0),
        velocity_std=spread(lift_k[:, None] * a1 + vel_k[:, None] * a0),
        acceleration_std=spread(lift_k[:, None] * a2),
        form=form,
    )
    readonly(out.lift_std, out.velocity_std, out.acceleration_std)
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class Compensation:
    """The corrected profile: design offset by ``correction`` = −e(u) along the outward normal.

    ``phi`` (n,) [rad], ``correction`` (n,) [mm], ``point`` and ``normal`` (n, 2)
    in the cam frame, ``radius`` (n,) signed radius of curvature [mm] (convex > 0).
    """

    phi: FloatArray
    correction: FloatArray
    point: FloatArray
    normal: FloatArray
    radius: FloatArray


def compensate(
    cam: Cam, form: FormFit, *, stock: float, tool_radius: float, phi: ArrayLike | None = None
) -> Compensation:
    """The profile that removes the measured systematic error ``form``, checked against stock and tool.

    Parameters
    ----------
    cam
        The design.
    form
        The smoothed form error (:func:`smooth_deviation`, ``ActualMotion.form``).
    stock
        The most the correction may move the profile either way [mm], ≥ 0.
    tool_radius
        Radius of the tool that cuts it [mm]: every concave radius must be larger.
    phi
        Cam angles [rad]; default the design's samples.

    Raises
    ------
    DesignLimitError
        Where |correction| > stock (named by angle range).
    GougeError
        Where the corrected profile is concave tighter than the tool.
    """
    if not (math.isfinite(stock) and stock >= 0.0):
        raise DesignError("stock", f"{stock!r} mm; allowed: ≥ 0")
    if not (math.isfinite(tool_radius) and tool_radius >= 0.0):
        raise DesignError("tool_radius", f"{tool_radius!r} mm; allowed: ≥ 0")
    ph = cam.sample_phi() if phi is None else np.asarray(phi, dtype=float).ravel()
    e, _, _ = form(ph)
    over = np.abs(e) > stock
    if np.any(over):
        where = format_ranges(flagged_ranges(ph, over))
        raise DesignLimitError(
            f"the correction needs up to {float(np.max(np.abs(e))) * 1000:.1f} µm at {where}, beyond the "
            f"stock {stock * 1000:g} µm; allowed: a correction within the stock"
        )

    def negated(u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        e0, e1, e2 = form(u)
        return -e0, -e1, -e2

    curve = made_curve(cam, ph, np.full(ph.size, -cam.roller_radius), negated)
    with np.errstate(divide="ignore"):
        radius = np.where(curve.curvature == 0.0, np.inf, 1.0 / curve.curvature)
    tight = (radius < 0.0) & (-radius < tool_radius)
    if np.any(tight):
        worst = float(np.min(-radius[tight]))
        ranges = flagged_ranges(ph, tight)
        raise GougeError(
            f"the corrected profile is concave with radius {worst:.3f} mm at {format_ranges(ranges)}, "
            f"tighter than the tool radius {tool_radius:g} mm; allowed: a smaller tool, or no correction",
            phi_range=ranges[0],
            max_tool_radius=worst,
        )
    out = Compensation(phi=ph, correction=-e, point=curve.x, normal=curve.normal, radius=radius)
    readonly(out.correction, out.point, out.normal, out.radius)
    return out
