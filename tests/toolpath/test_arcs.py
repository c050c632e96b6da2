"""Biarcs: construction invariants, exact circles, and measured tolerance on analytic curves."""

from __future__ import annotations

import math
from functools import cache

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.spatial import cKDTree

from camcad.errors import ArcSearchStallError
from camcad.toolpath.arcs import spline
from camcad.toolpath.arcs.biarc import (
    biarc_pieces,
    chord_pieces,
    measure_deviation,
    offset_pieces,
    sample_pieces,
)
from camcad.toolpath.arcs.search import search_arcs
from camcad.toolpath.arcs.spline import fit_arc_spline


def ellipse(a: float, b: float):
    """x = a cos φ, y = b sin φ with its φ-derivatives."""

    def curve(phi):
        phi = np.asarray(phi, dtype=float)
        p = np.column_stack((a * np.cos(phi), b * np.sin(phi)))
        d1 = np.column_stack((-a * np.sin(phi), b * np.cos(phi)))
        return p, d1, -p

    return curve


def wobble(r0: float = 50.0, amp: float = 6.0, k: int = 3):
    """A star-shaped curve r = r0 + amp cos kφ, with concave stretches when amp·k² is large."""

    def curve(phi):
        phi = np.asarray(phi, dtype=float)
        r = r0 + amp * np.cos(k * phi)
        return polar(phi, r, -amp * k * np.sin(k * phi), -amp * k * k * np.cos(k * phi))

    return curve


def polar(phi, r, r1, r2):
    """Point, first and second φ-derivative of the polar curve r(φ) from r, r′ and r″."""
    c, s = np.cos(phi), np.sin(phi)
    p = np.column_stack((r * c, r * s))
    d1 = np.column_stack((r1 * c - r * s, r1 * s + r * c))
    d2 = np.column_stack((r2 * c - 2 * r1 * s - r * c, r2 * s + 2 * r1 * c - r * s))
    return p, d1, d2


def unit(angle):
    return np.column_stack((np.cos(angle), np.sin(angle)))


def dense_distance(points, poly):
    """Distance from points to a dense polyline: the segments beside the 4 nearest vertices."""
    _, idx = cKDTree(poly).query(points, k=4)
    best = np.full(len(points), np.inf)
    for col in range(4):
        for first in (idx[:, col] - 1, idx[:, col]):
            j = np.clip(first, 0, len(poly) - 2)
            a, w = poly[j], poly[j + 1] - poly[j]
            ww = np.maximum(np.einsum("ij,ij->i", w, w), 1e-300)
            t = np.clip(np.einsum("ij,ij->i", points - a, w) / ww, 0.0, 1.0)
            best = np.minimum(best, np.linalg.norm(points - (a + w * t[:, None]), axis=1))
    return best


@settings(max_examples=200, deadline=None)
@given(
    x=st.floats(1.0, 30.0),
    y=st.floats(-10.0, 10.0),
    a0=st.floats(-1.2, 1.2),
    a1=st.floats(-1.2, 1.2),
    ratio=st.sampled_from([0.75, 1.0, 1.33]),
)
def test_biarc_meets_ends_and_joins_tangentially(x, y, a0, a1, ratio):
    p0, p1 = np.array([[0.0, 0.0]]), np.array([[x, y]])
    chord = math.atan2(y, x)
    t0, t1 = unit(np.array([chord + a0])), unit(np.array([chord + a1]))
    pc = biarc_pieces(np.zeros(1), np.ones(1), p0, t0, p1, t1, ratio=ratio)
    assert_allclose(pc.start[0, 0], p0[0], atol=1e-12)
    assert_allclose(pc.end[0, 1], p1[0], atol=1e-9)
    assert_allclose(pc.end[0, 0], pc.start[0, 1], atol=0)
    # both arcs pass through the joint and keep their radius
    for k in (0, 1):
        if not pc.line[0, k]:
            r_a = np.linalg.norm(pc.start[0, k] - pc.center[0, k])
            r_b = np.linalg.norm(pc.end[0, k] - pc.center[0, k])
            assert abs(r_a - r_b) <= 1e-9 * max(1.0, r_a)
    # tangents: the first arc leaves along t0, the second arrives along t1, and they agree at the joint

    def tangent(k, at_end):
        if pc.line[0, k]:
            d = pc.end[0, k] - pc.start[0, k]
            return d / np.linalg.norm(d)
        p = pc.end[0, k] if at_end else pc.start[0, k]
        rad = p - pc.center[0, k]
        left = np.array([-rad[1], rad[0]]) / np.linalg.norm(rad)
        return left if pc.ccw[0, k] else -left

    assert_allclose(tangent(0, False), t0[0], atol=1e-7)
    assert_allclose(tangent(1, True), t1[0], atol=1e-7)
    assert_allclose(tangent(0, True), tangent(1, False), atol=1e-7)


def test_circle_is_one_exact_biarc_per_break():
    circle = ellipse(40.0, 40.0)
    pieces, dev = fit_arc_spline(circle, np.linspace(0.0, 2 * np.pi, 5), 1e-4)
    assert len(pieces) == 4
    assert dev.max() < 1e-9
    assert_allclose(pieces.r_start, 40.0, rtol=1e-9)
    assert_allclose(pieces.center.reshape(-1, 2), 0.0, atol=1e-9)


@pytest.mark.parametrize("tol", [0.05, 0.005, 0.001], ids=lambda t: f"tol{t:g}")
@pytest.mark.parametrize("name", ["ellipse", "wobble"])
def test_fit_stays_within_tolerance_by_independent_measure(name, tol):
    curve = ellipse(60.0, 35.0) if name == "ellipse" else wobble()
    pieces, dev = fit_arc_spline(curve, np.linspace(0.0, 2 * np.pi, 5), tol)
    assert dev.max() <= tol
    assert_two_way_within(curve, pieces, tol)


def assert_two_way_within(curve, pieces, tol):
    """Independent two-way check on dense samples of both the curve and the pieces."""
    exact = curve(np.linspace(0.0, 2 * np.pi, 40001))[0]
    samples = sample_pieces(pieces, 400)  # chord sagitta < 1e-6 mm
    lengths = pieces.length()
    both = np.vstack(
        [
            np.stack([pieces.start[i, k], *samples[i, k], pieces.end[i, k]])
            for i in range(len(pieces))
            for k in (0, 1)
            if lengths[i, k] > 0.0  # an interval with one arc has an empty second piece
        ]
    )
    probe = exact[::3]
    assert dense_distance(both, exact).max() <= tol * 1.001
    assert dense_distance(probe, both).max() <= tol * 1.001


def test_pieces_are_g1_continuous_across_intervals():
    pieces, _ = fit_arc_spline(wobble(), np.linspace(0.0, 2 * np.pi, 7), 0.002)
    assert_allclose(pieces.end[:-1, 1], pieces.start[1:, 0], atol=0)
    assert_allclose(pieces.end[:, 0], pieces.start[:, 1], atol=0)


def test_biarcs_need_far_fewer_blocks_than_chords():
    curve = ellipse(60.0, 35.0)
    arcs, _ = fit_arc_spline(curve, np.linspace(0.0, 2 * np.pi, 5), 0.004)
    chords, _ = fit_arc_spline(curve, np.linspace(0.0, 2 * np.pi, 5), 0.004, arcs=False)
    assert 2 * len(arcs) * 3 < len(chords)


def test_chords_deviation_is_their_sagitta():
    circle = ellipse(10.0, 10.0)
    n = 16
    phi = np.linspace(0.0, 2 * np.pi, n + 1)
    p, d1, _ = circle(phi)
    t = d1 / np.linalg.norm(d1, axis=1)[:, None]
    pc = chord_pieces(phi[:-1], phi[1:], p[:-1], t[:-1], p[1:], t[1:])
    sagitta = 10.0 * (1.0 - math.cos(math.pi / n))
    assert_allclose(measure_deviation(circle, pc, samples=101), sagitta, rtol=1e-3)


def _piece_tangents(pieces):
    """Unit tangents (m, 2) at the start and at the end of every non-empty piece, in path order."""
    starts, ends = [], []
    for i in range(len(pieces)):
        for k in (0, 1):
            s, e = pieces.start[i, k], pieces.end[i, k]
            if np.array_equal(s, e):
                continue
            if pieces.line[i, k]:
                d = (e - s) / np.linalg.norm(e - s)
                starts.append(d)
                ends.append(d)
                continue
            sign = 1.0 if pieces.ccw[i, k] else -1.0
            for p, out in ((s, starts), (e, ends)):
                rad = (p - pieces.center[i, k]) / np.linalg.norm(p - pieces.center[i, k])
                out.append(sign * np.array([-rad[1], rad[0]]))
    return np.array(starts), np.array(ends)


def dwelled(r0: float = 40.0, lift: float = 8.0):
    """A cam-like closed curve r(φ): circles r0 on [0, π/2] and r0 + lift on [π, 3π/2], cycloidal between."""

    def curve(phi):
        phi = np.asarray(phi, dtype=float)
        u = np.mod(phi, 2 * np.pi)
        beta = np.pi / 2
        r = np.where((u >= np.pi) & (u <= 3 * np.pi / 2), r0 + lift, r0)
        r1, r2 = np.zeros_like(u), np.zeros_like(u)
        for start, sign, base in ((np.pi / 2, 1.0, r0), (3 * np.pi / 2, -1.0, r0 + lift)):
            x = (u - start) / beta
            on = (x > 0) & (x < 1)
            r = np.where(on, base + sign * lift * (x - np.sin(2 * np.pi * x) / (2 * np.pi)), r)
            r1 = np.where(on, sign * lift * (1 - np.cos(2 * np.pi * x)) / beta, r1)
            r2 = np.where(on, sign * lift * 2 * np.pi * np.sin(2 * np.pi * x) / beta**2, r2)
        return polar(phi, r, r1, r2)

    return curve


def arc_count(pieces) -> int:
    return int(np.sum(np.abs(pieces.sweep()) > 0.0) + np.sum(pieces.line & (pieces.length() > 0.0)))


@pytest.mark.parametrize("tol", [0.004, 0.001])
def test_a_closed_curve_closes_on_its_first_arc_one_arc_shorter(tol):
    """closed=True: one tangent-continuous loop within tol two-way, fewer arcs than the fit held at C(0)."""
    curve = dwelled()
    pieces, dev = fit_arc_spline(curve, [0.0, 2 * np.pi], tol, closed=True)
    held, _ = fit_arc_spline(curve, [0.0, 2 * np.pi], tol)
    assert dev.max() <= tol
    assert_two_way_within(curve, pieces, tol)
    assert arc_count(pieces) < arc_count(held)
    # the start moved off C(0) (within the band), and the φ-intervals still make one turn
    assert pieces.lo[0] != 0.0
    assert abs(pieces.hi[-1] - pieces.lo[0] - 2 * np.pi) <= 1e-12
    # a closed chain: every piece starts where the one before ends, the last ends at the start
    flat_start, flat_end = pieces.start.reshape(-1, 2), pieces.end.reshape(-1, 2)
    assert_allclose(flat_end, np.roll(flat_start, -1, axis=0), atol=1e-12)
    starts, ends = _piece_tangents(pieces)
    assert_allclose(ends, np.roll(starts, -1, axis=0), atol=1e-9)


@settings(max_examples=300, deadline=None)
@given(
    px=st.floats(-50.0, 50.0), py=st.floats(-50.0, 50.0), heading=st.floats(-np.pi, np.pi),
    cx=st.floats(-50.0, 50.0), cy=st.floats(-50.0, 50.0), rho=st.floats(2.0, 80.0), ccw=st.booleans(),
)  # fmt: skip
# κρ₁ = 1 − 7.5e-5: |t_x| is 1 + 2.3e-9
@example(px=0.0, py=2.0, heading=0.0, cx=0.0, cy=0.0003, rho=2.0, ccw=False)
# p 1.2e-7 inside the circle, along it (κρ₁ = 1 − 1.3e-8): the arc is the circle, so there is no X
@example(
    px=0.0, py=1.192092896e-07, heading=0.0, cx=0.0, cy=4.111226595503638, rho=4.111226595503638, ccw=True
)
def test_an_arc_touching_a_circle_lands_on_it_with_the_circle_s_tangent(px, py, heading, cx, cy, rho, ccw):
    """_touching: X lies on both circles, and both travel through X with the same unit tangent."""
    from camcad.toolpath.arcs.search import _touching

    p, t = np.array([[px, py]]), unit(np.array([heading]))
    c1, rho1 = np.array([[cx, cy]]), np.array([rho if ccw else -rho])
    kappa, x, t_x = _touching(p, t, c1, rho1)
    if not (np.isfinite(kappa[0]) and np.all(np.isfinite(x))) or abs(kappa[0]) < 1e-9:
        return  # no such arc (p on the circle), or a straight line
    left = lambda v: np.array([-v[1], v[0]])  # noqa: E731
    centre = p[0] + left(t[0]) / kappa[0]  # the arc leaving p along t with curvature κ
    # nearly coincident circles (κρ₁ → 1) touch at an ill-conditioned point: the error grows as 1/|1 − κρ₁|
    scale = max(1.0, abs(1.0 / kappa[0]), rho) / min(1.0, abs(1.0 - kappa[0] * rho1[0]))
    assert abs(np.linalg.norm(x[0] - centre) - 1.0 / abs(kappa[0])) <= 1e-9 * scale
    assert abs(np.linalg.norm(x[0] - c1[0]) - rho) <= 1e-9 * scale
    assert abs(np.linalg.norm(t_x[0]) - 1.0) <= 1e-9 * scale  # m = (κw + n)/(1 − κρ₁) carries the same error
    # travelling with curvature κ (ρ₁) the centre lies 1/κ (ρ₁) along the left normal
    assert_allclose(x[0] + left(t_x[0]) / kappa[0], centre, atol=1e-8 * scale)
    assert_allclose(x[0] + left(t_x[0]) * rho1[0], c1[0], atol=1e-8 * scale)


def test_the_dwells_of_a_curve_are_found_as_its_circles():
    """_circles: the two dwells of dwelled(), centred on the origin, radii 40 and 48, over their φ-ranges."""
    from camcad.toolpath.arcs.search import _circles, _table

    phi = _table(0.0, 2 * np.pi)
    pts, d1, d2 = dwelled()(phi)
    found = _circles(pts, d1, d2)
    assert_allclose(found.center, np.zeros((2, 2)), atol=1e-9)
    assert_allclose(found.rho, [40.0, 48.0], rtol=1e-12)  # counter-clockwise: positive
    step = phi[1] - phi[0]
    assert_allclose(phi[found.first], [0.0, np.pi], atol=1.01 * step)
    assert_allclose(phi[found.last], [np.pi / 2, 3 * np.pi / 2], atol=1.01 * step)
    # an ellipse has no stretch of constant curvature
    pts, d1, d2 = ellipse(60.0, 35.0)(phi)
    assert _circles(pts, d1, d2).rho.size == 0


def test_states_landed_on_a_dwell_lie_on_its_circle_and_their_arcs_are_in_tolerance():
    """_onto_circles: from states on the rise before a dwell, each new state is on the dwell's circle with its
    tangent, ahead of its parent, and the arc to it is within tol of the curve (independent dense check)."""
    from camcad.toolpath.arcs.search import _circles, _Layer, _onto_circles, _table

    curve, tol = dwelled(), 0.004
    phi = _table(0.0, 2 * np.pi)
    pts, d1, d2 = curve(phi)
    circles = _circles(pts, d1, d2)
    j = np.arange(470, 512)  # φ ≈ 165° … 180°, the end of the rise to the dwell at r = 48 (φ ≥ 180°)
    tan = d1 / np.linalg.norm(d1, axis=1)[:, None]
    layer = _Layer(j, pts[j], tan[j], np.zeros(j.size, int), None, np.zeros(j.size), phi[j])
    got = _onto_circles(curve, layer, circles, phi, pts, tol, 512)
    assert got is not None and got.j.size > 0
    assert_allclose(np.linalg.norm(got.p, axis=1), 48.0, atol=1e-9)
    assert_allclose(np.einsum("ij,ij->i", got.p, got.t), 0.0, atol=1e-9)  # tangent ⟂ radius
    assert np.all(got.p[:, 0] * got.t[:, 1] - got.p[:, 1] * got.t[:, 0] > 0.0)  # counter-clockwise
    assert np.all(got.at > layer.at[got.parent])
    for i in range(got.j.size):  # each arc against the curve over its own φ-span, densely
        exact = curve(np.linspace(got.arc.lo[i], got.arc.hi[i], 4001))[0]
        arc = np.vstack((got.arc.start[i, 0], sample_pieces(take(got.arc, i), 400)[0, 0], got.arc.end[i, 0]))
        assert dense_distance(arc, exact).max() <= tol * 1.001
        assert dense_distance(exact[::3], arc).max() <= tol * 1.001


def take(pieces, i):
    from camcad.toolpath.arcs.biarc import take_pieces

    return take_pieces(pieces, np.array([i]))


def test_a_stalled_arc_search_raises_its_own_error():
    # 1e-7 mm is below what the sampled screen and the measurement can separate
    with pytest.raises(ArcSearchStallError, match="stalled"):
        search_arcs(ellipse(60.0, 35.0), 0.0, 0.5, 1e-7)


def test_a_stalled_search_falls_back_to_the_biarc_march_within_tolerance(monkeypatch):
    def stall(*args, **kwargs):
        raise ArcSearchStallError("arc search stalled")

    monkeypatch.setattr(spline, "search_arcs", stall)
    curve, tol = wobble(), 0.004
    pieces, dev = fit_arc_spline(curve, np.linspace(0.0, 2 * np.pi, 5), tol)
    assert dev.max() <= tol
    assert_two_way_within(curve, pieces, tol)
    assert_allclose(pieces.end[:-1, 1], pieces.start[1:, 0], atol=0)  # still one connected path


def test_other_errors_of_the_search_are_not_taken_for_a_stall(monkeypatch):
    def broken(*args, **kwargs):
        raise ValueError("not a stall")

    monkeypatch.setattr(spline, "search_arcs", broken)
    with pytest.raises(ValueError, match="not a stall"):
        fit_arc_spline(wobble(), np.linspace(0.0, 2 * np.pi, 5), 0.004)


def chain_points(pieces):
    """Dense points along every non-empty piece (chord sagitta below 1e-6 mm)."""
    samples = sample_pieces(pieces, 400)
    lengths = pieces.length()
    return np.vstack(
        [
            np.stack([pieces.start[i, k], *samples[i, k], pieces.end[i, k]])
            for i in range(len(pieces))
            for k in (0, 1)
            if lengths[i, k] > 0.0
        ]
    )


@cache
def ellipse_spline(a: float, b: float):
    pieces, _ = fit_arc_spline(ellipse(a, b), np.linspace(0.0, 2 * np.pi, 5), 0.004)
    return pieces


@settings(max_examples=25, deadline=None)
@given(
    axes=st.sampled_from([(60.0, 35.0), (45.0, 40.0), (30.0, 25.0)]),
    delta=st.floats(-3.0, 3.0).filter(lambda d: abs(d) > 1e-3),
)
def test_offset_arc_spline_is_the_parallel_curve_with_as_many_pieces(axes, delta):
    # against the definition of a parallel curve: every point of the offset chain lies at |δ| from the
    # original chain and every point of the original at |δ| from the offset (both measured on dense
    # polylines with a k-d tree), and the chain stays one closed connected path
    pieces = ellipse_spline(*axes)
    moved = offset_pieces(pieces, delta)
    assert moved is not None
    assert len(moved) == len(pieces)
    assert_allclose(moved.end[:-1, 1], moved.start[1:, 0], atol=1e-9)
    assert_allclose(moved.end[:, 0], moved.start[:, 1], atol=1e-9)
    assert_allclose(moved.end[-1, 1], moved.start[0, 0], atol=1e-9)
    old, new = chain_points(pieces), chain_points(moved)
    assert_allclose(dense_distance(new, old), abs(delta), atol=2e-6)
    assert_allclose(dense_distance(old, new), abs(delta), atol=2e-6)
    # δ moves to the left of travel; the ellipse runs counter-clockwise, so δ > 0 moves inward
    assert (shoelace(new) < shoelace(old)) == (delta > 0.0)


def shoelace(p):
    """Signed area enclosed by a closed polyline (n, 2)."""
    return 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])


def test_offset_that_would_turn_an_arc_inside_out_is_refused():
    # a circle of radius 10 run counter-clockwise: its centre is on the left, 10 mm away
    pieces, _ = fit_arc_spline(ellipse(10.0, 10.0), np.linspace(0.0, 2 * np.pi, 5), 1e-4)
    assert offset_pieces(pieces, 10.0) is None
    inner = offset_pieces(pieces, 9.9)
    assert inner is not None
    assert_allclose(inner.r_start[~inner.line], 0.1, atol=1e-9)
    assert_allclose(inner.center.reshape(-1, 2)[~inner.line.ravel()], 0.0, atol=1e-9)


@settings(max_examples=200, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    radius=st.floats(-200.0, 200.0).filter(lambda r: abs(r) > 2.0),
    band=st.floats(1e-4, 0.05),
    behind=st.booleans(),
)
def test_the_screen_reach_is_the_first_sample_a_walk_finds_outside_the_band(seed, radius, band, behind):
    """_admissible + _first_out (running curvature intervals, binary search) against walking every sample.

    The walk measures each sample's distance to the arc from its centre, |‖q − c‖ − R| (a line: |w·n|),
    and takes a sample behind the start (w·t ≤ 0) as outside unless it lies beyond the arc's half
    turn (κ·(w·n) > 1/2), the screen's rule.
    """
    from camcad.toolpath.arcs.search import _admissible, _first_out

    rng = np.random.default_rng(seed)
    # samples along a circle of the given radius from the origin (the state), with noise of about the band
    s = np.sort(rng.uniform(-2.0 if behind else 0.01, 30.0, 64))
    ang = s / radius
    pts = np.column_stack((radius * np.sin(ang), radius * (1.0 - np.cos(ang))))
    pts += rng.normal(0.0, band, pts.shape)
    a, b = pts[:, 0], pts[:, 1]  # the state's tangent is +x, its normal +y
    kappa = 1.0 / radius + rng.normal(0.0, 0.02 / abs(radius), 40)
    kappa[:3] = (0.0, 1.0 / radius, -1.0 / radius)
    lo, hi = _admissible(a[None], b[None], (a * a + b * b)[None], band)
    got = _first_out(np.maximum.accumulate(lo, axis=1), np.minimum.accumulate(hi, axis=1), kappa[None])[0]
    for k, first in zip(kappa, got, strict=True):
        if k == 0.0:
            dist = np.abs(b)
        else:
            centre = np.array([0.0, 1.0 / k])
            dist = np.abs(np.hypot(a - centre[0], b - centre[1]) - 1.0 / abs(k))
        out = (dist > band) | ((a <= 0.0) & (k * b <= 0.5))
        walk = int(np.argmax(out)) if out.any() else a.size
        near_tie = np.abs(dist - band) < 1e-9 * max(1.0, float(np.max(np.abs(pts))))
        if walk != first:  # only a sample on the band's edge (to round-off) may be judged either way
            assert near_tie[min(walk, first)]


@settings(max_examples=100, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    radius=st.floats(-500.0, 500.0).filter(lambda r: abs(r) > 2.0),
    straight=st.booleans(),
)
def test_the_gap_between_samples_is_the_distance_to_the_arc_s_circle(seed, radius, straight):
    """_between_samples against each point's distance from the circle's centre, |‖q − c‖ − R| or |w·n|."""
    from camcad.toolpath.arcs.search import _between_samples

    rng = np.random.default_rng(seed)
    mids = rng.uniform(-20.0, 20.0, (200, 2))
    arcs = 12
    p = rng.uniform(-20.0, 20.0, (arcs, 2))
    t = unit(rng.uniform(-math.pi, math.pi, arcs))
    kappa = np.zeros(arcs) if straight else 1.0 / radius * rng.uniform(0.5, 1.5, arcs)
    j0 = rng.integers(0, 150, arcs)
    j1 = j0 + rng.integers(1, 50, arcs)
    got = _between_samples(p, t, kappa, mids, j0, j1)
    for i in range(arcs):
        w = mids[j0[i] : j1[i]] - p[i]
        if kappa[i] == 0.0:
            dist = np.abs(w[:, 0] * -t[i, 1] + w[:, 1] * t[i, 0])
        else:
            centre = p[i] + np.array([-t[i, 1], t[i, 0]]) / kappa[i]
            dist = np.abs(np.linalg.norm(mids[j0[i] : j1[i]] - centre, axis=1) - 1.0 / abs(kappa[i]))
        assert got[i] == pytest.approx(dist.max(), rel=1e-9, abs=1e-9)


CURVES = {"ellipse": ellipse(60.0, 35.0), "wobble": wobble(), "concave": wobble(40.0, 3.0, 5)}


@pytest.mark.parametrize("closed", [False, True], ids=["open", "closed"])
@pytest.mark.parametrize("tol", [0.004, 0.001], ids=lambda t: f"tol{t:g}")
@pytest.mark.parametrize("name", sorted(CURVES))
def test_arcs_kept_unmeasured_give_the_search_of_every_arc_measured(name, tol, closed):
    """The search keeps arcs midway in the band unmeasured: the same arcs, bit for bit, as measuring all."""
    from dataclasses import fields

    from camcad.toolpath.arcs.search import _search

    b = 2.0 * math.pi if closed else 2.5
    lazy, devs = search_arcs(CURVES[name], 0.0, b, tol, closed=closed)
    every = _search(CURVES[name], 0.0, b, tol, closed, -math.inf)
    assert every is not None
    assert len(lazy) == len(every[0])
    for got, want in zip(lazy, every[0], strict=True):
        for f in fields(got):
            np.testing.assert_array_equal(getattr(got, f.name), getattr(want, f.name))
    for got, want in zip(devs, every[1], strict=True):
        np.testing.assert_array_equal(got, want)
    assert max(float(d.max()) for d in devs) <= tol


def test_an_unmeasured_arc_that_fails_on_the_path_makes_the_search_measure_every_arc(monkeypatch):
    """When the path's unmeasured arcs fail their measurement, the search runs again measuring every arc."""
    from camcad.toolpath.arcs import search

    curve, tol = wobble(), 0.004
    want = search._search(curve, 0.0, 2.5, tol, False, -math.inf)
    assert want is not None
    monkeypatch.setattr(search, "_SURE", math.inf)  # no layer measures: the path's arcs are, in _trace
    real, runs, failed = search.measure_deviation, [], []

    def failing_once(curve, pieces, **kw):
        out = real(curve, pieces, **kw)
        if kw.get("samples") == search._LAYER_SAMPLES and not failed:
            failed.append(len(pieces))
            return out + 2.0 * tol
        return out

    def counted(*args, **kw):
        runs.append(args[-1])  # sure
        return real_search(*args, **kw)

    real_search = search._search
    monkeypatch.setattr(search, "measure_deviation", failing_once)
    monkeypatch.setattr(search, "_search", counted)
    got, devs = search.search_arcs(curve, 0.0, 2.5, tol)
    assert runs == [math.inf, -math.inf] and failed
    assert len(got) == len(want[0])
    for a, b in zip(got, want[0], strict=True):
        np.testing.assert_array_equal(a.center, b.center)
    for a, b in zip(devs, want[1], strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("sure", [math.inf, -math.inf], ids=["path", "layers"])
def test_a_measurement_that_comes_back_nan_rejects_the_arc(monkeypatch, sure):
    """An arc measured as NaN fails as one measured far off, in the layers and on the path.

    (The layers mark an arc not yet measured with a NaN deviation.)
    """
    from camcad.toolpath.arcs import search

    curve, tol, real = wobble(), 0.004, search.measure_deviation

    def spoiled(value):
        def measure(curve, pieces, **kw):
            out = real(curve, pieces, **kw)
            if kw.get("samples") == search._LAYER_SAMPLES:
                out = np.where(out > 0.9 * tol, value, out)  # the same arcs spoiled either way
            return out

        return measure

    runs = {}
    for value in (np.nan, np.inf):
        monkeypatch.setattr(search, "measure_deviation", spoiled(value))
        runs[str(value)] = search._search(curve, 0.0, 2.5, tol, False, sure)
    if sure == math.inf:  # nothing measured in the layers: the path's spoiled arcs fail it
        assert runs["nan"] is None and runs["inf"] is None
    else:
        assert runs["nan"] is not None and runs["inf"] is not None
        for a, b in zip(runs["nan"][0], runs["inf"][0], strict=True):
            np.testing.assert_array_equal(a.center, b.center)
        assert all(float(d.max()) <= 0.9 * tol for d in runs["nan"][1][:-1])


def test_the_refit_s_jacobians_are_its_finite_differences():
    """refine: dg/dx of every sample's gap and of the four loop equations equal central differences."""
    from camcad.toolpath.arcs import refine

    rng = np.random.default_rng(7)
    n = 6
    x = np.concatenate(([1.0, -2.0, 0.3], rng.uniform(-0.05, 0.05, n), rng.uniform(5.0, 15.0, n)))
    q = rng.uniform(-30.0, 30.0, (50, 2))
    seg = rng.integers(0, n, 50)
    c0, t0 = np.array([0.5, 0.2]), np.array([0.6, 0.8])

    def values(y):
        loop = refine._joints(y, n)
        return refine._gaps(loop, q, seg)[0], refine._closure(loop, 2 * np.pi, c0, t0)[0]

    loop = refine._joints(x, n)
    jac = refine._gaps(loop, q, seg)[1]
    eq_jac = refine._closure(loop, 2 * np.pi, c0, t0)[1]
    h = 1e-6
    for k in range(x.size):
        e = np.zeros_like(x)
        e[k] = h
        (g1, c1), (g0, c0_) = values(x + e), values(x - e)
        assert_allclose(jac[:, k], (g1 - g0) / (2 * h), rtol=1e-6, atol=1e-6 * np.abs(jac).max())
        assert_allclose(eq_jac[:, k], (c1 - c0_) / (2 * h), rtol=1e-6, atol=1e-6 * np.abs(eq_jac).max())


@cache
def harmonic_finish():
    """The finishing path of the shipped quintero_harmonic sample: its exact curve, fit band and start φ."""
    from camcad.design import load_design
    from camcad.geometry.cam import Cam
    from camcad.toolpath.contour import offset_curve
    from camcad.toolpath.plan import _fit_tolerance
    from tests.conftest import ROOT

    design = load_design(ROOT / "samples" / "quintero_harmonic.toml")
    cam = Cam.from_design(design)
    return offset_curve(cam, design.gcode.tool_radius), _fit_tolerance(design.gcode.tolerance)


def test_a_thinned_loop_has_fewer_arcs_is_one_g1_loop_in_tolerance_and_starts_abeam_its_start():
    """fewest_arcs=True: arcs dropped by the minimax refit; a dense two-way check, closure and tangents."""
    curve, tol = harmonic_finish()
    searched, _ = fit_arc_spline(curve, [0.0, 2 * np.pi], tol, closed=True)
    pieces, dev = fit_arc_spline(curve, [0.0, 2 * np.pi], tol, closed=True, fewest_arcs=True)
    assert arc_count(pieces) <= arc_count(searched) - 1
    assert dev.max() <= tol
    assert_two_way_within(curve, pieces, tol)
    flat_start, flat_end = pieces.start.reshape(-1, 2), pieces.end.reshape(-1, 2)
    assert_allclose(flat_end, np.roll(flat_start, -1, axis=0), atol=1e-9)
    starts, ends = _piece_tangents(pieces)
    assert_allclose(ends, np.roll(starts, -1, axis=0), atol=1e-9)
    # the loop starts on the normal of C(0), within the band, and its φ-intervals make one turn
    c0, d0, _ = curve(np.array([0.0]))
    along = (pieces.start[0, 0] - c0[0]) @ (d0[0] / np.linalg.norm(d0[0]))
    assert abs(along) <= 1e-9
    assert np.linalg.norm(pieces.start[0, 0] - c0[0]) <= tol
    assert pieces.lo[0] == 0.0 and pieces.hi[-1] == 2 * np.pi and np.all(np.diff(pieces.lo) > 0)
