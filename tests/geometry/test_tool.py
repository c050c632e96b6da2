"""Whether a milling tool fits: the smallest concave profile radius, against a circle through three points."""

from __future__ import annotations

import math

import numpy as np
import pytest

from camcad.design.paths import named_error
from camcad.errors import DesignLimitError, GougeError
from camcad.geometry.cam import Cam
from camcad.geometry.tool import check_tool
from tests.conftest import make_design

CONCAVE = {"spans": (45.0, 135.0, 45.0, 135.0), "lift": 25.0, "base_radius": 20.0, "roller_radius": 8.0}


def concave_radius_from_points(cam: Cam, n: int = 200_000) -> float:
    """Smallest radius of the circles through three neighbouring profile points that turn against the
    contour's own sense (concave stretches); points only, no curvature formula."""
    phi = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    p = cam.profile(phi).point
    a, b, c = np.roll(p, 1, axis=0), p, np.roll(p, -1, axis=0)
    ab, bc, ca = (np.linalg.norm(u, axis=1) for u in (b - a, c - b, a - c))
    turn = (b - a)[:, 0] * (c - b)[:, 1] - (b - a)[:, 1] * (c - b)[:, 0]  # 2 × signed triangle area
    radius = ab * bc * ca / np.maximum(2.0 * np.abs(turn), 1e-300)  # R = abc / (4 · area)
    sense = np.sign(np.sum(turn))
    concave = np.sign(turn) == -sense
    return float(radius[concave].min())


def test_smallest_concave_radius_matches_three_point_circles():
    cam = Cam.from_design(make_design(**CONCAVE))
    smallest = check_tool(cam, 1.0)
    assert smallest == pytest.approx(concave_radius_from_points(cam), rel=1e-4)
    rho = cam.profile(cam.sample_phi()).rho
    assert smallest <= float(np.min(-rho[rho < 0.0]))  # refined: never above the sampled minimum


def test_convex_cam_fits_any_tool():
    cam = Cam.from_design(make_design())
    assert check_tool(cam, 50.0) == math.inf


def test_tool_larger_than_concave_radius_is_a_gouge_error_naming_the_largest_tool():
    cam = Cam.from_design(make_design(**CONCAVE))
    smallest = check_tool(cam, 1.0)
    assert 12.0 < smallest < 15.0
    assert check_tool(cam, 0.999 * smallest) == smallest  # just fits
    with pytest.raises(GougeError) as err:
        check_tool(cam, 15.0)
    message = str(named_error(err.value))  # as the user reads it, its field named by its TOML path
    assert "°" in message and "φ =" in message
    assert f"Ø{2 * smallest:.3f} mm" in message and "gcode.tool_diameter" in message
    assert err.value.max_tool_radius == pytest.approx(smallest)
    lo, hi = err.value.phi_range
    rho = cam.profile(np.array([lo, hi])).rho
    assert np.all(rho < 0) and np.all(-rho < 15.0)
    assert isinstance(err.value, DesignLimitError)
    with pytest.raises(GougeError):
        check_tool(cam, 1.001 * smallest)  # just too big, however narrow the stretch
