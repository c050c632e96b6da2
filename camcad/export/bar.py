"""A linear cam's bar: its closed outline, ``profile.dxf``, ``profile_poly.dxf``, ``cam.step``, ``cam.stl``.

The bar's outline is the certified clamped B-spline of the open edge (the
cam, from x0 at φ = 0 to x0 + L at φ = 2π) followed by three straight sides:
down the end at x0 + L to the bottom, back along the bottom, up the end at
x0 to the edge's start (:class:`~camcad.geometry.families.Bar`). The sides
are written as cubic Bézier pieces with collinear, evenly spaced poles
(exact straight lines) joined to the edge by triple knots (C⁰ corners), so
the whole outline is one closed clamped cubic B-spline: the STEP writer
(:mod:`camcad.export._step_brep`) extrudes it as it does a plate's profile,
and the mesh is its flattened polygon extruded by manifold3d.
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import manifold3d
import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import ExportError
from camcad.export._ezdxf import save_reproducible
from camcad.export._outline import bspline_area, bspline_length, chord_budget, flatten_bspline, oriented
from camcad.export._step_brep import Body, Prism
from camcad.export.atomic import atomic_write
from camcad.export.dxf import (
    TEXT_HEIGHT,
    _add_closed_polyline,
    _add_dashes,
    _add_sheet_frame,
    _annotation_lines,
    _audited,
    _frame,
    _new_document,
    pitch_dashes,
)
from camcad.export.mesh import AREA_ROUNDOFF, SolidResult, _checked_mesh, write_meshes
from camcad.export.step import write_step
from camcad.fit.curve import BSplineCurve

if TYPE_CHECKING:
    from ezdxf.layouts import Modelspace

    from camcad.export.spec import DxfSpec, MeshSpec
    from camcad.fit.result import ProfileFit
    from camcad.geometry.cam import Cam
    from camcad.geometry.families import Bar, Part
    from camcad.geometry.plate import Plate

__all__ = ["bar_body", "bar_outline", "bar_solid", "write_bar_dxfs", "write_bar_mesh", "write_bar_step"]

PITCH_SAMPLES_PER_DEG = 4  # pitch-line vertices per degree of motion (a reference line, dashed)


def _line_piece(a: FloatArray, b: FloatArray, degree: int) -> FloatArray:
    """Poles (p + 1, 2) of the straight segment a–b as a Bézier curve of degree p (evenly spaced: exact)."""
    t = np.linspace(0.0, 1.0, degree + 1)[:, None]
    out: FloatArray = (1.0 - t) * a + t * b
    return out


def bar_outline(fit: ProfileFit, bar: Bar) -> BSplineCurve:
    """The bar's closed outline as one clamped B-spline: the edge, then its three straight sides.

    The edge is ``fit.clamped`` on its domain [0, 1]; the sides take the
    parameters [1, 2], [2, 3], [3, 4]. The first and last poles are the
    edge's start, so the curve closes there (a corner).
    """
    edge = fit.clamped
    if edge.periodic or not math.isclose(edge.domain[0], 0.0) or not math.isclose(edge.domain[1], 1.0):
        raise ExportError("a bar's outline needs the clamped open edge of a linear cam on [0, 1]")
    p = edge.degree
    ctrl = np.asarray(edge.control_points, dtype=float)
    start, end = ctrl[0], ctrl[-1]
    corners = [end, np.array([end[0], bar.bottom]), np.array([start[0], bar.bottom]), start]
    poles = [ctrl]
    knots = [np.asarray(edge.knots, dtype=float)[:-1]]  # the edge's end knot keeps p copies: C⁰ there
    for k in range(3):
        poles.append(_line_piece(corners[k], corners[k + 1], p)[1:])
        knots.append(np.full(p, float(k + 2)))
    knots.append(np.array([4.0]))
    out = BSplineCurve(degree=p, knots=np.concatenate(knots), control_points=np.vstack(poles), periodic=False)
    readonly(out.knots, out.control_points)
    return out


def _spline(msp: Modelspace, curve: BSplineCurve, layer: str) -> None:
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
    """``profile{suffix}.dxf`` and ``profile_poly{suffix}.dxf`` of a linear cam's bar.

    ``profile.dxf``: the edge as the fit's SPLINE and the bar's three sides
    as LINEs, head to tail on ``CAM_PROFILE`` (one closed outline), the
    pitch line dashed on ``PITCH_CURVE``, the annotation. ``profile_poly.dxf``:
    the whole outline as one closed LWPOLYLINE within ``[dxf] chord_tolerance``
    of the exact bar (the chord budget less the fit's certified error).
    """
    bar = part.bar
    assert bar is not None  # the caller writes a bar's part here
    cam = part.cam
    outline = bar_outline(fit, bar)
    tol = options.chord_tolerance
    poly = flatten_bspline(outline, chord_budget(tol, fit.max_error, field="dxf.chord_tolerance"))
    lo, hi = poly.min(axis=0), poly.max(axis=0)

    doc, msp = _new_document()
    _spline(msp, fit.clamped, "CAM_PROFILE")
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
    return paths


def bar_body(fit: ProfileFit, bar: Bar, plate: Plate) -> Body:
    """The bar as a STEP body: its closed outline extruded by the plate thickness, named after the design."""
    return Body(name=plate.name, prism=Prism(outer=bar_outline(fit, bar), height=plate.thickness))


def write_bar_step(folder: str | os.PathLike[str], part: Part, *, fit: ProfileFit, plate: Plate) -> Path:
    """``cam{suffix}.step`` of a linear cam's bar."""
    assert part.bar is not None
    return write_step(Path(folder) / f"cam{part.suffix}.step", [bar_body(fit, part.bar, plate)])


def bar_solid(fit: ProfileFit, bar: Bar, plate: Plate, options: MeshSpec) -> SolidResult:
    """The bar's outline flattened within ``[mesh] chord_tolerance`` and extruded: a checked closed solid.

    Checks as for a plate (:func:`camcad.export.mesh.build_solid`): manifold3d
    reports no error, genus 0, a closed consistently wound mesh whose volume
    is the polygon's area times the thickness, and the polygon's area within
    the chord bound of the outline spline's exact area.
    """
    tol = options.chord_tolerance
    outline = bar_outline(fit, bar)
    polygon = oriented(
        np.asarray(flatten_bspline(outline, chord_budget(tol, fit.max_error, field="mesh.chord_tolerance"))),
        ccw=True,
    )
    readonly(polygon)
    section = manifold3d.CrossSection([polygon], manifold3d.FillRule.Positive)
    solid = manifold3d.Manifold.extrude(section, plate.thickness)
    mesh, genus = _checked_mesh(solid, 0, "the bar", "; the edge crosses the bar's sides")
    area = float(
        abs(np.sum(polygon[:, 0] * np.roll(polygon[:, 1], -1) - np.roll(polygon[:, 0], -1) * polygon[:, 1]))
        / 2.0
    )
    spline = abs(bspline_area(outline))
    bound = tol * bspline_length(outline) + AREA_ROUNDOFF * spline
    if abs(area - spline) > bound:
        raise ExportError(
            f"solid check failed: the bar's polygon area {area:.9g} mm² differs from its spline's "
            f"{spline:.9g} mm² by more than the chord bound {bound:.3g} mm²"
        )
    return SolidResult(
        mesh=mesh,
        volume=float(mesh.volume),
        genus=genus,
        holes=0,
        thickness=plate.thickness,
        chord_tolerance=tol,
        contours=(polygon,),
        polygon_area=area,
        spline_area=spline,
        profile_area=None,
        chord_area_bound=bound,
        fit_area_bound=None,
    )


def write_bar_mesh(
    folder: str | os.PathLike[str],
    part: Part,
    *,
    fit: ProfileFit,
    plate: Plate,
    options: MeshSpec,
    formats: Sequence[str] = ("stl",),
) -> list[Path]:
    """``cam{suffix}.stl`` (and the other formats) of a linear cam's bar."""
    assert part.bar is not None
    return write_meshes(folder, bar_solid(fit, part.bar, plate, options), formats, stem=f"cam{part.suffix}")
