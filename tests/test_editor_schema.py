"""`camcad schema` against the loader, read by an independent JSON Schema validator (jsonschema).

Every shipped sample validates; for every numeric key, random values the
schema refuses are refused by the loader naming that key, and values the
loader refuses with a range message are refused by the schema.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camcad.cli import main
from camcad.design import parse_design
from camcad.design.editor_schema import design_json_schema
from camcad.errors import DesignError

jsonschema = pytest.importorskip("jsonschema")

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

SAMPLES = sorted((Path(__file__).resolve().parents[1] / "samples").glob("*.toml"))
VALIDATOR = jsonschema.Draft202012Validator(design_json_schema())
BASE = tomllib.loads((Path(__file__).resolve().parents[1] / "samples" / "quintero_vap_b01.toml").read_text())
NUMERIC = [
    (section, key)
    for section, table in design_json_schema()["properties"].items()
    if section in BASE and section != "motion"
    for key, prop in table["properties"].items()
    if "minimum" in prop or "exclusiveMinimum" in prop or "anyOf" in prop
]


def test_the_schema_is_valid_json_schema_and_printed_by_the_cli(capsys):
    jsonschema.Draft202012Validator.check_schema(design_json_schema())
    assert main(["schema"]) == 0
    assert json.loads(capsys.readouterr().out) == design_json_schema()


@pytest.mark.parametrize("path", SAMPLES, ids=[p.stem for p in SAMPLES])
def test_every_sample_validates(path):
    errors = [e.message for e in VALIDATOR.iter_errors(tomllib.loads(path.read_text(encoding="utf-8")))]
    assert errors == []


def test_unknown_keys_and_words_are_flagged():
    bad = {**BASE, "cam": {**BASE["cam"], "base_radus": 40.0}}
    assert not VALIDATOR.is_valid(bad)
    bad = {**BASE, "cam": {**BASE["cam"], "rotation": "clockwise"}}
    assert not VALIDATOR.is_valid(bad)


@settings(max_examples=300, deadline=None)
@given(
    where=st.sampled_from(NUMERIC),
    value=st.one_of(
        st.floats(allow_nan=False, allow_infinity=False, width=64),
        st.floats(min_value=-2.0, max_value=400.0),
        st.sampled_from([0.0, 1e-7, 0.001, 0.1, 0.5, 1.0, 10.0, 90.0, 1e4, 1e5, 1e7]),
    ),
)
def test_schema_and_loader_agree_on_one_key(where, value):
    section, key = where
    data = {**BASE, section: {**BASE[section], key: value}}
    schema_ok = VALIDATOR.is_valid(data)
    try:
        parse_design(data)
        loader_error = None
    except DesignError as err:
        loader_error = err
    if not schema_ok:  # the schema never flags a value the loader accepts
        assert loader_error is not None and loader_error.path == f"{section}.{key}", (where, value)
    # the key's own range: the loader states the schema's allowed text (cross-field rules such as
    # "roller_radius > 0 for a roller follower" are the loader's alone)
    own = design_json_schema()["properties"][section]["properties"][key]["description"].removeprefix(
        "allowed: "
    )
    if loader_error is not None and loader_error.path == f"{section}.{key}" and own in loader_error.message:
        assert not schema_ok, (where, value, loader_error.message)
