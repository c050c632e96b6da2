"""STEP (AP214) solid of the cam: the certified periodic B-spline itself, extruded, with bore and keyway.

``cam.step`` holds the plate as one solid, in millimetres, named after the
design: its profile face is a linear extrusion of the fit's periodic
B-spline (the same poles and knots as :attr:`ProfileFit.curve`, not a mesh
or a polyline), and the bore with its keyway is an exact circle arc and
four lines. OpenCASCADE (through ``cadquery-ocp-novtk``, import name
``OCP``) builds the solid and writes the file; it is the optional extra
``camcad[step]``. :func:`ocp_missing` says whether it can be imported.

The writer takes any number of :class:`Body` s, each a :class:`Prism` (a
plane region bounded by closed :data:`Outline` s, extruded along +z) minus
further prisms (pockets), so a groove blank with its pocket or a conjugate
pair's second plate is one more ``Body``, not a new writer.

The file is the same bytes for the same bodies: the header's time stamp,
author, organisation and system are fixed, and entity numbers are
sequential (no random ids).
"""

from __future__ import annotations

import importlib
import itertools
import os
import unicodedata
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad._version import __version__
from camcad.errors import ExportError
from camcad.export.atomic import atomic_write
from camcad.fit.curve import BSplineCurve
from camcad.geometry.plate import BoreOutline

if TYPE_CHECKING:
    from camcad.fit.result import ProfileFit
    from camcad.geometry.plate import Plate

__all__ = [
    "STEP_EXTRA",
    "STEP_TIMESTAMP",
    "Body",
    "Outline",
    "Prism",
    "groove_body",
    "ocp_missing",
    "plate_body",
    "step_text",
    "write_cam_step",
    "write_step",
]

STEP_EXTRA = "pip install 'camcad[step]'"
"""The command that installs what ``cam.step`` needs (OpenCASCADE through cadquery-ocp-novtk)."""

STEP_TIMESTAMP = "2000-01-01T00:00:00"  # FILE_NAME time stamp: fixed, like the DXF header dates
MAX_NAME_CHARS = 250

Outline = BSplineCurve | BoreOutline
"""A closed plane curve in the cam frame [mm]: a periodic B-spline, or a bore with its keyway."""


def ocp_missing() -> str | None:
    """None when OpenCASCADE (``OCP``) can be imported; otherwise one line saying how to get STEP."""
    try:
        importlib.import_module("OCP")
    except ImportError:
        return f"cam.step not written: it needs OpenCASCADE; {STEP_EXTRA} adds it"
    return None


@dataclass(frozen=True, slots=True, kw_only=True)
class Prism:
    """A plane region inside ``outer`` and outside every hole, from z = ``z0`` to ``z0 + height`` [mm].

    Outlines may run either way round; the writer orients them.
    """

    outer: Outline
    holes: tuple[Outline, ...] = ()
    height: float
    z0: float = 0.0


@dataclass(frozen=True, slots=True, kw_only=True)
class Body:
    """One solid of the file: ``prism`` minus every prism in ``cuts``; ``name`` becomes its product name."""

    name: str
    prism: Prism
    cuts: tuple[Prism, ...] = ()


def plate_body(fit: ProfileFit, plate: Plate) -> Body:
    """The cam plate: the fit's periodic B-spline extruded by the plate thickness, minus bore and keyway."""
    if not fit.curve.periodic:
        raise ExportError("cam.step needs the periodic profile of a closed cam (ProfileFit.curve)")
    holes = (plate.bore,) if plate.bore is not None else ()
    return Body(name=plate.name, prism=Prism(outer=fit.curve, holes=holes, height=plate.thickness))


def step_text(text: str) -> str:
    r"""Text made safe for a STEP string: printable ASCII, one line, at most ``MAX_NAME_CHARS``.

    Examples
    --------
    >>> step_text("Nocken Süd\n2")
    'Nocken Sud 2'
    """
    plain = unicodedata.normalize("NFKD", text)
    plain = "".join(c for c in plain if not unicodedata.combining(c))
    plain = plain.encode("ascii", "replace").decode("ascii")
    plain = " ".join("".join(c if c.isprintable() else " " for c in plain).split())
    return plain[:MAX_NAME_CHARS] or "cam"


# --- OpenCASCADE -----------------------------------------------------------------------------
# Everything below imports OCP inside the function, so that this module imports without it.


def _bspline_edge(curve: BSplineCurve, z: float) -> Any:
    """An edge at height ``z`` on the periodic ``Geom_BSplineCurve`` with exactly ``curve``'s poles and knots.

    The extended knot vector of :class:`BSplineCurve` (K distinct poles, one
    period ``tau`` of K knots from 0) becomes OpenCASCADE's periodic form:
    the K poles, the distinct knots of ``tau`` and 1 with their
    multiplicities (the last repeating the first's), Periodic = true.
    OpenCASCADE counts the poles of a periodic curve from the last copy of
    its first knot, so with a first knot of multiplicity m (a double knot at
    a joint at φ = 0) the poles start m − 1 places later. The edge is
    checked against ``curve`` at every knot span's midpoint before it is used.
    """
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int
    from OCP.Geom import Geom_BSplineCurve
    from OCP.gp import gp_Pnt

    p = curve.degree
    if curve.periodic:
        count = curve.control_points.shape[0] - p
        lo, hi = curve.domain
        tau = np.asarray(curve.knots[p : p + count], dtype=float)
        values, mults = np.unique(np.append(tau, hi), return_counts=True)
        mults[-1] = mults[0]
        if values[0] != lo:
            raise ExportError("the periodic profile's knots do not start its period")
        ctrl = np.roll(np.asarray(curve.control_points[:count], dtype=float), 1 - int(mults[0]), axis=0)
    else:
        ctrl = np.asarray(curve.control_points, dtype=float)
        values, mults = np.unique(np.asarray(curve.knots, dtype=float), return_counts=True)
    poles = Array1_gp_Pnt(1, len(ctrl))
    for i, (x, y) in enumerate(ctrl):
        poles.SetValue(i + 1, gp_Pnt(float(x), float(y), z))
    knots = Array1_double(1, len(values))
    multiplicities = Array1_int(1, len(values))
    for i, (value, mult) in enumerate(zip(values, mults, strict=True)):
        knots.SetValue(i + 1, float(value))
        multiplicities.SetValue(i + 1, int(mult))
    geom = Geom_BSplineCurve(poles, knots, multiplicities, p, curve.periodic)
    mid = 0.5 * (values[:-1] + values[1:])
    made = np.array([[geom.Value(float(u)).X(), geom.Value(float(u)).Y()] for u in mid])
    scale = float(np.max(np.abs(ctrl)))
    if not np.allclose(made, curve.evaluate(mid), rtol=0.0, atol=1e-12 * scale):
        raise ExportError("OpenCASCADE's B-spline differs from the fitted profile")
    return BRepBuilderAPI_MakeEdge(geom).Edge()


def _bore_edges(bore: BoreOutline, z: float) -> list[Any]:
    """The bore at height ``z``: a circle edge, or four keyway lines and the exact arc (ccw)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pnt

    circle = gp_Circ(gp_Ax2(gp_Pnt(0.0, 0.0, z), gp_Dir(0.0, 0.0, 1.0)), bore.radius)
    if not bore.has_keyway:
        return [BRepBuilderAPI_MakeEdge(circle).Edge()]
    corners = [gp_Pnt(x, y, z) for x, y, _ in bore.bulge_vertices()]
    edges = [BRepBuilderAPI_MakeEdge(a, b).Edge() for a, b in itertools.pairwise(corners)]
    # the arc runs counter-clockwise (the circle's sense) from the last corner (−w/2, y₀)
    # round the bottom to the first (w/2, y₀)
    edges.append(BRepBuilderAPI_MakeEdge(circle, corners[-1], corners[0]).Edge())
    return edges


def _wire(outline: Outline, z0: float) -> Any:
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeWire

    maker = BRepBuilderAPI_MakeWire()
    edges = [_bspline_edge(outline, z0)] if isinstance(outline, BSplineCurve) else _bore_edges(outline, z0)
    for edge in edges:
        maker.Add(edge)
    if not maker.IsDone():
        raise ExportError("an outline of the STEP solid does not close")
    return maker.Wire()


def _prism_solid(prism: Prism) -> Any:
    """The solid of one prism: a plane face (outer wire, hole wires), extruded along +z."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Dir, gp_Pln, gp_Pnt, gp_Vec
    from OCP.ShapeFix import ShapeFix_Face

    if not prism.height > 0.0:
        raise ExportError(f"a STEP prism needs a height > 0 mm, got {prism.height!r}")
    plane = gp_Pln(gp_Pnt(0.0, 0.0, prism.z0), gp_Dir(0.0, 0.0, 1.0))
    maker = BRepBuilderAPI_MakeFace(plane, _wire(prism.outer, prism.z0), True)
    for hole in prism.holes:
        maker.Add(_wire(hole, prism.z0))
    fix = ShapeFix_Face(maker.Face())
    fix.FixOrientation()  # outer wire counter-clockwise, holes clockwise, whatever way the outlines run
    fix.Perform()
    return BRepPrimAPI_MakePrism(fix.Face(), gp_Vec(0.0, 0.0, prism.height)).Shape()


def _body_solid(body: Body) -> Any:
    """The body's solid, checked: one valid solid with one shell."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.TopAbs import TopAbs_SHELL, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    shape = _prism_solid(body.prism)
    for cut in body.cuts:
        op = BRepAlgoAPI_Cut(shape, _prism_solid(cut))
        if not op.IsDone():
            raise ExportError(f"{body.name}: the boolean cut of the STEP solid failed")
        shape = op.Shape()

    def count(kind: Any) -> int:
        explorer, n = TopExp_Explorer(shape, kind), 0
        while explorer.More():
            n += 1
            explorer.Next()
        return n

    if not BRepCheck_Analyzer(shape).IsValid() or count(TopAbs_SOLID) != 1 or count(TopAbs_SHELL) != 1:
        raise ExportError(f"{body.name}: OpenCASCADE did not make one valid solid of the STEP body")
    return shape


def _quiet() -> Any:
    """Remove OpenCASCADE's console printers (it reports every transfer on stdout); give them back."""
    from OCP.Message import Message

    messenger = Message.DefaultMessenger_s()
    printers = [messenger.Printers().Value(i) for i in range(1, messenger.Printers().Length() + 1)]
    for printer in printers:
        messenger.RemovePrinter(printer)
    return messenger, printers


def _write_document(tmp: Path, bodies: Sequence[Body], file_name: str) -> None:
    from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_StepModelType
    from OCP.TCollection import TCollection_ExtendedString, TCollection_HAsciiString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    solids = [(step_text(body.name), _body_solid(body)) for body in bodies]
    messenger, printers = _quiet()
    try:
        document = TDocStd_Document(TCollection_ExtendedString("camcad"))
        shapes = XCAFDoc_DocumentTool.ShapeTool_s(document.Main())
        for name, solid in solids:
            label = shapes.AddShape(solid, False)
            TDataStd_Name.Set_s(label, TCollection_ExtendedString(name))
        writer = STEPCAFControl_Writer()
        Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
        Interface_Static.SetCVal_s("write.step.unit", "MM")
        if not writer.Transfer(document, STEPControl_StepModelType.STEPControl_AsIs):
            raise ExportError("OpenCASCADE could not transfer the solid to STEP")
        header = APIHeaderSection_MakeHeader(writer.ChangeWriter().Model())
        header.SetName(TCollection_HAsciiString(file_name))
        header.SetTimeStamp(TCollection_HAsciiString(STEP_TIMESTAMP))
        header.SetAuthorValue(1, TCollection_HAsciiString(""))
        header.SetOrganizationValue(1, TCollection_HAsciiString(""))
        header.SetOriginatingSystem(TCollection_HAsciiString(f"camcad {__version__}"))
        header.SetAuthorisation(TCollection_HAsciiString(""))
        status = writer.Write(str(tmp))
    finally:
        for printer in printers:
            messenger.AddPrinter(printer)
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise ExportError(f"OpenCASCADE could not write {file_name}: {status}")


def groove_body(
    flanks: tuple[ProfileFit, ProfileFit], plate: Plate, *, outer_radius: float, depth: float
) -> Body:
    """A groove cam: a disc of ``outer_radius`` [mm] with bore and keyway, less the groove pocket.

    The pocket lies between the outer and the inner flank's periodic
    B-splines (the fits of :func:`camcad.geometry.groove.flank_offsets`'
    curves), ``depth`` [mm] deep from the top face.
    """
    inner, outer = flanks
    if not (inner.curve.periodic and outer.curve.periodic):
        raise ExportError("cam.step needs the periodic flanks of a closed groove (ProfileFit.curve)")
    holes = (plate.bore,) if plate.bore is not None else ()
    t = plate.thickness
    return Body(
        name=plate.name,
        prism=Prism(outer=BoreOutline(radius=outer_radius), holes=holes, height=t),
        cuts=(Prism(outer=outer.curve, holes=(inner.curve,), height=depth, z0=t - depth),),
    )


def write_step(path: str | os.PathLike[str], bodies: Sequence[Body]) -> Path:
    """Write ``bodies`` as STEP AP214 (millimetres) to ``path``, atomically.

    Raises
    ------
    ExportError
        When a body does not make one valid solid, or OpenCASCADE cannot
        write the file (nothing is written then).
    ImportError
        When OpenCASCADE is not installed (see :func:`ocp_missing`).
    """
    if not bodies:
        raise ExportError("a STEP file needs at least one body")
    name = Path(path).name
    return atomic_write(path, lambda tmp: _write_document(tmp, bodies, name))


def write_cam_step(path: str | os.PathLike[str], *, fit: ProfileFit, plate: Plate) -> Path:
    """Write ``cam.step``: the plate of :func:`plate_body` as one solid named after the design."""
    return write_step(path, [plate_body(fit, plate)])
