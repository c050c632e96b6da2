"""Dowson–Higginson film thickness against a hand computation in SI units, and the entraining speed."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from camcad.design import parse_design
from camcad.design.paths import path_of
from camcad.dynamics.contact import contact_curvature, effective_modulus
from camcad.dynamics.film import (
    LubricationSpec,
    analyse_film,
    entraining_speed,
    minimum_film_thickness,
    reduced_modulus,
)
from camcad.dynamics.rolling import contact_motion
from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from tests.dynamics.test_life import _eccentric_circle

E_STAR = effective_modulus(modulus_1=206000.0, poisson_1=0.3, modulus_2=206000.0, poisson_2=0.3)  # MPa
OIL = LubricationSpec(
    viscosity_Pa_s=0.1, pressure_viscosity_coefficient=2.0e-8, roughness_cam_um=0.3, roughness_follower_um=0.2
)


def _hand_si(force_n: float, length_m: float, radius_m: float, speed_m_s: float) -> float:
    """h_min [m] in SI units, written out from Dowson & Higginson (1977) with 2/E' = 2(1 − ν²)/E."""
    e_prime = 206e9 / (1.0 - 0.3**2)  # Pa: two equal steels, 2/E' = 2(1 - nu^2)/E
    u = 0.1 * speed_m_s / (e_prime * radius_m)
    g = 2.0e-8 * e_prime
    w = (force_n / length_m) / (e_prime * radius_m)
    return radius_m * 2.65 * u**0.70 * g**0.54 * w**-0.13


# (force N, length mm, cam ρ mm, roller r_f mm, entraining speed mm/s)
CASES = {
    "convex nose": (1200.0, 12.0, 25.0, 10.0, 1500.0),
    "base circle": (400.0, 12.0, 40.0, 10.0, 4200.0),
    "concave flank (groove outer flank)": (800.0, 12.0, -50.0, 10.0, 2000.0),
}


@pytest.mark.parametrize("case", CASES.values(), ids=CASES.keys())
def test_film_against_a_hand_computation(case):
    force, length, rho, roller, speed = case
    kappa = contact_curvature(np.array([rho]), roller_radius=roller)
    radius_m = 1.0 / (1.0 / rho + 1.0 / roller) * 1e-3  # concave: 1/R = 1/r_f − 1/|ρ|
    assert 1.0 / kappa[0] * 1e-3 == pytest.approx(radius_m, rel=1e-12)
    h = minimum_film_thickness(
        load_per_length=np.array([force / length]),
        speed=np.array([speed]),
        curvature=kappa,
        modulus=reduced_modulus(E_STAR),
        viscosity_Pa_s=0.1,
        pressure_viscosity_coefficient=2.0e-8,
    )
    expect_m = _hand_si(force, length * 1e-3, radius_m, speed * 1e-3)
    assert h[0] * 1e-3 == pytest.approx(expect_m, rel=1e-9)
    assert 0.05e-6 < expect_m < 5e-6  # a plausible EHL film: tenths of a micrometre to micrometres


def test_film_at_the_concave_flank_is_thicker_than_on_the_convex_nose():
    """Same load and speed: the conforming (concave) contact has the larger R, so the thicker film."""
    h = minimum_film_thickness(
        load_per_length=np.full(2, 50.0),
        speed=np.full(2, 1000.0),
        curvature=contact_curvature(np.array([25.0, -50.0]), roller_radius=10.0),
        modulus=reduced_modulus(E_STAR),
        viscosity_Pa_s=0.1,
        pressure_viscosity_coefficient=2e-8,
    )
    assert h[1] > h[0]


@settings(max_examples=50, deadline=None)
@given(scale=st.floats(0.1, 10.0), w=st.floats(1.0, 1e3), u=st.floats(10.0, 1e4), kappa=st.floats(1e-3, 1.0))
def test_film_power_laws(scale, w, u, kappa):
    """h ∝ u^0.70 and ∝ w^−0.13 at fixed R (the exponents of Dowson & Higginson)."""

    def h(load, speed):
        return minimum_film_thickness(
            load_per_length=np.array([load]),
            speed=np.array([speed]),
            curvature=np.array([kappa]),
            modulus=226e3,
            viscosity_Pa_s=0.05,
            pressure_viscosity_coefficient=2e-8,
        )[0]

    base = h(w, u)
    assert h(w, scale * u) == pytest.approx(base * scale**0.70, rel=1e-9)
    assert h(scale * w, u) == pytest.approx(base * scale**-0.13, rel=1e-9)


def test_no_contact_no_speed():
    h = minimum_film_thickness(
        load_per_length=np.array([0.0, 10.0, 10.0]),
        speed=np.array([100.0, 0.0, 100.0]),
        curvature=np.array([0.1, 0.1, 0.0]),
        modulus=226e3,
        viscosity_Pa_s=0.05,
        pressure_viscosity_coefficient=2e-8,
    )
    assert math.isinf(h[0]) and h[1] == 0.0 and math.isinf(h[2])


def test_flat_face_entraining_speed_is_the_dowson_closed_form():
    """Radial flat tappet: u = ω(r_b + s + 2a)/2; the contact runs over the cam at ω(r_b + s + a)."""
    cam = _eccentric_circle(40.0, 8.0)
    phi = cam.sample_phi(math.radians(2.0))
    omega = 10.0
    m = cam.motion(phi)
    motion = contact_motion(cam, phi, omega=omega)
    assert_allclose(motion.contact_speed, omega * (40.0 + m.s + m.a), rtol=1e-12)
    assert_allclose(
        motion.entraining_speed, omega * np.abs(40.0 + m.s + 2.0 * m.a) / 2.0, rtol=1e-9, atol=1e-9
    )


def test_roller_entrains_at_the_contact_speed():
    design = parse_design(
        {
            "cam": {"base_radius": 40.0, "speed_rpm": 100.0},
            "follower": {"roller_radius": 15.0},
            "motion": [
                {"kind": "rise", "angle": 180.0, "lift": 20.0, "law": "cycloidal"},
                {"kind": "return", "angle": 180.0, "lift": 20.0, "law": "cycloidal"},
            ],
        }
    )
    cam = Cam.from_design(design)
    phi = cam.sample_phi(math.radians(3.0))
    motion = contact_motion(cam, phi, omega=5.0)
    assert motion.rolling
    assert_allclose(motion.entraining_speed, 5.0 * np.hypot(*cam.profile(phi).d1.T), rtol=1e-12)
    assert not motion.sliding_speed.any()


def test_film_ratio_minimum_and_finding():
    phi = np.linspace(0.0, 2.0 * math.pi, 361)[:-1]
    force = 500.0 + 400.0 * np.cos(phi)
    speed = 800.0 + 600.0 * np.sin(phi) ** 2
    kappa = np.full(phi.size, 0.12)
    result = analyse_film(
        phi, force, curvature=kappa, length=10.0, speed=speed, contact_modulus=E_STAR, spec=OIL
    )
    i = int(np.argmin(result.ratio))
    assert result.min_ratio == result.ratio[i] and result.angle == phi[i]
    assert_allclose(result.ratio, result.thickness_um / math.hypot(0.3, 0.2), rtol=1e-12)
    strict = LubricationSpec(
        viscosity_Pa_s=0.1,
        pressure_viscosity_coefficient=2e-8,
        roughness_cam_um=0.3,
        roughness_follower_um=0.2,
        min_film_ratio=2.0 * result.min_ratio,
    )
    (finding,) = analyse_film(
        phi, force, curvature=kappa, length=10.0, speed=speed, contact_modulus=E_STAR, spec=strict
    ).findings
    assert path_of(finding.field) == "lubrication.min_film_ratio" and finding.angle == result.angle
    assert not result.findings or result.min_ratio < 1.0


@pytest.mark.parametrize(
    "field", ["viscosity_Pa_s", "pressure_viscosity_coefficient", "roughness_cam_um", "roughness_follower_um"]
)
@pytest.mark.parametrize("value", [0.0, -1.0, math.inf])
def test_bad_lubrication_input_names_the_field(field, value):
    kwargs = {
        "viscosity_Pa_s": 0.1,
        "pressure_viscosity_coefficient": 2e-8,
        "roughness_cam_um": 0.3,
        "roughness_follower_um": 0.2,
        field: value,
    }
    with pytest.raises(DesignError) as err:
        LubricationSpec(**kwargs)
    assert path_of(err.value.path) == f"lubrication.{field}"


def test_entraining_speed_is_the_mean_of_the_surface_speeds():
    """Surfaces at −w (cam) and slip − w (follower) relative to the contact: u = |mean|."""
    w = np.array([3.0, 3.0, 0.0])
    slip = np.array([0.0, 6.0, 4.0])
    assert_allclose(entraining_speed(w, slip), [3.0, 0.0, 2.0])
