"""Minimum base radius against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from camcad.geometry import Cam, min_base_radius
from tests.conftest import make_design


def dense_motion(cam: Cam):
    """s, v, a on 10^6 points plus both one-sided limits at every joint: an independent dense sweep."""
    phi = np.linspace(0.0, 2 * math.pi, 1_000_000, endpoint=False)
    joints = np.array([bp.phi for bp in cam.program.breakpoints])
    parts = [cam.motion(phi), cam.motion(joints, side="left"), cam.motion(joints, side="right")]
    return (np.concatenate([getattr(m, k) for m in parts]) for k in ("s", "v", "a"))


@pytest.mark.parametrize("law", ["cycloidal", "harmonic", "poly-4567"])
@pytest.mark.parametrize("limit_deg", [20.0, 30.0])
def test_radial_roller_pressure_limit_matches_closed_form(law, limit_deg):
    """Radial roller: tan α = v/(r_b + r_f + s) ≤ tan α_max ⇔ r_b ≥ max(v/tan α_max − s) − r_f."""
    cam = Cam.from_design(make_design(law=law, base_radius=80.0, roller_radius=10.0, lift=30.0))
    alpha = math.radians(limit_deg)
    s, v, _ = dense_motion(cam)
    expected = float(np.max(np.abs(v) / math.tan(alpha) - s)) - 10.0
    result = min_base_radius(cam, max_pressure_angle=alpha)
    assert result.limit == "pressure angle"
    assert result.base_radius == pytest.approx(expected, abs=1e-5)
    assert math.degrees(result.pressure_angle_max) == pytest.approx(limit_deg, abs=1e-4)


def test_flat_follower_curvature_limit_matches_closed_form():
    """Flat face: ρ = r_b + s + a ≥ ρ_min ⇔ r_b ≥ ρ_min − min(s + a)."""
    cam = Cam.from_design(make_design(law="cycloidal", follower="translating-flat", lift=15.0))
    s, _, a = dense_motion(cam)
    expected = 5.0 - float(np.min(s + a))
    result = min_base_radius(cam, min_curvature_radius=5.0)
    assert result.limit == "curvature"
    assert result.base_radius == pytest.approx(expected, abs=1e-5)


def test_sized_radius_passes_and_a_smaller_one_fails():
    cam = Cam.from_design(make_design(law="harmonic", offset=10.0, roller_radius=15.0, lift=40.0))
    result = min_base_radius(cam, max_pressure_angle=math.radians(25), min_curvature_radius=2.0)
    from dataclasses import replace

    from camcad.geometry.sizing import feasible_margins

    phi = cam.sample_phi()
    for radius, ok in ((result.base_radius, True), (result.base_radius - 0.01, False)):
        m_alpha, m_rho, _, _ = feasible_margins(
            replace(cam, base_radius=radius),
            phi,
            max_pressure_angle=math.radians(25),
            min_curvature_radius=2.0,
        )
        assert (m_alpha >= 0 and m_rho >= 0) is ok


def test_a_conjugate_pair_is_sized_for_both_plates():
    """A yoke whose 40 mm second roller undercuts its plate first: sized with ``conjugate=``, the pair
    passes check's own undercut test on both plates, and 1 µm smaller the second plate loops."""
    from camcad.design import parse_design
    from camcad.pipeline import analyse

    data = {
        "cam": {"name": "yoke", "base_radius": 60.0, "style": "conjugate", "max_pressure_angle": 80.0},
        "follower": {"type": "translating-roller", "roller_radius": 6.0},
        "conjugate": {"angle": 180.0, "roller_radius": 40.0},
        "motion": [
            {"kind": "rise", "angle": 100.0, "lift": 30.0, "law": "cycloidal"},
            {"kind": "dwell", "angle": 80.0},
            {"kind": "return", "angle": 100.0, "lift": 30.0, "law": "cycloidal"},
            {"kind": "dwell", "angle": 80.0},
        ],
    }
    design = parse_design(data)
    cam = Cam.from_design(design)
    alpha = design.cam.max_pressure_angle
    first = min_base_radius(cam, max_pressure_angle=alpha)
    pair = min_base_radius(cam, max_pressure_angle=alpha, conjugate=design.conjugate)
    assert pair.limit == "curvature" and pair.base_radius > first.base_radius + 1.0

    def findings(radius: float) -> list[str]:
        data["cam"]["base_radius"] = radius
        return [
            f.message for f in analyse(parse_design(data), fit=False, toolpath=False, strict=False).findings
        ]

    assert findings(pair.base_radius) == []
    below = findings(pair.base_radius - 1e-6)
    assert below and all(m.startswith("second plate:") and "undercut" in m for m in below)
