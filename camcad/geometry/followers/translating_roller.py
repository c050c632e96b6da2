"""Translating roller follower, with eccentricity (offset)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray
from camcad.geometry.envelope import Guide, PointElement
from camcad.geometry.followers.base import (
    OFFSET,
    ROLLER_RADIUS,
    ROLLER_WORDS,
    SLIDE_LIFT,
    FollowerSketch,
    FollowerType,
    Problem,
    Words,
    slide_point,
    slide_sketch,
)
from camcad.motion.program import Motion

if TYPE_CHECKING:
    from camcad.geometry.spec import FollowerSpec

__all__ = ["TYPE", "TranslatingRoller"]


@dataclass(frozen=True, slots=True, kw_only=True)
class TranslatingRoller:
    """A roller of radius r_f on a slide along the machine's y axis, at x = e.

    At s = 0 the roller touches the base circle r_b, so its centre stands at
    (e, k) with k = √((r_b + r_f)² − e²) (Quang & Hung 2015, eq. 2).
    """

    base_radius: float  # r_b [mm]
    roller_radius: float  # r_f [mm]
    eccentricity: float = 0.0  # e [mm]: the slide's axis is the line x = e

    @property
    def prime_k(self) -> float:
        """Roller-centre height k [mm] at s = 0."""
        return math.sqrt((self.base_radius + self.roller_radius) ** 2 - self.eccentricity**2)

    @property
    def guide(self) -> Guide:
        """The slide: along +y."""
        return Guide(axis=(0.0, 1.0))

    def element(self, motion: Motion) -> PointElement:
        """M = (e, k + s), M′ = (0, v), M″ = (0, a), M‴ = (0, j) [mm/radᵏ]."""
        return slide_point(self.eccentricity, self.prime_k, motion)

    def trace(self, motion: Motion) -> PointElement:
        """The roller centre: the element itself."""
        return self.element(motion)

    def describe(self) -> str:
        """E.g. ``"translating roller, r_f = 15 mm, e = 20 mm"``."""
        return f"translating roller, r_f = {self.roller_radius:g} mm, e = {self.eccentricity:g} mm"

    def contact_position(self, contact: FloatArray, motion: Motion) -> FloatArray:
        """X − e [mm]: the contact's distance from the slide's axis (r_f·sin α)."""
        out: FloatArray = contact[:, 0] - self.eccentricity
        return out

    def sketch(self, motion: Motion, *, size: float) -> list[FollowerSketch]:
        """Roller circle, stem along +y and the slide's axis, at each angle."""
        centres = self.element(motion).m0
        axis = np.array([0.0, 1.0])
        return [slide_sketch(c, axis, radius=self.roller_radius, half_face=0.0, size=size) for c in centres]

    @property
    def contact_radius(self) -> float:
        """r_f [mm]: the roller's radius sets the contact stress."""
        return self.roller_radius

    @property
    def rolls(self) -> bool:
        """True: a roller turning on its bearing."""
        return True

    @property
    def arm_direction(self) -> None:
        """None: a slide."""
        return None

    @property
    def words(self) -> Words:
        """A roller's names."""
        return ROLLER_WORDS

    def rows(self) -> tuple[tuple[str, float | None], ...]:
        """Roller radius and offset."""
        return (("roller radius [mm]", self.roller_radius), ("follower offset [mm]", self.eccentricity))


def _build(spec: FollowerSpec, base_radius: float) -> TranslatingRoller:
    return TranslatingRoller(
        base_radius=base_radius, roller_radius=spec.roller_radius, eccentricity=spec.eccentricity
    )


def _check(spec: FollowerSpec, base_radius: float, swing: float) -> Problem:
    """The slide's axis must cut the prime circle: |e| < r_b + r_f."""
    if abs(spec.eccentricity) >= base_radius + spec.roller_radius:
        return (
            "follower.offset",
            f"|{spec.eccentricity:g}| must be smaller than base_radius + roller_radius = "
            f"{base_radius + spec.roller_radius:g} mm",
        )
    return None


TYPE = FollowerType(
    word="translating-roller",
    order=1,
    default=True,
    keys=(ROLLER_RADIUS, OFFSET),
    required=("roller_radius",),
    lift=SLIDE_LIFT,
    face=False,
    two_sided=True,
    radial_slide=True,
    build=_build,
    check=_check,
)
"""``type = "translating-roller"``: a roller on a slide, the default follower."""
