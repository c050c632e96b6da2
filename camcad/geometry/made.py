"""The motion a made cam gives: the follower's position re-solved by contact on the exact curves.

The second method of the tolerance analysis, independent of the linear one
(:mod:`camcad.geometry.sensitivity`): the made cam is the design's base curve
(a roller's pitch curve, a face's profile) offset along its normal by
w(u) = δ(roller radius) + δ(form) + e(u), e an optional measured form error,
keyed on its shaft δ late, and the follower sits on its (perturbed) mount.
At each cam angle φ the contact is found on the exact curve, not on samples:
the cam-frame parameter u where

* a roller's centre Y(u) lies on the slide's axis or on the arm's circle
  |Y − P| = l;
* a face's normal equals the made profile's normal (slide), or the made
  profile's tangent line lies at f from the pivot (arm);

by Newton's method on u from the nominal contact (u = φ − δ), each step with
the curve's exact derivative. Velocity and acceleration of the made motion
come from differentiating the contact condition along φ (the curve's first
and second derivatives; the acceleration of a face on an arm would need the
made curve's third and is left NaN). The pressure angle is measured from the
made curve's normal at the contact, not from the Kennedy identity the linear
method uses.

Made curve X = P + w·N with N′ = P′/ρ (Frenet; P the design base curve, ρ its
signed radius, ρ′ = dρ/dφ from the envelope):
X′ = P′(1 + w/ρ) + w′N, X″ = P″(1 + w/ρ) + P′(2w′/ρ − wρ′/ρ²) + w″N
(for w constant, Quintero & Vanegas 2016, eq. 13).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.errors import DesignLimitError
from camcad.geometry.cam import Cam
from camcad.geometry.envelope import PointElement, line_envelope, point_envelope
from camcad.geometry.sensitivity import Mount, Tol, mount_of

__all__ = ["FormError", "MadeCurve", "MadeMotion", "made_curve", "made_motion"]

FormError = Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]
"""e(u), de/du, d²e/du² [mm, mm/rad, mm/rad²]: a normal form error along the cam angle u [rad]."""

_MAX_STEP = 0.05  # rad: Newton steps are clipped to this
_ITERATIONS = 40


@dataclass(frozen=True, slots=True, kw_only=True)
class MadeMotion:
    """The follower motion of a made cam, arrays (..., n) over variants and cam angles.

    ``lift`` in the program's unit (mm or ° of swing), ``velocity`` per rad,
    ``acceleration`` per rad² (NaN for a face on an arm), ``pressure_angle``
    [rad], ``contact`` the cam-frame parameter u of the contact on the design [rad].
    For the contact stress: ``profile_rho`` the made cam profile's signed radius
    of curvature at the contact [mm] (convex > 0, ``inf`` straight),
    ``roller_radius`` the made roller's radius [mm] (0 for a face) and
    ``lever`` the distance from an arm's pivot to the driven point (the roller
    centre, a face's contact) [mm], NaN on a slide.
    """

    phi: FloatArray
    lift: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    pressure_angle: FloatArray
    contact: FloatArray
    profile_rho: FloatArray
    roller_radius: FloatArray
    lever: FloatArray


def _j(v: FloatArray) -> FloatArray:
    return np.stack((-v[..., 1], v[..., 0]), axis=-1)


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    out: FloatArray = np.sum(a * b, axis=-1)
    return out


def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    out: FloatArray = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def _turn(v: FloatArray, angle: FloatArray) -> FloatArray:
    """R(angle)·v, each (m, 2) vector by its own angle (m,)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.stack((c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]), axis=-1)


@dataclass(frozen=True, slots=True)
class MadeCurve:
    """A made curve at parameters u (m,), cam frame: point, X′, X″ [mm/radᵏ], outward normal, 1/ρ [1/mm].

    ``curvature`` is 1/ρ with ρ signed as everywhere (convex > 0).
    """

    x: FloatArray
    d1: FloatArray
    d2: FloatArray
    normal: FloatArray
    curvature: FloatArray


def made_curve(cam: Cam, u: FloatArray, w: FloatArray, form: FormError | None) -> MadeCurve:
    """The design's base curve (a roller's pitch curve, a face's profile) offset by w + e(u), exact to X″.

    ``w`` (m,) [mm] per point; for a roller, w = −r_f gives the profile itself.
    """
    m = cam.motion(u)
    element = cam.follower.element(m)
    if isinstance(element, PointElement):
        base, drho = point_envelope(m.phi, element, cam.sigma)
    else:
        base, drho = line_envelope(m.phi, element, cam.sigma)
    e0 = e1 = e2 = np.zeros_like(u)
    if form is not None:
        e0, e1, e2 = form(u)
    off = w + e0
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(np.isinf(base.rho), 0.0, 1.0 / base.rho)  # 1/ρ
        dk = np.where(np.isinf(base.rho), 0.0, -drho / base.rho**2)  # d(1/ρ)/dφ
    n = base.normal
    stretch = 1.0 + off * k
    d1 = base.d1 * stretch[:, None] + e1[:, None] * n
    d2 = base.d2 * stretch[:, None] + base.d1 * (2.0 * e1 * k + off * dk)[:, None] + e2[:, None] * n
    side = np.sign(_dot(n, _j(base.tangent)))  # N = ±J·T, kept for the made curve
    speed = np.hypot(d1[:, 0], d1[:, 1])
    normal = side[:, None] * _j(d1 / speed[:, None])
    curvature = -side * _cross(d1, d2) / speed**3  # 1/ρ, convex > 0
    return MadeCurve(base.point + off[:, None] * n, d1, d2, normal, curvature)


def _as_variants(deltas: Mapping[Tol, ArrayLike]) -> tuple[dict[Tol, FloatArray], tuple[int, ...]]:
    arrays = {k: np.asarray(v, dtype=float) for k, v in deltas.items()}
    shape = np.broadcast_shapes(*(a.shape for a in arrays.values())) if arrays else ()
    return {k: np.broadcast_to(a, shape).ravel() for k, a in arrays.items()}, shape


def made_motion(
    cam: Cam,
    phi: ArrayLike,
    *,
    deltas: Mapping[Tol, ArrayLike] | None = None,
    form: FormError | None = None,
) -> MadeMotion:
    """Re-solve the follower's motion on the made cam at cam angles φ (n,) [rad].

    Parameters
    ----------
    cam
        The design.
    phi
        (n,) cam angles [rad], the same for every variant, or (V, n): each variant's own.
    deltas
        Errors by :class:`~camcad.geometry.sensitivity.Tol`, each a scalar or an
        array of variants (V,) (lengths mm, ``PHASE`` rad); broadcast together.
    form
        An optional normal form error e(u) with two derivatives, on top of ``FORM``.

    Returns
    -------
    MadeMotion
        Arrays (V, n), or (n,) without variants.

    Raises
    ------
    DesignLimitError
        Where the follower finds no contact near the nominal one (an error
        so large the follower jumps to another part of the cam).
    """
    mount0 = mount_of(cam)
    var, shape = _as_variants(deltas or {})
    nv = int(np.prod(shape)) if shape else 1
    phi_in = np.asarray(phi, dtype=float)
    own = phi_in.ndim == 2
    if own and phi_in.shape[0] != nv:
        raise ValueError(f"phi of shape {phi_in.shape} for {nv} variants; allowed: (n,) or ({nv}, n)")
    ph = phi_in.reshape(nv, -1) if own else phi_in.ravel()
    count = ph.shape[-1]

    def per_point(tol: Tol) -> FloatArray:
        a = var.get(tol, np.zeros(nv))
        return np.repeat(a if a.size == nv else np.zeros(nv), count)

    phi_all = ph.ravel() if own else np.tile(ph, nv)
    phase = per_point(Tol.PHASE)
    w = per_point(Tol.FORM) + (per_point(Tol.ROLLER_RADIUS) if mount0.has_circle else 0.0)
    mounts = _mount_arrays(mount0, {t: per_point(t) for t in Tol})
    sigma = mount0.sigma
    angle = sigma * (phi_all - phase)  # the cam's turn: R(σ(φ − δ))
    u = phi_all - phase
    done = np.zeros(u.shape, dtype=bool)
    for _ in range(_ITERATIONS):  # each point stops on its own: a batch gives each variant's own bytes
        curve = made_curve(cam, u, w, form)
        g, g_u = _condition(mount0, mounts, curve, angle)
        step = np.clip(g / g_u, -_MAX_STEP, _MAX_STEP)
        u = np.where(done, u, u - step)
        done |= np.abs(step) < 1e-13
        if np.all(done):
            break
    curve = made_curve(cam, u, w, form)
    g, g_u = _condition(mount0, mounts, curve, angle)
    bad = ~(np.abs(g) < 1e-9 * max(1.0, float(np.max(np.abs(g_u))))) | (np.abs(u - phi_all + phase) > 0.5)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise DesignLimitError(
            f"no contact near the design's at {math.degrees(phi_all[i]):.2f}°: the errors move the "
            "follower onto another part of the cam; allowed: errors small against the cam's radii"
        )
    lift, vel, acc, alpha = _kinematics(mount0, mounts, curve, angle, g_u)
    scale = mount0.lift_scale
    roller = mount0.roller_radius + (per_point(Tol.ROLLER_RADIUS) if mount0.has_circle else 0.0)
    # the made profile is the made base curve offset inwards by the made roller: ρ = ρ_base − r_f
    # (an offset curve's radius, Rothbart 2004, §6), as 1/ρ = κ/(1 − r_f·κ) so a straight flank stays finite
    kappa = curve.curvature
    with np.errstate(divide="ignore", invalid="ignore"):
        profile_rho = 1.0 / (kappa / (1.0 - roller * kappa))
    if mount0.axis is None:
        arm = _turn(curve.x, angle) - mounts.pivot  # to the roller centre, or to a face's contact
        lever = np.hypot(arm[:, 0], arm[:, 1])
    else:
        lever = np.full(u.shape, np.nan)
    out_shape = (*shape, count)
    out = MadeMotion(
        phi=ph,
        lift=(lift * scale).reshape(out_shape),
        velocity=(vel * scale).reshape(out_shape),
        acceleration=(acc * scale).reshape(out_shape),
        pressure_angle=alpha.reshape(out_shape),
        contact=u.reshape(out_shape),
        profile_rho=np.asarray(profile_rho, dtype=float).reshape(out_shape),
        roller_radius=np.broadcast_to(np.asarray(roller, dtype=float), u.shape).reshape(out_shape).copy(),
        lever=lever.reshape(out_shape),
    )
    readonly(out.phi, out.lift, out.velocity, out.acceleration, out.pressure_angle, out.contact)
    readonly(out.profile_rho, out.roller_radius, out.lever)
    return out


@dataclass(frozen=True, slots=True)
class _Mounts:
    """A mount's numbers per point (m,), for vectorised variants."""

    origin: FloatArray  # (m, 2) slide reference point
    pivot: FloatArray  # (m, 2)
    arm: FloatArray  # (m,)
    face: FloatArray  # (m,)


def _mount_arrays(mount: Mount, d: dict[Tol, FloatArray]) -> _Mounts:
    m = d[Tol.PHASE].size
    if mount.axis is not None:
        a = np.asarray(mount.axis)
        origin = np.asarray(mount.origin)[None, :] + np.column_stack(
            (d[Tol.ECCENTRICITY] + d[Tol.CENTRE_DISTANCE] * a[0], d[Tol.CENTRE_DISTANCE] * a[1])
        )
        return _Mounts(origin, np.zeros((m, 2)), np.zeros(m), np.zeros(m))
    p = np.asarray(mount.pivot)
    radial = p / np.hypot(*p)
    pivot = p[None, :] + np.column_stack(
        (
            d[Tol.PIVOT_X] + d[Tol.CENTRE_DISTANCE] * radial[0],
            d[Tol.PIVOT_Y] + d[Tol.CENTRE_DISTANCE] * radial[1],
        )
    )
    return _Mounts(
        np.zeros((m, 2)), pivot, mount.arm_length + d[Tol.ARM_LENGTH], mount.face_offset + d[Tol.FACE_OFFSET]
    )


def _condition(
    mount: Mount, mounts: _Mounts, curve: MadeCurve, angle: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """g(u) = 0 at the contact, and dg/du (see the module notes)."""
    y = _turn(curve.x, angle)
    y_u = _turn(curve.d1, angle)
    if mount.has_circle:
        if mount.axis is not None:
            a_perp = np.array([mount.axis[1], -mount.axis[0]])
            return _dot(y - mounts.origin, a_perp), _dot(y_u, a_perp)
        r = y - mounts.pivot
        return _dot(r, r) - mounts.arm**2, 2.0 * _dot(r, y_u)
    n = _turn(curve.normal, angle)
    n_u = y_u * curve.curvature[:, None]  # N′ = X′/ρ
    if mount.axis is not None:
        a_perp = np.array([mount.axis[1], -mount.axis[0]])
        return _dot(n, a_perp), _dot(n_u, a_perp)
    r = y - mounts.pivot
    return _dot(n, r) + mounts.face, _dot(n_u, r)


def _kinematics(
    mount: Mount, mounts: _Mounts, curve: MadeCurve, angle: FloatArray, g_u: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """q, dq/dφ, d²q/dφ² [mm or rad] and α [rad] at the converged contact."""
    sigma = mount.sigma
    y = _turn(curve.x, angle)
    y_u = _turn(curve.d1, angle)
    y_uu = _turn(curve.d2, angle)
    n = _turn(curve.normal, angle)
    n_u = y_u * curve.curvature[:, None]
    nan = np.full(y.shape[0], np.nan)
    if mount.has_circle:
        if mount.axis is not None:
            a = np.asarray(mount.axis)
            a_perp = np.array([a[1], -a[0]])
            u1 = -_dot(sigma * _j(y), a_perp) / g_u
            yd = sigma * _j(y) + y_u * u1[:, None]
            rest = -y + 2.0 * sigma * _j(y_u) * u1[:, None] + y_uu * (u1**2)[:, None]
            u2 = -_dot(rest, a_perp) / _dot(y_u, a_perp)
            ydd = rest + y_u * u2[:, None]
            q, q1, q2 = _dot(y - mounts.origin, a), _dot(yd, a), _dot(ydd, a)
            d = np.broadcast_to(a, y.shape)
        else:
            r = y - mounts.pivot
            u1 = -2.0 * _dot(r, sigma * _j(y)) / g_u
            yd = sigma * _j(y) + y_u * u1[:, None]
            rest = -y + 2.0 * sigma * _j(y_u) * u1[:, None] + y_uu * (u1**2)[:, None]
            u2 = -(_dot(r, rest) + _dot(yd, yd)) / _dot(r, y_u)
            ydd = rest + y_u * u2[:, None]
            rr = _dot(r, r)
            theta = np.arctan2(r[:, 1], r[:, 0])
            q = _wrap(theta - mount.theta0) / mount.turn
            q1 = _cross(r, yd) / rr / mount.turn
            q2 = _cross(r, ydd) / rr / mount.turn
            d = mount.turn * _j(r)
    else:
        if mount.axis is not None:
            a = np.asarray(mount.axis)
            a_perp = np.array([a[1], -a[0]])
            u1 = -_dot(sigma * _j(n), a_perp) / g_u
            yd = sigma * _j(y) + y_u * u1[:, None]
            p = _dot(y, a)
            q, q1 = p - _dot(mounts.origin, a), _dot(yd, a)
            q2 = 1.0 / curve.curvature - p  # support function: p″ + p = ρ
            d = np.broadcast_to(a, y.shape)
        else:
            r = y - mounts.pivot
            u1 = sigma * _dot(_j(n), mounts.pivot) / g_u  # g_φ = −σ·Jn·P
            nd = sigma * _j(n) + n_u * u1[:, None]
            theta = np.arctan2(n[:, 1], n[:, 0])
            q = _wrap(theta - mount.theta0) / mount.turn
            q1 = _cross(n, nd) / mount.turn
            q2 = nan
            d = mount.turn * _j(r)
    alpha = sigma * np.arctan2(_cross(d, n), _dot(d, n))
    return q, q1, q2, alpha


def _wrap(x: FloatArray) -> FloatArray:
    out: FloatArray = (x + np.pi) % (2.0 * np.pi) - np.pi
    return out
