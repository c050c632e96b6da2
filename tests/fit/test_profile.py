"""Tolerance-driven profile fit: certificate checked by independent dense evaluation.

Synthetic cams stand in for camcad.geometry: a radial profile r(φ) = 40 + s(φ)
with a 12 mm rise over 150°, dwell 30°, return 150°, dwell 30°. The
cycloidal law has jerk jumps at the joints (profile C², simple knots); the
harmonic law has acceleration jumps (profile C¹, double knots).
"""

from dataclasses import dataclass

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.spatial import cKDTree

from camcad.errors import FitError
from camcad.fit import ProfileFit, fit_points, fit_profile, to_geomdl

DEG = np.pi / 180
TOL = 1e-3
PHI = np.arange(3600) * 2 * np.pi / 3600
RISE, BETA, BASE = 12.0, 150 * DEG, 40.0


def rise_fraction(x, law):
    if law == "cycloidal":
        return x - np.sin(2 * np.pi * x) / (2 * np.pi)
    return 0.5 * (1 - np.cos(np.pi * x))


def lift(phi, law):
    phi = np.mod(phi, 2 * np.pi)
    s = np.zeros_like(phi)
    up = phi < BETA
    top = (phi >= BETA) & (phi < 180 * DEG)
    down = (phi >= 180 * DEG) & (phi < 330 * DEG)
    s[up] = RISE * rise_fraction(phi[up] / BETA, law)
    s[top] = RISE
    s[down] = RISE * (1 - rise_fraction((phi[down] - 180 * DEG) / BETA, law))
    return s


def cam_exact(law):
    def exact(phi):
        r = BASE + lift(phi, law)
        return np.column_stack((r * np.cos(phi), r * np.sin(phi)))

    return exact


def cam_breaks(law):
    k = 2 if law == "cycloidal" else 1
    return [(a * DEG, k) for a in (0.0, 150.0, 180.0, 330.0)]


def circle(phi, radius=30.0):
    return radius * np.column_stack((np.cos(phi), np.sin(phi)))


def ellipse(phi):
    return np.column_stack((50 * np.cos(phi), 20 * np.sin(phi)))


def polyline_distance(curve, points, n=300_000):
    """Distance from points to a dense polyline of ``curve`` (scipy evaluation, exact segments)."""
    a, b = curve.domain
    verts = curve.evaluate(np.linspace(a, b, n))
    tree = cKDTree(verts)
    _, near = tree.query(points, k=3)
    best = np.full(len(points), np.inf)
    for j in range(3):
        for step in (-1, 0):
            i0 = np.clip(near[:, j] + step, 0, n - 2)
            p0, p1 = verts[i0], verts[i0 + 1]
            d = p1 - p0
            w = np.clip(np.einsum("ij,ij->i", points - p0, d) / np.einsum("ij,ij->i", d, d), 0, 1)
            best = np.minimum(best, np.hypot(*(p0 + w[:, None] * d - points).T))
    return best


def fit_cam(law):
    exact = cam_exact(law)
    return law, exact, fit_profile(PHI, exact(PHI), exact=exact, breakpoints=cam_breaks(law))


@pytest.fixture(scope="module")
def cycloidal():
    return fit_cam("cycloidal")


@pytest.fixture(scope="module")
def harmonic():
    return fit_cam("harmonic")


@pytest.fixture(params=["cycloidal", "harmonic"])
def cam(request):
    return request.getfixturevalue(request.param)


def test_circle_radius_error_below_tolerance_everywhere():
    fit = fit_profile(PHI, circle(PHI), exact=circle, tolerance=TOL)
    assert fit.max_error <= TOL
    for curve in (fit.curve, fit.clamped):
        radius = np.hypot(*curve.evaluate(np.linspace(*curve.domain, 200_001)).T)
        assert np.max(np.abs(radius - 30.0)) <= TOL
    u = np.linspace(0.0, 1.0, 200_001)
    assert np.max(np.abs(np.hypot(*fit.curve.evaluate(u).T) - 30.0)) == pytest.approx(fit.max_error, rel=0.02)


def test_cam_reported_error_is_below_tolerance(cam):
    _, _, fit = cam
    assert 0.0 < fit.rms_error <= fit.max_error <= TOL


def test_cam_error_agrees_with_independent_dense_check(cam):
    # 10 exact points per sample interval against a 300k-vertex polyline of the export form
    _, exact, fit = cam
    dense = np.arange(36_000) * 2 * np.pi / 36_000
    dist = polyline_distance(fit.clamped, exact(dense))
    assert dist.max() <= TOL
    assert dist.max() == pytest.approx(fit.max_error, abs=0.03 * TOL)


def test_cycloidal_cam_meets_the_control_point_target(cycloidal):
    _, _, fit = cycloidal
    assert fit.control_point_count <= 27


def test_seam_is_smooth_where_the_profile_is():
    for exact, breaks in [(circle, ()), (ellipse, ()), (cam_exact("cycloidal"), cam_breaks("cycloidal"))]:
        fit = fit_profile(PHI, exact(PHI), exact=exact, breakpoints=breaks)
        assert fit.seam_tangent_jump < 1e-9
        assert fit.seam_curvature_jump < 1e-9


def curvature(curve, u):
    d1, d2 = curve.evaluate(u, 1), curve.evaluate(u, 2)
    return (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.hypot(*d1.T) ** 3


def test_harmonic_seam_is_smooth_and_keeps_off_the_profiles_curvature_jump(harmonic):
    _, exact, fit = harmonic
    assert fit.seam_tangent_jump < 1e-9
    assert fit.seam_curvature_jump < 1e-9
    # the clamped form opens mid-rise (longest stretch 0°–150°), a quarter stretch from φ = 0 and 150°
    start = fit.clamped.evaluate(np.array([fit.clamped.domain[0]]))
    dense = np.arange(3600) * 2 * np.pi / 3600
    phi_start = dense[np.argmin(np.hypot(*(exact(dense) - start).T))]
    assert 37.5 * DEG <= phi_start <= 112.5 * DEG
    # φ = 0 joins dwell and rise; for r = R + s: κ = (r² + 2r'² − r r'')/(r² + r'²)^{3/2},
    # r' = 0 there, so Δκ = s''/R² with s'' = (h/2)(π/β)² (double knot: C1 curve). The
    # clamped form keeps that jump inside, at the curve's parameter of φ = 0.
    knots, counts = np.unique(fit.curve.knots, return_counts=True)
    assert counts[knots == 0.0] == 2
    u0 = 1.0 - fit.seam  # φ = 0 (u = 0 on the periodic curve) on the clamped form
    left, right = curvature(fit.clamped, np.array([u0 - 1e-9, u0 + 1e-9]))
    expected = 0.5 * RISE * (np.pi / BETA) ** 2 / BASE**2
    assert abs(right - left) == pytest.approx(expected, rel=0.05)


def test_clamped_and_periodic_forms_agree(cam):
    _, _, fit = cam
    assert fit.clamped.domain == (0.0, 1.0)
    assert 0.0 < fit.seam < 1.0
    v = np.linspace(0.0, 1.0, 20_001)
    assert_allclose(fit.clamped.evaluate(v), fit.curve.evaluate(v + fit.seam), rtol=0, atol=1e-9)
    # the same point set, also read from the periodic curve's side
    assert_allclose(fit.clamped.evaluate(np.mod(v - fit.seam, 1.0)), fit.curve.evaluate(v), rtol=0, atol=1e-9)
    assert np.array_equal(fit.clamped.control_points[0], fit.clamped.control_points[-1])
    assert fit.control_point_count == len(fit.clamped.control_points)


def test_geomdl_agrees_with_the_fit(cam):
    _, _, fit = cam
    crv = to_geomdl(fit.clamped)
    v = np.linspace(0.0, 1.0, 2001)
    theirs = np.array(crv.evaluate_list(v.tolist()))
    assert_allclose(theirs, fit.curve.evaluate(v + fit.seam), rtol=0, atol=1e-9)


def test_params_are_foot_points(cam):
    _, exact, fit = cam
    assert np.all(np.diff(fit.params) > 0)
    on_curve = fit.curve.evaluate(fit.params)
    assert np.max(np.hypot(*(on_curve - exact(PHI)).T)) <= fit.max_error + 1e-9
    on_clamped = fit.clamped.evaluate(fit.clamped_params)
    assert np.all((fit.clamped_params >= 0.0) & (fit.clamped_params < 1.0))
    assert_allclose(on_clamped, on_curve, rtol=0, atol=1e-9)


def test_double_knots_at_c1_breakpoints_save_control_points(harmonic):
    _, exact, with_knots = harmonic
    without = fit_profile(PHI, exact(PHI), exact=exact)
    assert without.max_error <= TOL
    assert with_knots.control_point_count < 0.8 * without.control_point_count


def test_unreachable_tolerance_raises_with_best_error():
    with pytest.raises(FitError, match="tolerance = 1e-09 mm") as info:
        fit_profile(PHI, ellipse(PHI), exact=ellipse, tolerance=1e-9, max_control_points=20)
    assert info.value.best_error > 1e-9
    assert info.value.control_point_count <= 20
    assert str(info.value).startswith("max_control_points: 20 ")


def test_between_sample_check_catches_what_the_samples_miss():
    # the exact profile bulges 2 µm between samples, which all lie on a circle
    def wavy(phi):
        r = 30.0 + 0.002 * np.sin(1800 * phi) ** 2
        return r[:, None] * np.column_stack((np.cos(phi), np.sin(phi)))

    assert np.max(np.abs(np.hypot(*wavy(PHI).T) - 30.0)) < 1e-12
    with pytest.raises(FitError) as info:
        fit_profile(PHI, wavy(PHI), exact=wavy, max_control_points=40)
    assert 0.0015 < info.value.best_error < 0.004


def test_fit_points_open_sine_arc():
    x = np.linspace(0.0, 100.0, 2000)
    pts = np.column_stack((x, 10 * np.sin(x / 10)))
    fit = fit_points(pts, closed=False)
    assert fit.max_error <= TOL
    assert not fit.curve.periodic
    assert fit.clamped is fit.curve
    assert_allclose(fit.curve.evaluate(np.array([0.0, 1.0])), pts[[0, -1]], atol=1e-12)
    assert fit.seam_tangent_jump == 0.0
    # independent: distance from the exact sine (also between samples) to a dense polyline
    xs = np.linspace(0.0, 100.0, 40_000)
    assert polyline_distance(fit.curve, np.column_stack((xs, 10 * np.sin(xs / 10)))).max() <= TOL


def test_fit_points_closed_drops_a_repeated_closing_point():
    pts = ellipse(np.linspace(0.0, 2 * np.pi, 1801))
    fit = fit_points(pts, closed=True)
    assert len(fit.params) == 1800
    assert fit.curve.periodic
    assert fit.max_error <= TOL
    assert fit.seam_curvature_jump < 1e-9


def test_sparse_samples_are_certified_between_samples():
    # 90 samples (Quang & Hung's worked case size): the error between samples dominates
    phi = np.arange(90) * 2 * np.pi / 90
    fit = fit_profile(phi, ellipse(phi), exact=ellipse, tolerance=0.01)
    assert fit.max_error <= 0.01
    dense = ellipse(np.linspace(0.0, 2 * np.pi, 20_000, endpoint=False))
    assert polyline_distance(fit.clamped, dense).max() <= 0.01


@pytest.mark.parametrize("degree", [2, 4])
def test_other_degrees(degree):
    fit = fit_profile(PHI, ellipse(PHI), exact=ellipse, degree=degree)
    assert fit.degree == degree
    assert fit.max_error <= TOL
    assert polyline_distance(fit.clamped, ellipse(np.linspace(0, 2 * np.pi, 20_000))).max() <= TOL


def test_breakpoints_may_be_motion_program_records():
    @dataclass(frozen=True)
    class Breakpoint:
        phi: float
        continuity: int

    exact = cam_exact("harmonic")
    records = [Breakpoint(phi, k) for phi, k in cam_breaks("harmonic")]
    a = fit_profile(PHI, exact(PHI), exact=exact, breakpoints=records)
    b = fit_profile(PHI, exact(PHI), exact=exact, breakpoints=cam_breaks("harmonic"))
    assert a.control_point_count == b.control_point_count
    assert_allclose(a.clamped.control_points, b.clamped.control_points, atol=0)


def test_result_is_frozen_and_read_only():
    fit = fit_profile(PHI, circle(PHI), exact=circle)
    assert isinstance(fit, ProfileFit)
    arrays = (
        fit.params,
        fit.curve.control_points,
        fit.curve.knots,
        fit.clamped.control_points,
        fit.clamped.knots,
    )
    for arr in arrays:
        assert not arr.flags.writeable
    with pytest.raises(AttributeError):
        fit.max_error = 0.0  # type: ignore[misc]
    summary = fit.summary()
    assert set(summary) == {"tolerance_mm", "max_error_mm", "rms_error_mm", "control_points", "degree"}
    assert summary["control_points"] == fit.control_point_count


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"phi": PHI[::-1]}, "increase"),
        ({"phi": PHI[:-1]}, "shape"),
        ({"tolerance": 0.0}, "tolerance"),
        ({"exact": lambda phi: circle(phi)[:-1]}, "exact"),
        ({"points": circle(PHI)[:, :1]}, "shape"),
    ],
    ids=["decreasing", "phi-shape", "tolerance", "exact-shape", "points-shape"],
)
def test_invalid_input_is_refused(kwargs, message):
    args = {"phi": PHI, "points": circle(PHI), "exact": circle} | kwargs
    with pytest.raises(ValueError, match=message):
        fit_profile(args.pop("phi"), args.pop("points"), **args)
