"""OpenSCAD extrudes the polyline DXF to the expected volume and takes cam.stl into CGAL."""

from __future__ import annotations

import math
import re
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import trimesh

from camcad.export._outline import polygon_area, polygon_perimeter
from tests.readers.conftest import Built, require, run

pytestmark = pytest.mark.slow

HOLE_FN = 64  # facets of the test hole cut in the CGAL test
DXF_GRID = 0.001  # mm, the grid OpenSCAD snaps imported DXF vertices to


def openscad(script: str, out: Path) -> str:
    """Render ``script`` to ``out`` (format from its suffix); OpenSCAD's log (stderr)."""
    program = require("openscad")
    scad = out.with_suffix(".scad")
    scad.write_text(script, encoding="utf-8")
    result = run([program, "-o", str(out), str(scad)], cwd=out.parent)
    assert result.returncode == 0, result.stderr[-3000:]
    assert out.is_file() and out.stat().st_size > 0, result.stderr[-3000:]
    return result.stderr


def poly_dxf_area(path: Path) -> float:
    """Area of the polyline DXF's plate: profile polygon minus bore polygon [mm²]."""
    msp = ezdxf.readfile(path).modelspace()
    areas = {e.dxf.layer: abs(polygon_area(np.asarray(e.get_points("xy")))) for e in msp.query("LWPOLYLINE")}
    return areas["CAM_PROFILE"] - areas.get("BORE", 0.0)


def poly_dxf_perimeter(path: Path) -> float:
    """Total length of the polyline DXF's contours [mm]."""
    msp = ezdxf.readfile(path).modelspace()
    return sum(polygon_perimeter(np.asarray(e.get_points("xy"))) for e in msp.query("LWPOLYLINE"))


def test_linear_extrude_of_the_polyline_dxf_has_the_expected_volume(built: Built, tmp_path):
    t = built.design.cam.thickness
    dxf = tmp_path / "profile_poly.dxf"
    dxf.write_bytes(built.poly_dxf.read_bytes())
    openscad(f'linear_extrude(height = {t!r}) import("{dxf.name}");\n', tmp_path / "plate.stl")
    mesh = trimesh.load(tmp_path / "plate.stl", force="mesh")
    assert mesh.is_watertight
    # OpenSCAD's DXF import snaps vertices to a 0.001 mm grid (GRID_COARSE), moving
    # each by at most 0.001/√2 mm: the area changes by less than that × perimeter.
    area, perimeter = poly_dxf_area(dxf), poly_dxf_perimeter(dxf)
    assert mesh.volume == pytest.approx(area * t, abs=DXF_GRID / math.sqrt(2) * perimeter * t)
    # and the polyline plate is the solid's cross-section within the chord bound
    assert abs(poly_dxf_area(dxf) - built.solid.spline_area) <= built.solid.chord_area_bound


def test_cam_stl_is_a_simple_solid_in_a_cgal_difference(built: Built, tmp_path):
    """Cut a small round hole through the plate between bore and base circle with CGAL."""
    design = built.design
    t = design.cam.thickness
    stl = tmp_path / "cam.stl"
    stl.write_bytes(built.stl.read_bytes())
    y = -(design.cam.bore / 2.0 + design.cam.base_radius) / 2.0  # the bore's keyway points to +y
    script = (
        f'difference() {{ import("{stl.name}"); '
        f"translate([0, {y!r}, -1]) cylinder(r = 1, h = {t + 2!r}, $fn = {HOLE_FN}); }}\n"
    )
    log = openscad(script, tmp_path / "cut.off")
    assert re.search(r"Simple:\s+yes", log), log[-3000:]
    cut = trimesh.load(tmp_path / "cut.off", force="mesh")
    assert cut.is_watertight
    hole = 0.5 * HOLE_FN * math.sin(2.0 * math.pi / HOLE_FN)  # area of the unit 64-gon
    assert cut.volume == pytest.approx(built.solid.volume - hole * t, rel=1e-6)
    holes = built.solid.holes + 1
    assert cut.euler_number == 2 - 2 * holes
