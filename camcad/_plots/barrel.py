"""The figures of a barrel cam (issue 36): its developed groove, its pressure angles, a 3-D view.

- the groove developed (unrolled) at the roller's pitch station: the pitch
  line and both walls, u = t_p·φ + y along the circumference, z along the axis
  (:func:`camcad.geometry.barrel_limits.developed_walls`);
- the pressure angle over the turn at the groove's bottom, the pitch station
  and the barrel's surface (:func:`camcad.geometry.barrel.barrel_walls`), with
  the design's limit;
- the barrel in 3-D: its outline and the groove's edges on the barrel's
  surface and at its bottom (:func:`camcad.geometry.barrel.walls_at_radius`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from camcad._plots._base import COLORS, FONT, LIMIT, Plot, figure, svg
from camcad.geometry.barrel import WallSide, barrel_walls, walls_at_radius
from camcad.geometry.barrel_limits import developed_walls

if TYPE_CHECKING:
    from camcad.analysis import Analysis
    from camcad.geometry.families import Barrel

__all__ = ["barrel_plots"]


def _axes_style(ax: object) -> None:
    ax.tick_params(labelsize=FONT - 1)  # type: ignore[attr-defined]
    ax.grid(True, color="#eeeeee", linewidth=0.6)  # type: ignore[attr-defined]
    ax.set_axisbelow(True)  # type: ignore[attr-defined]


def _developed(barrel: Barrel) -> Plot:
    o = barrel.options
    phi = np.linspace(0.0, 2.0 * math.pi, 1441)
    walls = developed_walls(barrel.program.evaluate(phi), barrel.follower, o, o.pitch_station)
    fig = figure((7.0, 3.2))
    ax = fig.add_subplot(1, 1, 1)
    for curve, color, label in (
        (walls.upper, COLORS[0], "upper wall"),
        (walls.lower, COLORS[1], "lower wall"),
        (walls.pitch, "#888888", "pitch line"),
    ):
        pts = np.asarray(curve.point)
        ax.plot(
            pts[:, 0], pts[:, 1], color=color, linewidth=1.1 if label != "pitch line" else 0.8, label=label
        )
    span = 2.0 * math.pi * o.pitch_station
    for x in (0.0, span):
        ax.axvline(x, color="#bbbbbb", linewidth=0.8)
    ax.axhline(0.0, color="#bbbbbb", linewidth=0.8)
    ax.axhline(o.length, color="#bbbbbb", linewidth=0.8)
    ax.set_xlim(-0.02 * span, 1.02 * span)
    ax.set_ylim(-0.05 * o.length, 1.05 * o.length)
    ax.set_xlabel("developed circumference at the pitch station u [mm]", fontsize=FONT)
    ax.set_ylabel("along the axis z [mm]", fontsize=FONT)
    ax.legend(fontsize=FONT - 1, loc="upper right")
    _axes_style(ax)
    return Plot(
        key="profile",  # the report's drawing beside the key numbers
        title="Developed groove",
        caption=(
            f"The groove unrolled at the roller's pitch station (radius {o.pitch_station:g} mm), as "
            "profile.dxf draws it: both walls and the pitch line; grey lines mark the barrel's ends and "
            "the seam at 0°/360°."
        ),
        svg=svg(fig),
    )


def _pressure(barrel: Barrel, limit_deg: float) -> Plot:
    o = barrel.options
    phi = barrel.program.sample_phi(math.radians(0.25))
    stations = np.array([o.bottom_radius, o.pitch_station, o.barrel_radius])
    alpha = np.degrees(
        np.abs(barrel_walls(barrel.program.evaluate(phi), barrel.follower, o, stations).pressure_angle)
    )
    fig = figure()
    ax = fig.add_subplot(1, 1, 1)
    deg = np.degrees(phi)
    for j, (name, color) in enumerate((("bottom", COLORS[3]), ("pitch", COLORS[0]), ("top", COLORS[2]))):
        ax.plot(deg, alpha[:, j], color=color, linewidth=1.1, label=f"{name}, r = {stations[j]:g} mm")
    ax.axhline(limit_deg, label=f"limit {limit_deg:g}°", **LIMIT)
    ax.set_xlim(0.0, 360.0)
    ax.set_xlabel("cam angle φ [°]", fontsize=FONT)
    ax.set_ylabel("|pressure angle| [°]", fontsize=FONT)
    ax.legend(fontsize=FONT - 1, loc="upper right")
    _axes_style(ax)
    peaks = barrel.limits.pressure_angle_max
    return Plot(
        key="barrel-pressure",
        title="Pressure angle at the groove's bottom, pitch and top",
        caption=(
            "The angle between the contact normal and the direction the follower is driven, on three "
            "cylinders; largest at the groove's bottom (for a translating roller tan α = s′/r). Peaks: "
            + ", ".join(
                f"{n} {math.degrees(e.value):.2f}° at {e.angle_deg:.1f}°"
                for n, e in zip(("bottom", "pitch", "top"), peaks, strict=True)
            )
            + "."
        ),
        svg=svg(fig),
    )


def _picture(barrel: Barrel) -> Plot:
    o = barrel.options
    phi = np.linspace(0.0, 2.0 * math.pi, 721)
    motion = barrel.program.evaluate(phi)
    fig = figure((5.0, 4.6), left=0.1, right=0.1, top=0.1, bottom=0.1)
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    ring = np.linspace(0.0, 2.0 * math.pi, 181)
    for z in (0.0, o.length):  # the barrel's ends
        ax.plot(
            o.barrel_radius * np.cos(ring), o.barrel_radius * np.sin(ring), z, color="#999999", linewidth=0.8
        )
        if o.bore > 0.0:
            r = 0.5 * o.bore
            ax.plot(r * np.cos(ring), r * np.sin(ring), z, color="#bbbbbb", linewidth=0.6)
    for a in np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False):  # generators of the cylinder
        x, y = o.barrel_radius * math.cos(a), o.barrel_radius * math.sin(a)
        ax.plot([x, x], [y, y], [0.0, o.length], color="#dddddd", linewidth=0.6)
    for radius, width in ((o.barrel_radius, 1.2), (o.bottom_radius, 0.7)):
        for side, color in ((WallSide.UPPER, COLORS[0]), (WallSide.LOWER, COLORS[1])):
            pts = walls_at_radius(motion, barrel.follower, o, radius, side)[1].point[:, 0]
            ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], color=color, linewidth=width)
    lim = o.barrel_radius
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_zlim(0.0, o.length)
    ax.set_box_aspect((2.0 * lim, 2.0 * lim, o.length))
    ax.tick_params(labelsize=FONT - 2)
    ax.set_xlabel("x [mm]", fontsize=FONT - 1)
    ax.set_ylabel("y [mm]", fontsize=FONT - 1)
    ax.set_zlabel("z [mm]", fontsize=FONT - 1)
    return Plot(
        key="barrel-3d",
        title="The barrel",
        caption=(
            "The barrel and its groove in its own frame (axis z): the walls' edges on the barrel's "
            "surface (thick) and at the groove's bottom (thin), upper wall blue, lower wall orange. "
            "cam.step holds the exact solid, cam.stl its mesh."
        ),
        svg=svg(fig),
    )


def barrel_plots(analysis: Analysis) -> list[Plot]:
    """The barrel's figures, for a part with a barrel shape (none for any other part)."""
    barrel = analysis.parts[0].part.barrel
    if barrel is None:
        return []
    limit = math.degrees(analysis.design.cam.max_pressure_angle)
    return [_developed(barrel), _pressure(barrel, limit), _picture(barrel)]
