"""The report's figures, drawn off-screen with matplotlib and returned as PNG bytes.

Only :class:`matplotlib.figure.Figure` with an explicit
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg` is used: never
``pyplot`` and never ``rcParams``, so drawing needs no display, leaves the
global matplotlib state alone and is safe to run in threads.

Angles are plotted in degrees, lengths in mm, forces in N, torques in N·mm
and stresses in MPa.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle, FancyArrowPatch, Polygon

from camcad._typing import FloatArray
from camcad.geometry.envelope import to_cam

if TYPE_CHECKING:
    from camcad.analysis import Analysis

__all__ = [
    "CURVATURE_CLIP",
    "FOLLOWER_ANGLES_DEG",
    "Plot",
    "compare_plots",
    "plot_text",
    "report_plots",
]

CURVATURE_CLIP = 5.0
"""Radii of curvature are plotted within ± this many base radii (ρ → ±∞ on straight bits)."""

FOLLOWER_ANGLES_DEG = (0.0, 90.0, 180.0, 270.0)
"""Cam angles at which the follower is drawn on the profile plot [deg]."""

_DPI = 110
_WIDE = (7.2, 4.4)  # inches
_LIMIT = {"color": "#c0392b", "linestyle": "--", "linewidth": 1.1}
_BOUND = {"color": "#8e8e8e", "linestyle": ":", "linewidth": 0.9}
_ZERO = {"color": "#444444", "linewidth": 0.6}
_COLORS = ("#1f5f9e", "#d9731a", "#2e8b57", "#a23b72", "#6c5b7b", "#8c6d1f", "#3b8ea5", "#b03a2e")


@dataclass(frozen=True, slots=True, kw_only=True)
class Plot:
    """One rendered figure: a short title, a caption and the PNG bytes."""

    key: str  # stable identifier, e.g. "motion"
    title: str
    caption: str
    png: bytes


# ---------------------------------------------------------------------------
# helpers


def _plan_axes(ax: Axes, lim: float) -> None:
    """A to-scale plan view of the cam frame, ±``lim`` mm on both axes."""
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]", fontsize=9)
    ax.set_ylabel("y [mm]", fontsize=9)
    ax.tick_params(labelsize=8)
    ax.grid(True, color="#eeeeee", linewidth=0.6)


def _figure(size: tuple[float, float] = _WIDE) -> Figure:
    """A new off-screen figure with the Agg canvas attached (no pyplot)."""
    fig = Figure(figsize=size, dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _png(fig: Figure) -> bytes:
    """The figure as PNG bytes, without a timestamp so output is reproducible."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=_DPI, metadata={"Software": None})
    return buf.getvalue()


def _style(ax: Axes, ylabel: str, *, xlabel: bool = True) -> None:
    ax.set_ylabel(ylabel, fontsize=9)
    if xlabel:
        ax.set_xlabel("cam angle φ [°]", fontsize=9)
    ax.set_xlim(0.0, 360.0)
    ax.set_xticks(np.arange(0.0, 361.0, 45.0))
    ax.tick_params(labelsize=8)
    ax.grid(True, color="#e3e3e3", linewidth=0.6)
    ax.set_axisbelow(True)


def _bounds(ax: Axes, analysis: Analysis) -> None:
    """Vertical lines at the segment boundaries."""
    for start in analysis.cam.program.segment_bounds[1:]:
        ax.axvline(math.degrees(start), **_BOUND)


def _closed(phi_deg: FloatArray, *values: FloatArray) -> tuple[FloatArray, ...]:
    """Append the 360° sample (a copy of the 0° one) so curves span the full turn."""
    if phi_deg.size and phi_deg[0] == 0.0 and phi_deg[-1] < 360.0:
        return (np.append(phi_deg, 360.0), *(np.append(v, v[0]) for v in values))
    return (phi_deg, *values)


# ---------------------------------------------------------------------------
# single-design figures


def _motion_plot(analysis: Analysis) -> Plot:
    m = analysis.motion
    fig = _figure((7.2, 7.0))
    axes = fig.subplots(4, 1, sharex=True)
    series = (
        (m.s, "s [mm]", "displacement"),
        (m.v, "v = ds/dφ [mm/rad]", "velocity"),
        (m.a, "a = d²s/dφ² [mm/rad²]", "acceleration"),
        (m.j, "j = d³s/dφ³ [mm/rad³]", "jerk"),
    )
    if analysis.cam.follower.kind.oscillating:  # an arm's lift is its swing ψ, in degrees
        series = (
            (m.s, "ψ [°]", "arm angle"),
            (m.v, "ψ′ = dψ/dφ [°/rad]", "angular velocity"),
            (m.a, "ψ″ = d²ψ/dφ² [°/rad²]", "angular acceleration"),
            (m.j, "ψ‴ = d³ψ/dφ³ [°/rad³]", "angular jerk"),
        )
    for k, (ax, (values, label, _)) in enumerate(zip(axes, series, strict=True)):
        x, y = _closed(np.degrees(m.phi), np.asarray(values))
        ax.plot(x, y, color=_COLORS[k], linewidth=1.3)
        ax.axhline(0.0, **_ZERO)
        _bounds(ax, analysis)
        _style(ax, label, xlabel=k == 3)
    bounds = [*analysis.cam.program.segment_bounds, 2.0 * math.pi]
    for seg, lo, hi in zip(analysis.cam.program.segments, bounds[:-1], bounds[1:], strict=False):
        axes[0].text(
            math.degrees(0.5 * (lo + hi)),
            1.02,
            seg.kind.value,
            transform=axes[0].get_xaxis_transform(),
            ha="center",
            va="bottom",
            fontsize=8,
            color="#555555",
        )
    return Plot(
        key="motion",
        title="Follower motion",
        caption="Displacement and its derivatives with respect to the cam angle; "
        "dotted lines mark segment boundaries.",
        png=_png(fig),
    )


def _pressure_plot(analysis: Analysis) -> Plot:
    geo = analysis.geometry
    limit = math.degrees(geo.max_pressure_angle)
    x, alpha = _closed(np.degrees(geo.phi), np.degrees(geo.pressure_angle))
    fig = _figure()
    ax = fig.subplots()
    over = np.abs(alpha) > limit
    ax.plot(x, alpha, color=_COLORS[0], linewidth=1.4, label="pressure angle α")
    if over.any():
        ax.plot(
            x, np.where(over, alpha, np.nan), color=_LIMIT["color"], linewidth=2.2, label="over the limit"
        )
    ax.axhline(limit, label=f"limit ±{limit:g}°", **_LIMIT)
    ax.axhline(-limit, **_LIMIT)
    ax.axhline(0.0, **_ZERO)
    _bounds(ax, analysis)
    _style(ax, "α [°]")
    top = max(limit, float(np.abs(alpha).max())) * 1.15
    ax.set_ylim(-top, top)
    ax.legend(fontsize=8, loc="upper right")
    i = int(np.argmax(np.abs(alpha)))
    return Plot(
        key="pressure",
        title="Pressure angle",
        caption=f"Largest |α| = {abs(alpha[i]):.2f}° at φ = {x[i]:.1f}°; limit ±{limit:g}°.",
        png=_png(fig),
    )


def _curvature_plot(analysis: Analysis) -> Plot:
    geo, cam = analysis.geometry, analysis.cam
    clip = CURVATURE_CLIP * cam.base_radius
    fig = _figure()
    ax = fig.subplots()
    phi_deg = np.degrees(geo.phi)
    for k, (curve, label) in enumerate(((geo.pitch, "pitch curve"), (geo.profile, "cam profile"))):
        x, rho = _closed(phi_deg, np.asarray(curve.rho, dtype=float))
        shown = np.where(np.abs(rho) <= clip, rho, np.nan)  # break the line where ρ leaves the window
        ax.plot(x, shown, color=_COLORS[k], linewidth=1.3, label=f"ρ {label}")
    if cam.is_roller:
        ax.axhline(
            cam.roller_radius,
            label=f"roller radius {cam.roller_radius:g} mm (pitch ρ must stay above)",
            **_LIMIT,
        )
    elif analysis.design.min_curvature_radius > 0.0:
        ax.axhline(analysis.design.min_curvature_radius, label="smallest allowed ρ", **_LIMIT)
    ax.axhline(0.0, **_ZERO)
    _bounds(ax, analysis)
    _style(ax, "ρ [mm]  (+ convex, − concave)")
    ax.set_ylim(-clip * 1.02, clip * 1.02)
    ax.legend(fontsize=8, loc="lower right")
    return Plot(
        key="curvature",
        title="Radius of curvature",
        caption=f"Signed radius of curvature, clipped to ±{CURVATURE_CLIP:g} base radii "
        f"(±{clip:g} mm); gaps are nearly straight stretches where |ρ| is larger.",
        png=_png(fig),
    )


def _dynamics_plot(analysis: Analysis) -> Plot:
    dyn, spec = analysis.dynamics, analysis.design.dynamics
    phi_deg = np.degrees(np.asarray(dyn.phi))
    fig = _figure((7.2, 6.0))
    axes = fig.subplots(3, 1, sharex=True)
    series = (
        (dyn.contact_force, "contact force F [N]"),
        (dyn.torque, "input torque T [N·mm]"),
        (dyn.hertz_stress, "Hertz stress σ [MPa]"),
    )
    for k, (ax, (values, label)) in enumerate(zip(axes, series, strict=True)):
        x, y = _closed(phi_deg, np.asarray(values, dtype=float))
        ax.plot(x, y, color=_COLORS[k + 4], linewidth=1.3)
        ax.axhline(0.0, **_ZERO)
        _bounds(ax, analysis)
        _style(ax, label, xlabel=k == 2)
    if spec.min_contact_force > 0.0:
        axes[0].axhline(spec.min_contact_force, label=f"minimum {spec.min_contact_force:g} N", **_LIMIT)
        axes[0].legend(fontsize=8, loc="upper right")
    if spec.allowable_stress is not None:
        axes[2].axhline(spec.allowable_stress, label=f"allowable {spec.allowable_stress:g} MPa", **_LIMIT)
        axes[2].legend(fontsize=8, loc="upper right")
    return Plot(
        key="dynamics",
        title="Dynamics",
        caption="Contact force between follower and cam, input torque on the camshaft "
        "and peak Hertz contact stress.",
        png=_png(fig),
    )


def _bore_outline(bore: float, width: float, depth: float) -> FloatArray:
    """The bore of diameter ``bore`` with the keyway on its +y side, as a closed (n, 2) polygon."""
    r = 0.5 * bore
    if width <= 0.0 or depth <= 0.0 or width >= bore:
        t = np.linspace(0.0, 2.0 * math.pi, 181)
        return np.column_stack((r * np.cos(t), r * np.sin(t)))
    delta = math.asin(width / (2.0 * r))
    t = np.linspace(0.5 * math.pi + delta, 2.5 * math.pi - delta, 181)
    arc = np.column_stack((r * np.cos(t), r * np.sin(t)))
    top = np.array([[0.5 * width, r + depth], [-0.5 * width, r + depth]])
    return np.vstack((arc, top))


def _draw_followers(ax: Axes, analysis: Analysis, reach: float) -> float:
    """Draw the follower at :data:`FOLLOWER_ANGLES_DEG` in the cam frame (kinematic inversion).

    The follower module draws itself (:meth:`Follower.sketch`): roller or face,
    stem or arm, pivot. Returns the largest distance of a drawn point from the
    cam centre [mm].
    """
    cam = analysis.cam
    phis = np.radians(np.asarray(FOLLOWER_ANGLES_DEG))
    sketches = cam.kinematics.sketch(cam.motion(phis), size=reach)
    far = reach
    for k, (phi, sketch) in enumerate(zip(phis, sketches, strict=True)):
        color = _COLORS[(k + 1) % len(_COLORS)]

        def seen(points: np.ndarray, phi: float = phi) -> np.ndarray:
            return to_cam(np.full(len(points), phi), np.asarray(points, dtype=float), cam.sigma)

        for part in sketch.body:
            xy = seen(part)
            ax.plot(xy[:, 0], xy[:, 1], color=color, linewidth=1.4 if len(part) > 2 else 2.4)
            far = max(far, float(np.hypot(*xy.T).max()))
        for part in sketch.links:
            xy = seen(part)
            ax.plot(xy[:, 0], xy[:, 1], color=color, linewidth=2.0)
            far = max(far, float(np.hypot(*xy.T).max()))
        for part in sketch.axes:
            xy = seen(part)
            ax.plot(xy[:, 0], xy[:, 1], color=color, linewidth=0.6, linestyle="-.", alpha=0.7)
        if len(sketch.marks):
            xy = seen(sketch.marks)
            ax.plot(xy[:, 0], xy[:, 1], linestyle="none", marker="+", color=color, markersize=6)
        tip = seen(sketch.tip[None, :])[0]
        dx, dy = to_cam(np.array([phi]), sketch.heading[None, :], cam.sigma)[0]
        far = max(far, float(np.hypot(*tip)))
        # the label just beyond the tip, aligned so it never covers the follower
        ha = "center" if abs(dx) < 0.4 else ("left" if dx > 0 else "right")
        va = "center" if abs(dy) < 0.4 else ("bottom" if dy > 0 else "top")
        label = tip + 0.03 * reach * np.array([dx, dy])
        ax.text(label[0], label[1], f"φ = {math.degrees(phi):g}°", color=color, fontsize=8, ha=ha, va=va)
    return far


def _profile_plot(analysis: Analysis) -> Plot:
    cam, geo, spec = analysis.cam, analysis.geometry, analysis.design.cam
    profile = np.asarray(geo.profile.point)
    pitch = np.asarray(geo.pitch.point)
    reach = float(max(np.hypot(*pitch.T).max() + cam.roller_radius, np.hypot(*profile.T).max()))
    fig = _figure((6.6, 6.6))
    ax = fig.subplots()
    ax.add_patch(Polygon(profile, closed=True, facecolor="#dbe6f1", edgecolor="#1f3b57", linewidth=1.5))
    ax.plot([], [], color="#1f3b57", linewidth=1.5, label="cam profile")
    if spec.bore > 0.0:
        hole = _bore_outline(spec.bore, spec.keyway_width, spec.keyway_depth)
        ax.add_patch(Polygon(hole, closed=True, facecolor="white", edgecolor="#1f3b57", linewidth=1.1))
        ax.plot([], [], color="#1f3b57", linewidth=1.1, label=f"bore ⌀{spec.bore:g} mm")
    ax.plot(
        *np.vstack((pitch, pitch[:1])).T,
        color="#d9731a",
        linewidth=1.0,
        linestyle="--",
        label="pitch curve"
        if cam.is_roller
        else "face trace (point nearest the cam axis)"
        if cam.kinematics.guide.pivot is not None
        else "face-centre trace",
    )
    ax.add_patch(
        Circle((0.0, 0.0), cam.base_radius, fill=False, edgecolor="#7f7f7f", linestyle=":", linewidth=1.0)
    )
    ax.plot([], [], color="#7f7f7f", linestyle=":", label=f"base circle r = {cam.base_radius:g} mm")
    tick = 0.04 * reach
    ax.plot([-tick, tick], [0.0, 0.0], color="black", linewidth=0.8)
    ax.plot([0.0, 0.0], [-tick, tick], color="black", linewidth=0.8)
    far = _draw_followers(ax, analysis, reach)
    # direction of rotation, as an arc just outside the profile
    sign = 1.0 if cam.rotation.value == "ccw" else -1.0
    r_arrow = 1.08 * float(np.hypot(*profile.T).max())
    a0, a1 = math.radians(225.0 - 12.0 * sign), math.radians(225.0 + 12.0 * sign)
    ax.add_patch(
        FancyArrowPatch(
            (r_arrow * math.cos(a0), r_arrow * math.sin(a0)),
            (r_arrow * math.cos(a1), r_arrow * math.sin(a1)),
            connectionstyle=f"arc3,rad={0.1 * sign:g}",
            arrowstyle="-|>",
            mutation_scale=12,
            color="#333333",
        )
    )
    ax.text(
        1.16 * r_arrow * math.cos(math.radians(225.0)),
        1.16 * r_arrow * math.sin(math.radians(225.0)),
        "ω",
        fontsize=11,
        ha="center",
        va="center",
    )
    lim = far + 0.3 * reach  # room for the labels beyond the stem tips
    _plan_axes(ax, lim)
    ax.set_axisbelow(True)
    ax.legend(fontsize=8, loc="lower right", framealpha=0.9)
    kind = "roller" if cam.is_roller else "flat-face"
    return Plot(
        key="profile",
        title="Cam profile (to scale)",
        caption=f"Cam frame at φ = 0 (follower on +y, cam turning {cam.rotation.value}); the {kind} "
        f"follower is drawn where it meets the cam at φ = "
        + ", ".join(f"{a:g}°" for a in FOLLOWER_ANGLES_DEG)
        + " (kinematic inversion).",
        png=_png(fig),
    )


def report_plots(analysis: Analysis) -> list[Plot]:
    """Every figure of the single-design report, in display order."""
    return [
        _profile_plot(analysis),
        _motion_plot(analysis),
        _pressure_plot(analysis),
        _curvature_plot(analysis),
        _dynamics_plot(analysis),
    ]


# ---------------------------------------------------------------------------
# comparison figures


def plot_text(text: str) -> str:
    """User text (a design name) made safe for a matplotlib title, label or legend entry.

    Every ``$`` is escaped so no mathtext is parsed (an unbalanced ``$x^{$``
    would raise), control characters become spaces (no stray line breaks),
    and a leading ``_`` gets a space before it (matplotlib leaves labels
    starting with ``_`` out of the legend).
    """
    plain = "".join(" " if ord(c) < 32 or ord(c) == 127 else c for c in text)
    plain = plain.replace("$", r"\$")
    return " " + plain if plain.startswith("_") else plain


def _compare_curves(analyses: Sequence[Analysis], names: Sequence[str]) -> Plot:
    fig = _figure((11.0, 10.0))
    axes = fig.subplots(3, 2, sharex=True).ravel()
    quantities = (
        ("s [mm]", lambda a: (a.motion.phi, a.motion.s)),
        ("v = ds/dφ [mm/rad]", lambda a: (a.motion.phi, a.motion.v)),
        ("a = d²s/dφ² [mm/rad²]", lambda a: (a.motion.phi, a.motion.a)),
        ("pressure angle α [°]", lambda a: (a.geometry.phi, np.degrees(a.geometry.pressure_angle))),
        ("contact force F [N]", lambda a: (a.dynamics.phi, a.dynamics.contact_force)),
        ("input torque T [N·mm]", lambda a: (a.dynamics.phi, a.dynamics.torque)),
    )
    for k, (ax, (label, get)) in enumerate(zip(axes, quantities, strict=True)):
        for n, (analysis, name) in enumerate(zip(analyses, names, strict=True)):
            phi, values = get(analysis)
            x, y = _closed(np.degrees(np.asarray(phi)), np.asarray(values, dtype=float))
            ax.plot(x, y, color=_COLORS[n % len(_COLORS)], linewidth=1.2, label=plot_text(name))
        ax.axhline(0.0, **_ZERO)
        _style(ax, label, xlabel=k >= 4)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside upper center", ncol=min(2, len(labels)), fontsize=9)
    return Plot(
        key="compare",
        title="Motion, pressure angle and dynamics",
        caption="One line per design, against the cam angle.",
        png=_png(fig),
    )


def _compare_profiles(analyses: Sequence[Analysis], names: Sequence[str]) -> Plot:
    fig = _figure((6.6, 6.6))
    ax = fig.subplots()
    reach = 0.0
    for n, (analysis, name) in enumerate(zip(analyses, names, strict=True)):
        pts = np.asarray(analysis.geometry.profile.point)
        pts = np.vstack((pts, pts[:1]))
        reach = max(reach, float(np.hypot(*pts.T).max()))
        ax.plot(pts[:, 0], pts[:, 1], color=_COLORS[n % len(_COLORS)], linewidth=1.3, label=plot_text(name))
    ax.plot(0.0, 0.0, marker="+", color="black")
    lim = 1.1 * reach
    _plan_axes(ax, lim)
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=1, fontsize=8)
    return Plot(
        key="profiles",
        title="Cam profiles (to scale)",
        caption="Profiles overlaid in the cam frame at φ = 0.",
        png=_png(fig),
    )


def compare_plots(analyses: Sequence[Analysis], names: Sequence[str]) -> list[Plot]:
    """The comparison figures: overlaid curves and overlaid profiles, one line per design."""
    return [_compare_curves(analyses, names), _compare_profiles(analyses, names)]
