"""The free flight across a groove's clearance against closed forms (issue 31).

A free follower does not feel the cam: on a slide with a linear spring (or
none) and on an arm with a torsion spring and no weight its equation of motion
is a harmonic oscillator (or a parabola), q(t) written out here. The gap to
the groove's path along the common normal is then (q(t) − s(φ0 + ωt))·L·cos α
with s and α from the exact cam, and the touch-down is its first crossing of
the clearance (or of zero, coming back), found by a dense scan and
``scipy.optimize.brentq``: the hand-written Dormand–Prince integrator of
``camcad.dynamics.flight`` must find the same time and speed to 1e-9, and
come closer as its tolerance shrinks. (The comparison with an independent
LSODA integration of designs lives in ``tests/geometry/test_positive.py``.)
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from scipy.optimize import brentq

from camcad.design import parse_design
from camcad.dynamics.arm import ArmLoad
from camcad.dynamics.energy import STANDARD_GRAVITY, FollowerLoad
from camcad.dynamics.flight import free_flight, impact_speed
from camcad.dynamics.spring import Spring
from camcad.geometry.cam import Cam

MOTION = [  # harmonic: s″ jumps at both ends, so a flight from 95° crosses a jump of the cam's s″
    {"kind": "rise", "angle": 100.0, "lift": 20.0, "law": "harmonic"},
    {"kind": "dwell", "angle": 60.0},
    {"kind": "return", "angle": 140.0, "lift": 20.0, "law": "cycloidal"},
    {"kind": "dwell", "angle": 60.0},
]
SLIDE = {"type": "translating-roller", "roller_radius": 12.0, "offset": 8.0}
ARM = {"type": "oscillating-roller", "roller_radius": 12.0, "pivot_distance": 140.0, "arm_length": 100.0}
OMEGA = 300.0 * math.pi / 30.0  # rad/s: 300 rpm


def _cam(follower: dict[str, Any]) -> Cam:
    data = {
        "cam": {
            "name": "t",
            "base_radius": 52.0,
            "thickness": 20.0,
            "style": "groove",
            "speed_rpm": 300.0,
            "outer_radius": 140.0,
        },
        "groove": {"clearance": 0.05},
        "follower": follower,
        "motion": [dict(m) for m in MOTION],
    }
    return Cam.from_design(parse_design(data))


def _touch_down(
    cam: Cam, phi0: float, clearance: float, accel: tuple[float, float], arm: bool
) -> tuple[float, float, bool]:
    """(time [s], normal speed [mm/s], met the far flank) of the closed-form flight q̈ = −(α + λ·q).

    q(0) = s(φ0), q̇(0) = ω·s′(φ0); λ > 0: q = q_eq + (q0 − q_eq)·cos(ω_n t) + q̇0/ω_n·sin(ω_n t),
    q_eq = −α/λ, ω_n = √λ; λ = 0: q = q0 + q̇0·t − α·t²/2.
    """
    alpha, lam = accel
    start = cam.program.evaluate(np.array([phi0]), side="right")
    q0, dq0 = float(start.s[0]), float(start.v[0]) * OMEGA

    def q_of(t: np.ndarray | float) -> tuple[Any, Any]:
        if lam == 0.0:
            return q0 + dq0 * t - 0.5 * alpha * t * t, dq0 - alpha * t
        wn, q_eq = math.sqrt(lam), -alpha / lam
        return (
            q_eq + (q0 - q_eq) * np.cos(wn * t) + dq0 / wn * np.sin(wn * t),
            -(q0 - q_eq) * wn * np.sin(wn * t) + dq0 * np.cos(wn * t),
        )

    def gap(t: np.ndarray | float) -> tuple[Any, Any]:
        """(lead × L·cos α [mm], rate of the lead ė [q-units/s] × L·cos α)."""
        st = cam.state(np.atleast_1d(phi0 + OMEGA * np.asarray(t, dtype=float)), side="right")
        length = np.cos(st.pressure_angle) * (np.radians(st.lever) if arm and st.lever is not None else 1.0)
        q, dq = q_of(np.asarray(t, dtype=float))
        return (q - st.motion.s) * length, (dq - OMEGA * st.motion.v) * length

    relative = -alpha - lam * q0 - OMEGA**2 * float(start.a[0])  # ë(0): the side it drifts to
    leaving = math.copysign(1.0, relative)
    t = np.linspace(0.0, 0.5 * math.pi / OMEGA, 40001)  # a quarter turn, 0.00225° apart
    g = leaving * gap(t)[0]
    far = np.flatnonzero((g[:-1] - clearance) * (g[1:] - clearance) <= 0.0)
    back = np.flatnonzero((g[:-1] + 1e-9 * clearance >= 0.0) & (g[1:] + 1e-9 * clearance < 0.0))
    i = min(np.concatenate((far, back)))
    offset = -clearance if i in far else 1e-9 * clearance
    hit = brentq(lambda x: leaving * float(gap(x)[0][0]) + offset, t[i], t[i + 1], xtol=1e-16, rtol=8.9e-16)
    return hit, abs(float(gap(hit)[1][0])), bool(i in far)


def _errors(
    cam: Cam,
    load: FollowerLoad | ArmLoad,
    accel: tuple[float, float],
    phi0: float,
    clearance: float,
    *,
    arm: bool = False,
    rtol: float = 1e-10,
) -> tuple[float, float, bool]:
    """Relative errors of the touch-down time and speed against the closed form, and which flank it meets.

    The flight starts towards the side its relative acceleration ë(0) = −(α + λ·s) − ω²·s″ points to.
    """
    t, speed, far = _touch_down(cam, phi0, clearance, accel, arm)
    start = cam.program.evaluate(np.array([phi0]), side="right")
    leaving = math.copysign(1.0, -accel[0] - accel[1] * float(start.s[0]) - OMEGA**2 * float(start.a[0]))
    landing = free_flight(cam, phi0, load=load, omega=OMEGA, clearance=clearance, leaving=leaving, rtol=rtol)
    assert landing is not None and landing.far == far
    if rtol == 1e-10:  # the default: what a build reports
        assert impact_speed(cam, phi0, load=load, omega=OMEGA, clearance=clearance, leaving=leaving) == (
            landing.speed
        )
    return abs(landing.time / t - 1.0), abs(landing.speed / speed - 1.0), far


def _slide(mass: float, rate: float, preload: float) -> tuple[FollowerLoad, tuple[float, float]]:
    """The load and its q̈ = −(α + λ·q) [mm/s²]: m·q̈/1000 = −(m·g + k·q + F0)."""
    load = FollowerLoad(mass=mass, spring=Spring(rate=rate, preload=preload))
    return load, (1000.0 * (mass * STANDARD_GRAVITY + preload) / mass, 1000.0 * rate / mass)


@pytest.mark.parametrize("phi0_deg", [20.0, 60.0, 95.0, 200.0, 250.0])
@pytest.mark.parametrize("spring", [(0.0, 0.0), (3.0, 20.0)], ids=["weight", "spring"])
def test_slide_flight_against_the_harmonic_oscillator(spring: tuple[float, float], phi0_deg: float) -> None:
    load, accel = _slide(2.0, *spring)
    err_t, err_v, far = _errors(_cam(SLIDE), load, accel, math.radians(phi0_deg), 0.05)
    assert far and err_t < 1e-9 and err_v < 1e-9


def test_arm_flight_against_the_harmonic_oscillator() -> None:
    # I·ψ̈/1000 = −(k_t·ψ + M0) [N·mm], ψ in rad; in degrees q̈ = −(1000·k_t/I)·q − 1000·M0·180/(π·I)
    inertia, k_t, m0 = 8000.0, 3000.0, 150.0
    load = ArmLoad(inertia=inertia, spring_rate=k_t, preload=m0)
    accel = (1000.0 * m0 * 180.0 / (math.pi * inertia), 1000.0 * k_t / inertia)
    cam = _cam(ARM)
    for phi0 in np.radians([15.0, 80.0, 97.0, 190.0, 270.0]):
        err_t, err_v, far = _errors(cam, load, accel, float(phi0), 0.03, arm=True)
        assert far and err_t < 1e-9 and err_v < 1e-9


def test_a_flight_that_turns_back_lands_on_the_flank_it_left() -> None:
    # 10° into the return the groove falls away faster than the weight pulls the slide down,
    # then slows: with 3 mm of play it catches the follower again before the other flank
    load, accel = _slide(2.0, 0.0, 0.0)
    err_t, err_v, far = _errors(_cam(SLIDE), load, accel, math.radians(170.0), 3.0)
    assert not far and err_t < 1e-9 and err_v < 1e-9


def test_the_error_shrinks_with_the_tolerance() -> None:
    # a stiff spring (ω_n = 707 rad/s against 31 rad/s of the cam) and 1 mm of play: the
    # tolerance, not the 1° step limit, sets the steps; the error follows it down
    load, accel = _slide(2.0, 500.0, 2000.0)
    cam = _cam(SLIDE)
    for phi0 in np.radians([20.0, 95.0, 200.0]):
        errors = [max(_errors(cam, load, accel, float(phi0), 1.0, rtol=r)[:2]) for r in (1e-6, 1e-8, 1e-10)]
        assert errors[0] > 10.0 * errors[1] > 100.0 * errors[2]
        assert errors[2] < 1e-10
