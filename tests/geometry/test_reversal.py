"""A rise that runs backwards is a soft finding (issue 16's blend polynomials can overshoot).

Independent truth: the smallest ds/dφ of the rise on 10⁶ angles of the exact
motion; the finding's value and angle must match it, and no fixed law ever
raises the finding (they are monotone by construction).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camcad.design import parse_design
from camcad.geometry import Cam, analyse_geometry
from tests.conftest import make_design


def _web_cutter(lift: float):
    return parse_design(
        {
            "cam": {"base_radius": 80.0, "speed_rpm": 60.0, "max_pressure_angle": 40.0},
            "follower": {"type": "translating-roller", "roller_radius": 12.0},
            "motion": [
                {"kind": "dwell", "angle": 60.0},
                {"kind": "rise", "angle": 60.0, "lift": lift, "law": "polynomial", "degree": 7},
                {"kind": "rise", "angle": 60.0, "law": "constant-velocity", "velocity": 200.0},
                {"kind": "return", "angle": 120.0, "lift": "close", "law": "polynomial", "degree": 7},
                {"kind": "dwell", "angle": 60.0},
            ],
        }
    )


def _findings(design):
    cam = Cam.from_design(design)
    geo = analyse_geometry(cam, max_pressure_angle=design.cam.max_pressure_angle)
    return cam, [f for f in geo.findings if f.kind == "motion reversal"]


def test_a_short_rise_into_speed_runs_backwards_and_is_reported() -> None:
    cam, found = _findings(_web_cutter(10.0))
    found = [f for f in found if f.field == "motion[1].lift"]  # the return's overshoot: below
    assert len(found) == 1
    (f,) = found
    assert f.field == "motion[1].lift" and not f.hard
    phi = np.linspace(math.radians(60.0), math.radians(120.0), 1_000_001)
    v = cam.motion(phi).v
    assert v.min() < 0.0
    assert f.value == pytest.approx(v.min(), abs=1e-9)
    assert f.angle == pytest.approx(phi[np.argmin(v)], abs=1e-5)


def test_enough_lift_is_monotone_and_fixed_laws_never_reverse() -> None:
    assert [f for f in _findings(_web_cutter(20.0))[1] if f.field == "motion[1].lift"] == []
    for law in ("cycloidal", "harmonic", "poly-345", "modified-sine", "modified-trapezoid"):
        assert _findings(make_design(law=law))[1] == []


def test_a_return_out_of_speed_runs_forwards_beyond_its_start_and_is_reported() -> None:
    # issue 31: the return carries on at the constant-velocity stretch's speed before it turns back;
    # truth: the highest s on 10⁶ angles of the return, refined where ds/dφ = 0 by brentq
    from scipy.optimize import brentq

    cam, found = _findings(_web_cutter(20.0))
    (f,) = [f for f in found if f.field == "motion[3].lift"]
    assert not f.hard and f.unit == "mm" and "runs forwards" in f.message
    phi = np.linspace(math.radians(180.0), math.radians(300.0), 1_000_001)
    s = cam.motion(phi).s
    i = int(np.argmax(s))
    top = brentq(lambda p: float(cam.motion(np.array([p])).v[0]), phi[i - 1], phi[i + 1], xtol=1e-14)
    start = float(cam.motion(np.array([math.radians(180.0)])).s[0])
    assert f.angle == pytest.approx(top, abs=1e-9)
    assert f.value == pytest.approx(float(cam.motion(np.array([top])).s[0]) - start, abs=1e-9)
    assert f.value > 10.0  # the sample's return overshoots by about 10.4 mm
