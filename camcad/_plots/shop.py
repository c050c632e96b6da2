"""Pictures of what the shop receives: the fit's error, the toolpath in plan view, the solid.

* :func:`fit_error_plot`: the signed distance from each fitted sample of the
  exact profile to the B-spline (the sample's foot point on the curve, along
  the profile's outward normal), with the tolerance, the certified maximum
  and the knots marked at their cam angles.
* :func:`toolpath_plot`: the G-code moves in plan view, split by what they do
  (:func:`toolpath_layers`): roughing and finishing passes, leads, the stretches
  where the tool rides over a tab, rapids, the bore, over the exact profile.
* :func:`solid_plot`: the plate seen from above at an angle, drawn from the
  exact outline (profile less bore) in an oblique projection
  (:func:`solid_faces`): the same outline the STL mesh is built from.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.patches import PathPatch, Polygon
from matplotlib.path import Path as MplPath

from camcad._plots._base import (
    COLORS,
    FONT,
    Plot,
    figure,
    plan_axes,
    shape,
    svg,
)
from camcad._plots.chart import HLine, Panel, Series, line_chart
from camcad._plots.design import bore_outline
from camcad._typing import FloatArray
from camcad.fit.cam import FIT_STEP

if TYPE_CHECKING:
    from camcad.analysis import Analysis
    from camcad.fit import ProfileFit
    from camcad.geometry import Cam
    from camcad.toolpath import Toolpath
    from camcad.toolpath.moves import Move

__all__ = [
    "SOLID_VIEW",
    "TOOLPATH_LAYERS",
    "fit_error_along_profile",
    "fit_error_plot",
    "project_oblique",
    "solid_faces",
    "solid_plot",
    "toolpath_layers",
    "toolpath_plot",
]

SOLID_VIEW = (math.radians(-35.0), math.radians(35.0))
"""Azimuth (turn about the cam axis) and elevation of the solid view [rad]."""

TOOLPATH_LAYERS = ("rapid", "bore", "roughing", "finishing", "lead", "tab")
"""What each toolpath move does, in drawing order."""

_ARC_STEP = math.radians(2.0)  # rad, chord angle when an arc move is drawn
_SOLID_POINTS = 720  # outline points of the solid view


# ---------------------------------------------------------------------------
# fit error


def fit_error_along_profile(cam: Cam, fit: ProfileFit) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The fit's signed error at its own samples and its knots as cam angles.

    Returns
    -------
    phi, error, knots_phi
        (n,) cam angles of the fitted samples [rad], (n,) signed distance from
        each exact profile point to its foot point on the curve [mm], + outside
        the cam (along the outward normal), and the cam angle of every distinct
        interior knot of the periodic curve [rad] (interpolated between samples).
    """
    step = min(cam.sample_step, FIT_STEP)
    phi = cam.curve_phi(step)
    while len(phi) < len(fit.params) and step > 1e-6:  # the fit halved its step to meet the tolerance
        step *= 0.5
        phi = cam.curve_phi(step)
    if len(phi) != len(fit.params):
        raise ValueError(f"fit has {len(fit.params)} samples, the cam's grids give {len(phi)}")
    exact = cam.profile(phi)
    foot = fit.curve.evaluate(np.asarray(fit.params))
    error = np.einsum("ij,ij->i", foot - np.asarray(exact.point), np.asarray(exact.normal))
    lo, hi = fit.curve.domain
    knots = np.unique(np.asarray(fit.curve.knots))
    knots = knots[(knots >= lo) & (knots < hi)]
    params = np.asarray(fit.params)
    knots_phi = np.interp(knots, params, phi, period=None) if len(knots) else knots
    return phi, error, knots_phi


def fit_error_plot(analysis: Analysis) -> Plot | None:
    """The fit's error along the profile with the tolerance and the knots; None without a fit."""
    fit = analysis.fit
    if fit is None:
        return None
    phi, error, knots = fit_error_along_profile(analysis.cam, fit)
    micron = 1000.0
    tol, cert = fit.tolerance * micron, fit.max_error * micron
    green = "#2e8b57"
    top = 1.25 * max(tol, cert)
    panel = Panel(
        ylabel="distance to the spline [µm]\n(+ outside the cam)",
        series=[
            Series(
                x=np.degrees(phi), y=error * micron, color=COLORS[0], width=1.1, label="error at the samples"
            )
        ],
        lines=[
            HLine(y=tol, label=f"tolerance ±{tol:.3g} µm"),
            HLine(y=-tol),
            HLine(y=cert, color=green, dash="8 3 2 3", label=f"certified max {cert:.3g} µm"),
            HLine(y=-cert, color=green, dash="8 3 2 3"),
        ],
        ylim=(-top, top),
        height=220.0,
        ticks_at=np.degrees(knots),
        ticks_label=f"knots ({len(knots)})",
        legend=True,
    )
    bounds_deg = [math.degrees(b) for b in analysis.cam.program.segment_bounds[1:]]
    return Plot(
        key="fit-error",
        title="NURBS fit error along the profile",
        caption=f"Signed distance from the exact profile to the fitted B-spline ({fit.control_point_count} "
        f"control points, degree {fit.degree}) at the fit's {len(phi)} samples; the certificate bounds it "
        "between the samples too. Ticks at the bottom: the knots.",
        svg=line_chart([panel], bounds_deg=bounds_deg, title="NURBS fit error"),
    )


# ---------------------------------------------------------------------------
# toolpath


def _move_xy(move: Move) -> FloatArray:
    """(k, 2) plan-view points of one move [mm]; arcs as chords of at most 2°."""
    if move.center is None:
        return np.array([move.start[:2], move.end[:2]], dtype=float)
    cx, cy = move.center
    r0, r1 = move.radii
    sweep = move.sweep
    a0 = math.atan2(move.start[1] - cy, move.start[0] - cx)
    n = max(2, math.ceil(abs(sweep) / _ARC_STEP) + 1)
    t = np.linspace(0.0, 1.0, n)
    r = r0 + (r1 - r0) * t
    a = a0 + sweep * t
    return np.column_stack((cx + r * np.cos(a), cy + r * np.sin(a)))


def toolpath_layers(toolpath: Toolpath) -> dict[str, list[FloatArray]]:
    """The moves in plan view, grouped by what they do (keys :data:`TOOLPATH_LAYERS`).

    A pass starts at the comment the planner writes before it ("… roughing
    pass …", "… finishing pass …", "… bore …"). Within a profile pass the arc
    right after the plunge is the lead-in and the arc right before the climb to
    the safe height the lead-out; feed moves at the tab top ride over a tab.
    Each entry is a list of (k, 2) polylines [mm].
    """
    layers: dict[str, list[FloatArray]] = {k: [] for k in TOOLPATH_LAYERS}
    current = "finishing"
    moves = toolpath.moves
    tab_top = toolpath.tab_top
    for i, move in enumerate(moves):
        note = move.note.lower()
        if "roughing" in note:
            current = "roughing"
        elif "finishing" in note:
            current = "finishing"
        elif "bore" in note:
            current = "bore"
        if move.kind.value == "G0":
            layers["rapid"].append(_move_xy(move))
            continue
        planar = math.hypot(move.end[0] - move.start[0], move.end[1] - move.start[1]) > 0.0 or (
            move.center is not None
        )
        if not planar:
            continue  # a plunge or a climb: a point in plan view
        layer = current
        if current != "bore" and move.center is not None:
            before, after = moves[i - 1] if i else None, moves[i + 1] if i + 1 < len(moves) else None
            safe = toolpath.spec.safe_height
            plunged = (  # from the safe height: the pass starts (a plunge after a tab does not)
                before is not None
                and before.center is None
                and before.end[2] < before.start[2]
                and abs(before.start[2] - safe) <= 1e-9
            )
            climbs = (
                after is not None
                and after.center is None
                and after.end[2] > move.end[2]
                and (after.end[:2] == after.start[:2] and after.end[2] >= toolpath.spec.safe_height)
            )
            if plunged or climbs:
                layer = "lead"
        if layer in ("roughing", "finishing") and tab_top is not None and move.start[2] == tab_top:
            layer = "tab"
        layers[layer].append(_move_xy(move))
    return layers


def part_outline(analysis: Analysis) -> FloatArray:
    """(n, 2) the first part's outline in plan [mm]: its profile; a linear cam's bar adds its three sides."""
    profile = np.asarray(analysis.geometry.profile.point, dtype=float)
    bar = analysis.parts[0].part.bar
    if bar is None:
        return profile
    out: FloatArray = np.vstack((profile, [[bar.x0 + bar.length, bar.bottom], [bar.x0, bar.bottom]]))
    return out


def toolpath_plot(analysis: Analysis) -> Plot | None:
    """The G-code toolpath in plan view over the exact profile; None without a toolpath."""
    path = analysis.toolpath
    if path is None:
        return None
    spec = analysis.design.cam
    layers = toolpath_layers(path)
    fig = figure((6.0, 6.0), left=0.7, bottom=0.5, top=0.15, right=0.15)
    ax = fig.subplots()
    profile = part_outline(analysis)
    shape(ax, Polygon(profile, closed=True, facecolor="#e8eef5", edgecolor="black", linewidth=0.9))
    ax.plot([], [], color="black", linewidth=0.9, label="exact profile")
    if spec.bore > 0.0:
        hole = bore_outline(spec.bore, spec.keyway_width, spec.keyway_depth)
        shape(ax, Polygon(hole, closed=True, facecolor="white", edgecolor="black", linewidth=0.8))
    looks = {
        "rapid": ("rapids (G0)", {"color": "#9a9a9a", "linewidth": 0.7, "linestyle": "--"}),
        "bore": ("bore helix", {"color": COLORS[3], "linewidth": 1.0}),
        "roughing": (f"roughing ({len(path.levels)} depths)", {"color": COLORS[1], "linewidth": 1.0}),
        "finishing": ("finishing", {"color": COLORS[0], "linewidth": 1.3}),
        "lead": ("leads in and out", {"color": COLORS[2], "linewidth": 1.6}),
        "tab": ("over the tabs", {"color": "#c0392b", "linewidth": 2.6}),
    }
    for key in TOOLPATH_LAYERS:
        lines = layers[key]
        if not lines:
            continue
        label, look = looks[key]
        seen = {np.round(line, 3).tobytes(): line for line in lines}  # depths coincide in plan view
        ax.add_collection(LineCollection(list(seen.values()), label=label, **look), autolim=False)
    reach = max(float(np.abs(np.vstack([*(np.vstack(v) for v in layers.values() if v), profile])).max()), 1.0)
    plan_axes(ax, 1.08 * reach)
    if analysis.parts[0].part.bar is not None:  # a bar: its own extent, not a square round an axis
        every = np.vstack([*(np.vstack(v) for v in layers.values() if v), profile])
        (x0, y0), (x1, y1), pad = every.min(axis=0), every.max(axis=0), 0.05 * reach
        ax.set_xlim(x0 - pad, x1 + pad)
        ax.set_ylim(y0 - pad, y1 + pad)
        ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=FONT - 1, loc="lower right", framealpha=0.9)
    tabs = path.spec.tab_count if path.tab_top is not None else 0
    return Plot(
        key="toolpath",
        title="Toolpath (plan view)",
        caption=f"The moves of cam.ngc seen from above: tool ⌀{2.0 * path.tool_radius:g} mm, "
        f"{len(path.levels)} roughing depths and one finishing pass {path.spec.direction.value}, "
        f"{tabs} tabs; the finishing contour is within {path.max_deviation * 1000.0:.2f} µm of the "
        "exact tool-centre curve.",
        svg=svg(fig),
    )


# ---------------------------------------------------------------------------
# solid


def project_oblique(
    points: FloatArray, view: tuple[float, float] = SOLID_VIEW
) -> tuple[FloatArray, FloatArray]:
    """Screen coordinates (n, 2) and depth towards the viewer (n,) of (n, 3) points [mm].

    The cam is turned by the azimuth about its axis (z), then seen from the
    elevation above the xy plane: u = x', v = y' sin e + z cos e, depth
    = −y' cos e + z sin e (a parallel projection; larger depth is nearer).
    """
    az, el = view
    p = np.asarray(points, dtype=float)
    x = p[:, 0] * math.cos(az) - p[:, 1] * math.sin(az)
    y = p[:, 0] * math.sin(az) + p[:, 1] * math.cos(az)
    z = p[:, 2]
    screen = np.column_stack((x, y * math.sin(el) + z * math.cos(el)))
    return screen, -y * math.cos(el) + z * math.sin(el)


def _outline(points: FloatArray, n: int) -> FloatArray:
    """``points`` (a closed ring) thinned to about ``n`` points, counter-clockwise."""
    ring = np.asarray(points, dtype=float)
    if len(ring) > n:
        ring = ring[np.unique(np.linspace(0, len(ring) - 1, n).round().astype(int))]
    area = 0.5 * float(np.sum(ring[:, 0] * np.roll(ring[:, 1], -1) - np.roll(ring[:, 0], -1) * ring[:, 1]))
    return ring if area > 0.0 else ring[::-1]


def solid_faces(analysis: Analysis) -> dict[str, object]:
    """The visible faces of the plate in :func:`project_oblique`'s view.

    Returns a mapping with ``walls`` (list of (4, 2) screen quads, farthest
    first), ``shade`` (their brightness 0–1), ``top`` (the top face's outer
    ring (n, 2)) and ``hole`` (its bore ring, or None), all in screen mm.
    """
    spec = analysis.design.cam
    t = spec.thickness
    outer = _outline(part_outline(analysis), _SOLID_POINTS)
    rings = [(outer, 1.0)]
    hole = None
    if spec.bore > 0.0:
        hole = _outline(bore_outline(spec.bore, spec.keyway_width, spec.keyway_depth)[:-1], _SOLID_POINTS)
        rings.append((hole, -1.0))  # the bore's walls face into the hole
    light = np.array([-0.4, -0.5, 0.77])
    az = SOLID_VIEW[0]
    quads, shade, depth = [], [], []
    for ring, outward in rings:
        a, b = ring, np.roll(ring, -1, axis=0)
        d = b - a
        normal = outward * np.column_stack((d[:, 1], -d[:, 0]))
        normal /= np.maximum(np.hypot(*normal.T), 1e-300)[:, None]
        ny_view = normal[:, 0] * math.sin(az) + normal[:, 1] * math.cos(az)
        visible = ny_view < 0.0  # facing the viewer, who stands on −y' above the plane
        for i in np.flatnonzero(visible):
            corners = np.array([[*a[i], 0.0], [*b[i], 0.0], [*b[i], t], [*a[i], t]])
            screen, dep = project_oblique(corners)
            quads.append(screen)
            nx, ny = normal[i]
            c, s = math.cos(az), math.sin(az)
            turned = np.array([nx * c - ny * s, nx * s + ny * c, 0.0])
            shade.append(0.45 + 0.5 * max(0.0, float(turned @ light)))
            depth.append(float(dep.mean()))
    order = np.argsort(depth, kind="stable")
    top_ring = project_oblique(np.column_stack((outer, np.full(len(outer), t))))[0]
    hole_ring = None if hole is None else project_oblique(np.column_stack((hole, np.full(len(hole), t))))[0]
    return {
        "walls": [quads[i] for i in order],
        "shade": [shade[i] for i in order],
        "top": top_ring,
        "hole": hole_ring,
    }


def solid_plot(analysis: Analysis) -> Plot:
    """A small shaded view of the plate (profile extruded by the thickness, less the bore)."""
    faces = solid_faces(analysis)
    fig = figure((4.2, 3.4), left=0.1, right=0.1, top=0.1, bottom=0.1)
    ax = fig.add_axes((0.02, 0.02, 0.96, 0.96))
    walls = faces["walls"]
    assert isinstance(walls, list)
    colors = [(0.55 * s, 0.65 * s, 0.78 * s) for s in faces["shade"]]  # type: ignore[attr-defined]
    ax.add_collection(
        PolyCollection(walls, facecolors=colors, edgecolors=colors, linewidths=0.3), autolim=False
    )
    top = np.asarray(faces["top"])
    rings = [top]
    codes = [MplPath.MOVETO, *[MplPath.LINETO] * (len(top) - 1)]
    hole = faces["hole"]
    verts = [top]
    if hole is not None:
        hole = np.asarray(hole)[::-1]  # the opposite winding cuts the hole
        verts.append(hole)
        codes += [MplPath.MOVETO, *[MplPath.LINETO] * (len(hole) - 1)]
        rings.append(hole)
    shape(ax, PathPatch(MplPath(np.vstack(verts), codes), facecolor="#c9d8ea", edgecolor="#1f3b57",
                           linewidth=0.8))  # fmt: skip
    every = np.vstack([top, *walls]) if walls else top
    lo, hi = every.min(axis=0), every.max(axis=0)
    pad = 0.04 * float((hi - lo).max())
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_axis_off()
    spec = analysis.design.cam
    return Plot(
        key="solid",
        title="The plate",
        caption=f"The solid written to the mesh files: the profile extruded {spec.thickness:g} mm"
        + (f", bore ⌀{spec.bore:g} mm" if spec.bore > 0.0 else "")
        + (f" with a {spec.keyway_width:g} mm keyway" if spec.bore > 0.0 and spec.keyway_width > 0.0 else "")
        + "; seen from above at 35°.",
        svg=svg(fig),
    )
