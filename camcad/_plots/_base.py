"""Shared pieces of the report's figures: the figure, its SVG bytes, axes styles, colours.

Only :class:`matplotlib.figure.Figure` with an explicit
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg` is used, never
``pyplot``. Figures have fixed margins in inches (no constrained layout: it
draws every figure twice) and are written as SVG with text kept as text (it
prints crisply, scales to any column and is half the drawing time of a PNG).
The two SVG settings matplotlib reads only from ``rcParams`` (the text mode
and the salt of its element ids) are set under a lock for the ``savefig``
call alone and restored, so the output is byte-identical between runs and
threads do not see each other's settings.
"""

from __future__ import annotations

import io
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from camcad._typing import FloatArray

if TYPE_CHECKING:
    from camcad.analysis import Analysis

__all__ = ["Plot", "plot_text"]

WIDE = (7.0, 3.6)  # inches: one plot in a half-page column
LIMIT = {"color": "#c0392b", "linestyle": "--", "linewidth": 1.1}
COLORS = ("#1f5f9e", "#d9731a", "#2e8b57", "#a23b72", "#6c5b7b", "#8c6d1f", "#3b8ea5", "#b03a2e")
FONT = 9.0  # pt, axis labels; ticks one point less
_SVG_LOCK = threading.Lock()
_SVG_RC = {"svg.fonttype": "none", "svg.hashsalt": "camcad"}


@dataclass(frozen=True, slots=True, kw_only=True)
class Plot:
    """One rendered figure: a stable key, a short title, a caption and the image bytes.

    ``svg`` holds the figure as SVG; ``png`` is kept for figures drawn as PNG.
    With neither the figure is a note: the caption says why there is no picture.
    """

    key: str  # stable identifier, e.g. "motion"
    title: str
    caption: str
    svg: bytes | None = None
    png: bytes | None = None


def figure(size: tuple[float, float] = WIDE, *, left: float = 0.8, right: float = 0.15,
           top: float = 0.25, bottom: float = 0.5, hspace: float = 0.12) -> Figure:  # fmt: skip
    """A new off-screen figure with fixed margins given in inches (no pyplot, no layout engine)."""
    fig = Figure(figsize=size, dpi=100)
    FigureCanvasAgg(fig)
    w, h = size
    fig.subplots_adjust(left=left / w, right=1.0 - right / w, top=1.0 - top / h, bottom=bottom / h,
                        hspace=hspace)  # fmt: skip
    return fig


def svg(fig: Figure) -> bytes:
    """The figure as SVG bytes: text as text, no date, fixed element ids (reproducible)."""
    buf = io.BytesIO()
    with _SVG_LOCK, matplotlib.rc_context(_SVG_RC):
        fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
    return buf.getvalue()


def plan_axes(ax: Axes, lim: float) -> None:
    """A to-scale plan view of the cam frame, ±``lim`` mm on both axes."""
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]", fontsize=FONT)
    ax.set_ylabel("y [mm]", fontsize=FONT)
    ax.tick_params(labelsize=FONT - 1)
    ax.grid(True, color="#eeeeee", linewidth=0.6)
    ax.set_axisbelow(True)


def closed(phi_deg: FloatArray, *values: FloatArray) -> tuple[FloatArray, ...]:
    """Append the 360° sample (a copy of the 0° one) so curves span the full turn."""
    if phi_deg.size and phi_deg[0] == 0.0 and phi_deg[-1] < 360.0:
        return (np.append(phi_deg, 360.0), *(np.append(v, v[0]) for v in values))
    return (phi_deg, *values)


def trace_name(analysis: Analysis) -> str:
    """What the follower's reference curve is, in words, for this follower type."""
    return analysis.cam.follower.words.trace


def shape(ax: Axes, patch: Patch) -> None:
    """Add a patch in data coordinates without growing the data limits (the caller sets them).

    ``Axes.add_patch`` walks every vertex in Python to update the limits, a
    tenth of a second for a 3600-point profile; the plan views set their
    limits themselves.
    """
    patch.set_transform(ax.transData)
    ax.add_artist(patch)


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
