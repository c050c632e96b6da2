"""FreeCAD (its own OpenCASCADE, through ``Part.read`` and ``Import``) opens cam.step and every DXF.

FreeCAD 0.20 from Debian runs headless as ``freecadcmd``; each test writes a
small script that prints one ``RESULT {json}`` line, and compares it with
numbers computed here: the exact areas (Green's theorem on the fit, closed
forms for the bore), the fit's poles and knots, the polygon areas of the
polyline files, the design name.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad.export._outline import bspline_area, bspline_length, polygon_area
from tests.readers.conftest import Built, require, run

pytestmark = pytest.mark.slow

STEP_SCRIPT = """
import json, Part, FreeCAD, Import
shape = Part.read({path!r})
curves = []
for edge in shape.Edges:
    c = edge.Curve
    if type(c).__name__ == "BSplineCurve":
        curves.append(dict(poles=[[p.x, p.y, p.z] for p in c.getPoles()], knots=c.getKnots(),
                           mults=c.getMultiplicities(), periodic=c.isPeriodic(), degree=c.Degree))
doc = FreeCAD.newDocument("names")
Import.insert({path!r}, "names")
names = [o.Label for o in doc.Objects if o.TypeId == "Part::Feature"]
top = max((f for f in shape.Faces if type(f.Surface).__name__ == "Plane"), key=lambda f: f.CenterOfMass.z)
probes = [shape.isInside(FreeCAD.Vector(*p), 1e-7, False) for p in {probes!r}]
print("RESULT " + json.dumps(dict(
    valid=shape.isValid(), solids=len(shape.Solids), shells=len(shape.Shells), volume=shape.Volume,
    top_area=top.Area, top_z=top.CenterOfMass.z, curves=curves, names=names, probes=probes,
    surfaces=sorted(type(f.Surface).__name__ for f in shape.Faces))))
"""

DXF_SCRIPT = """
import json, FreeCAD, Import, Part
doc = FreeCAD.newDocument("dxf")
Import.readDXF({path!r}, "dxf", True)
edges = [e for o in doc.Objects if hasattr(o, "Shape") for e in o.Shape.Edges]
kinds = {{}}
for e in edges:
    kinds[type(e.Curve).__name__] = kinds.get(type(e.Curve).__name__, 0) + 1
splines = [dict(poles=[[p.x, p.y] for p in e.Curve.getPoles()], knots=e.Curve.getKnots(),
                mults=e.Curve.getMultiplicities(), closed=e.Curve.isClosed(), length=e.Length)
           for e in edges if type(e.Curve).__name__ == "BSplineCurve"]
wires = [Part.Wire(group) for group in Part.sortEdges(edges)]
closed = [w for w in wires if w.isClosed()]
faces = sorted((Part.Face(w).Area for w in closed), reverse=True)
print("RESULT " + json.dumps(dict(
    kinds=kinds, splines=splines, closed_areas=faces, open_wires=len(wires) - len(closed))))
"""


def freecad(script: str, folder: Path) -> dict:
    """Run ``script`` in ``freecadcmd``; the JSON it printed after ``RESULT``."""
    program = require("freecadcmd")
    path = folder / "script.py"
    path.write_text(script, encoding="utf-8")
    result = run([program, str(path)], cwd=folder)
    assert result.returncode == 0, (result.stdout + result.stderr)[-3000:]
    lines = [line for line in result.stdout.splitlines() if line.startswith("RESULT ")]
    assert len(lines) == 1, (result.stdout + result.stderr)[-3000:]
    return json.loads(lines[0][len("RESULT ") :])


def test_freecad_reads_cam_step_as_the_exact_solid(built: Built, tmp_path):
    """Part.read: one valid solid, one shell; the fit's B-spline; areas and volume; the product name."""
    from camcad.export.step import write_cam_step

    plate = built.design.plate()
    path = write_cam_step(tmp_path / "cam.step", fit=built.fit, plate=plate)
    # points just inside and just outside the exact profile, half way up: beyond the fit's certificate
    exact = built.cam.profile(np.linspace(0.0, 2.0 * math.pi, 48, endpoint=False))
    step = 2.0 * built.fit.max_error + 1e-4
    probes = [
        (float(x), float(y), 0.5 * plate.thickness)
        for side in (-1.0, 1.0)
        for x, y in exact.point + side * step * exact.normal
    ]
    got = freecad(STEP_SCRIPT.format(path=str(path), probes=probes), tmp_path)
    assert got["valid"] and got["solids"] == 1 and got["shells"] == 1
    assert "SurfaceOfExtrusion" in got["surfaces"] and len(got["surfaces"]) < 12  # exact faces, no facets
    assert got["names"] == [built.design.cam.name]
    hole = plate.bore.area if plate.bore is not None else 0.0
    area = abs(bspline_area(built.fit.clamped)) - hole  # Green's theorem on the fit, exact for a cubic
    # FreeCAD's Face.Area and Shape.Volume integrate with a fixed Gauss rule (up to 4e-4 and 2e-3 off on
    # these spline faces): a sanity check only; the exact checks are the poles and knots below and the
    # inside/outside probes; OCP's adaptive read-back in tests/export/test_step.py holds the 1e-6 volume
    assert got["top_area"] == pytest.approx(area, rel=1e-3)
    assert got["top_z"] == pytest.approx(plate.thickness, abs=1e-9)
    assert got["volume"] == pytest.approx(area * plate.thickness, rel=1e-2)
    # FreeCAD's classifier on the exact geometry: inside the profile by the certificate, outside beyond it
    assert got["probes"] == [True] * 48 + [False] * 48
    curve = built.fit.curve
    p = curve.degree
    count = curve.control_points.shape[0] - p
    values, mults = np.unique(np.append(curve.knots[p : p + count], 1.0), return_counts=True)
    mults[-1] = mults[0]
    assert len(got["curves"]) == 2  # bottom and top edge of the profile face
    for read in got["curves"]:
        assert read["periodic"] and read["degree"] == p
        assert read["mults"] == list(mults)
        assert_allclose(read["knots"], values, rtol=0, atol=1e-9)
        ours = np.roll(curve.control_points[:count], 1 - int(mults[0]), axis=0)  # OCC's periodic pole origin
        assert_allclose(np.asarray(read["poles"])[:, :2], ours, rtol=0, atol=1e-9)


def test_freecad_reads_the_profile_spline_from_profile_dxf(built: Built, tmp_path):
    """Import.readDXF: the SPLINE comes in as one closed B-spline with our poles, knots and length."""
    got = freecad(DXF_SCRIPT.format(path=str(built.dxf)), tmp_path)
    clamped = built.fit.clamped
    profile = [s for s in got["splines"] if len(s["poles"]) == clamped.control_points.shape[0]]
    assert len(profile) == 1
    spline = profile[0]
    assert spline["closed"]
    assert_allclose(spline["poles"], clamped.control_points, rtol=0, atol=1e-9)
    knots, mults = np.unique(clamped.knots, return_counts=True)
    assert_allclose(spline["knots"], knots, rtol=0, atol=1e-9)
    assert spline["mults"] == list(mults)
    assert spline["length"] == pytest.approx(bspline_length(clamped), rel=1e-6)


def test_freecad_makes_the_plate_faces_from_profile_poly_dxf(built: Built, tmp_path):
    """The polyline file's edges join into closed wires whose faces have the polygons' areas."""
    import ezdxf

    got = freecad(DXF_SCRIPT.format(path=str(built.poly_dxf)), tmp_path)
    assert got["open_wires"] == 0
    msp = ezdxf.readfile(built.poly_dxf).modelspace()
    areas = sorted(
        (abs(polygon_area(np.asarray(e.get_points("xy")))) for e in msp.query("LWPOLYLINE")), reverse=True
    )
    assert_allclose(got["closed_areas"], areas, rtol=1e-9)


def test_freecad_makes_the_plate_faces_from_profile_arcs_dxf(built: Built, tmp_path):
    """The arcs file's ARCs and LINEs join into closed wires whose faces have the exact (Green) areas."""
    import ezdxf

    from camcad.export.dxf import write_profile_arcs_dxf
    from tests.readers.test_openscad import loop_area

    plate = built.design.plate()
    dxf = write_profile_arcs_dxf(
        tmp_path / "profile_arcs.dxf", cam=built.cam, fit=built.fit, plate=plate, options=built.design.dxf
    )
    got = freecad(DXF_SCRIPT.format(path=str(dxf)), tmp_path)
    assert got["open_wires"] == 0
    assert set(got["kinds"]) <= {"Circle", "Line"}
    msp = ezdxf.readfile(dxf).modelspace()
    areas = []
    for layer in ("CAM_PROFILE", "BORE"):
        entities = [e for e in msp if e.dxf.layer == layer]
        if entities and entities[0].dxftype() == "CIRCLE":
            areas.append(math.pi * entities[0].dxf.radius ** 2)
        elif entities:
            areas.append(loop_area(entities, 0.0)[0])
    assert_allclose(got["closed_areas"], sorted(areas, reverse=True), rtol=1e-9)
