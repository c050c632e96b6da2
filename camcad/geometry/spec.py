"""What the user states about the follower and the cam's rotation: the geometry stage's options."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

__all__ = [
    "CamStyle",
    "ConjugateSpec",
    "FollowerKind",
    "FollowerSpec",
    "GrooveSpec",
    "Rotation",
    "arm_problem",
]


class Rotation(enum.Enum):
    """Direction the cam turns, seen from the viewer."""

    CCW = "ccw"
    CW = "cw"


class CamStyle(enum.Enum):
    """How the cam drives the follower: a plate (a spring holds the follower on), a groove or a pair."""

    PLATE = "plate"
    GROOVE = "groove"
    CONJUGATE = "conjugate"


@dataclass(frozen=True, slots=True, kw_only=True)
class GrooveSpec:
    """A groove (face) cam's groove: ``depth`` below the face and radial ``clearance``, both mm."""

    depth: float = 10.0
    clearance: float = 0.02


@dataclass(frozen=True, slots=True, kw_only=True)
class ConjugateSpec:
    """The second roller of a conjugate pair: its ``angle`` [rad] from the first and radius [mm].

    A slide's second roller stands at ``angle`` about the cam axis (180°: on
    the opposite side, a yoke); an arm's is on a second arm of the same length
    on the same pivot, ``angle`` the included angle between the arms. None of
    ``roller_radius``: the first roller's.
    """

    angle: float = math.pi
    roller_radius: float | None = None
    single_plate: bool = False  # a constant-breadth cam: both rollers on one plate (slides, 180°)


class FollowerKind(enum.Enum):
    """Kinds of follower."""

    TRANSLATING_ROLLER = "translating-roller"
    TRANSLATING_FLAT = "translating-flat"
    OSCILLATING_ROLLER = "oscillating-roller"
    OSCILLATING_FLAT = "oscillating-flat"

    @property
    def oscillating(self) -> bool:
        """Whether the follower swings on an arm about a pivot (its lift is an angle, in degrees)."""
        return self in (FollowerKind.OSCILLATING_ROLLER, FollowerKind.OSCILLATING_FLAT)

    @property
    def roller(self) -> bool:
        """Whether the follower touches the cam with a roller."""
        return self in (FollowerKind.TRANSLATING_ROLLER, FollowerKind.OSCILLATING_ROLLER)

    @property
    def lift_unit(self) -> str:
        """Unit of the motion program's lift: ``"mm"`` for a slide, ``"deg"`` of arm swing for an arm."""
        return "deg" if self.oscillating else "mm"


@dataclass(frozen=True, slots=True, kw_only=True)
class FollowerSpec:
    """The follower. Lengths mm.

    Translating followers use ``eccentricity``; oscillating ones the pivot
    distance d (cam axis to pivot), the arm length l (pivot to roller centre,
    roller only) and the face offset (flat only: the face line's distance from
    the pivot, positive when the pivot lies on the follower's side of it).
    """

    kind: FollowerKind = FollowerKind.TRANSLATING_ROLLER
    roller_radius: float = 0.0
    eccentricity: float = (
        0.0  # e [mm]: the follower axis is the line x = e, whatever the rotation (TOML: offset)
    )
    face_width: float | None = None
    face_margin: float = 1.0  # mm beyond the contact's travel at each edge of a flat face
    pivot_distance: float | None = None  # d [mm], oscillating followers
    arm_length: float | None = None  # l [mm], oscillating roller
    face_offset: float = 0.0  # f [mm], oscillating flat face


def arm_problem(follower: FollowerSpec, base_radius: float, swing: float) -> tuple[str, str] | None:
    """Why an oscillating follower cannot be built, as (field path, message); None if it can.

    ``swing`` is the largest arm angle ψ the motion reaches [degrees]. The
    pivot must lie outside the base circle; a roller's arm must reach the start
    position on the base circle (|d − l| ≤ r_b + r_f ≤ d + l) and must not swing
    past the line pivot → cam axis (β0 + ψ < 180°, after which the roller
    would come back towards the cam); a face must touch the base circle
    (|r_b + f| < d) and turn less than the angle that brings it square to the
    line pivot → cam axis.
    """
    d = follower.pivot_distance
    if d is None:
        return ("follower.pivot_distance", f"is required for a {follower.kind.value} follower (mm)")
    if d <= base_radius:
        return (
            "follower.pivot_distance",
            f"{d:g} mm puts the pivot inside the base circle; allowed: > base_radius = {base_radius:g} mm",
        )
    if follower.kind is FollowerKind.OSCILLATING_ROLLER:
        arm = follower.arm_length
        if arm is None:
            return ("follower.arm_length", "is required for an oscillating-roller follower (mm)")
        r0 = base_radius + follower.roller_radius
        if abs(d - arm) > r0 or d + arm < r0:
            return (
                "follower.arm_length",
                f"{arm:g} mm cannot reach the roller's start on the base circle: with pivot_distance "
                f"{d:g} mm the arm must be between |d − (r_b + r_f)| = {abs(d - r0):g} mm and "
                f"d + r_b + r_f = {d + r0:g} mm",
            )
        beta0 = math.degrees(math.acos(max(-1.0, min(1.0, (d * d + arm * arm - r0 * r0) / (2.0 * d * arm)))))
        if beta0 + swing >= 180.0:
            return (
                "motion",
                f"the arm swings {swing:g}° from its start at {beta0:.2f}° off the line pivot → cam "
                f"axis, past 180°: the roller would swing back towards the cam axis; allowed: a "
                f"largest lift below {180.0 - beta0:.2f}°",
            )
        return None
    y = base_radius + follower.face_offset
    if abs(y) >= d:
        return (
            "follower.face_offset",
            f"{follower.face_offset:g} mm: the face cannot touch the base circle from a pivot {d:g} mm "
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
