"""What the user states about the follower and the cam's rotation: the geometry stage's options."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from camcad.geometry.followers import DEFAULT_FOLLOWER, FollowerType

__all__ = [
    "CamStyle",
    "ConjugateSpec",
    "FollowerSpec",
    "GrooveSpec",
    "LinearSpec",
    "Rotation",
]


class Rotation(enum.Enum):
    """Direction the cam turns, seen from the viewer."""

    CCW = "ccw"
    CW = "cw"


class CamStyle(enum.Enum):
    """How the cam drives the follower: a plate (a spring holds it on), a groove, a pair, a barrel."""

    PLATE = "plate"
    GROOVE = "groove"
    CONJUGATE = "conjugate"
    LINEAR = "linear"
    BARREL = "barrel"  # issue 36: a groove round a cylinder (camcad.geometry.families.barrel)
    BARREL_RIB = "barrel-rib"  # issue 36: a rib round a cylinder, straddled by two rollers (the same module)


@dataclass(frozen=True, slots=True, kw_only=True)
class GrooveSpec:
    """A groove (face) cam's groove: ``depth`` below the face and radial ``clearance``, both mm."""

    depth: float = 10.0
    clearance: float = 0.02


@dataclass(frozen=True, slots=True, kw_only=True)
class LinearSpec:
    """A linear cam's bar (the ``[linear]`` table): lengths mm, speed mm/s.

    ``stroke_length`` L: the bar's travel per cycle of the motion program (its
    360°), and the bar's length; ``bar_height``: the bar's height from its
    bottom edge to the base line (the profile at s = 0); ``speed_mm_s``: the
    bar's speed, which sets the cycle time L/v of the dynamics (None: the
    cycle rate is ``cam.speed_rpm`` cycles per minute).
    """

    stroke_length: float = 0.0
    bar_height: float = 20.0
    speed_mm_s: float | None = None


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


@dataclass(frozen=True, slots=True, kw_only=True)
class FollowerSpec:
    """The follower: its kind (:data:`camcad.geometry.followers.FOLLOWER_TYPES`) and its values.

    Lengths mm. The attributes are the keys several kinds share: translating
    followers use ``eccentricity``; oscillating ones the pivot distance d (cam
    axis to pivot), the arm length l (pivot to roller centre) and the face
    offset (the face line's distance from the pivot, positive when the pivot
    lies on the follower's side of it). A kind's own keys that no attribute
    holds are in ``params`` as (key, value) pairs (:meth:`value` reads either).
    Which keys a kind takes, requires and checks is its module's
    (:class:`~camcad.geometry.followers.FollowerType`).
    """

    kind: FollowerType = DEFAULT_FOLLOWER
    roller_radius: float = 0.0
    eccentricity: float = (
        0.0  # e [mm]: the follower axis is the line x = e, whatever the rotation (TOML: offset)
    )
    face_width: float | None = None
    face_margin: float = 1.0  # mm beyond the contact's travel at each edge of a face
    pivot_distance: float | None = None  # d [mm], oscillating followers
    arm_length: float | None = None  # l [mm], oscillating roller
    face_offset: float = 0.0  # f [mm], oscillating flat face
    params: tuple[tuple[str, float], ...] = ()  # a kind's own keys, (TOML key, value) sorted by key

    def value(self, key: str) -> float | None:
        """The value of the TOML key ``key`` of this kind (None when not given and without default)."""
        own = dict(self.params)
        if key in own:
            return own[key]
        for k in self.kind.keys:
            if k.name == key and hasattr(self, k.attr or key):
                out: float | None = getattr(self, k.attr or key)
                return out
        return None
