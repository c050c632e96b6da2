"""Kernels of camcad.fit.bspline against scipy, dense least squares and geomdl."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.interpolate import BSpline

from camcad.fit.bspline import (
    basis_stages,
    chord_length_params,
    clamped_from_periodic,
    clamped_knot_vector,
    curve_derivatives,
    find_span,
    insert_knot,
    lsq_clamped,
    lsq_periodic,
    periodic_curve,
    periodic_knot_vector,
    to_geomdl,
)
from camcad.fit.curve import BSplineCurve


def random_periodic(rng, degree, n_knots, *, double=False):
    tau = np.sort(rng.random(n_knots))
    tau[0] = 0.0
    if double:
        tau[n_knots // 2] = tau[n_knots // 2 - 1]
    ctrl = rng.normal(0.0, 10.0, (n_knots, 2))
    return periodic_curve(tau, ctrl, degree)


CASES = [(2, 7, False), (3, 12, False), (3, 12, True), (4, 11, True), (5, 14, False), (3, 4, False)]
IDS = [f"p{p}-K{k}{'-double' if d else ''}" for p, k, d in CASES]


def test_chord_length_params_include_the_closing_chord():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert_allclose(chord_length_params(square, closed=True), [0.0, 0.25, 0.5, 0.75], atol=1e-15)
    assert_allclose(chord_length_params(square, closed=False), [0.0, 1 / 3, 2 / 3, 1.0], atol=1e-15)


def test_chord_length_params_reject_repeated_points():
    with pytest.raises(ValueError, match="coincide"):
        chord_length_params(np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 0.0]]), closed=False)


def test_periodic_knot_vector_extends_by_one_period():
    tau = np.array([0.0, 0.2, 0.2, 0.7])
    knots = periodic_knot_vector(tau, 3)
    assert_allclose(knots, [-0.8, -0.8, -0.3, 0.0, 0.2, 0.2, 0.7, 1.0, 1.2, 1.2, 1.7], atol=1e-15)


@pytest.mark.parametrize("degree", [1, 2, 3, 5])
def test_basis_matches_scipy_design_matrix(degree):
    rng = np.random.default_rng(degree)
    knots = clamped_knot_vector(np.sort(rng.random(9)), degree)
    m = len(knots) - degree - 1
    u = np.sort(rng.random(300))
    span = find_span(knots, degree, m, u)
    basis = basis_stages(knots, degree, u, span, lowest=degree)[-1]
    dense = np.zeros((len(u), m))
    for r in range(degree + 1):  # loop scatter, independent of the vectorised assembly
        dense[np.arange(len(u)), span - degree + r] = basis[r]
    assert_allclose(dense, BSpline.design_matrix(u, knots, degree).toarray(), atol=1e-14)
    assert_allclose(basis.sum(axis=0), 1.0, atol=1e-14)  # partition of unity


@pytest.mark.parametrize(("degree", "n_knots", "double"), CASES, ids=IDS)
def test_derivatives_match_scipy(degree, n_knots, double):
    curve = random_periodic(np.random.default_rng(n_knots), degree, n_knots, double=double)
    u = np.linspace(-0.3, 1.3, 777)  # wraps
    ours = curve_derivatives(curve, u, 2)
    scipy_curve = BSpline(curve.knots, curve.control_points, degree, extrapolate="periodic")
    for k in range(min(2, degree) + 1):
        theirs = scipy_curve.derivative(k)(u) if k else scipy_curve(u)
        assert_allclose(ours[k], theirs, atol=1e-9 * max(1.0, np.abs(ours[k]).max()))
        assert_allclose(curve.evaluate(u, k), theirs, atol=1e-9 * max(1.0, np.abs(ours[k]).max()))


@pytest.mark.parametrize("degree", [1, 2, 3, 5])
def test_clamped_evaluation_matches_scipy(degree):
    """BSplineCurve.evaluate (hand-written, no scipy.interpolate) against scipy's BSpline, ends included."""
    rng = np.random.default_rng(10 + degree)
    knots = clamped_knot_vector(np.sort(rng.random(7)), degree)
    ctrl = rng.normal(size=(len(knots) - degree - 1, 2))
    curve = BSplineCurve(degree=degree, knots=knots, control_points=ctrl)
    u = np.concatenate(([0.0, 1.0], knots[degree + 1 : -degree - 1], rng.random(199)))  # 208 values
    spline = BSpline(knots, curve.control_points, degree)
    for k in range(degree + 1):
        theirs = spline.derivative(k)(u) if k else spline(u)
        assert_allclose(curve.evaluate(u, k), theirs, rtol=1e-11, atol=1e-9)
    assert_allclose(curve.evaluate(u.reshape(2, -1)), spline(u).reshape(2, -1, 2), atol=1e-12)
    assert not np.any(curve.evaluate(u, degree + 1))  # beyond the degree every derivative is zero


@pytest.mark.parametrize(("degree", "n_knots", "double"), CASES, ids=IDS)
def test_lsq_periodic_matches_dense_least_squares(degree, n_knots, double):
    rng = np.random.default_rng(7)
    tau = np.sort(rng.random(n_knots))
    tau[0] = 0.0
    if double:
        tau[3] = tau[2]
    t = np.sort(rng.random(400))
    t[0] = 0.0
    data = rng.random((400, 2))
    fit = lsq_periodic(t, data, tau, degree)
    full = BSpline.design_matrix(t, periodic_knot_vector(tau, degree), degree).toarray()
    folded = full[:, :n_knots].copy()
    folded[:, :degree] += full[:, n_knots:]  # periodic basis N_j + N_{j+K}
    ref = np.linalg.lstsq(folded, data, rcond=None)[0]
    assert_allclose(fit.curve.control_points[:n_knots], ref, atol=1e-10)
    assert_allclose(fit.curve.control_points[n_knots:], ref[:degree], atol=1e-10)
    assert_allclose(fit.at_params, fit.curve.evaluate(t), atol=1e-12)
    assert_allclose(fit.tangent_at_params, fit.curve.evaluate(t, 1), atol=1e-10)


@pytest.mark.parametrize("degree", [2, 3, 4])
def test_lsq_clamped_interpolates_ends_and_matches_dense_least_squares(degree):
    rng = np.random.default_rng(3)
    t = np.sort(rng.random(300))
    t[0], t[-1] = 0.0, 1.0
    data = rng.random((300, 2))
    interior = np.sort(rng.random(6))
    fit = lsq_clamped(t, data, interior, degree)
    a = BSpline.design_matrix(t, clamped_knot_vector(interior, degree), degree).toarray()
    rhs = data - np.outer(a[:, 0], data[0]) - np.outer(a[:, -1], data[-1])
    ref = np.linalg.lstsq(a[:, 1:-1], rhs, rcond=None)[0]
    assert_allclose(fit.curve.control_points[1:-1], ref, atol=1e-10)
    assert_allclose(fit.curve.evaluate(np.array([0.0, 1.0])), data[[0, -1]], atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(u=st.floats(0.01, 0.99), times=st.integers(1, 3), seed=st.integers(0, 10_000))
def test_knot_insertion_keeps_the_curve(u, times, seed):
    rng = np.random.default_rng(seed)
    knots = clamped_knot_vector(np.sort(rng.random(5)), 3)
    ctrl = rng.normal(size=(len(knots) - 4, 2))
    new_knots, new_ctrl = insert_knot(knots, ctrl, 3, u, times)
    assert len(new_knots) == len(knots) + times
    assert len(new_ctrl) == len(ctrl) + times
    grid = np.linspace(0.0, 1.0, 501)
    before = BSplineCurve(degree=3, knots=knots, control_points=ctrl).evaluate(grid)
    after = BSplineCurve(degree=3, knots=new_knots, control_points=new_ctrl).evaluate(grid)
    assert_allclose(after, before, atol=1e-12)


def test_knot_insertion_beyond_degree_is_refused():
    knots = clamped_knot_vector(np.array([0.5, 0.5]), 3)
    with pytest.raises(ValueError, match="exceeds degree"):
        insert_knot(knots, np.zeros((6, 2)), 3, 0.5, 2)


@pytest.mark.parametrize(("degree", "n_knots", "double"), CASES, ids=IDS)
def test_clamped_form_is_the_same_closed_curve(degree, n_knots, double):
    periodic = random_periodic(np.random.default_rng(11), degree, n_knots, double=double)
    clamped = clamped_from_periodic(periodic)
    assert not clamped.periodic
    p = degree
    assert_allclose(clamped.knots[: p + 1], 0.0, atol=0)
    assert_allclose(clamped.knots[-p - 1 :], 1.0, atol=0)
    assert np.array_equal(clamped.control_points[0], clamped.control_points[-1])
    u = np.linspace(0.0, 1.0, 2001)
    assert_allclose(clamped.evaluate(u), periodic.evaluate(u), atol=1e-9)
    assert len(clamped.control_points) == n_knots + p  # simple seam knot: K + p


def seam_cases(curve):
    """Seams inside a span, at a simple knot, at the last knot and at a double knot (if any)."""
    p = curve.degree
    tau = curve.knots[p : len(curve.control_points)]
    values, counts = np.unique(tau, return_counts=True)
    cases = {"in-span": 0.5 * (tau[1] + tau[2]), "simple-knot": values[counts == 1][1], "last-knot": tau[-1]}
    if np.any(counts > 1):
        cases["double-knot"] = values[counts > 1][0]
    return cases


@pytest.mark.parametrize(("degree", "n_knots", "double"), CASES, ids=IDS)
def test_clamped_form_opened_anywhere_is_the_same_closed_curve(degree, n_knots, double):
    periodic = random_periodic(np.random.default_rng(11), degree, n_knots, double=double)
    p = degree
    for name, seam in seam_cases(periodic).items():
        clamped = clamped_from_periodic(periodic, seam=seam)
        assert clamped.domain == (0.0, 1.0), name
        assert np.all(clamped.knots[: p + 1] == 0.0), name
        assert np.all(clamped.knots[-p - 1 :] == 1.0), name
        assert np.all(np.diff(clamped.knots) >= 0.0), name
        assert len(clamped.knots) == len(clamped.control_points) + p + 1, name
        assert np.array_equal(clamped.control_points[0], clamped.control_points[-1]), name
        v = np.linspace(0.0, 1.0, 2001)
        assert_allclose(clamped.evaluate(v), periodic.evaluate(v + seam), atol=1e-9, err_msg=name)
        mult = int(np.count_nonzero(periodic.knots[p : len(periodic.control_points)] == seam))
        assert len(clamped.control_points) == n_knots + p + 1 - mult, name


def test_clamped_form_wraps_the_seam_into_the_domain():
    periodic = random_periodic(np.random.default_rng(4), 3, 9)
    inside = clamped_from_periodic(periodic, seam=0.3)
    for seam in (1.3, -0.7):
        other = clamped_from_periodic(periodic, seam=seam)
        assert_allclose(other.knots, inside.knots, atol=1e-15)
        assert_allclose(other.control_points, inside.control_points, atol=1e-12)
    at_one = clamped_from_periodic(periodic, seam=1.0)
    assert np.array_equal(at_one.control_points, clamped_from_periodic(periodic).control_points)


def test_clamped_form_of_a_clamped_curve_is_itself():
    knots = clamped_knot_vector(np.array([0.5]), 3)
    curve = BSplineCurve(degree=3, knots=knots, control_points=np.ones((5, 2)))
    assert clamped_from_periodic(curve) is curve


@pytest.mark.parametrize(("degree", "n_knots", "double"), CASES, ids=IDS)
def test_geomdl_agrees(degree, n_knots, double):
    periodic = random_periodic(np.random.default_rng(5), degree, n_knots, double=double)
    crv = to_geomdl(periodic)
    assert crv.degree == degree
    assert crv.knotvector[0] == 0.0
    assert crv.knotvector[-1] == 1.0
    u = np.linspace(0.0, 1.0, 401)
    theirs = np.array(crv.evaluate_list(u.tolist()))
    assert_allclose(theirs, periodic.evaluate(u), atol=1e-9)


@pytest.mark.parametrize(("degree", "n_knots", "double"), CASES, ids=IDS)
def test_geomdl_agrees_with_a_clamped_form_opened_inside(degree, n_knots, double):
    periodic = random_periodic(np.random.default_rng(5), degree, n_knots, double=double)
    seam = 0.5 * (periodic.knots[degree + 1] + periodic.knots[degree + 2])
    crv = to_geomdl(clamped_from_periodic(periodic, seam=seam))
    assert crv.knotvector[: degree + 1] == [0.0] * (degree + 1)
    assert crv.knotvector[-degree - 1 :] == [1.0] * (degree + 1)
    v = np.linspace(0.0, 1.0, 401)
    theirs = np.array(crv.evaluate_list(v.tolist()))
    assert_allclose(theirs, periodic.evaluate(seam + v), atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 60), w=st.integers(1, 6), cols=st.integers(1, 5), seed=st.integers(0, 2**32 - 1))
def test_band_cholesky_solve_matches_dense_solve(n, w, cols, seed):
    """The hand-written band Cholesky solve against numpy's dense LU solve, for any SPD band matrix."""
    from camcad.fit.bspline import _band_cholesky, _band_solve, _solve_spd_banded

    rng = np.random.default_rng(seed)
    half = np.tril(np.triu(rng.normal(size=(n, n)), -w), 0)  # lower band factor
    mat = half @ half.T + n * np.eye(n)  # SPD, bandwidth w
    rhs = rng.normal(size=(n, cols))
    dense = np.linalg.solve(mat, rhs)
    assert_allclose(_band_solve(_band_cholesky(mat, w), rhs), dense, rtol=1e-9, atol=1e-12)
    assert_allclose(_solve_spd_banded(mat, rhs, w), dense, rtol=1e-9, atol=1e-12)


def test_band_cholesky_refuses_an_indefinite_matrix():
    from camcad.fit.bspline import _band_cholesky

    with pytest.raises(np.linalg.LinAlgError, match="positive definite"):
        _band_cholesky(np.diag([1.0, -1.0, 1.0]), 1)


def test_large_periodic_fit_takes_the_band_path_and_matches_dense_least_squares():
    """A periodic fit beyond the dense cut-off (the band factor) against lstsq on the design matrix."""
    from camcad.fit.bspline import _DENSE_UP_TO

    k = _DENSE_UP_TO + 40
    tau = np.arange(k) / k
    params = (np.arange(8 * k) + 0.5) / (8 * k)
    points = np.column_stack((np.cos(2 * np.pi * params), np.sin(6 * np.pi * params)))
    fit = lsq_periodic(params, points, tau, 3)
    basis = np.zeros((params.size, k))
    for j in range(k):  # each periodic basis function as the curve of one unit control point
        ctrl = np.zeros((k, 2))
        ctrl[j, 0] = 1.0
        basis[:, j] = periodic_curve(tau, ctrl, 3).evaluate(params)[:, 0]
    expect = np.linalg.lstsq(basis, points, rcond=None)[0]
    assert_allclose(fit.curve.control_points[:k], expect, atol=1e-9)
