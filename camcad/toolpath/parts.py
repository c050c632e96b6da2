"""The tool path of one part of a cam family, by its shape and the machine.

A part with a :class:`~camcad.geometry.families.Barrel` is a barrel cam: its
groove (or the barrel round its rib) roughed and its walls (the rib's faces)
finished on a 4-axis machine (:func:`camcad.toolpath.barrel.plan_barrel`). A part with a
:class:`~camcad.geometry.families.Pocket` is a groove: slot and flank
passes (:func:`camcad.toolpath.groove.plan_groove`); a plate is cut along
its outline, on a three-axis mill (:func:`camcad.toolpath.plan_toolpath`)
or a rotary table (:func:`camcad.toolpath.rotary.plan_rotary`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from camcad.errors import DesignError
from camcad.geometry.barrel import BarrelKind
from camcad.geometry.families import Barrel, Part
from camcad.knobs import Knob
from camcad.toolpath.bar import plan_bar
from camcad.toolpath.groove import plan_groove
from camcad.toolpath.plan import Toolpath, plan_toolpath
from camcad.toolpath.rotary import RotaryToolpath, plan_rotary
from camcad.toolpath.spec import GcodeSpec, Machine

if TYPE_CHECKING:  # its module loads scipy: imported where a barrel is planned
    from camcad.toolpath.barrel import BarrelToolpath, BarrelToolpathOptions

__all__ = ["barrel_toolpath_options", "plan_part"]

ROUGH_SHARE = 0.625  # a chosen roughing cutter: this share of the groove's width less the stock


def barrel_toolpath_options(barrel: Barrel, spec: GcodeSpec) -> BarrelToolpathOptions:
    """The 4-axis options from ``[gcode]``: ``tool_diameter`` roughs (finishing takes the roller's).

    Without a stated ``tool_diameter`` the roughing cutter is the largest
    half-millimetre size within :data:`ROUGH_SHARE` of the groove's width
    (a rib: the gap 2r_f + c each roller runs in) less the stock on both
    walls; ``tool_number`` roughs and the next number finishes.

    Raises
    ------
    DesignError
        ``gcode.tool_diameter`` does not fit the groove with the stock on both walls.
    """
    from camcad.toolpath.barrel import BarrelToolpathOptions

    o = barrel.options
    room = 2.0 * (o.roller_radius + 0.5 * o.clearance - spec.stock_to_leave)  # mm, the widest rougher
    if spec.choose_tool:
        rough = max(0.5, math.floor(2.0 * ROUGH_SHARE * room) / 2.0)
    else:
        rough = spec.tool_diameter
    if rough > room:
        what = "the gap beside the rib" if o.kind is BarrelKind.RIB else "the groove"
        raise DesignError(
            Knob.TOOL_DIAMETER,
            f"{rough:g} mm does not fit {what} {2 * o.roller_radius + o.clearance:g} mm wide with "
            f"{spec.stock_to_leave:g} mm stock on each wall; allowed: ≤ {room:g} mm",
        )
    return BarrelToolpathOptions(
        tolerance=spec.tolerance,
        rough_diameter=rough,
        step_down=spec.step_down,
        stock=spec.stock_to_leave,
        clearance_height=spec.clearance_height,
        feed=spec.feed,
        plunge_feed=spec.plunge_feed,
        spindle_rpm=spec.spindle_rpm,
        rough_tool=spec.tool_number,
        finish_tool=spec.tool_number + 1,
    )


def plan_part(
    part: Part, spec: GcodeSpec, *, name: str, thickness: float, bore: float = 0.0
) -> Toolpath | RotaryToolpath | BarrelToolpath:
    """Plan the milling of ``part``: a barrel's groove, its pocket's slot and flanks, or its outline.

    ``name`` [the design's] is written with the part's label (:meth:`Part.title`);
    ``thickness`` and ``bore`` (diameter) [mm] as for :func:`camcad.toolpath.plan_toolpath`.
    """
    title = part.title(name)
    if part.barrel is not None:
        from camcad.toolpath.barrel import plan_barrel

        b = part.barrel
        return plan_barrel(b.program, b.follower, b.options, barrel_toolpath_options(b, spec))
    if part.pocket is not None:
        pocket = part.pocket
        return plan_groove(
            part.cam,
            spec,
            name=title,
            thickness=thickness,
            depth=pocket.depth,
            clearance=pocket.clearance,
            bore=bore,
        )
    if part.bar is not None:  # a linear cam's bar: its open edge, cut on an XY mill
        return plan_bar(part.cam, part.bar, spec, name=title, thickness=thickness)
    if spec.machine is Machine.ROTARY:  # X + A/C in inverse time
        return plan_rotary(part.cam, spec, name=title, thickness=thickness)
    return plan_toolpath(part.cam, spec, name=title, thickness=thickness, bore=bore)
