"""LinuxCNC's rs274 runs a linear cam's program; its finishing pass is the exact tool-centre curve, in arcs.

The canonical moves rs274 executes (STRAIGHT_FEED and ARC_FEED) are rebuilt
into the passes (each run of feed moves at one depth), sampled along the
lines and arcs the controller interpolates, and measured against the exact
offset of the bar's edge, ``cam.offset_curve(φ, r)``, both ways: every exact
point's distance to the nearest move (closed form for a line and an arc),
and every move point's distance to the exact curve (a polygon of 40 001
exact points, whose own sagitta is below 1e-6 mm). The finishing pass keeps
the plate's band (``gcode.tolerance``) after the program's 4-decimal
rounding, and the planner's certificate (``Toolpath.max_deviation``) bounds
what the brute force finds. The direction is the plate's rule (M3, climb
has the part on the tool's right: the closed loop of the pass and the bar's
bottom runs clockwise). Each dwell of the motion is a straight stretch of the
offset: rs274 runs it as one STRAIGHT_FEED on the exact line (the offset at
the dwell's ends, and the line y = base radius + lift + tool radius from the
sample's numbers) over the whole dwell, between ARC_FEEDs tangent to it.
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import cache

import numpy as np
import pytest
from scipy.spatial import cKDTree

from camcad.design import Design, load_design
from camcad.export.gcode import parse_canon, parse_gcode, render_gcode
from camcad.geometry.cam import Cam
from camcad.geometry.families import Bar, family_of
from camcad.toolpath import Toolpath
from camcad.toolpath.moves import Move, MoveKind
from camcad.toolpath.parts import plan_part
from camcad.toolpath.spec import Direction
from camcad.toolpath.verify import densify
from tests.conftest import ROOT
from tests.readers.test_rs274 import RS274, errors, run_rs274

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        RS274 is None, reason="LinuxCNC's rs274 is not installed (Debian package linuxcnc-uspace)"
    ),
]

SAMPLE = ROOT / "samples" / "linear_cam.toml"
_EXACT = 400_001  # exact points measured against the moves
_POLYGON = 40_001  # exact points of the polygon the moves' points are measured against
_STEP = 0.005  # mm between samples along the moves


@cache
def planned(direction: str, tolerance: float) -> tuple[Design, Cam, Bar, Toolpath]:
    design = load_design(SAMPLE)
    spec = replace(design.gcode, direction=Direction(direction), tolerance=tolerance)
    (part,) = family_of(design.cam.style).parts(Cam.from_design(design), design.family_options())
    assert part.bar is not None
    tp = plan_part(part, spec, name=design.cam.name, thickness=design.cam.thickness)
    assert isinstance(tp, Toolpath)
    return replace(design, gcode=spec), part.cam, part.bar, tp


def passes(moves: list[Move]) -> list[list[Move]]:
    """Runs of planar feed moves (lines and arcs at one depth), in program order."""
    runs, run = [], []
    for m in moves:
        if m.kind is not MoveKind.RAPID and m.start[2] == m.end[2]:
            run.append(m)
        elif run:
            runs.append(run)
            run = []
    return runs + ([run] if run else [])


def _to_move(points: np.ndarray, m: Move) -> np.ndarray:
    """Exact distance from each point (n, 2) to one move: a segment, or an arc (radius blended if unequal)."""
    a, b = np.asarray(m.start[:2]), np.asarray(m.end[:2])
    if not m.kind.is_arc:
        ab = b - a
        t = np.clip((points - a) @ ab / float(ab @ ab), 0.0, 1.0)
        out: np.ndarray = np.hypot(*(points - a - t[:, None] * ab).T)
        return out
    assert m.center is not None
    c = np.asarray(m.center)
    r0, r1 = m.radii
    rel = points - c
    start = math.atan2(a[1] - c[1], a[0] - c[0])
    at = (np.arctan2(rel[:, 1], rel[:, 0]) - start) * np.sign(m.sweep) % (2 * math.pi)
    radius = r0 + (r1 - r0) * np.clip(at / abs(m.sweep), 0.0, 1.0)  # a controller spirals between them
    ends = np.minimum(np.hypot(*(points - a).T), np.hypot(*(points - b).T))
    return np.where(at <= abs(m.sweep), np.abs(np.hypot(*rel.T) - radius), ends)


def distance_to_moves(points: np.ndarray, moves: list[Move]) -> np.ndarray:
    """Exact distance from each point (n, 2) to the nearest move (closed form for a segment and an arc).

    Each point is measured against the move holding its nearest move sample and
    that move's two neighbours (the moves join head to tail).
    """
    dense = [densify(m, 0.05)[:, :2] for m in moves]
    owner = np.repeat(np.arange(len(moves)), [len(d) for d in dense])
    _, k = cKDTree(np.vstack(dense)).query(points)
    best = np.full(len(points), np.inf)
    for shift in (-1, 0, 1):
        which = np.clip(owner[k] + shift, 0, len(moves) - 1)
        for i in np.unique(which):
            sel = which == i
            best[sel] = np.minimum(best[sel], _to_move(points[sel], moves[i]))
    return best


def distance_to_curve(points: np.ndarray, curve: np.ndarray) -> np.ndarray:
    """Distance from each point (n, 2) to a dense polyline (m, 2): the two segments at the nearest vertex."""
    _, k = cKDTree(curve).query(points)
    best = np.full(len(points), np.inf)
    for lo in (np.maximum(k - 1, 0), np.minimum(k, len(curve) - 2)):
        a, ab = curve[lo], curve[lo + 1] - curve[lo]
        t = np.clip(
            np.einsum("ij,ij->i", points - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300),
            0.0,
            1.0,
        )
        best = np.minimum(best, np.hypot(*(points - a - t[:, None] * ab).T))
    return best


def sampled(moves: list[Move]) -> np.ndarray:
    """Points along the moves, at most ``_STEP`` apart (arcs as the controller interpolates them)."""
    return np.vstack([densify(m, _STEP)[:, :2] for m in moves])


@pytest.mark.parametrize("tolerance", [0.005, 0.001])
@pytest.mark.parametrize("direction", ["climb", "conventional"])
def test_rs274_runs_the_bar_program_and_its_arcs_are_the_exact_offset(direction, tolerance, tmp_path):
    design, cam, bar, tp = planned(direction, tolerance)
    text = render_gcode(tp)
    proc, canon = run_rs274(text, design.gcode.tool_number, tmp_path)
    assert proc.returncode == 0, errors(proc)
    assert not errors(proc)
    moves = parse_canon(canon)
    ours = parse_gcode(text)
    assert [m.kind for m in moves] == [m.kind for m in ours]  # rs274 runs exactly the blocks written
    depth = min(m.end[2] for m in moves)
    assert depth == pytest.approx(-(design.cam.thickness + design.gcode.breakthrough), abs=1e-4)
    runs = passes(moves)
    finish = runs[-1]
    assert finish[0].end[2] == pytest.approx(depth)
    # the finishing pass is arcs (G2/G3), as a plate's: the planned blocks between two straight leads
    cut = finish[1:-1]
    assert len(cut) == tp.contour_blocks
    assert sum(m.kind.is_arc for m in cut) >= 0.8 * len(cut)
    r, tol = design.gcode.tool_radius, design.gcode.tolerance
    exact = np.asarray(cam.offset_curve(np.linspace(0.0, 2 * np.pi, _EXACT), r).point)
    polygon = exact[:: (_EXACT - 1) // (_POLYGON - 1)]
    # exact -> path, path -> exact, both brute force on what rs274 executes
    forth = float(distance_to_moves(exact, finish).max())
    back = float(distance_to_curve(sampled(cut), polygon).max())
    assert max(forth, back) <= tol
    # the planner's certificate bounds them (1e-6 mm: the brute force's own polygon and sampling)
    assert max(forth, back) <= tp.max_deviation + 1e-6
    assert tp.max_deviation <= tol
    # the leads run straight on along the path's end tangents, beyond the bar's ends
    x0, x1 = bar.x0, bar.x0 + bar.length
    lead_in, lead_out = finish[0], finish[-1]
    assert not lead_in.kind.is_arc and not lead_out.kind.is_arc
    for lead in (lead_in, lead_out):
        assert min(lead.start[0], lead.end[0]) <= x0 - r or max(lead.start[0], lead.end[0]) >= x1 + r
    # direction: climb runs with the part on the tool's right (G41 with M3), so the pass and the
    # bar's bottom make a clockwise loop; conventional the other way round
    loop = np.vstack([sampled(finish), [[finish[-1].end[0], bar.bottom], [finish[0].start[0], bar.bottom]]])
    area = 0.5 * float(np.sum(loop[:, 0] * np.roll(loop[:, 1], -1) - np.roll(loop[:, 0], -1) * loop[:, 1]))
    assert (area < 0.0) == (direction == "climb")
    # every roughing pass within the band of its own offset (the finishing arcs offset by the stock)
    rough = np.asarray(cam.offset_curve(np.linspace(0.0, 2 * np.pi, _EXACT), tp.rough_offset).point)
    for run in {tuple((m.kind, m.end[:2], m.center) for m in run): run for run in runs[:-1]}.values():
        assert float(distance_to_moves(rough, run).max()) <= tol
        assert float(distance_to_curve(sampled(run[1:-1]), rough[::10]).max()) <= tol
    # the tool never enters the bar: every feed point at least the tool radius (less the band) off the edge
    edge = np.asarray(cam.profile(np.linspace(0.0, 2 * np.pi, _POLYGON)).point)
    everywhere = np.vstack([sampled(run) for run in runs])
    assert float(distance_to_curve(everywhere, edge).min()) >= r - tol


def test_the_brute_force_sees_arcs_written_as_chords():
    """Not vacuous: the finishing arcs that bulge most, written as G1 chords, fail the band."""
    design, cam, _, tp = planned("climb", 0.005)
    finish = passes(parse_gcode(render_gcode(tp)))[-1]
    tol = design.gcode.tolerance

    def sagitta(m: Move) -> float:
        r = m.radii[0]
        return r * (1.0 - math.cos(0.5 * m.sweep)) if m.kind.is_arc else 0.0

    bulging = [m for m in finish if sagitta(m) > 2.0 * tol]
    assert bulging  # the sample's finishing pass has arcs whose chords leave the band
    chords = [replace(m, kind=MoveKind.LINE, center=None) for m in bulging]
    exact = np.asarray(
        cam.offset_curve(np.linspace(0.0, 2 * np.pi, _POLYGON), design.gcode.tool_radius).point
    )
    assert float(distance_to_curve(sampled(chords), exact).max()) > tol
    assert float(distance_to_curve(sampled(bulging), exact).max()) <= tol


@pytest.mark.parametrize("direction", ["climb", "conventional"])
def test_rs274_runs_each_dwell_as_one_straight_feed_on_the_exact_line(direction, tmp_path):
    design, cam, _, tp = planned(direction, 0.005)
    proc, canon = run_rs274(render_gcode(tp), design.gcode.tool_number, tmp_path)
    assert proc.returncode == 0, errors(proc)
    cut = passes(parse_canon(canon))[-1][1:-1]
    r = design.gcode.tool_radius
    spans = cam.straight_spans
    assert len(spans) == 2  # the sample's two dwells
    for a, b in spans:
        ends = np.asarray(cam.offset_curve(np.array([a, b]), r).point)
        # the line from the sample's numbers: at base radius + the dwell's lift + tool radius
        lift = 20.0 if a < math.pi else 0.0
        assert ends[:, 1] == pytest.approx(design.cam.base_radius + lift + r, abs=1e-9)
        xa, xb = sorted(ends[:, 0])
        over = [
            k
            for k, m in enumerate(cut)
            if min(m.start[0], m.end[0]) < xb - 1e-3 and max(m.start[0], m.end[0]) > xa + 1e-3
        ]
        assert len(over) == 1
        m = cut[over[0]]
        assert m.kind is MoveKind.LINE
        got = np.array(sorted([m.start[:2], m.end[:2]]))
        # on the line (as written: 4 decimals), to the dwell's end, from its start or from where the arc
        # before it landed on the line
        assert np.abs(got[:, 1] - ends[0, 1]).max() <= 5e-5
        assert got[1, 0] == pytest.approx(xb, abs=5e-5) and got[0, 0] <= xa + 5e-5
        # tangent continuity with the arcs beside it: their radius at the joint is normal to the line
        for k, joint in ((over[0] - 1, m.start), (over[0] + 1, m.end)):
            if 0 <= k < len(cut):
                arc = cut[k]
                assert arc.kind.is_arc and arc.center is not None
                radial = np.asarray(arc.center[:2]) - np.asarray(joint[:2])
                assert abs(radial[0]) / np.linalg.norm(radial) < 1e-6
