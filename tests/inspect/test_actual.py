"""The measured cam's motion, its uncertainty, and the compensated profile, against injected truths."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad.errors import DesignLimitError, GougeError
from camcad.geometry.cam import Cam
from camcad.geometry.made import made_motion
from camcad.inspect.actual import actual_motion, compensate, smooth_deviation
from camcad.inspect.measure import foot_points, inspect_points
from tests.conftest import make_design
from tests.inspect.conftest import CAMS

CAM = CAMS["offset-roller-ccw"]()
NOISE = 0.002


def true_form(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """e = 12 µm·sin 3u + 6 µm·cos 5u, and its derivatives."""
    e = 0.012 * np.sin(3 * u) + 0.006 * np.cos(5 * u)
    e1 = 0.036 * np.cos(3 * u) - 0.030 * np.sin(5 * u)
    e2 = -0.108 * np.sin(3 * u) - 0.150 * np.cos(5 * u)
    return e, e1, e2


TURN, SHIFT = 0.01, np.array([0.03, -0.01])


def _scan(noise: float, seed: int = 0):
    rng = np.random.default_rng(seed)
    u = np.linspace(0.0, 2 * np.pi, 1440, endpoint=False)
    prof = CAM.profile(u)
    dev = true_form(u)[0] + rng.normal(0.0, noise, u.size)
    c, s = math.cos(TURN), math.sin(TURN)
    pts = (prof.point + dev[:, None] * prof.normal) @ np.array([[c, -s], [s, c]]).T + SHIFT
    return inspect_points(CAM, pts, band=0.05)


def _j(v: np.ndarray) -> np.ndarray:
    return np.column_stack((-v[:, 1], v[:, 0]))


def test_gcv_fourier_smoothing_finds_the_form_and_the_noise():
    u = np.linspace(0.0, 2 * np.pi, 720, endpoint=False)
    y = true_form(u)[0] + np.random.default_rng(1).normal(0.0, NOISE, u.size)
    fit = smooth_deviation(u, y)
    assert 5 <= fit.order <= 12  # at least the 5th harmonic, and not the noise
    assert fit.noise == pytest.approx(NOISE, rel=0.1)
    grid = np.linspace(0.0, 2 * np.pi, 97)
    for d in range(2):
        err = np.abs(fit(grid)[d] - true_form(grid)[d])
        assert np.all(err < 5.0 * fit.std(grid, d) + 1e-12), d


def test_actual_motion_against_the_made_cam_with_the_true_form_error():
    """Lift and velocity rebuilt from noisy points lie within 5σ (+ second order) of the truth.

    The truth is the made cam seen in the fitted frame: the injected form e(u)
    plus what is left of the injected turn and shift after the fit, to first
    order e + Δθ·N·JP + N·Δc (and its u-derivative from the exact profile),
    re-solved on the exact curve.
    """
    ins = _scan(NOISE)
    phi = np.linspace(0.0, 2 * np.pi, 181, endpoint=False)
    act = actual_motion(CAM, ins, phi)
    d_turn = TURN - ins.rotation
    c, s = math.cos(-ins.rotation), math.sin(-ins.rotation)
    d_shift = np.array([[c, -s], [s, c]]) @ (SHIFT - ins.centre)

    def seen(u: np.ndarray):
        prof = CAM.profile(u)
        e, e1, _ = true_form(u)
        dn = prof.d1 / prof.rho[:, None]  # N′ = P′/ρ
        rigid = d_turn * np.einsum("ij,ij->i", prof.normal, _j(prof.point)) + prof.normal @ d_shift
        rigid1 = (
            d_turn
            * (np.einsum("ij,ij->i", dn, _j(prof.point)) + np.einsum("ij,ij->i", prof.normal, _j(prof.d1)))
            + dn @ d_shift
        )
        return e + rigid, e1 + rigid1, np.zeros_like(u)

    truth = made_motion(CAM, phi, form=seen)
    assert np.all(np.abs(act.lift - truth.lift) < 5.0 * act.lift_std + 1e-5)
    assert np.all(np.abs(act.velocity - truth.velocity) < 5.0 * act.velocity_std + 1e-5)
    assert np.all(np.isfinite(act.acceleration)) and np.all(act.acceleration_std > 0.0)
    # the uncertainty is the noise's: 2 µm on 1440 points gives a few tenths of a µm of lift
    assert 1e-5 < float(np.median(act.lift_std)) < 1e-3


def test_compensated_profile_lies_minus_e_off_the_design():
    """Distance of the corrected profile from the exact design (Newton foot points) is −e."""
    fit = smooth_deviation(
        np.linspace(0, 2 * np.pi, 360, endpoint=False),
        true_form(np.linspace(0, 2 * np.pi, 360, endpoint=False))[0],
    )
    comp = compensate(CAM, fit, stock=0.05, tool_radius=5.0)
    _, dist = foot_points(CAM, np.asarray(comp.point), comp.phi)
    assert_allclose(dist, -true_form(comp.phi)[0], atol=1e-9)
    assert_allclose(comp.correction, -true_form(comp.phi)[0], atol=1e-9)


def test_compensation_is_refused_beyond_the_stock_or_a_tool_too_big():
    u = np.linspace(0, 2 * np.pi, 360, endpoint=False)
    fit = smooth_deviation(u, true_form(u)[0])
    with pytest.raises(DesignLimitError, match=r"beyond the stock 10 µm"):
        compensate(CAM, fit, stock=0.010, tool_radius=5.0)
    steep = Cam.from_design(make_design(base_radius=40.0, lift=15.0, spans=(60.0, 120.0, 60.0, 120.0)))
    design = steep.profile(steep.sample_phi()).rho
    concave = float(np.min(-design[design < 0.0]))  # about 109 mm
    corrected = compensate(steep, fit, stock=0.05, tool_radius=0.9 * concave)
    assert np.min(-corrected.radius[corrected.radius < 0]) == pytest.approx(concave, rel=0.02)
    with pytest.raises(GougeError, match=r"tighter than the tool radius"):
        compensate(steep, fit, stock=0.05, tool_radius=1.1 * concave)
