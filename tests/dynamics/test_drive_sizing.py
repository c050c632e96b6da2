"""Motor torque, RMS, regeneration and inertia ratio against closed forms; VDI 2143 characteristic values."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.integrate import quad

from camcad.design.paths import path_of
from camcad.dynamics.drive import (
    DriveMode,
    DriveSpec,
    analyse_drive,
    characteristic_values,
    motor_torque,
    segment_characteristics,
)
from camcad.errors import DesignError
from camcad.motion.laws import make_law
from camcad.motion.program import MotionProgram
from camcad.motion.segments import SegmentKind, SegmentSpec

BETA = math.pi  # rise over 180°, return over 180°
LIFT = 30.0  # mm
MASS = 2.0  # kg
RATE, PRELOAD = 0.5, 40.0  # N/mm, N
OMEGA = 2.0 * math.pi * 120.0 / 60.0  # 120 rpm


def _program(law: str = "cycloidal") -> MotionProgram:
    return MotionProgram.from_segments(
        [
            SegmentSpec(kind=SegmentKind.RISE, span=BETA, lift=LIFT, law=make_law(law)),
            SegmentSpec(kind=SegmentKind.RETURN, span=BETA, lift=LIFT, law=make_law(law)),
        ]
    )


def _cycloidal(phi: float) -> tuple[float, float, float]:
    """s, ds/dφ, d²s/dφ² of the cycloidal rise-return, written out (Rothbart 2004, §2)."""
    x, sign = (phi / BETA, 1.0) if phi < BETA else ((phi - BETA) / BETA, -1.0)
    s = LIFT * (x - math.sin(2 * math.pi * x) / (2 * math.pi))
    v = LIFT / BETA * (1 - math.cos(2 * math.pi * x))
    a = LIFT / BETA**2 * 2 * math.pi * math.sin(2 * math.pi * x)
    return (s, v, a) if sign > 0 else (LIFT - s, -v, -a)


def _cam_torque(phi: float) -> float:
    """Energy method: T = (m a ω²/1000 + k s + F0)·ds/dφ [N·mm] (Quintero & Vanegas 2016, eq. 18)."""
    s, v, a = _cycloidal(phi)
    return (MASS * a * OMEGA**2 / 1000.0 + RATE * s + PRELOAD) * v


def test_rms_torque_of_a_cycloidal_move_by_quadrature():
    """RMS of the motor torque (i = 1, η = 1) against √(mean T²) by adaptive quadrature."""
    program = _program()
    phi = np.arange(3600) * (2 * math.pi / 3600)
    m = program.evaluate(phi)
    cam_torque = (MASS * m.a * OMEGA**2 / 1000.0 + RATE * m.s + PRELOAD) * m.v
    result = analyse_drive(
        phi, axis_load=cam_torque, axis_speed=1.0, axis_acceleration=0.0, omega=OMEGA, spec=DriveSpec()
    )
    mean_square = sum(quad(lambda p: _cam_torque(p) ** 2, lo, lo + BETA, limit=200)[0] for lo in (0.0, BETA))
    expect = math.sqrt(mean_square / (2 * math.pi)) / 1000.0  # N·m
    assert result.rms_torque == pytest.approx(expect, rel=1e-6)
    assert result.max_speed_rpm == pytest.approx(120.0, rel=1e-12)


def test_gearbox_efficiency_against_the_power_flow():
    """Driving: T/(iη); regenerating: Tη/i."""
    t = motor_torque(np.array([5000.0, -5000.0]), np.array([1.0, 1.0]), transmission=4.0, efficiency=0.8)
    assert_allclose(t, [5.0 / (4.0 * 0.8), -5.0 * 0.8 / 4.0], rtol=1e-15)


@settings(max_examples=60, deadline=None)
@given(
    loads=st.lists(st.floats(-1e4, 1e4), min_size=3, max_size=40),
    ratio=st.floats(0.5, 50.0),
    eff=st.floats(0.3, 1.0),
)
def test_motor_supplies_at_least_the_load_energy(loads, ratio, eff):
    """Losses are never negative: the motor's energy over the cycle ≥ the load's (equal at η = 1)."""
    q = np.asarray(loads)
    phi = np.arange(q.size) * (2 * math.pi / q.size)
    r = analyse_drive(
        phi,
        axis_load=q,
        axis_speed=1.0,
        axis_acceleration=0.0,
        omega=1.0,
        spec=DriveSpec(gear_ratio=ratio, gear_efficiency=eff),
    )
    motor = float(np.sum(r.motor_torque * ratio)) * 1000.0  # Σ T_m ω_m in N·mm units per unit ω
    load = float(np.sum(q))
    assert motor >= load - 1e-9 * (1.0 + np.abs(q).sum())


@pytest.mark.parametrize("eff", [1.0, 0.85])
def test_servo_slide_regenerates_the_kinetic_energy(eff):
    """A pure mass on a screw, rise and return: each deceleration gives back η·½ m v_max² to the motor."""
    program = _program()
    phi = np.arange(7200) * (2 * math.pi / 7200)
    m = program.evaluate(phi)
    force = MASS * m.a * OMEGA**2 / 1000.0  # N
    spec = DriveSpec(mode=DriveMode.SERVO_FOLLOWER, screw_lead_mm=10.0, gear_ratio=2.0, gear_efficiency=eff)
    r = analyse_drive(phi, axis_load=force, axis_speed=m.v, axis_acceleration=m.a, omega=OMEGA, spec=spec)
    v_max = 2.0 * LIFT / BETA * OMEGA / 1000.0  # m/s, cycloidal C_v = 2
    assert r.regenerated_energy_J == pytest.approx(2 * eff * 0.5 * MASS * v_max**2, rel=1e-5)
    # motor speed: ṡ/p revolutions per second times i
    assert r.max_speed_rpm == pytest.approx(v_max * 1000.0 / 10.0 * 2.0 * 60.0, rel=1e-6)


def test_servo_slide_inertia_ratio_and_friction():
    """Reflected mass m(p/2π)²/i² over J_m; Coulomb friction adds μ-force against the motion."""
    phi = np.array([0.0, 1.0, 2.0, 3.0])
    spec = DriveSpec(
        mode=DriveMode.SERVO_FOLLOWER,
        screw_lead_mm=5.0,
        gear_ratio=3.0,
        motor_inertia_kg_m2=1e-5,
        axis_friction=20.0,
    )
    r = analyse_drive(
        phi,
        axis_load=np.zeros(4),
        axis_speed=np.array([1.0, -1.0, 0.0, 2.0]),
        axis_acceleration=np.zeros(4),
        omega=1.0,
        spec=spec,
        load_inertia=4.0,
    )
    assert r.inertia_ratio == pytest.approx(4.0 * (5e-3 / (2 * math.pi)) ** 2 / 9.0 / 1e-5, rel=1e-12)
    assert_allclose(r.axis_load, [20.0, -20.0, 0.0, 20.0])
    assert_allclose(r.motor_torque[0], 20.0 * 5.0 / (2 * math.pi * 3.0) / 1000.0, rtol=1e-12)


def test_checks_pass_and_fail_per_line():
    phi = np.arange(360) * (2 * math.pi / 360)
    torque = 4000.0 * np.sin(phi)  # N·mm at the cam
    spec = DriveSpec(
        gear_ratio=2.0,
        gear_efficiency=0.9,
        motor_rated_torque_Nm=1.0,
        motor_peak_torque_Nm=2.0,
        motor_max_rpm=200.0,
        motor_inertia_kg_m2=1e-3,
        camshaft_inertia_kg_m2=0.05,
    )
    r = analyse_drive(phi, axis_load=torque, axis_speed=1.0, axis_acceleration=0.0, omega=OMEGA, spec=spec)
    lines = {c.name: c for c in r.checks}
    assert lines["peak torque"].value == pytest.approx(4.0 / (2.0 * 0.9), rel=1e-9)
    assert lines["peak torque"].ok is False
    assert lines["speed"].value == pytest.approx(240.0) and lines["speed"].ok is False
    assert (
        lines["inertia ratio"].value == pytest.approx(0.05 / 4.0 / 1e-3)
        and lines["inertia ratio"].ok is False
    )
    assert {path_of(f.field) for f in r.findings} == {
        "drive.motor_peak_torque_Nm",
        "drive.motor_max_rpm",
        "drive.max_inertia_ratio",
        *(["drive.motor_rated_torque_Nm"] if not lines["RMS torque"].ok else []),
    }


# VDI 2143 Blatt 1 / Rothbart 2004 Table 3.x: published characteristic values (rounded as printed)
PUBLISHED = {
    "cycloidal": (2.00, 6.28),
    "modified-sine": (1.76, 5.53),
    "modified-trapezoid": (2.00, 4.89),
    "poly-345": (1.88, 5.77),
    "harmonic": (1.57, 4.93),
}


@pytest.mark.parametrize(("law", "values"), PUBLISHED.items(), ids=PUBLISHED.keys())
def test_characteristic_values_match_the_published(law, values):
    cv = characteristic_values(make_law(law))
    assert cv.c_v == pytest.approx(values[0], abs=0.005)
    assert cv.c_a == pytest.approx(values[1], abs=0.005)


def test_characteristic_values_closed_forms():
    """Cycloid: C_j = 4π², C_Mdyn = max 2π(1 − cos t)sin t = 3√3π/2; harmonic: C_j = π³/2, C_Mdyn = π³/8."""
    cyc = characteristic_values(make_law("cycloidal"))
    assert cyc.c_j == pytest.approx(4 * math.pi**2, rel=1e-12)
    assert cyc.c_mdyn == pytest.approx(3 * math.sqrt(3) * math.pi / 2, rel=1e-10)
    har = characteristic_values(make_law("harmonic"))
    assert har.c_j == pytest.approx(math.pi**3 / 2, rel=1e-12)
    assert har.c_mdyn == pytest.approx(math.pi**3 / 8, rel=1e-10)
    assert characteristic_values(make_law("poly-345")).c_j == pytest.approx(60.0, rel=1e-12)


def test_segment_characteristics_skip_dwells():
    program = MotionProgram.from_segments(
        [
            SegmentSpec(kind=SegmentKind.RISE, span=2.0, lift=10.0, law=make_law("modified-sine")),
            SegmentSpec(kind=SegmentKind.DWELL, span=2 * math.pi - 4.0),
            SegmentSpec(kind=SegmentKind.RETURN, span=2.0, lift=10.0, law=make_law("cycloidal")),
        ]
    )
    rows = segment_characteristics(program)
    assert [r[0] for r in rows] == [0, 2]
    assert rows[1][2].c_v == pytest.approx(2.0)


@pytest.mark.parametrize(
    ("field", "kwargs"),
    [
        ("drive.gear_efficiency", {"gear_efficiency": 0.0}),
        ("drive.gear_efficiency", {"gear_efficiency": 1.2}),
        ("drive.gear_ratio", {"gear_ratio": -2.0}),
        ("drive.motor_max_rpm", {"motor_max_rpm": 0.0}),
        ("drive.screw_lead_mm", {"screw_lead_mm": 5.0}),  # a lead on a camshaft drive
    ],
)
def test_bad_drive_input_names_the_field(field, kwargs):
    with pytest.raises(DesignError) as err:
        DriveSpec(**kwargs)
    assert path_of(err.value.path) == field
