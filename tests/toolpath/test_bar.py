"""Arc splines on an open curve, and a linear cam's bar milled in arcs (issue 36).

- The law, over open curves (hypothesis): the arc spline of an open curve
  starts on C(a) with the curve's tangent, ends on C(b) (with its tangent,
  or an arc landing there within the band), joins G1, and lies within the
  tolerance of the curve both ways by a brute force independent of the
  fit's measurement (dense samples of both).
- The bar's plan (:func:`camcad.toolpath.bar.plan_bar`): its written
  finishing pass, rounded to 4 decimals, is within the plate's band of the
  exact offset both ways by brute force, which the reported
  ``max_deviation`` bounds; climb runs with the part on the tool's right
  (towards +x); G1 chords at the same tolerance need several times the blocks.
- Straight stretches (a linear cam's dwells): over open curves with an
  exactly straight stretch (hypothesis), the stretch is one line on it to
  its exact end, from its start or from where the arc before lands on it,
  G1 with the arcs beside it; on the bar,
  each dwell is one G1 move on the line the sample's numbers give
  (y = base radius + the dwell's lift + tool radius, x = Lφ/2π), between
  arcs tangent to it.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace
from functools import cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from camcad.design import load_design
from camcad.geometry.cam import Cam
from camcad.geometry.families import Bar, family_of
from camcad.toolpath.arcs.spline import fit_arc_spline
from camcad.toolpath.bar import plan_bar
from camcad.toolpath.spec import Direction
from camcad.toolpath.verify import densify
from tests.conftest import ROOT
from tests.readers.test_rs274_linear import passes
from tests.toolpath.test_arcs import assert_two_way_within, dense_distance


def graph(length: float, amp: float, k: int, slope: float):
    """The open curve x = cφ, y = amp·sin(kφ) + slope·cφ (c = length/2π), φ ∈ [0, 2π], and derivatives."""
    c = length / (2.0 * math.pi)

    def curve(phi):
        phi = np.asarray(phi, dtype=float)
        p = np.column_stack((c * phi, amp * np.sin(k * phi) + slope * c * phi))
        d1 = np.column_stack((np.full_like(phi, c), amp * k * np.cos(k * phi) + slope * c))
        d2 = np.column_stack((np.zeros_like(phi), -amp * k * k * np.sin(k * phi)))
        return p, d1, d2

    return curve


@settings(max_examples=8, deadline=None)
@given(
    length=st.floats(80.0, 400.0),
    amp=st.floats(0.0, 15.0),
    k=st.integers(1, 3),
    slope=st.floats(-0.5, 0.5),
    tol=st.sampled_from([0.002, 0.01]),
)
def test_an_open_curve_s_arc_spline_runs_end_to_end_g1_within_tolerance(length, amp, k, slope, tol):
    curve = graph(length, amp, k, slope)
    pieces, dev = fit_arc_spline(curve, np.array([0.0, 2.0 * math.pi]), tol, closed=False)
    assert dev.max() <= tol
    ends, d1, _ = curve(np.array([0.0, 2.0 * math.pi]))
    tangent = d1 / np.linalg.norm(d1, axis=1)[:, None]
    starts, stops = pieces.tangents()
    assert_allclose(pieces.start[0, 0], ends[0], atol=1e-12)
    assert_allclose(starts[0, 0], tangent[0], atol=1e-9)
    # it ends on the curve's end: by a biarc on the curve's tangent, or an arc that lands there (its
    # tangent then within the band's slack of the curve's)
    last = len(pieces) - 1
    k_end = 0 if np.all(pieces.start[last, 1] == pieces.end[last, 1]) else 1
    assert_allclose(pieces.end[last, k_end], ends[1], atol=1e-9)
    assert float(stops[last, k_end] @ tangent[1]) > math.cos(0.01)
    # G1: every piece starts where the one before ends, on its tangent
    flat_start, flat_end = pieces.start.reshape(-1, 2), pieces.end.reshape(-1, 2)
    live = np.linalg.norm(flat_end - flat_start, axis=1) > 0.0
    t0, t1 = starts.reshape(-1, 2)[live], stops.reshape(-1, 2)[live]
    assert_allclose(flat_end[live][:-1], flat_start[live][1:], atol=1e-9)
    # an arc bulging less than 1e-9 mm is kept as its chord (biarc.py); the chord's direction is off the
    # arc's end tangents by half its turn, κL/2 = 4·sagitta/L, which only a piece far below the G-code's
    # resolution makes visible: each joint may turn by that much for a line beside it
    chord = np.linalg.norm(flat_end - flat_start, axis=1)[live]
    slack = np.where(pieces.line.reshape(-1)[live], 4.0 * 1e-9 / chord, 0.0)
    turn = np.linalg.norm(t1[:-1] - t0[1:], axis=1)
    assert np.all(turn <= 1e-7 + slack[:-1] + slack[1:]), (turn.max(), chord[np.argmax(turn)])
    assert_two_way_within(curve, pieces, tol)


def flat_between(length: float, amp: float, slope: float, p: float, q: float):
    """x = cφ, y = slope·cφ + amp·g(φ): exactly the line y = slope·x for φ ∈ [p, q], curved outside.

    g = −(p − φ)³ before p, 0 on [p, q], (φ − q)³ after q: C² at p and q, so
    the curvature runs continuously into the straight stretch (as a cam's
    motion law into a dwell).
    """
    c = length / (2.0 * math.pi)

    def curve(phi):
        phi = np.asarray(phi, dtype=float)
        u = np.where(phi < p, phi - p, np.where(phi > q, phi - q, 0.0))  # (φ − p) before, (φ − q) after
        y = slope * c * phi + amp * u**3
        p_ = np.column_stack((c * phi, y))
        d1 = np.column_stack((np.full_like(phi, c), slope * c + 3.0 * amp * u**2))
        d2 = np.column_stack((np.zeros_like(phi), 6.0 * amp * u))
        return p_, d1, d2

    return curve


@settings(max_examples=8, deadline=None)
@given(
    length=st.floats(80.0, 400.0),
    amp=st.floats(0.05, 1.5),
    slope=st.floats(-0.5, 0.5),
    p=st.one_of(st.just(0.0), st.floats(0.5, 3.0)),
    width=st.floats(0.3, 2.5),
    tol=st.sampled_from([0.002, 0.01]),
)
def test_an_open_curve_s_straight_stretch_is_one_line_on_it_between_tangent_arcs(
    length, amp, slope, p, width, tol
):
    q = min(p + width, 2.0 * math.pi)
    curve = flat_between(length, amp, slope, p, q)
    breaks = np.array(sorted({0.0, p, q, 2.0 * math.pi}))
    straight = tuple(bool(a == p and b == q) for a, b in itertools.pairwise(breaks))
    pieces, dev = fit_arc_spline(curve, breaks, tol, closed=False, straight=straight)
    assert dev.max() <= tol
    # the stretch: exactly one line over all of it, on the exact line y = slope·x, ending at the stretch's
    # end; it starts at the stretch's start, or before it where the arc before lands on the line
    c = length / (2.0 * math.pi)
    flat = np.flatnonzero((pieces.hi > p) & (pieces.lo < q))
    assert flat.size == 1
    (i,) = flat
    assert pieces.line[i, 0] and np.array_equal(pieces.start[i, 1], pieces.end[i, 1])  # one line, no second
    assert pieces.lo[i] <= p and pieces.hi[i] == q
    start, end = pieces.start[i, 0], pieces.end[i, 0]
    assert_allclose(end, (c * q, slope * c * q), atol=1e-9)
    assert start[0] <= c * p + 1e-9
    assert abs(start[1] - slope * start[0]) <= 1e-9 * max(1.0, abs(start[0]))
    # G1 through the line's ends (on the line's own direction) and everywhere else, and two-way within
    # tol by brute force
    starts, stops = pieces.tangents()
    u = np.array([1.0, slope]) / math.hypot(1.0, slope)
    if i > 0:
        assert_allclose(
            stops[i - 1, 0 if pieces.line[i - 1, 1] and not pieces.length()[i - 1, 1] else 1], u, atol=1e-9
        )
    if i + 1 < len(pieces):
        assert_allclose(starts[i + 1, 0], u, atol=1e-9)
    flat_start, flat_end = pieces.start.reshape(-1, 2), pieces.end.reshape(-1, 2)
    live = np.linalg.norm(flat_end - flat_start, axis=1) > 0.0
    t0, t1 = starts.reshape(-1, 2)[live], stops.reshape(-1, 2)[live]
    assert_allclose(flat_end[live][:-1], flat_start[live][1:], atol=1e-9)
    # elsewhere: an arc bulging less than 1e-9 mm is stored as its chord (biarc.arc_from_tangent), whose
    # direction is off the arc's end tangents by up to 8·sagitta/chord: up to 3e-4 rad on a chord of a
    # few µm, which hypothesis finds now and then with or without straight stretches
    short_line = pieces.line.reshape(-1)[live] & (pieces.length().reshape(-1)[live] < 0.1)
    smooth = ~(short_line[:-1] | short_line[1:])
    assert_allclose(t1[:-1][smooth], t0[1:][smooth], atol=1e-7)
    assert_two_way_within(curve, pieces, tol)


def test_a_stretch_said_straight_that_is_not_is_refused():
    curve = graph(200.0, 10.0, 1, 0.0)
    with pytest.raises(ValueError, match="not straight"):
        fit_arc_spline(curve, np.array([0.0, 1.0, 2.0 * math.pi]), 0.005, straight=(True, False))


@cache
def bar_case() -> tuple[Cam, Bar, object]:
    design = load_design(ROOT / "samples" / "linear_cam.toml")
    (part,) = family_of(design.cam.style).parts(Cam.from_design(design), design.family_options())
    assert part.bar is not None
    return part.cam, part.bar, design


@pytest.mark.parametrize("direction", ["climb", "conventional"])
def test_the_bar_s_written_finishing_pass_is_within_the_band_and_its_certificate(direction):
    cam, bar, design = bar_case()
    spec = replace(design.gcode, direction=Direction(direction))
    tp = plan_bar(cam, bar, spec, name="bar", thickness=design.cam.thickness)
    finish = passes(list(tp.moves))[-1]
    assert finish[0].end[2] == tp.final_depth
    cut = finish[1:-1]  # the leads: straight, on along the end tangents
    assert len(cut) == tp.contour_blocks
    assert not finish[0].kind.is_arc and not finish[-1].kind.is_arc
    assert sum(m.kind.is_arc for m in cut) >= 0.8 * len(cut)
    r = spec.tool_radius
    exact = np.asarray(cam.offset_curve(np.linspace(0.0, 2.0 * math.pi, 40_001), r).point)
    written = np.vstack([densify(m, 0.005)[:, :2] for m in cut])
    brute = max(dense_distance(written, exact).max(), dense_distance(exact[::4], written).max())
    assert brute <= tp.max_deviation + 1e-6 <= spec.tolerance + 1e-6
    # climb: the part (below the edge) on the tool's right, so the tool travels towards +x
    assert (cut[-1].end[0] > cut[0].start[0]) == (direction == "climb")


def test_g1_chords_of_the_bar_need_several_times_the_blocks_of_its_arcs():
    cam, bar, design = bar_case()
    arcs = plan_bar(cam, bar, design.gcode, name="bar", thickness=design.cam.thickness)
    chords = plan_bar(cam, bar, design.gcode, name="bar", thickness=design.cam.thickness, arcs=False)
    assert chords.max_deviation <= design.gcode.tolerance
    assert all(not m.kind.is_arc for m in chords.moves)
    assert chords.contour_blocks >= 3 * arcs.contour_blocks


def test_the_fewest_arcs_refit_leaves_an_open_edge_as_searched_and_says_so():
    cam, bar, design = bar_case()
    plain = plan_bar(cam, bar, design.gcode, name="bar", thickness=design.cam.thickness)
    asked = plan_bar(
        cam, bar, replace(design.gcode, fewest_arcs=True), name="bar", thickness=design.cam.thickness
    )
    assert asked.moves == plain.moves
    assert any("fewest-arcs" in note for note in asked.notes)
    assert not any("fewest-arcs" in note for note in plain.notes)


def test_each_dwell_of_the_bar_is_one_g1_on_its_exact_line_between_tangent_arcs():
    cam, bar, design = bar_case()
    tp = plan_bar(cam, bar, design.gcode, name="bar", thickness=design.cam.thickness)
    cut = passes(list(tp.moves))[-1][1:-1]
    r = design.gcode.tool_radius
    # the sample: rise 20 mm over 120°, dwell 60°, return over 120°, dwell 60°; 360° = 240 mm of bar
    length, base = design.linear.stroke_length, design.cam.base_radius
    dwells = [((120.0, 180.0), base + 20.0 + r), ((300.0, 360.0), base + r)]
    for (a, b), y in dwells:
        xa, xb = bar.x0 + length * a / 360.0, bar.x0 + length * b / 360.0
        on = [
            k
            for k, m in enumerate(cut)
            if min(m.start[0], m.end[0]) < xb - 1e-3 and max(m.start[0], m.end[0]) > xa + 1e-3
        ]
        assert len(on) == 1  # the whole dwell is one move
        m = cut[on[0]]
        assert not m.kind.is_arc
        lo, hi = sorted((m.start[0], m.end[0]))
        # it ends where the dwell ends and starts there or before, where the arc before landed on the line
        assert hi == pytest.approx(xb, abs=1e-9) and lo <= xa + 1e-9
        assert m.start[1] == m.end[1] == pytest.approx(y, abs=1e-9)
        # its neighbours are arcs tangent to it: their centres straight above or below its ends
        for k, joint in ((on[0] - 1, m.start), (on[0] + 1, m.end)):
            if 0 <= k < len(cut):
                arc = cut[k]
                assert arc.kind.is_arc and arc.center is not None
                assert arc.center[0] == pytest.approx(joint[0], abs=1.5e-4)  # I/J rounded to 1e-4
