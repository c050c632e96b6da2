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

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from camcad._typing import ArrayLike, FloatArray
from camcad.angles import TWO_PI

__all__ = ["SIDE_WORDS", "Extreme", "Kind", "Quantity", "Side", "extremes", "maximum", "minimum", "side_text"]

Side = Literal["left", "right"]
"""Which one-sided limit at a joint: ``"left"`` (just before it), ``"right"`` (just after)."""

Kind = Literal["min", "max"]
"""Which extreme to find."""

Quantity = Callable[[FloatArray, Side], FloatArray]
"""An exact quantity q(φ) [any unit]: cam angles (n,) [rad] and a side → values (n,).

``side`` matters only at joints, where the quantity takes that one-sided limit.
"""

SIDE_WORDS = {"left": "before joint", "right": "after joint"}
"""How summary.json names a one-sided limit (the ``*_side`` keys)."""

_GOLDEN_SECTION = (3.0 - math.sqrt(5.0)) / 2.0  # 0.382: the golden step into the larger side
_CONTINUOUS_RTOL = 1e-9  # one-sided limits this close are one value: no "just before the joint"
_ITERATIONS = 60  # at most; a golden step alone shrinks a bracket by 0.618 (0.618^60 ≈ 3e-13)
_XTOL = 1e-11  # rad: the smallest step the search takes
_XSTOP = 1e-9  # rad: a parabolic step this small has converged (the value's error is ~q″·1e-18)
# Where a piece's first and last sample gaps are probed, as fractions of the gap (see _end_brackets):
# next to both ends, which catches a peak right beside a joint, and at eighths.
_END_PROBES = np.array([1e-3, *(np.arange(1, 8) / 8), 1.0 - 1e-3])


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
    value: FloatArray  # (m,)
    piece: np.ndarray  # (m,) int, piece index
    left: np.ndarray  # (m,) bool, a left limit at a joint


def _sequence(
    quantity: Quantity, grid: FloatArray, joints: FloatArray, values: FloatArray | None
) -> _Sequence:
    bounds = np.union1d(np.mod(joints, TWO_PI), [0.0])
    right = np.asarray(quantity(grid, "right") if values is None else values, dtype=float)
    missing = bounds[~np.isin(bounds, grid)]
    if missing.size:  # a joint off the grid: add its right value too
        grid = np.concatenate((grid, missing))
        right = np.concatenate((right, np.asarray(quantity(missing, "right"), dtype=float)))
    left_phi = np.where(bounds == 0.0, TWO_PI, bounds)
    left = np.asarray(quantity(left_phi, "left"), dtype=float)
    piece_grid = np.searchsorted(bounds, grid, side="right") - 1
    piece_left = np.searchsorted(bounds, left_phi, side="left") - 1  # the piece that ends there
    phi = np.concatenate((grid, left_phi))
    order = np.lexsort((phi, np.concatenate((piece_grid, piece_left))))
    return _Sequence(
        phi=phi[order],
        value=np.concatenate((right, left))[order],
        piece=np.concatenate((piece_grid, piece_left))[order],
        left=np.concatenate((np.zeros(grid.size, bool), np.ones(left_phi.size, bool)))[order],
    )


def _brackets(seq: _Sequence, sign: float) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(lo, mid, hi, sign·value at mid) of every non-flat local maximum of sign·value inside its piece."""
    val = sign * np.where(np.isnan(seq.value), -sign * np.inf, seq.value)
    m = val.size
    same_prev = np.zeros(m, bool)
    same_prev[1:] = seq.piece[1:] == seq.piece[:-1]
    same_next = np.zeros(m, bool)
    same_next[:-1] = seq.piece[:-1] == seq.piece[1:]
    prev_val = np.where(same_prev, np.roll(val, 1), -np.inf)
    next_val = np.where(same_next, np.roll(val, -1), -np.inf)
    peak = (val >= prev_val) & (val >= next_val) & np.isfinite(val)
    flat = (~same_prev | (val == prev_val)) & (~same_next | (val == next_val))
    idx = np.flatnonzero(peak & ~flat)
    # interior peaks only: a peak at a piece's end is a one-sided limit (or its right value), and
    # any maximum just inside the end is caught by the neighbouring sample's bracket
    idx = idx[same_prev[idx] & same_next[idx]]
    return seq.phi[idx - 1], seq.phi[idx], seq.phi[idx + 1], val[idx]


def _end_brackets(
    quantity: Quantity, seq: _Sequence, sign: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Brackets of maxima of sign·value hidden in a piece's first or last sample gap.

    Where a piece's end (a one-sided limit or the right value at a joint) is
    at least its neighbouring sample, the quantity may still rise from the end
    and fall back below it before that sample, so no sample shows the
    maximum. Each such gap is probed at ``_END_PROBES``: where a probe beats
    both ends, it and its neighbours bracket the maximum. The probes beside
    the ends see the slope there: a quantity that rises from the end into the
    gap beats the end a thousandth of the gap inside.
    """
    val = sign * np.where(np.isnan(seq.value), -sign * np.inf, seq.value)
    same_prev = np.zeros(val.size, bool)
    same_prev[1:] = seq.piece[1:] == seq.piece[:-1]
    same_next = np.zeros(val.size, bool)
    same_next[:-1] = seq.piece[:-1] == seq.piece[1:]
    finite = np.isfinite(val)
    first = np.flatnonzero(~same_prev & same_next & finite & (val >= np.roll(val, -1)))
    last = np.flatnonzero(same_prev & ~same_next & finite & (val >= np.roll(val, 1)))
    lo_i, hi_i = np.concatenate((first, last - 1)), np.concatenate((first + 1, last))
    if lo_i.size == 0:
        empty = np.zeros(0)
        return empty, empty, empty, empty
    a, b = seq.phi[lo_i], seq.phi[hi_i]
    inner = a[:, None] + (b - a)[:, None] * _END_PROBES
    f_inner = sign * np.asarray(quantity(inner.ravel(), "right"), dtype=float).reshape(inner.shape)
    pts = np.column_stack((a, inner, b))
    f_inner = np.where(np.isfinite(f_inner), f_inner, -np.inf)  # as _brackets: finite peaks only
    fs = np.column_stack((val[lo_i], f_inner, val[hi_i]))
    j = np.argmax(fs, axis=1)
    rows = np.flatnonzero((j > 0) & (j < pts.shape[1] - 1))
    j = j[rows]
    return pts[rows, j - 1], pts[rows, j], pts[rows, j + 1], fs[rows, j]


def _refine_max(
    quantity: Quantity, x1: FloatArray, x2: FloatArray, x3: FloatArray, f2: FloatArray, sign: float
) -> tuple[FloatArray, FloatArray]:
    """Maximise sign·q on every bracket x1 < x2 < x3 with q(x2) ≥ q(x1), q(x3); vectorised.

    Safeguarded successive parabolic interpolation (Brent 1973, ch. 5): each
    step evaluates the vertex of the parabola through the three best points,
    or a golden-section point of the larger side where the vertex is unusable,
    and keeps a bracket around the best point. It converges superlinearly on
    smooth maxima, so a dozen vectorised calls take every bracket to round-off.
    """

    def q(phi: FloatArray) -> FloatArray:
        out = sign * np.asarray(quantity(phi, "right"), dtype=float)
        return np.where(np.isnan(out), -np.inf, out)

    a, b = x1.copy(), x3.copy()
    x, fx = x2.copy(), f2.copy()
    w, fw = x1.copy(), q(x1)
    u_prev = x3.copy()
    fv_w = q(x3)
    v, fv = x3.copy(), fv_w
    live = np.ones(x.size, bool)
    for _ in range(_ITERATIONS):
        width = b - a
        tol = _XTOL * np.maximum(1.0, np.abs(x))
        live &= width > 4.0 * tol
        if not live.any():
            break
        # parabola through (v, fv), (w, fw), (x, fx): vertex u = x − ½·num/den
        with np.errstate(divide="ignore", invalid="ignore"):  # ±inf values give no parabola: nan
            r = (x - w) * (fx - fv)
            s = (x - v) * (fx - fw)
            num = (x - v) * s - (x - w) * r
            den = 2.0 * (s - r)
            u = x - num / den
        inside = np.isfinite(u) & (u > a + tol) & (u < b - tol)
        live &= ~(inside & (np.abs(u - x) <= _XSTOP))  # the parabola's vertex is the point itself
        usable = inside & (np.abs(u - x) > tol) & (np.abs(u - u_prev) > tol)  # no stalling on one point
        golden = np.where(x - a > b - x, x - _GOLDEN_SECTION * (x - a), x + _GOLDEN_SECTION * (b - x))
        u = np.where(usable, u, golden)
        u = np.where(live, u, x)
        fu = q(u)
        better = (fu > fx) & live
        # shrink the bracket around the best point
        a = np.where(better, np.where(u < x, a, x), np.where(u < x, u, a))
        b = np.where(better, np.where(u < x, x, b), np.where(u < x, b, u))
        a = np.where(live, a, a)
        v, fv = np.where(live, w, v), np.where(live, fw, fv)
        w = np.where(live, np.where(better, x, u), w)
        fw = np.where(live, np.where(better, fx, fu), fw)
        x = np.where(better, u, x)
        fx = np.where(better, fu, fx)
        u_prev = u
    return x, fx


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
    grid_a = np.asarray(grid, dtype=float)
    seq = _sequence(
        quantity,
        grid_a,
        np.asarray(joints, dtype=float).ravel(),
        None if values is None else np.asarray(values, dtype=float),
    )
    found = []
    for kind in find:
        sign = 1.0 if kind == "max" else -1.0
        val = sign * np.where(np.isnan(seq.value), -sign * np.inf, seq.value)
        k = int(np.argmax(val))
        best = Extreme(value=float(seq.value[k]), phi=float(seq.phi[k]), side=_sample_side(seq, k))
        inside, at_ends = _brackets(seq, sign), _end_brackets(quantity, seq, sign)
        lo, mid, hi, f_mid = (np.concatenate(pair) for pair in zip(inside, at_ends, strict=True))
        if lo.size:
            phi, f = _refine_max(quantity, lo, mid, hi, f_mid, sign)
            i = int(np.argmax(f))
            if f[i] > val[k]:
                best = Extreme(value=float(sign * f[i]), phi=float(phi[i]), side=None)
        found.append(best)
    return tuple(found)


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


def _sample_side(seq: _Sequence, k: int) -> Side | None:
    """The side of sample k: a left limit, or a right value where the left limit differs."""
    if seq.left[k]:
        twin = np.flatnonzero((np.mod(seq.phi, TWO_PI) == seq.phi[k] % TWO_PI) & ~seq.left)
        return None if twin.size and _same(seq.value[twin[0]], seq.value[k]) else "left"
    twin = np.flatnonzero((seq.phi == (TWO_PI if seq.phi[k] == 0.0 else seq.phi[k])) & seq.left)
    return "right" if twin.size and not _same(seq.value[twin[0]], seq.value[k]) else None


def _same(x: float, y: float) -> bool:
    """Whether two one-sided limits agree to round-off (the quantity is continuous there)."""
    return bool(x == y or abs(x - y) <= _CONTINUOUS_RTOL * max(abs(x), abs(y)))
