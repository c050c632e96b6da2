"""Design-file validation: every error names the field path, the value and what is allowed."""

from __future__ import annotations

import copy
import math
from typing import Any

import pytest

from camcad.design import DynamicsModel, FollowerKind, Rotation, load_design, parse_design
from camcad.errors import DesignError
from tests.conftest import SAMPLES

GOOD: dict[str, Any] = {
    "cam": {"base_radius": 40.0, "thickness": 8.0, "bore": 10.0},
    "follower": {"type": "translating-roller", "roller_radius": 10.0},
    "motion": [
        {"kind": "rise", "angle": 150, "lift": 20, "law": "vap", "b": 0.1},
        {"kind": "dwell", "angle": 30},
        {"kind": "return", "angle": 150, "lift": 20, "law": "dudley", "degree": 7},
        {"kind": "dwell", "angle": 30},
    ],
}


def broken(path: str, value: Any) -> dict[str, Any]:
    data = copy.deepcopy(GOOD)
    node: Any = data
    keys = path.replace("[", ".").replace("]", "").split(".")
    for key in keys[:-1]:
        node = node[int(key)] if key.isdigit() else node.setdefault(key, {})
    if value is DELETE:
        del node[keys[-1]]
    else:
        node[keys[-1]] = value
    return data


DELETE = object()

CASES = [
    ("motion[1].angle", 31, "motion", "total 360°"),
    ("motion[0].lift", -5, "motion[0].lift", "-5"),
    ("motion[0].b", 1.0, "motion[0].b", "0 < b < 1"),
    ("motion[2].degree", 8, "motion[2].degree", "8"),
    ("motion[0].law", "cycloid", "motion[0].law", "did you mean 'cycloidal'"),
    ("cam.base_radus", 40, "cam.base_radus", "did you mean 'base_radius'"),
    ("cam.base_radius", -3, "cam.base_radius", "must be > 0"),
    ("cam.base_radius", "forty", "cam.base_radius", "expected a number"),
    ("cam.thickness", 0, "cam.thickness", "must be > 0"),
    ("cam.rotation", "clockwise", "cam.rotation", "allowed: ccw, cw"),
    ("cam.bore", 90, "cam.bore", "inside the base circle"),
    ("follower.type", "roller", "follower.type", "translating-roller"),
    ("follower.roller_radius", DELETE, "follower.roller_radius", "is required"),
    ("follower.roller_radius", 0, "follower.roller_radius", "must be > 0"),
    ("motion[2].lift", 15, "motion", "does not close"),
    ("motion[1].lift", 3, "motion[1].lift", "unknown key 'lift'"),
    ("motion[0].kind", "raise", "motion[0].kind", "did you mean 'rise'"),
    ("motion[3].angle", DELETE, "motion[3].angle", "is required"),
    ("fit.tolerance", 0, "fit.tolerance", "must be > 0"),
    ("mesh.formats", ["stl", "step"], "mesh.formats", "unknown format 'step'"),
    ("gcode.dialect", "fanuc", "gcode.dialect", "allowed: linuxcnc, grbl, generic"),
    ("dynamics.gravity", "yes", "dynamics.gravity", "expected true or false"),
    ("dynamcis.follower_mass", 1.0, "dynamcis", "did you mean 'dynamics'"),
]


@pytest.mark.parametrize(
    ("where", "value", "path", "words"), CASES, ids=[c[0] + "=" + repr(c[1]) for c in CASES]
)
def test_bad_designs_name_the_field_and_what_is_allowed(where, value, path, words):
    with pytest.raises(DesignError) as info:
        parse_design(broken(where, value))
    assert info.value.path == path
    assert words in str(info.value)
    assert str(info.value).startswith(path)


def test_a_good_design_converts_units_at_the_edge():
    design = parse_design(broken("cam.max_pressure_angle", 25))
    assert design.cam.max_pressure_angle == pytest.approx(math.radians(25))
    assert design.motion[0].span == pytest.approx(math.radians(150))
    assert design.cam.rotation is Rotation.CCW
    assert design.follower.kind is FollowerKind.TRANSLATING_ROLLER
    assert design.dynamics.model is DynamicsModel.ENERGY
    assert design.motion[2].law is not None and design.motion[2].law.describe().lower().startswith("dudley")


def test_every_sample_loads():
    assert len(SAMPLES) >= 6
    for path in SAMPLES:
        design = load_design(path)
        assert design.cam.name and design.source == str(path)


def test_file_level_errors(tmp_path):
    with pytest.raises(DesignError, match="not found"):
        load_design(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[cam\nbase_radius = 3")
    with pytest.raises(DesignError, match="not valid TOML"):
        load_design(bad)
