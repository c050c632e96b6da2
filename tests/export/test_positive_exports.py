"""Groove cams and conjugate pairs through the build (issue 15): the files against the exact curves.

The solid is read back from ``cam.stl`` with trimesh and cut by planes: below
the groove its section is the blank less the bore, half-way down the groove
it also lacks the groove, whose area and flanks are compared with dense
polygons of the exact flank curves (``cam.offset``, not the fit). A conjugate
pair's second plate is checked the same way against the second roller's
exact profile, and its DXF spline, evaluated by ezdxf, against it too.
"""

from __future__ import annotations

import math
from functools import cache
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import trimesh

from camcad.design import load_design
from camcad.geometry.cam import Cam
from camcad.geometry.groove import groove_flanks
from camcad.pipeline import BuildResult, build
from tests.conftest import ROOT, distance_to_polygon

DENSE = np.linspace(0.0, 2.0 * math.pi, 100_000, endpoint=False)


@cache
def built(sample: str, folder: Path) -> BuildResult:
    return build(load_design(ROOT / "samples" / sample), folder, only=["stl", "dxf"])


@pytest.fixture(scope="module")
def groove(tmp_path_factory: pytest.TempPathFactory) -> BuildResult:
    return built("groove_rocker.toml", tmp_path_factory.mktemp("groove"))


@pytest.fixture(scope="module")
def pair(tmp_path_factory: pytest.TempPathFactory) -> BuildResult:
    return built("indexing_conjugate.toml", tmp_path_factory.mktemp("pair"))


def _area(points: np.ndarray) -> float:
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _section(mesh: trimesh.Trimesh, z: float) -> list[np.ndarray]:
    """The closed rings of the mesh's section by the plane at height z [mm], as (n, 2) arrays."""
    path = mesh.section(plane_origin=[0.0, 0.0, z], plane_normal=[0.0, 0.0, 1.0])
    planar, _ = path.to_2D(to_2D=np.eye(4))  # keep the cam frame's x and y
    return [np.asarray(ring)[:-1] for ring in planar.discrete]


def test_groove_solid_is_the_blank_less_bore_and_groove(groove: BuildResult) -> None:
    design = groove.analysis.design
    cam = groove.analysis.cam
    mesh = trimesh.load(groove.outdir / "cam.stl")
    assert mesh.is_watertight and mesh.is_winding_consistent
    t, depth, outer_r = design.cam.thickness, design.groove.depth, design.cam.outer_radius
    tol = design.mesh.chord_tolerance
    inner, outer = groove_flanks(cam, DENSE, design.groove.clearance)
    groove_area = abs(_area(outer.point)) - abs(_area(inner.point))  # dense exact flanks, not the fit
    bore = design.plate().bore
    assert bore is not None
    below = _section(mesh, 0.5 * (t - depth))  # under the groove: the blank less the bore
    floor_area = sum(abs(_area(r)) for r in below) - 2.0 * min(abs(_area(r)) for r in below)
    blank = math.pi * outer_r**2
    slack = tol * (2 * math.pi * outer_r + 200.0)
    assert floor_area == pytest.approx(blank - bore.area, abs=slack)
    rings = _section(mesh, t - 0.5 * depth)  # half-way down the groove: four rings
    assert len(rings) == 4
    areas = sorted(abs(_area(r)) for r in rings)
    # rim − outer flank + inner flank − bore
    cut = areas[3] - areas[2] + areas[1] - areas[0]
    length = float(np.sum(np.hypot(*np.diff(outer.point, axis=0).T)))
    assert cut == pytest.approx(blank - groove_area - bore.area, abs=slack + 2 * tol * length)
    # the groove's walls lie on the exact flanks (chord tolerance + the certified fit errors)
    fits = groove.analysis.parts[0].flank_fits
    assert len(fits) == 2
    by_size = sorted(rings, key=lambda r: abs(_area(r)))
    for ring, flank, fit in ((by_size[1], inner, fits[0]), (by_size[2], outer, fits[1])):
        assert distance_to_polygon(ring, flank.point).max() < tol + fit.max_error + 1e-6
    # the pocket's floor is at depth below the top face
    assert np.isclose(mesh.vertices[:, 2], t - depth, atol=1e-9).any()


def test_groove_width_in_the_solid_is_twice_the_roller_plus_clearance(groove: BuildResult) -> None:
    design = groove.analysis.design
    mesh = trimesh.load(groove.outdir / "cam.stl")
    rings = sorted(_section(mesh, design.cam.thickness - 1.0), key=lambda r: abs(_area(r)))
    inner_wall, outer_wall = rings[1], rings[2]
    # every point of the outer wall is 2 r_f + c from the inner wall (the groove's constant width)
    width = distance_to_polygon(outer_wall[::50], inner_wall)
    expected = 2.0 * design.follower.roller_radius + design.groove.clearance
    fits = groove.analysis.parts[0].flank_fits
    assert len(fits) == 2
    # each wall is a chord polygon of its fitted flank: within the chord tolerance and the fit error
    slack = 2.0 * design.mesh.chord_tolerance + fits[0].max_error + fits[1].max_error
    assert np.abs(width - expected).max() < slack


def test_conjugate_pair_writes_two_plates_on_their_own_profiles(pair: BuildResult) -> None:
    names = {p.name for p in pair.files}
    assert {"cam.stl", "cam_2.stl", "profile.dxf", "profile_2.dxf", "profile_poly_2.dxf"} <= names
    analysis = pair.analysis
    partner = analysis.parts[1].part.cam
    assert isinstance(partner, Cam)
    plates = {"": analysis.cam.profile(DENSE).point, "_2": partner.profile(DENSE).point}
    fits = {"": analysis.fit, "_2": analysis.parts[1].fit}
    for suffix, exact in plates.items():
        other = plates["_2" if suffix == "" else ""]
        mesh = trimesh.load(pair.outdir / f"cam{suffix}.stl")
        assert mesh.is_watertight
        ring = max(_section(mesh, 1.0), key=lambda r: abs(_area(r)))
        fit = fits[suffix]
        assert fit is not None
        near = distance_to_polygon(ring, exact)
        assert near.max() < analysis.design.mesh.chord_tolerance + fit.max_error + 1e-6
        assert distance_to_polygon(ring, other).max() > 1.0  # a different plate, not a copy
        # the DXF spline, evaluated by ezdxf, lies on the same exact profile
        doc = ezdxf.readfile(pair.outdir / f"profile{suffix}.dxf")
        splines = [e for e in doc.modelspace() if e.dxftype() == "SPLINE"]
        curve = splines[0].construction_tool()
        pts = np.array([(p.x, p.y) for p in curve.approximate(4000)])
        assert distance_to_polygon(pts, exact).max() < fit.max_error + 1e-5


def _entities(path: Path, layer: str, kind: str) -> list:
    return [e for e in ezdxf.readfile(path).modelspace() if e.dxf.layer == layer and e.dxftype() == kind]


def _arc_points(entities: list) -> np.ndarray:
    pts = []
    for e in entities:
        if e.dxftype() == "ARC":
            a0, a1 = math.radians(e.dxf.start_angle), math.radians(e.dxf.end_angle)
            a1 += 2.0 * math.pi if a1 < a0 else 0.0
            t = np.linspace(a0, a1, 40)
            c, r = e.dxf.center, e.dxf.radius
            pts.append(np.column_stack((c.x + r * np.cos(t), c.y + r * np.sin(t))))
    return np.vstack(pts)


def _distance_to_arcs(points: np.ndarray, arcs: list) -> np.ndarray:
    """Exact distance from each point to the nearest ARC entity (radial inside its span, else an end)."""
    best = np.full(len(points), np.inf)
    for e in arcs:
        c, r = np.array([e.dxf.center.x, e.dxf.center.y]), e.dxf.radius
        a0, a1 = math.radians(e.dxf.start_angle), math.radians(e.dxf.end_angle)
        rel = points - c
        inside = (np.arctan2(rel[:, 1], rel[:, 0]) - a0) % (2 * math.pi) <= (a1 - a0) % (2 * math.pi)
        ends = c + r * np.array([[math.cos(a0), math.sin(a0)], [math.cos(a1), math.sin(a1)]])
        to_end = np.min(np.hypot(*(points[:, None, :] - ends[None, :, :]).transpose(2, 0, 1)), axis=1)
        best = np.minimum(best, np.where(inside, np.abs(np.hypot(*rel.T) - r), to_end))
    return best


def test_groove_dxf_files_hold_both_flanks_on_their_exact_curves(groove: BuildResult) -> None:
    design, cam = groove.analysis.design, groove.analysis.cam
    fits = groove.analysis.parts[0].flank_fits
    assert len(fits) == 2
    inner, outer = groove_flanks(cam, DENSE, design.groove.clearance)
    exact = {"GROOVE_INNER": (inner.point, fits[0]), "GROOVE_OUTER": (outer.point, fits[1])}
    folder = groove.outdir
    for layer, (points, fit) in exact.items():
        # profile.dxf: the SPLINE, evaluated by ezdxf, within the certified fit error of the exact flank
        (spline,) = _entities(folder / "profile.dxf", layer, "SPLINE")
        pts = np.array([(p.x, p.y) for p in spline.construction_tool().approximate(4000)])
        assert distance_to_polygon(pts, points).max() < fit.max_error + 1e-5
        # profile_poly.dxf: one closed polyline within chord tolerance + fit error
        (poly,) = _entities(folder / "profile_poly.dxf", layer, "LWPOLYLINE")
        assert poly.closed
        vertices = np.array([(x, y) for x, y, *_ in poly.get_points()])
        assert distance_to_polygon(vertices, points).max() < design.dxf.chord_tolerance + fit.max_error + 1e-6
        # profile_arcs.dxf: arcs within the fit tolerance of the exact flank, covering all of it
        arcs = _arc_points(_entities(folder / "profile_arcs.dxf", layer, "ARC"))
        assert distance_to_polygon(arcs, points).max() < fit.tolerance + 1e-6
        arc_entities = _entities(folder / "profile_arcs.dxf", layer, "ARC")
        assert _distance_to_arcs(points[::20], arc_entities).max() < fit.tolerance + 1e-9
    # no plate profile in a groove cam's drawings: only the flanks, blank, bore and construction lines
    for name in ("profile.dxf", "profile_poly.dxf", "profile_arcs.dxf"):
        layers = {e.dxf.layer for e in ezdxf.readfile(folder / name).modelspace()}
        assert "CAM_PROFILE" not in layers and "BLANK" in layers
    (rim,) = _entities(folder / "profile.dxf", "BLANK", "CIRCLE")
    assert rim.dxf.radius == design.cam.outer_radius
