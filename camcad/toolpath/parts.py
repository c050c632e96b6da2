"""The tool path of one part of a cam family, by its shape and the machine.

A part with a :class:`~camcad.geometry.families.Pocket` is a groove: slot
and flank passes (:func:`camcad.toolpath.groove.plan_groove`); a plate is
cut along its outline, on a three-axis mill (:func:`camcad.toolpath.plan_toolpath`)
or a rotary table (:func:`camcad.toolpath.rotary.plan_rotary`).
"""

from __future__ import annotations

from camcad.geometry.families import Part
from camcad.toolpath.bar import plan_bar
from camcad.toolpath.groove import plan_groove
from camcad.toolpath.plan import Toolpath, plan_toolpath
from camcad.toolpath.rotary import RotaryToolpath, plan_rotary
from camcad.toolpath.spec import GcodeSpec, Machine

__all__ = ["plan_part"]


def plan_part(
    part: Part, spec: GcodeSpec, *, name: str, thickness: float, bore: float = 0.0
) -> Toolpath | RotaryToolpath:
    """Plan the milling of ``part``: its pocket's slot and flanks, or its outline.

    ``name`` [the design's] is written with the part's label (:meth:`Part.title`);
    ``thickness`` and ``bore`` (diameter) [mm] as for :func:`camcad.toolpath.plan_toolpath`.
    """
    title = part.title(name)
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
