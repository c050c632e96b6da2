"""What the user states about the follower and the cam's rotation: the geometry stage's options."""

from __future__ import annotations

import enum
from dataclasses import dataclass

__all__ = ["FollowerKind", "FollowerSpec", "Rotation"]


class Rotation(enum.Enum):
    """Direction the cam turns, seen from the viewer."""

    CCW = "ccw"
    CW = "cw"


class FollowerKind(enum.Enum):
    """Kinds of follower."""

    TRANSLATING_ROLLER = "translating-roller"
    TRANSLATING_FLAT = "translating-flat"


@dataclass(frozen=True, slots=True, kw_only=True)
class FollowerSpec:
    """The follower. Lengths mm."""

    kind: FollowerKind = FollowerKind.TRANSLATING_ROLLER
    roller_radius: float = 0.0
    eccentricity: float = (
        0.0  # e [mm]: the follower axis is the line x = e, whatever the rotation (TOML: offset)
    )
    face_width: float | None = None
    face_margin: float = 1.0  # mm beyond the contact's travel at each edge of a flat face
