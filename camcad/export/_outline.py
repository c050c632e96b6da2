"""Plane outlines for the exporters: bore outline, curve flattening, areas.

Conventions: points are (n, 2) arrays in the cam frame [mm]; a closed polygon
does not repeat its first point; positive signed area means counter-clockwise.
The keyway sits on the +y side of the bore, where the follower stands at cam
angle φ = 0, so the drawing, the solid and the G-code share one angular
reference.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from typing import Protocol

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import DesignError
from camcad.fit.curve import BSplineCurve, curve_derivatives
from camcad.toolpath.arcs.biarc import (
    CurveFn,
    Pieces,
    biarc_pieces,
    chord_pieces,
    concat_pieces,
    measure_deviation,
    take_pieces,
)

__all__ = [
    "analytic_area",
    "arc_outline",
    "bspline_area",
    "bspline_length",
    "chord_budget",
    "flatten_bspline",
    "flatten_curve",
    "knot_spans",
    "oriented",
    "polygon_area",
    "polygon_perimeter",
]


MIN_CHORD_BUDGET = 1e-4
"""Smallest chord error [mm] left for a polyline after the fit's (the schema's finest chord_tolerance)."""


def chord_budget(chord_tolerance: float, fit_error: float, *, field: str) -> float:
    """Chord error [mm] left for a fitted curve's polyline within ``chord_tolerance`` of the truth.

    The polyline is flattened from the fitted spline, which lies within its
    certified ``fit_error`` [mm] of the exact curve, so by the triangle
    inequality a chord error of ``chord_tolerance − fit_error`` keeps every
    vertex and chord within ``chord_tolerance`` of the exact curve.

    Raises
    ------
    DesignError
        ``field`` (``dxf.chord_tolerance`` or ``mesh.chord_tolerance``) when
        less than :data:`MIN_CHORD_BUDGET` is left: the fit alone uses the
        budget; the message names the fit's error and what is allowed.
    """
    budget = chord_tolerance - fit_error
    if budget < MIN_CHORD_BUDGET:
        raise DesignError(
            field,
            f"{chord_tolerance:g} mm leaves no chord error for the polyline: the fitted spline is already "
            f"up to {fit_error:.6f} mm from the exact profile; allowed: a chord_tolerance of at least "
            f"{fit_error + MIN_CHORD_BUDGET:.6f} mm, or a finer fit tolerance",
        )
    return budget


def polygon_area(points: FloatArray) -> float:
    """Signed area of a closed polygon [mm²]; positive when counter-clockwise.

    Parameters
    ----------
    points
        (n, 2) vertices [mm], the first not repeated at the end.

    Examples
    --------
    >>> polygon_area(np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]]))
    2.0
    """
    x, y = points[:, 0], points[:, 1]
    # Shoelace formula, centred to keep round-off at the scale of the polygon.
    x = x - x.mean()
    y = y - y.mean()
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def polygon_perimeter(points: FloatArray) -> float:
    """Length of a closed polygon [mm]; (n, 2) vertices, first not repeated."""
    return float(np.sum(np.linalg.norm(np.roll(points, -1, axis=0) - points, axis=1)))


def oriented(points: FloatArray, *, ccw: bool) -> FloatArray:
    """Return the polygon, its vertex order reversed if needed to run ccw (or cw)."""
    if (polygon_area(points) > 0.0) != ccw:
        points = points[::-1].copy()
    return points


def knot_spans(curve: BSplineCurve) -> tuple[FloatArray, FloatArray]:
    """Start and end parameter of every non-empty knot span inside the domain."""
    a, b = curve.domain
    breaks = np.unique(curve.knots[(curve.knots >= a) & (curve.knots <= b)])
    return breaks[:-1], breaks[1:]


def flatten_bspline(curve: BSplineCurve, chord_tolerance: float) -> FloatArray:
    """Polyline through a non-periodic B-spline within ``chord_tolerance`` [mm].

    Parameters
    ----------
    curve
        Clamped B-spline of degree ≤ 3 (``periodic=False``).
    chord_tolerance
        Largest distance between the curve and its polyline [mm].

    Returns
    -------
    FloatArray
        (n, 2) vertices [mm], read-only. For a closed curve (last control point
        equal to the first) the end point is not repeated.

    Notes
    -----
    On a knot span of a curve of degree ≤ 3, C'' is linear (or constant), so
    ‖C''‖ is largest at a span end. A chord over a parameter step h deviates
    from the curve by at most h²/8 · max‖C''‖ (error of linear
    interpolation, de Boor 2001, ch. II, eq. 2.2), so choosing
    h ≤ √(8 tol / max‖C''‖) per span is a bound, not an estimate.

    References
    ----------
    .. [1] de Boor (2001), A Practical Guide to Splines, revised ed.,
       Springer. doi:10.1007/978-1-4612-6333-3
    """
    if curve.periodic:
        raise ValueError("flatten_bspline needs the clamped form of the curve")
    if curve.degree > 3:
        raise ValueError(f"flatten_bspline supports degree ≤ 3, got {curve.degree}")
    if chord_tolerance <= 0.0:
        raise ValueError(f"chord_tolerance must be > 0, got {chord_tolerance!r}")
    start, end = knot_spans(curve)
    h = end - start
    if curve.degree < 2:
        counts = np.ones(start.size, dtype=int)
    else:
        # C'' is linear on the span: extrapolate its end values from two interior points.
        q1, q3 = np.split(curve.evaluate(np.concatenate((start + 0.25 * h, start + 0.75 * h)), 2), 2)
        at_start = 1.5 * q1 - 0.5 * q3
        at_end = 1.5 * q3 - 0.5 * q1
        bound = np.maximum(np.linalg.norm(at_start, axis=1), np.linalg.norm(at_end, axis=1))
        counts = np.maximum(1, np.ceil(h * np.sqrt(bound / (8.0 * chord_tolerance)))).astype(int)
    params = np.concatenate(
        [s + (e - s) * np.arange(k) / k for s, e, k in zip(start, end, counts, strict=True)]
    )
    closed = np.array_equal(curve.control_points[0], curve.control_points[-1])
    if not closed:
        params = np.append(params, end[-1])
        points = curve.evaluate(params[:-1])
        points = np.vstack((points, curve.control_points[-1]))
    else:
        points = curve.evaluate(params)
    points = np.ascontiguousarray(points, dtype=float)
    readonly(points)
    return points


def _gauss_legendre(start: FloatArray, end: FloatArray, nodes: int) -> tuple[FloatArray, FloatArray]:
    """Gauss-Legendre nodes and weights on each interval [start_i, end_i], flattened."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    half = 0.5 * (end - start)
    mid = 0.5 * (end + start)
    u = (mid[:, None] + half[:, None] * x[None, :]).ravel()
    weight = (half[:, None] * w[None, :]).ravel()
    return u, weight


def bspline_area(curve: BSplineCurve) -> float:
    """Signed area enclosed by a closed B-spline [mm²]; positive when counter-clockwise.

    Notes
    -----
    A = ½∮(x dy − y dx) (Green's theorem). On each knot span of a degree-p
    curve the integrand x y' − y x' is a polynomial of degree 2p − 1, which
    p-point Gauss-Legendre integrates exactly, so the result is exact up to
    round-off.
    """
    start, end = knot_spans(curve)
    u, weight = _gauss_legendre(start, end, max(curve.degree, 1) + 1)
    p, d = curve_derivatives(curve, u, 1)
    return 0.5 * float(np.sum(weight * (p[:, 0] * d[:, 1] - p[:, 1] * d[:, 0])))


def bspline_length(curve: BSplineCurve, *, nodes: int = 12) -> float:
    """Arc length of a B-spline [mm], by ``nodes``-point Gauss-Legendre on each knot span."""
    start, end = knot_spans(curve)
    u, weight = _gauss_legendre(start, end, nodes)
    d = curve.evaluate(u, 1)
    return float(np.sum(weight * np.linalg.norm(d, axis=1)))


class _Sample(Protocol):
    """What :func:`analytic_area` and :func:`flatten_curve` need of a CurveSample."""

    point: FloatArray
    d1: FloatArray
    d2: FloatArray


def analytic_area(
    sample: Callable[[FloatArray], _Sample],
    breakpoints: Sequence[float] = (),
    *,
    nodes: int = 24,
    pieces: int = 8,
) -> tuple[float, float]:
    """Signed area and length of a closed analytic curve P(φ), φ ∈ [0, 2π).

    Parameters
    ----------
    sample
        Maps (n,) angles [rad] to an object with ``point`` and ``d1 = dP/dφ``
        (n, 2) [mm, mm/rad], e.g. ``cam.profile``.
    breakpoints
        Angles [rad] where derivatives of P may jump (motion segment joins).
        The integral is split there, since Gauss-Legendre converges
        exponentially only on pieces where the integrand is smooth.
    nodes, pieces
        Gauss-Legendre nodes per piece and pieces per interval between
        breakpoints.

    Returns
    -------
    tuple[float, float]
        Signed area [mm²] (positive counter-clockwise) and arc length [mm].

    Notes
    -----
    A = ½∫₀^{2π} (x y' − y x') dφ (Green's theorem), L = ∫ ‖P'‖ dφ.
    """
    two_pi = 2.0 * math.pi
    cuts = np.unique(np.mod(np.asarray(breakpoints, dtype=float), two_pi))
    cuts = np.unique(np.concatenate(([0.0], cuts, [two_pi])))
    cuts = cuts[np.concatenate(([True], np.diff(cuts) > 1e-12))]
    edges = np.concatenate(
        [np.linspace(a, b, pieces + 1)[:-1] for a, b in itertools.pairwise(cuts)] + [[two_pi]]
    )
    phi, weight = _gauss_legendre(edges[:-1], edges[1:], nodes)
    s = sample(phi)
    p, d = s.point, s.d1
    area = 0.5 * float(np.sum(weight * (p[:, 0] * d[:, 1] - p[:, 1] * d[:, 0])))
    length = float(np.sum(weight * np.linalg.norm(d, axis=1)))
    return area, length


def flatten_curve(
    sample: Callable[[FloatArray], _Sample],
    chord_tolerance: float,
    *,
    breakpoints: Sequence[float] = (),
    probe_step: float = math.radians(0.1),
) -> FloatArray:
    """Polyline through a closed analytic curve P(φ), φ ∈ [0, 2π), to a chord tolerance.

    Parameters
    ----------
    sample
        Maps (n,) angles [rad] to an object with ``point`` and ``d2 = d²P/dφ²``.
    chord_tolerance
        Target largest chord deviation [mm].
    breakpoints
        Angles [rad] always included as vertices.
    probe_step
        Grid [rad] on which the largest ‖P''‖ is looked for.

    Returns
    -------
    FloatArray
        (n, 2) vertices [mm], the first not repeated; read-only.

    Notes
    -----
    A uniform step Δφ = √(8 tol / (1.25 max‖P''‖)) keeps the chord error
    h²/8 · ‖P''‖ within the tolerance where the probe found the maximum; the
    factor 1.25 covers peaks between probe points. Used for reference curves
    (the pitch curve); the cam profile itself is flattened from the fitted
    spline by the rigorous :func:`flatten_bspline`.
    """
    probe = np.arange(0.0, 2.0 * math.pi, probe_step)
    peak = float(np.max(np.linalg.norm(sample(probe).d2, axis=1)))
    step = math.sqrt(8.0 * chord_tolerance / max(1.25 * peak, 1e-300))
    count = max(8, math.ceil(2.0 * math.pi / step))
    phi = np.linspace(0.0, 2.0 * math.pi, count, endpoint=False)
    extra = np.mod(np.asarray(breakpoints, dtype=float), 2.0 * math.pi)
    phi = np.unique(np.concatenate((phi, extra)))
    points = np.ascontiguousarray(sample(phi).point, dtype=float)
    readonly(points)
    return points


ARC_MARGIN = 0.8  # biarcs are fitted to this fraction of the tolerance: the measured deviation is sampled
ARC_START_PIECES = 4  # first split of every interval between breakpoints
ARC_SPLIT_SAFETY = 1.15  # a few more parts than the h³ law asks for, so one split mostly suffices
ARC_MAX_ROUNDS = 40  # halvings of an interval: 2π/2^40 rad is far below any real tolerance


def arc_outline(
    curve: CurveFn,
    breakpoints: Sequence[float],
    tolerance: float,
    *,
    straight: Sequence[tuple[float, float]] = (),
) -> tuple[Pieces, FloatArray]:
    """Tangent-continuous arcs through a curve C(φ), φ ∈ [0, 2π], within ``tolerance`` [mm].

    A closed curve (a plate's profile) closes where C(2π) = C(0); an open one
    (a linear cam's edge) runs from its exact start C(0) to its exact end C(2π).

    Parameters
    ----------
    curve
        The exact curve with two φ-derivatives (e.g. ``cam.offset_curve(φ, 0)``, the
        profile); its tangent must be continuous (a cam without velocity jumps).
    breakpoints
        Angles [rad] every fit passes through with the curve's tangent
        (motion segment joins: the curvature may jump there).
    tolerance
        Largest two-way deviation [mm].
    straight
        φ-spans [rad] over which C is exactly a straight line (a linear
        cam's dwells, :attr:`camcad.geometry.cam.Cam.straight_spans`): each
        interval between breakpoints inside one is a single line from its
        exact start to its exact end (measured like the biarcs), not split.

    Returns
    -------
    (Pieces, FloatArray)
        Biarcs (two arcs, or lines where straight, per φ-interval) in φ order
        from φ = 0, and each interval's measured deviation [mm].

    Notes
    -----
    Adaptive biarc interpolation: each φ-interval gets the equal-chord biarc
    between the curve's points and unit tangents at its ends (Bolton 1975;
    :func:`~camcad.toolpath.arcs.biarc.biarc_pieces`), so consecutive arcs
    share end points and tangents (G1). Intervals whose two-way deviation
    (:func:`~camcad.toolpath.arcs.biarc.measure_deviation`, sampled) exceeds
    ``ARC_MARGIN`` × tolerance are split, all at once, into as many equal
    parts as the biarc's h³ error law asks for, until none exceeds it;
    this is vectorised and takes milliseconds, where the fewest-arcs search of
    :func:`~camcad.toolpath.arcs.spline.fit_arc_spline` takes about a second
    for about half as many arcs.
    """
    if tolerance <= 0.0:
        raise ValueError(f"tolerance must be > 0, got {tolerance!r}")
    two_pi = 2.0 * math.pi
    cuts = np.unique(np.concatenate(([0.0, two_pi], np.mod(np.asarray(breakpoints, dtype=float), two_pi))))
    cuts = cuts[np.concatenate(([True], np.diff(cuts) > 1e-9))]
    done: list[Pieces] = []
    devs: list[FloatArray] = []
    spans = [(a, b) for a, b in itertools.pairwise(cuts) if not _straight(a, b, straight)]
    lines = [(a, b) for a, b in itertools.pairwise(cuts) if _straight(a, b, straight)]
    if lines:  # one line per straight interval, on the curve's exact ends
        ends = np.array(lines)
        pt, d1, _d2 = curve(ends.ravel())
        tangent = d1 / np.linalg.norm(d1, axis=1)[:, None]
        chords = chord_pieces(ends[:, 0], ends[:, 1], pt[0::2], tangent[0::2], pt[1::2], tangent[1::2])
        dev = measure_deviation(curve, chords)
        if not np.all(dev <= tolerance):
            raise ValueError(f"a straight span is {float(dev.max()):.3g} mm off its line")
        done.append(chords)
        devs.append(dev)
    lo = np.concatenate([np.linspace(a, b, ARC_START_PIECES + 1)[:-1] for a, b in spans] or [np.zeros(0)])
    hi = np.concatenate(
        [np.append(np.linspace(a, b, ARC_START_PIECES + 1)[1:-1], b) for a, b in spans] or [lo]
    )
    for _ in range(ARC_MAX_ROUNDS):
        if lo.size == 0:  # every interval is straight
            break
        pt, d1, _d2 = curve(np.concatenate((lo, hi)))
        tangent = d1 / np.linalg.norm(d1, axis=1)[:, None]
        n = lo.size
        pieces = biarc_pieces(lo, hi, pt[:n], tangent[:n], pt[n:], tangent[n:])
        dev = measure_deviation(curve, pieces)
        good = dev <= ARC_MARGIN * tolerance
        if np.any(good):
            done.append(take_pieces(pieces, good))
            devs.append(dev[good])
        if np.all(good):
            break
        # a biarc's deviation grows as h³: split each bad interval into the parts that should fit
        parts = np.ceil((dev[~good] / (ARC_MARGIN * tolerance)) ** (1.0 / 3.0) * ARC_SPLIT_SAFETY)
        parts = np.clip(parts, 2, 64).astype(int)
        lo, hi = _split(lo[~good], hi[~good], parts)
    else:
        raise ValueError(f"no arcs within {tolerance} mm: the curve has a corner near φ = {lo[0]:.6f} rad")
    out = concat_pieces(done)
    order = np.argsort(np.concatenate([p.lo for p in done]), kind="stable")
    dev_all = np.concatenate(devs)[order]
    readonly(dev_all)
    return out, dev_all


def _straight(a: float, b: float, spans: Sequence[tuple[float, float]]) -> bool:
    """Whether [a, b] lies inside one of the straight φ-spans (1e-9 rad slack at the ends)."""
    return any(lo - 1e-9 <= a and b <= hi + 1e-9 for lo, hi in spans)


def _split(lo: FloatArray, hi: FloatArray, parts: np.ndarray) -> tuple[FloatArray, FloatArray]:
    """Split each [lo_i, hi_i] into parts_i equal intervals; their starts and ends."""
    index = np.repeat(np.arange(lo.size), parts)
    k = np.arange(index.size) - np.repeat(np.cumsum(parts) - parts, parts)
    width = (hi - lo)[index] / parts[index]
    start = lo[index] + k * width
    end = np.where(k == parts[index] - 1, hi[index], start + width)
    return start, end
