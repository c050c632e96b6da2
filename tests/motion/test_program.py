"""Motion programs: evaluation, joints, breakpoints, time derivatives."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from camcad.design import parse_design
from camcad.motion.laws import make_law
from camcad.motion.program import MotionProgram
from tests.conftest import make_design


def program(law: str = "cycloidal", **kw) -> MotionProgram:
    return MotionProgram.from_segments(make_design(law=law, **kw).motion)


def test_segments_follow_the_law_with_chain_rule():
    """s(φ) = h·y(φ/β) and v = h·y'/β, a = h·y''/β², j = h·y'''/β³ on the rise."""
    prog = program("cycloidal", lift=20.0)
    beta = math.radians(150.0)
    x = np.linspace(0.0, 0.999, 50)
    y, y1, y2, y3 = make_law("cycloidal").evaluate(x)
    m = prog.evaluate(x * beta)
    assert_allclose(m.s, 20 * y, atol=1e-12)
    assert_allclose(m.v, 20 * y1 / beta, atol=1e-12)
    assert_allclose(m.a, 20 * y2 / beta**2, atol=1e-12)
    assert_allclose(m.j, 20 * y3 / beta**3, atol=1e-11)


def test_return_mirrors_rise_and_dwells_are_flat():
    prog = program("poly-345", lift=12.0, spans=(100.0, 80.0, 100.0, 80.0))
    deg = np.radians
    up = prog.evaluate(deg(np.linspace(0, 100, 21)))
    down = prog.evaluate(deg(180 + np.linspace(0, 100, 21)))
    assert_allclose(down.s, 12.0 - up.s, atol=1e-12)
    assert_allclose(down.v, -up.v, atol=1e-12)
    dwell = prog.evaluate(deg(np.linspace(100.5, 179.5, 9)))
    assert_allclose(dwell.s, 12.0)
    assert_allclose([dwell.v, dwell.a, dwell.j], 0.0)


def test_evaluation_wraps_and_is_vectorised_over_any_shape():
    prog = program()
    phi = np.linspace(-1.0, 1.0, 12).reshape(3, 4)
    m = prog.evaluate(phi)
    assert m.s.shape == (12,)
    assert_allclose(prog.evaluate(phi + 2 * math.pi).s, m.s, atol=1e-12)


@given(step=st.floats(0.05, 2.0))
@settings(max_examples=25, deadline=None)
def test_sample_grid_contains_every_breakpoint(step):
    prog = program(spans=(123.4, 56.6, 100.0, 80.0))
    phi = prog.sample_phi(math.radians(step))
    assert np.all(np.diff(phi) > 0) and phi[0] == 0.0 and phi[-1] < 2 * math.pi
    for bp in prog.breakpoints:
        assert np.min(np.abs(phi - bp.phi)) == 0.0


@pytest.mark.parametrize(
    ("law", "continuity"),
    [("constant-velocity", 0), ("harmonic", 1), ("cycloidal", 2), ("poly-4567", 3)],
)
def test_joint_continuity_matches_the_law_end_conditions(law, continuity):
    prog = program(law)
    assert {bp.continuity for bp in prog.breakpoints} == {continuity}


def test_joint_jumps_equal_one_sided_law_derivatives():
    """000 case, harmonic: at 0° the return (120°) meets the rise (150°) directly.

    One-sided closed forms: y''(0) = π²/2 on the rise gives a = +h·π²/2/β_r²;
    y''(1) = −π²/2 on the return, negated by the descent, gives a = +h·π²/2/β_d²
    just before 360°. The jump is h·π²/2·(1/β_r² − 1/β_d²).
    """
    design = parse_design(
        {
            "cam": {"base_radius": 40},
            "follower": {"roller_radius": 20},
            "motion": [
                {"kind": "rise", "angle": 150, "lift": 30, "law": "harmonic"},
                {"kind": "dwell", "angle": 90},
                {"kind": "return", "angle": 120, "lift": 30, "law": "harmonic"},
            ],
        }
    )
    joint = MotionProgram.from_segments(design.motion).joints()[0]
    expected = 30 * (math.pi**2 / 2) * (1 / math.radians(150) ** 2 - 1 / math.radians(120) ** 2)
    assert joint.dv == 0.0
    assert_allclose(joint.da, expected, rtol=1e-9)
    assert joint.continuity == 1
    assert joint.describe().startswith("0°: acceleration jumps by -12.15 mm/rad²")


def test_vap_reports_its_mid_rise_acceleration_jump_as_an_internal_breakpoint():
    """VAP (000 eq. 3 with odd symmetry) is C1 at mid-rise: a knot belongs there."""
    prog = program("vap", params={"b": 0.5})
    inner = [j for j in prog.joints() if j.internal]
    assert [round(math.degrees(j.phi), 9) for j in inner] == [75.0, 255.0]
    assert all(j.continuity == 1 for j in inner)
    phi = prog.sample_phi(math.radians(0.7))
    assert np.min(np.abs(phi - math.radians(75.0))) < 1e-12


def test_time_derivatives_scale_with_speed():
    m = program().evaluate(np.linspace(0, 6, 7))
    t = m.in_time(10.0)
    assert_allclose(t.velocity, 10 * m.v)
    assert_allclose(t.acceleration, 100 * m.a)
    assert_allclose(t.jerk, 1000 * m.j)


def test_lift_is_the_peak_displacement():
    prog = program(lift=17.5)
    assert prog.lift == pytest.approx(17.5)
    assert prog.evaluate(np.linspace(0, 2 * np.pi, 3601)).s.max() == pytest.approx(17.5)
