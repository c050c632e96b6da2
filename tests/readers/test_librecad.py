"""LibreCAD prints every DXF, and draws the SPLINE where the exact profile is."""

from __future__ import annotations

import math
import re
import shutil
import zlib
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from tests.readers.conftest import Built, require, run

pytestmark = pytest.mark.slow

BLACK = "0 0 0"  # CAM_PROFILE has colour 7, printed black on white


def dxf2pdf(dxf: Path, folder: Path) -> Path:
    """Print ``dxf`` with ``librecad dxf2pdf`` (fit to page) into ``folder``; the PDF path."""
    librecad = require("librecad")
    folder.mkdir(exist_ok=True)
    local = folder / dxf.name
    shutil.copy(dxf, local)
    result = run([librecad, "dxf2pdf", "-a", str(local)], cwd=folder)
    assert result.returncode == 0, result.stderr[-2000:]
    return local.with_suffix(".pdf")


def strokes_by_colour(pdf: Path) -> dict[str, np.ndarray]:
    """Points of the stroked paths in a PDF, grouped by stroke colour (``SCN`` operands)."""
    data = pdf.read_bytes()
    points: dict[str, list[tuple[float, float]]] = {}
    for raw in re.findall(rb"stream\r?\n(.*?)\r?\nendstream", data, re.S):
        try:
            content = zlib.decompress(raw).decode("latin-1")
        except zlib.error:
            content = raw.decode("latin-1")
        colour = ""
        for line in content.splitlines():
            found = re.fullmatch(r"([\d.]+ [\d.]+ [\d.]+) SCN", line.strip())
            if found:
                colour = found.group(1)
                continue
            found = re.fullmatch(r"(-?[\d.]+) (-?[\d.]+) [ml]", line.strip())
            if found:
                points.setdefault(colour, []).append((float(found.group(1)), float(found.group(2))))
    return {k: np.asarray(v) for k, v in points.items()}


@pytest.mark.parametrize("which", ["dxf", "poly_dxf"])
def test_dxf2pdf_prints_a_non_empty_pdf(built: Built, which: str, tmp_path):
    pdf = dxf2pdf(getattr(built, which), tmp_path)
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF")
    strokes = strokes_by_colour(pdf)
    assert sum(len(v) for v in strokes.values()) > 100  # the drawing, not a blank page


def test_librecad_draws_the_spline_on_the_exact_profile(built: Built, tmp_path):
    """Map LibreCAD's black strokes back to mm by their bounding box; compare with the profile.

    Coordinates in LibreCAD's PDF are whole device units (about 0.02 mm of
    the drawing here). Drawn from our control points and knots, the spline
    stays within 3 units of the exact profile; the same spline drawn with
    uniform knots misses by about 6 units.
    """
    pdf = dxf2pdf(built.dxf, tmp_path)
    drawn = strokes_by_colour(pdf).get(BLACK)
    assert drawn is not None and len(drawn) > 50
    drawn = drawn * [1.0, -1.0]  # PDF y runs down in LibreCAD's content matrix
    exact = built.cam.profile(np.linspace(0.0, 2.0 * math.pi, 200000, endpoint=False)).point
    span_exact = exact.max(axis=0) - exact.min(axis=0)
    span_drawn = drawn.max(axis=0) - drawn.min(axis=0)
    scale = span_exact / span_drawn  # mm per device unit, per axis
    assert scale[0] == pytest.approx(scale[1], rel=2e-3)  # no distortion
    unit = float(scale.mean())
    mapped = (drawn - drawn.min(axis=0)) * unit + exact.min(axis=0)
    deviation, _ = cKDTree(exact).query(mapped)
    assert deviation.max() <= 3.0 * unit
