"""Barrel cams from a design file, end to end (issue 36): ``camcad build`` and ``camcad check``.

Independent truths:

- each sample's ``cam.step`` read back by OpenCASCADE's STEP reader is one solid that
  ``BRepCheck_Analyzer`` finds valid, of the volume a quadrature of the exact groove gives
  (tests/barrel_cases.py, which meshes nothing and fits nothing);
- ``cam.stl`` is watertight for trimesh, of the same volume within the polygons' sag;
- ``profile.dxf`` read by ezdxf has both walls, and on a translating roller's barrel each is
  the developed pitch line (t_p·φ, z0 + s) offset by ±(r_f + c/2) along its normal, computed
  here from the motion alone;
- ``cam.ngc`` runs in LinuxCNC's ``rs274`` (when installed) with the passes the summary counts;
- tan α = s′/r: a cycloidal 50 mm rise over 90° has s′max = 2h/β = 63.66 mm/rad, so the
  pressure angle is 51.9°, 46.7° and 42.3° at r = 50, 60 and 70 mm (Norton 2009, eq. 8.1,
  the barrel's radius in place of the prime circle's);
- bad input exits 2 naming the field; the same input gives the same bytes.
"""

from __future__ import annotations

import json
import math
import shutil
from functools import cache
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import tomllib

from camcad.cli import main
from camcad.design import load_design, parse_design
from camcad.pipeline import analyse
from tests.barrel_cases import CASES, assert_same_outputs, barrel_volume, step_solid_volume
from tests.conftest import ROOT, distance_to_polygon

SAMPLES = {"indexer": ROOT / "samples" / "barrel_indexer.toml", "arm": ROOT / "samples" / "barrel_arm.toml"}
FILES = ("profile.dxf", "cam.stl", "cam.step", "cam.ngc", "summary.json", "report.html")


@cache
def built(name: str, folder: Path) -> Path:
    out = folder / name
    assert main(["build", str(SAMPLES[name]), "-o", str(out), "-q"]) == 0
    return out


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("barrel")


@pytest.mark.parametrize("name", list(SAMPLES))
def test_build_writes_every_file_and_the_summary_gives_the_barrel(name, folder):
    out = built(name, folder)
    for f in FILES:
        assert (out / f).stat().st_size > 0, f
    for plate_only in ("profile_poly.dxf", "profile_arcs.dxf"):
        assert not (out / plate_only).exists()
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    barrel = summary["barrel"]
    case = CASES[name].options
    assert barrel["stations_mm"] == {
        "bottom": case.barrel_radius - case.depth,
        "pitch": case.barrel_radius - 0.5 * case.roller_length,
        "top": case.barrel_radius,
    }
    angles = [barrel["pressure_angle_max"][k]["value_deg"] for k in ("bottom", "pitch", "top")]
    assert angles[0] > angles[1] > angles[2] > 0.0  # largest at the groove's bottom
    assert summary["geometry"]["pressure_angle_max_deg"] == pytest.approx(angles[1], abs=1e-6)
    assert "profile_radius_min_mm" not in summary["geometry"]  # a developed plane has no radius
    assert summary["fit"]["certified"] and summary["fit"]["max_error_mm"] <= summary["fit"]["tolerance_mm"]
    assert summary["gcode"]["blocks"] > 100
    assert barrel["slip"]["across_max"]["value_mm_per_rad"] > 0.0
    report = (out / "report.html").read_text(encoding="utf-8")
    for key in ("profile", "barrel-pressure", "barrel-3d"):  # the developed groove is the drawing
        assert f'id="plot-{key}"' in report, key
    assert "Developed groove" in report and 'id="plot-solid"' not in report  # no plate's solid


def test_a_translating_cylinders_slip_is_the_closed_form(folder):
    """In a dwell the barrel's surface runs at ω·t, the roller at ω·t_p: slip ω·|t − t_p| at its ends."""
    barrel = json.loads((built("indexer", folder) / "summary.json").read_text(encoding="utf-8"))["barrel"]
    o = CASES["indexer"].options
    # across = √(t_p² + s′²) − √(t² + s′²) is largest at the end farthest from t_p, where s′ = 0 (a dwell)
    assert barrel["slip"]["across_max"]["value_mm_per_rad"] == pytest.approx(0.5 * o.roller_length, rel=1e-9)


@pytest.mark.parametrize("name", list(SAMPLES))
def test_step_reads_back_as_one_valid_solid_of_the_exact_volume(name, folder):
    assert step_solid_volume(built(name, folder) / "cam.step") == pytest.approx(
        barrel_volume(CASES[name]), rel=2e-5
    )


@pytest.mark.parametrize("name", list(SAMPLES))
def test_stl_is_watertight_and_of_the_exact_volume(name, folder):
    trimesh = pytest.importorskip("trimesh")
    mesh = trimesh.load(built(name, folder) / "cam.stl", force="mesh")
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume == pytest.approx(barrel_volume(CASES[name]), rel=2e-4)


def test_dxf_has_both_walls_at_the_closed_form_offsets_of_the_pitch_line(folder):
    case = CASES["indexer"]
    o = case.options
    doc = ezdxf.readfile(built("indexer", folder) / "profile.dxf")
    msp = doc.modelspace()
    phi = np.linspace(0.0, 2.0 * math.pi, 20_001)
    m = case.program.evaluate(phi)
    tp, r_w = o.pitch_station, o.roller_radius + 0.5 * o.clearance
    z0 = case.follower.axial_position
    # the developed pitch line (t_p·φ, z0 + s), its tangent (t_p, s′) and normal (−s′, t_p)/|…|
    norm = np.hypot(tp, m.v)
    normal = np.column_stack((-m.v, np.full_like(phi, tp))) / norm[:, None]
    pitch = np.column_stack((tp * phi, z0 + m.s))
    for layer, sign in (("WALL_UPPER", 1.0), ("WALL_LOWER", -1.0)):
        (spline,) = msp.query(f'SPLINE[layer=="{layer}"]')
        pts = np.array([(x, y) for x, y, _ in spline.construction_tool().approximate(20_000)])
        exact = pitch + sign * r_w * normal
        dist = distance_to_polygon(exact, pts)  # to the polyline's segments (it spans 0 … 2π)
        assert dist.max() <= 2e-3, layer  # the fit's tolerance + the 20 000-chord polyline's sag


def test_ngc_runs_in_rs274_with_every_pass(folder, tmp_path):
    rs274 = shutil.which("rs274")
    if rs274 is None:
        pytest.skip("rs274 is not installed")
    from tests.readers.conftest import run
    from tests.readers.test_barrel_readers import canon_passes

    out = built("indexer", folder)
    shutil.copy(out / "cam.ngc", tmp_path / "cam.ngc")
    (tmp_path / "tools.tbl").write_text("T1 P1 Z0 D10 ;rough\nT2 P2 Z0 D16 ;finish\n", encoding="ascii")
    proc = run([rs274, "-t", "tools.tbl", "-g", "cam.ngc", "canon.txt"], cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    canon = (tmp_path / "canon.txt").read_text(encoding="ascii")
    assert "PROGRAM_END" in canon
    kinds = [p["kind"] for p in canon_passes(canon)]
    assert kinds[-2:] == ["finish upper", "finish lower"] and set(kinds[:-2]) == {"rough"}


def _cycloid_design(barrel_radius: float, depth: float, roller_length: float) -> dict:
    return {
        "cam": {
            "style": "barrel",
            "barrel_radius": barrel_radius,
            "length": 100.0,
            "max_pressure_angle": 60.0,
        },
        "groove": {"depth": depth, "clearance": 0.0},
        "follower": {
            "type": "translating-roller",
            "roller_radius": 5.0,
            "roller_length": roller_length,
            "axial_position": 20.0,
        },
        "motion": [
            {"kind": "rise", "law": "cycloidal", "angle": 90.0, "lift": 50.0},
            {"kind": "dwell", "angle": 90.0},
            {"kind": "return", "law": "cycloidal", "angle": 90.0, "lift": 50.0},
            {"kind": "dwell", "angle": 90.0},
        ],
    }


def test_pressure_angle_is_atan_of_s_prime_over_r_at_50_60_70_mm():
    s_max = 2.0 * 50.0 / (math.pi / 2.0)  # cycloidal: s′max = 2h/β [mm/rad]
    assert s_max == pytest.approx(63.66, abs=5e-3)
    expected = {r: math.degrees(math.atan(s_max / r)) for r in (50.0, 60.0, 70.0)}
    assert [round(expected[r], 1) for r in (50.0, 60.0, 70.0)] == [51.9, 46.7, 42.3]
    deep = analyse(parse_design(_cycloid_design(70.0, 20.0, 10.0)), fit=False, toolpath=False)
    shallow = analyse(parse_design(_cycloid_design(60.0, 10.0, 5.0)), fit=False, toolpath=False)
    got = {
        50.0: deep.summary()["barrel"]["pressure_angle_max"]["bottom"],
        70.0: deep.summary()["barrel"]["pressure_angle_max"]["top"],
        60.0: shallow.summary()["barrel"]["pressure_angle_max"]["top"],
    }
    for r, ext in got.items():
        assert ext["value_deg"] == pytest.approx(expected[r], abs=1e-9), r
        assert ext["angle_deg"] == pytest.approx(45.0, abs=1e-6)  # s′ peaks mid-rise


def _edited(name: str, **tables: dict) -> dict:
    data = tomllib.loads(SAMPLES[name].read_text(encoding="utf-8"))
    for table, values in tables.items():
        for key, value in values.items():
            if value is None:
                data[table].pop(key)
            else:
                data.setdefault(table, {})[key] = value
    return data


def _toml(data: dict) -> str:
    lines = []
    for table, values in data.items():
        if table == "motion":
            continue
        lines.append(f"[{table}]")
        lines += [f"{k} = {json.dumps(v)}" for k, v in values.items()]
    for seg in data["motion"]:
        lines.append("[[motion]]")
        lines += [f"{k} = {json.dumps(v)}" for k, v in seg.items()]
    return "\n".join(lines) + "\n"


BAD = [
    ("groove deeper than the wall", "indexer", {"groove": {"depth": 55.0}}, "groove.depth"),
    (
        "roller longer than the groove",
        "indexer",
        {"follower": {"roller_length": 18.0}},
        "follower.roller_length",
    ),
    (
        "groove past the barrel's end",
        "indexer",
        {"follower": {"axial_position": 5.0}},
        "follower.axial_position",
    ),
    ("arm that cannot reach", "arm", {"follower": {"arm_length": 90.0}}, "follower.arm_length"),
    ("no barrel radius", "indexer", {"cam": {"barrel_radius": None}}, "cam.barrel_radius"),
    ("a plate's base radius", "indexer", {"cam": {"base_radius": 40.0}}, "cam.base_radius"),
    ("a plate's rotation", "indexer", {"cam": {"rotation": "cw"}}, "cam.rotation"),
    ("an unknown roller", "indexer", {"follower": {"roller": "spherical"}}, "follower.roller"),
    (
        "a flat face",
        "indexer",
        {"follower": {"type": "translating-flat", "roller_radius": None}},
        "cam.style",
    ),
]


@pytest.mark.parametrize(("what", "name", "edit", "field"), BAD, ids=[b[0] for b in BAD])
def test_bad_barrel_input_exits_2_naming_the_field(what, name, edit, field, tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(_toml(_edited(name, **edit)), encoding="utf-8")
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0], err


@pytest.mark.parametrize("key", ["barrel_radius", "length"])
def test_a_barrel_key_on_a_plate_is_refused_naming_it(key, tmp_path, capsys):
    text = (ROOT / "samples" / "offset_roller.toml").read_text(encoding="utf-8")
    path = tmp_path / "plate.toml"
    path.write_text(text.replace("[cam]\n", f"[cam]\n{key} = 70.0\n", 1), encoding="utf-8")
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert f"cam.{key}" in err and "barrel" in err


@pytest.mark.parametrize("key", ["axial_position", "roller_length"])
def test_a_barrel_follower_key_on_a_groove_cam_is_refused_naming_it(key, tmp_path, capsys):
    text = (ROOT / "samples" / "groove_rocker.toml").read_text(encoding="utf-8")
    path = tmp_path / "groove.toml"
    path.write_text(text.replace("[follower]\n", f"[follower]\n{key} = 10.0\n", 1), encoding="utf-8")
    assert main(["check", str(path)]) == 2
    assert f"follower.{key}" in capsys.readouterr().err


def test_check_gives_rows_for_a_barrel(capsys):
    assert main(["check", str(SAMPLES["indexer"])]) in (0, 3)
    out = capsys.readouterr().out
    assert "pressure" in out.lower()


def test_same_input_same_bytes(folder, tmp_path):
    first = built("indexer", folder)
    again = tmp_path / "again"
    assert main(["build", str(SAMPLES["indexer"]), "-o", str(again), "-q"]) == 0
    assert_same_outputs(first, again)


def test_the_samples_are_the_issues_cases():
    """The samples state the cases of issue 36: their loaded values, checked against the issue's text."""
    indexer, arm = load_design(SAMPLES["indexer"]), load_design(SAMPLES["arm"])
    assert indexer.barrel is not None and arm.barrel is not None
    assert indexer.barrel.axial_position == 30.0 and arm.follower.arm_length == 110.0
    assert CASES["indexer"].program.lift == pytest.approx(40.0)
    assert CASES["arm"].program.lift == pytest.approx(12.0)


def test_an_arm_that_runs_the_groove_backwards_is_refused_as_crossing_itself(tmp_path, capsys):
    """A 20° swing over 20°: the developed groove at the bottom runs backwards, so it crosses itself.

    Independent check: the roller's axis sits at y = d + l·cos(b0 − ψ) across the barrel
    (b0 from the arm's triangle at rest), so the developed bottom line u = r_b·φ + y(φ) runs
    backwards where du/dφ < 0, computed here from the poly-345 law's closed form.
    """
    data = _edited("arm")
    for i, span in ((0, 20.0), (1, 160.0), (2, 20.0), (3, 160.0)):
        data["motion"][i]["angle"] = span
        if "lift" in data["motion"][i]:
            data["motion"][i]["lift"] = 20.0
    d, arm, bottom = 100.0, 110.0, 70.0 - 20.0
    b0 = math.atan2(math.sqrt(arm * arm - d * d), -d)
    phi = np.linspace(180.0, 200.0, 20_001)  # the return, degrees
    x = (phi - 180.0) / 20.0
    psi = math.radians(20.0) * (1.0 - (10 * x**3 - 15 * x**4 + 6 * x**5))  # poly-345 return
    u = bottom * np.radians(phi) + d + arm * np.cos(b0 - psi)
    assert np.diff(u).min() < 0.0  # the developed groove runs backwards: it crosses itself
    path = tmp_path / "cross.toml"
    path.write_text(_toml(data), encoding="utf-8")
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "follower.arm_length" in err and "crosses itself" in err


def test_a_barrel_build_without_opencascade_is_one_line_and_exit_2(tmp_path):
    """Without the ``step`` extra (OCP made unimportable in a fresh interpreter) the build says what to
    install or leave out, exit 2, and writes nothing."""
    import subprocess
    import sys

    out = tmp_path / "out"
    code = (
        "import sys; sys.modules['OCP'] = None\n"  # what an environment without the extra gives
        "from camcad.cli import main\n"
        f"raise SystemExit(main(['build', {str(SAMPLES['indexer'])!r}, '-o', {str(out)!r}, '-q']))\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 2, proc.stderr
    (line,) = proc.stderr.strip().splitlines()
    assert line.startswith("camcad: error: --only: ") and "pip install 'camcad[step]'" in line
    assert not out.exists()
