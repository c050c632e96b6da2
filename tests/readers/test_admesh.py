"""admesh finds nothing to repair in cam.stl (it always exits 0, so its report is parsed)."""

from __future__ import annotations

import re

import pytest

from tests.readers.conftest import Built, require, run

pytestmark = pytest.mark.slow

MUST_BE_ZERO = (
    "Degenerate facets",
    "Edges fixed",
    "Facets removed",
    "Facets added",
    "Facets reversed",
    "Backwards edges",
    "Normals fixed",
)


def admesh_report(text: str) -> dict[str, list[float]]:
    """``name : value [value]`` lines of admesh's report as numbers (original, final)."""
    report: dict[str, list[float]] = {}
    for line in text.splitlines():
        # lines may hold two fields: "Number of parts : 1   Volume : 123.4"
        for name, values in re.findall(r"([A-Z][A-Za-z ]+?)\s*:\s*([-\d.eE+ ]+?)(?=\s{2,}[A-Z]|$)", line):
            numbers = [float(v) for v in values.split()]
            if numbers:
                report[name.strip()] = numbers
    return report


def test_admesh_reports_one_clean_part(built: Built, tmp_path):
    admesh = require("admesh")
    result = run([admesh, str(built.stl)], cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    text = result.stdout + result.stderr
    assert "Binary STL" in text
    report = admesh_report(text)
    assert report["Number of parts"] == [1.0], text
    facets = len(built.solid.mesh.faces)
    assert report["Number of facets"] == [facets, facets], text  # nothing added or removed
    assert report["Total disconnected facets"] == [0.0, 0.0], text
    for key in MUST_BE_ZERO:
        assert report[key] == [0.0], f"{key}: {report.get(key)}\n{text}"
    # admesh sums in single precision
    assert report["Volume"][0] == pytest.approx(built.solid.volume, rel=1e-5)
