"""LinuxCNC's rs274 runs a linear cam's program; its finishing pass is the exact tool-centre curve.

The canonical moves rs274 executes are rebuilt into the finishing pass (the
last run of feed moves at the full depth) and measured against the exact
offset of the bar's edge, ``cam.offset_curve(φ, r)``, both ways.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from camcad.design import load_design
from camcad.export.gcode import parse_canon
from camcad.geometry.cam import Cam
from camcad.geometry.families import family_of
from camcad.pipeline import analyse
from camcad.toolpath.moves import MoveKind
from tests.conftest import ROOT
from tests.readers.test_rs274 import RS274, errors, run_rs274

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        RS274 is None, reason="LinuxCNC's rs274 is not installed (Debian package linuxcnc-uspace)"
    ),
]


def segment_distance(points: np.ndarray, a: np.ndarray, ab: np.ndarray) -> np.ndarray:
    """Distance of each point (n, 2) to the nearest of the segments a + t·ab, t ∈ [0, 1] (m, 2)."""
    rel = points[:, None, :] - a[None, :, :]
    t = np.clip(np.einsum("nmk,mk->nm", rel, ab) / np.einsum("mk,mk->m", ab, ab), 0.0, 1.0)
    gap = rel - t[..., None] * ab[None, :, :]
    return np.min(np.hypot(gap[..., 0], gap[..., 1]), axis=1)


def test_rs274_runs_the_bar_program_and_its_finishing_pass_is_the_exact_offset(tmp_path):
    design = load_design(ROOT / "samples" / "linear_cam.toml")
    result = analyse(design)
    (part,) = result.parts
    assert part.gcode is not None
    proc, canon = run_rs274(part.gcode.text, design.gcode.tool_number, tmp_path)
    assert proc.returncode == 0, errors(proc)
    assert not errors(proc)
    moves = parse_canon(canon)
    assert not any(m.kind.is_arc for m in moves)  # G1 chords only
    depth = min(m.end[2] for m in moves)
    assert depth == pytest.approx(-(design.cam.thickness + design.gcode.breakthrough), abs=1e-4)
    # the finishing pass: the last run of feed moves at the full depth
    runs, run = [], []
    for m in moves:
        if (
            m.kind is MoveKind.LINE
            and m.start[2] == pytest.approx(depth)
            and m.end[2] == pytest.approx(depth)
        ):
            run.append(m)
        elif run:
            runs.append(run)
            run = []
    finish = runs[-1]
    path = np.array([m.start[:2] for m in finish] + [finish[-1].end[:2]])
    (designed,) = family_of(design.cam.style).parts(Cam.from_design(design), design.family_options())
    cam = designed.cam
    r = design.gcode.tool_radius
    exact = np.asarray(cam.offset_curve(np.linspace(0.0, 2 * np.pi, 40001), r).point)
    # exact -> path: distance to the nearest segment of the path (brute force over all segments)
    a, b = path[:-1], path[1:]
    ab = b - a
    d = np.concatenate([segment_distance(chunk, a, ab) for chunk in np.array_split(exact, 20)])
    assert float(np.max(d)) <= design.gcode.tolerance + 1e-4
    # path -> exact: every written vertex on the curve (within the tolerance) or on the leads beyond the ends
    inside = (path[:, 0] >= exact[0, 0]) & (path[:, 0] <= exact[-1, 0])
    dist, _ = cKDTree(exact).query(path[inside])
    assert float(np.max(dist)) <= design.gcode.tolerance + 1e-3
    # the tool never enters the bar: no vertex nearer the exact edge than the tool radius less the tolerance
    edge = np.asarray(cam.profile(np.linspace(0.0, 2 * np.pi, 40001)).point)
    gap, _ = cKDTree(edge).query(path)
    assert float(np.min(gap)) >= r - design.gcode.tolerance - 1e-3
