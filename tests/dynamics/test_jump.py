"""Follower jump: where contact is lost, and the closed-form preload and speed limits."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from camcad.design import Design, parse_design
from camcad.design.paths import path_of
from camcad.dynamics import analyse_dynamics, covering_arc, loss_runs, speed_limits
from camcad.geometry.cam import Cam


def jumpy_design(**dynamics: Any) -> Design:
    """A light spring on a fast cycloidal cam: the follower flies off mid-rise and mid-return."""
    dyn = {"follower_mass": 0.5, "spring_rate": 1.0, "spring_preload": 10.0} | dynamics
    return parse_design(
        {
            "cam": {"base_radius": 40.0, "speed_rpm": 600.0},
            "follower": {"roller_radius": 10.0},
            "motion": [
                {"kind": "rise", "angle": 90.0, "lift": 20.0, "law": "cycloidal"},
                {"kind": "dwell", "angle": 90.0},
                {"kind": "return", "angle": 90.0, "lift": 20.0, "law": "cycloidal"},
                {"kind": "dwell", "angle": 90.0},
            ],
            "dynamics": dyn,
        }
    )


def analyse(design: Design):
    cam = Cam.from_design(design)
    phi = cam.sample_phi()
    return analyse_dynamics(
        cam.motion(phi),
        pressure_angle=cam.pressure_angle(phi),
        profile_rho=cam.profile(phi).rho,
        setup=design.dynamics_setup(),
    )


def with_dynamics(design: Design, **changes: Any) -> Design:
    return replace(design, dynamics=replace(design.dynamics, **changes))


def with_speed(design: Design, rpm: float) -> Design:
    return replace(design, cam=replace(design.cam, speed_rpm=rpm))


@pytest.mark.parametrize("margin", [0.0, 5.0], ids=["margin-0", "margin-5N"])
def test_min_preload_is_exact(margin):
    """Solve F_C ≥ margin for F0 in closed form, then verify on the same samples."""
    design = jumpy_design(min_contact_force=margin)
    result = analyse(design)
    assert result.jump
    f0 = result.min_preload
    assert f0 > design.dynamics.spring_preload
    fixed = analyse(with_dynamics(design, spring_preload=f0))
    assert fixed.contact_force.min() == pytest.approx(margin, abs=1e-9 * f0)
    assert not analyse(with_dynamics(design, spring_preload=f0 + 1e-6)).jump
    assert analyse(with_dynamics(design, spring_preload=f0 - 1e-3)).jump


@pytest.mark.parametrize("margin", [0.0, 5.0], ids=["margin-0", "margin-5N"])
def test_max_speed_is_exact(margin):
    """Solve F_C ≥ margin for ω² in closed form, then verify on the same samples."""
    design = jumpy_design(min_contact_force=margin)
    low, high = analyse(design).speed_range_rpm
    assert low == 0.0
    assert 0.0 < high < 600.0
    at_limit = analyse(with_speed(design, high))
    assert at_limit.contact_force.min() == pytest.approx(margin, abs=1e-9 * 50.0)
    assert not analyse(with_speed(design, high * (1 - 1e-9))).jump
    assert analyse(with_speed(design, high * 1.001)).jump


def test_jump_is_reported_with_its_remedies():
    result = analyse(jumpy_design())
    summary = result.summary()
    assert summary["jump"] is True
    start, end = summary["jump_range_deg"]
    # contact is lost in the decelerating half of the rise (45°-90°) and the
    # accelerating-down half of the return (180°-225°), never on the dwells
    assert 45.0 < start < 90.0
    assert 180.0 < end < 225.0
    assert len(result.jump_ranges) == 2
    warning = result.findings[0].message
    preload = math.ceil(result.min_preload * 10) / 10
    speed = math.floor(result.speed_range_rpm[1] * 10) / 10
    assert warning.startswith(f"follower jumps between {start:.1f}° and {end:.1f}° (contact force ")
    assert "at 600 rpm" in warning
    assert f"raise the preload to ≥ {preload:.1f} N" in warning
    assert f"keep the speed ≤ {speed:.1f} rpm" in warning
    (jump,) = [f for f in result.findings if f.kind == "jump"]  # a soft limit, naming the knob
    assert not jump.hard and path_of(jump.field) == "dynamics.spring_preload" and jump.message == warning


def test_no_jump_for_an_unloaded_follower():
    """No mass, no spring, no margin: F_C ≡ 0 is not a loss of contact."""
    result = analyse(jumpy_design(follower_mass=0.0, spring_rate=0.0, spring_preload=0.0))
    assert not result.jump
    assert result.summary()["jump_range_deg"] is None
    assert not result.findings


def test_tappet_speed_limit_and_preload_deflection():
    """Guided tappet (Hren et al., Table 1): N1 = F/c with c from eq. 25 is linear in F0 and ω²."""
    from tests.dynamics.test_tappet import table1_design

    design = table1_design()
    result = analyse(design)
    assert not result.jump
    low, high = result.speed_range_rpm
    assert low == 0.0 and high > 1425.0
    at_limit = analyse(with_speed(design, high))
    assert at_limit.contact_force.min() == pytest.approx(0.0, abs=1e-9 * 1000.0)
    fast = analyse(with_speed(design, 1.05 * high))
    assert fast.jump
    assert fast.preload_deflection == pytest.approx(fast.min_preload / 31.6)
    assert "preload deflection ≥" in fast.findings[0].message
    fixed = analyse(
        with_dynamics(with_speed(design, 1.05 * high), preload_deflection=fast.preload_deflection)
    )
    assert fixed.contact_force.min() == pytest.approx(0.0, abs=1e-9 * 1000.0)


def test_loss_runs_join_across_zero():
    phi = np.radians(np.arange(0.0, 360.0, 10.0))
    lost = (phi < np.radians(25.0)) | (phi > np.radians(335.0)) | (np.abs(phi - np.radians(200.0)) < 0.01)
    runs = loss_runs(phi, lost)
    assert [tuple(round(math.degrees(x)) for x in r) for r in runs] == [(340, 20), (200, 200)]
    # the shortest arc holding both runs starts at 200° and ends at 20°, through 0°
    assert tuple(round(math.degrees(x)) for x in covering_arc(runs)) == (200, 20)
    assert loss_runs(phi, np.zeros(phi.size, bool)) == ()


def test_speed_limits_edge_cases():
    ones = np.ones(3)
    # never decelerates: any speed is fine
    assert speed_limits(inertia=[0.0, 1.0, 2.0], static=ones, ratio=ones) == (0.0, math.inf)
    # not enough force at rest where there is no inertia: no speed helps
    assert speed_limits(inertia=[0.0, -1.0, 1.0], static=[-1.0, 1.0, 1.0], ratio=ones) is None
    # inertia must supply the margin (ω ≥ 2) and the spring caps the speed (ω ≤ 3)
    low, high = speed_limits(inertia=[1.0, -1.0], static=[0.0, 9.0], ratio=[1.0, 1.0], margin=4.0)
    assert (low, high) == pytest.approx((2.0, math.sqrt(5.0)))
