"""Life and film of every part of a cam family, by the same code (issue 35 on the cam families of issue 33).

Each part's figures are checked against the closed forms evaluated here by
hand from that part's own load, speed and radius: the roller's L10 after
ISO 281 (P = (∮F^p dS / ∮dS)^(1/p), L10 = (C/P)^p) on a fine grid of this
test's own, with the profile's arc length from the chord lengths of its
points; the Dowson–Higginson film h_min = 2.65 U^0.70 G^0.54 W′^−0.13 R with
the radius of curvature and the contact's speed from finite differences of
the carrying surface's points (a conjugate pair's second plate with its own
roller; a groove's outer flank, which the roller touches from inside).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camcad import pipeline
from camcad.design import parse_design
from camcad.explore.measures import measure_values

C_RATING = 9000.0  # N
P_EXP = 10.0 / 3.0  # ISO 281 roller bearings (the default exponent)
OIL = {
    "viscosity_Pa_s": 0.09,
    "pressure_viscosity_coefficient": 2e-8,
    "roughness_cam_um": 0.4,
    "roughness_follower_um": 0.2,
}
E_REDUCED = 206000.0 / (1.0 - 0.3**2)  # E′: 2/E′ = 2(1 − ν²)/E for two steels (Dowson & Higginson 1977)
RPM = 300.0
OMEGA = RPM * 2.0 * math.pi / 60.0
WIDTH = 10.0  # mm, contact_width
MOTION = [
    {"kind": "rise", "angle": 120.0, "lift": 20.0, "law": "cycloidal"},
    {"kind": "dwell", "angle": 60.0},
    {"kind": "return", "angle": 120.0, "lift": 20.0, "law": "modified-sine"},
    {"kind": "dwell", "angle": 60.0},
]


def _analyse(cam: dict, follower: dict, **tables: dict) -> pipeline.Analysis:
    data = {
        "cam": {"base_radius": 50.0, "speed_rpm": RPM, "thickness": 12.0, **cam},
        "follower": follower,
        "motion": MOTION,
        "dynamics": {"follower_mass": 2.0, "friction_torque": 0.0, "contact_width": WIDTH},
        "life": {"roller_dynamic_load_rating": C_RATING},
        "lubrication": OIL,
        **tables,
    }
    return pipeline.analyse(parse_design(data), fit=False, toolpath=False, strict=False)


@pytest.fixture(scope="module")
def pair() -> pipeline.Analysis:
    """A yoke (second roller opposite the first) whose second roller is smaller: 8 mm against 12 mm."""
    return _analyse({"style": "conjugate"}, {"roller_radius": 12.0}, conjugate={"roller_radius": 8.0})


@pytest.fixture(scope="module")
def groove() -> pipeline.Analysis:
    """A groove with radial play: its outer flank is 2 r_f + c/2 from the profile."""
    return _analyse(
        {"style": "groove", "outer_radius": 110.0},
        {"roller_radius": 12.0},
        groove={"clearance": 0.2, "depth": 6.0},
    )


def _points(curve_at, phi: np.ndarray) -> np.ndarray:
    return np.asarray(curve_at(phi).point, dtype=float)


def _hand_l10_hours(
    cam,
    phi_part: np.ndarray,
    force_part: np.ndarray,
    roller: float,
    flanks: tuple[float, float] | None = None,
) -> tuple[float, float]:
    """L10 [h] and P [N] by hand: a uniform grid of 72 000 chords, the load interpolated onto it.

    ``flanks``: a groove's (inner, outer) offsets of the profile; the roller rolls on the inner
    where F ≥ 0 and on the outer, carrying |F|, where F < 0.
    """
    n = 72_000
    phi = np.arange(n) * (2.0 * math.pi / n)
    mid = phi + math.pi / n
    force = np.interp(mid, phi_part, force_part, period=2.0 * math.pi)

    def chords(curve_at) -> np.ndarray:
        pts = _points(curve_at, phi)
        return np.hypot(*(np.roll(pts, -1, axis=0) - pts).T)  # chord from φ_i to φ_i+1

    if flanks is None:
        ds, load = chords(cam.profile), np.clip(force, 0.0, None)
    else:
        inner, outer = (chords(lambda p, d=d: cam.offset_curve(p, d)) for d in flanks)
        ds, load = np.where(force < 0.0, outer, inner), np.abs(force)
    p_eq = (np.sum(load**P_EXP * ds) / np.sum(ds)) ** (1.0 / P_EXP)  # ISO 281 §7.2
    l10 = (C_RATING / p_eq) ** P_EXP  # ISO 281 §7, million revolutions
    turns = np.sum(ds) / (2.0 * math.pi * roller)  # per cam turn
    return l10 * 1e6 / (turns * RPM * 60.0), p_eq


def _radius_and_speed(curve_at, phi: float, convex_sign: float) -> tuple[float, float]:
    """Signed radius of curvature [mm] (convex +) and |dS/dφ| [mm/rad], by central differences."""
    h = 1e-4
    a, b, c = _points(curve_at, np.array([phi - h, phi, phi + h]))
    d1 = (c - a) / (2.0 * h)
    d2 = (c - 2.0 * b + a) / h**2
    kappa = (d1[0] * d2[1] - d1[1] * d2[0]) / np.hypot(*d1) ** 3
    return convex_sign / kappa, float(np.hypot(*d1))


def _hand_film_um(force: float, speed: float, curvature: float) -> float:
    """Dowson & Higginson (1977): h_min = R · 2.65 U^0.70 G^0.54 W′^−0.13 [µm]; mm, N, s, MPa inside."""
    r = 1.0 / curvature
    eta = OIL["viscosity_Pa_s"] * 1e-6  # N·s/mm²
    u = eta * speed / (E_REDUCED * r)
    g = OIL["pressure_viscosity_coefficient"] * 1e6 * E_REDUCED
    w = force / WIDTH / (E_REDUCED * r)
    return 1e3 * r * 2.65 * u**0.70 * g**0.54 * w**-0.13


def _convex_sign(curve_at) -> float:
    """+1 or −1: the sign that makes the curve's radius positive on the base-circle dwell (at 150°)."""
    rho, _ = _radius_and_speed(curve_at, math.radians(150.0), 1.0)
    return 1.0 if rho > 0.0 else -1.0


def test_each_plate_of_a_pair_has_its_own_roller_life(pair):
    first, second = pair.parts
    assert second.part.cam.roller_radius == 8.0 and first.part.cam.roller_radius == 12.0
    lives = []
    for result in (first, second):
        cam, dyn = result.part.cam, result.dynamics
        hours, p_eq = _hand_l10_hours(cam, dyn.phi, dyn.contact_force, cam.roller_radius)
        roller = result.duty.roller
        assert roller.equivalent_load == pytest.approx(p_eq, rel=2e-4)
        assert roller.hours == pytest.approx(hours, rel=1e-3)
        lives.append(roller.hours)
    assert abs(lives[0] - lives[1]) > 0.05 * max(lives)  # a smaller roller on another plate: another life
    summary = pair.summary()
    assert summary["life"]["roller_life_h"] == lives[0]
    assert summary["second_plate"]["life"]["roller_life_h"] == lives[1]
    assert summary["second_plate"]["lubrication"]["min_film_ratio"] == second.duty.film.min_ratio
    # the optimiser and the sweep hold every part to the limit: the shorter life, the thinner film
    measures = measure_values(pair, summary)
    assert measures["roller_life_h"] == min(lives)
    assert measures["min_film_ratio"] == min(r.duty.film.min_ratio for r in pair.parts)


def test_each_plate_of_a_pair_has_its_own_film(pair):
    """At three angles where each plate carries the follower, its film against the hand formula."""
    for result in pair.parts:
        cam, dyn, film = result.part.cam, result.dynamics, result.duty.film
        roller = cam.roller_radius
        sign = _convex_sign(cam.profile)
        force = np.asarray(dyn.contact_force)
        loaded = np.flatnonzero(force > 0.2 * force.max())
        for i in loaded[[0, loaded.size // 2, -1]]:
            rho, arc = _radius_and_speed(cam.profile, float(dyn.phi[i]), sign)
            expect = _hand_film_um(force[i], arc * OMEGA, 1.0 / rho + 1.0 / roller)
            assert film.thickness_um[i] == pytest.approx(expect, rel=1e-4)
        assert np.all(np.isinf(film.thickness_um[force <= 0.0]))  # the other plate carries it there
    one, two = (r.duty.film for r in pair.parts)
    assert one.min_ratio != pytest.approx(two.min_ratio, rel=1e-3)


def test_a_grooves_outer_flank_film_has_that_flanks_curvature(groove):
    (result,) = groove.parts
    cam, dyn, film = result.part.cam, result.dynamics, result.duty.film
    roller, clearance = cam.roller_radius, 0.2
    outer = 2.0 * roller + 0.5 * clearance  # the outer flank as an offset of the profile
    inner = -0.5 * clearance

    def outer_at(p):
        return cam.offset_curve(p, outer)

    def inner_at(p):
        return cam.offset_curve(p, inner)

    force = np.asarray(dyn.contact_force)
    back = np.flatnonzero(force < 0.2 * force.min())  # the outer flank pushes the roller back
    forth = np.flatnonzero(force > 0.2 * force.max())
    assert back.size and forth.size
    for at, flank, concave in ((outer_at, back, True), (inner_at, forth, False)):
        sign = _convex_sign(at)
        for i in flank[[0, flank.size // 2, -1]]:
            rho, arc = _radius_and_speed(at, float(dyn.phi[i]), sign)
            # the roller inside the outer flank sees it concave: 1/R = 1/r_f − 1/ρ (Johnson 1985, §4.3)
            curvature = 1.0 / roller - 1.0 / rho if concave else 1.0 / rho + 1.0 / roller
            expect = _hand_film_um(abs(force[i]), arc * OMEGA, curvature)
            assert film.thickness_um[i] == pytest.approx(expect, rel=1e-4)
    lowest = int(np.argmin(film.ratio))
    flank = "outer" if force[lowest] < 0.0 else "inner"
    assert groove.summary()["lubrication"]["min_film_ratio_flank"] == flank


def test_a_grooves_roller_rolls_on_the_flank_that_drives(groove):
    (result,) = groove.parts
    cam, dyn = result.part.cam, result.dynamics
    flanks = (-0.1, 2.0 * cam.roller_radius + 0.1)  # ∓ c/2 beyond the profile and the roller, c = 0.2
    hours, p_eq = _hand_l10_hours(cam, dyn.phi, dyn.contact_force, cam.roller_radius, flanks)
    assert result.duty.roller.equivalent_load == pytest.approx(p_eq, rel=2e-4)
    assert result.duty.roller.hours == pytest.approx(hours, rel=1e-3)


def test_a_pairs_check_rows_name_the_second_plates_life_and_film(pair):
    from camcad.cli.render import _duty_rows

    rows = dict(_duty_rows(pair.summary()["second_plate"], "second plate "))
    assert rows["second plate roller L10 life"].startswith(f"{pair.parts[1].duty.roller.hours:.4g} h")
    assert "second plate min film ratio λ" in rows
