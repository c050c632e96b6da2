"""`camcad schema` against the loader, read by an independent JSON Schema validator (jsonschema).

Every shipped sample validates. By property (hypothesis), over every
single-key change of every shipped sample that JSON can hold: when the
schema refuses it the loader refuses it too, and when the loader refuses it
by a key's own rule (:class:`~camcad.errors.ValueRuleError`: a type, a range,
a word) the schema refuses it too. The loader's cross-field rules (a bore
inside the base circle, a lift that closes) stay the loader's alone.

Not expressible in JSON, and so left out of the property: NaN and ±inf (JSON
has no such numbers; the loader refuses them, tested below) and an integral
float such as ``degree = 5.0`` for a whole-number key (JSON does not tell
5.0 from 5; the loader wants a TOML integer).
"""

from __future__ import annotations

import copy
import json
import math
import sys
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camcad.cli import main
from camcad.design import parse_design
from camcad.design.editor_schema import design_json_schema, rule_schema
from camcad.design.tables import _LAW_RULES, _MOTION_RULES, _SECTIONS
from camcad.errors import DesignError, ValueRuleError
from camcad.motion.laws import LAWS

jsonschema = pytest.importorskip("jsonschema")

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

SAMPLES_DIR = Path(__file__).resolve().parents[1] / "samples"
SAMPLES = sorted(SAMPLES_DIR.glob("*.toml"))
VALIDATOR = jsonschema.Draft202012Validator(design_json_schema())
DATA = {p.stem: tomllib.loads(p.read_text(encoding="utf-8")) for p in SAMPLES}
BASE = DATA["quintero_vap_b01"]


def test_the_schema_is_valid_json_schema_and_printed_by_the_cli(capsys):
    jsonschema.Draft202012Validator.check_schema(design_json_schema())
    assert main(["schema"]) == 0
    assert json.loads(capsys.readouterr().out) == design_json_schema()


@pytest.mark.parametrize("path", SAMPLES, ids=[p.stem for p in SAMPLES])
def test_every_sample_validates(path):
    errors = [e.message for e in VALIDATOR.iter_errors(DATA[path.stem])]
    assert errors == []


def test_unknown_keys_and_words_are_flagged():
    bad = {**BASE, "cam": {**BASE["cam"], "base_radus": 40.0}}
    assert not VALIDATOR.is_valid(bad)
    bad = {**BASE, "cam": {**BASE["cam"], "rotation": "clockwise"}}
    assert not VALIDATOR.is_valid(bad)


def test_the_law_rules_are_the_registrys_parameters():
    """Every parameter of every law has a rule, and no rule names a parameter the registry lacks."""
    declared = {(law, p.name) for law, info in LAWS.items() for p in info.parameters}
    ruled = {(law, name) for law, rules in _LAW_RULES.items() for name in rules}
    assert declared == ruled


# ---------------------------------------------------------------------------
# single-key changes


def _paths(sample: str) -> list[tuple[Any, ...]]:
    """Every key a single change can set: those of the sample, and every rule's key in its tables."""
    data = DATA[sample]
    out: set[tuple[Any, ...]] = set()
    for section, rules in _SECTIONS.items():
        if section in data:
            out.update((section, key) for key in (*rules, *data[section]))
    for i, seg in enumerate(data["motion"]):
        out.update(("motion", i, key) for key in seg if not isinstance(seg[key], dict))
        out.update(("motion", i, key, sub) for key in seg if isinstance(seg[key], dict) for sub in seg[key])
        law = seg.get("law")
        out.update(("motion", i, key) for key in _LAW_RULES.get(law, {}) if isinstance(law, str))
        out.update(("motion", i, key) for key in _MOTION_RULES if key != "file")
    return sorted(out, key=str)


def _changed(sample: str, path: tuple[Any, ...], value: Any) -> dict[str, Any]:
    data = copy.deepcopy(DATA[sample])
    node = data
    for key in path[:-1]:
        node = node.setdefault(key, {}) if isinstance(key, str) else node[key]
    node[path[-1]] = value
    return data


def _is_int_key(data: dict[str, Any], path: tuple[Any, ...]) -> bool:
    if path[0] == "motion":
        law = data["motion"][path[1]].get("law")
        rule = _LAW_RULES.get(law, {}).get(path[-1]) if isinstance(law, str) else None
        return rule is not None and rule.kind == "int"
    rule = _SECTIONS[path[0]].get(path[1])
    return rule is not None and rule.kind == "int"


def _field(path: tuple[Any, ...]) -> str:
    if path[0] == "motion":
        return f"motion[{path[1]}]." + ".".join(path[2:])
    return ".".join(path)


def _numbers_of(schema: Any) -> list[float]:
    """Every bound written in the schema: the values at and next to them probe each edge."""
    if isinstance(schema, dict):
        return [n for v in schema.values() for n in _numbers_of(v)]
    if isinstance(schema, list):
        return [n for v in schema for n in _numbers_of(v)]
    if isinstance(schema, int | float) and not isinstance(schema, bool):
        return [float(schema)]
    return []


def _rule_at(sample: str, path: tuple[Any, ...]) -> Any:
    """The loader's rule for the key at ``path`` in ``sample`` (None for a blend value or an unknown key)."""
    if path[0] != "motion":
        return _SECTIONS[path[0]].get(path[1])
    if len(path) > 3:
        return None
    law = DATA[sample]["motion"][path[1]].get("law")
    return _LAW_RULES.get(law, {}).get(path[2]) or _MOTION_RULES.get(path[2])


def _edges(rule: Any) -> list[Any]:
    """The values at and on either side of every bound of a rule, its words and one word too many."""
    if rule is None:
        return [0.0, 1.0, "match"]
    schema = rule_schema(rule)
    out: list[Any] = []
    for n in _numbers_of(schema):
        if rule.kind == "int":
            out += [int(n) - 1, int(n), int(n) + 1] if abs(n) < 1e18 else []
        else:
            out += [n, math.nextafter(n, math.inf), math.nextafter(n, -math.inf)]
    words = schema.get("enum", [])
    out += [*words, *(w.upper() for w in words[:1]), "no-such-word"] if words else []
    return out or [True, "x", 1.0]


# Changes swept at every edge of their rule: every table key on one sample (the rule is the
# same on every sample), and the motion keys on samples whose laws have those parameters.
SWEPT = [
    *(("quintero_vap_b01", (section, key)) for section, rules in _SECTIONS.items() for key in rules),
    *(("quintero_vap_b01", ("motion", 0, key)) for key in ("kind", "law", "angle", "lift", "b")),
    ("web_cutter", ("motion", 1, "degree")),
    ("hren_tappet", ("motion", 0, "degree")),
    ("quintero_vap_b01", ("motion", 0, "start", "v")),
]
EDGE_CASES = [(sample, path, v) for sample, path in SWEPT for v in _edges(_rule_at(sample, path))]


def test_schema_and_loader_agree_at_every_edge_of_every_rule():
    """Deterministic: each bound's value and its neighbours one ulp away (or one unit, for integers)."""
    assert len(EDGE_CASES) > 300
    for sample, path, value in EDGE_CASES:
        _check_agreement(sample, path, value)


GENERIC = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False),
    st.integers(min_value=-(10**30), max_value=10**30),
    st.integers(min_value=-3, max_value=40),
    st.booleans(),
    st.sampled_from(sorted({*LAWS, "table", "rise", "return", "dwell", "close", "match", "ccw", "plate"})),
    st.text(max_size=8),
    st.lists(st.sampled_from(["stl", "STL", "obj", "gltf", "3mf", "Vtu", ""]), max_size=3),
    st.lists(st.floats(min_value=-10.0, max_value=400.0), max_size=40),
)
# measured_table re-smooths its 360-point table on every load (seconds): its keys are covered by
# the sweep and the examples below
RANDOM_SAMPLES = sorted(s for s in DATA if s != "measured_table")


def _change(sample: str) -> st.SearchStrategy[tuple[str, tuple[Any, ...], Any]]:
    def value(path: tuple[Any, ...]) -> st.SearchStrategy[Any]:
        return st.one_of(st.sampled_from(_edges(_rule_at(sample, path))), GENERIC)

    return st.sampled_from(_paths(sample)).flatmap(lambda p: st.tuples(st.just(sample), st.just(p), value(p)))


CHANGES = st.sampled_from(RANDOM_SAMPLES).flatmap(_change)


def _loader(data: dict[str, Any], sample: str) -> DesignError | None:
    try:
        parse_design(data, source=str(SAMPLES_DIR / f"{sample}.toml"))
    except DesignError as err:
        return err
    return None


def _check_agreement(sample: str, path: tuple[Any, ...], value: Any) -> None:
    data = _changed(sample, path, value)
    if isinstance(value, float) and value.is_integer() and _is_int_key(data, path):
        return  # JSON does not tell 5.0 from 5
    schema_ok = VALIDATOR.is_valid(data)
    err = _loader(data, sample)
    if not schema_ok:  # the schema never flags a value the loader accepts
        assert err is not None, (sample, _field(path), value)
    if isinstance(err, ValueRuleError):  # a key's own rule: the schema states it too
        assert not schema_ok, (sample, _field(path), value, err.message)


@settings(max_examples=150, deadline=None)
@given(change=CHANGES)
def test_schema_and_loader_agree_on_every_single_key_change(change):
    _check_agreement(*change)


ISSUE_32 = [  # the changes the schema of issue 32 accepted and the loader refused
    ("quintero_vap_b01", ("motion", 0, "lift"), 1e6),
    ("quintero_vap_b01", ("motion", 0, "b"), 1.5),
    ("web_cutter", ("motion", 1, "degree"), 4),
    ("web_cutter", ("motion", 1, "degree"), 5.5),
    ("measured_table", ("motion", 0, "noise"), 0.0),
    ("measured_table", ("motion", 0, "noise"), 100.0),
    ("quintero_vap_b01", ("mesh", "formats"), ["gltf"]),
    ("quintero_poly4567", ("motion", 0, "law"), "poly-456"),
    ("quintero_vap_b01", ("motion", 0, "b"), 0.0),
    ("hren_tappet", ("motion", 0, "degree"), 8),
    ("quintero_vap_b01", ("cam", "speed_rpm"), 0.0),
    ("measured_table", ("motion", 0, "angle"), 300.0),
]


@pytest.mark.parametrize(
    ("sample", "path", "value"), ISSUE_32, ids=[_field(p) + f"={v}" for _, p, v in ISSUE_32]
)
def test_issue_32_changes_are_refused_by_both(sample, path, value):
    data = _changed(sample, path, value)
    assert not VALIDATOR.is_valid(data)
    err = _loader(data, sample)
    assert isinstance(err, ValueRuleError) and err.path == _field(path), err


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_not_a_number_is_refused_by_the_loader(value):
    """JSON cannot hold NaN or inf; TOML can (``nan``, ``inf``), and the loader refuses them."""
    err = _loader(_changed("quintero_vap_b01", ("cam", "base_radius"), value), "quintero_vap_b01")
    assert isinstance(err, ValueRuleError) and err.path == "cam.base_radius"
    assert "finite" in err.message


def test_the_motion_laws_parameters_are_checked_per_law():
    ok = _changed("quintero_vap_b01", ("motion", 0, "b"), 0.5)
    assert VALIDATOR.is_valid(ok) and _loader(ok, "quintero_vap_b01") is None
    degrees = range(1, 12)
    schema = [d for d in degrees if VALIDATOR.is_valid(_changed("hren_tappet", ("motion", 0, "degree"), d))]
    assert schema == [3, 5, 7, 9, 11]  # hren_tappet's rise is a Dudley polynomial: odd degrees from 3


_FOLLOWER_VALUES = {  # a value of every [follower] key that builds with the base below, whatever the kind
    "roller_radius": 10.0,
    "offset": 1.0,
    "face_width": 200.0,
    "face_margin": 1.0,
    "pivot_distance": 120.0,
    "arm_length": 90.0,
    "face_offset": 0.0,
    "face_radius": 40.0,
}


def _follower_design(follower: dict[str, Any]) -> dict[str, Any]:
    return {
        "cam": {"base_radius": 40.0},
        "follower": follower,
        "motion": [
            {"kind": "rise", "angle": 120.0, "lift": 15.0, "law": "cycloidal"},
            {"kind": "dwell", "angle": 60.0},
            {"kind": "return", "angle": 120.0, "lift": 15.0, "law": "cycloidal"},
            {"kind": "dwell", "angle": 60.0},
        ],
    }


def test_each_follower_types_keys_in_the_schema_are_the_loaders():
    """Issue 33: per type of the registry, its required keys and no other type's; schema and loader agree.

    For every type: its required keys alone load; each missing, and each other key added, is refused
    by the loader naming that key exactly when the schema refuses it.
    """
    from camcad.geometry.followers import DEFAULT_FOLLOWER, FOLLOWER_TYPES, follower_keys

    assert set(_FOLLOWER_VALUES) == set(follower_keys()), "give the new key a value here"
    for kind in FOLLOWER_TYPES.values():
        own = {k.name for k in kind.keys}
        base = {"type": kind.word} | {k: _FOLLOWER_VALUES[k] for k in kind.required}
        variants = [("", base)]
        variants += [(k, {n: v for n, v in base.items() if n != k}) for k in kind.required]
        variants += [(k, base | {k: _FOLLOWER_VALUES[k]}) for k in follower_keys() if k not in kind.required]
        if kind is DEFAULT_FOLLOWER:
            variants += [(k, {n: v for n, v in f.items() if n != "type"}) for k, f in variants]
        for key, follower in variants:
            data = _follower_design(follower)
            schema_ok = not list(VALIDATOR.iter_errors(data))
            try:
                parse_design(data)
                loader_ok = True
            except DesignError as err:
                assert err.path == f"follower.{key}", (kind.word, follower, err)
                loader_ok = False
            assert schema_ok == loader_ok == (key == "" or (key in own and key not in kind.required)), (
                kind.word,
                follower,
            )
