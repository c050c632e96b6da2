"""Translating roller follower, with eccentricity (offset)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray
from camcad.geometry.envelope import Guide, PointElement
from camcad.geometry.followers.base import FollowerSketch, slide_point, slide_sketch
from camcad.motion.program import Motion

__all__ = ["TranslatingRoller"]


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
