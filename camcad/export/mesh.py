"""The cam plate as a closed solid mesh: STL by default, OBJ, PLY, OFF, 3MF and VTU on request.

:func:`build_solid` flattens the fitted profile spline within
``[mesh].chord_tolerance`` (a proven bound, see
:func:`~camcad.export._outline.flatten_bspline`), cuts the bore and keyway as
one hole, and extrudes the section to ``[cam].thickness`` with manifold3d.
Every build is checked, and any failure raises
:class:`~camcad.errors.ExportError`:

1. manifold3d reports no error, and the mesh is watertight with consistent
   winding (trimesh);
2. the genus equals the number of holes (manifold3d, and again from the
   Euler characteristic χ = 2 − 2g of the triangle mesh);
3. the mesh volume equals (area of the extruded polygon) × thickness to
   1e-6 relative: this proves the triangulation and extrusion, not the
   polygon;
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
"""

from __future__ import annotations

import io
import math
import os
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import manifold3d
import meshio
import numpy as np
import trimesh

from camcad._typing import FloatArray, readonly
from camcad.errors import ExportError
from camcad.export._outline import (
    analytic_area,
    bspline_area,
    bspline_length,
    flatten_bspline,
    oriented,
    polygon_area,
)
from camcad.export.atomic import atomic_write, atomic_write_bytes
from camcad.export.spec import MeshSpec
from camcad.fit.result import ProfileFit
from camcad.geometry.plate import BoreOutline, Plate

if TYPE_CHECKING:
    from camcad.geometry.cam import Cam

__all__ = [
    "MESH_FORMATS",
    "VOLUME_RTOL",
    "SolidResult",
    "build_solid",
    "threemf_bytes",
    "write_meshes",
]

MESH_FORMATS = ("stl", "obj", "ply", "off", "3mf", "vtu")
VOLUME_RTOL = 1e-6  # mesh volume vs polygon area × thickness
# 80-byte binary STL header: says the unit, and must not begin with "solid" (ASCII STL)
STL_HEADER = b"camcad cam plate, binary STL, units mm".ljust(80, b"\0")
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

    mesh: trimesh.Trimesh
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
    outline = oriented(np.asarray(flatten_bspline(fit.clamped, tol)), ccw=True)
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
    breaks = [b.phi for b in cam.program.breakpoints]
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
    status = solid.status()
    if status != manifold3d.Error.NoError or solid.is_empty():
        raise ExportError(f"solid check failed: manifold3d reports {status.name} for the extrusion")
    genus = int(solid.genus())
    if genus != holes:
        raise ExportError(
            f"solid check failed: genus {genus} but the plate has {holes} hole(s); "
            "the profile or the bore outline self-intersects"
        )
    raw = solid.to_mesh64()
    mesh = trimesh.Trimesh(
        vertices=np.asarray(raw.vert_properties, dtype=float)[:, :3],
        faces=np.asarray(raw.tri_verts, dtype=np.int64),
        process=False,
    )
    if not (mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0.0):
        raise ExportError("solid check failed: the mesh is not a closed, consistently wound solid")
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


# ---------------------------------------------------------------------------
# writers

_CONTENT_TYPES = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
    '<Default Extension="rels" '
    'ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
    '<Default Extension="model" '
    'ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
    "</Types>\n"
)
_RELS = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
    '<Relationship Target="/3D/3dmodel.model" Id="rel0" '
    'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>'
    "</Relationships>\n"
)


def threemf_bytes(mesh: trimesh.Trimesh, *, name: str = "cam") -> bytes:
    """Encode a 3MF package (core spec 1.x, unit millimetre) holding one mesh object.

    Written with the standard library (zipfile), so it needs no XML package;
    entries carry a fixed timestamp, so equal meshes give equal bytes.
    """
    vertices = "".join(
        f'<vertex x="{x!r}" y="{y!r}" z="{z!r}"/>' for x, y, z in np.asarray(mesh.vertices).tolist()
    )
    triangles = "".join(
        f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in np.asarray(mesh.faces).tolist()
    )
    safe = "".join(ch for ch in name if ch.isalnum() or ch in "-_ .") or "cam"
    model = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<model unit="millimeter" xml:lang="en-US" '
        'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">'
        f'<resources><object id="1" type="model" name="{safe}"><mesh>'
        f"<vertices>{vertices}</vertices><triangles>{triangles}</triangles>"
        '</mesh></object></resources><build><item objectid="1"/></build></model>\n'
    )
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for entry, text in (
            ("[Content_Types].xml", _CONTENT_TYPES),
            ("_rels/.rels", _RELS),
            ("3D/3dmodel.model", model),
        ):
            info = zipfile.ZipInfo(entry, date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, text.encode("utf-8"))
    return buffer.getvalue()


def _write_vtu(tmp: Path, mesh: trimesh.Trimesh) -> None:
    cells = [meshio.CellBlock("triangle", np.asarray(mesh.faces, dtype=np.int64))]
    meshio.write(tmp, meshio.Mesh(np.asarray(mesh.vertices, dtype=float), cells), file_format="vtu")


def _encoded(mesh: trimesh.Trimesh, fmt: str) -> bytes:
    if fmt == "stl":
        data = bytes(mesh.export(file_type="stl"))  # binary STL
        return STL_HEADER + data[len(STL_HEADER) :]
    if fmt == "ply":
        return bytes(mesh.export(file_type="ply", encoding="binary"))
    if fmt == "obj":
        text = mesh.export(file_type="obj", include_normals=False, include_texture=False)
        return str(text).encode("utf-8")
    if fmt == "off":
        return str(mesh.export(file_type="off")).encode("utf-8")
    if fmt == "3mf":
        return threemf_bytes(mesh)
    raise ValueError(fmt)


def write_meshes(
    outdir: str | os.PathLike[str],
    solid: SolidResult,
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
        A checked solid from :func:`build_solid`.
    formats
        Any of ``stl, obj, ply, off, 3mf, vtu`` (``[mesh].formats``); STL is
        written whether listed or not.
    stem
        File name stem.

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
            atomic_write_bytes(path, _encoded(solid.mesh, fmt))
        written.append(path)
    return written
