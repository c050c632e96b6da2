"""Plan the milling of a groove (face) cam's groove with an end mill narrower than the groove.

The groove's centre line is the pitch curve, the profile offset by r_f
(``cam.offset(φ, r_f)``); its flanks are the profile offset by
``inner_offset`` and ``outer_offset`` (:func:`camcad.geometry.groove.flank_offsets`).
A tool of radius r_t, with width/3 < 2 r_t < width, mills it in three passes,
all on arc splines fitted to the exact offset curves within the tolerance:

1. Slot: the tool enters at the start angle on the centre line at Z0 (a
   plunge in the air above the face) and ramps down along the closed
   centre line, one ``step_down`` (or less) per lap, Z proportional to the
   path length (arcs become helical G2/G3), then runs one flat lap at the
   full depth. It cuts a band 2 r_t wide about the centre line.
2. Inner flank finish at the full depth, tool centre on
   ``cam.offset(φ, inner_offset + r_t)``: the material (the cam's core) lies
   inside the path, so climb milling with the spindle M3 runs clockwise
   (as around a plate's outside profile, see :mod:`camcad.toolpath.plan`).
3. Outer flank finish, tool centre on ``cam.offset(φ, outer_offset − r_t)``:
   the material lies outside the path, so climb runs counter-clockwise (as
   in a bore).

Each finishing pass enters from the centre line's start point by a straight
move along the normal at the start angle (all offsets of one φ lie on one
normal), inside the groove, and leaves back to it the same way; at the end
the tool feeds up to the safe height. Each finishing pass removes
``width/2 − r_t`` of radial stock, which must be less than the tool
diameter for the slot and the finishing bands to overlap (r_t > width/6),
else a ridge would stand between them.

The toolpath's ``max_deviation`` is the larger two-way deviation, measured
after rounding, of the two finishing contours from their exact curves; the
slot is roughing and is not certified.
"""

from __future__ import annotations

import math

from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.groove import GrooveAnalysis, analyse_groove
from camcad.toolpath.contour import Contour, Step, fit_contour, offset_contour, round_mm
from camcad.toolpath.moves import Move, move_length
from camcad.toolpath.passes import Program, check_bore, mill_bore
from camcad.toolpath.plan import Toolpath, _breaks, _check_corners, _fit_tolerance
from camcad.toolpath.spec import Direction, GcodeSpec, Machine

__all__ = ["check_groove_tool", "plan_groove", "slot_levels"]

TWO_PI = 2.0 * math.pi


def check_groove_tool(groove: GrooveAnalysis, tool_radius: float) -> None:
    """Raise unless a tool of ``tool_radius`` [mm] can mill the groove: slot, then finish both flanks.

    Raises
    ------
    DesignError
        ``gcode.tool_diameter``: the tool is not narrower than the groove,
        is larger than a concave flank radius (it would gouge that flank),
        or is so small (2 r_t ≤ width/3) that a ridge would stand between the
        slot and a flank pass. The message gives the range allowed.
    """
    half = 0.5 * groove.width
    d = 2.0 * tool_radius
    smallest = 2.0 * half / 3.0
    if tool_radius >= half:
        raise DesignError(
            "gcode.tool_diameter",
            f"the tool D{d:g} mm is not narrower than the groove ({groove.width:.4f} mm wide); "
            f"allowed: a tool diameter above {smallest:.3f} and below {groove.width:.4f} mm",
        )
    if tool_radius > groove.tool_radius_max:
        at = groove.tool_radius_at
        raise DesignError(
            "gcode.tool_diameter",
            f"the tool D{d:g} mm is larger than the flanks' smallest concave radius "
            f"{at.value:.3f} mm {at.where()}, so it would gouge that flank; allowed: a tool diameter "
            f"of at most {2.0 * groove.tool_radius_max:.3f} mm",
        )
    if 3.0 * tool_radius <= half:
        raise DesignError(
            "gcode.tool_diameter",
            f"the tool D{d:g} mm leaves a ridge between the centre-line slot and the flank passes "
            f"(each flank pass would remove {half - tool_radius:.3f} mm, more than the tool's "
            f"diameter); allowed: a tool diameter above {smallest:.3f} mm (one third of the groove width)",
        )


def slot_levels(depth: float, step_down: float) -> tuple[float, ...]:
    """Z [mm] at the end of each ramp lap, top down: equal steps of at most ``step_down``, the last −depth.

    The full depth is rounded towards the face to the output's 4 decimals, so
    the written program never goes deeper than ``depth``.
    """
    bottom = math.floor(depth * 1e4 + 1e-6) / 1e4
    n = max(1, math.ceil(bottom / step_down - 1e-9))
    levels = [round_mm(-bottom * k / n) for k in range(1, n + 1)]
    levels[-1] = round_mm(-bottom)
    return tuple(levels)


def _planar_length(step: Step) -> float:
    """Length [mm] of one planar step of a contour."""
    return move_length(
        Move(kind=step.kind, start=(*step.start, 0.0), end=(*step.end, 0.0), center=step.center)
    )


def _run(
    prog: Program, contour: Contour, feed: float, z_from: float | None = None, z_to: float = 0.0
) -> None:
    """Follow ``contour`` once; with ``z_from``, ramp Z from it to ``z_to`` in proportion to path length."""
    lengths = [_planar_length(st) for st in contour.steps]
    total = sum(lengths)
    done = 0.0
    for k, (st, length) in enumerate(zip(contour.steps, lengths, strict=True)):
        done += length
        z = None
        if z_from is not None:
            z = z_to if k == len(contour.steps) - 1 else z_from + (z_to - z_from) * done / total
        if st.center is None:
            prog.line(*st.end, z=z, feed=feed)
        else:
            prog.arc(st.kind, *st.end, st.center, feed=feed, z=z)


def plan_groove(
    cam: Cam,
    spec: GcodeSpec,
    *,
    name: str,
    thickness: float,
    depth: float,
    clearance: float,
    bore: float = 0.0,
) -> Toolpath:
    """Plan the slot and the two flank finishing passes that mill a groove cam's groove.

    Parameters
    ----------
    cam
        The cam (a roller follower); its pitch curve is the groove's centre line.
    spec
        Milling settings (tool, tolerance, step-down, heights, feeds, start angle, direction).
    name
        Design name for the header.
    thickness
        Blank thickness [mm].
    depth
        Groove depth below the face [mm] (``groove.depth``).
    clearance
        Radial play between roller and groove [mm] (``groove.clearance``).
    bore
        Bore diameter [mm]; helix-milled through the blank when ``spec.mill_bore``.

    Returns
    -------
    Toolpath
        The moves; ``levels`` are the slot's ramp laps, ``rough_offset`` the
        centre line's offset from the profile (r_f), ``max_deviation`` the
        worst measured deviation of the two flank finishing contours.

    Raises
    ------
    DesignError
        A rotary machine (``gcode.machine``), a groove not shallower than
        the blank (``groove.depth``), a tool that does not fit the groove
        (``gcode.tool_diameter``, :func:`check_groove_tool`), a tolerance
        finer than the output holds, a bore the tool cannot mill.
    DesignLimitError
        When the profile has a corner (a velocity jump in the motion).
    """
    if spec.machine is not Machine.XY:
        raise DesignError(
            "gcode.machine",
            f"{spec.machine.value!r}: a groove is milled on an XY machine; allowed: 'xy'",
        )
    if not 0.0 < depth < thickness:
        raise DesignError(
            "groove.depth", f"{depth:g} mm must be above 0 and below the blank's thickness {thickness:g} mm"
        )
    fit_tol = _fit_tolerance(spec.tolerance)
    _check_corners(cam)
    groove = analyse_groove(cam, clearance=clearance)
    r = spec.tool_radius
    check_groove_tool(groove, r)
    if spec.mill_bore:
        check_bore(spec, bore)
    tol = spec.tolerance
    phi0 = float(spec.start_angle) % TWO_PI
    breaks = _breaks(cam, phi0)
    climb = spec.direction is Direction.CLIMB
    centre = fit_contour(
        cam, cam.roller_radius, breaks, tol, fit_tol, clockwise=True, fewest_arcs=spec.fewest_arcs
    )
    inner_at, outer_at = groove.inner_offset + r, groove.outer_offset - r
    # the flank paths: the centre line's arc spline offset (arcs stay arcs), measured, refitted if out
    inner = offset_contour(cam, centre, inner_at, breaks, tol, fit_tol, clockwise=climb)
    outer = offset_contour(cam, centre, outer_at, breaks, tol, fit_tol, clockwise=not climb)
    levels = slot_levels(depth, spec.step_down)
    bottom = levels[-1]
    notes = [
        f"groove: {groove.width:.4f} wide (2 r_f + clearance), {-bottom:.4f} deep; "
        f"centre line at profile offset {cam.roller_radius:.4f}",
        f"slot: enter at the start angle on the centre line at Z0, ramp down the closed centre line "
        f"in {len(levels)} laps of {-bottom / len(levels):.4f} (helical arcs), "
        f"then 1 flat lap at Z{bottom:.4f}",
        f"inner flank finish at Z{bottom:.4f}, offset {inner_at:.4f}, "
        f"{'clockwise' if climb else 'counter-clockwise'} ({spec.direction.value})",
        f"outer flank finish at Z{bottom:.4f}, offset {outer_at:.4f}, "
        f"{'counter-clockwise' if climb else 'clockwise'} ({spec.direction.value})",
        "flank passes enter and leave along the normal at the start angle from the centre line; "
        f"each removes {groove.width / 2.0 - r:.4f} of stock",
        f"measured deviation: inner flank {inner.max_deviation:.4f}, outer flank {outer.max_deviation:.4f}, "
        f"slot {centre.max_deviation:.4f}",
        "the blank's rim is not milled (turn it)",
    ]
    if spec.tab_count:
        notes.append("no tabs: the groove does not cut through the blank")
    prog = Program(spec.clearance_height)
    if spec.mill_bore:
        mill_bore(prog, spec, bore, thickness + spec.breakthrough)
        prog.rapid(z=spec.clearance_height)
    elif bore > 0.0:
        notes.append(f"bore D{bore:g} not milled (gcode.mill_bore = false)")
    prog.comment(f"slot along the centre line: ramp {len(levels)} laps to Z{bottom:.4f}")
    prog.rapid(*centre.start)
    prog.rapid(z=spec.safe_height)
    prog.line(z=0.0, feed=spec.plunge_feed)
    top = 0.0
    for k, z in enumerate(levels, start=1):
        prog.comment(f"slot ramp lap {k}/{len(levels)}: Z{top:.4f} to Z{z:.4f}")
        _run(prog, centre, spec.feed, top, z)
        top = z
    prog.comment(f"slot flat lap at Z{bottom:.4f}")
    _run(prog, centre, spec.feed)
    for contour, which in ((inner, "inner"), (outer, "outer")):
        prog.comment(f"{which} flank finishing pass at Z{bottom:.4f}, offset {contour.distance:.4f}")
        prog.line(*contour.start, feed=spec.feed)
        _run(prog, contour, spec.feed)
        prog.line(*centre.start, feed=spec.feed)
    prog.line(z=spec.safe_height, feed=spec.feed)
    prog.rapid(z=spec.clearance_height)
    return Toolpath(
        name=name,
        spec=spec,
        thickness=thickness,
        bore=bore,
        moves=tuple(prog.moves),
        levels=levels,
        final_depth=bottom,
        tab_top=None,
        rough_offset=cam.roller_radius,
        max_deviation=max(inner.max_deviation, outer.max_deviation),
        contour_blocks=len(inner.steps) + len(outer.steps),
        contour_arcs=len(inner.steps) + len(outer.steps),
        notes=tuple(notes),
        operation="groove",
    )
