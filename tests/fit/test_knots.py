"""Knot placement: breakpoint multiplicities, equidistribution, grading, h^{p+1} law."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad.fit.bspline import lsq_periodic
from camcad.fit.knots import (
    GRADING,
    MIN_SAMPLE_GAP,
    Density,
    _graded,
    density_from_fit,
    estimate_free_knots,
    fixed_knots,
    place_knots,
)

PARAMS = np.arange(3600) / 3600.0


@pytest.mark.parametrize(
    ("continuity", "multiplicity"), [(0, 3), (1, 2), (2, 1), (3, 0), (5, 0)], ids=lambda v: str(v)
)
def test_breakpoint_multiplicity_is_degree_minus_continuity(continuity, multiplicity):
    fixed = fixed_knots([(0.4, continuity)], degree=3, periodic=True)
    expected = {0.0: 1} | ({0.4: multiplicity} if multiplicity else {})
    assert dict(zip(fixed.position.tolist(), fixed.multiplicity.tolist(), strict=True)) == expected


def test_breakpoint_at_the_seam_raises_the_seam_multiplicity_and_duplicates_merge():
    fixed = fixed_knots([(0.0, 1), (1.0, 2), (0.5, 2), (0.5, 0)], degree=3, periodic=True)
    assert fixed.position.tolist() == [0.0, 0.5]
    assert fixed.multiplicity.tolist() == [2, 3]  # lowest continuity wins
    assert fixed.n_fixed == 5
    assert fixed.n_segments == 2


def test_open_fixed_knots_have_free_ends():
    fixed = fixed_knots([(0.5, 1)], degree=3, periodic=False)
    assert fixed.position.tolist() == [0.0, 0.5, 1.0]
    assert fixed.multiplicity.tolist() == [0, 2, 0]


def test_negative_continuity_is_refused():
    with pytest.raises(ValueError, match="continuity"):
        fixed_knots([(0.5, -1)], degree=3, periodic=True)


def test_uniform_density_gives_uniform_knots():
    fixed = fixed_knots([], degree=3, periodic=True)
    tau = place_knots(fixed, Density.uniform(), 9, PARAMS)
    assert_allclose(tau, np.arange(10) / 10, atol=1e-12)


def test_place_knots_keeps_fixed_knots_with_multiplicity():
    fixed = fixed_knots([(0.25, 1), (0.5, 2)], degree=3, periodic=True)
    tau = place_knots(fixed, Density.uniform(), 7, PARAMS)
    assert len(tau) == fixed.n_fixed + 7
    assert np.all(np.diff(tau) >= 0.0)
    assert np.count_nonzero(tau == 0.25) == 2
    assert np.count_nonzero(tau == 0.5) == 1
    assert tau[0] == 0.0


def test_equidistribution_follows_the_density():
    fixed = fixed_knots([], degree=3, periodic=True)
    dens = Density(edges=np.array([0.0, 0.5, 1.0]), values=np.array([4.0, 1.0]), need=np.array([4.0, 1.0]))
    tau = place_knots(fixed, dens, 9, PARAMS)  # 10 spans, ∫m = 2.5, 0.25 per span
    assert np.count_nonzero(tau < 0.5) == 8
    assert_allclose(np.diff(tau[:9]), 1 / 16, atol=1e-12)


def test_free_knots_keep_samples_between_them():
    fixed = fixed_knots([], degree=3, periodic=True)
    params = np.arange(200) / 200.0
    spike = Density(edges=np.array([0.0, 0.01, 1.0]), values=np.array([1e6, 1.0]), need=np.array([1e6, 1.0]))
    tau = place_knots(fixed, spike, 20, params)
    index = np.interp(np.append(tau, 1.0), np.append(params, 1.0), np.arange(201.0))
    assert np.min(np.diff(index)) >= MIN_SAMPLE_GAP - 1e-9


def test_allocation_splits_free_knots_by_need():
    fixed = fixed_knots([(0.5, 2)], degree=3, periodic=True)
    need = Density(edges=np.array([0.0, 0.5, 1.0]), values=np.ones(2), need=np.array([3.0, 1.0]))
    tau = place_knots(fixed, need, 6, PARAMS)
    assert np.count_nonzero((tau > 0.0) & (tau < 0.5)) == 5  # shares 1.5/6 vs 0.5/2


def test_grading_limits_neighbour_ratio():
    raw = np.log(np.array([1.0, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3]))
    graded = np.exp(_graded(raw, np.log(GRADING), periodic=True))
    ratios = graded / np.roll(graded, 1)
    assert np.all(ratios <= GRADING * (1 + 1e-12))
    assert np.all(1 / ratios <= GRADING * (1 + 1e-12))
    assert graded[0] == 1.0
    assert_allclose(graded[3], GRADING**-3)  # three spans from the peak either way


def test_density_from_fit_has_both_densities_positive():
    phi = 2 * np.pi * PARAMS
    pts = np.column_stack((50 * np.cos(phi), 20 * np.sin(phi)))
    fixed = fixed_knots([], degree=3, periodic=True)
    tau = place_knots(fixed, Density.uniform(), 11, PARAMS)
    fit = lsq_periodic(PARAMS, pts, tau, 3)
    err = np.hypot(*(fit.at_params - pts).T)
    dens = density_from_fit(fit.curve, tau, fixed, PARAMS, err)
    assert np.all(dens.values > 0) and np.all(dens.need > 0)
    # the ellipse is sharpest at φ = 0 and π, so the need peaks there
    mid = 0.5 * (dens.edges[1:] + dens.edges[:-1])
    assert dens.need[np.argmin(np.abs(mid - 0.25))] < dens.need[np.argmin(np.abs(mid - 0.0))]


@pytest.mark.parametrize(("ratio", "factor"), [(16.0, 2.0), (1.0, 1.0), (1 / 16, 0.5)])
def test_h4_law_scales_spans(ratio, factor):
    # 10 free knots + 2 segments = 12 spans; error / tolerance = ratio
    assert estimate_free_knots(10, 2, ratio * 1e-3, 1e-3, 3) == int(np.ceil(12 * factor)) - 2
