"""The boundary representation of a prism with pockets, as STEP (ISO 10303-42) entity instances.

A :class:`Body` is a prism (a plane region between
closed outlines, extruded along +z) minus pockets opened from its top face.
Its boundary is exact and small, so it is written here entity by entity:

- **Walls.** Every outline segment swept between its two heights (a prism
  outline from the prism's z0 to its top, a pocket outline from the pocket's
  floor to the top): a B-spline becomes a ``SURFACE_OF_LINEAR_EXTRUSION`` of
  the curve itself, a circle or arc a ``CYLINDRICAL_SURFACE``, a keyway line
  a ``PLANE``. A closed curve has one vertex per height and a vertical seam
  edge that its wall's loop runs up and down; a keyed bore has a vertex at
  each of its five corners per height and a vertical edge at each, shared
  by the two walls that meet there.
- **Plane faces.** The bottom (normal −z) bounded by the prism's outlines,
  one floor per pocket (normal +z) bounded by the pocket's outlines, and the
  top (normal +z) bounded by all outlines: loops nest, a loop at even depth
  is the outer bound of a face and its children (odd depth) are its holes.
- **Orientation** (ISO 10303-42 §5.4.28, §5.4.31): a face's bounds run
  counter-clockwise seen from its outward side; ``same_sense`` says whether
  the surface's own normal points out of the material. The material lies
  inside a prism's outer outline and a pocket's islands, outside a prism's
  holes and a pocket's outer outline; a wall's outward normal is therefore
  on the right of its outline's direction T (T × ẑ, the normal of the
  extrusion surface) exactly when the outline runs counter-clockwise around
  material. Every edge is then used by two faces in opposite directions.

The nesting is decided on polygons sampled from the outlines (even–odd
point-in-polygon tests of every sample): outlines must nest without
crossing, and a pocket must lie in the material, open at the top and end
above the bottom; otherwise :class:`~camcad.errors.ExportError` names the
outlines. Nothing here imports OpenCASCADE (see :mod:`camcad.export.step`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray
from camcad.errors import ExportError
from camcad.export._outline import knot_spans, polygon_area
from camcad.fit.curve import BSplineCurve
from camcad.geometry.plate import BoreOutline

__all__ = ["Body", "Entities", "Outline", "Prism", "real", "shell"]

SAMPLES_PER_SPAN = 8  # polygon points per knot span of a B-spline outline, for the nesting tests only
CIRCLE_CHORD = 1e-3  # chord tolerance of a sampled circle, relative to its radius
CLOSE_REL = 1e-12  # a written B-spline closes within this fraction of its size
HEIGHT_REL = 1e-9  # a pocket's top meets the prism's top within this fraction of the height [mm/mm]
UP = (0.0, 0.0, 1.0)
DOWN = (0.0, 0.0, -1.0)
X_AXIS = (1.0, 0.0, 0.0)
Y_AXIS = (0.0, 1.0, 0.0)


Outline = BSplineCurve | BoreOutline
"""A closed plane curve in the cam frame [mm]: a periodic B-spline, or a bore with its keyway."""


@dataclass(frozen=True, slots=True, kw_only=True)
class Prism:
    """A plane region inside ``outer`` and outside every hole, from z = ``z0`` to ``z0 + height`` [mm].

    Outlines may run either way round; the writer orients them. Holes lie
    inside ``outer`` and apart from each other.
    """

    outer: Outline
    holes: tuple[Outline, ...] = ()
    height: float
    z0: float = 0.0


@dataclass(frozen=True, slots=True, kw_only=True)
class Body:
    """One solid of the file: ``prism`` minus every prism in ``cuts``; ``name`` becomes its product name.

    A cut is a pocket: it opens at the prism's top face (``z0 + height`` at
    or above the top), ends above its bottom, lies in the material (inside
    the outer outline; a prism hole or another pocket inside it lies in one
    of its own holes, its islands) and crosses no other outline.
    """

    name: str
    prism: Prism
    cuts: tuple[Prism, ...] = ()


def real(value: float) -> str:
    """A REAL of ISO 10303-21 (§6.3.3): shortest round-trip digits, a decimal point, an upper-case E.

    Examples
    --------
    >>> [real(v) for v in (0.0, -0.0, 12.0, 1e-07, -2.5e+20, 0.1)]
    ['0.', '0.', '12.', '1.E-07', '-2.5E+20', '0.1']
    """
    x = float(value) + 0.0  # no negative zero: the same point, the same bytes
    if not math.isfinite(x):
        raise ExportError(f"a STEP number must be finite, got {x!r}")
    mantissa, _, exponent = repr(x).partition("e")
    if mantissa.endswith(".0"):
        mantissa = mantissa[:-1]
    elif "." not in mantissa:
        mantissa += "."
    return mantissa + ("E" + exponent if exponent else "")


def reals(values: Iterable[float]) -> str:
    """A parenthesised list of :func:`real` s."""
    return "(" + ",".join(real(v) for v in values) + ")"


class Entities:
    """The DATA section: entity instances numbered #1, #2, … in the order they are added."""

    def __init__(self) -> None:
        self.records: list[str] = []
        self._directions: dict[tuple[float, ...], str] = {}

    def add(self, record: str) -> str:
        """Append one instance (without its number and ';'); its reference ``#n``."""
        self.records.append(record)
        return f"#{len(self.records)}"

    def point(self, xyz: Sequence[float]) -> str:
        return self.add(f"CARTESIAN_POINT('',{reals(xyz)})")

    def direction(self, xyz: Sequence[float]) -> str:
        """One DIRECTION per distinct vector (shared)."""
        key = tuple(float(v) + 0.0 for v in xyz)
        if key not in self._directions:
            self._directions[key] = self.add(f"DIRECTION('',{reals(key)})")
        return self._directions[key]

    def placement(self, origin: Sequence[float], axis: Sequence[float], ref: Sequence[float]) -> str:
        return self.add(
            f"AXIS2_PLACEMENT_3D('',{self.point(origin)},{self.direction(axis)},{self.direction(ref)})"
        )

    def vector(self, xyz: Sequence[float], magnitude: float) -> str:
        return self.add(f"VECTOR('',{self.direction(xyz)},{real(magnitude)})")


# --- outlines as segments ---------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Segment:
    """One edge of an outline in the plane, in the outline's own direction T.

    ``kind`` is ``"bspline"`` (the whole closed curve), ``"circle"`` (a whole
    circle, or the bore arc counter-clockwise about the origin) or ``"line"``.
    """

    kind: str
    start: tuple[float, float]
    end: tuple[float, float]


def _segments(outline: Outline) -> list[_Segment]:
    """The outline's segments head to tail, the first starting at its seam vertex."""
    if isinstance(outline, BSplineCurve):
        lo, _ = outline.domain
        x, y = (float(v) for v in outline.evaluate(np.array([lo]))[0])
        return [_Segment("bspline", (x, y), (x, y))]
    if not outline.has_keyway:
        return [_Segment("circle", (outline.radius, 0.0), (outline.radius, 0.0))]
    corners = [(x, y) for x, y, _ in outline.bulge_vertices()]
    lines = [_Segment("line", a, b) for a, b in itertools.pairwise(corners)]
    return [*lines, _Segment("circle", corners[-1], corners[0])]  # the arc runs ccw round the bottom


def _circle_ref(outline: BoreOutline) -> tuple[float, float, float]:
    """Where a circle's parameter 0 lies: +x for a plain bore (its vertex), +y in a keyway (off the arc)."""
    return Y_AXIS if outline.has_keyway else X_AXIS


def _polygon(outline: Outline) -> FloatArray:
    """(n, 2) points of the outline in its own direction [mm], for the nesting tests."""
    if isinstance(outline, BoreOutline):
        return outline.polygon(CIRCLE_CHORD * outline.radius)
    start, end = knot_spans(outline)
    fraction = np.arange(SAMPLES_PER_SPAN) / SAMPLES_PER_SPAN
    u = (start[:, None] + (end - start)[:, None] * fraction).ravel()
    return np.asarray(outline.evaluate(u), dtype=float)


def _inside(polygon: FloatArray, points: FloatArray) -> np.ndarray:
    """Whether each point lies inside the closed polygon (even–odd ray casting along +x)."""
    ax, ay = polygon[:, 0], polygon[:, 1]
    bx, by = np.roll(ax, -1), np.roll(ay, -1)
    px, py = points[:, :1], points[:, 1:2]
    straddles = (ay > py) != (by > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        cross_x = ax + (py - ay) * (bx - ax) / (by - ay)
    return np.count_nonzero(straddles & (px < cross_x), axis=1) % 2 == 1


# --- loops and their nesting ------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Loop:
    """One outline of a body with the heights its wall spans [mm] and the side the material is on."""

    label: str
    outline: Outline
    z_low: float
    z_top: float
    material_inside: bool
    polygon: FloatArray
    ccw: bool
    cut: int  # 0 for the prism's outlines, k for the k-th pocket's


def _loop(
    name: str, label: str, outline: Outline, z_low: float, z_top: float, inside: bool, cut: int
) -> _Loop:
    polygon = _polygon(outline)
    area = polygon_area(polygon)
    if not area != 0.0:
        raise ExportError(f"{name}: {label} encloses no area")
    return _Loop(label, outline, z_low, z_top, inside, polygon, area > 0.0, cut)


def _loops(body: Body) -> list[_Loop]:
    """The body's outlines with their heights; the heights checked."""
    prism = body.prism
    if not prism.height > 0.0:
        raise ExportError(f"{body.name}: a STEP prism needs a height > 0 mm, got {prism.height!r}")
    z0, top = prism.z0, prism.z0 + prism.height
    loops = [_loop(body.name, "the outer outline", prism.outer, z0, top, True, 0)]
    loops += [_loop(body.name, f"hole {i}", h, z0, top, False, 0) for i, h in enumerate(prism.holes, 1)]
    for k, cut in enumerate(body.cuts, 1):
        name = f"pocket {k}"
        if not cut.height > 0.0:
            raise ExportError(f"{body.name}: {name} needs a height > 0 mm, got {cut.height!r}")
        if not cut.z0 > z0:
            raise ExportError(
                f"{body.name}: {name} reaches z = {cut.z0!r} mm, not above the bottom at z = {z0!r} mm"
                " (a pocket ends above the bottom; a through hole is one of the prism's holes)"
            )
        if cut.z0 + cut.height < top - HEIGHT_REL * prism.height:
            raise ExportError(
                f"{body.name}: {name} ends at z = {cut.z0 + cut.height!r} mm, below the top at"
                f" z = {top!r} mm (a pocket opens at the top face)"
            )
        loops.append(_loop(body.name, f"{name}'s outer outline", cut.outer, cut.z0, top, False, k))
        loops += [
            _loop(body.name, f"{name}'s hole {i}", h, cut.z0, top, True, k)
            for i, h in enumerate(cut.holes, 1)
        ]
    return loops


def _containment(name: str, loops: Sequence[_Loop]) -> np.ndarray:
    """``within[i, j]``: loop j lies inside loop i; an outline crossing another is refused."""
    n = len(loops)
    within = np.zeros((n, n), dtype=bool)
    for i, outer in enumerate(loops):
        for j, inner in enumerate(loops):
            if i == j:
                continue
            hits = _inside(outer.polygon, inner.polygon)
            if hits.all() != hits.any():
                raise ExportError(f"{name}: {inner.label} crosses or touches {outer.label}")
            within[i, j] = bool(hits[0])
    both = within & within.T
    if both.any():
        i, j = np.argwhere(both)[0]
        raise ExportError(f"{name}: {loops[i].label} and {loops[j].label} coincide")
    return within


def _check_nesting(name: str, loops: Sequence[_Loop], within: np.ndarray) -> None:
    """Holes inside their outer outline and apart; every pocket inside the material, apart from the others.

    Then the top face's even–odd nesting of all outlines is the material's.
    """

    def fail(what: str) -> ExportError:
        return ExportError(f"{name}: {what}")

    groups: dict[int, list[int]] = {}
    for index, loop in enumerate(loops):
        groups.setdefault(loop.cut, []).append(index)
    for members in groups.values():
        outer, holes = members[0], members[1:]
        for h in holes:
            if not within[outer, h]:
                raise fail(f"{loops[h].label} is not inside {loops[outer].label}")
            for g in holes:
                if g != h and within[g, h]:
                    raise fail(f"{loops[h].label} lies inside {loops[g].label} (holes must lie apart)")
    prism = groups[0][0]
    for k, members in groups.items():
        if k == 0:
            continue
        pocket, islands = members[0], members[1:]
        if not within[prism, pocket]:
            raise fail(f"{loops[pocket].label} is not inside {loops[prism].label}")
        # the empty regions of the other groups (the prism's holes; another pocket, less its islands)
        empties = [(h, []) for h in groups[0][1:]]
        empties += [(group[0], group[1:]) for other, group in groups.items() if other not in (0, k)]
        for empty, kept in empties:
            if within[empty, pocket] and not any(within[g, pocket] for g in kept):
                raise fail(f"{loops[pocket].label} lies in {loops[empty].label}, where there is no material")
            if within[pocket, empty] and not any(within[g, empty] for g in islands):
                raise fail(f"{loops[empty].label} lies in {loops[pocket].label} but in none of its islands")


def _nested_faces(indices: Sequence[int], within: np.ndarray) -> list[tuple[int, list[int]]]:
    """Even–odd faces of some loops: (outer loop, its holes) for every loop at even depth."""
    chosen = list(indices)
    sub = within[np.ix_(chosen, chosen)]
    depth = sub.sum(axis=0)
    parent = {
        j: max((i for i in range(len(chosen)) if sub[i, j]), key=lambda i: depth[i], default=-1)
        for j in range(len(chosen))
    }
    return [
        (chosen[i], [chosen[j] for j in range(len(chosen)) if parent[j] == i])
        for i in range(len(chosen))
        if depth[i] % 2 == 0
    ]


# --- entities ---------------------------------------------------------------------------------


def _bspline(data: Entities, curve: BSplineCurve, z: float) -> str:
    """``curve`` at height ``z`` as a B_SPLINE_CURVE_WITH_KNOTS with exactly its poles and knots.

    A clamped closed curve is written as it is. A periodic one in the
    unclamped form OpenCASCADE writes for a periodic curve and reads back as
    periodic (closed_curve .T.): the extended knot vector of
    :class:`BSplineCurve`, whose first of m copies of the domain start sits
    at index p, less its first m − 1 knots and poles (their basis functions
    vanish on the domain), so that the domain starts at the last copy. The
    written poles and knots are evaluated at every knot span's midpoint and
    at both ends and must give ``curve``'s points (and close) to
    ``CLOSE_REL`` of its size before they are written.
    """
    p = curve.degree
    ctrl = np.asarray(curve.control_points, dtype=float)
    knots = np.asarray(curve.knots, dtype=float)
    if len(knots) != len(ctrl) + p + 1 or np.any(np.diff(knots) < 0.0):
        raise ExportError("a STEP outline's B-spline has an invalid knot vector")
    lo, hi = curve.domain
    if curve.periodic:
        drop = int(np.count_nonzero(knots == lo)) - 1
        ctrl, knots = ctrl[drop:], knots[drop:]
    written = BSplineCurve(degree=p, knots=knots, control_points=ctrl)
    start, end = knot_spans(curve)
    u = np.concatenate(([lo, hi], 0.5 * (start + end)))
    got = written.evaluate(u)
    size = float(np.max(np.abs(ctrl)))
    if not (
        written.domain == (lo, hi) and np.allclose(got, curve.evaluate(u), rtol=0.0, atol=CLOSE_REL * size)
    ):
        raise ExportError("the STEP form of an outline's B-spline differs from the curve")
    if not np.allclose(got[0], got[1], rtol=0.0, atol=CLOSE_REL * size):
        raise ExportError("a STEP outline's B-spline does not close")
    values, mults = np.unique(knots, return_counts=True)
    poles = ",".join(data.point((x, y, z)) for x, y in ctrl)
    return data.add(
        f"B_SPLINE_CURVE_WITH_KNOTS('',{p},({poles}),.UNSPECIFIED.,.T.,.F.,"
        f"({','.join(str(int(m)) for m in mults)}),{reals(values)},.UNSPECIFIED.)"
    )


def _curve(data: Entities, outline: Outline, segment: _Segment, z: float) -> str:
    if isinstance(outline, BSplineCurve):
        return _bspline(data, outline, z)
    if segment.kind == "circle":
        axes = data.placement((0.0, 0.0, z), UP, _circle_ref(outline))
        return data.add(f"CIRCLE('',{axes},{real(outline.radius)})")
    (ax, ay), (bx, by) = segment.start, segment.end
    length = math.hypot(bx - ax, by - ay)
    direction = data.vector(((bx - ax) / length, (by - ay) / length, 0.0), 1.0)
    return data.add(f"LINE('',{data.point((ax, ay, z))},{direction})")


def _edge(data: Entities, start: str, end: str, curve: str) -> str:
    return data.add(f"EDGE_CURVE('',{start},{end},{curve},.T.)")


def _vertices(data: Entities, segments: Sequence[_Segment], z: float) -> list[str]:
    return [data.add(f"VERTEX_POINT('',{data.point((*s.start, z))})") for s in segments]


def _bound(data: Entities, edges: Sequence[tuple[str, bool]], *, outer: bool) -> str:
    oriented = ",".join(data.add(f"ORIENTED_EDGE('',*,*,{e},{'.T.' if f else '.F.'})") for e, f in edges)
    loop = data.add(f"EDGE_LOOP('',({oriented}))")
    return data.add(f"{'FACE_OUTER_BOUND' if outer else 'FACE_BOUND'}('',{loop},.T.)")


def _face(data: Entities, bounds: Sequence[str], surface: str, same_sense: bool) -> str:
    return data.add(f"ADVANCED_FACE('',({','.join(bounds)}),{surface},{'.T.' if same_sense else '.F.'})")


@dataclass(frozen=True, slots=True)
class _Rings:
    """A loop's edges at its lower and upper height, in the outline's direction."""

    low: list[str]
    top: list[str]


def _walls(data: Entities, loop: _Loop) -> tuple[_Rings, list[str]]:
    """The loop's edges and wall faces."""
    segments = _segments(loop.outline)
    n = len(segments)
    height = loop.z_top - loop.z_low
    low_v, top_v = _vertices(data, segments, loop.z_low), _vertices(data, segments, loop.z_top)
    up = [
        _edge(
            data,
            low_v[i],
            top_v[i],
            data.add(f"LINE('',{data.point((*s.start, loop.z_low))},{data.vector(UP, 1.0)})"),
        )
        for i, s in enumerate(segments)
    ]
    low_curves = [_curve(data, loop.outline, s, loop.z_low) for s in segments]
    low = [_edge(data, low_v[i], low_v[(i + 1) % n], c) for i, c in enumerate(low_curves)]
    top = [
        _edge(data, top_v[i], top_v[(i + 1) % n], _curve(data, loop.outline, s, loop.z_top))
        for i, s in enumerate(segments)
    ]
    right = loop.ccw == loop.material_inside  # outward normal = T × ẑ, the right of the outline's direction
    faces = []
    for i, segment in enumerate(segments):
        a, b = up[i], up[(i + 1) % n]
        if right:  # lower edge along T, up at its end, upper edge back, down at its start
            edges = [(low[i], True), (b, True), (top[i], False), (a, False)]
        else:
            edges = [(low[i], False), (a, True), (top[i], True), (b, False)]
        if segment.kind == "bspline":
            surface = data.add(f"SURFACE_OF_LINEAR_EXTRUSION('',{low_curves[i]},{data.vector(UP, height)})")
            same_sense = right  # the extrusion surface's normal is T × ẑ
        elif segment.kind == "circle":
            assert isinstance(loop.outline, BoreOutline)
            axes = data.placement((0.0, 0.0, loop.z_low), UP, _circle_ref(loop.outline))
            surface = data.add(f"CYLINDRICAL_SURFACE('',{axes},{real(loop.outline.radius)})")
            same_sense = right  # the circle runs ccw: its right is away from the axis, the cylinder's normal
        else:
            (ax, ay), (bx, by) = segment.start, segment.end
            length = math.hypot(bx - ax, by - ay)
            tx, ty = (bx - ax) / length, (by - ay) / length
            normal = (ty, -tx, 0.0) if right else (-ty, tx, 0.0)
            surface = data.add(f"PLANE('',{data.placement((ax, ay, loop.z_low), normal, (tx, ty, 0.0))})")
            same_sense = True
        faces.append(_face(data, [_bound(data, edges, outer=False)], surface, same_sense))
    return _Rings(low, top), faces


def _plane_face(
    data: Entities, loops: Sequence[_Loop], rings: Sequence[list[str]], z: float, *, up: bool
) -> str:
    """A plane face at height ``z``, normal ±z: the first loop its outer bound, the others its holes."""
    bounds = []
    for index, (loop, ring) in enumerate(zip(loops, rings, strict=True)):
        outer = index == 0
        ccw_wanted = outer == up  # counter-clockwise seen from the outward side
        if ccw_wanted == loop.ccw:
            edges = [(e, True) for e in ring]
        else:
            edges = [(e, False) for e in reversed(ring)]
        bounds.append(_bound(data, edges, outer=outer))
    plane = data.add(f"PLANE('',{data.placement((0.0, 0.0, z), UP if up else DOWN, X_AXIS)})")
    return _face(data, bounds, plane, True)


def shell(data: Entities, body: Body) -> str:
    """The body's CLOSED_SHELL: walls, bottom, pocket floors and top faces; its reference."""
    loops = _loops(body)
    within = _containment(body.name, loops)
    _check_nesting(body.name, loops, within)
    faces: list[str] = []
    rings = []
    for loop in loops:
        ring, walls = _walls(data, loop)
        rings.append(ring)
        faces += walls
    prism = [i for i, loop in enumerate(loops) if loop.cut == 0]
    faces.append(
        _plane_face(data, [loops[i] for i in prism], [rings[i].low for i in prism], body.prism.z0, up=False)
    )
    for k, cut in enumerate(body.cuts, 1):
        members = [i for i, loop in enumerate(loops) if loop.cut == k]
        faces.append(
            _plane_face(data, [loops[i] for i in members], [rings[i].low for i in members], cut.z0, up=True)
        )
    top = body.prism.z0 + body.prism.height
    for outer, holes in _nested_faces(range(len(loops)), within):
        chosen = [outer, *holes]
        faces.append(
            _plane_face(data, [loops[i] for i in chosen], [rings[i].top for i in chosen], top, up=True)
        )
    return data.add(f"CLOSED_SHELL('',({','.join(faces)}))")
