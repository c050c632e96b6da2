"""The cam plate as a closed solid mesh: STL by default, OBJ, PLY, OFF, 3MF and VTU on request.

:func:`build_solid` flattens the fitted profile spline within
``[mesh].chord_tolerance`` (a proven bound, see
:func:`~camcad.export._outline.flatten_bspline`), cuts the bore and keyway as
one hole, and extrudes the section to ``[cam].thickness`` with manifold3d.
Every build is checked, and any failure raises
:class:`~camcad.errors.ExportError`:

1. manifold3d reports no error, and the mesh is watertight with consistent
   winding: no face repeats a vertex, and every undirected edge is used by
   exactly two faces, in opposite directions
   (:meth:`~camcad.export._triangles.TriangleMesh.closed_defect`, numpy);
2. the genus equals the number of holes (manifold3d, and again from the
   Euler characteristic χ = 2 − 2g of the triangle mesh);
3. the mesh volume (divergence theorem, numpy) equals (area of the extruded
   polygon) × thickness to 1e-6 relative: this proves the triangulation and
   extrusion, not the polygon;
4. the polygon's area (outline minus hole) agrees with the exact area
   (fitted spline's area by Green's theorem, exact for a cubic, minus the
   exact bore-and-keyway area) within tol × (spline length + hole
   perimeter), the largest area a chord error of tol can change;
5. when the exact ``cam`` is given, the fitted spline's area agrees with the
   analytic profile's area (Green's theorem on ``cam.profile``,
   Gauss-Legendre between motion breakpoints) within
   fit.max_error × profile length.

Together 3-5 tie the solid's volume to the exact cam: the polygon area may
differ from the curve area by O(chord tolerance), never more.

The mesh is a small value (:class:`~camcad.export._triangles.TriangleMesh`:
manifold3d's vertices and faces), and STL, PLY, OBJ, OFF and 3MF are written
by hand with numpy and the standard library (``camcad/export/_triangles.py``):
importing trimesh, with the networkx, meshio and SciPy modules it loads, took longer
(0.3-0.6 s) than building, checking and writing the solid. Only VTU
loads a library (meshio), and only when asked for. trimesh stays the
independent reader in the tests.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import manifold3d
import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import ExportError
from camcad.export._bar import bar_outline
from camcad.export._outline import (
    analytic_area,
    bspline_area,
    bspline_length,
    chord_budget,
    flatten_bspline,
    oriented,
    polygon_area,
)
from camcad.export._triangles import (
    TriangleMesh,
    obj_bytes,
    off_bytes,
    ply_bytes,
    stl_bytes,
    threemf_bytes,
)
from camcad.export.atomic import atomic_write, atomic_write_bytes
from camcad.export.spec import MeshSpec
from camcad.fit.result import ProfileFit
from camcad.geometry.plate import BoreOutline, Plate, circle_segments
from camcad.knobs import Knob

if TYPE_CHECKING:
    from camcad.geometry.cam import Cam
    from camcad.geometry.families import Bar, Part

__all__ = [
    "MESH_FORMATS",
    "VOLUME_RTOL",
    "GrooveSolidResult",
    "SolidResult",
    "TriangleMesh",
    "bar_solid",
    "build_groove_solid",
    "build_solid",
    "threemf_bytes",
    "write_bar_mesh",
    "write_meshes",
    "write_part_meshes",
]

MESH_FORMATS = ("stl", "obj", "ply", "off", "3mf", "vtu")
VOLUME_RTOL = 1e-6  # mesh volume vs polygon area × thickness
AREA_ROUNDOFF = 1e-9  # relative slack for round-off in the area comparisons


@dataclass(frozen=True, slots=True, kw_only=True)
class SolidResult:
    """The cam solid and the numbers its checks compared.

    Attributes
    ----------
    mesh
        Closed triangle mesh [mm]; the plate spans z ∈ [0, thickness].
    volume
        Mesh volume [mm³].
    genus
        Genus of the solid (manifold3d), equal to ``holes``.
    holes
        Number of through holes (1 with a bore, keyway included; else 0).
    thickness
        Plate thickness [mm].
    chord_tolerance
        Bound on the distance between the polygon and the fitted spline [mm].
    contours
        The extruded polygons [mm]: the outline (ccw), then the hole (cw);
        each (n, 2), first vertex not repeated, read-only.
    polygon_area
        Area of the extruded polygon, outline minus hole [mm²].
    spline_area
        Exact area of the fitted spline minus the exact hole area [mm²].
    profile_area
        Exact area of the analytic profile minus the exact hole area [mm²];
        None when no cam was given.
    chord_area_bound
        Largest allowed |polygon_area − spline_area| [mm²].
    fit_area_bound
        Largest allowed |spline_area − profile_area| [mm²]; None without cam.
    """

    mesh: TriangleMesh
    volume: float
    genus: int
    holes: int
    thickness: float
    chord_tolerance: float
    contours: tuple[FloatArray, ...]
    polygon_area: float
    spline_area: float
    profile_area: float | None
    chord_area_bound: float
    fit_area_bound: float | None


def _cross_section(fit: ProfileFit, plate: Plate, tol: float) -> tuple[list[FloatArray], BoreOutline | None]:
    """The outline (chord error ``tol`` less the fit's error: ``tol`` from the exact profile) and bore."""
    chord = chord_budget(tol, fit.max_error, field=Knob.MESH_CHORD_TOLERANCE)
    outline = oriented(np.asarray(flatten_bspline(fit.clamped, chord)), ccw=True)
    contours = [outline]
    bore = plate.bore
    if bore is not None:
        contours.append(oriented(np.asarray(bore.polygon(tol)), ccw=False))
    for contour in contours:
        readonly(contour)
    return contours, bore


def _check_areas(
    fit: ProfileFit, cam: Cam | None, bore: BoreOutline | None, polygon: float, tol: float
) -> tuple[float, float, float | None, float | None]:
    """Compare polygon, spline and analytic areas; returns (spline, chord bound, profile, fit bound)."""
    hole_area = bore.area if bore is not None else 0.0
    hole_length = bore.perimeter if bore is not None else 0.0
    spline_outer = abs(bspline_area(fit.clamped))  # exact for a cubic
    spline_length = bspline_length(fit.clamped)
    spline = spline_outer - hole_area
    chord_bound = tol * (spline_length + hole_length) + AREA_ROUNDOFF * spline_outer
    if abs(polygon - spline) > chord_bound:
        raise ExportError(
            f"solid check failed: polygon area {polygon:.9g} mm² differs from the exact "
            f"spline area {spline:.9g} mm² by {abs(polygon - spline):.3g} mm², more than the "
            f"chord-tolerance bound {chord_bound:.3g} mm²"
        )
    if cam is None:
        return spline, chord_bound, None, None
    breaks = list(cam.program.pieces)
    signed, length = analytic_area(cam.profile, breaks)
    profile = abs(signed) - hole_area
    fit_bound = fit.max_error * length + AREA_ROUNDOFF * abs(signed)
    if abs(spline - profile) > fit_bound:
        raise ExportError(
            f"solid check failed: fitted spline area {spline:.9g} mm² differs from the exact "
            f"profile area {profile:.9g} mm² by {abs(spline - profile):.3g} mm², more than "
            f"max fit error × length = {fit_bound:.3g} mm²"
        )
    return spline, chord_bound, profile, fit_bound


def _checked_mesh(
    solid: manifold3d.Manifold, holes: int, what: str, why: str = ""
) -> tuple[TriangleMesh, int]:
    """The manifold's triangle mesh, with its genus, after checks 1-2 of the module docstring.

    Raises
    ------
    ExportError
        When manifold3d reports an error, the genus is not ``holes``, or the
        mesh is not closed and consistently wound; ``why`` follows the genus message.
    """
    status = solid.status()
    if status != manifold3d.Error.NoError or solid.is_empty():
        raise ExportError(f"solid check failed: manifold3d reports {status.name} for {what}")
    genus = int(solid.genus())
    if genus != holes:
        raise ExportError(f"solid check failed: genus {genus} but {what} has {holes} through hole(s){why}")
    mesh = TriangleMesh.from_manifold(solid)
    defect = mesh.closed_defect()
    if defect is not None or mesh.volume <= 0.0:
        reason = defect or "its faces wind inward (volume ≤ 0)"
        raise ExportError(
            f"solid check failed: the mesh of {what} is not a closed, consistently wound solid: {reason}"
        )
    return mesh, genus


def build_solid(fit: ProfileFit, plate: Plate, options: MeshSpec, *, cam: Cam | None = None) -> SolidResult:
    """Extrude the fitted profile, less bore and keyway, to a checked closed solid.

    Parameters
    ----------
    fit
        The profile fit; uses ``fit.clamped`` and ``fit.max_error`` [mm].
    plate
        Thickness, bore and keyway [mm].
    options
        ``[mesh]``: ``chord_tolerance`` [mm].
    cam
        The exact cam. When given, the spline's area is also checked against
        the analytic profile's (check 5 of the module docstring).

    Returns
    -------
    SolidResult
        The mesh and the numbers each check compared.

    Raises
    ------
    ExportError
        When any check in the module docstring fails.
    """
    tol = options.chord_tolerance
    thickness = plate.thickness
    contours, bore = _cross_section(fit, plate, tol)
    holes = len(contours) - 1
    polygon = sum(polygon_area(c) for c in contours)
    section = manifold3d.CrossSection(contours, manifold3d.FillRule.Positive)
    solid = manifold3d.Manifold.extrude(section, thickness)
    why = "; the profile or the bore outline self-intersects"
    mesh, genus = _checked_mesh(solid, holes, "the plate", why)
    euler_genus = (2 - int(mesh.euler_number)) // 2
    if euler_genus != holes:
        raise ExportError(f"solid check failed: Euler characteristic gives genus {euler_genus}, not {holes}")
    volume = float(mesh.volume)
    expected = polygon * thickness
    if not math.isclose(volume, expected, rel_tol=VOLUME_RTOL):
        raise ExportError(
            f"solid check failed: mesh volume {volume:.9g} mm³ differs from polygon area × "
            f"thickness = {expected:.9g} mm³ by more than {VOLUME_RTOL:g} relative"
        )
    spline, chord_bound, profile, fit_bound = _check_areas(fit, cam, bore, polygon, tol)
    return SolidResult(
        mesh=mesh,
        volume=volume,
        genus=genus,
        holes=holes,
        thickness=thickness,
        chord_tolerance=tol,
        contours=tuple(contours),
        polygon_area=polygon,
        spline_area=spline,
        profile_area=profile,
        chord_area_bound=chord_bound,
        fit_area_bound=fit_bound,
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class GrooveSolidResult:
    """A groove cam's blank with its groove pocket, and the numbers its checks compared.

    Attributes
    ----------
    mesh
        Closed triangle mesh [mm]; the blank spans z ∈ [0, thickness], the
        groove is open at the top face z = thickness.
    volume
        Mesh volume [mm³], equal to ``expected_volume`` to 1e-6 relative.
    expected_volume
        (blank polygon − bore polygon) × thickness − groove polygon × depth [mm³].
    genus
        Genus of the solid (the bore; the blind groove adds none).
    groove_polygon_area, groove_spline_area, groove_exact_area
        The groove's area between the flanks [mm²]: of the extruded
        polygons, of the fitted flank splines (exact for cubics) and of the
        exact flank curves (Green's theorem on ``cam.offset``); each pair
        agrees within its bound (chord tolerance × length, fit error × length).
    blank_area
        Exact blank area less the exact bore area [mm²].
    """

    mesh: TriangleMesh
    volume: float
    expected_volume: float
    genus: int
    thickness: float
    depth: float
    groove_polygon_area: float
    groove_spline_area: float
    groove_exact_area: float | None
    blank_area: float


def build_groove_solid(
    flanks: tuple[ProfileFit, ProfileFit],
    plate: Plate,
    options: MeshSpec,
    *,
    outer_radius: float,
    depth: float,
    cam: Cam | None = None,
    offsets: tuple[float, float] | None = None,
) -> GrooveSolidResult:
    """The groove cam: a disc of ``outer_radius`` [mm], bore and keyway, the groove pocket ``depth`` deep.

    Parameters
    ----------
    flanks
        The certified fits of the inner and outer flank (``fit_cam_profile(cam, offset=…)``).
    plate
        Thickness, bore and keyway [mm].
    options
        ``[mesh]``: ``chord_tolerance`` [mm].
    outer_radius, depth
        The blank's radius and the groove's depth below the top face [mm].
    cam, offsets
        The exact cam and the flanks' offsets from its profile
        (:func:`camcad.geometry.groove.flank_offsets`): when given, the flank
        splines' areas are checked against the exact flank curves' too.

    Raises
    ------
    ExportError
        When the boolean fails, the mesh is not a closed solid of the right
        genus, or any volume or area check fails.
    """
    tol = options.chord_tolerance
    thickness = plate.thickness
    n = circle_segments(outer_radius, tol)
    angle = np.arange(n) * (2.0 * math.pi / n)
    rim = np.column_stack((outer_radius * np.cos(angle), outer_radius * np.sin(angle)))
    blank_contours = [rim]
    if plate.bore is not None:
        blank_contours.append(oriented(np.asarray(plate.bore.polygon(tol)), ccw=False))
    chords = [chord_budget(tol, f.max_error, field=Knob.MESH_CHORD_TOLERANCE) for f in flanks]
    inner, outer = (
        oriented(np.asarray(flatten_bspline(f.clamped, c)), ccw=True)
        for f, c in zip(flanks, chords, strict=True)
    )
    groove_contours = [outer, inner[::-1].copy()]
    blank = manifold3d.Manifold.extrude(
        manifold3d.CrossSection(blank_contours, manifold3d.FillRule.Positive), thickness
    )
    reach = 1.0  # mm above the top face, so the cut shares no face with the blank
    pocket = manifold3d.Manifold.extrude(
        manifold3d.CrossSection(groove_contours, manifold3d.FillRule.Positive), depth + reach
    ).translate((0.0, 0.0, thickness - depth))
    solid = blank - pocket
    mesh, genus = _checked_mesh(solid, len(blank_contours) - 1, "the groove cam")
    blank_polygon = sum(polygon_area(c) for c in blank_contours)
    groove_polygon = sum(polygon_area(c) for c in groove_contours)
    expected = blank_polygon * thickness - groove_polygon * depth
    volume = float(mesh.volume)
    if not math.isclose(volume, expected, rel_tol=VOLUME_RTOL):
        raise ExportError(
            f"solid check failed: groove cam volume {volume:.9g} mm³ differs from the extruded areas' "
            f"{expected:.9g} mm³ by more than {VOLUME_RTOL:g} relative"
        )
    hole_area = plate.bore.area if plate.bore is not None else 0.0
    blank_area = math.pi * outer_radius**2 - hole_area
    spline_areas = [abs(bspline_area(f.clamped)) for f in flanks]
    lengths = [bspline_length(f.clamped) for f in flanks]
    groove_spline = spline_areas[1] - spline_areas[0]
    chord_bound = tol * sum(lengths) + AREA_ROUNDOFF * spline_areas[1]
    if abs(groove_polygon - groove_spline) > chord_bound:
        raise ExportError(
            f"solid check failed: the groove polygon's area {groove_polygon:.9g} mm² differs from the flank "
            f"splines' {groove_spline:.9g} mm² by more than the chord bound {chord_bound:.3g} mm²"
        )
    exact = None
    if cam is not None and offsets is not None:
        breaks = list(cam.program.pieces)
        exact_areas = [abs(analytic_area(lambda p, d=d: cam.offset_curve(p, d), breaks)[0]) for d in offsets]
        exact = exact_areas[1] - exact_areas[0]
        fit_bound = sum(f.max_error * length for f, length in zip(flanks, lengths, strict=True))
        if abs(groove_spline - exact) > fit_bound + AREA_ROUNDOFF * exact_areas[1]:
            raise ExportError(
                f"solid check failed: the flank splines' groove area {groove_spline:.9g} mm² differs from "
                f"the exact flanks' {exact:.9g} mm² by more than fit error × length {fit_bound:.3g} mm²"
            )
    return GrooveSolidResult(
        mesh=mesh,
        volume=volume,
        expected_volume=expected,
        genus=genus,
        thickness=thickness,
        depth=depth,
        groove_polygon_area=groove_polygon,
        groove_spline_area=groove_spline,
        groove_exact_area=exact,
        blank_area=blank_area,
    )


# ---------------------------------------------------------------------------
# writers


def _write_vtu(tmp: Path, mesh: TriangleMesh) -> None:
    import meshio  # here: only the VTU format needs it

    cells = [meshio.CellBlock("triangle", np.asarray(mesh.faces, dtype=np.int64))]
    meshio.write(tmp, meshio.Mesh(np.asarray(mesh.vertices, dtype=float), cells), file_format="vtu")


def _encoded(mesh: TriangleMesh, fmt: str, stem: str) -> bytes:
    if fmt == "stl":
        return stl_bytes(mesh)  # binary
    if fmt == "ply":
        return ply_bytes(mesh)  # binary, float64 vertices
    if fmt == "obj":
        return obj_bytes(mesh)
    if fmt == "off":
        return off_bytes(mesh)
    if fmt == "3mf":
        return threemf_bytes(mesh, name=stem)
    raise ValueError(fmt)


def write_meshes(
    outdir: str | os.PathLike[str],
    solid: SolidResult | GrooveSolidResult,
    formats: Sequence[str] = ("stl",),
    *,
    stem: str = "cam",
) -> list[Path]:
    """Write ``cam.stl`` (binary, always) and ``cam.<format>`` for each other format.

    Parameters
    ----------
    outdir
        Existing output folder.
    solid
        A checked solid from :func:`build_solid` or :func:`build_groove_solid`.
    formats
        Any of ``stl, obj, ply, off, 3mf, vtu`` (``[mesh].formats``); STL is
        written whether listed or not.
    stem
        File name stem, also the 3MF object's name.

    Returns
    -------
    list[Path]
        Written files, STL first, then in the order of ``formats``.

    Raises
    ------
    ValueError
        For an unknown format (before anything is written).
    """
    wanted = ["stl", *(f.lower() for f in formats if f.lower() != "stl")]
    unknown = [f for f in wanted if f not in MESH_FORMATS]
    if unknown:
        raise ValueError(f"unknown mesh format {unknown[0]!r}; allowed: {', '.join(MESH_FORMATS)}")
    folder = Path(outdir)
    written: list[Path] = []
    for fmt in dict.fromkeys(wanted):
        path = folder / f"{stem}.{fmt}"
        if fmt == "vtu":
            atomic_write(path, lambda tmp: _write_vtu(tmp, solid.mesh))
        else:
            atomic_write_bytes(path, _encoded(solid.mesh, fmt, stem))
        written.append(path)
    return written


def write_part_meshes(
    outdir: str | os.PathLike[str],
    part: Part,
    *,
    fit: ProfileFit,
    flank_fits: Sequence[ProfileFit] = (),
    plate: Plate,
    options: MeshSpec,
    formats: Sequence[str] = ("stl",),
) -> list[Path]:
    """``cam{suffix}.stl`` (and the other formats) of one part: its blank with the pocket, or its plate.

    A part with a pocket is the blank less the pocket between its flanks'
    fits ``flank_fits`` (:func:`build_groove_solid`); a plate is its outline
    ``fit`` extruded (:func:`build_solid`).
    """
    if part.bar is not None:  # a linear cam's bar (camcad.export.bar)
        return write_bar_mesh(outdir, part, fit=fit, plate=plate, options=options, formats=formats)
    solid: SolidResult | GrooveSolidResult
    if part.pocket is not None:
        inner, outer = flank_fits
        first, second = part.pocket.flanks
        solid = build_groove_solid(
            (inner, outer),
            plate,
            options,
            outer_radius=part.pocket.outer_radius,
            depth=part.pocket.depth,
            cam=part.cam,
            offsets=(first.offset, second.offset),
        )
    else:
        solid = build_solid(fit, plate, options, cam=part.cam)
    return write_meshes(outdir, solid, formats, stem=f"cam{part.suffix}")


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
        np.asarray(
            flatten_bspline(outline, chord_budget(tol, fit.max_error, field=Knob.MESH_CHORD_TOLERANCE))
        ),
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
