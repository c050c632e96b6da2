"""A linear cam's files read back by independent readers (issue 36).

profile.dxf by ezdxf (the edge's SPLINE within the fit tolerance of the exact
edge, three LINEs closing the bar), cam.step by OpenCASCADE (one valid solid
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
