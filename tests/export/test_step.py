"""cam.step read back with OpenCASCADE's own STEP reader, against the fit and closed-form areas.

Independent truths: the plate's volume against the exact area of the fitted
periodic B-spline by Green's theorem (Gauss-Legendre on each knot span, exact
for a cubic; computed here from scipy's BSpline, not by the writer) minus the
closed-form bore and keyway area, times the thickness; the B-spline read from
the file against the fit's poles and knots; its points against the exact
profile (the fit's certificate); the product name against the design name.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.interpolate import BSpline

from camcad.design import Design, load_design
from camcad.errors import ExportError
from camcad.export.step import Body, Prism, plate_body, write_cam_step, write_step
from camcad.fit import ProfileFit, fit_cam_profile
from camcad.geometry.cam import Cam
from camcad.geometry.plate import BoreOutline, Plate
from tests.conftest import ROOT, distance_to_polygon, make_design

pytest.importorskip("OCP", reason="the reader of these tests is OpenCASCADE (cadquery-ocp-novtk, test extra)")

from OCP.BRep import BRep_Tool
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.collections import Sequence_TDF_Label as TDF_LabelSequence
from OCP.GProp import GProp_GProps
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.STEPCAFControl import STEPCAFControl_Reader
from OCP.STEPControl import STEPControl_Reader
from OCP.TCollection import TCollection_ExtendedString
from OCP.TDataStd import TDataStd_Name
from OCP.TDocStd import TDocStd_Document
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_SHELL, TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.XCAFDoc import XCAFDoc_DocumentTool

KEYED = {"cam": {"bore": 12.0, "keyway_width": 4.0, "keyway_depth": 2.0}}
DESIGNS = {
    "roller-keyed": lambda: make_design(extra=KEYED),
    "roller-offset-cw": lambda: make_design(
        rotation="cw", offset=6.0, law="poly-345", extra={"cam": {"bore": 10.0}}
    ),
    "flat-harmonic-no-bore": lambda: make_design(follower="translating-flat", law="harmonic"),
    "rocker-sample": lambda: load_design(ROOT / "samples" / "packaging_rocker.toml"),
}


def cam_and_fit(design: Design) -> tuple[Cam, ProfileFit]:
    cam = Cam.from_design(design)
    return cam, fit_cam_profile(
        cam, tolerance=design.fit.tolerance, max_control_points=design.fit.max_control_points
    )


def green_area(curve) -> float:
    """|½∮(x dy − y dx)| over one period of a periodic B-spline, Gauss-Legendre per knot span."""
    p = curve.degree
    spline = BSpline(curve.knots, curve.control_points, p, extrapolate="periodic")
    lo, hi = curve.domain
    breaks = np.unique(curve.knots[(curve.knots >= lo) & (curve.knots <= hi)])
    x, w = np.polynomial.legendre.leggauss(p + 2)  # integrand of degree 2p − 1 per span
    a, b = breaks[:-1, None], breaks[1:, None]
    u = (0.5 * (a + b) + 0.5 * (b - a) * x).ravel()
    weight = (0.5 * (b - a) * w).ravel()
    pt, d = spline(u), spline.derivative(1)(u)
    return abs(0.5 * float(np.sum(weight * (pt[:, 0] * d[:, 1] - pt[:, 1] * d[:, 0]))))


def read_step(path: Path):
    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_ReturnStatus.IFSelect_RetDone
    assert reader.TransferRoots() >= 1
    return reader.OneShape()


def shapes_of(shape, kind) -> list:
    """The distinct sub-shapes of one kind (an edge shared by two faces counts once)."""
    out, explorer = [], TopExp_Explorer(shape, kind)
    while explorer.More():
        current = explorer.Current()
        if not any(current.IsSame(seen) for seen in out):
            out.append(current)
        explorer.Next()
    return out


def volume(shape) -> float:
    props = GProp_GProps()
    # Gauss-Kronrod adaptive (the plain and Gauss adaptive integrators miss by ~1e-4 on B-spline prisms)
    assert BRepGProp.VolumePropertiesGK_s(shape, props, 1e-10) >= 0.0
    return props.Mass()


def bspline_curves(shape) -> list:
    """The distinct Geom_BSplineCurve s of the shape's edges."""
    curves = []
    for edge in shapes_of(shape, TopAbs_EDGE):
        curve = BRep_Tool.Curve_s(TopoDS.Edge(edge), 0.0, 0.0)
        if curve.DynamicType().Name() == "Geom_BSplineCurve":
            curves.append(curve)
    return curves


def product_names(path: Path) -> list[str]:
    """Names of the free shapes, as OpenCASCADE's XCAF reader takes them from the PRODUCT entities."""
    document = TDocStd_Document(TCollection_ExtendedString("test"))
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    assert reader.ReadFile(str(path)) == IFSelect_ReturnStatus.IFSelect_RetDone
    assert reader.Transfer(document)
    tool = XCAFDoc_DocumentTool.ShapeTool_s(document.Main())
    labels = TDF_LabelSequence()
    tool.GetFreeShapes(labels)
    names = []
    for i in range(1, labels.Length() + 1):
        attr = TDataStd_Name()
        assert labels.Value(i).FindAttribute(TDataStd_Name.GetID_s(), attr)
        names.append(attr.Get().ToExtString())
    return names


@pytest.fixture(scope="module", params=list(DESIGNS), ids=list(DESIGNS))
def case(request, tmp_path_factory) -> tuple[Design, Cam, ProfileFit, Path]:
    design = DESIGNS[request.param]()
    cam, fit = cam_and_fit(design)
    path = write_cam_step(tmp_path_factory.mktemp("step") / "cam.step", fit=fit, plate=design.plate())
    return design, cam, fit, path


def test_one_valid_solid_with_one_shell(case):
    shape = read_step(case[3])
    assert BRepCheck_Analyzer(shape).IsValid()
    assert len(shapes_of(shape, TopAbs_SOLID)) == 1
    assert len(shapes_of(shape, TopAbs_SHELL)) == 1


def test_volume_is_exact_area_times_thickness(case):
    """Green's theorem on the fit, closed-form bore and keyway area (BoreOutline.area, tested in geometry)."""
    design, cam, fit, path = case
    plate = design.plate()
    hole = plate.bore.area if plate.bore is not None else 0.0
    expected = (green_area(fit.curve) - hole) * plate.thickness
    assert volume(read_step(path)) == pytest.approx(expected, rel=1e-6)
    # and that area is the exact cam's within the certificate: |ΔA| ≤ max_error × length
    from camcad.export._outline import analytic_area

    exact, length = analytic_area(cam.profile, [b.phi for b in cam.program.breakpoints])
    assert abs(abs(exact) - green_area(fit.curve)) <= fit.max_error * length


def test_profile_is_the_fits_periodic_bspline(case):
    """Poles and knots read from the file equal the fit's (1e-9 mm; the file holds 12–14 digits)."""
    _, cam, fit, path = case
    curves = bspline_curves(read_step(path))
    assert len(curves) == 2  # the profile's edge at the bottom and at the top face
    p, curve = fit.degree, fit.curve
    count = curve.control_points.shape[0] - p
    tau = curve.knots[p : p + count]
    values, mults = np.unique(np.append(tau, 1.0), return_counts=True)
    mults[-1] = mults[0]
    for read in curves:
        assert read.IsPeriodic() and read.Degree() == p and not read.IsRational()
        poles = np.array(
            [[read.Pole(i).X(), read.Pole(i).Y(), read.Pole(i).Z()] for i in range(1, read.NbPoles() + 1)]
        )
        assert poles.shape[0] == count
        z = poles[0, 2]
        assert z in (0.0, pytest.approx(case[0].cam.thickness, abs=1e-12))
        # OpenCASCADE counts a periodic curve's poles from the last copy of its first knot
        ours = np.roll(curve.control_points[:count], 1 - int(mults[0]), axis=0)
        assert_allclose(poles[:, :2], ours, rtol=0, atol=1e-9)
        assert_allclose(poles[:, 2], z, rtol=0, atol=0)
        knots = np.array([read.Knot(i) for i in range(1, read.NbKnots() + 1)])
        assert_allclose(knots, values, rtol=0, atol=1e-9)
        assert [read.Multiplicity(i) for i in range(1, read.NbKnots() + 1)] == list(mults)
    # OpenCASCADE's evaluation of what it read lies on the exact profile within the certificate
    read = curves[0]
    u = np.linspace(0.0, 1.0, 4001)
    points = np.array([[read.Value(float(v)).X(), read.Value(float(v)).Y()] for v in u])
    assert_allclose(points, curve.evaluate(u), rtol=0, atol=1e-8)
    phi = np.linspace(0.0, 2.0 * math.pi, 2001)
    exact = cam.profile(phi).point
    dense = curve.evaluate(np.linspace(0.0, 1.0, 200001)[:-1])  # chords within 1e-9 mm of the spline
    assert distance_to_polygon(exact, dense).max() <= fit.max_error + 1e-9


def test_faces_are_exact_not_facets(case):
    design, _, _, path = case
    kinds = {
        BRep_Tool.Surface_s(TopoDS.Face(face)).DynamicType().Name()
        for face in shapes_of(read_step(path), TopAbs_FACE)
    }
    assert "Geom_SurfaceOfLinearExtrusion" in kinds  # the profile face: the spline extruded
    assert "Geom_Plane" in kinds
    if design.cam.bore > 0:
        assert "Geom_CylindricalSurface" in kinds
    assert len(shapes_of(read_step(path), TopAbs_FACE)) < 12  # no tessellation


def test_product_name_is_the_design_name(case):
    design, _, _, path = case
    assert product_names(path) == [design.cam.name]


def test_header_is_fixed_and_units_are_millimetres(case):
    text = case[3].read_text(encoding="ascii")
    assert "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));" in text  # AP214
    assert "FILE_NAME('cam.step','2000-01-01T00:00:00',(''),(''),\n" in text
    assert "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )" in text


def test_the_same_design_gives_the_same_bytes_written_twice(case, tmp_path):
    design, _, fit, path = case
    again = write_cam_step(tmp_path / "cam.step", fit=fit, plate=design.plate())
    assert again.read_bytes() == path.read_bytes()


def test_bytes_do_not_depend_on_the_process(tmp_path):
    """A fresh interpreter with another hash seed writes the same file: no clock, no random ids."""
    # DESIGNS['roller-keyed'] and cam_and_fit spelled out: importing this module would load OpenCASCADE
    # (~3 s a process) for nothing, the writer does not use it
    script = (
        f"import sys; sys.path.insert(0, {str(ROOT)!r})\n"
        "from tests.conftest import make_design\n"
        "from camcad.export.step import write_cam_step\n"
        "from camcad.fit import fit_cam_profile\n"
        "from camcad.geometry.cam import Cam\n"
        f"design = make_design(extra={KEYED!r})\n"
        "fit = fit_cam_profile(Cam.from_design(design), tolerance=design.fit.tolerance,"
        " max_control_points=design.fit.max_control_points)\n"
        "write_cam_step(sys.argv[1], fit=fit, plate=design.plate())\n"
    )
    paths = []
    for seed, folder in (("1", "a"), ("2", "b")):
        (tmp_path / folder).mkdir()
        target = tmp_path / folder / "cam.step"
        env = dict(os.environ, PYTHONHASHSEED=seed)
        run = subprocess.run(
            [sys.executable, "-c", script, str(target)], env=env, capture_output=True, text=True
        )
        assert run.returncode == 0, run.stderr[-2000:]
        assert run.stdout == ""  # the writer prints nothing
        paths.append(target)
    assert paths[0].read_bytes() == paths[1].read_bytes()
    design = DESIGNS["roller-keyed"]()  # the same design and fit as the script's
    _, fit = cam_and_fit(design)
    (tmp_path / "here").mkdir()  # the file's name is in its header: the same name
    here = write_cam_step(tmp_path / "here" / "cam.step", fit=fit, plate=design.plate())
    assert here.read_bytes() == paths[0].read_bytes()


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    radius=st.floats(2.0, 14.0),
    width_ratio=st.one_of(st.just(0.0), st.floats(0.0005, 0.9)),  # widths from 2 µm (schema floor 1 µm)
    depth=st.floats(0.2, 4.0),
    thickness=st.floats(0.5, 40.0),
)
def test_any_bore_and_keyway_volume(radius, width_ratio, depth, thickness, tmp_path_factory):
    """Law over bores, keyways and thicknesses: volume = (spline area − closed-form hole area) × t."""
    _, fit = FIT
    width = 2.0 * radius * width_ratio
    bore = BoreOutline.from_cam_spec(2.0 * radius, width, depth if width > 0 else 0.0)
    plate = Plate(name="law", thickness=thickness, bore=bore)
    path = write_cam_step(tmp_path_factory.mktemp("law") / "cam.step", fit=fit, plate=plate)
    shape = read_step(path)
    assert BRepCheck_Analyzer(shape).IsValid() and len(shapes_of(shape, TopAbs_SOLID)) == 1
    assert volume(shape) == pytest.approx((green_area(fit.curve) - bore.area) * thickness, rel=1e-6)


FIT = cam_and_fit(make_design())


def test_bodies_with_cuts_and_several_solids(tmp_path):
    """The shape the writer has room for: a pocket cut from a blank, and a second named body.

    A ring pocket (outer B-spline, inner circle) of depth 3 from z = 5 cut from an 8 mm plate:
    volume = plate − pocket, each by its exact area.
    """
    _, fit = FIT
    blank = plate_body(fit, Plate(name="blank", thickness=8.0, bore=BoreOutline(radius=6.0)))
    # the pocket between the profile scaled to 80 % and a 10 mm circle
    inner = replace(fit.curve, control_points=0.8 * fit.curve.control_points)
    pocket = Prism(outer=inner, holes=(BoreOutline(radius=10.0),), height=3.0, z0=5.0)
    grooved = replace(blank, name="groove blank", cuts=(pocket,))
    second = Body(name="second plate", prism=Prism(outer=fit.curve, height=8.0, z0=20.0))
    path = write_step(tmp_path / "pair.step", [grooved, second])
    shape = read_step(path)
    assert BRepCheck_Analyzer(shape).IsValid()
    solids = shapes_of(shape, TopAbs_SOLID)
    assert len(solids) == 2
    a = green_area(fit.curve)
    expected_grooved = (a - math.pi * 36.0) * 8.0 - (0.64 * a - math.pi * 100.0) * 3.0
    assert sorted(volume(s) for s in solids) == pytest.approx(sorted([expected_grooved, a * 8.0]), rel=1e-6)
    assert sorted(product_names(path)) == ["groove blank", "second plate"]


def test_refusals_write_nothing(tmp_path):
    _, fit = FIT
    with pytest.raises(ExportError, match="periodic"):
        plate_body(replace(fit, curve=fit.clamped), Plate(name="x", thickness=5.0))
    with pytest.raises(ExportError, match="height"):
        write_step(tmp_path / "x.step", [Body(name="x", prism=Prism(outer=fit.curve, height=0.0))])
    with pytest.raises(ExportError, match="at least one body"):
        write_step(tmp_path / "x.step", [])
    assert list(tmp_path.iterdir()) == []


def test_build_writes_cam_step_with_only_step(tmp_path):
    from camcad.pipeline import build

    design = make_design(extra=KEYED)
    result = build(design, tmp_path / "out", only=["step"])
    assert sorted(p.name for p in result.files) == ["cam.step", "summary.json"]
    assert product_names(tmp_path / "out" / "cam.step") == [design.cam.name]


BLOCK_OCP = """
import sys
class NoOpenCascade:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] == "OCP":
            raise ImportError(f"{name} is blocked: cam.step must be written without OpenCASCADE")
sys.meta_path.insert(0, NoOpenCascade())
sys.modules.pop("OCP", None)
"""


def test_a_whole_build_writes_cam_step_without_opencascade(tmp_path):
    """A fresh interpreter in which ``import OCP`` fails builds every output, cam.step included.

    The truth of "never imports OCP" is the interpreter's own ``sys.modules``
    after the build (and the blocker, which would fail the build on any
    attempt); the file is then read back here with OpenCASCADE: one valid
    solid of the exact volume.
    """
    sample = ROOT / "samples" / "quintero_harmonic.toml"
    out = tmp_path / "out"
    script = BLOCK_OCP + (
        "import camcad.export.step\n"
        "from camcad.cli import main\n"
        f"code = main(['build', {str(sample)!r}, '-o', {str(out)!r}, '-q'])\n"
        "assert not [m for m in sys.modules if m.split('.')[0] == 'OCP'], 'OCP was imported'\n"
        "sys.exit(code)\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, timeout=600
    )
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stderr == ""  # no note about STEP any more: it is always written
    names = {p.name for p in out.iterdir()}
    assert {"cam.step", "profile.dxf", "cam.stl", "cam.ngc", "report.html", "summary.json"} <= names
    design = load_design(sample)
    _, fit = cam_and_fit(design)
    plate = design.plate()
    hole = plate.bore.area if plate.bore is not None else 0.0
    shape = read_step(out / "cam.step")
    assert BRepCheck_Analyzer(shape).IsValid() and len(shapes_of(shape, TopAbs_SOLID)) == 1
    assert volume(shape) == pytest.approx((green_area(fit.curve) - hole) * plate.thickness, rel=1e-6)
    assert product_names(out / "cam.step") == [design.cam.name]


def test_groove_cam_step_is_the_blank_less_bore_and_groove(tmp_path: Path) -> None:
    """Issue 15: the groove cam's solid, read back, against the blank, bore and flank splines' areas."""
    from camcad.pipeline import build

    design = load_design(ROOT / "samples" / "groove_rocker.toml")
    result = build(design, tmp_path / "out", only=["step"])
    shape = read_step(tmp_path / "out" / "cam.step")
    assert len(shapes_of(shape, TopAbs_SOLID)) == 1
    assert BRepCheck_Analyzer(shape).IsValid()
    flanks = result.analysis.parts[0].flank_fits
    assert len(flanks) == 2
    bore = design.plate().bore
    assert bore is not None
    t, depth, radius = design.cam.thickness, design.groove.depth, design.cam.outer_radius
    groove = green_area(flanks[1].curve) - green_area(flanks[0].curve)
    expected = (math.pi * radius**2 - bore.area) * t - groove * depth
    assert volume(shape) == pytest.approx(expected, rel=1e-6)
    # both flanks are in the file as the fits' own B-splines (poles to 1e-9 mm)
    curves = bspline_curves(shape)
    for fit in flanks:
        count = fit.curve.control_points.shape[0] - fit.degree  # a periodic curve's distinct poles
        ours = sorted(map(tuple, np.asarray(fit.curve.control_points[:count])))

        def same(c, ours=ours) -> bool:
            read = sorted((c.Pole(i).X(), c.Pole(i).Y()) for i in range(1, c.NbPoles() + 1))
            return len(read) == len(ours) and np.allclose(read, ours, rtol=0, atol=1e-9)

        assert any(same(c) for c in curves)


def test_conjugate_pair_writes_a_step_file_per_plate(tmp_path: Path) -> None:
    from camcad.pipeline import build

    design = load_design(ROOT / "samples" / "indexing_conjugate.toml")
    result = build(design, tmp_path / "out", only=["step"])
    fits = {"cam.step": result.analysis.fit, "cam_2.step": result.analysis.parts[1].fit}
    bore = design.plate().bore
    assert bore is not None
    for name, fit in fits.items():
        assert fit is not None
        shape = read_step(tmp_path / "out" / name)
        expected = (green_area(fit.curve) - bore.area) * design.cam.thickness
        assert volume(shape) == pytest.approx(expected, rel=1e-6)


def test_a_conjugate_pair_names_each_plate_and_places_it_as_mounted(tmp_path):
    """Issue 31: cam.step and cam_2.step carry "<design> plate 1" and "plate 2" (OpenCASCADE's XCAF
    names) and sit on one shaft without overlapping: plate 1 at z 0 … t, plate 2 at t + gap … 2t + gap
    (OpenCASCADE's bounding boxes); each is one valid solid."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    from camcad.export.step import PAIR_GAP_MM
    from camcad.pipeline import build

    design = load_design(ROOT / "samples" / "indexing_conjugate.toml")
    build(design, tmp_path / "out", only=["step"])
    t, name = design.cam.thickness, design.cam.name
    boxes = []
    for k, file in ((1, "cam.step"), (2, "cam_2.step")):
        path = tmp_path / "out" / file
        assert product_names(path) == [f"{name} plate {k}"]
        shape = read_step(path)
        assert BRepCheck_Analyzer(shape).IsValid()
        assert len(shapes_of(shape, TopAbs_SOLID)) == 1
        box = Bnd_Box()
        BRepBndLib.AddOptimal_s(shape, box, False, False)
        boxes.append((box.GetZMin(), box.GetZMax()))
    z_lo = [b[0] for b in boxes]
    z_hi = [b[1] for b in boxes]
    assert z_lo[0] == pytest.approx(0.0, abs=1e-6) and z_hi[0] == pytest.approx(t, abs=1e-6)
    assert z_lo[1] == pytest.approx(t + PAIR_GAP_MM, abs=1e-6)
    assert z_hi[1] == pytest.approx(2 * t + PAIR_GAP_MM, abs=1e-6)
    assert z_lo[1] > z_hi[0]  # no overlap in an assembly
