"""DXF drawings of the cam: the exact SPLINE drawing, and polyline and arcs files for cutting.

Three files, one for each kind of program (the README's table "which file
for which program"):

- ``profile.dxf``: the drawing for CAD programs that read splines
  (LibreCAD, FreeCAD, …): the profile as one exact SPLINE, with the pitch
  curve, bore, centre lines and notes.
- ``profile_poly.dxf``: only the cutting contours as closed LWPOLYLINEs
  without bulges, for laser cutters and OpenSCAD.
- ``profile_arcs.dxf``: only the cutting contours as tangent-continuous
  ARCs (and LINEs), within the fit tolerance, for CNC controllers and CAM
  importers that do not read splines.

No file holds construction geometry as a closed outline, and ``profile.dxf``
holds nothing but SPLINEs, LINEs and TEXT: OpenSCAD, which extrudes every
LWPOLYLINE, CIRCLE and ARC it finds (open ones closed into slivers) and skips
SPLINE, extrudes the whole part from the cutting files and nothing from
``profile.dxf``.

``profile.dxf`` (DXF R2010, millimetres) holds, by layer:

``CAM_PROFILE``
    The fitted profile as one SPLINE: non-rational, clamped, cubic, last
    control point equal to the first, flags 0, written from control points
    and knots. Fit points and the periodic/closed encodings are avoided on
    purpose: CAD programs rebuild fit-point splines with their own end
    conditions, and LibreCAD and ezdxf's renderer misdraw periodic ones.
``PITCH_CURVE``
    Roller followers only (``[dxf].pitch_curve``): the roller-centre path,
    dashed by its geometry: one open degree-1 SPLINE per dash (``PITCH_DASH``
    mm long, ``PITCH_GAP`` mm apart, stretched to fit the curve's length),
    its control points within ``[dxf].chord_tolerance`` of the curve,
    linetype Continuous. LibreCAD restarts a linetype pattern at every
    vertex, so a DASHED closed polyline or spline with short segments prints
    solid; FreeCAD ignores linetypes. Dashes print dashed everywhere, and as
    SPLINEs OpenSCAD skips them (it closed each open LWPOLYLINE dash into a
    sliver body, issue 31).
``GROOVE_INNER``, ``GROOVE_OUTER``, ``BLANK``
    A groove cam (issue 15) instead of ``CAM_PROFILE``: its inner and outer
    flank as one SPLINE each (their own certified fits), the pitch curve
    being the groove's centre line, and the blank's rim as a CIRCLE. The
    polyline and arcs files hold the same layers.
``BORE``
    The bore (and keyway) as one closed cubic SPLINE of Bézier spans (triple
    knots): each arc span ≤ ``BORE_SPAN_DEG`` with the standard handles
    (4/3)·tan(θ/4)·r, whose radial error is below 1.1e-9 of the radius
    (Dokken et al. 1990), the keyway's sides straight spans with exact
    corners. A CIRCLE or a bulge polyline would be read by OpenSCAD (which
    ignores bulges); as a SPLINE OpenSCAD skips it, so ``profile.dxf`` gives
    OpenSCAD nothing to extrude, and the part comes from ``profile_poly.dxf``.
``CENTER``
    Two centre lines through the cam axis, CENTER linetype.
``ANNOTATION``
    Plain TEXT: name, sizes, follower, motion laws, fit tolerance.

``profile_poly.dxf`` holds only the cutting contours, ``CAM_PROFILE`` and
``BORE``, as closed LWPOLYLINEs without bulges within
``[dxf].chord_tolerance``, for laser cutters and OpenSCAD, which ignore
splines. ``profile_arcs.dxf`` holds the same two layers as ARC and LINE
entities: the profile as biarcs within the fit tolerance
(:func:`~camcad.export._outline.arc_outline`), the bore as a CIRCLE, or four
LINEs and one ARC with its keyway. The pitch curve, centre lines and text are
left out of both so a cutter does not cut them.

Every file has ``$EXTMIN``/``$EXTMAX`` and ``$LIMMIN``/``$LIMMAX`` set to
the drawing's extents plus ``EXTENTS_MARGIN`` and its initial view framed on them (not ezdxf's
±1e20 and 1000 mm defaults). More closed outlines (a groove's flanks, a
second plate) go on layers of their own through the same helpers
(``_add_profile_spline``, ``_add_closed_polyline``, ``_add_arcs``, each
taking a layer name) and a line in ``LAYERS``.

Every document is audited before saving; an audit error raises
:class:`~camcad.errors.ExportError` and nothing is written.
"""

from __future__ import annotations

import itertools
import math
import os
import re
import unicodedata
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

# First: this imports ezdxf without the user's config files and font cache.
from camcad.export._ezdxf import ezdxf, save_reproducible

# isort: split
import numpy as np
from ezdxf import zoom
from ezdxf.document import Drawing
from ezdxf.layouts import Modelspace

from camcad._typing import FloatArray
from camcad.errors import ExportError
from camcad.export._bar import bar_outline
from camcad.export._outline import arc_outline, chord_budget, flatten_bspline, flatten_curve
from camcad.export.atomic import atomic_write
from camcad.export.spec import DxfSpec
from camcad.fit.curve import BSplineCurve
from camcad.fit.result import ProfileFit
from camcad.geometry.plate import BoreOutline, Plate, circle_segments
from camcad.knobs import Knob
from camcad.motion.segments import SegmentKind
from camcad.toolpath.arcs.biarc import Pieces

if TYPE_CHECKING:
    from camcad.geometry.cam import Cam
    from camcad.geometry.families import Part

__all__ = [
    "DXF_VERSION",
    "LAYERS",
    "DxfCurve",
    "dxf_text",
    "pitch_dashes",
    "profile_arcs_document",
    "profile_document",
    "profile_poly_document",
    "write_bar_dxfs",
    "write_part_dxfs",
    "write_profile_arcs_dxf",
    "write_profile_dxf",
    "write_profile_poly_dxf",
]

DXF_VERSION = "R2010"
INSUNITS_MM = 4  # $INSUNITS code for millimetres
MEASUREMENT_METRIC = 1  # $MEASUREMENT: metric linetype and hatch patterns
TEXT_HEIGHT = 2.5  # mm, ISO 3098 lettering
CENTER_OVERHANG = 5.0  # mm beyond the largest profile radius
PITCH_DASH = 3.0  # mm, dash of the pitch curve (ISO 128-20 dashed line: dash 12 d, gap 3 d, d = 0.25 mm)
PITCH_GAP = 0.75  # mm
MIN_DASHES = 24  # a small cam still shows a dashed curve
TEXT_WIDTH = 1.0  # character width / height, a generous bound for the drawing's extents (no font metrics)
VIEW_MARGIN = 5.0  # mm around the extents in the initial view
EXTENTS_MARGIN = 5.0  # mm round the drawn box in $EXTMIN/$EXTMAX: a fit-to-page print keeps pen and text
BORE_SPAN_DEG = 11.25  # largest sweep of one Bézier span of the bore spline (radial error < 1.1e-9 r)

# layer name: (ACI colour, linetype)
LAYERS: dict[str, tuple[int, str]] = {
    "CAM_PROFILE": (7, "Continuous"),
    "GROOVE_INNER": (7, "Continuous"),  # a groove cam's flanks (issue 15)
    "GROOVE_OUTER": (5, "Continuous"),
    "BLANK": (8, "Continuous"),  # a groove cam's blank
    "PITCH_CURVE": (3, "Continuous"),  # dashed by its geometry (see the module docstring)
    "BORE": (1, "Continuous"),
    "CENTER": (4, "CENTER"),
    "ANNOTATION": (250, "Continuous"),  # dark grey: prints on white paper (yellow, 2, did not)
    "FRAME": (8, "Continuous"),  # not plotted: the sheet's margin round profile.dxf (see _frame)
}


@dataclass(frozen=True, slots=True, kw_only=True)
class DxfCurve:
    """One certified closed curve of a drawing: its layer, its fit, and the exact curve it stands for.

    The exact curve is ``cam.offset_curve(φ, offset)``: the profile for ``offset = 0``,
    a groove's flank for the offsets of :func:`camcad.geometry.groove.flank_offsets`.
    """

    layer: str
    fit: ProfileFit
    offset: float = 0.0


def _curves(fit: ProfileFit, curves: Sequence[DxfCurve] | None) -> Sequence[DxfCurve]:
    return curves if curves is not None else (DxfCurve(layer="CAM_PROFILE", fit=fit),)


def _add_blank(msp: Modelspace, radius: float | None) -> None:
    """A groove cam's blank outline as one CIRCLE on layer BLANK."""
    if radius is not None:
        msp.add_circle((0.0, 0.0), radius, dxfattribs={"layer": "BLANK"})


def _new_document() -> tuple[Drawing, Modelspace]:
    doc = ezdxf.new(DXF_VERSION, setup=["linetypes"], units=INSUNITS_MM)
    doc.header["$INSUNITS"] = INSUNITS_MM
    doc.header["$MEASUREMENT"] = MEASUREMENT_METRIC
    for name, (color, linetype) in LAYERS.items():
        layer = doc.layers.add(name, color=color, linetype=linetype)
        if name == "FRAME":
            layer.dxf.plot = 0
    return doc, doc.modelspace()


def _check_clamped(curve: BSplineCurve) -> None:
    """Raise ExportError unless ``curve`` is a closed, clamped, non-periodic B-spline."""
    p = curve.degree
    knots = np.asarray(curve.knots, dtype=float)
    ctrl = np.asarray(curve.control_points, dtype=float)
    problems = []
    if curve.periodic:
        problems.append("it is the periodic form")
    if knots.size != ctrl.shape[0] + p + 1:
        problems.append(f"{knots.size} knots for {ctrl.shape[0]} control points of degree {p}")
    elif np.any(knots[: p + 1] != knots[0]) or np.any(knots[-p - 1 :] != knots[-1]):
        problems.append("its end knots are not clamped")
    if np.any(np.diff(knots) < 0.0):
        problems.append("its knots decrease")
    if not np.array_equal(ctrl[0], ctrl[-1]):
        problems.append("its last control point differs from the first")
    if problems:
        raise ExportError(
            "the profile cannot be written as a DXF SPLINE: "
            + "; ".join(problems)
            + "; pass ProfileFit.clamped"
        )


def _add_profile_spline(msp: Modelspace, curve: BSplineCurve, layer: str = "CAM_PROFILE") -> None:
    """One SPLINE from control points and knots: non-rational, flags 0, no fit points."""
    _check_clamped(curve)
    spline = msp.add_spline(degree=curve.degree, dxfattribs={"layer": layer})
    spline.dxf.flags = 0
    spline.control_points = [(float(x), float(y), 0.0) for x, y in curve.control_points]  # type: ignore[assignment]
    spline.knots = [float(k) for k in curve.knots]  # type: ignore[assignment]


def _add_closed_polyline(msp: Modelspace, points: np.ndarray, layer: str) -> None:
    msp.add_lwpolyline(
        [(float(x), float(y)) for x, y in points],
        format="xy",
        close=True,
        dxfattribs={"layer": layer},
    )


def bore_bezier(bore: BoreOutline) -> np.ndarray:
    """Control points (3k + 1, 2) [mm] of the bore outline as k cubic Bézier spans, counter-clockwise, closed.

    Arc spans of sweep θ ≤ ``BORE_SPAN_DEG`` have handles of length
    (4/3)·tan(θ/4)·r along the tangents (Dokken et al. 1990); the radial
    error grows as θ⁶ (2.7e-4 r at 90°), so below 1.1e-9 r at 11.25°. Keyway sides are
    straight spans (control points at thirds), corners exact.
    """
    r = bore.radius
    if bore.has_keyway:
        (x0, y0, _), (x1, y1, _), (x2, y2, _), (x3, y3, _) = bore.bulge_vertices()
        a0 = math.atan2(y3, x3)
        sweep = 2.0 * math.pi - 2.0 * math.asin(bore.keyway_width / (2.0 * r))
        lines = [((x0, y0), (x1, y1)), ((x1, y1), (x2, y2)), ((x2, y2), (x3, y3))]
    else:
        a0, sweep, lines = -0.5 * math.pi, 2.0 * math.pi, []
    pts: list[tuple[float, float]] = []
    for a, b in lines:
        pa, pb = np.asarray(a), np.asarray(b)
        pts += [a, tuple(pa + (pb - pa) / 3.0), tuple(pa + 2.0 * (pb - pa) / 3.0)]
    n = max(1, math.ceil(math.degrees(sweep) / BORE_SPAN_DEG - 1e-9))
    theta = sweep / n
    k = 4.0 / 3.0 * math.tan(theta / 4.0) * r  # Dokken et al. 1990: the cubic arc's handle length
    for i in range(n):
        t0, t1 = a0 + i * theta, a0 + (i + 1) * theta
        p0 = (r * math.cos(t0), r * math.sin(t0))
        p3 = (r * math.cos(t1), r * math.sin(t1))
        pts += [
            p0,
            (p0[0] - k * math.sin(t0), p0[1] + k * math.cos(t0)),
            (p3[0] + k * math.sin(t1), p3[1] - k * math.cos(t1)),
        ]
    pts.append(pts[0])
    return np.asarray(pts, dtype=np.float64)


def _add_bore_exact(msp: Modelspace, bore: BoreOutline) -> None:
    """The bore (and keyway) as one closed cubic SPLINE of Bézier spans (see :func:`bore_bezier`)."""
    control = bore_bezier(bore)
    spans = (len(control) - 1) // 3
    spline = msp.add_spline(degree=3, dxfattribs={"layer": "BORE"})
    spline.dxf.flags = 0
    spline.control_points = [(float(x), float(y), 0.0) for x, y in control]  # type: ignore[assignment]
    knots = [0.0] + [float(j) for j in range(spans + 1) for _ in range(3)] + [float(spans)]
    spline.knots = knots  # type: ignore[assignment]


def _add_arcs(msp: Modelspace, pieces: Pieces, layer: str, *, positive_angles: bool = False) -> None:
    """ARC and LINE entities of biarc pieces (empty pieces skipped); an ARC runs ccw, so cw arcs swap ends.

    Angles are written in (−180°, 180°], or with ``positive_angles`` in
    [0°, 360°): LibreCAD (2.2) draws an ARC whose start angle is exactly −90°
    as a full circle, which a linear cam's edge meets where it starts (x = 0)
    on a horizontal tangent; a plate's profile never lands on exactly −90°.
    """
    attribs = {"layer": layer}
    for k in range(len(pieces)):
        for j in range(2):
            start, end = pieces.start[k, j], pieces.end[k, j]
            if np.array_equal(start, end):
                continue
            if pieces.line[k, j]:
                msp.add_line(tuple(map(float, start)), tuple(map(float, end)), dxfattribs=attribs)
                continue
            centre = pieces.center[k, j]
            a0 = math.degrees(math.atan2(start[1] - centre[1], start[0] - centre[0]))
            a1 = math.degrees(math.atan2(end[1] - centre[1], end[0] - centre[0]))
            if not pieces.ccw[k, j]:
                a0, a1 = a1, a0
            if positive_angles:
                a0, a1 = a0 % 360.0, a1 % 360.0
            msp.add_arc(
                (float(centre[0]), float(centre[1])), float(pieces.r_start[k, j]), a0, a1, dxfattribs=attribs
            )


def _add_bore_arcs(msp: Modelspace, bore: BoreOutline) -> None:
    """The bore as a CIRCLE, or its keyway as four LINEs and the bore as one ARC (no bulges)."""
    if not bore.has_keyway:
        msp.add_circle((0.0, 0.0), bore.radius, dxfattribs={"layer": "BORE"})
        return
    corners = [(x, y) for x, y, _ in bore.bulge_vertices()]
    for a, b in itertools.pairwise(corners):
        msp.add_line(a, b, dxfattribs={"layer": "BORE"})
    # the bore arc runs ccw from the last corner (−w/2, y₀) round the bottom to the first (w/2, y₀)
    a0 = math.degrees(math.atan2(corners[-1][1], corners[-1][0]))
    a1 = math.degrees(math.atan2(corners[0][1], corners[0][0]))
    msp.add_arc((0.0, 0.0), bore.radius, a0, a1, dxfattribs={"layer": "BORE"})


def pitch_dashes(points: np.ndarray) -> list[np.ndarray]:
    """A closed polyline cut into dashes: ``PITCH_DASH`` on, ``PITCH_GAP`` off, stretched to close evenly.

    Parameters
    ----------
    points
        (n, 2) vertices of a closed polyline [mm], the first not repeated.

    Returns
    -------
    list[np.ndarray]
        One (m, 2) open polyline per dash [mm]; its ends lie on the polyline
        (linear interpolation between vertices), its inner points are vertices.
    """
    ring = np.vstack((points, points[:1]))
    along = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(ring, axis=0), axis=1))))
    length = float(along[-1])
    count = max(MIN_DASHES, round(length / (PITCH_DASH + PITCH_GAP)))
    period = length / count
    on = period * PITCH_DASH / (PITCH_DASH + PITCH_GAP)
    dashes = []
    for k in range(count):
        a, b = k * period, k * period + on
        inner = (along > a) & (along < b)
        ends = np.column_stack([np.interp([a, b], along, ring[:, i]) for i in range(2)])
        dashes.append(np.vstack((ends[:1], ring[inner], ends[1:])))
    return dashes


def _add_dashes(msp: Modelspace, dashes: list[np.ndarray], layer: str) -> None:
    """Each dash as an open degree-1 SPLINE through its vertices (clamped, uniform knots)."""
    for dash in dashes:
        spline = msp.add_spline(degree=1, dxfattribs={"layer": layer})
        spline.dxf.flags = 0
        spline.control_points = [(float(x), float(y), 0.0) for x, y in dash]  # type: ignore[assignment]
        spline.knots = [0.0, *map(float, range(len(dash))), float(len(dash) - 1)]  # type: ignore[assignment]


def _frame(doc: Drawing, box: tuple[float, float, float, float]) -> None:
    """Set extents and limits to ``box`` (xmin, ymin, xmax, ymax) [mm] + ``EXTENTS_MARGIN``; frame the view.

    LibreCAD's ``dxf2pdf -a`` fits the extents to the page: without the
    margin it clipped the outline's pen and the last text line's descenders.
    """
    x0, y0, x1, y1 = (float(v) for v in box)
    x0, y0, x1, y1 = x0 - EXTENTS_MARGIN, y0 - EXTENTS_MARGIN, x1 + EXTENTS_MARGIN, y1 + EXTENTS_MARGIN
    msp = doc.modelspace()  # ezdxf copies the model space layout's extents and limits to the header on save
    msp.reset_extents((x0, y0, 0.0), (x1, y1, 0.0))
    msp.reset_limits((x0, y0), (x1, y1))
    zoom.window(msp, (x0 - VIEW_MARGIN, y0 - VIEW_MARGIN), (x1 + VIEW_MARGIN, y1 + VIEW_MARGIN))


def _add_sheet_frame(msp: Modelspace, box: tuple[float, float, float, float]) -> None:
    """A rectangle ``EXTENTS_MARGIN`` round ``box`` on the non-plotting layer FRAME: a closed degree-1 SPLINE.

    LibreCAD's ``dxf2pdf -a`` fits the drawn entities (not ``$EXTMIN``) to the
    page: the frame gives the print its margin and is itself not printed;
    OpenSCAD skips SPLINEs, so it closes no outline there.
    """
    x0, y0, x1, y1 = box
    m = EXTENTS_MARGIN
    corners = [(x0 - m, y0 - m), (x1 + m, y0 - m), (x1 + m, y1 + m), (x0 - m, y1 + m), (x0 - m, y0 - m)]
    spline = msp.add_spline(degree=1, dxfattribs={"layer": "FRAME"})
    spline.dxf.flags = 0
    spline.control_points = [(float(x), float(y), 0.0) for x, y in corners]  # type: ignore[assignment]
    spline.knots = [0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 4.0]  # type: ignore[assignment]


def _box(points: np.ndarray, bore: BoreOutline | None) -> tuple[float, float, float, float]:
    """Bounding box of an outline's vertices and a bore (its reach from the axis) [mm]."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    reach = bore.reach if bore is not None else 0.0
    return (min(lo[0], -reach), min(lo[1], -reach), max(hi[0], reach), max(hi[1], reach))


def _add_center_lines(msp: Modelspace, reach: float) -> None:
    for start, end in (((-reach, 0.0), (reach, 0.0)), ((0.0, -reach), (0.0, reach))):
        msp.add_line(start, end, dxfattribs={"layer": "CENTER"})


MAX_TEXT_CHARS = 250  # a DXF string value holds at most 255 characters in R12-era readers


def dxf_text(text: str) -> str:
    """Text made safe for one DXF TEXT entity.

    Every user text that reaches the drawing (the cam name) goes through
    here: ASCII only (accents dropped, other characters ``?``), every control
    character a space (a newline would end the group value and corrupt the
    file), no ``%%`` (the start of a TEXT control code such as ``%%u``
    underline or ``%%c`` diameter), no ``^`` (the DXF caret escape for
    control characters, ``^J``; it becomes ``'``), at most ``MAX_TEXT_CHARS``.
    """
    plain = unicodedata.normalize("NFKD", text)
    plain = "".join(c for c in plain if not unicodedata.combining(c))
    plain = plain.encode("ascii", "replace").decode("ascii")
    plain = "".join(" " if ord(c) < 32 or ord(c) == 127 else c for c in plain)
    plain = " ".join(plain.split())
    plain = re.sub(r"%{2,}", "%", plain).replace("^", "'")
    if len(plain) > MAX_TEXT_CHARS:
        plain = plain[: MAX_TEXT_CHARS - 3] + "..."
    return plain


def _annotation_lines(cam: Cam, plate: Plate, curves: Sequence[DxfCurve]) -> list[str]:
    """Plain-ASCII lines of the annotation block."""
    follower, bore = cam.follower_spec, plate.bore
    sizes = f"base radius {cam.base_radius:.3f} mm, thickness {plate.thickness:.3f} mm"
    if bore is not None:
        sizes += f", bore dia {2.0 * bore.radius:.3f} mm"
        if bore.has_keyway:
            sizes += f", keyway {bore.keyway_width:.3f} x {bore.keyway_depth:.3f} mm"
    who = cam.follower.describe()
    if follower.kind.face and follower.face_width is not None:
        who += f", face width {follower.face_width:.3f} mm"
    who = f"follower {follower.kind.word}: {who}, rotation {cam.rotation.value}"
    lines = [f"CAM {plate.name}", sizes, who]
    for seg in cam.program.segments:
        span = f"{math.degrees(seg.span):.3f} deg"
        if seg.kind is SegmentKind.DWELL or seg.law is None:
            lines.append(f"{seg.kind.value} {span}")
        else:
            lines.append(f"{seg.kind.value} {span}, lift {seg.lift:.3f} mm, {seg.law.describe()}")
    for curve in curves:
        what = "profile" if curve.layer == "CAM_PROFILE" else curve.layer.lower().replace("_", " ")
        fit = curve.fit
        lines.append(f"{what} spline: fit tolerance {fit.tolerance:.4g} mm, max error {fit.max_error:.3g} mm")
    lines.append("units mm")
    return [dxf_text(line) for line in lines]


def _add_annotation(msp: Modelspace, lines: list[str], reach: float) -> tuple[float, float]:
    """TEXT lines below the cam; the lowest y used and the largest x the text may reach [mm]."""
    y = -reach - 2.0 * TEXT_HEIGHT
    for line in lines:
        y -= 1.6 * TEXT_HEIGHT
        msp.add_text(line, height=TEXT_HEIGHT, dxfattribs={"layer": "ANNOTATION"}).set_placement((-reach, y))
    widest = max((len(line) for line in lines), default=0) * TEXT_WIDTH * TEXT_HEIGHT
    return y, -reach + widest


def _audited(doc: Drawing, name: str) -> Drawing:
    auditor = doc.audit()
    if auditor.has_errors:
        messages = "; ".join(str(e.message) for e in auditor.errors[:5])
        raise ExportError(f"{name}: the DXF audit found {len(auditor.errors)} error(s): {messages}")
    return doc


def profile_document(
    *,
    cam: Cam,
    fit: ProfileFit,
    plate: Plate,
    options: DxfSpec,
    curves: Sequence[DxfCurve] | None = None,
    blank_radius: float | None = None,
) -> Drawing:
    """Build the ``profile.dxf`` document (not saved); see the module docstring for layers.

    Parameters
    ----------
    cam
        The exact cam; supplies the pitch curve.
    fit
        The certified profile fit; ``fit.clamped`` becomes the SPLINE.
    plate
        Name, thickness, bore and keyway.
    options
        ``[dxf]`` settings.
    curves
        The closed curves to draw, each a SPLINE on its own layer (a
        groove's flanks); default: ``fit`` as the profile on ``CAM_PROFILE``.
    blank_radius
        A groove cam's blank [mm], drawn as a CIRCLE on ``BLANK``.

    Raises
    ------
    ExportError
        When the fit is not a closed clamped spline or the audit fails.
    """
    doc, msp = _new_document()
    reach = 0.0
    for curve in _curves(fit, curves):
        _add_profile_spline(msp, curve.fit.clamped, curve.layer)
        outline = flatten_bspline(curve.fit.clamped, options.chord_tolerance)
        reach = max(reach, float(np.max(np.hypot(outline[:, 0], outline[:, 1]))))
    _add_blank(msp, blank_radius)
    reach = max(reach, blank_radius or 0.0)
    if options.pitch_curve and cam.has_pitch_curve:
        breaks = list(cam.program.pieces)
        pitch = flatten_curve(cam.pitch, options.chord_tolerance, breakpoints=breaks)
        _add_dashes(msp, pitch_dashes(pitch), "PITCH_CURVE")
        reach = max(reach, float(np.max(np.hypot(pitch[:, 0], pitch[:, 1]))))
    bore = plate.bore
    if bore is not None:
        _add_bore_exact(msp, bore)
    reach += CENTER_OVERHANG
    _add_center_lines(msp, reach)
    bottom, right = -reach, reach
    if options.annotate:
        low, widest = _add_annotation(msp, _annotation_lines(cam, plate, _curves(fit, curves)), reach)
        bottom, right = low - TEXT_HEIGHT, max(reach, widest)
    _frame(doc, (-reach, bottom, right, reach))
    _add_sheet_frame(msp, (-reach, bottom, right, reach))
    return _audited(doc, "profile.dxf")


def profile_poly_document(
    *,
    cam: Cam,
    fit: ProfileFit,
    plate: Plate,
    options: DxfSpec,
    curves: Sequence[DxfCurve] | None = None,
    blank_radius: float | None = None,
) -> Drawing:
    """Build the ``profile_poly.dxf`` document: profile (or ``curves``) and bore as bulge-free LWPOLYLINEs.

    Each curve is flattened from its fit's clamped spline with a chord error
    bound of ``[dxf].chord_tolerance`` less the fit's certified error
    (:func:`~camcad.export._outline.chord_budget`), so every vertex and chord
    lies within ``chord_tolerance`` of the exact curve; the bore polygon (and
    a groove cam's blank) is inscribed in its exact circle within the
    tolerance, with exact keyway corners. ``cam`` is accepted for a uniform
    signature and not used.
    """
    del cam
    doc, msp = _new_document()
    tol = options.chord_tolerance
    outlines = [
        flatten_bspline(c.fit.clamped, chord_budget(tol, c.fit.max_error, field=Knob.DXF_CHORD_TOLERANCE))
        for c in _curves(fit, curves)
    ]
    for curve, outline in zip(_curves(fit, curves), outlines, strict=True):
        _add_closed_polyline(msp, outline, curve.layer)
    if blank_radius is not None:
        n = circle_segments(blank_radius, tol)
        angle = np.arange(n) * (2.0 * math.pi / n)
        rim = blank_radius * np.column_stack((np.cos(angle), np.sin(angle)))
        _add_closed_polyline(msp, rim, "BLANK")
        outlines.append(rim)
    bore = plate.bore
    if bore is not None:
        _add_closed_polyline(msp, bore.polygon(tol), "BORE")
    _frame(doc, _box(np.vstack(outlines), bore))
    return _audited(doc, "profile_poly.dxf")


def profile_arcs_document(
    *,
    cam: Cam,
    fit: ProfileFit,
    plate: Plate,
    options: DxfSpec,
    curves: Sequence[DxfCurve] | None = None,
    blank_radius: float | None = None,
) -> Drawing:
    """Build the ``profile_arcs.dxf`` document: the profile as tangent arcs, the bore as ARC/LINE/CIRCLE.

    The arcs are biarcs through the exact profile ``cam.offset_curve(φ, 0)``
    within the fit tolerance ``fit.tolerance``, measured two-way
    (:func:`~camcad.export._outline.arc_outline`); consecutive arcs share end
    points and tangents. ``options`` is accepted for a uniform signature.
    """
    del options
    doc, msp = _new_document()
    pad, boxes = 0.0, []
    for curve in _curves(fit, curves):

        def exact(phi: np.ndarray, d: float = curve.offset) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            o = cam.offset_curve(phi, d)
            return o.point, o.d1, o.d2

        tol = curve.fit.tolerance
        try:
            pieces, _ = arc_outline(exact, list(cam.program.pieces), tol, straight=cam.straight_spans)
        except ValueError as err:  # a corner in the profile: a velocity jump, refused earlier as a hard limit
            raise ExportError(f"profile_arcs.dxf: {err}") from err
        _add_arcs(msp, pieces, curve.layer)
        # the arcs lie within the tolerance of the exact curve, which lies within max_error of the spline
        boxes.append(flatten_bspline(curve.fit.clamped, tol))
        pad = max(pad, tol + curve.fit.max_error)
    if blank_radius is not None:
        _add_blank(msp, blank_radius)
        boxes.append(np.array([[-blank_radius, -blank_radius], [blank_radius, blank_radius]]) * (1.0 - pad))
    bore = plate.bore
    if bore is not None:
        _add_bore_arcs(msp, bore)
    x0, y0, x1, y1 = _box(np.vstack(boxes), bore)
    _frame(doc, (x0 - pad, y0 - pad, x1 + pad, y1 + pad))
    return _audited(doc, "profile_arcs.dxf")


def _save(doc: Drawing, path: str | os.PathLike[str]) -> Path:
    return atomic_write(path, lambda tmp: save_reproducible(doc, tmp))


def _writer(build: Callable[..., Drawing], name: str) -> Callable[..., Path]:
    """The atomic file writer of one document builder (the three share their keywords)."""

    def write(
        path: str | os.PathLike[str],
        *,
        cam: Cam,
        fit: ProfileFit,
        plate: Plate,
        options: DxfSpec,
        curves: Sequence[DxfCurve] | None = None,
        blank_radius: float | None = None,
    ) -> Path:
        doc = build(cam=cam, fit=fit, plate=plate, options=options, curves=curves, blank_radius=blank_radius)
        return _save(doc, path)

    write.__name__ = write.__qualname__ = f"write_{name}_dxf"
    write.__doc__ = f"Write ``{name}.dxf`` atomically and return its path; see :func:`{build.__name__}`."
    return write


write_profile_dxf = _writer(profile_document, "profile")
write_profile_arcs_dxf = _writer(profile_arcs_document, "profile_arcs")
write_profile_poly_dxf = _writer(profile_poly_document, "profile_poly")


def write_part_dxfs(
    folder: str | os.PathLike[str],
    part: Part,
    *,
    fit: ProfileFit,
    flank_fits: Sequence[ProfileFit] = (),
    plate: Plate,
    options: DxfSpec,
) -> list[Path]:
    """``profile{suffix}.dxf``, ``profile_poly{suffix}.dxf`` and ``profile_arcs{suffix}.dxf`` of one part.

    A part with a pocket is drawn as its blank (``BLANK``) with the pocket's
    flanks (their fits ``flank_fits``, on the flanks' layers); a plate as its outline.
    """
    if part.bar is not None:  # a linear cam's bar: its open edge and three sides (camcad.export.bar)
        return write_bar_dxfs(folder, part, fit=fit, plate=plate, options=options)
    curves: tuple[DxfCurve, ...] | None = None
    blank_radius: float | None = None
    if part.pocket is not None:
        curves = tuple(
            DxfCurve(layer=flank.layer, fit=flank_fit, offset=flank.offset)
            for flank, flank_fit in zip(part.flanks, flank_fits, strict=True)
        )
        blank_radius = part.pocket.outer_radius
    return [
        write(
            Path(folder) / f"{name}{part.suffix}.dxf",
            cam=part.cam,
            fit=fit,
            plate=plate,
            options=options,
            curves=curves,
            blank_radius=blank_radius,
        )
        for name, write in (
            ("profile", write_profile_dxf),
            ("profile_poly", write_profile_poly_dxf),
            ("profile_arcs", write_profile_arcs_dxf),
        )
    ]


PITCH_SAMPLES_PER_DEG = 4  # a linear cam's pitch-line vertices per degree of motion (dashed reference)


def _open_spline(msp: Modelspace, curve: BSplineCurve, layer: str) -> None:
    """An open SPLINE from the curve's poles and knots: non-rational, flags 0, no fit points."""
    spline = msp.add_spline(degree=curve.degree, dxfattribs={"layer": layer})
    spline.dxf.flags = 0
    spline.control_points = [(float(x), float(y), 0.0) for x, y in curve.control_points]  # type: ignore[assignment]
    spline.knots = [float(k) for k in curve.knots]  # type: ignore[assignment]


def _pitch_line(cam: Cam) -> FloatArray:
    """The roller centre's path over one cycle, sampled (a dashed reference line, not a cut curve)."""
    phi = np.linspace(0.0, 2.0 * math.pi, 360 * PITCH_SAMPLES_PER_DEG + 1)
    out: FloatArray = np.asarray(cam.pitch(phi).point, dtype=float)
    return out


def write_bar_dxfs(
    folder: str | os.PathLike[str], part: Part, *, fit: ProfileFit, plate: Plate, options: DxfSpec
) -> list[Path]:
    """``profile``, ``profile_poly`` and ``profile_arcs`` DXF files (with the part's suffix) of a bar.

    ``profile.dxf``: the edge as the fit's SPLINE and the bar's three sides
    as LINEs, head to tail on ``CAM_PROFILE`` (one closed outline), the
    pitch line dashed on ``PITCH_CURVE``, the annotation. ``profile_poly.dxf``:
    the whole outline as one closed LWPOLYLINE within ``[dxf] chord_tolerance``
    of the exact bar (the chord budget less the fit's certified error).
    ``profile_arcs.dxf``: the open edge as tangent-continuous ARCs within the
    fit tolerance of the exact edge, as a plate's profile
    (:func:`~camcad.export._outline.arc_outline` on φ ∈ [0, 2π], from the
    edge's exact start to its exact end), then the three sides as LINEs from
    the edge's end back to its start: one closed outline on ``CAM_PROFILE``.
    """
    bar = part.bar
    assert bar is not None  # the caller writes a bar's part here
    cam = part.cam
    outline = bar_outline(fit, bar)
    tol = options.chord_tolerance
    poly = flatten_bspline(outline, chord_budget(tol, fit.max_error, field=Knob.DXF_CHORD_TOLERANCE))
    lo, hi = poly.min(axis=0), poly.max(axis=0)

    doc, msp = _new_document()
    _open_spline(msp, fit.clamped, "CAM_PROFILE")
    ctrl = np.asarray(fit.clamped.control_points, dtype=float)
    start, end = ctrl[0], ctrl[-1]
    corners = [end, (end[0], bar.bottom), (start[0], bar.bottom), start]
    for a, b in itertools.pairwise(corners):
        msp.add_line(
            (float(a[0]), float(a[1])), (float(b[0]), float(b[1])), dxfattribs={"layer": "CAM_PROFILE"}
        )
    if options.pitch_curve:
        pitch = _pitch_line(cam)
        _add_dashes(msp, pitch_dashes(pitch), "PITCH_CURVE")
        hi = np.maximum(hi, pitch.max(axis=0))
    box = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    if options.annotate:
        lines = _annotation_lines(cam, plate, ())
        lines.insert(
            1, f"linear cam bar: stroke {bar.length:.3f} mm per cycle, bottom at y {bar.bottom:.3f} mm"
        )
        y = box[1] - 2.0 * TEXT_HEIGHT
        for line in lines:
            y -= 1.6 * TEXT_HEIGHT
            msp.add_text(line, height=TEXT_HEIGHT, dxfattribs={"layer": "ANNOTATION"}).set_placement(
                (box[0], y)
            )
        box = (box[0], y - TEXT_HEIGHT, box[2], box[3])
    _frame(doc, box)
    _add_sheet_frame(msp, box)
    paths = [Path(folder) / f"profile{part.suffix}.dxf", Path(folder) / f"profile_poly{part.suffix}.dxf"]
    atomic_write(paths[0], lambda tmp: save_reproducible(_audited(doc, "profile.dxf"), tmp))

    doc2, msp2 = _new_document()
    _add_closed_polyline(msp2, poly, "CAM_PROFILE")
    _frame(doc2, (float(lo[0]), float(lo[1]), float(poly[:, 0].max()), float(poly[:, 1].max())))
    atomic_write(paths[1], lambda tmp: save_reproducible(_audited(doc2, "profile_poly.dxf"), tmp))

    doc3, msp3 = _new_document()
    _add_arcs(msp3, _bar_edge_arcs(cam, fit.tolerance), "CAM_PROFILE", positive_angles=True)
    ends = cam.profile(np.array([2.0 * math.pi, 0.0])).point  # where the arcs end and start: on the edge
    corners = [ends[0], (ends[0][0], bar.bottom), (ends[1][0], bar.bottom), ends[1]]
    for a, b in itertools.pairwise(corners):
        msp3.add_line(
            (float(a[0]), float(a[1])), (float(b[0]), float(b[1])), dxfattribs={"layer": "CAM_PROFILE"}
        )
    pad = fit.tolerance + fit.max_error  # the arcs lie within the tolerance of the exact edge
    _frame(
        doc3,
        (
            float(lo[0]) - pad,
            float(lo[1]) - pad,
            float(poly[:, 0].max()) + pad,
            float(poly[:, 1].max()) + pad,
        ),
    )
    paths.append(Path(folder) / f"profile_arcs{part.suffix}.dxf")
    atomic_write(paths[2], lambda tmp: save_reproducible(_audited(doc3, "profile_arcs.dxf"), tmp))
    return paths


def _bar_edge_arcs(cam: Cam, tolerance: float) -> Pieces:
    """The bar's open edge ``cam.offset_curve(φ, 0)``, φ ∈ [0, 2π], as biarcs within ``tolerance`` [mm].

    Raises
    ------
    ExportError
        When the edge has a corner (a velocity jump, refused earlier as a hard limit).
    """

    def exact(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        o = cam.offset_curve(phi, 0.0)
        return o.point, o.d1, o.d2

    try:
        pieces, _ = arc_outline(exact, list(cam.program.pieces), tolerance, straight=cam.straight_spans)
    except ValueError as err:
        raise ExportError(f"profile_arcs.dxf: {err}") from err
    return pieces
