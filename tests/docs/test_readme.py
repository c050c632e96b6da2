"""The README's statements hold (issue 39): short, its commands and examples real, its tables true.

The README keeps what a newcomer needs in five minutes and links into the docs
for the rest; these tests hold each statement it keeps to the code: the Quick
start's two commands, the examples run, the limits table names fields the
loader knows, the architecture's layers are those ``tests/test_architecture.py``
enforces, every relative link and the picture exist.
"""

from __future__ import annotations

import re

import pytest

from camcad.design.editor_schema import design_json_schema
from tests.conftest import ROOT
from tests.docs.test_examples import FENCE
from tests.test_architecture import LAYER_ORDER

README = ROOT / "README.md"
TEXT = README.read_text(encoding="utf-8")


def blocks(language: str) -> list[str]:
    return [body for lang, body in FENCE.findall(TEXT) if lang == language]


def section(title: str) -> str:
    """The README's text under the heading ``title``, up to the next heading of its level or above."""
    match = re.search(rf"^(#+) {re.escape(title)}\n", TEXT, re.M)
    assert match is not None, title
    body = TEXT[match.end() :]
    end = re.search(rf"^#{{1,{len(match.group(1))}}} ", body, re.M)
    return body[: end.start()] if end else body


def test_the_readme_is_short():
    assert len(TEXT.splitlines()) <= 250


def test_the_quick_start_is_two_commands_the_first_with_a_virtual_environment():
    commands = blocks("sh")[:2]
    first, second = (c.strip() for c in commands)
    assert first.startswith("python3 -m venv .venv && . .venv/bin/activate && pip install . && ")
    assert first.endswith("camcad build samples/quintero_vap_b01.toml -o out/")
    assert (ROOT / "samples" / "quintero_vap_b01.toml").is_file()
    assert second == 'pip install -e ".[test]" && python -m pytest -q'
    quick = section("Quick start")
    assert re.search(r"about \d+ minutes on a 2-core machine\. <!-- suite time -->", quick)


def test_the_python_example_runs(tmp_path, monkeypatch):
    (tmp_path / "samples").symlink_to(ROOT / "samples", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    (code,) = blocks("python")
    exec(compile(code, "README.md python block", "exec"), {"__name__": "__readme__"})
    assert (tmp_path / "out" / "summary.json").is_file()


def test_the_design_file_example_loads():
    from camcad.design import parse_design
    from tests.docs.test_examples import tomllib

    (example,) = blocks("toml")
    design = parse_design(tomllib.loads(example), source="README.md")
    assert design.cam.base_radius == 40.0


# Fields the code's findings name that are no key of the design file. The list only shrinks.
KNOWN_NOT_KEYS: set[str] = set()


def _fields() -> set[str]:
    schema = design_json_schema()
    out = set()
    for table, spec in schema["properties"].items():
        props = spec["items"]["properties"] if spec.get("type") == "array" else spec["properties"]
        name = "motion[i]" if spec.get("type") == "array" else table
        out.update(f"{name}.{key}" for key in props)
    return out


def test_the_limits_table_names_fields_the_loader_knows():
    rows = [line for line in section("Hard and soft limits").splitlines() if line.startswith("| ")][2:]
    assert len(rows) >= 15
    known = _fields()
    kinds = set()
    for row in rows:
        limit, kind, fields, codes = (cell.strip() for cell in row.strip("|").split("|"))
        kinds.add(kind)
        assert kind in {"hard", "soft"}, row
        build, strict, check = (c.strip() for c in codes.split("/"))
        assert (build, strict) == (("3", "3") if kind == "hard" else ("warning", "3")), row
        assert check in {"3", "not checked"}, row
        for field in re.findall(r"`([a-z_]+(?:\[i\])?\.[a-z0-9_]+)`", fields):
            assert field in known or field in KNOWN_NOT_KEYS, f"{field} ({limit!r}): no such key"
    assert kinds == {"hard", "soft"}


def test_the_architecture_lists_the_enforced_layers_in_order():
    (diagram,) = re.findall(r"```text\n(shared bottom.*?)```", TEXT, re.S)
    named = re.findall(r"[a-z_0-9]+", re.sub(r"^shared bottom", "", diagram))
    expected = [name for layer in LAYER_ORDER for name in sorted(layer) if name != "__main__"]
    assert sorted(named) == sorted(expected)
    rank = {name: i for i, layer in enumerate(LAYER_ORDER) for name in layer}
    ranks = [rank[name] for name in named]
    assert ranks == sorted(ranks), "the README's layers are out of order"


@pytest.mark.parametrize("target", sorted(set(re.findall(r"\]\(((?!https?:)[^)#\s]+)", TEXT))))
def test_every_relative_link_and_picture_exists(target):
    assert (ROOT / target).exists(), target


def test_the_picture_is_a_png_of_the_report():
    (picture,) = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", TEXT)
    data = (ROOT / picture).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000
