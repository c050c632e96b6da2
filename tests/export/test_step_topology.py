"""cam.step's hand-written B-rep, read back with OpenCASCADE: closed shells, the right faces, exact volumes.

Independent truths: OpenCASCADE's own checks of the shape it read
(``BRepCheck_Analyzer``; ``ShapeAnalysis_FreeBounds``: no free edge;
``BRepCheck_Shell``: closed), its edge-use bookkeeping (every edge used by
two faces in opposite directions), its surface types and plane positions,
and its adaptive surface and volume integrals against closed forms: π r²
for circles, :attr:`BoreOutline.area` for bore and keyway, and Green's
theorem on the fits' B-splines (``green_area`` of ``test_step.py``). The
REAL syntax against the grammar of ISO 10303-21 §6.3.3.
"""

from __future__ import annotations

import math
import re
from collections import Counter
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from camcad.design import load_design
from camcad.errors import ExportError
from camcad.export.step import Body, Prism, groove_body, plate_body, write_step
from camcad.geometry.plate import BoreOutline, Plate
from tests.conftest import ROOT

pytest.importorskip("OCP", reason="the reader of these tests is OpenCASCADE (cadquery-ocp-novtk, test extra)")

from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepCheck import BRepCheck_Analyzer, BRepCheck_Shell, BRepCheck_Status
from OCP.BRepGProp import BRepGProp
from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as ShapeMap
from OCP.GProp import GProp_GProps
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_SHELL, TopAbs_SOLID
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS

from tests.export.test_step import FIT, green_area, read_step, shapes_of, volume


def edge_uses(shape) -> Counter:
    """(edge index, orientation in the solid) for every use of an edge by a face."""
    edges = ShapeMap()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)
    uses: Counter = Counter()
    faces = TopExp_Explorer(shape, TopAbs_FACE)
    while faces.More():
        explorer = TopExp_Explorer(faces.Current(), TopAbs_EDGE)  # orientations composed with the face's
        while explorer.More():
            edge = explorer.Current()
            uses[(edges.FindIndex(edge), edge.Orientation() == TopAbs_FORWARD)] += 1
            explorer.Next()
        faces.Next()
    return uses


def assert_closed_valid_solid(shape) -> None:
    assert BRepCheck_Analyzer(shape).IsValid()
    assert len(shapes_of(shape, TopAbs_SOLID)) == 1
    shells = shapes_of(shape, TopAbs_SHELL)
    assert len(shells) == 1
    assert BRepCheck_Shell(TopoDS.Shell(shells[0])).Closed(False) == BRepCheck_Status.BRepCheck_NoError
    free = ShapeAnalysis_FreeBounds(shape)
    assert not shapes_of(free.GetClosedWires(), TopAbs_EDGE)
    assert not shapes_of(free.GetOpenWires(), TopAbs_EDGE)
    # a closed oriented 2-manifold: each edge once forward and once reversed
    uses = edge_uses(shape)
    indices = {index for index, _ in uses}
    assert all(uses[(i, True)] == 1 and uses[(i, False)] == 1 for i in indices), uses


def faces_of(shape) -> list[tuple[str, tuple[float, float] | None, float]]:
    """(surface type, (z, normal z) for a horizontal plane, area) of every face, areas adaptive."""
    out = []
    for face in shapes_of(shape, TopAbs_FACE):
        face = TopoDS.Face(face)
        kind = BRep_Tool.Surface_s(face).DynamicType().Name().removeprefix("Geom_")
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(face, props, 1e-10)
        where = None
        if kind == "Plane":
            plane = BRepAdaptor_Surface(face).Plane()
            normal = plane.Axis().Direction()
            if face.Orientation() != TopAbs_FORWARD:
                normal = normal.Reversed()
            if abs(normal.Z()) == 1.0:
                where = (round(plane.Location().Z(), 9), normal.Z())
        out.append((kind, where, props.Mass()))
    return out


@pytest.fixture(scope="module")
def groove(tmp_path_factory):
    from camcad.pipeline import build

    design = load_design(ROOT / "samples" / "groove_rocker.toml")
    out = tmp_path_factory.mktemp("groove") / "out"
    result = build(design, out, only=["step"])
    return design, result.analysis.parts[0].flank_fits, out / "cam.step"


def test_groove_blank_faces_volume_and_shell(groove):
    """Rim ⊃ outer flank ⊃ inner flank ⊃ bore: two top faces, one pocket floor, one bottom, seven walls."""
    design, flanks, path = groove
    shape = read_step(path)
    assert_closed_valid_solid(shape)
    bore = design.plate().bore
    assert bore is not None and bore.has_keyway
    t, depth, radius = design.cam.thickness, design.groove.depth, design.cam.outer_radius
    inner, outer = (green_area(f.curve) for f in flanks)
    faces = faces_of(shape)
    walls = Counter(kind for kind, where, _ in faces if where is None)
    # rim and bore arc, both flanks, the keyway's three sides
    assert walls == {"CylindricalSurface": 2, "SurfaceOfLinearExtrusion": 2, "Plane": 3}
    plane_areas = sorted((where, area) for _, where, area in faces if where is not None)
    assert [where for where, _ in plane_areas] == [(0.0, -1.0), (t - depth, 1.0), (t, 1.0), (t, 1.0)]
    disc = math.pi * radius**2
    assert plane_areas[0][1] == pytest.approx(disc - bore.area, rel=1e-7)  # the bottom
    assert plane_areas[1][1] == pytest.approx(outer - inner, rel=1e-7)  # the groove's floor
    # the top: rim less outer flank, and inner flank less bore
    assert sorted(a for _, a in plane_areas[2:]) == pytest.approx(
        sorted([disc - outer, inner - bore.area]), rel=1e-7
    )
    assert volume(shape) == pytest.approx((disc - bore.area) * t - (outer - inner) * depth, rel=1e-6)


def test_groove_body_gives_the_same_bytes_twice(groove, tmp_path):
    design, flanks, path = groove
    body = groove_body(
        flanks, design.plate(), outer_radius=design.cam.outer_radius, depth=design.groove.depth
    )
    again = write_step(tmp_path / "cam.step", [body])
    assert again.read_bytes() == path.read_bytes()


def test_reals_follow_the_exchange_structure_grammar(groove):
    """ISO 10303-21 §6.3.3: REAL = [sign] digit {digit} "." {digit} ["E" [sign] digit {digit}]."""
    data = groove[2].read_text(encoding="ascii").split("DATA;", 1)[1]
    data = re.sub(r"'(?:[^']|'')*'", "''", data)  # strings are not numbers
    numbers = re.findall(r"(?<![#\w.])[-+]?\d[\d.]*(?:[eE][-+]?\d+)?", data)
    reals = [n for n in numbers if not n.isdigit()]
    assert len(reals) > 100
    bad = [n for n in reals if not re.fullmatch(r"[-+]?\d+\.\d*(E[-+]?\d+)?", n)]
    assert bad == []


@pytest.mark.parametrize(
    "bore",
    [None, BoreOutline(radius=6.0), BoreOutline(radius=6.0, keyway_width=3.0, keyway_depth=1.5)],
    ids=["no-bore", "plain-bore", "keyed-bore"],
)
def test_plates_are_closed_valid_shells(bore, tmp_path):
    """Profile wall, bore wall (a circle: one face with a seam; keyed: arc and three planes), top, bottom."""
    _, fit = FIT
    plate = Plate(name="plate", thickness=7.5, bore=bore)
    shape = read_step(write_step(tmp_path / "cam.step", [plate_body(fit, plate)]))
    assert_closed_valid_solid(shape)
    kinds = Counter(kind for kind, _, _ in faces_of(shape))
    expected = Counter({"SurfaceOfLinearExtrusion": 1, "Plane": 2})
    if bore is not None:
        expected["CylindricalSurface"] = 1
        expected["Plane"] += 3 if bore.has_keyway else 0
    assert kinds == expected
    hole = bore.area if bore is not None else 0.0
    assert volume(shape) == pytest.approx((green_area(fit.curve) - hole) * 7.5, rel=1e-6)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    radii=st.lists(st.floats(1.0, 50.0), min_size=6, max_size=6, unique=True).filter(
        lambda r: min(np.diff(sorted(r))) > 0.05
    ),
    depths=st.tuples(st.floats(0.1, 0.95), st.floats(0.1, 0.95)),
    thickness=st.floats(0.5, 30.0),
    z0=st.floats(-20.0, 20.0),
)
def test_nested_pockets_of_two_depths(radii, depths, thickness, z0, tmp_path_factory):
    """Law: a disc R0 with bore R5, a ring pocket R1..R2 and, in its island, a ring pocket R3..R4.

    volume = π(R0² − R5²) t − π(R1² − R2²) d₁ − π(R3² − R4²) d₂; three top faces, two floors, one bottom.
    """
    r0, r1, r2, r3, r4, r5 = sorted(radii, reverse=True)
    d1, d2 = depths[0] * thickness, depths[1] * thickness
    top = z0 + thickness
    circle = BoreOutline
    body = Body(
        name="rings",
        prism=Prism(outer=circle(radius=r0), holes=(circle(radius=r5),), height=thickness, z0=z0),
        cuts=(
            Prism(outer=circle(radius=r1), holes=(circle(radius=r2),), height=d1, z0=top - d1),
            Prism(outer=circle(radius=r3), holes=(circle(radius=r4),), height=d2, z0=top - d2),
        ),
    )
    shape = read_step(write_step(tmp_path_factory.mktemp("rings") / "rings.step", [body]))
    assert_closed_valid_solid(shape)
    area = lambda a, b: math.pi * (a * a - b * b)  # noqa: E731
    expected = area(r0, r5) * thickness - area(r1, r2) * d1 - area(r3, r4) * d2
    assert volume(shape) == pytest.approx(expected, rel=1e-6)
    planes = Counter(where[1] for _, where, _ in faces_of(shape) if where is not None)
    assert planes == {1.0: 3 + 2, -1.0: 1}


def test_bad_bodies_are_refused_naming_the_outlines(tmp_path):
    """Crossing outlines, pockets below, through or short of the faces, pockets where there is no material."""
    _, fit = FIT
    plate = Plate(name="bad", thickness=8.0, bore=BoreOutline(radius=6.0))
    blank = plate_body(fit, plate)
    crossing = BoreOutline(radius=50.0)  # the profile runs from r = 40 to r = 60
    shifted = replace(fit.curve, control_points=fit.curve.control_points + np.array([15.0, 0.0]))

    def pocket(outer, holes=(), z0=5.0, height=3.0) -> Body:
        return replace(blank, cuts=(Prism(outer=outer, holes=holes, z0=z0, height=height),))

    cases = [
        (
            pocket(crossing, (BoreOutline(radius=10.0),)),
            "pocket 1's outer outline crosses or touches the outer outline",
        ),
        (
            replace(
                blank, cuts=(Prism(outer=shifted, holes=(BoreOutline(radius=8.0),), z0=5.0, height=3.0),)
            ),
            "crosses or touches the outer outline",
        ),
        (pocket(BoreOutline(radius=30.0), z0=-1.0, height=9.0), "not above the bottom"),
        (pocket(BoreOutline(radius=30.0), z0=0.0, height=8.0), "not above the bottom"),
        (pocket(BoreOutline(radius=30.0), z0=2.0, height=3.0), "a pocket opens at the top face"),
        (
            pocket(BoreOutline(radius=3.0)),
            "pocket 1's outer outline lies in hole 1, where there is no material",
        ),
        (
            pocket(BoreOutline(radius=30.0)),
            "hole 1 lies in pocket 1's outer outline but in none of its islands",
        ),
        (
            replace(blank, prism=replace(blank.prism, holes=(crossing,))),
            "hole 1 crosses or touches the outer outline",
        ),
        (
            replace(blank, prism=replace(blank.prism, holes=(BoreOutline(radius=70.0),))),
            "hole 1 is not inside the outer outline",
        ),
        (
            replace(
                blank, prism=replace(blank.prism, holes=(BoreOutline(radius=6.0), BoreOutline(radius=9.0)))
            ),
            "hole 1 lies inside hole 2",
        ),
    ]
    cases = [(body, re.escape(message)) for body, message in cases]
    # two equal outlines: on the samples of each other, so "crosses or touches" (or, exactly, "coincide")
    same = pocket(BoreOutline(radius=30.0), (BoreOutline(radius=30.0),))
    cases.append((same, "pocket 1's (hole 1|outer outline) (crosses or touches|and) pocket 1's"))
    for body, pattern in cases:
        with pytest.raises(ExportError, match=pattern) as raised:
            write_step(tmp_path / "bad.step", [body])
        assert str(raised.value).startswith("bad: ")  # names the body
    assert list(tmp_path.iterdir()) == []


def test_a_pocket_of_the_same_outline_sticking_out_above_is_the_same_solid(tmp_path):
    """A pocket whose top lies above the prism's cuts the same material as one ending at the top."""
    _, fit = FIT
    plate = plate_body(fit, Plate(name="p", thickness=8.0, bore=BoreOutline(radius=6.0)))
    ring = (BoreOutline(radius=30.0), (BoreOutline(radius=10.0),))
    flush = replace(plate, cuts=(Prism(outer=ring[0], holes=ring[1], z0=5.0, height=3.0),))
    above = replace(plate, cuts=(Prism(outer=ring[0], holes=ring[1], z0=5.0, height=30.0),))
    a = write_step(tmp_path / "a.step", [flush])
    b = write_step(tmp_path / "b.step", [above])
    assert Path(a).read_bytes().replace(b"a.step", b"b.step") == Path(b).read_bytes()
    expected = (green_area(fit.curve) - math.pi * 36.0) * 8.0 - math.pi * (900.0 - 100.0) * 3.0
    assert volume(read_step(b)) == pytest.approx(expected, rel=1e-6)
