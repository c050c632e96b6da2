"""The translating curved-face (mushroom) follower against independent closed forms (issue 33).

A face of radius ρ_f whose centre C moves on a slide is, for the envelope, a
roller of radius ρ_f: its pitch curve is Quang & Hung 2015, eq. 2 (with the
erratum) with r_f = ρ_f, its pressure angle eq. 4, tan α = (σv − e)/(s + k).
The contact point lies where the common normal, through C and the velocity
pole I = (σv, 0) of the cam relative to the slide (Rothbart 2004, §6.3), cuts
the face: its angle off the slide's axis is δ = atan2(σv − e, k + s), so it
slides ρ_f·δ along the face from the apex, and ρ_f·sin δ across the axis.
"""

from __future__ import annotations

import math
import re
import struct
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from camcad.cli import main
from camcad.design import parse_design
from camcad.design.paths import path_of
from camcad.errors import DesignError
from camcad.geometry import Cam, analyse_geometry
from camcad.geometry.followers import FOLLOWER_TYPES
from tests.conftest import distance_to_polygon


def mushroom(
    *,
    face_radius: float = 40.0,
    offset: float = 0.0,
    base_radius: float = 30.0,
    rotation: str = "ccw",
    lift: float = 8.0,
    law: str = "cycloidal",
    follower: dict[str, Any] | None = None,
    extra: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """A rise–dwell–return–dwell design with a mushroom follower, as a TOML-like mapping."""
    data: dict[str, Any] = {
        "cam": {"name": "mushroom", "base_radius": base_radius, "rotation": rotation, "thickness": 8.0},
        "follower": {"type": "translating-mushroom", "face_radius": face_radius, "offset": offset}
        | (follower or {}),
        "motion": [
            {"kind": "rise", "angle": 120.0, "lift": lift, "law": law},
            {"kind": "dwell", "angle": 60.0},
            {"kind": "return", "angle": 120.0, "lift": lift, "law": law},
            {"kind": "dwell", "angle": 60.0},
        ],
    }
    for key, value in (extra or {}).items():
        data.setdefault(key, {}).update(value)
    return data


def closed_form(cam: Cam, phi: np.ndarray, face_radius: float) -> dict[str, np.ndarray]:
    """Pitch point, pressure angle and contact slide written out from the papers, not from camcad."""
    m = cam.motion(phi)
    e, sigma = cam.eccentricity, cam.sigma
    k = math.sqrt((cam.base_radius + face_radius) ** 2 - e**2)
    c, s = np.cos(sigma * phi), np.sin(sigma * phi)
    # R(−σφ)·(e, k + s): Quang & Hung 2015, eq. 2 (erratum) for σ = +1
    pitch = np.column_stack((c * e + s * (k + m.s), -s * e + c * (k + m.s)))
    delta = np.arctan2(sigma * m.v - e, k + m.s)  # Quang & Hung 2015, eq. 4 on a ccw cam
    return {
        "pitch": pitch,
        "alpha": delta,
        "slide": face_radius * delta,
        "across": face_radius * np.sin(delta),
    }


@pytest.mark.parametrize("rotation", ["ccw", "cw"])
@pytest.mark.parametrize("offset", [0.0, 7.5, -5.0])
def test_pitch_curve_is_the_rollers_with_the_face_radius(rotation, offset):
    """Against eq. 2 written out, and against a translating roller of radius ρ_f (a second follower)."""
    design = parse_design(mushroom(offset=offset, rotation=rotation))
    cam = Cam.from_design(design)
    phi = np.linspace(0.0, 2.0 * math.pi, 721, endpoint=False)
    want = closed_form(cam, phi, 40.0)
    assert_allclose(cam.pitch(phi).point, want["pitch"], rtol=0, atol=1e-10)
    roller = parse_design(
        mushroom(offset=offset, rotation=rotation)
        | {"follower": {"type": "translating-roller", "roller_radius": 40.0, "offset": offset}}
    )
    twin = Cam.from_design(roller)
    assert_allclose(cam.profile(phi).point, twin.profile(phi).point, rtol=0, atol=1e-12)
    assert_allclose(cam.profile(phi).rho, twin.profile(phi).rho, rtol=0, atol=1e-9)


def test_profile_is_tangent_to_every_face_circle_and_inside_none():
    """Brute force: the profile keeps exactly ρ_f from the face centre's path (an envelope, not a guess)."""
    cam = Cam.from_design(parse_design(mushroom(offset=6.0, face_radius=25.0)))
    profile = cam.profile(np.linspace(0.0, 2.0 * math.pi, 1441, endpoint=False)).point
    centres = closed_form(cam, np.linspace(0.0, 2.0 * math.pi, 20001, endpoint=False), 25.0)["pitch"]
    gap = np.min(np.hypot(*(profile[:, None, :] - centres[None, ::5, :]).transpose(2, 0, 1)), axis=1)
    assert gap.min() > 25.0 - 1e-3  # no face circle cuts into the cam
    assert gap.max() < 25.0 + 0.02  # and each profile point touches one (to the centres' sampling)


@pytest.mark.parametrize("rotation", ["ccw", "cw"])
@pytest.mark.parametrize("offset", [0.0, 7.5, -5.0])
def test_pressure_angle_and_the_contacts_slide_along_the_face(rotation, offset):
    cam = Cam.from_design(parse_design(mushroom(offset=offset, rotation=rotation)))
    phi = np.linspace(0.0, 2.0 * math.pi, 721, endpoint=False)
    want = closed_form(cam, phi, 40.0)
    assert_allclose(np.abs(cam.pressure_angle(phi)), np.abs(want["alpha"]), rtol=0, atol=1e-10)
    assert_allclose(cam.contact_offset(phi), want["slide"], rtol=0, atol=1e-9)
    # the contact point itself: ρ_f·sin δ across the slide's axis, ρ_f·cos δ below the face centre
    m = cam.motion(phi)
    k = math.sqrt((cam.base_radius + 40.0) ** 2 - offset**2)
    st_ = cam.state(phi)
    c, s = np.cos(cam.sigma * phi), np.sin(cam.sigma * phi)
    p = st_.profile.point
    machine = np.column_stack((c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]))
    assert_allclose(machine[:, 0] - offset, want["across"], rtol=0, atol=1e-9)
    assert_allclose(k + m.s - machine[:, 1], 40.0 * np.cos(want["alpha"]), rtol=0, atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(
    base_radius=st.floats(10.0, 80.0),
    face_radius=st.floats(5.0, 200.0),
    offset_share=st.floats(-0.5, 0.5),
    lift=st.floats(1.0, 15.0),
    rotation=st.sampled_from(["ccw", "cw"]),
)
def test_closed_forms_hold_for_any_mushroom(base_radius, face_radius, offset_share, lift, rotation):
    offset = offset_share * base_radius
    data = mushroom(
        face_radius=face_radius, offset=offset, base_radius=base_radius, lift=lift, rotation=rotation
    )
    cam = Cam.from_design(parse_design(data))
    phi = np.linspace(0.0, 2.0 * math.pi, 73, endpoint=False)
    want = closed_form(cam, phi, face_radius)
    scale = base_radius + face_radius + lift
    assert_allclose(cam.pitch(phi).point, want["pitch"], rtol=0, atol=1e-11 * scale)
    assert_allclose(cam.contact_offset(phi), want["slide"], rtol=0, atol=1e-10 * scale)
    assert_allclose(np.abs(cam.pressure_angle(phi)), np.abs(want["alpha"]), rtol=0, atol=1e-11)


def test_face_width_must_cover_the_contacts_slide():
    """The face needed is 2(max ρ_f|δ| + margin), δ the normal's angle off the axis, by dense sampling."""
    cam = Cam.from_design(parse_design(mushroom(offset=4.0)))
    dense = np.linspace(0.0, 2.0 * math.pi, 200_001)
    travel = float(np.max(np.abs(closed_form(cam, dense, 40.0)["slide"])))
    needed = 2.0 * (travel + 1.0)
    geo = analyse_geometry(
        cam, max_pressure_angle=math.radians(30.0), face_width=needed - 0.05, face_margin=1.0
    )
    assert geo.face_width_min == pytest.approx(needed, abs=1e-6)
    (found,) = [f for f in geo.findings if f.kind == "face width"]
    assert path_of(found.field) == "follower.face_width" and found.limit == pytest.approx(needed, abs=1e-6)
    wide = analyse_geometry(cam, max_pressure_angle=math.radians(30.0), face_width=needed + 0.05)
    assert not [f for f in wide.findings if f.kind == "face width"]


def test_its_contact_stress_radius_is_the_face_radius_and_it_slides():
    design = parse_design(mushroom(face_radius=55.0))
    assert design.dynamics_setup().roller_radius == 55.0  # Hertz: 1/R = 1/ρ_cam + 1/ρ_f
    kin = Cam.from_design(design).follower
    assert kin.contact_radius == 55.0 and not kin.rolls and kin.arm_direction is None
    assert dict(kin.rows())["face radius [mm]"] == 55.0


def test_the_loader_reads_its_keys_from_the_module():
    kind = FOLLOWER_TYPES["translating-mushroom"]
    design = parse_design(mushroom(face_radius=33.0, follower={"face_width": 20.0}))
    assert design.follower.kind is kind and design.follower.value("face_radius") == 33.0
    data = mushroom()
    del data["follower"]["face_radius"]
    with pytest.raises(DesignError, match=r"follower\.face_radius: is required for a translating-mushroom"):
        parse_design(data)
    with pytest.raises(
        DesignError, match=r"follower\.face_radius: 0.0 must be > 0 \(allowed: 0.001 to 10000 mm\)"
    ):
        parse_design(mushroom(face_radius=0.0))
    with pytest.raises(DesignError, match=r"follower\.roller_radius: applies to"):
        parse_design(mushroom(follower={"roller_radius": 5.0}))
    with pytest.raises(
        DesignError, match=r"follower\.offset: \|75\| must be smaller than base_radius \+ face_radius"
    ):
        parse_design(mushroom(offset=75.0, face_radius=40.0, base_radius=30.0))
    roller = mushroom() | {
        "follower": {"type": "translating-roller", "roller_radius": 5.0, "face_radius": 4.0}
    }
    with pytest.raises(
        DesignError, match=r"follower\.face_radius: applies to a translating-mushroom follower only"
    ):
        parse_design(roller)
    groove = mushroom(extra={"cam": {"style": "groove", "outer_radius": 150.0}})
    with pytest.raises(DesignError, match=r"cam\.style: a groove cam needs a roller follower"):
        parse_design(groove)


def _stl_triangles(data: bytes) -> np.ndarray:
    """(n, 3, 3) vertices of a binary STL, read with struct (the format's own layout)."""
    (count,) = struct.unpack_from("<I", data, 80)
    assert len(data) == 84 + 50 * count
    rows = [struct.unpack_from("<12f", data, 84 + 50 * i)[3:] for i in range(count)]
    return np.asarray(rows, dtype=float).reshape(count, 3, 3)


def test_a_mushroom_design_builds_every_output_and_checks(tmp_path, capsys):
    """DXF (ezdxf), STL (struct), STEP (its text) and G-code (its words) read back against the profile."""
    ezdxf = pytest.importorskip("ezdxf")
    source = tmp_path / "mushroom.toml"
    source.write_text(
        "[cam]\nname = 'mushroom'\nbase_radius = 30.0\nthickness = 8.0\nbore = 10.0\nspeed_rpm = 600.0\n"
        "[follower]\ntype = 'translating-mushroom'\nface_radius = 40.0\noffset = 3.0\nface_width = 30.0\n"
        "[[motion]]\nkind = 'rise'\nangle = 120.0\nlift = 8.0\nlaw = 'cycloidal'\n"
        "[[motion]]\nkind = 'dwell'\nangle = 60.0\n"
        "[[motion]]\nkind = 'return'\nangle = 120.0\nlift = 8.0\nlaw = 'cycloidal'\n"
        "[[motion]]\nkind = 'dwell'\nangle = 60.0\n"
        "[dynamics]\nfollower_mass = 0.2\nspring_rate = 20.0\nspring_preload = 200.0\n"
        "[gcode]\ntool_diameter = 6.0\n",
        encoding="utf-8",
    )
    assert main(["check", str(source)]) == 0
    assert "all design limits hold" in capsys.readouterr().out
    out = tmp_path / "out"
    assert main(["build", str(source), "-o", str(out), "-q"]) == 0
    names = {p.name for p in out.iterdir()}
    assert {"profile.dxf", "cam.stl", "cam.step", "cam.ngc", "report.html", "summary.json"} <= names
    cam = Cam.from_design(parse_design(mushroom(offset=3.0)))
    exact = cam.profile(np.linspace(0.0, 2.0 * math.pi, 20_000, endpoint=False)).point

    doc = ezdxf.readfile(out / "profile.dxf")
    (spline,) = doc.modelspace().query("SPLINE[layer=='CAM_PROFILE']")
    pts = np.array([(p.x, p.y) for p in spline.construction_tool().approximate(4000)])
    assert distance_to_polygon(pts, exact).max() < 2e-3

    tri = _stl_triangles((out / "cam.stl").read_bytes())
    radius = np.hypot(tri[..., 0], tri[..., 1])
    assert radius.max() == pytest.approx(np.hypot(*exact.T).max(), abs=0.02)
    assert tri[..., 2].min() == pytest.approx(0.0, abs=1e-6) and tri[..., 2].max() == pytest.approx(8.0)

    step = (out / "cam.step").read_text(encoding="ascii")
    assert step.startswith("ISO-10303-21;") and step.rstrip().endswith("END-ISO-10303-21;")
    assert "ADVANCED_BREP_SHAPE_REPRESENTATION" in step or "MANIFOLD_SOLID_BREP" in step

    blocks = (out / "cam.ngc").read_text(encoding="ascii").splitlines()
    xy = [
        (float(m.group(1)), float(m.group(2)))
        for b in blocks
        if re.match(r"G[0123]\b", b) and (m := re.search(r"X(-?[\d.]+) Y(-?[\d.]+)", b))
    ]
    ends = np.array(xy)
    near = ends[(np.hypot(*ends.T) > 20.0) & (np.hypot(*ends.T) < 60.0)]  # the finishing contour
    gap = distance_to_polygon(near, exact)
    assert gap.min() > 3.0 - 0.01  # the Ø6 tool's centre never comes nearer the cam than its radius
    assert np.isclose(gap, 3.0, atol=0.01).sum() > 15  # and the finishing contour runs at exactly 3 mm
