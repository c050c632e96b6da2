"""STEP (AP214) solid of a barrel cam, built with OpenCASCADE: the barrel with its groove cut (or its rib).

The solid is the blank (a cylinder of ``barrel_radius`` and ``length`` less
the bore) minus the groove; the groove is the region between the two wall
surfaces of the certified fit (:mod:`camcad.fit.surface`; their poles and
knots unchanged, as ``B_SPLINE_SURFACE_WITH_KNOTS``, periodic round the
barrel) above the groove's bottom cylinder. The walls' fitted stations reach
a margin below the bottom and above the barrel's surface, closed at both
ends by ruled faces into a ring-shaped tool; OpenCASCADE's Boolean cuts then
trim the walls with both cylinders.

Why OpenCASCADE and not camcad's own STEP writer (:mod:`camcad.export.step`):
the plate is a prism whose every edge is known in closed form, but here the
walls' edges are the intersections of B-spline surfaces with cylinders, which
have no closed form. Writing them by hand means fitting each intersection as
a 3-D curve plus its two parameter-space curves, and proving the three agree
within the edge tolerance a reader assumes; that is a surface–surface
intersection code of its own. OpenCASCADE does it, and BRepCheck then
validates the result, so the STEP file is written through ``OCP``
(``cadquery-ocp-novtk``, the ``step`` extra); its import costs seconds.

Same input, same bytes: the header's time stamp and system are replaced by
fixed text.
"""

from __future__ import annotations

import math
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad.errors import ExportError
from camcad.export.step import STEP_TIMESTAMP

if TYPE_CHECKING:
    from camcad.fit.surface import BarrelWallFit, BSplineSurface
    from camcad.geometry.barrel import BarrelOptions

__all__ = ["BarrelSolid", "barrel_shape", "barrel_step_bytes", "occ_surface"]

CYLINDER_SEAM = 2.0  # rad: where the cylinders open, well away from φ = 0
SEW_TOLERANCE = 1e-5  # mm: the walls' end curves and the ruled faces share their curves exactly


@dataclass(frozen=True, slots=True)
class BarrelSolid:
    """The OpenCASCADE solid (``shape``, a ``TopoDS_Shape``) and its volume [mm³] as measured by it."""

    shape: Any
    volume: float


def occ_surface(surface: BSplineSurface) -> Any:
    """The fit's surface as a ``Geom_BSplineSurface``, closed (not periodic) in u, opened at φ = 0.

    The periodic rows are turned into their exact clamped form by knot
    insertion (:func:`~camcad.fit.bspline.clamped_from_periodic`), so the
    poles and knots are the fit's own, written out once round the barrel
    (OpenCASCADE's Booleans fail on the periodic form's seam here).
    """
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt
    from OCP.OCP.collections import Array1_double, Array1_int, Array2_gp_Pnt

    from camcad.fit.bspline import clamped_from_periodic
    from camcad.fit.curve import BSplineCurve

    kv = surface.control_points.shape[1]
    rows = BSplineCurve(
        degree=surface.degree_u,
        knots=surface.knots_u,
        control_points=np.ascontiguousarray(surface.control_points.reshape(-1, kv * 3)),
        periodic=True,
    )
    clamped = clamped_from_periodic(rows)
    cp = clamped.control_points.reshape(-1, kv, 3)
    uk, um = np.unique(clamped.knots, return_counts=True)
    vk, vm = np.unique(surface.knots_v, return_counts=True)

    def arr(values: list[Any], cls: Any) -> Any:
        out = cls(1, len(values))
        for i, x in enumerate(values):
            out.SetValue(i + 1, x)
        return out

    poles = Array2_gp_Pnt(1, cp.shape[0], 1, kv)
    for i in range(cp.shape[0]):
        for j in range(kv):
            poles.SetValue(i + 1, j + 1, gp_Pnt(*(float(x) for x in cp[i, j])))
    return Geom_BSplineSurface(
        poles,
        arr([float(x) for x in uk], Array1_double),
        arr([float(x) for x in vk], Array1_double),
        arr([int(x) for x in um], Array1_int),
        arr([int(x) for x in vm], Array1_int),
        surface.degree_u,
        surface.degree_v,
        False,
        False,
    )


def _cylinder(radius: float, z0: float, height: float) -> Any:
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    # the cylinder's own seam away from the walls' seam at φ = 0 (coincident seams defeat the Booleans)
    seam = gp_Dir(math.cos(CYLINDER_SEAM), math.sin(CYLINDER_SEAM), 0.0)
    frame = gp_Ax2(gp_Pnt(0.0, 0.0, z0), gp_Dir(0.0, 0.0, 1.0), seam)
    return BRepPrimAPI_MakeCylinder(frame, radius, height).Shape()


def _cut(a: Any, b: Any, what: str) -> Any:
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut

    op = BRepAlgoAPI_Cut(a, b)
    if not op.IsDone():
        raise ExportError(f"OpenCASCADE could not cut {what}")
    return op.Shape()


def _boolean(kind: str, a: Any, b: Any, what: str) -> Any:
    """``Common`` or ``Fuse`` of two shapes (a fuse with its coplanar faces merged)."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Fuse

    op = BRepAlgoAPI_Common(a, b) if kind == "common" else BRepAlgoAPI_Fuse(a, b)
    if not op.IsDone():
        raise ExportError(f"OpenCASCADE could not {kind} {what}")
    if kind == "common":
        return op.Shape()
    from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain

    unify = ShapeUpgrade_UnifySameDomain(op.Shape(), True, True, False)
    unify.Build()
    return unify.Shape()


def _groove_tool(fit: BarrelWallFit) -> Any:
    """The closed ring between the walls over the fitted stations."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_Sewing
    from OCP.BRepFill import BRepFill
    from OCP.BRepLib import BRepLib
    from OCP.ShapeFix import ShapeFix_Solid
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    upper, lower = occ_surface(fit.upper), occ_surface(fit.lower)
    sew = BRepBuilderAPI_Sewing(SEW_TOLERANCE)
    for surf in (upper, lower):
        sew.Add(BRepBuilderAPI_MakeFace(surf, 1e-7).Face())
    for v in (0.0, 1.0):
        e_up = BRepBuilderAPI_MakeEdge(upper.VIso(v)).Edge()
        e_low = BRepBuilderAPI_MakeEdge(lower.VIso(v)).Edge()
        sew.Add(BRepFill.Face_s(e_up, e_low))
    sew.Perform()
    explorer = TopExp_Explorer(sew.SewedShape(), TopAbs_SHELL)
    if not explorer.More():
        raise ExportError("the groove's walls and ends did not sew into a closed shell")
    fix = ShapeFix_Solid()
    solid = fix.SolidFromShell(TopoDS.Shell(explorer.Current()))
    BRepLib.OrientClosedSolid_s(solid)
    return solid


def barrel_shape(fit: BarrelWallFit, options: BarrelOptions) -> BarrelSolid:
    """The barrel with its groove (or rib) as one OpenCASCADE solid, checked by ``BRepCheck_Analyzer``.

    A groove: the blank less the ring between the walls above the bottom
    cylinder. A rib (``options.kind``): the ring between its faces within the
    blank, fused with the core cylinder (radius R − depth), less the bore.

    Raises
    ------
    ExportError
        A Boolean failed, the result is not valid or not exactly one solid.
    """
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    from camcad.geometry.barrel import BarrelKind

    o = options
    blank = _cylinder(o.barrel_radius, 0.0, o.length)
    if o.kind is BarrelKind.RIB:
        rib = _boolean("common", _groove_tool(fit), blank, "the rib with the blank")
        blank = _boolean("fuse", _cylinder(o.bottom_radius, 0.0, o.length), rib, "the rib onto the core")
    if o.bore > 0.0:
        blank = _cut(blank, _cylinder(0.5 * o.bore, -1.0, o.length + 2.0), "the bore")
    if o.kind is BarrelKind.RIB:
        shape = blank
    else:
        reach = fit.upper.station_range[1] - fit.upper.station_range[0]
        inner = _cylinder(o.bottom_radius, -reach - o.length, 3.0 * o.length + 2.0 * reach)
        groove = _cut(_groove_tool(fit), inner, "the groove's bottom")
        shape = _cut(blank, groove, "the groove")
    solids = 0
    explorer = TopExp_Explorer(shape, TopAbs_SOLID)
    while explorer.More():
        solids += 1
        explorer.Next()
    if solids != 1:
        raise ExportError(f"the barrel came out as {solids} solids, not one")
    if not BRepCheck_Analyzer(shape).IsValid():
        raise ExportError("OpenCASCADE's BRepCheck_Analyzer finds the barrel's solid invalid")
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-7)  # adaptive: the default rule is off by 1e-4 here
    return BarrelSolid(shape=shape, volume=float(props.Mass()))


def barrel_step_bytes(solid: BarrelSolid, *, name: str = "barrel cam") -> bytes:
    """ISO 10303-21 text (AP214, mm) of the solid, one product named ``name``, the same bytes each time."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    from OCP.Message import Message, Message_PrinterOStream

    Message.DefaultMessenger_s().RemovePrinters(Message_PrinterOStream.get_type_descriptor_s())
    writer = STEPControl_Writer()
    writer.Transfer(solid.shape, STEPControl_AsIs)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "cam.step"
        if writer.Write(str(path)) != IFSelect_RetDone:
            raise ExportError("OpenCASCADE could not write the barrel's STEP file")
        text = path.read_text(encoding="ascii", errors="replace")
    text = re.sub(
        r"FILE_NAME\(.*?\);",
        f"FILE_NAME('cam.step','{STEP_TIMESTAMP}',(''),(''),'camcad','camcad','');",
        text,
        count=1,
        flags=re.DOTALL,
    )
    safe = name.replace("'", "")  # OpenCASCADE numbers its products per session: name it ourselves
    text = re.sub(r"PRODUCT\('[^']*',\s*'[^']*'", f"PRODUCT('{safe}','{safe}'", text)
    return text.encode("ascii")
