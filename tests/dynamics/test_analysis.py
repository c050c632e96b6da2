"""The entry point analyse_dynamics and its DynamicsResult (summary, CSV rows)."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from camcad.design import DynamicsModel
from camcad.dynamics import DynamicsResult, analyse_dynamics
from camcad.geometry.cam import Cam
from tests.dynamics.test_energy import paper_design
from tests.dynamics.test_tappet import table1_design

SUMMARY_KEYS = {
    f"{name}_{suffix}"
    for name, unit in (
        ("torque_max", "Nmm"),
        ("torque_min", "Nmm"),
        ("contact_force_max", "N"),
        ("contact_force_min", "N"),
        ("hertz_stress_max", "MPa"),
    )
    for suffix in (unit, "angle_deg", "side")
} | {"jump", "jump_range_deg", "min_preload_N", "speed_range_rpm"}


def analyse(design, step=None) -> DynamicsResult:
    cam = Cam.from_design(design)
    phi = cam.sample_phi(step)
    return analyse_dynamics(
        cam.motion(phi),
        pressure_angle=cam.pressure_angle(phi),
        profile_rho=cam.profile(phi).rho,
        setup=design.dynamics_setup(),
    )


@pytest.mark.parametrize(
    "design",
    [paper_design("vap", {"b": 0.1}), table1_design()],
    ids=["energy", "guided-tappet"],
)
def test_summary_and_read_only_arrays(design):
    result = analyse(design, step=math.radians(1.0))
    assert result.model is design.dynamics.model
    summary = result.summary()
    assert set(summary) == SUMMARY_KEYS
    json.dumps(summary)  # plain Python values only
    k = int(np.argmax(result.torque))
    assert summary["torque_max_Nmm"] == result.torque[k]
    assert summary["torque_max_angle_deg"] == pytest.approx(math.degrees(result.phi[k]))
    for arr in (result.phi, result.contact_force, result.torque, result.hertz_stress):
        assert not arr.flags.writeable
    tappet = design.dynamics.model is DynamicsModel.GUIDED_TAPPET
    assert (result.normal_force is not None) == tappet


def test_allowable_stress_warns():
    design = paper_design("harmonic")
    peak = analyse(design).summary()["hertz_stress_max_MPa"]
    strict = replace(design, dynamics=replace(design.dynamics, allowable_stress=0.5 * peak))
    (found,) = analyse(strict).findings
    assert found.kind == "contact stress" and "above the allowable" in found.message
    lax = replace(design, dynamics=replace(design.dynamics, allowable_stress=2.0 * peak))
    assert analyse(lax).findings == ()


def test_contact_width_overrides_the_cam_thickness():
    """σ ∝ 1/√L: half the width, √2 times the stress."""
    design = paper_design("harmonic")
    thick = analyse(design).hertz_stress
    half = replace(design, dynamics=replace(design.dynamics, contact_width=design.cam.thickness / 2))
    np.testing.assert_allclose(analyse(half).hertz_stress, math.sqrt(2.0) * thick, rtol=1e-12)


def test_convex_roller_stress_by_hand():
    """On the top dwell of the 000 case (s = 30 mm) the cam is a circle of radius 40 + 30 = 70 mm.

    F_C = m g + k s = 1.63 + 0.1·30 = 4.63 N, 1/R* = 1/70 + 1/20, L = 10 mm
    (cam thickness), E* = 206000/1.82 MPa:
    σ = √(4.63·113186.81·(1/70 + 1/20)/(π·10)) = 32.75 MPa.
    """
    design = paper_design("harmonic")
    cam = Cam.from_design(design)
    phi = np.radians([200.0])
    result = analyse_dynamics(
        cam.motion(phi),
        pressure_angle=cam.pressure_angle(phi),
        profile_rho=cam.profile(phi).rho,
        setup=design.dynamics_setup(),
    )
    assert result.contact_force[0] == pytest.approx(4.63, rel=1e-12)
    expected = math.sqrt(4.63 * (206000 / 1.82) * (1 / 70 + 1 / 20) / (math.pi * 10.0))
    assert expected == pytest.approx(32.75, abs=0.01)
    assert result.hertz_stress[0] == pytest.approx(expected, rel=1e-9)


def test_array_lengths_must_match():
    design = paper_design("harmonic")
    cam = Cam.from_design(design)
    phi = np.radians([10.0, 20.0])
    with pytest.raises(ValueError, match="pressure_angle has 1 samples"):
        analyse_dynamics(
            cam.motion(phi), pressure_angle=[0.0], profile_rho=[1.0, 1.0], setup=design.dynamics_setup()
        )
