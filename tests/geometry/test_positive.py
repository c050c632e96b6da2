"""Groove cams and conjugate pairs (issue 15) against independent truths.

- flanks: distance to the pitch curve by minimisation (r_f + c/2), groove width
  constant;
- conjugate pairs: each roller centre, built in the machine frame from the
  first follower's own motion (a rigid yoke on a slide, a second arm on the
  same pivot), touches its plate at every φ (minimisation over the plate's
  profile, and no point of the plate inside the roller);
- constant breadth: one plate for both rollers exactly when s(φ + 180°) = h − s(φ);
- crossovers: roots of the follower's generalised force computed from the
  motion law alone, and the impact speed by integrating the free flight
  across the clearance on the exact motion (Norton 2009, §8.11).
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

from camcad.design import parse_design
from camcad.design.paths import path_of
from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.envelope import to_cam
from camcad.geometry.groove import analyse_groove, groove_flanks
from camcad.pipeline import analyse
from tests.conftest import ROOT, distance_to_polygon

PHI = np.linspace(0.0, 2.0 * math.pi, 97, endpoint=False) + 0.011


def _design(style: str, follower: dict[str, Any], motion: list[dict[str, Any]], **extra: Any) -> Any:
    data: dict[str, Any] = {
        "cam": {"name": "t", "base_radius": 50.0, "thickness": 20.0, "style": style, "speed_rpm": 200.0},
        "follower": follower,
        "motion": motion,
    }
    for key, value in extra.items():
        data.setdefault(key, {}).update(value)
    return parse_design(data)


RDRD = [
    {"kind": "rise", "angle": 140.0, "lift": 20.0, "law": "modified-sine"},
    {"kind": "dwell", "angle": 40.0},
    {"kind": "return", "angle": 140.0, "lift": 20.0, "law": "cycloidal"},
    {"kind": "dwell", "angle": 40.0},
]
SLIDE = {"type": "translating-roller", "roller_radius": 12.0, "offset": 8.0}
ARM = {"type": "oscillating-roller", "roller_radius": 12.0, "pivot_distance": 140.0, "arm_length": 100.0}


def _nearest_on(curve: Any, phi: float, target: np.ndarray) -> float:
    """min over φ' near φ of |curve(φ') − target|, by bounded minimisation."""

    def dist(t: float) -> float:
        return float(np.hypot(*(curve(np.array([t])).point[0] - target)))

    res = minimize_scalar(dist, bounds=(phi - 0.4, phi + 0.4), method="bounded", options={"xatol": 1e-12})
    return float(res.fun)


@pytest.mark.parametrize("follower", [SLIDE, ARM], ids=["slide", "arm"])
@pytest.mark.parametrize("rotation", ["ccw", "cw"])
def test_groove_flanks_lie_at_half_width_from_the_pitch_curve(follower: dict, rotation: str) -> None:
    design = _design(
        "groove",
        follower,
        [dict(m) for m in RDRD],
        cam={"outer_radius": 120.0, "rotation": rotation},
        groove={"clearance": 0.04},
    )
    cam = Cam.from_design(design)
    inner, outer = groove_flanks(cam, PHI, 0.04)
    half = 12.0 + 0.02
    for k in range(0, PHI.size, 8):
        for flank in (inner, outer):
            assert _nearest_on(cam.pitch, float(PHI[k]), flank.point[k]) == pytest.approx(half, abs=1e-8)
    # the width across the groove, measured along the common normal, is 2 r_f + c everywhere
    width = np.einsum("ij,ij->i", outer.point - inner.point, cam.pitch(PHI).normal)
    assert np.abs(width - 2.0 * half).max() < 1e-9
    assert analyse_groove(cam, clearance=0.04).width == pytest.approx(2.0 * half, abs=1e-12)


@pytest.mark.parametrize(
    ("base_radius", "lift", "span", "flanks"),
    [(15.0, 40.0, 50.0, {"outer"}), (12.0, 30.0, 40.0, {"inner", "outer"})],
)
def test_groove_loops_are_hard_findings_naming_the_base_radius(
    base_radius: float, lift: float, span: float, flanks: set[str]
) -> None:
    rest = 180.0 - span
    design = _design(
        "groove",
        SLIDE | {"offset": 0.0},
        [
            {"kind": "rise", "angle": span, "lift": lift, "law": "cycloidal"},
            {"kind": "dwell", "angle": rest},
            {"kind": "return", "angle": span, "lift": lift, "law": "cycloidal"},
            {"kind": "dwell", "angle": rest},
        ],
        cam={"outer_radius": 140.0, "base_radius": base_radius, "bore": 10.0},
    )
    cam = Cam.from_design(design)
    result = analyse_groove(cam, clearance=0.02)
    found = {f.message.split("groove's ")[1].split(" ")[0]: f for f in result.findings if f.hard}
    assert set(found) == flanks
    assert all(path_of(f.field) == "cam.base_radius" for f in found.values())
    # independent: the pitch curve's smallest convex and concave radii on a dense grid
    rho = cam.pitch(np.linspace(0.0, 2.0 * math.pi, 400_000, endpoint=False)).rho
    dense = {"inner": rho[rho > 0.0].min(), "outer": (-rho[rho < 0.0]).min()}
    for flank, finding in found.items():
        assert finding.value == pytest.approx(dense[flank], abs=1e-6)
        assert dense[flank] < 12.01
    for flank in {"inner", "outer"} - flanks:
        assert dense[flank] > 12.01


def _machine_centres(cam: Cam, partner: Cam, phi: np.ndarray, design: Any) -> tuple[np.ndarray, np.ndarray]:
    """Both roller centres in the machine frame, built from the first follower's motion alone."""
    first = cam.follower.trace(cam.motion(phi)).m0  # machine frame (tested in test_oscillating/test_cam)
    conj = design.conjugate
    pivot = cam.follower.guide.pivot
    if pivot is None:  # a yoke: the second roller rides rigidly with the first
        joints = np.array([bp.phi for bp in cam.program.breakpoints])  # the top of a lift is at a joint
        top_phi = joints[np.argmax(cam.motion(joints).s)]
        top = cam.follower.trace(cam.motion(np.array([top_phi]))).m0[0]
        r2 = conj.roller_radius or cam.roller_radius
        c, s = math.cos(conj.angle), math.sin(conj.angle)
        u = top / np.hypot(*top)
        second_top = (cam.base_radius + r2) * np.array([c * u[0] - s * u[1], s * u[0] + c * u[1]])
        return first, first + (second_top - top)
    p = np.asarray(pivot)
    c, s = math.cos(conj.angle), math.sin(conj.angle)
    rel = first - p
    return first, p + np.column_stack((c * rel[:, 0] - s * rel[:, 1], s * rel[:, 0] + c * rel[:, 1]))


@pytest.mark.parametrize(
    ("follower", "conjugate"),
    [(SLIDE, {"angle": 180.0, "roller_radius": 10.0}), (ARM, {"angle": 80.0, "roller_radius": 14.0})],
    ids=["yoke", "two-arms"],
)
@pytest.mark.parametrize("rotation", ["ccw", "cw"])
def test_both_rollers_touch_their_plates_at_every_angle(
    follower: dict, conjugate: dict, rotation: str
) -> None:
    design = _design(
        "conjugate", follower, [dict(m) for m in RDRD], cam={"rotation": rotation}, conjugate=conjugate
    )
    cam = Cam.from_design(design)
    partner = cam.partner(design.conjugate)
    phi = np.union1d(np.linspace(0.0, 2.0 * math.pi, 2000, endpoint=False), PHI)
    m1, m2 = _machine_centres(cam, partner, phi, design)
    sigma = cam.sigma
    seen1, seen2 = to_cam(phi, m1, sigma), to_cam(phi, m2, sigma)  # the centres seen from the turning cam
    dense = np.linspace(0.0, 2.0 * math.pi, 100_000, endpoint=False)
    plate1, plate2 = cam.profile(dense).point, partner.profile(dense).point
    r1, r2 = cam.roller_radius, conjugate["roller_radius"]
    for k in range(0, phi.size, 40):
        assert _nearest_on(cam.profile, float(phi[k]), seen1[k]) == pytest.approx(r1, abs=1e-7)
        assert _nearest_on(partner.profile, float(phi[k]), seen2[k]) == pytest.approx(r2, abs=1e-7)
    # no part of either plate inside its roller (a dense polygon: within the chord sag)
    assert distance_to_polygon(seen1, plate1).min() > r1 - 1e-4
    assert distance_to_polygon(seen2, plate2).min() > r2 - 1e-4
    # the tie is rigid: a yoke keeps its centres' distance, two arms keep their length on one pivot
    if cam.follower.guide.pivot is None:
        gap = np.hypot(*(m2 - m1).T)
        assert np.ptp(gap) < 1e-9
    else:
        pivot = np.asarray(cam.follower.guide.pivot)
        assert np.abs(np.hypot(*(m2 - pivot).T) - 100.0).max() < 1e-9


SYMMETRIC = [
    {"kind": "rise", "angle": 180.0, "lift": 16.0, "law": "cycloidal"},
    {"kind": "return", "angle": 180.0, "lift": 16.0, "law": "cycloidal"},
]


def test_constant_breadth_pair_is_one_plate() -> None:
    design = _design(
        "conjugate",
        SLIDE | {"offset": 0.0},
        SYMMETRIC,
        conjugate={"angle": 180.0, "single_plate": True},
    )
    cam = Cam.from_design(design)
    partner = cam.partner(design.conjugate)
    dense = np.linspace(0.0, 2.0 * math.pi, 200_000, endpoint=False)
    # the second roller's plate is the first plate itself (as point sets)
    gap = distance_to_polygon(partner.profile(PHI).point, cam.profile(dense).point)
    assert gap.max() < 1e-5
    # and the breadth across the yoke is constant: 2 r_b + 2 r_f + h between the roller centres
    m1, m2 = _machine_centres(cam, partner, PHI, design)
    assert np.abs(np.hypot(*(m2 - m1).T) - (2 * 50.0 + 2 * 12.0 + 16.0)).max() < 1e-9


def test_constant_breadth_refuses_an_asymmetric_program() -> None:
    with pytest.raises(DesignError) as info:
        _design(
            "conjugate",
            SLIDE | {"offset": 0.0},
            [dict(m) for m in RDRD],
            conjugate={"angle": 180.0, "single_plate": True},
        )
    assert info.value.path == "motion"
    assert "s(φ + 180°)" in str(info.value)


@pytest.mark.parametrize(
    ("table", "value", "field"),
    [
        ({"groove": {"depth": 5.0}}, None, "groove"),  # a [groove] table on a plate cam
        ({"cam": {"style": "groove"}}, None, "cam.outer_radius"),  # the blank is required
        ({"cam": {"style": "groove", "outer_radius": 70.0}}, None, "cam.outer_radius"),  # no room
        (
            {"cam": {"style": "groove", "outer_radius": 120.0}, "groove": {"depth": 25.0}},
            None,
            "groove.depth",
        ),
    ],
)
def test_groove_input_errors_name_the_field(table: dict, value: Any, field: str) -> None:
    data: dict[str, Any] = {
        "cam": {"name": "t", "base_radius": 50.0, "thickness": 20.0},
        "follower": dict(SLIDE),
        "motion": [dict(m) for m in RDRD],
    }
    for key, extra in table.items():
        data.setdefault(key, {}).update(extra)
    with pytest.raises(DesignError) as info:
        parse_design(data)
    assert info.value.path == field


def _crossover_roots(cam: Cam, force_of_motion: Any) -> list[float]:
    """Sign changes of a generalised force computed from the motion alone, zero stretches passed over."""
    grid = np.linspace(0.0, 2.0 * math.pi, 36_001)
    f = force_of_motion(cam.motion(grid))
    live = np.flatnonzero(np.abs(f) > 1e-9 * np.abs(f).max())
    roots = []
    for i, n in itertools.pairwise(live):
        if np.sign(f[i]) != np.sign(f[n]):
            if n == i + 1:
                roots.append(
                    brentq(
                        lambda p: float(force_of_motion(cam.motion(np.array([p])))[0]),
                        grid[i],
                        grid[n],
                        xtol=1e-13,
                    )
                )
            else:
                roots.append(float(grid[n - 1]))  # a rest ends at a joint on the grid (whole degrees)
    return sorted(r % (2.0 * math.pi) for r in roots)


def test_crossovers_of_a_groove_slide_where_inertia_balances_weight() -> None:
    # a translating follower of mass m in a groove: F ∝ m(s̈ + g); it changes flank where s̈ = −g
    design = _design(
        "groove",
        SLIDE,
        [dict(m) for m in RDRD],
        cam={"outer_radius": 120.0, "speed_rpm": 300.0},
        groove={"clearance": 0.05},
        dynamics={"follower_mass": 2.0},
    )
    result = analyse(design, fit=False, toolpath=False)
    omega = design.cam.omega
    cam = result.cam
    expected = _crossover_roots(cam, lambda m: m.a * omega**2 + 9806.65)  # standard gravity, mm/s²
    assert len(expected) >= 2
    assert sorted(result.dynamics.crossovers) == pytest.approx(expected, abs=1e-9)


def _free_flight_speed(
    cam: Cam, phi0: float, omega: float, c: float, lever: float | None, accel: Any
) -> float:
    """Normal approach speed [mm/s] when the free follower meets a flank, integrated by LSODA.

    The follower's own equation of motion q̈ = accel(q) (q in mm, or in rad of
    swing on an arm), started on the groove's path with its speed; the gap to
    the path along the common normal is (q − q_cam)·L·cos α (L = 1 on a slide,
    the lever on an arm), and a flank is met at |gap| = c, or back at 0.
    """
    deg = lever is not None
    k = math.pi / 180.0 if deg else 1.0  # the motion's unit (° of swing) to rad

    def cam_at(t: float) -> tuple[float, float, float]:
        st = cam.state(np.array([phi0 + omega * t]), side="right")
        length = (float(st.lever[0]) if deg else 1.0) * math.cos(float(st.pressure_angle[0]))
        return float(st.motion.s[0]) * k, float(st.motion.v[0]) * k * omega, length

    def rhs(t: float, y: np.ndarray) -> list[float]:
        return [y[1], accel(y[0])]

    def gap(t: float, y: np.ndarray) -> float:
        q, _, length = cam_at(t)
        return (y[0] - q) * length

    def far(t: float, y: np.ndarray) -> float:
        return abs(gap(t, y)) - c

    def home(t: float, y: np.ndarray) -> float:  # back on the flank it left (past round-off in q − q_cam)
        return gap(t, y) * lead + 1e-6 * c

    far.terminal = home.terminal = True
    q0, dq0, _ = cam_at(0.0)
    probe = solve_ivp(rhs, (0.0, 1e-3), [q0, dq0], method="LSODA", rtol=1e-12, atol=1e-15)
    lead = math.copysign(1.0, gap(1e-3, probe.y[:, -1]))  # the side it drifts to
    home.direction = -1.0
    sol = solve_ivp(
        rhs,
        (0.0, 2.0 * math.pi / omega),
        [q0, dq0],
        method="LSODA",
        rtol=1e-12,
        atol=1e-15,
        events=(far, home),
        max_step=1e-3,
    )
    t, y = next((te[0], ye[0]) for te, ye in zip(sol.t_events, sol.y_events, strict=True) if te.size)
    _, dq, length = cam_at(t)
    return abs(y[1] - dq) * length


def test_impact_speed_against_the_free_flight_across_the_clearance() -> None:
    # the sample: an arm with nothing but its inertia, which flies straight on
    design = parse_design_file("groove_rocker.toml")
    result = analyse(design, fit=False, toolpath=False)
    crossovers, speeds = result.dynamics.crossovers, result.dynamics.impact_speeds
    assert crossovers and len(speeds) == len(crossovers)
    for phi0, speed in zip(crossovers, speeds, strict=True):
        expected = _free_flight_speed(
            result.cam, phi0, design.cam.omega, design.groove.clearance, 100.0, lambda q: 0.0
        )
        assert speed == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("spring", [(0.0, 0.0), (0.3, 2.0)], ids=["weight", "spring"])
def test_impact_speed_of_a_slide_under_weight_and_spring(spring: tuple[float, float]) -> None:
    # m·ẍ = −(m·g + k·x + F0) in N with ẍ in mm/s² / 1000: the spring and weight act in the flight
    rate, preload = spring
    mass, c = 2.0, 0.05
    design = _design(
        "groove",
        SLIDE,
        [dict(m) for m in RDRD],
        cam={"outer_radius": 120.0, "speed_rpm": 300.0},
        groove={"clearance": c},
        dynamics={"follower_mass": mass, "spring_rate": rate, "spring_preload": preload},
    )
    result = analyse(design, fit=False, toolpath=False)
    crossovers, speeds = result.dynamics.crossovers, result.dynamics.impact_speeds
    assert len(crossovers) >= 2 and len(speeds) == len(crossovers)

    def accel(x: float) -> float:
        return -1000.0 * (mass * 9.80665 + rate * x + preload) / mass

    for phi0, speed in zip(crossovers, speeds, strict=True):
        expected = _free_flight_speed(result.cam, phi0, design.cam.omega, c, None, accel)
        assert speed == pytest.approx(expected, rel=1e-6)


def test_impact_speed_of_an_arm_with_a_torsion_spring() -> None:
    # I·ψ̈ / 1000 = −(k_t·ψ + M0) [N·mm], ψ in rad: the spring pulls the free arm back
    inertia, k_t, m0 = 8000.0, 3000.0, 150.0
    design = _design(
        "groove",
        ARM,
        [dict(m) for m in RDRD],
        cam={"outer_radius": 140.0, "speed_rpm": 240.0, "base_radius": 52.0},
        groove={"clearance": 0.03},
        dynamics={"arm_inertia": inertia, "spring_rate_torsional": k_t, "spring_preload_torsional": m0},
    )
    result = analyse(design, fit=False, toolpath=False)
    crossovers, speeds = result.dynamics.crossovers, result.dynamics.impact_speeds
    assert crossovers and len(speeds) == len(crossovers)
    for phi0, speed in zip(crossovers, speeds, strict=True):
        expected = _free_flight_speed(
            result.cam, phi0, design.cam.omega, 0.03, 100.0, lambda psi: -1000.0 * (k_t * psi + m0) / inertia
        )
        assert speed == pytest.approx(expected, rel=1e-6)


def parse_design_file(name: str) -> Any:
    from camcad.design import load_design

    return load_design(ROOT / "samples" / name)
