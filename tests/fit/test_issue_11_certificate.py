"""Issue 11 parts 3–4: the fit certificate is a true bound at any sampling; the budget scales.

The reference is an independent dense check: the exact profile ``cam.profile``
at 10^6 (or 2·10^5) cam angles, each projected onto the fitted curve by
Newton's method written here on scipy's own ``BSpline`` (start: the nearest of
20 000 curve points by a k-d tree), not through camcad.fit.certify.
"""

import dataclasses
import math
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import BSpline
from scipy.spatial import cKDTree

import camcad
from camcad.design import parse_design
from camcad.design.paths import path_of
from camcad.errors import FitError
from camcad.fit import fit_cam_profile, fit_profile
from camcad.fit.bspline import lsq_periodic
from camcad.fit.certify import ExactProfile, certify_exact, project
from camcad.geometry.cam import Cam

SAMPLES = sorted(p.stem for p in (Path(__file__).resolve().parents[2] / "samples").glob("*.toml"))
STEPS_DEG = [0.1, 1.0, 5.0, 9.9]
TOLERANCE = {0.1: 1e-3, 1.0: 2e-3, 5.0: 0.03, 9.9: 0.2}  # mm, reachable with the data at each step
DEG = math.pi / 180


@cache
def sample_cam(name: str) -> Cam:
    root = Path(__file__).resolve().parents[2]
    return Cam.from_design(camcad.load_design(root / "samples" / f"{name}.toml"))


@cache
def dense_profile(name: str, n: int) -> np.ndarray:
    phi = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.asarray(sample_cam(name).profile(phi).point)


def dense_distance(curve, points: np.ndarray, chunk: int = 250_000) -> np.ndarray:
    """Distance from each point to a periodic curve: k-d tree start, three Newton steps on scipy's BSpline."""
    spline = BSpline(curve.knots, curve.control_points, curve.degree, extrapolate="periodic")
    d1, d2 = spline.derivative(1), spline.derivative(2)
    a, b = curve.domain
    grid = np.linspace(a, b, 20_000, endpoint=False)
    verts = spline(grid)
    tree = cKDTree(verts)
    out = np.zeros(len(points))
    for lo in range(0, len(points), chunk):
        p = points[lo : lo + chunk]
        near_d, near = tree.query(p)
        u = grid[near]
        for _ in range(3):  # (C − P)·C' = 0 by Newton
            r = spline(u) - p
            c1, c2 = d1(u), d2(u)
            u = u - np.einsum("ij,ij->i", r, c1) / (
                np.einsum("ij,ij->i", c1, c1) + np.einsum("ij,ij->i", r, c2)
            )
        out[lo : lo + chunk] = np.minimum(np.hypot(*(spline(u) - p).T), near_d)
    return out


def breaks_of(cam: Cam) -> list[tuple[float, int]]:
    return [(bp.phi, bp.continuity) for bp in cam.program.breakpoints]


@pytest.mark.parametrize("step_deg", STEPS_DEG, ids=lambda s: f"{s:g}deg")
@pytest.mark.parametrize("name", SAMPLES)
def test_certified_error_agrees_with_dense_check_at_any_sample_step(name, step_deg):
    cam = sample_cam(name)
    phi = cam.sample_phi(step_deg * DEG)
    fit = fit_profile(
        phi,
        np.asarray(cam.profile(phi).point),
        exact=lambda p: cam.profile(p).point,
        breakpoints=breaks_of(cam),
        tolerance=TOLERANCE[step_deg],
    )
    n = 10**6 if name == "offset_roller" else 200_000  # the issue's 10^6 where it reported the failure
    dense = dense_distance(fit.curve, dense_profile(name, n)).max()
    assert dense <= fit.max_error <= 1.01 * dense


def test_issue_case_offset_roller_at_5_degrees_does_not_pass_a_broken_fit():
    # issue 11: certified 0.00566 mm, true 0.00622 mm, accepted at tolerance 0.0058 mm
    cam = sample_cam("offset_roller")
    phi = cam.sample_phi(5.0 * DEG)
    tol = 0.0058
    try:
        fit = fit_profile(
            phi,
            np.asarray(cam.profile(phi).point),
            exact=lambda p: cam.profile(p).point,
            breakpoints=breaks_of(cam),
            tolerance=tol,
        )
    except FitError:
        return
    assert fit.max_error <= tol
    assert dense_distance(fit.curve, dense_profile("offset_roller", 10**6)).max() <= tol


def test_coarse_cam_sample_step_does_not_starve_the_fit():
    cam = dataclasses.replace(sample_cam("offset_roller"), sample_step=5.0 * DEG)
    fit = fit_cam_profile(cam, tolerance=0.0058)
    assert fit.max_error <= 0.0058
    assert len(fit.params) >= 3600  # the fit samples at 0.1°, not at the cam's 5°
    assert dense_distance(fit.curve, dense_profile("offset_roller", 10**6)).max() <= fit.max_error


def bumped_circle_case():
    """A periodic curve C and an exact profile C(u) + d(u)·n(u) with a narrow bump d between samples."""
    t = np.arange(64) / 64
    circle = 30.0 * np.column_stack((np.cos(2 * np.pi * t), np.sin(2 * np.pi * t)))
    curve = lsq_periodic(t, circle, np.arange(12) / 12, 3).curve
    height, centre, width = 0.01, 3.25 / 36, 0.002  # mm; u; u (the samples are 1/36 apart)

    def exact(phi):
        u = np.asarray(phi) / (2 * np.pi)
        c1 = curve.evaluate(u, 1)
        normal = np.column_stack((c1[:, 1], -c1[:, 0])) / np.hypot(*c1.T)[:, None]
        gap = (u - centre + 0.5) % 1.0 - 0.5
        return curve.evaluate(u) + (height * np.exp(-((gap / width) ** 2)))[:, None] * normal

    phi = np.arange(36) * 2 * np.pi / 36  # samples at u = k/36: the bump is a quarter way from 3/36 to 4/36
    return curve, exact, phi, height


def test_certify_exact_finds_a_bump_the_samples_and_midpoints_miss():
    curve, exact, phi, height = bumped_circle_case()
    points = exact(phi)
    feet = project(curve, points, phi / (2 * np.pi)).foot
    mids = exact(phi + np.pi / 36)
    old_style = max(
        project(curve, points, feet).max_error,
        project(curve, mids, (phi + np.pi / 36) / (2 * np.pi)).max_error,
    )
    assert old_style < 0.1 * height  # the sample + midpoint check sees almost nothing
    cert = certify_exact(curve, ExactProfile(point=exact, phi=phi, breaks=np.array([])), points, feet)
    # closed form: the offset by d has distance d from the curve (d ≪ the radius 30 mm)
    assert height <= cert.max_error <= 1.01 * height


def test_certify_exact_is_exact_at_a_corner_on_a_breakpoint():
    # a tent-shaped bump whose apex (a corner of the profile) is a breakpoint between samples
    curve, _, phi, height = bumped_circle_case()
    apex, half = 3.4 / 36, 0.01

    def exact(angle):
        u = np.asarray(angle) / (2 * np.pi)
        c1 = curve.evaluate(u, 1)
        normal = np.column_stack((c1[:, 1], -c1[:, 0])) / np.hypot(*c1.T)[:, None]
        tent = height * np.maximum(0.0, 1.0 - np.abs(u - apex) / half)
        return curve.evaluate(u) + tent[:, None] * normal

    points = exact(phi)
    feet = project(curve, points, phi / (2 * np.pi)).foot
    profile = ExactProfile(point=exact, phi=phi, breaks=np.array([2 * np.pi * apex]))
    cert = certify_exact(curve, profile, points, feet)
    assert height <= cert.max_error <= 1.01 * height
    assert cert.phi is not None and np.min(np.abs(cert.phi - 2 * np.pi * apex)) < 1e-12


def cycloidal_128_design():
    motion = []
    for _ in range(64):
        motion.append({"kind": "rise", "angle": 360 / 128, "lift": 0.2, "law": "cycloidal"})
        motion.append({"kind": "return", "angle": 360 / 128, "lift": 0.2, "law": "cycloidal"})
    return parse_design(
        {
            "cam": {"base_radius": 60.0},
            "follower": {"type": "translating-roller", "roller_radius": 5.0},
            "motion": motion,
        }
    )


def test_128_segment_program_fits_at_1_um_with_the_default_budget():
    design = cycloidal_128_design()
    cam = Cam.from_design(design)
    assert len(cam.program.breakpoints) == 128
    fit = fit_cam_profile(cam, tolerance=1e-3, max_control_points=design.fit.max_control_points)
    assert fit.control_point_count > 500  # the old fixed default could not hold it
    assert fit.max_error <= 1e-3
    phi = np.linspace(0.0, 2 * np.pi, 200_000, endpoint=False)
    assert dense_distance(fit.curve, np.asarray(cam.profile(phi).point)).max() <= fit.max_error


def test_default_budget_is_not_capped_by_the_search_subsample():
    # 5 nm needs about 600 control points: more than the 1200-sample search subsample leaves room for
    cam = sample_cam("offset_roller")
    fit = fit_cam_profile(cam, tolerance=5e-9)
    assert fit.control_point_count > 550
    assert fit.max_error <= 5e-9
    assert dense_distance(fit.curve, dense_profile("offset_roller", 200_000)).max() <= fit.max_error


def test_fit_error_names_the_budget_and_the_count_reached():
    with pytest.raises(FitError) as info:
        fit_cam_profile(sample_cam("offset_roller"), tolerance=1e-3, max_control_points=20, name_of=path_of)
    message = str(info.value)
    assert message.startswith(
        "fit.max_control_points: 20 control points are too few for fit.tolerance = 0.001 mm"
    )
    assert "reached 20" in message
    assert info.value.control_point_count <= 20
    assert info.value.best_error > 1e-3


def test_fit_error_names_the_step_when_the_callers_samples_bind():
    with pytest.raises(FitError) as info:
        fit_cam_profile(sample_cam("offset_roller"), tolerance=1e-3, step=9.9 * DEG, name_of=path_of)
    assert str(info.value).startswith("step: ")
    assert "control points" in str(info.value)
    assert "fit.tolerance = 0.001 mm" in str(info.value)


def test_design_default_budget_is_automatic():
    design = cycloidal_128_design()
    assert design.fit.max_control_points is None
    with pytest.raises(ValueError, match="max_control_points"):
        parse_design({**_minimal(), "fit": {"max_control_points": 4}})


def _minimal():
    return {
        "cam": {"base_radius": 40.0},
        "follower": {"type": "translating-roller", "roller_radius": 10.0},
        "motion": [
            {"kind": "rise", "angle": 180, "lift": 10.0, "law": "cycloidal"},
            {"kind": "dwell", "angle": 180},
        ],
    }
