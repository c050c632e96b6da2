"""dynamics.csv holds every part's figures: a conjugate pair's second plate gets its own columns (``_2``).

The truth is the second plate's own refined extremes in ``summary.json``
(found on the exact functions, not on the table's angles), and the
Dowson–Higginson ratio's definition: λ = h_min / √(Rq₁² + Rq₂²).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
import tomllib

from camcad.design import parse_design
from camcad.pipeline import analyse, write_tables

ROOT = Path(__file__).resolve().parents[2]
ROUGH_CAM_UM, ROUGH_FOLLOWER_UM = 0.4, 0.3


@pytest.fixture(scope="module")
def pair_tables(tmp_path_factory):
    data = tomllib.loads((ROOT / "samples" / "indexing_conjugate.toml").read_text(encoding="utf-8"))
    data["lubrication"] = {
        "viscosity_Pa_s": 0.05,
        "pressure_viscosity_coefficient": 2e-8,
        "roughness_cam_um": ROUGH_CAM_UM,
        "roughness_follower_um": ROUGH_FOLLOWER_UM,
    }
    analysis = analyse(parse_design(data), fit=False, toolpath=False, strict=False)
    folder = tmp_path_factory.mktemp("pair")
    write_tables(analysis, folder)
    with (folder / "dynamics.csv").open(encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    columns = {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}
    return analysis, columns


def test_the_second_plate_has_its_own_force_stress_and_film_columns(pair_tables):
    _, columns = pair_tables
    for key in ("contact_force_N", "hertz_stress_MPa", "film_thickness_um", "film_ratio"):
        assert f"{key}_2" in columns, key
        assert not np.allclose(columns[key], columns[f"{key}_2"]), key  # each plate its own


def test_the_columns_peak_at_the_second_plates_true_extreme(pair_tables):
    analysis, columns = pair_tables
    second = analysis.summary()["second_plate"]["dynamics"]
    peak = float(second["hertz_stress_max_MPa"])  # refined on the exact functions
    sampled = float(np.max(columns["hertz_stress_MPa_2"]))
    assert sampled <= peak * (1 + 1e-9)
    assert sampled >= 0.99 * peak  # the table's angles come within 1 % of the true peak


def test_the_film_ratio_is_the_film_over_the_composite_roughness(pair_tables):
    _, columns = pair_tables
    composite = math.hypot(ROUGH_CAM_UM, ROUGH_FOLLOWER_UM)
    loaded = columns["film_thickness_um_2"] > 0
    np.testing.assert_allclose(
        columns["film_ratio_2"][loaded], columns["film_thickness_um_2"][loaded] / composite, rtol=1e-4
    )
