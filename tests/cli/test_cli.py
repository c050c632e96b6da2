"""The command line end to end: exit codes, one-line errors, all-or-nothing output."""

from __future__ import annotations

import csv
import hashlib
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from camcad.cli import main
from camcad.motion.laws import LAWS
from tests.conftest import ROOT

HARMONIC = (ROOT / "samples" / "quintero_harmonic.toml").read_text()
VAP = (ROOT / "samples" / "quintero_vap_b01.toml").read_text()
HREN = (ROOT / "samples" / "hren_tappet.toml").read_text()


def edit(text: str, pattern: str, replacement: str, count: int = 1) -> str:
    new, n = re.subn(pattern, replacement, text, count=count, flags=re.MULTILINE)
    assert n, pattern
    return new


def snapshot(folder: Path) -> dict[str, str]:
    """Every file below ``folder`` with a hash of its content."""
    if not folder.exists():
        return {}
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


BROKEN = {
    "not_toml": ("[cam\nbase_radius = ", 2, "not valid TOML"),
    "wrong_type": (edit(HARMONIC, r"^base_radius = .*$", 'base_radius = "forty"'), 2, "cam.base_radius"),
    "negative_radius": (
        edit(HARMONIC, r"^roller_radius = .*$", "roller_radius = -20.0"),
        2,
        "follower.roller_radius",
    ),
    "zero_thickness": (edit(HARMONIC, r"^thickness = .*$", "thickness = 0"), 2, "cam.thickness"),
    "unknown_law": (edit(HARMONIC, r'^law = "harmonic"', 'law = "harmonik"'), 2, "motion[0].law"),
    "not_360": (edit(HARMONIC, r"^angle = 90.0", "angle = 80.0"), 2, "360"),
    "lift_not_closing": ("lift = 25.0".join(HARMONIC.rsplit("lift = 30.0", 1)), 2, "does not close"),
    "return_below_base": (edit(HARMONIC, r"^lift = 30.0", "lift = 25.0"), 2, "below the base circle"),
    "bore_too_large": (edit(HARMONIC, r"^bore = .*$", "bore = 100.0"), 2, "cam.bore"),
    # a 30° harmonic rise: the pitch radius R²/(R + |a|) ≈ 13 mm at the top, below the 20 mm roller
    "undercut": (
        edit(edit(HARMONIC, r"^angle = 150.0", "angle = 30.0"), r"^angle = 90.0", "angle = 210.0"),
        3,
        "undercut",
    ),
    "b_equals_1": (edit(VAP, r"^b = 0.1", "b = 1.0"), 2, "motion[0].b"),
    "even_degree": (edit(HREN, r"^degree = 9", "degree = 8"), 2, "motion[0].degree"),
    "misspelt_key": (edit(HARMONIC, r"^roller_radius", "roler_radius"), 2, "did you mean 'roller_radius'"),
    "negative_lift": (edit(HARMONIC, r"^lift = 30.0", "lift = -30.0"), 2, "motion[0].lift"),
    "gouge": (edit(VAP, r"^tool_diameter = .*$", "tool_diameter = 130.0"), 3, "gouge"),
}


@pytest.fixture
def outdir(tmp_path: Path) -> Path:
    """An output folder that already holds a file from an earlier build."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text('{"old": true}\n')
    return out


@pytest.mark.parametrize("case", sorted(BROKEN))
def test_broken_designs_exit_cleanly_and_leave_outdir_as_it_was(case, tmp_path, outdir, capsys):
    text, code, words = BROKEN[case]
    design = tmp_path / f"{case}.toml"
    design.write_text(text)
    before = snapshot(tmp_path)
    assert main(["build", str(design), "-o", str(outdir), "--quiet"]) == code
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert words.lower() in err[0].lower()
    assert "Traceback" not in err[0]
    assert snapshot(tmp_path) == before


def test_missing_file_and_unwritable_output(tmp_path, capsys):
    assert main(["build", str(tmp_path / "nope.toml"), "-o", str(tmp_path / "o")]) == 2
    assert "not found" in capsys.readouterr().err
    blocker = tmp_path / "file"
    blocker.write_text("x")
    sample = ROOT / "samples" / "quintero_harmonic.toml"
    assert main(["build", str(sample), "-o", str(blocker / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--output" in err[0]
    assert blocker.read_text() == "x"


def test_build_writes_every_file_with_the_documented_columns(tmp_path, capsys):
    out = tmp_path / "vap"
    sample = ROOT / "samples" / "quintero_vap_b01.toml"
    assert main(["build", str(sample), "-o", str(out)]) == 0
    names = {p.name for p in out.iterdir()}
    assert names == {
        "profile.dxf",
        "profile_poly.dxf",
        "profile_arcs.dxf",
        "cam.stl",
        "cam.step",
        "cam.ngc",
        "points.csv",
        "lift.csv",
        "motion.csv",
        "profile.csv",
        "dynamics.csv",
        "summary.json",
        "report.html",
    }
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], "temporary folder left behind"
    err = capsys.readouterr().err
    for stage in ("geometry", "dynamics", "fit", "toolpath", "dxf", "mesh", "gcode", "report"):
        assert stage in err
    with open(out / "motion.csv", newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["angle_deg", "s_mm", "v_mm_per_rad", "a_mm_per_rad2", "j_mm_per_rad3"]
    angles = np.array([float(r[0]) for r in rows[1:]])
    np.testing.assert_allclose(angles, np.arange(3600) * 0.1, atol=1e-9)
    header = (out / "profile.csv").read_text().splitlines()[0]
    assert header == "angle_deg,pitch_x,pitch_y,x,y,nx,ny,pressure_angle_deg,rho_pitch_mm,rho_profile_mm"
    assert (out / "dynamics.csv").read_text().splitlines()[
        0
    ] == "angle_deg,contact_force_N,torque_Nmm,hertz_stress_MPa"
    summary = json.loads((out / "summary.json").read_text())
    for section in ("motion", "geometry", "dynamics", "fit", "gcode"):
        assert section in summary
    assert summary["motion"]["lift_mm"] == pytest.approx(30.0)
    assert summary["geometry"]["profile_radius_max_mm"] == pytest.approx(70.0)
    assert summary["fit"]["max_error_mm"] <= summary["fit"]["tolerance_mm"]
    joints = summary["motion"]["joints"]
    assert any("acceleration jumps by" in j["text"] for j in joints)


def test_only_limits_the_outputs(tmp_path):
    out = tmp_path / "o"
    assert (
        main(
            ["build", str(ROOT / "samples" / "quintero_harmonic.toml"), "-o", str(out), "-q", "--only", "dxf"]
        )
        == 0
    )
    assert {p.name for p in out.iterdir()} == {
        "profile.dxf",
        "profile_poly.dxf",
        "profile_arcs.dxf",
        "summary.json",
    }
    assert (
        main(
            ["build", str(ROOT / "samples" / "quintero_harmonic.toml"), "-o", str(out), "-q", "--only", "pdf"]
        )
        == 2
    )


def test_check_exit_codes(tmp_path, capsys):
    assert main(["check", str(ROOT / "samples" / "quintero_harmonic.toml")]) == 0
    out = capsys.readouterr().out
    for words in ("lift", "max pressure angle", "max torque", "max contact force", "fit control points"):
        assert words in out
    bad = tmp_path / "undercut.toml"
    bad.write_text(BROKEN["undercut"][0])
    assert main(["check", str(bad)]) == 3
    assert "undercut" in capsys.readouterr().out
    limit = tmp_path / "pressure.toml"
    limit.write_text(edit(HARMONIC, r"^max_pressure_angle = .*$", "max_pressure_angle = 10.0"))
    assert main(["check", str(limit)]) == 3
    assert "pressure angle" in capsys.readouterr().out
    wrong = tmp_path / "wrong.toml"
    wrong.write_text(BROKEN["unknown_law"][0])
    assert main(["check", str(wrong)]) == 2


def test_size_laws_and_version(capsys):
    assert main(["size", str(ROOT / "samples" / "offset_roller.toml")]) == 0
    assert "smallest base radius" in capsys.readouterr().out
    assert main(["laws"]) == 0
    listing = capsys.readouterr().out
    for name in LAWS:
        assert name in listing
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0


def test_the_installed_entry_point_runs(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "camcad", "check", str(ROOT / "samples" / "hren_tappet.toml")],
        capture_output=True,
        text=True,
        check=False,
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    proc = subprocess.run(
        [sys.executable, "-m", "camcad", "build"], capture_output=True, text=True, check=False
    )
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
