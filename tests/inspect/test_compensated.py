"""The corrected cam against the design's own offsets and against the made curve of the library.

A constant correction c is an offset: the corrected profile offset by d is the
design's offset by d + c (every follower, both rotations, both one-sided
limits). A varying correction matches :func:`camcad.geometry.made.made_curve`
(point and both derivatives), and its derivatives match central differences.
"""

from __future__ import annotations

import numpy as np
import pytest

from camcad.geometry.made import made_curve
from camcad.inspect.compensated import CompensatedCam, offset_error


def _constant(c: float):
    return lambda u: (np.full(np.shape(u), c), np.zeros(np.shape(u)), np.zeros(np.shape(u)))


def _wave(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return 0.03 * np.sin(5 * u), 0.15 * np.cos(5 * u), -0.75 * np.sin(5 * u)


@pytest.mark.parametrize("side", ["right", "left"])
@pytest.mark.parametrize("c", [-0.05, 0.0, 0.2])
def test_a_constant_correction_is_an_offset(any_cam, c, side):
    phi = any_cam.sample_phi()
    fixed = CompensatedCam.of(any_cam, _constant(c))
    want, got = any_cam.offset_curve(phi, 3.0 + c, side=side), fixed.offset_curve(phi, 3.0, side=side)
    for name in ("point", "d1", "d2", "normal", "tangent"):
        np.testing.assert_allclose(getattr(got, name), getattr(want, name), atol=1e-9, err_msg=name)
    finite = np.isfinite(want.rho) & (np.abs(want.rho) < 1e6)
    np.testing.assert_allclose(got.rho[finite], want.rho[finite], rtol=1e-9)
    assert offset_error(fixed, 3.0) < 1e-12  # the normal does not turn


def test_a_varying_correction_is_the_made_curve_and_its_derivatives_are_exact(any_cam):
    u = np.linspace(0.05, 2 * np.pi - 0.05, 997)
    corrected = CompensatedCam.of(any_cam, _wave)
    got = corrected.offset_curve(u, 0.0)
    made = made_curve(any_cam, u, np.full(u.size, -any_cam.roller_radius), _wave)
    np.testing.assert_allclose(got.point, made.x, atol=1e-10)
    np.testing.assert_allclose(got.d1, made.d1, atol=1e-9)
    np.testing.assert_allclose(got.d2, made.d2, atol=1e-8)
    np.testing.assert_allclose(got.normal, made.normal, atol=1e-12)
    h = 1e-5  # central differences away from the joints (the test's own check, not the code's)
    joints = np.array([bp.phi for bp in any_cam.program.breakpoints])
    away = np.min(np.abs(np.subtract.outer(u, joints)), axis=1) > 1e-3
    up, down = corrected.offset_curve(u + h, 0.0), corrected.offset_curve(u - h, 0.0)
    np.testing.assert_allclose(((up.point - down.point) / (2 * h))[away], got.d1[away], atol=1e-5)
    np.testing.assert_allclose(((up.d1 - down.d1) / (2 * h))[away], got.d2[away], atol=1e-4)
