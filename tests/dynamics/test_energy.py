"""Model A, the energy method (Quintero & Vanegas 2016, section 4 and section 5)."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from camcad.design import Design, parse_design
from camcad.dynamics import (
    STANDARD_GRAVITY,
    FollowerLoad,
    Spring,
    analyse_dynamics,
    contact_force,
    input_torque,
)
from camcad.geometry.cam import Cam
from camcad.motion.program import Motion, MotionProgram

OMEGA_PAPER = 10.0  # rad/s, Quintero & Vanegas 2016, section 5.1
RPM_PAPER = OMEGA_PAPER * 60.0 / (2.0 * math.pi)


def paper_design(law: str, params: dict[str, Any] | None = None, **dynamics: Any) -> Design:
    """Quintero & Vanegas (2016), section 5: R_O = 60 (base 40 + roller 20), rise 30 mm.

    Rise over 150°, dwell 90°, return over 120°; m_f g = 1.63 N, T_f = 100 N·mm,
    k = 100 N/m = 0.1 N/mm with δ = s (no preload), ω = 10 rad/s.
    """
    p = params or {}
    dyn = {
        "follower_mass": 1.63 / STANDARD_GRAVITY,
        "spring_rate": 0.1,
        "friction_torque": 100.0,
    } | dynamics
    return parse_design(
        {
            "cam": {"base_radius": 40.0, "speed_rpm": RPM_PAPER},
            "follower": {"roller_radius": 20.0},
            "motion": [
                {"kind": "rise", "angle": 150.0, "lift": 30.0, "law": law, **p},
                {"kind": "dwell", "angle": 90.0},
                {"kind": "return", "angle": 120.0, "lift": 30.0, "law": law, **p},
            ],
            "dynamics": dyn,
        }
    )


def analyse(design: Design):
    cam = Cam.from_design(design)
    phi = cam.sample_phi()
    result = analyse_dynamics(
        cam.motion(phi),
        pressure_angle=cam.pressure_angle(phi),
        profile_rho=cam.profile(phi).rho,
        setup=design.dynamics_setup(),
    )
    return cam, result


# ------------------------------------------------------------------ formulas


def test_units_of_the_axial_load_by_hand():
    """1 kg at a = 2 mm/rad², ω = 10 rad/s: s̈ = 200 mm/s² = 0.2 m/s² → 0.2 N."""
    motion = Motion(phi=np.zeros(1), s=np.array([5.0]), v=np.zeros(1), a=np.array([2.0]), j=np.zeros(1))
    load = FollowerLoad(mass=1.0, spring=Spring(rate=3.0, preload=7.0), gravity=True)
    # 0.2 N inertia + 9.80665 N weight + 3 N/mm · 5 mm + 7 N preload
    assert_allclose(load.axial_force(motion, omega=10.0), [0.2 + 9.80665 + 15.0 + 7.0], rtol=1e-15)
    no_g = FollowerLoad(mass=1.0, spring=Spring(rate=3.0, preload=7.0), gravity=False)
    assert_allclose(no_g.axial_force(motion, omega=10.0), [0.2 + 15.0 + 7.0], rtol=1e-15)


finite = {"allow_nan": False, "allow_infinity": False}


@settings(max_examples=60, deadline=None)
@given(
    mass=st.floats(0.0, 50.0, **finite),
    rate=st.floats(0.0, 100.0, **finite),
    preload=st.floats(0.0, 1000.0, **finite),
    omega=st.floats(0.0, 500.0, **finite),
    friction=st.floats(0.0, 1000.0, **finite),
    gravity=st.booleans(),
    seed=st.integers(0, 2**32 - 1),
)
def test_force_and_torque_formulas_agree(mass, rate, preload, omega, friction, gravity, seed):
    """F_C·cosα − k s − F0 − m g = m·a·ω²/1000 and T = F_C·cosα·v + T_f (eqs. 18, 19).

    The second identity ties the torque to the contact force: torque is the
    force along the follower times the pseudo velocity.
    """
    rng = np.random.default_rng(seed)
    n = 16
    motion = Motion(
        phi=np.linspace(0.0, 2 * np.pi, n, endpoint=False),
        s=rng.uniform(0.0, 50.0, n),
        v=rng.uniform(-60.0, 60.0, n),
        a=rng.uniform(-300.0, 300.0, n),
        j=np.zeros(n),
    )
    alpha = rng.uniform(-1.2, 1.2, n)
    load = FollowerLoad(mass=mass, spring=Spring(rate=rate, preload=preload), gravity=gravity)
    axial = load.axial_force(motion, omega=omega)
    fc = contact_force(axial, alpha)
    torque = input_torque(axial, motion.v, friction_torque=friction)
    weight = mass * 9.80665 if gravity else 0.0
    lhs = fc * np.cos(alpha) - rate * motion.s - preload - weight
    scale = np.abs(fc) + rate * motion.s + preload + weight + 1.0
    assert_allclose(lhs, mass * motion.a * omega**2 / 1000.0, rtol=0, atol=1e-12 * scale.max())
    assert_allclose(torque, fc * np.cos(alpha) * motion.v + friction, rtol=0, atol=1e-12 * (scale * 60).max())


def _gauss_nodes(program: MotionProgram, order: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on every smooth piece of the program."""
    x, w = np.polynomial.legendre.leggauss(order)
    cuts = [0.0]
    for start, seg in zip(program.starts, program.segments, strict=True):
        inner = seg.law.breakpoints if seg.law is not None else ()
        cuts += [start + t * seg.span for t in inner] + [start + seg.span]
    nodes, weights = [], []
    for lo, hi in itertools.pairwise(cuts):
        nodes.append(0.5 * (hi - lo) * x + 0.5 * (hi + lo))
        weights.append(0.5 * (hi - lo) * w)
    return np.concatenate(nodes), np.concatenate(weights)


@pytest.mark.parametrize(
    ("law", "params"),
    [("poly-4567", None), ("harmonic", None), ("vap", {"b": 0.2}), ("cycloidal", None)],
    ids=["poly-4567", "harmonic", "vap-0.2", "cycloidal"],
)
def test_torque_integrates_to_zero_over_a_cycle(law, params):
    """No friction, no gravity: ∫T dφ = ∫(m a ω² + k s + F0) v dφ = 0 over a closed cycle.

    Integrated by Gauss–Legendre on each smooth piece (segments, and the VAP
    mid-rise joint), exact for the polynomials and spectrally accurate for the
    others, with the motion evaluated exactly by the program.
    """
    design = paper_design(
        law, params, friction_torque=0.0, gravity=False, spring_preload=25.0, follower_mass=2.0
    )
    program = MotionProgram.from_segments(design.motion)
    phi, w = _gauss_nodes(program)
    motion = program.evaluate(phi)
    load = FollowerLoad(mass=2.0, spring=Spring(rate=0.1, preload=25.0), gravity=False)
    torque = input_torque(load.axial_force(motion, omega=OMEGA_PAPER), motion.v)
    work = float(np.sum(w * torque))
    assert abs(work) <= 1e-9 * float(np.sum(w * np.abs(torque)))


# ---------------------------------------------------------- paper, section 5

PAPER_LAWS = [
    ("poly-4567", None),
    ("harmonic", None),
    ("vap", {"b": 0.1}),
    ("vap", {"b": 0.2}),
]


def _peaks(law: str, params: dict[str, Any] | None) -> tuple[float, float]:
    cam, result = analyse(paper_design(law, params))
    alpha = float(np.max(np.abs(cam.pressure_angle(result.phi))))
    return math.degrees(alpha), float(np.max(result.torque))


def test_paper_section_5_vap_beats_harmonic_beats_4567():
    """Quintero & Vanegas (2016), sections 5.2 and 6: the VAP cams have lower peak
    pressure angle and lower peak input torque than the harmonic cam, which is
    below the 4-5-6-7 cam. Case: R_O = 60 mm, r_f = 20 mm, ω = 10 rad/s, rise
    30 mm over 150°, dwell 90°, return over 120°, m_f g = 1.63 N, T_f = 100 N·mm,
    k = 0.1 N/mm, δ = s.
    """
    peaks = {law + str(p or ""): _peaks(law, p) for law, p in PAPER_LAWS}
    poly, harmonic = peaks["poly-4567"], peaks["harmonic"]
    vaps = [peaks["vap{'b': 0.1}"], peaks["vap{'b': 0.2}"]]
    for which in (0, 1):  # 0: max pressure angle, 1: max torque
        assert harmonic[which] < poly[which]
        for vap in vaps:
            assert vap[which] < harmonic[which]
    # The paper's text: the smaller b, the closer VAP is to constant velocity and
    # the lower its pressure angle.
    assert vaps[0][0] < vaps[1][0]


def test_paper_case_statics_on_the_dwell():
    """On the 90° dwell (s = 30 mm, a = 0): F_C = m g + k s = 1.63 + 3 = 4.63 N and T = T_f."""
    design = paper_design("harmonic")
    cam = Cam.from_design(design)
    phi = np.radians([160.0, 200.0, 235.0])
    result = analyse_dynamics(
        cam.motion(phi),
        pressure_angle=cam.pressure_angle(phi),
        profile_rho=cam.profile(phi).rho,
        setup=design.dynamics_setup(),
    )
    assert_allclose(result.contact_force, 4.63, rtol=1e-12)
    assert_allclose(result.torque, 100.0, rtol=1e-12)


def test_flat_follower_energy_equals_frictionless_axial_load():
    """A flat face has α = 0, so F_C is the axial load itself."""
    design = parse_design(
        {
            "cam": {"base_radius": 50.0, "speed_rpm": 300.0},
            "follower": {"type": "translating-flat"},
            "motion": [
                {"kind": "rise", "angle": 120.0, "lift": 10.0, "law": "cycloidal"},
                {"kind": "return", "angle": 240.0, "lift": 10.0, "law": "cycloidal"},
            ],
            "dynamics": {"follower_mass": 0.5, "spring_rate": 2.0, "spring_preload": 30.0},
        }
    )
    cam, result = analyse(design)
    motion = cam.motion(result.phi)
    omega = 300.0 * 2 * math.pi / 60.0
    expected = 0.5 * motion.a * omega**2 / 1000 + 0.5 * 9.80665 + 2.0 * motion.s + 30.0
    assert_allclose(result.contact_force, expected, rtol=1e-12)
