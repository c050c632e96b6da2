"""The greedy biarc march: the fallback of the arc-spline fit, and the G1-chord comparison.

From the current node of every φ-interval at once, a march step measures
the fits (biarcs, or chords) ending on the curve at a geometric ladder of
angles and keeps the farthest that passes; it then tries up to 1.8 times as
far with the end node moved inside the band (±0.4 tol along the normal,
tangent turned by ±2 tol/chord) and the joint moved (d₁/d of 0.75 or 1.33).
Every accepted piece has been measured with
:func:`~camcad.toolpath.arcs.biarc.measure_deviation`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.toolpath.arcs.biarc import (
    CurveFn,
    Pieces,
    biarc_pieces,
    chord_pieces,
    concat_pieces,
    curve_nodes,
    measure_deviation,
    take_pieces,
)

__all__ = ["march_arcs"]

Builder = Callable[[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray], Pieces]

_LADDER = 40  # candidate end angles per march step
_RATIOS = (0.75, 1.0, 1.33)
# stage 2 of a march step: reach × these, with the end node moved by
# (δ/tol, θ·chord/tol): δ along the normal, θ a turn of the end tangent
_GROW = np.array([1.0, 1.06, 1.12, 1.19, 1.26, 1.34, 1.42, 1.5, 1.6, 1.8])
_SHIFTS = np.array([(d, t, q) for d in (-0.4, 0.0, 0.4) for t in (-2.0, 0.0, 2.0) for q in _RATIOS])
_MAX_STEPS = 100_000
_MIN_SPAN = 1e-9  # rad: an interval this short that still fails cannot be fitted
_RUNGS = 2.0 ** (-np.arange(_LADDER) / 4.0)  # 1 … ~1/1000 of the remaining span


@dataclass(slots=True)
class _Front:
    """Where each interval's march stands: node φ [rad], point, unit tangent, and the span scale."""

    cur: FloatArray
    stop: FloatArray
    p: FloatArray
    t: FloatArray
    scale: FloatArray


def _ladder_reach(
    curve: CurveFn, builder: Builder, front: _Front, active: np.ndarray, span: FloatArray, tolerance: float
) -> tuple[np.ndarray, FloatArray]:
    """Stage 1: the farthest rung of the ladder whose fit, ending on the curve, passes.

    Returns the intervals (rows of ``front``) where one passed and how far
    it reached [rad]; intervals where none passed get a shorter ladder.
    """
    rep = np.repeat(active, _LADDER)
    b = np.minimum(front.cur[rep] + np.repeat(span, _LADDER) * np.tile(_RUNGS, active.size), front.stop[rep])
    p1, t1 = curve_nodes(curve, b)
    dev = measure_deviation(curve, builder(front.cur[rep], b, front.p[rep], front.t[rep], p1, t1))
    ok = (dev <= tolerance).reshape(-1, _LADDER)
    found = ok.any(axis=1)
    front.scale[active[~found]] *= _RUNGS[-1]
    rows = active[found]
    reach = b.reshape(-1, _LADDER)[found, ok[found].argmax(axis=1)] - front.cur[rows]
    return rows, reach


def _reach_further(
    curve: CurveFn,
    front: _Front,
    rows: np.ndarray,
    reach: FloatArray,
    tolerance: float,
    *,
    arcs: bool,
) -> tuple[Pieces, FloatArray]:
    """Stage 2: reach a little farther with the end node moved within the band; advance the front.

    Returns the accepted pieces of the intervals ``rows`` and their measured deviations.
    """
    shifts = _SHIFTS if arcs else np.array([[0.0, 0.0, 1.0]])
    grow = np.repeat(rows, _GROW.size * len(shifts))
    cur = front.cur[grow]
    b2 = np.minimum(cur + np.repeat(np.outer(reach, _GROW).ravel(), len(shifts)), front.stop[grow])
    shift = np.tile(shifts, (rows.size * _GROW.size, 1))
    p2, t2 = curve_nodes(curve, b2)
    chord = np.maximum(np.linalg.norm(p2 - front.p[grow], axis=1), 1e-12)
    at_stop = b2 >= front.stop[grow]
    delta = np.where(at_stop, 0.0, shift[:, 0] * tolerance)
    theta = np.where(at_stop, 0.0, shift[:, 1] * tolerance / chord)
    p2 = p2 + delta[:, None] * np.column_stack((-t2[:, 1], t2[:, 0]))
    c, s_ = np.cos(theta), np.sin(theta)
    t2 = np.column_stack((c * t2[:, 0] - s_ * t2[:, 1], s_ * t2[:, 0] + c * t2[:, 1]))
    if arcs:
        pieces = biarc_pieces(cur, b2, front.p[grow], front.t[grow], p2, t2, ratio=shift[:, 2])
    else:
        pieces = chord_pieces(cur, b2, front.p[grow], front.t[grow], p2, t2)
    dev = measure_deviation(curve, pieces)
    # the farthest passing candidate, the one with the least deviation among equals
    score = np.where(dev <= tolerance, b2 - cur - 1e-12 * dev / tolerance, -np.inf)
    pick = np.arange(rows.size) * (_GROW.size * len(shifts)) + score.reshape(rows.size, -1).argmax(axis=1)
    front.cur[rows], front.p[rows], front.t[rows] = b2[pick], p2[pick], t2[pick]
    front.scale[rows] = 1.0
    return take_pieces(pieces, pick), dev[pick]


def march_arcs(
    curve: CurveFn, edges: FloatArray, tolerance: float, *, arcs: bool
) -> tuple[Pieces, FloatArray]:
    """Greedy march of biarcs (or chords) with end nodes on or near the curve.

    Parameters
    ----------
    curve
        The exact curve C(φ).
    edges
        (k + 1,) increasing φ [rad]; every interval is marched from its start to its end.
    tolerance
        Two-way deviation allowed for each accepted piece [mm].
    arcs
        True for biarcs, False for straight chords.

    Returns
    -------
    (Pieces, FloatArray)
        The accepted pieces in φ order and their measured deviations (n,) [mm].

    Raises
    ------
    ValueError
        When an interval shorter than 1e-9 rad still misses the tolerance
        (a corner or cusp of the curve).
    """
    builder: Builder = biarc_pieces if arcs else chord_pieces
    cur = edges[:-1].copy()
    p, t = curve_nodes(curve, cur)
    front = _Front(cur=cur, stop=edges[1:].copy(), p=p, t=t, scale=np.ones_like(cur))
    done: list[Pieces] = []
    devs: list[FloatArray] = []
    for _ in range(_MAX_STEPS):
        active = np.flatnonzero(front.cur < front.stop)
        if active.size == 0:
            break
        span = (front.stop - front.cur)[active] * front.scale[active]
        if np.any(span < _MIN_SPAN):
            where = math.degrees(float(front.cur[active][np.argmin(span)]))
            raise ValueError(f"cannot fit the curve within {tolerance:g} mm near φ = {where:.3f}°")
        rows, reach = _ladder_reach(curve, builder, front, active, span, tolerance)
        if rows.size == 0:
            continue
        pieces, dev = _reach_further(curve, front, rows, reach, tolerance, arcs=arcs)
        done.append(pieces)
        devs.append(dev)
    else:  # pragma: no cover - needs a pathological curve
        raise ValueError(f"cannot fit the curve within {tolerance:g} mm in {_MAX_STEPS} steps")
    out = concat_pieces(done)
    dev_all = np.concatenate(devs)[np.argsort(np.concatenate([p.lo for p in done]), kind="stable")]
    readonly(dev_all)
    return out, dev_all
