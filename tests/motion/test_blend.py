"""Blend points: polynomial and inclined-sine segments that take their boundary values from neighbours.

Independent truths: the closed-form 3-4-5 and 4-5-6-7 laws, scipy's
``BPoly.from_derivatives`` (Hermite interpolation), a brute-force
minimisation of the jerk norm over monomial coefficients (``scipy.optimize.least_squares``),
and one-sided limits of the exact program at every joint.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.interpolate import BPoly
from scipy.linalg import null_space
from scipy.optimize import least_squares

from camcad.design import parse_design
from camcad.errors import DesignError
from camcad.motion.laws import InclinedSine, make_law
from camcad.motion.program import MotionProgram
from camcad.motion.segments import Boundary, SegmentKind, SegmentSpec

RAD = math.radians


def seg(kind: str, angle: float, lift: float = 0.0, law: str | None = None, **kw) -> SegmentSpec:
    params = {k: kw.pop(k) for k in list(kw) if k in ("degree",)}
    return SegmentSpec(
        kind=SegmentKind(kind),
        span=RAD(angle),
        lift=lift,
        law=make_law(law, **params) if law else None,
        **kw,
    )


def one_sided(prog: MotionProgram, phi: float) -> tuple[np.ndarray, np.ndarray]:
    left = prog.evaluate(phi, side="left")
    right = prog.evaluate(phi, side="right")
    return (
        np.array([left.s[0], left.v[0], left.a[0], left.j[0]]),
        np.array([right.s[0], right.v[0], right.a[0], right.j[0]]),
    )


def packaging(rise: float, cv_lift: float, spans: tuple[float, float, float, float, float]) -> MotionProgram:
    """dwell – polynomial rise into constant velocity – constant velocity – polynomial return – dwell."""
    d0, r, c, b, d1 = spans
    return MotionProgram.from_segments(
        [
            seg("dwell", d0),
            seg("rise", r, rise, "polynomial"),
            seg("rise", c, cv_lift, "constant-velocity"),
            seg("return", b, rise + cv_lift, "polynomial"),
            seg("dwell", d1),
        ]
    )


# ------------------------------------------------------------------ equivalences


def test_hermite_quintic_between_rests_is_the_345_law():
    """s, v, a matched to dwells at both ends: the lowest-degree polynomial is 10x³ − 15x⁴ + 6x⁵."""
    prog = MotionProgram.from_segments(
        [
            seg("rise", 150, 12, "polynomial"),
            seg("dwell", 30),
            seg("return", 150, 12, "poly-345"),
            seg("dwell", 30),
        ]
    )
    x = np.linspace(0, 1, 41)
    y = make_law("poly-345").evaluate(x)
    got = prog.segments[0].law.evaluate(x)
    for k in range(4):
        assert_allclose(got[k], y[k], atol=1e-12 * max(1, np.max(np.abs(y[k]))))
    assert len(prog.segments[0].law.coefficients) == 6


def test_degree_seven_between_rests_is_the_4567_law_and_c3():
    """degree = 7 also matches the jerk (0 at a dwell): the septic is 35x⁴ − 84x⁵ + 70x⁶ − 20x⁷."""
    prog = MotionProgram.from_segments([seg("rise", 150, 12, "polynomial", degree=7), seg("dwell", 210)])
    x = np.linspace(0, 1, 41)
    y = make_law("poly-4567").evaluate(x)
    got = prog.segments[0].law.evaluate(x)
    for k in range(4):
        assert_allclose(got[k], y[k], atol=1e-11 * max(1, np.max(np.abs(y[k]))))
    assert {bp.continuity for bp in prog.breakpoints} == {3}


@given(
    v0=st.floats(-40, 40),
    a0=st.floats(-200, 200),
    v1=st.floats(-40, 40),
    a1=st.floats(-200, 200),
    h=st.floats(1, 50),
    span=st.floats(30, 300),
)
@settings(max_examples=40, deadline=None)
def test_specified_ends_give_the_hermite_quintic_of_bpoly(v0, a0, v1, a1, h, span):
    """s, v, a given at both ends: scipy's BPoly.from_derivatives; the return matches them."""
    prog = MotionProgram.from_segments(
        [
            seg("rise", span, h, "polynomial", start=Boundary(v=v0, a=a0), end=Boundary(v=v1, a=a1)),
            seg("return", 360 - span, h, "polynomial"),
        ]
    )
    beta = RAD(span)
    rise = BPoly.from_derivatives([0.0, beta], [[0.0, v0, a0], [h, v1, a1]])
    back = BPoly.from_derivatives([beta, 2 * math.pi], [[h, v1, a1], [0.0, v0, a0]])
    phi_r = np.linspace(0, beta, 23)[:-1]
    phi_b = np.linspace(beta, 2 * math.pi, 23)[:-1]
    for phi, ref in ((phi_r, rise), (phi_b, back)):
        m = prog.evaluate(phi)
        for k, got in enumerate((m.s, m.v, m.a, m.j)):
            want = ref(phi, nu=k)
            assert_allclose(got, want, atol=1e-8 * (1 + np.max(np.abs(want))))


# ------------------------------------------------------------------ blend points


@given(
    rise=st.floats(1, 30),
    cv=st.floats(1, 60),
    spans=st.lists(st.floats(20, 100), min_size=5, max_size=5),
)
@settings(max_examples=40, deadline=None)
def test_every_blend_point_of_a_constant_velocity_stretch_is_c2(rise, cv, spans):
    """s, v, a equal on both sides of every joint (one-sided limits), to 1e-9 of their scale."""
    total = sum(spans)
    spans = tuple(360 * s / total for s in spans)
    spans = (*spans[:4], 360 - sum(spans[:4]))
    prog = packaging(rise, cv, spans)
    scale = [rise + cv, *(max(1.0, (rise + cv) / RAD(min(spans)) ** k) for k in (1, 2))]
    for joint in prog.joints():
        left, right = one_sided(prog, joint.phi)
        for k in range(3):
            assert abs(left[k] - right[k]) <= 1e-9 * scale[k], (joint.describe(), k)
        assert joint.continuity >= 2
    cv_velocity = cv / RAD(spans[2])
    start = RAD(spans[0] + spans[1])
    assert_allclose(prog.evaluate(start + np.linspace(0, RAD(spans[2]), 7)[1:-1]).v, cv_velocity, rtol=1e-12)


def test_specified_values_are_met_and_matched_across():
    """start.v given on one polynomial: the neighbour polynomial's end takes the same value (to 1e-9)."""
    prog = MotionProgram.from_segments(
        [
            seg("rise", 120, 10, "polynomial", start=Boundary(v=2.0, a=-5.0, j=30.0)),
            seg("dwell", 60),
            seg("return", 180, 10, "polynomial"),
        ]
    )
    left, right = one_sided(prog, 0.0)
    assert_allclose(right[1:], [2.0, -5.0, 30.0], atol=1e-9)
    assert_allclose(left[1:], [2.0, -5.0, 30.0], atol=1e-9)
    assert len(prog.segments[0].law.coefficients) == 7  # s, v, a both ends + the given jerk: degree 6
    assert len(prog.segments[2].law.coefficients) == 7  # its end takes the jerk across the blend point


def brute_min_jerk(degree: int, beta: float, conditions: list[tuple[float, int, float]]) -> np.ndarray:
    """Coefficients c of s(φ) = Σ c_i (φ/β)^i minimising ∫₀^β s‴² dφ under s^(k)(φ₀) = value (SLSQP)."""
    powers = np.arange(degree + 1)

    def deriv_row(phi: float, k: int) -> np.ndarray:  # d^k/dφ^k of (φ/β)^p
        x = phi / beta
        return np.array([math.perm(int(p), k) * x ** (p - k) / beta**k if p >= k else 0.0 for p in powers])

    nodes, weights = np.polynomial.legendre.leggauss(40)
    xs, ws = 0.5 * beta * (nodes + 1), 0.5 * beta * weights
    jerk = np.array([deriv_row(x, 3) for x in xs])

    def objective(c):
        return float(ws @ (jerk @ c) ** 2)

    # eliminate the conditions (particular solution + null space), then minimise freely with BFGS
    a = np.array([deriv_row(p, k) for p, k, _ in conditions])
    b = np.array([v for _, _, v in conditions])
    c0 = np.linalg.lstsq(a, b, rcond=None)[0]
    z = null_space(a)
    root_w = np.sqrt(ws)
    res = least_squares(
        lambda w: root_w * (jerk @ (c0 + z @ w)), np.zeros(z.shape[1]), xtol=1e-15, ftol=1e-15, gtol=1e-15
    )
    assert objective(c0 + z @ res.x) <= objective(c0)
    return c0 + z @ res.x


@pytest.mark.parametrize("degree", [6, 8, 9])
def test_minimum_jerk_polynomial_against_a_brute_force_optimization(degree):
    """degree > lowest: least ∫ j² dφ subject to the blend conditions, against SLSQP on monomials."""
    cv_lift, cv_span = 20.0, 80.0
    v = cv_lift / RAD(cv_span)
    prog = MotionProgram.from_segments(
        [
            seg("dwell", 80),
            seg("rise", 100, 15, "polynomial", degree=degree),
            seg("rise", cv_span, cv_lift, "constant-velocity"),
            seg(
                "return",
                100,
                35,
                "poly-345",
            ),
        ]
    )
    beta = RAD(100)
    conds = [(0.0, 0, 0.0), (0.0, 1, 0.0), (0.0, 2, 0.0), (beta, 0, 15.0), (beta, 1, v), (beta, 2, 0.0)]
    if degree >= 7:  # the jerk is matched too: 0 at the dwell and on the constant-velocity stretch
        conds += [(0.0, 3, 0.0), (beta, 3, 0.0)]
    c = brute_min_jerk(degree, beta, conds)
    phi = np.linspace(0, beta, 31)
    m = prog.evaluate(RAD(80) + phi)
    ref = np.polynomial.polynomial.polyval(phi / beta, c)
    assert_allclose(m.s, ref, atol=1e-6)
    ref_j = np.polynomial.polynomial.polyval(phi / beta, np.polynomial.polynomial.polyder(c, 3)) / beta**3
    assert_allclose(m.j, ref_j, atol=1e-4 * np.max(np.abs(ref_j)))


def test_two_polynomials_sharing_a_blend_point_take_the_least_jerk_shared_values():
    """Shared v, a at a polynomial–polynomial blend are free: the KKT optimum has zero gradient in them."""
    segs = [
        seg("rise", 90, 10, "polynomial"),
        seg("rise", 90, 10, "polynomial"),
        seg("dwell", 30),
        seg("return", 120, 20, "poly-345"),
        seg("dwell", 30),
    ]
    prog = MotionProgram.from_segments(segs)
    at = RAD(90)
    left, right = one_sided(prog, at)
    assert_allclose(left[:3], right[:3], atol=1e-9)

    def cost(v: float, a: float) -> float:  # jerk norm of both quintics with the shared values given
        b = RAD(90)
        p1 = BPoly.from_derivatives([0, b], [[0, 0, 0], [10, v, a]])
        p2 = BPoly.from_derivatives([0, b], [[10, v, a], [20, 0, 0]])
        x = np.linspace(0, b, 2001)
        return sum(float(np.trapezoid(p(x, nu=3) ** 2, x)) for p in (p1, p2))

    best = cost(left[1], left[2])
    for dv, da in ((1e-2, 0), (-1e-2, 0), (0, 1e-1), (0, -1e-1)):
        assert cost(left[1] + dv, left[2] + da) > best


# ------------------------------------------------------------------ inclined sine


def test_inclined_sine_between_rests_is_the_cycloid():
    prog = MotionProgram.from_segments([seg("rise", 150, 12, "inclined-sine"), seg("dwell", 210)])
    x = np.linspace(0, 1, 33)
    y = make_law("cycloidal").evaluate(x)
    got = prog.segments[0].law.evaluate(x)
    for k in range(4):
        assert_allclose(got[k], y[k], atol=1e-12 * max(1, np.max(np.abs(y[k]))))


def test_inclined_sine_into_constant_velocity_is_c2():
    prog = MotionProgram.from_segments(
        [
            seg("dwell", 60),
            seg("rise", 60, 8, "inclined-sine"),
            seg("rise", 90, 30, "constant-velocity"),
            seg("return", 90, 38, "inclined-sine"),
            seg("dwell", 60),
        ]
    )
    for joint in prog.joints():
        left, right = one_sided(prog, joint.phi)
        assert_allclose(left[:3], right[:3], atol=1e-9 * 100)
        assert joint.continuity >= 2


@given(c0=st.floats(-3, 3), c1=st.floats(-3, 3), x=st.floats(0.01, 0.99))
@settings(max_examples=60, deadline=None)
def test_inclined_sine_boundary_values_and_derivatives(c0, c1, x):
    """y(0) = 0, y(1) = 1, y′ = c₀, c₁, y″ = 0 at the ends; derivatives against central differences."""
    law = InclinedSine(start_velocity=c0, end_velocity=c1)
    ends = law.evaluate(np.array([0.0, 1.0]))
    assert_allclose(ends[0], [0, 1], atol=1e-12)
    assert_allclose(ends[1], [c0, c1], atol=1e-12)
    assert_allclose(ends[2], [0, 0], atol=1e-11)
    h = 1e-4
    for k in range(3):
        fd = (law.evaluate(x + h)[k] - law.evaluate(x - h)[k]) / (2 * h)
        assert_allclose(law.evaluate(x)[k + 1], fd, atol=1e-5 * (1 + abs(float(fd))))


# ------------------------------------------------------------------ design file


def design(*motion, follower=None, **cam):
    fol = follower or {"type": "translating-roller", "roller_radius": 10}
    return parse_design(
        {"cam": {"base_radius": 60, "thickness": 10, **cam}, "follower": fol, "motion": list(motion)}
    )


def test_design_with_velocity_and_close_needs_no_hand_computed_value():
    """200 mm/s at 60 rpm (ω = 2π/s) over 60°: lift = 200/2π · π/3 = 33.33 mm; the return closes it."""
    d = design(
        {"kind": "dwell", "angle": 60},
        {"kind": "rise", "angle": 60, "lift": 10, "law": "polynomial"},
        {"kind": "rise", "angle": 60, "law": "constant-velocity", "velocity": 200},
        {"kind": "return", "angle": 120, "lift": "close", "law": "polynomial"},
        {"kind": "dwell", "angle": 60},
        speed_rpm=60,
    )
    assert d.motion[2].lift == pytest.approx(200 / (2 * math.pi) * math.pi / 3, rel=1e-12)
    assert d.motion[3].lift == pytest.approx(10 + d.motion[2].lift, rel=1e-12)
    prog = MotionProgram.from_segments(d.motion)
    omega = 2 * math.pi
    v = prog.evaluate(np.radians(np.linspace(125, 175, 11))).v * omega  # mm/s
    assert_allclose(v, 200.0, rtol=1e-12)
    assert min(bp.continuity for bp in prog.breakpoints) >= 2


@pytest.mark.parametrize(
    ("motion", "field"),
    [
        (
            [
                {"kind": "rise", "angle": 180, "lift": 5, "law": "cycloidal", "start": {"v": 1.0}},
                {"kind": "return", "angle": 180, "lift": 5, "law": "cycloidal"},
            ],
            "motion[0].start",
        ),
        (
            [
                {"kind": "rise", "angle": 180, "lift": 5, "law": "polynomial", "degree": 4},
                {"kind": "return", "angle": 180, "lift": 5, "law": "cycloidal"},
            ],
            "motion[0].degree",
        ),
        (
            [
                {
                    "kind": "rise",
                    "angle": 180,
                    "lift": 5,
                    "law": "polynomial",
                    "start": {"j": 1.0},
                    "degree": 5,
                },
                {"kind": "return", "angle": 180, "lift": 5, "law": "cycloidal"},
            ],
            "motion[0].degree",
        ),
        (
            [
                {"kind": "rise", "angle": 180, "lift": 5, "law": "inclined-sine", "end": {"a": 1.0}},
                {"kind": "return", "angle": 180, "lift": 5, "law": "cycloidal"},
            ],
            "motion[0].end.a",
        ),
        (
            [
                {"kind": "rise", "angle": 180, "lift": 5, "law": "polynomial", "start": {"w": 1.0}},
                {"kind": "return", "angle": 180, "lift": 5, "law": "cycloidal"},
            ],
            "motion[0].start.w",
        ),
        (
            [
                {"kind": "rise", "angle": 180, "lift": 5, "law": "polynomial", "start": {"v": "fast"}},
                {"kind": "return", "angle": 180, "lift": 5, "law": "cycloidal"},
            ],
            "motion[0].start.v",
        ),
        (
            [
                {"kind": "rise", "angle": 180, "lift": "close", "law": "polynomial"},
                {"kind": "return", "angle": 180, "lift": "close", "law": "cycloidal"},
            ],
            "motion[1].lift",
        ),
        (
            [
                {"kind": "rise", "angle": 180, "lift": 5, "law": "cycloidal"},
                {"kind": "rise", "angle": 180, "lift": "close", "law": "cycloidal"},
            ],
            "motion[1].lift",
        ),
        (
            [
                {"kind": "rise", "angle": 180, "velocity": 5, "law": "cycloidal"},
                {"kind": "return", "angle": 180, "lift": 5, "law": "cycloidal"},
            ],
            "motion[0].velocity",
        ),
    ],
    ids=[
        "start-on-fixed-law",
        "degree-too-low",
        "degree-too-low-for-jerk",
        "inclined-sine-a",
        "unknown-key",
        "not-a-number",
        "close-twice",
        "close-wrong-way",
        "velocity-not-cv",
    ],
)
def test_impossible_boundary_conditions_name_the_field(motion, field):
    with pytest.raises(DesignError) as err:
        design(*motion)
    assert err.value.path == field, str(err.value)


def test_oscillating_follower_blend_in_degrees_builds():
    """An arm's lift is in degrees of swing: the blend program resolves the same way and analyses."""
    import camcad
    from camcad.pipeline import analyse

    d = design(
        {"kind": "dwell", "angle": 40},
        {"kind": "rise", "angle": 80, "lift": 6, "law": "polynomial"},
        {"kind": "rise", "angle": 60, "lift": 6, "law": "constant-velocity"},
        {"kind": "return", "angle": 140, "lift": "close", "law": "polynomial"},
        {"kind": "dwell", "angle": 40},
        follower={"type": "oscillating-roller", "roller_radius": 10, "pivot_distance": 110, "arm_length": 80},
    )
    result = analyse(d, fit=False)
    assert result.summary()["motion"]["lift_deg"] == pytest.approx(12.0)
    assert camcad  # imported for the public API


FIXED = ["harmonic", "cycloidal", "constant-velocity", "modified-sine", "poly-345"]


@st.composite
def blended_programs(draw):
    """2–5 segments of fixed laws, dwells and polynomials; a last polynomial closes the lift."""
    count = draw(st.integers(2, 5))
    spans = draw(st.lists(st.floats(10, 100), min_size=count + 1, max_size=count + 1))
    spans = [360 * x / sum(spans) for x in spans]
    spans[-1] = 360 - sum(spans[:-1])
    out, s = [], 0.0
    for span in spans[:-1]:
        choice = draw(st.sampled_from(["dwell", "polynomial", *FIXED]))
        if choice == "dwell":
            out.append(seg("dwell", span))
            continue
        lift = draw(st.floats(1, 20))
        kind = draw(st.sampled_from(["rise", "return"]))
        s += lift if kind == "rise" else -lift
        extra = {"degree": draw(st.sampled_from([0, 6, 7, 9]))} if choice == "polynomial" else {}
        out.append(seg(kind, span, lift, choice, **extra))
    assume(abs(s) > 0.5)
    out.append(seg("return" if s > 0 else "rise", spans[-1], abs(s), "polynomial"))
    return out


@given(segments=blended_programs())
@settings(max_examples=60, deadline=None)
def test_every_blend_point_is_c2_whatever_the_neighbours(segments):
    """At every joint next to a polynomial: s, v, a equal on both sides (one-sided limits)."""
    prog = MotionProgram.from_segments(segments)
    n = len(segments)
    bounds = [*prog.starts]
    for k, start in enumerate(bounds):
        left_k = (k - 1) % n
        if segments[k].law is None or segments[k].law.name != "polynomial":
            if segments[left_k].law is None or segments[left_k].law.name != "polynomial":
                continue
        left, right = one_sided(prog, start)
        scale = max(1.0, prog.lift) / min(g.span for g in segments) ** np.arange(4)
        assert np.all(np.abs(left[:3] - right[:3]) <= 1e-8 * scale[:3]), (k, left, right)


def test_blend_points_are_the_joints_next_to_adaptive_segments():
    prog = packaging(10, 20, (60, 60, 60, 120, 60))
    assert [round(math.degrees(bp.phi), 9) for bp in prog.blend_points] == [60, 120, 180, 300]
    assert all(bp.continuity >= 2 for bp in prog.blend_points)
