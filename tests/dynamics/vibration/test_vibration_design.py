"""The ``[vibration]`` table through the design, pipeline, files, ``camcad check`` and report (issue 34).

Independent truths: a polydyne cam's lift read back from the built geometry
(the roller centre over the profile) against the compensated lift c; the
Gauss–Legendre integrator of ``test_vibration`` driven by that built cam with
a train written from the sample's numbers (not ``train_from_specs``); the
CSV files read back with the standard library; the report with the HTML parser.
"""

from __future__ import annotations

import copy
import csv
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad.cli import main
from camcad.cli.render import _vibration_rows
from camcad.design import load_design, parse_design
from camcad.design.paths import path_of
from camcad.dynamics.vibration import Train, TrainModel, VibrationSpec
from camcad.errors import DesignError
from camcad.pipeline import OUTPUT_GROUPS, analyse, build
from tests.conftest import ROOT
from tests.dynamics.vibration.test_vibration import collocate

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

POLYDYNE = ROOT / "samples" / "vibration_packaging.toml"
PLAIN = ROOT / "samples" / "vibration_speed_map.toml"
RPM = 60.0 / (2.0 * math.pi)
G = 9.80665


def _data(path: Path = PLAIN) -> dict:
    return tomllib.loads(path.read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def polydyne(tmp_path_factory: pytest.TempPathFactory):
    """The polydyne sample built (tables and report): its analysis and output folder."""
    out = tmp_path_factory.mktemp("polydyne") / "out"
    result = build(load_design(POLYDYNE), out, only=["tables"])
    return result.analysis, out


@pytest.fixture(scope="module")
def plain():
    return analyse(load_design(PLAIN), fit=False, toolpath=False, strict=False)


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


# ------------------------------------------------------------------ schema


def test_the_table_loads_into_a_vibration_spec():
    design = load_design(POLYDYNE)
    v = design.vibration
    assert isinstance(v, VibrationSpec)
    assert (v.model, v.stiffness, v.damping_ratio, v.compensate_rpm) == (
        TrainModel.SINGLE_MASS,
        1500.0,
        0.05,
        600.0,
    )
    assert (v.speed_min_rpm, v.speed_max_rpm, v.speed_points, v.max_residual) == (200.0, 1000.0, 161, 0.05)
    data = _data()
    del data["vibration"]
    assert parse_design(data).vibration is None


@pytest.mark.parametrize(
    ("table", "field", "words"),
    [
        ({"stiffness": -5.0}, "vibration.stiffness", "must be > 0"),
        ({"stiffness": 800.0, "damping_ratio": -0.1}, "vibration.damping_ratio", "[0, 1)"),
        (
            {"stiffness": 800.0, "speed_min_rpm": 500.0, "speed_max_rpm": 500.0},
            "vibration.speed_max_rpm",
            "exceed",
        ),
        ({"stiffness": 800.0, "speed_min_rpm": 950.0}, "vibration.speed_min_rpm", "empty"),  # default max 900
        ({"stiffness": 800.0, "model": "two-mass", "mass_1": 1.0}, "vibration.mass_2", "required"),
        ({"stiffness": 800.0, "model": "three-mass"}, "vibration.model", "single-mass"),
        ({"stiffnes": 800.0}, "vibration.stiffnes", "did you mean 'stiffness'"),
        ({}, "vibration.stiffness", "required"),
    ],
)
def test_bad_tables_name_the_field(table, field, words):
    data = _data()
    data["vibration"] = table
    with pytest.raises(DesignError) as err:
        parse_design(data)
    assert path_of(err.value.path) == field
    assert words in str(err.value)


def test_an_arm_takes_the_torsional_stiffness():
    data = _data(ROOT / "samples" / "packaging_rocker.toml")
    data["vibration"] = {"stiffness": 800.0}
    with pytest.raises(DesignError) as err:
        parse_design(data)
    assert path_of(err.value.path) == "vibration.stiffness" and "stiffness_torsional" in str(err.value)


def test_compensating_a_law_not_smooth_enough_names_the_segment():
    data = _data(POLYDYNE)
    data["motion"][2] = {"kind": "return", "angle": 120.0, "lift": 25.0, "law": "cycloidal"}
    with pytest.raises(DesignError) as err:
        parse_design(data)
    assert path_of(err.value.path) == "motion[2].law"


def test_the_json_schema_has_the_table():
    from camcad.design.editor_schema import design_json_schema

    props = design_json_schema()["properties"]["vibration"]["properties"]
    assert {"stiffness", "damping_ratio", "compensate_rpm", "speed_points", "model"} <= set(props)
    assert props["model"]["enum"] == ["single-mass", "two-mass"]


# ------------------------------------------------------------------ polydyne: the cam is cut from c


def test_the_built_profile_carries_the_compensated_lift(polydyne):
    """The roller centre over the built profile, |P + r_f·n| − (r_b + r_f), is c to 1e-9, not the program."""
    analysis, _ = polydyne
    comp = analysis.vibration.compensated
    geo, design = analysis.geometry, analysis.design
    k = design.cam.base_radius + design.follower.roller_radius
    centre = np.asarray(geo.profile.point) + design.follower.roller_radius * np.asarray(geo.profile.normal)
    lift_read = np.hypot(centre[:, 0], centre[:, 1]) - k
    c = comp.evaluate(geo.phi).s
    assert_allclose(lift_read, c, atol=1e-9 * comp.lift)
    y = comp.program.evaluate(geo.phi).s
    assert np.max(np.abs(lift_read - y)) > 0.5  # mm: the correction is real, and it is in the profile


def test_profile_csv_is_the_compensated_cam(polydyne):
    analysis, out = polydyne
    rows = _rows(out / "profile.csv")
    design = analysis.design
    phi = np.radians([float(r["angle_deg"]) for r in rows])
    pitch = np.array([[float(r["pitch_x"]), float(r["pitch_y"])] for r in rows])
    lift = np.hypot(pitch[:, 0], pitch[:, 1]) - (design.cam.base_radius + design.follower.roller_radius)
    assert_allclose(lift, analysis.vibration.compensated.evaluate(phi).s, atol=1e-6)  # 9 significant digits


def test_an_independent_integrator_driven_by_the_built_cam_follows_the_program(polydyne):
    """The sample's train written out here; the lift and its rate from the built cam's pitch curve."""
    analysis, _ = polydyne
    design = analysis.design
    m = design.dynamics.follower_mass / 1000.0
    kf, zeta = design.vibration.stiffness, design.vibration.damping_ratio
    train = Train(
        mass=(m,),
        contact_rate=kf,
        contact_damping=2.0 * zeta * math.sqrt(kf * m),  # c = 2ζ√(k_f m) (docs/guides/vibration.md)
        spring_rate=design.dynamics.spring_rate,
        preload=design.dynamics.spring_preload,
        weight=(design.dynamics.follower_mass * G,),
    )
    k = design.cam.base_radius + design.follower.roller_radius
    omega = design.cam.speed_rpm / RPM
    cam = analysis.cam

    def lift(phi):
        p = cam.pitch(phi)
        r = np.hypot(p.point[:, 0], p.point[:, 1])
        rate = np.einsum("ij,ij->i", p.point, p.d1) / r  # d|P|/dφ
        return r - k, rate * omega

    program = analysis.vibration.compensated.program
    grid = np.linspace(0.0, 2 * math.pi, 721)
    phi = np.union1d(grid, np.mod(program.pieces, 2 * math.pi))
    start = program.evaluate(np.array([0.0]))
    states = collocate(train, lift, omega, np.array([start.s[0], 0.0]), phi)
    assert_allclose(states[:, 0], program.evaluate(phi).s, atol=1e-9 * program.lift)


def test_summary_files_and_check_report_the_polydyne_cam(polydyne):
    analysis, out = polydyne
    summary = json.loads((out / "summary.json").read_text())
    vib = summary["vibration"]
    comp = analysis.vibration.compensated
    dense = np.linspace(0.0, 2 * math.pi, 20_001)
    assert vib["compensate_rpm"] == 600.0
    assert vib["lift_correction_max_mm"] >= np.max(np.abs(comp.correction(dense))) - 1e-12  # a true extreme
    assert abs(vib["error_peak_mm"]) < 1e-9 * comp.lift  # the output follows the program at 600 rpm
    response = _rows(out / "vibration.csv")
    phi = np.radians([float(r["angle_deg"]) for r in response])
    x = np.array([float(r["x_mm"]) for r in response])
    assert_allclose(x, comp.program.evaluate(phi).s, atol=2e-9)  # written with 9 decimals
    speeds = _rows(out / "speed_map.csv")
    assert len(speeds) == 161 and float(speeds[0]["speed_rpm"]) == 200.0
    at = {float(r["speed_rpm"]): r for r in speeds}
    tuned = float(at[600.0]["error_peak_mm"])
    assert abs(tuned) < 1e-8 and all(
        abs(float(r["error_peak_mm"])) > abs(tuned) for r in speeds if r is not at[600.0]
    )
    assert set(OUTPUT_GROUPS["tables"]) >= {"vibration.csv", "speed_map.csv"}
    rows = dict(_vibration_rows({"vibration": vib}))  # what camcad check prints for it
    assert rows["leaves the cam"] == "no"
    assert rows["residual in dwell 2"] == f"{vib['residual_mm'][1]:.4g} mm"
    assert rows["min dynamic contact force"].startswith(f"{vib['contact_force_min']:.4g} N at ")
    assert rows["polydyne lift correction"].startswith(f"max |c − s| {vib['lift_correction_max_mm']:.4g} mm")


# ------------------------------------------------------------------ the plain cam: findings, report, measures


def test_leaving_the_cam_is_a_hard_finding_where_the_flight_starts(tmp_path, capsys):
    """400 N of preload: at 600 rpm the train's force turns negative and the follower flies twice a turn."""
    text = PLAIN.read_text(encoding="utf-8").replace("spring_preload = 500.0", "spring_preload = 400.0")
    text = text.replace("speed_points = 161", "speed_points = 5")
    path = tmp_path / "weak.toml"
    path.write_text(text, encoding="utf-8")
    analysis = analyse(load_design(path), fit=False, toolpath=False, strict=False)
    found = [f for f in analysis.findings if f.kind == "leaves the cam"]
    assert len(found) == 1 and found[0].hard and path_of(found[0].field) == "dynamics.spring_preload"
    vib = analysis.summary()["vibration"]
    assert vib["leaves_cam"] and vib["periodic"] and len(vib["flights"]) == 2
    assert math.degrees(found[0].angle) == pytest.approx(vib["flights"][0]["leave_deg"], abs=1e-6)
    r = analysis.vibration.response
    assert r.contact_force_min.value < 0.0  # the contact-held solution would pull
    # in flight the contact force is zero and the output is above the cam's lift less the train's deflection
    flying = ~np.asarray(r.in_contact)
    assert flying.any() and np.all(np.asarray(r.contact_force)[flying] == 0.0)
    rows = dict(_vibration_rows({"vibration": vib}))
    assert rows["leaves the cam"] == f"yes, at {vib['flights'][0]['leave_deg']:.1f}°"
    assert main(["check", str(path)]) == 3
    assert "hard limit: the elastic follower train leaves the cam" in capsys.readouterr().out


def test_residual_above_max_residual_is_a_soft_finding(plain):
    data = _data()
    data["vibration"]["max_residual"] = 0.01
    analysis = analyse(parse_design(data), fit=False, toolpath=False, strict=False)
    found = [f for f in analysis.findings if f.kind == "residual vibration"]
    assert len(found) == 1 and not found[0].hard and path_of(found[0].field) == "vibration.max_residual"
    assert found[0].value == pytest.approx(max(plain.summary()["vibration"]["residual_mm"]))
    assert "residual vibration" in analysis.violations  # a soft limit: check exits 3
    assert not [f for f in plain.findings if f.kind == "residual vibration"]  # 0.036 mm < 0.05 mm


def test_the_speed_map_of_the_plain_cam_has_no_tuned_minimum(plain):
    """Without compensation the dynamic error never vanishes: nothing cancels the train's deflection."""
    m = plain.vibration.speed_map
    assert np.min(np.abs(m.error_peak)) > 0.1
    assert plain.summary()["vibration"].get("compensate_rpm") is None


def test_explore_measures_read_the_vibration_entry(plain):
    from camcad.explore.measures import measure_values, parse_limit

    values = measure_values(plain)
    vib = plain.summary()["vibration"]
    assert values["vibration_residual_mm"] == max(vib["residual_mm"])
    assert values["min_dynamic_contact_force_N"] == vib["contact_force_min"]
    assert parse_limit("min_dynamic_contact_force>=0").holds(values)
    assert not parse_limit("vibration_residual_mm<=0.001").holds(values)
    data = _data()
    del data["vibration"]
    bare = measure_values(analyse(parse_design(data), fit=False, toolpath=False, strict=False))
    assert bare["vibration_residual_mm"] is None and bare["min_dynamic_contact_force_N"] is None


def test_report_has_the_speed_map_and_the_response(plain):
    from html.parser import HTMLParser

    from camcad.report import render_report

    html = render_report(plain)

    class Ids(HTMLParser):
        def __init__(self) -> None:
            super().__init__()
            self.ids: set[str] = set()

        def handle_starttag(self, tag, attrs):
            self.ids |= {v for k, v in attrs if k == "id" and v}

    page = Ids()
    page.feed(html)
    assert {"vibration", "plot-speed-map", "plot-vibration", "table-vibration"} <= page.ids
    assert "The follower would leave the cam from" in html  # the map runs past 635 rpm
    data = copy.deepcopy(_data())
    del data["vibration"]
    assert "vibration-heading" not in render_report(analyse(parse_design(data), fit=False, toolpath=False))
