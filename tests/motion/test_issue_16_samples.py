"""Issue 16 end to end: the web-cutter sample (constant-velocity stretch between blend points).

Independent checks: the web speed stated in the file against motion.csv read
back with the csv module; one-sided limits at every joint; the DXF read back
with ezdxf and its spline measured against the exact profile; the G-code
read back by camcad's parser and proved against the exact offset curve.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from numpy.testing import assert_allclose

import camcad
from camcad.export.gcode import parse_gcode
from camcad.geometry.cam import Cam
from camcad.pipeline import build
from camcad.toolpath import check_toolpath
from tests.conftest import ROOT, distance_to_polygon

SAMPLE = ROOT / "samples" / "web_cutter.toml"


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[camcad.Design, Path]:
    design = camcad.load_design(SAMPLE)
    out = tmp_path_factory.mktemp("cutter") / "out"
    build(design, out)
    return design, out


def test_the_knife_moves_with_the_web_at_200_mm_per_s_for_60_degrees(built):
    design, out = built
    with (out / "motion.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    angle = np.array([float(r["angle_deg"]) for r in rows])
    v = np.array([float(r["v_mm_per_rad"]) for r in rows])
    omega = design.cam.speed_rpm * 2 * math.pi / 60  # rad/s
    stretch = (angle >= 120.0) & (angle <= 180.0)
    assert stretch.sum() >= 590
    assert_allclose(v[stretch] * omega, 200.0, rtol=1e-8)


def test_continuous_to_the_jerk_at_every_blend_point(built):
    design, _ = built
    cam = Cam.from_design(design)
    for joint in cam.program.joints():
        left = cam.program.evaluate(joint.phi, side="left")
        right = cam.program.evaluate(joint.phi, side="right")
        for k, scale in (("s", 1.0), ("v", 1e1), ("a", 1e2), ("j", 1e3)):
            assert abs(getattr(left, k)[0] - getattr(right, k)[0]) <= 1e-9 * scale, (joint.describe(), k)
        assert joint.continuity == 3


def test_dxf_spline_lies_on_the_exact_profile(built):
    design, out = built
    doc = ezdxf.readfile(out / "profile.dxf")
    splines = list(doc.modelspace().query('SPLINE[layer=="CAM_PROFILE"]'))  # not the bore's spline
    assert len(splines) == 1
    cam = Cam.from_design(design)
    exact = np.asarray(cam.profile(np.linspace(0, 2 * math.pi, 200_000, endpoint=False)).point)
    outer = max(splines, key=lambda s: len(s.control_points))
    pts = np.array([(p.x, p.y) for p in outer.construction_tool().approximate(4000)])
    assert np.max(distance_to_polygon(pts, exact)) <= design.fit.tolerance + 1e-4


def test_gcode_read_back_proves_against_the_exact_offset(built):
    design, out = built
    cam = Cam.from_design(design)
    moves = parse_gcode((out / "cam.ngc").read_text())
    check = check_toolpath(moves, cam, design.gcode, thickness=design.cam.thickness, bore=design.cam.bore)
    assert check.ok, check.problems
    assert check.hausdorff <= design.gcode.tolerance


def test_summary_lists_the_blend_points_and_their_continuity(built):
    import json

    _, out = built
    motion = json.loads((out / "summary.json").read_text())["motion"]
    assert motion["blend_points_deg"] == [60.0, 120.0, 180.0, 300.0]
    by_angle = {round(j["angle_deg"], 6): j["continuity"] for j in motion["joints"]}
    assert all(by_angle[a] == 3 for a in motion["blend_points_deg"])
