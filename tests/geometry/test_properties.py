"""Laws of the envelope that hold for every design (hypothesis)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from camcad.geometry import Cam
from tests.conftest import make_design

LAWS = ["harmonic", "cycloidal", "poly-345", "poly-4567", "modified-sine", "modified-trapezoid"]

designs = st.builds(
    dict,
    law=st.sampled_from(LAWS),
    base_radius=st.floats(20.0, 120.0),
    roller_radius=st.floats(2.0, 25.0),
    offset_frac=st.floats(-0.6, 0.6),
    lift=st.floats(1.0, 40.0),
    rise=st.floats(60.0, 200.0),
)


def build(d: dict) -> Cam:
    rise = d["rise"]
    rest = 360.0 - rise
    spans = (rise, rest * 0.25, rest * 0.5, rest * 0.25)
    offset = d["offset_frac"] * d["base_radius"]
    design = make_design(
        law=d["law"],
        base_radius=d["base_radius"],
        roller_radius=d["roller_radius"],
        offset=offset,
        lift=d["lift"],
        spans=spans,
    )
    return Cam.from_design(design)


@given(designs)
@settings(max_examples=40, deadline=None)
def test_contact_point_is_one_roller_radius_along_the_inward_normal(d):
    cam = build(d)
    phi = np.linspace(0, 2 * math.pi, 181)
    pitch, prof = cam.pitch(phi), cam.profile(phi)
    gap = pitch.point - prof.point
    assert_allclose(np.hypot(*gap.T), cam.roller_radius, rtol=1e-12)
    assert_allclose(gap / cam.roller_radius, pitch.normal, atol=1e-12)
    # the profile's own tangent is perpendicular to that normal (an envelope touches the roller)
    ok = np.abs(pitch.rho) > cam.roller_radius * 1.01
    cross = prof.d1[:, 0] * gap[:, 0] + prof.d1[:, 1] * gap[:, 1]
    assert_allclose(cross[ok] / np.hypot(*prof.d1[ok].T) / cam.roller_radius, 0.0, atol=1e-9)


@given(designs)
@settings(max_examples=40, deadline=None)
def test_pressure_angle_is_quang_eq_4_and_offsets_shift_curvature_exactly(d):
    cam = build(d)
    phi = np.linspace(0, 2 * math.pi, 181)
    m = cam.motion(phi)
    e = cam.eccentricity
    k = math.sqrt((cam.base_radius + cam.roller_radius) ** 2 - e**2)
    assert_allclose(cam.pressure_angle(phi), np.arctan((m.v - e) / (m.s + k)), atol=1e-12)
    for distance in (0.0, 3.0):
        off = cam.offset(phi, distance)
        assert_allclose(off.rho, cam.pitch(phi).rho - cam.roller_radius + distance, rtol=1e-12)


@given(designs, st.floats(0.0, 2 * math.pi))
@settings(max_examples=30, deadline=None)
def test_offset_curve_derivative_matches_its_points(d, phi0):
    """d1 and d2 of the offset curve are the φ-derivatives of its points and of d1 (h = 1e-5)."""
    cam = build(d)
    assume(all(abs(math.remainder(phi0 - bp.phi, 2 * math.pi)) > 1e-3 for bp in cam.program.breakpoints))
    h = 1e-5
    pts = cam.offset(np.array([phi0 - h, phi0 + h]), 4.0).point
    here = cam.offset(np.array([phi0]), 4.0)
    assert_allclose((pts[1] - pts[0]) / (2 * h), here.d1[0], rtol=1e-6, atol=1e-6)
    d1 = cam.offset(np.array([phi0 - h, phi0 + h]), 4.0).d1
    assert_allclose((d1[1] - d1[0]) / (2 * h), here.d2[0], rtol=1e-5, atol=1e-5)
