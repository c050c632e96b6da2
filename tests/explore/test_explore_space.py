"""Variables, Latin-hypercube sampling, the Pareto filter and the TOML writer, against their definitions."""

from __future__ import annotations

import math

import numpy as np
import pytest
import tomllib
from hypothesis import given, settings
from hypothesis import strategies as st

from camcad.design import parse_design
from camcad.design.toml_text import toml_text
from camcad.errors import UsageError
from camcad.explore.pareto import pareto_mask
from camcad.explore.space import apply_values, grid_points, lhs_points, parse_variable
from tests.conftest import SAMPLES
from tests.explore.cases import sample_data


def test_short_names_and_paths():
    data = sample_data("offset_roller")
    assert parse_variable("base_radius=30:80:6", data, flag="--grid", counted=True).path == "cam.base_radius"
    assert parse_variable("offset=0:20", data, flag="--vary", counted=False).path == "follower.offset"
    assert parse_variable("law=cycloidal,harmonic", data, flag="--grid", counted=True).path == "motion[*].law"
    assert parse_variable(
        "law.b=0.1,0.2", sample_data("quintero_vap_b01"), flag="--grid", counted=True
    ).path == ("motion[*].b")
    v = parse_variable("dynamics.spring_rate=0.5:2:4", data, flag="--grid", counted=True)
    assert v.grid() == (0.5, 1.0, 1.5, 2.0)


def test_grid_is_the_product_last_variable_fastest():
    data = sample_data("offset_roller")
    a = parse_variable("base_radius=40:60:3", data, flag="--grid", counted=True)
    b = parse_variable("law=cycloidal,harmonic", data, flag="--grid", counted=True)
    assert grid_points([a, b]) == [
        (40.0, "cycloidal"), (40.0, "harmonic"), (50.0, "cycloidal"),
        (50.0, "harmonic"), (60.0, "cycloidal"), (60.0, "harmonic"),
    ]  # fmt: skip


def test_law_choice_keeps_only_the_new_laws_parameters():
    """VAP's b goes when the law becomes cycloidal; every rise and return takes the law; it validates."""
    data = sample_data("quintero_vap_b01")
    law = parse_variable("law=cycloidal", data, flag="--grid", counted=True)
    out = apply_values(data, [law], ["cycloidal"])
    moving = [s for s in out["motion"] if s["kind"] != "dwell"]
    assert moving and all(s["law"] == "cycloidal" and "b" not in s for s in moving)
    assert data["motion"][0]["law"] == "vap"  # the base mapping is left alone
    parse_design(out)


@pytest.mark.parametrize(
    "text",
    [
        "base_radius",
        "=3:4",
        "base_radus=1:2",
        "base_radius=a:b:3",
        "base_radius=1:2:0",
        "base_radius=2:1:3",
        "base_radius=1:2:3:4",
        "base_radius=0:80:3",
        "motion[7].law=cycloidal",
        "motion.law=cycloidal",
        "cam[0].base_radius=1:2:3",
        "law=cycloidal,cycloidal",
        "motion[1].b=0.1",
        "follower.pivot_distance=100:200:3",
    ],
)
def test_bad_variables_are_usage_errors_naming_the_flag(text):
    with pytest.raises(UsageError) as info:
        parse_variable(text, sample_data("offset_roller"), flag="--grid", counted=True)
    assert info.value.path == "--grid"


def test_a_cross_field_limit_at_a_range_end_is_left_to_the_rows():
    """An offset beyond r_b + r_f at the file's r_b may be fine at a larger r_b of the same grid."""
    data = sample_data("offset_roller")
    v = parse_variable("offset=0:150:4", data, flag="--grid", counted=True)
    assert v.grid()[-1] == 150.0


@settings(max_examples=40, deadline=None)
@given(samples=st.integers(1, 60), seed=st.integers(0, 2**32 - 1))
def test_latin_hypercube_uses_each_stratum_once(samples, seed):
    """Latin hypercube: for every variable each of n equal strata of its range holds exactly one design."""
    data = sample_data("offset_roller")
    variables = [
        parse_variable("base_radius=20:120", data, flag="--grid", counted=False),
        parse_variable("offset=-10:30", data, flag="--grid", counted=False),
        parse_variable("law=cycloidal,harmonic,poly-345", data, flag="--grid", counted=False),
    ]
    points = lhs_points(variables, samples, seed=seed)
    assert points == lhs_points(variables, samples, seed=seed)  # reproducible
    for j, (low, high) in enumerate([(20.0, 120.0), (-10.0, 30.0)]):
        strata = sorted(min(int((p[j] - low) / (high - low) * samples), samples - 1) for p in points)
        assert strata == list(range(samples))
    counts = np.bincount([["cycloidal", "harmonic", "poly-345"].index(p[2]) for p in points], minlength=3)
    assert counts.max() - counts.min() <= math.ceil(samples / 3) - math.floor(samples / 3) + 1


def _brute_front(f1, f2):
    """The definition, O(n²): no other point at least as good in both and better in one; NaN never on it."""
    n = len(f1)
    out = []
    for i in range(n):
        if math.isnan(f1[i]) or math.isnan(f2[i]):
            out.append(False)
            continue
        out.append(
            not any(
                f1[j] <= f1[i] and f2[j] <= f2[i] and (f1[j] < f1[i] or f2[j] < f2[i])
                for j in range(n)
                if not (math.isnan(f1[j]) or math.isnan(f2[j]))
            )
        )
    return out


@settings(max_examples=200, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.one_of(st.integers(0, 6).map(float), st.just(math.nan)),
            st.one_of(st.integers(0, 6).map(float), st.just(math.nan)),
        ),
        max_size=40,
    )
)
def test_pareto_mask_equals_the_dominance_definition(points):
    """The sort-and-scan filter against the O(n²) definition, ties and NaNs included."""
    f1 = [p[0] for p in points]
    f2 = [p[1] for p in points]
    assert pareto_mask(f1, f2).tolist() == _brute_front(f1, f2)


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_toml_text_round_trips_every_sample(path):
    """A sample's mapping written by toml_text and read by tomllib is the same mapping and the same Design."""
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    again = tomllib.loads(toml_text(data, header="a header\nover two lines"))
    assert again == data
    assert parse_design(again, source=str(path)) == parse_design(data, source=str(path))


_keys = st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), min_size=1, max_size=8)
_values = st.one_of(
    st.booleans(),
    st.integers(-(2**62), 2**62),
    st.floats(allow_nan=False, allow_infinity=False),
    st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=12),
    st.lists(st.text(max_size=4), max_size=3),
    st.dictionaries(_keys, st.integers(-5, 5), max_size=2),
)


@settings(max_examples=100, deadline=None)
@given(
    st.dictionaries(_keys, st.dictionaries(_keys, _values, max_size=4), max_size=3),
    st.lists(st.dictionaries(_keys, _values, max_size=3), max_size=3),
)
def test_toml_text_round_trips_any_table(tables, motion):
    """tomllib reads back exactly what toml_text wrote: floats to the bit, any text, keys quoted if needed."""
    data = {**tables}
    data.pop("motion", None)
    if motion:
        data["motion"] = motion
    assert tomllib.loads(toml_text(data)) == data


_TOML_LEAF = st.one_of(
    st.none(), st.booleans(), st.integers(), st.floats(allow_nan=False), st.text(max_size=4)
)
_TOML_TREE = st.recursive(
    _TOML_LEAF,
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=3), inner, max_size=3),
    max_leaves=12,
)


def _containers(value: object) -> list[object]:
    if isinstance(value, dict):
        return [value, *(c for v in value.values() for c in _containers(v))]
    if isinstance(value, list):
        return [value, *(c for v in value for c in _containers(v))]
    return []


@settings(max_examples=80, deadline=None)
@given(tree=_TOML_TREE)
def test_tree_copy_is_deepcopy(tree) -> None:
    """tree_copy (a sweep's per-variant copy) is copy.deepcopy and shares no dict or list with its input."""
    import copy

    from camcad._typing import tree_copy

    got = tree_copy(tree)
    assert got == copy.deepcopy(tree)
    assert repr(got) == repr(tree)  # the same types, in the same order
    mine = {id(c) for c in _containers(tree)}
    assert not mine & {id(c) for c in _containers(got)}
