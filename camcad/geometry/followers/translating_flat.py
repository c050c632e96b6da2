"""Translating flat-faced follower (the worked example of docs/reference/architecture.md)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray
from camcad.geometry.envelope import Guide, LineElement, PointElement
from camcad.geometry.followers.base import (
    FACE_MARGIN,
    FACE_WIDTH,
    OFFSET,
    SLIDE_LIFT,
    FollowerSketch,
    FollowerType,
    Words,
    no_problem,
    slide_point,
    slide_sketch,
)
from camcad.motion.program import Motion

if TYPE_CHECKING:
    from camcad.geometry.spec import FollowerSpec

__all__ = ["TYPE", "TranslatingFlat"]


@dataclass(frozen=True, slots=True, kw_only=True)
class TranslatingFlat:
    """A flat face perpendicular to a slide along the machine's y axis, at x = e.

    The face is the line y = r_b + s: normal angle θ = 90°, distance
    p = r_b + s from the cam axis. Its eccentricity does not change the
    profile, only where on the face the contact sits.
    """

    base_radius: float  # r_b [mm]
    eccentricity: float = 0.0  # e [mm]: the slide's axis is the line x = e
    face_width: float | None = None  # mm, centred on the slide's axis (drawings)

    @property
    def roller_radius(self) -> float:
        """0: a face, not a roller."""
        return 0.0

    @property
    def guide(self) -> Guide:
        """The slide: along +y."""
        return Guide(axis=(0.0, 1.0))

    def element(self, motion: Motion) -> LineElement:
        """θ = π/2 (fixed), p = r_b + s with p′ = v, p″ = a, p‴ = j."""
        zero = np.zeros_like(motion.s)
        return LineElement(
            normal=np.column_stack((zero, zero + 1.0)),
            theta=(zero + math.pi / 2.0, zero, zero, zero),
            p=(self.base_radius + motion.s, motion.v, motion.a, motion.j),
        )

    def trace(self, motion: Motion) -> PointElement:
        """The face centre (e, r_b + s): the point of the face on the slide's axis."""
        return slide_point(self.eccentricity, self.base_radius, motion)

    def describe(self) -> str:
        """E.g. ``"translating flat face, e = 0 mm"``."""
        return f"translating flat face, e = {self.eccentricity:g} mm"

    def contact_position(self, contact: FloatArray, motion: Motion) -> FloatArray:
        """X − e [mm]: the contact's distance from the slide's axis (σ·v − e, Hren et al. eq. 27)."""
        out: FloatArray = contact[:, 0] - self.eccentricity
        return out

    def sketch(self, motion: Motion, *, size: float) -> list[FollowerSketch]:
        """Face, stem along +y and the slide's axis, at each angle."""
        half = 0.5 * self.face_width if self.face_width else 0.6 * size
        centres = self.trace(motion).m0
        axis = np.array([0.0, 1.0])
        return [slide_sketch(c, axis, radius=0.0, half_face=half, size=size) for c in centres]

    @property
    def contact_radius(self) -> float:
        """0: a flat face."""
        return 0.0

    @property
    def rolls(self) -> bool:
        """False: the face slides on the cam."""
        return False

    @property
    def arm_direction(self) -> None:
        """None: a slide."""
        return None

    @property
    def words(self) -> Words:
        """A face on a slide: its reference curve is the face centre's path."""
        return Words(trace="face-centre trace")

    def rows(self) -> tuple[tuple[str, float | None], ...]:
        """No roller; the offset."""
        return (("roller radius [mm]", None), ("follower offset [mm]", self.eccentricity))


def _build(spec: FollowerSpec, base_radius: float) -> TranslatingFlat:
    return TranslatingFlat(
        base_radius=base_radius, eccentricity=spec.eccentricity, face_width=spec.face_width
    )


TYPE = FollowerType(
    word="translating-flat",
    order=2,
    keys=(OFFSET, FACE_WIDTH, FACE_MARGIN),
    required=(),
    lift=SLIDE_LIFT,
    face=True,
    two_sided=False,
    guided_tappet=True,
    min_curvature_radius=1.0,
    build=_build,
    check=no_problem,
)
"""``type = "translating-flat"``: a flat face square to a slide (a tappet)."""
