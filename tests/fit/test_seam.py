"""Seam of the clamped export form: inside the longest smooth stretch, no jumps added."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

import camcad
from camcad.fit import clamped_from_periodic, fit_cam_profile, to_geomdl
from camcad.fit.bspline import periodic_curve
from camcad.fit.certify import seam_jumps
from camcad.fit.seam import longest_stretch, seam_parameter
from camcad.geometry import Cam

DEG = np.pi / 180


def circular_distance(a, b):
    return np.abs(np.mod(a - b + np.pi, 2 * np.pi) - np.pi)


@pytest.mark.parametrize(
    ("breaks_deg", "expected_deg"),
    [
        ([0.0, 150.0, 240.0], (0.0, 150.0)),
        ([240.0, 0.0, 150.0], (0.0, 150.0)),
        ([30.0, 100.0, 200.0], (200.0, 390.0)),  # wraps past 2π
        ([-60.0, 45.0], (45.0, 300.0)),
        ([10.0], (10.0, 370.0)),
        ([0.0, 90.0, 180.0, 270.0, 360.0], (0.0, 90.0)),  # ties: the first; 360° is 0°
    ],
    ids=["harmonic", "unsorted", "wrapping", "negative", "single", "ties"],
)
def test_longest_stretch(breaks_deg, expected_deg):
    lo, hi = longest_stretch(np.radians(breaks_deg))
    assert_allclose(np.degrees([lo, hi]), expected_deg, atol=1e-12)


def test_no_breakpoints_no_stretch():
    assert longest_stretch([]) is None


def cubic(tau):
    rng = np.random.default_rng(1)
    return periodic_curve(np.asarray(tau), rng.normal(0.0, 10.0, (len(tau), 2)), 3)


def test_seam_parameter_prefers_a_simple_knot_near_the_middle():
    curve = cubic([0.0, 0.0, 0.3, 0.48, 0.55, 0.9])
    assert seam_parameter(curve, 0.25, 0.75) == 0.48  # exactly the knot: no new control point
    assert seam_parameter(curve, 0.525, 0.575) == 0.55


def test_seam_parameter_skips_multiple_knots_and_knots_outside_the_window():
    curve = cubic([0.0, 0.3, 0.6, 0.6, 0.9])
    assert seam_parameter(curve, 0.25, 0.75) == 0.3  # nearer 0.6 is double (C1 there): skipped
    curve = cubic([0.0, 0.1, 0.8, 0.8, 0.9])
    assert seam_parameter(curve, 0.25, 0.75) == pytest.approx(0.5, abs=1e-15)  # no simple knot inside


def test_seam_parameter_wraps():
    curve = cubic([0.0, 0.4, 0.5, 0.6])
    assert seam_parameter(curve, 0.95, 1.15) == 0.0  # the knot at 0 = 1 is nearest the middle 1.05
    assert seam_parameter(curve, -0.05, 0.05) == 0.0
    assert seam_parameter(curve, 1.05, 1.25) == pytest.approx(0.15, abs=1e-15)  # middle 1.15, no knot near


def test_seam_parameter_of_a_quadratic_is_never_a_knot():
    curve = periodic_curve(np.array([0.0, 0.2, 0.5, 0.8]), np.eye(4, 2), 2)
    assert seam_parameter(curve, 0.25, 0.75) == 0.5  # middle; the knot 0.5 is only C1


def test_seam_at_a_c1_knot_shows_the_jump_and_inside_a_stretch_does_not():
    # a cubic with a double knot at 0 (C1 there): opened there the seam shows the curve's own jump
    curve = cubic([0.0, 0.0, 0.2, 0.4, 0.6, 0.8])
    _, at_joint = seam_jumps(clamped_from_periodic(curve))
    assert at_joint > 1e-4
    tangent, inside = seam_jumps(clamped_from_periodic(curve, seam=seam_parameter(curve, 0.25, 0.75)))
    assert tangent < 1e-9
    assert inside < 1e-9


def test_shipped_samples_open_smoothly_away_from_breakpoints(sample_path):
    cam = Cam.from_design(camcad.load_design(sample_path))
    fit = fit_cam_profile(cam)
    assert fit.seam_tangent_jump < 1e-9
    assert fit.seam_curvature_jump < 1e-9
    clamped = fit.clamped
    p = clamped.degree
    assert clamped.domain == (0.0, 1.0)
    assert np.all(clamped.knots[: p + 1] == 0.0)
    assert np.all(clamped.knots[-p - 1 :] == 1.0)
    assert np.array_equal(clamped.control_points[0], clamped.control_points[-1])
    v = np.linspace(0.0, 1.0, 20_001)
    assert_allclose(clamped.evaluate(v), fit.curve.evaluate(v + fit.seam), rtol=0, atol=1e-9)
    theirs = np.array(to_geomdl(clamped).evaluate_list(v.tolist()))
    assert_allclose(theirs, clamped.evaluate(v), rtol=0, atol=1e-9)
    # the start point lies at least a quarter of the longest stretch from every breakpoint
    breaks = np.array([bp.phi for bp in cam.program.breakpoints])
    lo, hi = longest_stretch(breaks)
    phi = np.arange(36_000) * 2 * np.pi / 36_000
    start = clamped.evaluate(np.array([0.0]))
    phi_start = phi[np.argmin(np.hypot(*(np.asarray(cam.profile(phi).point) - start).T))]
    assert np.min(circular_distance(phi_start, breaks)) >= 0.25 * (hi - lo) - 0.05 * DEG
    assert np.min(circular_distance(phi_start, breaks)) >= 20 * DEG
