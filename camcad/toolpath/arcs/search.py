"""Breadth-first search for short arc splines inside a tolerance band.

Layer k holds the end states (curve sample, point, tangent) reachable with k
tangent-continuous single arcs from the start node. Each state's arcs are
screened against curve samples for every aim in the band at once; every arc
may end at any sample it still covers, and of all those ends each cell of
(normal offset, tangent error) keeps the one farthest along the curve. A
kept arc is measured when its gap between the samples leaves doubt, and
otherwise once it is on the path (:func:`_search`).
Stretches of constant curvature (a cam's dwells) add states: the arc from a
state that touches such a circle lands on it with the circle's tangent
(:func:`_onto_circles`), which the sampled aims hit only by chance. The
search stops at the first layer from which a measured biarc reaches the end
node, or, on a closed curve, one arc reaches back onto the path's own first
arc (:func:`_close_loop`), so it finds the fewest arcs its grid of states
allows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from camcad._typing import FloatArray
from camcad.errors import ArcSearchStallError
from camcad.toolpath.arcs.biarc import (
    CurveFn,
    Pieces,
    abeam,
    angle_of,
    biarc_pieces,
    circle_gap,
    concat_pieces,
    cross,
    distance_to_pieces,
    left_normal,
    measure_deviation,
    norm2,
    single_arcs,
    take_pieces,
)

__all__ = ["search_arcs"]

_TABLE_STEP = 2.0 * np.pi / 1024  # rad between curve samples the arcs are screened against
_AIMS = 14  # aimed samples per state
_AIM_OFFSETS = np.linspace(-0.9, 0.9, 5)  # × band: aims moved along the normal
_PROXY = 0.97  # × tolerance: band of the sampled screen
_OFFSET_CELLS, _TURN_CELLS = 15, 8  # cells across the band; tangent cells each side of zero
_FINISH_RATIOS = np.array([0.5, 0.7, 1.0, 1.4, 2.0])
_CLOSE_TURN = 0.2  # rad: a closing biarc may turn this much more than the curve (no loops)
_MAX_LAYERS = 2000
# samples per arc measuring a layer's arcs: the screen has checked every table sample of each arc
# already, and a written contour is measured again after rounding on 48 (the certificate)
_LAYER_SAMPLES = 16
# a layer's arc whose largest gap from the curve at these fractions of every table step it spans
# is at most _SURE × tolerance is kept unmeasured, and measured only if it ends up on the path
# (:func:`_search`). On the shipped samples at 1 and 5 µm every arc so kept measures at most
# 0.983 tol, and every arc the measurement rejects has a gap of 0.983 tol or more there; with
# midpoints alone, arcs of a sample or two that bulge near their ends slipped through at 1 µm
_BETWEEN = np.array([0.25, 0.5, 0.75])
_SURE = 0.97
_FIELDS = fields(Pieces)
_LOOP_STATES = 64  # farthest states of a layer tried for a loop closure
_CIRCLE_RUN = 4  # samples: a stretch of constant curvature at least this long is a circle to land on
_CIRCLE_SAME = 1e-6  # mm: samples whose centres and radii of curvature agree this closely share a circle
_CIRCLE_LARGEST = 1e6  # mm: a larger radius is a straight line, not a circle
_CIRCLE_STATES = 8  # states kept per layer on circles ahead
_SAME_CIRCLE = 1e-6  # |1 − κρ₁| below this, an arc that would touch a circle is the circle (_touching)


@dataclass(frozen=True, slots=True)
class _Layer:
    """End states after k arcs: sample index, point, tangent, parent state and the arc there."""

    j: np.ndarray
    p: FloatArray
    t: FloatArray
    parent: np.ndarray
    arc: Pieces | None
    dev: FloatArray  # mm, measured; NaN: kept on the samples' evidence (:func:`_between_samples`)
    at: FloatArray  # φ [rad] of the curve abeam each state (the sample's, or between samples)


def _table(a: float, b: float) -> FloatArray:
    """φ samples [rad] from a to b, about ``_TABLE_STEP`` apart."""
    return np.linspace(a, b, max(4, math.ceil((b - a) / _TABLE_STEP)) + 1)


def _screen(
    j: np.ndarray,
    p: FloatArray,
    t: FloatArray,
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
    room = np.maximum(np.minimum(n - j, width), 0)  # samples up to the end
    frac = (np.arange(_AIMS) + 1.0) / _AIMS
    e = np.minimum(j[:, None] + np.maximum(np.rint(frac[None, :] * room[:, None]).astype(int), 1), n)
    q = pts[e][:, :, None, :] + (_AIM_OFFSETS * band)[None, None, :, None] * nrm[e][:, :, None, :]
    w = q - p[:, None, None, :]
    kappa = 2.0 * cross(t[:, None, None, :], w) / np.maximum(np.sum(w * w, axis=-1), 1e-300)
    kappa = kappa.reshape(j.size, -1)
    w = pts[idx] - p[:, None, :]
    abw = np.stack(
        (np.einsum("swi,si->sw", w, t), np.einsum("swi,si->sw", w, left_normal(t)), np.sum(w * w, axis=-1))
    )  # (3, s, width): a = w·t, b = w·n, |w|²
    lo, hi = _admissible(*abw, band)
    first = _first_out(np.maximum.accumulate(lo, axis=1), np.minimum.accumulate(hi, axis=1), kappa)
    # an arc's reach ends before its first sample outside the band, or at the end
    reach = np.minimum(first, room[:, None]) - 1
    return kappa, reach, abw


def _admissible(a: FloatArray, b: FloatArray, ww: FloatArray, band: float) -> tuple[FloatArray, FloatArray]:
    """The curvatures [lo, hi] (1/mm) of the arcs from a state that pass within ``band`` of each sample.

    The arc of curvature κ through the state's point along its tangent has
    the signed distance :func:`~camcad.toolpath.arcs.biarc.circle_gap` from a sample at w (w·t = a, w·n = b),
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
    return s_i, w_i, kk, circle_gap(kk, b, ww), a, b, last


def _expand(
    layer: _Layer,
    pts: FloatArray,
    tan_ang: FloatArray,
    nrm: FloatArray,
    band: float,
    width: int,
) -> tuple[np.ndarray, np.ndarray, FloatArray]:
    """Best arc end per (offset, tangent) cell: (state, end sample, curvature) for each cell reached.

    States whose arcs still cover the last sample of the window are screened
    again on a window twice as long.
    """
    n = pts.shape[0] - 1
    j, p, t = layer.j, layer.p, layer.t
    todo = np.arange(j.size)
    found: list[tuple[np.ndarray, ...]] = []
    while todo.size:
        jj = j[todo]
        kappa, reach, abw = _screen(jj, p[todo], t[todo], pts, nrm, band, width)
        more = np.any(reach == width - 1, axis=1) & (jj + width < n) & (width < n)
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
    a, b = np.sum(w * t, axis=-1), np.sum(w * left_normal(t), axis=-1)
    small = np.abs(kappa) < 1e-12
    k = np.where(small, 1.0, kappa)
    turn = np.where(small, 0.0, np.arctan2(kappa * a, 1.0 - kappa * b))
    along = np.where(small, a, np.sin(turn) / k)
    side = np.where(small, 0.0, (1.0 - np.cos(turn)) / k)
    return p + along[:, None] * t + side[:, None] * left_normal(t)


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
            layer.at[s], np.full(s.size, phi[n]), layer.p[s], layer.t[s], end, end_t, ratio=ratio
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


def _land(
    curve: CurveFn, layer: _Layer, phi: FloatArray, pts: FloatArray, tan: FloatArray, tol: float
) -> tuple[int, Pieces, float] | None:
    """The measured arc from a state of the layer that lands on the line C(b) + λ·t_b at or before C(b).

    The line through the end node q₀ along its unit tangent u (left normal ν)
    is where the curve runs on straight (a linear cam's dwell). The arc from
    a state (p, t, left normal n) of curvature κ has its centre at p + n/κ;
    it touches the line travelling along u where its left normal is ν, at
    X = p + (n − ν)/κ, which lies on the line when κ = (1 − n·ν)/h with
    h = (p − q₀)·ν (the limit of :func:`_touching` for a circle of infinite
    radius). Of the arcs that land at or before q₀ (λ ≤ 0), ahead of their
    state, turn no more than the curve (:func:`_plain`) and pass the
    measurement, the one with the least deviation is taken.

    Returns the state, the arc (its φ-interval ending abeam X) and its
    deviation; None when no arc lands within ``tol``.
    """
    n = phi.size - 1
    q0, u = pts[n], tan[n]
    nu = left_normal(u[None, :])[0]
    p, t = layer.p, layer.t
    nl = left_normal(t)
    h = (p - q0) @ nu
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = (1.0 - nl @ nu) / h
        x = p + (nl - nu[None, :]) / kappa[:, None]
    along = (x - q0) @ u
    ok = np.isfinite(kappa) & np.all(np.isfinite(x), axis=1) & (np.abs(h) > 0.0) & (along <= 0.0)
    ok &= np.einsum("si,si->s", x - p, t) > 0.0  # ahead of the state
    ok &= np.linalg.norm(x - p, axis=1) > tol
    cand = np.flatnonzero(ok)
    if cand.size == 0:
        return None
    speed = float(np.linalg.norm(curve(phi[n : n + 1])[1][0]))
    phi_x, foot = abeam(curve, x[cand], phi[n] + along[cand] / speed)
    ok = (norm2(foot - x[cand]) <= tol) & (phi_x > layer.at[cand]) & (phi_x <= phi[n])
    cand, phi_x = cand[ok], phi_x[ok]
    # the arc runs from its state to X, the line on from there: its circle near the samples between
    land = np.clip(np.searchsorted(phi, phi_x), 0, n)
    ok = _near_samples(p[cand], t[cand], kappa[cand], pts, layer.j[cand], land, tol)
    cand, phi_x = cand[ok], phi_x[ok]
    if cand.size == 0:
        return None
    pc = single_arcs(layer.at[cand], phi_x, p[cand], t[cand], x[cand])
    plain = _plain(curve, pc)
    if not plain.any():
        return None
    cand, pc = cand[plain], take_pieces(pc, plain)
    # the farthest first: measure a few
    order = np.argsort(-pc.hi, kind="stable")[:_CIRCLE_STATES]
    cand, pc = cand[order], take_pieces(pc, order)
    with np.errstate(divide="ignore", invalid="ignore"):
        dev = measure_deviation(curve, pc)
    dev = np.where(np.isfinite(dev), dev, np.inf)
    i = int(dev.argmin())
    if dev[i] > tol:
        return None
    return int(cand[i]), take_pieces(pc, np.array([i])), float(dev[i])


def _near_samples(
    p: FloatArray,
    t: FloatArray,
    kappa: FloatArray,
    pts: FloatArray,
    j0: np.ndarray,
    j1: np.ndarray | int,
    tol: float,
) -> np.ndarray:
    """Whether the circles (p, t, κ) pass within ``tol`` of 7 curve samples evenly between samples j0 and j1.

    A cheap necessary condition for an arc from sample j0 to j1 to be within
    ``tol`` of the curve (its circle is), checked before any measurement.
    """
    idx = np.rint(j0[:, None] + (j1 - j0)[:, None] * np.linspace(0.0, 1.0, 9)[1:-1]).astype(int)
    w = pts[np.clip(idx, 0, pts.shape[0] - 1)] - p[:, None, :]
    b = np.einsum("swi,si->sw", w, left_normal(t))
    with np.errstate(invalid="ignore"):
        out: np.ndarray = np.all(np.abs(circle_gap(kappa[:, None], b, np.sum(w * w, axis=-1))) <= tol, axis=1)
    return out


def _touching(
    p: FloatArray, t: FloatArray, c1: FloatArray, rho1: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The arcs from states (p, t) that touch circles (centre c₁, signed radius ρ₁), travelling the same way.

    With n the left normal and w = p − c₁, the arc of signed curvature κ
    touches the circle where |w + n/κ| = |1/κ − ρ₁|, which is linear in κ:
    κ = 2(n·w + ρ₁)/(ρ₁² − |w|²); the circles touch at X = c₁ − ρ₁ m with the
    unit normal m = (κw + n)/(1 − κρ₁). Returns κ (1/mm), X and the unit
    tangent there (NaN where there is none). Where |1 − κρ₁| < ``_SAME_CIRCLE``
    the arc is the circle itself (the state lies on it, along it): X is then
    any point of both, and the formula's is noise (off both circles by
    millimetres at 1e-8), so there is none.
    """
    w = p - c1
    nl = left_normal(t)
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = 2.0 * (np.sum(nl * w, axis=1) + rho1) / (rho1 * rho1 - np.sum(w * w, axis=1))
        kappa = np.where(np.abs(1.0 - kappa * rho1) < _SAME_CIRCLE, np.nan, kappa)
        m = (kappa[:, None] * w + nl) / (1.0 - kappa * rho1)[:, None]
    x = c1 - rho1[:, None] * m
    return kappa, x, np.stack((m[:, 1], -m[:, 0]), axis=1)


def _plain(curve: CurveFn, pc: Pieces) -> np.ndarray:
    """Whether each single arc turns at most ``_CLOSE_TURN`` more than the curve over its φ-span."""
    grid = pc.lo[:, None] + (pc.hi - pc.lo)[:, None] * np.linspace(0.0, 1.0, 17)
    _, d1, _ = curve(grid.ravel())
    turn = np.abs(np.diff(np.unwrap(angle_of(d1).reshape(grid.shape), axis=1), axis=1)).sum(axis=1)
    out: np.ndarray = np.abs(pc.sweep()[:, 0]) <= turn + _CLOSE_TURN
    return out


@dataclass(frozen=True, slots=True)
class _Circles:
    """Stretches of constant curvature (a dwell's circle): centres (m, 2), signed radii, sample ranges."""

    center: FloatArray
    rho: FloatArray
    first: np.ndarray
    last: np.ndarray


def _circles(pts: FloatArray, d1: FloatArray, d2: FloatArray) -> _Circles:
    """The runs of at least ``_CIRCLE_RUN`` samples on one circle (centre and radius equal to 1e-6 mm)."""
    speed = np.linalg.norm(d1, axis=1)
    kappa = cross(d1, d2) / speed**3
    # a straight stretch (a linear cam's dwell) has κ = 0: an infinite radius, no centre, no circle
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = 1.0 / kappa
        center = pts + rho[:, None] * left_normal(d1 / speed[:, None])
        same = (np.abs(np.diff(rho)) <= _CIRCLE_SAME) & (norm2(np.diff(center, axis=0)) <= _CIRCLE_SAME)
    same &= np.isfinite(rho[1:]) & (np.abs(rho[1:]) < _CIRCLE_LARGEST)
    edges = np.flatnonzero(np.diff(np.concatenate(([0], same.astype(int), [0]))))
    first, last = edges[::2], edges[1::2]  # run k: samples first[k] … last[k]
    long = last - first >= _CIRCLE_RUN
    first, last = first[long], last[long]
    return _Circles(center[first], rho[first], first, last)


def _onto_circles(
    curve: CurveFn,
    layer: _Layer,
    circles: _Circles,
    phi: FloatArray,
    pts: FloatArray,
    tol: float,
    width: int,
) -> _Layer | None:
    """States on a circle of the curve ahead (a dwell's), each reached by one measured arc from the layer.

    A dwell is one arc at best, and it can reach back into the motion before
    it while its circle stays in the band there; from a state the arc that
    touches the circle (:func:`_touching`) lands on it with the circle's own
    tangent, so the next arc can run along the circle. The sampled aims find
    such a state only by chance. Circles that begin within ``width`` samples
    of a state are tried; returns the farthest ``_CIRCLE_STATES`` states
    whose arcs pass the measurement (their arcs, parents and deviations),
    or None.
    """
    k = circles.rho.size
    s = np.repeat(np.arange(layer.j.size), k)
    c = np.tile(np.arange(k), layer.j.size)
    ahead = (circles.last[c] > layer.j[s] + 1) & (circles.first[c] - layer.j[s] <= width)
    s, c = s[ahead], c[ahead]
    kappa, x, t_x = _touching(layer.p[s], layer.t[s], circles.center[c], circles.rho[c])
    # where X lies on the circle: as a turn from the stretch's first sample, in the travel direction
    sign = np.sign(circles.rho[c])
    first, last = circles.first[c], circles.last[c]
    c1 = circles.center[c]
    ref = angle_of(pts[first] - c1)
    span = (sign * (angle_of(pts[last] - c1) - ref)) % (2.0 * np.pi)
    # wrapped about the stretch's middle, so X before the stretch is negative
    along = (sign * (angle_of(x - c1) - ref) - 0.5 * span + np.pi) % (2.0 * np.pi) - np.pi + 0.5 * span
    ok = np.isfinite(kappa) & np.all(np.isfinite(x), axis=1) & (along <= span)
    ok &= np.sum((x - layer.p[s]) * layer.t[s], axis=1) > 0.0  # ahead of the state
    s, c, x, t_x, along, span, ok_c = s[ok], c[ok], x[ok], t_x[ok], along[ok], span[ok], np.flatnonzero(ok)
    if s.size == 0:
        return None
    first, last = circles.first[c], circles.last[c]
    guess = phi[first] + along / np.maximum(span, 1e-300) * (phi[last] - phi[first])
    at, foot = abeam(curve, x, guess)
    land = np.searchsorted(phi, at) - 1
    ok = (norm2(foot - x) <= tol) & (at > layer.at[s]) & (at < phi[-1])
    ok &= _near_samples(layer.p[s], layer.t[s], kappa[ok_c], pts, layer.j[s], land, tol)
    # the farthest first: measure at most a few times the states kept
    order = np.flatnonzero(ok)[np.argsort(-at[ok], kind="stable")][: 4 * _CIRCLE_STATES]
    s, x, t_x, at = s[order], x[order], t_x[order], at[order]
    pc = single_arcs(layer.at[s], at, layer.p[s], layer.t[s], x)
    order = np.flatnonzero(_plain(curve, pc))
    if order.size == 0:
        return None
    pc = take_pieces(pc, order)
    with np.errstate(divide="ignore", invalid="ignore"):
        dev = measure_deviation(curve, pc)
    good = np.flatnonzero(dev <= tol)[:_CIRCLE_STATES]
    if good.size == 0:
        return None
    keep = order[good]
    j = np.searchsorted(phi, at[keep], side="right") - 1
    return _Layer(j, x[keep], t_x[keep], s[keep], take_pieces(pc, good), dev[good], at[keep])


def _close_loop(
    curve: CurveFn, layers: list[_Layer], states: np.ndarray, phi: FloatArray, pts: FloatArray, tol: float
) -> tuple[int, Pieces, float, Pieces, float] | None:
    """One arc from a state of the last layer onto its own first arc, closing a closed curve's loop.

    On a closed curve the path may start anywhere in the band near C(a), so
    the loop can close with one arc instead of a biarc onto C(a): the arc
    from the state that touches the circle of the state's first arc
    (:func:`_touching`) at a point X. The path then starts at X, and its
    first arc runs from X (before or after C(a) on the same circle) to its
    end. (Closing onto the second arc instead, dropping the first, never
    gave fewer arcs on the shipped samples.) Of the closures whose two arcs
    pass the measurement, the one starting nearest C(a) is taken.

    Returns the state (an index into ``states``), the closing arc, its
    deviation, the arc from X and its deviation; None when no closure is
    within ``tol``.
    """
    n = phi.size - 1
    # each state's first arc, traced back through the layers
    own = states.copy()
    for k in range(len(layers) - 1, 1, -1):
        own = layers[k].parent[own]
    target = layers[1]
    assert target.arc is not None
    arc, layer = target.arc, layers[-1]
    p, t = layer.p[states], layer.t[states]
    c1 = arc.center[own, 0]
    rho1 = np.where(arc.ccw[own, 0], arc.r_start[own, 0], -arc.r_start[own, 0])
    kappa, x, t_x = _touching(p, t, c1, rho1)
    kappa = np.where(_near_samples(p, t, kappa, pts, layer.j[states], n, tol), kappa, np.nan)
    # where X lies on the first arc's circle, as a turn from C(a) in the arc's direction
    sweep1 = np.abs(arc.sweep()[own, 0])
    rel = angle_of(x - c1) - angle_of(arc.start[own, 0] - c1)
    along = np.where(arc.ccw[own, 0], 1.0, -1.0) * ((rel + np.pi) % (2.0 * np.pi) - np.pi)
    ok = (
        ~arc.line[own, 0] & np.isfinite(kappa) & np.all(np.isfinite(x), axis=1) & (along < sweep1)
        & (np.linalg.norm(p - x, axis=1) > tol)
    )  # fmt: skip
    cand = np.flatnonzero(ok)
    if cand.size == 0:
        return None
    # φ of the curve abeam X, from the first arc's φ-span
    guess = phi[0] + along[cand] / np.maximum(sweep1[cand], 1e-300) * (target.at[own[cand]] - phi[0])
    phi_x, _ = abeam(curve, x[cand], guess)
    hi = phi[n] + (phi_x - phi[0])
    lo = layer.at[states[cand]]
    ok = (phi_x < target.at[own[cand]]) & (hi > lo)
    cand, phi_x, hi, lo = cand[ok], phi_x[ok], hi[ok], lo[ok]
    if cand.size == 0:
        return None
    close = single_arcs(lo, hi, p[cand], t[cand], x[cand])
    ok = _plain(curve, close)
    if not ok.any():
        return None
    cand, phi_x, close = cand[ok], phi_x[ok], take_pieces(close, ok)
    start = single_arcs(phi_x, target.at[own[cand]], x[cand], t_x[cand], target.p[own[cand]])
    with np.errstate(divide="ignore", invalid="ignore"):
        dev_close, dev_start = measure_deviation(curve, close), measure_deviation(curve, start)
    fits = np.flatnonzero((dev_close <= tol) & (dev_start <= tol))
    if fits.size == 0:
        return None
    i = int(fits[np.argmin(np.abs(phi_x[fits] - phi[0]))])
    pick = np.array([i])
    close, start = take_pieces(close, pick), take_pieces(start, pick)
    return int(cand[i]), close, float(dev_close[i]), start, float(dev_start[i])


def search_arcs(
    curve: CurveFn,
    a: float,
    b: float,
    tolerance: float,
    *,
    closed: bool = False,
    onto_line: bool = False,
) -> tuple[list[Pieces], list[FloatArray]]:
    """Arcs from C(a) to C(b), tangent-continuous, on the curve's own tangents at both ends.

    Returns the pieces in φ order (single arcs, then the closing biarc) and their
    measured deviations. With ``closed`` (a closed curve, b = a + 2π) the
    loop may instead close with one arc onto its own first arc
    (:func:`_close_loop`): the path then starts within the band near C(a),
    on the first arc's circle, and its φ-intervals run from there to the
    same φ + 2π.

    With ``onto_line`` C runs on from C(b) as a straight line along its
    tangent there (a linear cam's dwell begins at b): the path may then
    end with one arc that lands on that line at or before C(b), touching
    it (:func:`_land`), instead of a biarc onto C(b); its last piece then
    ends at that point X on the line, φ-interval up to the φ abeam X, and
    the line continues from X.

    Raises
    ------
    ArcSearchStallError
        When no arc from some layer passes the measurement even in a band
        shrunk to 0.2 tol.
    """
    # when an arc kept unmeasured fails on the path, search again measuring every arc
    found = _search(curve, a, b, tolerance, closed, _SURE, onto_line=onto_line)
    found = found or _search(curve, a, b, tolerance, closed, -math.inf, onto_line=onto_line)
    assert found is not None  # every arc measured: none can fail on the path
    return found


def _search(
    curve: CurveFn, a: float, b: float, tolerance: float, closed: bool, sure: float, onto_line: bool = False
) -> tuple[list[Pieces], list[FloatArray]] | None:
    """The search of :func:`search_arcs`; None when an arc kept unmeasured fails on the path.

    A layer's arcs are measured only when their largest gap from the curve
    between the table samples (at ``_BETWEEN`` of each step) exceeds
    ``sure`` × tolerance (:func:`_between_samples`): about 4 % of them on the
    shipped samples. The others keep a NaN deviation until the path is
    traced, where every such arc on it is measured (:func:`_trace`).
    Measuring every arc of every layer took a quarter of a plan's time, and
    0.2 % (5 µm) to 0.8 % (1 µm) of them fail.
    """
    phi = _table(a, b)
    pts, d1, d2 = curve(phi)
    tan = d1 / norm2(d1)[:, None]
    circles = _circles(pts, d1, d2)
    tan_ang = angle_of(tan)
    nrm = left_normal(tan)
    between = curve((phi[:-1, None] + _BETWEEN[None, :] * np.diff(phi)[:, None]).ravel())[0]
    per = _BETWEEN.size
    zero = np.zeros(1, int)
    layers = [_Layer(zero, pts[:1], tan[:1], zero, None, np.zeros(1), phi[:1])]
    width = 64
    for _ in range(_MAX_LAYERS):
        layer = layers[-1]
        near = np.argsort(-layer.j, kind="stable")
        if closed and len(layers) > 1 and near.size:
            loop = _close_loop(curve, layers, near[:_LOOP_STATES], phi, pts, tolerance)
            if loop:
                state, close, close_dev, start, start_dev = loop
                first = (start, start_dev)
                return _trace(curve, layers, int(near[state]), close, close_dev, tolerance, first)
        if onto_line and (landed := _land(curve, layer, phi, pts, tan, tolerance)):
            return _trace(curve, layers, *landed, tolerance)
        near = near[:24]
        if near.size and (done := _close(curve, _pick(layer, near), phi, pts, tan, tan_ang, tolerance)):
            return _trace(curve, layers, int(near[done[0]]), done[1], done[2], tolerance)
        band = _PROXY * tolerance
        while True:
            s, end, kappa = _expand(layer, pts, tan_ang, nrm, band, width)
            q = _arc_to(layer.p[s], layer.t[s], kappa, pts[end])
            pc = single_arcs(layer.at[s], phi[end], layer.p[s], layer.t[s], q)
            dev = np.full(s.size, np.nan)
            if s.size:
                gap = _between_samples(layer.p[s], layer.t[s], kappa, between, per * layer.j[s], per * end)
                doubt = np.flatnonzero(~(gap <= sure * tolerance))
                if doubt.size:
                    measured = measure_deviation(curve, take_pieces(pc, doubt), samples=_LAYER_SAMPLES)
                    dev[doubt] = np.where(np.isnan(measured), np.inf, measured)  # NaN marks the unmeasured
            keep = ~(dev > tolerance)
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
        t2 = np.cos(turn)[:, None] * layer.t[s] + np.sin(turn)[:, None] * left_normal(layer.t[s])
        new = _Layer(end, q[keep], t2, s, pc, dev, phi[end])
        extra = _onto_circles(curve, layer, circles, phi, pts, tolerance, width) if circles.rho.size else None
        layers.append(new if extra is None else _join(new, extra))
        width = max(32, int(1.5 * np.median(end - layer.j[s])))
    raise ArcSearchStallError("arc search did not close")  # pragma: no cover


def _between_samples(
    p: FloatArray, t: FloatArray, kappa: FloatArray, points: FloatArray, j0: np.ndarray, j1: np.ndarray
) -> FloatArray:
    """Largest |gap| [mm] of each arc (p, t, κ) from the curve points ``points[j0:j1]``.

    The points are the curve between the table samples (``_BETWEEN`` of each
    step, in order), which the screen has not seen: where an arc strays
    farthest from what it saw.
    """
    count = np.maximum(j1 - j0, 1)
    ends = np.cumsum(count)
    arc = np.repeat(np.arange(p.shape[0]), count)
    k = np.minimum(np.arange(int(ends[-1])) - np.repeat(ends - count, count) + j0[arc], points.shape[0] - 1)
    w = points[k] - p[arc]
    gap = np.abs(circle_gap(kappa[arc], cross(t[arc], w), np.sum(w * w, axis=1)))
    out: FloatArray = np.maximum.reduceat(gap, ends - count)
    return out


def _join(a: _Layer, b: _Layer) -> _Layer:
    """The states of two layers of arcs from the same parents, as one layer."""
    assert a.arc is not None and b.arc is not None
    return _Layer(
        np.concatenate((a.j, b.j)), np.concatenate((a.p, b.p)), np.concatenate((a.t, b.t)),
        np.concatenate((a.parent, b.parent)),
        Pieces(**{f.name: np.concatenate((getattr(a.arc, f.name), getattr(b.arc, f.name))) for f in _FIELDS}),
        np.concatenate((a.dev, b.dev)), np.concatenate((a.at, b.at)),
    )  # fmt: skip


def _pick(layer: _Layer, keep: np.ndarray) -> _Layer:
    return _Layer(
        layer.j[keep], layer.p[keep], layer.t[keep], layer.parent[keep], None, layer.dev[keep], layer.at[keep]
    )


def _trace(
    curve: CurveFn,
    layers: list[_Layer],
    state: int,
    close: Pieces,
    dev: float,
    tol: float,
    start: tuple[Pieces, float] | None = None,
) -> tuple[list[Pieces], list[FloatArray]] | None:
    """The arcs of ``state`` back to the start, then ``close``; ``start`` replaces the first arc.

    The arcs kept unmeasured are measured here, all in one call; None when
    one of them is off by more than ``tol`` [mm].
    """
    pieces, devs = [close], [np.array([dev])]
    for layer in reversed(layers[1:]):
        assert layer.arc is not None
        pieces.append(take_pieces(layer.arc, np.array([state])))
        devs.append(layer.dev[state : state + 1].copy())
        state = int(layer.parent[state])
    if start is not None:
        pieces[-1], devs[-1] = start[0], np.array([start[1]])
    todo = np.array([k for k, d in enumerate(devs) if np.isnan(d[0])], dtype=int)
    if todo.size:
        # concat_pieces sorts by φ: the measurements come in that order
        todo = todo[np.argsort([pieces[k].lo[0] for k in todo], kind="stable")]
        measured = measure_deviation(curve, concat_pieces([pieces[k] for k in todo]), samples=_LAYER_SAMPLES)
        if not np.all(measured <= tol):
            return None
        for k, d in zip(todo, measured, strict=True):
            devs[k][0] = d
    return pieces[::-1], devs[::-1]
