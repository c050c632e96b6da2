"""Knot placement: breakpoint knots with multiplicity, equidistributed free knots.

A motion breakpoint where the profile is only C^k becomes a knot of
multiplicity p − k, so the spline may break exactly where the profile does.
The free knots between these fixed knots are placed in two steps:

- how many free knots each segment between fixed knots gets follows the
  intrinsic density |D^{p+1} C|^{1/(p+1)}, estimated from the jumps of the
  fitted spline's p-th derivative across its free knots (de Boor's NEWNOT,
  de Boor 2001, ch. XII). It is a property of the curve, so the split does
  not chase error that a segment only inherits from its neighbours;
- inside a segment the knots sit at equal shares of the error density
  m = e_j^{1/(p+1)} / h_j (e_j the largest error on span j): with
  e_j ≈ c_j h_j^{p+1}, equal shares give each span a similar error
  (equidistribution). Neighbouring densities are limited to a ratio
  ``GRADING`` so the re-placement does not oscillate.

References
----------
.. [1] de Boor (2001), A Practical Guide to Splines, rev. ed., Springer.
   doi:10.1007/978-1-4612-6333-3
.. [2] Piegl & Tiller (1997), The NURBS Book, 2nd ed., Springer.
   doi:10.1007/978-3-642-59223-2
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.fit.curve import BSplineCurve, IntArray, derivative_control_points, find_span

__all__ = [
    "GRADING",
    "MIN_SAMPLE_GAP",
    "Density",
    "FixedKnots",
    "density_from_fit",
    "estimate_free_knots",
    "fixed_knots",
    "place_knots",
]

MIN_SAMPLE_GAP = 2.0  # samples between neighbouring free knots, keeps every span fitted
GRADING = 1.5  # largest knot-density ratio between neighbouring spans


@dataclass(frozen=True, slots=True, kw_only=True)
class FixedKnots:
    """Knots that every layout keeps: the seam (or the ends) and the breakpoints.

    Attributes
    ----------
    position
        (f,) distinct fixed knot parameters, increasing. Periodic: in [0, 1)
        with ``position[0] = 0`` (the seam). Open: ``0 … 1`` including the
        clamped ends.
    multiplicity
        (f,) multiplicity of each fixed knot in the spline (ends of an open
        curve: 0 here, the clamped end knots are added by the knot vector).
    periodic
        Whether the spline is periodic with unit period.
    """

    position: FloatArray
    multiplicity: IntArray
    periodic: bool

    @property
    def edges(self) -> FloatArray:
        """(s + 1,) segment ends: the fixed knots and, for periodic, the period end 1."""
        return np.append(self.position, 1.0) if self.periodic else self.position

    @property
    def n_segments(self) -> int:
        """Number of segments between fixed knots."""
        return len(self.edges) - 1

    @property
    def n_fixed(self) -> int:
        """Number of fixed knots counted with multiplicity (inside one period)."""
        return int(np.sum(self.multiplicity))


@dataclass(frozen=True, slots=True, kw_only=True)
class Density:
    """Piecewise-constant knot density m(u) on [0, 1].

    Attributes
    ----------
    edges
        (e + 1,) increasing span ends from 0 to 1.
    values
        (e,) density on each span [1/unit u], positive; knots sit at equal
        shares of its integral inside a segment.
    need
        (e,) intrinsic density |D^{p+1} C|^{1/(p+1)}; its integral over a
        segment decides how many free knots the segment gets.
    """

    edges: FloatArray
    values: FloatArray
    need: FloatArray

    @classmethod
    def uniform(cls) -> Density:
        """The constant density (uniform knots in chord length)."""
        one = np.array([1.0])
        return cls(edges=np.array([0.0, 1.0]), values=one, need=one)

    def cumulative(self, u: FloatArray, *, need: bool = False) -> FloatArray:
        """∫₀ᵘ m (or the ungraded need), piecewise linear in u."""
        dens = self.need if need else self.values
        cum = np.concatenate(([0.0], np.cumsum(dens * np.diff(self.edges))))
        return np.interp(u, self.edges, cum)


def fixed_knots(breaks: Sequence[tuple[float, int]], *, degree: int, periodic: bool) -> FixedKnots:
    """Fixed knots from breakpoints given as (parameter, continuity).

    Parameters
    ----------
    breaks
        (u_k, k) pairs: the curve is C^k at parameter u_k (in [0, 1)). A
        breakpoint with k >= degree needs no knot; equal parameters merge,
        keeping the lowest continuity.
    degree
        Degree p.
    periodic
        Add the seam knot u = 0 (multiplicity at least 1) for a periodic
        spline; ends 0 and 1 for an open one.

    Returns
    -------
    FixedKnots
        Fixed knots with multiplicity p − k (Piegl & Tiller 1997, §2.2,
        §2.2: a knot of multiplicity μ leaves C^{p−μ}).
    """
    mult: dict[float, int] = {0.0: 1 if periodic else 0}
    if not periodic:
        mult[1.0] = 0
    for u, k in breaks:
        if k < 0:
            raise ValueError(f"breakpoint continuity must be >= 0, got {k}")
        if k >= degree:
            continue
        key = float(u) % 1.0 if periodic else float(u)
        if not periodic and key in (0.0, 1.0):
            continue
        mult[key] = max(mult.get(key, 0), degree - k)  # C^{p−μ} at a μ-fold knot, Piegl & Tiller 1997, §2.2
    keys = sorted(mult)
    position = np.array(keys, dtype=float)
    multiplicity = np.array([mult[k] for k in keys], dtype=np.intp)
    readonly(position)
    multiplicity.flags.writeable = False
    return FixedKnots(position=position, multiplicity=multiplicity, periodic=periodic)


def _allocate(weights: FloatArray, capacity: IntArray, n_free: int) -> IntArray:
    """Split ``n_free`` knots among segments, minimising max weight / (count + 1)."""
    counts = np.zeros(len(weights), dtype=np.intp)
    heap = [(-w, i) for i, w in enumerate(weights) if capacity[i] > 0]
    heapq.heapify(heap)
    for _ in range(n_free):
        if not heap:
            break
        _, i = heapq.heappop(heap)
        counts[i] += 1
        if counts[i] < capacity[i]:
            heapq.heappush(heap, (-weights[i] / (counts[i] + 1), i))
    return counts


def _spread(x: FloatArray, lo: float, hi: float, gap: float) -> FloatArray:
    """Move sorted x inside [lo, hi] so neighbours (and the ends) are >= gap apart."""
    n = len(x)
    if n == 0:
        return x
    g = min(gap, (hi - lo) / (n + 1))
    k = np.arange(1, n + 1)
    x = np.maximum.accumulate(np.maximum(x - k * g, lo)) + k * g
    tail = (n + 1 - k) * g
    x = np.minimum.accumulate(np.minimum(x + tail, hi)[::-1])[::-1] - tail
    return x


def place_knots(fixed: FixedKnots, density: Density, n_free: int, params: FloatArray) -> FloatArray:
    """Knot sequence with ``n_free`` knots equidistributed between the fixed ones.

    Parameters
    ----------
    fixed
        Fixed knots.
    density
        Knot density: ``need`` splits the free knots among segments,
        ``values`` (m) places them inside a segment at equal shares of ∫ m.
    n_free
        Number of free knots.
    params
        (n,) increasing sample parameters; free knots keep at least
        ``MIN_SAMPLE_GAP`` samples apart so every span is fitted.

    Returns
    -------
    FloatArray
        Periodic: (K,) one period ``0 = tau[0] <= …< 1`` with multiplicities.
        Open: the interior knots in (0, 1).

    Notes
    -----
    Segments between fixed knots receive free knots greedily so that the
    largest share ∫_seg need / (count + 1) is smallest; inside a segment the
    knots sit at equal quantiles of ∫ m (equidistribution, de Boor 2001,
    ch. XII).
    """
    edges = fixed.edges
    t_ext = np.append(params, 1.0) if fixed.periodic else np.asarray(params)
    index = np.arange(len(t_ext), dtype=float)
    cum_edges = density.cumulative(edges)
    weights = np.diff(cum_edges)
    edge_index = np.interp(edges, t_ext, index)
    capacity = np.floor(np.diff(edge_index) / MIN_SAMPLE_GAP).astype(np.intp) - 1
    counts = _allocate(np.diff(density.cumulative(edges, need=True)), np.maximum(capacity, 0), n_free)
    grid = np.union1d(density.edges, edges)
    cum_grid = density.cumulative(grid)
    free = []
    for s, count in enumerate(counts):
        if count == 0:
            continue
        targets = cum_edges[s] + weights[s] * np.arange(1, count + 1) / (count + 1)
        knots = np.interp(targets, cum_grid, grid)  # equal shares of ∫ m (de Boor 2001, ch. XII)
        pos = _spread(np.interp(knots, t_ext, index), edge_index[s], edge_index[s + 1], MIN_SAMPLE_GAP)
        free.append(np.interp(pos, index, t_ext))
    fixed_rep = np.repeat(fixed.position, fixed.multiplicity)
    out = np.sort(np.concatenate([fixed_rep, *free]))
    readonly(out)
    return out


def _graded(log_values: FloatArray, log_ratio: float, periodic: bool) -> FloatArray:
    """Raise log densities so neighbours differ by at most ``log_ratio``.

    Running maxima of lv_j ± j·log_ratio in both directions (over three
    copies for a periodic spline, so the wrap is seen from both sides).
    """
    n = len(log_values)
    x = np.tile(log_values, 3) if periodic else log_values.copy()
    j = np.arange(len(x)) * log_ratio
    x = np.maximum.accumulate(x + j) - j
    x = (np.maximum.accumulate((x - j)[::-1]) + j[::-1])[::-1]
    graded: FloatArray = x[n : 2 * n] if periodic else x
    return graded


def _error_density(edges: FloatArray, params: FloatArray, errors: FloatArray, degree: int) -> FloatArray:
    """Log of e_j^{1/(p+1)} / h_j per span (spans without error get the smallest value)."""
    h = np.diff(edges)
    span = np.clip(np.searchsorted(edges, params, side="right") - 1, 0, len(h) - 1)
    emax = np.zeros(len(h))
    np.maximum.at(emax, span, errors)
    with np.errstate(divide="ignore"):
        log_m = np.log(emax) / (degree + 1) - np.log(h)  # e_j ≈ c_j h_j^{p+1}
    finite = np.isfinite(log_m)
    log_m[~finite] = np.min(log_m[finite]) if np.any(finite) else 0.0
    return log_m - np.max(log_m)


def _intrinsic_density(curve: BSplineCurve, edges: FloatArray, fixed: FixedKnots) -> FloatArray:
    """|D^{p+1} C|^{1/(p+1)} per span from jumps of C^{(p)} at the free knots (NaN: no free end).

    The p-th derivative is constant on each span; its jump at knot x_{j+1}
    over the distance between the neighbouring span midpoints estimates
    D^{p+1} C there, and a span averages the estimates at its two ends
    (de Boor 2001, ch. XII, NEWNOT). Jumps at fixed knots are genuine
    (breakpoints) and are skipped.
    """
    p = curve.degree
    mid = 0.5 * (edges[1:] + edges[:-1])
    span = find_span(curve.knots, p, len(curve.control_points), mid)
    dp = derivative_control_points(curve.knots, p, curve.control_points, p)[p][span]  # C^(p) per span
    inner = edges[1:-1]
    is_free = ~np.isin(inner, fixed.position)
    jump = np.hypot(*(dp[1:] - dp[:-1]).T) / np.diff(mid)  # NEWNOT, de Boor 2001, ch. XII
    if fixed.periodic:
        wrap = np.hypot(*(dp[0] - dp[-1])) / (mid[0] + 1.0 - mid[-1])
        jump = np.append(jump, wrap)
        is_free = np.append(is_free, not np.isin(0.0, fixed.position))
        left, left_ok = np.roll(jump, 1), np.roll(is_free, 1)
    else:
        left, left_ok = np.r_[0.0, jump], np.r_[False, is_free]
        jump, is_free = np.r_[jump, 0.0], np.r_[is_free, False]
    total = np.where(left_ok, left, 0.0) + np.where(is_free, jump, 0.0)
    count = left_ok.astype(float) + is_free
    estimate = np.where(count > 0, total / np.maximum(count, 1.0), np.nan)
    return estimate ** (1.0 / (p + 1))


def density_from_fit(
    curve: BSplineCurve,
    knots: FloatArray,
    fixed: FixedKnots,
    params: FloatArray,
    errors: FloatArray,
    *,
    grading: float = GRADING,
    floor: float = 0.05,
) -> Density:
    """Knot density for the next placement from a fitted curve and its errors.

    Parameters
    ----------
    curve
        The fitted curve.
    knots
        Its knot sequence (one period, or interior knots).
    fixed
        Fixed knots of the layout.
    params
        (n,) sample parameters.
    errors
        (n,) distance of each sample to ``curve`` [mm].
    grading
        Largest ratio of the placement density between neighbouring spans.
    floor
        Lower bound of each density as a fraction of its mean, so
        error-free spans keep a finite width.

    Returns
    -------
    Density
        ``values``: graded error density e_j^{1/(p+1)} / h_j (placement);
        ``need``: intrinsic density |D^{p+1} C|^{1/(p+1)} (allocation); on
        spans between two fixed knots, where no jump can be measured, the
        error density scaled by the median ratio of the two densities.
    """
    edges = np.unique(np.concatenate(([0.0], knots, [1.0])))
    h = np.diff(edges)
    log_m = _error_density(edges, params, errors, curve.degree)
    values = np.exp(_graded(log_m, np.log(grading), fixed.periodic))
    need = _intrinsic_density(curve, edges, fixed)
    known = np.isfinite(need) & (need > 0)
    if np.any(known):
        # spans between two fixed knots have no jump to measure: use their
        # error density, scaled like the intrinsic one (both ∝ c_j^{1/(p+1)})
        scale = float(np.median(need[known] / np.exp(log_m[known])))
        need = np.where(np.isfinite(need), need, scale * np.exp(log_m))
    else:
        need = np.exp(log_m)
    values = np.maximum(values, floor * float(np.sum(values * h)))
    need = np.maximum(need, floor * float(np.sum(need * h)))
    readonly(edges, values, need)
    return Density(edges=edges, values=values, need=need)


def estimate_free_knots(n_free: int, n_segments: int, error: float, tolerance: float, degree: int) -> int:
    """Free-knot count that the h^{p+1} law predicts will meet the tolerance.

    With equidistributed knots the max error scales like S^{-(p+1)} in the
    number of spans S = n_free + n_segments, so S_new = S (error /
    tolerance)^{1/(p+1)}.
    """
    spans = n_free + n_segments
    ratio = min(max(error / tolerance, 1e-12), 1e12)
    growth: float = ratio ** (1.0 / (degree + 1))
    return max(math.ceil(spans * growth) - n_segments, 0)
