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


def _fd(curve, phi, h=1e-3):
    """dP/dφ and d²P/dφ² of a curve's points by five-point central differences [mm/rad, mm/rad²]."""
    f = {k: curve(phi + k * h).point for k in (-2, -1, 0, 1, 2)}
    d1 = (f[-2] - 8 * f[-1] + 8 * f[1] - f[2]) / (12 * h)
    d2 = (-f[-2] + 16 * f[-1] - 30 * f[0] + 16 * f[1] - f[2]) / (12 * h**2)
    return d1, d2


def _turning(points):
    """+1 when a closed polygon runs counter-clockwise, −1 clockwise (the sign of its shoelace area)."""
    x, y = points.T
    return float(np.sign(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)))


def _away_from_joints(cam, phi, margin=3e-3):
    """Samples at least ``margin`` rad from every breakpoint, where derivatives may jump."""
    gaps = [np.remainder(phi - bp.phi + math.pi, 2 * math.pi) - math.pi for bp in cam.program.breakpoints]
    return np.min(np.abs(gaps), axis=0) > margin


@given(designs)
@settings(max_examples=40, deadline=None)
def test_contact_point_is_one_roller_radius_along_the_inward_normal(d):
    """The roller centre is where the follower puts it, and the profile is its envelope.

    Independent truths: the kinematic inversion of the roller centre, which
    stands at (e, k + s) in the machine frame with k = √((r_b + r_f)² − e²),
    turned by −φ into the frame of the ccw cam; and the tangents of the pitch
    curve and of the profile from finite differences of their points, with the
    outward side from the curve's sense of travel (shoelace).
    """
    cam = build(d)
    phi = np.linspace(0, 2 * math.pi, 181)
    pitch, prof = cam.pitch(phi), cam.profile(phi)
    m = cam.motion(phi)
    e, r = cam.eccentricity, cam.roller_radius
    k = math.sqrt((cam.base_radius + r) ** 2 - e**2)
    c, s = np.cos(phi), np.sin(phi)
    inverted = np.column_stack((c * e + s * (k + m.s), -s * e + c * (k + m.s)))
    assert_allclose(pitch.point, inverted, atol=1e-12 * (k + d["lift"]))

    gap = pitch.point - prof.point
    assert_allclose(np.hypot(*gap.T), r, rtol=1e-12)
    smooth = _away_from_joints(cam, phi)
    d1, _ = _fd(cam.pitch, phi[smooth])
    tangent = d1 / np.hypot(*d1.T)[:, None]
    outward = _turning(pitch.point) * np.column_stack((tangent[:, 1], -tangent[:, 0]))
    assert_allclose(gap[smooth] / r, outward, atol=1e-7)
    # the profile's tangent is perpendicular to that normal: the envelope touches the roller
    ok = smooth & (np.abs(pitch.rho) > r * 1.01)
    p1, _ = _fd(cam.profile, phi[ok])
    cross = p1[:, 0] * gap[ok, 0] + p1[:, 1] * gap[ok, 1]
    assert_allclose(cross / np.hypot(*p1.T) / r, 0.0, atol=1e-7)


@given(designs)
@settings(max_examples=40, deadline=None)
def test_pressure_angle_is_quang_eq_4_and_offset_curvature_is_that_of_its_points(d):
    """α against Quang & Hung 2015, eq. 4; ρ of the profile and of an offset against their points.

    The curvature κ = (x′y″ − y′x″)/|P′|³ of the returned points themselves,
    differenced in φ, signed by the curve's sense of travel so that convex is
    positive; compared as 1/ρ, which stays finite through an inflection. Where
    the offset runs against the pitch curve (the loop of an undercut) its ρ is
    negative by convention although the points turn the convex way.
    """
    cam = build(d)
    phi = np.linspace(0, 2 * math.pi, 181)
    m = cam.motion(phi)
    e = cam.eccentricity
    k = math.sqrt((cam.base_radius + cam.roller_radius) ** 2 - e**2)
    assert_allclose(cam.pressure_angle(phi), np.arctan((m.v - e) / (m.s + k)), atol=1e-12)
    turning = _turning(cam.pitch(phi).point)
    smooth = phi[_away_from_joints(cam, phi)]
    c1, _ = _fd(cam.pitch, smooth)
    for distance in (0.0, 3.0):
        off = cam.offset_curve(smooth, distance)
        p1, p2 = _fd(lambda x, dist=distance: cam.offset_curve(x, dist), smooth)
        forward = np.sign(np.sum(p1 * c1, axis=1))
        speed = np.hypot(*p1.T)
        kappa = forward * turning * (p1[:, 0] * p2[:, 1] - p1[:, 1] * p2[:, 0]) / speed**3
        ok = speed > 1e-2 * cam.base_radius  # not at a cusp of an undercut offset
        assert_allclose(1.0 / off.rho[ok], kappa[ok], rtol=1e-4, atol=1e-5 / cam.base_radius)


@given(designs, st.floats(0.0, 2 * math.pi))
@settings(max_examples=30, deadline=None)
def test_offset_curve_derivative_matches_its_points(d, phi0):
    """d1 and d2 of the offset curve are the φ-derivatives of its points and of d1 (h = 1e-5)."""
    cam = build(d)
    assume(all(abs(math.remainder(phi0 - bp.phi, 2 * math.pi)) > 1e-3 for bp in cam.program.breakpoints))
    h = 1e-5
    pts = cam.offset_curve(np.array([phi0 - h, phi0 + h]), 4.0).point
    here = cam.offset_curve(np.array([phi0]), 4.0)
    assert_allclose((pts[1] - pts[0]) / (2 * h), here.d1[0], rtol=1e-6, atol=1e-6)
    d1 = cam.offset_curve(np.array([phi0 - h, phi0 + h]), 4.0).d1
    assert_allclose((d1[1] - d1[0]) / (2 * h), here.d2[0], rtol=1e-5, atol=1e-5)
