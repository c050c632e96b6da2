"""rs274 runs the groove cam's program (issue 15); its canonical motion is proved on the exact flanks.

The harness is :mod:`tests.readers.test_rs274`'s (``rs274 -t TOOLS -g FILE OUT``).
From the canonical output alone (:func:`parse_canon`), the tool-centre path
is rebuilt and measured against dense polylines of the exact flank curves
``cam.offset_curve(φ, d)`` (:func:`tests.toolpath.test_groove.prove`), independent
of the arc fit: the flank passes hold the tool's edge on each flank within
``gcode.tolerance``, nothing comes closer than r_t − tol to either flank or
leaves the groove, the slot reaches −depth and no deeper, no rapid runs below
the safe height, and the ramp descends at most ``step_down`` per lap.
"""

from __future__ import annotations

from functools import cache

import pytest

from camcad.design import Design, load_design
from camcad.export.gcode import parse_canon, parse_gcode, render_gcode
from camcad.geometry.cam import Cam
from camcad.toolpath import Toolpath
from tests.readers.test_rs274 import DIALECTS, RS274, errors, run_rs274
from tests.toolpath.test_groove import SAMPLE, assert_proved, plan, prove

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        RS274 is None, reason="LinuxCNC's rs274 is not installed (Debian package linuxcnc-uspace)"
    ),
]


@cache
def planned() -> tuple[Design, Cam, Toolpath]:
    design = load_design(SAMPLE)
    return (design, *plan(design))


@pytest.mark.parametrize("dialect", DIALECTS)
def test_rs274_runs_the_groove_program_and_its_motion_is_proved_on_the_exact_flanks(dialect, tmp_path):
    design, cam, tp = planned()
    text = render_gcode(tp, dialect)
    proc, canon = run_rs274(text, design.gcode.tool_number, tmp_path)
    assert proc.returncode == 0, errors(proc)
    assert not errors(proc)
    assert "PROGRAM_END" in canon
    moves = parse_canon(canon)
    assert_proved(prove(moves, cam, design), cam, design)
    # the interpreter executes exactly the blocks we wrote, helical arcs included
    ours = parse_gcode(text)
    assert [m.kind for m in moves] == [m.kind for m in ours]
    assert sum(1 for line in canon.splitlines() if "ARC_FEED(" in line) == sum(
        1 for m in ours if m.kind.is_arc
    )
    for a, b in zip(moves, ours, strict=True):
        assert max(abs(u - v) for u, v in zip(a.end, b.end, strict=True)) <= 1e-4


@pytest.mark.parametrize("tool", ["chosen", "D6"])
def test_rs274_runs_a_groove_built_without_a_gcode_table(tool, tmp_path):
    """Issue 31: groove_rocker without [gcode] builds; LinuxCNC reads its cam.ngc (the chosen cutter),
    and a D6 clears the 24.03 mm groove in stepover passes; both motions are proved, the swept tool
    covering the whole groove."""
    from dataclasses import replace

    from camcad.cli import main
    from tests.toolpath.test_groove import no_gcode_design

    path = no_gcode_design(tmp_path)
    if tool == "D6":
        path.write_text(path.read_text() + "\n[gcode]\ntool_diameter = 6.0\n")
    out = tmp_path / "out"
    assert main(["build", str(path), "-o", str(out), "-q", "--only", "gcode"]) == 0
    text = (out / "cam.ngc").read_text(encoding="ascii")
    design = load_design(path)
    design = replace(design, gcode=replace(design.gcode, tool_diameter=16.0 if tool == "chosen" else 6.0))
    proc, canon = run_rs274(text, design.gcode.tool_number, tmp_path)
    assert proc.returncode == 0 and not errors(proc), errors(proc)
    assert "PROGRAM_END" in canon
    cam = Cam.from_design(design)
    assert_proved(prove(parse_canon(canon), cam, design), cam, design)
