"""A linear cam's files read back by independent readers (issue 36).

profile.dxf by ezdxf (the edge's SPLINE within the fit tolerance of the exact
edge, three LINEs closing the bar), profile_arcs.dxf by ezdxf (the edge as
tangent-continuous ARCs and LINEs within the fit tolerance of the exact edge
both ways, head to tail with the bar's three sides), cam.step by OpenCASCADE (one valid solid
whose volume is the exact bar's area × thickness), cam.stl (closed, its
volume the same), summary.json's extremes, and the same bytes twice.
"""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from ezdxf.math import BSpline as EzBSpline
from scipy.spatial import cKDTree

from camcad.design import load_design
from camcad.geometry.cam import Cam
from camcad.geometry.families import family_of
from camcad.pipeline import build
from tests.conftest import ROOT
from tests.readers.test_rs274_linear import distance_to_curve

SAMPLE = ROOT / "samples" / "linear_cam.toml"


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Cam]:
    design = load_design(SAMPLE)
    out = tmp_path_factory.mktemp("linear") / "out"
    build(design, out, only=["dxf", "stl", "step", "gcode"], parallel=False)
    (part,) = family_of(design.cam.style).parts(Cam.from_design(design), design.family_options())
    return out, part.cam


def exact_bar_area(cam: Cam, bottom: float) -> float:
    """∫ (y(φ) − bottom) dx(φ) over the edge, by the trapezoid rule on 200 001 exact points."""
    phi = np.linspace(0.0, 2 * np.pi, 200_001)
    p = np.asarray(cam.profile(phi).point)
    return float(np.trapezoid(p[:, 1] - bottom, p[:, 0]))


def test_profile_dxf_is_the_edge_closed_by_three_lines(built):
    out, cam = built
    design = load_design(SAMPLE)
    doc = ezdxf.readfile(out / "profile.dxf")
    assert not doc.audit().has_errors
    msp = doc.modelspace()
    (spline,) = msp.query('SPLINE[layer=="CAM_PROFILE"]')
    lines = list(msp.query('LINE[layer=="CAM_PROFILE"]'))
    assert len(lines) == 3
    curve = EzBSpline(spline.control_points, order=spline.dxf.degree + 1, knots=spline.knots)
    pts = np.array([(v.x, v.y) for v in curve.approximate(200_000)])  # ~1.5 µm apart
    exact = np.asarray(cam.profile(np.linspace(0.0, 2 * np.pi, 20001)).point)
    # every exact point lies within the fit tolerance of the spline (+ the spacing of its dense points)
    d, _ = cKDTree(pts).query(exact)
    assert float(np.max(d)) <= design.fit.tolerance + 1e-3
    # head to tail: spline end -> down -> back -> up -> spline start
    ends = [(v[0], v[1]) for v in (spline.control_points[-1], spline.control_points[0])]
    chain = [((ln.dxf.start.x, ln.dxf.start.y), (ln.dxf.end.x, ln.dxf.end.y)) for ln in lines]
    assert chain[0][0] == pytest.approx(ends[0])
    assert chain[-1][1] == pytest.approx(ends[1])
    for (_, a), (b, _) in itertools.pairwise(chain):
        assert a == pytest.approx(b)
    assert chain[1][0][1] == pytest.approx(cam.base_radius - design.linear.bar_height)
    assert chain[0][0][0] - chain[1][1][0] == pytest.approx(design.linear.stroke_length)


def entity_ends(e) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Start, end and unit tangents there of a LINE or an ARC (an ARC runs ccw from its start angle)."""
    if e.dxftype() == "LINE":
        a, b = np.array(e.dxf.start)[:2], np.array(e.dxf.end)[:2]
        t = (b - a) / np.linalg.norm(b - a)
        return a, b, t, t
    c, r = np.array(e.dxf.center)[:2], e.dxf.radius
    a0, a1 = math.radians(e.dxf.start_angle), math.radians(e.dxf.end_angle)
    u0, u1 = np.array([math.cos(a0), math.sin(a0)]), np.array([math.cos(a1), math.sin(a1)])
    return c + r * u0, c + r * u1, np.array([-u0[1], u0[0]]), np.array([-u1[1], u1[0]])


def chain(entities: list, start: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """The entities head to tail from ``start``, each oriented along the chain (1e-6 mm joints)."""
    left = [entity_ends(e) for e in entities]
    out, here = [], start
    while left:
        k = next(
            (i for i, (a, b, _, _) in enumerate(left) if min(math.dist(a, here), math.dist(b, here)) < 1e-6),
            None,
        )
        assert k is not None, f"no entity continues the outline at {here}"
        a, b, ta, tb = left.pop(k)
        if math.dist(b, here) < math.dist(a, here):
            a, b, ta, tb = b, a, -tb, -ta
        out.append((a, b, ta, tb))
        here = b
    return out


def distance_to_entities(points: np.ndarray, entities: list) -> np.ndarray:
    """Exact distance of each point (n, 2) to the nearest LINE or ARC (radial in its span, else an end)."""
    best = np.full(len(points), np.inf)
    for e in entities:
        a, b, _, _ = entity_ends(e)
        ends = np.minimum(np.hypot(*(points - a).T), np.hypot(*(points - b).T))
        if e.dxftype() == "LINE":
            t = np.clip((points - a) @ (b - a) / float((b - a) @ (b - a)), 0.0, 1.0)
            best = np.minimum(best, np.hypot(*(points - a - t[:, None] * (b - a)).T))
            continue
        c, r = np.array(e.dxf.center)[:2], e.dxf.radius
        a0, a1 = math.radians(e.dxf.start_angle), math.radians(e.dxf.end_angle)
        rel = points - c
        inside = (np.arctan2(rel[:, 1], rel[:, 0]) - a0) % (2 * math.pi) <= (a1 - a0) % (2 * math.pi)
        best = np.minimum(best, np.where(inside, np.abs(np.hypot(*rel.T) - r), ends))
    return best


def test_profile_arcs_dxf_is_the_edge_in_tangent_arcs_closed_by_three_lines(built):
    out, cam = built
    design = load_design(SAMPLE)
    doc = ezdxf.readfile(out / "profile_arcs.dxf")
    assert not doc.audit().has_errors
    entities = list(doc.modelspace().query('*[layer=="CAM_PROFILE"]'))
    assert {e.dxftype() for e in entities} == {"ARC", "LINE"}
    assert len(list(doc.modelspace())) == len(entities)  # nothing but the outline
    phi = np.linspace(0.0, 2 * np.pi, 200_001)
    exact = cam.profile(phi)
    edge = np.asarray(exact.point)
    tangent = np.asarray(exact.tangent)
    loop = chain(entities, edge[0])
    assert math.dist(loop[-1][1], edge[0]) < 1e-6  # closed
    # the edge: from its exact start on its exact tangent, G1 joints, to its exact end on its tangent
    k_end = next(i for i, piece in enumerate(loop) if math.dist(piece[1], edge[-1]) < 1e-6)
    arcs, sides = loop[: k_end + 1], loop[k_end + 1 :]
    assert np.allclose(arcs[0][2], tangent[0], atol=1e-9)
    assert np.allclose(arcs[-1][3], tangent[-1], atol=1e-9)
    for (_, _, _, t_out), (_, _, t_in, _) in itertools.pairwise(arcs):
        assert abs(math.atan2(t_out[0] * t_in[1] - t_out[1] * t_in[0], t_out @ t_in)) < 1e-6
    # two-way within the fit tolerance of the exact edge: every exact point to the nearest entity (closed
    # form), and points along every edge entity to the exact edge (a polygon of 200 001 exact points)
    tol = design.fit.tolerance
    assert float(distance_to_entities(edge[::4], entities).max()) <= tol  # 50 001 points, ~5 µm apart
    along = []
    for a, b, ta, _ in arcs:
        chord = b - a
        bulge = chord @ np.array([-ta[1], ta[0]])  # 0 for a line
        if abs(bulge) < 1e-12:
            along.append(a + chord * np.linspace(0.0, 1.0, 50)[:, None])
            continue
        r = float(chord @ chord) / (2.0 * bulge)  # signed: the centre is r along the left normal of ta
        c = a + r * np.array([-ta[1], ta[0]])
        a0 = math.atan2(*(a - c)[::-1])
        sweep = (math.atan2(*(b - c)[::-1]) - a0) % (2 * math.pi)
        sweep = sweep if r > 0 else sweep - 2 * math.pi
        t = a0 + sweep * np.linspace(0.0, 1.0, 50)
        along.append(c + abs(r) * np.column_stack((np.cos(t), np.sin(t))))
    assert float(distance_to_curve(np.vstack(along), edge).max()) <= tol + 1e-9
    # the three sides: down the end x0 + L to the bottom, back along it, up the end x0
    bottom = cam.base_radius - design.linear.bar_height
    assert len(sides) == 3
    (a1, b1, *_), (a2, b2, *_), (a3, b3, *_) = sides
    assert a1[0] == b1[0] == pytest.approx(edge[-1][0], abs=1e-9) and b1[1] == pytest.approx(bottom)
    assert a2[1] == b2[1] == pytest.approx(bottom) and b2[0] == pytest.approx(edge[0][0], abs=1e-9)
    assert a3[0] == b3[0] == pytest.approx(edge[0][0], abs=1e-9)
    assert b2[0] - a2[0] == pytest.approx(-design.linear.stroke_length)


def test_profile_arcs_dxf_draws_each_dwell_as_one_line_on_the_exact_edge(built):
    """ezdxf reads each dwell back as one LINE from the dwell's start to its end, ARCs tangent to it."""
    out, cam = built
    design = load_design(SAMPLE)
    doc = ezdxf.readfile(out / "profile_arcs.dxf")
    entities = list(doc.modelspace().query('*[layer=="CAM_PROFILE"]'))
    edge = np.asarray(cam.profile(np.array([0.0, 2 * np.pi])).point)
    loop = chain(entities, edge[0])
    kinds = [e.dxftype() for e in entities]
    # the sample: a dwell at lift 20 mm over 120°..180° and one at 0 over 300°..360°; 360° = 240 mm
    length, base = design.linear.stroke_length, design.cam.base_radius
    for a, b, y in ((120.0, 180.0, base + 20.0), (300.0, 360.0, base)):
        xa, xb = edge[0][0] + length * a / 360.0, edge[0][0] + length * b / 360.0
        over = [
            k
            for k, (p, q, _, _) in enumerate(loop)
            if min(p[0], q[0]) < xb - 1e-3 and max(p[0], q[0]) > xa + 1e-3 and min(p[1], q[1]) > base - 1.0
        ]
        assert len(over) == 1
        p, q, t_in, t_out = loop[over[0]]
        assert np.allclose(t_in, t_out) and np.allclose(t_in, (1.0, 0.0))  # a line along +x
        assert np.allclose([p, q], [(xa, y), (xb, y)], atol=1e-9)
        # tangent continuous with the pieces before and after it on the edge
        before = loop[over[0] - 1]
        assert abs(before[3] @ (0.0, 1.0)) < 1e-9
        if math.dist(q, edge[-1]) > 1e-6:
            assert abs(loop[over[0] + 1][2] @ (0.0, 1.0)) < 1e-9
    assert kinds.count("LINE") == 3 + 2  # the bar's three sides and the two dwells


def test_cam_stl_is_closed_with_the_bars_volume(built):
    trimesh = pytest.importorskip("trimesh")
    out, cam = built
    design = load_design(SAMPLE)
    mesh = trimesh.load_mesh(out / "cam.stl")
    assert mesh.is_watertight and mesh.is_winding_consistent
    area = exact_bar_area(cam, cam.base_radius - design.linear.bar_height)
    assert mesh.volume == pytest.approx(area * design.cam.thickness, rel=1e-4)


def test_cam_step_is_one_valid_solid_with_the_bars_volume(built):
    pytest.importorskip("OCP", reason="the reader is OpenCASCADE (cadquery-ocp-novtk, test extra)")
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    out, cam = built
    design = load_design(SAMPLE)
    reader = STEPControl_Reader()
    assert reader.ReadFile(str(out / "cam.step")) == IFSelect_ReturnStatus.IFSelect_RetDone
    reader.TransferRoots()
    shape = reader.OneShape()
    assert BRepCheck_Analyzer(shape).IsValid()
    solids, explorer = 0, TopExp_Explorer(shape, TopAbs_SOLID)
    while explorer.More():
        solids += 1
        explorer.Next()
    assert solids == 1
    props = GProp_GProps()
    BRepGProp.VolumePropertiesGK_s(shape, props, 1e-10)
    area = exact_bar_area(cam, cam.base_radius - design.linear.bar_height)
    assert props.Mass() == pytest.approx(area * design.cam.thickness, rel=1e-5)


def test_summary_reports_true_extremes_and_the_bar(tmp_path):
    design = load_design(SAMPLE)
    build(design, tmp_path / "out", only=["tables"], parallel=False)
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    geo = summary["geometry"]
    # cycloidal 20 mm over 120° = 80 mm of travel: ds/dx peaks at 2h/80 = 0.5 mid-rise (closed form)
    assert geo["pressure_angle_max_deg"] == pytest.approx(math.degrees(math.atan(0.5)), abs=1e-9)
    assert geo["undercut"] is False
    lin = summary["linear"]
    assert lin["pressure_angle_max_x_mm"] == pytest.approx(40.0, abs=1e-4)  # mid-rise: 60° of 360° × 240 mm
    assert lin["stroke_length_mm"] == 240.0
    assert lin["drive_force_max_N"] == pytest.approx(
        summary["dynamics"]["torque_max_Nmm"] / (240.0 / (2 * math.pi)), rel=1e-12
    )


def test_same_input_same_bytes(tmp_path):
    design = load_design(SAMPLE)
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):
        build(design, out, only=["dxf", "stl", "step", "gcode", "tables"], parallel=False)
    names = sorted(p.name for p in a.iterdir())
    assert names == sorted(p.name for p in b.iterdir())
    for name in names:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
