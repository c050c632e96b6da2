"""[life], [lubrication] and [drive] through the design schema and the pipeline (issue 35)."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad import pipeline
from camcad.design import load_design, parse_design
from camcad.design.paths import path_of
from camcad.errors import DesignError

SAMPLE = Path(__file__).resolve().parents[2] / "samples" / "indexing_drive.toml"

LIFE = {"roller_dynamic_load_rating": 8000.0, "roller_life_exponent": 3.333, "required_hours": 1e4}
OIL = {
    "viscosity_Pa_s": 0.09,
    "pressure_viscosity_coefficient": 2e-8,
    "roughness_cam_um": 0.4,
    "roughness_follower_um": 0.2,
}
DRIVE = {"gear_ratio": 1.0, "gear_efficiency": 1.0}


def _data(follower=None, **tables):
    return {
        "cam": {"base_radius": 50.0, "speed_rpm": 150.0, "thickness": 12.0},
        "follower": follower or {"roller_radius": 12.0},
        "motion": [
            {"kind": "rise", "angle": 120.0, "lift": 20.0, "law": "cycloidal"},
            {"kind": "dwell", "angle": 60.0},
            {"kind": "return", "angle": 120.0, "lift": 20.0, "law": "modified-sine"},
            {"kind": "dwell", "angle": 60.0},
        ],
        "dynamics": {
            "follower_mass": 1.0,
            "spring_rate": 2.0,
            "spring_preload": 80.0,
            "friction_torque": 30.0,
        },
        **tables,
    }


def _analyse(data):
    return pipeline.analyse(parse_design(data), fit=False, toolpath=False, strict=False)


def test_sample_has_every_section_and_csv_column(tmp_path):
    analysis = pipeline.analyse(load_design(SAMPLE), fit=False, toolpath=False, strict=False)
    summary = analysis.summary()
    assert {"life", "lubrication", "drive"} <= set(summary)
    assert summary["life"]["roller_life_h"] > 0
    assert [c["name"] for c in summary["drive"]["checks"]] == [
        "peak torque",
        "RMS torque",
        "speed",
        "inertia ratio",
    ]
    pipeline.write_tables(analysis, tmp_path)
    with (tmp_path / "dynamics.csv").open() as f:
        header = next(csv.reader(f))
    assert header[-3:] == ["film_thickness_um", "film_ratio", "motor_torque_Nm"]


def test_motor_torque_is_the_exact_input_torque_through_a_unit_gearbox():
    analysis = _analyse(_data(drive=DRIVE))
    assert_allclose(analysis.drive.drive.motor_torque, analysis.dynamics.torque / 1000.0, rtol=1e-15)
    assert analysis.summary()["drive"]["motor_max_speed_rpm"] == pytest.approx(150.0)


def test_film_ratio_below_the_limit_is_a_soft_finding():
    analysis = _analyse(_data(lubrication={**OIL, "min_film_ratio": 50.0}))
    (finding,) = [f for f in analysis.findings if f.kind == "film ratio"]
    assert not finding.hard and path_of(finding.field) == "lubrication.min_film_ratio"
    assert finding.value == pytest.approx(analysis.summary()["lubrication"]["min_film_ratio"])
    assert "film ratio" in analysis.violations


def test_roller_life_short_of_required_is_a_soft_finding():
    analysis = _analyse(_data(life={**LIFE, "roller_dynamic_load_rating": 300.0}))
    (finding,) = [f for f in analysis.findings if f.kind == "roller life"]
    assert finding.value < 1e4 and finding.limit == 1e4
    life = analysis.summary()["life"]
    # L10 = (C/P)^(10/3) with the reported P and turns
    revs = (300.0 / life["roller_equivalent_load_N"]) ** (10.0 / 3.0) * 1e6
    assert life["roller_life_h"] == pytest.approx(revs / (life["roller_turns_per_cam_turn"] * 2.5) / 3600.0)


def test_flat_face_has_no_rolling_life_but_a_sliding_speed():
    analysis = _analyse(_data(follower={"type": "translating-flat"}, life=LIFE))
    life = analysis.summary()["life"]
    assert life["rolling_life"].startswith("does not apply")
    omega = 150.0 * 2 * math.pi / 60.0
    # radial flat face: sliding ω(r_b + s), largest at full lift
    assert life["sliding_speed_max_mm_per_s"] == pytest.approx(omega * 70.0, rel=1e-6)
    assert "roller_life_h" not in life


def test_servo_follower_on_a_screw():
    drive = {"mode": "servo-follower", "screw_lead_mm": 10.0, "gear_ratio": 1.0, "gear_efficiency": 1.0}
    analysis = _analyse(_data(drive=drive))
    d = analysis.drive.drive
    m = analysis.motion
    # ideal screw: T = F·p/(2π), F = m a ω² + k s + F0 + m g
    omega = 150.0 * 2 * math.pi / 60.0
    force = 1.0 * m.a * omega**2 / 1000.0 + 2.0 * m.s + 80.0 + 9.80665
    assert_allclose(d.motor_torque, force * 10.0 / (2 * math.pi) / 1000.0, rtol=1e-12)
    assert analysis.summary()["drive"]["mode"] == "servo-follower"
    assert [row["segment"] for row in analysis.summary()["drive"]["characteristic_values"]] == [0, 2]


def test_oscillating_roller_runs_every_table():
    follower = {
        "type": "oscillating-roller",
        "roller_radius": 10.0,
        "pivot_distance": 90.0,
        "arm_length": 70.0,
    }
    data = _data(follower=follower, life=LIFE, lubrication=OIL, drive={"mode": "servo-follower"})
    data["motion"] = [
        {"kind": "rise", "angle": 150.0, "lift": 15.0, "law": "cycloidal"},
        {"kind": "return", "angle": 150.0, "lift": 15.0, "law": "cycloidal"},
        {"kind": "dwell", "angle": 60.0},
    ]
    data["dynamics"] = {
        "arm_inertia": 2000.0,
        "spring_rate_torsional": 500.0,
        "spring_preload_torsional": 3000.0,
    }
    summary = _analyse(data).summary()
    assert summary["life"]["roller_life_h"] > 0
    assert math.isfinite(summary["lubrication"]["min_film_ratio"])
    assert summary["drive"]["motor_peak_torque_Nm"] > 0


@pytest.mark.parametrize(
    ("tables", "path"),
    [
        ({"life": {"roller_dynamic_load_rating": 0.0}}, "life.roller_dynamic_load_rating"),
        (
            {"life": {"roller_dynamic_load_rating": 5e3, "roller_life_exponent": 3.5}},
            "life.roller_life_exponent",
        ),
        ({"life": {"track_slope": 8.0}}, "life.track_intercept"),
        ({"lubrication": {**OIL, "viscosity_Pa_s": 0.0}}, "lubrication.viscosity_Pa_s"),
        ({"lubrication": {**OIL, "roughness_cam_um": -0.1}}, "lubrication.roughness_cam_um"),
        ({"lubrication": {"viscosity_Pa_s": 0.1}}, "lubrication.pressure_viscosity_coefficient"),
        ({"drive": {"gear_efficiency": 1.2}}, "drive.gear_efficiency"),
        ({"drive": {"gear_efficiency": 0.0}}, "drive.gear_efficiency"),
        ({"drive": {"screw_lead_mm": 5.0}}, "drive.screw_lead_mm"),
        ({"drive": {"mode": "servo-follower"}}, "drive.screw_lead_mm"),
        ({"drive": {"mode": "linear-motor"}}, "drive.mode"),
    ],
)
def test_bad_tables_name_the_field(tables, path):
    with pytest.raises(DesignError) as err:
        parse_design(_data(**tables))
    assert path_of(err.value.path) == path
    assert "\n" not in str(err.value)


def test_no_tables_no_duty():
    analysis = _analyse(_data())
    assert analysis.duty is None
    assert not {"life", "lubrication", "drive"} & set(analysis.summary())
    assert np.all(np.isfinite(analysis.dynamics.torque))


def test_explore_measures_read_the_new_sections():
    """roller_life_h, min_film_ratio, motor_rms_torque for optimize and sweep; None without the table."""
    from camcad.explore.measures import measure_values, parse_limit

    analysis = pipeline.analyse(load_design(SAMPLE), fit=False, toolpath=False, strict=False)
    values = measure_values(analysis)
    summary = analysis.summary()
    assert values["roller_life_h"] == summary["life"]["roller_life_h"]
    assert values["min_film_ratio"] == summary["lubrication"]["min_film_ratio"]
    assert values["motor_rms_torque_Nm"] == summary["drive"]["motor_rms_torque_Nm"]
    assert parse_limit("min_film_ratio>=1").holds(values)
    assert not parse_limit("motor_rms_torque<=0.01").holds(values)
    plain = measure_values(_analyse(_data()))
    assert plain["roller_life_h"] is None and plain["min_film_ratio"] is None


def test_report_has_a_figure_per_analysis():
    from camcad.report import render_report

    html = render_report(pipeline.analyse(load_design(SAMPLE), fit=False, toolpath=False, strict=False))
    for key in ("plot-life", "plot-film", 'plot-drive"', "plot-drive-envelope", "table-life", "table-drive"):
        assert key in html
    flat = _analyse(_data(follower={"type": "translating-flat"}, life=LIFE))
    html = render_report(flat)
    assert "rolling life does not apply" in html
    assert "duty-heading" not in render_report(_analyse(_data()))


def test_extremes_are_true_on_a_coarse_grid():
    """Smallest λ, largest K, peak motor torque: a 3° grid refined on the exact cam gives the 0.01° grid's."""
    tables = {
        "life": {"track_slope": 8.0, "track_intercept": 34.0},
        "lubrication": OIL,
        "drive": {"gear_ratio": 5.0, "gear_efficiency": 0.8},
    }
    data = _data(**tables)
    data["motion"] = [
        {"kind": "rise", "angle": 170.0, "lift": 25.0, "law": "modified-sine"},
        {"kind": "return", "angle": 190.0, "lift": 25.0, "law": "cycloidal"},
    ]
    coarse_analysis = _analyse({**data, "cam": {**data["cam"], "sample_step_deg": 3.0}})
    fine_analysis = _analyse({**data, "cam": {**data["cam"], "sample_step_deg": 0.01}})
    coarse, fine = coarse_analysis.duty, fine_analysis.duty
    assert coarse.film.min_ratio == pytest.approx(fine.film.min_ratio, rel=1e-7)
    assert coarse.film.min_ratio <= np.min(coarse.film.ratio)
    assert coarse.track.factor_max == pytest.approx(fine.track.factor_max, rel=1e-7)
    rough, smooth = coarse_analysis.drive, fine_analysis.drive
    assert rough.drive.peak_torque == pytest.approx(smooth.drive.peak_torque, rel=1e-7)
    assert rough.drive.peak_torque >= np.max(np.abs(rough.drive.motor_torque))
