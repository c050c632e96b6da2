"""Line charts against the cam angle written directly as SVG: the report's curves in milliseconds.

matplotlib spends about 35 ms of CPU on an empty axes (ticks, markers, font
layout) before a curve is drawn, so the report's eleven curve panels cost a
quarter of a second; these charts need a few milliseconds each. They draw
what a cam engineer reads off such a plot and nothing more: stacked panels
sharing the angle axis (0–360°, a tick every 45°), segment boundaries and
names, curves with gaps where a value is undefined, horizontal limit lines,
a legend, tick marks along the bottom (the fit's knots). Text stays text
(crisp in print, found by ``pdftotext``); numbers use "−" and as many
decimals as the tick step needs; coordinates are rounded to 0.01 px, so the
same data give the same bytes. Curves are thinned per pixel column to their
first, last, lowest and highest sample (the M4 rule), which draws the same
picture as every sample.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from html import escape

import numpy as np

from camcad._typing import FloatArray

__all__ = ["HLine", "Panel", "Series", "line_chart", "nice_ticks"]

WIDTH = 700.0  # px of the viewBox: the chart is drawn for a column about this wide
_LEFT, _RIGHT, _TOP_SPACE, _BOTTOM = 78.0, 14.0, 22.0, 44.0
_GAP = 10.0  # px between stacked panels
_FONT = 12.0  # px, labels; ticks 11 px
_INK, _MUTED, _GRID, _FRAME = "#1d2733", "#555555", "#e3e3e3", "#8a8a8a"


@dataclass(frozen=True, slots=True, kw_only=True)
class Series:
    """One curve: x [deg of cam angle], y (NaN for a gap), colour, width, legend label ("" for none)."""

    x: FloatArray
    y: FloatArray
    color: str
    width: float = 1.5
    label: str = ""


@dataclass(frozen=True, slots=True, kw_only=True)
class HLine:
    """A horizontal line at ``y`` (a limit, a tolerance), dashed unless ``dash`` is empty."""

    y: float
    color: str = "#c0392b"
    dash: str = "6 4"
    label: str = ""
    width: float = 1.2


@dataclass(frozen=True, slots=True, kw_only=True)
class Panel:
    """One stacked panel: its y label (a newline splits it), curves, lines, fixed limits and marks.

    ``ticks_at`` [deg] are drawn as short marks along the bottom of the panel
    (``ticks_label`` names them in the legend).
    """

    ylabel: str
    series: Sequence[Series] = ()
    lines: Sequence[HLine] = ()
    ylim: tuple[float, float] | None = None
    height: float = 150.0
    ticks_at: FloatArray | None = None
    ticks_label: str = ""
    legend: bool = False
    extra: list[str] = field(default_factory=list)


def nice_ticks(lo: float, hi: float, most: int = 6) -> tuple[list[float], int]:
    """Round tick values covering [lo, hi] (at most about ``most``) and the decimals they need."""
    span = hi - lo
    if not math.isfinite(span) or span <= 0.0:
        return [lo], 0
    raw = span / most
    mag = 10.0 ** math.floor(math.log10(raw))
    step = next(m * mag for m in (1.0, 2.0, 2.5, 5.0, 10.0) if m * mag >= raw)
    first = math.ceil(lo / step - 1e-9)
    ticks = [k * step for k in range(first, math.floor(hi / step + 1e-9) + 1)]
    decimals = max(0, -math.floor(math.log10(step) + 1e-12))
    if abs(step * 10**decimals - round(step * 10**decimals)) > 1e-6:  # 2.5 × 10^k needs one more
        decimals += 1
    return ticks, decimals


def _num(value: float, decimals: int) -> str:
    text = f"{value:.{decimals}f}"
    if float(text) == 0.0:
        text = text.lstrip("-")
    return text.replace("-", "−")


def _m4(x: FloatArray, y: FloatArray, columns: int) -> np.ndarray:
    """Indices to draw: per pixel column the first, last, lowest and highest finite sample, plus gap edges."""
    n = len(x)
    if n <= 4 * columns:
        return np.arange(n)
    finite = np.isfinite(y)
    span = float(x[-1] - x[0]) or 1.0
    bucket = np.minimum(((x - x[0]) / span * columns).astype(int), columns - 1)
    keep = np.zeros(n, dtype=bool)
    starts = np.flatnonzero(np.r_[True, np.diff(bucket) != 0])
    ends = np.r_[starts[1:], n] - 1
    keep[starts] = keep[ends] = True
    yy = np.where(finite, y, np.inf)
    order = np.lexsort((yy, bucket))  # by bucket, then by value: first of a bucket is its lowest
    first_of = np.r_[True, np.diff(bucket[order]) != 0]
    keep[order[first_of]] = True
    yy = np.where(finite, y, -np.inf)
    order = np.lexsort((-yy, bucket))
    keep[order[np.r_[True, np.diff(bucket[order]) != 0]]] = True
    edges = np.flatnonzero(np.diff(finite.astype(np.int8)) != 0)
    keep[edges] = keep[np.minimum(edges + 1, n - 1)] = True
    return np.flatnonzero(keep)


def _path(xs: np.ndarray, ys: np.ndarray) -> str:
    """SVG path data with a new sub-path after every gap (NaN)."""
    out, pen = [], False
    for x, y in zip(xs.tolist(), ys.tolist(), strict=True):
        if not (math.isfinite(x) and math.isfinite(y)):
            pen = False
            continue
        out.append(f"{'L' if pen else 'M'}{x:.2f} {y:.2f}")
        pen = True
    return "".join(out)


def _text(x: float, y: float, text: str, *, size: float = _FONT, anchor: str = "middle", color: str = _INK,
          rotate: bool = False, extra: str = "") -> str:  # fmt: skip
    lines = text.split("\n")
    turn = f' transform="rotate(-90 {x:.2f} {y:.2f})"' if rotate else ""
    place = f'x="{x:.2f}" y="{y:.2f}" font-size="{size:g}" text-anchor="{anchor}" fill="{color}"'
    head = f"<text {place}{turn}{extra}>"
    if len(lines) == 1:
        return head + escape(text) + "</text>"
    shift = -(len(lines) - 1) * 0.55
    spans = "".join(
        f'<tspan x="{x:.2f}" dy="{(shift if i == 0 else 1.1):g}em">{escape(line)}</tspan>'
        for i, line in enumerate(lines)
    )
    return head + spans + "</text>"


def line_chart(
    panels: Sequence[Panel],
    *,
    xlabel: str = "cam angle φ [°]",
    bounds_deg: Sequence[float] = (),
    segments: Sequence[tuple[float, float, str]] = (),
    title: str = "",
) -> bytes:
    """Stacked panels over the cam angle 0–360° as SVG bytes.

    Parameters
    ----------
    panels
        Top to bottom; the angle axis is labelled under the last one.
    bounds_deg
        Segment boundaries [deg], dotted in every panel.
    segments
        (start, end, name) [deg] written above the first panel.
    title
        The chart's accessible name (``<title>``).
    """
    top = _TOP_SPACE + (14.0 if segments else 0.0)
    height = top + sum(p.height for p in panels) + _GAP * (len(panels) - 1) + _BOTTOM
    x0, x1 = _LEFT, WIDTH - _RIGHT
    sx = (x1 - x0) / 360.0
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {WIDTH:g} {height:g}" width="{WIDTH:g}" '
        f'height="{height:g}" font-family="DejaVu Sans, Verdana, Arial, sans-serif">',
        f"<title>{escape(title)}</title>" if title else "",
        f'<rect x="0" y="0" width="{WIDTH:g}" height="{height:g}" fill="#ffffff"/>',
    ]
    for a, b, name in segments:
        out.append(_text(x0 + sx * 0.5 * (a + b), top - 6.0, name, size=11.0, color=_MUTED))
    y_top = top
    for k, panel in enumerate(panels):
        yb = y_top + panel.height
        values = [s.y[np.isfinite(s.y)] for s in panel.series]
        every = (
            np.concatenate([*values, np.array([h.y for h in panel.lines])]) if values or panel.lines else []
        )
        if panel.ylim is not None:
            lo, hi = panel.ylim
        elif len(every):
            lo, hi = float(np.min(every)), float(np.max(every))
            pad = 0.06 * (hi - lo) if hi > lo else max(1.0, abs(hi)) * 0.5
            lo, hi = lo - pad, hi + pad
        else:
            lo, hi = -1.0, 1.0

        def Y(
            v: np.ndarray | float, lo: float = lo, hi: float = hi, y_top: float = y_top, yb: float = yb
        ) -> np.ndarray:
            return yb - (np.asarray(v, dtype=float) - lo) / (hi - lo) * (yb - y_top)

        ticks, decimals = nice_ticks(lo, hi, most=max(4, int(panel.height // 26)))
        for t in ticks:  # horizontal grid and y tick labels
            y = float(Y(t))
            color = "#666666" if abs(t) < 1e-12 * max(abs(lo), abs(hi), 1.0) else _GRID
            out.append(f'<path d="M{x0:.2f} {y:.2f}H{x1:.2f}" stroke="{color}" stroke-width="0.8"/>')
            out.append(_text(x0 - 6.0, y + 4.0, _num(t, decimals), size=11.0, anchor="end"))
        for a in range(0, 361, 45):  # vertical grid
            out.append(
                f'<path d="M{x0 + sx * a:.2f} {y_top:.2f}V{yb:.2f}" stroke="{_GRID}" stroke-width="0.8"/>'
            )
        for b in bounds_deg:
            out.append(
                f'<path d="M{x0 + sx * b:.2f} {y_top:.2f}V{yb:.2f}" stroke="#8e8e8e" stroke-width="1" '
                'stroke-dasharray="2 3"/>'
            )
        clip = f"clip{k}"
        out.append(
            f'<clipPath id="{clip}"><rect x="{x0:.2f}" y="{y_top:.2f}" width="{x1 - x0:.2f}" '
            f'height="{panel.height:.2f}"/></clipPath><g clip-path="url(#{clip})">'
        )
        for h in panel.lines:
            dash = f' stroke-dasharray="{h.dash}"' if h.dash else ""
            out.append(f'<path d="M{x0:.2f} {float(Y(h.y)):.2f}H{x1:.2f}" stroke="{h.color}" '
                       f'stroke-width="{h.width:g}"{dash}/>')  # fmt: skip
        for s in panel.series:
            x = np.asarray(s.x, dtype=float)
            y = np.asarray(s.y, dtype=float)
            keep = _m4(x, y, int(x1 - x0))
            d = _path(x0 + sx * x[keep], Y(y[keep]))
            out.append(f'<path d="{d}" fill="none" stroke="{s.color}" stroke-width="{s.width:g}" '
                       'stroke-linejoin="round"/>')  # fmt: skip
        out.append("</g>")
        if panel.ticks_at is not None and len(panel.ticks_at):
            marks = "".join(f"M{x0 + sx * float(a):.2f} {yb:.2f}v-9" for a in panel.ticks_at)
            out.append(f'<path d="{marks}" stroke="#555555" stroke-width="1"/>')
        out.append(
            f'<rect x="{x0:.2f}" y="{y_top:.2f}" width="{x1 - x0:.2f}" height="{panel.height:.2f}" '
            f'fill="none" stroke="{_FRAME}" stroke-width="1"/>'
        )
        out.append(_text(18.0, 0.5 * (y_top + yb), panel.ylabel, rotate=True))
        if panel.legend:
            out.append(_legend(panel, x1 - 8.0, y_top + 8.0))
        out += panel.extra
        last = k == len(panels) - 1
        for a in range(0, 361, 45):
            out.append(f'<path d="M{x0 + sx * a:.2f} {yb:.2f}v4" stroke="{_FRAME}" stroke-width="1"/>')
            if last:
                out.append(_text(x0 + sx * a, yb + 17.0, f"{a}", size=11.0))
        y_top = yb + _GAP
    out.append(_text(0.5 * (x0 + x1), height - 8.0, xlabel))
    out.append("</svg>\n")
    return "".join(out).encode("utf-8")


def _legend(panel: Panel, right: float, top: float) -> str:
    """A boxed legend in the panel's top right corner."""
    entries = [(s.label, s.color, "", s.width) for s in panel.series if s.label]
    entries += [(h.label, h.color, h.dash, h.width) for h in panel.lines if h.label]
    if panel.ticks_label:
        entries.append((panel.ticks_label, "#555555", "ticks", 1.0))
    if not entries:
        return ""
    width = 34.0 + 6.4 * max(len(e[0]) for e in entries)
    height = 8.0 + 16.0 * len(entries)
    left = right - width
    out = [f'<rect x="{left:.2f}" y="{top:.2f}" width="{width:.2f}" height="{height:.2f}" fill="#ffffff" '
           'fill-opacity="0.92" stroke="#cccccc" stroke-width="0.8" rx="3"/>']  # fmt: skip
    for i, (label, color, dash, width_) in enumerate(entries):
        y = top + 12.0 + 16.0 * i
        if dash == "ticks":
            out.append(f'<path d="M{left + 15:.2f} {y + 5:.2f}v-9" stroke="{color}" stroke-width="1"/>')
        else:
            style = f' stroke-dasharray="{dash}"' if dash else ""
            out.append(
                f'<path d="M{left + 6:.2f} {y:.2f}h20" stroke="{color}" stroke-width="{width_:g}"{style}/>'
            )
        out.append(_text(left + 30.0, y + 4.0, label, size=11.0, anchor="start"))
    return "".join(out)
