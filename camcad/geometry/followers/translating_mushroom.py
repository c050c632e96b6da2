"""Translating curved-face (mushroom) follower: a spherical or crowned face on a slide, as in valve trains.

The whole module is the follower: its TOML keys, its check, its kinematics,
its names and its drawing. Nothing else in camcad knows it exists
(README "Adding a follower").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray
from camcad.geometry.envelope import Guide, PointElement
from camcad.geometry.followers.base import (
    FACE_MARGIN,
    FACE_WIDTH,
    OFFSET,
    SLIDE_LIFT,
    FollowerKey,
    FollowerSketch,
    FollowerType,
    Problem,
    Words,
    slide_point,
)
from camcad.motion.program import Motion

if TYPE_CHECKING:
    from camcad.geometry.spec import FollowerSpec

__all__ = ["FACE_RADIUS", "TYPE", "TranslatingMushroom"]

FACE_RADIUS = FollowerKey(
    name="face_radius", description="the curved face's radius ρ_f (mm); its centre moves with the follower"
)

_WORDS = Words(
    trace="pitch curve (face-centre path)",
    path="face-centre path",
    radius="face radius",
    smaller="use a smaller face radius",
    why_rho="the face centre's path's convex ρ must stay above the face radius or the profile loops",
)


@dataclass(frozen=True, slots=True, kw_only=True)
class TranslatingMushroom:
    """A convex face of radius ρ_f on a slide along the machine's y axis, at x = e.

    The face is an arc of the circle of radius ρ_f whose centre C moves with
    the follower, so the contact element is that circle: the profile is the
    envelope of a roller of radius ρ_f (Rothbart 2004, §6.3: a curved-face
    follower is designed as a roller of the face's radius), and its pitch
    curve is the centre's path. At s = 0 the face touches the base circle r_b:
    C = (e, k) with k = √((r_b + ρ_f)² − e²). Unlike a roller, the face does
    not turn: the contact slides over it, from the apex (the face's point on
    the slide's axis) by the arc ρ_f·δ, δ the angle of the contact normal off
    the axis. ``face_width`` is measured along the face, centred on the apex.
    """

    base_radius: float  # r_b [mm]
    face_radius: float  # ρ_f [mm]
    eccentricity: float = 0.0  # e [mm]: the slide's axis is the line x = e
    face_width: float | None = None  # mm along the face, centred on the apex (drawings)

    @property
    def roller_radius(self) -> float:
        """ρ_f [mm]: the envelope's offset from the centre's path (the contact circle's radius)."""
        return self.face_radius

    @property
    def prime_k(self) -> float:
        """Face-centre height k [mm] at s = 0."""
        return math.sqrt((self.base_radius + self.face_radius) ** 2 - self.eccentricity**2)

    @property
    def guide(self) -> Guide:
        """The slide: along +y."""
        return Guide(axis=(0.0, 1.0))

    def element(self, motion: Motion) -> PointElement:
        """C = (e, k + s), C′ = (0, v), C″ = (0, a), C‴ = (0, j) [mm/radᵏ]: the face's centre."""
        return slide_point(self.eccentricity, self.prime_k, motion)

    def trace(self, motion: Motion) -> PointElement:
        """The face's centre: the element itself."""
        return self.element(motion)

    def describe(self) -> str:
        """E.g. ``"translating curved face, ρ_f = 60 mm, e = 0 mm"``."""
        return f"translating curved face, face radius {self.face_radius:g} mm, e = {self.eccentricity:g} mm"

    def contact_position(self, contact: FloatArray, motion: Motion) -> FloatArray:
        """ρ_f·δ [mm]: the arc from the apex to the contact, δ = atan2(x_P − x_C, y_C − y_P), + towards +x."""
        rel = contact - self.element(motion).m0
        out: FloatArray = self.face_radius * np.arctan2(rel[:, 0], -rel[:, 1])
        return out

    def sketch(self, motion: Motion, *, size: float) -> list[FollowerSketch]:
        """The face's arc, the stem from its apex along +y, and the slide's axis, at each angle."""
        half = 0.5 * self.face_width if self.face_width else 0.6 * size  # arc length either side
        sweep = np.linspace(-1.0, 1.0, 41) * min(half / self.face_radius, 0.5 * math.pi)
        arc = self.face_radius * np.column_stack((np.sin(sweep), -np.cos(sweep)))
        rise = self.face_radius * (1.0 - math.cos(float(sweep[-1])))  # the edges stand above the apex
        axis = np.array([0.0, 1.0])
        out = []
        for centre in self.element(motion).m0:
            apex = centre - self.face_radius * axis
            tip = apex + (rise + 0.25 * size) * axis
            out.append(
                FollowerSketch(
                    body=(centre + arc,),
                    links=(np.array([apex, tip]),),
                    axes=(np.array([[centre[0], 0.0], tip]),),
                    marks=np.empty((0, 2)),
                    tip=tip,
                    heading=axis,
                )
            )
        return out

    @property
    def contact_radius(self) -> float:
        """ρ_f [mm]: the face's radius sets the contact stress (Johnson 1985, §4.3)."""
        return self.face_radius

    @property
    def rolls(self) -> bool:
        """False: the contact slides over the face."""
        return False

    @property
    def arm_direction(self) -> None:
        """None: a slide."""
        return None

    @property
    def words(self) -> Words:
        """A curved face's names."""
        return _WORDS

    def rows(self) -> tuple[tuple[str, float | None], ...]:
        """Face radius and offset."""
        return (("face radius [mm]", self.face_radius), ("follower offset [mm]", self.eccentricity))


def _radius(spec: FollowerSpec) -> float:
    radius = spec.value(FACE_RADIUS.name)
    assert radius is not None  # the loader requires it
    return radius


def _build(spec: FollowerSpec, base_radius: float) -> TranslatingMushroom:
    return TranslatingMushroom(
        base_radius=base_radius,
        face_radius=_radius(spec),
        eccentricity=spec.eccentricity,
        face_width=spec.face_width,
    )


def _check(spec: FollowerSpec, base_radius: float, swing: float) -> Problem:
    """The slide's axis must cut the circle through the face centre at s = 0: |e| < r_b + ρ_f."""
    reach = base_radius + _radius(spec)
    if abs(spec.eccentricity) >= reach:
        return (
            "follower.offset",
            f"|{spec.eccentricity:g}| must be smaller than base_radius + face_radius = {reach:g} mm",
        )
    return None


TYPE = FollowerType(
    word="translating-mushroom",
    order=5,
    keys=(FACE_RADIUS, OFFSET, FACE_WIDTH, FACE_MARGIN),
    required=(FACE_RADIUS.name,),
    lift=SLIDE_LIFT,
    face=True,
    two_sided=False,
    build=_build,
    check=_check,
)
"""``type = "translating-mushroom"``: a curved (spherical, crowned) face on a slide."""
