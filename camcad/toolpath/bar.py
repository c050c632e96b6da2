"""The tool path of a linear cam's bar: a straight profile cut along its open edge on an XY mill.

The bar's blank is squared beforehand; the program mills its top edge, the
cam, through the bar's thickness: roughing passes at the tool radius plus
the stock to leave, one per ``step_down`` level, then one finishing pass at
the tool radius, each along the exact offset curve ``cam.offset_curve(φ, r)`` from
one end of the bar to the other, entering and leaving along the edge's end
tangents outside the bar. Climb milling (the material on the tool's left
with a clockwise spindle) runs from the end x0 + L to the start x0,
conventional the other way.

The offset curve is written as G1 chords chosen greedily on a dense exact
sampling so that no sample lies farther than the tolerance from its chord;
the deviation reported is measured the same way, after rounding to the
written 4 decimals.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from camcad._typing import FloatArray
from camcad.angles import TWO_PI
from camcad.geometry.cam import Cam
from camcad.geometry.families import Bar
from camcad.geometry.tool import check_tool
from camcad.knobs import Knob
from camcad.toolpath.passes import Program
from camcad.toolpath.plan import Toolpath
from camcad.toolpath.spec import Direction, GcodeSpec

__all__ = ["DENSE_SAMPLES", "chord_path", "plan_bar"]

DENSE_SAMPLES = 20_001
"""Exact samples of the offset curve per cycle the chords are chosen on (and measured against)."""
_DECIMALS = 4  # the writer's coordinate digits


def _deviation(points: FloatArray, a: FloatArray, b: FloatArray) -> float:
    """The largest distance of ``points`` (n, 2) from the segment a–b [mm]."""
    d = b - a
    length2 = float(d @ d)
    t = np.clip(((points - a) @ d) / length2, 0.0, 1.0) if length2 > 0.0 else np.zeros(len(points))
    near = a + t[:, None] * d
    return float(np.max(np.hypot(*(points - near).T))) if len(points) else 0.0


def chord_path(points: FloatArray, tolerance: float) -> tuple[FloatArray, float]:
    """Vertices (m, 2) of a polyline through ``points``' ends within ``tolerance`` of all of them [mm].

    Greedy: from each vertex, the farthest sample whose chord keeps every
    sample in between within ``tolerance`` (found by doubling, then
    bisection). Returns the vertices rounded to the written decimals and
    the largest distance of any sample from the rounded polyline.
    """
    n = len(points)
    keep = [0]
    i = 0
    while i < n - 1:

        def fits(j: int, i: int = i) -> bool:
            return _deviation(points[i + 1 : j], points[i], points[j]) <= tolerance

        step = 1
        while i + 2 * step < n and fits(i + 2 * step):
            step *= 2
        lo, hi = i + step, min(n - 1, i + 2 * step)  # lo fits; hi may not
        if fits(hi):
            lo = hi
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (mid, hi) if fits(mid) else (lo, mid)
        keep.append(lo)
        i = lo
    vertices = np.round(points[keep], _DECIMALS)
    worst = max(
        _deviation(points[a : b + 1], vertices[k], vertices[k + 1])
        for k, (a, b) in enumerate(itertools.pairwise(keep))
    )
    return vertices, worst


def plan_bar(cam: Cam, bar: Bar, spec: GcodeSpec, *, name: str, thickness: float) -> Toolpath:
    """Plan the roughing and finishing passes along a linear cam's edge.

    Parameters
    ----------
    cam
        The linear cam; its exact offset ``cam.offset_curve(φ, r)`` is the tool path.
    bar
        The bar (its ends x0 and x0 + L [mm]).
    spec
        Milling settings (tool, tolerance, step down, stock, feeds, heights).
    name
        The program's name.
    thickness
        The bar's thickness [mm]; the cut goes to −(thickness + breakthrough).

    Raises
    ------
    GougeError
        Where a concave radius of the edge is smaller than the tool radius
        (:func:`camcad.geometry.tool.check_tool`).
    """
    r = spec.tool_radius
    concave = check_tool(cam, r)
    stock = (
        min(spec.stock_to_leave, max(0.0, 0.5 * (concave - r)))
        if math.isfinite(concave)
        else spec.stock_to_leave
    )
    phi = np.linspace(0.0, TWO_PI, DENSE_SAMPLES)
    climb = spec.direction is Direction.CLIMB
    lead = r + spec.tool_diameter  # the tool enters and leaves this far beyond the bar's ends [mm]

    def contour(distance: float) -> tuple[FloatArray, float, FloatArray, FloatArray]:
        curve = cam.offset_curve(phi, distance)
        pts = np.asarray(curve.point, dtype=float)
        path, worst = chord_path(pts[::-1] if climb else pts, spec.tolerance)
        ends = curve.tangent[[-1, 0]] if climb else curve.tangent[[0, -1]]
        sense = -1.0 if climb else 1.0  # the path runs against the curve's direction when climbing
        return path, worst, sense * ends[0], sense * ends[1]

    depth = thickness + spec.breakthrough
    n_levels = max(1, math.ceil(depth / spec.step_down - 1e-9))
    levels = tuple(round(-depth * k / n_levels, _DECIMALS) for k in range(1, n_levels + 1))
    prog = Program(spec.clearance_height)
    rough, _, t_in, t_out = contour(r + stock)
    finish, deviation, f_in, f_out = contour(r)

    def cut(path: FloatArray, t_in: FloatArray, t_out: FloatArray, z: float, text: str) -> None:
        start = np.round(path[0] - lead * t_in, _DECIMALS)
        end = np.round(path[-1] + lead * t_out, _DECIMALS)
        prog.rapid(z=spec.clearance_height)
        prog.rapid(x=float(start[0]), y=float(start[1]))
        prog.rapid(z=spec.safe_height)
        prog.comment(text)
        prog.line(z=z, feed=spec.plunge_feed)
        for x, y in (*path, end):
            prog.line(x=float(x), y=float(y), feed=spec.feed)

    for k, z in enumerate(levels, start=1):
        cut(
            rough, t_in, t_out, z, f"edge roughing pass {k}/{n_levels} at Z{z:.4f}, offset {r + stock:.4f} mm"
        )
    cut(finish, f_in, f_out, levels[-1], f"edge finishing pass at Z{levels[-1]:.4f}, offset {r:.4f} mm")
    prog.rapid(z=spec.clearance_height)
    x1 = bar.x0 + bar.length
    return Toolpath(
        name=name,
        spec=spec,
        thickness=thickness,
        bore=0.0,
        moves=tuple(prog.moves),
        levels=levels,
        final_depth=levels[-1],
        tab_top=None,
        rough_offset=r + stock,
        max_deviation=deviation,
        contour_blocks=len(finish) - 1,
        contour_arcs=len(finish) - 1,
        notes=(
            f"linear cam bar: open edge cut from X{bar.x0:.4f} to X{x1:.4f}, bottom at Y{bar.bottom:.4f}; "
            "the blank is squared beforehand",
            *([f"no tabs on a bar edge ({spec.name_of(Knob.TAB_COUNT)} ignored)"] if spec.tab_count else []),
        ),
    )
