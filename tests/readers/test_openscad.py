"""OpenSCAD extrudes the polyline and arcs DXFs to the expected volume and one body, takes cam.stl into
CGAL, and extrudes nothing from profile.dxf (issue 31: no dash slivers, no bore without its bulge)."""

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


ARC_FN = 3600  # $fn for the arcs file: OpenSCAD cuts an arc of sweep θ into ceil(ARC_FN θ / 2π) chords


def arcs_area_and_bound(path: Path) -> tuple[float, float]:
    """Exact area of the arcs file's plate (profile loop minus bore loop) by Green's theorem, and the bound
    on what OpenSCAD's chords (≤ 2π/ARC_FN each) and 0.001 mm vertex grid may change it [mm²]."""
    msp = ezdxf.readfile(path).modelspace()
    areas, bound = {}, 0.0
    delta = 2.0 * math.pi / ARC_FN
    for layer in ("CAM_PROFILE", "BORE"):
        entities = [e for e in msp if e.dxf.layer == layer]
        if not entities:
            continue
        if [e.dxftype() for e in entities] == ["CIRCLE"]:
            r = entities[0].dxf.radius
            areas[layer], length = math.pi * r * r, 2.0 * math.pi * r
            bound += r * r * math.pi * delta**2 / 6.0  # 2π r²Δ²/12: the segments a Δ-chord polygon cuts off
        else:
            areas[layer], length, segments = loop_area(entities, delta)
            bound += segments
        bound += DXF_GRID / math.sqrt(2) * length
    return areas["CAM_PROFILE"] - areas.get("BORE", 0.0), bound


def loop_area(entities, delta: float) -> tuple[float, float, float]:
    """|½∮(x dy − y dx)| of a closed chain of ARC and LINE entities (closed forms), its length, and the
    largest area the chords of sweep ≤ delta can cut off or add (Σ r² θ Δ² / 12)."""
    pieces = []  # (start, end, contribution ½∫(x dy − y dx) in the entity's own direction, length, segments)
    for e in entities:
        if e.dxftype() == "LINE":
            a, b = np.asarray(e.dxf.start)[:2], np.asarray(e.dxf.end)[:2]
            pieces.append((a, b, 0.5 * (a[0] * b[1] - a[1] * b[0]), float(np.linalg.norm(b - a)), 0.0))
            continue
        c, r = np.asarray(e.dxf.center)[:2], e.dxf.radius
        t0 = math.radians(e.dxf.start_angle)
        sweep = math.radians(e.dxf.end_angle - e.dxf.start_angle) % (2.0 * math.pi)
        t1 = t0 + sweep
        a = c + r * np.array([math.cos(t0), math.sin(t0)])
        b = c + r * np.array([math.cos(t1), math.sin(t1)])
        green = 0.5 * (
            r * r * sweep + r * (c[0] * (math.sin(t1) - math.sin(t0)) - c[1] * (math.cos(t1) - math.cos(t0)))
        )
        pieces.append((a, b, green, r * sweep, r * r * sweep * delta**2 / 12.0))
    total, length, segments = 0.0, 0.0, 0.0
    start, end, contribution, size, cut = pieces.pop(0)
    total, length, segments, here = contribution, size, cut, end
    while pieces:
        k = int(np.argmin([min(np.linalg.norm(p[0] - here), np.linalg.norm(p[1] - here)) for p in pieces]))
        a, b, contribution, size, cut = pieces.pop(k)
        forward = np.linalg.norm(a - here) <= np.linalg.norm(b - here)
        total += contribution if forward else -contribution
        here = b if forward else a
        length += size
        segments += cut
    assert np.linalg.norm(here - start) < 1e-6  # the chain closes
    return abs(total), length, segments


def test_linear_extrude_of_the_arcs_dxf_has_the_expected_volume(built: Built, tmp_path):
    """profile_arcs.dxf: ARC and LINE entities, which OpenSCAD reads (it ignores SPLINE)."""
    from camcad.export.dxf import write_profile_arcs_dxf

    t = built.design.cam.thickness
    dxf = write_profile_arcs_dxf(
        tmp_path / "profile_arcs.dxf",
        cam=built.cam, fit=built.fit, plate=built.design.plate(), options=built.design.dxf,
    )  # fmt: skip
    openscad(
        f'linear_extrude(height = {t!r}) import("{dxf.name}", $fn = {ARC_FN});\n', tmp_path / "plate.stl"
    )
    mesh = trimesh.load(tmp_path / "plate.stl", force="mesh")
    assert mesh.is_watertight
    area, bound = arcs_area_and_bound(dxf)
    assert mesh.volume == pytest.approx(area * t, abs=bound * t)
    # and the arcs' plate is the solid's cross-section within the arcs' tolerance × the perimeter
    perimeter = poly_dxf_perimeter(built.poly_dxf)
    assert abs(area - built.solid.spline_area) <= 1.01 * built.fit.tolerance * perimeter + 1e-9


def bodies(mesh: trimesh.Trimesh) -> int:
    """Connected components of a mesh (the bodies OpenSCAD made)."""
    return len(mesh.split(only_watertight=False))


def test_profile_dxf_gives_openscad_nothing_to_extrude(built: Built, tmp_path):
    """Issue 31: OpenSCAD closed each open LWPOLYLINE dash of the pitch curve into a sliver (133–195
    bodies) and read the keyed bore without its bulge. profile.dxf now holds SPLINEs (profile, bore,
    pitch dashes, the non-plotting frame), LINEs and TEXT only: OpenSCAD makes no body at all."""
    t = built.design.cam.thickness
    dxf = tmp_path / "profile.dxf"
    dxf.write_bytes(built.dxf.read_bytes())
    program = require("openscad")
    scad = tmp_path / "plate.scad"
    scad.write_text(f'linear_extrude(height = {t!r}) import("{dxf.name}");\n', encoding="utf-8")
    result = run([program, "-o", str(tmp_path / "plate.stl"), str(scad)], cwd=tmp_path)
    out = tmp_path / "plate.stl"
    if out.is_file() and out.stat().st_size > 0:
        count = bodies(trimesh.load(out, force="mesh"))
        pytest.fail(f"OpenSCAD extruded {count} bodies from profile.dxf")
    assert "top level object is empty" in result.stderr, result.stderr[-3000:]


def test_polyline_dxf_extrudes_to_one_body_the_cam(built: Built, tmp_path):
    """profile_poly.dxf: OpenSCAD makes exactly one connected body (the plate, its bore a hole)."""
    t = built.design.cam.thickness
    dxf = tmp_path / "profile_poly.dxf"
    dxf.write_bytes(built.poly_dxf.read_bytes())
    openscad(f'linear_extrude(height = {t!r}) import("{dxf.name}");\n', tmp_path / "plate.stl")
    mesh = trimesh.load(tmp_path / "plate.stl", force="mesh")
    assert bodies(mesh) == 1
    assert mesh.euler_number == (0 if built.design.cam.bore > 0 else 2)  # a ring (genus 1) or a disc
