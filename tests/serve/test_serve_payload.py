"""What the designer sends is what a screen needs and loses no extreme (issue 37's latency work).

The min-max decimation against a brute-force pass over every bucket (Hypothesis: any length,
bucket count and gaps); each chart of a real answer against the full-grid arrays of ``analyse()``:
the same largest and smallest value, and every sent sample a sample of the grid, not an
interpolation; the answer encodes as strict JSON as it is (no second pass over it).
"""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camcad.design import parse_design
from camcad.pipeline import analyse
from camcad.serve.payload import CHART_BUCKETS, OUTLINE_POINTS, decimate, evaluate
from tests.conftest import ROOT

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib


@st.composite
def _columns(draw):
    """1-3 columns of one length: random values (ties when quantized) with NaN gaps of any density."""
    n = draw(st.integers(1, 3000))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    gaps = draw(st.sampled_from([0.0, 0.002, 0.05, 0.5, 1.0]))
    ties = draw(st.booleans())
    columns = []
    for _ in range(draw(st.integers(1, 3))):
        col = np.cumsum(rng.normal(size=n)) if draw(st.booleans()) else rng.normal(size=n) * 1e3
        if ties:
            col = np.round(col)
        col[rng.random(n) < gaps] = np.nan
        columns.append(col)
    return columns


@settings(max_examples=200, deadline=None)
@given(_columns(), st.integers(1, 400))
def test_decimation_keeps_every_buckets_extremes_and_gap_edges(columns, buckets):
    n = len(columns[0])
    kept = decimate(columns, buckets)
    assert np.all(np.diff(kept) > 0) and (n == 0 or (kept[0] == 0 and kept[-1] == n - 1))
    if n <= 2 * buckets:
        assert kept.tolist() == list(range(n))
        return
    size = -(-n // buckets)
    chosen = set(kept.tolist())
    for col in columns:
        for start in range(0, n, size):  # brute force: every bucket's own smallest and largest value
            part = col[start : start + size]
            if np.isnan(part).all():
                continue
            inside = kept[(kept >= start) & (kept < start + size)]
            for extreme in (np.nanmin(part), np.nanmax(part)):
                assert np.any(col[inside] == extreme)
        for i in np.flatnonzero(np.isnan(col[:-1]) != np.isnan(col[1:])):  # a gap starts or ends:
            assert i in chosen and i + 1 in chosen  # both samples kept, so the line breaks there
    assert len(kept) <= 2 + len(columns) * (2 * buckets + 2 * (n - 1))


@pytest.mark.parametrize(
    "sample", ["quintero_vap_b01", "groove_rocker", "indexing_conjugate", "rotary_plate"]
)
def test_each_chart_reaches_the_grid_extremes_and_the_answer_is_strict_json(sample):
    data = tomllib.loads((ROOT / "samples" / f"{sample}.toml").read_text(encoding="utf-8"))
    out = evaluate(data)
    assert out["ok"], out["errors"]
    json.dumps(out, allow_nan=False)  # plain finite numbers: the server encodes it as it is
    analysis = analyse(parse_design(data), fit=False, toolpath=False, strict=False)
    grid = np.degrees(np.asarray(analysis.geometry.phi))
    full = {
        "s": analysis.motion.s,
        "a": analysis.motion.a,
        "pressure": np.degrees(analysis.geometry.pressure_angle),
        "torque": analysis.dynamics.torque,
    }
    for chart in out["charts"]:
        phi = np.asarray(chart["phi_deg"])
        assert len(phi) <= 2 + 2 * CHART_BUCKETS * len(chart["series"]) + 20
        index = np.searchsorted(grid, phi - 1e-4)
        np.testing.assert_allclose(grid[index], phi, atol=1e-4)  # grid samples, none made up
        if chart["key"] in full:
            y = np.asarray(chart["series"][0]["y"], dtype=float)
            values = np.asarray(full[chart["key"]], dtype=float)
            assert y.max() == pytest.approx(values.max(), abs=1e-6)
            assert y.min() == pytest.approx(values.min(), abs=1e-6)
            np.testing.assert_allclose(y, values[index], atol=1e-6)
    joints = np.degrees([bp.phi for bp in analysis.cam.program.breakpoints]) % 360.0
    for chart in out["charts"]:  # every blend point is a sample of every chart
        phi = np.asarray(chart["phi_deg"])
        assert all(np.min(np.abs(phi - j)) < 1e-4 for j in joints if j < grid[-1] + 1e-9)
    profile = out["drawing"]["profile"]
    assert len(profile) <= OUTLINE_POINTS
    assert np.hypot(*np.asarray(profile).T).max() == pytest.approx(
        out["drawing"]["profile_radius_max"], abs=5e-3
    )


def test_an_edit_that_leaves_the_vibration_inputs_reuses_their_analysis():
    """The speed map (seconds) is kept by its inputs: a new base radius reuses it, a new stiffness does
    not; the kept result equals analyse_vibration() called afresh (summary.json's vibration section)."""
    from dataclasses import replace

    from camcad.design import load_design
    from camcad.dynamics.vibration import analyse_vibration
    from camcad.geometry import Cam

    design = load_design(ROOT / "samples" / "vibration_speed_map.toml")
    design = replace(design, vibration=replace(design.vibration, speed_points=5))  # a quick map
    first = analyse(design, fit=False, toolpath=False, strict=False)
    wider = replace(design, cam=replace(design.cam, base_radius=design.cam.base_radius + 5.0))
    assert analyse(wider, fit=False, toolpath=False, strict=False).vibration is first.vibration
    setup = design.dynamics_setup()
    fresh = analyse_vibration(
        Cam.from_design(design).program,
        design.vibration,
        design.dynamics,
        speed_rpm=design.cam.speed_rpm,
        arm_angle=setup.arm_angle,
        spring_loaded=not setup.positive_drive,
    )
    assert json.dumps(fresh.summary(), default=str) == json.dumps(first.vibration.summary(), default=str)
    stiffer = replace(design, vibration=replace(design.vibration, stiffness=2 * design.vibration.stiffness))
    other = analyse(stiffer, fit=False, toolpath=False, strict=False).vibration
    assert other is not first.vibration and other.summary() != first.vibration.summary()
