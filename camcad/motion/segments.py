"""The segments of a motion program as the user states them: kind, span, lift, law and boundary values."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from camcad.motion.laws import Law

__all__ = ["Boundary", "SegmentKind", "SegmentSpec"]


class SegmentKind(enum.Enum):
    """Kinds of motion segment.

    ``TABLE`` is a point table over the whole turn (``law = "table"``): its
    law gives the displacement itself [mm], not a normalised rise.
    """

    RISE = "rise"
    RETURN = "return"
    DWELL = "dwell"
    TABLE = "table"


@dataclass(frozen=True, slots=True, kw_only=True)
class Boundary:
    """Values a segment must take at one of its ends; ``None`` means "match" the neighbour.

    Attributes
    ----------
    v
        ds/dφ [mm/rad] (arm: [°/rad]), or ``None``.
    a
        d²s/dφ² [mm/rad²], or ``None``.
    j
        d³s/dφ³ [mm/rad³], or ``None``.
    """

    v: float | None = None
    a: float | None = None
    j: float | None = None

    def value(self, order: int) -> float | None:
        """The specified value of derivative ``order`` (1 = v, 2 = a, 3 = j), or ``None``."""
        return (self.v, self.a, self.j)[order - 1]

    @property
    def is_match(self) -> bool:
        """True when nothing is specified (every order matches the neighbour)."""
        return self.v is None and self.a is None and self.j is None


@dataclass(frozen=True, slots=True, kw_only=True)
class SegmentSpec:
    """One rise, return, dwell or point table.

    ``span`` rad, ``lift`` mm (positive for rise and return; degrees of swing
    on an arm). ``start`` and ``end`` hold the boundary values a segment whose
    law adapts (``polynomial``, ``inclined-sine``) must meet; unspecified
    orders match the neighbouring segment (a blend point).
    """

    kind: SegmentKind
    span: float
    lift: float = 0.0
    law: Law | None = None
    start: Boundary = Boundary()
    end: Boundary = Boundary()

    @property
    def signed_lift(self) -> float:
        """The scale h of the law: +lift on a rise, −lift on a return, 1 for a table, 0 for a dwell."""
        if self.kind is SegmentKind.RISE:
            return self.lift
        if self.kind is SegmentKind.RETURN:
            return -self.lift
        if self.kind is SegmentKind.TABLE:
            return 1.0
        return 0.0
