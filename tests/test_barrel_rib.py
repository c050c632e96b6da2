"""The rib barrel cam from a design file, end to end (issue 36): ``cam.style = "barrel-rib"``.

Independent truths:

- the sample loads to the objects tests/barrel_cases.py builds by hand (``RIB``);
- ``cam.step`` read back by OpenCASCADE is one solid ``BRepCheck_Analyzer`` finds valid, of
  the volume the core plus a quadrature of the rib between its exact faces gives
  (tests/barrel_cases.py: no fit, no mesh);
- ``cam.stl`` is watertight for trimesh, of the same volume within the polygons' sag;
- ``profile.dxf`` read by ezdxf holds both faces within the fit's tolerance of the exact
  developed faces, each computed here twice: from the lower layer
  (:func:`~camcad.geometry.barrel_limits.developed_walls` of each of
  :func:`~camcad.geometry.barrel.rib_rollers`) and in closed form, the roller's pitch line
  (t_p·φ, z0 ± h + s) offset by ∓(r_f + c/2) along its normal;
- the rib's least thickness at its root and top (summary and ``check`` rows) against a brute
  force distance between the two closed-form developed faces at those stations;
- the positive drive: with no spring the torque is the power balance
  T = m·(g + s″ω²)·s′ (Norton 2009, §8.11), its largest value over the turn;
- cam.ngc holds rough passes and one finishing pass per face (rs274 and the 3-D measure:
  tests/readers/test_rib_program.py); a rougher wider than the gap beside the rib exits 2;
- bad input exits 2 naming the field; a rib too thin for its flanks is a hard limit (exit 3)
  naming ``cam.rib_width``; the same input gives the same bytes.
"""

from __future__ import annotations

import json
import math
from functools import cache
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import tomllib

from camcad.cli import main
from camcad.design import load_design
from camcad.geometry.barrel import BarrelKind, rib_rollers
from camcad.geometry.barrel_limits import developed_walls
from camcad.geometry.cam import Cam
from camcad.geometry.families.barrel import barrel_of
from tests.barrel_cases import RIB, assert_same_outputs, barrel_volume, step_solid_volume
from tests.conftest import ROOT, distance_to_polygon

SAMPLE = ROOT / "samples" / "barrel_rib.toml"
FILES = ("profile.dxf", "cam.stl", "cam.step", "cam.ngc", "summary.json", "report.html")
G = 9.80665  # m/s², standard gravity


@cache
def built(folder: Path) -> Path:
    out = folder / "rib"
    assert main(["build", str(SAMPLE), "-o", str(out), "-q"]) == 0
    return out


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("rib")


def _summary(folder: Path) -> dict:
    return json.loads((built(folder) / "summary.json").read_text(encoding="utf-8"))


def test_the_sample_loads_to_the_rib_case():
    design = load_design(SAMPLE)
    barrel = barrel_of(Cam.from_design(design), design.family_options())
    assert barrel.options == RIB.options and barrel.options.kind is BarrelKind.RIB
    assert barrel.follower == RIB.follower
    phi = np.linspace(0.0, 2.0 * math.pi, 721)
    assert np.allclose(barrel.program.evaluate(phi).s, RIB.program.evaluate(phi).s, atol=1e-12)


def test_build_writes_the_barrels_files_and_its_4_axis_program(folder):
    """cam.ngc: rough passes then one finishing pass per face (rs274 reads and measures it in
    tests/readers/test_rib_program.py); the rougher the largest half-millimetre within 0.625 of the
    gap 2r_f + c less the stock on both sides, 2·0.625·(16.05 − 0.4) = 19.56 → 9.5 mm."""
    out = built(folder)
    for f in FILES:
        assert (out / f).stat().st_size > 0, f
    summary = _summary(folder)
    assert not [f for f in summary["findings"] if f["kind"] == "no program"]
    gcode = summary["gcode"]
    assert gcode["tool_diameter_mm"] == 9.5
    assert gcode["max_deviation_mm"] <= 0.005  # the [gcode] tolerance's default
    text = (out / "cam.ngc").read_text(encoding="ascii")
    kinds = [
        line.split(": ", 1)[1].split(" at Z")[0] for line in text.splitlines() if line.startswith("(pass ")
    ]
    assert kinds[-2:] == ["finish upper", "finish lower"] and set(kinds[:-2]) == {"rough"}
    assert "rib: 14 wide" in text and "T2 flat end mill D16.000" in text
    assert summary["fit"]["certified"] and summary["fit"]["max_error_mm"] <= summary["fit"]["tolerance_mm"]
    rib = summary["barrel"]["rib"]
    o = RIB.options
    assert rib["width_mm"] == 14.0
    assert rib["roller_offset_mm"] == pytest.approx(7.0 + o.roller_radius + 0.5 * o.clearance, abs=1e-12)


def test_step_reads_back_as_one_valid_solid_of_the_exact_volume(folder):
    volume = step_solid_volume(built(folder) / "cam.step")
    o = RIB.options
    core = math.pi * (o.bottom_radius**2 - (0.5 * o.bore) ** 2) * o.length
    assert volume > core + 1000.0  # a rib stands on the core
    assert volume == pytest.approx(barrel_volume(RIB), rel=2e-5)


def test_stl_is_watertight_and_of_the_exact_volume(folder):
    trimesh = pytest.importorskip("trimesh")
    mesh = trimesh.load(built(folder) / "cam.stl", force="mesh")
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume == pytest.approx(barrel_volume(RIB), rel=2e-4)


def _closed_form_faces(station: float, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rib's (upper, lower) developed faces at ``station``: each roller's pitch line offset by ∓r_w."""
    o = RIB.options
    m = RIB.program.evaluate(np.mod(phi, 2.0 * math.pi))
    h, r_w, z0 = o.rib_offset, o.roller_radius + 0.5 * o.clearance, RIB.follower.axial_position
    normal = np.column_stack((-m.v, np.full_like(phi, station))) / np.hypot(station, m.v)[:, None]
    line = np.column_stack((station * phi, z0 + m.s))
    shift = np.array([0.0, h])
    upper = line + shift - r_w * normal  # the +h roller's lower wall
    lower = line - shift + r_w * normal  # the −h roller's upper wall
    return upper, lower


def test_dxf_holds_both_faces_within_the_fit_tolerance_of_the_exact_faces(folder):
    o = RIB.options
    tolerance = load_design(SAMPLE).fit.tolerance
    msp = ezdxf.readfile(built(folder) / "profile.dxf").modelspace()
    phi = np.linspace(0.0, 2.0 * math.pi, 20_001)
    motion = RIB.program.evaluate(phi)
    up_roller, low_roller = rib_rollers(RIB.follower, o)
    lower_layer = {
        "WALL_UPPER": developed_walls(motion, up_roller, o, o.pitch_station).lower.point,
        "WALL_LOWER": developed_walls(motion, low_roller, o, o.pitch_station).upper.point,
    }
    closed = dict(zip(("WALL_UPPER", "WALL_LOWER"), _closed_form_faces(o.pitch_station, phi), strict=True))
    for layer in ("WALL_UPPER", "WALL_LOWER"):
        assert np.abs(lower_layer[layer] - closed[layer]).max() < 1e-9, layer  # the two methods agree
        (spline,) = msp.query(f'SPLINE[layer=="{layer}"]')
        pts = np.array([(x, y) for x, y, _ in spline.construction_tool().approximate(20_000)])
        dist = distance_to_polygon(closed[layer], pts)
        assert dist.max() <= tolerance + 1e-3, layer  # the fit's tolerance + the 20 000-chord polyline's sag


def test_rib_thickness_rows_are_the_brute_force_least_width(folder, capsys):
    o = RIB.options
    rib = _summary(folder)["barrel"]["rib"]["thickness_min"]
    # the lower face past the period's ends (the faces repeat), a polygon of 0.0002 rad chords (sag < 1e-7 mm)
    lower_phi = np.linspace(-0.5, 2.0 * math.pi + 0.5, 34_001)
    for where, station in (("bottom", o.bottom_radius), ("top", o.barrel_radius)):
        lower = _closed_form_faces(station, lower_phi)[1]
        coarse = np.linspace(0.0, 2.0 * math.pi, 7_200, endpoint=False)  # each upper point's distance
        k = int(np.argmin(distance_to_polygon(_closed_form_faces(station, coarse)[0], lower)))
        fine = coarse[k] + np.linspace(-0.002, 0.002, 4_001)  # then 1e-6 rad steps round the least
        least = distance_to_polygon(_closed_form_faces(station, fine)[0], lower)
        j = int(np.argmin(least))
        assert rib[where]["value_mm"] == pytest.approx(least[j], abs=1e-5), where
        assert rib[where]["angle_deg"] == pytest.approx(math.degrees(fine[j]), abs=0.1), where
        assert 0.0 < rib[where]["value_mm"] < o.rib_width  # the flanks narrow it, the dwells keep w
    assert main(["check", str(SAMPLE)]) == 0
    out = capsys.readouterr().out
    for label, where in (("root", "bottom"), ("top", "top")):
        assert f"rib thickness at {label}" in out
        assert f"{rib[where]['value_mm']:.3f} mm" in out
    assert "rib along the axis" in out


def test_the_two_rollers_drive_it_positively_by_the_power_balance(folder):
    """No spring: T(φ) = F·s′ with F = m(g + s″ω²) along the axis; its largest value over the turn."""
    design = load_design(SAMPLE)
    dyn = _summary(folder)["dynamics"]
    assert dyn["jump"] is False
    omega = design.cam.speed_rpm * 2.0 * math.pi / 60.0
    phi = np.linspace(0.0, 2.0 * math.pi, 400_001)
    m = RIB.program.evaluate(phi)
    torque = design.dynamics.follower_mass * (G + m.a * 1e-3 * omega**2) * m.v  # N·mm (s′ in mm/rad)
    assert dyn["torque_max_Nmm"] == pytest.approx(torque.max(), rel=1e-5)
    assert dyn["torque_max_angle_deg"] == pytest.approx(math.degrees(phi[np.argmax(torque)]), abs=0.05)


def _bad(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _rib_text(**cam: object) -> str:
    text = SAMPLE.read_text(encoding="utf-8")
    for key, value in cam.items():
        old = next(line for line in text.splitlines() if line.startswith(f"{key} ="))
        text = text.replace(old + "\n", "" if value is None else f"{key} = {json.dumps(value)}\n")
    return text


@pytest.mark.parametrize(
    ("what", "text"),
    [
        ("no rib_width on a rib", lambda: _rib_text(rib_width=None)),
        ("a zero rib_width", lambda: _rib_text(rib_width=0.0)),
        ("a negative rib_width", lambda: _rib_text(rib_width=-3.0)),
        ("a word for rib_width", lambda: _rib_text(rib_width="wide")),
        (
            "rib_width on a groove barrel",
            lambda: (
                (ROOT / "samples" / "barrel_indexer.toml")
                .read_text(encoding="utf-8")
                .replace("[cam]\n", "[cam]\nrib_width = 14.0\n", 1)
            ),
        ),
        (
            "rib_width on a plate",
            lambda: (
                (ROOT / "samples" / "offset_roller.toml")
                .read_text(encoding="utf-8")
                .replace("[cam]\n", "[cam]\nrib_width = 14.0\n", 1)
            ),
        ),
    ],
)
def test_bad_rib_width_exits_2_naming_the_field(what, text, tmp_path, capsys):
    assert main(["check", str(_bad(tmp_path, text()))]) == 2, what
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cam.rib_width" in err[0], err


def test_a_rib_without_a_barrel_radius_exits_2_naming_it(tmp_path, capsys):
    assert main(["check", str(_bad(tmp_path, _rib_text(barrel_radius=None)))]) == 2
    assert "cam.barrel_radius" in capsys.readouterr().err


def test_a_rib_too_thin_for_its_flanks_is_a_hard_limit_naming_rib_width(tmp_path, capsys):
    """The flanks narrow a 14 mm rib to 10.34 mm at its root (the brute force above): at 2 mm they cross."""
    assert main(["check", str(_bad(tmp_path, _rib_text(rib_width=2.0)))]) == 3
    assert "cam.rib_width" in capsys.readouterr().out


def test_a_rougher_wider_than_the_gap_beside_the_rib_exits_2_naming_it(tmp_path, capsys):
    """The gap each roller runs in is 2r_f + c = 16.05 mm; with 0.2 mm stock on each side 15.65 mm fits."""
    text = SAMPLE.read_text(encoding="utf-8") + "\n[gcode]\ntool_diameter = 15.7\n"
    out = tmp_path / "out"
    assert main(["build", str(_bad(tmp_path, text)), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "gcode.tool_diameter" in err[0] and "15.65" in err[0], err
    assert not out.exists()
    fits = SAMPLE.read_text(encoding="utf-8") + "\n[gcode]\ntool_diameter = 15.6\n"
    assert main(["check", str(_bad(tmp_path, fits))]) == 0


def test_the_editor_schema_takes_the_sample_and_refuses_rib_width_elsewhere():
    jsonschema = pytest.importorskip("jsonschema")
    from camcad.design.editor_schema import design_json_schema

    schema = design_json_schema()
    data = tomllib.loads(SAMPLE.read_text(encoding="utf-8"))
    jsonschema.validate(data, schema)
    no_width = tomllib.loads(_rib_text(rib_width=None))
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(no_width, schema)
    groove = tomllib.loads((ROOT / "samples" / "barrel_indexer.toml").read_text(encoding="utf-8"))
    jsonschema.validate(groove, schema)
    groove["cam"]["rib_width"] = 14.0
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(groove, schema)


def test_same_input_same_bytes(folder, tmp_path):
    first = built(folder)
    again = tmp_path / "again"
    assert main(["build", str(SAMPLE), "-o", str(again), "-q"]) == 0
    assert_same_outputs(first, again)


def test_the_designers_form_asks_a_rib_for_its_width_and_a_groove_barrel_not():
    from camcad.design.editor_schema import design_json_schema
    from camcad.serve.form import _conditional_required

    schema = design_json_schema()
    rib = _conditional_required(schema, {"cam": {"style": "barrel-rib"}})
    assert {"barrel_radius", "length", "rib_width"} <= rib["cam"] and "base_radius" not in rib["cam"]
    groove = _conditional_required(schema, {"cam": {"style": "barrel"}})
    assert {"barrel_radius", "length"} <= groove["cam"] and "rib_width" not in groove["cam"]
    plate = _conditional_required(schema, {"cam": {"style": "plate"}})
    assert "base_radius" in plate["cam"] and "rib_width" not in plate["cam"]
