"""Roller L10 (ISO 281) and track surface fatigue (Cam Design Handbook §9) against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from camcad.design import parse_design
from camcad.design.paths import path_of
from camcad.dynamics.contact import contact_curvature, effective_modulus, hertz_stress
from camcad.dynamics.life import (
    PSI_PER_MPA,
    ROLLER_EXPONENT,
    LifeSpec,
    LoadStressLine,
    equivalent_load,
    life_findings,
    load_stress_factor,
    roller_l10,
    roller_life,
    roller_turns_per_cam_turn,
    summary_entry,
    track_life,
)
from camcad.dynamics.rolling import contact_motion
from camcad.errors import DesignError
from camcad.geometry.cam import Cam

OMEGA = 2.0 * math.pi * 100.0 / 60.0  # 100 rpm


def _grid(n: int = 3600) -> np.ndarray:
    return np.arange(n) * (2.0 * math.pi / n)


@pytest.mark.parametrize("p", [3.0, ROLLER_EXPONENT], ids=["ball", "roller"])
def test_l10_constant_load_is_the_closed_form(p):
    """F ≡ F0: P = F0 whatever the roller's speed, L10 = (C/F0)^p, hours from the revolutions."""
    phi = _grid(720)
    rng = np.random.default_rng(1)
    arc = 10.0 + 40.0 * rng.random(phi.size)  # any positive arc speed [mm/rad]
    spec = LifeSpec(roller_dynamic_load_rating=12_000.0, roller_life_exponent=p, hours_per_day=16.0)
    life = roller_life(phi, np.full(phi.size, 800.0), arc, roller_radius=15.0, omega=OMEGA, spec=spec)
    assert life.equivalent_load == pytest.approx(800.0, rel=1e-12)
    assert life.l10_million_revolutions == pytest.approx((12_000.0 / 800.0) ** p, rel=1e-12)
    turns = float(np.sum(arc)) * (2.0 * math.pi / phi.size) / (2.0 * math.pi * 15.0)
    hours = (12_000.0 / 800.0) ** p * 1e6 / (turns * 100.0 / 60.0) / 3600.0
    assert life.hours == pytest.approx(hours, rel=1e-12)
    assert life.days == pytest.approx(hours / 16.0, rel=1e-12)


def test_l10_two_level_load():
    """Two loads over n1 and n2 roller revolutions: P = ((F1^p n1 + F2^p n2)/(n1 + n2))^(1/p)."""
    phi = _grid(36_000)
    first = phi < math.pi
    force = np.where(first, 1500.0, 600.0)
    arc = np.where(first, 20.0, 60.0)  # the roller turns 3 times as fast on the second half
    p = ROLLER_EXPONENT
    n1, n2 = 20.0 * math.pi, 60.0 * math.pi  # arc length [mm] over each half
    expect = ((1500.0**p * n1 + 600.0**p * n2) / (n1 + n2)) ** (1.0 / p)
    spec = LifeSpec(roller_dynamic_load_rating=9000.0)
    life = roller_life(phi, force, arc, roller_radius=10.0, omega=OMEGA, spec=spec)
    # the periodic trapezoid smears each jump over one interval (1e-4 of the turn)
    assert life.equivalent_load == pytest.approx(expect, rel=1e-3)
    assert life.l10_million_revolutions == pytest.approx((9000.0 / expect) ** p, rel=4e-3)
    assert life.turns_per_cam_turn == pytest.approx((n1 + n2) / (2.0 * math.pi * 10.0), rel=1e-4)


@settings(max_examples=60, deadline=None)
@given(
    loads=st.lists(st.floats(0.0, 1e5), min_size=2, max_size=30),
    scale=st.floats(0.01, 100.0),
    p=st.sampled_from([3.0, ROLLER_EXPONENT]),
)
def test_equivalent_load_bounds_and_homogeneity(loads, scale, p):
    """min F ≤ P ≤ max F, and P(λF) = λP(F) (ISO 281 §7.2 is a power mean)."""
    f = np.asarray(loads)
    dn = np.linspace(1.0, 2.0, f.size)
    load = equivalent_load(f, dn, exponent=p)
    assert f.min() * (1 - 1e-12) <= load <= f.max() * (1 + 1e-12)
    assert equivalent_load(scale * f, dn, exponent=p) == pytest.approx(scale * load, rel=1e-9, abs=1e-300)


def test_l10_unloaded_is_infinite():
    assert math.isinf(roller_l10(1000.0, 0.0, exponent=3.0))


def _eccentric_circle(base: float, eccentricity: float):
    """A translating flat face on harmonic rise/return over 180° each: s = e(1 − cos φ).

    Its profile is exactly the circle of radius r_b + e centred e off the axis
    (the support function of that circle is r_b + e − e cos φ).
    """
    design = parse_design(
        {
            "cam": {"base_radius": base, "speed_rpm": 100.0},
            "follower": {"type": "translating-flat"},
            "motion": [
                {"kind": "rise", "angle": 180.0, "lift": 2.0 * eccentricity, "law": "harmonic"},
                {"kind": "return", "angle": 180.0, "lift": 2.0 * eccentricity, "law": "harmonic"},
            ],
        }
    )
    return Cam.from_design(design)


@pytest.mark.parametrize("roller", [5.0, 12.5, 30.0])
def test_roller_turns_on_an_eccentric_circle(roller):
    """A roller rolling once round a circle cam of radius R turns R/r_f times per cam turn."""
    cam = _eccentric_circle(40.0, 8.0)
    phi = cam.sample_phi(math.radians(1.0))
    profile = cam.profile(phi)
    assert_allclose(np.hypot(*profile.point.T).max(), 56.0, rtol=1e-12)  # r_b + 2e
    arc = np.hypot(*profile.d1.T)
    turns = roller_turns_per_cam_turn(phi, arc, roller_radius=roller)
    assert turns == pytest.approx(48.0 / roller, rel=1e-12)  # R = r_b + e = 48


def test_roller_turns_match_the_profile_polyline():
    """A second method: the length of a dense polyline through the profile points."""
    design = parse_design(
        {
            "cam": {"base_radius": 40.0, "speed_rpm": 100.0},
            "follower": {"roller_radius": 15.0},
            "motion": [
                {"kind": "rise", "angle": 140.0, "lift": 25.0, "law": "modified-sine"},
                {"kind": "dwell", "angle": 60.0},
                {"kind": "return", "angle": 120.0, "lift": 25.0, "law": "cycloidal"},
                {"kind": "dwell", "angle": 40.0},
            ],
        }
    )
    cam = Cam.from_design(design)
    phi = cam.sample_phi(math.radians(0.5))
    turns = roller_turns_per_cam_turn(phi, np.hypot(*cam.profile(phi).d1.T), roller_radius=15.0)
    dense = cam.profile(np.linspace(0.0, 2.0 * math.pi, 200_001)).point
    length = float(np.sum(np.hypot(*np.diff(dense, axis=0).T)))
    assert turns == pytest.approx(length / (2.0 * math.pi * 15.0), rel=1e-6)


def test_load_stress_factor_is_pi_p0_squared_over_e_star():
    """K = (F/L)(1/R1 + 1/R2) equals π p0²/E* with the Hertz p0 (Johnson 1985, eq. 4.45)."""
    force = np.array([0.0, 150.0, 900.0, 2500.0])
    kappa = contact_curvature(np.array([30.0, -80.0, 12.0, np.inf]), roller_radius=10.0)
    e_star = effective_modulus(modulus_1=206000.0, poisson_1=0.3, modulus_2=206000.0, poisson_2=0.3)
    p0 = hertz_stress(force, curvature=kappa, length=12.0, modulus=e_star)
    assert_allclose(
        load_stress_factor(force, curvature=kappa, length=12.0), math.pi * p0**2 / e_star, rtol=1e-12
    )


@settings(max_examples=50, deadline=None)
@given(slope=st.floats(2.0, 20.0), intercept=st.floats(20.0, 60.0), log_n=st.floats(4.0, 12.0))
def test_load_stress_line_round_trip(slope, intercept, log_n):
    """eq. 9.15 both ways: N(K(N)) = N, and K at 10^B/A... in psi: log10 K = (B − log10 N)/A."""
    line = LoadStressLine(slope=slope, intercept=intercept)
    k = line.factor(10.0**log_n)
    assert math.log10(k * PSI_PER_MPA) == pytest.approx((intercept - log_n) / slope, rel=1e-12, abs=1e-12)
    assert float(np.log10(line.cycles(k))) == pytest.approx(log_n, rel=1e-9)


def test_track_life_at_the_worst_point():
    """The track point under the largest K fails first, after N(K_max) cam turns."""
    phi = _grid(360)
    force = 500.0 + 300.0 * np.sin(phi) ** 2
    kappa = np.full(phi.size, 0.1)
    line = LoadStressLine(slope=8.0, intercept=34.0)
    spec = LifeSpec(track=line, required_hours=1e9)
    life = track_life(phi, force, curvature=kappa, length=10.0, omega=OMEGA, spec=spec)
    k_max = 800.0 / 10.0 * 0.1
    assert life.factor_max == pytest.approx(k_max, rel=1e-12)
    n = 10.0 ** (34.0 - 8.0 * math.log10(k_max * PSI_PER_MPA))
    assert life.cycles == pytest.approx(n, rel=1e-9)
    assert life.hours == pytest.approx(n / (100.0 / 60.0) / 3600.0, rel=1e-9)
    (finding,) = life_findings(spec, roller=None, track=life)
    assert path_of(finding.field) == "life.track_slope" and finding.limit == 1e9
    entry = summary_entry(None, life, sliding_max=None)
    assert entry["track_life_h"] == life.hours


def test_flat_face_slides_at_omega_times_rb_plus_s():
    """A radial translating flat face slides at ω(r_b + s) (Norton 2009, ch. 8); no rolling life."""
    cam = _eccentric_circle(40.0, 8.0)
    phi = cam.sample_phi(math.radians(2.0))
    motion = contact_motion(cam, phi, omega=OMEGA)
    s = cam.motion(phi).s
    assert not motion.rolling
    assert_allclose(motion.sliding_speed, OMEGA * (40.0 + s), rtol=1e-12)
    entry = summary_entry(None, None, sliding_max=float(motion.sliding_speed.max()))
    assert entry["rolling_life"].startswith("does not apply")


@pytest.mark.parametrize(
    ("field", "kwargs"),
    [
        ("life.roller_dynamic_load_rating", {"roller_dynamic_load_rating": 0.0}),
        ("life.roller_dynamic_load_rating", {"roller_dynamic_load_rating": -5.0}),
        ("life.roller_life_exponent", {"roller_life_exponent": 3.5}),
        ("life.hours_per_day", {"hours_per_day": 25.0}),
        ("life.required_hours", {"required_hours": math.nan}),
    ],
)
def test_bad_life_input_names_the_field(field, kwargs):
    with pytest.raises(DesignError) as err:
        LifeSpec(**kwargs)
    assert path_of(err.value.path) == field
    assert "\n" not in str(err.value)
