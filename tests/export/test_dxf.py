"""DXF export: read back with ezdxf.recover and compared by meaning, not bytes."""

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
from scipy.spatial import cKDTree

from camcad.design import Design
from camcad.errors import ExportError
from camcad.export._outline import flatten_bspline, polygon_area
from camcad.export.dxf import (
    profile_document,
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
def written(case, tmp_path_factory) -> tuple[Path, Path]:
    design, cam, fit = case
    folder = tmp_path_factory.mktemp("dxf")
    return (
        write_profile_dxf(folder / "profile.dxf", cam=cam, fit=fit, **writer_options(design)),
        write_profile_poly_dxf(folder / "profile_poly.dxf", cam=cam, fit=fit, **writer_options(design)),
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
    splines = doc.modelspace().query("SPLINE")
    assert len(splines) == 1
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
    elif not bore.has_keyway:
        assert [e.dxftype() for e in entities] == ["CIRCLE"]
        assert entities[0].dxf.radius == pytest.approx(design.cam.bore / 2.0, abs=1e-12)
    else:
        assert [e.dxftype() for e in entities] == ["LWPOLYLINE"]
        assert entities[0].closed
        outline = lwpolyline_outline(entities[0])
        assert_allclose(np.hypot(outline[4:, 0], outline[4:, 1]), bore.radius, rtol=0, atol=1e-12)
        assert polygon_area(outline) == pytest.approx(bore.area, abs=1e-5)  # ccw, exact arc


def test_annotation_is_plain_text(case, written):
    design, _, fit = case
    doc = read_back(written[0])
    assert len(doc.modelspace().query("DIMENSION MTEXT INSERT")) == 0
    texts = [e.dxf.text for e in doc.modelspace().query('TEXT[layer=="ANNOTATION"]')]
    joined = "\n".join(texts)
    assert design.cam.name in joined
    assert f"base radius {design.cam.base_radius:.3f} mm" in joined
    assert design.follower.kind.value in joined
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
    pitch = msp.query('LWPOLYLINE[layer=="PITCH_CURVE"]')
    if not cam.is_roller:
        assert len(pitch) == 0
        return
    assert len(pitch) == 1 and pitch[0].closed
    pts = np.asarray(pitch[0].get_points("xy"))
    exact = cam.pitch(cam.sample_phi()).point
    _, nearest = cKDTree(exact).query(pts)
    assert_allclose(pts, exact[nearest], rtol=0, atol=0.5)  # vertices lie on the pitch curve
    radius = np.hypot(pts[:, 0], pts[:, 1])
    prime = design.cam.base_radius + design.follower.roller_radius
    assert radius.max() == pytest.approx(np.hypot(exact[:, 0], exact[:, 1]).max(), abs=1e-3)
    assert radius.min() >= np.sqrt(prime**2 - design.follower.eccentricity**2) - 1e-9


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
    assert_allclose(profile, flatten_bspline(fit.clamped, design.dxf.chord_tolerance), rtol=0, atol=1e-12)
    # chord error, measured independently: spline points between vertices vs the polygon
    a, b = fit.clamped.domain
    dense = fit.clamped.evaluate(np.linspace(a, b, 200001)[:-1])
    dist = distance_to_polygon(dense, profile)
    assert dist.max() <= design.dxf.chord_tolerance
    assert dist.max() >= 0.1 * design.dxf.chord_tolerance  # not needlessly dense


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
