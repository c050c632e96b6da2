"""The follower interface of the generic envelope."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from camcad.geometry.envelope import Guide, LineElement, PointElement
from camcad.motion.program import Motion

__all__ = ["Follower", "slide_point"]


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
