"""G-code writer and reader: a planned toolpath in three dialects, read back; the reader's rules."""

from __future__ import annotations

import math
from functools import cache

import numpy as np
import pytest

from camcad.design import Design, Dialect
from camcad.errors import EXIT_INVALID, CamcadError, DesignError, GcodeSyntaxError, exit_code
from camcad.export.gcode import count_blocks, parse_gcode, render_gcode, render_program
from camcad.geometry.cam import Cam
from camcad.toolpath import MoveKind, Toolpath, check_toolpath, plan_toolpath
from tests.conftest import make_design

CONFIGS = {
    "climb": {},
    "tabs-bore-coolant": {"tab_count": 3, "mill_bore": True, "coolant": True},
}


@cache
def planned(config: str) -> tuple[Design, Cam, Toolpath]:
    design = make_design(extra={"cam": {"bore": 10.0}, "gcode": CONFIGS[config]})
    cam = Cam.from_design(design)
    tp = plan_toolpath(
        cam, design.gcode, name=design.cam.name, thickness=design.cam.thickness, bore=design.cam.bore
    )
    return design, cam, tp


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


def test_summary_reports_what_was_written():
    design, _, tp = planned("tabs-bore-coolant")
    program = render_program(tp)  # rendered once: the summary counts the text that is written
    text = program.text
    assert text == render_gcode(tp)
    summary = program.summary()
    assert set(summary) == {
        "blocks", "arcs", "cutting_length_mm", "cycle_time_s", "max_deviation_mm",
        "tool_diameter_mm", "tool_chosen",
    }  # fmt: skip
    assert summary["blocks"] == count_blocks(text)
    assert summary["arcs"] == sum(1 for line in text.splitlines() if line.startswith(("G2 ", "G3 ")))
    assert 0.0 < summary["max_deviation_mm"] <= design.gcode.tolerance
    feed_time = 60.0 * summary["cutting_length_mm"] / design.gcode.feed
    assert summary["cycle_time_s"] > feed_time  # plunges are slower, rapids add time


def test_program_is_deterministic_and_pure():
    design, cam, tp = planned("climb")
    again = plan_toolpath(cam, design.gcode, name=design.cam.name, thickness=design.cam.thickness, bore=10.0)
    assert render_gcode(again) == render_gcode(tp)


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
    with pytest.raises(GcodeSyntaxError, match=why) as err:
        parse_gcode(text)
    # one line of the hierarchy: bad input (exit 2), still a ValueError, naming the line
    assert exit_code(err.value) == EXIT_INVALID
    assert isinstance(err.value, CamcadError) and isinstance(err.value, ValueError)
    line_no = err.value.line_no
    assert str(err.value).startswith(f"line {line_no}: ")
    assert text.splitlines()[line_no - 1].strip() in str(err.value)


def test_full_circle_arc_is_one_turn():
    (_, m) = parse_gcode("G0 X2 Y0\nG3 X2 Y0 Z-1 I-2 J0 F100")
    assert m.sweep == pytest.approx(2 * math.pi)
    assert m.length == pytest.approx(math.hypot(4 * math.pi, 1.0))


def test_defaults_mill_climb_to_five_microns_in_linuxcnc_dialect():
    # the defaults (0.005 mm, linuxcnc, climb), measured on the program of a design without a
    # [gcode] table rather than read off GcodeSpec: LinuxCNC's blending word G64 P<tolerance> and tool
    # length offset G43 (no other dialect writes them), the spindle clockwise (M3) and the finishing
    # contour clockwise around the part (climb milling outside), within 0.005 mm of the exact offset curve
    design = make_design()
    cam = Cam.from_design(design)
    text = render_gcode(plan_toolpath(cam, design.gcode, name="x", thickness=design.cam.thickness))
    blocks = text.splitlines()
    assert "G64 P0.0050" in blocks and "G43 H1" in blocks
    assert any(line.split()[-1:] == ["M3"] for line in blocks)
    moves = parse_gcode(text)
    last_rapid = max(i for i, m in enumerate(moves[:-1]) if m.kind is MoveKind.RAPID)
    finishing = moves[last_rapid + 1 : -1]  # the last pass, up to the final retract
    low = min(m.end[2] for m in finishing)
    ring = [m for m in finishing if m.start[2] == m.end[2] == low]
    area = sum(m.start[0] * m.end[1] - m.end[0] * m.start[1] for m in ring)
    assert area < 0.0  # clockwise seen from +Z
    check = check_toolpath(moves, cam, design.gcode, thickness=design.cam.thickness)
    assert 0.001 < check.hausdorff <= 0.005  # the arcs use the tolerance, not a finer one
