"""Monte Carlo on made cams against the linear method, and tolerance allocation against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.stats import norm

from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.made import made_motion
from camcad.geometry.sensitivity import Tol
from camcad.inspect.tolerance import (
    Distribution,
    Method,
    Tolerance,
    allocate,
    dwell_angles,
    linear_dwell,
    monte_carlo,
)
from tests.conftest import make_design
from tests.inspect.conftest import CAMS
from tests.named import raises_named

SMALL = {
    "offset-roller-ccw": [
        Tolerance(tol=Tol.FORM, value=0.01),
        Tolerance(tol=Tol.ROLLER_RADIUS, value=0.006, distribution=Distribution.NORMAL),
        Tolerance(tol=Tol.ECCENTRICITY, value=0.02),
        Tolerance(tol=Tol.PHASE, value=math.radians(0.05)),
    ],
    "oscillating-roller": [
        Tolerance(tol=Tol.FORM, value=0.01),
        Tolerance(tol=Tol.PIVOT_X, value=0.02),
        Tolerance(tol=Tol.ARM_LENGTH, value=0.02, distribution=Distribution.NORMAL),
        Tolerance(tol=Tol.CENTRE_DISTANCE, value=0.02),
    ],
    "oscillating-flat-cw": [
        Tolerance(tol=Tol.FORM, value=0.01),
        Tolerance(tol=Tol.PIVOT_Y, value=0.02),
        Tolerance(tol=Tol.FACE_OFFSET, value=0.02),
    ],
}


@pytest.mark.parametrize("name", sorted(SMALL))
def test_monte_carlo_agrees_with_linear_within_sampling_error(name):
    """Small tolerances: MC mean ≈ 0 and σ ≈ the RSS σ, within 4 standard errors of sampling."""
    cam = CAMS[name]()
    n = 1500
    mc = monte_carlo(cam, SMALL[name], samples=n, seed=7, peaks=False)
    lin = linear_dwell(cam, SMALL[name])
    assert mc.dwell_error.shape == (n, dwell_angles(cam).size)
    std = mc.dwell_error.std(axis=0, ddof=1)
    assert np.all(np.abs(std - lin.sigma) < 4.0 * lin.sigma / math.sqrt(2 * n)), (std, lin.sigma)
    assert np.all(np.abs(mc.dwell_error.mean(axis=0)) < 4.0 * lin.sigma / math.sqrt(n))
    assert np.all(np.abs(mc.dwell_error) <= lin.worst_case * (1 + 1e-3))  # the worst case bounds all


def test_monte_carlo_is_reproducible_and_orders_percentiles():
    cam = CAMS["offset-roller-ccw"]()
    a = monte_carlo(cam, SMALL["offset-roller-ccw"], samples=50, seed=3, step=math.radians(10.0))
    b = monte_carlo(cam, SMALL["offset-roller-ccw"], samples=50, seed=3, step=math.radians(10.0))
    assert_allclose(a.dwell_error, b.dwell_error, rtol=0, atol=0)
    for values in a.percentiles.values():
        assert np.all(np.diff(values) >= 0.0)


def test_monte_carlo_peaks_are_the_made_motions_true_extremes():
    """Each variant's peak |a| and |α| from a 10° grid, refined, equal a dense 0.002° scan of its made cam."""
    cam = CAMS["oscillating-roller"]()
    tols = SMALL["oscillating-roller"]
    mc = monte_carlo(cam, tols, samples=3, seed=5, step=math.radians(10.0))
    dense = np.linspace(0.0, 2 * np.pi, 180_000, endpoint=False)
    for i in range(3):
        one = made_motion(cam, dense, deltas={k: float(v[i]) for k, v in mc.deltas.items()})
        scan_a = np.max(np.abs(one.acceleration))
        scan_alpha = np.max(np.abs(one.pressure_angle))
        assert scan_a - 1e-6 * scan_a <= mc.peak_acceleration[i] <= scan_a + 1e-6 * scan_a
        assert scan_alpha - 1e-9 <= mc.peak_pressure_angle[i] <= scan_alpha + 1e-7
    grid = np.union1d(cam.sample_phi(math.radians(10.0)), np.mod(dwell_angles(cam), 2 * np.pi))
    coarse = made_motion(cam, grid, deltas={k: float(v[0]) for k, v in mc.deltas.items()})
    assert np.max(np.abs(coarse.acceleration)) < mc.peak_acceleration[0] - 1e-3  # the grid alone misses it


def test_monte_carlo_peaks_of_the_design_are_its_true_extremes():
    """Zero tolerances: every variant is the design, whose peak |a| is the program's true extreme."""
    from camcad.extremes import maximum

    cam = CAMS["offset-roller-cw"]()
    mc = monte_carlo(cam, [Tolerance(tol=Tol.FORM, value=0.0)], samples=2, step=math.radians(7.0))
    joints = [bp.phi for bp in cam.program.breakpoints]
    true = maximum(lambda phi, side: np.abs(cam.motion(phi, side=side).a), cam.sample_phi(), joints)
    assert mc.peak_acceleration[0] == pytest.approx(true.value, rel=1e-9)


def test_bad_tolerances_are_named():
    cam = CAMS["translating-flat"]()
    with raises_named(DesignError, match=r"tolerance\.roller_radius: does not apply"):
        monte_carlo(cam, [Tolerance(tol=Tol.ROLLER_RADIUS, value=0.01)], samples=10)
    with raises_named(DesignError, match=r"tolerance\.form: -0\.1"):
        linear_dwell(cam, [Tolerance(tol=Tol.FORM, value=-0.1)])
    with raises_named(
        DesignError, match=r"tolerance\.form: ±60 is larger than the part; allowed: below 50 mm"
    ):
        linear_dwell(cam, [Tolerance(tol=Tol.FORM, value=60.0)])
    with raises_named(DesignError, match=r"tolerance\.phase: ±2 is larger than the part"):
        monte_carlo(cam, [Tolerance(tol=Tol.PHASE, value=2.0)], samples=10)


def _radial() -> Cam:
    return Cam.from_design(make_design(offset=0.0))


def test_allocation_closed_form_on_a_radial_roller():
    """Radial roller in a dwell: c = (1, 1, −1, 0) for form, roller, centre distance, phase.

    Worst case, equal effect: t = E/3 each. RSS of normal tolerances (σ = t/3) at confidence p:
    t = 3E/(z·√3), z = Φ⁻¹((1 + p)/2). Phase moves no dwell: unlimited.
    """
    cam = _radial()
    tols = [
        Tolerance(tol=t, value=0.01) for t in (Tol.FORM, Tol.ROLLER_RADIUS, Tol.CENTRE_DISTANCE, Tol.PHASE)
    ]
    lin = linear_dwell(cam, tols)
    assert_allclose(lin.coefficients, [[1, 1, -1, 0]] * 2, atol=1e-12)
    e = 0.03
    worst = allocate(lin.coefficients, lin.parameters, required=e, method=Method.WORST_CASE)
    assert [worst.tolerances[t] for t in lin.parameters[:3]] == pytest.approx([e / 3] * 3, rel=1e-12)
    assert worst.tolerances[Tol.PHASE] == math.inf
    z = norm.ppf(0.5 + 0.5 * 0.95)
    rss = allocate(
        lin.coefficients, lin.parameters, required=e, confidence=0.95, distribution=Distribution.NORMAL
    )
    assert [rss.tolerances[t] for t in lin.parameters[:3]] == pytest.approx([3 * e / (z * math.sqrt(3))] * 3)
    assert_allclose(rss.predicted, e, rtol=1e-12)


def test_rss_allocation_meets_its_confidence_on_made_cams():
    """Tolerances allocated by RSS at 95 %: about 95 % of re-solved made cams hold the dwell within ±E."""
    cam = CAMS["offset-roller-ccw"]()
    params = (Tol.FORM, Tol.ECCENTRICITY, Tol.CENTRE_DISTANCE)
    lin = linear_dwell(cam, [Tolerance(tol=t, value=0.01) for t in params])
    alloc = allocate(
        lin.coefficients, params, required=0.02, confidence=0.95, distribution=Distribution.NORMAL
    )
    tols = [Tolerance(tol=t, value=alloc.tolerances[t], distribution=Distribution.NORMAL) for t in params]
    n = 4000
    mc = monte_carlo(cam, tols, samples=n, seed=11, peaks=False)
    binding = int(np.argmax(alloc.predicted))
    inside = np.mean(np.abs(mc.dwell_error[:, binding]) <= 0.02)
    assert abs(inside - 0.95) < 4 * math.sqrt(0.95 * 0.05 / n)


def test_weighted_allocation_scales_one_factor():
    coef = np.array([[2.0, 0.5], [1.0, 1.0]])
    out = allocate(
        coef,
        (Tol.FORM, Tol.PHASE),
        required=1.0,
        method=Method.WORST_CASE,
        weights={Tol.FORM: 1.0, Tol.PHASE: 2.0},
    )
    # worst dwell: 2·λ + 0.5·2λ = 3λ = 1
    assert out.tolerances[Tol.FORM] == pytest.approx(1 / 3)
    assert out.tolerances[Tol.PHASE] == pytest.approx(2 / 3)
    with raises_named(DesignError, match="dwell_accuracy"):
        allocate(coef, (Tol.FORM, Tol.PHASE), required=0.0)
