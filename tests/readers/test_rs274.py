"""LinuxCNC's standalone interpreter ``rs274`` runs every program, and its canonical output passes the proof.

``rs274 -t TOOLS -g FILE OUT`` interprets a program without a machine and
writes the canonical machining calls (STRAIGHT_TRAVERSE, STRAIGHT_FEED,
ARC_FEED, ...). It needs a tool table holding the program's tool number; its
standalone machine reads tool tables in inches, so the table only names the
tool and the diameter stays in the program. Errors go to stderr and make the
exit status 1 (e.g. "Radius to end of arc differs from radius to start").
"""

from __future__ import annotations

import shutil
import subprocess
from dataclasses import replace
from functools import cache
from pathlib import Path

import pytest

from camcad.design import Design, load_design
from camcad.export.gcode import parse_canon, parse_gcode, render_gcode
from camcad.geometry.cam import Cam
from camcad.toolpath import Toolpath, check_toolpath, plan_toolpath
from tests.conftest import DISC_SAMPLES, make_design

RS274 = shutil.which("rs274")
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        RS274 is None, reason="LinuxCNC's rs274 is not installed (Debian package linuxcnc-uspace)"
    ),
]

CONFIGS = {
    "default": {},
    "tabs-bore-conventional": {
        "tab_count": 4,
        "mill_bore": True,
        "direction": "conventional",
        "coolant": True,
        "tool_number": 7,
    },
    "start-200-fine": {"start_angle": 200.0, "tolerance": 0.001, "tool_diameter": 4.0, "step_down": 3.0},
    "fewest-arcs-tabs": {"fewest_arcs": True, "tab_count": 3},
}
LAWS = {"fewest-arcs-tabs": "cycloidal"}  # a cam whose finishing loop the refit thins (22 → 20 arcs)
DIALECTS = ("linuxcnc", "grbl", "generic")


@cache
def planned(config: str) -> tuple[Design, Cam, Toolpath]:
    design = make_design(
        law=LAWS.get(config, "poly-345"), offset=4.0, extra={"cam": {"bore": 12.0}, "gcode": CONFIGS[config]}
    )
    cam = Cam.from_design(design)
    tp = plan_toolpath(
        cam, design.gcode, name=design.cam.name, thickness=design.cam.thickness, bore=design.cam.bore
    )
    return design, cam, tp


def run_rs274(text: str, tool: int, folder: Path) -> tuple[subprocess.CompletedProcess[str], str]:
    """Interpret a program; return the process and the canonical output."""
    program, out, tools = folder / "cam.ngc", folder / "canon.txt", folder / "tools.tbl"
    program.write_text(text, encoding="ascii")
    tools.write_text(f"T{tool} P{tool} Z0 D0.25 ;camcad test tool\n", encoding="ascii")
    proc = subprocess.run(
        [RS274, "-t", str(tools), "-g", str(program), str(out)],
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    return proc, out.read_text(encoding="ascii") if out.exists() else ""


def errors(proc: subprocess.CompletedProcess[str]) -> list[str]:
    """Lines of rs274's output other than its 'executing' banner."""
    lines = (proc.stdout + proc.stderr).splitlines()
    return [line for line in lines if line.strip() and line.strip() != "executing"]


@pytest.mark.parametrize("dialect", DIALECTS)
@pytest.mark.parametrize("config", list(CONFIGS))
def test_rs274_accepts_program_and_its_motion_passes_the_proof(config, dialect, tmp_path):
    design, cam, tp = planned(config)
    text = render_gcode(tp, dialect)
    proc, canon = run_rs274(text, design.gcode.tool_number, tmp_path)
    assert proc.returncode == 0, errors(proc)
    assert not errors(proc)
    assert "PROGRAM_END" in canon
    moves = parse_canon(canon)
    check = check_toolpath(moves, cam, design.gcode, thickness=design.cam.thickness, bore=design.cam.bore)
    assert check.ok, check.problems
    assert check.hausdorff <= design.gcode.tolerance
    assert check.max_radius_mismatch <= 1e-3
    assert check.direction is design.gcode.direction
    # the interpreter executes exactly the blocks we wrote
    ours = parse_gcode(text)
    assert len(moves) == len(ours)
    assert [m.kind for m in moves] == [m.kind for m in ours]
    assert sum(1 for line in canon.splitlines() if "ARC_FEED(" in line) == sum(
        1 for m in ours if m.kind.is_arc
    )


def test_the_fewest_arcs_program_it_runs_is_a_thinned_loop():
    """The fewest-arcs configuration above exercises the refit: fewer arcs than the search's loop."""
    design, cam, tp = planned("fewest-arcs-tabs")
    plain = replace(design.gcode, fewest_arcs=False)
    searched = plan_toolpath(
        cam, plain, name=design.cam.name, thickness=design.cam.thickness, bore=design.cam.bore
    )
    assert tp.contour_arcs < searched.contour_arcs


def test_rs274_catches_an_arc_whose_radii_disagree(tmp_path):
    """The harness is not vacuous: a corrupted arc end point makes rs274 fail."""
    design, _, tp = planned("default")
    text = render_gcode(tp)
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("G2 ") and " X" in line and " Y" in line)
    words = lines[k].split()
    words = [f"X{float(w[1:]) + 0.5:.4f}" if w.startswith("X") else w for w in words]
    lines[k] = " ".join(words)
    proc, _ = run_rs274("\n".join(lines) + "\n", design.gcode.tool_number, tmp_path)
    assert proc.returncode != 0
    assert any("differs" in line for line in errors(proc))


@cache
def planned_sample(path: Path) -> tuple[Design, Cam, Toolpath]:
    design = load_design(path)
    cam = Cam.from_design(design)
    tp = plan_toolpath(
        cam, design.gcode, name=design.cam.name, thickness=design.cam.thickness, bore=design.cam.bore
    )
    return design, cam, tp


@pytest.mark.parametrize("dialect", DIALECTS)
@pytest.mark.parametrize("path", DISC_SAMPLES, ids=[p.stem for p in DISC_SAMPLES])
def test_rs274_runs_every_sample_in_every_dialect(path, dialect, tmp_path):
    design, cam, tp = planned_sample(path)
    text = render_gcode(tp, dialect)
    proc, canon = run_rs274(text, design.gcode.tool_number, tmp_path)
    assert proc.returncode == 0, errors(proc)
    assert not errors(proc)
    moves = parse_canon(canon)
    if dialect == "linuxcnc":
        check = check_toolpath(moves, cam, design.gcode, thickness=design.cam.thickness, bore=design.cam.bore)
        assert check.ok, check.problems
    else:  # the same motion as the checked dialect, to the 4 decimals printed
        reference = parse_gcode(render_gcode(tp, "linuxcnc"))
        assert len(moves) == len(reference)
        for a, b in zip(moves, reference, strict=True):
            assert a.kind is b.kind
            assert max(abs(u - v) for u, v in zip(a.end, b.end, strict=True)) <= 1e-4
