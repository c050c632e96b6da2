"""The figures of one design: the cam drawing, motion, pressure angle, curvature and dynamics.

Angles are plotted in degrees, lengths in mm, forces in N, torques in N·mm
and stresses in MPa; an oscillating follower's motion is its arm angle ψ in
degrees. Labels follow the follower type (roller-centre path, face-centre
trace, face trace of an arm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.patches import Circle, FancyArrowPatch, Polygon

from camcad._plots._base import (
    COLORS,
    FONT,
    LIMIT,
    Plot,
    closed,
    figure,
    plan_axes,
    shape,
    svg,
    trace_name,
)
from camcad._plots.chart import HLine, Panel, Series, line_chart
from camcad._typing import FloatArray
from camcad.geometry.envelope import to_cam

if TYPE_CHECKING:
    from camcad.analysis import Analysis
    from camcad.geometry.cam import Cam
    from camcad.geometry.families import Pocket

__all__ = [
    "CURVATURE_CLIP",
    "FOLLOWER_ANGLES_DEG",
    "FollowerDrawing",
    "bore_outline",
    "curvature_plot",
    "dynamics_plot",
    "follower_drawings",
    "motion_plot",
    "pressure_plot",
    "profile_plot",
]

CURVATURE_CLIP = 5.0
"""Radii of curvature are plotted within ± this many base radii (ρ → ±∞ on straight bits)."""

FOLLOWER_ANGLES_DEG = (0.0, 90.0, 180.0, 270.0)
"""Cam angles at which the follower is drawn on the profile plot [deg]."""

_FLAT_ALPHA_DEG = 1e-9  # a pressure angle below this everywhere is identically zero (face ⟂ slide)


def _segments(analysis: Analysis) -> tuple[list[float], list[tuple[float, float, str]]]:
    """Segment boundaries [deg] (without 0) and (start, end, kind) of each segment [deg]."""
    starts = [math.degrees(b) for b in analysis.cam.program.segment_bounds]
    edges = [*starts, 360.0]
    names = [seg.kind.value for seg in analysis.cam.program.segments]
    return starts[1:], [(a, b, n) for a, b, n in zip(edges[:-1], edges[1:], names, strict=False)]


def _curve(phi_deg: FloatArray, values: object, color: str, *, width: float = 1.5, label: str = "") -> Series:
    x, y = closed(np.asarray(phi_deg, dtype=float), np.asarray(values, dtype=float))
    return Series(x=x, y=y, color=color, width=width, label=label)


def motion_plot(analysis: Analysis) -> Plot:
    """s, v, a, j (or ψ and its derivatives for an arm) against the cam angle."""
    m = analysis.motion
    phi = np.degrees(m.phi)
    labels = analysis.cam.follower_spec.kind.lift.labels  # an arm's lift is its swing ψ, in degrees
    values = (m.s, m.v, m.a, m.j)
    blends = analysis.cam.program.blend_points  # joints solved to match their neighbours (issue 16)
    blend_deg = np.degrees([b.phi for b in blends])
    smooth = min((b.continuity for b in blends), default=3)
    panels = [
        Panel(
            ylabel=label,
            series=[_curve(phi, v, COLORS[k])],
            height=118.0,
            ticks_at=blend_deg if len(blends) else None,
            ticks_label=f"blend points (C{smooth} or better)" if len(blends) and k == 0 else "",
            legend=bool(len(blends)) and k == 0,
        )
        for k, (label, v) in enumerate(zip(labels, values, strict=True))
    ]
    bounds_deg, segments = _segments(analysis)
    what = analysis.cam.follower_spec.kind.lift.title
    blend_note = (
        f"; ticks along the bottom mark the {len(blends)} blend points, where the laws meet continuous "
        + ("to the jerk" if smooth >= 3 else "to the acceleration" if smooth == 2 else f"to order {smooth}")
        if len(blends)
        else ""
    )
    return Plot(
        key="motion",
        title="Follower motion",
        caption=f"{what} and its derivatives with respect to the cam angle; "
        f"dotted lines mark segment boundaries{blend_note}.",
        svg=line_chart(panels, bounds_deg=bounds_deg, segments=segments, title="Follower motion"),
    )


def pressure_plot(analysis: Analysis) -> Plot:
    """The pressure angle with its limit; a note instead where it is identically zero."""
    geo = analysis.geometry
    limit = math.degrees(geo.max_pressure_angle)
    phi, alpha = closed(np.degrees(geo.phi), np.degrees(geo.pressure_angle))
    if float(np.abs(alpha).max()) < _FLAT_ALPHA_DEG:
        return Plot(
            key="pressure",
            title="Pressure angle",
            caption="0° at every cam angle, so there is nothing to plot: the flat face is square to "
            "the slide, the contact normal is always along the direction the follower moves, and the "
            "cam pushes it with no side load from the contact. Watch the face width and the "
            "curvature instead.",
        )
    series = [Series(x=phi, y=alpha, color=COLORS[0], label="pressure angle α")]
    over = np.abs(alpha) > limit
    if over.any():
        series.append(Series(x=phi, y=np.where(over, alpha, np.nan), color=LIMIT["color"], width=3.0,
                             label="over the limit"))  # fmt: skip
    top = max(limit, float(np.abs(alpha).max())) * 1.15
    panel = Panel(
        ylabel="pressure angle α [°]",
        series=series,
        lines=[HLine(y=limit, label=f"limit ±{limit:g}°"), HLine(y=-limit)],
        ylim=(-top, top),
        height=220.0,
        legend=True,
    )
    bounds_deg, _ = _segments(analysis)
    i = int(np.argmax(np.abs(alpha)))
    return Plot(
        key="pressure",
        title="Pressure angle",
        caption=f"Largest |α| on the plotted samples {abs(alpha[i]):.2f}° at φ = {phi[i]:.1f}°; "
        f"limit ±{limit:g}°.",
        svg=line_chart([panel], bounds_deg=bounds_deg, title="Pressure angle"),
    )


def curvature_plot(analysis: Analysis) -> Plot:
    """Signed radius of curvature of the profile (and of the roller-centre path), clipped."""
    geo, cam = analysis.geometry, analysis.cam
    clip = CURVATURE_CLIP * cam.base_radius
    phi = np.degrees(geo.phi)
    curves = [(geo.profile, "cam profile")]
    circle = cam.has_pitch_curve  # a flat face's reference trace has no curvature limit of its own
    words = cam.follower.words
    if circle:
        curves.insert(0, (geo.pitch, trace_name(analysis)))
    series = []
    for k, (curve, label) in enumerate(curves):
        rho = np.asarray(curve.rho, dtype=float)
        shown = np.where(np.abs(rho) <= clip, rho, np.nan)  # break the line where ρ leaves the window
        series.append(_curve(phi, shown, COLORS[k if circle else 1], label=f"ρ of the {label}"))
    lines = []
    if circle:
        lines.append(HLine(y=cam.roller_radius, label=f"{words.radius} {cam.roller_radius:g} mm"))
    elif analysis.design.min_curvature_radius > 0.0:
        lines.append(HLine(y=analysis.design.min_curvature_radius, label="smallest allowed ρ"))
    panel = Panel(ylabel="ρ [mm]  (+ convex)", series=series, lines=lines, ylim=(-clip * 1.02, clip * 1.02),
                  height=220.0, legend=True)  # fmt: skip
    bounds_deg, _ = _segments(analysis)
    why = words.why_rho
    return Plot(
        key="curvature",
        title="Radius of curvature",
        caption=f"Signed radius of curvature, clipped to ±{CURVATURE_CLIP:g} base radii (±{clip:g} mm; "
        f"gaps are nearly straight stretches); {why}.",
        svg=line_chart([panel], bounds_deg=bounds_deg, title="Radius of curvature"),
    )


def dynamics_plot(analysis: Analysis) -> Plot:
    """Contact force, input torque and Hertz stress against the cam angle."""
    dyn, spec = analysis.dynamics, analysis.design.dynamics
    phi = np.degrees(np.asarray(dyn.phi))
    force_lines = [] if spec.min_contact_force <= 0.0 else [
        HLine(y=spec.min_contact_force, label=f"minimum {spec.min_contact_force:g} N")
    ]  # fmt: skip
    stress_lines = [] if spec.allowable_stress is None else [
        HLine(y=spec.allowable_stress, label=f"allowable {spec.allowable_stress:g} MPa")
    ]  # fmt: skip
    # a conjugate pair: the second plate's own force and stress (its roller, its dynamics), same code
    later = [r.dynamics for r in analysis.parts[1:]]  # every further part (a pair's second plate), same code
    one = "plate 1" if later else ""
    force = [_curve(phi, dyn.contact_force, COLORS[4], label=one)]
    stress = [_curve(phi, dyn.hertz_stress, COLORS[6], label=one)]
    for i, dyn2 in enumerate(later, start=2):
        phi2 = np.degrees(np.asarray(dyn2.phi))
        force.append(_curve(phi2, dyn2.contact_force, COLORS[1], label=f"plate {i}"))
        stress.append(_curve(phi2, dyn2.hertz_stress, COLORS[1], label=f"plate {i}"))
    panels = [
        Panel(ylabel="contact force\nF [N]", series=force,
              lines=force_lines, legend=bool(force_lines) or bool(later), height=130.0),
        Panel(ylabel="input torque\nT [N·mm]", series=[_curve(phi, dyn.torque, COLORS[5])], height=130.0),
        Panel(ylabel="Hertz stress\nσ [MPa]", series=stress,
              lines=stress_lines, legend=bool(stress_lines) or bool(later), height=130.0),
    ]  # fmt: skip
    bounds_deg, _ = _segments(analysis)
    return Plot(
        key="dynamics",
        title="Dynamics",
        caption="Contact force between follower and cam (below zero the follower leaves the cam), "
        "input torque on the camshaft and peak Hertz contact stress.",
        svg=line_chart(panels, bounds_deg=bounds_deg, title="Dynamics"),
    )


def bore_outline(bore: float, width: float, depth: float) -> FloatArray:
    """The bore of diameter ``bore`` with the keyway on its +y side, as a closed (n, 2) polygon [mm]."""
    r = 0.5 * bore
    if width <= 0.0 or depth <= 0.0 or width >= bore:
        t = np.linspace(0.0, 2.0 * math.pi, 181)
        return np.column_stack((r * np.cos(t), r * np.sin(t)))
    delta = math.asin(width / (2.0 * r))
    t = np.linspace(0.5 * math.pi + delta, 2.5 * math.pi - delta, 181)
    arc = np.column_stack((r * np.cos(t), r * np.sin(t)))
    top = np.array([[0.5 * width, r + depth], [-0.5 * width, r + depth]])
    return np.vstack((arc, top))


@dataclass(frozen=True, slots=True, kw_only=True)
class FollowerDrawing:
    """The follower at one cam angle, seen in the cam frame (kinematic inversion) [mm].

    ``body`` (roller, face), ``links`` (stem, arm) and ``axes`` (construction
    lines) are (k, 2) polylines, ``marks`` (m, 2) points; the label goes at
    ``label_at``, aligned ``ha``/``va`` so it never covers the follower.
    """

    phi_deg: float
    body: tuple[FloatArray, ...]
    links: tuple[FloatArray, ...]
    axes: tuple[FloatArray, ...]
    marks: FloatArray
    label_at: FloatArray
    ha: str
    va: str


def follower_drawings(analysis: Analysis, reach: float, *, cam: Cam | None = None) -> list[FollowerDrawing]:
    """The follower at :data:`FOLLOWER_ANGLES_DEG` in the cam frame, from its own sketch.

    The follower module draws itself (:meth:`Follower.sketch`: roller or face,
    stem or arm, pivot); ``reach`` [mm] scales stems and places the labels.
    ``cam``: another plate of the design (a conjugate pair's second plate,
    whose follower module is the tied second roller); default the cam.
    """
    cam = analysis.cam if cam is None else cam
    phis = np.radians(np.asarray(FOLLOWER_ANGLES_DEG))
    out = []
    for phi, sketch in zip(phis, cam.follower.sketch(cam.motion(phis), size=reach), strict=True):

        def seen(points: np.ndarray, phi: float = phi) -> np.ndarray:
            return cam.seen_from_cam(np.full(len(points), phi), np.asarray(points, dtype=float))

        tip = seen(sketch.tip[None, :])[0]
        dx, dy = to_cam(cam.frame_angle(np.array([phi])), sketch.heading[None, :], cam.sigma)[0]
        out.append(
            FollowerDrawing(
                phi_deg=math.degrees(phi),
                body=tuple(seen(p) for p in sketch.body),
                links=tuple(seen(p) for p in sketch.links),
                axes=tuple(seen(p) for p in sketch.axes),
                marks=seen(sketch.marks) if len(sketch.marks) else np.empty((0, 2)),
                label_at=tip + 0.03 * reach * np.array([dx, dy]),
                ha="center" if abs(dx) < 0.4 else ("left" if dx > 0 else "right"),
                va="center" if abs(dy) < 0.4 else ("bottom" if dy > 0 else "top"),
            )
        )
    return out


def _draw_followers(ax: Axes, analysis: Analysis, reach: float, *, cam: Cam | None = None) -> float:
    """Draw :func:`follower_drawings`; returns the largest distance of a drawn point from the axis [mm]."""
    far = reach
    for k, drawing in enumerate(follower_drawings(analysis, reach, cam=cam)):
        color = COLORS[(k + 1) % len(COLORS)]
        for xy in drawing.body:
            ax.plot(xy[:, 0], xy[:, 1], color=color, linewidth=1.4 if len(xy) > 2 else 2.4)
            far = max(far, float(np.hypot(*xy.T).max()))
        for xy in drawing.links:
            ax.plot(xy[:, 0], xy[:, 1], color=color, linewidth=2.0)
            far = max(far, float(np.hypot(*xy.T).max()))
        for xy in drawing.axes:
            ax.plot(xy[:, 0], xy[:, 1], color=color, linewidth=0.6, linestyle="-.", alpha=0.7)
        if len(drawing.marks):
            ax.plot(*drawing.marks.T, linestyle="none", marker="+", color=color, markersize=6)
        far = max(far, float(np.hypot(*drawing.label_at)))
        ax.text(*drawing.label_at, f"φ = {drawing.phi_deg:g}°", color=color, fontsize=FONT - 1,
                ha=drawing.ha, va=drawing.va)  # fmt: skip
    return far


SECOND_PLATE = "#b5651d"
"""Outline colour of a conjugate pair's second plate."""


def _draw_pocket(ax: Axes, analysis: Analysis, pocket: Pocket) -> None:
    """A part with a pocket seen from its face: the blank, the pocket (white) between its flanks."""
    cam, phi = analysis.cam, analysis.geometry.phi
    inner, outer = (np.asarray(cam.offset_curve(phi, flank.offset).point) for flank in pocket.flanks)
    shape(
        ax, Circle((0.0, 0.0), pocket.outer_radius, facecolor="#dbe6f1", edgecolor="#1f3b57", linewidth=1.2)
    )
    shape(ax, Polygon(outer, closed=True, facecolor="white", edgecolor="#1f3b57", linewidth=1.5))
    shape(ax, Polygon(inner, closed=True, facecolor="#dbe6f1", edgecolor="#1f3b57", linewidth=1.5))
    ax.plot([], [], color="#1f3b57", linewidth=1.5, label=f"groove flanks ({pocket.width:.3f} mm wide)")


def family_caption(analysis: Analysis) -> str:
    """What the cam drawing adds for the cam's family (a groove, a pair's second plate), as a sentence."""
    return analysis.family.caption([r.part for r in analysis.parts])


def further_plates(analysis: Analysis) -> list[Cam]:
    """The cams of the family's further plates to draw behind the first (a pair's second plate)."""
    return [r.part.cam for r in analysis.parts[1:] if r.part.made and r.part.pocket is None]


def profile_plot(analysis: Analysis, *, size: float = 6.0) -> Plot:
    """The cam to scale at φ = 0 with its follower drawn at four angles, the bore and the rotation."""
    cam, geo, spec = analysis.cam, analysis.geometry, analysis.design.cam
    profile = np.asarray(geo.profile.point)
    pitch = np.asarray(geo.pitch.point)
    reach = float(max(np.hypot(*pitch.T).max() + cam.roller_radius, np.hypot(*profile.T).max()))
    pocket = analysis.parts[0].part.pocket
    if pocket is not None:
        reach = max(reach, pocket.outer_radius)
    fig = figure((size, size), left=0.7, bottom=0.5, top=0.15, right=0.15)
    ax = fig.subplots()
    bar = analysis.parts[0].part.bar
    if pocket is not None:
        _draw_pocket(ax, analysis, pocket)
    elif bar is not None:  # a linear cam: the bar under its edge
        x1 = bar.x0 + bar.length
        outline = np.vstack((profile, [[x1, bar.bottom], [bar.x0, bar.bottom]]))
        shape(ax, Polygon(outline, closed=True, facecolor="#dbe6f1", edgecolor="#1f3b57", linewidth=1.5))
        ax.plot([], [], color="#1f3b57", linewidth=1.5, label="bar (its top edge is the cam)")
    else:
        shape(ax, Polygon(profile, closed=True, facecolor="#dbe6f1", edgecolor="#1f3b57", linewidth=1.5))
        ax.plot([], [], color="#1f3b57", linewidth=1.5, label="cam profile")
    further = further_plates(analysis)
    for plate in further:
        second = np.asarray(plate.profile(geo.phi).point)
        reach = max(reach, float(np.hypot(*second.T).max()))
        shape(ax, Polygon(second, closed=True, fill=False, edgecolor=SECOND_PLATE, linewidth=1.5))
        ax.plot([], [], color=SECOND_PLATE, linewidth=1.5, label="second plate (behind)")
    if spec.bore > 0.0:
        hole = bore_outline(spec.bore, spec.keyway_width, spec.keyway_depth)
        shape(ax, Polygon(hole, closed=True, facecolor="white", edgecolor="#1f3b57", linewidth=1.1))
        ax.plot([], [], color="#1f3b57", linewidth=1.1, label=f"bore ⌀{spec.bore:g} mm")
    closing = pitch[:1] if cam.closed else pitch[:0]  # a linear cam's pitch line runs open
    ax.plot(*np.vstack((pitch, closing)).T, color="#d9731a", linewidth=1.0, linestyle="--",
            label=trace_name(analysis))  # fmt: skip
    if cam.closed:
        shape(
            ax,
            Circle(
                (0.0, 0.0), cam.base_radius, fill=False, edgecolor="#7f7f7f", linestyle=":", linewidth=1.0
            ),
        )
        ax.plot([], [], color="#7f7f7f", linestyle=":", label=f"base circle r = {cam.base_radius:g} mm")
    else:
        ax.plot(profile[[0, -1], 0], [cam.base_radius] * 2, color="#7f7f7f", linestyle=":", linewidth=1.0,
                label=f"base line y = {cam.base_radius:g} mm")  # fmt: skip
    tick = 0.04 * reach
    ax.plot([-tick, tick], [0.0, 0.0], color="black", linewidth=0.8)
    ax.plot([0.0, 0.0], [-tick, tick], color="black", linewidth=0.8)
    far = _draw_followers(ax, analysis, reach)
    for plate in further:
        far = max(far, _draw_followers(ax, analysis, reach, cam=plate))
    if bar is not None:  # the bar slides towards −x: an arrow below it
        y = bar.bottom - 0.08 * reach
        shape(ax, FancyArrowPatch((bar.x0 + 0.6 * bar.length, y), (bar.x0 + 0.4 * bar.length, y),
                                  arrowstyle="-|>", mutation_scale=12, color="#333333"))  # fmt: skip
        ax.text(bar.x0 + 0.5 * bar.length, y - 0.04 * reach, "v", fontsize=FONT + 2, ha="center", va="top")
        plan_axes(ax, far)
        ax.autoscale(tight=False)  # the bar's own extent, not a square round an axis
        ax.margins(0.08)
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(fontsize=FONT - 1, loc="upper right", framealpha=0.9)
        return Plot(
            key="profile",
            title="Cam profile (to scale)",
            caption=f"Bar frame at φ = 0 (follower on +y, bar sliding towards −x): "
            f"{cam.follower.describe()}, drawn where it meets the bar at φ = "
            + ", ".join(f"{a:g}°" for a in FOLLOWER_ANGLES_DEG)
            + "."
            + family_caption(analysis),
            svg=svg(fig),
        )
    # direction of rotation, as an arc just outside the profile
    sign = 1.0 if cam.rotation.value == "ccw" else -1.0
    r_arrow = 1.08 * float(np.hypot(*profile.T).max())
    a0, a1 = math.radians(225.0 - 12.0 * sign), math.radians(225.0 + 12.0 * sign)
    shape(
        ax,
        FancyArrowPatch(
            (r_arrow * math.cos(a0), r_arrow * math.sin(a0)),
            (r_arrow * math.cos(a1), r_arrow * math.sin(a1)),
            connectionstyle=f"arc3,rad={0.1 * sign:g}", arrowstyle="-|>", mutation_scale=12, color="#333333",
        ),
    )  # fmt: skip
    corner = 1.16 * r_arrow * math.cos(math.radians(225.0))
    ax.text(corner, corner, "ω", fontsize=FONT + 2, ha="center", va="center")
    plan_axes(ax, far + 0.3 * reach)  # room for the labels beyond the stem tips
    ax.legend(fontsize=FONT - 1, loc="lower right", framealpha=0.9)
    return Plot(
        key="profile",
        title="Cam profile (to scale)",
        caption=f"Cam frame at φ = 0 (follower on +y, cam turning {cam.rotation.value}): "
        f"{cam.follower.describe()}, drawn where it meets the cam at φ = "
        + ", ".join(f"{a:g}°" for a in FOLLOWER_ANGLES_DEG)
        + " (kinematic inversion)."
        + family_caption(analysis),
        svg=svg(fig),
    )
