"""The toolpath stage's options: the ``[gcode]`` table, the milling direction, the dialect and the machine."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from camcad.geometry.spec import Rotation
from camcad.knobs import Namer

__all__ = ["Cutter", "Dialect", "Direction", "GcodeSpec", "Machine", "RotaryAxis"]


class Dialect(enum.Enum):
    """G-code dialects."""

    LINUXCNC = "linuxcnc"
    GRBL = "grbl"
    GENERIC = "generic"


class Direction(enum.Enum):
    """Milling direction."""

    CLIMB = "climb"
    CONVENTIONAL = "conventional"


class Machine(enum.Enum):
    """How the cam is cut: contoured on an XY table, or turned past the tool on a rotary axis."""

    XY = "xy"
    ROTARY = "rotary"


class RotaryAxis(enum.Enum):
    """The letter of the rotary axis the cam turns on (``machine = "rotary"``)."""

    A = "A"
    C = "C"


class Cutter(enum.Enum):
    """The rotary machine's tool: an end mill on its side (step-downs) or a wheel (one pass)."""

    END_MILL = "end-mill"
    WHEEL = "wheel"


@dataclass(frozen=True, slots=True, kw_only=True)
class GcodeSpec:
    """Milling settings. Lengths mm, feeds mm/min, ``start_angle`` rad."""

    tool_diameter: float = 6.0
    choose_tool: bool = (
        False  # no tool_diameter stated: a groove gets the largest standard end mill that fits
    )
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
    fewest_arcs: bool = False  # refit the finishing arc spline to drop arcs (refine.thin_loop)
    tab_width: float = 6.0
    tab_height: float = 1.0
    clearance_height: float = 10.0
    safe_height: float = 2.0
    feed: float = 600.0
    plunge_feed: float = 150.0
    spindle_rpm: float = 10000.0
    coolant: bool = False
    mill_bore: bool = False
    machine: Machine = Machine.XY
    rotary_axis: RotaryAxis = RotaryAxis.A
    rotary_direction: Rotation = Rotation.CCW  # how the cam turns, seen from +Z, as the rotary word grows
    cutter: Cutter = Cutter.END_MILL  # rotary machine only
    name_of: Namer = field(default=str, compare=False, repr=False)
    """How the program's notes name a setting (the design layer gives its TOML path; default: words)."""

    @property
    def tool_radius(self) -> float:
        """Tool radius [mm]."""
        return self.tool_diameter / 2.0
