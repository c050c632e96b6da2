"""The tool path of a linear cam's bar: a straight profile cut along its open edge on an XY mill.

The bar's blank is squared beforehand; the program mills its top edge, the
cam, through the bar's thickness: roughing passes at the tool radius plus
the stock to leave, one per ``step_down`` level, then one finishing pass at
the tool radius, each along the exact offset curve ``cam.offset_curve(φ, r)`` from
one end of the bar to the other, entering and leaving outside the bar on
straight G1 leads along the path's own end tangents.

Direction, by the plate's rule (:mod:`camcad.toolpath.plan`: M3 turns the
spindle clockwise seen from +Z, and climb milling has the part on the tool's
right, G41): the bar lies below the path, so climb runs towards +x, from
x0 to x0 + L, and conventional the other way.

The offset curve is an arc spline as on a plate (:func:`~camcad.toolpath.contour.fit_open_path`:
the layered arc search of :mod:`camcad.toolpath.arcs` on the open curve,
from the curve's start on its tangent to its end), fitted within the
plate's band (``_fit_tolerance`` of :mod:`camcad.toolpath.plan`), rounded to the
written 4 decimals with each arc's I/J from its rounded start, and measured
two-way against the exact curve after rounding; the roughing path is the
finishing arc spline offset by the stock, measured the same way. Each
dwell of the motion is a straight stretch of the edge and of its offsets
(:attr:`~camcad.geometry.cam.Cam.straight_spans`): its ends are break
nodes and it is cut as one line (G1) on the exact line to its end, from
its start or from before it where one arc lands on the line touching it;
the arcs beside it are tangent to it (``profile_arcs.dxf`` draws it as one
LINE from its start to its end).
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
from camcad.toolpath.contour import OpenPath, fit_open_path, offset_open_path, round_mm, round_point
from camcad.toolpath.passes import Program
from camcad.toolpath.plan import Toolpath, _fit_tolerance
from camcad.toolpath.spec import Direction, GcodeSpec

__all__ = ["plan_bar"]

_SAME_NODE = 1e-9  # rad: break nodes this close are one
_NO_REFIT = "the fewest-arcs refit thins closed contours only: the edge keeps the search's arcs"


def plan_bar(
    cam: Cam, bar: Bar, spec: GcodeSpec, *, name: str, thickness: float, arcs: bool = True
) -> Toolpath:
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
    arcs
        False writes the passes as G1 chords only, at the same tolerance
        (for comparison).

    Raises
    ------
    GougeError
        Where a concave radius of the edge is smaller than the tool radius
        (:func:`camcad.geometry.tool.check_tool`).
    DesignError
        When the tolerance is finer than 4-decimal output holds.
    """
    r = spec.tool_radius
    concave = check_tool(cam, r)
    stock = (
        min(spec.stock_to_leave, max(0.0, 0.5 * (concave - r)))
        if math.isfinite(concave)
        else spec.stock_to_leave
    )
    fit_tol = _fit_tolerance(spec.tolerance)
    breaks, straight = _breaks(cam)
    lead = r + spec.tool_diameter  # the tool enters and leaves this far beyond the bar's ends [mm]
    reverse = spec.direction is not Direction.CLIMB  # climb runs towards +x, with increasing φ
    finish = fit_open_path(
        cam, r, breaks, spec.tolerance, fit_tol, reverse=reverse, arcs=arcs, straight=straight
    )
    if stock <= 0.0:
        rough = finish
    elif (
        arcs
    ):  # the finishing arc spline offset by the stock (arcs stay arcs), measured; refitted if it misses
        rough = offset_open_path(cam, finish, r + stock, breaks, spec.tolerance, fit_tol, straight=straight)
    else:  # chords offset apart at their corners: fit them afresh
        rough = fit_open_path(cam, r + stock, breaks, spec.tolerance, fit_tol, reverse=reverse, arcs=False)

    depth = thickness + spec.breakthrough
    n_levels = max(1, math.ceil(depth / spec.step_down - 1e-9))
    levels = tuple(round_mm(-depth * k / n_levels) for k in range(1, n_levels + 1))
    prog = Program(spec.clearance_height)

    def cut(path: OpenPath, z: float, text: str) -> None:
        t_in, t_out = path.start_tangent, path.end_tangent
        start = round_point((path.start[0] - lead * t_in[0], path.start[1] - lead * t_in[1]))
        end = round_point((path.end[0] + lead * t_out[0], path.end[1] + lead * t_out[1]))
        prog.rapid(z=spec.clearance_height)
        prog.rapid(*start)
        prog.rapid(z=spec.safe_height)
        prog.comment(text)
        prog.line(z=z, feed=spec.plunge_feed)
        prog.line(*path.start, feed=spec.feed)  # the lead in, along the path's start tangent
        for st in path.steps:
            if st.center is None:
                prog.line(*st.end, feed=spec.feed)
            else:
                prog.arc(st.kind, *st.end, st.center, feed=spec.feed)
        prog.line(*end, feed=spec.feed)  # the lead out, along its end tangent

    for k, z in enumerate(levels, start=1):
        cut(rough, z, f"edge roughing pass {k}/{n_levels} at Z{z:.4f}, offset {r + stock:.4f} mm")
    cut(finish, levels[-1], f"edge finishing pass at Z{levels[-1]:.4f}, offset {r:.4f} mm")
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
        max_deviation=finish.max_deviation,
        contour_blocks=len(finish.steps),
        contour_arcs=len(finish.steps),  # no tabs split a bar's steps
        notes=(
            f"linear cam bar: open edge cut from X{bar.x0:.4f} to X{x1:.4f}, bottom at Y{bar.bottom:.4f}; "
            "the blank is squared beforehand",
            *([f"no tabs on a bar edge ({spec.name_of(Knob.TAB_COUNT)} ignored)"] if spec.tab_count else []),
            *([_NO_REFIT] if spec.fewest_arcs and arcs else []),
        ),
    )


def _breaks(cam: Cam) -> tuple[FloatArray, tuple[bool, ...]]:
    """The edge's break nodes φ [rad] and, per interval between them, whether the edge is straight there.

    The nodes are the edge's ends (a corner, a velocity jump, is refused
    earlier) and the ends of its straight stretches (the motion's dwells,
    :attr:`~camcad.geometry.cam.Cam.straight_spans`), each of which is cut
    as one line (G1) between the arcs.
    """
    nodes = [0.0, TWO_PI]
    spans = []
    for a, b in cam.straight_spans:
        lo, hi = max(a, 0.0), min(b, TWO_PI)
        # a span's end within 1e-9 rad of a node is that node (2π summed from the segments' spans)
        lo, hi = (next((n for n in nodes if abs(n - v) <= _SAME_NODE), v) for v in (lo, hi))
        if hi - lo > _SAME_NODE:
            spans.append((lo, hi))
            nodes += [lo, hi]
    edges = np.array(sorted(set(nodes)))
    straight = tuple(any(lo <= a and b <= hi for lo, hi in spans) for a, b in itertools.pairwise(edges))
    return edges, straight
