"""LinuxCNC's ``rs274`` runs every rotary program (X + A/C in G93), and its motion passes the proof.

The standalone interpreter's machine has the axes X Y Z A B C (its canon
reports an axis mask of 0x3f and angles in degrees), so no INI file is
needed for A or C. It insists on F in every G93 feed block ("F word missing
with inverse time g1 move"). Its canonical output has
``STRAIGHT_FEED(x, y, z, a, b, c)`` and ``SET_FEED_RATE(f)``, f being the raw
inverse-time F in G93 (feed mode changes appear as comments
``interpreter: feed mode set to inverse time`` / ``units per minute``).

From that output alone each cut is rebuilt the way a controller moves (X and
the rotary axis linear in time within a block), mapped into the cam frame
(the tool at (X, 0) seen on a cam turned by θ is at R(−θ)·(X, 0)) and
measured against a dense polygon of the exact offset curve; each G93 block's
time 1/F is checked against the length of profile its contact runs over,
found independently (the block's end points located on a dense exact curve,
the profile between them measured as a fine polyline).
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from camcad.design import load_design, parse_design
from camcad.export.gcode.rotary import render_rotary
from camcad.geometry.cam import Cam
from camcad.toolpath.rotary import plan_rotary
from camcad.toolpath.spec import Dialect, Machine
from tests.conftest import SAMPLES, distance_to_polygon, make_design
from tests.readers.test_rs274 import RS274, errors, run_rs274

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        RS274 is None, reason="LinuxCNC's rs274 is not installed (Debian package linuxcnc-uspace)"
    ),
]

_CALL = re.compile(r"([A-Z_]+)\((.*)\)")
DENSE = 60_000


def canon_moves(canon: str, axis: str) -> list[dict]:
    """Every move of the canonical output: kind, start/end (x, z, rotary), feed mode and F in force."""
    col = {"A": 3, "C": 5}[axis]
    pos, feed, inverse, out = (0.0, 0.0, 0.0), 0.0, False, []
    for line in canon.splitlines():
        m = _CALL.search(line.split("N.....", 1)[-1])
        if not m:
            continue
        name, args = m.group(1), m.group(2)
        if name == "COMMENT" and "feed mode set to" in args:
            inverse = "inverse time" in args
        elif name == "SET_FEED_RATE":
            feed = float(args)
        elif name in ("STRAIGHT_FEED", "STRAIGHT_TRAVERSE"):
            v = [float(a) for a in args.split(",")]
            assert v[1] == 0.0  # the tool centre stays on the X line
            end = (v[0], v[2], v[col])
            out.append({"kind": name, "start": pos, "end": end, "inverse": inverse, "feed": feed})
            pos = end
        elif name == "ARC_FEED":
            raise AssertionError("a rotary program has no arcs")
    return out


def rebuild(moves: list[dict], sign: float, spacing: float = 0.01) -> np.ndarray:
    """The G93 cut in the cam frame: X and the rotary axis linear within each block."""
    pts = []
    for mv in moves:
        (x0, _, a0), (x1, _, a1) = mv["start"], mv["end"]
        n = max(8, math.ceil(abs(math.radians(a1 - a0)) * max(x0, x1) / spacing))
        t = np.arange(n) / n
        x, theta = x0 + (x1 - x0) * t, np.radians(sign * (a0 + (a1 - a0) * t))
        pts.append(np.column_stack((x * np.cos(-theta), x * np.sin(-theta))))
    return np.concatenate(pts)


def proven(design, text: str, tmp_path: Path, *, dialect_end: str = "M2") -> list[dict]:
    """rs274 accepts the program; its G93 cut stays within tolerance of the exact curve; F gives the times."""
    spec = design.gcode
    proc, canon = run_rs274(text, spec.tool_number, tmp_path)
    assert proc.returncode == 0, errors(proc)
    assert not errors(proc)
    assert "PROGRAM_END" in canon
    moves = canon_moves(canon, spec.rotary_axis.value)
    cuts = [m for m in moves if m["inverse"]]
    assert cuts and all(m["kind"] == "STRAIGHT_FEED" for m in cuts)
    assert not moves[-1]["inverse"]  # back in G94 (units per minute) at the end
    assert text.rstrip().endswith(dialect_end)
    cam = Cam.from_design(design)
    sign = 1.0 if spec.rotary_direction.value == "ccw" else -1.0
    phi = np.linspace(0.0, 2.0 * math.pi, DENSE, endpoint=False)
    exact = cam.offset_curve(phi, spec.tool_radius).point
    profile = cam.offset_curve(phi, 0.0).point
    levels = list(dict.fromkeys(m["end"][1] for m in cuts))  # in cutting order, top first
    revolution = len(cuts) // len(levels)
    first = cuts[:revolution]
    path = rebuild(first, sign)
    hausdorff = max(distance_to_polygon(path, exact).max(), distance_to_polygon(exact, path).max())
    assert hausdorff <= spec.tolerance
    assert (distance_to_polygon(path, profile) - spec.tool_radius).min() >= -spec.tolerance  # no gouge
    turn = first[-1]["end"][2] - first[0]["start"][2]
    assert abs(turn) == pytest.approx(360.0, abs=1e-6)
    for k, z in enumerate(levels):  # every level repeats the proven revolution, one turn further on
        rev = cuts[k * revolution : (k + 1) * revolution]
        assert all(m["start"][1] == z == m["end"][1] for m in rev)
        assert [m["end"][0] for m in rev] == [m["end"][0] for m in first]
        assert np.allclose([m["end"][2] - k * turn for m in rev], [m["end"][2] for m in first], atol=1e-4)
    # block times: 1/F minutes = contact length / feed, the contact length found independently
    fine = np.linspace(0.0, 2.0 * math.pi, 20 * DENSE, endpoint=False)  # ~3e-4 mm apart
    tree = cKDTree(cam.offset_curve(fine, spec.tool_radius).point)
    fine_profile = cam.offset_curve(fine, 0.0).point
    step = np.hypot(*np.diff(np.vstack((fine_profile, fine_profile[:1])), axis=0).T)
    arc = np.concatenate(([0.0], np.cumsum(step)))  # profile length from φ = 0 on the fine grid
    perimeter = arc[-1]

    def arc_at(x: float, a: float) -> float:
        theta = math.radians(sign * a)
        _, i = tree.query([x * math.cos(-theta), x * math.sin(-theta)])
        return float(arc[int(i)])

    for m in cuts[:revolution]:
        start, end = arc_at(m["start"][0], m["start"][2]), arc_at(m["end"][0], m["end"][2])
        length = min((end - start) % perimeter, (start - end) % perimeter)
        # rs274 turns F into a rate over the block's X length, or its rotary length when X stands still,
        # and never below 0.1 (Interp::inverse_time_rate_straight): the block takes length / rate minutes
        dx, da = abs(m["end"][0] - m["start"][0]), abs(m["end"][2] - m["start"][2])
        assert m["feed"] > 0.1  # not clamped: the block runs in the time it was given
        minutes = (dx if dx > 0.0 else da) / m["feed"]
        assert minutes * spec.feed == pytest.approx(length, rel=2e-3, abs=2e-3)
    return cuts


def rotary_design(design, **gcode):
    raw = {
        "cam": {"base_radius": design.cam.base_radius, "thickness": design.cam.thickness},
        "follower": {"type": "translating-roller", "roller_radius": 10.0},
        "motion": [{"kind": "dwell", "angle": 360.0}],
        "gcode": {"machine": "rotary", **gcode},
    }
    return replace(design, gcode=parse_design(raw).gcode)


def plan_text(design, dialect=None) -> str:
    cam = Cam.from_design(design)
    tp = plan_rotary(cam, design.gcode, name=design.cam.name, thickness=design.cam.thickness)
    return render_rotary(tp, dialect)


CONFIGS = {
    "A-climb-ccw-end-mill": {},
    "C-conventional-cw-wheel": {
        "rotary_axis": "C",
        "direction": "conventional",
        "rotary_direction": "cw",
        "cutter": "wheel",
        "tool_diameter": 20.0,
        "tool_number": 7,
    },
    "A-fine-start-200-coolant": {"tolerance": 0.001, "start_angle": 200.0, "coolant": True, "step_down": 4.0},
}


@pytest.mark.parametrize("dialect", ["linuxcnc", "generic"])
@pytest.mark.parametrize("config", list(CONFIGS))
def test_rs274_runs_the_rotary_program_and_its_motion_passes_the_proof(config, dialect, tmp_path):
    design = rotary_design(make_design(law="poly-345", offset=4.0), **CONFIGS[config])
    cuts = proven(
        design, plan_text(design, dialect), tmp_path, dialect_end="M2" if dialect == "linuxcnc" else "M30"
    )
    levels = {m["end"][1] for m in cuts}
    assert len(levels) == (
        1 if design.gcode.cutter.value == "wheel" else math.ceil(8.5 / design.gcode.step_down)
    )


@pytest.mark.parametrize(
    "path",
    [p for p in SAMPLES if p.stem in ("offset_roller", "hren_tappet", "packaging_rocker")],
    ids=lambda p: p.stem,
)
def test_rs274_runs_samples_as_rotary_programs(path, tmp_path):
    """A slide with offset, a flat tappet and a swinging-arm roller, each turned past an end mill."""
    design = load_design(path)
    design = replace(design, gcode=replace(design.gcode, machine=Machine.ROTARY, dialect=Dialect.LINUXCNC))
    proven(design, plan_text(design), tmp_path)


def test_rs274_circular_cam_is_a_constant_x_rotation(tmp_path):
    design = rotary_design(parse_design({
        "cam": {"base_radius": 30.0, "thickness": 6.0},
        "follower": {"type": "translating-roller", "roller_radius": 10.0},
        "motion": [{"kind": "dwell", "angle": 360.0}],
    }), cutter="wheel", tool_diameter=12.0)  # fmt: skip
    cuts = proven(design, plan_text(design), tmp_path)
    assert {m["end"][0] for m in cuts} == {36.0}


def test_rs274_refuses_a_g93_block_without_f(tmp_path):
    """The harness is not vacuous: drop the F of one G93 block and rs274 stops."""
    design = rotary_design(make_design(law="poly-345", offset=4.0))
    lines = plan_text(design).splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("G1 ") and " A" in line and " F" in line)
    lines[k] = " ".join(w for w in lines[k].split() if not w.startswith("F"))
    proc, _ = run_rs274("\n".join(lines) + "\n", 1, tmp_path)
    assert proc.returncode != 0
    assert any("F word missing" in line for line in errors(proc))
