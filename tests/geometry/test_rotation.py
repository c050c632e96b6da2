"""Issue 11.1: the follower stays where the machine puts it, whatever the rotation.

The independent construction works in the machine frame: the follower axis is
the fixed line x = e, the roller centre stands at M(φ) = (e, k + s(φ)) and the
cam turns by +φ (ccw) or −φ (cw). In the cam frame the roller centre is then
R(∓φ)·M(φ), and the profile is the set of points at distance r_f from that
curve, checked by minimising the distance over φ.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import minimize_scalar

from camcad.geometry import Cam
from tests.conftest import make_design

CASES = [(e, rot) for e in (20.0, -20.0) for rot in ("ccw", "cw")]


def cam_002(offset: float, rotation: str) -> Cam:
    """The issue's 002-style cam: r_b = 80, r_f = 15, cycloidal 25 mm over 120°."""
    return Cam.from_design(
        make_design(
            law="cycloidal",
            base_radius=80.0,
            roller_radius=15.0,
            offset=offset,
            rotation=rotation,
            lift=25.0,
            spans=(120.0, 60.0, 120.0, 60.0),
        )
    )


def machine_roller_centre(cam: Cam, offset: float, rotation: str, phi: np.ndarray) -> np.ndarray:
    """R(∓φ)·(e, k + s(φ)): the machine's roller centre seen from the turning cam."""
    s = cam.motion(phi).s
    k = math.sqrt((cam.base_radius + cam.roller_radius) ** 2 - offset**2)
    turn = -phi if rotation == "ccw" else phi  # the cam turns by +φ (ccw) or −φ (cw)
    x, y = np.full_like(s, offset), k + s
    c, sn = np.cos(turn), np.sin(turn)
    return np.column_stack((c * x - sn * y, sn * x + c * y))


@pytest.mark.parametrize(("offset", "rotation"), CASES, ids=[f"e{e:+g}-{r}" for e, r in CASES])
def test_profile_is_the_envelope_of_the_machine_roller(offset, rotation):
    cam = cam_002(offset, rotation)
    phi = np.linspace(0.0, 2 * math.pi, 61, endpoint=False)
    assert_allclose(cam.pitch(phi).point, machine_roller_centre(cam, offset, rotation, phi), atol=1e-10)

    def centre(t: float) -> np.ndarray:
        return machine_roller_centre(cam, offset, rotation, np.array([t]))[0]

    for f, c in zip(phi, cam.profile(phi).point, strict=True):
        res = minimize_scalar(
            lambda t, c=c: float(np.hypot(*(centre(t) - c))),
            bounds=(f - 0.3, f + 0.3),
            method="bounded",
            options={"xatol": 1e-12},
        )
        assert abs(res.fun - cam.roller_radius) < 1e-9


@pytest.mark.parametrize(("offset", "rotation"), CASES, ids=[f"e{e:+g}-{r}" for e, r in CASES])
def test_pressure_angle_is_the_machine_angle(offset, rotation):
    """|α| is the angle between the follower axis and the contact normal in the machine frame,
    and tan α = (v ∓ e)/(s + k) with − for ccw and + for cw (002 eq. 4 with the rotation's sign)."""
    cam = cam_002(offset, rotation)
    phi = np.linspace(0.0, 2 * math.pi, 721, endpoint=False)
    centre = machine_roller_centre(cam, offset, rotation, phi)
    normal = (centre - cam.profile(phi).point) / cam.roller_radius
    turn = -phi if rotation == "ccw" else phi
    axis = np.column_stack((-np.sin(turn), np.cos(turn)))  # the machine's +y seen from the cam
    alpha = cam.pressure_angle(phi)
    assert_allclose(np.abs(alpha), np.arccos(np.clip(np.einsum("ij,ij->i", normal, axis), -1, 1)), atol=1e-7)
    m = cam.motion(phi)
    k = math.sqrt(95.0**2 - offset**2)
    sign = -1.0 if rotation == "ccw" else 1.0
    assert_allclose(np.tan(alpha), (m.v + sign * offset) / (m.s + k), atol=1e-12)


def test_cw_offset_sees_the_real_machine_pressure_angle():
    """The issue's numbers: a cw cam with e = +20 sees about 23° at mid-rise, not about 2°."""
    mid = np.array([math.radians(60.0)])
    cw = cam_002(20.0, "cw")
    ccw = cam_002(20.0, "ccw")
    assert 22.0 < math.degrees(float(cw.pressure_angle(mid)[0])) < 24.5
    assert abs(math.degrees(float(ccw.pressure_angle(mid)[0]))) < 3.0
