"""``camcad inspect``: measured files made from the exact profile with known errors, through the CLI.

Truths: the injected turn, centre offset and defects (the points made
outside the band) are known independently of the fit; the compensated
program is read by LinuxCNC's ``rs274`` and its tool path is measured by
brute force against a dense polygon of the design's exact profile: it must
sit a tool radius off the design minus the injected waviness.
"""

from __future__ import annotations

import csv
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from camcad.cli import main
from camcad.design import load_design
from camcad.export.gcode import parse_canon
from camcad.geometry.cam import Cam
from tests.conftest import ROOT

SAMPLE = ROOT / "samples" / "tolerance_roller.toml"
MEASURED = ROOT / "samples" / "tolerance_roller_measured.csv"
CAM = Cam.from_design(load_design(SAMPLE))
ISSUE_TOML = """[cam]
name = "issue 38 case"
base_radius = 40.0
thickness = 8.0
[follower]
type = "translating-roller"
roller_radius = 10.0
offset = 8.0
[[motion]]
kind = "rise"
angle = 150.0
lift = 20.0
law = "cycloidal"
[[motion]]
kind = "dwell"
angle = 30.0
[[motion]]
kind = "return"
angle = 150.0
lift = 20.0
law = "cycloidal"
[[motion]]
kind = "dwell"
angle = 30.0
"""
RS274 = shutil.which("rs274")
DEFECTS = {40: 0.05, 200: -0.05, 333: 0.06, 500: -0.045, 611: 0.07}
HEADER_LINES = 2  # a comment and the header precede the first point


def _turn(points: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return points @ np.array([[c, -s], [s, c]]).T


def _scan(
    *,
    n: int = 720,
    phase_deg: float = 0.3,
    centre: tuple[float, float] = (0.020, 0.0),
    wave: float = 0.010,
    lobes: int = 7,
    noise: float = 0.002,
    defects: dict[int, float] | None = None,
    seed: int = 0,
    cam: Cam = CAM,
) -> tuple[np.ndarray, np.ndarray]:
    """Points evenly spaced in cam angle, shuffled as a CMM might list them; and their true deviations."""
    rng = np.random.default_rng(seed)
    u = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    prof = cam.profile(u)
    dev = wave * np.sin(lobes * u) + rng.normal(0.0, noise, n)
    for i, extra in (defects or {}).items():
        dev[i] += extra
    pts = _turn(prof.point + dev[:, None] * prof.normal, math.radians(phase_deg)) + np.asarray(centre)
    order = rng.permutation(n)
    return pts[order], dev[order]


def _write(path: Path, points: np.ndarray, header: str = "x,y") -> Path:
    lines = ["# made by tests/cli/test_inspect_cli.py", header]
    lines += [f"{float(x)!r},{float(y)!r}" for x, y in points]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _csv(path: Path) -> list[dict[str, str]]:
    with path.open(newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def test_the_fit_recovers_phase_and_offset_and_flags_exactly_the_defects(tmp_path, capsys):
    """Issue 38: 0.3° turn, 20 µm offset, 10 µm waviness, 2 µm noise: 0.01° and 1 µm; defects: exit 3."""
    design = tmp_path / "issue.toml"
    design.write_text(ISSUE_TOML, encoding="utf-8")
    pts, dev = _scan(defects=DEFECTS, cam=Cam.from_design(load_design(design)))
    measured = _write(tmp_path / "scan.csv", pts)
    code = main(["inspect", str(design), str(measured), "--band", "0.02", "-o", str(tmp_path / "o")])
    out = capsys.readouterr().out
    assert code == 3, out
    summary = json.loads((tmp_path / "o" / "inspection.json").read_text(encoding="utf-8"))
    assert abs(summary["fit"]["rotation_deg"] - 0.3) < 0.01
    assert math.hypot(summary["fit"]["centre_mm"][0] - 0.020, summary["fit"]["centre_mm"][1]) < 0.001
    assert summary["passed"] is False and summary["outside"] == len(DEFECTS)
    rows = _csv(tmp_path / "o" / "inspection.csv")
    assert [int(r["line"]) for r in rows] == list(range(HEADER_LINES + 1, HEADER_LINES + 1 + len(pts)))
    flagged = {int(r["line"]) for r in rows if r["in_band"] == "false"}
    truth = {HEADER_LINES + 1 + i for i in np.flatnonzero(np.abs(dev) > 0.02)}
    assert flagged == truth and len(truth) == len(DEFECTS)
    assert sorted(summary["outside_lines"]) == sorted(truth)
    np.testing.assert_allclose([float(r["deviation_mm"]) for r in rows], dev, atol=0.001)
    assert f"outside its band at {len(DEFECTS)} points" in out
    motion = _csv(tmp_path / "o" / "actual_motion.csv")
    assert len(motion) == Cam.from_design(load_design(design)).sample_phi().size
    lift_err = np.array([float(r["lift_actual_mm"]) - float(r["lift_mm"]) for r in motion])
    assert (
        0.005 < np.max(np.abs(lift_err)) < 0.02
    )  # the 10 µm waviness moves the follower, the defects do not
    page = (tmp_path / "o" / "inspection.html").read_text(encoding="utf-8")
    assert 'id="polar"' in page and 'id="motion"' in page and "OUTSIDE" in page


def test_a_good_part_in_polar_columns_passes_with_the_design_band(tmp_path, capsys):
    """angle/radius columns about a CMM centre; the band from the design's form_pm (±10 µm)."""
    pts, _ = _scan(phase_deg=123.0, centre=(500.0, -300.0), wave=0.004, noise=0.001)
    rel = pts - [500.0, -300.0]
    polar = np.column_stack((np.degrees(np.arctan2(rel[:, 1], rel[:, 0])), np.hypot(rel[:, 0], rel[:, 1])))
    measured = _write(tmp_path / "polar.csv", polar, header="Angle [deg]; Radius [mm]")
    text = measured.read_text(encoding="utf-8").replace(",", ";")
    measured.write_text(text, encoding="utf-8")
    assert main(["inspect", str(SAMPLE), str(measured), "-o", str(tmp_path / "o")]) == 0
    summary = json.loads((tmp_path / "o" / "inspection.json").read_text(encoding="utf-8"))
    assert summary["layout"] == "polar" and summary["band_mm"] == [-0.01, 0.01]
    assert abs(summary["fit"]["rotation_deg"] - 123.0) < 0.01
    assert math.hypot(*summary["fit"]["centre_mm"]) < 0.001  # polar about (500, −300): the axis at its origin
    assert "within its band" in capsys.readouterr().out


def test_the_shipped_measured_sample_through_the_installed_entry(tmp_path):
    run = subprocess.run(
        [sys.executable, "-m", "camcad", "inspect", str(SAMPLE), str(MEASURED), "-o", str(tmp_path / "o")],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert run.returncode == 0, run.stderr
    assert "the part is within its band" in run.stdout
    assert {p.name for p in (tmp_path / "o").iterdir()} == {
        "inspection.csv",
        "inspection.json",
        "actual_motion.csv",
        "inspection.html",
    }


def _refused(tmp_path: Path, capsys: pytest.CaptureFixture[str], measured: Path, *extra: str) -> str:
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    (out / "keep.txt").write_text("old", encoding="utf-8")
    code = main(["inspect", str(SAMPLE), str(measured), "--band", "0.02", "-o", str(out), *extra])
    err = capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["keep.txt"]  # the folder as it was
    assert len(err.strip().splitlines()) == 1, err
    return f"{code} {err.strip()}"


def test_a_file_in_inches_exits_2_with_a_clear_message(tmp_path, capsys):
    pts, _ = _scan(wave=0.0)
    measured = _write(tmp_path / "inches.csv", pts / 25.4)
    said = _refused(tmp_path, capsys, measured)
    assert said.startswith(f"2 camcad: error: {measured}: the points are 0.0394 times the size"), said
    assert "they look like inches: multiply by 25.4" in said


@pytest.mark.parametrize(
    ("body", "words"),
    [
        ("x,y\n1,2\n3,oops\n", "line 3: y 'oops' is not a number"),
        ("x,y\n1,2\n3,inf\n", "line 3: y 'inf' is not finite"),
        ("x_in,y_in\n1,2\n", "line 1: column 'x_in' is in 'in'; allowed: mm"),
        ("u,v\n1,2\n", "line 1: header 'u, v' names no point columns"),
        ("x,y\n" + "1,2\n" * 3, "3 points; allowed: at least 24"),
        ("# only a comment\n", "no header line"),
    ],
)
def test_bad_measured_files_exit_2_naming_the_file_and_line(tmp_path, capsys, body, words):
    measured = tmp_path / "bad.csv"
    measured.write_text(body, encoding="utf-8")
    said = _refused(tmp_path, capsys, measured)
    assert said.startswith(f"2 camcad: error: {measured}: ") and words in said, said


def test_duplicated_points_and_a_partial_scan_name_their_lines(tmp_path, capsys):
    pts, _ = _scan(wave=0.0, n=120)
    dup = pts.copy()
    dup[17] = dup[5]
    said = _refused(tmp_path, capsys, _write(tmp_path / "dup.csv", dup))
    assert f"lines {HEADER_LINES + 1 + 5} and {HEADER_LINES + 1 + 17} are the same point" in said, said
    centre = pts.mean(axis=0)
    keep = np.arctan2(pts[:, 1] - centre[1], pts[:, 0] - centre[0]) < 1.5  # a quarter turn left out
    said = _refused(tmp_path, capsys, _write(tmp_path / "part.csv", pts[keep]))
    assert said.startswith("2 ") and "the scan covers only" in said, said


def test_a_folder_or_a_device_is_not_read(tmp_path, capsys):
    said = _refused(tmp_path, capsys, Path("/dev/zero"))
    assert said.startswith("2 camcad: error: /dev/zero: ") and "regular file" in said, said


def _compensated(tmp_path: Path, *extra: str) -> tuple[int, Path]:
    design = tmp_path / "d.toml"
    text = SAMPLE.read_text(encoding="utf-8").replace(
        "step_down = 5.0", "step_down = 5.0\ntolerance = 0.002\nstock_to_leave = 0.0"
    )
    design.write_text(text, encoding="utf-8")
    pts, _ = _scan(wave=0.040, lobes=5, noise=0.001, centre=(0.0, 0.0), phase_deg=0.0)
    measured = _write(tmp_path / "worn.csv", pts)
    code = main(["inspect", str(design), str(measured), "--band", "0.1", "-o", str(tmp_path / "o"), *extra])
    return code, tmp_path / "o"


@pytest.mark.skipif(
    RS274 is None, reason="LinuxCNC's rs274 is not installed (Debian package linuxcnc-uspace)"
)
def test_the_compensated_program_runs_in_rs274_and_removes_the_waviness(tmp_path):
    """40 µm of 5-lobe waviness: the corrected path is a tool radius off the design minus that waviness."""
    code, out = _compensated(tmp_path, "--stock", "0.1", "--tool-diameter", "8")
    assert code == 0
    assert (out / "profile.dxf").read_bytes().startswith(b"  0\nSECTION")
    tools = tmp_path / "tools.tbl"
    tools.write_text("T1 P1 Z0 D0.25 ;camcad test tool\n", encoding="ascii")
    canon = tmp_path / "canon.txt"
    proc = subprocess.run(
        [RS274, "-t", str(tools), "-g", str(out / "cam.ngc"), str(canon)],
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    noise = [
        ln for ln in (proc.stdout + proc.stderr).splitlines() if ln.strip() and ln.strip() != "executing"
    ]
    assert proc.returncode == 0 and not noise, noise
    moves = parse_canon(canon.read_text(encoding="ascii"))
    ends = np.array([m.end[:2] for m in moves if m.kind.name != "RAPID"])
    phi = np.linspace(0.0, 2 * np.pi, 72_000, endpoint=False)  # a 0.005° polygon: chord error ≈ 1e-8 mm
    dense = CAM.profile(phi).point
    dist, k = cKDTree(dense).query(ends)
    radius = 4.0
    on = np.abs(dist - radius) < 0.2  # the contour's points (the leads lie farther out)
    assert np.count_nonzero(on) > 50
    # the fit cannot tell the waviness's rigid part (N·δ, δ the fitted frame's move) from a frame: it stays
    fit = json.loads((out / "inspection.json").read_text(encoding="utf-8"))["fit"]
    theta = math.radians(fit["rotation_deg"])
    prof = CAM.profile(phi[k[on]])
    moved = _turn(prof.point, theta) + np.asarray(fit["centre_mm"]) - prof.point
    rigid = np.einsum("ij,ij->i", moved, prof.normal)
    wave = 0.040 * np.sin(5 * phi[k[on]]) - rigid
    np.testing.assert_allclose(dist[on] - radius, -wave, atol=0.002 + 0.001)  # G-code tolerance + smoothing
    assert np.max(np.abs(dist[on] - radius)) > 0.03  # the correction is really in the path


def test_a_correction_beyond_the_stock_is_refused_and_nothing_is_written(tmp_path, capsys):
    code, out = _compensated(tmp_path, "--stock", "0.01")
    err = capsys.readouterr().err
    assert code == 3 and "beyond the stock 10 µm" in err, err
    assert not out.exists()
    code, out = _compensated(tmp_path, "--tool-diameter", "8")
    assert code == 2 and "--tool-diameter: a compensated program needs --stock too" in capsys.readouterr().err
