"""Inspection: measured points fitted onto the exact profile, judged, and refused when they are bad.

The points are made from the exact profile with known errors injected (a
turn, a centre offset, waviness, noise, defects), so the truth is known
independently of the fit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.inspect.measure import inspect_points, points_from_polar
from tests.conftest import make_design
from tests.inspect.conftest import CAMS

CAM = CAMS["offset-roller-ccw"]()


def _turn(points: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return points @ np.array([[c, -s], [s, c]]).T


def measured(
    *,
    n: int = 720,
    phase_deg: float = 0.3,
    centre: tuple[float, float] = (0.020, 0.0),
    wave: float = 0.010,
    lobes: int = 7,
    noise: float = 0.002,
    defects: dict[int, float] | None = None,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """Points evenly spaced in cam angle, as a CMM scan would give, shuffled; and their true deviations."""
    rng = np.random.default_rng(seed)
    u = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    prof = CAM.profile(u)
    dev = wave * np.sin(lobes * u) + rng.normal(0.0, noise, n)
    for i, extra in (defects or {}).items():
        dev[i] += extra
    pts = _turn(prof.point + dev[:, None] * prof.normal, math.radians(phase_deg)) + np.asarray(centre)
    order = rng.permutation(n)
    return pts[order], dev[order]


DEFECTS = {40: 0.05, 200: -0.05, 333: 0.06, 500: -0.045, 611: 0.07}


def test_fit_recovers_phase_and_centre_and_flags_exactly_the_bad_points():
    """0.3° turn, 20 µm offset, 10 µm waviness, 2 µm noise: 0.01° and 1 µm; flags: |true dev| > band."""
    pts, dev = measured(defects=DEFECTS)
    ins = inspect_points(CAM, pts, band=0.02)
    assert abs(math.degrees(ins.rotation) - 0.3) < 0.01
    assert np.hypot(*(ins.centre - [0.020, 0.0])) < 0.001
    truth = np.abs(dev) > 0.02
    assert truth.sum() == len(DEFECTS)  # only the defects are outside, by a clear margin
    assert np.array_equal(ins.outside, truth)
    assert not ins.passed
    assert np.max(np.abs(ins.deviation - dev)) < 0.001  # every deviation within 1 µm of the truth
    assert not ins.inlier[truth].any()  # the defects did not steer the final fit


def test_fit_in_a_foreign_frame_and_from_polar_points():
    """A CMM frame turned by 123° and moved by (500, −300) mm, given as polar angle/radius."""
    pts, dev = measured(phase_deg=123.0, centre=(500.0, -300.0), wave=0.0)
    rel = pts - [500.0, -300.0]
    polar = points_from_polar(np.degrees(np.arctan2(rel[:, 1], rel[:, 0])), np.hypot(rel[:, 0], rel[:, 1]))
    ins = inspect_points(CAM, polar + np.array([500.0, -300.0]), band=0.01)
    assert abs(math.degrees(ins.rotation) - 123.0) < 0.01
    assert np.hypot(*(ins.centre - [500.0, -300.0])) < 0.001
    assert ins.passed
    np.testing.assert_allclose(ins.deviation, dev, atol=0.001)


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    phase=st.floats(-3.0, 3.0),
    cx=st.floats(-0.05, 0.05),
    cy=st.floats(-0.05, 0.05),
    seed=st.integers(0, 2**16),
)
def test_fit_recovers_any_small_phase_and_offset(phase, cx, cy, seed):
    pts, dev = measured(n=720, phase_deg=phase, centre=(cx, cy), seed=seed, defects={7: 0.05, 100: -0.06})
    ins = inspect_points(CAM, pts, band=0.02)
    assert abs(math.degrees(ins.rotation) - phase) < 0.01
    assert np.hypot(*(ins.centre - [cx, cy])) < 0.001
    assert np.array_equal(ins.outside, np.abs(dev) > 0.02)


def test_too_few_points():
    pts, _ = measured(n=20)
    with pytest.raises(DesignError, match=r"measured: 20 points; allowed: at least 24"):
        inspect_points(CAM, pts, band=0.02)


def test_a_nan_is_named_by_its_row():
    pts, _ = measured()
    pts[17, 1] = np.nan
    with pytest.raises(DesignError, match=r"measured: point 17: .* is not finite"):
        inspect_points(CAM, pts, band=0.02)


def test_duplicated_points_are_named():
    pts, _ = measured()
    pts[99] = pts[5]
    with pytest.raises(DesignError, match=r"points 5 and 99 are the same point"):
        inspect_points(CAM, pts, band=0.02)


def test_a_partial_scan_is_refused():
    pts, _ = measured()
    centre = pts.mean(axis=0)
    keep = np.arctan2(*(pts - centre).T[::-1]) < 1.0  # a scan that stops short
    with pytest.raises(DesignError, match=r"the scan covers only \d+° of the profile"):
        inspect_points(CAM, pts[keep], band=0.02)


def test_inches_are_recognised():
    pts, _ = measured()
    with pytest.raises(DesignError, match=r"look like inches: multiply by 25\.4"):
        inspect_points(CAM, pts / 25.4, band=0.02)


def test_another_cam_is_not_fitted():
    """Points of a cam with a different lift and offset: refused, never fitted silently."""
    other = Cam.from_design(make_design(offset=8.0, lift=17.0))
    u = np.linspace(0.0, 2 * np.pi, 720, endpoint=False)
    pts = other.profile(u).point
    with pytest.raises(DesignError, match=r"measured: .*(not this cam|turned by)"):
        inspect_points(CAM, pts, band=0.02)


def test_a_bad_band_is_named():
    pts, _ = measured()
    with pytest.raises(DesignError, match=r"band: \(0\.01, 0\.02\) mm"):
        inspect_points(CAM, pts, band=(0.01, 0.02))


def test_a_profile_that_repeats_itself_is_refused():
    """Two equal lobes: the turn is ambiguous by 180°, so the fit refuses rather than guess."""
    from camcad.design import parse_design

    lobe = [
        {"kind": "rise", "angle": 60.0, "lift": 10.0, "law": "cycloidal"},
        {"kind": "dwell", "angle": 30.0},
        {"kind": "return", "angle": 60.0, "lift": 10.0, "law": "cycloidal"},
        {"kind": "dwell", "angle": 30.0},
    ]
    data = {
        "cam": {"name": "two lobes", "base_radius": 40.0, "thickness": 8.0},
        "follower": {"type": "translating-roller", "roller_radius": 10.0},
        "motion": lobe + lobe,
    }
    cam = Cam.from_design(parse_design(data))
    pts = cam.profile(np.linspace(0.0, 2 * np.pi, 720, endpoint=False)).point
    with pytest.raises(DesignError, match=r"repeats itself"):
        inspect_points(cam, pts, band=0.02)


def test_a_face_follower_cam_on_a_cw_arm():
    """The fit needs only the exact profile: an oscillating flat-face cam turning cw fits as well."""
    cam = CAMS["oscillating-flat-cw"]()
    u = np.linspace(0.0, 2 * np.pi, 720, endpoint=False)
    prof = cam.profile(u)
    dev = 0.005 * np.cos(11 * u)
    pts = _turn(prof.point + dev[:, None] * prof.normal, math.radians(-0.2)) + np.array([0.01, 0.015])
    ins = inspect_points(cam, pts, band=0.01)
    assert abs(math.degrees(ins.rotation) + 0.2) < 0.01
    assert np.hypot(*(ins.centre - [0.01, 0.015])) < 0.001
    assert ins.passed
