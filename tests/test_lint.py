"""The project's static gates run in the suite, so they run wherever the suite does (CI too).

ruff keeps the whole tree clean and formatted, and mypy keeps the typed core strict: motion,
geometry and fit and the bottom modules they share (rules and settings in
pyproject.toml). Both run through ``sys.executable -m``, so they are the ones
installed with the test extra, and a missing tool fails instead of skipping.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from typing import Any

import pytest

from tests.conftest import ROOT

# The modules held to ``mypy --strict``; the list only grows.
STRICT_TYPED = (
    "camcad/motion",
    "camcad/geometry",
    "camcad/fit",
    "camcad/inspect",
    "camcad/extremes.py",
    "camcad/findings.py",
    "camcad/roots.py",
    "camcad/angles.py",
    "camcad/errors.py",
    "camcad/_typing.py",
    "camcad/_lazy.py",
    "camcad/api.py",
)


def _run(tool: str, *args: str) -> subprocess.CompletedProcess[str]:
    if importlib.util.find_spec(tool) is None:
        pytest.fail(f"{tool} is not installed for {sys.executable}: pip install -e '.[test]'")
    return subprocess.run(
        [sys.executable, "-m", tool, *args], cwd=ROOT, capture_output=True, text=True, check=False
    )


def test_ruff_is_clean():
    proc = _run("ruff", "check", ".")
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_ruff_format_leaves_every_file_as_it_is():
    proc = _run("ruff", "format", "--check", ".")
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_mypy_strict_is_clean_on_the_typed_core():
    proc = _run("mypy", "--strict", *STRICT_TYPED)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def _tool_config(name: str) -> dict[str, Any]:
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    tools: dict[str, Any] = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]
    config: dict[str, Any] = tools[name]
    return config


def test_mypy_config_checks_the_same_set_strictly():
    """``python -m mypy`` alone reads [tool.mypy] in pyproject.toml: the same modules, strict."""
    config = _tool_config("mypy")
    assert config["strict"] is True
    assert sorted(config["files"]) == sorted(STRICT_TYPED)


def test_doctests_run_in_the_suite():
    """A plain ``python -m pytest`` collects the docstrings' examples in camcad/ as tests."""
    config = _tool_config("pytest")["ini_options"]
    assert "--doctest-modules" in config["addopts"].split()
    assert "camcad" in config["testpaths"]
