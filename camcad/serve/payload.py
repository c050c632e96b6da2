"""What the designer's page draws after each change: numbers, warnings, the drawing and the curves.

:func:`evaluate` validates a design mapping with the loader, runs the
analysis without fit and toolpath (motion, geometry, dynamics: tens of
milliseconds) and returns plain JSON data: the report's key-number cards
and warning banner (the same HTML fragments as ``report.html``), the cam
drawing (profile, reference trace, base circle, bore, the follower at four
angles, all in mm in the cam frame) and the curves against the cam angle,
thinned to at most :data:`CURVE_POINTS` points (the extremes shown in the
cards are camcad's true extremes, not those of the thinned curves). An
invalid design gives the loader's message with the field it names.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad._plots import trace_name
from camcad._plots.design import (
    CURVATURE_CLIP,
    bore_outline,
    family_caption,
    follower_drawings,
)
from camcad.design import parse_design
from camcad.errors import CamcadError
from camcad.pipeline import analyse
from camcad.report import alerts_html, key_numbers_html

if TYPE_CHECKING:
    from camcad.analysis import Analysis

__all__ = ["CURVE_POINTS", "evaluate"]

CURVE_POINTS = 721
"""Points per curve sent to the page (every 0.5° on the default grid)."""

_OUTLINE_POINTS = 1441


def _xy(points: Any, n: int = _OUTLINE_POINTS) -> list[list[float]]:
    arr = np.asarray(points, dtype=float)
    if len(arr) > n:
        arr = arr[np.unique(np.linspace(0, len(arr) - 1, n).round().astype(int))]
    return np.round(arr, 4).tolist()


def _series(values: Any, index: np.ndarray, clip: float | None = None) -> list[float | None]:
    arr = np.asarray(values, dtype=float)[index]
    with np.errstate(invalid="ignore"):
        keep = np.isfinite(arr) if clip is None else np.isfinite(arr) & (np.abs(arr) <= clip)
    out: list[float | None] = np.round(np.where(keep, arr, 0.0), 6).tolist()
    for i in np.flatnonzero(~keep).tolist():  # a gap in the curve (null in the JSON)
        out[i] = None
    return out


def _followers(analysis: Analysis, reach: float, cam: Any = None) -> list[dict[str, Any]]:
    return [
        {
            "phi_deg": d.phi_deg,
            "body": [_xy(p) for p in d.body],
            "links": [_xy(p) for p in d.links],
            "axes": [_xy(p) for p in d.axes],
            "marks": _xy(d.marks),
            "label_at": np.round(d.label_at, 4).tolist(),
        }
        for d in follower_drawings(analysis, reach, cam=cam)
    ]


def _drawing(analysis: Analysis) -> dict[str, Any]:
    """The cam to scale: profile (or a groove's blank and flanks), a pair's second plate, followers."""
    cam, geo, spec = analysis.cam, analysis.geometry, analysis.design.cam
    profile = np.asarray(geo.profile.point)
    pitch = np.asarray(geo.pitch.point)
    reach = float(max(np.hypot(*pitch.T).max() + cam.roller_radius, np.hypot(*profile.T).max()))
    pocket = analysis.parts[0].part.pocket
    groove = None
    if pocket is not None:  # as the report draws it
        inner, outer = (_xy(cam.offset_curve(geo.phi, flank.offset).point) for flank in pocket.flanks)
        groove = {"outer_radius": pocket.outer_radius, "inner": inner, "outer": outer, "width": pocket.width}
    second = None
    for result in analysis.parts[1:]:  # a pair's second plate
        if not result.part.made or result.part.pocket is not None:
            continue
        plate, later = result.part.cam, result.geometry  # its profile on the same grid, as analysed
        same = np.array_equal(later.phi, geo.phi)
        outline = np.asarray(later.profile.point if same else plate.profile(geo.phi).point)
        second = {"profile": _xy(outline), "followers": _followers(analysis, reach, plate)}
    return {
        "groove": groove,
        "second": second,
        "profile": _xy(profile),
        "trace": _xy(pitch),
        "base_radius": cam.base_radius,
        "bore": _xy(bore_outline(spec.bore, spec.keyway_width, spec.keyway_depth)) if spec.bore > 0.0 else [],
        "followers": _followers(analysis, reach),
        "rotation": cam.rotation.value,
        "caption": f"To scale, cam frame at φ = 0, turning {cam.rotation.value}: the profile (filled), the "
        f"{trace_name(analysis)} (dashed), the base circle r = {cam.base_radius:g} mm (dotted) and "
        f"{cam.follower.describe()} at φ = 0°, 90°, 180°, 270°." + family_caption(analysis),
        "profile_radius_max": float(np.hypot(*profile.T).max()),
    }


def _chart(
    key: str, title: str, unit: str, series: list[dict[str, Any]], limits: list[float]
) -> dict[str, Any]:
    return {"key": key, "title": title, "unit": unit, "series": series, "limits": limits}


def _curves(analysis: Analysis) -> tuple[list[float | None], list[dict[str, Any]]]:
    """The cam angles [°] of the thinned grid and the charts drawn over them."""
    geo, m, dyn, cam = analysis.geometry, analysis.motion, analysis.dynamics, analysis.cam
    spec = analysis.design.dynamics
    phi = np.asarray(geo.phi)
    index = np.unique(np.linspace(0, len(phi) - 1, min(CURVE_POINTS, len(phi))).round().astype(int))
    lift = cam.follower_spec.kind.lift
    u, x = lift.short, lift.variable
    limit = math.degrees(geo.max_pressure_angle)
    clip = CURVATURE_CLIP * cam.base_radius

    def one(label: str, values: Any, bound: float | None = None) -> list[dict[str, Any]]:
        return [{"label": label, "y": _series(values, index, bound)}]

    rho = one("cam profile", geo.profile.rho, clip)
    if cam.has_pitch_curve:
        rho = one(cam.follower.words.path, geo.pitch.rho, clip) + rho
    roller = [cam.roller_radius] if cam.has_pitch_curve else []
    stress_limits = [] if spec.allowable_stress is None else [spec.allowable_stress]
    charts = [
        _chart("s", f"{lift.title} {x}", u, one("s", m.s), []),
        _chart("v", "Velocity d" + x + "/dφ", f"{u}/rad", one("v", m.v), []),
        _chart("a", "Acceleration d²" + x + "/dφ²", f"{u}/rad²", one("a", m.a), []),
        _chart("j", "Jerk d³" + x + "/dφ³", f"{u}/rad³", one("j", m.j), []),
        _chart(
            "pressure", "Pressure angle α", "°", one("α", np.degrees(geo.pressure_angle)), [limit, -limit]
        ),
        _chart("curvature", "Radius of curvature ρ (clipped)", "mm", rho, roller),
        _chart("force", "Contact force", "N", one("F", dyn.contact_force), [spec.min_contact_force]),
        _chart("torque", "Input torque", "N·mm", one("T", dyn.torque), []),
        _chart("stress", "Hertz stress", "MPa", one("σ", dyn.hertz_stress), stress_limits),
    ]
    _second_plate_curves(analysis, charts, index)
    points = _table_points(analysis)
    if points is not None:
        charts[0]["points"] = points
    return _series(np.degrees(phi), index), charts


def _second_plate_curves(analysis: Analysis, charts: list[dict[str, Any]], index: np.ndarray) -> None:
    """Add every further part's own force and stress to ``charts`` (a conjugate pair's second plate).

    Each part's curves come from its own dynamics (its roller, its drive sign),
    by the same code as the first part's. Where a part carries a pocket (a
    groove), the outer flank drives where the signed contact force is
    negative; its force is drawn as its own series (magnitude, N) beside the
    inner flank's.
    """
    by_key = {c["key"]: c for c in charts}
    parts = analysis.parts
    n = len(np.asarray(analysis.geometry.phi))
    later = [
        (i, r.dynamics)
        for i, r in enumerate(parts[1:], start=2)
        if len(np.asarray(r.dynamics.contact_force)) == n
    ]
    if later:
        by_key["force"]["series"][0]["label"] = "F plate 1"
        by_key["stress"]["series"][0]["label"] = "σ plate 1"
    for i, dyn in later:
        by_key["force"]["series"].append({"label": f"F plate {i}", "y": _series(dyn.contact_force, index)})
        by_key["stress"]["series"].append({"label": f"σ plate {i}", "y": _series(dyn.hertz_stress, index)})
    if parts[0].part.pocket is not None:
        force = np.asarray(analysis.dynamics.contact_force, dtype=float)
        inner = np.where(force >= 0.0, force, np.nan)  # gaps where the other flank drives
        outer = np.where(force < 0.0, -force, np.nan)
        by_key["force"]["series"] += [
            {"label": "F inner flank drives", "y": _series(inner, index)},
            {"label": "F outer flank drives (|F|)", "y": _series(outer, index)},
        ]


def _table_points(analysis: Analysis) -> dict[str, list[float]] | None:
    """A point table's own points (angle [°], lift): the smooth law at each angle plus its residual."""
    fit = next((getattr(seg.law, "fit", None) for seg in analysis.design.motion), None)
    if fit is None:
        return None
    angle = np.asarray(fit.angle, dtype=float)
    lift = np.asarray(analysis.cam.motion(angle).s, dtype=float) + np.asarray(fit.residual, dtype=float)
    return {"phi_deg": np.round(np.degrees(angle), 6).tolist(), "s": np.round(lift, 6).tolist()}


def evaluate(data: Mapping[str, Any], *, source: str = "") -> dict[str, Any]:
    """Validate and analyse a design mapping; the page's JSON (``ok`` False with ``errors`` when invalid)."""
    try:
        design = parse_design(data, source=source)
        analysis = analyse(design, fit=False, toolpath=False, strict=False)
    except CamcadError as err:  # bad input, or a limit the analysis cannot get past even when not strict
        return {"ok": False, "errors": [{"field": err.field, "message": err.message}]}
    summary = analysis.summary()
    phi_deg, charts = _curves(analysis)
    return {
        "ok": True,
        "errors": [],
        "cards": key_numbers_html(analysis),
        "alerts": alerts_html(analysis),
        "drawing": _drawing(analysis),
        "phi_deg": phi_deg,
        "charts": charts,
        "lift_unit": analysis.cam.follower_spec.kind.lift.short,
        "summary": {k: summary[k] for k in ("motion", "geometry", "dynamics") if k in summary},
        "findings": [f.summary() for f in analysis.findings],
    }
