"""The second roller of a conjugate pair: rigidly tied to the first follower, on its own plate."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray
from camcad.geometry.envelope import Guide, PointElement
from camcad.geometry.followers.base import ROLLER_WORDS, Follower, FollowerSketch, Words, circle_points
from camcad.motion.program import Motion

__all__ = ["TiedRoller"]


def _turn(v: FloatArray, angle: float) -> FloatArray:
    c, s = math.cos(angle), math.sin(angle)
    out: FloatArray = np.column_stack((c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]))
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class TiedRoller:
    """A roller of radius r_f2 carried by the same follower as ``first``, driving a second plate.

    Slide (``first.guide.axis`` set): the second roller moves with the first,
    M2(φ) = M1(φ) + Δ, Δ fixed. It stands at ``angle`` about the cam axis from
    the first roller and touches its plate's base circle r_b when the first is
    at its highest, ``top`` (s = lift): M2 at the top is (r_b + r_f2)·R(angle)·û,
    û the direction of M1 at the top. For ``angle`` = 180° on a radial slide
    this is the yoke of a constant-breadth cam: both rollers on one line, their
    centres 2(r_b) + r_f + r_f2 + lift apart.

    Arm (``first.guide.pivot`` set): a second arm on the same pivot, of the
    same length, turned by ``angle`` (the included angle between the arms):
    M2 = P + R(angle)·(M1 − P).
    """

    first: Follower
    roller_radius: float  # r_f2 [mm]
    angle: float  # rad
    shift: tuple[float, float] = (0.0, 0.0)  # Δ [mm], slides only

    @classmethod
    def on(
        cls, first: Follower, *, roller_radius: float, angle: float, top: PointElement, base_radius: float
    ) -> TiedRoller:
        """The tied roller of ``first``; ``top`` is the first roller's element at the top of the lift."""
        if first.guide.pivot is not None:
            return cls(first=first, roller_radius=roller_radius, angle=angle)
        m1 = top.m0[0]
        unit = m1 / math.hypot(*m1)
        m2 = (base_radius + roller_radius) * _turn(unit[None, :], angle)[0]
        shift = m2 - m1
        return cls(
            first=first, roller_radius=roller_radius, angle=angle, shift=(float(shift[0]), float(shift[1]))
        )

    @property
    def guide(self) -> Guide:
        """The first follower's guide, reversed: the second roller drives the pair back (a return).

        Its plate pushes the follower the other way, so its pressure angle is
        measured against the direction it drives: the slide's −axis, or the
        arm's opposite turn.
        """
        g = self.first.guide
        if g.axis is not None:
            return Guide(axis=(-g.axis[0], -g.axis[1]))
        return Guide(pivot=g.pivot, turn=-g.turn)

    def element(self, motion: Motion) -> PointElement:
        """M2 and its φ-derivatives: shifted (slide) or turned about the pivot (arm)."""
        el = self.first.element(motion)
        assert isinstance(el, PointElement), "a conjugate pair needs roller followers"
        pivot = self.first.guide.pivot  # the pair moves as one: the first follower's guide
        if pivot is None:
            return PointElement(m0=el.m0 + np.asarray(self.shift), m1=el.m1, m2=el.m2, m3=el.m3)
        p = np.asarray(pivot)
        return PointElement(
            m0=p + _turn(el.m0 - p, self.angle),
            m1=_turn(el.m1, self.angle),
            m2=_turn(el.m2, self.angle),
            m3=_turn(el.m3, self.angle),
        )

    def trace(self, motion: Motion) -> PointElement:
        """The second roller's centre."""
        return self.element(motion)

    def describe(self) -> str:
        """E.g. ``"second roller r_f = 15 mm at 180° (conjugate)"``."""
        return f"second roller r_f = {self.roller_radius:g} mm at {math.degrees(self.angle):g}° (conjugate)"

    def contact_position(self, contact: FloatArray, motion: Motion) -> FloatArray:
        """The contact's distance from the roller centre across the driven direction [mm]."""
        centre = self.element(motion).m0
        d = self.guide.driven(centre)  # the pair's (reversed) drive direction
        rel = contact - centre
        out: FloatArray = d[:, 0] * rel[:, 1] - d[:, 1] * rel[:, 0]
        return out

    def sketch(self, motion: Motion, *, size: float) -> list[FollowerSketch]:
        """The second roller and what ties it to the first: its own arm from the pivot, or the yoke.

        On an arm the link is the second arm, pivot → second roller; on a slide
        it is the yoke's bar from the first roller's centre to the second's.
        """
        first = self.first.trace(motion).m0
        pivot = self.first.guide.pivot
        out = []
        for c1, c2 in zip(first, self.element(motion).m0, strict=True):
            radial = c2 / np.hypot(*c2)
            start = c1 if pivot is None else np.asarray(pivot)
            out.append(
                FollowerSketch(
                    body=(circle_points(c2, self.roller_radius),),
                    links=(np.array([start, c2]),),
                    axes=(),
                    marks=c2[None, :],
                    tip=c2 + (self.roller_radius + 0.05 * size) * radial,
                    heading=radial,
                )
            )
        return out

    @property
    def contact_radius(self) -> float:
        """r_f2 [mm]: the second roller's radius sets its plate's contact stress."""
        return self.roller_radius

    @property
    def rolls(self) -> bool:
        """True: a roller turning on its bearing."""
        return True

    @property
    def arm_direction(self) -> float | None:
        """The first follower's: the pair moves as one."""
        return self.first.arm_direction

    @property
    def words(self) -> Words:
        """A roller's names."""
        return ROLLER_WORDS

    def rows(self) -> tuple[tuple[str, float | None], ...]:
        """The second roller's radius, and the first follower's offset."""
        return (("roller radius [mm]", self.roller_radius), *self.first.rows()[1:])
