"""DXF export: read back with ezdxf.recover and compared by meaning, not bytes.

Independent truths: the exact profile and pitch curve (``cam.profile``,
``cam.pitch``), the fit's control points and knots, closed-form bore areas,
exact arc geometry sampled here (not by the writer), ezdxf's own bounding
boxes for the extents.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from ezdxf import recover
from ezdxf.entitydb import EntityDB
from ezdxf.math import bulge_to_arc
from numpy.testing import assert_allclose

from camcad.design import Design
from camcad.errors import ExportError
from camcad.export._outline import bspline_area, bspline_length, flatten_bspline, polygon_area
from camcad.export.dxf import (
    EXTENTS_MARGIN,
    PITCH_DASH,
    PITCH_GAP,
    profile_arcs_document,
    profile_document,
    profile_poly_document,
    write_profile_arcs_dxf,
    write_profile_dxf,
    write_profile_poly_dxf,
)
from camcad.fit import ProfileFit, fit_cam_profile
from camcad.geometry.cam import Cam
from camcad.geometry.plate import BoreOutline
from tests.conftest import distance_to_polygon, make_design


def writer_options(design):
    """The DXF writers' plate and options for a design."""
    return {"plate": design.plate(), "options": design.dxf}


KEYED = {"cam": {"bore": 12.0, "keyway_width": 4.0, "keyway_depth": 2.0}}
DESIGNS = {
    "roller-keyed": lambda: make_design(extra=KEYED),
    "roller-offset-cw": lambda: make_design(
        rotation="cw", offset=6.0, law="poly-345", extra={"cam": {"bore": 10.0}}
    ),
    "flat-harmonic": lambda: make_design(follower="translating-flat", law="harmonic"),
}


def cam_and_fit(design: Design) -> tuple[Cam, ProfileFit]:
    """The exact cam and its certified fit, as the pipeline makes them."""
    cam = Cam.from_design(design)
    return cam, fit_cam_profile(
        cam, tolerance=design.fit.tolerance, max_control_points=design.fit.max_control_points
    )


def lwpolyline_outline(entity, samples: int = 20000) -> np.ndarray:
    """Vertices of a closed LWPOLYLINE with its bulge arcs sampled exactly (ezdxf paths use Béziers)."""
    pts = entity.get_points("xyb")
    out = []
    for k, (x, y, bulge) in enumerate(pts):
        out.append((x, y))
        if bulge:
            nx, ny, _ = pts[(k + 1) % len(pts)]
            center, start, end, radius = bulge_to_arc((x, y), (nx, ny), bulge)
            sweep = (end - start) % (2.0 * math.pi)
            t = start + sweep * np.arange(1, samples) / samples
            out.extend(zip(center.x + radius * np.cos(t), center.y + radius * np.sin(t), strict=True))
    return np.asarray(out)


@pytest.fixture(scope="module", params=list(DESIGNS), ids=list(DESIGNS))
def case(request: pytest.FixtureRequest) -> tuple[Design, Cam, ProfileFit]:
    design = DESIGNS[request.param]()
    return (design, *cam_and_fit(design))


@pytest.fixture(scope="module")
def written(case, tmp_path_factory) -> tuple[Path, Path, Path]:
    design, cam, fit = case
    folder = tmp_path_factory.mktemp("dxf")
    return (
        write_profile_dxf(folder / "profile.dxf", cam=cam, fit=fit, **writer_options(design)),
        write_profile_poly_dxf(folder / "profile_poly.dxf", cam=cam, fit=fit, **writer_options(design)),
        write_profile_arcs_dxf(folder / "profile_arcs.dxf", cam=cam, fit=fit, **writer_options(design)),
    )


def read_back(path: Path) -> ezdxf.document.Drawing:
    doc, auditor = recover.readfile(path)
    assert not auditor.has_errors, [e.message for e in auditor.errors]
    return doc


def test_header_units_version_and_layers(written):
    for path in written:
        doc = read_back(path)
        assert doc.dxfversion == "AC1024"  # R2010
        assert doc.header["$INSUNITS"] == 4  # millimetres
        assert doc.header["$MEASUREMENT"] == 1  # metric
        assert {"CAM_PROFILE", "BORE"} <= {layer.dxf.name for layer in doc.layers}
    doc = read_back(written[0])
    assert "CENTER" in doc.linetypes
    assert doc.layers.get("CENTER").dxf.linetype == "CENTER"


def test_one_clamped_spline_from_control_points_and_knots(case, written):
    _, _, fit = case
    doc = read_back(written[0])
    splines = doc.modelspace().query('SPLINE[layer=="CAM_PROFILE"]')
    assert len(splines) == 1
    assert all(e.dxf.flags == 0 and len(e.weights) == 0 for e in doc.modelspace().query("SPLINE"))
    spline = splines[0]
    assert spline.dxf.layer == "CAM_PROFILE"
    assert spline.dxf.flags == 0  # not closed, not periodic, not rational
    assert spline.dxf.degree == 3
    assert spline.fit_point_count() == 0
    assert len(spline.weights) == 0
    ctrl = np.asarray(spline.control_points)
    knots = np.asarray(spline.knots)
    assert_allclose(ctrl[:, :2], fit.clamped.control_points, rtol=0, atol=1e-12)
    assert_allclose(ctrl[:, 2], 0.0, atol=0)
    assert np.array_equal(ctrl[0], ctrl[-1])
    assert_allclose(knots, fit.clamped.knots, rtol=0, atol=1e-15)
    assert np.all(knots[:4] == knots[0]) and np.all(knots[-4:] == knots[-1])


def test_spline_read_back_matches_exact_profile_within_fit_tolerance(case, written):
    """ezdxf's own evaluation of the SPLINE, against the analytic profile."""
    design, cam, fit = case
    spline = read_back(written[0]).modelspace().query("SPLINE")[0]
    tool = spline.construction_tool()
    a, b = fit.clamped.domain
    u = np.linspace(a, b, 40001)
    dense = np.asarray([(v.x, v.y) for v in tool.points(u)])
    # ezdxf rounds knots to its knot tolerance (1e-10): agreement to ~1e-8 mm
    assert_allclose(dense, fit.clamped.evaluate(np.clip(u, a, np.nextafter(b, a))), rtol=0, atol=1e-6)
    # distance from exact points (samples and mid-samples) to the dense spline polyline
    phi = np.linspace(0.0, 2.0 * math.pi, 7201)[:-1]
    exact = cam.profile(phi).point
    assert distance_to_polygon(exact, dense[:-1]).max() <= design.fit.tolerance


def test_bore_layer(case, written):
    design, _, _ = case
    doc = read_back(written[0])
    bore = BoreOutline.from_cam_spec(design.cam.bore, design.cam.keyway_width, design.cam.keyway_depth)
    entities = doc.modelspace().query('*[layer=="BORE"]')
    if bore is None:
        assert len(entities) == 0
    else:
        # one closed cubic SPLINE of Bézier spans (issue 31: OpenSCAD skips it, it read a CIRCLE or a
        # bulge polyline, ignoring the bulge); measured against the exact bore and keyway
        assert [e.dxftype() for e in entities] == ["SPLINE"]
        tool = entities[0].construction_tool()
        pts = np.asarray([(v.x, v.y) for v in tool.approximate(20000)])
        assert_allclose(pts[0], pts[-1], atol=1e-12)  # closed
        r = np.hypot(pts[:, 0], pts[:, 1])
        corner_y = (
            math.sqrt(bore.radius**2 - (0.5 * design.cam.keyway_width) ** 2) if bore.has_keyway else 0.0
        )
        on_arc = ~(
            (np.abs(pts[:, 0]) <= 0.5 * design.cam.keyway_width + 1e-9) & (pts[:, 1] >= corner_y - 1e-9)
        )
        assert_allclose(r[on_arc], bore.radius, rtol=1e-8, atol=0)
        assert abs(polygon_area(pts[:-1])) == pytest.approx(bore.area, rel=1e-6)  # 20000 chords: ~1e-7


def test_annotation_is_plain_text(case, written):
    design, _, fit = case
    doc = read_back(written[0])
    assert len(doc.modelspace().query("DIMENSION MTEXT INSERT")) == 0
    texts = [e.dxf.text for e in doc.modelspace().query('TEXT[layer=="ANNOTATION"]')]
    joined = "\n".join(texts)
    assert design.cam.name in joined
    assert f"base radius {design.cam.base_radius:.3f} mm" in joined
    assert design.follower.kind.word in joined
    for seg in design.motion:
        if seg.law is not None:
            assert seg.law.describe() in joined
    assert f"fit tolerance {fit.tolerance:.4g} mm" in joined
    assert all(t.isascii() for t in texts)


def test_centre_lines_and_pitch_curve(case, written):
    design, cam, _ = case
    msp = read_back(written[0]).modelspace()
    lines = msp.query('LINE[layer=="CENTER"]')
    assert len(lines) == 2
    assert all(line.dxf.start.isclose(-line.dxf.end) for line in lines)  # through the cam axis
    pitch = msp.query('*[layer=="PITCH_CURVE"]')
    if not cam.has_pitch_curve:
        assert len(pitch) == 0
        return
    # dashed by geometry: open degree-1 SPLINEs (OpenSCAD skips SPLINE; it closed open polylines into
    # slivers, issue 31), no closed outline a program could extrude
    assert {e.dxftype() for e in pitch} == {"SPLINE"}
    assert all(e.dxf.degree == 1 and not e.closed for e in pitch)
    dashes = [np.asarray(e.control_points)[:, :2] for e in pitch]
    assert not any(np.allclose(d[0], d[-1]) for d in dashes)
    exact = cam.pitch(np.linspace(0.0, 2.0 * math.pi, 400001)[:-1]).point
    pts = np.vstack(dashes)
    # every vertex (dash ends interpolated on chords) within the chord tolerance of the exact curve
    assert distance_to_polygon(pts, exact).max() <= design.dxf.chord_tolerance + 1e-6
    # dash and gap lengths: the ISO ratio, stretched evenly round the curve
    on = np.array([np.sum(np.linalg.norm(np.diff(d, axis=0), axis=1)) for d in dashes])
    gaps = np.linalg.norm(
        np.array([b[0] - a[-1] for a, b in zip(dashes, dashes[1:] + dashes[:1], strict=True)]), axis=1
    )
    period = on + gaps
    assert_allclose(period, period.mean(), rtol=1e-3)
    assert_allclose(on / period, PITCH_DASH / (PITCH_DASH + PITCH_GAP), rtol=1e-3)
    assert period.mean() == pytest.approx(PITCH_DASH + PITCH_GAP, rel=0.2)
    # together they follow the whole curve: largest and smallest radius reached
    radius = np.hypot(pts[:, 0], pts[:, 1])
    prime = design.cam.base_radius + design.follower.roller_radius
    assert radius.max() == pytest.approx(np.hypot(exact[:, 0], exact[:, 1]).max(), abs=0.05)
    # dash ends lie on chords: inside the curve by at most the chord tolerance
    assert radius.min() >= np.sqrt(prime**2 - design.follower.eccentricity**2) - design.dxf.chord_tolerance


def test_pitch_curve_and_annotation_can_be_switched_off(case):
    design, cam, fit = case
    design = replace(design, dxf=replace(design.dxf, pitch_curve=False, annotate=False))
    msp = profile_document(cam=cam, fit=fit, **writer_options(design)).modelspace()
    assert len(msp.query('*[layer=="PITCH_CURVE"]')) == 0
    assert len(msp.query('*[layer=="ANNOTATION"]')) == 0


def test_polyline_dxf_holds_bulge_free_closed_contours_within_chord_tolerance(case, written):
    design, _, fit = case
    msp = read_back(written[1]).modelspace()
    kinds = {e.dxftype() for e in msp}
    assert kinds == {"LWPOLYLINE"}
    layers = sorted(e.dxf.layer for e in msp)
    assert layers == (["BORE", "CAM_PROFILE"] if design.cam.bore > 0 else ["CAM_PROFILE"])
    for poly in msp:
        assert poly.closed
        assert not poly.has_arc  # all bulges 0
    profile = np.asarray(msp.query('LWPOLYLINE[layer=="CAM_PROFILE"]')[0].get_points("xy"))
    chord = design.dxf.chord_tolerance - fit.max_error  # issue 31: the fit's error is part of the budget
    assert_allclose(profile, flatten_bspline(fit.clamped, chord), rtol=0, atol=1e-12)
    # chord error, measured independently: spline points between vertices vs the polygon
    a, b = fit.clamped.domain
    dense = fit.clamped.evaluate(np.linspace(a, b, 200001)[:-1])
    dist = distance_to_polygon(dense, profile)
    assert dist.max() <= chord
    assert dist.max() >= 0.1 * chord  # not needlessly dense


def test_periodic_curve_is_refused_and_nothing_is_written(case, tmp_path):
    design, cam, fit = case
    bad = replace(fit, clamped=fit.curve)  # the periodic encoding
    with pytest.raises(ExportError, match="periodic"):
        write_profile_dxf(tmp_path / "profile.dxf", cam=cam, fit=bad, **writer_options(design))
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "order", [sorted, lambda types: sorted(types, reverse=True)], ids=["sorted", "reversed"]
)
def test_the_same_drawing_gives_the_same_bytes(case, tmp_path, monkeypatch, order):
    """No clock, no random GUID, and the CLASSES section does not follow ezdxf's set order."""
    design, cam, fit = case
    reference = write_profile_dxf(
        tmp_path / "one.dxf", cam=cam, fit=fit, **writer_options(design)
    ).read_bytes()
    in_use = EntityDB.dxf_types_in_use
    monkeypatch.setattr(EntityDB, "dxf_types_in_use", lambda self: order(in_use(self)))
    option = ezdxf.options.write_fixed_meta_data_for_testing
    again = write_profile_dxf(tmp_path / "two.dxf", cam=cam, fit=fit, **writer_options(design)).read_bytes()
    assert again == reference
    assert ezdxf.options.write_fixed_meta_data_for_testing == option  # the user's setting is restored
    lines = (tmp_path / "two.dxf").read_text().splitlines()  # raw: ezdxf replaces nil GUIDs when reading

    def header(name: str) -> str:  # a header variable is: name, group code, value
        return lines[lines.index(name) + 2]

    assert header("$FINGERPRINTGUID") == header("$VERSIONGUID") == "{00000000-0000-0000-0000-000000000000}"
    assert header("$TDCREATE") == header("$TDUPDATE")


def arc_points(entity, samples: int = 2000) -> np.ndarray:
    """Points along an ARC (counter-clockwise from its start angle) or a LINE, sampled here."""
    if entity.dxftype() == "LINE":
        a, b = np.asarray(entity.dxf.start)[:2], np.asarray(entity.dxf.end)[:2]
        return a + (b - a) * np.linspace(0.0, 1.0, samples)[:, None]
    c, r = np.asarray(entity.dxf.center)[:2], entity.dxf.radius
    a0, a1 = math.radians(entity.dxf.start_angle), math.radians(entity.dxf.end_angle)
    t = a0 + np.mod(a1 - a0, 2.0 * math.pi) * np.linspace(0.0, 1.0, samples)
    return c + r * np.column_stack((np.cos(t), np.sin(t)))


def chain(entities) -> list[np.ndarray]:
    """ARC/LINE entities as point runs ordered end to start, each oriented to follow its neighbour."""
    runs = [arc_points(e) for e in entities]
    ordered = [runs.pop(0)]
    while runs:
        tail = ordered[-1][-1]
        k = int(np.argmin([min(np.linalg.norm(r[0] - tail), np.linalg.norm(r[-1] - tail)) for r in runs]))
        run = runs.pop(k)
        ordered.append(run if np.linalg.norm(run[0] - tail) <= np.linalg.norm(run[-1] - tail) else run[::-1])
    return ordered


def test_arcs_dxf_holds_tangent_arcs_within_the_fit_tolerance(case, written):
    """Two-way distance to the exact profile, G1 joints, and the area the arcs enclose."""
    design, cam, fit = case
    msp = read_back(written[2]).modelspace()
    assert {e.dxftype() for e in msp} <= {"ARC", "LINE", "CIRCLE"}
    assert {e.dxf.layer for e in msp} == ({"CAM_PROFILE", "BORE"} if design.cam.bore > 0 else {"CAM_PROFILE"})
    profile = [e for e in msp if e.dxf.layer == "CAM_PROFILE"]
    assert 8 <= len(profile) <= 400
    runs = chain(profile)

    # closed, every joint shared and tangent (G1)
    def tangent(run: np.ndarray, at_end: bool) -> np.ndarray:
        """Exact unit tangent at a run's end (or start), along the run: ⟂ to the radius of its circle."""
        i, j = (-1, -2) if at_end else (0, 1)
        chord = (run[i] - run[j]) if at_end else (run[j] - run[i])
        mid = run[len(run) // 2]
        # the circle through the run's ends and middle (a line when they are collinear)
        (x1, y1), (x2, y2), (x3, y3) = run[0], mid, run[-1]
        d = 2.0 * (x1 * (y2 - y3) + x2 * (y3 - y1) + x3 * (y1 - y2))
        if abs(d) < 1e-12:
            return chord / np.linalg.norm(chord)
        ux = ((x1**2 + y1**2) * (y2 - y3) + (x2**2 + y2**2) * (y3 - y1) + (x3**2 + y3**2) * (y1 - y2)) / d
        uy = ((x1**2 + y1**2) * (x3 - x2) + (x2**2 + y2**2) * (x1 - x3) + (x3**2 + y3**2) * (x2 - x1)) / d
        radial = run[i] - (ux, uy)
        t = np.array([-radial[1], radial[0]]) / np.linalg.norm(radial)
        return t if np.dot(t, chord) > 0 else -t

    for a, b in zip(runs, runs[1:] + runs[:1], strict=True):
        assert np.linalg.norm(a[-1] - b[0]) <= 1e-9
        ta, tb = tangent(a, True), tangent(b, False)
        assert abs(math.atan2(ta[0] * tb[1] - ta[1] * tb[0], float(np.dot(ta, tb)))) <= 1e-6  # G1
    pts = np.vstack([r[:-1] for r in runs])
    exact = cam.profile(np.linspace(0.0, 2.0 * math.pi, 400001)[:-1]).point
    tol = fit.tolerance
    assert distance_to_polygon(pts, exact).max() <= tol  # arcs → exact curve
    assert distance_to_polygon(exact[::20], pts).max() <= tol + 1e-6  # exact curve → arcs (sampled chords)
    # the enclosed area: polygon of the dense arc samples plus the chord-sagitta correction, vs the spline's
    area = abs(polygon_area(pts))
    assert area == pytest.approx(abs(bspline_area(fit.clamped)), abs=2.0 * tol * bspline_length(fit.clamped))


def test_arcs_dxf_bore_is_exact(case, written):
    design, _, _ = case
    msp = read_back(written[2]).modelspace()
    bore = BoreOutline.from_cam_spec(design.cam.bore, design.cam.keyway_width, design.cam.keyway_depth)
    entities = [e for e in msp if e.dxf.layer == "BORE"]
    if bore is None:
        assert entities == []
    elif not bore.has_keyway:
        assert [e.dxftype() for e in entities] == ["CIRCLE"]
        assert entities[0].dxf.radius == bore.radius
    else:
        assert sorted(e.dxftype() for e in entities) == ["ARC", "LINE", "LINE", "LINE"]
        outline = np.vstack([r[:-1] for r in chain(entities)])
        arc = next(e for e in entities if e.dxftype() == "ARC")
        assert arc.dxf.radius == bore.radius
        # the sampled arc's 1999 chords cut off (r²/2)(Δ − sin Δ) each: add it back
        sweep = math.radians(np.mod(arc.dxf.end_angle - arc.dxf.start_angle, 360.0))
        delta = sweep / 1999
        segments = 1999 * 0.5 * bore.radius**2 * (delta - math.sin(delta))
        assert abs(polygon_area(outline)) + segments == pytest.approx(bore.area, rel=1e-12)


@pytest.mark.parametrize("index", [0, 1, 2], ids=["profile", "poly", "arcs"])
def test_extents_limits_and_view_frame_the_drawing(case, written, index):
    """$EXTMIN/$EXTMAX against ezdxf's own bounding box of the entities (text excluded: no font metrics)."""
    from ezdxf import bbox

    doc = read_back(written[index])
    lo, hi = np.asarray(doc.header["$EXTMIN"])[:2], np.asarray(doc.header["$EXTMAX"])[:2]
    shapes = bbox.extents(e for e in doc.modelspace() if e.dxftype() != "TEXT" and e.dxf.layer != "FRAME")
    frame = doc.modelspace().query('SPLINE[layer=="FRAME"]')  # the sheet's margin in profile.dxf: the extents
    if index == 0:
        corners = np.asarray(frame[0].control_points)[:, :2]
        assert_allclose(corners.min(axis=0), lo, atol=1e-9)
        assert_allclose(corners.max(axis=0), hi, atol=1e-9)
    else:
        assert len(frame) == 0
    assert np.all(lo <= np.asarray(shapes.extmin)[:2] + 1e-6)
    assert np.all(hi >= np.asarray(shapes.extmax)[:2] - 1e-6)
    if index > 0:  # cutting files: the contours' box, within the chord tolerance, plus the print margin
        assert_allclose(lo, np.asarray(shapes.extmin)[:2] - EXTENTS_MARGIN, atol=0.01)
        assert_allclose(hi, np.asarray(shapes.extmax)[:2] + EXTENTS_MARGIN, atol=0.01)
    assert np.all(np.abs(np.concatenate((lo, hi))) < 1e4)  # not ezdxf's ±1e20 defaults
    assert_allclose(doc.header["$LIMMIN"], lo)
    assert_allclose(doc.header["$LIMMAX"], hi)
    view = doc.viewports.get("*Active")[0]
    centre, height = np.asarray(view.dxf.center)[:2], view.dxf.height
    assert_allclose(centre, 0.5 * (lo + hi), atol=1e-9)
    assert hi[1] - lo[1] < height <= hi[1] - lo[1] + 20.0  # the whole drawing, not a 1000 mm window


def test_no_file_holds_construction_geometry_as_a_closed_outline(written):
    """What a program extruding every closed contour (OpenSCAD) would take: only the part's contours."""
    for path in written:
        msp = read_back(path).modelspace()
        closed = [e for e in msp.query("LWPOLYLINE POLYLINE CIRCLE") if e.dxftype() == "CIRCLE" or e.closed]
        assert {e.dxf.layer for e in closed} <= {"CAM_PROFILE", "BORE"}


@pytest.mark.parametrize(
    "build", [profile_document, profile_poly_document, profile_arcs_document], ids=["profile", "poly", "arcs"]
)
def test_every_dxf_is_the_same_bytes_twice(case, tmp_path, build):
    from camcad.export._ezdxf import save_reproducible

    design, cam, fit = case
    paths = []
    for name in ("a.dxf", "b.dxf"):
        save_reproducible(build(cam=cam, fit=fit, **writer_options(design)), tmp_path / name)
        paths.append(tmp_path / name)
    assert paths[0].read_bytes() == paths[1].read_bytes()
