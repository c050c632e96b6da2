"""The comparison figures: one small plot per quantity and the profiles overlaid, one line per design."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad._plots._base import COLORS, Plot, closed, figure, plan_axes, plot_text, svg
from camcad._plots.chart import HLine, Panel, Series, line_chart

if TYPE_CHECKING:
    from camcad.analysis import Analysis

__all__ = ["compare_colors", "compare_plots"]


def compare_colors(count: int) -> list[str]:
    """The line colour of each of ``count`` designs in the comparison figures (for the page's key)."""
    return [COLORS[n % len(COLORS)] for n in range(count)]


_Getter = Callable[[Any], tuple[Any, Any]]
_QUANTITIES: tuple[tuple[str, str, str, _Getter], ...] = (
    ("compare-s", "Displacement", "s [mm]", lambda a: (a.motion.phi, a.motion.s)),
    ("compare-v", "Velocity", "v = ds/dφ [mm/rad]", lambda a: (a.motion.phi, a.motion.v)),
    ("compare-a", "Acceleration", "a = d²s/dφ² [mm/rad²]", lambda a: (a.motion.phi, a.motion.a)),
    ("compare-alpha", "Pressure angle", "pressure angle α [°]",
     lambda a: (a.geometry.phi, np.degrees(a.geometry.pressure_angle))),
    ("compare-force", "Contact force", "contact force F [N]",
     lambda a: (a.dynamics.phi, a.dynamics.contact_force)),
    ("compare-torque", "Input torque", "input torque T [N·mm]",
     lambda a: (a.dynamics.phi, a.dynamics.torque)),
)  # fmt: skip


def _curve(analyses: Sequence[Analysis], names: Sequence[str], key: str, title: str, label: str,
           get: _Getter) -> Plot:  # fmt: skip
    series = []
    for n, analysis in enumerate(analyses):
        phi, values = get(analysis)
        x, y = closed(np.degrees(np.asarray(phi)), np.asarray(values, dtype=float))
        series.append(Series(x=x, y=y, color=COLORS[n % len(COLORS)], width=1.4))
    caption = "One line per design (colours as in the key above)."
    panel = Panel(ylabel=label, series=series, lines=[HLine(y=0.0, color="#666666", dash="", width=0.8)],
                  height=220.0)  # fmt: skip
    return Plot(key=key, title=title, caption=caption, svg=line_chart([panel], title=title))


def _profiles(analyses: Sequence[Analysis], names: Sequence[str]) -> Plot:
    fig = figure((6.0, 6.0), left=0.7, bottom=0.5, top=0.15, right=0.15)
    ax = fig.subplots()
    reach = 0.0
    for n, (analysis, name) in enumerate(zip(analyses, names, strict=True)):
        pts = np.asarray(analysis.geometry.profile.point)
        pts = np.vstack((pts, pts[:1]))
        reach = max(reach, float(np.hypot(*pts.T).max()))
        ax.plot(pts[:, 0], pts[:, 1], color=COLORS[n % len(COLORS)], linewidth=1.3, label=plot_text(name))
    ax.plot(0.0, 0.0, marker="+", color="black")
    plan_axes(ax, 1.1 * reach)
    return Plot(
        key="profiles",
        title="Cam profiles (to scale)",
        caption="Profiles overlaid in the cam frame at φ = 0.",
        svg=svg(fig),
    )


def compare_plots(analyses: Sequence[Analysis], names: Sequence[str]) -> list[Plot]:
    """The comparison figures: the profiles, then s, v, a, pressure angle, force and torque overlaid.

    The figures carry no legend (long names would cover the curves): the page
    shows one key for all of them, in :func:`compare_colors`.
    """
    units = {a.cam.follower_spec.kind.lift.short for a in analyses}
    unit = units.pop() if len(units) == 1 else "mm or °"  # an arm's s, v, a are in degrees of swing
    quantities = [(k, t, label.replace("[mm", f"[{unit}"), get) for k, t, label, get in _QUANTITIES]
    return [_profiles(analyses, names), *(_curve(analyses, names, *q) for q in quantities)]
