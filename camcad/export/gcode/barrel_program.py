"""A barrel cam's 4-axis program with its figures (:class:`~camcad.export.gcode.writer.GcodeProgram`)."""

from __future__ import annotations

import math

import numpy as np

from camcad.export.gcode.barrel import render_barrel_program
from camcad.export.gcode.writer import GcodeProgram, GcodeSummary, count_blocks
from camcad.toolpath.barrel import BarrelToolpath

__all__ = ["barrel_program"]


def barrel_program(toolpath: BarrelToolpath, *, name: str) -> GcodeProgram:
    """Render the barrel's passes (:func:`render_barrel_program`) and count its figures.

    The cutting length is the tool axis's path on the barrel's surface
    (radius R, straight in (Rθ, y, z) between blocks, as the program's feed
    counts it); the cycle time adds each pass's plunge at its feed and
    leaves out the rapids.
    """
    text = render_barrel_program(toolpath, name=name)
    s, radius = toolpath.options, toolpath.barrel.barrel_radius
    length = plunge = 0.0
    for p in toolpath.passes:
        da = np.radians(np.diff(p.a)) * radius
        length += float(np.sum(np.sqrt(np.diff(p.x) ** 2 + np.diff(p.y) ** 2 + da * da)))
        plunge += radius + s.clearance_height - p.z
    seconds = 60.0 * (length / s.feed + plunge / s.plunge_feed)
    figures = GcodeSummary(
        blocks=count_blocks(text),
        arcs=0,
        cutting_length_mm=length,
        cycle_time_s=seconds if math.isfinite(seconds) else 0.0,
        max_deviation_mm=toolpath.max_deviation,
        tool_diameter_mm=2.0 * toolpath.passes[0].radius,
    )
    return GcodeProgram(text=text, figures=figures)
