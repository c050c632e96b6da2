"""Breadth-first search for short arc splines inside a tolerance band.

Layer k holds the end states (curve sample, point, tangent) reachable with k
tangent-continuous single arcs from the start node. Each state's arcs are
screened against curve samples for every aim in the band at once; every arc
may end at any sample it still covers, and of all those ends each cell of
(normal offset, tangent error) keeps the one farthest along the curve. The
search stops at the first layer from which a measured biarc reaches the end
node, so it finds the fewest arcs its grid of states allows.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray
from camcad.errors import ArcSearchStallError
from camcad.toolpath.arcs.biarc import (
    CurveFn,
    Pieces,
    angle_of,
    arc_from_tangent,
    biarc_pieces,
    cross,
    curve_nodes,
    distance_to_pieces,
    measure_deviation,
    take_pieces,
)

__all__ = ["search_arcs"]

_TABLE_STEP = 2.0 * np.pi / 1024  # rad between curve samples the arcs are screened against
_AIMS = 20  # aimed samples per state
_AIM_OFFSETS = np.linspace(-0.9, 0.9, 7)  # × band: aims moved along the normal
_PROXY = 0.97  # × tolerance: band of the sampled screen (each kept arc is then measured)
_OFFSET_CELLS, _TURN_CELLS = 11, 6  # cells across the band; tangent cells each side of zero
_FINISH_RATIOS = np.array([0.5, 0.7, 1.0, 1.4, 2.0])
_CLOSE_TURN = 0.2  # rad: a closing biarc may turn this much more than the curve (no loops)
_MAX_LAYERS = 2000


def _left(t: FloatArray) -> FloatArray:
    return np.stack((-t[..., 1], t[..., 0]), axis=-1)


@dataclass(frozen=True, slots=True)
class _Layer:
    """End states after k arcs: sample index, point, tangent, parent state and the arc there."""

    j: np.ndarray
    p: FloatArray
    t: FloatArray
    parent: np.ndarray
    arc: Pieces | None
    dev: FloatArray


def _single(lo: FloatArray, hi: FloatArray, p: FloatArray, t: FloatArray, q: FloatArray) -> Pieces:
    """One arc per interval (from p along t to q), then an empty second piece at q."""
    center, radius, ccw, line = arc_from_tangent(p, t, q)
    zero = np.zeros_like(radius)
    return Pieces(
        lo=lo, hi=hi, start=np.stack((p, q), axis=1), end=np.stack((q, q), axis=1),
        center=np.stack((center, q), axis=1), r_start=np.stack((radius, zero), axis=1),
        r_end=np.stack((radius, zero), axis=1), ccw=np.stack((ccw, np.zeros_like(ccw)), axis=1),
        line=np.stack((line, np.ones_like(line)), axis=1),
    )  # fmt: skip


def _table(a: float, b: float, soft: Sequence[float]) -> tuple[FloatArray, np.ndarray]:
    """φ samples from a to b with every soft node among them, and the indices that stop an arc."""
    cuts = [a, *[s for s in soft if a < s < b], b]
    parts, stops = [], []
    count = 0
    for lo, hi in itertools.pairwise(cuts):
        m = max(4, math.ceil((hi - lo) / _TABLE_STEP))
        parts.append(np.linspace(lo, hi, m + 1)[:-1])
        count += m
        stops.append(count)
    return np.concatenate([*parts, [b]]), np.asarray(stops)


def _screen(
    j: np.ndarray,
    p: FloatArray,
    t: FloatArray,
    limit: np.ndarray,
    pts: FloatArray,
    nrm: FloatArray,
    band: float,
    width: int,
) -> tuple[FloatArray, np.ndarray, FloatArray]:
    """Aimed arcs from states (s,) screened on the next ``width`` samples.

    Returns curvatures (s, k), reach (s, k) as a window index (−1: none) and
    the window samples (s, width, 3) seen from each state: a = w·t, b = w·n
    and |w|² (for :func:`_ends`).

    An arc from a state (point p, tangent t) is fixed by its curvature κ, and
    its signed distance from a sample w grows with κ, so each sample admits
    an interval of curvatures (:func:`_admissible`); an arc stays in the band
    up to a sample exactly while κ lies in the intersection of the intervals
    so far. Those intersections are running maxima and minima along the
    window, so every arc's reach is two binary searches (:func:`_first_out`)
    instead of a walk along its samples: the same reach, found in
    O(width + arcs · log width) per state.
    """
    n = pts.shape[0] - 1
    idx = np.minimum(j[:, None] + np.arange(1, width + 1)[None, :], n)
    room = np.maximum(np.minimum(limit - j, width), 0)  # samples up to the state's stop
    frac = (np.arange(_AIMS) + 1.0) / _AIMS
    e = np.minimum(j[:, None] + np.maximum(np.rint(frac[None, :] * room[:, None]).astype(int), 1), n)
    q = pts[e][:, :, None, :] + (_AIM_OFFSETS * band)[None, None, :, None] * nrm[e][:, :, None, :]
    w = q - p[:, None, None, :]
    kappa = 2.0 * cross(t[:, None, None, :], w) / np.maximum(np.sum(w * w, axis=-1), 1e-300)
    kappa = kappa.reshape(j.size, -1)
    w = pts[idx] - p[:, None, :]
    abw = np.stack(
        (np.einsum("swi,si->sw", w, t), np.einsum("swi,si->sw", w, _left(t)), np.sum(w * w, axis=-1))
    )  # (3, s, width): a = w·t, b = w·n, |w|²
    lo, hi = _admissible(*abw, band)
    first = _first_out(np.maximum.accumulate(lo, axis=1), np.minimum.accumulate(hi, axis=1), kappa)
    # an arc's reach ends before its first sample outside the band, or at its state's stop
    reach = np.minimum(first, room[:, None]) - 1
    return kappa, reach, abw


def _admissible(a: FloatArray, b: FloatArray, ww: FloatArray, band: float) -> tuple[FloatArray, FloatArray]:
    """The curvatures [lo, hi] (1/mm) of the arcs from a state that pass within ``band`` of each sample.

    The arc of curvature κ through the state's point along its tangent has
    the signed distance :func:`_gap` from a sample at w (w·t = a, w·n = b),
    which grows with κ; it equals δ at κ = 2(b + δ)/(|w|² − δ²), so the band
    |gap| ≤ band is κ between the values at δ = ∓band (a sample within the
    band of the point itself bounds nothing). A sample behind the start
    (a ≤ 0) is passed only beyond the arc's half turn, κ·b > 1/2.
    """
    den = ww - band * band
    far = den > 0.0
    safe = np.where(far, den, 1.0)
    lo = np.where(far, 2.0 * (b - band) / safe, -np.inf)
    hi = np.where(far, 2.0 * (b + band) / safe, np.inf)
    behind = a <= 0.0
    with np.errstate(divide="ignore"):
        half = 0.5 / b
    lo = np.where(behind & (b > 0.0), np.maximum(lo, half), lo)
    hi = np.where(behind & (b < 0.0), np.minimum(hi, half), hi)
    lo = np.where(behind & (b == 0.0), np.inf, lo)
    return lo, hi


def _first_out(lo: FloatArray, hi: FloatArray, kappa: FloatArray) -> np.ndarray:
    """Per row, the first window index where κ leaves [lo, hi] (nested: lo rising, hi falling).

    All rows are searched at once: each value is squashed monotonically into
    (0, 1) by arctan and shifted by twice its row number, so the rows lie
    one after another in one sorted array.
    """
    rows, width = lo.shape
    shift = 2.0 * np.arange(rows)[:, None]

    def key(x: FloatArray) -> FloatArray:
        return shift + (0.5 + np.arctan(x) / np.pi)

    base = np.arange(rows)[:, None] * width
    below = np.searchsorted(key(lo).ravel(), key(kappa).ravel(), side="right").reshape(kappa.shape) - base
    above = np.searchsorted(key(-hi).ravel(), key(-kappa).ravel(), side="right").reshape(kappa.shape) - base
    return np.minimum(below, above)


def _ends(kappa: FloatArray, reach: np.ndarray, abw: FloatArray, rows: np.ndarray) -> tuple[np.ndarray, ...]:
    """Every sample of the second half of each arc's reach, for the states ``rows`` (bool).

    Returns state and window index of each, in (state, aim, sample) order,
    the arc's curvature, its gap [mm] there, the sample's a = w·t, b = w·n,
    and whether it is the last sample the arc reaches.
    """
    states, aims = kappa.shape
    width = abw.shape[2]
    reach = np.where(rows[:, None], reach, -1).reshape(-1)
    first = (reach + 1) // 2
    count = np.maximum(reach - first + 1, 0)
    ends = np.cumsum(count)
    total = int(ends[-1]) if ends.size else 0
    w_i = np.arange(total) + np.repeat(first - (ends - count), count)
    last = np.zeros(total, dtype=bool)
    last[ends[count > 0] - 1] = True
    s_i = np.repeat(np.repeat(np.arange(states), aims), count)
    kk = np.repeat(kappa.reshape(-1), count)
    flat = s_i * width + w_i
    a, b, ww = (np.take(abw[k].reshape(-1), flat) for k in range(3))
    return s_i, w_i, kk, _gap(kk, b, ww), a, b, last


def _gap(k: FloatArray, b: FloatArray, ww: FloatArray) -> FloatArray:
    """Signed distance [mm] of samples (w·n = b, |w|² = ww) from the arc of curvature k."""
    return (k * ww - 2.0 * b) / (1.0 + np.sqrt(np.maximum(1.0 - 2.0 * (k * b) + k * k * ww, 0.0)))


def _expand(
    layer: _Layer,
    pts: FloatArray,
    tan_ang: FloatArray,
    nrm: FloatArray,
    stops: np.ndarray,
    band: float,
    width: int,
) -> tuple[np.ndarray, np.ndarray, FloatArray]:
    """Best arc end per (offset, tangent) cell: (state, end sample, curvature) for each cell reached.

    States whose arcs still cover the last sample of the window are screened
    again on a window twice as long.
    """
    n = pts.shape[0] - 1
    j, p, t = layer.j, layer.p, layer.t
    limit = stops[np.minimum(np.searchsorted(stops, j, side="right"), stops.size - 1)]
    todo = np.arange(j.size)
    found: list[tuple[np.ndarray, ...]] = []
    while todo.size:
        jj = j[todo]
        kappa, reach, abw = _screen(jj, p[todo], t[todo], limit[todo], pts, nrm, band, width)
        more = np.any(reach == width - 1, axis=1) & (jj + width < limit[todo]) & (width < n)
        s_i, w_i, kk, off, aa, bb, last = _ends(kappa, reach, abw, ~more)
        turn = np.arctan2(kk * aa, 1.0 - kk * bb)
        found.append((todo[s_i], kk, jj[s_i] + 1 + w_i, off, turn, last))
        todo, width = todo[more], 2 * width
    if len(found) == 1:  # most layers: one window was enough for every state
        s_i, kk, end, off, turn, last = found[0]
    else:
        s_i, kk, end, off, turn, last = (np.concatenate(f) for f in zip(*found, strict=True))
    if s_i.size == 0:
        return s_i, end, kk
    ang = angle_of(t)[s_i] + turn - tan_ang[end]
    ang = (ang + np.pi) % (2.0 * np.pi) - np.pi
    scale = max(float(np.quantile(np.abs(ang[last]), 0.9)) / _TURN_CELLS, 1e-12)
    ob = np.clip(((off / band + 1.0) * 0.5 * _OFFSET_CELLS).astype(int), 0, _OFFSET_CELLS - 1)
    ab = np.clip(np.rint(ang / scale).astype(int), -_TURN_CELLS, _TURN_CELLS) + _TURN_CELLS
    cell = ob * (2 * _TURN_CELLS + 1) + ab
    code = end.astype(np.int64) * s_i.size + np.arange(s_i.size)
    best = np.full(_OFFSET_CELLS * (2 * _TURN_CELLS + 1), -1, dtype=np.int64)
    np.maximum.at(best, cell, code)
    pick = best[best >= 0] % s_i.size
    return s_i[pick], end[pick], kk[pick]


def _arc_to(p: FloatArray, t: FloatArray, kappa: FloatArray, q: FloatArray) -> FloatArray:
    """The point of the arc (p, t, κ) abeam q (n, 2): where the ray from the centre to q meets it."""
    w = q - p
    a, b = np.sum(w * t, axis=-1), np.sum(w * _left(t), axis=-1)
    small = np.abs(kappa) < 1e-12
    k = np.where(small, 1.0, kappa)
    turn = np.where(small, 0.0, np.arctan2(kappa * a, 1.0 - kappa * b))
    along = np.where(small, a, np.sin(turn) / k)
    side = np.where(small, 0.0, (1.0 - np.cos(turn)) / k)
    return p + along[:, None] * t + side[:, None] * _left(t)


def _close(
    curve: CurveFn,
    layer: _Layer,
    phi: FloatArray,
    pts: FloatArray,
    tan: FloatArray,
    tan_ang: FloatArray,
    tol: float,
) -> tuple[int, Pieces, float] | None:
    """The measured biarc from a state of the layer onto the end node with the smallest deviation."""
    n = phi.size - 1
    m = _FINISH_RATIOS.size
    s = np.repeat(np.arange(layer.j.size), m)
    end, end_t = np.tile(pts[n], (s.size, 1)), np.tile(tan[n], (s.size, 1))
    ratio = np.tile(_FINISH_RATIOS, layer.j.size)
    at = np.rint(layer.j[s][:, None] + (n - layer.j[s])[:, None] * np.linspace(0.0, 1.0, 17)).astype(int)
    # a state on the end node (a closed loop's start, or an arc that lands there) gives a
    # degenerate biarc: NaN, or two null pieces
    with np.errstate(divide="ignore", invalid="ignore"):
        pc = biarc_pieces(
            phi[layer.j[s]], np.full(s.size, phi[n]), layer.p[s], layer.t[s], end, end_t, ratio=ratio
        )
        gap = distance_to_pieces(pts[at], pc).max(axis=1)
    # within tol of the node a biarc could loop unseen: only a state on the node's tangent closes there;
    # elsewhere the biarc may not turn much more than the curve does (no loops)
    apart = np.linalg.norm(layer.p[s] - end, axis=1) > tol
    aligned = (np.abs(cross(layer.t[s], end_t)) <= 1e-12) & (np.sum(layer.t[s] * end_t, axis=1) > 0.0)
    turn = np.abs(np.diff(np.unwrap(tan_ang[at], axis=1), axis=1)).sum(axis=1)
    with np.errstate(invalid="ignore"):
        plain = np.abs(pc.sweep()).sum(axis=1) <= turn + _CLOSE_TURN
    fits = np.nonzero((gap <= tol) & ((apart & plain) | aligned))[0]
    if fits.size == 0:
        return None
    with np.errstate(divide="ignore", invalid="ignore"):
        dev = measure_deviation(curve, take_pieces(pc, fits))
    dev = np.where(np.isfinite(dev), dev, np.inf)
    i = int(dev.argmin())
    if dev[i] > tol:
        return None
    return int(s[fits[i]]), take_pieces(pc, fits[i : i + 1]), float(dev[i])


def search_arcs(
    curve: CurveFn, a: float, b: float, tolerance: float, soft: Sequence[float] = ()
) -> tuple[list[Pieces], list[FloatArray]]:
    """Arcs from C(a) to C(b), tangent-continuous, on the curve's own tangents at both ends.

    An arc ends at every φ of ``soft`` (anywhere in the band there). Returns
    the pieces in φ order (single arcs, then the closing biarc) and their
    measured deviations.

    Raises
    ------
    ArcSearchStallError
        When no arc from some layer passes the measurement even in a band
        shrunk to 0.2 tol.
    """
    phi, stops = _table(a, b, soft)
    pts, tan = curve_nodes(curve, phi)
    tan_ang = angle_of(tan)
    nrm = _left(tan)
    layers = [_Layer(np.zeros(1, int), pts[:1], tan[:1], np.zeros(1, int), None, np.zeros(1))]
    width = 64
    for _ in range(_MAX_LAYERS):
        layer = layers[-1]
        near = np.nonzero(layer.j >= (stops[-2] if stops.size > 1 else 0))[0]
        near = near[np.argsort(-layer.j[near], kind="stable")[:24]]
        if near.size and (done := _close(curve, _pick(layer, near), phi, pts, tan, tan_ang, tolerance)):
            return _trace(layers, int(near[done[0]]), done[1], done[2])
        band = _PROXY * tolerance
        while True:
            s, end, kappa = _expand(layer, pts, tan_ang, nrm, stops, band, width)
            q = _arc_to(layer.p[s], layer.t[s], kappa, pts[end])
            pc = _single(phi[layer.j[s]], phi[end], layer.p[s], layer.t[s], q)
            dev = measure_deviation(curve, pc) if s.size else np.zeros(0)
            keep = dev <= tolerance
            if keep.any():
                break
            if band < 0.2 * tolerance:
                raise ArcSearchStallError("arc search stalled")
            band *= 0.8
        s, end, kappa, dev = s[keep], end[keep], kappa[keep], dev[keep]
        pc = take_pieces(pc, keep)
        turn = 2.0 * np.arctan2(
            cross(layer.t[s], q[keep] - layer.p[s]), np.sum((q[keep] - layer.p[s]) * layer.t[s], axis=-1)
        )
        t2 = np.cos(turn)[:, None] * layer.t[s] + np.sin(turn)[:, None] * _left(layer.t[s])
        layers.append(_Layer(end, q[keep], t2, s, pc, dev))
        width = max(32, int(1.5 * np.median(end - layer.j[s])))
    raise ArcSearchStallError("arc search did not close")  # pragma: no cover


def _pick(layer: _Layer, keep: np.ndarray) -> _Layer:
    return _Layer(layer.j[keep], layer.p[keep], layer.t[keep], layer.parent[keep], None, layer.dev[keep])


def _trace(
    layers: list[_Layer], state: int, close: Pieces, dev: float
) -> tuple[list[Pieces], list[FloatArray]]:
    pieces, devs = [close], [np.array([dev])]
    for layer in reversed(layers[1:]):
        assert layer.arc is not None
        pieces.append(take_pieces(layer.arc, np.array([state])))
        devs.append(layer.dev[state : state + 1])
        state = int(layer.parent[state])
    return pieces[::-1], devs[::-1]
