"""Write a barrel cam's 4-axis program: X, Y, Z and A words, G93 inverse-time feed while cutting.

Each pass (:mod:`camcad.toolpath.barrel`): a tool change when the tool
changes, a rapid to the clearance height, to the pass's first X Y A, a plunge
to its Z (G94, ``plunge_feed``), one revolution of ``G1 X… Y… A… F…`` blocks in
G93 (F = 1/T, T the block's time in minutes for ``feed`` mm/min of the tool
axis's path on the barrel's surface), back to G94 and a retract. A passes
unwind (A runs 0 → −360 in every pass, the way back being a rapid at the
clearance height). LinuxCNC dialect (G-code that its ``rs274`` reads). A rib's program
(:func:`camcad.toolpath.barrel.plan_barrel`, module notes) is written the
same way; its header names the rib and its faces.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from camcad.export.gcode.rotary import inverse_feed_text
from camcad.export.gcode.writer import comment_text
from camcad.geometry.barrel import BarrelKind

if TYPE_CHECKING:
    from camcad.toolpath.barrel import BarrelToolpath

__all__ = ["render_barrel_program"]


def _n(v: float) -> str:
    text = f"{v:.4f}"
    return "0.0000" if text == "-0.0000" else text


def render_barrel_program(toolpath: BarrelToolpath, *, name: str = "barrel cam") -> str:
    """The program as text with a final newline (module notes)."""
    s, o = toolpath.options, toolpath.barrel
    clear = o.barrel_radius + s.clearance_height
    head = [
        f"camcad barrel G-code: {name}",
        "units: millimetres [G21]; X, Y, Z in mm, A in degrees; G93 inverse-time feed while cutting",
        "machine: 4-axis; barrel axis = machine X [X0 at the barrel's end z = 0], barrel on the A axis",
        "A turns the barrel about +X; at A0 the barrel's x axis points to +Z; the tool points down -Z",
        "Z = distance of the tool tip from the barrel axis; Y = offset of the tool axis from it",
        f"rough: T{s.rough_tool} flat end mill D{2 * toolpath.passes[0].radius:.3f}, stock {s.stock:.3f}",
        f"tolerance: {s.tolerance:.4f}, measured path deviation {toolpath.max_deviation:.4f}",
    ]
    finish = toolpath.passes[-1]
    if finish.taper > 0.0:
        head[-1:-1] = [
            f"finish: T{s.finish_tool} tapered end mill, tip D{2 * finish.radius:.4f} at Z{finish.z:.4f}, "
            f"flank half-angle {math.degrees(math.atan(finish.taper)):.4f} deg",
            f"radius grows {finish.taper:.6f}/mm up the tool: the conical roller's taper (apex on the axis)",
            "the tapered cutter follows the roller's own path: one pass cuts both walls",
        ]
    elif o.kind is BarrelKind.RIB:
        head[-1:-1] = [
            f"rib: {o.rib_width:g} wide, top Z{o.barrel_radius:.4f}; the barrel round it is cut to its root "
            f"Z{o.bottom_radius:.4f} over X0 to X{o.length:g}",
            f"finish: T{s.finish_tool} flat end mill D{2 * o.roller_radius:.3f} (the rollers' diameter) "
            "along each face's roller's own path, one pass per face",
        ]
        head.append(
            f"a face finished with T{s.rough_tool} instead (exact at the pitch station) would be off by "
            f"up to {float(abs(toolpath.small_cutter[0]).max()):.4f} at the rib's root and "
            f"{float(abs(toolpath.small_cutter[1]).max()):.4f} at its top"
        )
        head.append(
            f"the flat ends leave a fillet up to {toolpath.root_fillet:.4f} high at the rib's root beside "
            "its flanks, where the faces' root edges stand off the root cylinder"
        )
        if toolpath.floor_rise > 0.0:
            head.append(
                f"the floor round the rib stays up to {toolpath.floor_rise:.4f} above the root where the "
                f"roughing cutter's axis runs more than its radius off the barrel's axis [Y]"
            )
    else:
        head[-1:-1] = [
            f"finish: T{s.finish_tool} flat end mill D{2 * o.roller_radius:.3f} (the roller's diameter) "
            "along the roller's own path, one pass per wall",
        ]
        head.append(
            f"a wall finished with T{s.rough_tool} instead (exact at the pitch station) would be off by "
            f"up to {float(abs(toolpath.small_cutter[0]).max()):.4f} at the groove's bottom and "
            f"{float(abs(toolpath.small_cutter[1]).max()):.4f} at its top"
        )
    out = [f"({comment_text(t)})" for t in head]
    out += ["G21 G90 G17 G40 G49 G94 G64 P" + _n(s.tolerance)]
    tool = None
    for i, p in enumerate(toolpath.passes):
        if p.tool != tool:
            if tool is not None:
                out.append("M5")
            out.append(f"T{p.tool} M6")
            out.append(f"G43 H{p.tool}")
            out.append(f"G0 Z{_n(clear)}")
            out.append(f"S{s.spindle_rpm:.0f} M3")
            tool = p.tool
        out.append(f"({comment_text(f'pass {i + 1}/{len(toolpath.passes)}: {p.kind} at Z{p.z:.4f}')})")
        out.append(f"G0 Z{_n(clear)}")
        out.append(f"G0 X{_n(p.x[0])} Y{_n(p.y[0])} A{_n(p.a[0])}")
        out.append(f"G1 Z{_n(p.z)} F{s.plunge_feed:g}")
        out.append("G93")
        # the block's time: the tool axis's path on the barrel's surface (radius R), straight in (Rθ, y, z)
        dx, dy = np.diff(p.x), np.diff(p.y)
        da = np.radians(np.diff(p.a)) * o.barrel_radius
        minutes = np.sqrt(dx * dx + dy * dy + da * da) / s.feed
        for x, y, a, t in zip(p.x[1:], p.y[1:], p.a[1:], minutes, strict=True):
            f = 1.0 / max(float(t), 1e-9)
            out.append(f"G1 X{_n(x)} Y{_n(y)} A{_n(a)} F{inverse_feed_text(f)}")
        out.append("G94")
        out.append(f"G0 Z{_n(clear)}")
        out.append(f"G0 A{_n(p.a[0])}")
    out += ["M5", "M2"]
    if not math.isfinite(clear):
        raise ValueError("clearance height is not finite")
    return "\n".join(out) + "\n"
