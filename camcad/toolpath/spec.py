"""The toolpath stage's options: the ``[gcode]`` table, the milling direction and the dialect."""

from __future__ import annotations

import enum
from dataclasses import dataclass

__all__ = ["Dialect", "Direction", "GcodeSpec"]


class Dialect(enum.Enum):
    """G-code dialects."""

    LINUXCNC = "linuxcnc"
    GRBL = "grbl"
    GENERIC = "generic"


class Direction(enum.Enum):
    """Milling direction."""

    CLIMB = "climb"
    CONVENTIONAL = "conventional"


@dataclass(frozen=True, slots=True, kw_only=True)
class GcodeSpec:
    """Milling settings. Lengths mm, feeds mm/min, ``start_angle`` rad."""

    tool_diameter: float = 6.0
    tool_number: int = 1
    tolerance: float = 0.005
    dialect: Dialect = Dialect.LINUXCNC
    direction: Direction = Direction.CLIMB
    stock_to_leave: float = 0.2
    step_down: float = 2.0
    breakthrough: float = 0.5
    lead_radius: float | None = None  # None: the tool diameter
    start_angle: float = 0.0
    tab_count: int = 0
    tab_width: float = 6.0
    tab_height: float = 1.0
    clearance_height: float = 10.0
    safe_height: float = 2.0
    feed: float = 600.0
    plunge_feed: float = 150.0
    spindle_rpm: float = 10000.0
    coolant: bool = False
    mill_bore: bool = False

    @property
    def tool_radius(self) -> float:
        """Tool radius [mm]."""
        return self.tool_diameter / 2.0
