"""The figures of the elastic follower train (issue 34): the speed map and the response at the design speed.

- speed map: the residual vibration in each dwell, the peak dynamic error
  and the smallest contact force against the cam speed, the design speed and
  a polydyne cam's ``compensate_rpm`` marked (DYNACAM's vibration screen;
  Norton 2009, §15.4);
- response: the output's dynamic error x − s and the contact force over the
  turn at the design speed, flights shaded by the zero force.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from camcad._plots._base import COLORS, LIMIT, Plot, closed, figure, svg
from camcad._plots.chart import HLine, Panel, Series, line_chart

if TYPE_CHECKING:
    from camcad.analysis import Analysis

__all__ = ["response_plot", "speed_map_plot", "vibration_plots"]


def speed_map_plot(analysis: Analysis) -> Plot | None:
    """Residual per dwell, peak dynamic error and minimum contact force against the cam speed [rpm]."""
    vib = analysis.vibration
    if vib is None:
        return None
    m = vib.speed_map
    shown = "mm" if vib.unit == "mm" else "°"
    force_unit = "N" if vib.unit == "mm" else "N·mm"
    rpm = np.asarray(m.speeds_rpm, dtype=float)
    design = analysis.design.cam.speed_rpm
    tuned = vib.compensated.speed_rpm if vib.compensated is not None else None
    fig = figure((7.2, 5.6), left=1.05, hspace=0.12)
    axes = fig.subplots(3, 1, sharex=True)
    marker = "o" if rpm.size < 3 else ""
    for k in range(m.residuals.shape[1] if m.residuals.ndim == 2 else 0):
        d = m.dwells[k]
        label = f"dwell {k + 1} ({math.degrees(d.start):.0f}°–{math.degrees(d.end):.0f}°)"
        axes[0].plot(rpm, m.residuals[:, k], marker=marker, color=COLORS[k % len(COLORS)], label=label)
    spec = analysis.design.vibration
    if spec is not None and spec.max_residual is not None:
        axes[0].axhline(spec.max_residual, **LIMIT, label="max_residual")
    axes[0].set_ylabel(f"residual\n[{shown}]")
    axes[1].plot(rpm, np.abs(m.error_peak), marker=marker, color=COLORS[3])
    axes[1].set_ylabel(f"peak |x − s|\n[{shown}]")
    axes[2].plot(rpm, m.contact_force_min, marker=marker, color=COLORS[4])
    axes[2].axhline(0.0, **LIMIT)
    axes[2].set_ylabel(f"min contact\nforce [{force_unit}]")
    axes[2].set_xlabel("cam speed [rpm]")
    for ax in axes:
        ax.axvline(design, color="#333333", linewidth=1.0, linestyle=":", label="design speed")
        if tuned is not None:
            ax.axvline(tuned, color=COLORS[2], linewidth=1.0, linestyle="-.", label="compensate_rpm")
        ax.grid(True, linewidth=0.3, alpha=0.5)
    axes[0].legend(loc="upper right", fontsize=7)
    leaving = rpm[np.asarray(m.leaves, dtype=bool)]
    tail = ""
    if leaving.size:
        tail = f" The follower would leave the cam from {leaving.min():g} rpm in this range."
    tune = f"; compensate_rpm {tuned:g} rpm (dash-dot)" if tuned is not None else ""
    return Plot(
        key="speed-map",
        title="Speed map",
        caption=f"The contact-held periodic response of the elastic follower train at {rpm.size} speeds "
        f"from {rpm.min():g} to {rpm.max():g} rpm: residual vibration at the start of each dwell, the peak "
        f"dynamic error and the smallest contact force. Design speed {design:g} rpm (dotted){tune}." + tail,
        svg=svg(fig),
    )


def response_plot(analysis: Analysis) -> Plot | None:
    """The dynamic error x − s and the contact force over the turn at the design speed."""
    vib = analysis.vibration
    if vib is None:
        return None
    r = vib.response
    shown = "mm" if vib.unit == "mm" else "°"
    force_unit = "N" if vib.unit == "mm" else "N·mm"
    phi = np.degrees(np.asarray(r.phi, dtype=float))
    x, err = closed(phi, np.asarray(r.error, dtype=float))
    _, force = closed(phi, np.asarray(r.contact_force, dtype=float))
    target = "the motion program (the polydyne cam's output)" if vib.compensated is not None else "s"
    panels = [
        Panel(ylabel=f"error x − s\n[{shown}]", series=[Series(x=x, y=err, color=COLORS[3])], height=140.0),
        Panel(
            ylabel=f"contact force\n[{force_unit}]",
            series=[Series(x=x, y=force, color=COLORS[4])],
            lines=[HLine(y=0.0, label="leaves the cam below")],
            legend=True,
            height=140.0,
        ),
    ]
    bounds = [math.degrees(b) for b in analysis.cam.program.segment_bounds][1:]
    peak = r.error_peak
    flights = "; ".join(
        f"flies {math.degrees(f.leave):.1f}°–{math.degrees(f.land):.1f}°"
        for f in r.flights
        if not math.isnan(f.land)
    )
    return Plot(
        key="vibration",
        title="Response at the design speed",
        caption=f"The output's dynamic error against {target} and the contact force of the elastic train "
        f"at {r.speed_rpm:g} rpm (periodic steady state): peak error {peak.value:.4g} {shown} at "
        f"{peak.angle_deg:.1f}°, smallest force {r.contact_force_min.value:.4g} {force_unit} at "
        f"{r.contact_force_min.angle_deg:.1f}°" + (f"; {flights}" if flights else "") + ".",
        svg=line_chart(panels, bounds_deg=bounds, title="Response at the design speed"),
    )


def vibration_plots(analysis: Analysis) -> list[Plot]:
    """Both figures of the ``[vibration]`` analysis, when the design has one."""
    return [p for p in (speed_map_plot(analysis), response_plot(analysis)) if p is not None]
