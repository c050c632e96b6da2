"""Write a rotary program (``machine = "rotary"``): X and A (or C) words in inverse-time feed.

The program, for each depth level: rapid to the clear X and the first rotary
word at the clearance height, down to the level, a radial infeed (G94,
``plunge_feed``), one revolution of G93 blocks ``G1 X… A… F…`` with F on
every block (G93 requires it; F = 1/T with T the block's time in minutes),
back to G94 and a radial retract. The header says the machine convention,
the tool (end mill on its side, or wheel) and how the depth is cut.

Dialects: ``linuxcnc`` and ``generic`` (Fanuc-like) both read G93 and a
rotary axis; ``grbl`` has no rotary axis (grblHAL has one, but camcad does not
write for it yet), so a rotary program in that dialect is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from camcad.errors import DesignError
from camcad.export.gcode.dialects import dialect_rules
from camcad.export.gcode.writer import GcodeProgram, GcodeSummary, comment_text, count_blocks, program_start
from camcad.knobs import Knob
from camcad.toolpath.rotary import ANGLE_DECIMALS, X_DECIMALS
from camcad.toolpath.spec import Cutter, Dialect, Direction

if TYPE_CHECKING:
    from camcad.toolpath.rotary import RotaryToolpath

__all__ = ["ROTARY_DIALECTS", "RotarySummary", "inverse_feed_text", "render_rotary", "render_rotary_program"]

ROTARY_DIALECTS = (Dialect.LINUXCNC, Dialect.GENERIC)
"""Dialects that run a rotary program (G93 and a rotary axis)."""

_F_DIGITS = 6  # significant digits of an inverse-time F word (at least 3 decimals)


def _x(v: float) -> str:
    text = f"{v:.{X_DECIMALS}f}"
    return "0.0000" if text == f"-{0:.{X_DECIMALS}f}" else text


def _angle(v: float) -> str:
    text = f"{v:.{ANGLE_DECIMALS}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def _feed(v: float) -> str:
    return f"{v:.3f}".rstrip("0").rstrip(".")


def inverse_feed_text(value: float) -> str:
    """The F word of a G93 block: ``_F_DIGITS`` significant digits, plain decimals, never 0.

    >>> inverse_feed_text(18.89216), inverse_feed_text(0.000123456789)
    ('18.8922', '0.000123457')
    """
    if not value > 0.0 or not math.isfinite(value):
        raise ValueError(f"an inverse-time feed must be a positive number, got {value!r}")
    decimals = max(3, _F_DIGITS - 1 - math.floor(math.log10(value)))
    return f"{value:.{decimals}f}".rstrip("0").rstrip(".")


def _check_dialect(dialect: Dialect) -> None:
    if dialect not in ROTARY_DIALECTS:
        allowed = ", ".join(d.value for d in ROTARY_DIALECTS)
        raise DesignError(
            Knob.DIALECT,
            f"{dialect.value!r} cannot run a rotary program: grbl has no rotary axis and no G93 "
            f"inverse-time feed (grblHAL has both, but is not a camcad dialect yet); allowed with "
            f"machine = 'rotary': {allowed}",
        )


def _header(tp: RotaryToolpath, dialect: str) -> list[str]:
    s = tp.spec
    axis = s.rotary_axis.value
    turn = "counter-clockwise" if s.rotary_direction.value == "ccw" else "clockwise"
    depth = s.breakthrough + tp.thickness
    if s.cutter is Cutter.WHEEL:
        tool = f"tool: T{s.tool_number} grinding wheel D{s.tool_diameter:.3f} (radius {s.tool_radius:.3f})"
        cut = (
            f"depth: wheel, full thickness in one pass at Z{tp.levels[0]:.4f} "
            f"[the wheel face must be at least {depth:.3f} wide]"
        )
    else:
        tool = (
            f"tool: T{s.tool_number} flat end mill D{s.tool_diameter:.3f} (radius {s.tool_radius:.3f}), "
            "cutting with its side"
        )
        cut = f"depth: end mill, {len(tp.levels)} step-downs along the cam axis (Z) to Z{tp.levels[-1]:.4f}"
    milled = (
        "climb: the cam turns counter-clockwise seen from +Z"
        if s.direction is Direction.CLIMB
        else ("conventional: the cam turns clockwise seen from +Z")
    )
    lines = [
        f"camcad rotary G-code: {tp.name}",
        f"dialect: {dialect}",
        "units: millimetres [G21]; X in mm, rotary axis in degrees; G93 inverse-time feed while cutting",
        f"machine: rotary; cam axis = Z, cam on the {axis} axis, tool centre on the +X line through it",
        "X = distance from the cam axis to the tool centre [radius, not diameter]",
        f"{axis} = turn of the cam; {axis} grows as the cam turns {turn} seen from +Z; "
        f"at {axis}0 the cam frame lies on the machine frame",
        "origin: G54 X0 on the cam axis, Z0 on top of the stock",
        tool,
        cut,
        f"stock: plate {tp.thickness:.3f} thick [breakthrough {s.breakthrough:.3f}]; finishing only: "
        "rough the blank to within reach of the tool first",
        f"direction: {milled}, spindle M3",
        f"tolerance: {s.tolerance:.4f}, measured path deviation {tp.max_deviation:.4f} [radial, cam frame]",
        f"feed: {_feed(s.feed)} mm/min of contact path over the cam surface; "
        f"{tp.blocks_per_revolution} blocks per revolution, {tp.revolution_time():.1f} s each",
        f"retract: X{_x(tp.x_clear)} clears the cam; clearance Z{s.clearance_height:.3f}",
    ]
    return [f"({comment_text(t)})" for t in lines]


def render_rotary(toolpath: RotaryToolpath, dialect: Dialect | str | None = None) -> str:
    """The rotary G-code program, as text with a final newline.

    Parameters
    ----------
    toolpath
        The planned revolution (:func:`camcad.toolpath.rotary.plan_rotary`).
    dialect
        ``linuxcnc`` or ``generic`` (default: the toolpath's spec).

    Raises
    ------
    DesignError
        For ``grbl`` (no rotary axis, no G93), naming ``gcode.dialect``.
    """
    s = toolpath.spec
    chosen = dialect_rules(s.dialect if dialect is None else dialect)
    _check_dialect(Dialect(chosen.name))
    axis = s.rotary_axis.value
    words = toolpath.rotary_words
    out = _header(toolpath, chosen.name) + program_start(s, chosen)
    out.append(f"G0 X{_x(toolpath.x_clear)} {axis}{_angle(words[0])}")
    turn = 360.0 if words[-1] > words[0] else -360.0
    n_levels = len(toolpath.levels)
    for level, z in enumerate(toolpath.levels):
        shift = turn * level
        out.append(f"({comment_text(f'revolution {level + 1}/{n_levels} at Z{z:.4f}')})")
        out.append(f"G0 Z{_x(z)}")
        out.append(f"G1 X{_x(toolpath.x[0])} F{_feed(s.plunge_feed)}")
        out.append("G93")
        for x, a, f in zip(toolpath.x[1:], words[1:], toolpath.inverse_feed, strict=True):
            out.append(f"G1 X{_x(x)} {axis}{_angle(a + shift)} F{inverse_feed_text(f)}")
        out.append("G94")
        out.append(f"G1 X{_x(toolpath.x_clear)} F{_feed(s.plunge_feed)}")
    out.append(f"G0 Z{_x(s.clearance_height)}")
    if s.coolant:
        out.append("M9")
    out.append("M5")
    out.append(chosen.end)
    return "\n".join(out) + "\n"


@dataclass(frozen=True, slots=True, kw_only=True)
class RotarySummary(GcodeSummary):
    """Figures of a rotary program for summary.json (those of :class:`GcodeSummary` and more).

    Attributes
    ----------
    machine, rotary_axis, cutter
        ``"rotary"``, ``"A"`` or ``"C"``, ``"end-mill"`` or ``"wheel"``.
    blocks_per_revolution
        G93 blocks in one revolution.
    revolutions
        Depth levels (one revolution each).
    largest_tool_radius_mm
        The smallest concave radius of the profile: the largest end mill or
        wheel radius that cuts it exactly (None: no concave stretch).
    """

    machine: str
    rotary_axis: str
    cutter: str
    blocks_per_revolution: int
    revolutions: int
    largest_tool_radius_mm: float | None


def render_rotary_program(toolpath: RotaryToolpath, dialect: Dialect | str | None = None) -> GcodeProgram:
    """Render a rotary toolpath (:func:`render_rotary`) with its figures for summary.json."""
    text = render_rotary(toolpath, dialect)
    s = toolpath.spec
    concave = toolpath.concave_radius_min
    figures = RotarySummary(
        blocks=count_blocks(text),
        arcs=0,
        cutting_length_mm=float(toolpath.contact_length.sum()) * len(toolpath.levels),
        cycle_time_s=toolpath.cycle_time(),
        max_deviation_mm=toolpath.max_deviation,
        tool_diameter_mm=s.tool_diameter,
        machine=s.machine.value,
        rotary_axis=s.rotary_axis.value,
        cutter=s.cutter.value,
        blocks_per_revolution=toolpath.blocks_per_revolution,
        revolutions=len(toolpath.levels),
        largest_tool_radius_mm=round(concave, 6) if math.isfinite(concave) else None,
    )
    return GcodeProgram(text=text, figures=figures)
