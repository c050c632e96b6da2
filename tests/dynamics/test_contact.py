"""Hertz line contact (Johnson 1985, §4.3, eq. 4.45) between cam and roller or flat face."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.integrate import quad

from camcad.dynamics import contact_curvature, effective_modulus, hertz_half_width, hertz_stress

STEEL = {"modulus_1": 206000.0, "poisson_1": 0.3, "modulus_2": 206000.0, "poisson_2": 0.3}


def test_effective_modulus_of_steel_on_steel_by_hand():
    """1/E* = 2·(1 − 0.09)/206000 → E* = 206000/1.82 = 113186.81 MPa."""
    assert effective_modulus(**STEEL) == pytest.approx(206000.0 / 1.82, rel=1e-15)


def test_roller_on_flat_by_hand():
    """Steel roller r = 10 mm on a flat face, F = 1000 N over L = 10 mm.

    1/R* = 1/10 → p0 = √(F E*/(π L R*)) = √(1000·113186.81·0.1/(π·10)) = 600.24 MPa.
    """
    e_star = effective_modulus(**STEEL)
    stress = hertz_stress([1000.0], curvature=[0.1], length=10.0, modulus=e_star)
    assert stress[0] == pytest.approx(math.sqrt(1000.0 * 113186.8131868 * 0.1 / (math.pi * 10.0)), rel=1e-9)
    assert stress[0] == pytest.approx(600.24, abs=0.01)


finite = {"allow_nan": False, "allow_infinity": False}


@settings(max_examples=80, deadline=None)
@given(
    force=st.floats(0.1, 1e5, **finite),
    curvature=st.floats(1e-4, 10.0, **finite),
    length=st.floats(0.5, 100.0, **finite),
    modulus=st.floats(1e3, 5e5, **finite),
)
def test_peak_pressure_matches_half_width_form(force, curvature, length, modulus):
    """Independent form: b = √(4 F R*/(π L E*)) and p0 = 2F/(π b L) (mean pressure π/4·p0)."""
    b = hertz_half_width([force], curvature=[curvature], length=length, modulus=modulus)[0]
    assert b == pytest.approx(math.sqrt(4.0 * force / (curvature * math.pi * length * modulus)), rel=1e-12)
    p0 = hertz_stress([force], curvature=[curvature], length=length, modulus=modulus)[0]
    assert p0 == pytest.approx(2.0 * force / (math.pi * b * length), rel=1e-12)
    # the elliptical distribution p0·√(1 − x²/b²) carries the load
    per_length, _ = quad(lambda x: p0 * math.sqrt(max(0.0, 1.0 - (x / b) ** 2)), -b, b)
    assert per_length * length == pytest.approx(force, rel=1e-6)


@pytest.mark.parametrize(
    ("rho", "roller", "expected"),
    [
        (30.0, 10.0, 1 / 30 + 1 / 10),  # convex cam + roller
        (-30.0, 10.0, 1 / 10 - 1 / 30),  # concave cam + roller
        (30.0, None, 1 / 30),  # convex cam + flat face
        (np.inf, 10.0, 1 / 10),  # straight flank + roller
        (np.inf, None, 0.0),  # flat on flat: conforming, no Hertz peak
        (-8.0, 10.0, 0.0),  # pocket sharper than the roller (undercut): clipped to 0
    ],
    ids=["convex-roller", "concave-roller", "convex-flat", "straight-roller", "straight-flat", "undercut"],
)
def test_contact_curvature_cases(rho, roller, expected):
    assert contact_curvature([rho], roller_radius=roller)[0] == pytest.approx(expected, rel=1e-15)


def test_no_stress_without_contact():
    stress = hertz_stress([-5.0, 0.0, 10.0], curvature=[0.1, 0.1, 0.0], length=10.0, modulus=1e5)
    assert_allclose(stress, 0.0)
    assert not stress.flags.writeable
