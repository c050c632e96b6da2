"""Every code and TOML block of the documentation runs (issue 39): examples cannot rot.

Each page's ```python blocks run in order in one namespace, in a scratch
folder that sees the shipped samples as ``samples/``; each ```toml block (a
``--8<-- "samples/…"`` line stands for that file, as pymdownx.snippets
includes it) must be a design the loader accepts. Blocks of other languages
(``sh``, ``text``) are shown, not run.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

from camcad.design import load_design, parse_design
from tests.conftest import ROOT

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

DOCS = ROOT / "docs"
PAGES = sorted(p for p in DOCS.rglob("*.md") if "_hooks" not in p.parts)
FENCE = re.compile(r"^```(\w+)[^\n]*\n(.*?)^```\s*$", re.MULTILINE | re.DOTALL)
SNIPPET = re.compile(r'^--8<-- "([^"]+)"\s*$')


def blocks(page: Path, language: str) -> list[str]:
    """The page's fenced blocks of one language, in order."""
    return [body for lang, body in FENCE.findall(page.read_text(encoding="utf-8")) if lang == language]


def test_the_docs_have_blocks_to_run():
    """The collector finds the blocks (a pattern that matched nothing would pass every page)."""
    assert sum(len(blocks(p, "python")) for p in PAGES) >= 8
    assert sum(len(blocks(p, "toml")) for p in PAGES) >= 5
    assert blocks(DOCS / "guides" / "first-cam.md", "python")[0].startswith("import camcad")


@pytest.mark.parametrize("page", PAGES, ids=[str(p.relative_to(DOCS)) for p in PAGES])
def test_toml_blocks_are_designs_the_loader_accepts(page):
    for body in blocks(page, "toml"):
        included = SNIPPET.match(body.strip())
        if included is not None:
            load_design(ROOT / included.group(1))  # a point table is read beside its file
        else:
            parse_design(tomllib.loads(body), source=str(page))


PYTHON_PAGES = [p for p in PAGES if blocks(p, "python")]


@pytest.mark.parametrize("page", PYTHON_PAGES, ids=[str(p.relative_to(DOCS)) for p in PYTHON_PAGES])
def test_python_blocks_run(page, tmp_path, monkeypatch):
    (tmp_path / "samples").symlink_to(ROOT / "samples", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, object] = {"__name__": "__docs__"}
    for i, body in enumerate(blocks(page, "python")):
        code = compile(body, f"{page.relative_to(ROOT)} block {i + 1}", "exec")
        exec(code, namespace)  # the page's own example, as a reader would run it
