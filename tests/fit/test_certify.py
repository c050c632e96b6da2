"""Foot-point certificate and seam continuity, checked against scipy.optimize."""

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import minimize_scalar

from camcad.fit.bspline import clamped_from_periodic, clamped_knot_vector, lsq_periodic
from camcad.fit.certify import certify, normal_distance, project, seam_jumps
from camcad.fit.curve import BSplineCurve


@pytest.fixture(scope="module")
def ellipse_fit():
    t = np.arange(720) / 720
    phi = 2 * np.pi * t
    pts = np.column_stack((50 * np.cos(phi), 20 * np.sin(phi)))
    return t, lsq_periodic(t, pts, np.arange(16) / 16, 3)


def test_projection_matches_scalar_minimisation(ellipse_fit):
    _, fit = ellipse_fit
    rng = np.random.default_rng(2)
    u0 = np.sort(rng.random(40))
    normal = fit.curve.evaluate(u0, 1)[:, ::-1] * [1, -1]
    points = fit.curve.evaluate(u0) + rng.normal(0, 0.5, (40, 1)) * normal / np.hypot(*normal.T)[:, None]
    cert = project(fit.curve, points, u0 + rng.normal(0, 2e-3, 40))
    for i, p in enumerate(points):
        res = minimize_scalar(
            lambda u, p=p: float(np.hypot(*(fit.curve.evaluate(np.array([u]))[0] - p))),
            bounds=(u0[i] - 0.02, u0[i] + 0.02),
            method="bounded",
            options={"xatol": 1e-12},
        )
        assert cert.distance[i] == pytest.approx(res.fun, abs=1e-9)
    assert_allclose(cert.distance, np.abs(np.hypot(*(points - fit.curve.evaluate(cert.foot)).T)), atol=1e-12)


def test_normal_distance_is_first_order_projection(ellipse_fit):
    t, fit = ellipse_fit
    pts = np.column_stack((50 * np.cos(2 * np.pi * t), 20 * np.sin(2 * np.pi * t)))
    quick = normal_distance(fit.at_params, fit.tangent_at_params, pts)
    exact = project(fit.curve, pts, t).distance
    assert_allclose(quick, exact, atol=1e-3 * exact.max())


def test_certify_checks_between_samples(ellipse_fit):
    t, fit = ellipse_fit
    pts = fit.curve.evaluate(t)
    mids = fit.curve.evaluate(t + 0.5 / 720) + np.array([0.0, 1e-3])  # off the curve by up to 1 µm
    at_samples, between = certify(fit.curve, pts, t, mids)
    assert at_samples.max_error < 1e-12
    assert between is not None
    assert 0.3e-3 < between.max_error <= 1e-3 + 1e-12


def test_seam_jumps_vanish_for_the_clamped_form_of_a_periodic_curve(ellipse_fit):
    _, fit = ellipse_fit
    tangent, curvature = seam_jumps(clamped_from_periodic(fit.curve))
    assert tangent < 1e-12
    assert curvature < 1e-12


def test_seam_jumps_see_a_corner():
    # closed clamped square-ish curve: the seam is a 90° corner
    ctrl = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]])
    knots = clamped_knot_vector(np.array([0.5]), 3)
    tangent, _ = seam_jumps(BSplineCurve(degree=3, knots=knots, control_points=ctrl))
    assert tangent == pytest.approx(np.pi / 2, abs=1e-12)
