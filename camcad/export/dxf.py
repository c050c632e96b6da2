"""DXF drawings of the cam: the fitted profile as one exact SPLINE, and a polyline twin.

``profile.dxf`` (DXF R2010, millimetres) holds, by layer:

``CAM_PROFILE``
    The fitted profile as one SPLINE: non-rational, clamped, cubic, last
    control point equal to the first, flags 0, written from control points
    and knots. Fit points and the periodic/closed encodings are avoided on
    purpose: CAD programs rebuild fit-point splines with their own end
    conditions, and LibreCAD and ezdxf's renderer misdraw periodic ones.
``PITCH_CURVE``
    Roller followers only (``[dxf].pitch_curve``): the roller-centre path as
    a closed LWPOLYLINE within ``[dxf].chord_tolerance``.
``BORE``
    The bore as a CIRCLE, or bore and keyway as one closed LWPOLYLINE whose
    bore arc is an exact bulge.
``CENTER``
    Two centre lines through the cam axis, CENTER linetype.
``ANNOTATION``
    Plain TEXT: name, sizes, follower, motion laws, fit tolerance.

``profile_poly.dxf`` holds only the cutting contours, ``CAM_PROFILE`` and
``BORE``, as closed LWPOLYLINEs without bulges within
``[dxf].chord_tolerance``, for laser cutters and OpenSCAD, which ignore
splines and arcs. The pitch curve, centre lines and text are left out so a
cutter does not cut them.

Both documents are audited before saving; an audit error raises
:class:`~camcad.errors.ExportError` and nothing is written.
"""

from __future__ import annotations

import math
import os
import re
import unicodedata
from pathlib import Path
from typing import TYPE_CHECKING

# First: this imports ezdxf without the user's config files and font cache.
from camcad.export._ezdxf import ezdxf, save_reproducible

# isort: split
import numpy as np
from ezdxf import zoom
from ezdxf.document import Drawing
from ezdxf.layouts import Modelspace

from camcad.errors import ExportError
from camcad.export._outline import flatten_bspline, flatten_curve
from camcad.export.atomic import atomic_write
from camcad.export.spec import DxfSpec
from camcad.fit.curve import BSplineCurve
from camcad.fit.result import ProfileFit
from camcad.geometry.plate import BoreOutline, Plate
from camcad.geometry.spec import FollowerKind
from camcad.motion.segments import SegmentKind

if TYPE_CHECKING:
    from camcad.geometry.cam import Cam

__all__ = [
    "DXF_VERSION",
    "LAYERS",
    "dxf_text",
    "profile_document",
    "profile_poly_document",
    "write_profile_dxf",
    "write_profile_poly_dxf",
]

DXF_VERSION = "R2010"
INSUNITS_MM = 4  # $INSUNITS code for millimetres
MEASUREMENT_METRIC = 1  # $MEASUREMENT: metric linetype and hatch patterns
TEXT_HEIGHT = 2.5  # mm, ISO 3098 lettering
CENTER_OVERHANG = 5.0  # mm beyond the largest profile radius

# layer name: (ACI colour, linetype)
LAYERS: dict[str, tuple[int, str]] = {
    "CAM_PROFILE": (7, "Continuous"),
    "PITCH_CURVE": (3, "DASHED"),
    "BORE": (1, "Continuous"),
    "CENTER": (4, "CENTER"),
    "ANNOTATION": (2, "Continuous"),
}


def _new_document() -> tuple[Drawing, Modelspace]:
    doc = ezdxf.new(DXF_VERSION, setup=["linetypes"], units=INSUNITS_MM)
    doc.header["$INSUNITS"] = INSUNITS_MM
    doc.header["$MEASUREMENT"] = MEASUREMENT_METRIC
    for name, (color, linetype) in LAYERS.items():
        doc.layers.add(name, color=color, linetype=linetype)
    return doc, doc.modelspace()


def _check_clamped(curve: BSplineCurve) -> None:
    """Raise ExportError unless ``curve`` is a closed, clamped, non-periodic B-spline."""
    p = curve.degree
    knots = np.asarray(curve.knots, dtype=float)
    ctrl = np.asarray(curve.control_points, dtype=float)
    problems = []
    if curve.periodic:
        problems.append("it is the periodic form")
    if knots.size != ctrl.shape[0] + p + 1:
        problems.append(f"{knots.size} knots for {ctrl.shape[0]} control points of degree {p}")
    elif np.any(knots[: p + 1] != knots[0]) or np.any(knots[-p - 1 :] != knots[-1]):
        problems.append("its end knots are not clamped")
    if np.any(np.diff(knots) < 0.0):
        problems.append("its knots decrease")
    if not np.array_equal(ctrl[0], ctrl[-1]):
        problems.append("its last control point differs from the first")
    if problems:
        raise ExportError(
            "the profile cannot be written as a DXF SPLINE: "
            + "; ".join(problems)
            + "; pass ProfileFit.clamped"
        )


def _add_profile_spline(msp: Modelspace, curve: BSplineCurve) -> None:
    """One SPLINE from control points and knots: non-rational, flags 0, no fit points."""
    _check_clamped(curve)
    spline = msp.add_spline(degree=curve.degree, dxfattribs={"layer": "CAM_PROFILE"})
    spline.dxf.flags = 0
    spline.control_points = [(float(x), float(y), 0.0) for x, y in curve.control_points]  # type: ignore[assignment]
    spline.knots = [float(k) for k in curve.knots]  # type: ignore[assignment]


def _add_closed_polyline(msp: Modelspace, points: np.ndarray, layer: str) -> None:
    msp.add_lwpolyline(
        [(float(x), float(y)) for x, y in points],
        format="xy",
        close=True,
        dxfattribs={"layer": layer},
    )


def _add_bore_exact(msp: Modelspace, bore: BoreOutline) -> None:
    if not bore.has_keyway:
        msp.add_circle((0.0, 0.0), bore.radius, dxfattribs={"layer": "BORE"})
        return
    msp.add_lwpolyline(bore.bulge_vertices(), format="xyb", close=True, dxfattribs={"layer": "BORE"})


def _add_center_lines(msp: Modelspace, reach: float) -> None:
    for start, end in (((-reach, 0.0), (reach, 0.0)), ((0.0, -reach), (0.0, reach))):
        msp.add_line(start, end, dxfattribs={"layer": "CENTER"})


MAX_TEXT_CHARS = 250  # a DXF string value holds at most 255 characters in R12-era readers


def dxf_text(text: str) -> str:
    """Text made safe for one DXF TEXT entity.

    Every user text that reaches the drawing (the cam name) goes through
    here: ASCII only (accents dropped, other characters ``?``), every control
    character a space (a newline would end the group value and corrupt the
    file), no ``%%`` (the start of a TEXT control code such as ``%%u``
    underline or ``%%c`` diameter), no ``^`` (the DXF caret escape for
    control characters, ``^J``; it becomes ``'``), at most ``MAX_TEXT_CHARS``.
    """
    plain = unicodedata.normalize("NFKD", text)
    plain = "".join(c for c in plain if not unicodedata.combining(c))
    plain = plain.encode("ascii", "replace").decode("ascii")
    plain = "".join(" " if ord(c) < 32 or ord(c) == 127 else c for c in plain)
    plain = " ".join(plain.split())
    plain = re.sub(r"%{2,}", "%", plain).replace("^", "'")
    if len(plain) > MAX_TEXT_CHARS:
        plain = plain[: MAX_TEXT_CHARS - 3] + "..."
    return plain


def _annotation_lines(cam: Cam, plate: Plate, fit: ProfileFit) -> list[str]:
    """Plain-ASCII lines of the annotation block."""
    follower, bore = cam.follower, plate.bore
    sizes = f"base radius {cam.base_radius:.3f} mm, thickness {plate.thickness:.3f} mm"
    if bore is not None:
        sizes += f", bore dia {2.0 * bore.radius:.3f} mm"
        if bore.has_keyway:
            sizes += f", keyway {bore.keyway_width:.3f} x {bore.keyway_depth:.3f} mm"
    if follower.kind is FollowerKind.TRANSLATING_ROLLER:
        who = f"roller radius {follower.roller_radius:.3f} mm"
    else:
        who = "flat face" + (
            f" width {follower.face_width:.3f} mm" if follower.face_width is not None else ""
        )
    lines = [
        f"CAM {plate.name}",
        sizes,
        f"follower {follower.kind.value}, {who}, offset {follower.eccentricity:.3f} mm, "
        f"rotation {cam.rotation.value}",
    ]
    for seg in cam.program.segments:
        span = f"{math.degrees(seg.span):.3f} deg"
        if seg.kind is SegmentKind.DWELL or seg.law is None:
            lines.append(f"{seg.kind.value} {span}")
        else:
            lines.append(f"{seg.kind.value} {span}, lift {seg.lift:.3f} mm, {seg.law.describe()}")
    lines.append(f"profile spline: fit tolerance {fit.tolerance:.4g} mm, max error {fit.max_error:.3g} mm")
    lines.append("units mm")
    return [dxf_text(line) for line in lines]


def _add_annotation(msp: Modelspace, lines: list[str], reach: float) -> float:
    """TEXT lines below the cam; returns the lowest y used [mm]."""
    y = -reach - 2.0 * TEXT_HEIGHT
    for line in lines:
        y -= 1.6 * TEXT_HEIGHT
        msp.add_text(line, height=TEXT_HEIGHT, dxfattribs={"layer": "ANNOTATION"}).set_placement((-reach, y))
    return y


def _audited(doc: Drawing, name: str) -> Drawing:
    auditor = doc.audit()
    if auditor.has_errors:
        messages = "; ".join(str(e.message) for e in auditor.errors[:5])
        raise ExportError(f"{name}: the DXF audit found {len(auditor.errors)} error(s): {messages}")
    return doc


def profile_document(*, cam: Cam, fit: ProfileFit, plate: Plate, options: DxfSpec) -> Drawing:
    """Build the ``profile.dxf`` document (not saved); see the module docstring for layers.

    Parameters
    ----------
    cam
        The exact cam; supplies the pitch curve.
    fit
        The certified profile fit; ``fit.clamped`` becomes the SPLINE.
    plate
        Name, thickness, bore and keyway.
    options
        ``[dxf]`` settings.

    Raises
    ------
    ExportError
        When the fit is not a closed clamped spline or the audit fails.
    """
    doc, msp = _new_document()
    _add_profile_spline(msp, fit.clamped)
    outline = flatten_bspline(fit.clamped, options.chord_tolerance)
    reach = float(np.max(np.hypot(outline[:, 0], outline[:, 1])))
    if options.pitch_curve and cam.is_roller:
        breaks = [b.phi for b in cam.program.breakpoints]
        pitch = flatten_curve(cam.pitch, options.chord_tolerance, breakpoints=breaks)
        _add_closed_polyline(msp, pitch, "PITCH_CURVE")
        reach = max(reach, float(np.max(np.hypot(pitch[:, 0], pitch[:, 1]))))
    bore = plate.bore
    if bore is not None:
        _add_bore_exact(msp, bore)
    reach += CENTER_OVERHANG
    _add_center_lines(msp, reach)
    bottom = -reach
    if options.annotate:
        bottom = _add_annotation(msp, _annotation_lines(cam, plate, fit), reach) - TEXT_HEIGHT
    zoom.window(msp, (-reach - 5.0, bottom - 5.0), (reach + 5.0, reach + 5.0))
    return _audited(doc, "profile.dxf")


def profile_poly_document(*, cam: Cam, fit: ProfileFit, plate: Plate, options: DxfSpec) -> Drawing:
    """Build the ``profile_poly.dxf`` document: profile and bore as bulge-free LWPOLYLINEs.

    The profile is flattened from ``fit.clamped`` with a chord error bound of
    ``[dxf].chord_tolerance``; the bore polygon is inscribed in the circle
    within the same tolerance with exact keyway corners. ``cam`` is accepted
    for a uniform signature and not used.
    """
    del cam
    doc, msp = _new_document()
    tol = options.chord_tolerance
    _add_closed_polyline(msp, flatten_bspline(fit.clamped, tol), "CAM_PROFILE")
    bore = plate.bore
    if bore is not None:
        _add_closed_polyline(msp, bore.polygon(tol), "BORE")
    return _audited(doc, "profile_poly.dxf")


def _save(doc: Drawing, path: str | os.PathLike[str]) -> Path:
    return atomic_write(path, lambda tmp: save_reproducible(doc, tmp))


def write_profile_dxf(
    path: str | os.PathLike[str], *, cam: Cam, fit: ProfileFit, plate: Plate, options: DxfSpec
) -> Path:
    """Write ``profile.dxf`` atomically; see :func:`profile_document`.

    Returns
    -------
    Path
        The written file.
    """
    return _save(profile_document(cam=cam, fit=fit, plate=plate, options=options), path)


def write_profile_poly_dxf(
    path: str | os.PathLike[str], *, cam: Cam, fit: ProfileFit, plate: Plate, options: DxfSpec
) -> Path:
    """Write ``profile_poly.dxf`` atomically; see :func:`profile_poly_document`.

    Returns
    -------
    Path
        The written file.
    """
    return _save(profile_poly_document(cam=cam, fit=fit, plate=plate, options=options), path)
