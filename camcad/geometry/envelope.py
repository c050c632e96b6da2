"""The generic envelope: a follower's contact element, seen from the turning cam, becomes the profile.

A follower module describes, in the fixed machine frame, what its contact
element does at cam angle φ: a roller centre M(φ) (a :class:`PointElement`)
or a face line n(θ)·x = p (a :class:`LineElement`), each with its first
three φ-derivatives in closed form, and how the follower is guided (a
:class:`Guide`: a translation axis or a pivot). This module turns that into
cam-frame curves with exact tangents, outward normals and signed radii of
curvature, and into the pressure angle, for any follower.

Kinematic inversion: the cam turns by +φ (ccw, σ = +1) or −φ (cw, σ = −1)
about the origin while the machine stays put, so a machine-frame point M(φ)
is, in the cam frame, X(φ) = R(−σφ)·M(φ). Its derivatives are
X^(k) = R(−σφ)·D^k M with D(L) = L′ − σ·J·L and J the quarter turn
J(x, y) = (−y, x) (Rothbart 2004, §6.3: inversion of a disc cam mechanism).
A line n(θ)·x = p keeps p and turns its normal angle to θ − σφ.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.geometry.curves import CurveSample, curve_sample

__all__ = [
    "Guide",
    "LineElement",
    "PointElement",
    "keep_turn",
    "line_envelope",
    "offset_curve",
    "point_envelope",
    "pressure_angle",
    "to_cam",
    "translation_envelope",
]


def _quarter(v: FloatArray) -> FloatArray:
    """J·v: each (n, 2) vector turned by +90°."""
    return np.column_stack((-v[:, 1], v[:, 0]))


_TURNS: dict[tuple[int, float], tuple[weakref.ref[FloatArray], FloatArray, FloatArray]] = {}
_TURNS_KEPT = 8  # angle arrays whose cos and sin are kept
_TURNS_MIN = 64  # ... of at least this many angles


def _turn(phi: FloatArray, sigma: float) -> tuple[FloatArray, FloatArray]:
    """The cos σφ and sin σφ of a read-only angle array, kept (one cam state turns it several times).

    The cos and sin of an array of many angles cost more than the rest of a
    turn; every curve of one cam state is turned by the same angles, so
    they are computed once per (read-only) array and σ, the same values.
    """
    if phi.size < _TURNS_MIN or phi.flags.writeable:
        return np.cos(sigma * phi), np.sin(sigma * phi)
    key = (id(phi), sigma)
    hit = _TURNS.get(key)
    if hit is not None and hit[0]() is phi:
        return hit[1], hit[2]
    c, s = np.cos(sigma * phi), np.sin(sigma * phi)
    if len(_TURNS) >= _TURNS_KEPT:
        _TURNS.clear()
    _TURNS[key] = (weakref.ref(phi), c, s)
    return c, s


def keep_turn(phi: FloatArray, sigma: float, cos: FloatArray, sin: FloatArray) -> None:
    """Hand :func:`to_cam` the cos σφ and sin σφ of a read-only angle array computed elsewhere.

    For a batch that stacks one sample grid many times (:mod:`camcad.explore.batch`):
    the grid's cos and sin, tiled, are the stacked array's, value for value.
    """
    if phi.size >= _TURNS_MIN and not phi.flags.writeable:
        if len(_TURNS) >= _TURNS_KEPT:
            _TURNS.clear()
        _TURNS[(id(phi), sigma)] = (weakref.ref(phi), cos, sin)


def to_cam(phi: FloatArray, vectors: FloatArray, sigma: float) -> FloatArray:
    """R(−σφ)·v: machine-frame vectors (n, 2) seen from the cam at cam angles φ (n,) [rad]."""
    c, s = _turn(np.asarray(phi), sigma)
    x, y = vectors[:, 0], vectors[:, 1]
    return np.column_stack((c * x + s * y, -s * x + c * y))


@dataclass(frozen=True, slots=True, kw_only=True)
class Guide:
    """How the follower is guided in the machine frame: along ``axis`` or about ``pivot``.

    Exactly one is given. ``axis`` is the unit direction in which the follower
    moves as its displacement grows; ``pivot`` [mm] is the arm's pivot, with
    ``turn`` = +1 when a growing arm angle turns the arm counter-clockwise.
    """

    axis: tuple[float, float] | None = None
    pivot: tuple[float, float] | None = None
    turn: float = 1.0

    def driven(self, point: FloatArray) -> FloatArray:
        """(n, 2) unit direction in which the follower drives the machine-frame points (n, 2)."""
        if self.axis is not None:
            along: FloatArray = np.broadcast_to(np.asarray(self.axis, dtype=np.float64), point.shape).copy()
            return along
        assert self.pivot is not None
        arm = point - np.asarray(self.pivot, dtype=float)
        unit: FloatArray = self.turn * _quarter(arm) / np.hypot(arm[:, 0], arm[:, 1])[:, None]
        return unit


@dataclass(frozen=True, slots=True, kw_only=True)
class PointElement:
    """A roller centre M(φ) in the machine frame and its φ-derivatives, each (n, 2) [mm/radᵏ]."""

    m0: FloatArray
    m1: FloatArray
    m2: FloatArray
    m3: FloatArray


@dataclass(frozen=True, slots=True, kw_only=True)
class LineElement:
    """A face line n(θ)·x = p in the machine frame, n(θ) = (cos θ, sin θ) pointing at the follower.

    ``theta`` [rad] and ``p`` [mm], each with its first three φ-derivatives, (n,);
    ``normal`` (n, 2) is n(θ) itself, given exactly (e.g. (0, 1) for a face
    across the y axis, where cos(π/2) would leave a 6e-17 residue).
    """

    normal: FloatArray
    theta: tuple[FloatArray, FloatArray, FloatArray, FloatArray]
    p: tuple[FloatArray, FloatArray, FloatArray, FloatArray]


def point_envelope(phi: FloatArray, element: PointElement, sigma: float) -> tuple[CurveSample, FloatArray]:
    """The cam-frame path of a roller centre (the pitch curve) and dρ/dφ of it.

    Returns the pitch curve with its outward normal and signed radius ρ [mm],
    and dρ/dφ [mm/rad] from the third derivative (for exact offsets).

    Notes
    -----
    With L_k = D^k M: L1 = M′ − σJM, L2 = M″ − 2σJM′ − M,
    L3 = M‴ − 3σJM″ − 3M′ + σJM. ρ = s|L1|³/(L1×L2) with s = −σ (the curve
    runs clockwise for a ccw cam), and
    dρ/dφ = s(3|L1|(L1·L2)(L1×L2) − |L1|³(L1×L3))/(L1×L2)².
    """
    m0, m1, m2, m3 = element.m0, element.m1, element.m2, element.m3
    l1 = m1 - sigma * _quarter(m0)
    l2 = m2 - 2.0 * sigma * _quarter(m1) - m0
    l3 = m3 - 3.0 * sigma * _quarter(m2) - 3.0 * m1 + sigma * _quarter(m0)
    pitch = curve_sample(
        phi, to_cam(phi, m0, sigma), to_cam(phi, l1, sigma), to_cam(phi, l2, sigma), clockwise=sigma > 0
    )
    return pitch, _rho_rate(l1, l2, l3, sigma)


def _rho_rate(l1: FloatArray, l2: FloatArray, l3: FloatArray, sigma: float) -> FloatArray:
    """dρ/dφ [mm/rad] of a curve with φ-derivatives L1, L2, L3 (n, 2), running clockwise for σ = +1.

    dρ/dφ = s(3|L1|(L1·L2)(L1×L2) − |L1|³(L1×L3))/(L1×L2)² with s = −σ
    (the derivative of ρ = s|L1|³/(L1×L2)); 0 where the curve is straight.
    """
    speed = np.hypot(l1[:, 0], l1[:, 1])
    cross12 = l1[:, 0] * l2[:, 1] - l1[:, 1] * l2[:, 0]
    cross13 = l1[:, 0] * l3[:, 1] - l1[:, 1] * l3[:, 0]
    dot12 = np.einsum("ij,ij->i", l1, l2)
    with np.errstate(divide="ignore", invalid="ignore"):
        drho = -sigma * (3.0 * speed * dot12 * cross12 - speed**3 * cross13) / cross12**2
    out: FloatArray = np.where(cross12 == 0.0, 0.0, drho)
    return out


def translation_envelope(
    phi: FloatArray, element: PointElement, speed: float
) -> tuple[CurveSample, FloatArray]:
    """The path of a machine point M(φ) seen from a plate that moves by −speed·φ along x, and dρ/dφ.

    The translating counterpart of :func:`point_envelope` (a linear cam, or a
    barrel cam developed at one radius): in the plate's frame the point is
    X(φ) = M(φ) + (cφ, 0) with c = ``speed`` [mm/rad] > 0, so X′ = M′ + (c, 0),
    X″ = M″, X‴ = M‴. The curve runs towards +x, its outward normal is on its
    left (towards the follower, +y), and its radius ρ is positive where it is
    convex seen from there, as for a counter-clockwise disc cam, of which it
    is the limit R → ∞ with Rφ held (Rothbart 2004, §6.3 with the rotation
    replaced by a translation).
    """
    m0, m1, m2, m3 = element.m0, element.m1, element.m2, element.m3
    shift = np.zeros_like(m0)
    shift[:, 0] = speed
    l1 = m1 + shift
    point = m0 + np.column_stack((speed * np.asarray(phi, dtype=float), np.zeros_like(phi)))
    pitch = curve_sample(phi, point, l1, m2, clockwise=True)
    return pitch, _rho_rate(l1, m2, m3, 1.0)


def line_envelope(phi: FloatArray, element: LineElement, sigma: float) -> tuple[CurveSample, FloatArray]:
    """The profile a family of face lines envelopes, in the cam frame, and dρ/dφ of it.

    Notes
    -----
    In the cam frame the line is n(ϑ)·x = p with ϑ = θ − σφ. The envelope
    (n·x = p and n′·x = p′) is C = p·n + q·t with t = dn/dϑ and q = p′/ϑ′;
    C′ = (p·ϑ′ + q′)·t, so the radius of curvature is ρ = p + q′/ϑ′ and the
    outward normal is n (Rothbart 2004, §6.4; for a translating flat face
    ϑ′ = −σ and ρ = r_b + s + d²s/dφ², Hren et al. with the papers/README
    reading).
    """
    _, t1, t2, t3 = element.theta
    p0, p1, p2, p3 = element.p
    w1 = t1 - sigma  # ϑ′, never 0: the face turns relative to the cam
    w2, w3 = t2, t3
    q0 = p1 / w1
    q1 = (p2 * w1 - p1 * w2) / w1**2
    q2 = (p3 * w1**2 - 2.0 * p2 * w1 * w2 - p1 * w1 * w3 + 2.0 * p1 * w2**2) / w1**3
    rho = p0 + q1 / w1
    drho = p1 + (q2 * w1 - q1 * w2) / w1**2
    normal = to_cam(phi, element.normal, sigma)  # n(ϑ) = R(−σφ)·n(θ)
    tang = _quarter(normal)
    point = p0[:, None] * normal + q0[:, None] * tang
    speed = p0 * w1 + q1  # C′ = speed·t
    d1 = speed[:, None] * tang
    d2 = (p1 * w1 + p0 * w2 + q2)[:, None] * tang - (speed * w1)[:, None] * normal
    # the tangent in the direction of increasing φ; the outward normal is n
    direction = np.sign(np.where(speed == 0.0, 1.0, speed))
    profile = CurveSample(
        phi=np.asarray(phi, dtype=float),
        point=point,
        d1=d1,
        d2=d2,
        tangent=direction[:, None] * tang,
        normal=normal,
        rho=rho,
    )
    readonly(profile.point, profile.d1, profile.d2, profile.tangent, profile.normal, profile.rho)
    return profile, drho


def offset_curve(base: CurveSample, drho: FloatArray, delta: float) -> CurveSample:
    """The curve ``base`` offset outward by ``delta`` [mm], exact to its second derivative.

    For a base curve P with outward unit normal n and signed radius ρ, the
    offset O = P + δn has O′ = P′(1 + δ/ρ), O″ = P″(1 + δ/ρ) − P′δρ′/ρ² and
    radius ρ + δ (Quintero & Vanegas 2016, eq. 13; papers/README erratum to
    Quang & Hung 2015, eq. 3). Where 1 + δ/ρ < 0 the offset loops (undercut
    or gouge); ``tangent`` and ``normal`` stay those of the base curve.
    """
    if delta == 0.0:
        return base
    rho = base.rho
    with np.errstate(divide="ignore", invalid="ignore"):
        stretch = np.where(np.isinf(rho), 1.0, 1.0 + delta / rho)
        bend = np.where(np.isinf(rho), 0.0, delta * drho / rho**2)
    out = CurveSample(
        phi=base.phi,
        point=base.point + delta * base.normal,
        d1=base.d1 * stretch[:, None],
        d2=base.d2 * stretch[:, None] - base.d1 * bend[:, None],
        tangent=base.tangent,
        normal=base.normal,
        rho=rho + delta,
    )
    readonly(out.point, out.d1, out.d2, out.rho)
    return out


def pressure_angle(
    phi: FloatArray, normal: FloatArray, contact_machine: FloatArray, guide: Guide, sigma: float
) -> FloatArray:
    """Signed pressure angle α [rad]: from the driven direction d to the common normal.

    Parameters
    ----------
    phi
        (n,) cam angles [rad].
    normal
        (n, 2) outward profile normal at the contact, cam frame.
    contact_machine
        (n, 2) the point of the follower that is driven (roller centre, or the
        contact point on a face), machine frame [mm].
    guide
        How the follower is guided.
    sigma
        +1 ccw, −1 cw.

    Notes
    -----
    α = atan2(−σ n·d⊥, n·d) with d⊥ = d turned by −90°: |α| is the angle
    between the normal and the direction the follower is driven in, and
    α > 0 where the normal leans the way the cam surface moves at the
    contact. For an offset translating roller this is
    tan α = (v ∓ e)/(s + k), − for ccw and + for cw (Quang & Hung 2015, eq. 4).
    """
    d = to_cam(phi, guide.driven(contact_machine), sigma)
    d_perp = np.column_stack((d[:, 1], -d[:, 0]))
    along = np.einsum("ij,ij->i", normal, d)
    across = np.einsum("ij,ij->i", normal, d_perp)
    out: FloatArray = np.arctan2(-sigma * across, along)
    readonly(out)
    return out
