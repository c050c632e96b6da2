"""Arc splines: tangent-continuous circular arcs fitted to an exact curve within a measured tolerance.

:func:`fit_arc_spline` fits each φ-interval between break nodes with single arcs,
each leaving along the previous arc's end tangent and ending anywhere in the
tolerance band, found by the layered search of
:mod:`camcad.toolpath.arcs.search`; the interval closes with a measured
biarc onto the break node, which stays on the curve with its exact tangent
(a closed curve without breaks may instead close with one arc onto its own
first arc). Where that search stalls it falls back to the biarc march of
:mod:`camcad.toolpath.arcs.march`. Every accepted piece's two-way deviation is
measured (:func:`~camcad.toolpath.arcs.biarc.measure_deviation`), so the
tolerance never rests on an estimate.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import ArcSearchStallError
from camcad.toolpath.arcs.biarc import CurveFn, Pieces, chord_pieces, concat_pieces, measure_deviation
from camcad.toolpath.arcs.march import march_arcs
from camcad.toolpath.arcs.refine import thin_loop
from camcad.toolpath.arcs.search import search_arcs

__all__ = ["fit_arc_spline"]


def fit_arc_spline(
    curve: CurveFn,
    breaks: Sequence[float] | FloatArray,
    tolerance: float,
    *,
    arcs: bool = True,
    closed: bool = False,
    fewest_arcs: bool = False,
    straight: Sequence[bool] = (),
) -> tuple[Pieces, FloatArray]:
    """Fit a tangent-continuous arc spline (or chords) to C(φ) between sorted φ-breaks within a tolerance.

    Parameters
    ----------
    curve
        The exact curve C(φ) with its derivatives; tangents C′/|C′| must be
        continuous inside each break interval.
    breaks
        (k + 1,) strictly increasing φ [rad]: points every fit must pass
        through (corners of the curve, the start angle).
    tolerance
        Two-way deviation allowed for each interval [mm].
    arcs
        True for arcs, False for straight chords (the G1-only comparison).
    closed
        True when C is closed (C(φ + 2π) = C(φ)) and ``breaks`` is [a, a + 2π]:
        the loop may then close with one arc onto its own first arc, so the
        path starts within the band near C(a) instead of on it (one arc
        fewer than a closing biarc); the pieces' φ-intervals then run from
        the start's φ to the same φ + 2π.
    fewest_arcs
        With ``closed``: refit the loop with fewer arcs where the measured
        deviation allows (:func:`~camcad.toolpath.arcs.refine.thin_loop`);
        the loop then starts abeam C(a).
    straight
        Per break interval, True where C is exactly a straight line there (a
        linear cam's dwell, :attr:`camcad.geometry.cam.Cam.straight_spans`);
        empty: none is. Such an interval is one line to C(b), measured like
        every piece: the search before it ends with one arc that lands on
        the line, touching it at or before C(a), where it can
        (:func:`~camcad.toolpath.arcs.search.search_arcs` with ``onto_line``),
        else with a biarc onto C(a) on the line's direction, and the line
        runs on from there; the search after it starts on C(b) with the
        line's direction. The spline stays tangent continuous.

    Returns
    -------
    (Pieces, FloatArray)
        The accepted pieces in φ order and their measured deviations (n,) [mm].
        An interval holds one arc (and an empty second piece) or a biarc.

    Raises
    ------
    ValueError
        When an interval shorter than 1e-9 rad still misses the tolerance
        (a corner or cusp of the curve), when ``straight`` does not have one
        flag per interval, or when an interval said to be straight is not
        (its line misses the tolerance).

    Notes
    -----
    With arcs, each break interval is an arc spline (in the spirit of Meek &
    Walton 1992, who fit G1 arc splines to a tolerance channel): single arcs,
    each leaving along the previous arc's end tangent and ending anywhere
    within the band. A breadth-first search keeps, after k arcs, the end
    state farthest along the curve in each cell of (normal offset, tangent
    error); arcs are screened on curve samples (0.97 tol) and checked between
    them, measured where that leaves doubt, and every arc of the path is
    measured; states exactly on the circles of stretches of constant
    curvature (dwells) are added. The interval closes with a measured biarc
    onto the break node, which stays on the curve with the curve's tangent,
    from the first layer where one fits, or, with ``closed``, with one arc
    onto the path's own first arc. An interval where that stalls falls back to a
    greedy biarc march: from the current node it measures the fits ending on the curve at a geometric
    ladder of angles, then tries up to 1.8 times as far with the end node
    moved inside the band (±0.4 tol along the normal, tangent turned by
    ±2 tol/chord) and the joint moved (d₁/d of 0.75 or 1.33). Chords use
    that march. Every accepted interval has been measured
    (:func:`~camcad.toolpath.arcs.biarc.measure_deviation`), so the tolerance does not rest on an
    error estimate.
    """
    edges = np.asarray(breaks, dtype=float)
    if not arcs:
        return march_arcs(curve, edges, tolerance, arcs=False)
    parts: list[Pieces] = []
    devs: list[FloatArray] = []
    loop = closed and edges.size == 2
    flags = tuple(straight) or (False,) * (edges.size - 1)
    if len(flags) != edges.size - 1:
        raise ValueError(f"{len(flags)} straight flags for {edges.size - 1} break intervals")
    for k, ((a, b), line) in enumerate(zip(itertools.pairwise(edges), flags, strict=True)):
        if line:
            # the line runs on from where the arcs before it landed on it (at or before C(a))
            landed = parts[-1] if parts else None
            piece, piece_dev = _line(curve, float(a), float(b), tolerance, landed)
            parts.append(piece)
            devs.append(piece_dev)
            continue
        onto = k + 1 < len(flags) and flags[k + 1]
        try:
            done, dev = search_arcs(curve, float(a), float(b), tolerance, closed=loop, onto_line=onto)
        except ArcSearchStallError:
            fallback, fdev = march_arcs(curve, np.array([a, b]), tolerance, arcs=True)
            done, dev = [fallback], [fdev]
        parts += done
        devs += dev
    out = concat_pieces(parts)
    dev_all = np.concatenate(devs)[np.argsort(np.concatenate([p.lo for p in parts]), kind="stable")]
    if fewest_arcs and loop and (fewer := thin_loop(curve, out, tolerance, float(edges[0]))):
        out, dev_all = fewer
    readonly(dev_all)
    return out, dev_all


def _line(
    curve: CurveFn, a: float, b: float, tolerance: float, before: Pieces | None
) -> tuple[Pieces, FloatArray]:
    """The line of a straight interval to C(b) [mm], and its measured deviation (1,) [mm].

    It starts at C(a), or where the pieces ``before`` it end when their last
    arc landed on the line ahead of C(a) (its φ-interval then starts abeam
    that point).
    """
    ends = np.array([a, b])
    pts, d1, _ = curve(ends)
    tan = d1 / np.linalg.norm(d1, axis=1)[:, None]
    if before is not None and float(before.hi[-1]) < a:
        pts = pts.copy()
        ends[0] = before.hi[-1]
        pts[0] = before.end[-1, 1]  # the landing arc's end (its second piece is empty)
    piece = chord_pieces(ends[:1], ends[1:], pts[:1], tan[:1], pts[1:], tan[1:])
    dev = measure_deviation(curve, piece)
    if not float(dev[0]) <= tolerance:
        raise ValueError(
            f"the interval {a:.6f}..{b:.6f} rad is not straight: its line is {dev[0]:.3g} mm off"
        )
    return piece, dev
