"""Linear cams (issue 36) against independent truths.

- closed forms for a translating roller: pitch (e + cφ, k + s), tan α = s′/c with
  c = L/2π, ρ = −(c² + s′²)^{3/2}/(c·s″);
- a brute-force envelope: the profile's distance to a dense polyline of the pitch line
  is the roller radius (k-d tree), and no profile point is inside any roller position;
- the oscillating roller: the pressure angle against the angle between the profile's
  normal and the arm's perpendicular, constructed here from the pivot.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.spatial import cKDTree

from camcad.design.paths import path_of
from camcad.errors import EXIT_INVALID, DesignError, exit_code
from camcad.findings import Severity
from camcad.geometry.followers import OscillatingFlat, OscillatingRoller, TranslatingFlat, TranslatingRoller
from camcad.geometry.linear import LinearOptions, linear_limits, linear_state
from camcad.knobs import Knob
from camcad.motion.laws import make_law
from camcad.motion.program import MotionProgram
from camcad.motion.segments import SegmentKind, SegmentSpec


def program(lift: float = 50.0, *, law: str = "cycloidal", span_deg: float = 90.0) -> MotionProgram:
    dwell = math.radians(180.0 - span_deg)
    span = math.radians(span_deg)
    return MotionProgram.from_segments(
        [
            SegmentSpec(kind=SegmentKind.RISE, span=span, lift=lift, law=make_law(law)),
            SegmentSpec(kind=SegmentKind.DWELL, span=dwell),
            SegmentSpec(kind=SegmentKind.RETURN, span=span, lift=lift, law=make_law(law)),
            SegmentSpec(kind=SegmentKind.DWELL, span=dwell),
        ]
    )


PHI = np.linspace(0.0, 2.0 * math.pi, 721, endpoint=False) + 0.007


@pytest.mark.parametrize("e", [0.0, 12.0])
def test_translating_roller_closed_forms(e: float):
    prog = program()
    m = prog.evaluate(PHI)
    follower = TranslatingRoller(base_radius=30.0, roller_radius=10.0, eccentricity=e)
    opt = LinearOptions(stroke_length=400.0)
    c = 400.0 / (2 * math.pi)
    st_ = linear_state(m, follower, opt)
    k = math.sqrt(40.0**2 - e * e)
    assert_allclose(st_.pitch.point, np.column_stack((e + c * PHI, k + m.s)), atol=1e-10)
    assert_allclose(st_.travel, c * PHI, atol=1e-12)
    assert_allclose(st_.pressure_angle, np.arctan(m.v / c), atol=1e-12)  # tan α = s′/c
    moving = np.abs(m.a) > 1e-6
    rho = -((c * c + m.v[moving] ** 2) ** 1.5) / (c * m.a[moving])
    assert_allclose(st_.pitch.rho[moving], rho, rtol=1e-10)
    assert_allclose(st_.profile.rho[moving], rho - 10.0, rtol=1e-10)
    # the normal points at the follower (+y), the profile lies below the pitch line
    assert np.all(st_.pitch.normal[:, 1] > 0.0)
    assert_allclose(st_.pitch.point - st_.profile.point, 10.0 * st_.pitch.normal, atol=1e-12)


@pytest.mark.parametrize(
    "follower",
    [
        TranslatingRoller(base_radius=30.0, roller_radius=10.0),
        OscillatingRoller(base_radius=30.0, roller_radius=10.0, pivot_distance=120.0, arm_length=100.0),
    ],
    ids=["translating", "oscillating"],
)
def test_profile_is_the_roller_envelope_by_brute_force(follower):
    """Second method: every profile point is r_f from a dense polyline of the pitch line (never nearer)."""
    lift = 50.0 if isinstance(follower, TranslatingRoller) else 25.0  # ψ in degrees on an arm
    prog = program(lift)
    opt = LinearOptions(stroke_length=500.0)
    dense = np.linspace(-0.3, 2 * math.pi + 0.3, 300_001)
    line = linear_state(prog.evaluate(dense), follower, opt).pitch.point
    tree = cKDTree(line)
    st_ = linear_state(prog.evaluate(PHI), follower, opt)
    dist, _ = tree.query(st_.profile.point)
    assert_allclose(dist, 10.0, atol=1e-6)


def test_oscillating_pressure_angle_against_the_arm():
    prog = program(20.0)
    follower = OscillatingRoller(base_radius=30.0, roller_radius=10.0, pivot_distance=120.0, arm_length=100.0)
    opt = LinearOptions(stroke_length=600.0)
    m = prog.evaluate(PHI)
    st_ = linear_state(m, follower, opt)
    centre = follower.element(m).m0  # machine frame: the plate frame shifted by −cφ
    pivot = np.asarray(follower.pivot)
    arm = centre - pivot
    # a growing ψ turns the arm clockwise: the roller is driven along −J·arm
    driven = np.column_stack((arm[:, 1], -arm[:, 0])) / np.hypot(*arm.T)[:, None]
    cosine = np.abs(np.sum(st_.profile.normal * driven, axis=1))
    assert_allclose(np.abs(st_.pressure_angle), np.arccos(np.clip(cosine, -1, 1)), atol=1e-7)


def test_limits_true_extremes_and_undercut():
    prog = program()
    follower = TranslatingRoller(base_radius=30.0, roller_radius=10.0)
    c = 400.0 / (2 * math.pi)
    lim = linear_limits(prog, follower, LinearOptions(stroke_length=400.0))
    assert lim.pressure_angle_max.value == pytest.approx(math.atan(2 * 50.0 / (math.pi / 2) / c), abs=1e-12)
    dense = np.linspace(0.0, 2 * math.pi, 400_001)
    st_ = linear_state(prog.evaluate(dense), follower, LinearOptions(stroke_length=400.0))
    convex = np.where(st_.pitch.rho > 0, st_.pitch.rho, np.inf).min()
    assert lim.pitch_convex_min.value <= convex + 1e-9
    assert lim.pitch_convex_min.value == pytest.approx(convex, rel=1e-6)
    assert not lim.findings
    short = linear_limits(prog, follower, LinearOptions(stroke_length=90.0))
    assert [f.severity for f in short.findings] == [Severity.HARD]
    assert short.findings[0].field is Knob.STROKE_LENGTH
    assert short.pitch_convex_min.value < 10.0


@pytest.mark.parametrize(
    ("follower", "opt", "field"),
    [
        (TranslatingFlat(base_radius=30.0), LinearOptions(stroke_length=400.0), "follower.type"),
        (
            OscillatingFlat(base_radius=30.0, pivot_distance=100.0),
            LinearOptions(stroke_length=400.0),
            "follower.type",
        ),
        (
            TranslatingRoller(base_radius=30.0, roller_radius=10.0),
            LinearOptions(stroke_length=0.0),
            "linear.stroke_length",
        ),
        (
            TranslatingRoller(base_radius=30.0, roller_radius=10.0),
            LinearOptions(stroke_length=math.inf),
            "linear.stroke_length",
        ),
    ],
    ids=["translating-flat", "oscillating-flat", "zero-stroke", "infinite-stroke"],
)
def test_bad_input_names_the_field(follower, opt, field):
    with pytest.raises(DesignError) as err:
        linear_state(program().evaluate(PHI), follower, opt)
    assert path_of(err.value.path) == field
    assert exit_code(err.value) == EXIT_INVALID


@settings(max_examples=30, deadline=None)
@given(
    law=st.sampled_from(["cycloidal", "poly-345", "harmonic", "poly-4567"]),
    lift=st.floats(1.0, 60.0),
    span=st.floats(30.0, 170.0),
    stroke=st.floats(50.0, 2000.0),
)
def test_laws_and_strokes(law, lift, span, stroke):
    prog = program(lift, law=law, span_deg=span)
    m = prog.evaluate(PHI)
    opt = LinearOptions(stroke_length=stroke)
    st_ = linear_state(m, TranslatingRoller(base_radius=20.0, roller_radius=5.0), opt)
    assert_allclose(np.tan(st_.pressure_angle), m.v * 2 * math.pi / stroke, rtol=1e-9, atol=1e-12)
    assert_allclose(np.hypot(*(st_.pitch.point - st_.profile.point).T), 5.0, atol=1e-10)
