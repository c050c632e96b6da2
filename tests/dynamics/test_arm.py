"""The energy method about an oscillating follower's pivot (issue 14), against independent computations."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from camcad.design import Design, parse_design
from camcad.design.paths import path_of
from camcad.dynamics import STANDARD_GRAVITY, analyse_dynamics
from camcad.geometry.cam import Cam
from camcad.geometry.envelope import to_cam

RPM = 180.0


def rocker(kind: str = "oscillating-roller", rotation: str = "ccw", **dynamics: Any) -> Design:
    follower: dict[str, Any] = {"type": kind, "pivot_distance": 125.0}
    if kind == "oscillating-roller":
        follower |= {"roller_radius": 14.0, "arm_length": 90.0}
    else:
        follower |= {"face_offset": 6.0}
    dyn = {
        "arm_inertia": 3000.0,
        "spring_rate_torsional": 5000.0,
        "spring_preload_torsional": 4000.0,
        "follower_mass": 0.5,
        "cg_distance": 40.0,
    } | dynamics
    return parse_design(
        {
            "cam": {"base_radius": 50.0, "speed_rpm": RPM, "rotation": rotation},
            "follower": follower,
            "motion": [
                {"kind": "rise", "angle": 120.0, "lift": 15.0, "law": "modified-sine"},
                {"kind": "dwell", "angle": 60.0},
                {"kind": "return", "angle": 120.0, "lift": 15.0, "law": "cycloidal"},
                {"kind": "dwell", "angle": 60.0},
            ],
            "dynamics": dyn,
        }
    )


def run(design: Design, phi: np.ndarray | None = None):
    cam = Cam.from_design(design)
    phi = cam.sample_phi() if phi is None else phi
    st = cam.state(phi)
    result = analyse_dynamics(
        st.motion,
        pressure_angle=st.pressure_angle,
        profile_rho=st.profile.rho,
        setup=design.dynamics_setup(),
        cam=cam,
    )
    return cam, st, result


GRID = np.linspace(0.0, 2.0 * math.pi, 7200, endpoint=False)
CASES = [("oscillating-roller", "ccw"), ("oscillating-roller", "cw"), ("oscillating-flat", "ccw")]


def energy(design: Design, phi: np.ndarray) -> np.ndarray:
    """Kinetic + potential energy [N·mm] of the arm at constant ω, straight from ψ and ψ′ (Lagrange)."""
    cam = Cam.from_design(design)
    m = cam.motion(phi)
    dyn, omega = design.dynamics, design.cam.omega
    psi, dpsi = np.radians(m.s), np.radians(m.v)
    kinetic = 0.5 * dyn.arm_inertia * (dpsi * omega) ** 2 / 1000.0  # kg·mm²/s² → N·mm
    spring = 0.5 * dyn.spring_rate_torsional * psi**2 + dyn.spring_preload_torsional * psi
    theta0 = design.dynamics_setup().arm_angle
    height = dyn.cg_distance * np.sin(theta0 - psi)  # the centre of mass turns clockwise by ψ
    return kinetic + spring + dyn.follower_mass * STANDARD_GRAVITY * height


@pytest.mark.parametrize(("kind", "rotation"), CASES)
def test_torque_is_the_rate_of_energy_and_does_no_net_work(kind: str, rotation: str) -> None:
    design = rocker(kind, rotation, friction_torque=0.0)
    _, _, result = run(design, GRID)
    h = 1e-5
    lagrange = (energy(design, GRID + h) - energy(design, GRID - h)) / (2.0 * h)
    scale = np.abs(result.torque).max()
    # the modified-sine and cycloidal laws have continuous acceleration: no joint terms
    assert np.abs(result.torque - lagrange).max() < 1e-5 * scale
    work = result.torque.mean() * 2.0 * math.pi
    assert abs(work) < 1e-6 * scale


@pytest.mark.parametrize(("kind", "rotation"), CASES)
def test_contact_force_balances_the_moment_about_the_pivot(kind: str, rotation: str) -> None:
    """F_C·|(X − P) × n| equals the moment M = T/ψ′ + …, with X, n from the profile in the machine frame."""
    design = rocker(kind, rotation)
    cam, st, result = run(design, GRID[::7])
    dyn, omega = design.dynamics, design.cam.omega
    m = st.motion
    psi, ddpsi = np.radians(m.s), np.radians(m.a)
    theta0 = design.dynamics_setup().arm_angle
    moment = (
        dyn.arm_inertia * ddpsi * omega**2 / 1000.0
        + dyn.spring_rate_torsional * psi
        + dyn.spring_preload_torsional
        - dyn.follower_mass * STANDARD_GRAVITY * dyn.cg_distance * np.cos(theta0 - psi)
    )
    # the force acts along the profile normal through the contact (or the roller centre)
    point = to_cam(m.phi, st.base.point if cam.has_pitch_curve else st.profile.point, -cam.sigma)
    normal = to_cam(m.phi, st.profile.normal, -cam.sigma)
    arm = point - np.asarray(cam.follower.guide.pivot)
    lever = -(arm[:, 0] * normal[:, 1] - arm[:, 1] * normal[:, 0])  # a rise turns the arm clockwise
    assert np.abs(result.contact_force * lever - moment).max() < 1e-9 * np.abs(moment).max()


def test_the_preload_advice_is_the_true_limit() -> None:
    """Jump at high speed; the advised torsional preload keeps contact, a little less does not."""
    design = rocker(spring_preload_torsional=100.0)
    fast = parse_design(
        {**_raw(design), "cam": {"base_radius": 50.0, "speed_rpm": 600.0}},
    )
    _, _, result = run(fast)
    assert result.jump
    assert result.preload_unit == "N·mm"
    assert any(path_of(f.field) == "dynamics.spring_preload_torsional" for f in result.findings)
    need = result.min_preload
    for preload, jumps in ((need * 1.001, False), (need * 0.99, True)):
        trial = parse_design(
            {
                **_raw(design),
                "cam": {"base_radius": 50.0, "speed_rpm": 600.0},
                "dynamics": {**_raw(design)["dynamics"], "spring_preload_torsional": preload},
            }
        )
        assert run(trial)[2].jump is jumps


def test_a_linear_spring_at_a_lever_is_a_torsion_spring() -> None:
    """k at lever r acts like k_t = k·r², M0 = F0·r (the spring perpendicular to the arm)."""
    torsion = rocker(spring_rate_torsional=8.0 * 30.0**2, spring_preload_torsional=120.0 * 30.0)
    linear_dyn = {
        k: v
        for k, v in _raw(torsion)["dynamics"].items()
        if k not in ("spring_rate_torsional", "spring_preload_torsional")
    }
    linear = parse_design(
        {
            **_raw(torsion),
            "dynamics": {**linear_dyn, "spring_rate": 8.0, "spring_preload": 120.0, "spring_arm": 30.0},
        }
    )
    a, b = run(torsion, GRID[::9])[2], run(linear, GRID[::9])[2]
    assert np.allclose(a.contact_force, b.contact_force, rtol=1e-12, atol=1e-9)
    assert np.allclose(a.torque, b.torque, rtol=1e-12, atol=1e-9)


def _raw(design: Design) -> dict[str, Any]:
    """The mapping rocker() built ``design`` from (rebuilt from its fields)."""
    fol, dyn = design.follower, design.dynamics
    follower: dict[str, Any] = {"type": fol.kind.word, "pivot_distance": fol.pivot_distance}
    if fol.kind.word == "oscillating-roller":
        follower |= {"roller_radius": fol.roller_radius, "arm_length": fol.arm_length}
    else:
        follower |= {"face_offset": fol.face_offset}
    return {
        "cam": {"base_radius": design.cam.base_radius, "speed_rpm": design.cam.speed_rpm},
        "follower": follower,
        "motion": [
            {"kind": "rise", "angle": 120.0, "lift": 15.0, "law": "modified-sine"},
            {"kind": "dwell", "angle": 60.0},
            {"kind": "return", "angle": 120.0, "lift": 15.0, "law": "cycloidal"},
            {"kind": "dwell", "angle": 60.0},
        ],
        "dynamics": {
            "arm_inertia": dyn.arm_inertia,
            "spring_rate_torsional": dyn.spring_rate_torsional,
            "spring_preload_torsional": dyn.spring_preload_torsional,
            "follower_mass": dyn.follower_mass,
            "cg_distance": dyn.cg_distance,
        },
    }
