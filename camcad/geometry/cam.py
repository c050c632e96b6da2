"""The cam as a function of the cam angle: pitch curve, profile and offsets.

Everything here is exact: points and their first and second φ-derivatives
follow from the motion's s, v, a, j in closed form. The follower frame turns
with the cam; a curve given there by L(φ) has the cam-frame derivative
R(−φ)·D(L) with D(L) = L′ + (L_y, −L_x), applied repeatedly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.design import Design, FollowerKind, FollowerSpec, Rotation
from camcad.geometry.curves import CurveSample, curve_sample, rotate_to_cam
from camcad.motion.program import Motion, MotionProgram, Side

__all__ = ["Cam"]


@dataclass(frozen=True, slots=True, kw_only=True)
class _Local:
    """A curve in the follower frame: the point and D, D², D³ of it, each (n, 2)."""

    l0: FloatArray
    l1: FloatArray
    l2: FloatArray
    l3: FloatArray | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Cam:
    """A disc cam with a translating follower.

    Attributes
    ----------
    program
        The motion program s(φ).
    base_radius
        r_b [mm]: the smallest radius of the cam profile.
    follower
        Follower kind, roller radius r_f [mm], offset e [mm].
    rotation
        ``CCW`` (default) or ``CW``.

    Notes
    -----
    Cam frame: origin on the cam axis, x right, y up; at φ = 0 the follower
    stands on +y and its axis is the line x = e, whatever the rotation. For a
    counter-clockwise cam the roller centre is P = R(−φ)·(e, k + s) with
    k = √((r_b + r_f)² − e²) (Quang & Hung 2015, eq. 2 with the erratum
    y_p = (k + s) cos φ − e sin φ). A clockwise cam is the mirror image, about
    the y axis, of a counter-clockwise cam whose follower is at −e: its roller
    centre is P = R(+φ)·(e, k + s). Everything is computed in the follower
    frame of that counter-clockwise cam, with the eccentricity
    :attr:`local_eccentricity`, and mirrored into the cam frame at the end.
    """

    program: MotionProgram
    base_radius: float
    follower: FollowerSpec
    rotation: Rotation = Rotation.CCW
    sample_step: float = math.radians(0.1)

    @classmethod
    def from_design(cls, design: Design) -> Cam:
        """The cam a validated design describes."""
        return cls(
            program=MotionProgram.from_segments(design.motion),
            base_radius=design.cam.base_radius,
            follower=design.follower,
            rotation=design.cam.rotation,
            sample_step=design.cam.sample_step,
        )

    # -- basic quantities -------------------------------------------------

    @property
    def is_roller(self) -> bool:
        """Whether the follower is a roller."""
        return self.follower.kind is FollowerKind.TRANSLATING_ROLLER

    @property
    def roller_radius(self) -> float:
        """r_f [mm]; 0 for a flat follower."""
        return self.follower.roller_radius if self.is_roller else 0.0

    @property
    def offset_e(self) -> float:
        """Follower offset e [mm]."""
        return self.follower.offset

    @property
    def local_eccentricity(self) -> float:
        """e [mm] in the computing frame: e for a ccw cam, −e for a cw cam (its mirror image)."""
        return self._sign * self.offset_e

    @property
    def prime_k(self) -> float:
        """k [mm]: roller centre height at s = 0 along the follower axis (Quang & Hung 2015, eq. 2)."""
        if self.is_roller:
            prime = self.base_radius + self.roller_radius
            return math.sqrt(prime**2 - self.offset_e**2)
        return self.base_radius

    @property
    def _sign(self) -> float:
        return 1.0 if self.rotation is Rotation.CCW else -1.0

    def motion(self, phi: ArrayLike, *, side: Side = "right") -> Motion:
        """The follower motion at cam angles φ [rad]; ``side`` picks the one-sided limit at joints."""
        return self.program.evaluate(phi, side=side)

    def sample_phi(self, step: float | None = None) -> FloatArray:
        """Cam angles in [0, 2π) at ``step`` [rad] (default: the design's) plus every breakpoint."""
        return self.program.sample_phi(self.sample_step if step is None else step)

    # -- curves -------------------------------------------------------------

    def _pitch_local(self, m: Motion) -> _Local:
        e, k = self.local_eccentricity, self.prime_k
        ks = k + m.s
        return _Local(
            l0=np.column_stack((np.full_like(ks, e), ks)),
            l1=np.column_stack((ks, m.v - e)),
            l2=np.column_stack((2.0 * m.v - e, m.a - ks)),
            l3=np.column_stack((3.0 * m.a - ks, m.j - 3.0 * m.v + e)),
        )

    def _to_cam(self, phi: FloatArray, local: FloatArray) -> FloatArray:
        return rotate_to_cam(phi, local, self._sign)

    def pitch(self, phi: ArrayLike, *, side: Side = "right") -> CurveSample:
        """The pitch curve at cam angles φ [rad].

        For a roller follower it is the path of the roller centre; for a flat
        follower, the path of the face centre (the point of the face on the
        follower axis). ``side`` picks the one-sided limit at joints.
        """
        m = self.motion(phi, side=side)
        loc = self._pitch_local(m)
        return curve_sample(
            m.phi,
            self._to_cam(m.phi, loc.l0),
            self._to_cam(m.phi, loc.l1),
            self._to_cam(m.phi, loc.l2),
            clockwise=self.rotation is Rotation.CCW,
        )

    def _base_curve(self, phi: ArrayLike, side: Side) -> tuple[CurveSample, FloatArray, FloatArray]:
        """The curve offsets are taken from, with its signed ρ and dρ/dφ.

        Roller: the pitch curve (the profile is its offset by −r_f).
        Flat: the profile itself, with ρ = r_b + s + a and dρ/dφ = v + j.
        """
        m = self.motion(phi, side=side)
        phi_a = m.phi
        clockwise = self.rotation is Rotation.CCW
        if self.is_roller:
            loc = self._pitch_local(m)
            base = curve_sample(
                phi_a,
                self._to_cam(phi_a, loc.l0),
                self._to_cam(phi_a, loc.l1),
                self._to_cam(phi_a, loc.l2),
                clockwise=clockwise,
            )
            d1, d2 = loc.l1, loc.l2
            assert loc.l3 is not None
            d3 = loc.l3
            speed = np.hypot(d1[:, 0], d1[:, 1])
            cross12 = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
            cross13 = d1[:, 0] * d3[:, 1] - d1[:, 1] * d3[:, 0]
            dot12 = np.einsum("ij,ij->i", d1, d2)
            # ρ = σ|P′|³/(P′×P″); dρ/dφ = σ(3|P′|(P′·P″)(P′×P″) − |P′|³(P′×P‴))/(P′×P″)²
            sigma = -1.0  # the follower frame is unmirrored and runs clockwise
            with np.errstate(divide="ignore", invalid="ignore"):
                drho = sigma * (3.0 * speed * dot12 * cross12 - speed**3 * cross13) / cross12**2
            drho = np.where(cross12 == 0.0, 0.0, drho)
            return base, base.rho, drho
        rho = self.base_radius + m.s + m.a  # Hren et al.; papers/README: ρ = r_b + s + a
        local = np.column_stack((m.v, self.base_radius + m.s))
        d1_local = np.column_stack((rho, np.zeros_like(rho)))
        d2_local = np.column_stack((m.v + m.j, -rho))
        ones, zeros = np.ones_like(rho), np.zeros_like(rho)
        tangent = self._to_cam(phi_a, np.column_stack((ones, zeros)))
        if not clockwise:
            tangent = -tangent  # mirrored: the curve runs counter-clockwise
        normal = self._to_cam(phi_a, np.column_stack((zeros, ones)))
        base = CurveSample(
            phi=phi_a,
            point=self._to_cam(phi_a, local),
            d1=self._to_cam(phi_a, d1_local),
            d2=self._to_cam(phi_a, d2_local),
            tangent=tangent,
            normal=normal,
            rho=rho,
        )
        readonly(base.point, base.d1, base.d2, base.tangent, base.normal, base.rho)
        return base, rho, m.v + m.j

    def offset(self, phi: ArrayLike, distance: float, *, side: Side = "right") -> CurveSample:
        """The profile offset outward by ``distance`` [mm] at cam angles φ [rad].

        ``distance = r`` is the centre path of a milling tool (or a roller) of
        radius r rolling on the profile; ``distance = 0`` is the profile.

        Notes
        -----
        For a base curve P with outward unit normal n and signed radius of
        curvature ρ, the offset O = P + δn has O′ = P′(1 + δ/ρ),
        O″ = P″(1 + δ/ρ) − P′ δρ′/ρ² and radius ρ + δ. The roller profile is
        the pitch curve offset by δ = −r_f (Quintero & Vanegas 2016, eq. 13;
        papers/README erratum to Quang & Hung 2015, eq. 3). Where 1 + δ/ρ < 0
        the offset loops (undercut or gouge); ``tangent`` and ``normal`` then
        stay those of the base curve. ``side`` picks the one-sided limit at joints.
        """
        base, rho, drho = self._base_curve(phi, side)
        delta = distance - self.roller_radius
        if delta == 0.0:
            return base
        with np.errstate(divide="ignore", invalid="ignore"):
            stretch = np.where(np.isinf(rho), 1.0, 1.0 + delta / rho)
            bend = np.where(np.isinf(rho), 0.0, delta * drho / rho**2)
        point = base.point + delta * base.normal
        d1 = base.d1 * stretch[:, None]
        d2 = base.d2 * stretch[:, None] - base.d1 * bend[:, None]
        out = CurveSample(
            phi=base.phi,
            point=point,
            d1=d1,
            d2=d2,
            tangent=base.tangent,
            normal=base.normal,
            rho=rho + delta,
        )
        readonly(out.point, out.d1, out.d2, out.rho)
        return out

    def profile(self, phi: ArrayLike, *, side: Side = "right") -> CurveSample:
        """The cam profile (contact point C) at cam angles φ [rad]; ``side`` as in :meth:`offset`."""
        return self.offset(phi, 0.0, side=side)

    def pressure_angle(self, phi: ArrayLike, *, side: Side = "right") -> FloatArray:
        """Signed pressure angle α [rad] at cam angles φ [rad].

        Notes
        -----
        General form: the angle from the follower's direction of travel u to
        the common normal n at the contact, α = atan2(−n·u⊥, n·u) with
        u = R(−φ)(0, 1), u⊥ = R(−φ)(1, 0) in the computing (ccw) frame. For an
        offset roller this is tan α = (v − e)/(s + k) (Quang & Hung 2015,
        eq. 4), and for a clockwise cam, the mirror image of a ccw cam with
        the follower at −e, tan α = (v + e)/(s + k). Its magnitude is
        arccos(R·n/|R|) for a radial follower (Quintero & Vanegas 2016,
        eq. 14). α > 0 where the normal leans towards the side the cam
        surface comes from (on a rise, for either rotation). A flat-faced
        follower has α ≡ 0. ``side`` picks the one-sided limit at joints.
        """
        if not self.is_roller:
            m = self.motion(phi, side=side)
            out = np.zeros_like(m.s)
            readonly(out)
            return out
        p = self.pitch(phi, side=side)
        n = p.normal
        ones, zeros = np.ones(len(p.phi)), np.zeros(len(p.phi))
        u = self._to_cam(p.phi, np.column_stack((zeros, ones)))
        u_perp = self._to_cam(p.phi, np.column_stack((ones, zeros)))
        along = np.einsum("ij,ij->i", n, u)
        across = np.einsum("ij,ij->i", n, u_perp)  # mirror-invariant
        out = np.arctan2(-across, along)
        readonly(out)
        return out

    def contact_offset(self, phi: ArrayLike, *, side: Side = "right") -> FloatArray:
        """Lateral distance of the contact from the follower axis [mm], along +x of the computing frame.

        For a flat face it equals v = ds/dφ minus the eccentricity (Hren et
        al., eq. 27 with the papers/README reading r_m = |ds/dφ|); for a
        roller it is the roller radius times sin α. For a clockwise cam the
        computing frame is the mirror image of the machine (see the class
        notes), so the machine sees the contact at −contact_offset.
        """
        m = self.motion(phi, side=side)
        if not self.is_roller:
            out = m.v - self.local_eccentricity
        else:
            out = self.roller_radius * np.sin(self.pressure_angle(phi, side=side))
        out = np.asarray(out, dtype=float)
        readonly(out)
        return out
