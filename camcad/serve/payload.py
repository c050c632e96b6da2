"""What the designer's page draws after each change: numbers, warnings, the drawing and the curves.

:func:`evaluate` validates a design mapping with the loader, runs the
analysis without fit and toolpath (motion, geometry, dynamics: tens of
milliseconds) and returns plain JSON data: the report's key-number cards
and warning banner (the same HTML fragments as ``report.html``), the cam
drawing (profile, reference trace, base circle, bore, the follower at four
angles, all in mm in the cam frame) and the curves against the cam angle.
Only what a screen shows is sent (an edit is answered in well under 150 ms
on a plate): each chart's curves are thinned to :data:`CHART_BUCKETS`
angle buckets keeping each bucket's smallest and largest sample of every
series (min-max decimation: the drawn curve reaches every sampled extreme,
and every gap stays a gap), on the chart's own angles; outlines to
:data:`OUTLINE_POINTS` points (0.5°: a chord error below 1 µm on a 100 mm
cam). The extremes shown in the cards are camcad's true extremes, not
those of any samples. Every number in the answer is finite (gaps and
unbounded ends are ``None``), so it encodes without a second pass. An
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
from camcad.design.paths import named_error
from camcad.errors import CamcadError
from camcad.export.records import json_safe
from camcad.pipeline import analyse
from camcad.report import alerts_html, key_numbers_html

if TYPE_CHECKING:
    from camcad.analysis import Analysis

__all__ = ["CHART_BUCKETS", "OUTLINE_POINTS", "evaluate"]

CHART_BUCKETS = 200
"""Angle buckets per chart (1.8° each): a chart sends at most two samples per bucket and series."""

OUTLINE_POINTS = 721
"""Points per closed outline sent for the cam drawing (every 0.5° on the default 0.1° grid)."""


def _thin(n: int, points: int) -> np.ndarray:
    """Indices of about ``points`` evenly spread samples of ``n`` (first and last kept)."""
    if n <= points:
        return np.arange(n)
    index: np.ndarray = np.linspace(0, n - 1, points).round().astype(int)
    return index


def _xy(points: Any, n: int = OUTLINE_POINTS) -> list[list[float]]:
    arr = np.asarray(points, dtype=float)
    if len(arr) > n:
        arr = arr[_thin(len(arr), n)]
    out: list[list[float]] = np.round(arr, 4).tolist()
    return out


def _shown(values: Any, clip: float | None = None) -> np.ndarray:
    """``values`` as floats with NaN where the chart shows a gap (non-finite, or beyond ``clip``)."""
    arr = np.array(values, dtype=float)
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(arr) if clip is None else ~(np.isfinite(arr) & (np.abs(arr) <= clip))
    arr[bad] = np.nan
    return arr


def decimate(
    columns: list[np.ndarray], buckets: int = CHART_BUCKETS, always: np.ndarray | None = None
) -> np.ndarray:
    """Sample indices that keep every bucket's smallest and largest value of every column (min-max).

    The ``n`` samples are cut into ``buckets`` runs of equal length; of each
    run the samples holding each column's smallest and largest finite value
    are kept, with the first and last sample, the indices ``always`` (the
    segments' joints: the curve passes through every blend point) and both
    ends of every gap (a NaN run), so a line through the kept samples
    reaches every sampled extreme and breaks where the curve does. Sorted,
    unique.
    """
    n = len(columns[0]) if columns else 0
    if n <= 2 * buckets:
        return np.arange(n)
    size = -(-n // buckets)
    keep = [np.array([0, n - 1]), np.zeros(0, dtype=int) if always is None else np.asarray(always, dtype=int)]
    for col in columns:
        finite = np.isfinite(col)
        pad = np.full(size * buckets, np.nan)
        pad[:n] = col
        rows = pad.reshape(buckets, size)
        base = np.arange(buckets) * size
        some = np.isfinite(rows).any(axis=1)
        low = np.argmin(np.where(np.isnan(rows), np.inf, rows), axis=1) + base
        high = np.argmax(np.where(np.isnan(rows), -np.inf, rows), axis=1) + base
        edges = np.flatnonzero(np.diff(finite.astype(np.int8)))  # the last sample before a change
        keep += [low[some], high[some], edges, edges + 1]
    return np.unique(np.concatenate(keep))


def _series(arr: np.ndarray, index: np.ndarray) -> list[float | None]:
    """``arr[index]`` (NaN for a gap) as JSON numbers rounded to 1e-6, None in the gaps."""
    part = arr[index]
    gaps = np.isnan(part)
    out: list[float | None] = np.round(np.where(gaps, 0.0, part), 6).tolist()
    for i in np.flatnonzero(gaps).tolist():  # a gap in the curve (null in the JSON)
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
    shown = np.asarray(geo.phi)[_thin(len(geo.phi), OUTLINE_POINTS)]  # the angles an outline is drawn at
    if pocket is not None:  # as the report draws it
        inner, outer = (_xy(cam.offset_curve(shown, flank.offset).point) for flank in pocket.flanks)
        groove = {"outer_radius": pocket.outer_radius, "inner": inner, "outer": outer, "width": pocket.width}
    second = None
    for result in analysis.parts[1:]:  # a pair's second plate
        if not result.part.made or result.part.pocket is not None:
            continue
        plate, later = result.part.cam, result.geometry  # its profile on the same grid, as analysed
        same = np.array_equal(later.phi, geo.phi)
        outline = np.asarray(later.profile.point if same else plate.profile(shown).point)
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
    key: str, title: str, unit: str, series: list[tuple[str, np.ndarray]], limits: list[float]
) -> dict[str, Any]:
    return {"key": key, "title": title, "unit": unit, "series": series, "limits": limits}


def _curves(analysis: Analysis) -> list[dict[str, Any]]:
    """The charts against the cam angle [°], each on its own min-max decimated angles (:func:`decimate`)."""
    geo, m, dyn, cam = analysis.geometry, analysis.motion, analysis.dynamics, analysis.cam
    spec = analysis.design.dynamics
    phi = np.degrees(np.asarray(geo.phi, dtype=float))
    lift = cam.follower_spec.kind.lift
    u, x = lift.short, lift.variable
    limit = math.degrees(geo.max_pressure_angle)
    clip = CURVATURE_CLIP * cam.base_radius

    def one(label: str, values: Any, bound: float | None = None) -> list[tuple[str, np.ndarray]]:
        return [(label, _shown(values, bound))]

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
    _second_plate_curves(analysis, charts)
    grid = np.asarray(geo.phi, dtype=float)
    marks = np.mod([bp.phi for bp in cam.program.breakpoints], 2.0 * math.pi)
    joints = np.clip(np.searchsorted(grid, marks - 1e-9), 0, len(grid) - 1)  # the grid holds every joint
    for chart in charts:
        index = decimate([y for _, y in chart["series"]], always=joints)
        chart["phi_deg"] = np.round(phi[index], 4).tolist()
        chart["series"] = [{"label": label, "y": _series(y, index)} for label, y in chart["series"]]
    points = _table_points(analysis)
    if points is not None:
        charts[0]["points"] = points
    return charts


def _second_plate_curves(analysis: Analysis, charts: list[dict[str, Any]]) -> None:
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
    force, stress = by_key["force"]["series"], by_key["stress"]["series"]
    if later:
        force[0] = ("F plate 1", force[0][1])
        stress[0] = ("σ plate 1", stress[0][1])
    for i, dyn in later:
        force.append((f"F plate {i}", _shown(dyn.contact_force)))
        stress.append((f"σ plate {i}", _shown(dyn.hertz_stress)))
    if parts[0].part.pocket is not None:
        signed = np.asarray(analysis.dynamics.contact_force, dtype=float)
        inner = np.where(signed >= 0.0, signed, np.nan)  # gaps where the other flank drives
        outer = np.where(signed < 0.0, -signed, np.nan)
        force += [("F inner flank drives", _shown(inner)), ("F outer flank drives (|F|)", _shown(outer))]


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
        return {"ok": False, "errors": [{"field": named_error(err).field, "message": err.message}]}
    summary = analysis.summary()
    return {
        "ok": True,
        "errors": [],
        "cards": key_numbers_html(analysis),
        "alerts": alerts_html(analysis),
        "drawing": _drawing(analysis),
        "charts": _curves(analysis),
        "lift_unit": analysis.cam.follower_spec.kind.lift.short,
        # the small parts that may hold a non-finite number (an unbounded speed range): null in the JSON
        "summary": json_safe({k: summary[k] for k in ("motion", "geometry", "dynamics") if k in summary}),
        "findings": json_safe([f.summary() for f in analysis.findings]),
    }
