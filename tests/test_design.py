"""Design-file validation: every error names the field path, the value and what is allowed."""

from __future__ import annotations

import copy
import math
from typing import Any

import pytest

from camcad.design import FOLLOWER_TYPES, DynamicsModel, Rotation, load_design, parse_design
from camcad.design.tables import _SECTIONS
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
    ("where", "value", "path", "words"),
    CASES,
    ids=[c[0] + ("-deleted" if c[1] is DELETE else "=" + repr(c[1])) for c in CASES],
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
    assert design.follower.kind is FOLLOWER_TYPES["translating-roller"]
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


# ---------------------------------------------------------------------------
# issue 12: every number in the schema is bounded, and the error names its own field

NUMERIC_RULES = [
    (section, key, rule.kind)
    for section, rules in _SECTIONS.items()
    for key, rule in rules.items()
    if rule.kind in ("float", "int") and (section, key) != ("fit", "max_control_points")
]


@pytest.mark.parametrize(
    ("section", "key", "kind"), NUMERIC_RULES, ids=[f"{s}.{k}" for s, k, _ in NUMERIC_RULES]
)
@pytest.mark.parametrize("sign", [1, -1], ids=["huge", "minus-huge"])
def test_every_number_in_the_schema_has_a_bound_that_names_its_field(section, key, kind, sign):
    value = sign * (10**30 if kind == "int" else 1e308)
    with pytest.raises(DesignError) as info:
        parse_design(broken(f"{section}.{key}", value))
    assert info.value.path == f"{section}.{key}"
    assert "allowed" in str(info.value) or "must be" in str(info.value)
    assert "\n" not in str(info.value) and len(str(info.value)) < 300


@pytest.mark.parametrize("value", [10**400, -(10**400)], ids=["plus", "minus"])
def test_a_huge_integer_for_a_length_is_an_error_not_an_overflow(value):
    with pytest.raises(DesignError) as info:
        parse_design(broken("cam.base_radius", value))
    assert info.value.path == "cam.base_radius"
    assert "digits" in str(info.value) and len(str(info.value)) < 200


def test_a_deeply_nested_value_from_python_gives_a_short_message():
    deep: Any = 1
    for _ in range(5000):
        deep = [deep]
    with pytest.raises(DesignError) as info:
        parse_design(broken("cam.thickness", deep))
    assert info.value.path == "cam.thickness" and len(str(info.value)) < 200


@pytest.mark.parametrize(
    ("toml", "path"),
    [
        ("[cam]\nname = " + "[" * 3000 + "]" * 3000 + "\n", "cam.name"),
        ("[gcode]\nfeed = 1\n[[motion]]\n[[motion]]\nx = " + "{a=" * 3000 + "1" + "}" * 3000, "motion[1].x"),
        ("top = [\n" + "[" * 3000 + "\n" + "]" * 3000 + "\n]\n", "top"),
    ],
    ids=["table-key", "array-of-tables", "multi-line-top-level"],
)
def test_nesting_too_deep_for_the_toml_parser_names_the_field(tmp_path, toml, path):
    file = tmp_path / "deep.toml"
    file.write_text(toml)
    with pytest.raises(DesignError) as info:
        load_design(file)
    assert info.value.path == path
    assert "at most 100 levels" in str(info.value)


@pytest.mark.parametrize(
    ("where", "value", "path", "words"),
    [
        ("cam.keyway_width", 3.0, "cam.keyway_depth", "both"),
        ("cam.keyway_depth", 2.0, "cam.keyway_width", "both"),
        ("dynamics.wire_diameter", 2.0, "dynamics.coil_diameter", "is required"),
        ("gcode.step_down", 0.001, "gcode.step_down", "8500 passes"),
        ("gcode.tab_count", 10**12, "gcode.tab_count", "0 to 100"),
        ("cam.sample_step_deg", 1e-6, "cam.sample_step_deg", "72000 samples"),
        ("tables.step_deg", 1e-7, "tables.step_deg", "36000 rows"),
        ("dxf.chord_tolerance", 1e-9, "dxf.chord_tolerance", "0.0001 to 10 mm"),
        ("mesh.chord_tolerance", 1e-9, "mesh.chord_tolerance", "0.0001 to 10 mm"),
        ("motion[1].angle", 1e-6, "motion[1].angle", "0.01 to 360"),
        ("cam.name", "x" * 201, "cam.name", "200 characters"),
    ],
)
def test_cross_field_and_resolution_errors_name_the_field_at_fault(where, value, path, words):
    with pytest.raises(DesignError) as info:
        parse_design(broken(where, value))
    assert info.value.path == path
    assert words in str(info.value)


def test_a_keyway_too_deep_blames_the_keyway_and_states_the_room_left():
    data = broken("cam.keyway_width", 3.0)
    data["cam"]["keyway_depth"] = 36.0  # bore 10 mm: 5 + 36 > 40
    with pytest.raises(DesignError) as info:
        parse_design(data)
    assert info.value.path == "cam.keyway_depth"
    assert "< 35 mm" in str(info.value)  # 40 - 10 / 2
    data["cam"]["keyway_depth"] = 34.9
    assert parse_design(data).cam.keyway_depth == 34.9


def test_an_unknown_key_with_a_newline_keeps_the_message_on_one_line():
    with pytest.raises(DesignError) as info:
        parse_design(broken("cam.evil\nkey", 1))
    assert "\n" not in str(info.value)
    assert info.value.path == "cam.'evil\\nkey'"


@pytest.mark.parametrize(
    ("where", "value"),
    [
        ("cam.base_radius", 10_000.0),
        ("cam.thickness", 0.001),
        ("follower.offset", -49.999),
        ("cam.speed_rpm", 100_000.0),
        ("cam.sample_step_deg", 0.005),
        ("tables.step_deg", 0.01),
        ("dxf.chord_tolerance", 1e-4),
        ("gcode.tab_count", 100),
        ("gcode.tool_number", 99_999),
        ("gcode.start_angle", -360.0),
    ],
)
def test_the_bounds_themselves_are_allowed(where, value):
    parse_design(broken(where, value))


def test_the_total_lift_is_bounded_where_it_is_exceeded():
    data = copy.deepcopy(GOOD)
    data["motion"] = [
        {"kind": "rise", "angle": 90, "lift": 6000, "law": "cycloidal"},
        {"kind": "rise", "angle": 90, "lift": 6000, "law": "cycloidal"},
        {"kind": "return", "angle": 90, "lift": 6000, "law": "cycloidal"},
        {"kind": "return", "angle": 90, "lift": 6000, "law": "cycloidal"},
    ]
    with pytest.raises(DesignError) as info:
        parse_design(data)
    assert info.value.path == "motion[1].lift"
    assert "12000 mm above the base circle" in str(info.value)


def test_bore_helix_turns_are_bounded_through_the_tool_diameter():
    data = broken("gcode.mill_bore", True)
    data["gcode"].update(tool_diameter=0.001, step_down=5.0)
    data["cam"].update(thickness=1000.0, bore=0.004)  # 1000.5 mm deep at ≥ 0.0001 mm a turn
    with pytest.raises(DesignError) as info:
        parse_design(data)
    assert info.value.path == "gcode.tool_diameter"
    assert "10005000 helix turns" in str(info.value) and "≥ 0.10005 mm" in str(
        info.value
    )  # 1000.5 / (0.1 × 100000)
    data["gcode"]["tool_diameter"] = 0.1  # 1000 mm deep: exactly 100000 turns at worst
    data["cam"]["thickness"] = 999.5
    assert parse_design(data).gcode.tool_diameter == 0.1


def test_the_python_api_accepts_numpy_numbers_and_rejects_unwritable_names():
    np = pytest.importorskip("numpy")
    design = parse_design(broken("gcode.tab_count", np.int64(2)))
    assert design.gcode.tab_count == 2 and type(design.gcode.tab_count) is int
    assert parse_design(broken("cam.base_radius", np.float32(40.0))).cam.base_radius == 40.0
    with pytest.raises(DesignError) as info:
        parse_design(broken("cam.name", "a\ud800b"))
    assert info.value.path == "cam.name"
    with pytest.raises(DesignError) as info:
        parse_design(broken("cam.5", 1))  # a key that is not a string
    assert info.value.path == "cam.5"
