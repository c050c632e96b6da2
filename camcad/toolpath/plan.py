"""Plan the toolpath that mills a cam plate's outside profile (and its bore) from stock.

The tool-centre path is the exact profile offset outward by the tool radius,
``cam.offset_curve(phi, r_tool)``, approximated by arc splines within the tolerance.
Roughing passes step down to the full depth on the path offset by the tool
radius plus the stock to leave; one full-depth finishing pass follows. Passes
enter and leave on tangent arcs off the part, may leave holding tabs, and
never rapid below the safe height.

Milling direction (outside profile, spindle M3 = clockwise seen from +Z).
Take the tool moving +x above the part's top edge, part below it. Turning
clockwise, a tooth passes the front of the tool (+x side) moving down into
the uncut stock, then the bottom (the finished surface) moving −x: it enters
the chip thick and leaves it thin, and its edge at the surface moves against
the tool's travel. That is climb milling, with the part on the tool's right
(the G41 + M3 rule), so climb travels CLOCKWISE around the part and
conventional counter-clockwise. In a bore the material is outside the path,
so climb runs counter-clockwise there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray
from camcad.errors import DesignError, DesignLimitError
from camcad.geometry.cam import Cam
from camcad.geometry.tool import check_tool
from camcad.knobs import Knob
from camcad.toolpath.arcs.biarc import norm2
from camcad.toolpath.contour import LINE_SAGITTA, Contour, fit_contour, offset_contour, round_mm
from camcad.toolpath.moves import Move, MoveKind, path_length
from camcad.toolpath.passes import Program, check_bore, cut_contour, lead_points, mill_bore
from camcad.toolpath.spec import Direction, GcodeSpec

__all__ = ["RAPID_RATE", "Toolpath", "plan_toolpath"]

TWO_PI = 2.0 * math.pi
RAPID_RATE = 5000.0  # mm/min, assumed for the cycle-time estimate
_ROUNDING_ALLOWANCE = 3e-4  # mm: end points, centre and spiral from 4-decimal output
_BREAK_MERGE = 1e-7  # rad: breaks closer than this are one
_DENSE = 20_000  # samples for arc length along the profile


@dataclass(frozen=True, slots=True, kw_only=True)
class Toolpath:
    """A planned milling program.

    Attributes
    ----------
    name
        Design name, for the header.
    spec
        The milling settings.
    thickness
        Plate thickness [mm].
    bore
        Bore diameter [mm] (0: none).
    moves
        Every motion block in order.
    levels
        Z of each roughing pass [mm], top down; the last is the full depth.
    final_depth
        Z of the full depth [mm] (−thickness − breakthrough).
    tab_top
        Z of the top of the tabs [mm], or None without tabs.
    rough_offset
        Distance of the roughing path from the profile [mm] (tool radius + stock).
    max_deviation
        Two-way distance between the written finishing contour and the exact
        offset curve, measured after rounding [mm].
    contour_blocks
        Blocks in one finishing contour (leads excluded; tab edges split its steps).
    contour_arcs
        Arcs and lines of the finishing contour's arc spline, before tab edges split them.
    notes
        Remarks for the header (e.g. a keyway left for another operation).
    operation
        ``"profile"`` (a plate's outline, cut through) or ``"groove"`` (a
        groove cam's slot and flank passes, :func:`camcad.toolpath.groove.plan_groove`).
    clearing_laps
        A groove's clearing laps between the slot and the flank passes (one per pass and level).
    """

    name: str
    spec: GcodeSpec
    thickness: float
    bore: float
    moves: tuple[Move, ...]
    levels: tuple[float, ...]
    final_depth: float
    tab_top: float | None
    rough_offset: float
    max_deviation: float
    contour_blocks: int
    contour_arcs: int
    notes: tuple[str, ...] = ()
    operation: str = "profile"
    clearing_laps: int = 0

    @property
    def tool_radius(self) -> float:
        """Tool radius [mm]."""
        return self.spec.tool_radius

    def cutting_length(self) -> float:
        """Length of all feed moves [mm]."""
        return path_length(self.moves, (MoveKind.LINE, MoveKind.CW, MoveKind.CCW))

    def cycle_time(self, *, rapid_rate: float = RAPID_RATE) -> float:
        """Estimated run time [s]: feed moves at their feed, rapids at ``rapid_rate`` [mm/min].

        Acceleration, tool change and spindle start are not included.
        """
        minutes = 0.0
        for m in self.moves:
            rate = rapid_rate if m.kind is MoveKind.RAPID else m.feed
            minutes += m.length / rate
        return 60.0 * minutes


def _check_corners(cam: Cam) -> None:
    for bp in cam.program.breakpoints:
        if bp.continuity == 0:
            raise DesignLimitError(
                f"the follower velocity jumps at φ = {math.degrees(bp.phi):.1f}°, so the profile "
                "has a corner there; the toolpath needs a tangent-continuous profile "
                "(use a law whose velocity matches its neighbours, e.g. cycloidal)"
            )


def _fit_tolerance(tol: float) -> float:
    fit = min(0.8 * tol, (1.0 - LINE_SAGITTA) * tol - _ROUNDING_ALLOWANCE)
    if fit < 0.25 * tol:
        raise DesignError(
            Knob.GCODE_TOLERANCE,
            f"{tol:g} mm is finer than 4-decimal output can hold; use at least 0.0005 mm",
        )
    return fit


# ---------------------------------------------------------------------------
# tabs


def _tab_windows(cam: Cam, spec: GcodeSpec, phi0: float) -> list[tuple[float, float]]:
    """φ-windows [rad] (unwrapped in [phi0, phi0 + 2π]) where the tool rides over a tab."""
    if spec.tab_count == 0:
        return []
    phi = phi0 + np.linspace(0.0, TWO_PI, _DENSE + 1)
    pts = cam.offset_curve(phi, spec.tool_radius).point
    s = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))))
    total = float(s[-1])
    spacing = total / spec.tab_count
    half = 0.5 * spec.tab_width + spec.tool_radius
    lead = spec.lead_radius if spec.lead_radius is not None else spec.tool_diameter
    if half >= 0.5 * spacing - 0.5 * lead:
        # each tab needs its width + the tool diameter, and room for a lead between tabs
        most = math.floor(total / (2.0 * half + lead) - 1e-9)
        widest = spacing - lead - spec.tool_diameter
        room = f"{spec.tab_count} tabs of {spec.tab_width:g} mm (plus the tool Ø{spec.tool_diameter:g} mm) "
        room += f"do not fit around the {total:.1f} mm contour"
        if most >= 1:
            raise DesignError(
                Knob.TAB_COUNT,
                f"{room}; allowed: at most {most} tab(s) of this width"
                + (f", or tabs narrower than {widest:.2f} mm" if widest > 0 else ""),
            )
        raise DesignError(Knob.TAB_WIDTH, f"{room}: not even one fits; use narrower tabs or a smaller tool")
    out = []
    for i in range(spec.tab_count):
        mid = (i + 0.5) * spacing
        lo, hi = np.interp([mid - half, mid + half], s, phi)
        out.append((float(lo), float(hi)))
    return out


def _lead_radius(
    cam: Cam, contour: Contour, distance: float, wanted: float, tol: float, phi0: float
) -> float:
    """The largest lead radius ≤ ``wanted`` [mm] whose leads keep ``distance`` from the profile.

    Raises
    ------
    DesignError
        When even a lead of a tenth of ``wanted`` would cut into the part.
    """
    phi = cam.sample_phi()
    profile = cam.profile(phi).point
    radius = wanted
    while radius >= 0.1 * wanted:
        pts = np.asarray(lead_points(contour, radius))
        gap = np.min(norm2(pts[:, None, :] - profile[None, :, :]), axis=1)
        if gap.min() >= distance - tol:
            return radius
        radius /= 1.25
    raise DesignError(
        Knob.START_ANGLE,
        f"no room for a lead of {0.1 * wanted:g} mm or more at φ = {math.degrees(phi0):g}°; "
        "choose another start_angle (a dwell is best)",
    )


def _breaks(cam: Cam, phi0: float) -> FloatArray:
    """Fit breaks [rad]: the start angle, every breakpoint after it where the velocity jumps, and start + 2π.

    The arc search passes over breakpoints where only the curvature (or its
    rate) jumps, ending arcs wherever they reach (measured: fewer blocks than
    nodes held on the curve there); a velocity jump is a corner and keeps a node.
    """
    joints = [phi0 + (bp.phi - phi0) % TWO_PI for bp in cam.program.breakpoints if bp.continuity < 1]
    pts: FloatArray = np.unique(np.asarray([phi0, *joints, phi0 + TWO_PI]))
    keep = np.concatenate(([True], np.diff(pts) > _BREAK_MERGE))
    out = pts[keep]
    out[-1] = phi0 + TWO_PI
    return out


def plan_toolpath(
    cam: Cam,
    spec: GcodeSpec,
    *,
    name: str,
    thickness: float,
    bore: float = 0.0,
    arcs: bool = True,
) -> Toolpath:
    """Plan roughing and finishing passes around the cam profile (and the bore).

    Parameters
    ----------
    cam
        The cam; its exact offset curve ``cam.offset_curve(phi, r)`` is the tool path.
    spec
        Milling settings (tool, tolerance, passes, tabs, heights, feeds).
    name
        Design name for the header.
    thickness
        Plate thickness [mm]; the cut goes to −(thickness + breakthrough).
    bore
        Bore diameter [mm]; milled when ``spec.mill_bore``.
    arcs
        False writes the contour as G1 chords only, at the same tolerance
        (for comparison; see ``benchmarks/gcode.py``).

    Returns
    -------
    Toolpath
        The moves, with the measured deviation of the finishing contour.

    Raises
    ------
    GougeError
        When a concave radius of the profile is smaller than the tool radius.
    DesignError
        When the tolerance is finer than 4-decimal output holds, the tabs do
        not fit, the tab height reaches the top of the plate, or the bore is
        not larger than the tool.
    DesignLimitError
        When the profile has a corner (a velocity jump in the motion).

    Notes
    -----
    ``start_angle`` is the cam angle φ at which the passes enter and leave
    the profile. The roughing stock is reduced where a concave radius is
    smaller than tool radius + stock, so that the roughing path never loops.
    Tab width is the bridge left on the part; the tool rises over
    ``tab_width + tool diameter`` of its path, measured on the finishing path.
    """
    fit_tol = _fit_tolerance(spec.tolerance)
    _check_corners(cam)
    if spec.mill_bore:
        check_bore(spec, bore)
    concave = check_tool(cam, spec.tool_radius)
    tab_top = _tab_top(spec, thickness)
    notes: list[str] = []
    stock = _roughing_stock(spec, concave, notes)
    finish, rough, lead = _fit_contours(cam, spec, stock, fit_tol, arcs=arcs, notes=notes)
    depth = thickness + spec.breakthrough
    n_levels = max(1, math.ceil(depth / spec.step_down - 1e-9))
    levels = tuple(round_mm(-depth * k / n_levels) for k in range(1, n_levels + 1))
    prog = Program(spec.clearance_height)
    if spec.mill_bore:
        mill_bore(prog, spec, bore, depth)
        prog.rapid(z=spec.clearance_height)
    elif bore > 0.0:
        notes.append(f"bore D{bore:g} not milled ({spec.name_of(Knob.MILL_BORE)} = false)")
    r = spec.tool_radius
    for k, z in enumerate(levels, start=1):
        cut_contour(
            prog, rough, spec, z, tab_top, lead,
            f"profile roughing pass {k}/{n_levels} at Z{z:.4f}, offset {r + stock:.4f} mm",
        )  # fmt: skip
    cut_contour(
        prog, finish, spec, levels[-1], tab_top, lead,
        f"profile finishing pass at Z{levels[-1]:.4f}, offset {r:.4f} mm",
    )  # fmt: skip
    prog.rapid(z=spec.clearance_height)
    return Toolpath(
        name=name,
        spec=spec,
        thickness=thickness,
        bore=bore,
        moves=tuple(prog.moves),
        levels=levels,
        final_depth=levels[-1],
        tab_top=tab_top,
        rough_offset=r + stock,
        max_deviation=finish.max_deviation,
        contour_blocks=len(finish.tabbed_steps()),
        contour_arcs=len(finish.steps),
        notes=tuple(notes),
    )


def _tab_top(spec: GcodeSpec, thickness: float) -> float | None:
    """Z of the top of the tabs [mm], or None without tabs.

    Raises
    ------
    DesignError
        When the tabs would reach the top of the plate (``gcode.tab_height``).
    """
    if spec.tab_count == 0:
        return None
    if spec.tab_height >= thickness:
        raise DesignError(
            Knob.TAB_HEIGHT,
            f"{spec.tab_height:g} mm must be below the plate thickness {thickness:g} mm",
        )
    return round_mm(-thickness + spec.tab_height)


def _roughing_stock(spec: GcodeSpec, concave: float, notes: list[str]) -> float:
    """Stock left by the roughing passes [mm], reduced so that the roughing path never loops.

    Where the smallest concave radius ``concave`` [mm] is below 1/0.9 × (tool
    radius + stock), the stock shrinks to 0.9 × concave − tool radius (a note says so).
    """
    r, stock = spec.tool_radius, spec.stock_to_leave
    if math.isfinite(concave) and r + stock >= 0.9 * concave:
        stock = max(0.0, 0.9 * concave - r)
        notes.append(f"roughing stock reduced to {stock:.3f} mm by a concave radius of {concave:.3f} mm")
    return stock


def _fit_contours(
    cam: Cam, spec: GcodeSpec, stock: float, fit_tol: float, *, arcs: bool, notes: list[str]
) -> tuple[Contour, Contour, float]:
    """The finishing and roughing contours and the lead radius [mm] that keeps both leads off the part."""
    r, tol = spec.tool_radius, spec.tolerance
    phi0 = float(spec.start_angle) % TWO_PI
    windows = _tab_windows(cam, spec, phi0)
    breaks = _breaks(cam, phi0)
    clockwise = spec.direction is Direction.CLIMB
    finish = fit_contour(
        cam, r, breaks, tol, fit_tol,
        clockwise=clockwise, windows=windows, arcs=arcs, fewest_arcs=spec.fewest_arcs,
    )  # fmt: skip
    if stock > 0.0 and arcs:
        # the finishing arc spline offset by the stock (arcs stay arcs), measured; refitted if it misses
        rough = offset_contour(
            cam, finish, r + stock, breaks, tol, fit_tol, clockwise=clockwise, windows=windows
        )
    elif stock > 0.0:  # chords offset apart at their corners: fit them afresh
        rough = fit_contour(
            cam, r + stock, breaks, tol, fit_tol,
            clockwise=clockwise, windows=windows, arcs=arcs,
        )  # fmt: skip
    else:
        rough = finish
    wanted = spec.lead_radius if spec.lead_radius is not None else spec.tool_diameter
    lead = _lead_radius(cam, finish, r, wanted, tol, phi0)
    if rough is not finish:
        lead = min(lead, _lead_radius(cam, rough, r + stock, lead, tol, phi0))
    if lead < wanted:
        notes.append(f"lead radius reduced to {lead:.3f} mm to stay clear of the part")
    return finish, rough, lead
