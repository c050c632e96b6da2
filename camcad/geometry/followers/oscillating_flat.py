"""Oscillating (swinging-arm) flat-faced follower."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray
from camcad.geometry.envelope import Guide, LineElement, PointElement
from camcad.geometry.followers._arm import arm_swing, per_angle, pivot_problem
from camcad.geometry.followers.base import (
    ARM_LIFT,
    FACE_MARGIN,
    FACE_WIDTH,
    PIVOT_DISTANCE,
    FollowerKey,
    FollowerSketch,
    FollowerType,
    KeyRange,
    Problem,
    Words,
)
from camcad.motion.program import Motion

if TYPE_CHECKING:
    from camcad.geometry.spec import FollowerSpec

__all__ = ["FACE_OFFSET", "TYPE", "OscillatingFlat"]

FACE_OFFSET = FollowerKey(
    name="face_offset",
    range=KeyRange.SIGNED,
    description="the face line's distance f from the pivot (mm), + when the pivot is on the follower's side",
)


@dataclass(frozen=True, slots=True, kw_only=True)
class OscillatingFlat:
    """A flat face on an arm that swings about a pivot at distance d from the cam axis.

    The face line lies at distance f (``face_offset``) from the pivot, the
    pivot on the follower's side of it for f > 0. Convention: at φ = 0 the face
    is tangent to the base circle at (0, r_b) (face horizontal, the contact on
    +y) and the pivot lies to the right, at (√(d² − (r_b + f)²), r_b + f). A
    rise turns the face clockwise about the pivot by ψ, lifting it off the
    cam: its normal angle is θ = 90° − ψ and its distance from the cam axis
    p = d·cos(θ − γ) − f, γ the pivot's polar angle (Rothbart 2004, §5.4).
    """

    base_radius: float  # r_b [mm]
    pivot_distance: float  # d [mm]
    face_offset: float = 0.0  # f [mm]
    face_width: float | None = None  # mm, measured along the face from the pivot's foot

    @property
    def roller_radius(self) -> float:
        """0: a face, not a roller."""
        return 0.0

    @property
    def pivot(self) -> tuple[float, float]:
        """The pivot [mm], machine frame."""
        y = self.base_radius + self.face_offset
        return (math.sqrt(max(self.pivot_distance**2 - y * y, 0.0)), y)

    @property
    def pivot_angle(self) -> float:
        """γ [rad]: the pivot's polar angle about the cam axis."""
        px, py = self.pivot
        return math.atan2(py, px)

    @property
    def arm_direction(self) -> float:
        """The arm's direction at ψ = 0, machine frame [rad]: along the face towards the cam (−x)."""
        return math.pi

    @property
    def guide(self) -> Guide:
        """The pivot; a growing ψ turns the face clockwise."""
        return Guide(pivot=self.pivot, turn=-1.0)

    def _line(self, motion: Motion) -> tuple[FloatArray, tuple[FloatArray, ...], tuple[FloatArray, ...]]:
        """n(θ), (θ, θ′, θ″, θ‴) and (p, p′, p″, p‴)."""
        psi, d1, d2, d3 = arm_swing(motion)
        d = self.pivot_distance
        u = self._from_pivot(psi)
        t1, t2, t3 = -d1, -d2, -d3
        cu, su = np.cos(u), np.sin(u)
        p0 = self._distance(cu)
        p1 = -d * su * t1
        p2 = -d * cu * t1**2 - d * su * t2
        p3 = d * su * t1**3 - 3.0 * d * cu * t1 * t2 - d * su * t3
        return self._normal(psi), (math.pi / 2.0 - psi, t1, t2, t3), (p0, p1, p2, p3)

    def _from_pivot(self, psi: FloatArray) -> FloatArray:
        """θ − γ [rad] at arm swing ψ [rad]."""
        out: FloatArray = math.pi / 2.0 - psi - self.pivot_angle
        return out

    def _distance(self, cos_from_pivot: FloatArray) -> FloatArray:
        """The face line's distance p = d·cos(θ − γ) − f [mm] from the cam axis."""
        out: FloatArray = self.pivot_distance * cos_from_pivot - self.face_offset
        return out

    @staticmethod
    def _normal(psi: FloatArray) -> FloatArray:
        """(n, 2) n(θ) = (cos θ, sin θ) = (sin ψ, cos ψ): exact (0, 1) at ψ = 0."""
        out: FloatArray = np.column_stack((np.sin(psi), np.cos(psi)))
        return out

    def element(self, motion: Motion) -> LineElement:
        """The face line n(θ)·x = p with θ = 90° − ψ and p = d·cos(θ − γ) − f, three φ-derivatives."""
        normal, theta, p = self._line(motion)
        return LineElement(normal=normal, theta=theta, p=p)  # type: ignore[arg-type]

    def trace(self, motion: Motion) -> PointElement:
        """The face's point nearest the cam axis, p·n(θ), with three φ-derivatives."""
        n, (_, t1, t2, t3), (p0, p1, p2, p3) = self._line(motion)
        jn = np.column_stack((-n[:, 1], n[:, 0]))

        def mix(a: FloatArray, b: FloatArray) -> FloatArray:
            out: FloatArray = a[:, None] * n + b[:, None] * jn
            return out

        return PointElement(
            m0=mix(p0, 0.0 * p0),
            m1=mix(p1, p0 * t1),
            m2=mix(p2 - p0 * t1**2, 2.0 * p1 * t1 + p0 * t2),
            m3=mix(
                p3 - 3.0 * p1 * t1**2 - 3.0 * p0 * t1 * t2,
                3.0 * p2 * t1 + 3.0 * p1 * t2 + p0 * t3 - p0 * t1**3,
            ),
        )

    def _foot_and_direction(self, motion: Motion) -> tuple[FloatArray, FloatArray]:
        """The pivot's foot on the face, P − f·n, and the unit face direction from it towards the cam."""
        psi = arm_swing(motion)[0]  # the line's n and p alone, as _line computes them
        n, p0 = self._normal(psi), self._distance(np.cos(self._from_pivot(psi)))
        pivot = np.asarray(self.pivot)
        foot = pivot - per_angle(self.face_offset) * n
        along = p0[:, None] * n - foot
        return foot, along / np.hypot(along[:, 0], along[:, 1])[:, None]

    def contact_position(self, contact: FloatArray, motion: Motion) -> FloatArray:
        """B [mm]: the contact's distance along the face from the pivot's foot, positive towards the cam."""
        foot, t = self._foot_and_direction(motion)
        out: FloatArray = np.einsum("ij,ij->i", contact - foot, t)
        return out

    def describe(self) -> str:
        """E.g. ``"oscillating flat face, d = 120 mm, face offset 0 mm"``."""
        return f"oscillating flat face, d = {self.pivot_distance:g} mm, face offset {self.face_offset:g} mm"

    def sketch(self, motion: Motion, *, size: float) -> list[FollowerSketch]:
        """The face from the pivot's foot over the cam, the arm from the pivot to it, and the pivot."""
        foot, t = self._foot_and_direction(motion)
        pivot = np.asarray(self.pivot)
        length = self.face_width or 1.3 * float(np.max(np.hypot(*(self.trace(motion).m0 - pivot).T)))
        out = []
        for f, direction in zip(foot, t, strict=True):
            end = f + length * direction
            out.append(
                FollowerSketch(
                    body=(np.array([f, end]),),
                    links=(np.array([pivot, f]),),
                    axes=(),
                    marks=pivot[None, :],
                    tip=end + 0.05 * size * direction,
                    heading=direction,
                )
            )
        return out

    @property
    def contact_radius(self) -> float:
        """0: a flat face."""
        return 0.0

    @property
    def rolls(self) -> bool:
        """False: the face slides on the cam."""
        return False

    @property
    def words(self) -> Words:
        """A face on an arm: its reference curve is the face's point nearest the cam axis."""
        return Words(trace="face trace (point nearest the cam axis)")

    def rows(self) -> tuple[tuple[str, float | None], ...]:
        """Neither a roller nor an offset."""
        return (("roller radius [mm]", None), ("follower offset [mm]", None))


def _build(spec: FollowerSpec, base_radius: float) -> OscillatingFlat:
    assert spec.pivot_distance is not None  # the schema requires it
    return OscillatingFlat(
        base_radius=base_radius,
        pivot_distance=spec.pivot_distance,
        face_offset=spec.face_offset,
        face_width=spec.face_width,
    )


def _check(spec: FollowerSpec, base_radius: float, swing: float) -> Problem:
    """The face must touch the base circle (|r_b + f| < d) and turn less than the angle that squares it.

    ``swing`` is the largest ψ [degrees]; past 90° − atan2(r_b + f, √(d² − (r_b + f)²))
    the face is square to the line pivot → cam axis and would approach the cam again.
    """
    problem = pivot_problem(spec, base_radius)
    if problem is not None:
        return problem
    d = spec.pivot_distance
    assert d is not None
    y = base_radius + spec.face_offset
    if abs(y) >= d:
        return (
            "follower.face_offset",
            f"{spec.face_offset:g} mm: the face cannot touch the base circle from a pivot {d:g} mm "
            f"away; allowed: |base_radius + face_offset| < pivot_distance",
        )
    start = 90.0 - math.degrees(math.atan2(y, math.sqrt(d * d - y * y)))
    if swing >= start:
        return (
            "motion",
            f"the face swings {swing:g}° but turns square to the line pivot → cam axis after "
            f"{start:.2f}° (it would approach the cam again); allowed: a largest lift below {start:.2f}°",
        )
    return None


TYPE = FollowerType(
    word="oscillating-flat",
    order=4,
    keys=(PIVOT_DISTANCE, FACE_OFFSET, FACE_WIDTH, FACE_MARGIN),
    required=("pivot_distance",),
    lift=ARM_LIFT,
    face=True,
    two_sided=False,
    min_curvature_radius=1.0,
    build=_build,
    check=_check,
)
"""``type = "oscillating-flat"``: a flat face on a swinging arm; its lift is the arm's swing in degrees."""
