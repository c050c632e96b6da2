"""rs274 runs the second plate's program of a conjugate pair (issue 15), proved on that plate.

The build writes ``cam_2.ngc`` for the second plate; LinuxCNC's interpreter
must accept it, and its canonical motion must pass the same proof as a
plate's (:func:`camcad.toolpath.check_toolpath`) against the SECOND plate's
exact offset curve, and fail it against the first plate's (a different cam).
"""

from __future__ import annotations

import pytest

from camcad.design import load_design
from camcad.export.gcode import parse_canon
from camcad.pipeline import build
from camcad.toolpath import check_toolpath
from tests.conftest import ROOT
from tests.readers.test_rs274 import RS274, errors, run_rs274

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        RS274 is None, reason="LinuxCNC's rs274 is not installed (Debian package linuxcnc-uspace)"
    ),
]


def test_rs274_runs_the_second_plate_and_it_is_proved_on_that_plate(tmp_path):
    design = load_design(ROOT / "samples" / "indexing_conjugate.toml")
    result = build(design, tmp_path / "out", only=["gcode"])
    partner = result.analysis.parts[1].part.cam
    text = (tmp_path / "out" / "cam_2.ngc").read_text(encoding="ascii")
    proc, canon = run_rs274(text, design.gcode.tool_number, tmp_path)
    assert proc.returncode == 0, errors(proc)
    assert not errors(proc)
    moves = parse_canon(canon)
    spec, t, bore = design.gcode, design.cam.thickness, design.cam.bore
    check = check_toolpath(moves, partner, spec, thickness=t, bore=bore)
    assert check.ok, check.problems
    assert check.hausdorff <= spec.tolerance
    # the same moves are not a program for the first plate
    assert not check_toolpath(moves, result.analysis.cam, spec, thickness=t, bore=bore).ok
