"""The toolpath planner: passes, leads, tabs, bore, limits; every program is proved against the exact cam.

The proof (:func:`check_toolpath`) runs on the program as written and read
back by the G-code reader, and measures it against ``cam.offset_curve(φ, r)``.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from functools import cache

import numpy as np
import pytest

from camcad.design import Design, load_design
from camcad.errors import DesignError, DesignLimitError, GougeError
from camcad.export.gcode import parse_gcode, render_gcode
from camcad.geometry.cam import Cam
from camcad.geometry.tool import check_tool
from camcad.toolpath import MoveKind, Toolpath, check_toolpath, contour, plan_toolpath
from camcad.toolpath.contour import Step, split_tabs
from camcad.toolpath.verify import densify, distance_to_polyline
from tests.conftest import DISC_SAMPLES, make_design
from tests.named import raises_named

CONFIGS = {
    "climb": {},
    "conventional": {"direction": "conventional"},
    "tabs-bore-coolant": {"tab_count": 3, "mill_bore": True, "coolant": True},
    "start-75-no-stock": {"start_angle": 75.0, "stock_to_leave": 0.0, "lead_radius": 4.0},
    "grbl-tight": {"dialect": "grbl", "tolerance": 0.002, "tool_diameter": 8.0},
    "fewest-arcs-tabs": {"fewest_arcs": True, "tab_count": 2},
}


def design_for(config: str) -> Design:
    if config == "flat":
        return make_design(follower="translating-flat", law="harmonic", extra={"gcode": {"tab_count": 2}})
    if config == "cw-offset":
        return make_design(rotation="cw", offset=6.0, law="poly-345", extra={"cam": {"bore": 12.0}})
    return make_design(extra={"cam": {"bore": 10.0}, "gcode": CONFIGS[config]})


@cache
def planned(config: str) -> tuple[Design, Cam, Toolpath]:
    design = design_for(config)
    cam = Cam.from_design(design)
    tp = plan_toolpath(
        cam, design.gcode, name=design.cam.name, thickness=design.cam.thickness, bore=design.cam.bore
    )
    return design, cam, tp


ALL = [*CONFIGS, "flat", "cw-offset"]


@pytest.mark.parametrize("config", ALL)
def test_parsed_program_passes_the_geometric_proof(config):
    design, cam, tp = planned(config)
    moves = parse_gcode(render_gcode(tp))
    check = check_toolpath(moves, cam, design.gcode, thickness=design.cam.thickness, bore=design.cam.bore)
    assert check.ok, check.problems
    assert check.hausdorff <= design.gcode.tolerance
    assert check.min_clearance >= -design.gcode.tolerance
    assert check.max_radius_mismatch <= 1e-3
    assert check.direction is design.gcode.direction
    assert not check.missing_levels
    assert check.low_rapids == 0


def profile_passes(tp: Toolpath) -> list[list]:
    """The profile passes of a program: runs of feed moves between rapids that hold arcs outside the bore."""
    runs, cur = [], []
    for m in tp.moves:
        if m.kind is MoveKind.RAPID:
            runs.append(cur)
            cur = []
        else:
            cur.append(m)
    runs.append(cur)
    bore = tp.bore / 2.0 + 1e-6
    return [r for r in runs if r and any(math.hypot(*m.end[:2]) > bore for m in r if m.kind.is_arc)]


@pytest.mark.parametrize("config", [c for c in ALL if c != "start-75-no-stock"])
def test_roughing_contour_is_within_tolerance_of_its_own_exact_offset(config):
    # the roughing contour is the finishing arc spline offset by the stock (issue 18); measured here
    # against the exact curve cam.offset_curve(φ, r + stock), two-way, on dense samples of both (the
    # exact curve at 200 000 φ, the moves every 0.02 mm), leads excluded
    design, cam, tp = planned(config)
    *rough, finish = profile_passes(tp)
    assert rough and tp.rough_offset > design.gcode.tool_radius
    planar = [m for m in rough[-1] if m.kind.is_arc or m.start[:2] != m.end[:2]][1:-1]
    path = np.vstack([densify(m) for m in planar])[:, :2]
    exact = np.asarray(cam.offset_curve(np.linspace(0.0, 2.0 * math.pi, 200_001), tp.rough_offset).point)
    tol = design.gcode.tolerance
    assert distance_to_polyline(path, exact).max() <= tol
    assert distance_to_polyline(exact[::4], path).max() <= tol
    # as many blocks as the finishing contour, whose arcs it offsets
    finish_planar = [m for m in finish if m.kind.is_arc or m.start[:2] != m.end[:2]][1:-1]
    assert len(planar) == len(finish_planar)


def test_roughing_contour_is_fitted_afresh_when_the_offset_spline_cannot_be_used(monkeypatch):
    # an offset that would turn an arc inside out (or miss the tolerance) falls back to the arc search
    design = design_for("climb")
    cam = Cam.from_design(design)
    calls = []

    def refuse(pieces, delta):
        calls.append(delta)

    monkeypatch.setattr(contour, "offset_pieces", refuse)
    tp = plan_toolpath(cam, design.gcode, name="x", thickness=design.cam.thickness, bore=design.cam.bore)
    assert calls, "the offset was not tried"
    *rough, _ = profile_passes(tp)
    planar = [m for m in rough[-1] if m.kind.is_arc or m.start[:2] != m.end[:2]][1:-1]
    path = np.vstack([densify(m) for m in planar])[:, :2]
    exact = np.asarray(cam.offset_curve(np.linspace(0.0, 2.0 * math.pi, 200_001), tp.rough_offset).point)
    assert distance_to_polyline(path, exact).max() <= design.gcode.tolerance
    assert distance_to_polyline(exact[::4], path).max() <= design.gcode.tolerance


def test_fewest_arcs_drops_arcs_and_starts_the_contour_abeam_the_start_angle():
    """[gcode] fewest_arcs: fewer finishing arcs than the search alone, within the same certificate."""
    design, cam, tp = planned("fewest-arcs-tabs")
    plain = plan_toolpath(
        cam,
        replace(design.gcode, fewest_arcs=False),
        name="x",
        thickness=design.cam.thickness,
        bore=design.cam.bore,
    )
    assert tp.contour_arcs < plain.contour_arcs
    assert tp.max_deviation <= design.gcode.tolerance
    # the finishing contour starts on the normal of the exact path at start_angle (to the 4-decimal rounding)
    from camcad.toolpath.plan import _breaks, _fit_tolerance

    r, tol, phi = design.gcode.tool_radius, design.gcode.tolerance, math.radians(40.0)
    finish = contour.fit_contour(
        cam, r, _breaks(cam, phi), tol, _fit_tolerance(tol), clockwise=True, fewest_arcs=True
    )
    point, d1, _ = contour.offset_curve(cam, r)(np.array([phi]))
    assert abs((np.asarray(finish.start) - point[0]) @ (d1[0] / np.linalg.norm(d1[0]))) <= 1e-4


def test_climb_runs_clockwise_and_conventional_counter_clockwise():
    # outside profile, spindle M3: climb keeps the part on the tool's right, i.e. clockwise
    for config, sign in (("climb", -1.0), ("conventional", 1.0)):
        _, _, tp = planned(config)
        finish = tp.moves[-60:]  # inside the finishing pass
        area = sum(
            m.start[0] * m.end[1] - m.end[0] * m.start[1] for m in finish if m.end[2] == tp.final_depth
        )
        assert np.sign(area) == sign


def test_no_rapid_below_safe_height_and_plunges_are_off_the_part():
    design, cam, tp = planned("tabs-bore-coolant")
    spec = design.gcode
    for i, m in enumerate(tp.moves):
        if m.kind is MoveKind.RAPID:
            assert m.end[2] >= spec.safe_height and (i == 0 or m.start[2] >= spec.safe_height)
    plunges = [m for m in tp.moves if m.kind is MoveKind.LINE and m.end[2] < m.start[2] and m.start[2] > 0]
    assert len(plunges) == len(tp.levels) + 2  # roughing levels, finishing, bore
    for m in plunges[1:]:  # the first is the bore
        radius = np.hypot(*m.end[:2])
        assert radius > cam.base_radius


def _pass_depths(moves):
    """Lowest Z [mm] of every pass: the runs of feed moves between rapids."""
    depths, run = [], []
    for m in (*moves, None):
        if m is None or m.kind is MoveKind.RAPID:
            if run:
                depths.append(min(run))
            run = []
        else:
            run.append(m.end[2])
    return depths


@pytest.mark.parametrize("config", ["climb", "grbl-tight"])
def test_every_step_down_level_is_cut(config):
    # measured on the program as written and read back, against the design's own numbers: the
    # profile is cut from the stock top (Z0) down to -(thickness + breakthrough) in equal steps of at
    # most step_down, in the fewest passes that allows, and finished at the full depth
    design, _, tp = planned(config)
    spec = design.gcode
    full = -(design.cam.thickness + spec.breakthrough)
    depths = _pass_depths(parse_gcode(render_gcode(tp)))
    *rough, finish = depths
    assert finish == pytest.approx(full, abs=1e-4)
    assert rough[-1] == pytest.approx(full, abs=1e-4)
    steps = -np.diff([0.0, *rough])
    assert np.all(steps <= spec.step_down + 1e-4)
    assert np.ptp(steps) <= 2e-4  # equal steps, to the 4 decimals written
    assert (len(rough) - 1) * spec.step_down < -full  # one pass fewer could not reach the depth


def test_tabs_lift_the_tool_on_passes_below_tab_top():
    design, _, tp = planned("tabs-bore-coolant")
    assert tp.tab_top == pytest.approx(-design.cam.thickness + design.gcode.tab_height)
    lifts = [
        m for m in tp.moves if m.kind is MoveKind.LINE and m.end[2] == tp.tab_top and m.start[2] < tp.tab_top
    ]
    passes_below = sum(1 for z in tp.levels if z < tp.tab_top) + 1  # + finishing
    assert len(lifts) == design.gcode.tab_count * passes_below


def _pass_xy(tp: Toolpath, label: str) -> list:
    """The XY moves of the pass whose comment starts with ``label``, leads excluded."""
    start = next(k for k, m in enumerate(tp.moves) if m.note.startswith(label))
    stop = next((k for k, m in enumerate(tp.moves[start + 1 :], start + 1) if m.note), len(tp.moves))
    xy = [m for m in tp.moves[start:stop] if m.kind is not MoveKind.RAPID and m.start[:2] != m.end[:2]]
    return xy[1:-1]


def test_tabs_split_the_contour_where_needed_and_leave_the_path_alone():
    """With tabs the finishing pass runs the same arcs (same circles, every vertex kept), split at most twice
    per tab; a roughing pass above the tabs is not split at all."""
    design, cam, tp = planned("tabs-bore-coolant")
    spec = replace(design.gcode, tab_count=0)
    plain = plan_toolpath(cam, spec, name="x", thickness=design.cam.thickness, bore=design.cam.bore)
    tabbed, untabbed = _pass_xy(tp, "profile finishing"), _pass_xy(plain, "profile finishing")
    assert len(untabbed) == plain.contour_arcs == tp.contour_arcs == plain.contour_blocks
    assert len(tabbed) == tp.contour_blocks
    assert len(untabbed) < len(tabbed) <= len(untabbed) + 2 * design.gcode.tab_count
    circles = lambda moves: {(m.kind, m.center) for m in moves if m.kind.is_arc}  # noqa: E731
    assert circles(tabbed) == circles(untabbed)
    assert {m.end[:2] for m in untabbed} <= {m.end[:2] for m in tabbed}
    above = [z for z in tp.levels if z >= tp.tab_top]
    assert above, "the sample needs a roughing pass above the tabs"
    label = "profile roughing pass 1/"
    assert len(_pass_xy(tp, label)) == len(_pass_xy(plain, label))


def _tangent(m, at_end: bool) -> np.ndarray:
    """Unit XY tangent of a move, in its direction of travel, at its end or start."""
    p = np.array(m.end[:2] if at_end else m.start[:2])
    if not m.kind.is_arc:
        d = np.array(m.end[:2]) - np.array(m.start[:2])
        return d / np.linalg.norm(d)
    r = p - np.array(m.center)
    t = np.array([-r[1], r[0]]) * (1.0 if m.kind is MoveKind.CCW else -1.0)
    return t / np.linalg.norm(t)


@pytest.mark.parametrize("config", ALL)
def test_leads_join_the_contour_tangentially(config):
    """Each lead-in ends along the contour's first step and each lead-out leaves along its last (the contour
    may start off the exact curve, within the band, where its loop closes)."""
    _, _, tp = planned(config)
    labels = [m.note.splitlines()[0] for m in tp.moves if m.note.startswith("profile ")]
    assert labels
    for label in labels:
        start = next(k for k, m in enumerate(tp.moves) if m.note.startswith(label))
        stop = next((k for k, m in enumerate(tp.moves[start + 1 :], start + 1) if m.note), len(tp.moves))
        xy = [m for m in tp.moves[start:stop] if m.kind is not MoveKind.RAPID and m.start[:2] != m.end[:2]]
        # 4-decimal output turns a tangent by at most ~1e-4 mm over the lead or step radius
        assert np.linalg.norm(_tangent(xy[0], True) - _tangent(xy[1], False)) <= 1e-3, label
        assert np.linalg.norm(_tangent(xy[-2], True) - _tangent(xy[-1], False)) <= 1e-3, label


def test_bore_is_helix_milled_inside_its_wall():
    design, _, tp = planned("tabs-bore-coolant")
    bore = [m for m in tp.moves if m.kind.is_arc and math.hypot(*m.end[:2]) < design.cam.bore / 2]
    assert bore and all(m.kind is MoveKind.CCW for m in bore)  # climb inside a hole
    reach = max(math.hypot(*m.end[:2]) for m in bore) + design.gcode.tool_radius
    assert reach == pytest.approx(design.cam.bore / 2.0, abs=1e-4)
    assert min(m.end[2] for m in bore) == pytest.approx(tp.final_depth)


def test_bore_not_larger_than_tool_is_an_error_naming_sizes():
    design = make_design(extra={"cam": {"bore": 6.0}, "gcode": {"mill_bore": True, "tool_diameter": 6.0}})
    cam = Cam.from_design(design)
    with pytest.raises(DesignError, match=r"bore Ø6 mm is not larger than the tool Ø6 mm"):
        plan_toolpath(cam, design.gcode, name="x", thickness=8.0, bore=6.0)
    with pytest.raises(DesignError, match="no bore"):
        plan_toolpath(cam, design.gcode, name="x", thickness=8.0, bore=0.0)


CONCAVE = {"spans": (45.0, 135.0, 45.0, 135.0), "lift": 25.0, "base_radius": 20.0, "roller_radius": 8.0}


def test_tool_larger_than_concave_radius_stops_the_plan_with_a_gouge_error():
    design = make_design(**CONCAVE, extra={"gcode": {"tool_diameter": 30.0}})
    cam = Cam.from_design(design)
    with raises_named(
        GougeError, match=r"^gcode\.tool_diameter: .*\(set the tool diameter below it\)$"
    ) as err:
        plan_toolpath(cam, design.gcode, name="x", thickness=8.0)
    assert err.value.max_tool_radius == pytest.approx(check_tool(cam, 1.0))


def test_largest_fitting_tool_mills_the_concave_cam_without_gouging():
    design = make_design(**CONCAVE)
    cam = Cam.from_design(design)
    tool = 2 * 0.95 * check_tool(cam, 1.0)
    spec = replace(design.gcode, tool_diameter=round(tool, 2))
    tp = plan_toolpath(cam, spec, name="x", thickness=8.0)
    check = check_toolpath(parse_gcode(render_gcode(tp)), cam, spec, thickness=8.0)
    assert check.ok, check.problems
    assert tp.rough_offset < spec.tool_radius + spec.stock_to_leave  # stock reduced in the concave part
    assert any("stock reduced" in note for note in tp.notes)
    assert any("lead radius reduced" in note for note in tp.notes)


def test_bad_settings_are_design_errors():
    design, cam, _ = planned("climb")
    with raises_named(DesignError, match=r"gcode\.tolerance"):
        plan_toolpath(cam, replace(design.gcode, tolerance=0.0003), name="x", thickness=8.0)
    with raises_named(DesignError, match=r"gcode\.tab_height"):
        plan_toolpath(cam, replace(design.gcode, tab_count=2, tab_height=8.0), name="x", thickness=8.0)
    with raises_named(DesignError, match=r"gcode\.tab_width: .* not even one fits"):
        plan_toolpath(cam, replace(design.gcode, tab_count=1, tab_width=5000.0), name="x", thickness=8.0)


def test_too_many_tabs_name_the_count_that_fits():
    """The advised count is the true limit: that many tabs plan, one more does not."""
    design, cam, _ = planned("climb")
    with raises_named(DesignError, match=r"gcode\.tab_count: .* at most (\d+) tab") as info:
        plan_toolpath(cam, replace(design.gcode, tab_count=40, tab_width=10.0), name="x", thickness=8.0)
    most = int(re.search(r"at most (\d+) tab", str(info.value)).group(1))
    plan_toolpath(cam, replace(design.gcode, tab_count=most, tab_width=10.0), name="x", thickness=8.0)
    with raises_named(DesignError, match=r"gcode\.tab_count"):
        plan_toolpath(cam, replace(design.gcode, tab_count=most + 1, tab_width=10.0), name="x", thickness=8.0)


def test_velocity_jump_is_refused():
    design = make_design(law="constant-velocity")
    with pytest.raises(DesignLimitError, match="velocity jumps"):
        plan_toolpath(Cam.from_design(design), design.gcode, name="x", thickness=8.0)


def test_g1_only_path_meets_the_same_tolerance_with_many_more_blocks():
    design, cam, tp = planned("climb")
    lines = plan_toolpath(cam, design.gcode, name="x", thickness=8.0, arcs=False)
    arcs = sum(1 for m in lines.moves if m.kind.is_arc)
    assert arcs == 2 * (len(lines.levels) + 1)  # only the tangent leads
    assert lines.max_deviation <= design.gcode.tolerance
    check = check_toolpath(parse_gcode(render_gcode(lines)), cam, design.gcode, thickness=8.0)
    assert check.ok, check.problems
    assert lines.contour_blocks > 5 * tp.contour_blocks


@pytest.mark.parametrize("path", DISC_SAMPLES[:2], ids=[p.stem for p in DISC_SAMPLES[:2]])
def test_samples_plan_and_prove(path):
    design = load_design(path)
    cam = Cam.from_design(design)
    tp = plan_toolpath(
        cam, design.gcode, name=design.cam.name, thickness=design.cam.thickness, bore=design.cam.bore
    )
    check = check_toolpath(
        parse_gcode(render_gcode(tp)), cam, design.gcode, thickness=design.cam.thickness, bore=design.cam.bore
    )
    assert check.ok, check.problems


def test_tool_nearly_filling_the_bore_gets_a_bounded_helix():
    design = make_design(extra={"cam": {"bore": 10.2}, "gcode": {"mill_bore": True, "tool_diameter": 10.0}})
    cam = Cam.from_design(design)
    tp = plan_toolpath(cam, design.gcode, name="x", thickness=8.0, bore=10.2)
    helix = [m for m in tp.moves if m.kind.is_arc and math.hypot(*m.end[:2]) < 5.1]
    assert 5 <= len(helix) <= 12
    check = check_toolpath(parse_gcode(render_gcode(tp)), cam, design.gcode, thickness=8.0, bore=10.2)
    assert check.ok, check.problems
    assert check.bore_excess <= design.gcode.tolerance


def test_tab_edges_split_steps_and_flag_the_span_between():
    line = MoveKind.LINE
    steps = [
        Step(kind=line, start=(0.0, 0.0), end=(10.0, 0.0)),
        Step(kind=line, start=(10.0, 0.0), end=(20.0, 0.0)),
        Step(kind=line, start=(20.0, 0.0), end=(30.0, 0.0)),
    ]
    # one edge inside the first step, one exactly at the end of the second
    out = split_tabs(steps, np.array([[4.0, 0.001], [20.0, 0.0]]))
    assert [(s.start[0], s.end[0], s.tab) for s in out] == [
        (0.0, 4.0, False),
        (4.0, 10.0, True),
        (10.0, 20.0, True),
        (20.0, 30.0, False),
    ]
