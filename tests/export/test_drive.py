"""Drive cam tables (cam_table.csv): values against the exact motion, layouts, units, the build.

Independent truths: the motion program evaluated at the master angles (the
table must hold exactly those values), central differences of the table's own
slave column over master degrees (velocity and acceleration per degree), and
Python's csv module reading the written file back.
"""

from __future__ import annotations

import csv
import math
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad.design import parse_design
from camcad.export.drive import drive_table
from camcad.export.spec import DriveLayout
from camcad.motion.program import MotionProgram
from camcad.pipeline import build


def packaging_design(**tables):
    return parse_design(
        {
            "cam": {"base_radius": 60, "thickness": 10, "speed_rpm": 60},
            "follower": {"roller_radius": 12},
            "motion": [
                {"kind": "dwell", "angle": 60},
                {"kind": "rise", "angle": 60, "lift": 10, "law": "polynomial"},
                {"kind": "rise", "angle": 60, "law": "constant-velocity", "velocity": 200},
                {"kind": "return", "angle": 120, "lift": "close", "law": "polynomial"},
                {"kind": "dwell", "angle": 60},
            ],
            "tables": tables,
        }
    )


@pytest.mark.parametrize("points", [12, 360, 1000])
def test_table_holds_the_exact_motion_at_each_master_angle(points):
    prog = MotionProgram.from_segments(packaging_design().motion)
    table = drive_table(prog, points)
    master = table["master_deg"]
    assert master.size == points + 1 and master[0] == 0.0 and master[-1] == 360.0
    m = prog.evaluate(np.radians(master[:-1]))
    assert_allclose(table["slave_mm"][:-1], m.s, atol=1e-12)
    assert_allclose(table["velocity_mm_per_deg"][:-1], m.v * math.pi / 180, atol=1e-12)
    assert_allclose(table["acceleration_mm_per_deg2"][:-1], m.a * (math.pi / 180) ** 2, atol=1e-12)
    for col in table.values():
        if col is not master:
            assert col[-1] == col[0]  # the period closes


def test_velocity_and_acceleration_are_per_master_degree():
    """Central differences of the slave column over master degrees (3600 steps) give the other columns."""
    prog = MotionProgram.from_segments(packaging_design().motion)
    t = drive_table(prog, 3600)
    s, step = t["slave_mm"], 0.1
    fd_v = (s[2:] - s[:-2]) / (2 * step)
    fd_a = (s[2:] - 2 * s[1:-1] + s[:-2]) / step**2
    assert_allclose(t["velocity_mm_per_deg"][1:-1], fd_v, atol=1e-5)
    assert_allclose(t["acceleration_mm_per_deg2"][1:-1], fd_a, atol=1e-4)


def test_layouts():
    prog = MotionProgram.from_segments(packaging_design().motion)
    full = drive_table(prog, 8)
    pairs = drive_table(prog, 8, layout=DriveLayout.MASTER_SLAVE)
    equi = drive_table(prog, 8, layout=DriveLayout.EQUIDISTANT, unit="deg")
    assert list(pairs) == ["master_deg", "slave_mm"]
    assert list(equi) == ["slave_deg"]
    assert_allclose(pairs["slave_mm"], full["slave_mm"])
    assert_allclose(equi["slave_deg"], full["slave_mm"])
    assert np.all(np.diff(pairs["master_deg"]) > 0)  # strictly ascending master (MC_TABLETYPE_NONEQUIDISTANT)


def test_build_writes_cam_table_csv_read_back(tmp_path):
    design = packaging_design(cam_table_points=360, cam_table_layout="full")
    result = build(design, tmp_path / "out", only=["tables"])
    path = tmp_path / "out" / "cam_table.csv"
    assert path in result.files
    with path.open(newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["master_deg", "slave_mm", "velocity_mm_per_deg", "acceleration_mm_per_deg2"]
    data = np.array(rows[1:], dtype=float)
    assert data.shape == (361, 4)
    prog = MotionProgram.from_segments(design.motion)
    m = prog.evaluate(np.radians(data[:-1, 0]))
    assert_allclose(data[:-1, 1], m.s, rtol=0.0, atol=5e-10 + 1e-12)  # nine decimals
    # the constant-velocity stretch: 200 mm/s at 60 rpm = 360°/s is 200/360 mm per master degree
    stretch = (data[:, 0] > 121) & (data[:, 0] < 179)
    assert_allclose(data[stretch, 2], 200 / 360, rtol=0.0, atol=5e-10 + 1e-12)


def test_no_cam_table_unless_asked(tmp_path):
    result = build(packaging_design(), tmp_path / "out", only=["tables"])
    assert not (tmp_path / "out" / "cam_table.csv").exists()
    assert all(p.name != "cam_table.csv" for p in result.files)


CELL = re.compile(r"-?[0-9]+\.[0-9]{9}")


def _cam_table_designs():
    from tests.conftest import SAMPLES

    shipped = [(p.stem, p) for p in SAMPLES if "cam_table_points" in p.read_text(encoding="utf-8")]
    return [*shipped, ("packaging", None)]


@pytest.mark.parametrize(
    ("name", "path"), _cam_table_designs(), ids=lambda x: x if isinstance(x, str) else ""
)
def test_every_cam_table_cell_is_fixed_notation_within_its_decimals(name, path, tmp_path):
    """Issue 31: no e-notation (``-1.66533454e-15`` before), no ``-0``; every cell within 0.5e-9 of the
    motion program evaluated here at the master angle (v, a per master degree by the chain rule)."""
    from camcad.design import load_design

    design = packaging_design(cam_table_points=3600) if path is None else load_design(path)
    build(design, tmp_path / "out", only=["tables"])
    with (tmp_path / "out" / "cam_table.csv").open(newline="") as fh:
        rows = list(csv.reader(fh))
    cells = [c for row in rows[1:] for c in row]
    assert cells and all(CELL.fullmatch(c) for c in cells), [c for c in cells if not CELL.fullmatch(c)][:5]
    assert not any(c.startswith("-") and float(c) == 0.0 for c in cells)
    data = np.array(rows[1:], dtype=float)
    n = design.tables.cam_table_points
    master = np.arange(n + 1) * (360.0 / n)
    m = MotionProgram.from_segments(design.motion).evaluate(np.radians(master[:-1]))
    exact = {"master_deg": master[:-1], "slave": m.s, "velocity": m.v * math.pi / 180}
    exact["acceleration"] = m.a * (math.pi / 180) ** 2
    for k, head in enumerate(rows[0]):
        want = next(v for key, v in exact.items() if head.startswith(key))
        assert_allclose(data[:-1, k], want, rtol=0.0, atol=5e-10 + 1e-12 * np.abs(want).max(), err_msg=head)
