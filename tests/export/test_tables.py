"""points.csv and lift.csv: grid, values against the exact cam, polar radius by an independent method."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad.design import Design, Rotation
from camcad.errors import ExportError
from camcad.export.tables import (
    LIFT_HEADER,
    POINTS_HEADER,
    polar_radius,
    table_angles,
    write_lift_csv,
    write_points_csv,
)
from camcad.geometry.cam import Cam
from tests.conftest import make_design

DESIGNS = {
    "radial-roller": lambda: make_design(),
    "offset-roller-cw": lambda: make_design(rotation="cw", offset=8.0, law="poly-345"),
    "flat": lambda: make_design(follower="translating-flat", law="harmonic"),
}


@pytest.fixture(scope="module", params=list(DESIGNS), ids=list(DESIGNS))
def case(request) -> tuple[Design, Cam]:
    design = DESIGNS[request.param]()
    return design, Cam.from_design(design)


def read_csv(path: Path, header: str) -> np.ndarray:
    text = path.read_text(encoding="utf-8")
    assert text.endswith("\n") and "\r" not in text
    assert text.splitlines()[0] == header
    assert "-0.000000," not in text and not text.startswith("-0.000000")
    return np.loadtxt(path, delimiter=",", skiprows=1)


def ray_crossing_radius(cam: Cam, theta: np.ndarray, sign: float) -> np.ndarray:
    """Independent polar radius: intersect each ray with a 10⁵-gon of the exact profile."""
    poly = cam.profile(np.linspace(0.0, 2.0 * math.pi, 100001)[:-1]).point
    p, q = poly, np.roll(poly, -1, axis=0)
    out = []
    for th in theta:
        u = np.array([sign * math.sin(th), math.cos(th)])
        # solve p + t (q - p) = r u  for t in [0, 1), r > 0
        d = q - p
        den = d[:, 0] * u[1] - d[:, 1] * u[0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = -(p[:, 0] * u[1] - p[:, 1] * u[0]) / den
        hit = (t >= 0) & (t < 1)
        r = np.einsum("ij,j->i", p[hit] + t[hit, None] * d[hit], u)
        r = r[r > 0]
        assert len(r) == 1
        out.append(r[0])
    return np.asarray(out)


def test_table_grid_closes_the_turn():
    assert len(table_angles(math.radians(1.0))) == 360
    grid = table_angles(math.radians(0.7))
    assert len(grid) == math.ceil(360 / 0.7)
    assert_allclose(np.diff(grid), 2 * math.pi / len(grid), rtol=0, atol=1e-14)
    assert grid[0] == 0.0
    with pytest.raises(ValueError):
        table_angles(0.0)


def test_points_csv_is_the_exact_profile(case, tmp_path):
    design, cam = case
    data = read_csv(write_points_csv(tmp_path / "points.csv", cam, design.tables), POINTS_HEADER)
    phi = table_angles(design.tables.step)
    assert data.shape == (len(phi), 6)
    assert_allclose(data[:, 0], np.degrees(phi), rtol=0, atol=5e-7)
    prof = cam.profile(phi)
    assert_allclose(data[:, 1:3], prof.point, rtol=0, atol=5e-7)
    assert_allclose(data[:, 3:5], prof.normal, rtol=0, atol=5e-10)
    assert_allclose(np.hypot(data[:, 3], data[:, 4]), 1.0, rtol=0, atol=2e-9)
    assert_allclose(data[:, 5], prof.rho, rtol=0, atol=5e-7)
    assert np.hypot(data[:, 1], data[:, 2]).min() >= design.cam.base_radius - 1e-6


def test_lift_csv_lift_and_polar_radius(case, tmp_path):
    design, cam = case
    data = read_csv(write_lift_csv(tmp_path / "lift.csv", cam, design.tables), LIFT_HEADER)
    angle = table_angles(design.tables.step)
    assert_allclose(data[:, 0], np.degrees(angle), rtol=0, atol=5e-7)
    assert_allclose(data[:, 1], cam.motion(angle).s, rtol=0, atol=5e-7)
    sign = 1.0 if design.cam.rotation is Rotation.CCW else -1.0
    every_5th = angle[::5]
    assert_allclose(data[::5, 2], ray_crossing_radius(cam, every_5th, sign), rtol=0, atol=2e-5)


def test_polar_radius_on_dwells_of_a_radial_follower():
    """Radial follower: on a dwell the profile is a circle, so r(θ) = r_b + s exactly."""
    design = make_design(spans=(150.0, 60.0, 90.0, 60.0))
    cam = Cam.from_design(design)
    theta = np.radians([160.0, 180.0, 200.0, 310.0, 330.0, 350.0])
    r = polar_radius(cam, theta, rotation=design.cam.rotation)
    assert_allclose(r, [60.0, 60.0, 60.0, 40.0, 40.0, 40.0], rtol=0, atol=1e-11)


def test_polar_radius_is_not_the_contact_radius(case):
    """On a rise the contact point lies off the ray at θ = φ (roller or offset flat face)."""
    design, cam = case
    phi = np.radians([60.0, 75.0])
    contact = np.hypot(*cam.profile(phi).point.T)
    polar = polar_radius(cam, phi, rotation=design.cam.rotation)
    assert np.all(np.abs(polar - contact) > 1e-3)


def test_steps_from_the_design(tmp_path):
    design = make_design(extra={"tables": {"step_deg": 2.5}})
    cam = Cam.from_design(design)
    data = read_csv(write_lift_csv(tmp_path / "lift.csv", cam, design.tables), LIFT_HEADER)
    assert len(data) == 144 and data[1, 0] == 2.5


@dataclass(frozen=True)
class _Sample:
    point: np.ndarray


@dataclass(frozen=True)
class _Lift:
    s: np.ndarray


@dataclass(frozen=True)
class FoldedCam:
    """A stand-in whose polar angle runs backwards near φ = π/2: not star-shaped."""

    rotation = Rotation.CCW

    def profile(self, phi):
        phi = np.asarray(phi, dtype=float)
        theta = phi + 0.6 * np.sin(2 * phi)
        r = 40 + 5 * np.cos(phi)
        return _Sample(point=np.column_stack((r * np.sin(theta), r * np.cos(theta))))

    def motion(self, phi):
        return _Lift(s=np.zeros_like(np.asarray(phi, dtype=float)))

    def sample_phi(self):
        return np.linspace(0, 2 * math.pi, 3600, endpoint=False)


def test_non_star_shaped_profile_is_refused(tmp_path):
    with pytest.raises(ExportError, match="star-shaped"):
        polar_radius(FoldedCam(), np.radians([10.0]), rotation=Rotation.CCW)


def test_failed_table_leaves_no_file(tmp_path):
    design = make_design()
    cam = FoldedCam()
    with pytest.raises(ExportError):
        write_lift_csv(tmp_path / "lift.csv", cam, design.tables)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []
