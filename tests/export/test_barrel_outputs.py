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


def _wall_nodes(shape) -> np.ndarray:
    """Triangulation nodes of the B-spline faces of the solid."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.GeomAbs import GeomAbs_BSplineSurface
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    BRepMesh_IncrementalMesh(shape, 0.05, False, 0.2)
    pts = []
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        face = TopoDS.Face(ex.Current())
        if BRepAdaptor_Surface(face).GetType() == GeomAbs_BSplineSurface:
            tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
            pts += [[tri.Node(i).X(), tri.Node(i).Y(), tri.Node(i).Z()] for i in range(1, tri.NbNodes() + 1)]
        ex.Next()
    return np.array(pts)


@pytest.mark.parametrize("name", NAMES)
def test_step_solid_is_valid_and_its_walls_and_volume_are_exact(name):
    from OCP.BRepCheck import BRepCheck_Analyzer

    c, s = CASES[name], solid(name)
    assert BRepCheck_Analyzer(s.shape).IsValid()
    assert s.volume == pytest.approx(barrel_volume(c), abs=0.05)
    nodes = _wall_nodes(s.shape)
    o = c.options
    rho = np.hypot(nodes[:, 0], nodes[:, 1])
    assert rho.min() < o.bottom_radius + 0.5 and rho.max() > o.barrel_radius - 0.5
    assert np.any(np.abs(rho - o.pitch_station) < 1.0)
    phi = np.linspace(0.0, 2.0 * math.pi, 36000, endpoint=False)
    t = np.linspace(o.bottom_radius - 1.0, o.barrel_radius + 0.5, 90)
    exact = barrel_walls(c.program.evaluate(phi), c.follower, o, t)
    pts = np.concatenate((exact.upper.point.reshape(-1, 3), exact.lower.point.reshape(-1, 3)))
    nrm = np.concatenate((exact.upper.normal.reshape(-1, 3), exact.lower.normal.reshape(-1, 3)))
    _, idx = cKDTree(pts).query(nodes)
    dist = np.abs(np.einsum("ij,ij->i", nodes - pts[idx], nrm[idx]))
    assert dist.max() <= fitted(name).tolerance


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
