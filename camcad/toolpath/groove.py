"""Plan the milling of a groove (face) cam's groove with an end mill narrower than the groove.

The groove's centre line is the pitch curve, the profile offset by r_f
(``cam.offset_curve(φ, r_f)``); its flanks are the profile offset by
``inner_offset`` and ``outer_offset`` (:func:`camcad.geometry.groove.flank_offsets`).
Any tool of radius r_t with 2 r_t < width (and r_t no larger than the flanks'
smallest concave radius) mills it, as a CAM program clears a slot wider than
its cutter, in passes on arc splines fitted to the exact offset curves within
the tolerance:

1. Slot: the tool enters at the start angle on the centre line at Z0 (a
   plunge in the air above the face) and ramps down along the closed
   centre line, one ``step_down`` (or less) per lap, Z proportional to the
   path length (arcs become helical G2/G3), then runs one flat lap at the
   full depth. It cuts a band 2 r_t wide about the centre line.
2. Clearing (only where the flank passes would remove more than r_t, half
   the tool, of radial stock): passes at evenly spaced offsets between the
   centre line and each flank's finishing offset, at most r_t apart (a 50 %
   stepover), first towards the inner flank then towards the outer, each
   nearer the centre line first, each run once at every slot level top
   down. The tool reaches each level at the centre line's start point (in
   the slot, cut to full depth) and moves out along the normal to the pass.
3. Inner flank finish at the full depth, tool centre on
   ``cam.offset_curve(φ, inner_offset + r_t)``: the material (the cam's core) lies
   inside the path, so climb milling with the spindle M3 runs clockwise
   (as around a plate's outside profile, see :mod:`camcad.toolpath.plan`).
4. Outer flank finish, tool centre on ``cam.offset_curve(φ, outer_offset − r_t)``:
   the material lies outside the path, so climb runs counter-clockwise (as
   in a bore).

Each finishing pass enters from the centre line's start point by a straight
move along the normal at the start angle (all offsets of one φ lie on one
normal), inside the groove, and leaves back to it the same way; at the end
the tool feeds up to the safe height. Adjacent passes are at most r_t
apart, so the bands they cut (2 r_t wide, offsets of one curve keep their
distance) overlap by r_t and no ridge stands between them.

Without a stated ``gcode.tool_diameter`` (``GcodeSpec.choose_tool``) the
planner chooses the cutter: the largest standard end mill
(:data:`STANDARD_END_MILLS`) no wider than 80 % of the groove and the flanks'
largest cutter (:func:`default_groove_tool`), and says so in the header.

The toolpath's ``max_deviation`` is the larger two-way deviation, measured
after rounding, of the two finishing contours from their exact curves; the
slot is roughing and is not certified.
"""

from __future__ import annotations

import math
from dataclasses import replace

from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.groove import GrooveAnalysis, analyse_groove
from camcad.knobs import Knob
from camcad.toolpath.contour import Contour, Step, fit_contour, offset_contour, round_mm
from camcad.toolpath.moves import Move, move_length
from camcad.toolpath.passes import Program, check_bore, mill_bore
from camcad.toolpath.plan import Toolpath, _breaks, _check_corners, _fit_tolerance
from camcad.toolpath.spec import Direction, GcodeSpec, Machine

__all__ = [
    "STANDARD_END_MILLS",
    "check_groove_tool",
    "clearing_offsets",
    "default_groove_tool",
    "plan_groove",
    "slot_levels",
]

TWO_PI = 2.0 * math.pi
STANDARD_END_MILLS = (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0, 32.0)
"""Diameters [mm] of the metric flat end mills a default cutter is chosen from (DIN 6527 sizes)."""
DEFAULT_TOOL_SHARE = 0.8
"""A default groove cutter is at most this share of the groove's width, leaving stock to finish each flank."""
MAX_CLEARING_PASSES = 200
"""Clearing passes on one side of the groove at most (a tool too small for the groove is refused)."""


def default_groove_tool(groove: GrooveAnalysis) -> float:
    """The default cutter's diameter [mm] for a groove: the largest standard end mill that fits it.

    Fits: at most :data:`DEFAULT_TOOL_SHARE` of the groove's width (stock left
    on each flank for the finishing passes) and at most twice the flanks'
    largest cutter radius (no gouge).

    Raises
    ------
    DesignError
        ``gcode.tool_diameter`` when no standard size fits (a groove under
        1.25 mm wide): the user must state a tool.
    """
    limit = min(DEFAULT_TOOL_SHARE * groove.width, 2.0 * groove.tool_radius_max)
    fits = [d for d in STANDARD_END_MILLS if d <= limit]
    if not fits:
        raise DesignError(
            Knob.TOOL_DIAMETER,
            f"no standard end mill fits the groove ({groove.width:.4f} mm wide, largest cutter "
            f"D{2.0 * groove.tool_radius_max:.3f} mm); allowed: state a tool diameter below {limit:.4f} mm",
        )
    return fits[-1]


def clearing_offsets(centre: float, finish: float, tool_radius: float) -> tuple[float, ...]:
    """Offsets [mm] of the clearing passes between the centre line and one flank's finishing pass.

    Evenly spaced, at most ``tool_radius`` apart, nearest the centre line
    first; empty when the finishing pass is within ``tool_radius`` of the
    centre line.

    Examples
    --------
    >>> clearing_offsets(12.0, 3.0, 3.0)
    (9.0, 6.0)
    >>> clearing_offsets(12.0, 4.015 + 8.0, 8.0)
    ()
    """
    gap = abs(finish - centre)
    n = max(1, math.ceil(gap / tool_radius - 1e-9))
    return tuple(centre + (finish - centre) * k / n for k in range(1, n))


def check_groove_tool(groove: GrooveAnalysis, tool_radius: float) -> None:
    """Raise unless a tool of ``tool_radius`` [mm] can mill the groove: slot, then finish both flanks.

    Raises
    ------
    DesignError
        ``gcode.tool_diameter``: the tool is not narrower than the groove,
        is larger than a concave flank radius (it would gouge that flank),
        or so small that one side of the groove would need more than
        :data:`MAX_CLEARING_PASSES` clearing passes. The message gives the
        range allowed.
    """
    half = 0.5 * groove.width
    d = 2.0 * tool_radius
    smallest = 2.0 * half / (MAX_CLEARING_PASSES + 1)
    if tool_radius >= half:
        raise DesignError(
            Knob.TOOL_DIAMETER,
            f"the tool D{d:g} mm is not narrower than the groove ({groove.width:.4f} mm wide); "
            f"allowed: a tool diameter below {groove.width:.4f} mm",
        )
    if tool_radius > groove.tool_radius_max:
        at = groove.tool_radius_at
        raise DesignError(
            Knob.TOOL_DIAMETER,
            f"the tool D{d:g} mm is larger than the flanks' smallest concave radius "
            f"{at.value:.3f} mm {at.where()}, so it would gouge that flank; allowed: a tool diameter "
            f"of at most {2.0 * groove.tool_radius_max:.3f} mm",
        )
    if (half - tool_radius) / tool_radius > MAX_CLEARING_PASSES:
        raise DesignError(
            Knob.TOOL_DIAMETER,
            f"the tool D{d:g} mm would need more than {MAX_CLEARING_PASSES} clearing passes on each side "
            f"of the groove ({groove.width:.4f} mm wide); allowed: a tool diameter above {smallest:.4f} mm",
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
            Knob.MACHINE,
            f"{spec.machine.value!r}: a groove is milled on an XY machine; allowed: 'xy'",
        )
    if not 0.0 < depth < thickness:
        raise DesignError(
            Knob.GROOVE_DEPTH,
            f"{depth:g} mm must be above 0 and below the blank's thickness {thickness:g} mm",
        )
    fit_tol = _fit_tolerance(spec.tolerance)
    _check_corners(cam)
    groove = analyse_groove(cam, clearance=clearance)
    chosen = spec.choose_tool
    if chosen:
        spec = replace(spec, tool_diameter=default_groove_tool(groove))
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
    clearing = [
        (offset_contour(cam, centre, at, breaks, tol, fit_tol, clockwise=cw), which)
        for finish, cw, which in ((inner_at, climb, "inner"), (outer_at, not climb, "outer"))
        for at in clearing_offsets(cam.roller_radius, finish, r)
    ]
    levels = slot_levels(depth, spec.step_down)
    bottom = levels[-1]
    notes = [
        f"groove: {groove.width:.4f} wide (2 r_f + clearance), {-bottom:.4f} deep; "
        f"centre line at profile offset {cam.roller_radius:.4f}",
        f"slot: enter at the start angle on the centre line at Z0, ramp down the closed centre line "
        f"in {len(levels)} laps of {-bottom / len(levels):.4f} (helical arcs), "
        f"then 1 flat lap at Z{bottom:.4f}",
    ]
    if chosen:
        notes.insert(
            0,
            f"tool D{spec.tool_diameter:g} chosen by camcad (no {spec.name_of(Knob.TOOL_DIAMETER)} given): "
            "the largest "
            f"standard end mill at most {DEFAULT_TOOL_SHARE:g} x the groove width and within the flanks' "
            f"largest cutter D{2.0 * groove.tool_radius_max:.3f}",
        )
    if clearing:
        sides = {w: sum(1 for _, x in clearing if x == w) for w in ("inner", "outer")}
        notes.append(
            f"clearing: {sides['inner']} pass(es) towards the inner flank, "
            f"{sides['outer']} towards the outer, "
            f"at most {r:.4f} apart (50% stepover), each at every slot level, entered along the normal "
            "at the start angle from the centre line"
        )
    notes += [
        f"inner flank finish at Z{bottom:.4f}, offset {inner_at:.4f}, "
        f"{'clockwise' if climb else 'counter-clockwise'} ({spec.direction.value})",
        f"outer flank finish at Z{bottom:.4f}, offset {outer_at:.4f}, "
        f"{'counter-clockwise' if climb else 'clockwise'} ({spec.direction.value})",
        "flank passes enter and leave along the normal at the start angle from the centre line; "
        f"each removes {(groove.width / 2.0 - r) / (len(clearing) // 2 + 1):.4f} of stock",
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
        notes.append(f"bore D{bore:g} not milled ({spec.name_of(Knob.MILL_BORE)} = false)")
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
    for contour, which in clearing:
        for z in levels:
            prog.comment(f"{which} clearing pass at Z{z:.4f}, offset {contour.distance:.4f}")
            prog.line(*centre.start, z=z, feed=spec.feed)  # in the slot, cut to full depth
            prog.line(*contour.start, feed=spec.feed)
            _run(prog, contour, spec.feed)
            prog.line(*centre.start, feed=spec.feed)
    if clearing:
        prog.line(z=bottom, feed=spec.feed)
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
        clearing_laps=len(clearing) * len(levels),
    )
