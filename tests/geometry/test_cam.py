"""Follower geometry against independent checks (000 eqs. 11–14, 002 eqs. 2–4, 003 eq. 27)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import minimize_scalar

from camcad.design import load_design, parse_design
from camcad.design.paths import path_of
from camcad.errors import UndercutError
from camcad.geometry import Cam, analyse_geometry, undercut_error
from tests.conftest import ROOT, make_design

LAWS = ["harmonic", "cycloidal", "poly-345", "poly-4567", "modified-sine"]


def pitch_002(cam: Cam, phi: np.ndarray) -> np.ndarray:
    """Quang & Hung 2015, eq. 2 with the erratum, written out independently."""
    m = cam.motion(phi)
    e, r = cam.eccentricity, cam.base_radius + cam.roller_radius
    k = math.sqrt(r**2 - e**2)
    x = (k + m.s) * np.sin(phi) + e * np.cos(phi)
    y = (k + m.s) * np.cos(phi) - e * np.sin(phi)
    return np.column_stack((x, y))


@pytest.mark.parametrize("offset", [0.0, 12.0, -8.0])
@pytest.mark.parametrize("law", ["cycloidal", "harmonic"])
def test_profile_is_the_envelope_at_roller_distance_from_the_pitch_curve(law, offset):
    """Each contact point lies r_f from the pitch curve, its nearest pitch point being P(φ).

    The distance to the pitch curve is found by minimising over an independent
    evaluation of 002 eq. 2, so a radial offset (the common bug) would fail.
    """
    cam = Cam.from_design(make_design(law=law, offset=offset, base_radius=45.0))
    phi = np.linspace(0.0, 2 * math.pi, 97, endpoint=False)
    contact = cam.profile(phi).point
    assert_allclose(pitch_002(cam, phi), cam.pitch(phi).point, atol=1e-12)
    for f, c in zip(phi, contact, strict=True):
        res = minimize_scalar(
            lambda t, c=c: float(np.hypot(*(pitch_002(cam, np.array([t]))[0] - c))),
            bounds=(f - 0.3, f + 0.3),
            method="bounded",
            options={"xatol": 1e-12},
        )
        assert abs(res.fun - cam.roller_radius) < 1e-9
        assert abs(res.x - f) < 1e-5


def test_every_pitch_point_is_a_roller_radius_from_the_profile_polygon():
    cam = Cam.from_design(make_design(law="cycloidal", offset=10.0))
    phi = cam.sample_phi()
    poly = cam.profile(phi).point
    seg_a, seg_b = poly, np.roll(poly, -1, axis=0)
    chord = np.hypot(*(seg_b - seg_a).T).max()
    pitch = cam.pitch(np.linspace(0, 2 * math.pi, 181)).point
    ab = seg_b - seg_a
    for p in pitch:
        t = np.clip(np.einsum("ij,ij->i", p - seg_a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
        d = np.hypot(*(seg_a + t[:, None] * ab - p).T).min()
        # the polygon's chords lie inside the convex arcs: within the sagitta of r_f
        assert abs(d - cam.roller_radius) <= chord**2 / 8 / 10.0 + 1e-9


def test_a_full_dwell_is_a_base_circle():
    for follower, extra in (
        ("translating-roller", {"roller_radius": 7.0, "offset": 5.0}),
        ("translating-flat", {}),
    ):
        design = parse_design(
            {
                "cam": {"base_radius": 33.0},
                "follower": {"type": follower, **extra},
                "motion": [{"kind": "dwell", "angle": 360}],
            }
        )
        cam = Cam.from_design(design)
        phi = np.linspace(0, 2 * math.pi, 50, endpoint=False)
        prof = cam.profile(phi)
        assert_allclose(np.hypot(*prof.point.T), 33.0, atol=1e-12)
        assert_allclose(prof.rho, 33.0, atol=1e-9)
        assert_allclose(np.einsum("ij,ij->i", prof.normal, prof.point) / 33.0, 1.0, atol=1e-12)


def test_quintero_case_spans_radii_40_to_70():
    design = load_design(ROOT / "samples" / "quintero_vap_b01.toml")
    geo = analyse_geometry(Cam.from_design(design), max_pressure_angle=design.cam.max_pressure_angle)
    summary = geo.summary()
    assert summary["profile_radius_min_mm"] == pytest.approx(40.0, abs=1e-12)
    assert summary["profile_radius_max_mm"] == pytest.approx(70.0, abs=1e-12)


def discrete_rho(points: np.ndarray) -> np.ndarray:
    """Signed circumradius of consecutive point triples (finite differences of points)."""
    a, b, c = np.roll(points, 1, axis=0), points, np.roll(points, -1, axis=0)
    ab, bc, ca = b - a, c - b, a - c
    cross = ab[:, 0] * bc[:, 1] - ab[:, 1] * bc[:, 0]
    la, lb, lc = (np.hypot(*v.T) for v in (ab, bc, ca))
    return -la * lb * lc / (2.0 * cross)  # clockwise traversal: convex is negative cross


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("follower", ["translating-roller", "translating-flat"])
def test_analytic_radius_of_curvature_matches_dense_finite_differences(law, follower):
    cam = Cam.from_design(make_design(law=law, follower=follower, offset=6.0, base_radius=60.0))
    phi = np.linspace(0, 2 * math.pi, 200_000, endpoint=False)
    for curve in (cam.pitch(phi), cam.profile(phi)):
        rho_fd = discrete_rho(curve.point)
        finite = np.abs(curve.rho) < 1e4
        # compare curvature (1/ρ) away from joints, where ρ may jump
        kappa, kappa_fd = 1 / curve.rho[finite], 1 / rho_fd[finite]
        near_joint = np.zeros(phi.size, dtype=bool)
        for bp in cam.program.breakpoints:
            near_joint |= np.abs(np.angle(np.exp(1j * (phi - bp.phi)))) < 1e-3
        ok = ~near_joint[finite]
        assert_allclose(kappa_fd[ok], kappa[ok], atol=1e-6)


@pytest.mark.parametrize("law", LAWS)
def test_radial_pressure_angle_matches_quintero_eq_14(law):
    cam = Cam.from_design(make_design(law=law))
    phi = np.linspace(0, 2 * math.pi, 721)
    pitch = cam.pitch(phi)
    r = pitch.point
    cos_alpha = np.einsum("ij,ij->i", r, pitch.normal) / np.hypot(*r.T)
    eq14 = np.arccos(np.clip(cos_alpha, -1.0, 1.0))  # 000 eq. 14
    assert_allclose(np.abs(cam.pressure_angle(phi)), eq14, atol=1e-7)


@pytest.mark.parametrize("offset", [-15.0, -5.0, 5.0, 20.0])
@pytest.mark.parametrize("law", LAWS)
def test_offset_pressure_angle_matches_quang_eq_4(law, offset):
    cam = Cam.from_design(make_design(law=law, offset=offset, base_radius=50.0, roller_radius=12.0))
    phi = np.linspace(0, 2 * math.pi, 721)
    m = cam.motion(phi)
    k = math.sqrt((50.0 + 12.0) ** 2 - offset**2)
    eq4 = np.arctan((m.v - offset) / (m.s + k))  # 002 eq. 4
    assert_allclose(cam.pressure_angle(phi), eq4, atol=1e-12)


def test_offset_sign_convention_puts_the_follower_at_plus_x():
    """e > 0: at φ = 0 the roller centre is at x = +e, and the rise's pressure angle drops."""
    plain = Cam.from_design(make_design(offset=0.0))
    shifted = Cam.from_design(make_design(offset=10.0))
    p0 = shifted.pitch(np.array([0.0])).point[0]
    assert p0[0] == pytest.approx(10.0)
    assert p0[1] == pytest.approx(math.sqrt(50.0**2 - 10.0**2))
    rise = np.radians(np.linspace(10, 140, 50))
    assert np.all(shifted.pressure_angle(rise) < plain.pressure_angle(rise))


def test_flat_follower_contact_offset_equals_pseudo_velocity():
    cam = Cam.from_design(make_design(law="cycloidal", follower="translating-flat", base_radius=50.0))
    phi = np.linspace(0, 2 * math.pi, 400, endpoint=False)
    m = cam.motion(phi)
    assert_allclose(cam.contact_offset(phi), m.v, atol=1e-12)
    # the contact point lies on the face line: its height along the follower axis is r_b + s
    c = cam.profile(phi).point
    axis = np.column_stack((np.sin(phi), np.cos(phi)))
    across = np.column_stack((np.cos(phi), -np.sin(phi)))
    assert_allclose(np.einsum("ij,ij->i", c, axis), 50.0 + m.s, atol=1e-12)
    assert_allclose(np.einsum("ij,ij->i", c, across), m.v, atol=1e-12)
    assert_allclose(cam.profile(phi).rho, 50.0 + m.s + m.a, atol=1e-12)


def test_hren_cam_has_no_cusp_and_a_narrow_face_is_a_hard_limit():
    """Issue 11.4: the face must cover r_m = |ds/dφ| (003 eq. 27) plus face_margin each side."""
    design = load_design(ROOT / "samples" / "hren_tappet.toml")
    cam = Cam.from_design(design)
    v = cam.motion(np.linspace(0, 2 * math.pi, 1_000_000, endpoint=False)).v  # dense, independent
    needed = 2 * (np.abs(v).max() + 1.5)
    for width, hard in ((needed - 0.01, True), (needed + 0.01, False)):
        geo = analyse_geometry(
            cam, max_pressure_angle=design.cam.max_pressure_angle, face_width=width, face_margin=1.5
        )
        assert geo.undercut is None
        assert geo.face_width_min == pytest.approx(needed, rel=1e-9)
        found = [f for f in geo.findings if f.kind == "face width"]
        assert bool(found) is hard
        if hard:
            assert found[0].hard and path_of(found[0].field) == "follower.face_width"
            assert f"face_width ≥ {math.ceil(needed * 100) / 100:.2f} mm" in found[0].message


def test_small_base_radius_gives_undercut_with_a_radius_that_works():
    design = make_design(
        law="cycloidal", base_radius=5.0, roller_radius=20.0, lift=15.0, spans=(90, 90, 90, 90)
    )
    cam = Cam.from_design(design)
    geo = analyse_geometry(cam, max_pressure_angle=math.radians(89))
    assert geo.undercut is not None
    err = undercut_error(geo)
    assert isinstance(err, UndercutError)
    start, end = (math.degrees(a) for a in err.phi_range)
    # the sharpest convex part of a cycloidal rise is past mid-rise, inside the rise,
    # and every flagged sample there has a convex pitch radius below the roller's
    assert 45.0 <= start < end <= 90.0
    inside = (geo.phi >= err.phi_range[0]) & (geo.phi <= err.phi_range[1])
    assert np.all((geo.pitch.rho[inside] > 0) & (geo.pitch.rho[inside] < 20.0))
    assert len(geo.undercut.ranges) == 2  # the return undercuts too
    assert "base_radius" in str(err) and "undercut" in str(err)
    fixed = Cam.from_design(design.with_base_radius(err.suggested_base_radius))
    assert analyse_geometry(fixed, max_pressure_angle=math.radians(89)).undercut is None
    # and it is the smallest such radius, to the 0.01 mm it is rounded to
    smaller = Cam.from_design(design.with_base_radius(err.suggested_base_radius - 0.02))
    assert analyse_geometry(smaller, max_pressure_angle=math.radians(89)).undercut is not None


def test_clockwise_rotation_is_the_mirror_image_of_the_mirrored_follower():
    """A cw cam with its follower at x = +e mirrors a ccw cam whose follower is at −e."""
    ccw = Cam.from_design(make_design(law="poly-345", offset=-7.0))
    cw = Cam.from_design(make_design(law="poly-345", offset=7.0, rotation="cw"))
    phi = np.linspace(0, 2 * math.pi, 300, endpoint=False)
    a, b = ccw.profile(phi), cw.profile(phi)
    assert_allclose(b.point, a.point * [-1, 1], atol=1e-12)
    assert_allclose(b.normal, a.normal * [-1, 1], atol=1e-12)
    assert_allclose(b.rho, a.rho, rtol=1e-12)
    assert_allclose(cw.pressure_angle(phi), ccw.pressure_angle(phi), atol=1e-12)


def test_pressure_angle_over_the_limit_is_a_warning_with_angles():
    cam = Cam.from_design(make_design(law="cycloidal", base_radius=20.0, roller_radius=5.0, lift=30.0))
    geo = analyse_geometry(cam, max_pressure_angle=math.radians(30))
    assert geo.undercut is None
    assert any(
        w.startswith("pressure angle reaches") and "°–" in w
        for w in (f.message for f in geo.findings if not f.hard)
    )
