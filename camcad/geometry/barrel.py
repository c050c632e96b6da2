"""Barrel (cylindrical) cams: the exact groove walls of a roller running in a groove round a cylinder.

Frames and signs
----------------
The barrel's axis is z; its frame has x, y across it and z along it. In the
machine the roller's axis lies in the plane y = 0 at φ = 0; the barrel turns
by −φ about z (clockwise seen from +z), so in the barrel's frame the follower
(the roller's carrier) stands at barrel angle θ = φ and walks the groove
towards growing θ. With e_r(φ) = (cos φ, sin φ, 0), e_θ(φ) = (−sin φ, cos φ, 0)
and ẑ, the roller's axis is the line A(φ, t) = t·e_r + y·e_θ + z·ẑ: t is the
*station* along the roller's axis [mm], and (y, z)(φ) is where the follower
holds the axis, in the plane perpendicular to it:

- :class:`TranslatingBarrelRoller`: radial axis, y = 0, z = z0 + s(φ)
  (``axial_position`` z0 at φ = 0); the follower is driven along +z.
- :class:`OscillatingBarrelRoller`: an arm of length l on a pivot whose axis
  is parallel to the roller's (perpendicular to the barrel's axis), at
  distance d (``pivot_distance``) from the barrel's axis:
  (y, z) = P + l(cos b, sin b), P = (d, z0 − √(l² − d²)), b = b0 − ψ(φ)
  with (cos b0, sin b0) = (−d, √(l² − d²))/l, so the roller stands at
  (0, z0) at ψ = 0 and a rise (ψ growing) moves it towards +z (and +y).

The roller is a surface of revolution about its axis with radius
r(t) = r0 + k·t: a cylinder (k = 0, r = r_f) or a cone with its apex on the
barrel's axis (k = r_f/t_p, r_f its radius at the pitch station t_p, only
with a radial axis). A wall is the roller's envelope with r widened by half
the clearance c.

The envelope, exactly
---------------------
A point of the roller at station t and angle γ round its axis is
Q = A + r(cos γ e_θ + sin γ ẑ), its outward normal N ∝ −k e_r + cos γ e_θ +
sin γ ẑ. Holding t and γ, dQ/dφ = −(y + r cos γ)e_r + (t + y′)e_θ + z′ẑ, and
the contact condition N·dQ/dφ = 0 (the envelope condition, Rothbart 2004,
§6.3; Litvin & Fuentes 2004, §6.1) reads, with y ≡ 0 whenever k ≠ 0,

    cos γ·q + sin γ·z′ = 0,  q = t + y′ + k·r,

so (cos γ, sin γ) = σ(−z′, q)/D, D = √(z′² + q²): σ = +1 is the *upper* wall
(on the +z side of the roller; it drives the return), σ = −1 the *lower*
wall (it drives the rise). For a cylinder at y ≡ 0 this is the developed
pitch line (tφ, z0 + s) offset by r along its normal: in the plane
perpendicular to the roller's axis at station t the wall is the plate-like
envelope of a circle of radius r round the pitch line developed at radius t
(the roller's cross-section by the cylinder of radius t is not a circle: the
exact statement holds in the plane, see :func:`developed_walls`).

Pressure angle: the angle between the contact normal and the direction d in
which the follower drives the roller's axis (ẑ, or perpendicular to the arm);
for a translating cylinder tan α = s′/t exactly, largest at the groove's
bottom. For a cone it is the 3-D angle, cos α = q/(D√(1 + k²)).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import DesignError
from camcad.geometry.envelope import PointElement
from camcad.geometry.followers import arm_swing, turning_point
from camcad.geometry.followers.base import slide_point
from camcad.knobs import Knob
from camcad.motion.program import Motion

__all__ = [
    "BarrelFollower",
    "BarrelKind",
    "BarrelOptions",
    "BarrelWalls",
    "FaceSource",
    "OscillatingBarrelRoller",
    "RibRoller",
    "RollerShape",
    "Slip",
    "TranslatingBarrelRoller",
    "WallSheet",
    "WallSide",
    "barrel_faces",
    "barrel_walls",
    "check_barrel",
    "face_rollers",
    "faces_at_radius",
    "rib_rollers",
    "roller_slip",
    "walls_at_radius",
]


class RollerShape(enum.Enum):
    """The roller: a cylinder, or a cone with its apex on the barrel's axis (pure rolling in dwells)."""

    CYLINDRICAL = "cylindrical"
    CONICAL = "conical"


class BarrelKind(enum.Enum):
    """A ``GROOVE`` cut into the barrel (one roller runs between its walls) or a ``RIB`` standing on it.

    A rib is straddled by two rollers on the same follower, one on each side
    (the rib form of the cylindrical cam, Rothbart 2004, ch. 1):
    each of the rib's faces is the same 3-D envelope as a groove's wall, of
    one roller, with the material on the other side.
    """

    GROOVE = "groove"
    RIB = "rib"


class WallSide(enum.Enum):
    """Which wall: ``UPPER`` on the roller's +z side (drives the return), ``LOWER`` on its −z side."""

    UPPER = 1.0
    LOWER = -1.0


@dataclass(frozen=True, slots=True, kw_only=True)
class BarrelOptions:
    """The barrel and its groove [mm].

    ``barrel_radius`` R (outer), ``length`` along z (the barrel spans
    0 ≤ z ≤ length), ``bore`` diameter, groove ``depth`` (bottom at R − depth)
    and radial ``clearance`` c (the groove is 2r + c wide), ``roller_radius``
    r_f (a cone's radius at the pitch station), ``roller_length`` ℓ (the
    roller reaches from the barrel's surface to station R − ℓ, its pitch
    station t_p = R − ℓ/2), and the roller's shape.

    ``kind`` :attr:`BarrelKind.RIB`: a rib of height ``depth`` (its top at
    R, the barrel's core of radius R − depth) and of ``rib_width`` w [mm]
    along the barrel's axis where the follower dwells, at the pitch station;
    its two rollers' axes stand ±h = ±(w/2 + r_f + c/2) from the follower's
    pitch path (:attr:`rib_offset`), so each face clears its roller by c/2
    as a groove's wall does.
    """

    barrel_radius: float
    length: float
    depth: float
    roller_radius: float
    roller_length: float
    bore: float = 0.0
    clearance: float = 0.0
    roller: RollerShape = RollerShape.CYLINDRICAL
    kind: BarrelKind = BarrelKind.GROOVE
    rib_width: float = 0.0

    @property
    def rib_offset(self) -> float:
        """The rib rollers' offset h = w/2 + r_f + c/2 [mm] from the pitch path (0 for a groove)."""
        if self.kind is BarrelKind.GROOVE:
            return 0.0
        return 0.5 * self.rib_width + self.roller_radius + 0.5 * self.clearance

    @property
    def bottom_radius(self) -> float:
        """R − depth [mm]: the groove's bottom."""
        return self.barrel_radius - self.depth

    @property
    def pitch_station(self) -> float:
        """t_p = R − ℓ/2 [mm]: the middle of the roller's length, where it rolls without slip."""
        return self.barrel_radius - 0.5 * self.roller_length

    @property
    def taper(self) -> float:
        """Taper k = dr/dt: 0 for a cylinder, r_f/t_p for a cone with its apex on the barrel's axis."""
        return 0.0 if self.roller is RollerShape.CYLINDRICAL else self.roller_radius / self.pitch_station

    def roller_at(self, station: FloatArray | float, *, clearance: bool) -> FloatArray:
        """r(t) [mm] at stations t [mm]: the roller's radius, or with c/2 added the wall's."""
        t = np.asarray(station, dtype=float)
        base = 0.0 if self.roller is RollerShape.CONICAL else self.roller_radius
        out: FloatArray = base + self.taper * t + (0.5 * self.clearance if clearance else 0.0)
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class TranslatingBarrelRoller:
    """A roller on a radial axis, driven along the barrel's axis: (y, z) = (0, z0 + s) [mm]."""

    axial_position: float  # z0 [mm] at φ = 0

    def centre(self, motion: Motion) -> PointElement:
        """(y, z) = (0, z0 + s) and its φ-derivatives (0, v), (0, a), (0, j)."""
        return slide_point(0.0, self.axial_position, motion)

    def driven(self, motion: Motion) -> FloatArray:
        """(n, 2) unit (y, z) direction the axis is driven in: +z."""
        out: FloatArray = np.tile([0.0, 1.0], (np.size(motion.phi), 1))
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class OscillatingBarrelRoller:
    """A roller on an arm of length l [mm] about a pivot axis parallel to its own, d [mm] off the axis.

    The lift of the motion is the arm angle ψ in degrees, as for a plate
    cam's oscillating follower (:func:`camcad.geometry.followers._arm.arm_swing`).
    """

    axial_position: float  # z0 [mm]: the roller's axial position at φ = 0 (ψ = 0)
    pivot_distance: float  # d [mm]
    arm_length: float  # l [mm]

    @property
    def pivot(self) -> tuple[float, float]:
        """P = (d, z0 − √(l² − d²)) [mm], (y, z) in the plane perpendicular to the roller's axis."""
        d, arm = self.pivot_distance, self.arm_length
        return (d, self.axial_position - math.sqrt(max(arm * arm - d * d, 0.0)))

    @property
    def initial_arm_angle(self) -> float:
        """b0 [rad]: the arm's direction pivot → roller at ψ = 0, from +y towards +z."""
        d, arm = self.pivot_distance, self.arm_length
        return math.atan2(math.sqrt(max(arm * arm - d * d, 0.0)), -d)

    def centre(self, motion: Motion) -> PointElement:
        """(y, z) = P + l(cos b, sin b), b = b0 − ψ, with three φ-derivatives by the chain rule.

        b′ = −ψ′, b″ = −ψ″, b‴ = −ψ‴ (ψ in rad from the motion's degrees);
        (y, z)′ = l b′(−sin b, cos b), and so on
        (:func:`~camcad.geometry.followers._arm.turning_point`).
        """
        psi, d1, d2, d3 = arm_swing(motion)
        return turning_point(self.pivot, self.arm_length, (self.initial_arm_angle - psi, -d1, -d2, -d3))

    def driven(self, motion: Motion) -> FloatArray:
        """(n, 2) unit (y, z) direction the roller's axis moves in as ψ grows: (sin b, −cos b)."""
        b = self.initial_arm_angle - arm_swing(motion)[0]
        out: FloatArray = np.column_stack((np.sin(b), -np.cos(b)))
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class RibRoller:
    """One of a rib's two rollers: carried by ``follower``, ``offset`` h [mm] from its pitch path.

    The offset is along the direction the follower drives the roller's axis
    and moves rigidly with the follower: +z for a translating follower; for
    an arm, a yoke across the arm's end, so the roller sits at
    P + l·e(b) + h·(sin b, −cos b) = P + L·e(b − β), L = √(l² + h²),
    tan β = h/l (the arm's kinematics with a longer arm turned by −β).
    """

    follower: TranslatingBarrelRoller | OscillatingBarrelRoller
    offset: float  # h [mm], + towards the follower's rise

    def centre(self, motion: Motion) -> PointElement:
        """(y, z) of this roller's axis and its φ-derivatives (see the class notes)."""
        f = self.follower
        if isinstance(f, TranslatingBarrelRoller):
            return slide_point(0.0, f.axial_position + self.offset, motion)
        psi, d1, d2, d3 = arm_swing(motion)
        beta = math.atan2(self.offset, f.arm_length)
        length = math.hypot(f.arm_length, self.offset)
        return turning_point(f.pivot, length, (f.initial_arm_angle - beta - psi, -d1, -d2, -d3))

    def driven(self, motion: Motion) -> FloatArray:
        """(n, 2) unit (y, z) direction this roller's axis moves in as the lift grows."""
        f = self.follower
        if isinstance(f, TranslatingBarrelRoller):
            return f.driven(motion)
        b = f.initial_arm_angle - math.atan2(self.offset, f.arm_length) - arm_swing(motion)[0]
        out: FloatArray = np.column_stack((np.sin(b), -np.cos(b)))
        return out


BarrelFollower = TranslatingBarrelRoller | OscillatingBarrelRoller | RibRoller


@dataclass(frozen=True, slots=True, kw_only=True)
class WallSheet:
    """One wall on a grid of motion angles × stations, barrel frame.

    ``point`` (n, m, 3) [mm]; ``normal`` (n, m, 3) unit, pointing out of the
    barrel's material into the groove (towards the roller's axis).
    """

    point: FloatArray
    normal: FloatArray


@dataclass(frozen=True, slots=True, kw_only=True)
class BarrelWalls:
    """Both walls of the groove at motion angles φ (n,) [rad] and stations t (m,) [mm].

    ``axis`` (n, 2) the roller axis's (y, z) [mm]; ``pressure_angle`` (n, m)
    [rad], signed: positive where the normal of the upper wall leans back
    against the travel (on a translating rise), the same magnitude at both
    walls.
    """

    phi: FloatArray
    station: FloatArray
    axis: FloatArray
    upper: WallSheet
    lower: WallSheet
    pressure_angle: FloatArray


def _frame(phi: FloatArray) -> tuple[FloatArray, FloatArray]:
    """e_r and e_θ (n, 3) at barrel angles φ."""
    c, s = np.cos(phi), np.sin(phi)
    zero = np.zeros_like(phi)
    return np.stack((c, s, zero), axis=-1), np.stack((-s, c, zero), axis=-1)


@dataclass(frozen=True, slots=True, kw_only=True)
class _Contact:
    """The contact on one wall: (n, m) arrays, see the module's notes."""

    t: FloatArray
    r: FloatArray
    cos: FloatArray
    sin: FloatArray
    q: FloatArray
    y: FloatArray
    y1: FloatArray
    z: FloatArray
    z1: FloatArray


def _contact(
    axis: PointElement, station: FloatArray, options: BarrelOptions, side: WallSide, *, clearance: bool
) -> _Contact:
    """(cos γ, sin γ) = σ(−z′, q)/D with q = t + y′ + k·r on a grid of angles (n) × stations (m)."""
    t = np.asarray(station, dtype=float)
    if t.ndim == 1:
        t = t[None, :]
    y, z = axis.m0[:, 0:1], axis.m0[:, 1:2]
    y1, z1 = axis.m1[:, 0:1], axis.m1[:, 1:2]
    r = options.roller_at(t, clearance=clearance)
    q = t + y1 + options.taper * r
    big = np.hypot(z1, q)
    sigma = side.value
    t_b, r_b = np.broadcast_arrays(t + 0.0 * y, r + 0.0 * y)
    return _Contact(
        t=t_b,
        r=r_b,
        cos=-sigma * z1 / big,
        sin=sigma * q / big,
        q=q,
        y=np.broadcast_to(y, q.shape),
        y1=np.broadcast_to(y1, q.shape),
        z=np.broadcast_to(z, q.shape),
        z1=np.broadcast_to(z1, q.shape),
    )


def _sheet(phi: FloatArray, c: _Contact, taper: float) -> WallSheet:
    e_r, e_t = _frame(phi)
    e_r, e_t = e_r[:, None, :], e_t[:, None, :]
    zhat = np.array([0.0, 0.0, 1.0])
    across = c.y + c.r * c.cos
    point = c.t[..., None] * e_r + across[..., None] * e_t + (c.z + c.r * c.sin)[..., None] * zhat
    roller_normal = -taper * e_r + c.cos[..., None] * e_t + c.sin[..., None] * zhat
    normal = -roller_normal / math.sqrt(1.0 + taper * taper)
    readonly(point, normal)
    return WallSheet(point=point, normal=normal)


def _pressure(c: _Contact, driven: FloatArray, taper: float) -> FloatArray:
    """Signed 3-D angle between the upper wall's contact normal N and the driven direction d.

    With N = (−k, cos γ, sin γ)/√(1 + k²) in (e_r, e_θ, ẑ) and d = (0, d_y, d_z):
    |N × d| = √((N_θ d_z − N_z d_y)² + N_r²), N·d = N_θ d_y + N_z d_z; the sign
    is that of the in-plane d × N = d_y N_z − d_z N_θ.
    """
    norm = math.sqrt(1.0 + taper * taper)
    n_r, n_t, n_z = -taper / norm, c.cos / norm, c.sin / norm
    d_y, d_z = driven[:, 0:1], driven[:, 1:2]
    inplane = d_y * n_z - d_z * n_t
    along = n_t * d_y + n_z * d_z
    out: FloatArray = np.sign(inplane) * np.arctan2(np.hypot(inplane, n_r), along)
    return out


def barrel_walls(
    motion: Motion, follower: BarrelFollower, options: BarrelOptions, station: FloatArray
) -> BarrelWalls:
    """Both walls, their normals and the pressure angle on the grid φ (n) × stations t (m).

    Parameters
    ----------
    motion
        s, v, a, j at the angles φ (n,) [rad] (ψ in degrees for an arm).
    follower
        Where the roller's axis is held.
    options
        Barrel, groove and roller.
    station
        (m,) stations t along the roller's axis [mm]; t = R − depth … R spans
        the groove (a wall point at station t lies at √(t² + (y + r cos γ)²)
        from the barrel's axis, a little outside t; :func:`walls_at_radius`
        gives the wall on a cylinder).
    """
    axis = follower.centre(motion)
    phi = np.asarray(motion.phi, dtype=float)
    k = options.taper
    up = _contact(axis, station, options, WallSide.UPPER, clearance=True)
    low = _contact(axis, station, options, WallSide.LOWER, clearance=True)
    alpha = _pressure(up, follower.driven(motion), k)
    readonly(alpha)
    st = np.array(station, dtype=float)
    readonly(st)
    return BarrelWalls(
        phi=phi,
        station=st,
        axis=axis.m0,
        upper=_sheet(phi, up, k),
        lower=_sheet(phi, low, k),
        pressure_angle=alpha,
    )


def walls_at_radius(
    motion: Motion, follower: BarrelFollower, options: BarrelOptions, radius: float, side: WallSide
) -> tuple[FloatArray, WallSheet]:
    """The wall's section by the cylinder of ``radius`` [mm]: stations (n,) and points, normals (n, 1, 3).

    Solves |W(φ, t)|² = t² + (y + r cos γ)² = radius² for the station t by
    Newton's method from t = √(radius² − (y + r cos γ(radius))²). Hand-written
    and vectorised over φ because scipy's root finders loop in Python over
    scalar problems; it stops when every step is below 1e-13·radius (h′ ≈ 2t
    is far from 0 inside a groove, so it converges quadratically).
    """
    axis = follower.centre(motion)
    k = options.taper
    t = np.full((np.size(motion.phi), 1), float(radius))
    for _ in range(50):
        c = _contact(axis, t, options, side, clearance=True)
        g = c.y + c.r * c.cos
        # d cos γ/dt = σ z′ q (dq/dt)/D³ with dq/dt = 1 + k², so dg/dt = k cos γ + r d cos γ/dt
        big = np.hypot(c.z1, c.q)
        dcos = side.value * c.z1 * c.q * (1.0 + k * k) / big**3
        h = t * t + g * g - radius * radius
        dh = 2.0 * t + 2.0 * g * (k * c.cos + c.r * dcos)
        step = h / dh
        t = t - step
        if np.all(np.abs(step) < 1e-13 * radius):
            break
    c = _contact(axis, t, options, side, clearance=True)
    phi = np.asarray(motion.phi, dtype=float)
    out_t = t[:, 0].copy()
    readonly(out_t)
    return out_t, _sheet(phi, c, k)


def rib_rollers(
    follower: TranslatingBarrelRoller | OscillatingBarrelRoller, options: BarrelOptions
) -> tuple[RibRoller, RibRoller]:
    """A rib's two rollers: (+h, on the rib's +z side; −h, on its −z side), h: ``options.rib_offset``."""
    h = options.rib_offset
    return RibRoller(follower=follower, offset=h), RibRoller(follower=follower, offset=-h)


FaceSource = tuple[BarrelFollower, WallSide]


def face_rollers(follower: BarrelFollower, options: BarrelOptions) -> tuple[FaceSource, FaceSource]:
    """Which roller, and which of its walls, bounds the material on the +z side and on the −z side.

    A groove: the follower's one roller, its (upper, lower) walls. A rib
    (:class:`BarrelKind`): its upper face is the lower wall of the roller at
    +h, its lower face the upper wall of the roller at −h.
    """
    if options.kind is BarrelKind.GROOVE or isinstance(follower, RibRoller):
        return (follower, WallSide.UPPER), (follower, WallSide.LOWER)
    up, low = rib_rollers(follower, options)
    return (up, WallSide.LOWER), (low, WallSide.UPPER)


def _side_sheet(walls: BarrelWalls, side: WallSide) -> WallSheet:
    return walls.upper if side is WallSide.UPPER else walls.lower


def barrel_faces(
    motion: Motion, follower: BarrelFollower, options: BarrelOptions, station: FloatArray
) -> BarrelWalls:
    """The material's two faces on the grid φ (n) × stations t (m): a groove's walls or a rib's faces.

    For a groove this is :func:`barrel_walls`. For a rib, ``upper`` is the
    rib's +z face and ``lower`` its −z face (:func:`face_rollers`), normals
    out of the rib towards the roller that runs on it; ``axis`` is the
    follower's pitch path (between the rollers) and ``pressure_angle`` at
    each point the larger in magnitude of the two rollers' (equal for a
    translating follower).
    """
    (up_f, up_side), (low_f, low_side) = face_rollers(follower, options)
    if up_f is follower:
        return barrel_walls(motion, follower, options, station)
    up = barrel_walls(motion, up_f, options, station)
    low = barrel_walls(motion, low_f, options, station)
    alpha = np.where(
        np.abs(up.pressure_angle) >= np.abs(low.pressure_angle), up.pressure_angle, low.pressure_angle
    )
    readonly(alpha)
    axis = follower.centre(motion).m0
    readonly(axis)
    return BarrelWalls(
        phi=up.phi,
        station=up.station,
        axis=axis,
        upper=_side_sheet(up, up_side),
        lower=_side_sheet(low, low_side),
        pressure_angle=alpha,
    )


def faces_at_radius(
    motion: Motion, follower: BarrelFollower, options: BarrelOptions, radius: float, side: WallSide
) -> tuple[FloatArray, WallSheet]:
    """The ``side`` face cut by the cylinder of ``radius`` [mm]: its roller's :func:`walls_at_radius`."""
    source = face_rollers(follower, options)[0 if side is WallSide.UPPER else 1]
    return walls_at_radius(motion, source[0], options, radius, source[1])


@dataclass(frozen=True, slots=True, kw_only=True)
class Slip:
    """Sliding of the roller on one wall, per radian of barrel turn [mm/rad] (× ω [rad/s] for mm/s).

    ``across`` (n, m): along the roller's circumference (rolling direction);
    ``along`` (n, m): along the roller's generator (its axis, for a cylinder).
    The roller spins so that ``across`` is 0 at the pitch station.
    """

    phi: FloatArray
    station: FloatArray
    across: FloatArray
    along: FloatArray


def roller_slip(
    motion: Motion, follower: BarrelFollower, options: BarrelOptions, station: FloatArray, side: WallSide
) -> Slip:
    """The slip between the roller and one wall (no clearance: the roller on its own envelope).

    Notes
    -----
    In the barrel's frame the roller's material at the contact moves at
    dQ/dφ + Ω·r·c, with dQ/dφ the carrier's velocity at the contact point
    (module notes), c = −sin γ e_θ + cos γ ẑ the roller's circumferential
    direction and Ω its spin per radian of barrel turn; the barrel's material
    stands still. Components:

    - across = dQ/dφ·c + Ω r = −(t + y′) sin γ + z′ cos γ + Ω r,
    - along = dQ/dφ·g with g = (e_r + k(cos γ e_θ + sin γ ẑ))/√(1 + k²):
      (−(y + r cos γ) + k((t + y′) cos γ + z′ sin γ))/√(1 + k²),

    with Ω fixed by across = 0 at the pitch station t_p. A translating
    cylinder: across = σ(√(t_p² + s′²) − √(t² + s′²)) ≈ σ(t_p − t) in a
    dwell (the barrel's surface speed ωt against the roller's, rolling at
    t_p), and along = σ r_f s′/√(t² + s′²), a slide along the roller's axis
    while the follower moves. A cone with its apex on the axis
    (q = t(1 + k²)): across = along = 0 at every station wherever s′ = 0; in a
    rise neither vanishes (the relative motion of barrel and follower is then
    a screw of pitch s′, which no rolling body can follow without sliding).
    """
    axis = follower.centre(motion)
    k = options.taper
    t = np.asarray(station, dtype=float)[None, :]
    tp = np.array([[options.pitch_station]])
    phi = np.asarray(motion.phi, dtype=float)

    def parts(c: _Contact) -> tuple[FloatArray, FloatArray]:
        across = -(c.t + c.y1) * c.sin + c.z1 * c.cos
        along = (-(c.y + c.r * c.cos) + k * ((c.t + c.y1) * c.cos + c.z1 * c.sin)) / math.sqrt(1.0 + k * k)
        return across, along

    at_pitch, _ = parts(_contact(axis, tp, options, side, clearance=False))
    spin = -at_pitch / options.roller_at(options.pitch_station, clearance=False)  # Ω (n, 1)
    c = _contact(axis, t, options, side, clearance=False)
    across, along = parts(c)
    across = across + spin * c.r
    st = t[0].copy()
    readonly(across, along, st)
    return Slip(phi=phi, station=st, across=across, along=along)


def check_barrel(options: BarrelOptions, follower: BarrelFollower) -> None:
    """Refuse a barrel, groove, roller or arm that cannot be built, naming the field (exit 2).

    Raises
    ------
    DesignError
        ``cam.barrel_radius``, ``cam.length``, ``groove.depth`` (≤ 0, or into
        the bore), ``groove.clearance``, ``follower.roller_radius``,
        ``follower.roller_length`` (not shorter than the groove is deep),
        ``follower.roller`` (a cone on an arm), ``follower.arm_length`` (an arm
        shorter than its pivot's distance from the barrel's axis cannot bring
        the roller over it), ``cam.rib_width`` (a rib's width ≤ 0).
    """
    o = options
    if isinstance(follower, RibRoller):
        follower = follower.follower
    if o.kind is BarrelKind.RIB and not (math.isfinite(o.rib_width) and o.rib_width > 0.0):
        raise DesignError(Knob.RIB_WIDTH, f"{o.rib_width!r} mm is not allowed; give a rib width > 0 mm")
    for path, value in (
        (Knob.BARREL_RADIUS, o.barrel_radius),
        (Knob.CAM_LENGTH, o.length),
        (Knob.GROOVE_DEPTH, o.depth),
        (Knob.ROLLER_RADIUS, o.roller_radius),
        (Knob.ROLLER_LENGTH, o.roller_length),
    ):
        if not (math.isfinite(value) and value > 0.0):
            raise DesignError(path, f"{value!r} mm is not allowed; give a length > 0 mm")
    if not (math.isfinite(o.clearance) and o.clearance >= 0.0):
        raise DesignError(Knob.GROOVE_CLEARANCE, f"{o.clearance!r} mm is not allowed; give 0 mm or more")
    if not (math.isfinite(o.bore) and 0.0 <= o.bore < 2.0 * o.barrel_radius):
        raise DesignError(
            Knob.BORE,
            f"{o.bore!r} mm is not allowed; give 0 ≤ bore < 2·barrel_radius = {2 * o.barrel_radius:g} mm",
        )
    wall = o.barrel_radius - 0.5 * o.bore
    if o.depth >= wall:
        raise DesignError(
            Knob.GROOVE_DEPTH,
            f"{o.depth:g} mm reaches the bore: the barrel's wall is {wall:g} mm thick "
            f"(barrel_radius − bore/2); give depth < {wall:g} mm",
        )
    if o.roller_length >= o.depth:
        raise DesignError(
            Knob.ROLLER_LENGTH,
            f"{o.roller_length:g} mm would touch the groove's bottom, {o.depth:g} mm deep; "
            f"give roller_length < {o.depth:g} mm or a deeper groove",
        )
    if isinstance(follower, OscillatingBarrelRoller):
        if o.roller is RollerShape.CONICAL:
            raise DesignError(
                Knob.ROLLER,
                '"conical" needs a radial roller axis (its apex on the barrel\'s axis); '
                'on an arm use "cylindrical"',
            )
        d, arm = follower.pivot_distance, follower.arm_length
        if not (math.isfinite(d) and d >= 0.0):
            raise DesignError(Knob.PIVOT_DISTANCE, f"{d!r} mm is not allowed; give 0 mm or more")
        if not (math.isfinite(arm) and arm > d):
            raise DesignError(
                Knob.ARM_LENGTH,
                f"{arm!r} mm cannot reach the barrel: the pivot is {d:g} mm from the barrel's axis; "
                f"give arm_length > pivot_distance = {d:g} mm",
            )
