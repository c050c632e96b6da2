"""LibreCAD and OpenSCAD read a linear cam's ``profile_arcs.dxf``: the bar's outline, its edge in arcs.

LibreCAD's ``dxf2pdf`` draws the ARCs and LINEs of ``CAM_PROFILE`` (colour 7,
black on white); its strokes are mapped back to mm by their bounding box
(as :mod:`tests.readers.test_librecad` does for a plate) and measured both
ways against the exact outline: the edge ``cam.profile(φ)`` and the bar's
three straight sides. OpenSCAD extrudes the file into one closed body whose
volume is the arcs' own area (Green's theorem, closed form) × the
thickness, within its chords' bound, and that area is the exact bar's
within the fit tolerance × the outline's length (as
:mod:`tests.readers.test_openscad` does for a plate).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from camcad.design import load_design
from camcad.geometry.cam import Cam
from camcad.geometry.families import family_of
from camcad.pipeline import build
from tests.conftest import ROOT
from tests.export.test_linear_outputs import exact_bar_area
from tests.readers.test_librecad import BLACK, dxf2pdf, paths_by_colour
from tests.readers.test_openscad import ARC_FN, arcs_area_and_bound, openscad
from tests.readers.test_rs274_linear import distance_to_curve

pytestmark = pytest.mark.slow

SAMPLE = ROOT / "samples" / "linear_cam.toml"


@pytest.fixture(scope="module")
def bar_files(tmp_path_factory: pytest.TempPathFactory):
    design = load_design(SAMPLE)
    out = tmp_path_factory.mktemp("linear") / "out"
    build(design, out, only=["dxf"], parallel=False)
    (part,) = family_of(design.cam.style).parts(Cam.from_design(design), design.family_options())
    assert part.bar is not None
    return design, part, out


def test_librecad_draws_the_bars_arcs_on_the_exact_outline(bar_files, tmp_path):
    _, part, out = bar_files
    pdf = dxf2pdf(out / "profile_arcs.dxf", tmp_path / "print")
    paths = paths_by_colour(pdf).get(BLACK)
    assert paths is not None
    drawn = np.vstack(paths) * [1.0, -1.0]  # PDF y runs down in LibreCAD's content matrix
    edge = np.asarray(part.cam.profile(np.linspace(0.0, 2.0 * math.pi, 200_001)).point)
    x0, x1, bottom = part.bar.x0, part.bar.x0 + part.bar.length, part.bar.bottom
    corners = [edge[-1], (x1, bottom), (x0, bottom), edge[0]]
    sides = [np.linspace(a, b, 2000) for a, b in itertools.pairwise(corners)]
    outline = np.vstack([edge, *sides])
    span_exact = outline.max(axis=0) - outline.min(axis=0)
    span_drawn = drawn.max(axis=0) - drawn.min(axis=0)
    scale = span_exact / span_drawn  # mm per device unit, per axis
    assert scale[0] == pytest.approx(scale[1], rel=2e-3)  # no distortion
    unit = float(scale.mean())

    def mapped(points: np.ndarray) -> np.ndarray:
        out: np.ndarray = (points * [1.0, -1.0] - drawn.min(axis=0)) * unit + outline.min(axis=0)
        return out

    # every stroke point on the exact outline, within 3 device units (as a plate's arcs)
    assert float(distance_to_curve(mapped(np.vstack(paths)), outline).max()) <= 3.0 * unit
    # and the whole edge drawn: every exact point within 3 units of a stroke segment
    strokes = [mapped(p) for p in paths if len(p) > 1]
    gap = np.full(len(edge[::20]), np.inf)
    for stroke in strokes:
        gap = np.minimum(gap, distance_to_curve(edge[::20], stroke))
    assert float(gap.max()) <= 3.0 * unit


def test_openscad_extrudes_the_bars_arcs_into_the_bar(bar_files, tmp_path):
    trimesh = pytest.importorskip("trimesh")
    design, part, out = bar_files
    t = design.cam.thickness
    dxf = tmp_path / "profile_arcs.dxf"
    dxf.write_bytes((out / "profile_arcs.dxf").read_bytes())
    openscad(f'linear_extrude(height = {t!r}) import("{dxf.name}", $fn = {ARC_FN});\n', tmp_path / "bar.stl")
    mesh = trimesh.load(tmp_path / "bar.stl", force="mesh")
    assert mesh.is_watertight and len(mesh.split(only_watertight=False)) == 1
    area, bound = arcs_area_and_bound(dxf)
    assert mesh.volume == pytest.approx(area * t, abs=bound * t)
    edge = np.asarray(part.cam.profile(np.linspace(0.0, 2.0 * math.pi, 20_001)).point)
    perimeter = float(np.sum(np.hypot(*np.diff(edge, axis=0).T))) + 2.0 * part.bar.length
    exact = exact_bar_area(part.cam, part.bar.bottom)
    assert abs(area - exact) <= 1.01 * design.fit.tolerance * perimeter
