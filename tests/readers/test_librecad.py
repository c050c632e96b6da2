"""LibreCAD prints every DXF, draws the SPLINE and the arcs on the exact profile, the pitch curve dashed."""

from __future__ import annotations

import itertools
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


def dxf2pdf(dxf: Path, folder: Path, *options: str) -> Path:
    """Print ``dxf`` with ``librecad dxf2pdf -a`` (fit to page) and ``options`` into ``folder``; the PDF."""
    librecad = require("librecad")
    folder.mkdir(exist_ok=True)
    local = folder / dxf.name
    shutil.copy(dxf, local)
    result = run([librecad, "dxf2pdf", "-a", *options, str(local)], cwd=folder)
    assert result.returncode == 0, result.stderr[-2000:]
    return local.with_suffix(".pdf")


def arcs_dxf(built: Built, folder: Path) -> Path:
    """``profile_arcs.dxf`` of the case, written here (the shared fixture predates it)."""
    from camcad.export.dxf import write_profile_arcs_dxf

    folder.mkdir(exist_ok=True)
    plate, options = built.design.plate(), built.design.dxf
    return write_profile_arcs_dxf(
        folder / "profile_arcs.dxf", cam=built.cam, fit=built.fit, plate=plate, options=options
    )


def paths_by_colour(pdf: Path) -> dict[str, list[np.ndarray]]:
    """The stroked paths of a PDF (each from its ``m`` through its ``l`` points), by stroke colour."""
    data = pdf.read_bytes()
    paths: dict[str, list[list[tuple[float, float]]]] = {}
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
            found = re.fullmatch(r"(-?[\d.]+) (-?[\d.]+) ([ml])", line.strip())
            if found:
                point = (float(found.group(1)), float(found.group(2)))
                if found.group(3) == "m":
                    paths.setdefault(colour, []).append([point])
                else:
                    paths[colour][-1].append(point)
    return {k: [np.asarray(p) for p in v] for k, v in paths.items()}


def strokes_by_colour(pdf: Path) -> dict[str, np.ndarray]:
    """Points of the stroked paths in a PDF, grouped by stroke colour (``SCN`` operands)."""
    return {k: np.vstack(v) for k, v in paths_by_colour(pdf).items()}


@pytest.mark.parametrize("which", ["dxf", "poly_dxf", "arcs_dxf"])
def test_dxf2pdf_prints_a_non_empty_pdf(built: Built, which: str, tmp_path):
    source = arcs_dxf(built, tmp_path / "src") if which == "arcs_dxf" else getattr(built, which)
    pdf = dxf2pdf(source, tmp_path)
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


def on_exact_profile(built: Built, drawn: np.ndarray) -> float:
    """Largest distance of LibreCAD's strokes from the exact profile [device units], mapped by their bbox."""
    drawn = drawn * [1.0, -1.0]  # PDF y runs down in LibreCAD's content matrix
    exact = built.cam.profile(np.linspace(0.0, 2.0 * math.pi, 200000, endpoint=False)).point
    scale = (exact.max(axis=0) - exact.min(axis=0)) / (drawn.max(axis=0) - drawn.min(axis=0))
    assert scale[0] == pytest.approx(scale[1], rel=2e-3)  # no distortion
    unit = float(scale.mean())
    mapped = (drawn - drawn.min(axis=0)) * unit + exact.min(axis=0)
    deviation, _ = cKDTree(exact).query(mapped)
    return float(deviation.max()) / unit


def test_librecad_draws_the_arcs_on_the_exact_profile(built: Built, tmp_path):
    """profile_arcs.dxf: LibreCAD's black strokes (the CAM_PROFILE arcs) within 3 device units of it."""
    pdf = dxf2pdf(arcs_dxf(built, tmp_path / "src"), tmp_path)
    drawn = strokes_by_colour(pdf).get(BLACK)
    assert drawn is not None and len(drawn) > 50
    assert on_exact_profile(built, drawn) <= 3.0


GREEN = "0 1 0"  # PITCH_CURVE has colour 3


def test_pitch_curve_prints_dashed_in_colour_and_monochrome(built: Built, tmp_path):
    """LibreCAD restarts a linetype at every vertex, so only real gaps print: one run of strokes per dash.

    In colour the green strokes break into as many separate runs as the file has
    dashes; ``-m`` (monochrome) prints the very same strokes, all black.
    """
    import ezdxf

    if not built.cam.has_pitch_curve or not built.design.dxf.pitch_curve:
        pytest.skip("no pitch curve: not a roller follower")
    dashes = len(ezdxf.readfile(built.dxf).modelspace().query('SPLINE[layer=="PITCH_CURVE"]'))
    colour = paths_by_colour(dxf2pdf(built.dxf, tmp_path / "colour"))
    green = colour[GREEN]
    unit_gap = 1.5  # device units: consecutive strokes of one dash share their end point exactly
    runs = 1 + sum(1 for a, b in itertools.pairwise(green) if np.linalg.norm(b[0] - a[-1]) > unit_gap)
    assert runs >= 0.95 * dashes  # a solid curve would be one run (or a handful where LibreCAD splits)
    mono = paths_by_colour(dxf2pdf(built.dxf, tmp_path / "mono", "-m"))
    assert set(mono) == {BLACK} or set(mono) <= {BLACK, ""}
    drawn = [p for k, v in colour.items() if k for p in v]  # "" is the page's clip path
    everything = sorted(map(tuple, np.vstack(drawn).tolist()))
    assert sorted(map(tuple, np.vstack(mono[BLACK]).tolist())) == everything


PT_PER_MM = 72.0 / 25.4


def test_dxf2pdf_at_true_scale_centred(built: Built, tmp_path):
    """``librecad dxf2pdf -c -s 1`` (docs/reference/outputs.md): the profile prints at its true size in mm.

    Without ``-a`` or ``-c`` LibreCAD 2.2 collapses the drawing to a point (an empty page);
    centred at scale 1 the black strokes span the exact profile's width and height.
    """
    librecad = require("librecad")
    local = tmp_path / "profile_poly.dxf"
    shutil.copy(built.poly_dxf, local)
    result = run([librecad, "dxf2pdf", "-c", "-s", "1", str(local)], cwd=tmp_path)
    assert result.returncode == 0, result.stderr[-2000:]
    data = local.with_suffix(".pdf").read_bytes()
    matrix = re.search(rb"([\d.]+) 0 0 -([\d.]+) 0 [\d.]+ cm", data)
    if matrix is None:  # the content stream is compressed: read the matrix from it
        for raw in re.findall(rb"stream\r?\n(.*?)\r?\nendstream", data, re.S):
            try:
                matrix = re.search(rb"([\d.]+) 0 0 -([\d.]+) 0 [\d.]+ cm", zlib.decompress(raw))
            except zlib.error:
                continue
            if matrix:
                break
    assert matrix is not None
    pt_per_unit = float(matrix.group(1))
    drawn = strokes_by_colour(local.with_suffix(".pdf"))[BLACK] * pt_per_unit / PT_PER_MM  # mm on paper
    exact = built.cam.profile(np.linspace(0.0, 2.0 * math.pi, 200000, endpoint=False)).point
    span_exact = exact.max(axis=0) - exact.min(axis=0)
    span_drawn = drawn.max(axis=0) - drawn.min(axis=0)
    # whole device units (0.02 mm) and the pen's round caps: measured 0.01–0.05 mm; a 1 % scale error is 1 mm
    assert np.all(np.abs(span_drawn - span_exact) <= 0.08), (span_drawn, span_exact)


@pytest.mark.parametrize("sample", ["quintero_vap_b01", "groove_rocker"])
def test_fit_to_page_print_keeps_the_outline_and_every_note_line_on_the_page(sample, tmp_path):
    """Issue 31: ``dxf2pdf -a`` cut the outline at the page edge and half the last note line, and the
    notes printed yellow. Rendered by pdftoppm, the drawing's ink keeps off every page edge, the notes
    below the cam are as many separate lines of ink as the file has TEXT lines, and no ink is yellow.
    (LibreCAD draws text as strokes, so pdftotext has no text to read; the raster is the check.)"""
    import ezdxf
    from PIL import Image

    from camcad.design import load_design
    from camcad.pipeline import build

    build(load_design(Path(__file__).resolve().parents[2] / "samples" / f"{sample}.toml"), tmp_path / "out",
          only=["dxf"])  # fmt: skip
    pdf = dxf2pdf(tmp_path / "out" / "profile.dxf", tmp_path / "print")
    ppm = require("pdftoppm")
    result = run([ppm, "-r", "100", "-png", "-singlefile", str(pdf), "page"], cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    rgb = np.asarray(Image.open(tmp_path / "page.png").convert("RGB")).astype(int)
    ink = rgb.min(axis=2) < 200
    rows, cols = np.nonzero(ink)
    h, w = ink.shape
    edge = round(2.0 / 25.4 * 100)  # 2 mm at 100 dpi
    assert rows.min() > edge and rows.max() < h - 1 - edge, (rows.min(), rows.max(), h)
    assert cols.min() > edge and cols.max() < w - 1 - edge, (cols.min(), cols.max(), w)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    assert not np.any((r > 180) & (g > 180) & (b < 100)), "yellow ink"
    # the notes: the lowest bands of inked rows, one per TEXT line, the last as tall as the others
    msp = ezdxf.readfile(tmp_path / "out" / "profile.dxf").modelspace()
    texts = len(msp.query('TEXT[layer=="ANNOTATION"]'))
    band = np.concatenate(([False], ink.any(axis=1), [False]))
    starts, ends = np.flatnonzero(band[1:] & ~band[:-1]), np.flatnonzero(~band[1:] & band[:-1])
    assert len(starts) >= texts + 1  # the drawing above, then one band per note line
    heights = (ends - starts)[-texts:]
    assert heights.max() < 0.05 * h  # text lines, not the drawing
    assert heights[-1] >= 0.7 * np.median(heights), heights  # the last line is whole
