"""The FE check of every made plate of a cam family, each loaded by its own roller (issues 22, 33).

A conjugate pair (a yoke) whose second roller is smaller than the first:
each plate's load cases carry the Hertz peak pressure of that plate's own
contact, p₀ = √(F·E*/(π·L·R)) with 1/R = 1/ρ + 1/r_f (Johnson 1985, eq. 4.45),
evaluated here from the case's force, the plate's radius of curvature by
central differences of its profile points, and its own roller's radius.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from camcad import pipeline
from camcad.design import parse_design
from camcad.errors import DesignError

E_STAR = 206000.0 / (2.0 * (1.0 - 0.3**2))  # 1/E* = 2(1 − ν²)/E, two steels (Johnson 1985, §4.2)
WIDTH = 10.0


def _pair(**extra: dict) -> dict:
    return {
        "cam": {
            "base_radius": 50.0,
            "speed_rpm": 300.0,
            "thickness": 12.0,
            "bore": 16.0,
            "style": "conjugate",
        },
        "follower": {"roller_radius": 12.0},
        "conjugate": {"roller_radius": 8.0},
        "motion": [
            {"kind": "rise", "angle": 120.0, "lift": 20.0, "law": "cycloidal"},
            {"kind": "dwell", "angle": 60.0},
            {"kind": "return", "angle": 120.0, "lift": 20.0, "law": "modified-sine"},
            {"kind": "dwell", "angle": 60.0},
        ],
        "dynamics": {"follower_mass": 2.0, "contact_width": WIDTH},
        "fea": {"contact_divisions": 2, "growth": 1.0, "mesh_size": 20.0},
        **extra,
    }


def _radius(cam, phi: float) -> float:
    """The profile's radius of curvature at φ [mm], convex positive, by central differences."""
    h = 1e-4
    a, b, c = np.asarray(cam.profile(np.array([phi - h, phi, phi + h])).point, dtype=float)
    d1, d2 = (c - a) / (2.0 * h), (c - 2.0 * b + a) / h**2
    kappa = (d1[0] * d2[1] - d1[1] * d2[0]) / np.hypot(*d1) ** 3
    a, b, c = np.asarray(cam.profile(np.radians([149.9999, 150.0, 150.0001])).point, dtype=float)
    dwell = ((c - a)[0] * (c - 2 * b + a)[1] - (c - a)[1] * (c - 2 * b + a)[0]) > 0.0  # base circle: convex
    return (1.0 if dwell else -1.0) / kappa


@pytest.fixture(scope="module")
def pair():
    return pipeline.analyse(parse_design(_pair()), fit=False, toolpath=False, strict=False, fea=True)


def test_each_plate_of_a_pair_is_checked_with_its_own_roller(pair):
    first, second = pair.parts
    assert first.fea is not None and second.fea is not None
    for result in pair.parts:
        cam = result.part.cam
        assert result.fea.cases
        for sc in result.fea.cases:
            c = sc.case
            rho = _radius(cam, c.phi)
            expect = math.sqrt(c.force * E_STAR / (math.pi * WIDTH) * (1.0 / rho + 1.0 / cam.roller_radius))
            assert c.peak_pressure == pytest.approx(expect, rel=1e-4)
        peak = max(sc.case.force for sc in result.fea.cases)
        assert peak == pytest.approx(result.dynamics.contact_force_max.value, rel=1e-9)
    summary = pair.summary()
    assert summary["fea"] == first.fea.summary()
    assert summary["second_plate"]["fea"] == second.fea.summary()
    assert (
        summary["fea"]["cases"][0]["hertz_stress_MPa"]
        != summary["second_plate"]["fea"]["cases"][0]["hertz_stress_MPa"]
    )


def test_each_made_plate_gets_its_stress_file(tmp_path):
    design = parse_design(_pair())
    built = pipeline.build(design, tmp_path / "out", only=["fea"], parallel=False)
    names = sorted(p.name for p in built.files)
    assert "stress.vtu" in names and "stress_2.vtu" in names
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["second_plate"]["fea"]["nodes"] > 0


def test_a_groove_has_no_plate_to_check():
    data = _pair()
    data["cam"] = {**data["cam"], "style": "groove", "outer_radius": 110.0}
    del data["conjugate"]
    data["groove"] = {"depth": 6.0}
    with pytest.raises(DesignError) as err:
        parse_design(data)
    assert err.value.path == "fea" and "'plate' or 'conjugate'" in str(err.value)
