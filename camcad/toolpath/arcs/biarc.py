"""Biarcs and the machinery to measure arc paths against an exact curve.

The curve is any smooth plane curve C(φ) given with its first two
φ-derivatives (for camcad: ``cam.offset_curve(phi, tool_radius)``). A biarc
replaces a φ-interval by two circular arcs that meet the curve's end points
and end tangents and join each other tangentially; :func:`measure_deviation`
gives the two-way distance between pieces and the curve, measured on samples
of both. The arc-spline fit in :mod:`camcad.toolpath.arcs.spline` builds on
these.

Pieces are held in :class:`Pieces`, a set of arrays of shape (n, 2, ...): two
pieces (arcs or lines) per φ-interval, the second empty where one arc
suffices. A piece runs from ``start`` to ``end``
about ``center``; its radius may change linearly from ``r_start`` to ``r_end``
(a controller interpolates a slightly inconsistent arc as a spiral, and
rounded output is measured that way).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly

__all__ = [
    "CurveFn",
    "Pieces",
    "abeam",
    "angle_of",
    "arc_from_tangent",
    "biarc_pieces",
    "chord_pieces",
    "circle_gap",
    "concat_pieces",
    "cross",
    "curve_nodes",
    "distance_to_pieces",
    "left_normal",
    "measure_deviation",
    "norm2",
    "offset_pieces",
    "sample_pieces",
    "single_arcs",
    "take_pieces",
]

CurveFn = Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]
"""φ (n,) [rad] → point (n, 2) [mm], dC/dφ (n, 2) [mm/rad], d²C/dφ² (n, 2) [mm/rad²]."""

_STRAIGHT_SAGITTA = 1e-9  # mm: an arc bulging less than this is a line
_SAMPLES = 24  # per interval and direction while fitting
# Newton steps of a projection onto the curve: it starts from the nearest of 26 curve samples of
# the interval, and the distance is stationary at the foot point, so its error after two steps is
# far below a nanometre (a third step left every sample's G-code byte-identical and cost 7 %);
# every iterate is a curve point, so fewer steps can only make the measured distance larger
_NEWTON_STEPS = 2
_ABEAM_STEPS = 4  # Newton steps of abeam() from a guess that is not a nearby sample


@dataclass(frozen=True, slots=True, kw_only=True)
class Pieces:
    """Arcs and lines, two per φ-interval, in the order of increasing φ.

    Attributes
    ----------
    lo, hi
        (n,) φ-interval of each pair [rad].
    start, end, center
        (n, 2, 2) end points and arc centres [mm] (centre unused for lines).
    r_start, r_end
        (n, 2) radius at the start and at the end [mm] (0 for lines).
    ccw
        (n, 2) bool, True where an arc turns counter-clockwise.
    line
        (n, 2) bool, True where the piece is a straight line.
    """

    lo: FloatArray
    hi: FloatArray
    start: FloatArray
    end: FloatArray
    center: FloatArray
    r_start: FloatArray
    r_end: FloatArray
    ccw: np.ndarray
    line: np.ndarray

    def __len__(self) -> int:
        """Number of φ-intervals."""
        return int(self.lo.size)

    def sweep(self) -> FloatArray:
        """(n, 2) signed sweep angle of each arc [rad], + counter-clockwise; 0 for lines."""
        a0 = angle_of(self.start - self.center)
        a1 = angle_of(self.end - self.center)
        turn = np.mod(a1 - a0, 2.0 * np.pi)
        out = np.where(self.ccw, turn, turn - 2.0 * np.pi)
        out = np.where(turn == 0.0, 0.0, out)
        return np.where(self.line, 0.0, out)

    def length(self) -> FloatArray:
        """(n, 2) length of each piece [mm]."""
        chord = np.linalg.norm(self.end - self.start, axis=-1)
        radius = 0.5 * (self.r_start + self.r_end)
        return np.where(self.line, chord, np.abs(self.sweep()) * radius)

    def curvature(self) -> FloatArray:
        """(n, 2) signed curvature of each piece [1/mm], + counter-clockwise; 0 for lines."""
        with np.errstate(divide="ignore"):
            return np.where(self.line, 0.0, np.where(self.ccw, 1.0, -1.0) / self.r_start)

    def tangents(self) -> tuple[FloatArray, FloatArray]:
        """(n, 2, 2) unit tangents of each piece at its start and at its end, along it (NaN if null)."""
        chord = self.end - self.start
        side = np.where(self.ccw, 1.0, -1.0)[..., None]
        out = []
        for at in (self.start, self.end):
            d = np.where(self.line[..., None], chord, side * left_normal(at - self.center))
            with np.errstate(invalid="ignore", divide="ignore"):
                out.append(d / norm2(d)[..., None])
        return out[0], out[1]


def angle_of(v: FloatArray) -> FloatArray:
    """Direction angle [rad] of 2-D vectors (..., 2), in (−π, π]."""
    return np.arctan2(v[..., 1], v[..., 0])


def cross(a: FloatArray, b: FloatArray) -> FloatArray:
    """z-component of the cross product of 2-D vectors (..., 2)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def left_normal(v: FloatArray) -> FloatArray:
    """2-D vectors (..., 2) turned by +90° (the left normal of a tangent)."""
    return np.stack((-v[..., 1], v[..., 0]), axis=-1)


def circle_gap(kappa: FloatArray, b: FloatArray, ww: FloatArray) -> FloatArray:
    """Signed distance [mm] of points from the circle of curvature κ through p along t (w·n = b, |w|² = ww).

    w = point − p and n the left normal of t; the form (κ|w|² − 2b)/(1 + √(1 − 2κb + κ²|w|²)) holds
    for every κ, a straight line (κ = 0) included, without cancellation.
    """
    root = np.sqrt(np.maximum(1.0 - 2.0 * (kappa * b) + kappa * kappa * ww, 0.0))
    out: FloatArray = (kappa * ww - 2.0 * b) / (1.0 + root)
    return out


def norm2(v: FloatArray) -> FloatArray:
    """Length of 2-D vectors (..., 2): ``np.linalg.norm(v, axis=-1)`` to the last bit, without its reduction.

    Hand-written because the reduction over an axis of two is several times slower.
    """
    x, y = v[..., 0], v[..., 1]
    out: FloatArray = np.sqrt(x * x + y * y)
    return out


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.einsum("...i,...i->...", a, b)


def arc_from_tangent(
    p: FloatArray, t: FloatArray, q: FloatArray
) -> tuple[FloatArray, FloatArray, np.ndarray, np.ndarray]:
    """The arc leaving ``p`` along unit tangent ``t`` and ending at ``q``.

    Returns centre (n, 2), radius (n,), ccw (n,) and line (n,) flags. The
    signed curvature is κ = 2 (t × w)/|w|² with chord w = q − p.
    """
    w = q - p
    ww = _dot(w, w)
    turn = cross(t, w)
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = np.where(ww > 0.0, 2.0 * turn / ww, 0.0)
    line = np.abs(kappa) * ww / 8.0 <= _STRAIGHT_SAGITTA  # sagitta ≈ κ|w|²/8
    safe = np.where(line, 1.0, kappa)
    left = np.stack((-t[..., 1], t[..., 0]), axis=-1)
    center = p + left / safe[..., None]
    radius = np.where(line, 0.0, 1.0 / np.abs(safe))
    center = np.where(line[..., None], 0.5 * (p + q), center)
    return center, radius, kappa > 0.0, line


def biarc_pieces(
    lo: FloatArray,
    hi: FloatArray,
    p0: FloatArray,
    t0: FloatArray,
    p1: FloatArray,
    t1: FloatArray,
    *,
    ratio: FloatArray | float = 1.0,
) -> Pieces:
    """Equal-chord biarcs between end points with given unit tangents.

    Parameters
    ----------
    lo, hi
        (n,) φ-interval of each biarc [rad] (carried along, not used).
    p0, p1
        (n, 2) start and end points [mm].
    t0, t1
        (n, 2) unit tangents at the start and end, in the direction of travel.
    ratio
        (n,) or scalar d₁/d: 1 gives the equal-chord biarc; other values
        move the joint along the circle of possible joints.

    Returns
    -------
    Pieces
        Two tangent-continuous arcs per interval.

    Notes
    -----
    The biarc with equal tangent lengths d₁ = d₂ = d (the "equal chord"
    biarc, Bolton 1975; see also Meek & Walton 1992): the control points
    Q₀ = P₀ + d·T₀ and Q₁ = P₁ − d·T₁ are 2d apart, so with v = P₁ − P₀ and
    t = T₀ + T₁, 2(1 − T₀·T₁)d² + 2(v·t)d − v·v = 0, whose positive root is
    taken in the cancellation-free form d = v·v / (v·t + √((v·t)² + 2(1 − T₀·T₁) v·v)).
    The joint is J = (Q₀ + Q₁)/2 with tangent (Q₁ − Q₀)/2d.

    References
    ----------
    .. [1] Meek, D. S. & Walton, D. J. (1992), Approximation of discrete data
       by G1 arc splines, Computer-Aided Design 24(6), 301–306.
    .. [2] Bolton, K. M. (1975), Biarc curves, Computer-Aided Design 7(2), 89–92.
    """
    v = p1 - p0
    vt = _dot(v, t0 + t1)
    vv = _dot(v, v)
    c = 1.0 - _dot(t0, t1)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = vv / (vt + np.sqrt(np.maximum(vt * vt + 2.0 * c * vv, 0.0)))  # Bolton 1975
    d = np.where(np.isfinite(d) & (d > 0.0), d, 0.5 * np.sqrt(vv))
    # general d₁: |Q₁ − Q₀| = d₁ + d₂ gives d₂ = (v·v − 2d₁ v·T₀) / (2(v·T₁ + d₁(1 − T₀·T₁)))
    d1 = d * ratio
    with np.errstate(divide="ignore", invalid="ignore"):
        d2 = (vv - 2.0 * d1 * _dot(v, t0)) / (2.0 * (_dot(v, t1) + d1 * c))
    bad = ~(np.isfinite(d2) & (d2 > 0.0))
    d1, d2 = np.where(bad, d, d1), np.where(bad, d, d2)
    q0 = p0 + d1[:, None] * t0
    q1 = p1 - d2[:, None] * t1
    joint = q0 + (d1 / (d1 + d2))[:, None] * (q1 - q0)
    c1, r1, ccw1, line1 = arc_from_tangent(p0, t0, joint)
    # the second arc, traced backwards from P1 along −T1, is the same circle
    c2, r2, ccw2, line2 = arc_from_tangent(p1, -t1, joint)
    out = Pieces(
        lo=np.asarray(lo, dtype=float),
        hi=np.asarray(hi, dtype=float),
        start=np.stack((p0, joint), axis=1),
        end=np.stack((joint, p1), axis=1),
        center=np.stack((c1, c2), axis=1),
        r_start=np.stack((r1, r2), axis=1),
        r_end=np.stack((r1, r2), axis=1),
        ccw=np.stack((ccw1, ~ccw2), axis=1),
        line=np.stack((line1, line2), axis=1),
    )
    return out


def chord_pieces(
    lo: FloatArray, hi: FloatArray, p0: FloatArray, t0: FloatArray, p1: FloatArray, t1: FloatArray
) -> Pieces:
    """Straight chords (the G1-only comparison): each chord, then an empty second piece."""
    del t0, t1
    zero = np.zeros((p0.shape[0], 2))
    flag = np.ones((p0.shape[0], 2), dtype=bool)
    return Pieces(
        lo=np.asarray(lo, dtype=float),
        hi=np.asarray(hi, dtype=float),
        start=np.stack((p0, p1), axis=1),
        end=np.stack((p1, p1), axis=1),
        center=np.stack((p1, p1), axis=1),
        r_start=zero,
        r_end=zero.copy(),
        ccw=~flag,
        line=flag,
    )


def sample_pieces(pieces: Pieces, m: int) -> FloatArray:
    """Points along every piece, (n, 2, m, 2) [mm], at fractions (k + 1)/(m + 1) of the sweep."""
    u = (np.arange(m) + 1.0) / (m + 1.0)
    start, end = pieces.start[..., None, :], pieces.end[..., None, :]
    on_line = start + (end - start) * u[:, None]
    a0 = angle_of(pieces.start - pieces.center)[..., None]
    ang = a0 + pieces.sweep()[..., None] * u
    rad = pieces.r_start[..., None] + (pieces.r_end - pieces.r_start)[..., None] * u
    on_arc = pieces.center[..., None, :] + rad[..., None] * np.stack((np.cos(ang), np.sin(ang)), axis=-1)
    return np.where(pieces.line[..., None, None], on_line, on_arc)


def distance_to_pieces(q: FloatArray, pieces: Pieces) -> FloatArray:
    """Distance [mm] from points q (n, m, 2) to the nearer piece of their own interval.

    Exact for lines and circular arcs; for a spiral (r_start ≠ r_end) the mean
    radius is used and half the difference added, which bounds it from above.
    """
    best = np.full(q.shape[:2], np.inf)
    for k in range(2):
        s, e, c = pieces.start[:, k, None, :], pieces.end[:, k, None, :], pieces.center[:, k, None, :]
        # line: clamp the projection onto the segment
        w = e - s
        ww = np.maximum(_dot(w, w), 1e-300)
        t = np.clip(_dot(q - s, w) / ww, 0.0, 1.0)
        d_line = norm2(q - (s + w * t[..., None]))
        # arc: radial distance inside the sweep, else the nearer end point
        radius = 0.5 * (pieces.r_start[:, k] + pieces.r_end[:, k])[:, None]
        spiral = 0.5 * np.abs(pieces.r_end[:, k] - pieces.r_start[:, k])[:, None]
        sweep = pieces.sweep()[:, k, None]
        rel = angle_of(q - c) - angle_of(s - c)
        along = np.where(sweep >= 0.0, np.mod(rel, 2.0 * np.pi), np.mod(-rel, 2.0 * np.pi))
        inside = along <= np.abs(sweep)
        radial = np.abs(norm2(q - c) - radius) + spiral
        ends = np.minimum(norm2(q - s), norm2(q - e))
        d_arc = np.where(inside, radial, ends)
        best = np.minimum(best, np.where(pieces.line[:, k, None], d_line, d_arc))
    return best


def _distance_to_curve(
    curve: CurveFn,
    p: FloatArray,
    guess: FloatArray,
    low: FloatArray,
    high: FloatArray,
    at_guess: tuple[FloatArray, FloatArray, FloatArray],
) -> FloatArray:
    """Upper bound of the distance [mm] from points p (N, 2) to the curve.

    Newton's method on g(φ) = (C(φ) − p)·C′(φ) from ``guess`` (N,), kept in
    [low, high]; every iterate is a point of the curve, so the smallest
    distance seen bounds the true one from above. ``at_guess`` is C, C′, C″
    at the guesses (already known to the caller).
    """
    phi = guess.copy()
    best = np.full(guess.shape, np.inf)
    for step in range(_NEWTON_STEPS + 1):
        pt, d1, d2 = at_guess if step == 0 else curve(phi)
        diff = pt - p
        best = np.minimum(best, norm2(diff))
        if step == _NEWTON_STEPS:
            break
        g = _dot(diff, d1)
        gp = _dot(d1, d1) + _dot(diff, d2)
        gp = np.where(gp > 0.0, gp, _dot(d1, d1))
        phi = np.clip(phi - g / gp, low, high)
    return best


def _peak(values: FloatArray) -> FloatArray:
    """Row maxima of (n, m) samples, raised to the vertex of a parabola through the top three."""
    j = values.argmax(axis=1)
    rows = np.arange(values.shape[0])
    top = values[rows, j]
    inner = (j > 0) & (j < values.shape[1] - 1)
    jj = np.clip(j, 1, values.shape[1] - 2)
    left, right = values[rows, jj - 1], values[rows, jj + 1]
    curv = 2.0 * top - left - right
    with np.errstate(divide="ignore", invalid="ignore"):
        bump = np.where(inner & (curv > 0.0), (right - left) ** 2 / (8.0 * curv), 0.0)
    return top + np.minimum(bump, top)


def measure_deviation(curve: CurveFn, pieces: Pieces, *, samples: int = _SAMPLES) -> FloatArray:
    """Two-way deviation [mm] between each interval's pieces and the exact curve.

    Parameters
    ----------
    curve
        The exact curve C(φ).
    pieces
        The approximation, two pieces per φ-interval.
    samples
        Sample count per interval along the curve, and per piece along the pieces.

    Returns
    -------
    FloatArray
        (n,) the larger of max over curve samples of the distance to the
        pieces, and max over piece samples of the distance to the curve.

    Notes
    -----
    Both directions are upper bounds at the samples: the first uses the exact
    point-to-arc distance restricted to the interval's own pieces, the second
    the distance to a curve point found by Newton's method. Each maximum is
    raised to the vertex of the parabola through the three largest samples,
    which catches a peak between samples; the maximum is still not strictly
    bounded, which is why the toolpath fits with a margin.
    """
    n = len(pieces)
    u = (np.arange(samples) + 1.0) / (samples + 1.0)
    phi = pieces.lo[:, None] + (pieces.hi - pieces.lo)[:, None] * u
    # the curve at the ends and the samples of every interval, in one evaluation
    cand_phi = np.concatenate((pieces.lo[:, None], phi, pieces.hi[:, None]), axis=1)
    c_pt, c_d1, c_d2 = (v.reshape(n, samples + 2, 2) for v in curve(cand_phi.ravel()))
    cand = c_pt
    q = c_pt[:, 1:-1]
    to_pieces = _peak(distance_to_pieces(q, pieces))
    half = max(samples // 2, 2)
    pts = sample_pieces(pieces, half).reshape(n, 2 * half, 2)
    # each piece sample is projected onto the curve in [lo − h, hi + h] (h the interval's length),
    # from the nearest curve sample of its interval; a null second piece (a single arc's) is one
    # point sampled `half` times: it is projected once
    null = pieces.line[:, 1] & np.all(pieces.start[:, 1] == pieces.end[:, 1], axis=1)
    take = np.ones((n, 2 * half), dtype=bool)
    take[null, half + 1 :] = False
    rows, cols = np.nonzero(take)
    near = norm2(pts[rows, cols][:, None, :] - cand[rows]).argmin(axis=1)
    span = pieces.hi - pieces.lo
    dist = np.empty((n, 2 * half))
    dist[rows, cols] = _distance_to_curve(
        curve, pts[rows, cols], cand_phi[rows, near], (pieces.lo - span)[rows], (pieces.hi + span)[rows],
        (c_pt[rows, near], c_d1[rows, near], c_d2[rows, near]),
    )  # fmt: skip
    dist[null, half + 1 :] = dist[null, half : half + 1]
    to_curve = np.maximum(_peak(dist[:, :half]), _peak(dist[:, half:]))
    out = np.maximum(to_pieces, to_curve)
    readonly(out)
    return out


def offset_pieces(pieces: Pieces, delta: float) -> Pieces | None:
    """The tangent-continuous chain of pieces offset by ``delta`` [mm] to the left of travel (increasing φ).

    An arc offset is the concentric arc of radius r − δ (counter-clockwise)
    or r + δ (clockwise) over the same angles, a line moves by δ along its
    left normal, and a null piece (a single arc's empty second piece) moves
    with the end of the piece before it. Because the chain is tangent
    continuous the offset pieces join again: the offset of an arc spline of
    a curve C is an arc spline of the offset curve C + δ·n with the same
    number of pieces (a circle's offset is the concentric circle). Its
    distance from the offset curve is not implied by the original's and
    must be measured.

    Returns None where an arc would vanish or turn inside out (|δ| ≥ r on
    its concave side); the caller then fits the offset curve itself.
    """
    n = len(pieces)
    start, end = pieces.start.reshape(-1, 2), pieces.end.reshape(-1, 2)
    center = pieces.center.reshape(-1, 2)
    ccw, line = pieces.ccw.reshape(-1), pieces.line.reshape(-1)
    radius = pieces.r_start.reshape(-1)
    chord = end - start
    length = np.linalg.norm(chord, axis=1)
    null = line & (length <= 0.0)
    turn = np.where(ccw, 1.0, -1.0)
    new_r = radius - delta * turn
    if np.any(~line & (new_r <= 0.0)):
        return None
    with np.errstate(divide="ignore", invalid="ignore"):
        u_s = (start - center) / radius[:, None]
        u_e = (end - center) / radius[:, None]
        d = chord / length[:, None]
    left = np.stack((-d[:, 1], d[:, 0]), axis=1)
    a_start = center + new_r[:, None] * u_s
    a_end = center + new_r[:, None] * u_e
    out_s = np.where(line[:, None], start + delta * left, a_start)
    out_e = np.where(line[:, None], end + delta * left, a_end)
    # a null piece sits where the previous real piece ends (the chain is closed)
    real = np.flatnonzero(~null)
    if real.size == 0:
        return None
    prev = real[np.searchsorted(real, np.arange(null.size), side="right") - 1]
    at = out_e[prev]
    out_s = np.where(null[:, None], at, out_s)
    out_e = np.where(null[:, None], at, out_e)
    out_c = np.where(null[:, None], at, np.where(line[:, None], 0.5 * (out_s + out_e), center))
    r_out = np.where(line, 0.0, new_r)
    return Pieces(
        lo=pieces.lo, hi=pieces.hi, start=out_s.reshape(n, 2, 2), end=out_e.reshape(n, 2, 2),
        center=out_c.reshape(n, 2, 2), r_start=r_out.reshape(n, 2), r_end=r_out.reshape(n, 2).copy(),
        ccw=pieces.ccw, line=pieces.line,
    )  # fmt: skip


def curve_nodes(curve: CurveFn, phi: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Points (n, 2) and unit tangents (n, 2) of the curve at φ."""
    pt, d1, _ = curve(phi)
    return np.array(pt, dtype=float), d1 / np.linalg.norm(d1, axis=1)[:, None]


def take_pieces(p: Pieces, keep: np.ndarray) -> Pieces:
    """The intervals of ``p`` selected by ``keep`` (indices or a boolean mask)."""
    return Pieces(
        lo=p.lo[keep], hi=p.hi[keep], start=p.start[keep], end=p.end[keep], center=p.center[keep],
        r_start=p.r_start[keep], r_end=p.r_end[keep], ccw=p.ccw[keep], line=p.line[keep],
    )  # fmt: skip


def concat_pieces(parts: Sequence[Pieces]) -> Pieces:
    """Join piece sets and sort them by φ."""
    fields = ("lo", "hi", "start", "end", "center", "r_start", "r_end", "ccw", "line")
    joined = {f: np.concatenate([getattr(p, f) for p in parts]) for f in fields}
    order = np.argsort(joined["lo"], kind="stable")
    return Pieces(**{f: v[order] for f, v in joined.items()})


def single_arcs(lo: FloatArray, hi: FloatArray, p: FloatArray, t: FloatArray, q: FloatArray) -> Pieces:
    """One arc per φ-interval [rad]: from p [mm] along the unit tangent t to q, then an empty piece at q."""
    center, radius, ccw, line = arc_from_tangent(p, t, q)
    zero = np.zeros_like(radius)
    return Pieces(
        lo=lo, hi=hi, start=np.stack((p, q), axis=1), end=np.stack((q, q), axis=1),
        center=np.stack((center, q), axis=1), r_start=np.stack((radius, zero), axis=1),
        r_end=np.stack((radius, zero), axis=1), ccw=np.stack((ccw, np.zeros_like(ccw)), axis=1),
        line=np.stack((line, np.ones_like(line)), axis=1),
    )  # fmt: skip


def abeam(curve: CurveFn, x: FloatArray, guess: FloatArray) -> tuple[FloatArray, FloatArray]:
    """φ [rad] of the curve point nearest each x, and the point: Newton on (C(φ) − x)·C′(φ) from ``guess``."""
    phi_x = guess.copy()
    for _ in range(_ABEAM_STEPS):
        pt, d1, d2 = curve(phi_x)
        diff = pt - x
        g, gp = np.sum(diff * d1, axis=1), np.sum(d1 * d1, axis=1) + np.sum(diff * d2, axis=1)
        phi_x = phi_x - g / np.where(gp > 0.0, gp, np.sum(d1 * d1, axis=1))
    return phi_x, curve(phi_x)[0]
