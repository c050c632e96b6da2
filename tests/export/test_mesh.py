"""Solid export: the checks on every build, the contour maths, every mesh format, atomic writes."""

from __future__ import annotations

import math
import struct
import zipfile
from dataclasses import dataclass, replace
from pathlib import Path
from xml.etree import ElementTree

import meshio
import numpy as np
import pytest
import trimesh
from numpy.testing import assert_allclose
from scipy.interpolate import make_interp_spline

from camcad.design import Design
from camcad.errors import ExportError
from camcad.export._outline import (
    analytic_area,
    bspline_area,
    bspline_length,
    flatten_bspline,
    polygon_area,
)
from camcad.export.atomic import atomic_write, atomic_write_text
from camcad.export.mesh import MESH_FORMATS, SolidResult, TriangleMesh, build_solid, write_meshes
from camcad.fit import ProfileFit, fit_cam_profile
from camcad.fit.bspline import clamped_from_periodic
from camcad.fit.curve import BSplineCurve
from camcad.geometry.cam import Cam
from camcad.geometry.plate import BoreOutline, circle_segments
from tests.conftest import distance_to_polygon, make_design

KEYED = {"cam": {"bore": 12.0, "keyway_width": 4.0, "keyway_depth": 2.0}}


def cam_and_fit(design: Design) -> tuple[Cam, ProfileFit]:
    """The exact cam and its certified fit, as the pipeline makes them."""
    cam = Cam.from_design(design)
    return cam, fit_cam_profile(
        cam, tolerance=design.fit.tolerance, max_control_points=design.fit.max_control_points
    )


def as_trimesh(mesh: TriangleMesh) -> trimesh.Trimesh:
    """Our mesh as trimesh's, unprocessed (same vertices and faces), for trimesh's independent checks."""
    return trimesh.Trimesh(vertices=mesh.vertices, faces=mesh.faces, process=False)


@pytest.fixture(scope="module")
def keyed() -> tuple[Design, Cam, ProfileFit, SolidResult]:
    design = make_design(extra=KEYED)
    cam, fit = cam_and_fit(design)
    return design, cam, fit, build_solid(fit, design.plate(), design.mesh, cam=cam)


# -- contour maths -------------------------------------------------------------


def circle_spline(radius: float = 30.0, n: int = 24) -> BSplineCurve:
    """A closed clamped cubic close to a circle, through a periodic interpolating spline."""
    t = np.linspace(0.0, 2.0 * math.pi, n + 1)
    pts = radius * np.column_stack((np.cos(t), np.sin(t)))
    pts[-1] = pts[0]
    spl = make_interp_spline(t, pts, k=3, bc_type="periodic")
    return clamped_from_periodic(BSplineCurve(degree=3, knots=spl.t, control_points=spl.c, periodic=True))


@pytest.mark.parametrize("tol", [0.5, 0.05, 0.005], ids=["0.5", "0.05", "0.005"])
def test_flatten_bspline_meets_its_chord_bound(tol):
    curve = circle_spline()
    poly = np.asarray(flatten_bspline(curve, tol))
    a, b = curve.domain
    dense = curve.evaluate(np.linspace(a, b, 200001)[:-1])
    error = distance_to_polygon(dense, poly).max()
    assert error <= tol
    assert error >= tol / 4  # the bound is not wildly pessimistic on a circle
    assert_allclose(distance_to_polygon(poly, dense), 0.0, rtol=0, atol=1e-6)  # vertices on the curve


def test_bspline_area_and_length_of_a_near_circle():
    """Exact spline area vs a 10⁶-gon of the spline; both near πR² and 2πR."""
    curve = circle_spline()
    a, b = curve.domain
    fine = curve.evaluate(np.linspace(a, b, 1_000_001)[:-1])
    assert bspline_area(curve) == pytest.approx(polygon_area(fine), rel=1e-10)
    assert bspline_area(curve) == pytest.approx(math.pi * 900.0, rel=1e-4)
    assert bspline_length(curve) == pytest.approx(2 * math.pi * 30.0, rel=1e-4)


@dataclass(frozen=True)
class _Ellipse:
    """x = a cos φ, y = b sin φ with derivatives: area πab in closed form."""

    point: np.ndarray
    d1: np.ndarray
    d2: np.ndarray


def ellipse(phi: np.ndarray) -> _Ellipse:
    c, s = np.cos(phi), np.sin(phi)
    return _Ellipse(
        point=np.column_stack((30 * c, 20 * s)),
        d1=np.column_stack((-30 * s, 20 * c)),
        d2=np.column_stack((-30 * c, -20 * s)),
    )


def test_analytic_area_of_an_ellipse_with_breakpoints():
    area, length = analytic_area(ellipse, [0.3, 2.0, 5.9])
    assert area == pytest.approx(math.pi * 600.0, rel=1e-13)
    # Ramanujan's second approximation, ~1e-10 relative for b/a = 2/3
    h = ((30 - 20) / (30 + 20)) ** 2
    assert length == pytest.approx(math.pi * 50 * (1 + 3 * h / (10 + math.sqrt(4 - 3 * h))), rel=1e-9)


def test_analytic_area_of_a_cam_matches_a_dense_polygon(keyed):
    _, cam, _, _ = keyed
    area, _ = analytic_area(cam.profile, [b.phi for b in cam.program.breakpoints])
    dense = cam.profile(np.linspace(0, 2 * math.pi, 400001)[:-1]).point
    assert abs(area) == pytest.approx(abs(polygon_area(dense)), rel=1e-9)


@pytest.mark.parametrize(
    "bore",
    [BoreOutline(radius=6.0), BoreOutline(radius=6.0, keyway_width=4.0, keyway_depth=2.0)],
    ids=["plain", "keyed"],
)
def test_bore_outline_area_perimeter_and_polygon(bore):
    poly = np.asarray(bore.polygon(1e-7))
    assert polygon_area(poly) > 0  # counter-clockwise
    assert polygon_area(poly) == pytest.approx(bore.area, abs=1e-7 * bore.perimeter)
    closed = np.vstack((poly, poly[:1]))
    assert np.sum(np.linalg.norm(np.diff(closed, axis=0), axis=1)) == pytest.approx(bore.perimeter, rel=1e-8)
    assert np.hypot(poly[:, 0], poly[:, 1]).max() == pytest.approx(bore.reach, rel=1e-12)
    if bore.has_keyway:
        assert bore.area == pytest.approx(
            math.pi * 36 + 4 * (8 - math.sqrt(32)) - (36 * math.asin(1 / 3) - 2 * math.sqrt(32))
        )


def test_circle_segments_sagitta():
    for r, tol in [(6.0, 0.005), (100.0, 0.001), (1.0, 0.3)]:
        n = circle_segments(r, tol)
        assert r * (1 - math.cos(math.pi / n)) <= tol < r * (1 - math.cos(math.pi / (n - 1)))


# -- build_solid ----------------------------------------------------------------------


def test_keyed_solid_passes_every_check(keyed):
    design, _, _, solid = keyed
    assert solid.holes == 1 and solid.genus == 1
    reader = as_trimesh(solid.mesh)  # trimesh's own edge checks, not ours
    assert reader.is_watertight and reader.is_winding_consistent
    assert solid.volume == pytest.approx(solid.polygon_area * design.cam.thickness, rel=1e-6)
    assert abs(solid.polygon_area - solid.spline_area) <= solid.chord_area_bound
    assert solid.profile_area is not None and solid.fit_area_bound is not None
    assert abs(solid.spline_area - solid.profile_area) <= solid.fit_area_bound
    bounds = solid.mesh.bounds
    assert_allclose(bounds[:, 2], [0.0, design.cam.thickness], rtol=0, atol=1e-12)
    # the outline is ccw, the hole cw; the hole is the keyed bore polygon
    assert polygon_area(solid.contours[0]) > 0 > polygon_area(solid.contours[1])
    bore = BoreOutline.from_cam_spec(12.0, 4.0, 2.0)
    assert -polygon_area(solid.contours[1]) == pytest.approx(
        bore.area, abs=solid.chord_tolerance * bore.perimeter
    )


@pytest.mark.parametrize(
    "kwargs",
    [
        {"follower": "translating-flat", "law": "harmonic"},
        {"rotation": "cw", "offset": 6.0, "law": "poly-345", "extra": {"cam": {"bore": 8.0}}},
    ],
    ids=["flat-no-bore", "cw-offset-bore"],
)
def test_solid_genus_counts_holes(kwargs):
    design = make_design(**kwargs)
    cam, fit = cam_and_fit(design)
    solid = build_solid(fit, design.plate(), design.mesh, cam=cam)
    holes = 1 if design.cam.bore > 0 else 0
    assert solid.genus == holes == solid.holes
    assert as_trimesh(solid.mesh).euler_number == 2 - 2 * holes  # trimesh counts V - E + F
    assert solid.volume == pytest.approx(solid.polygon_area * design.cam.thickness, rel=1e-6)


def test_without_cam_the_analytic_check_is_skipped(keyed):
    design, _, fit, solid = keyed
    plain = build_solid(fit, design.plate(), design.mesh)
    assert plain.profile_area is None and plain.fit_area_bound is None
    assert plain.volume == solid.volume


def test_self_intersecting_profile_is_refused(keyed):
    """A figure-eight outline: the genus check catches what a slicer would choke on."""
    design, _, fit, _ = keyed
    t = np.linspace(0.0, 2.0 * math.pi, 41)
    pts = np.column_stack((40 * np.sin(t), 20 * np.sin(2 * t)))
    pts[-1] = pts[0]
    spl = make_interp_spline(t, pts, k=3, bc_type="periodic")
    eight = clamped_from_periodic(BSplineCurve(degree=3, knots=spl.t, control_points=spl.c, periodic=True))
    no_bore = replace(design, cam=replace(design.cam, bore=0.0, keyway_width=0.0, keyway_depth=0.0))
    with pytest.raises(ExportError, match="solid check failed"):
        build_solid(replace(fit, clamped=eight), no_bore.plate(), no_bore.mesh)


def test_a_fit_error_larger_than_claimed_is_caught(keyed):
    """Shrink the spline by 0.05 mm but claim 1e-6 mm: the analytic-area check fails."""
    design, cam, fit, _ = keyed
    c = fit.clamped
    scale = 1.0 - 0.05 / 60.0
    shrunk = BSplineCurve(degree=3, knots=c.knots, control_points=c.control_points * scale)
    with pytest.raises(ExportError, match="exact profile area"):
        build_solid(replace(fit, clamped=shrunk, max_error=1e-6), design.plate(), design.mesh, cam=cam)


# -- writers ---------------------------------------------------------------------------


def load_3mf(path: Path) -> trimesh.Trimesh:
    """Read a 3MF with the standard library (trimesh's reader needs lxml)."""
    with zipfile.ZipFile(path) as archive:
        names = set(archive.namelist())
        assert {"[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model"} <= names
        root = ElementTree.fromstring(archive.read("3D/3dmodel.model"))
    ns = {"m": "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"}
    assert root.get("unit") == "millimeter"
    verts = [[float(v.get(k)) for k in "xyz"] for v in root.iterfind(".//m:vertex", ns)]
    faces = [[int(f.get(k)) for k in ("v1", "v2", "v3")] for f in root.iterfind(".//m:triangle", ns)]
    return trimesh.Trimesh(verts, faces)


def reload(path: Path) -> trimesh.Trimesh:
    if path.suffix == ".vtu":
        mesh = meshio.read(path)
        return trimesh.Trimesh(mesh.points, mesh.cells_dict["triangle"])
    if path.suffix == ".3mf":
        return load_3mf(path)
    return trimesh.load(path, force="mesh")


def test_every_format_reloads_watertight_with_the_volume(keyed, tmp_path):
    _, _, _, solid = keyed
    paths = write_meshes(tmp_path, solid, MESH_FORMATS)
    assert [p.name for p in paths] == [f"cam.{f}" for f in MESH_FORMATS]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in paths)  # no temp files
    for path in paths:
        mesh = reload(path)
        assert mesh.is_watertight, path.name
        rtol = 1e-6 if path.suffix == ".stl" else 1e-9  # STL is float32 by definition, the rest float64
        assert mesh.volume == pytest.approx(solid.volume, rel=rtol), path.name
        assert len(mesh.faces) == len(solid.mesh.faces)


def test_3mf_through_trimesh_when_lxml_is_there(keyed, tmp_path):
    pytest.importorskip("lxml", reason="trimesh reads 3MF only with lxml installed")
    _, _, _, solid = keyed
    (path,) = [p for p in write_meshes(tmp_path, solid, ["3mf"]) if p.suffix == ".3mf"]
    mesh = trimesh.load(path, force="mesh")
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(solid.volume, rel=1e-9)


def test_stl_is_binary_and_always_written(keyed, tmp_path):
    _, _, _, solid = keyed
    paths = write_meshes(tmp_path, solid, ["obj"])
    assert [p.name for p in paths] == ["cam.stl", "cam.obj"]
    data = paths[0].read_bytes()
    assert data.startswith(b"camcad") and b"units mm" in data[:80]
    (count,) = struct.unpack("<I", data[80:84])
    assert count == len(solid.mesh.faces)
    assert len(data) == 84 + 50 * count


def test_3mf_bytes_are_deterministic(keyed, tmp_path):
    _, _, _, solid = keyed
    for name in ("a", "b"):
        (tmp_path / name).mkdir()
        write_meshes(tmp_path / name, solid, ["3mf"])
    assert (tmp_path / "a" / "cam.3mf").read_bytes() == (tmp_path / "b" / "cam.3mf").read_bytes()


def test_unknown_format_writes_nothing(keyed, tmp_path):
    _, _, _, solid = keyed
    with pytest.raises(ValueError, match="allowed: stl"):
        write_meshes(tmp_path, solid, ["stl", "step"])
    assert list(tmp_path.iterdir()) == []


# -- atomic writes ---------------------------------------------------------------------


def test_failed_writer_leaves_no_file_and_keeps_the_old_one(tmp_path):
    target = tmp_path / "cam.stl"

    def broken(tmp: Path) -> None:
        tmp.write_bytes(b"partial")
        raise OSError("disk full")

    with pytest.raises(OSError, match="disk full"):
        atomic_write(target, broken)
    assert list(tmp_path.iterdir()) == []
    atomic_write_text(target, "old")
    with pytest.raises(OSError):
        atomic_write(target, broken)
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["cam.stl"]


@pytest.mark.parametrize(
    "writer", [lambda tmp: None, lambda tmp: tmp.write_bytes(b"")], ids=["none", "empty"]
)
def test_empty_output_is_an_error(tmp_path, writer):
    with pytest.raises(ExportError, match="nothing was written"):
        atomic_write(tmp_path / "cam.obj", writer)
    assert list(tmp_path.iterdir()) == []


def test_atomic_write_keeps_the_suffix_for_format_sniffing(tmp_path):
    seen = []
    atomic_write(tmp_path / "cam.vtu", lambda tmp: (seen.append(tmp.suffix), tmp.write_text("x")))
    assert seen == [".vtu"]
