"""Issue 11.2: reported extremes are true extremes, one-sided limits at joints included.

The independent truths are hand calculations from the VAP law (Quintero &
Vanegas 2016, eq. 3 differentiated twice: y″ = −2·sgn(u)(2 + k|u|)e^{k(|u|−1)},
k = (1 − b)/b, so y″(1⁻) = −2(2 + k)) and dense evaluations approaching the joint.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from camcad.design import load_design, parse_design
from camcad.geometry import Cam, analyse_geometry, min_base_radius
from camcad.pipeline import analyse
from tests.conftest import ROOT

G = 9.80665  # m/s², camcad's standard gravity


def vap_end_acceleration(lift: float, span_deg: float, b: float) -> float:
    """d²s/dφ² [mm/rad²] just before the end of a VAP rise (000 eq. 3, hand-differentiated)."""
    k = (1.0 - b) / b
    return lift * (-2.0 * (2.0 + k)) / math.radians(span_deg) ** 2


def jump_design(rpm: float = 141.6, preload: float = 5.0):
    """The issue's case: VAP b = 0.05, 30 mm over 90° into a dwell; r_b 60, r_f 10; m 0.2 kg, k 0.5 N/mm."""
    return parse_design(
        {
            "cam": {"base_radius": 60.0, "speed_rpm": rpm},
            "follower": {"roller_radius": 10.0},
            "motion": [
                {"kind": "rise", "angle": 90.0, "lift": 30.0, "law": "vap", "b": 0.05},
                {"kind": "dwell", "angle": 90.0},
                {"kind": "return", "angle": 90.0, "lift": 30.0, "law": "vap", "b": 0.05},
                {"kind": "dwell", "angle": 90.0},
            ],
            "dynamics": {"follower_mass": 0.2, "spring_rate": 0.5, "spring_preload": preload},
        }
    )


def test_jump_just_before_the_joint_is_found_with_the_right_advice():
    a = vap_end_acceleration(30.0, 90.0, 0.05)
    omega = 141.6 * 2 * math.pi / 60
    static = 0.2 * G + 0.5 * 30.0  # m·g + k·s at the end of the rise, without preload
    force = 0.2 * a * omega**2 / 1000 + static + 5.0  # α = 0 there (v = 0, radial follower)
    preload_needed = 5.0 - force
    top_rpm = math.sqrt((static + 5.0) / (-0.2 * a / 1000)) * 60 / (2 * math.pi)
    assert force == pytest.approx(-0.5, abs=0.02)  # the figures (it rounds them)
    assert preload_needed == pytest.approx(5.5, abs=0.02)
    assert top_rpm == pytest.approx(140.0, abs=0.05)

    analysis = analyse(jump_design(), fit=False, toolpath=False, strict=False)
    dyn = analysis.summary()["dynamics"]
    assert dyn["jump"] is True
    assert dyn["contact_force_min_N"] == pytest.approx(force, rel=1e-9)
    assert dyn["contact_force_min_angle_deg"] == pytest.approx(90.0)
    assert dyn["contact_force_min_side"] == "before joint"
    assert dyn["min_preload_N"] == pytest.approx(preload_needed, rel=1e-9)
    assert dyn["speed_range_rpm"][1] == pytest.approx(top_rpm, rel=1e-9)
    (warning,) = [f.message for f in analysis.findings if f.kind == "jump"]
    assert "at 90.0° (just before the joint)" in warning
    assert f"raise the preload to ≥ {math.ceil(preload_needed * 10) / 10:.1f} N" in warning  # rounded up
    assert f"keep the speed ≤ {math.floor(top_rpm * 10) / 10:.1f} rpm" in warning  # rounded down


def test_the_advice_works_and_is_tight():
    """At the advised preload or top speed contact holds; a little beyond it, it is lost."""
    dyn = analyse(jump_design(), fit=False, toolpath=False, strict=False).summary()["dynamics"]
    preload, top = dyn["min_preload_N"], dyn["speed_range_rpm"][1]
    for rpm, f0, jumps in ((141.6, preload + 1e-6, False), (141.6, preload - 1e-3, True),
                           (top - 1e-6, 5.0, False), (top + 1e-2, 5.0, True)):  # fmt: skip
        result = analyse(jump_design(rpm=rpm, preload=f0), fit=False, toolpath=False, strict=False)
        assert result.summary()["dynamics"]["jump"] is jumps, (rpm, f0)


def size_design(base_radius: float = 80.0):
    """The issue's case: VAP b = 0.1, 20 mm over 60° into a dwell, r_f = 20."""
    return parse_design(
        {
            "cam": {"base_radius": base_radius},
            "follower": {"roller_radius": 20.0},
            "motion": [
                {"kind": "rise", "angle": 60.0, "lift": 20.0, "law": "vap", "b": 0.1},
                {"kind": "dwell", "angle": 120.0},
                {"kind": "return", "angle": 60.0, "lift": 20.0, "law": "vap", "b": 0.1},
                {"kind": "dwell", "angle": 120.0},
            ],
        }
    )


def dense_min_pitch_radius(cam: Cam) -> float:
    """Smallest convex pitch-curve radius on 10^6 points plus both sides of every joint."""
    phi = np.linspace(0.0, 2 * math.pi, 1_000_000, endpoint=False)
    joints = np.array([bp.phi for bp in cam.program.breakpoints])
    rho = np.concatenate(
        [cam.pitch(phi).rho, cam.pitch(joints, side="left").rho, cam.pitch(joints, side="right").rho]
    )
    return float(rho[rho > 0].min())


def test_size_finds_the_true_smallest_base_radius():
    result = min_base_radius(Cam.from_design(size_design()))
    assert result.base_radius == pytest.approx(60.137, abs=1e-3)  # the true value
    at = Cam.from_design(size_design(result.base_radius))
    assert dense_min_pitch_radius(at) >= 20.0 - 1e-6
    below = Cam.from_design(size_design(result.base_radius - 1e-3))
    assert dense_min_pitch_radius(below) < 20.0
    # the hand calculation at the joint: ρ = R²/(R − a) for v = 0 (papers/README, 002 eq. 5) is a bound
    a = vap_end_acceleration(20.0, 60.0, 0.1)
    radius = result.base_radius + 20.0 + 20.0
    assert radius**2 / (radius - a) >= 20.0 - 1e-6


def test_check_sees_the_undercut_in_the_last_tenth_of_a_degree():
    cam = Cam.from_design(size_design(59.4))
    geo = analyse_geometry(cam, max_pressure_angle=math.radians(30))
    assert geo.undercut is not None
    assert geo.curvature_radius_min is not None
    # the profile's ρ = pitch ρ − r_f: below zero means it loops
    assert dense_min_pitch_radius(cam) - 20.0 == pytest.approx(geo.undercut.worst - 20.0, abs=1e-6)
    assert geo.undercut.worst - 20.0 == pytest.approx(-0.26, abs=0.01)


def test_quintero_peak_contact_force_is_the_limit_at_360():
    """The Quintero VAP b = 0.1 case without its spring: the peak is the limit at the end of the return."""
    design = load_design(ROOT / "samples" / "quintero_vap_b01.toml")
    design = replace(design, dynamics=replace(design.dynamics, spring_rate=0.0))
    dyn = analyse(design, fit=False, toolpath=False, strict=False).summary()["dynamics"]
    a = -vap_end_acceleration(30.0, 120.0, 0.1)  # the return mirrors the rise: a(1⁻) = +h·2(2 + k)/β²
    omega = design.cam.omega
    mass = design.dynamics.follower_mass
    force = mass * a * omega**2 / 1000 + mass * G  # s = 0, α = 0, no preload
    assert dyn["contact_force_max_N"] == pytest.approx(force, rel=1e-9)
    assert dyn["contact_force_max_angle_deg"] == pytest.approx(360.0)
    assert dyn["contact_force_max_side"] == "before joint"
    sampled = analyse_geometry(Cam.from_design(design), max_pressure_angle=1.0)
    assert sampled.phi[-1] < 2 * math.pi  # no sample sits at 360°: only the one-sided limit gives it


def test_size_command_says_where_the_limit_is_reached(tmp_path, capsys):
    from camcad.cli import main

    path = tmp_path / "vap.toml"
    rise = 'kind = "rise"\nangle = 60.0\nlift = 20.0\nlaw = "vap"\nb = 0.1'
    ret = rise.replace("rise", "return")
    dwell = 'kind = "dwell"\nangle = 120.0'
    path.write_text(
        "[cam]\nbase_radius = 80.0\n[follower]\nroller_radius = 20.0\n"
        + "".join(f"[[motion]]\n{seg}\n" for seg in (rise, dwell, ret, dwell))
    )
    assert main(["size", str(path)]) == 0
    out = capsys.readouterr().out
    assert "smallest base radius: 60.137 mm" in out
    assert "limited by curvature at cam angle 60.0° (just before the joint)" in out
