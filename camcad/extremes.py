"""True extremes of functions of the cam angle, one-sided limits at joints included.

Every quantity camcad reports (pressure angle, radius of curvature, contact
force, torque, stress, the jump limits) is an exact function of the cam angle
φ, smooth between the joints of the motion program and possibly jumping at
them. Its extreme over a turn is either an interior extremum of a smooth
piece or a one-sided limit at a joint, which no sample hits. :func:`extremes`
finds both: it evaluates the function on the sample grid and at both sides of
every joint, then refines each local extremum of the samples by a bounded
search (Brent's parabolic interpolation with golden-section safeguard) on
the exact function inside its bracketing samples.

The search is hand-written and vectorised over all brackets at once: one call
of the quantity per iteration for every bracket together, where
``scipy.optimize.minimize_scalar(method="bounded")`` would need a Python loop
over brackets and one call of the quantity per evaluation.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator, Sequence
from contextvars import ContextVar
from dataclasses import dataclass
from typing import Literal

import numpy as np

from camcad._typing import ArrayLike, FloatArray
from camcad.angles import TWO_PI

__all__ = [
    "SIDE_WORDS",
    "Extreme",
    "Kind",
    "Quantity",
    "RowPick",
    "Rows",
    "Side",
    "extremes",
    "extremes_each",
    "extremes_rows",
    "extremes_stacked",
    "maximum",
    "minimum",
    "served",
    "side_text",
]

Side = Literal["left", "right"]
"""Which one-sided limit at a joint: ``"left"`` (just before it), ``"right"`` (just after)."""

Kind = Literal["min", "max"]
"""Which extreme to find."""

Rows = Callable[[FloatArray, Side], ArrayLike]
"""Several quantities at once: cam angles (n,) [rad] and a side → values (k, n)."""

RowPick = Callable[[FloatArray, np.ndarray, Side], ArrayLike]
"""Many independent quantities: angles (n,) [rad], the row of each (n,) and a side → values (n,).

Each row is evaluated only at its own angles (e.g. one row per cam speed).
"""

Quantity = Callable[[FloatArray, Side], FloatArray]
"""An exact quantity q(φ) [any unit]: cam angles (n,) [rad] and a side → values (n,).

``side`` matters only at joints, where the quantity takes that one-sided limit.
"""

SIDE_WORDS = {"left": "before joint", "right": "after joint"}
"""How summary.json names a one-sided limit (the ``*_side`` keys)."""

_GOLDEN_SECTION = (3.0 - math.sqrt(5.0)) / 2.0  # 0.382: the golden step into the larger side
_ROUNDOFF = 1e-12  # relative: a refined value must beat the samples by more than this
_CONTINUOUS_RTOL = 1e-9  # one-sided limits this close are one value: no "just before the joint"
_ITERATIONS = 60  # at most; a golden step alone shrinks a bracket by 0.618 (0.618^60 ≈ 3e-13)
_XTOL = 1e-11  # rad: the smallest step the search takes
_XSTOP = 1e-9  # rad: a parabolic step this small has converged (the value's error is ~q″·1e-18)
# Where a piece's first and last sample gaps are probed, as fractions of the gap (see _probe_end_gaps):
# next to both ends, which catches a peak right beside a joint, and at eighths.
_END_PROBES = np.array([1e-3, *(np.arange(1, 8) / 8), 1.0 - 1e-3])
_ROW_BLOCK = 64  # rows whose samples are scanned together (see _extremes)


def side_text(side: Side | None) -> str:
    """``" (just before the joint)"``, ``" (just after the joint)"`` or ``""``."""
    if side == "left":
        return " (just before the joint)"
    if side == "right":
        return " (just after the joint)"
    return ""


@dataclass(frozen=True, slots=True, kw_only=True)
class Extreme:
    """The true maximum or minimum of a quantity over the cam turn.

    Attributes
    ----------
    value
        The extreme value (the quantity's unit).
    phi
        Where it is reached [rad], in [0, 2π]; 2π only for the limit just
        before the joint at 0°.
    side
        ``"left"`` when the extreme is the limit just before a joint at
        ``phi``, ``"right"`` just after it; ``None`` where the quantity is
        continuous.
    """

    value: float
    phi: float
    side: Side | None = None

    @property
    def angle_deg(self) -> float:
        """Where it is reached [deg], in [0, 360]; 360 only just before the joint at 0°."""
        deg = math.degrees(self.phi)
        return 360.0 if self.side == "left" and self.phi >= TWO_PI else round(deg % 360.0, 9)

    def where(self) -> str:
        """``"at 90.0°"`` or ``"at 90.0° (just before the joint)"``.

        Examples
        --------
        >>> Extreme(value=1.0, phi=math.pi / 2).where()
        'at 90.0°'
        >>> Extreme(value=-0.5, phi=math.pi / 2, side="left").where()
        'at 90.0° (just before the joint)'

        The limit just before the joint at 0° is reported at 360°:

        >>> Extreme(value=2.0, phi=TWO_PI, side="left").where()
        'at 360.0° (just before the joint)'
        """
        return f"at {self.angle_deg:.1f}°{side_text(self.side)}"


@dataclass(frozen=True, slots=True)
class _Sequence:
    """The samples of one turn split into smooth pieces: right values on the grid, left limits at ends."""

    phi: FloatArray  # (m,) rad, ascending within each piece
    value: FloatArray  # (k, m), one row per quantity
    piece: np.ndarray  # (m,) int, piece index
    left: np.ndarray  # (m,) bool, a left limit at a joint


def _rows(values: ArrayLike, k: int) -> FloatArray:
    out = np.asarray(values, dtype=float)
    return out.reshape(k, -1)


@dataclass(frozen=True, slots=True)
class _Layout:
    """Where each row's samples go in its :class:`_Sequence`: the grid's right values, then the extra columns.

    ``right`` (k, n) are the values on the grid, ``extra`` (k, j) the right
    values at joints off the grid and the left limits at the joints; ``order``
    (n + j,) sorts their columns into the sequence.
    """

    phi: FloatArray
    piece: np.ndarray
    left: np.ndarray
    order: np.ndarray
    right: FloatArray
    extra: FloatArray

    def rows(self, lo: int, hi: int) -> _Sequence:
        """The sequence of rows lo … hi − 1.

        Its columns are copied run by run (the grid's columns keep their
        order, the extra ones fall in between): one pass over the values.
        """
        n = self.right.shape[1]
        value = np.empty((hi - lo, self.order.size))
        for a, b, src in self.runs():
            if src < n:
                value[:, a:b] = self.right[lo:hi, src : src + b - a]
            else:
                value[:, a:b] = self.extra[lo:hi, src - n : src - n + b - a]
        return _Sequence(phi=self.phi, value=value, piece=self.piece, left=self.left)

    def runs(self) -> list[tuple[int, int, int]]:
        """(a, b, src): columns a … b − 1 of the sequence are source columns src … of right, then extra."""
        order, n = self.order, self.right.shape[1]
        cut = np.flatnonzero((np.diff(order) != 1) | (order[1:] == n)) + 1
        starts, ends = np.r_[0, cut].tolist(), np.r_[cut, order.size].tolist()
        return [(a, b, int(order[a])) for a, b in zip(starts, ends, strict=True)]


def _layout(
    quantity: Rows, grid: FloatArray, joints: FloatArray, values: FloatArray | None, k: int
) -> _Layout:
    bounds = np.union1d(np.mod(joints, TWO_PI), [0.0])
    right = _rows(quantity(grid, "right") if values is None else values, k)
    missing = bounds[~np.isin(bounds, grid)]
    extra = []
    if missing.size:  # a joint off the grid: add its right value too
        grid = np.concatenate((grid, missing))
        extra.append(_rows(quantity(missing, "right"), k))
    left_phi = np.where(bounds == 0.0, TWO_PI, bounds)
    extra.append(_rows(quantity(left_phi, "left"), k))
    piece_grid = np.searchsorted(bounds, grid, side="right") - 1
    piece_left = np.searchsorted(bounds, left_phi, side="left") - 1  # the piece that ends there
    phi = np.concatenate((grid, left_phi))
    order = np.lexsort((phi, np.concatenate((piece_grid, piece_left))))
    return _Layout(
        phi=phi[order],
        piece=np.concatenate((piece_grid, piece_left))[order],
        left=np.concatenate((np.zeros(grid.size, bool), np.ones(left_phi.size, bool)))[order],
        order=order,
        right=right,
        extra=np.concatenate(extra, axis=1),
    )


def _sequence(
    quantity: Rows, grid: FloatArray, joints: FloatArray, values: FloatArray | None, k: int
) -> _Sequence:
    """The samples of every row in one sequence (right values on the grid, left limits at the joints)."""
    return _layout(quantity, grid, joints, values, k).rows(0, k)


@dataclass(frozen=True, slots=True)
class _Brackets:
    """Brackets x1 < x2 < x3 [rad] of sampled maxima, with the (signed) values known there (nan: unknown)."""

    row: np.ndarray
    x1: FloatArray
    x2: FloatArray
    x3: FloatArray
    f1: FloatArray
    f2: FloatArray
    f3: FloatArray


def _peaks(val: FloatArray, same_prev: np.ndarray, same_next: np.ndarray) -> np.ndarray:
    """(k, m) bool: a finite sample at least its neighbours in its piece, not flat on both sides.

    Compared on the whole array (a neighbour outside the piece counts as
    −inf). ``val`` holds no NaN (a NaN sample is −inf), so x ≥ y is not
    (y > x) and x = y is y = x: two comparisons of neighbours serve both sides.
    """
    with np.errstate(invalid="ignore"):
        ge_prev, eq_prev = np.empty(val.shape, bool), np.empty(val.shape, bool)
        ge_next, eq_next = np.empty(val.shape, bool), np.empty(val.shape, bool)
        np.greater(val[:, 1:], val[:, :-1], out=ge_prev[:, 1:])  # for now: greater than the previous
        np.equal(val[:, 1:], val[:, :-1], out=eq_prev[:, 1:])
        np.logical_not(ge_prev[:, 1:], out=ge_next[:, :-1])  # v[i] ≥ v[i + 1]: v[i + 1] not greater
        eq_next[:, :-1] = eq_prev[:, 1:]
        np.logical_or(ge_prev[:, 1:], eq_prev[:, 1:], out=ge_prev[:, 1:])
        outside_prev, outside_next = np.flatnonzero(~same_prev), np.flatnonzero(~same_next)
        ge_prev[:, outside_prev] = eq_prev[:, outside_prev] = True  # no neighbour before a piece's start
        ge_next[:, outside_next] = eq_next[:, outside_next] = True  # nor after its end
        np.logical_and(ge_prev, ge_next, out=ge_prev)
        np.logical_and(ge_prev, np.isfinite(val), out=ge_prev)  # a peak
        np.logical_and(eq_prev, eq_next, out=eq_prev)  # flat on both sides
        np.logical_and(ge_prev, ~eq_prev, out=ge_prev)
    return ge_prev


def _neighbours(seq: _Sequence) -> tuple[np.ndarray, np.ndarray]:
    """Whether each sample's previous and next one lie in its piece."""
    m = seq.phi.size
    same_prev = np.zeros(m, bool)
    same_prev[1:] = seq.piece[1:] == seq.piece[:-1]
    same_next = np.zeros(m, bool)
    same_next[:-1] = seq.piece[:-1] == seq.piece[1:]
    return same_prev, same_next


def _outside_rests(seq: _Sequence, rests: Sequence[tuple[float, float]]) -> list[tuple[int, int]]:
    """The runs [a, b) of samples whose bracket may reach out of every rest (:func:`_without_rests`).

    A peak's bracket lies within its neighbours in its piece; where those lie
    within one rest, so does any bracket of it, which :func:`_without_rests`
    drops: such samples need not be looked at.
    """
    m = seq.phi.size
    if not len(rests) or m == 0:
        return [(0, m)]
    same_prev, same_next = _neighbours(seq)
    lo = np.where(same_prev, np.roll(seq.phi, 1), seq.phi)
    hi = np.where(same_next, np.roll(seq.phi, -1), seq.phi)
    span = np.asarray(rests, dtype=float).reshape(-1, 2)
    inside = np.any((lo[:, None] >= span[:, 0]) & (hi[:, None] <= span[:, 1]), axis=1)
    edges = np.flatnonzero(np.diff(np.r_[0, (~inside).astype(np.int8), 0]))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))


def _brackets(
    seq: _Sequence, val: FloatArray, best: FloatArray, runs: Sequence[tuple[int, int]] | None = None
) -> _Brackets:
    """Every sampled local maximum of each row of ``val`` (signed: maxima sought) that could beat ``best``.

    Interior peaks are bracketed by their two neighbours. A peak at a piece's
    end (a one-sided limit larger than its neighbour) gets the bracket
    [neighbour, end] too, since the function may rise above the limit just
    inside the piece. A peak is kept where its value plus four times its drop
    to the lower neighbour reaches the best sample: for a smooth peak the gain
    of the true maximum over the sample is at most a quarter of that drop, so
    this keeps a 16-fold margin. ``runs``: look at these runs [a, b) of
    samples only (:func:`_outside_rests`); all by default.
    """
    m = val.shape[1]
    same_prev, same_next = _neighbours(seq)
    if runs is None or list(runs) == [(0, m)]:
        rows, idx = np.nonzero(_peaks(val, same_prev, same_next))
    else:  # each run with its neighbours, the peaks then in the whole array's order (row by row)
        found_rows, found_idx = [np.empty(0, np.intp)], [np.empty(0, np.intp)]
        for a, b in runs:
            a0, b0 = max(a - 1, 0), min(b + 1, m)
            peak = _peaks(val[:, a0:b0], same_prev[a0:b0], same_next[a0:b0])
            r, i = np.nonzero(peak[:, a - a0 : b - a0])
            found_rows.append(r)
            found_idx.append(i + a)
        rows, idx = np.concatenate(found_rows), np.concatenate(found_idx)
        by_row = np.lexsort((idx, rows))
        rows, idx = rows[by_row], idx[by_row]
    with np.errstate(invalid="ignore"):
        here = val[rows, idx]
        prev_val = np.where(same_prev[idx], val[rows, idx - 1], -np.inf)
        next_val = np.where(same_next[idx], val[rows, (idx + 1) % m], -np.inf)
        lower = np.minimum(
            np.where(same_prev[idx], prev_val, np.inf), np.where(same_next[idx], next_val, np.inf)
        )
        drop = np.where(np.isfinite(lower), here - lower, np.inf)
        promising = here + 4.0 * drop >= best[rows]
    rows, idx = rows[promising], idx[promising]
    inner = same_prev[idx] & same_next[idx]
    out_rows, x1, x2, x3, f1, f2, f3 = [], [], [], [], [], [], []
    r, i = rows[inner], idx[inner]
    out_rows.append(r)
    x1.append(seq.phi[i - 1])
    x2.append(seq.phi[i])
    x3.append(seq.phi[i + 1])
    f1.append(val[r, i - 1])
    f2.append(val[r, i])
    f3.append(val[r, i + 1])
    for end_side, nb_step in ((same_prev & ~same_next, -1), (same_next & ~same_prev, 1)):
        sel = end_side[idx] & ~inner
        r, i = rows[sel], idx[sel]
        j = i + nb_step
        lo, hi = np.minimum(seq.phi[i], seq.phi[j]), np.maximum(seq.phi[i], seq.phi[j])
        out_rows.append(r)
        x1.append(lo)
        x3.append(hi)
        x2.append(np.full(r.size, np.nan))  # to be probed (see _probe_end_gaps)
        f_end, f_nb = val[r, i], val[r, j]
        f1.append(f_nb if nb_step < 0 else f_end)
        f3.append(f_end if nb_step < 0 else f_nb)
        f2.append(np.full(r.size, np.nan))

    def joined(parts: list[FloatArray]) -> FloatArray:
        out: FloatArray = np.concatenate(parts).astype(float)
        return out

    return _Brackets(
        np.concatenate(out_rows), joined(x1), joined(x2), joined(x3), joined(f1), joined(f2), joined(f3)
    )


def _fields(b: _Brackets) -> tuple[np.ndarray, ...]:
    return (b.row, b.x1, b.x2, b.x3, b.f1, b.f2, b.f3)


def _without_rests(b: _Brackets, rests: Sequence[tuple[float, float]]) -> _Brackets:
    """The brackets that do not lie within one of the ``rests`` (intervals [rad] where every row is flat)."""
    if not len(rests) or not b.x1.size:
        return b
    span = np.asarray(rests, dtype=float).reshape(-1, 2)
    inside: np.ndarray = np.any((b.x1[:, None] >= span[:, 0]) & (b.x3[:, None] <= span[:, 1]), axis=1)
    return _select(b, np.logical_not(inside))


def _select(b: _Brackets, keep: np.ndarray) -> _Brackets:
    """The brackets where ``keep`` (bool) is True."""
    if keep.all():
        return b
    return _Brackets(b.row[keep], b.x1[keep], b.x2[keep], b.x3[keep], b.f1[keep], b.f2[keep], b.f3[keep])


def _probe_end_gaps(f: _Picker, b: _Brackets) -> _Brackets:
    """Bracket the maxima hidden in the first or last sample gap of a piece, or drop the gap.

    Where a piece's end (a one-sided limit or the right value at a joint) is
    at least its neighbouring sample, the quantity may still rise from the end
    and fall back below it before that sample, so no sample shows the maximum
    (hypothesis found one: a contact force peaking 0.045° after a joint of a
    modified trapezoid). Each such gap (x2 unknown) is probed at
    ``_END_PROBES``, all in one call: where a probe beats both ends, it and
    its neighbours bracket the maximum; the probes a thousandth of the gap
    from the ends see a quantity that rises out of the end. Other gaps are
    dropped: the end's own value is already a candidate.
    """
    gap = np.flatnonzero(np.isnan(b.x2))
    if gap.size == 0:
        return b
    lo, hi = b.x1[gap], b.x3[gap]
    probes = lo[:, None] + (hi - lo)[:, None] * _END_PROBES
    f_probes = f(probes.ravel(), np.repeat(gap, _END_PROBES.size)).reshape(probes.shape)
    pts = np.column_stack((lo, probes, hi))
    fs = np.column_stack((b.f1[gap], f_probes, b.f3[gap]))
    # a probe must beat both ends: one that only ties the end (the top of a rise, flat to round-off
    # there) shows nothing rising above it
    j = 1 + np.argmax(fs[:, 1:-1], axis=1)
    hit = fs[np.arange(gap.size), j] > np.maximum(fs[:, 0], fs[:, -1])
    keep = np.ones(b.x1.size, bool)
    keep[gap[~hit]] = False
    g, jj, k = gap[hit], j[hit], np.flatnonzero(hit)
    x1, x2, x3 = b.x1.copy(), b.x2.copy(), b.x3.copy()
    f1, f2, f3 = b.f1.copy(), b.f2.copy(), b.f3.copy()
    x1[g], x2[g], x3[g] = pts[k, jj - 1], pts[k, jj], pts[k, jj + 1]
    f1[g], f2[g], f3[g] = fs[k, jj - 1], fs[k, jj], fs[k, jj + 1]
    return _Brackets(b.row[keep], x1[keep], x2[keep], x3[keep], f1[keep], f2[keep], f3[keep])


def _refine_max(f: _Picker, b: _Brackets) -> tuple[FloatArray, FloatArray]:
    """Maximise f on every bracket x1 < x2 < x3 with f known at all three; vectorised.

    Safeguarded successive parabolic interpolation (Brent 1973, ch. 5): each
    step evaluates the vertex of the parabola through the three best points,
    or a golden-section point of the larger side where the vertex is unusable,
    and keeps a bracket around the best point. It converges superlinearly on
    smooth maxima, so a dozen vectorised calls take every bracket to round-off.
    Only interior points are evaluated; the values at x1 and x3 come from the
    samples (they may be one-sided limits at joints).
    """
    a, b_, x = b.x1.copy(), b.x3.copy(), b.x2.copy()
    fx = b.f2.copy()
    w, fw = b.x1.copy(), b.f1.copy()
    v, fv = b.x3.copy(), b.f3.copy()
    # the best of the three seeds the search
    start = np.where(fw > fx, 1, np.where(fv > fx, 2, 0))
    x, fx, w, fw = (np.where(start == 1, w, x), np.where(start == 1, fw, fx),
                    np.where(start == 1, x, w), np.where(start == 1, fx, fw))  # fmt: skip
    x, fx, v, fv = (np.where(start == 2, v, x), np.where(start == 2, fv, fx),
                    np.where(start == 2, x, v), np.where(start == 2, fx, fv))  # fmt: skip
    u_prev = b.x3.copy()
    live = np.ones(x.size, bool)
    for _ in range(_ITERATIONS):
        width = b_ - a
        tol = _XTOL * np.maximum(1.0, np.abs(x))
        live &= width > 4.0 * tol
        if not live.any():
            break
        with np.errstate(divide="ignore", invalid="ignore"):  # ±inf values give no parabola: nan
            r = (x - w) * (fx - fv)
            s = (x - v) * (fx - fw)
            num = (x - v) * s - (x - w) * r
            den = 2.0 * (s - r)
            u = x - num / den
        inside = np.isfinite(u) & (u > a + tol) & (u < b_ - tol)
        live &= ~(inside & (np.abs(u - x) <= _XSTOP))  # the parabola's vertex is the point itself
        if not live.any():
            break
        usable = inside & (np.abs(u - x) > tol) & (np.abs(u - u_prev) > tol)  # no stalling on one point
        golden = np.where(x - a > b_ - x, x - _GOLDEN_SECTION * (x - a), x + _GOLDEN_SECTION * (b_ - x))
        u = np.where(usable, u, golden)
        fu = np.full(x.size, -np.inf)
        fu[live] = f(u[live], np.flatnonzero(live))
        # shrink the bracket around the best point
        better = (fu > fx) & live
        worse = ~better & live
        a = np.where(better & (u >= x), x, np.where(worse & (u < x), u, a))
        b_ = np.where(better & (u < x), x, np.where(worse & (u >= x), u, b_))
        v, fv = np.where(live, w, v), np.where(live, fw, fv)
        w = np.where(live, np.where(better, x, u), w)
        fw = np.where(live, np.where(better, fx, fu), fw)
        x = np.where(better, u, x)
        fx = np.where(better, fu, fx)
        u_prev = np.where(live, u, u_prev)
    return x, fx


def extremes_rows(
    quantity: Rows,
    grid: ArrayLike,
    joints: Sequence[float] | ArrayLike,
    kinds: Sequence[Kind],
    *,
    values: ArrayLike | None = None,
    rests: Sequence[tuple[float, float]] = (),
    settled: Sequence[bool] = (),
) -> tuple[Extreme, ...]:
    """The true extremes of several quantities at once, one per row of ``quantity``.

    Parameters
    ----------
    quantity
        q(φ, side) → (k, n) values: row r is the quantity whose extreme
        ``kinds[r]`` is sought. Rows share the angles, so a stage evaluates
        its model once per refinement step for all its quantities.
    grid, joints
        As for :func:`extremes`.
    kinds
        ``"min"`` or ``"max"`` for each row.
    values
        (k, n) ``quantity(grid, "right")`` if already computed.
    rests
        Intervals [start, end] [rad] of [0, 2π] over which every row is
        constant (the motion's dwells, where the follower stands still). A
        sampled "extremum" inside one is round-off on a flat stretch: it is
        not refined, and the samples there, both ends included, stand for
        the constant. Without them such a bracket is searched to the end
        (some forty evaluations) and kept only if it beats the samples by
        more than round-off, which it cannot.
    settled
        For each row (or none): True where the row takes only a few constant
        values over the whole turn (0 or ±inf, say, as a bound that is
        identically zero where it applies), so that its sampled extreme is
        exact and no search can beat it.

    Returns
    -------
    tuple[Extreme, ...]
        One per row, in order.
    """

    def pick(phi: FloatArray, rows: np.ndarray, side: Side) -> FloatArray:
        out: FloatArray = _rows(quantity(phi, side), k)[rows, np.arange(phi.size)]
        return out

    k = len(kinds)
    return _extremes(quantity, pick, grid, joints, kinds, values, rests=rests, settled=settled)


def extremes_each(
    pick: RowPick,
    rows: int,
    grid: ArrayLike,
    joints: Sequence[float] | ArrayLike,
    kinds: Sequence[Kind],
    *,
    values: ArrayLike | None = None,
) -> tuple[Extreme, ...]:
    """The true extremes of ``rows`` independent quantities, each evaluated only where its search needs it.

    Same search as :func:`extremes_rows` (samples, both sides of every
    joint, end-gap probes, vectorised Brent refinement of every promising
    sampled peak), but the quantity is called with the row of every angle,
    so one call serves the brackets of all rows at once without evaluating
    every row at every angle: a speed map refines all its speeds together.

    Parameters
    ----------
    pick
        q(φ, row, side) → values (n,), see :data:`RowPick`.
    rows
        Number of quantities k.
    grid, joints
        As for :func:`extremes`; shared by every row.
    kinds
        ``"min"`` or ``"max"`` for each row (k,).
    values
        (k, n) the rows on the grid (right values) if already computed.

    Returns
    -------
    tuple[Extreme, ...]
        One per row, in order.
    """

    def full(phi: FloatArray, side: Side) -> FloatArray:
        n = phi.size
        which = np.repeat(np.arange(rows), n)
        return np.asarray(pick(np.tile(phi, rows), which, side), dtype=float).reshape(rows, n)

    def each(phi: FloatArray, which: np.ndarray, side: Side) -> FloatArray:
        return np.asarray(pick(phi, which, side), dtype=float)

    return _extremes(full, each, grid, joints, kinds, values)


def _extremes(
    quantity: Rows,
    pick: RowPick,
    grid: ArrayLike,
    joints: Sequence[float] | ArrayLike,
    kinds: Sequence[Kind],
    values: ArrayLike | None,
    *,
    rests: Sequence[tuple[float, float]] = (),
    settled: Sequence[bool] = (),
) -> tuple[Extreme, ...]:
    """:func:`extremes_rows` with ``quantity`` for whole rows and ``pick`` for one row per angle."""
    answers = _SERVED.get()
    if answers is not None and values is not None:
        got = answers.take(grid, joints, kinds, values, rests, settled)
        if got is not None:
            return got
    k = len(kinds)
    grid_a = np.asarray(grid, dtype=float)
    layout = _layout(
        quantity,
        grid_a,
        np.asarray(joints, dtype=float).ravel(),
        None if values is None else _rows(values, k),
        k,
    )
    sign = np.array([1.0 if kind == "max" else -1.0 for kind in kinds])[:, None]
    best = np.empty(k)
    found: list[Extreme] = []
    twins: dict[int, int] = {}
    parts: list[_Brackets] = []
    runs: list[tuple[int, int]] | None = None
    # the samples' extremes and the brackets, _ROW_BLOCK rows at a time (each row's alone: a block's
    # arrays stay in the processor's cache when a batch stacks the rows of many analyses)
    for lo in range(0, k, _ROW_BLOCK):
        hi = min(k, lo + _ROW_BLOCK)
        seq = layout.rows(lo, hi)
        sg = sign[lo:hi]
        val = sg * seq.value  # signed (exact: ±1), a NaN sample then −inf
        np.copyto(val, -np.inf, where=np.isnan(val))
        top = np.argmax(val, axis=1)
        best[lo:hi] = val[np.arange(hi - lo), top]
        found += [
            Extreme(value=v, phi=f, side=side)
            for v, f, side in zip(
                seq.value[np.arange(hi - lo), top].tolist(),
                seq.phi[top].tolist(),
                _sample_sides(seq, top, twins),
                strict=True,
            )
        ]
        if runs is None:  # the samples a bracket outside every rest may come from (the same for all rows)
            runs = _outside_rests(seq, rests)
        b = _brackets(seq, val, best[lo:hi], runs)
        parts.append(_Brackets(b.row + lo, b.x1, b.x2, b.x3, b.f1, b.f2, b.f3))
    br = (
        parts[0]
        if len(parts) == 1
        else _Brackets(*(np.concatenate(f) for f in zip(*(_fields(b) for b in parts), strict=True)))
    )
    br = _without_rests(br, rests)
    if any(settled):
        searched: np.ndarray = np.logical_not(np.asarray(settled, dtype=bool))[br.row]
        br = _select(br, searched)
    picker = _Picker(pick, sign[:, 0], br.row)
    br = _probe_end_gaps(picker, br)
    if br.x1.size:
        phi_best, f_best = _refine_max(_Picker(pick, sign[:, 0], br.row), br)
        by_row = np.argsort(br.row, kind="stable")  # each row's brackets together, in their order
        rows_sorted = br.row[by_row]
        starts = np.flatnonzero(np.r_[True, rows_sorted[1:] != rows_sorted[:-1]])
        for lo, hi in zip(starts.tolist(), [*starts[1:].tolist(), by_row.size], strict=True):
            r = int(rows_sorted[lo])
            mine = by_row[lo:hi]
            if mine.size:
                i = mine[int(np.argmax(f_best[mine]))]
                # a gain within round-off (a flat stretch, say a dwell) keeps the sample
                if f_best[i] > best[r] + _ROUNDOFF * max(1.0, abs(best[r])):
                    found[r] = Extreme(value=float(sign[r, 0] * f_best[i]), phi=float(phi_best[i]), side=None)
    return tuple(found)


@dataclass(frozen=True, slots=True)
class _Picker:
    """f(φ) for the refinement: each bracket's own row of the quantity, signed so maxima are sought."""

    pick: RowPick
    sign: FloatArray
    row: np.ndarray

    def __call__(self, phi: FloatArray, which: np.ndarray) -> FloatArray:
        """sign·q_row(φ) for the brackets ``which`` (indices), at their points ``phi``; nan → −inf."""
        rows = self.row[which]
        out = self.sign[rows] * np.asarray(self.pick(phi, rows, "right"), dtype=float)
        return np.where(np.isnan(out), -np.inf, out)


def extremes(
    quantity: Quantity,
    grid: ArrayLike,
    joints: Sequence[float] | ArrayLike,
    *,
    values: ArrayLike | None = None,
    find: tuple[Kind, ...] = ("min", "max"),
) -> tuple[Extreme, ...]:
    """The true minimum and/or maximum of ``quantity`` over the cam turn.

    Parameters
    ----------
    quantity
        The exact quantity, see :data:`Quantity`. It may return ``inf`` where
        it is not defined for the extreme sought (e.g. a convex radius of
        curvature on a concave stretch) and ``nan`` nowhere it matters.
    grid
        (n,) sorted sample angles in [0, 2π) [rad]; every joint should be one.
    joints
        Angles [rad] where the quantity may jump (the motion's breakpoints);
        0° is always treated as one.
    values
        ``quantity(grid, "right")`` if already computed.
    find
        Which extremes, in the order returned: ``("min", "max")`` by default.

    Returns
    -------
    tuple[Extreme, ...]
        One per entry of ``find``; each is an interior extremum refined on the
        exact quantity (φ to ~1e-9 rad, the value to round-off), a one-sided
        limit at a joint, or a sample of a flat stretch, whichever is more
        extreme.
    """
    k = len(find)

    def rows(phi: FloatArray, side: Side) -> FloatArray:
        return np.broadcast_to(np.asarray(quantity(phi, side), dtype=float), (k, np.size(phi)))

    stacked = (
        None if values is None else np.broadcast_to(np.asarray(values, dtype=float), (k, np.size(values)))
    )
    return extremes_rows(rows, grid, joints, find, values=stacked)


def maximum(
    quantity: Quantity,
    grid: ArrayLike,
    joints: Sequence[float] | ArrayLike,
    *,
    values: ArrayLike | None = None,
) -> Extreme:
    """The true maximum of ``quantity`` over the cam turn; see :func:`extremes`."""
    return extremes(quantity, grid, joints, values=values, find=("max",))[0]


def minimum(
    quantity: Quantity,
    grid: ArrayLike,
    joints: Sequence[float] | ArrayLike,
    *,
    values: ArrayLike | None = None,
) -> Extreme:
    """The true minimum of ``quantity`` over the cam turn; see :func:`extremes`."""
    return extremes(quantity, grid, joints, values=values, find=("min",))[0]


def _sample_side(seq: _Sequence, row: int, k: int, twins: dict[int, int] | None = None) -> Side | None:
    """The side of sample k of a row: a left limit, or a right value where the left limit differs.

    ``twins`` keeps each sample's twin (the other side at the same joint, −1
    for none) across the rows of one search, which share the samples.
    """
    twin = -1 if twins is None else twins.get(k, -2)
    if twin == -2 or twins is None:
        if seq.left[k]:
            found = np.flatnonzero((np.mod(seq.phi, TWO_PI) == seq.phi[k] % TWO_PI) & ~seq.left)
        else:
            found = np.flatnonzero((seq.phi == (TWO_PI if seq.phi[k] == 0.0 else seq.phi[k])) & seq.left)
        twin = int(found[0]) if found.size else -1
        if twins is not None:
            twins[k] = twin
    value = seq.value[row]
    if seq.left[k]:
        return None if twin >= 0 and _same(value[twin], value[k]) else "left"
    return "right" if twin >= 0 and not _same(value[twin], value[k]) else None


def _sample_sides(seq: _Sequence, top: np.ndarray, twins: dict[int, int]) -> list[Side | None]:
    """:func:`_sample_side` of sample ``top[r]`` of every row r, all rows at once (the same rule)."""
    for k in np.unique(top).tolist():
        if k not in twins:
            _sample_side(seq, 0, k, twins)  # finds and keeps the sample's twin
    twin = np.array([twins[k] for k in top.tolist()], dtype=int)
    rows = np.arange(top.size)
    x = seq.value[rows, np.maximum(twin, 0)]
    y = seq.value[rows, top]
    with np.errstate(invalid="ignore"):  # _same, elementwise
        same = (x == y) | (np.abs(x - y) <= _CONTINUOUS_RTOL * np.maximum(np.abs(x), np.abs(y)))
    paired = twin >= 0
    left = seq.left[top]
    words: list[Side | None] = [None, "left", "right"]
    code = np.where(left, np.where(paired & same, 0, 1), np.where(paired & ~same, 2, 0))
    return [words[c] for c in code.tolist()]


def _same(x: float, y: float) -> bool:
    """Whether two one-sided limits agree to round-off (the quantity is continuous there)."""
    return bool(x == y or abs(x - y) <= _CONTINUOUS_RTOL * max(abs(x), abs(y)))


@dataclass(frozen=True, slots=True)
class _Answer:
    """One search done ahead (see :func:`served`): its inputs, which must match, and its extremes."""

    grid: FloatArray
    joints: FloatArray
    kinds: tuple[Kind, ...]
    values: FloatArray
    rests: tuple[tuple[float, float], ...]
    settled: tuple[bool, ...]
    found: tuple[Extreme, ...]


class _Answers:
    """Searches done ahead for one analysis, each given once to the call with exactly its inputs."""

    def __init__(self, answers: Sequence[_Answer]) -> None:
        self.left = list(answers)
        self.used = 0

    def take(
        self,
        grid: ArrayLike,
        joints: Sequence[float] | ArrayLike,
        kinds: Sequence[Kind],
        values: ArrayLike,
        rests: Sequence[tuple[float, float]],
        settled: Sequence[bool],
    ) -> tuple[Extreme, ...] | None:
        for i, a in enumerate(self.left):
            if (
                a.kinds == tuple(kinds)
                and a.rests == tuple(tuple(r) for r in rests)
                and a.settled == tuple(bool(x) for x in settled)
                and _same_bits(a.grid, np.asarray(grid, dtype=float))
                and _same_bits(a.joints, np.asarray(joints, dtype=float).ravel())
                and _same_bits(a.values, _rows(values, len(kinds)))
            ):
                del self.left[i]
                self.used += 1
                return a.found
        return None


def _same_bits(a: FloatArray, b: FloatArray) -> bool:
    """Whether two arrays hold the same numbers bit for bit (−0.0 is not 0.0, NaN is NaN)."""
    if a.shape != b.shape:
        return False
    if a.dtype == b.dtype == np.float64:  # the bits as integers, compared in place (no copies)
        return bool(
            np.array_equal(np.ascontiguousarray(a).view(np.int64), np.ascontiguousarray(b).view(np.int64))
        )
    return np.ascontiguousarray(a).tobytes() == np.ascontiguousarray(b).tobytes()


_SERVED: ContextVar[_Answers | None] = ContextVar("camcad_extremes_served", default=None)


def extremes_stacked(
    quantity: Rows,
    pick: RowPick,
    grid: ArrayLike,
    joints: Sequence[float] | ArrayLike,
    kinds: Sequence[Kind],
    *,
    values: ArrayLike | None = None,
    rests: Sequence[tuple[float, float]] = (),
    settled: Sequence[bool] = (),
) -> tuple[Extreme, ...]:
    """:func:`extremes_rows` for many independent rows: ``quantity`` for all rows, ``pick`` for one each.

    The search of every row is the one :func:`extremes_rows` does for it
    alone: its samples, its brackets and the vectorised refinement are
    elementwise per row and per bracket, so stacking the rows of many
    analyses (a batch of design variants, :mod:`camcad.explore.batch`)
    changes no bit of any row's result, only how many calls the quantity
    takes.
    """
    return _extremes(quantity, pick, grid, joints, kinds, values, rests=rests, settled=settled)


@contextlib.contextmanager
def served(
    answers: Sequence[
        tuple[
            FloatArray,
            FloatArray,
            Sequence[Kind],
            FloatArray,
            Sequence[tuple[float, float]],
            Sequence[bool],
            tuple[Extreme, ...],
        ]
    ],
) -> Iterator[_Answers]:
    """Within the block, a search whose inputs equal one of ``answers`` returns that answer's extremes.

    Each answer is (grid, joints, kinds, values, rests, settled, extremes),
    found ahead by :func:`extremes_stacked` for many analyses at once. A call
    takes an answer only when its grid, joints, kinds, rests, settled rows
    and sampled values are exactly the answer's, bit for bit (the values decide the
    search, the quantity being the one the answer was found on), and each
    answer once; any other call searches as usual. The yielded object's
    ``used`` counts the answers taken.
    """
    held = _Answers(
        [
            _Answer(
                grid=np.asarray(g, dtype=float),
                joints=np.asarray(j, dtype=float).ravel(),
                kinds=tuple(k),
                values=_rows(v, len(k)),
                rests=tuple(tuple(r) for r in rs),  # type: ignore[misc]
                settled=tuple(bool(x) for x in st),
                found=found,
            )
            for g, j, k, v, rs, st, found in answers
        ]
    )
    token = _SERVED.set(held)
    try:
        yield held
    finally:
        _SERVED.reset(token)
