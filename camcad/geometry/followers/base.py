"""The follower interface of the generic envelope."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from camcad._typing import FloatArray
from camcad.geometry.envelope import Guide, LineElement, PointElement
from camcad.motion.program import Motion

__all__ = ["Follower", "FollowerSketch", "slide_point", "slide_sketch"]

_CIRCLE = np.linspace(0.0, 2.0 * np.pi, 73)


@dataclass(frozen=True, slots=True, kw_only=True)
class FollowerSketch:
    """A drawing of the follower at one cam angle, machine frame [mm].

    ``body`` are the parts that touch or carry the cam load (roller, face),
    ``links`` what holds them (stem, arm), ``axes`` construction lines (the
    slide's axis); each a (k, 2) polyline. ``marks`` (m, 2) are points to mark
    (roller centre, pivot); the label goes at ``tip``, leaning ``heading``.
    """

    body: tuple[FloatArray, ...]
    links: tuple[FloatArray, ...]
    axes: tuple[FloatArray, ...]
    marks: FloatArray
    tip: FloatArray
    heading: FloatArray


def circle_points(centre: FloatArray, radius: float) -> FloatArray:
    """(73, 2) points of a closed circle [mm]."""
    return np.column_stack((centre[0] + radius * np.cos(_CIRCLE), centre[1] + radius * np.sin(_CIRCLE)))


def slide_sketch(
    centre: FloatArray, axis: FloatArray, *, radius: float, half_face: float, size: float
) -> FollowerSketch:
    """A translating follower at ``centre`` driven along unit ``axis``: roller (radius > 0) or face.

    The stem is ``size``/4 long beyond the roller or face; the slide's axis runs
    from its foot nearest the cam centre to the stem's tip.
    """
    across = np.array([axis[1], -axis[0]])
    if radius > 0.0:
        body: tuple[FloatArray, ...] = (circle_points(centre, radius),)
        foot = centre + radius * axis
        marks = centre[None, :]
    else:
        body = (np.array([centre - half_face * across, centre + half_face * across]),)
        foot = centre
        marks = np.empty((0, 2))
    tip = foot + 0.25 * size * axis
    back = centre - float(np.dot(centre, axis)) * axis
    return FollowerSketch(
        body=body,
        links=(np.array([foot, tip]),),
        axes=(np.array([back, tip]),),
        marks=marks,
        tip=tip,
        heading=axis,
    )


def slide_point(x: float, height: float, motion: Motion) -> PointElement:
    """A point on a slide along the machine's +y at x [mm]: (x, height + s) and its φ-derivatives.

    M = (x, h + s), M′ = (0, v), M″ = (0, a), M‴ = (0, j): the roller centre of
    a translating roller (h = k) or the face centre of a translating face (h = r_b).
    """
    zero = np.zeros_like(motion.s)
    return PointElement(
        m0=np.column_stack((zero + x, height + motion.s)),
        m1=np.column_stack((zero, motion.v)),
        m2=np.column_stack((zero, motion.a)),
        m3=np.column_stack((zero, motion.j)),
    )


class Follower(Protocol):
    """What a follower tells the envelope.

    Attributes
    ----------
    roller_radius
        r_f [mm] of a roller follower (the profile is the element's path
        offset inward by it); 0 for a face.
    guide
        How the follower is guided in the machine frame.
    """

    @property
    def roller_radius(self) -> float:
        """r_f [mm]; 0 for a face."""
        ...

    @property
    def guide(self) -> Guide:
        """Translation axis or pivot, machine frame."""
        ...

    def element(self, motion: Motion) -> PointElement | LineElement:
        """The contact element at the motion's cam angles, machine frame, with three φ-derivatives."""
        ...

    def trace(self, motion: Motion) -> PointElement:
        """The follower's reference point (roller centre, face centre), machine frame, for drawings."""
        ...

    def describe(self) -> str:
        """A short label for reports, e.g. ``"translating roller r_f = 15 mm, e = 20 mm"``."""
        ...

    def contact_position(self, contact: FloatArray, motion: Motion) -> FloatArray:
        """(n,) where the contact sits on the follower [mm], from the machine-frame contact points (n, 2).

        Slides: its distance from the slide's axis along +x. Oscillating flat
        face: its distance along the face from the pivot's foot. Oscillating
        roller: its distance from the arm's line (r_f·sin of the angle off it).
        """
        ...

    def sketch(self, motion: Motion, *, size: float) -> list[FollowerSketch]:
        """The follower drawn at each of the motion's angles, machine frame; ``size`` [mm] scales stems."""
        ...
