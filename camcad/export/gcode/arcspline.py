"""Arc splines: tangent-continuous circular arcs fitted to an exact curve within a measured tolerance.

:func:`fit_curve` fits each φ-interval between break nodes with single arcs,
each leaving along the previous arc's end tangent and ending anywhere in the
tolerance band, chosen by a short beam search; the interval closes with a
measured biarc onto the break node, which stays on the curve with its exact
tangent. Where that march stalls it falls back to the biarc march of
:mod:`camcad.export.gcode.biarc`. Every accepted piece's two-way deviation is
measured (:func:`~camcad.export.gcode.biarc.measure_deviation`), so the
tolerance never rests on an estimate.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.export.gcode.biarc import (
    _MAX_STEPS,
    CurveFn,
    Pieces,
    _arc_from_tangent,
    _biarc_march,
    _cross,
    _dot,
    _node,
    _take,
    biarc_pieces,
    concat_pieces,
    measure_deviation,
)

__all__ = ["fit_curve"]


# ---------------------------------------------------------------------------
# arc spline: single arcs, each leaving along the previous one's end tangent

_TABLE_STEP = 2.0 * np.pi / 1024  # rad between the curve samples a march step checks against
_AIMS, _AIM_OFFSETS = 24, np.linspace(-0.9, 0.9, 5)  # arcs aimed at window samples ± offsets × tol
_PROXY = 0.97  # × tolerance: band for the sampled channel check (each accepted arc is then measured)
_TOP, _FRACTIONS = 16, (1.0, 0.85, 0.7)  # lookahead: longest arcs, ended at these fractions of reach
_BEAM = 2
_FINISH_RATIOS = np.array([0.5, 0.7, 1.0, 1.4, 2.0])


def _left(t: FloatArray) -> FloatArray:
    return np.stack((-t[..., 1], t[..., 0]), axis=-1)


def _circle_gap(
    p: FloatArray, t: FloatArray, kappa: FloatArray, q: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Signed distance (s, k, w) [mm] of samples q (s, w, 2) from the circles leaving p (s, 2)
    along t (s, 2) with curvature κ (s, k), and whether each sample lies ahead of p.

    With w = q − p: (κ|w|² − 2 w·n) / (1 + √(1 − 2κ w·n + κ²|w|²)), stable as κ → 0.
    """
    w = q - p[:, None, :]
    a = _dot(w, t[:, None, :])[:, None, :]
    b = _dot(w, _left(t)[:, None, :])[:, None, :]
    ww = _dot(w, w)[:, None, :]
    k = kappa[:, :, None]
    den = 1.0 + np.sqrt(np.maximum(1.0 - 2.0 * k * b + k * k * ww, 0.0))
    return (k * ww - 2.0 * b) / den, (a > 0.0) | (k * b > 0.5)


def _aimed(
    p: FloatArray, t: FloatArray, pts: FloatArray, nrm: FloatArray, first: np.ndarray, tol: float
) -> FloatArray:
    """Curvatures (s, k) of arcs from p along t through samples ahead of ``first``, moved along the normal."""
    span = pts.shape[1] - 1 - first
    frac = ((np.arange(_AIMS) + 1.0) / _AIMS) ** 1.5
    e = np.minimum(first[:, None] + np.maximum((frac * span[:, None]).astype(int), 1), pts.shape[1] - 1)
    q = (
        np.take_along_axis(pts, e[:, :, None], axis=1)[:, :, None, :]
        + (_AIM_OFFSETS * tol)[None, None, :, None]
        * np.take_along_axis(nrm, e[:, :, None], axis=1)[:, :, None, :]
    )
    w = q - p[:, None, None, :]
    kappa = 2.0 * _cross(t[:, None, None, :], w) / np.maximum(_dot(w, w), 1e-300)
    return kappa.reshape(p.shape[0], -1)


def _reach(
    p: FloatArray, t: FloatArray, kappa: FloatArray, pts: FloatArray, first: np.ndarray, tol: float
) -> np.ndarray:
    """Last sample index (s, k) that each arc keeps within ``tol`` (samples up to ``first`` skipped)."""
    gap, ahead = _circle_gap(p, t, kappa, pts)
    skip = np.arange(pts.shape[1])[None, None, :] <= first[:, None, None]
    bad = ~skip & ((np.abs(gap) > tol) | ~ahead)
    return np.where(bad.any(axis=2), bad.argmax(axis=2), pts.shape[1]) - 1


def _arc_to(p: FloatArray, t: FloatArray, kappa: FloatArray, q: FloatArray) -> FloatArray:
    """The point of the arc (p, t, κ) abeam q (n, 2): where the ray from the centre to q meets it."""
    w = q - p
    a, b = _dot(w, t), _dot(w, _left(t))
    small = np.abs(kappa) < 1e-12
    k = np.where(small, 1.0, kappa)
    turn = np.where(small, 0.0, np.arctan2(kappa * a, 1.0 - kappa * b))
    along = np.where(small, a, np.sin(turn) / k)
    side = np.where(small, 0.0, (1.0 - np.cos(turn)) / k)
    return p + along[:, None] * t + side[:, None] * _left(t)


def _single_arcs(lo: FloatArray, hi: FloatArray, p: FloatArray, t: FloatArray, q: FloatArray) -> Pieces:
    """One arc per interval (from p along t to q), then an empty second piece at q."""
    center, radius, ccw, line = _arc_from_tangent(p, t, q)
    zero = np.zeros_like(radius)
    return Pieces(
        lo=lo, hi=hi, start=np.stack((p, q), axis=1), end=np.stack((q, q), axis=1),
        center=np.stack((center, q), axis=1), r_start=np.stack((radius, zero), axis=1),
        r_end=np.stack((radius, zero), axis=1), ccw=np.stack((ccw, np.zeros_like(ccw)), axis=1),
        line=np.stack((line, np.ones_like(line)), axis=1),
    )  # fmt: skip


def _end_tangent(pc: Pieces, t: FloatArray) -> FloatArray:
    """Unit tangent at the end of the first piece (t for a line)."""
    rad = pc.end[0, 0] - pc.center[0, 0]
    if pc.line[0, 0]:
        return t
    tan = _left(rad) / np.linalg.norm(rad)
    return tan if pc.ccw[0, 0] else -tan


def _lookahead(
    p: FloatArray, t: FloatArray, pts: FloatArray, nrm: FloatArray, tol: float
) -> list[tuple[int, int, float]]:
    """Arcs from (p, t) over window samples: (two-arc reach, end index, κ), best first."""
    one = np.zeros(1, dtype=int)
    kappa = _aimed(p[None], t[None], pts[None], nrm[None], one, tol)
    reach = _reach(p[None], t[None], kappa, pts[None], one, tol)[0]
    best = np.argsort(-reach, kind="stable")[:_TOP]
    best = best[reach[best] >= 1]
    if best.size == 0:
        return []
    ends = np.maximum(np.rint(np.outer(reach[best], _FRACTIONS)).astype(int), 1).ravel()
    k1 = np.repeat(kappa[0, best], len(_FRACTIONS))
    s = k1.size
    q = _arc_to(np.tile(p, (s, 1)), np.tile(t, (s, 1)), k1, pts[ends])
    rad = q - p
    # end tangent: t turned by the arc's angle, 2·atan2(t × w, t · w) for chord w
    ang = 2.0 * np.arctan2(_cross(t, rad), _dot(rad, t))
    t2 = np.cos(ang)[:, None] * t + np.sin(ang)[:, None] * _left(t)
    window = np.broadcast_to(pts, (s, *pts.shape))
    k2 = _aimed(q, t2, window, np.broadcast_to(nrm, (s, *nrm.shape)), ends, tol)
    two = _reach(q, t2, k2, window, ends, tol).max(axis=1)
    order = np.lexsort((-ends, -two))
    return [(int(two[i]), int(ends[i]), float(k1[i])) for i in order]


def _arc_spline(
    curve: CurveFn, a: float, b: float, tolerance: float
) -> tuple[list[Pieces], list[FloatArray]]:
    """Arcs from C(a) to C(b), tangent-continuous, ending on the curve's own tangents at both ends.

    A beam search over single arcs: each leaves along the previous one's end
    tangent, and the search keeps the few end states whose next arc reaches
    farthest. Arcs are screened against curve samples, then measured; the
    interval closes with a biarc onto C(b) once one fits.
    """
    n = max(16, math.ceil((b - a) / _TABLE_STEP))
    phi = np.linspace(a, b, n + 1)
    pts, tan = _node(curve, phi)
    nrm = _left(tan)
    # state: (sample index, point, tangent, pieces, deviations, window)
    states: list[tuple[int, FloatArray, FloatArray, list[Pieces], list[FloatArray], int]] = [
        (0, pts[0], tan[0], [], [], 64)
    ]
    band = _PROXY * tolerance
    m = _FINISH_RATIOS.size
    for _ in range(_MAX_STEPS):
        finished = []
        for j, p, t, done, devs, _w in states:
            pc = biarc_pieces(
                np.full(m, phi[j]), np.full(m, b), np.tile(p, (m, 1)), np.tile(t, (m, 1)),
                np.tile(pts[n], (m, 1)), np.tile(tan[n], (m, 1)), ratio=_FINISH_RATIOS,
            )  # fmt: skip
            dev = measure_deviation(curve, pc)
            k = int(dev.argmin())
            if dev[k] <= tolerance:
                finished.append((float(dev[k]), [*done, _take(pc, np.array([k]))], [*devs, dev[k : k + 1]]))
        if finished:
            _, done, devs = min(finished, key=lambda f: f[0])
            return done, devs
        cands = []
        for i, (j, p, t, _d, _v, win) in enumerate(states):
            while True:
                hi = min(n, j + win)
                moves = _lookahead(p, t, pts[j : hi + 1], nrm[j : hi + 1], band)
                if hi == n or not moves or moves[0][0] < hi - j:
                    break
                win *= 2
            cands += [(j + two, j + end, i, kappa) for two, end, kappa in moves]
        cands.sort(key=lambda c: (-c[0], -c[1]))
        new, seen = [], set()
        for _two, end, i, kappa in cands:
            if len(new) == _BEAM:
                break
            if (end, kappa) in seen:
                continue
            seen.add((end, kappa))
            j, p, t, done, devs, _w = states[i]
            q = _arc_to(p[None], t[None], np.array([kappa]), pts[end][None])
            pc = _single_arcs(phi[j : j + 1], phi[end : end + 1], p[None], t[None], q)
            dev = measure_deviation(curve, pc)
            if dev[0] <= tolerance:
                win = max(64, 3 * (end - j))
                new.append((end, pc.end[0, 0], _end_tangent(pc, t), [*done, pc], [*devs, dev], win))
        if new:
            states, band = new, _PROXY * tolerance
        elif band > 0.2 * tolerance:
            band *= 0.8
        else:
            raise ValueError("arc spline stalled")
    raise ValueError("arc spline did not close")  # pragma: no cover


def fit_curve(
    curve: CurveFn,
    breaks: Sequence[float] | FloatArray,
    tolerance: float,
    *,
    arcs: bool = True,
) -> tuple[Pieces, FloatArray]:
    """Fit a tangent-continuous arc spline (or chords) to C(φ) between sorted φ-breaks within a tolerance.

    Parameters
    ----------
    curve
        The exact curve C(φ) with its derivatives; tangents C′/|C′| must be
        continuous inside each break interval.
    breaks
        (k + 1,) strictly increasing φ [rad]: points every fit must pass
        through (motion breakpoints, the start angle, tab edges).
    tolerance
        Two-way deviation allowed for each interval [mm].
    arcs
        True for arcs, False for straight chords (the G1-only comparison).

    Returns
    -------
    (Pieces, FloatArray)
        The accepted pieces in φ order and their measured deviations (n,) [mm].
        An interval holds one arc (and an empty second piece) or a biarc.

    Raises
    ------
    ValueError
        When an interval shorter than 1e-9 rad still misses the tolerance
        (a corner or cusp of the curve).

    Notes
    -----
    With arcs, each break interval is an arc spline (in the spirit of Meek &
    Walton 1992, who fit G1 arc splines to a tolerance channel): single arcs,
    each leaving along the previous arc's end tangent and ending anywhere
    within the band, chosen by a beam search with one step of lookahead
    (the end state whose next arc reaches farthest), closed by a biarc onto
    the break node, which stays on the curve with the curve's tangent. An
    interval where that stalls falls back to a greedy biarc march: from the
    current node it measures the fits ending on the curve at a geometric
    ladder of angles, then tries up to 1.8 times as far with the end node
    moved inside the band (±0.4 tol along the normal, tangent turned by
    ±2 tol/chord) and the joint moved (d₁/d of 0.75 or 1.33). Chords use
    that march. Every accepted interval has been measured
    (:func:`measure_deviation`), so the tolerance does not rest on an
    error estimate.
    """
    edges = np.asarray(breaks, dtype=float)
    if not arcs:
        return _biarc_march(curve, edges, tolerance, arcs=False)
    parts: list[Pieces] = []
    devs: list[FloatArray] = []
    for a, b in itertools.pairwise(edges):
        try:
            done, dev = _arc_spline(curve, float(a), float(b), tolerance)
        except ValueError:
            fallback, fdev = _biarc_march(curve, np.array([a, b]), tolerance, arcs=True)
            done, dev = [fallback], [fdev]
        parts += done
        devs += dev
    out = concat_pieces(parts)
    dev_all = np.concatenate(devs)[np.argsort(np.concatenate([p.lo for p in parts]), kind="stable")]
    readonly(dev_all)
    return out, dev_all
