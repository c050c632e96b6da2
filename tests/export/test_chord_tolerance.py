"""Issue 31: ``chord_tolerance`` is a promise against the exact profile, in every shipped sample's files.

The polylines of ``profile_poly.dxf`` (read back with ezdxf) and the outline
of ``cam.stl`` (read back with trimesh and cut at mid-height) are measured,
vertices and points along every chord, against the exact curve
``cam.offset_curve(φ, d)`` evaluated densely from the geometry (100 000 points, so
the dense polygon's own sagitta is below 1e-8 mm), never against the fitted
spline. Before the fix the chord error was measured against the spline and
the fit's certified error came on top (5.02–5.74 µm for 5 µm).
``profile_arcs.dxf``'s arcs are measured the same way against their own
promise, the fit tolerance.
"""

from __future__ import annotations

import itertools
import math
from functools import cache

import ezdxf
import numpy as np
import pytest
import trimesh

from camcad.design import load_design
from camcad.design.paths import path_of
from camcad.errors import DesignError
from camcad.export._outline import chord_budget
from camcad.pipeline import build
from tests.conftest import DISC_SAMPLES, SAMPLES, distance_to_polygon

_DENSE = 100_000
_SUB = np.linspace(0.0, 1.0, 9)  # points along each chord


@cache
def exact(name: str, plate: int, offset: float) -> np.ndarray:
    """(n, 2) dense exact curve of one sample's plate at one offset from its profile."""
    result = built(name)
    part = result.analysis.parts[plate - 1].part
    cam = part.cam
    if part.bar is not None:  # a linear cam's bar: its exact open edge, then its three straight sides
        edge = np.asarray(cam.offset_curve(np.linspace(0.0, 2.0 * math.pi, _DENSE), offset).point)
        x0, x1, y0 = part.bar.x0, part.bar.x0 + part.bar.length, part.bar.bottom
        corners = [edge[-1], (x1, y0), (x0, y0), edge[0]]
        sides = [  # each side from its first corner on, 0.02 mm apart: a nearest vertex is on its side
            np.linspace(a, b, max(2, int(math.dist(a, b) / 0.02)), endpoint=False)
            for a, b in itertools.pairwise(corners)
        ]
        sides[0] = sides[0][1:]  # the edge's last point is already there
        return np.vstack([edge, *sides])
    phi = np.linspace(0.0, 2.0 * math.pi, _DENSE, endpoint=False)
    return np.asarray(cam.offset_curve(phi, offset).point)


_BUILT: dict[str, object] = {}


def built(name: str):
    return _BUILT[name]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("chord")


def _build(name: str, folder) -> object:
    if name not in _BUILT:
        design = load_design(next(p for p in SAMPLES if p.stem == name))
        _BUILT[name] = build(design, folder / name, only=["dxf", "stl"])
    return _BUILT[name]


def along(loop: np.ndarray) -> np.ndarray:
    """Vertices of a closed polyline and 7 points inside each chord."""
    a, b = loop, np.roll(loop, -1, axis=0)
    return (a[:, None, :] + (b - a)[:, None, :] * _SUB[None, :, None]).reshape(-1, 2)


def curves(name: str) -> dict[str, tuple[int, float]]:
    """Layer → (plate, offset from the profile) of every curve a sample's profile_poly.dxf draws."""
    analysis = built(name).analysis
    (groove,) = analysis.parts[0].part.checks or (None,)  # a groove cam's flank checks
    if groove is not None:
        return {"GROOVE_INNER": (1, groove.inner_offset), "GROOVE_OUTER": (1, groove.outer_offset)}
    return {"CAM_PROFILE": (1, 0.0)}


@pytest.mark.parametrize("name", [p.stem for p in DISC_SAMPLES])
def test_polylines_and_stl_keep_within_chord_tolerance_of_the_exact_profile(name, folder):
    result = _build(name, folder)
    out = folder / name
    design = result.analysis.design
    plates = [("", 1)] + ([("_2", 2)] if len(result.analysis.parts) > 1 else [])
    for suffix, plate in plates:
        doc = ezdxf.readfile(out / f"profile_poly{suffix}.dxf")
        layers = curves(name)
        seen = 0
        for e in doc.modelspace().query("LWPOLYLINE"):
            if e.dxf.layer not in layers:
                continue
            _, offset = layers[e.dxf.layer]
            pts = np.array([(x, y) for x, y, *_ in e.get_points()])
            gap = distance_to_polygon(along(pts), exact(name, plate, offset)).max()
            assert gap <= design.dxf.chord_tolerance, (suffix, e.dxf.layer, gap)
            seen += 1
        assert seen == len(layers)
        arcs = ezdxf.readfile(out / f"profile_arcs{suffix}.dxf").modelspace()  # a bar's too (its open edge)
        fit_tol = design.fit.tolerance
        for layer, (_, offset) in layers.items():
            pts = []
            for arc in arcs.query(f'ARC[layer=="{layer}"]'):
                a0, a1 = math.radians(arc.dxf.start_angle), math.radians(arc.dxf.end_angle)
                sweep = (a1 - a0) % (2.0 * math.pi)
                t = a0 + sweep * _SUB
                pts.append(np.column_stack((arc.dxf.center.x + arc.dxf.radius * np.cos(t),
                                            arc.dxf.center.y + arc.dxf.radius * np.sin(t))))  # fmt: skip
            assert pts, layer
            gap = distance_to_polygon(np.vstack(pts), exact(name, plate, offset)).max()
            assert gap <= fit_tol * (1 + 1e-9) + 1e-9, (suffix, layer, gap)
        mesh = trimesh.load_mesh(out / f"cam{suffix}.stl")
        zmin, zmax = mesh.bounds[:, 2]
        z = (
            zmax - 0.5 * design.groove.depth
            if result.analysis.parts[0].part.pocket is not None
            else 0.5 * (zmin + zmax)
        )
        section = mesh.section(plane_origin=(0.0, 0.0, z), plane_normal=(0.0, 0.0, 1.0))
        loops = [np.asarray(d)[:, :2] for d in section.discrete]
        matched = set()
        for loop in loops:
            for layer, (_, offset) in layers.items():
                # points 1 mm from every vertex get inf: their distance is > 1 mm − half an edge (edges of
                # 10⁵ points, ~0.01 mm), far above 0.05 and the tolerance, so the verdicts are the exact ones
                gap = distance_to_polygon(along(loop), exact(name, plate, offset), beyond=1.0)
                if np.median(gap) < 0.05:  # this loop is that curve (the rim and bore are mm away)
                    assert gap.max() <= design.mesh.chord_tolerance, (suffix, layer, gap.max())
                    matched.add(layer)
        assert matched == set(layers)


def test_a_chord_tolerance_the_fit_already_uses_is_refused_naming_the_field():
    assert chord_budget(0.005, 0.001, field="dxf.chord_tolerance") == pytest.approx(0.004)
    with pytest.raises(DesignError) as err:
        chord_budget(0.001, 0.00095, field="mesh.chord_tolerance")
    assert path_of(err.value.path) == "mesh.chord_tolerance" and "at least 0.001050" in err.value.message
