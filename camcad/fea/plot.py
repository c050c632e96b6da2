"""Pictures of the finite-element check: the von Mises field of each load case, as PNG bytes.

Drawn off-screen with :class:`matplotlib.figure.Figure` and the Agg canvas
(never ``pyplot``, never ``rcParams``), as the report's other figures. Each
picture has the whole plate (cam frame, mm) with the contact and the peak
marked, and a close-up of the contact in units of the Hertz half-width b,
the surface on top and depth downwards.
"""

from __future__ import annotations

import io

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure
from matplotlib.tri import Triangulation

from camcad._typing import FloatArray
from camcad.fea.results import FeaResult, StressCase

__all__ = ["stress_figure", "stress_figures"]

_DPI = 110
_SIZE = (9.6, 4.4)  # inches
_CMAP = "viridis"
# each quadratic triangle (corners 0, 1, 2; edge middles 3 = 01, 4 = 12, 5 = 02) as four linear ones
_SPLIT = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]])


def _triangulation(nodes: FloatArray, cells: np.ndarray) -> Triangulation:
    triangles = cells[:, _SPLIT].reshape(-1, 3)
    return Triangulation(nodes[:, 0], nodes[:, 1], triangles)


def stress_figure(result: FeaResult, index: int, *, title_text: str = "") -> bytes:
    """The PNG of load case ``index``: von Mises [MPa] on the plate, and the contact close up.

    ``title_text`` is shown above the picture as given (the caller cleans it for the figure).
    """
    sc: StressCase = result.cases[index]
    case = sc.case
    vm = sc.von_mises
    fig = Figure(figsize=_SIZE, dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    whole, close = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.15, 1.0]})
    tri = _triangulation(result.nodes, result.cells)
    top = max(float(vm.max()), 1e-12)
    # the whole plate on a log scale: the contact's peak and the bore's stresses differ by decades
    log_levels = np.geomspace(top * 1e-3, top, 31)
    overall = whole.tricontourf(
        tri, np.clip(vm, log_levels[0], top), levels=log_levels, cmap=_CMAP, norm=LogNorm(log_levels[0], top)
    )
    levels = np.linspace(0.0, top, 41)
    cx, cy = case.point
    nx, ny = case.normal
    reach = float(np.abs(result.nodes).max())
    whole.annotate(
        "",
        xy=(cx, cy),
        xytext=(cx + 0.18 * reach * nx, cy + 0.18 * reach * ny),
        arrowprops={"arrowstyle": "-|>", "color": "#c0392b", "lw": 1.6},
    )
    px, py = sc.peak.point
    whole.plot([px], [py], marker="x", color="#ffffff", markersize=7, mew=2.0)
    whole.set_aspect("equal")
    whole.set_xlim(-1.25 * reach, 1.25 * reach)
    whole.set_ylim(-1.25 * reach, 1.25 * reach)
    whole.set_xlabel("x [mm]", fontsize=9)
    whole.set_ylabel("y [mm]", fontsize=9)
    whole.tick_params(labelsize=8)
    whole.set_title(f"von Mises on the plate, peak {sc.peak.value:.1f} MPa (×)", fontsize=9.5)
    # the contact close up, in units of b: s along the tangent, depth along −normal
    b = case.half_width
    rel = result.nodes - np.asarray(case.point)
    s = rel @ np.asarray(case.tangent) / b
    z = rel @ np.asarray(case.normal) / b
    near = np.all(np.abs(np.stack((s, z)))[:, result.cells[:, :3]] < 6.0, axis=(0, 2))
    if np.any(near):
        cells = result.cells[near]
        local = Triangulation(s, z, cells[:, _SPLIT].reshape(-1, 3))
        filled = close.tricontourf(local, vm, levels=levels, cmap=_CMAP)
        bar = fig.colorbar(filled, ax=close, shrink=0.85)
        bar.set_label("von Mises [MPa]", fontsize=9)
        bar.ax.tick_params(labelsize=8)
    close.set_xlim(-3.0, 3.0)
    close.set_ylim(-3.0, 0.4)
    close.set_aspect("equal")
    close.axhline(0.0, color="#444444", linewidth=0.6)
    xs = np.linspace(-1.0, 1.0, 41)
    close.fill_between(xs, 0.0, 0.3 * np.sqrt(1.0 - xs**2), color="#c0392b", alpha=0.35, linewidth=0)
    if sc.peak.depth is not None:
        ps = (np.asarray(sc.peak.point) - np.asarray(case.point)) @ np.asarray(case.tangent) / b
        close.plot([ps], [-sc.peak.depth / b], marker="x", color="#ffffff", markersize=7, mew=2.0)
    close.set_xlabel("along the surface s / b", fontsize=9)
    close.set_ylabel("depth −z / b", fontsize=9)
    close.tick_params(labelsize=8)
    close.set_title(f"close up: b = {b * 1000.0:.1f} µm, p0 = {case.peak_pressure:.1f} MPa", fontsize=9)
    bar = fig.colorbar(overall, ax=whole, shrink=0.85, ticks=top * np.array([1e-3, 1e-2, 1e-1, 1.0]))
    bar.ax.set_yticklabels([f"{t:.3g}" for t in top * np.array([1e-3, 1e-2, 1e-1, 1.0])])
    bar.set_label("von Mises [MPa], log scale", fontsize=9)
    bar.ax.tick_params(labelsize=8)
    if title_text:
        fig.suptitle(title_text, fontsize=10)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=_DPI, metadata={"Software": None})
    return buf.getvalue()


def stress_figures(result: FeaResult) -> list[tuple[str, str, bytes]]:
    """(title, caption, PNG) for every load case, in the order of ``result.cases``."""
    out = []
    for i, sc in enumerate(result.cases):
        c = sc.case
        title = f"FE case {i + 1}: {c.label} at φ = {c.angle_deg:.1f}°"
        caption = (
            f"Contact force {c.force:.1f} N over {c.length:g} mm, drive torque {c.torque:.1f} N·mm"
            + (f", friction μ = {c.friction:g}" if c.friction else "")
            + f"; {result.plane.value.replace('stress', 'plane stress').replace('strain', 'plane strain')}. "
            f"Peak von Mises {sc.peak.value:.1f} MPa {sc.peak.where} (Hertz p0 {c.peak_pressure:.1f} MPa); "
            f"the key's flank: {sc.key_flank}. Fields of every case in stress.vtu "
            f"(case{i + 1}_von_mises_MPa, …)."
        )
        out.append((title, caption, stress_figure(result, i)))
    return out
