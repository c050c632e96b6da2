"""The hand-written mesh value and writers (camcad/export/_triangles.py), against independent programs.

What each test checks against:

- trimesh (its own readers, edge checks and mass properties) reads our STL
  and 3MF back: the same triangles (float32-rounded in STL, exact in 3MF),
  watertight, consistently wound, and its volume equals manifold3d's own
  ``Manifold.volume()`` of the solid;
- on random convex solids (manifold3d hulls of random points, hypothesis):
  our volume, area and Euler number equal trimesh's and manifold3d's, our
  closed check passes, and trimesh reads every format back to the same mesh;
- removing any one face, or flipping any one face (hypothesis picks which),
  is caught by our closed check, and trimesh agrees the result is no longer
  a closed, consistently wound surface;
- the same design built in a fresh interpreter writes byte-identical files
  in every format;
- binary STL's layout is read with :mod:`struct` (not numpy): header, count,
  50 bytes per facet, attribute 0, normals equal to trimesh's face normals.
"""

from __future__ import annotations

import io
import math
import struct
import subprocess
import sys
import zipfile

import manifold3d
import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from numpy.testing import assert_allclose, assert_array_equal

from camcad.export._triangles import (
    STL_HEADER,
    TriangleMesh,
    obj_bytes,
    off_bytes,
    ply_bytes,
    stl_bytes,
    threemf_bytes,
)
from camcad.export.mesh import MESH_FORMATS, SolidResult, build_solid, write_meshes
from camcad.fit import fit_cam_profile
from camcad.geometry.cam import Cam
from tests.conftest import ROOT, make_design

KEYED = {"cam": {"bore": 12.0, "keyway_width": 4.0, "keyway_depth": 2.0}}

# A fresh interpreter builds the keyed plate and writes every format into argv[1].
_BUILD = """
import sys
from pathlib import Path
from camcad.export.mesh import MESH_FORMATS, build_solid, write_meshes
from camcad.fit import fit_cam_profile
from camcad.geometry.cam import Cam
from tests.conftest import make_design
design = make_design(extra={extra!r})
cam = Cam.from_design(design)
fit = fit_cam_profile(cam, tolerance=design.fit.tolerance, max_control_points=design.fit.max_control_points)
write_meshes(Path(sys.argv[1]), build_solid(fit, design.plate(), design.mesh, cam=cam), MESH_FORMATS)
"""


@pytest.fixture(scope="module")
def keyed() -> SolidResult:
    design = make_design(extra=KEYED)
    cam = Cam.from_design(design)
    fit = fit_cam_profile(
        cam, tolerance=design.fit.tolerance, max_control_points=design.fit.max_control_points
    )
    return build_solid(fit, design.plate(), design.mesh, cam=cam)


def manifold_of(solid: SolidResult) -> manifold3d.Manifold:
    """The plate rebuilt in manifold3d from the extruded contours, for manifold3d's own volume."""
    section = manifold3d.CrossSection(list(solid.contours), manifold3d.FillRule.Positive)
    return manifold3d.Manifold.extrude(section, solid.thickness)


def as_trimesh(mesh: TriangleMesh) -> trimesh.Trimesh:
    return trimesh.Trimesh(vertices=mesh.vertices, faces=mesh.faces, process=False)


def read(data: bytes, file_type: str) -> trimesh.Trimesh:
    """trimesh's reader on our bytes (STL merged into shared vertices, as trimesh loads it by default)."""
    loaded = trimesh.load(io.BytesIO(data), file_type=file_type, force="mesh", process=file_type == "stl")
    assert isinstance(loaded, trimesh.Trimesh)
    return loaded


def closed_for_trimesh(mesh: TriangleMesh) -> bool:
    reader = as_trimesh(mesh)
    return bool(reader.is_watertight and reader.is_winding_consistent)


# -- the keyed cam plate --------------------------------------------------------------


def test_trimesh_reads_our_stl_back(keyed):
    mesh = keyed.mesh
    back = read(stl_bytes(mesh), "stl")
    assert_array_equal(back.triangles, mesh.triangles.astype(np.float32))  # facet order kept, float32
    assert back.is_watertight and back.is_winding_consistent
    assert back.volume == pytest.approx(manifold_of(keyed).volume(), rel=1e-6)  # float32 corners


def test_trimesh_reads_our_3mf_back_exactly(keyed):
    pytest.importorskip("lxml", reason="trimesh reads 3MF only with lxml installed")
    mesh = keyed.mesh
    back = read(threemf_bytes(mesh), "3mf")
    assert_array_equal(back.vertices, mesh.vertices)  # shortest round-trip repr: exact float64
    assert_array_equal(back.faces, mesh.faces)
    assert back.is_watertight and back.is_winding_consistent
    reference = manifold_of(keyed)
    assert back.volume == pytest.approx(reference.volume(), rel=1e-12)
    assert mesh.volume == pytest.approx(reference.volume(), rel=1e-12)
    assert mesh.area == pytest.approx(reference.surface_area(), rel=1e-12)


def test_3mf_package_keeps_its_conventions(keyed):
    """The package's parts, unit millimetre, the object's name, fixed zip dates (read with zipfile)."""
    data = threemf_bytes(keyed.mesh, name="cam_2")
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        assert archive.namelist() == ["[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model"]
        assert {info.date_time for info in archive.infolist()} == {(1980, 1, 1, 0, 0, 0)}
        model = archive.read("3D/3dmodel.model").decode()
    assert 'unit="millimeter"' in model and 'name="cam_2"' in model
    with zipfile.ZipFile(io.BytesIO(threemf_bytes(keyed.mesh, name='<"cam">'))) as archive:
        assert 'name="cam"' in archive.read("3D/3dmodel.model").decode()  # markup dropped from the name


def test_binary_stl_layout_read_with_struct(keyed):
    mesh = keyed.mesh
    data = stl_bytes(mesh)
    assert data[:80] == STL_HEADER and not data.startswith(b"solid")
    (count,) = struct.unpack_from("<I", data, 80)
    assert count == len(mesh.faces) and len(data) == 84 + 50 * count
    facets = [struct.unpack_from("<12fH", data, 84 + 50 * i) for i in range(count)]
    normals = np.array([f[:3] for f in facets])
    corners = np.array([f[3:12] for f in facets]).reshape(-1, 3, 3)
    assert {f[12] for f in facets} == {0}
    assert_array_equal(corners, mesh.triangles.astype(np.float32))
    assert_allclose(normals, as_trimesh(mesh).face_normals, rtol=0, atol=1e-7)  # trimesh's normals


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data(), flip=st.booleans())
def test_one_face_removed_or_flipped_is_not_closed(keyed, data, flip):
    mesh = keyed.mesh
    k = data.draw(st.integers(0, len(mesh.faces) - 1), label="face")
    faces = mesh.faces.copy()
    if flip:
        faces[k] = faces[k, ::-1]
    else:
        faces = np.delete(faces, k, axis=0)
    broken = TriangleMesh(vertices=mesh.vertices, faces=faces)
    defect = broken.closed_defect()
    assert defect is not None
    assert ("same direction" if flip else "no opposite edge") in defect
    assert not closed_for_trimesh(broken)  # trimesh agrees


def test_the_unbroken_plate_is_closed(keyed):
    assert keyed.mesh.closed_defect() is None and closed_for_trimesh(keyed.mesh)
    assert keyed.mesh.euler_number == as_trimesh(keyed.mesh).euler_number == 0  # genus 1: the bore


def test_a_face_repeating_a_vertex_is_refused():
    mesh = TriangleMesh(vertices=np.eye(3), faces=np.array([[0, 1, 1]]))
    assert mesh.closed_defect() == "face 0 repeats a vertex"


@pytest.mark.parametrize(
    ("vertices", "faces", "message"),
    [
        (np.zeros((3, 2)), np.array([[0, 1, 2]]), "vertices must be"),
        (np.zeros((3, 3)), np.array([0, 1, 2]), "faces must be"),
        (np.zeros((3, 3)), np.array([[0, 1, 3]]), "face indices"),
    ],
)
def test_malformed_meshes_are_refused(vertices, faces, message):
    with pytest.raises(ValueError, match=message):
        TriangleMesh(vertices=vertices, faces=faces)


def test_mesh_arrays_are_read_only(keyed):
    assert not keyed.mesh.vertices.flags.writeable and not keyed.mesh.faces.flags.writeable


# -- random convex solids ---------------------------------------------------------------

coordinates = st.floats(-50.0, 50.0, allow_nan=False, allow_infinity=False)


@settings(max_examples=40, deadline=None)
@given(points=arrays(np.float64, st.tuples(st.integers(4, 30), st.just(3)), elements=coordinates))
def test_random_hulls_agree_with_trimesh_and_manifold3d(points):
    hull = manifold3d.Manifold.hull_points(points)
    assume(not hull.is_empty() and hull.volume() > 1e-3 * np.ptp(points, axis=0).max() ** 3)
    mesh = TriangleMesh.from_manifold(hull)
    reader = as_trimesh(mesh)
    scale = float(np.ptp(mesh.vertices, axis=0).max())
    assert mesh.closed_defect() is None and reader.is_watertight and reader.is_winding_consistent
    assert mesh.euler_number == reader.euler_number == 2
    assert mesh.volume == pytest.approx(hull.volume(), rel=1e-9, abs=1e-12 * scale**3)
    assert mesh.volume == pytest.approx(reader.volume, rel=1e-9, abs=1e-12 * scale**3)
    assert mesh.area == pytest.approx(hull.surface_area(), rel=1e-9, abs=1e-12 * scale**2)
    for encode, kind in ((ply_bytes, "ply"), (obj_bytes, "obj"), (off_bytes, "off")):
        back = read(encode(mesh), kind)
        assert_array_equal(back.triangles, mesh.triangles)  # float64 (PLY) or exact repr (OBJ, OFF)
    stl = read(stl_bytes(mesh), "stl")
    assert stl.is_watertight and stl.is_winding_consistent
    assert_array_equal(np.asarray(stl.triangles, dtype=np.float32), mesh.triangles.astype(np.float32))


# -- determinism -------------------------------------------------------------------------


def test_a_fresh_interpreter_writes_the_same_bytes(keyed, tmp_path):
    here, there = tmp_path / "here", tmp_path / "there"
    here.mkdir()
    there.mkdir()
    write_meshes(here, keyed, MESH_FORMATS)
    subprocess.run(
        [sys.executable, "-c", _BUILD.format(extra=KEYED), str(there)],
        cwd=ROOT,
        check=True,
        capture_output=True,
        timeout=300,
    )
    names = sorted(p.name for p in here.iterdir())
    assert names == sorted(f"cam.{f}" for f in MESH_FORMATS) == sorted(p.name for p in there.iterdir())
    for name in names:
        assert (here / name).read_bytes() == (there / name).read_bytes(), name


def test_volume_is_translation_invariant(keyed):
    """The divergence-theorem sum does not depend on where the solid sits (up to round-off)."""
    mesh = keyed.mesh
    moved = TriangleMesh(vertices=mesh.vertices + np.array([1e3, -2e3, 5e2]), faces=mesh.faces)
    assert moved.volume == pytest.approx(mesh.volume, rel=1e-12)
    assert math.isclose(moved.area, mesh.area, rel_tol=1e-12)


def test_write_meshes_writes_the_encodings(keyed, tmp_path):
    """write_meshes writes exactly the encoders' bytes; a second plate's 3MF object is named by its stem."""
    paths = write_meshes(tmp_path, keyed, ["3mf", "ply"], stem="cam_2")
    assert [p.name for p in paths] == ["cam_2.stl", "cam_2.3mf", "cam_2.ply"]
    assert paths[0].read_bytes() == stl_bytes(keyed.mesh)
    assert paths[1].read_bytes() == threemf_bytes(keyed.mesh, name="cam_2")
    assert paths[2].read_bytes() == ply_bytes(keyed.mesh)
