"""The segments of a motion program as the user states them: kind, span, lift and law."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from camcad.motion.laws import Law

__all__ = ["SegmentKind", "SegmentSpec"]


class SegmentKind(enum.Enum):
    """Kinds of motion segment."""

    RISE = "rise"
    RETURN = "return"
    DWELL = "dwell"


@dataclass(frozen=True, slots=True, kw_only=True)
class SegmentSpec:
    """One rise, return or dwell. ``span`` rad, ``lift`` mm (positive for rise and return)."""

    kind: SegmentKind
    span: float
    lift: float = 0.0
    law: Law | None = None
