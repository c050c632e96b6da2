"""G-code toolpath: planned, written, read back by our own parser and proved against the exact cam."""

from __future__ import annotations

import math
from dataclasses import replace
from functools import cache

import numpy as np
import pytest

from camcad.design import Design, Dialect, Direction, GcodeSpec, load_design
from camcad.errors import DesignError, DesignLimitError, GougeError
from camcad.export.gcode import (
    MoveKind,
    Toolpath,
    check_gouge,
    check_toolpath,
    count_blocks,
    parse_gcode,
    plan_toolpath,
    render_gcode,
    write_gcode,
)
from camcad.export.gcode.parse import GcodeSyntaxError
from camcad.geometry.cam import Cam
from tests.conftest import SAMPLES, make_design

DEG = math.pi / 180.0

CONFIGS = {
    "climb": {},
    "conventional": {"direction": "conventional"},
    "tabs-bore-coolant": {"tab_count": 3, "mill_bore": True, "coolant": True},
    "start-75-no-stock": {"start_angle": 75.0, "stock_to_leave": 0.0, "lead_radius": 4.0},
    "grbl-tight": {"dialect": "grbl", "tolerance": 0.002, "tool_diameter": 8.0},
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


@pytest.mark.parametrize("config", ["climb", "tabs-bore-coolant"])
def test_parsed_moves_equal_planned_moves(config):
    _, _, tp = planned(config)
    first, *moves = parse_gcode(render_gcode(tp))
    assert first.end[2] == tp.spec.clearance_height  # the writer's opening retract
    assert len(moves) == len(tp.moves)
    for ours, back in zip(tp.moves, moves, strict=True):
        assert back.kind is ours.kind
        np.testing.assert_allclose(back.end, ours.end, atol=1e-9)
        if ours.center is not None:
            np.testing.assert_allclose(back.center, ours.center, atol=2e-4)


def test_climb_runs_clockwise_and_conventional_counter_clockwise():
    # outside profile, spindle M3: climb keeps the part on the tool's right, i.e. clockwise
    for config, sign in (("climb", -1.0), ("conventional", 1.0)):
        _, _, tp = planned(config)
        finish = tp.moves[-60:]  # inside the finishing pass
        area = sum(
            m.start[0] * m.end[1] - m.end[0] * m.start[1] for m in finish if m.end[2] == tp.final_depth
        )
        assert np.sign(area) == sign


def test_summary_reports_what_was_written():
    design, _, tp = planned("tabs-bore-coolant")
    summary = tp.summary()
    assert set(summary) == {"blocks", "arcs", "cutting_length_mm", "cycle_time_s", "max_deviation_mm"}
    text = render_gcode(tp)
    assert summary["blocks"] == count_blocks(text)
    assert summary["arcs"] == sum(1 for line in text.splitlines() if line.startswith(("G2 ", "G3 ")))
    assert 0.0 < summary["max_deviation_mm"] <= design.gcode.tolerance
    feed_time = 60.0 * summary["cutting_length_mm"] / design.gcode.feed
    assert summary["cycle_time_s"] > feed_time  # plunges are slower, rapids add time


def test_program_is_deterministic_and_pure():
    design, cam, tp = planned("climb")
    again = write_gcode(cam, design.gcode, name=design.cam.name, thickness=design.cam.thickness, bore=10.0)
    assert again == render_gcode(tp)


def test_header_names_design_tool_stock_tolerance_units():
    _, _, tp = planned("climb")
    head = "\n".join(line for line in render_gcode(tp).splitlines() if line.startswith("("))[:2000]
    assert "test cycloidal" in head
    assert "D6.000" in head and "T1" in head
    assert "8.000 thick" in head and "Z-8.5000" in head
    assert "tolerance: 0.0050" in head
    assert "millimetres" in head and "G54" in head


def test_dialects_write_what_their_controllers_accept():
    _, _, tp = planned("climb")
    linuxcnc = render_gcode(tp, Dialect.LINUXCNC)
    grbl = render_gcode(tp, "grbl")
    generic = render_gcode(tp, "generic")
    assert "G17 G21 G40 G49 G54 G80 G90 G91.1 G94" in linuxcnc
    assert "G64 P0.0050" in linuxcnc and "T1 M6" in linuxcnc and "G43 H1" in linuxcnc
    code = [line for line in grbl.splitlines() if not line.startswith("(")]
    for word in ("G64", "M6", "G43", "G49", "G80"):
        assert not any(word in line.split() for line in code), word
    assert "(load tool T1" in grbl
    assert "G64" not in generic and "T1 M6" in generic
    # the motion is the same in every dialect
    assert parse_gcode(linuxcnc) == parse_gcode(grbl) == parse_gcode(generic)
    with pytest.raises(DesignError, match="allowed: linuxcnc, grbl, generic"):
        render_gcode(tp, "fanuc")


def test_arc_words_are_incremental_ij_with_four_decimals():
    _, _, tp = planned("climb")
    arcs = [line for line in render_gcode(tp).splitlines() if line.startswith(("G2 ", "G3 "))]
    assert arcs
    for line in arcs:
        for word in line.split()[1:]:
            if word[0] in "XYZIJ":
                assert len(word.split(".")[1]) == 4, line


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


def test_every_step_down_level_is_cut():
    design, _, tp = planned("climb")
    depth = design.cam.thickness + design.gcode.breakthrough
    n = math.ceil(depth / design.gcode.step_down)
    assert tp.levels == tuple(round(-depth * k / n, 4) for k in range(1, n + 1))
    assert all(
        -lo + hi <= design.gcode.step_down + 1e-9
        for lo, hi in zip(tp.levels[1:], tp.levels[:-1], strict=True)
    )


def test_tabs_lift_the_tool_on_passes_below_tab_top():
    design, _, tp = planned("tabs-bore-coolant")
    assert tp.tab_top == pytest.approx(-design.cam.thickness + design.gcode.tab_height)
    lifts = [
        m for m in tp.moves if m.kind is MoveKind.LINE and m.end[2] == tp.tab_top and m.start[2] < tp.tab_top
    ]
    passes_below = sum(1 for z in tp.levels if z < tp.tab_top) + 1  # + finishing
    assert len(lifts) == design.gcode.tab_count * passes_below


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


def test_tool_larger_than_concave_radius_is_a_gouge_error():
    design = make_design(**CONCAVE, extra={"gcode": {"tool_diameter": 30.0}})
    cam = Cam.from_design(design)
    smallest = check_gouge(cam, 1.0)
    assert 12.0 < smallest < 15.0
    with pytest.raises(GougeError) as err:
        plan_toolpath(cam, design.gcode, name="x", thickness=8.0)
    message = str(err.value)
    assert "°" in message and "φ =" in message
    assert f"Ø{2 * smallest:.3f} mm" in message
    assert err.value.max_tool_radius == pytest.approx(smallest)
    lo, hi = err.value.phi_range
    rho = cam.profile(np.array([lo, hi])).rho
    assert np.all(rho < 0) and np.all(-rho < 15.0)
    assert isinstance(err.value, DesignLimitError)


def test_largest_fitting_tool_mills_the_concave_cam_without_gouging():
    design = make_design(**CONCAVE)
    cam = Cam.from_design(design)
    tool = 2 * 0.95 * check_gouge(cam, 1.0)
    spec = replace(design.gcode, tool_diameter=round(tool, 2))
    tp = plan_toolpath(cam, spec, name="x", thickness=8.0)
    check = check_toolpath(parse_gcode(render_gcode(tp)), cam, spec, thickness=8.0)
    assert check.ok, check.problems
    assert tp.rough_offset < spec.tool_radius + spec.stock_to_leave  # stock reduced in the concave part
    assert any("stock reduced" in note for note in tp.notes)
    assert any("lead radius reduced" in note for note in tp.notes)


def test_bad_settings_are_design_errors():
    design, cam, _ = planned("climb")
    with pytest.raises(DesignError, match=r"gcode\.tolerance"):
        plan_toolpath(cam, replace(design.gcode, tolerance=0.0003), name="x", thickness=8.0)
    with pytest.raises(DesignError, match=r"gcode\.tab_height"):
        plan_toolpath(cam, replace(design.gcode, tab_count=2, tab_height=8.0), name="x", thickness=8.0)
    with pytest.raises(DesignError, match=r"gcode\.tab_width"):
        plan_toolpath(cam, replace(design.gcode, tab_count=40, tab_width=10.0), name="x", thickness=8.0)


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


@pytest.mark.parametrize("path", SAMPLES[:2], ids=[p.stem for p in SAMPLES[:2]])
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


# -- the reader ------------------------------------------------------------------


def test_parser_reads_units_modes_and_comments():
    text = """
    (a comment) G21 G90 G91.1 ; trailing comment
    G0 X1 Y2 Z3
    G1 Z-1 F100
    G2 X3 Y2 I1 J0
    G20 G91
    G1 X1 F10
    G90.1 G90 G21
    G3 X3 Y2 I2 J2
    """
    moves = parse_gcode(text)
    assert [m.kind for m in moves] == [
        MoveKind.RAPID,
        MoveKind.LINE,
        MoveKind.CW,
        MoveKind.LINE,
        MoveKind.CCW,
    ]
    assert moves[0].start == (0.0, 0.0, 0.0) and moves[0].end == (1.0, 2.0, 3.0)
    assert moves[2].center == (2.0, 2.0) and moves[2].feed == 100.0
    assert moves[3].end == pytest.approx((3.0 + 25.4, 2.0, -1.0)) and moves[3].feed == pytest.approx(254.0)
    assert moves[4].center == (2.0, 2.0)  # absolute centre under G90.1


@pytest.mark.parametrize(
    ("text", "why"),
    [
        ("G18\nG0 X1", "XY plane"),
        ("G2 X1 Y1 R1 F1", "R-format"),
        ("G1 X1", "zero feed"),
        ("G0 X1 Q", "cannot read"),
    ],
)
def test_parser_rejects_what_it_cannot_check(text, why):
    with pytest.raises(GcodeSyntaxError, match=why):
        parse_gcode(text)


def test_full_circle_arc_is_one_turn():
    (_, m) = parse_gcode("G0 X2 Y0\nG3 X2 Y0 Z-1 I-2 J0 F100")
    assert m.sweep == pytest.approx(2 * math.pi)
    assert m.length == pytest.approx(math.hypot(4 * math.pi, 1.0))


def test_spec_defaults_match_the_issue():
    spec = GcodeSpec()
    assert spec.tolerance == 0.005 and spec.dialect is Dialect.LINUXCNC and spec.direction is Direction.CLIMB


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
    from camcad.export.gcode._contour import Step, _split_tabs

    line = MoveKind.LINE
    steps = [
        Step(kind=line, start=(0.0, 0.0), end=(10.0, 0.0)),
        Step(kind=line, start=(10.0, 0.0), end=(20.0, 0.0)),
        Step(kind=line, start=(20.0, 0.0), end=(30.0, 0.0)),
    ]
    # one edge inside the first step, one exactly at the end of the second
    out = _split_tabs(steps, np.array([[4.0, 0.001], [20.0, 0.0]]))
    assert [(s.start[0], s.end[0], s.tab) for s in out] == [
        (0.0, 4.0, False),
        (4.0, 10.0, True),
        (10.0, 20.0, True),
        (20.0, 30.0, False),
    ]
