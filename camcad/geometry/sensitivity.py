"""First-order (linear) tolerance sensitivities of the follower motion, from the exact envelope.

A made cam differs from its design by a normal profile error (the form
band), and its follower by its roller radius, where its slide or pivot sits,
its arm length and how the cam is keyed on its shaft. To first order each
error moves the follower's lift q (a slide's displacement [mm] or an arm's
swing ψ) by ``lift[k] · δk``, its velocity dq/dφ by ``velocity[k] · δk`` and
the pressure angle by ``pressure_angle[k] · δk``.

The method (the contact condition differentiated analytically): at the
nominal contact C with outward cam normal n, every error is a small rigid or
normal displacement of the cam (field γ_k) or of the follower at fixed lift
(field β_k); the follower's lift must move so the two bodies still touch,
n·(β_q δq + β_k δk − γ_k δk) = 0, so

    δq/δk = A_k/B,   A_k = n·(γ_k − β_k),   B = n·β_q,

with β_q the follower's motion per unit lift (the slide's axis, or J(x − P)
turned the arm's way about the pivot P). For a roller on a slide B = cos α
and a normal error gives δs = δn / cos α; an eccentricity error gives
δs = ∓tan α·δe; a keyway error δ (events later by δ) gives δs = −v·δ
(Rothbart 2004, §10: mechanical error analysis; Wu & Chang). The velocity
sensitivity is d(A_k/B)/dφ, from the φ-derivatives of n (n′ = (|X′|/ρ)·t in
the cam frame, plus the turn of the frame) and of C, all exact from the
envelope's first and second derivatives; no sample is differenced.

The pressure angle follows from Kennedy's theorem: the common normal passes
through the cam–follower instant centre I, on the line through the cam axis
and the follower's centre of rotation (at infinity across a slide), at the
place the velocities agree. So α = F(q, v, mount) is a closed-form function
of the lift, the velocity and the mount (for the slide it is Quang & Hung
2015, eq. 4);
δα = F_q δq + F_v δv + F_mount δmount, its partial derivatives taken by the
complex step (F evaluated at a complex argument q + iη: exact to round-off,
no subtraction; Squire & Trapp 1998).

References
----------
.. [1] Rothbart (2004), Cam Design Handbook, McGraw-Hill, §10.
.. [2] Quang & Hung (2015), Computer aided cam design of roller-follower cam mechanism
   (../shared/papers/002_3938fa916e46e710.txt).
.. [3] Squire & Trapp (1998), Using complex variables to estimate derivatives of real
   functions, SIAM Review 40(1), 110–112. doi:10.1137/S003614459631241X
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, replace

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.envelope import LineElement, PointElement, to_cam
from camcad.knobs import Knob, TableKey
from camcad.motion.program import Side

__all__ = [
    "Mount",
    "Sensitivity",
    "Tol",
    "applicable",
    "applicable_to",
    "mount_of",
    "pressure_angle_identity",
    "sensitivities",
]

_STEP = 1e-20  # complex step; any tiny value is exact (no subtraction)


class Tol(enum.Enum):
    """A toleranced quantity. Lengths in mm, ``PHASE`` in rad (degrees only at the edges).

    ``FORM``: outward normal error of the whole profile (+ = more material).
    ``ROLLER_RADIUS``: the roller is bigger than designed. ``ECCENTRICITY``: a
    slide's axis moved along +x (the design's ``offset``). ``CENTRE_DISTANCE``:
    the slide moved along its axis away from the cam, or the pivot moved
    radially away from the cam axis. ``PIVOT_X``, ``PIVOT_Y``: the pivot moved.
    ``ARM_LENGTH``: the roller centre farther from the pivot. ``FACE_OFFSET``:
    an arm's face line farther from its pivot (towards the cam). ``PHASE``:
    the cam keyed late by δ, so every event comes δ later: s̃(φ) = s(φ − δ).
    """

    FORM = "form"
    ROLLER_RADIUS = "roller_radius"
    ECCENTRICITY = "eccentricity"
    CENTRE_DISTANCE = "centre_distance"
    PIVOT_X = "pivot_x"
    PIVOT_Y = "pivot_y"
    ARM_LENGTH = "arm_length"
    FACE_OFFSET = "face_offset"
    PHASE = "phase"


@dataclass(frozen=True, slots=True, kw_only=True)
class Mount:
    """How the follower sits in the machine frame, in the few numbers a tolerance can move.

    Slide (``axis`` set): the follower's reference point (roller centre or face
    centre) is ``origin + q·axis``, q the lift [mm]; a face is the line
    axis·x = axis·origin + q. Arm (``pivot`` set), ψ the swing [rad] and
    θ = theta0 + turn·ψ: the roller centre is P + l·(cos θ, sin θ); a face has
    the normal (cos θ, sin θ) and lies at ``face_offset`` f from the pivot,
    n·x = n·P − f. ``roller_radius`` is 0 for
    a face. ``lift_scale`` turns q into the program's lift unit (1 for mm,
    180/π for an arm's degrees).
    """

    sigma: float
    roller_radius: float
    axis: tuple[float, float] | None = None
    origin: tuple[float, float] = (0.0, 0.0)
    pivot: tuple[float, float] | None = None
    turn: float = -1.0
    arm_length: float = 0.0
    theta0: float = 0.0
    face_offset: float = 0.0

    @property
    def has_circle(self) -> bool:
        """Whether the contact element is a circle of ``roller_radius`` (a roller, a curved face)."""
        return self.roller_radius > 0.0

    @property
    def lift_scale(self) -> float:
        """The program's lift unit per unit of q: 1 (mm) on a slide, 180/π (degrees) on an arm."""
        return 1.0 if self.axis is not None else 180.0 / math.pi


def applicable(mount: Mount) -> tuple[Tol, ...]:
    """The tolerances that mean something for this follower, in :class:`Tol` order."""
    out = [Tol.FORM]
    if mount.has_circle:
        out.append(Tol.ROLLER_RADIUS)
    if mount.axis is not None:
        out += [Tol.ECCENTRICITY, Tol.CENTRE_DISTANCE]
    else:
        out += [Tol.CENTRE_DISTANCE, Tol.PIVOT_X, Tol.PIVOT_Y]
        out.append(Tol.ARM_LENGTH if mount.has_circle else Tol.FACE_OFFSET)
    out.append(Tol.PHASE)
    return tuple(out)


def applicable_to(cam: Cam) -> tuple[Tol, ...]:
    """``applicable(mount_of(cam))``, a slide's read off its guide and roller (no motion evaluated).

    A slide's mount has the guide's axis and the follower's roller radius,
    all :func:`applicable` reads; an arm's (whose element decides whether it
    has a circle) is found by :func:`mount_of`. Refuses what it refuses.
    """
    if cam.conjugate is not None:
        return applicable(mount_of(cam))  # its refusal
    kin = cam.follower
    if kin.guide.axis is None:
        return applicable(mount_of(cam))
    return applicable(Mount(sigma=cam.sigma, roller_radius=kin.roller_radius, axis=kin.guide.axis))


def mount_of(cam: Cam) -> Mount:
    """The mount of a cam's follower, read from its contact element and guide at φ = 0.

    Refuses a conjugate pair's tied roller (its two rollers share one mount).
    """
    if cam.conjugate is not None:
        raise DesignError("tolerance", "a conjugate pair's second plate is not supported; analyse the first")
    kin = cam.follower
    guide = kin.guide
    m = cam.motion(np.array([0.0]))
    element = kin.element(m)
    sigma = cam.sigma
    if guide.axis is not None:
        axis = (float(guide.axis[0]), float(guide.axis[1]))
        ref = kin.trace(m).m0[0] - float(m.s[0]) * np.asarray(axis)
        return Mount(
            sigma=sigma,
            roller_radius=kin.roller_radius,
            axis=axis,
            origin=(float(ref[0]), float(ref[1])),
        )
    assert guide.pivot is not None
    pivot = (float(guide.pivot[0]), float(guide.pivot[1]))
    psi = math.radians(float(m.s[0]))
    if isinstance(element, PointElement):
        arm = element.m0[0] - np.asarray(pivot)
        theta = math.atan2(float(arm[1]), float(arm[0]))
        return Mount(
            sigma=sigma,
            roller_radius=kin.roller_radius,
            pivot=pivot,
            turn=guide.turn,
            arm_length=float(np.hypot(*arm)),
            theta0=theta - guide.turn * psi,
        )
    assert isinstance(element, LineElement)
    normal = element.normal[0]
    return Mount(
        sigma=sigma,
        roller_radius=0.0,
        pivot=pivot,
        turn=guide.turn,
        theta0=math.atan2(float(normal[1]), float(normal[0])) - guide.turn * psi,
        face_offset=float(normal @ np.asarray(pivot) - element.p[0][0]),
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class Sensitivity:
    """First-order sensitivities at cam angles φ, one row per toleranced quantity.

    Attributes
    ----------
    phi
        (n,) cam angles [rad].
    parameters
        The quantities, one per row (units: mm, ``PHASE`` rad).
    lift
        (k, n) δ(lift)/δ(parameter) in the program's lift unit (mm or ° of swing) per mm or per rad.
    velocity
        (k, n) δ(dq/dφ)/δ(parameter) [lift unit/rad per mm or per rad].
    pressure_angle
        (k, n) δα/δ(parameter) [rad per mm or per rad].
    lift_unit
        ``"mm"`` or ``"deg"``.
    """

    phi: FloatArray
    parameters: tuple[Tol, ...]
    lift: FloatArray
    velocity: FloatArray
    pressure_angle: FloatArray
    lift_unit: str

    def row(self, tol: Tol) -> int:
        """The row of ``tol``; a one-line error if it does not apply to this follower."""
        if tol not in self.parameters:
            allowed = ", ".join(t.value for t in self.parameters)
            raise DesignError(
                TableKey(Knob.TOLERANCE_TABLE, tol.value),
                f"does not apply to this follower; allowed: {allowed}",
            )
        return self.parameters.index(tol)


def _j(v: FloatArray) -> FloatArray:
    """J·v: (n, 2) vectors turned by +90°."""
    return np.stack((-v[..., 1], v[..., 0]), axis=-1)


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    out: FloatArray = np.sum(a * b, axis=-1)
    return out


def pressure_angle_identity(mount: Mount, q: ArrayLike, v: ArrayLike) -> FloatArray:
    """α [rad] from the lift q and velocity dq/dφ alone (Kennedy's theorem); complex-step safe.

    Parameters
    ----------
    mount
        The (possibly perturbed) mount; the cam axis is the origin.
    q, v
        Lift [mm or rad of swing] and dq/dφ [mm/rad or rad/rad], same shape.

    Notes
    -----
    The cam turns at σ (per unit φ). Slide with axis a: I = σ·v·a⊥, a⊥ = a
    turned by −90° (tan α = (v − e)/(s + k) for a radial-axis roller on a ccw
    cam, Quang & Hung 2015, eq. 4). Arm turning at ω = turn·v about P:
    σ·J·I = ω·J·(I − P) gives I = ω·P/(ω − σ). A roller's normal is the line
    from I to its centre M; a face's is the face normal and its contact the
    foot of I on the face. α = σ·atan((d × n)/(d·n)), d the driven direction
    (|α| < 90° for any working cam).
    """
    qa = np.asarray(q)
    va = np.asarray(v)
    if mount.axis is not None:
        a = np.asarray(mount.axis, dtype=float)
        a_perp = np.array([a[1], -a[0]])
        if not mount.has_circle:  # a face square to its slide: α ≡ 0 (complex zeros under the complex step)
            flat: FloatArray = 0.0 * qa * va
            return flat
        centre = np.asarray(mount.origin) + qa[..., None] * a
        inst = mount.sigma * va[..., None] * a_perp
        n = centre - inst
        d = np.broadcast_to(a, n.shape)
    else:
        assert mount.pivot is not None
        p = np.asarray(mount.pivot)
        omega = mount.turn * va
        inst = (omega / (omega - mount.sigma))[..., None] * p
        if mount.has_circle:
            theta = mount.theta0 + mount.turn * qa
            contact = p + mount.arm_length * np.stack((np.cos(theta), np.sin(theta)), axis=-1)
            n = contact - inst
        else:
            theta = mount.theta0 + mount.turn * qa
            n = np.stack((np.cos(theta), np.sin(theta)), axis=-1) + 0.0 * inst
            level = _dot(n, p) - mount.face_offset
            contact = inst + (level - _dot(n, inst))[..., None] * n
        arm = contact - p
        d = mount.turn * _j(arm)
    cross = d[..., 0] * n[..., 1] - d[..., 1] * n[..., 0]
    out: FloatArray = mount.sigma * np.arctan(cross / _dot(d, n))
    return out


def _direct_pressure_terms(mount: Mount, tol: Tol, q: FloatArray, v: FloatArray) -> FloatArray:
    """∂F/∂(mount parameter) at fixed q and v, by the complex step (0 for cam-side errors)."""
    if tol in (Tol.FORM, Tol.ROLLER_RADIUS, Tol.PHASE):
        return np.zeros_like(q)
    moved = _complex_mount(mount, tol)
    return np.asarray(pressure_angle_identity(moved, q + 0j, v + 0j).imag / _STEP, dtype=float)


def _complex_mount(mount: Mount, tol: Tol) -> Mount:
    """``mount`` moved by i·_STEP in ``tol`` (fields hold complex numbers for the complex step)."""
    h = 1j * _STEP
    if mount.axis is not None:
        ox, oy = mount.origin
        ax, ay = mount.axis
        shift = {Tol.ECCENTRICITY: (h, 0.0), Tol.CENTRE_DISTANCE: (h * ax, h * ay)}[tol]
        return replace(mount, origin=(ox + shift[0], oy + shift[1]))  # type: ignore[arg-type]
    assert mount.pivot is not None
    px, py = mount.pivot
    d = math.hypot(px, py)
    if tol is Tol.ARM_LENGTH:
        return replace(mount, arm_length=mount.arm_length + h)  # type: ignore[arg-type]
    if tol is Tol.FACE_OFFSET:
        return replace(mount, face_offset=mount.face_offset + h)  # type: ignore[arg-type]
    shift = {
        Tol.PIVOT_X: (h, 0.0),
        Tol.PIVOT_Y: (0.0, h),
        Tol.CENTRE_DISTANCE: (h * px / d, h * py / d),
    }[tol]
    return replace(mount, pivot=(px + shift[0], py + shift[1]))  # type: ignore[arg-type]


def sensitivities(cam: Cam, phi: ArrayLike, *, side: Side = "right") -> Sensitivity:
    """First-order sensitivities of lift, velocity and pressure angle at cam angles φ [rad].

    See the module notes for the method. Every quantity is exact at each
    angle (closed-form envelope derivatives); ``side`` picks the one-sided
    limit at joints.
    """
    mount = mount_of(cam)
    state = cam.state(phi, side=side)
    sigma = mount.sigma
    prof, base = state.profile, state.base
    ph = prof.phi
    speed = np.hypot(base.d1[:, 0], base.d1[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        turn_rate = np.where(np.isinf(base.rho), 0.0, speed / base.rho)
    n_cam = prof.normal
    dn_cam = turn_rate[:, None] * base.tangent  # N′ = (|X′|/ρ)·t (Frenet, outward normal)
    to_machine = -sigma
    n = to_cam(ph, n_cam, to_machine)
    dn = to_cam(ph, dn_cam + sigma * _j(n_cam), to_machine)  # d/dφ [R(σφ)N] = R(N′ + σJN)
    c = to_cam(ph, prof.point, to_machine)
    dc = to_cam(ph, prof.d1 + sigma * _j(prof.point), to_machine)
    scale = mount.lift_scale
    q = state.motion.s / scale
    qv = state.motion.v / scale
    if mount.axis is not None:
        beta_q = np.broadcast_to(np.asarray(mount.axis), n.shape)
        dbeta_q = np.zeros_like(n)
    else:
        p = np.asarray(mount.pivot)
        beta_q = mount.turn * _j(c - p)
        dbeta_q = mount.turn * _j(dc)
    b = _dot(n, beta_q)
    db = _dot(dn, beta_q) + _dot(n, dbeta_q)
    rows_lift, rows_vel, rows_alpha = [], [], []
    f_q = pressure_angle_identity(mount, q + 1j * _STEP, qv + 0j).imag / _STEP
    f_v = pressure_angle_identity(mount, q + 0j, qv + 1j * _STEP).imag / _STEP
    params = applicable(mount)
    for tol in params:
        a_k, da_k = _numerator(mount, tol, n, dn, c, dc)
        lift = a_k / b
        vel = (da_k * b - a_k * db) / b**2
        rows_lift.append(lift * scale)
        rows_vel.append(vel * scale)
        rows_alpha.append(f_q * lift + f_v * vel + _direct_pressure_terms(mount, tol, q, qv))
    out = Sensitivity(
        phi=np.array(ph, dtype=float),
        parameters=params,
        lift=np.array(rows_lift),
        velocity=np.array(rows_vel),
        pressure_angle=np.array(rows_alpha),
        lift_unit="mm" if mount.axis is not None else "deg",
    )
    readonly(out.phi, out.lift, out.velocity, out.pressure_angle)
    return out


def _numerator(
    mount: Mount,
    tol: Tol,
    n: FloatArray,
    dn: FloatArray,
    c: FloatArray,
    dc: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """A_k = n·(γ_k − β_k) and dA_k/dφ for one tolerance (fields at the contact, machine frame)."""
    zero = np.zeros(n.shape[0])
    if tol in (Tol.FORM, Tol.ROLLER_RADIUS, Tol.FACE_OFFSET):
        return zero + 1.0, zero  # the cam grows, the roller grows, the face moves towards the cam by δ
    if tol is Tol.PHASE:  # γ = −σ J C: the cam turned back by δ
        jc, jdc = _j(c), _j(dc)
        return -mount.sigma * _dot(n, jc), -mount.sigma * (_dot(dn, jc) + _dot(n, jdc))
    if tol is Tol.ARM_LENGTH:  # β = (M − P)/l at the roller centre M = C + r_f·n
        p = np.asarray(mount.pivot)
        centre = c + mount.roller_radius * n
        dcentre = dc + mount.roller_radius * dn
        arm = (centre - p) / mount.arm_length
        return -_dot(n, arm), -(_dot(dn, arm) + _dot(n, dcentre) / mount.arm_length)
    shift = _mount_shift(mount, tol)  # the follower translated rigidly
    return -_dot(n, shift), -_dot(dn, shift)


def _mount_shift(mount: Mount, tol: Tol) -> FloatArray:
    """The follower's rigid translation per unit of ``tol`` (mm/mm), machine frame."""
    if mount.axis is not None:
        return np.array([1.0, 0.0]) if tol is Tol.ECCENTRICITY else np.asarray(mount.axis, dtype=float)
    assert mount.pivot is not None
    px, py = mount.pivot
    d = math.hypot(px, py)
    return {
        Tol.PIVOT_X: np.array([1.0, 0.0]),
        Tol.PIVOT_Y: np.array([0.0, 1.0]),
        Tol.CENTRE_DISTANCE: np.array([px / d, py / d]),
    }[tol]
