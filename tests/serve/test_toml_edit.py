"""Save's in-place TOML edit, by property: any change of keys reads back (tomllib) as the new mapping,
and every line of the file the change does not touch is kept as it was (comments, spacing, order)."""

from __future__ import annotations

import copy
import re
import sys
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from camcad.serve.toml_edit import edit_toml

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

SAMPLES = Path(__file__).resolve().parents[2] / "samples"
TEXT = (SAMPLES / "measured_table.toml").read_text(encoding="utf-8")
OLD = tomllib.loads(TEXT)

_values = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False),
    st.integers(-(2**63), 2**63 - 1),
    st.booleans(),
    st.text(max_size=12),
    st.lists(st.floats(allow_nan=False, allow_infinity=False), max_size=3),
)
_keys = st.text("abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=10)
_tables = [("cam",), ("follower",), ("dynamics",), ("tables",), ("gcode",), ("motion", 0)]


def _table(data, where):
    return data[where[0]][where[1]] if len(where) == 2 else data[where[0]]


@st.composite
def changes(draw):
    """A new mapping: some keys changed, removed or added, maybe a new table, a table removed."""
    new = copy.deepcopy(OLD)
    touched = set()
    for _ in range(draw(st.integers(1, 6))):
        where = draw(st.sampled_from(_tables))
        table = _table(new, where)
        action = draw(st.sampled_from(["change", "remove", "add"]))
        if action == "add" or not table:
            key = draw(_keys)
            table[key] = draw(_values)
        else:
            key = draw(st.sampled_from(sorted(table)))
            if action == "remove":
                del table[key]
            else:
                table[key] = draw(_values)
        touched.add((where[0], key))
    if draw(st.booleans()):
        new["fit"] = {"tolerance": draw(st.floats(1e-6, 1.0))}
    if draw(st.booleans()):
        del new["gcode"]
        touched |= {("gcode", k) for k in OLD["gcode"]} | {("gcode", "")}
    return new, touched


def _untouched_lines(touched):
    """The original's lines that no change touches: (line, its table)."""
    section = ""
    for line in TEXT.splitlines():
        header = re.match(r"\[\[?([a-z_]+)\]\]?", line)
        if header:
            section = header.group(1)
        key = re.match(r"([A-Za-z0-9_]+)\s*=", line)
        if (section, key.group(1) if key else "") in touched or (section, "") in touched:
            continue
        yield line


@settings(max_examples=150, deadline=None)
@given(changes())
def test_an_edit_reads_back_as_the_new_mapping_and_keeps_every_other_line(change):
    new, touched = change
    out = edit_toml(TEXT, OLD, new)
    assert tomllib.loads(out) == new
    lines = out.splitlines()
    for line in _untouched_lines(touched):
        assert line in lines, line


def test_unchanged_numbers_keep_their_spelling():
    """55 typed for a file's 55.0 is the same value: the line is not rewritten."""
    new = copy.deepcopy(OLD)
    new["cam"]["base_radius"] = 45
    assert edit_toml(TEXT, OLD, new) == TEXT


def test_motion_tables_added_and_deleted_read_back():
    """A segment added is a new [[motion]] table at the end, one deleted is gone; the rest as it was."""
    longer = copy.deepcopy(OLD)
    longer["motion"].append({"kind": "dwell", "angle": 10.0, "start": {"v": 0.0}})
    out = edit_toml(TEXT, OLD, longer)
    assert tomllib.loads(out) == longer
    assert out.startswith(TEXT.split("[[motion]]")[0])  # everything before the motion untouched
    shorter = copy.deepcopy(OLD)
    del shorter["motion"][-1]
    out = edit_toml(TEXT, OLD, shorter)
    assert tomllib.loads(out) == shorter
    assert out.count("[[motion]]") == len(OLD["motion"]) - 1
