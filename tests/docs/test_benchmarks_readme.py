"""benchmarks/_readme.py replaces one marked section of benchmarks/README.md and nothing else (issue 39)."""

from __future__ import annotations

import importlib.util
import re
import sys

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.conftest import ROOT

_spec = importlib.util.spec_from_file_location("bench_readme", ROOT / "benchmarks" / "_readme.py")
assert _spec is not None and _spec.loader is not None
bench = importlib.util.module_from_spec(_spec)
sys.modules["bench_readme"] = bench
_spec.loader.exec_module(bench)

SCRIPTS = sorted(p for p in (ROOT / "benchmarks").glob("*.py") if not p.name.startswith("_"))
text_without_markers = st.text(alphabet=st.characters(blacklist_characters="<>"), max_size=200)


def test_a_section_is_replaced_and_the_rest_kept_byte_for_byte():
    old = "# B\n\nintro\n\n<!-- BEGIN fit -->\nold table\n<!-- END fit -->\n\n"
    old += "tail <!-- BEGIN gcode -->\nx\n<!-- END gcode -->\n"
    new = bench.replace_section(old, "fit", "| a |\n| --- |\n| 1 |\n")
    assert new == old.replace("old table", "| a |\n| --- |\n| 1 |")
    assert bench.replace_section(new, "fit", "| a |\n| --- |\n| 1 |") == new  # idempotent


@given(head=text_without_markers, tail=text_without_markers, body=text_without_markers)
def test_only_the_named_section_changes(head, tail, body):
    old = f"{head}<!-- BEGIN s -->\nold\n<!-- END s -->{tail}"
    new = bench.replace_section(old, "s", body)
    assert new == f"{head}<!-- BEGIN s -->\n{body.strip()}\n<!-- END s -->{tail}"


def test_a_missing_section_is_appended_and_broken_markers_refused():
    assert bench.replace_section("# B\n", "vibration", "t").endswith(
        "\n\n<!-- BEGIN vibration -->\nt\n<!-- END vibration -->\n"
    )
    for broken in (
        "<!-- END s -->\n<!-- BEGIN s -->",
        "<!-- BEGIN s -->\n",
        "<!-- BEGIN s --><!-- END s --><!-- END s -->",
    ):
        with pytest.raises(ValueError, match="markers of section 's'"):
            bench.replace_section(broken, "s", "t")
    with pytest.raises(ValueError, match="section name"):
        bench.replace_section("", "a -->", "t")


def test_publish_heads_the_table_with_command_machine_date_and_load(tmp_path):
    readme = tmp_path / "README.md"
    readme.write_text("# B\n\n<!-- BEGIN x -->\nold\n<!-- END x -->\n", encoding="utf-8")
    bench.publish("x", "| a |\n| --- |", command="python benchmarks/x.py", path=readme)
    body = readme.read_text(encoding="utf-8")
    assert re.search(
        r"Written by `python benchmarks/x\.py` on .+, \d+ cores, Python [\d.]+, "
        r"\d{4}-\d\d-\d\d \d\d:\d\d UTC, load average [\d.]+\.",
        body,
    )
    assert "old" not in body and "| a |" in body


@pytest.mark.parametrize("script", SCRIPTS, ids=[p.stem for p in SCRIPTS])
def test_every_benchmark_script_writes_its_own_section(script):
    source = script.read_text(encoding="utf-8")
    (name,) = re.findall(r'with captured\("([a-z0-9_-]+)"', source)
    readme = (ROOT / "benchmarks" / "README.md").read_text(encoding="utf-8")
    assert readme.count(f"<!-- BEGIN {name} -->") == 1 and readme.count(f"<!-- END {name} -->") == 1


def test_a_scripts_headings_nest_under_the_sections_heading(tmp_path):
    readme = tmp_path / "README.md"
    bench.publish("x", "## camcad.fit at 1 µm\n\n| a |\n\n### cost\n", command="c", path=readme)
    body = readme.read_text(encoding="utf-8")
    assert "\n#### camcad.fit at 1 µm\n" in body and "\n##### cost\n" in body
    assert not any(line.startswith(("## ", "### ")) for line in body.splitlines())
