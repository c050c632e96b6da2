"""Groove milling (issue 15): slot with a ramp, then both flanks finished, proved on the exact flanks.

The truth is the exact geometry, not the fit: the flanks are dense polylines
of ``cam.offset_curve(φ, d)`` at the flank offsets (the pitch curve ∓ (r_f + c/2),
:func:`camcad.geometry.groove.flank_offsets`), and the program's motion is
rebuilt here from the written G-code (read back by :func:`parse_gcode`;
``tests/readers/test_rs274_groove.py`` rebuilds it from LinuxCNC's canonical
output instead) by densifying its lines and (helical) arcs with this
module's own code. On it:

- the tool's edge reaches each flank within ``gcode.tolerance`` all along
  the finishing passes (tool centre r_t ± tol from that flank) and every
  point of each flank is reached (nearest tool centre within r_t + tol);
- nowhere below the face does the tool come closer than r_t − tol to either
  flank, nor leave the groove (tool centre within width/2 − r_t + tol of the
  pitch curve);
- the swept tool clears the whole groove: every point across it (exact
  offsets from flank to flank) lies within r_t of a tool centre at full
  depth, however many clearing passes a narrow tool needs (issue 31);
- the slot reaches −depth and never goes deeper; no rapid below the safe
  height; a plunge below Z0 only at the centre line's start point once the
  slot is cut to full depth (the clearing passes step down there); the ramp
  descends at most ``step_down`` per lap of the centre line (slope bound,
  and the depths at which it passes its start point);
- climb milling on both flanks: with the spindle M3, the flank (the
  material) lies on the tool's right (the G41 rule), whatever the code calls
  clockwise.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from camcad.design import Design, load_design
from camcad.design.paths import path_of
from camcad.errors import DesignError
from camcad.export.gcode import parse_gcode, render_gcode
from camcad.geometry.cam import Cam
from camcad.geometry.groove import analyse_groove, flank_offsets
from camcad.toolpath import Move, MoveKind, Toolpath
from camcad.toolpath.groove import check_groove_tool, plan_groove, slot_levels
from tests.conftest import ROOT
from tests.named import raises_named

SAMPLE = ROOT / "samples" / "groove_rocker.toml"
_DENSE = 10_000  # samples of each exact curve: spacing < 0.07 mm, chord sagitta < 2e-5 mm at ρ ≥ 50 mm
_STEP = 0.02  # mm between points of the rebuilt tool path


def plan(design: Design) -> tuple[Cam, Toolpath]:
    cam = Cam.from_design(design)
    tp = plan_groove(
        cam, design.gcode, name=design.cam.name, thickness=design.cam.thickness,
        depth=design.groove.depth, clearance=design.groove.clearance, bore=design.cam.bore,
    )  # fmt: skip
    return cam, tp


@cache
def sample() -> tuple[Design, Cam, Toolpath]:
    design = load_design(SAMPLE)
    return (design, *plan(design))


def exact(cam: Cam, distance: float) -> np.ndarray:
    """(n, 2) dense points of the exact curve ``cam.offset_curve(φ, distance)``, closed."""
    phi = np.linspace(0.0, 2.0 * math.pi, _DENSE + 1)
    return np.asarray(cam.offset_curve(phi, distance).point)


def points(move: Move) -> np.ndarray:
    """(k, 3) points along a line or a (helical) arc, at most _STEP apart, start and end included."""
    a, b = np.asarray(move.start), np.asarray(move.end)
    if not move.kind.is_arc:
        n = max(1, math.ceil(float(np.linalg.norm(b - a)) / _STEP))
        return a + (b - a) * np.linspace(0.0, 1.0, n + 1)[:, None]
    c = np.asarray(move.center)
    a0 = math.atan2(a[1] - c[1], a[0] - c[0])
    sweep = (math.atan2(b[1] - c[1], b[0] - c[0]) - a0) % (2.0 * math.pi)
    if move.kind is MoveKind.CW:
        sweep -= 2.0 * math.pi
    if math.dist(a[:2], b[:2]) < 1e-9:
        sweep = 2.0 * math.pi if move.kind is MoveKind.CCW else -2.0 * math.pi
    r0, r1 = math.dist(a[:2], c), math.dist(b[:2], c)
    n = max(1, math.ceil(abs(sweep) * max(r0, r1) / _STEP))
    u = np.linspace(0.0, 1.0, n + 1)
    ang, rad = a0 + sweep * u, r0 + (r1 - r0) * u
    return np.column_stack((c[0] + rad * np.cos(ang), c[1] + rad * np.sin(ang), a[2] + (b[2] - a[2]) * u))


@dataclass(frozen=True)
class Proof:
    """What :func:`prove` measured on a program's motion [mm]."""

    closed: tuple[bool, bool]  # the inner and outer flank pass each run once round, back to their start
    inner_band: tuple[float, float]  # tool centre to inner flank along the inner pass: min, max
    outer_band: tuple[float, float]
    inner_reach: float  # largest distance from an inner-flank point to the nearest tool centre at depth
    outer_reach: float
    closest: float  # smallest distance from any tool centre below Z0 to either flank
    off_centre: float  # largest distance from a tool centre below Z0 to the pitch curve
    deepest: float  # lowest Z
    lap_depths: tuple[float, ...]  # Z each time the ramp passes its start point
    ramp_slope: float  # largest descent per mm of travel on the ramp
    lap_length: float  # length of the exact pitch curve
    inner_right: bool  # the inner flank lies on the tool's right all along its pass
    outer_right: bool
    rapid_low: float  # lowest Z of a rapid's XY travel or end
    plunge_ends: tuple[float, ...]  # Z where each pure Z descent at feed ends, but in the cut slot
    groove_reach: float  # largest distance from a point across the groove to the nearest tool centre at depth


def _planar(pts: np.ndarray) -> float:
    """Length [mm] of a polyline's projection on the XY plane."""
    return float(np.linalg.norm(np.diff(pts[:, :2], axis=0), axis=1).sum())


class Curve:
    """A closed exact curve as a dense polyline, with distances measured to its segments."""

    def __init__(self, pts: np.ndarray) -> None:
        self.data = pts[:-1]  # the last point repeats the first
        # leaves of 128 vertices: the same nearest vertices as the default 16, found faster for 10⁶ queries
        self.tree = cKDTree(self.data, leafsize=128)
        # every point of the polyline lies within half its longest segment of a vertex
        self.slack = 0.5 * float(np.linalg.norm(np.diff(pts, axis=0), axis=1).max())

    def query(self, q: np.ndarray, *, near: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Distance [mm] from points q (n, 2) to the polyline, and the nearest vertex's index.

        ``near`` [mm] only speeds the search: the vertices within it are searched first (a bounded
        search is fast), the unbounded search only for the points left; the answers are the same.
        """
        if near is None:
            _, j = self.tree.query(q)
        else:
            d, j = self.tree.query(q, distance_upper_bound=near)
            far = ~np.isfinite(d)
            if far.any():
                j[far] = self.tree.query(q[far])[1]
        return self._to_segments(q, j), j

    def lower_bounds(self, q: np.ndarray, beyond: float) -> np.ndarray:
        """Distances [mm] from points q (n, 2) to the polyline, exact where a vertex lies within ``beyond``.

        Elsewhere the lower bound ``beyond`` − :attr:`slack`: such a point's nearest polyline point is
        within :attr:`slack` of a vertex, more than ``beyond`` away. So the minimum is exact whenever it
        is below ``beyond`` − slack, and the slow far searches are skipped.
        """
        d, j = self.tree.query(q, distance_upper_bound=beyond)
        near = np.isfinite(d)
        out = np.full(len(q), beyond - self.slack)
        out[near] = self._to_segments(q[near], j[near])
        return out

    def _to_segments(self, q: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Distance [mm] from points q (n, 2) to the two segments at their nearest vertices j."""
        n = len(self.data)
        best = np.full(len(q), np.inf)
        for a_at, b_at in ((j - 1, j), (j, j + 1)):
            a, b = self.data[a_at % n], self.data[b_at % n]
            w = b - a
            t = np.clip(np.einsum("ij,ij->i", q - a, w) / np.einsum("ij,ij->i", w, w), 0.0, 1.0)
            best = np.minimum(best, np.linalg.norm(q - (a + w * t[:, None]), axis=1))
        return best


def _nearest(curve: Curve, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return curve.query(pts)


def _flank_pass(moves: list[Move], flank: Curve, r: float, tol: float, bottom: float) -> list[Move]:
    """The longest run of consecutive full-depth feed moves whose end points lie r ± 2 tol from ``flank``."""
    best: list[Move] = []
    run: list[Move] = []
    for m in moves:
        ends = np.asarray([m.start[:2], m.end[:2]])
        on = (
            m.kind is not MoveKind.RAPID
            and abs(m.end[2] - bottom) < 1e-6
            and abs(m.start[2] - bottom) < 1e-6
            and bool(np.all(np.abs(_nearest(flank, ends)[0] - r) <= 2.0 * tol))
        )
        run = [*run, m] if on else []
        if len(run) > len(best):
            best = run
    return best


def prove(moves: list[Move], cam: Cam, design: Design) -> Proof:
    """Measure a groove program's motion against the exact flanks and pitch curve."""
    spec = design.gcode
    r, tol = spec.tool_radius, spec.tolerance
    inner_d, outer_d = flank_offsets(cam, design.groove.clearance)
    inner, outer, pitch = (Curve(exact(cam, d)) for d in (inner_d, outer_d, cam.roller_radius))
    feeds = [m for m in moves if m.kind is not MoveKind.RAPID]
    pts = np.vstack([points(m) for m in feeds])
    cutting = pts[pts[:, 2] < -1e-9]
    bottom = float(pts[:, 2].min())
    at_depth = pts[np.abs(pts[:, 2] - bottom) < 1e-6][:, :2]
    bands = []
    rights = []
    closed = []
    for flank in (inner, outer):
        run = _flank_pass(feeds, flank, r, tol, bottom)
        closed.append(bool(run) and math.dist(run[0].start[:2], run[-1].end[:2]) < 1e-6)
        along = np.vstack([points(m) for m in run])
        gap, at = _nearest(flank, along[:, :2])
        bands.append((float(gap.min()), float(gap.max())))
        travel = np.diff(along[:, :2], axis=0)
        to_flank = flank.data[at[1:]] - along[1:, :2]
        keep = np.linalg.norm(travel, axis=1) > 1e-9
        cross = travel[keep, 0] * to_flank[keep, 1] - travel[keep, 1] * to_flank[keep, 0]
        rights.append(bool(np.all(cross < 0.0)))  # the flank on the right of the travel
    depth_tree = cKDTree(at_depth)  # built once: the reaches below and the groove reach read it
    reach = [float(depth_tree.query(flank.data)[0].max()) for flank in (inner, outer)]
    # the claim is closest ≥ r − tol: exact below r + 1 − slack, a lower bound above (far points)
    closest = min(float(flank.lower_bounds(cutting[:, :2], r + 1.0).min()) for flank in (inner, outer))
    near = cam.roller_radius + design.groove.clearance  # a search hint only: the groove's half-width and more
    off_centre = float(pitch.query(cutting[:, :2], near=near)[0].max())
    lap = _planar(exact(cam, cam.roller_radius))
    start = np.asarray(cam.offset_curve(np.array([spec.start_angle]), cam.roller_radius).point[0])
    ramp = [m for m in feeds if m.end[2] < m.start[2] - 1e-9 and math.dist(m.start[:2], m.end[:2]) > 1e-9]
    slope = max((m.start[2] - m.end[2]) / _planar(points(m)) for m in ramp)
    passes = tuple(m.end[2] for m in feeds if math.dist(m.end[:2], start) < 1e-3 and m.end[2] <= 0.0)
    laps = tuple(sorted(set(passes), reverse=True))
    rapids = [m for m in moves if m.kind is MoveKind.RAPID]
    low = min(
        min(m.end[2], m.start[2] if math.dist(m.start[:2], m.end[:2]) > 1e-9 else m.end[2]) for m in rapids
    )
    first_bottom = next(k for k, m in enumerate(feeds) if abs(m.end[2] - bottom) < 1e-6)
    plunges = tuple(
        m.end[2]
        for k, m in enumerate(feeds)
        if m.end[2] < m.start[2]
        and math.dist(m.start[:2], m.end[:2]) <= 1e-9
        and not (k > first_bottom and math.dist(m.end[:2], start) < 1e-3)
    )
    across = np.vstack([exact(cam, d)[::4] for d in np.linspace(inner_d, outer_d, 41)])
    groove_reach = float(depth_tree.query(across)[0].max())
    return Proof(
        closed=(closed[0], closed[1]),
        inner_band=bands[0],
        outer_band=bands[1],
        inner_reach=reach[0],
        outer_reach=reach[1],
        closest=closest,
        off_centre=off_centre,
        deepest=bottom,
        lap_depths=laps,
        ramp_slope=slope,
        lap_length=lap,
        inner_right=rights[0],
        outer_right=rights[1],
        rapid_low=low,
        plunge_ends=plunges,
        groove_reach=groove_reach,
    )


def assert_proved(p: Proof, cam: Cam, design: Design) -> None:
    """The groove program's motion meets every claim of the module docstring."""
    spec = design.gcode
    r, tol, depth = spec.tool_radius, spec.tolerance, design.groove.depth
    half = cam.roller_radius + 0.5 * design.groove.clearance
    assert p.closed == (True, True)
    for lo, hi in (p.inner_band, p.outer_band):
        assert r - tol <= lo and hi <= r + tol, (lo, hi)
    assert p.inner_reach <= r + tol and p.outer_reach <= r + tol
    assert p.groove_reach <= r + tol  # no ridge left anywhere across the groove
    assert p.closest >= r - tol
    assert p.off_centre <= half - r + tol
    assert p.deepest == pytest.approx(-depth, abs=1e-9)
    assert p.inner_right and p.outer_right  # climb on both flanks
    assert p.rapid_low >= spec.safe_height - 1e-9
    assert all(z >= -1e-9 for z in p.plunge_ends)  # a plunge into material stops on the face, Z0
    assert p.ramp_slope <= spec.step_down / p.lap_length * 1.001
    assert p.lap_depths[0] == 0.0 and p.lap_depths[-1] == pytest.approx(-depth)
    assert all(0.0 < a - b <= spec.step_down + 1e-9 for a, b in itertools.pairwise(p.lap_depths))


def test_sample_groove_program_is_proved_on_the_exact_flanks():
    design, cam, tp = sample()
    moves = parse_gcode(render_gcode(tp))
    assert_proved(prove(moves, cam, design), cam, design)
    assert tp.max_deviation <= design.gcode.tolerance
    assert tp.levels == (-3.0, -6.0, -9.0, -12.0)  # 12 mm deep at step_down 3: four laps of 3 mm


def test_fewest_arcs_groove_program_is_proved_on_the_exact_flanks_with_fewer_arcs():
    """[gcode] fewest_arcs refits the centre line: fewer arcs, and the same proof on the flanks."""
    design, _, _ = sample()
    design = replace(design, gcode=replace(design.gcode, start_angle=0.6))  # rad: one arc fewer from here
    _, plain = plan(design)
    design = replace(design, gcode=replace(design.gcode, fewest_arcs=True))
    cam, tp = plan(design)
    assert tp.contour_arcs < plain.contour_arcs
    assert_proved(prove(parse_gcode(render_gcode(tp)), cam, design), cam, design)
    assert tp.max_deviation <= design.gcode.tolerance


def test_conventional_puts_both_flanks_on_the_left():
    """The direction is not hard-wired: conventional milling reverses both finishing passes."""
    design = load_design(SAMPLE)
    design = replace(
        design, gcode=replace(design.gcode, direction=type(design.gcode.direction)("conventional"))
    )
    cam, tp = plan(design)
    p = prove(parse_gcode(render_gcode(tp)), cam, design)
    assert not p.inner_right and not p.outer_right
    assert p.closest >= design.gcode.tool_radius - design.gcode.tolerance


def test_the_proof_catches_a_gouge():
    """The proof is not vacuous: the outer pass's entry moved 0.05 mm outward breaks the no-cut bound."""
    design, cam, tp = sample()
    text = render_gcode(tp)
    lines = text.splitlines()
    k = lines.index(next(line for line in lines if line.startswith("(outer flank finishing pass")))
    entry = lines[k + 1]  # the entry move's end, on the normal at φ = 0
    assert entry == "G1 Y68.0150"
    lines[k + 1] = "G1 Y68.0650"
    p = prove(parse_gcode("\n".join(lines) + "\n"), cam, design)
    assert p.closest < design.gcode.tool_radius - design.gcode.tolerance


def test_header_says_what_each_pass_is():
    _, _, tp = sample()
    text = render_gcode(tp)
    for what in ("slot: enter at the start angle", "inner flank finish", "outer flank finish", "normal"):
        assert what in text


@pytest.mark.parametrize(
    ("diameter", "allowed"),
    [(24.03, "below 24.0300"), (30.0, "below 24.0300"), (0.1, "above 0.1196")],
)
def test_a_tool_that_does_not_fit_is_refused_naming_the_field(diameter, allowed):
    """Against the groove's width 2 r_f + c = 24.03 mm: a tool as wide or wider, or one so small that a
    side would need over 200 clearing passes (2 x 12.015 / 201 = 0.1196 mm)."""
    design = load_design(SAMPLE)
    design = replace(design, gcode=replace(design.gcode, tool_diameter=diameter))
    with pytest.raises(DesignError) as err:
        plan(design)
    assert path_of(err.value.path) == "gcode.tool_diameter"
    assert allowed in err.value.message


def test_a_tool_above_the_concave_radius_is_refused():
    """A flank's concave radius (seen from the groove) is ρ_pitch + r_f + c/2 > width/2, so the width
    check always binds first on a real groove; the concave check is fed a smaller limit directly."""
    design, cam, _ = sample()
    g = analyse_groove(cam, clearance=design.groove.clearance)
    assert g.tool_radius_max == pytest.approx(g.width / 2.0)
    with raises_named(DesignError, match=r"gcode\.tool_diameter: .*at most 10\.000 mm"):
        check_groove_tool(replace(g, tool_radius_max=5.0), 6.0)


def test_depth_and_machine_are_checked():
    design = load_design(SAMPLE)
    with raises_named(DesignError, match=r"^groove\.depth"):
        plan(replace(design, groove=replace(design.groove, depth=design.cam.thickness)))
    rotary = replace(design, gcode=replace(design.gcode, machine=type(design.gcode.machine)("rotary")))
    with raises_named(DesignError, match=r"^gcode\.machine"):
        plan(rotary)


@settings(max_examples=200, deadline=None)
@given(depth=st.floats(0.1, 60.0), step=st.floats(0.2, 10.0))
def test_slot_levels_step_at_most_step_down_and_stop_at_depth(depth, step):
    """For all depths and step-downs: laps descend by at most step_down, end at −depth, never deeper."""
    levels = slot_levels(depth, step)
    assert -depth - 1e-12 <= levels[-1] <= -depth + 1e-4
    tops = (0.0, *levels)
    assert all(0.0 < a - b <= step + 1e-4 for a, b in itertools.pairwise(tops))
    assert (len(levels) - 1) * step < depth  # no more laps than needed


def test_pipeline_plans_a_groove_cam_with_the_groove_passes():
    """``analyse`` routes a groove cam to :func:`plan_groove`, not to the plate's outside profile."""
    from camcad.pipeline import analyse

    analysis = analyse(load_design(SAMPLE), strict=False, fit=False, toolpath=True)
    assert analysis.gcode is not None
    assert "inner flank finishing pass" in analysis.gcode.text
    assert "profile finishing pass" not in analysis.gcode.text


def without_gcode_table(text: str) -> str:
    """A design's TOML text with its ``[gcode]`` table (to the next table or the end) left out."""
    out, skip = [], False
    for line in text.splitlines():
        if line.startswith("["):
            skip = line.strip() == "[gcode]"
        if not skip:
            out.append(line)
    return "\n".join(out) + "\n"


def no_gcode_design(tmp_path) -> Path:
    path = tmp_path / "groove_no_gcode.toml"
    path.write_text(without_gcode_table(SAMPLE.read_text(encoding="utf-8")), encoding="utf-8")
    return path


@pytest.mark.parametrize("diameter", [6.0])
def test_a_narrow_tool_clears_the_groove_in_stepover_passes(diameter):
    """Issue 31: a tool a quarter or a third of the groove's width is not refused; the clearing passes
    leave no ridge (the swept tool reaches every point across the groove) and their count is the
    closed form 2 (⌈(w/2 − r_t)/r_t⌉ − 1) per slot level, w = 2 r_f + c."""
    design = load_design(SAMPLE)
    design = replace(design, gcode=replace(design.gcode, tool_diameter=diameter))
    cam, tp = plan(design)
    assert_proved(prove(parse_gcode(render_gcode(tp)), cam, design), cam, design)
    half, r = 12.0 + 0.015, diameter / 2.0
    assert tp.clearing_laps == 2 * (math.ceil((half - r) / r) - 1) * len(tp.levels) > 0
    assert tp.max_deviation <= design.gcode.tolerance


def test_without_a_gcode_table_a_groove_gets_a_standard_cutter_that_fits(tmp_path):
    """No [gcode]: the default D6 no longer matters; the largest standard end mill ≤ 0.8 × 24.03 mm
    (the groove's width 2 r_f + c) is D16, said in the header, and the program is proved."""
    design = load_design(no_gcode_design(tmp_path))
    assert design.gcode.choose_tool
    cam, tp = plan(design)
    assert tp.spec.tool_diameter == 16.0
    text = render_gcode(tp)
    assert "D16.000 (radius 8.000), chosen by camcad to fit the groove" in text.replace("[", "(").replace(
        "]", ")"
    )
    used = replace(design, gcode=tp.spec)
    assert_proved(prove(parse_gcode(text), cam, used), cam, used)


def test_check_and_build_work_without_a_gcode_table(tmp_path, capsys):
    """``camcad check`` plans no toolpath and passes; ``camcad build`` writes cam.ngc with the chosen
    cutter, and summary.json and the report say it was chosen."""
    import json

    from camcad.cli import main

    path = no_gcode_design(tmp_path)
    assert main(["check", str(path)]) == 0
    assert "all design limits hold" in capsys.readouterr().out
    out = tmp_path / "out"
    assert main(["build", str(path), "-o", str(out), "-q", "--only", "gcode,report"]) == 0
    gcode = json.loads((out / "summary.json").read_text())["gcode"]
    assert gcode["tool_diameter_mm"] == 16.0 and gcode["tool_chosen"] is True
    assert "chosen by camcad to fit the groove" in (out / "report.html").read_text(encoding="utf-8")
    assert "chosen by camcad" in (out / "cam.ngc").read_text(encoding="ascii")
