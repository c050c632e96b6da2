"""One closed contour of the toolpath: fitted, oriented for the milling direction, rounded.

The arc splines of :mod:`camcad.toolpath.arcs` are put in travel order, their
end points rounded to 4 decimals, and each arc's I/J taken from its rounded
start point, so that a controller's radius check (start and end radius within
0.001 mm) passes. The deviation is then measured again on what is written.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray
from camcad.errors import DesignLimitError
from camcad.geometry.cam import Cam
from camcad.toolpath.arcs.biarc import CurveFn, Pieces, cross, measure_deviation, offset_pieces
from camcad.toolpath.arcs.spline import fit_arc_spline
from camcad.toolpath.moves import MoveKind

__all__ = [
    "DECIMALS",
    "LINE_SAGITTA",
    "Contour",
    "OpenPath",
    "Step",
    "fit_contour",
    "fit_open_path",
    "offset_contour",
    "offset_curve",
    "offset_open_path",
    "round_mm",
    "round_point",
    "split_tabs",
]

DECIMALS = 4
LINE_SAGITTA = 0.05  # × tolerance: an arc bulging less is written as G1
_MERGE = 2e-4  # mm: consecutive arcs with centres and radii this close are one circle
_SNAP = 1e-3  # mm: a tab edge this close to a step's end is put there


def offset_curve(cam: Cam, distance: float) -> CurveFn:
    """The exact curve ``cam.offset_curve(phi, distance)`` as point, C′, C″."""

    def evaluate(phi: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        o = cam.offset_curve(phi, distance)
        return o.point, o.d1, o.d2

    return evaluate


def round_mm(v: float) -> float:
    """``v`` rounded to the output's 4 decimals (never −0.0)."""
    return round(float(v), DECIMALS) + 0.0


def round_point(p: Sequence[float]) -> tuple[float, float]:
    """A 2-D point rounded to 4 decimals."""
    return (round_mm(p[0]), round_mm(p[1]))


@dataclass(frozen=True, slots=True, kw_only=True)
class Step:
    """One planar move of a contour: a line, or an arc about ``center`` [mm]."""

    kind: MoveKind
    start: tuple[float, float]
    end: tuple[float, float]
    center: tuple[float, float] | None = None
    tab: bool = False


@dataclass(frozen=True, slots=True, kw_only=True)
class Contour:
    """A closed contour in travel order, rounded, from ``start`` back to it."""

    start: tuple[float, float]
    steps: tuple[Step, ...]
    max_deviation: float  # mm, measured after rounding
    start_tangent: tuple[float, float]  # unit, travel direction
    end_tangent: tuple[float, float]
    normal: tuple[float, float]  # outward at the start
    distance: float  # mm: the offset from the profile this contour follows
    pieces: Pieces  # the fitted pieces before rounding, in φ order
    tab_edges: tuple[tuple[float, float], ...] = ()  # points [mm] on the path where a tab starts or ends

    def tabbed_steps(self) -> list[Step]:
        """The steps split at the tab edges, those over a tab flagged (:func:`split_tabs`)."""
        if not self.tab_edges:
            return list(self.steps)
        return split_tabs(list(self.steps), np.asarray(self.tab_edges))


def _signed_area(pieces: Pieces) -> float:
    pts = pieces.start.reshape(-1, 2)
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _emit(pieces: Pieces, *, reverse: bool, tol: float, closed: bool = True) -> tuple[list[Step], Pieces]:
    """Round the pieces into steps in travel order; also return them as realised, in φ order.

    A closed contour's last step ends on its (rounded) start; an open path's
    on its own rounded end.
    """
    n = len(pieces)
    order = [(i, k) for i in range(n) for k in (0, 1)]
    if reverse:
        order.reverse()
    sweep = pieces.sweep()
    start, end, center = pieces.start.copy(), pieces.end.copy(), pieces.center.copy()
    r0, r1 = np.zeros((n, 2)), np.zeros((n, 2))
    line = np.ones((n, 2), dtype=bool)
    origin = round_point(pieces.end[n - 1, 1] if reverse else pieces.start[0, 0])
    cur = origin
    steps: list[Step] = []
    for idx, (i, k) in enumerate(order):
        far = pieces.start[i, k] if reverse else pieces.end[i, k]
        e = origin if closed and idx == len(order) - 1 else round_point(far)
        sag = 0.0 if pieces.line[i, k] else pieces.r_start[i, k] * (1.0 - math.cos(0.5 * sweep[i, k]))
        ctr = None
        if cur == e:
            pass
        elif pieces.line[i, k] or abs(sag) < LINE_SAGITTA * tol:
            steps.append(Step(kind=MoveKind.LINE, start=cur, end=e))
        else:
            kind = MoveKind.CCW if bool(pieces.ccw[i, k]) != reverse else MoveKind.CW
            ij = round_point(
                (center[i, k, 0] - cur[0], center[i, k, 1] - cur[1])
            )  # I/J from the rounded start
            ctr = (cur[0] + ij[0], cur[1] + ij[1])
            steps.append(Step(kind=kind, start=cur, end=e, center=ctr))
        s_phi, e_phi = (e, cur) if reverse else (cur, e)
        start[i, k], end[i, k] = s_phi, e_phi
        if ctr is not None:
            ra, rb = math.dist(s_phi, ctr), math.dist(e_phi, ctr)
            if abs(ra - rb) > 1e-3:  # pragma: no cover - rounding cannot reach this
                raise DesignLimitError(f"arc radius mismatch {abs(ra - rb):.5f} mm after rounding")
            center[i, k], r0[i, k], r1[i, k], line[i, k] = ctr, ra, rb, False
        cur = e
    real = Pieces(
        lo=pieces.lo, hi=pieces.hi, start=start, end=end, center=center,
        r_start=r0, r_end=r1, ccw=pieces.ccw, line=line,
    )  # fmt: skip
    return steps, real


def _merge(steps: list[Step]) -> list[Step]:
    """Join consecutive arcs of one circle (same turn, centres and radii within 2e-4 mm)."""
    out: list[Step] = []
    for st in steps:
        prev = out[-1] if out else None
        if (
            prev is not None
            and st.center is not None
            and prev.center is not None
            and st.kind is prev.kind
            and math.dist(st.center, prev.center) <= _MERGE
            and abs(math.dist(prev.start, prev.center) - math.dist(st.end, prev.center)) <= _MERGE
            and _turn(prev.kind, prev.start, st.end, prev.center)
            > _turn(prev.kind, prev.start, prev.end, prev.center)
        ):
            out[-1] = Step(kind=prev.kind, start=prev.start, end=st.end, center=prev.center)
        else:
            out.append(st)
    return out


def _turn(kind: MoveKind, a: tuple[float, float], b: tuple[float, float], c: tuple[float, float]) -> float:
    """Angle [rad] swept from a to b about c in the arc's direction, in [0, 2π)."""
    t = math.atan2(b[1] - c[1], b[0] - c[0]) - math.atan2(a[1] - c[1], a[0] - c[0])
    return t % (2.0 * math.pi) if kind is MoveKind.CCW else (-t) % (2.0 * math.pi)


def _project(st: Step, q: FloatArray) -> tuple[float, float, float]:
    """Distance [mm] from q to a step, and the nearest point on it."""
    a, b = np.asarray(st.start), np.asarray(st.end)
    if st.center is None:
        w = b - a
        t = float(np.clip(np.dot(q - a, w) / max(float(np.dot(w, w)), 1e-300), 0.0, 1.0))
        p = a + t * w
        return float(np.linalg.norm(q - p)), float(p[0]), float(p[1])
    c = np.asarray(st.center)
    radius = math.dist(st.start, st.center)
    full = _turn(st.kind, st.start, st.end, st.center)
    at = _turn(st.kind, st.start, (float(q[0]), float(q[1])), st.center)
    if at > full:  # outside the sweep: the nearer end point
        da, db = float(np.linalg.norm(q - a)), float(np.linalg.norm(q - b))
        p = a if da <= db else b
        return min(da, db), float(p[0]), float(p[1])
    u = (q - c) / max(float(np.linalg.norm(q - c)), 1e-300)
    p = c + radius * u
    return float(np.linalg.norm(q - p)), float(p[0]), float(p[1])


def split_tabs(steps: list[Step], edges: FloatArray) -> list[Step]:
    """Split steps at the tab edges (points (m, 2) on the path) and flag the steps over tabs.

    The path starts outside every tab, so the flag flips at each edge met.
    """
    cuts: dict[int, list[tuple[float, tuple[float, float]]]] = {}
    for q in edges:
        dist = [_project(st, q) for st in steps]
        j = int(np.argmin([d[0] for d in dist]))
        point = round_point(dist[j][1:])
        st = steps[j]
        point = next((e for e in (st.start, st.end) if math.dist(e, point) <= _SNAP), point)
        along = (
            math.dist(st.start, point) if st.center is None else _turn(st.kind, st.start, point, st.center)
        )
        cuts.setdefault(j, []).append((along, point))
    out: list[Step] = []
    tab = False
    for j, st in enumerate(steps):
        begin = st.start
        after = False  # an edge at the step's end flips the flag for the next step
        for _, point in sorted(cuts.get(j, [])):
            if point == st.end:
                after = not after
                continue
            if point != begin:
                out.append(Step(kind=st.kind, start=begin, end=point, center=st.center, tab=tab))
                begin = point
            tab = not tab
        out.append(Step(kind=st.kind, start=begin, end=st.end, center=st.center, tab=tab))
        tab = tab != after
    return out


def fit_contour(
    cam: Cam,
    distance: float,
    breaks: FloatArray,
    tol: float,
    fit_tol: float,
    *,
    clockwise: bool,
    windows: Sequence[tuple[float, float]] = (),
    arcs: bool = True,
    fewest_arcs: bool = False,
) -> Contour:
    """Fit, orient, round and measure the closed path ``cam.offset_curve(phi, distance)``.

    Parameters
    ----------
    cam
        The cam.
    distance
        Offset from the profile [mm] (tool radius, plus stock for roughing).
    breaks
        Strictly increasing φ from the start angle to start + 2π [rad].
    tol, fit_tol
        Tolerance to meet after rounding, and the tighter one to fit to [mm].
    clockwise
        Travel clockwise around the part (climb milling outside).
    windows
        φ-windows [rad] over tabs: their edges, on the path abeam the exact
        curve's, are kept for the passes that ride over the tabs
        (:meth:`Contour.tabbed_steps`); the fit ignores them.
    arcs
        False for G1 chords only.
    fewest_arcs
        Refit the closed arc spline with fewer arcs where the tolerance
        allows (``[gcode] fewest_arcs``).

    Returns
    -------
    Contour
        Steps from the start point back to it, with the deviation measured on
        the rounded geometry (before the arc merges and tab splits, which keep
        every step on its circle or line to within 1e-4 mm). With one
        interval (no corner) the arc spline closes on itself, so the start
        lies within the band near ``cam.offset_curve(breaks[0], distance)``, on the
        first arc (:func:`~camcad.toolpath.arcs.spline.fit_arc_spline`).
    """
    curve = offset_curve(cam, distance)
    try:
        pieces, _ = fit_arc_spline(
            curve, breaks, fit_tol, arcs=arcs, closed=breaks.size == 2, fewest_arcs=fewest_arcs
        )
    except ValueError as err:  # pragma: no cover - only for a cusp the gouge check missed
        raise DesignLimitError(f"cannot fit the toolpath: {err}") from err
    return _realise(cam, distance, pieces, breaks, tol, clockwise=clockwise, windows=windows)


def offset_contour(
    cam: Cam,
    base: Contour,
    distance: float,
    breaks: FloatArray,
    tol: float,
    fit_tol: float,
    *,
    clockwise: bool,
    windows: Sequence[tuple[float, float]] = (),
) -> Contour:
    """The closed path ``cam.offset_curve(phi, distance)`` as the offset of another contour's arc spline.

    ``base`` is an arc-spline contour of the same cam fitted with the same
    ``breaks`` and ``windows``; its pieces are offset by
    ``distance − base.distance`` outward (arcs stay arcs: same centres, radii changed
    by the offset) and measured two-way against the exact curve. Where
    every interval is within ``fit_tol`` they are used, so the contour has
    as many pieces as ``base`` and its tolerance certificate is measured
    like a fitted one's; otherwise (an arc that would turn inside out, or a
    piece out of tolerance) the curve is fitted afresh with
    :func:`fit_contour`. Offsetting takes milliseconds where a fit takes a
    search (the roughing contour of :func:`camcad.toolpath.plan_toolpath`).
    """
    curve = offset_curve(cam, distance)
    at = cam.offset_curve(np.array([breaks[0]]), base.distance)
    left = float(np.sign(cross(at.tangent[0], at.normal[0])))  # +1: outward is left of increasing φ
    moved = offset_pieces(base.pieces, left * (distance - base.distance))
    if moved is not None and float(measure_deviation(curve, moved).max()) <= fit_tol:
        return _realise(cam, distance, moved, breaks, tol, clockwise=clockwise, windows=windows)
    return fit_contour(cam, distance, breaks, tol, fit_tol, clockwise=clockwise, windows=windows)


def _realise(
    cam: Cam,
    distance: float,
    pieces: Pieces,
    breaks: FloatArray,
    tol: float,
    *,
    clockwise: bool,
    windows: Sequence[tuple[float, float]],
) -> Contour:
    """Orient, round, measure and merge the pieces of ``cam.offset_curve(phi, distance)`` into a contour."""
    curve = offset_curve(cam, distance)
    reverse = (_signed_area(pieces) > 0.0) == clockwise
    steps, real = _emit(pieces, reverse=reverse, tol=tol)
    dev = float(measure_deviation(curve, real, samples=48).max())
    if dev > tol:  # pragma: no cover - the fit keeps a margin for rounding
        raise DesignLimitError(f"toolpath deviation {dev:.5f} mm exceeds the tolerance {tol:g} mm")
    steps = _merge(steps)
    edges: tuple[tuple[float, float], ...] = ()
    if windows:
        at = np.asarray(curve(np.asarray([a for w in windows for a in w]))[0])
        edges = tuple((float(x), float(y)) for x, y in at)
    t_lo, t_hi = _end_tangents(pieces)
    t_start, t_end = (-t_hi, -t_lo) if reverse else (t_lo, t_hi)
    # outward: the side of the exact curve's normal where the path starts
    outward = cam.offset_curve(np.array([pieces.lo[0]]), distance).normal[0]
    normal = np.array([-t_start[1], t_start[0]])
    normal = normal if float(normal @ outward) > 0.0 else -normal
    return Contour(
        start=steps[0].start,
        steps=tuple(steps),
        max_deviation=dev,
        start_tangent=(float(t_start[0]), float(t_start[1])),
        end_tangent=(float(t_end[0]), float(t_end[1])),
        normal=(float(normal[0]), float(normal[1])),
        distance=distance,
        pieces=pieces,
        tab_edges=edges,
    )


def _end_tangents(pieces: Pieces) -> tuple[FloatArray, FloatArray]:
    """Unit tangents (in the direction of increasing φ) where the pieces start and where they end."""
    starts, ends = pieces.tangents()
    last = len(pieces) - 1
    null = bool(pieces.line[last, 1] and np.all(pieces.start[last, 1] == pieces.end[last, 1]))
    return starts[0, 0], ends[last, 0 if null else 1]


@dataclass(frozen=True, slots=True, kw_only=True)
class OpenPath:
    """An open path in travel order, rounded: from ``steps[0].start`` to ``steps[-1].end``.

    The open counterpart of :class:`Contour` (a linear cam's edge,
    :func:`camcad.toolpath.bar.plan_bar`): its ends lie on the exact curve's
    ends (rounded); its end tangents are the arc spline's own there.
    """

    steps: tuple[Step, ...]
    max_deviation: float  # mm, measured after rounding
    start_tangent: tuple[float, float]  # unit, travel direction
    end_tangent: tuple[float, float]
    distance: float  # mm: the offset from the profile this path follows
    pieces: Pieces  # the fitted pieces before rounding, in φ order
    reverse: bool  # travels against increasing φ

    @property
    def start(self) -> tuple[float, float]:
        """Where the path starts [mm] (rounded)."""
        return self.steps[0].start

    @property
    def end(self) -> tuple[float, float]:
        """Where the path ends [mm] (rounded)."""
        return self.steps[-1].end


def fit_open_path(
    cam: Cam,
    distance: float,
    breaks: FloatArray,
    tol: float,
    fit_tol: float,
    *,
    reverse: bool,
    arcs: bool = True,
    straight: Sequence[bool] = (),
) -> OpenPath:
    """Fit, orient, round and measure the open path ``cam.offset_curve(phi, distance)`` over ``breaks``.

    The arc spline (:func:`~camcad.toolpath.arcs.spline.fit_arc_spline`, not
    closed) starts on the exact curve at ``breaks[0]`` with its tangent and
    ends on it at ``breaks[-1]`` (by a biarc on its tangent, or an arc that
    lands there, its tangent within the band's); every break in between is
    a node on the curve. The path's end tangents are its own. ``reverse``
    travels from the last break to the first. ``tol`` and ``fit_tol`` [mm]
    as for :func:`fit_contour`: the deviation is measured after rounding,
    two-way, and must be within ``tol``. ``arcs`` False writes G1 chords
    only (for comparison). ``straight`` flags the break intervals over which
    the curve is a straight line (a linear cam's dwells): each is written as
    one line on the exact curve's ends (with arcs; chords are lines anyway).
    """
    curve = offset_curve(cam, distance)
    try:
        pieces, _ = fit_arc_spline(
            curve, breaks, fit_tol, arcs=arcs, closed=False, straight=straight if arcs else ()
        )
    except ValueError as err:  # pragma: no cover - only for a cusp the gouge check missed
        raise DesignLimitError(f"cannot fit the toolpath: {err}") from err
    return _realise_open(curve, distance, pieces, tol, reverse=reverse)


def offset_open_path(
    cam: Cam,
    base: OpenPath,
    distance: float,
    breaks: FloatArray,
    tol: float,
    fit_tol: float,
    *,
    straight: Sequence[bool] = (),
) -> OpenPath:
    """The open path ``cam.offset_curve(phi, distance)`` as the offset of another path's arc spline.

    As :func:`offset_contour` for a closed contour: ``base``'s pieces offset
    by ``distance − base.distance`` (arcs stay arcs), measured two-way
    against the exact curve and used where within ``fit_tol``; otherwise
    the curve is fitted afresh (:func:`fit_open_path`, with ``straight``). The
    travel direction is ``base``'s; a line of ``base`` stays a line.
    """
    curve = offset_curve(cam, distance)
    at = cam.offset_curve(np.array([breaks[0]]), base.distance)
    left = float(np.sign(cross(at.tangent[0], at.normal[0])))  # +1: outward is left of increasing φ
    moved = offset_pieces(base.pieces, left * (distance - base.distance))
    if moved is not None and float(measure_deviation(curve, moved).max()) <= fit_tol:
        return _realise_open(curve, distance, moved, tol, reverse=base.reverse)
    return fit_open_path(cam, distance, breaks, tol, fit_tol, reverse=base.reverse, straight=straight)


def _realise_open(curve: CurveFn, distance: float, pieces: Pieces, tol: float, *, reverse: bool) -> OpenPath:
    """Round, measure and merge the pieces of an open path into steps in travel order."""
    steps, real = _emit(pieces, reverse=reverse, tol=tol, closed=False)
    dev = float(measure_deviation(curve, real, samples=48).max())
    if dev > tol:  # pragma: no cover - the fit keeps a margin for rounding
        raise DesignLimitError(f"toolpath deviation {dev:.5f} mm exceeds the tolerance {tol:g} mm")
    starts, ends = pieces.tangents()
    live = np.flatnonzero(pieces.length().reshape(-1) > 0.0)  # a null piece has no tangent
    t_lo, t_hi = starts.reshape(-1, 2)[live[0]], ends.reshape(-1, 2)[live[-1]]
    t_start, t_end = (-t_hi, -t_lo) if reverse else (t_lo, t_hi)
    return OpenPath(
        steps=tuple(_merge(steps)),
        max_deviation=dev,
        start_tangent=(float(t_start[0]), float(t_start[1])),
        end_tangent=(float(t_end[0]), float(t_end[1])),
        distance=distance,
        pieces=pieces,
        reverse=reverse,
    )
