"""The documentation site builds with ``mkdocs build --strict``, offline (issue 39).

A broken link, a page missing from the navigation or a stale API reference
fails the build. The design-file reference is generated from ``camcad
schema``'s JSON at build time, so every key the loader knows must be on it.
Any fetch from the network would go to a dead proxy, so a plugin that needs
the network fails here.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from camcad.design.editor_schema import design_json_schema
from tests.conftest import ROOT

pytest.importorskip("mkdocs", reason="the docs extra: pip install -e '.[docs]'")
pytest.importorskip("material", reason="the docs extra: pip install -e '.[docs]'")
pytest.importorskip("mkdocstrings", reason="the docs extra: pip install -e '.[docs]'")

DEAD_PROXY = "http://127.0.0.1:9"  # the discard port: nothing answers


def mkdocs_build(config: Path, site: Path) -> subprocess.CompletedProcess[str]:
    env = {
        **os.environ,
        "PYTHONPATH": str(ROOT),
        "NO_MKDOCS_2_WARNING": "1",
        "HTTP_PROXY": DEAD_PROXY,
        "HTTPS_PROXY": DEAD_PROXY,
        "http_proxy": DEAD_PROXY,
        "https_proxy": DEAD_PROXY,
        "NO_PROXY": "",
        "no_proxy": "",
    }
    return subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config), "-d", str(site)],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=600,
    )


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("site")
    run = mkdocs_build(ROOT / "mkdocs.yml", out)
    assert run.returncode == 0, run.stderr[-3000:]
    return out


def test_the_site_builds_strictly_with_every_page(site):
    for page in ("index.html", "guides/first-cam.html", "reference/api.html", "decisions/index.html"):
        assert (site / page).is_file(), page
    for decision in (ROOT / "docs" / "decisions").glob("*.md"):
        assert (site / "decisions" / f"{decision.stem}.html").is_file(), decision.name
    assert (site / "examples" / "first_cam.ipynb").is_file()


def test_the_design_file_reference_has_every_key_of_camcad_schema(site):
    page = (site / "reference" / "design-file.html").read_text(encoding="utf-8")
    schema = design_json_schema()
    for section, table in schema["properties"].items():
        props = table["items"]["properties"] if table.get("type") == "array" else table["properties"]
        assert f"[{section}]" in page, section
        for key in props:
            assert f"<code>{key}</code>" in page, f"{section}.{key}"


def test_the_api_reference_is_rendered_from_the_docstrings(site):
    page = (site / "reference" / "api.html").read_text(encoding="utf-8")
    for name in ("load", "analyse", "Design", "Result", "replace", "optimize", "sweep"):
        assert f'id="camcad.api.{name}"' in page or f'id="camcad.api.Design.{name}"' in page, name
    assert "A variant with design-file keys changed" in page  # Design.replace's docstring


def test_a_broken_link_fails_the_build(tmp_path):
    """The strictness is real: the same settings refuse a link to a page that does not exist."""
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("# x\n\nSee [nowhere](missing.md).\n", encoding="utf-8")
    config = tmp_path / "mkdocs.yml"
    config.write_text(
        "site_name: t\ndocs_dir: docs\nstrict: true\ntheme:\n  name: material\n  font: false\n",
        encoding="utf-8",
    )
    run = mkdocs_build(config, tmp_path / "site")
    assert run.returncode != 0 and "missing.md" in run.stderr


def test_the_reference_shows_what_the_schema_gives(tmp_path):
    """Defaults, descriptions, bounds, enums and local references of a schema all reach the page."""
    import importlib.util

    source = ROOT / "docs" / "_hooks" / "design_reference.py"
    spec = importlib.util.spec_from_file_location("design_reference", source)
    assert spec is not None and spec.loader is not None
    hook = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hook)
    schema = {
        "$defs": {"length": {"type": "number", "minimum": 0.1, "maximum": 10000}},
        "required": ["cam"],
        "properties": {
            "cam": {
                "type": "object",
                "required": ["base_radius"],
                "properties": {
                    "base_radius": {
                        "$ref": "#/$defs/length",
                        "default": 40,
                        "description": "mm, the base circle",
                    },
                    "rotation": {"enum": ["ccw", "cw"]},
                },
            },
            "motion": {
                "type": "array",
                "items": {"properties": {"kind": {"enum": ["rise"]}}, "required": ["kind"]},
            },
        },
    }
    page = hook.reference_markdown(schema)
    assert "## `[cam]` (required)" in page and "## `[[motion]]`" in page
    assert "| `base_radius` (required) | number | ≥ 0.1, ≤ 10000 | `40` | mm, the base circle |" in page
    assert "| `rotation` | one of `ccw`, `cw` |  |  |  |" in page
