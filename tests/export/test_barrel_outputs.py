"""A barrel cam's outputs (issue 36) against independent truths.

- the walls' surfaces: the certified bound holds at random parameters off the check grid;
- cam.step (OpenCASCADE reads its own solid back): BRepCheck valid, one solid, B-spline wall
  faces whose triangulation nodes lie within the fit's tolerance of the exact walls (distance
  along the exact normal of the nearest exact point) over the groove's bottom, pitch and top
  radii; the volume against a quadrature of the exact groove (tests/barrel_cases.py);
- cam.stl: watertight and consistently wound for trimesh, volume within the facets' sag;
- profile.dxf: read by ezdxf, its SPLINEs within tolerance of the exact developed walls.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from camcad.fit.surface import BarrelWallFit, fit_barrel_walls
from camcad.geometry.barrel import WallSide, barrel_walls
from camcad.geometry.barrel_limits import developed_walls
from tests.barrel_cases import CASES, barrel_volume

pytest.importorskip("OCP")
NAMES = list(CASES)


@cache
def fitted(name: str) -> BarrelWallFit:
    c = CASES[name]
    return fit_barrel_walls(c.program, c.follower, c.options)


@cache
def solid(name: str):
    from camcad.export.barrel_step import barrel_shape

    return barrel_shape(fitted(name), CASES[name].options)


@pytest.mark.parametrize("name", NAMES)
def test_certified_bound_holds_off_the_grid(name):
    c, fit = CASES[name], fitted(name)
    rng = np.random.default_rng(7)
    for side, surf, cert in (
        (WallSide.UPPER, fit.upper, fit.upper_certificate),
        (WallSide.LOWER, fit.lower, fit.lower_certificate),
    ):
        assert cert.max_error <= fit.tolerance
        phi = np.sort(rng.uniform(0.0, 2.0 * math.pi, 4000))
        t = np.sort(rng.uniform(*surf.station_range, 23))
        exact = barrel_walls(c.program.evaluate(phi), c.follower, c.options, t)
        w = exact.upper.point if side is WallSide.UPPER else exact.lower.point
        err = np.linalg.norm(surf.at(phi, t) - w, axis=-1)
        assert err.max() <= cert.max_error
        assert err.max() > 0.05 * cert.max_error  # the bound is not vacuous


def _wall_nodes(shape) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per B-spline face of the solid: its triangulation nodes (n, 3) and their (u, v) (n, 2)."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.GeomAbs import GeomAbs_BSplineSurface
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    BRepMesh_IncrementalMesh(shape, 0.1, False, 0.3)
    out = []
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        face = TopoDS.Face(ex.Current())
        if BRepAdaptor_Surface(face).GetType() == GeomAbs_BSplineSurface:
            tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
            idx = range(1, tri.NbNodes() + 1)
            xyz = np.array([[tri.Node(i).X(), tri.Node(i).Y(), tri.Node(i).Z()] for i in idx])
            uv = np.array([[tri.UVNode(i).X(), tri.UVNode(i).Y()] for i in idx])
            out.append((xyz, uv))
        ex.Next()
    return out


@pytest.mark.parametrize("name", NAMES)
def test_step_solid_is_valid_and_its_walls_and_volume_are_exact(name):
    """The walls' faces as OpenCASCADE meshes them: each node within tolerance of the exact wall.

    A node at surface parameters (u, v) is compared with the exact wall point W(2πu, t(v)) of the
    same parameters, on whichever wall it is nearer: that distance bounds its distance to the wall.
    """
    from OCP.BRepCheck import BRepCheck_Analyzer

    c, s, fit = CASES[name], solid(name), fitted(name)
    assert BRepCheck_Analyzer(s.shape).IsValid()
    assert s.volume == pytest.approx(barrel_volume(c), abs=0.05)
    faces = _wall_nodes(s.shape)
    assert len(faces) >= 2
    o = c.options
    t0, t1 = fit.upper.station_range
    worst, radii = 0.0, []
    for xyz, uv in faces:
        phi, t = 2.0 * math.pi * uv[:, 0], t0 + uv[:, 1] * (t1 - t0)
        walls = barrel_walls(c.program.evaluate(phi), c.follower, o, t[:, None])  # one station per angle
        up = np.linalg.norm(walls.upper.point[:, 0] - xyz, axis=1)
        low = np.linalg.norm(walls.lower.point[:, 0] - xyz, axis=1)
        worst = max(worst, float(np.minimum(up, low).max()))
        radii.append(np.hypot(xyz[:, 0], xyz[:, 1]))
    rho = np.concatenate(radii)
    assert rho.min() < o.bottom_radius + 0.5 and rho.max() > o.barrel_radius - 0.5  # trimmed at both
    assert rho.min() > o.bottom_radius - 1e-3 and rho.max() < o.barrel_radius + 1e-3
    assert np.any(np.abs(rho - o.pitch_station) < 1.0)
    assert worst <= fit.tolerance


def test_a_conical_rollers_barrel_is_valid_with_the_quadratures_volume():
    from dataclasses import replace

    from OCP.BRepCheck import BRepCheck_Analyzer

    from camcad.export.barrel_step import barrel_shape
    from camcad.geometry.barrel import RollerShape
    from tests.barrel_cases import INDEXER

    cone = replace(INDEXER, options=replace(INDEXER.options, roller=RollerShape.CONICAL))
    fit = fit_barrel_walls(cone.program, cone.follower, cone.options)
    assert fit.max_error <= fit.tolerance
    s = barrel_shape(fit, cone.options)
    assert BRepCheck_Analyzer(s.shape).IsValid()
    assert s.volume == pytest.approx(barrel_volume(cone), abs=0.05)
    assert s.volume != pytest.approx(barrel_volume(INDEXER), abs=10.0)  # the cone's groove differs


@settings(max_examples=4, deadline=None)
@given(
    radius=st.floats(55.0, 90.0),
    depth=st.floats(14.0, 22.0),
    roller=st.floats(4.0, 9.0),
    lift=st.floats(5.0, 40.0),
    span=st.floats(80.0, 160.0),
    law=st.sampled_from(["cycloidal", "poly-345", "modified-sine", "harmonic"]),
)
def test_fit_certificate_holds_for_any_translating_barrel(radius, depth, roller, lift, span, law):
    from camcad.geometry.barrel import BarrelOptions, TranslatingBarrelRoller
    from camcad.geometry.barrel_limits import barrel_limits
    from tests.barrel_cases import _program

    program = _program(lift, law, span)
    options = BarrelOptions(
        barrel_radius=radius,
        length=lift + 2.0 * roller + 20.0,
        depth=depth,
        roller_radius=roller,
        roller_length=0.7 * depth,
        clearance=0.05,
    )
    follower = TranslatingBarrelRoller(axial_position=roller + 10.0)
    assume(not barrel_limits(program, follower, options).findings)
    fit = fit_barrel_walls(program, follower, options)
    rng = np.random.default_rng(1)
    phi = rng.uniform(0.0, 2.0 * math.pi, 3000)
    for surf, cert, pick in ((fit.upper, fit.upper_certificate, 0), (fit.lower, fit.lower_certificate, 1)):
        assert cert.max_error <= fit.tolerance
        t = rng.uniform(*surf.station_range, 7)
        walls = barrel_walls(program.evaluate(phi), follower, options, t)
        w = (walls.upper, walls.lower)[pick].point
        assert np.linalg.norm(surf.at(phi, t) - w, axis=-1).max() <= cert.max_error


def test_step_bytes_are_reproducible_and_hold_one_brep():
    from camcad.export.barrel_step import barrel_step_bytes

    a = barrel_step_bytes(solid("indexer"), name="indexer")
    b = barrel_step_bytes(solid("indexer"), name="indexer")
    assert a == b
    text = a.decode("ascii")
    assert text.count("MANIFOLD_SOLID_BREP") == 1
    assert text.count("B_SPLINE_SURFACE_WITH_KNOTS") >= 2
    assert "PRODUCT('indexer'" in text


@pytest.mark.parametrize("name", NAMES)
def test_stl_is_watertight_and_its_volume_within_the_sag(name, tmp_path):
    import trimesh

    from camcad.export.barrel_mesh import BarrelMeshOptions, barrel_mesh, barrel_stl_bytes

    c = CASES[name]
    opts = BarrelMeshOptions()
    mesh = barrel_mesh(c.program, c.follower, c.options, opts)
    path = tmp_path / "cam.stl"
    path.write_bytes(barrel_stl_bytes(mesh))
    tm = trimesh.load(path, process=True)
    assert tm.is_watertight and tm.is_winding_consistent
    assert len(tm.split(only_watertight=False)) == 1
    # every facet lies within the sag of the exact surface: |ΔV| ≤ area × sag (walls sampled finer)
    assert abs(tm.volume - barrel_volume(c)) <= tm.area * opts.chord


@pytest.mark.parametrize("name", NAMES)
def test_developed_dxf_holds_both_walls(name, tmp_path):
    import ezdxf

    from camcad.export.barrel_dxf import developed_groove, write_developed_dxf

    c = CASES[name]
    groove = developed_groove(c.program, c.follower, c.options, tolerance=0.005)
    path = tmp_path / "profile.dxf"
    write_developed_dxf(groove, path, length=c.options.length)
    doc = ezdxf.readfile(path)
    phi = np.linspace(0.0, 2.0 * math.pi, 200001)
    exact = developed_walls(c.program.evaluate(phi), c.follower, c.options, c.options.pitch_station)
    for layer, curve in (("WALL_UPPER", exact.upper), ("WALL_LOWER", exact.lower), ("PITCH", exact.pitch)):
        (spline,) = doc.modelspace().query(f'SPLINE[layer=="{layer}"]')
        ez = spline.construction_tool()
        pts = np.array([(p.x, p.y) for p in ez.approximate(40000)])
        d, _ = cKDTree(curve.point).query(pts)
        assert d.max() <= 0.005 + 0.001  # plus half the exact points' spacing (< 0.002 mm)
    # the walls are the roller's width apart across the pitch line
    gap = np.linalg.norm(exact.upper.point - exact.lower.point, axis=1)
    assert gap == pytest.approx(2 * c.options.roller_radius + c.options.clearance, abs=1e-9)


# -- a rib -------------------------------------------------------------------------------


@cache
def rib_fit() -> BarrelWallFit:
    from tests.barrel_cases import RIB

    return fit_barrel_walls(RIB.program, RIB.follower, RIB.options)


def test_rib_step_is_one_valid_solid_with_the_quadratures_volume_and_exact_faces():
    """The rib's STEP solid: BRepCheck valid, one solid, its faces' nodes on the exact faces, its volume.

    The volume's truth is the core (less the bore) plus the quadrature of the rib between its exact
    faces on cylinders (tests/barrel_cases.py), independent of the fit and of OpenCASCADE.
    """
    from OCP.BRepCheck import BRepCheck_Analyzer

    from camcad.export.barrel_step import barrel_shape, barrel_step_bytes
    from camcad.geometry.barrel import barrel_faces
    from tests.barrel_cases import RIB

    fit = rib_fit()
    assert fit.max_error <= fit.tolerance
    s = barrel_shape(fit, RIB.options)
    assert BRepCheck_Analyzer(s.shape).IsValid()
    assert s.volume == pytest.approx(barrel_volume(RIB), abs=0.05)
    o = RIB.options
    blank = math.pi * (o.barrel_radius**2 - (0.5 * o.bore) ** 2) * o.length
    core = math.pi * (o.bottom_radius**2 - (0.5 * o.bore) ** 2) * o.length
    assert core + 1000.0 < s.volume < blank - 1000.0  # a rib, not a groove nor a bare core
    faces = _wall_nodes(s.shape)
    assert len(faces) >= 2
    t0, t1 = fit.upper.station_range
    worst, radii = 0.0, []
    for xyz, uv in faces:
        phi, t = 2.0 * math.pi * uv[:, 0], t0 + uv[:, 1] * (t1 - t0)
        exact = barrel_faces(RIB.program.evaluate(phi), RIB.follower, o, t[:, None])
        up = np.linalg.norm(exact.upper.point[:, 0] - xyz, axis=1)
        low = np.linalg.norm(exact.lower.point[:, 0] - xyz, axis=1)
        worst = max(worst, float(np.minimum(up, low).max()))
        radii.append(np.hypot(xyz[:, 0], xyz[:, 1]))
    rho = np.concatenate(radii)
    assert rho.min() < o.bottom_radius + 0.5 and rho.max() > o.barrel_radius - 0.5
    assert rho.min() > o.bottom_radius - 1e-3 and rho.max() < o.barrel_radius + 1e-3
    assert worst <= fit.tolerance
    data = barrel_step_bytes(s, name="rib")
    assert data == barrel_step_bytes(s, name="rib")  # same input, same bytes
    text = data.decode("ascii")
    assert text.count("MANIFOLD_SOLID_BREP") == 1 and text.count("B_SPLINE_SURFACE_WITH_KNOTS") >= 2


def test_rib_stl_is_watertight_and_its_volume_within_the_sag(tmp_path):
    import trimesh

    from camcad.export.barrel_mesh import BarrelMeshOptions, barrel_mesh, barrel_stl_bytes
    from tests.barrel_cases import RIB

    opts = BarrelMeshOptions()
    mesh = barrel_mesh(RIB.program, RIB.follower, RIB.options, opts)
    path = tmp_path / "cam.stl"
    path.write_bytes(barrel_stl_bytes(mesh))
    tm = trimesh.load(path, process=True)
    assert tm.is_watertight and tm.is_winding_consistent
    assert len(tm.split(only_watertight=False)) == 1
    assert abs(tm.volume - barrel_volume(RIB)) <= tm.area * opts.chord
    rho = np.hypot(tm.vertices[:, 0], tm.vertices[:, 1])
    assert rho.max() == pytest.approx(RIB.options.barrel_radius, abs=1e-3)


def test_rib_developed_dxf_holds_both_faces(tmp_path):
    """The SPLINEs against the developed faces, and the faces against their rollers' shifted pitch lines."""
    import ezdxf

    from camcad.export.barrel_dxf import developed_groove, write_developed_dxf
    from tests.barrel_cases import RIB

    o = RIB.options
    groove = developed_groove(RIB.program, RIB.follower, o, tolerance=0.005)
    path = tmp_path / "profile.dxf"
    write_developed_dxf(groove, path, length=o.length)
    doc = ezdxf.readfile(path)
    tp, h, r_w = o.pitch_station, o.rib_offset, o.roller_radius + 0.5 * o.clearance
    z0 = RIB.follower.axial_position
    for layer, sign in (("WALL_UPPER", 1.0), ("WALL_LOWER", -1.0), ("PITCH", 0.0)):
        # vertices 0.015 mm apart: the nearest is within (0.0075 mm)²/(2·8 mm) of a curve 8 mm away; 20×
        # denser on the pitch line itself, where it is within half the spacing
        phi = np.linspace(-0.2, 2.0 * math.pi + 0.2, 30001 if sign else 600001)
        s = RIB.program.evaluate(np.mod(phi, 2.0 * math.pi)).s
        (spline,) = doc.modelspace().query(f'SPLINE[layer=="{layer}"]')
        pts = np.array([(p.x, p.y) for p in spline.construction_tool().approximate(20000)])
        # the roller's path unrolled at the pitch station: (t_p φ, z0 ± h + s)
        path_pts = np.column_stack((tp * phi, z0 + sign * h + s))
        d, idx = cKDTree(path_pts).query(pts)
        assert np.abs(d - (r_w if sign else 0.0)).max() <= 0.005 + 0.002
        if sign:
            assert np.all(sign * (pts[:, 1] - path_pts[idx, 1]) < 0.0)  # on the rib's side of the roller


@pytest.mark.parametrize("variant", ["arm", "cone"])
def test_an_arm_rib_and_a_conical_rib_are_valid_with_the_quadratures_volume(variant):
    """A rib on an arm's yoke and a rib between conical rollers: BRepCheck valid, the quadrature's volume."""
    from dataclasses import replace

    from OCP.BRepCheck import BRepCheck_Analyzer

    from camcad.export.barrel_step import barrel_shape
    from camcad.geometry.barrel import BarrelKind, RollerShape
    from tests.barrel_cases import ARM, RIB

    if variant == "arm":
        o = replace(ARM.options, kind=BarrelKind.RIB, rib_width=12.0, depth=15.0, roller_length=12.0)
        case = replace(ARM, name="arm-rib", options=o)
    else:
        case = replace(RIB, name="cone-rib", options=replace(RIB.options, roller=RollerShape.CONICAL))
    fit = fit_barrel_walls(case.program, case.follower, case.options)
    assert fit.max_error <= fit.tolerance
    s = barrel_shape(fit, case.options)
    assert BRepCheck_Analyzer(s.shape).IsValid()
    assert s.volume == pytest.approx(barrel_volume(case), abs=0.05)
