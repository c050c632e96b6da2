"""The report's figures, drawn off-screen with matplotlib and returned as SVG bytes.

Never ``pyplot`` and never a lasting change to ``rcParams``: drawing needs no
display, leaves the global matplotlib state alone and is safe in threads
(the designer of :mod:`camcad.serve` draws from a thread pool). Modules:
``_base`` (figure with fixed margins, SVG bytes, styles), ``design`` (the cam
drawing, motion, pressure angle, curvature, dynamics), ``shop`` (fit error,
toolpath plan view, solid), ``compare``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camcad._plots._base import Plot, figure, plot_text, svg, trace_name
from camcad._plots.compare import compare_plots
from camcad._plots.design import (
    CURVATURE_CLIP,
    FOLLOWER_ANGLES_DEG,
    curvature_plot,
    dynamics_plot,
    motion_plot,
    pressure_plot,
    profile_plot,
)
from camcad._plots.shop import fit_error_plot, solid_plot, toolpath_plot

if TYPE_CHECKING:
    from camcad.analysis import Analysis

__all__ = [
    "CURVATURE_CLIP",
    "FOLLOWER_ANGLES_DEG",
    "Plot",
    "compare_plots",
    "design_plots",
    "figure",
    "plot_text",
    "report_plots",
    "svg",
    "trace_name",
]


def design_plots(analysis: Analysis) -> list[Plot]:
    """The figures that follow the design as it is edited: drawing, motion, α, ρ, dynamics."""
    return [
        profile_plot(analysis),
        motion_plot(analysis),
        pressure_plot(analysis),
        curvature_plot(analysis),
        dynamics_plot(analysis),
    ]


def report_plots(analysis: Analysis) -> list[Plot]:
    """Every figure of the single-design report, in display order (the shop's pictures last)."""
    shop = [fit_error_plot(analysis), toolpath_plot(analysis), solid_plot(analysis)]
    plots = [*design_plots(analysis), *(p for p in shop if p is not None)]
    if analysis.parts[0].part.barrel is not None:  # a barrel's shape: its own drawing and pictures
        from camcad._plots.barrel import barrel_plots

        plate = {"profile", "solid"}  # a plate's outline and its extruded solid: not a barrel's
        return [*barrel_plots(analysis), *(p for p in plots if p.key not in plate)]
    return plots
