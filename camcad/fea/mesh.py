"""Triangle meshes of plane regions bounded by exact curves, graded towards refined spots.

Every boundary node is a point of the exact curve (the cam profile at some φ,
the bore circle, the keyway's lines and fillets): the boundary is sampled
here at the local element size and handed to gmsh as a chain of straight
edges that it must not split, so gmsh only fills the interior. The element
size grows linearly away from each refined spot (the contact strips, the
keyway fillets), h(x) = min(h_max, minᵢ hᵢ + g·max(0, |x − cᵢ| − rᵢ)), both on
the boundary (here) and inside (a gmsh background field of the same formula).

gmsh (GPL) is imported only when a mesh is made; it is the optional extra
``camcad[fea]``.
"""

from __future__ import annotations

import itertools
import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from camcad._typing import FloatArray, readonly
from camcad.errors import UsageError

__all__ = [
    "MAX_ELEMENTS",
    "Loop",
    "Piece",
    "PlateMesh",
    "Spot",
    "element_size",
    "estimated_triangles",
    "mesh_region",
    "sample_loop",
    "smallest_mesh_size",
]

IntArray = NDArray[np.int64]
Curve = Callable[[FloatArray], FloatArray]
"""A plane curve: parameters (n,) → points (n, 2) [mm]."""

_PRESAMPLES = 64  # per piece, before the geometric clusters around spots
_GMSH_LOCK = threading.Lock()  # gmsh keeps one global model: one mesh at a time


MAX_ELEMENTS = 30_000
"""Most triangles a plate mesh may have, estimated before meshing (:func:`estimated_triangles`).

Measured (docs/reference/commands.md, "Hard and soft limits"): the test plate at 47 000 P2
triangles took 74 s to mesh and solve its load cases on a shared 2-core
machine, at 7 300 triangles 5.5 s; 30 000 keeps a check under about a minute.
"""
_TRIANGLE_AREA = math.sqrt(3.0) / 4.0  # an equilateral triangle of edge h has area (√3/4)·h²


def estimated_triangles(area: float, h_max: float) -> float:
    """How many triangles of edge ``h_max`` [mm] fill ``area`` [mm²]: A / ((√3/4)·h²).

    A lower bound on what :func:`mesh_region` makes, which only refines from
    ``h_max`` towards the spots. The plate is meshed in the plane (plane
    stress or strain): no elements across the thickness.
    """
    return area / (_TRIANGLE_AREA * h_max * h_max)


def smallest_mesh_size(area: float) -> float:
    """The smallest ``h_max`` [mm] whose estimate stays within :data:`MAX_ELEMENTS` for ``area`` [mm²]."""
    return math.sqrt(area / (_TRIANGLE_AREA * MAX_ELEMENTS))


@dataclass(frozen=True, slots=True, kw_only=True)
class Spot:
    """Where the mesh is refined: size ``size`` [mm] within ``radius`` [mm] of ``centre``."""

    centre: tuple[float, float]
    size: float
    radius: float = 0.0


_MERGE = 1e-6  # × a piece's parameter range: fixed nodes closer than this are merged


def element_size(points: FloatArray, spots: Sequence[Spot], *, h_max: float, growth: float) -> FloatArray:
    """The target element size [mm] at points (n, 2): h = min(h_max, minᵢ hᵢ + g·max(0, dᵢ − rᵢ)).

    Examples
    --------
    >>> spot = Spot(centre=(0.0, 0.0), size=0.1, radius=1.0)
    >>> element_size(np.array([[0.5, 0.0], [3.0, 0.0], [20.0, 0.0]]), [spot], h_max=2.0, growth=0.3)
    array([0.1, 0.7, 2. ])
    """
    xy = np.atleast_2d(np.asarray(points, dtype=float))
    out = np.full(len(xy), float(h_max))
    for spot in spots:
        d = np.hypot(xy[:, 0] - spot.centre[0], xy[:, 1] - spot.centre[1])
        out = np.minimum(out, spot.size + growth * np.maximum(0.0, d - spot.radius))
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class Piece:
    """One smooth piece of a boundary loop: ``curve(t)`` for t from ``start`` to ``stop`` > ``start``.

    ``fixed`` are parameters that must be nodes (a contact strip's edges and
    divisions); ``tag`` names the piece's edges (see :class:`PlateMesh`);
    ``speed`` is |dcurve/dt| for the clusters of presamples around spots
    (None: the chord of the presamples).
    """

    curve: Curve
    start: float
    stop: float
    tag: int
    fixed: tuple[float, ...] = ()
    speed: Callable[[FloatArray], FloatArray] | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Loop:
    """A closed boundary: pieces end to end, each ending where the next begins."""

    pieces: tuple[Piece, ...]


def _presamples(piece: Piece, spots: Sequence[Spot], h_max: float) -> FloatArray:
    """Parameters dense enough to integrate 1/h along the piece, clustered geometrically near spots."""
    t = np.linspace(piece.start, piece.stop, _PRESAMPLES + 1)
    extra = [t, np.asarray(piece.fixed, dtype=float)]
    pts = piece.curve(t)
    chord = np.hypot(*np.diff(pts, axis=0).T)
    mean_speed = float(chord.sum()) / abs(piece.stop - piece.start) if piece.stop != piece.start else 1.0
    lo, hi = piece.start, piece.stop
    for spot in spots:
        # parameters of the nearest presample, then a geometric ladder of offsets around it
        d = np.hypot(pts[:, 0] - spot.centre[0], pts[:, 1] - spot.centre[1])
        if float(d.min()) > spot.radius + 4.0 * h_max:
            continue
        k = int(np.argmin(d))
        # refine the nearest parameter on a fine local grid
        span = abs(t[1] - t[0])
        local = np.linspace(max(lo, t[k] - span), min(hi, t[k] + span), 257)
        dl = np.hypot(*(piece.curve(local) - np.asarray(spot.centre)).T)
        t0 = float(local[int(np.argmin(dl))])
        speed = float(piece.speed(np.array([t0]))[0]) if piece.speed is not None else mean_speed
        steps = spot.size * 1.1 ** np.arange(0, 200)
        steps = steps[steps < 2.0 * (spot.radius + h_max) + spot.size]
        ladder = np.concatenate(([0.0], np.cumsum(steps))) + spot.radius
        ladder = np.concatenate((np.linspace(0.0, spot.radius, 16), ladder)) / max(speed, 1e-300)
        extra.append(t0 - ladder)
        extra.append(t0 + ladder)
    return np.unique(np.clip(np.concatenate(extra), lo, hi))


def _sample_piece(piece: Piece, spots: Sequence[Spot], h_max: float, growth: float) -> FloatArray:
    """Node parameters of one piece (its start included, its stop not): spacing ≈ the local size.

    Between consecutive fixed parameters the nodes split ∫ ds/h into equal
    parts (at least one edge), by inverting the cumulative integral.
    """
    t = _presamples(piece, spots, h_max)
    pts = piece.curve(t)
    h = element_size(pts, spots, h_max=h_max, growth=growth)
    ds = np.hypot(*np.diff(pts, axis=0).T)
    density = np.concatenate(([0.0], np.cumsum(ds * 0.5 * (1.0 / h[1:] + 1.0 / h[:-1]))))
    fixed = np.asarray(sorted(set(piece.fixed) | {piece.start, piece.stop}), dtype=float)
    # nodes closer than _MERGE of the piece are one (the start and the stop stay): an edge of
    # 1e-8 mm at 45 mm from the axis leaves skfem's inverse map no digits to converge in
    gap = _MERGE * (piece.stop - piece.start)
    keep = np.concatenate(([True], np.diff(fixed) > gap))
    keep[-1] = True  # the stop stays; a fixed node a hair before it goes
    keep[-2] = keep[-2] and fixed[-1] - fixed[-2] > gap
    fixed = fixed[keep]
    nodes: list[FloatArray] = []
    for a, b in itertools.pairwise(fixed):
        da, db = np.interp([a, b], t, density)
        n = max(1, round(db - da))
        levels = da + (db - da) * np.arange(n) / n
        inside = np.interp(levels, density, t)
        inside[0] = a
        nodes.append(inside)
    return np.concatenate(nodes)


def sample_loop(
    loop: Loop, spots: Sequence[Spot], *, h_max: float, growth: float
) -> tuple[FloatArray, IntArray, FloatArray, FloatArray]:
    """Boundary nodes of a loop at the local element size.

    Returns
    -------
    points, tags, params, midpoints
        (n, 2) exact curve points [mm]; (n,) the tag of the edge from node i
        to node i + 1 (cyclic); (n, 2) the curve parameters at both ends of
        that edge; (n, 2) the exact curve point at the edge's middle parameter
        (the quadratic elements' edge node).
    """
    points, tags, params, mids = [], [], [], []
    for piece in loop.pieces:
        t = _sample_piece(piece, spots, h_max, growth)
        ends = np.column_stack((t, np.append(t[1:], piece.stop)))
        points.append(piece.curve(t))
        tags.append(np.full(len(t), piece.tag, dtype=np.int64))
        params.append(ends)
        mids.append(piece.curve(ends.mean(axis=1)))
    return np.vstack(points), np.concatenate(tags), np.vstack(params), np.vstack(mids)


@dataclass(frozen=True, slots=True, kw_only=True)
class PlateMesh:
    """A triangle mesh of a plane region and its tagged boundary edges.

    Attributes
    ----------
    points
        (N, 2) vertices [mm].
    triangles
        (M, 3) vertex indices, counter-clockwise.
    edges
        (B, 2) vertex indices of the boundary edges, in loop order.
    edge_tags
        (B,) the tag of each boundary edge (what part of the outline it lies on).
    edge_params
        (B, 2) the curve parameters of each edge's ends (φ on the cam profile).
    edge_midpoints
        (B, 2) the exact curve point halfway (in the parameter) along each
        edge [mm]: the quadratic elements' boundary nodes, so that the
        elements follow the curved outline (isoparametric).
    """

    points: FloatArray
    triangles: IntArray
    edges: IntArray
    edge_tags: IntArray
    edge_params: FloatArray
    edge_midpoints: FloatArray
    spots: tuple[Spot, ...] = field(default=())

    @property
    def size(self) -> tuple[int, int]:
        """(vertices, triangles)."""
        return len(self.points), len(self.triangles)


def _import_gmsh() -> Any:
    try:
        import gmsh
    except ImportError as err:  # pragma: no cover - the test extra installs it
        raise UsageError(
            "fea",
            "the finite-element check needs gmsh and scikit-fem: pip install 'camcad[fea]'",
        ) from err
    return gmsh


def mesh_region(
    outer: Loop, holes: Sequence[Loop], spots: Sequence[Spot], *, h_max: float, growth: float
) -> PlateMesh:
    """Mesh the region inside ``outer`` and outside every hole with gmsh (Frontal-Delaunay).

    The boundary nodes are :func:`sample_loop`'s exact curve points and the
    edges between them are kept whole; the interior follows the same size
    formula through a gmsh background field. Deterministic: one thread, a
    fixed algorithm, the same input gives the same mesh.
    """
    gmsh = _import_gmsh()
    loops = [sample_loop(loop, spots, h_max=h_max, growth=growth) for loop in (outer, *holes)]
    with _GMSH_LOCK:
        gmsh.initialize(interruptible=False)
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.option.setNumber("General.NumThreads", 1)
            gmsh.model.add("plate")
            geo = gmsh.model.geo
            curve_loops, all_lines = [], []
            for i, (xy, _, _, _) in enumerate(loops):
                area = 0.5 * float(
                    np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1])
                )
                ccw = area > 0.0
                tags = [geo.addPoint(float(x), float(y), 0.0) for x, y in xy]
                n = len(tags)
                lines = [geo.addLine(tags[k], tags[(k + 1) % n]) for k in range(n)]
                signed = lines if (ccw == (i == 0)) else [-ln for ln in reversed(lines)]
                curve_loops.append(geo.addCurveLoop(signed))
                all_lines.extend(lines)
            geo.addPlaneSurface(curve_loops)
            geo.synchronize()
            for ln in all_lines:
                gmsh.model.mesh.setTransfiniteCurve(ln, 2)
            fields = []
            for spot in spots:
                f = gmsh.model.mesh.field.add("MathEval")
                d = f"Sqrt((x-({spot.centre[0]!r}))^2+(y-({spot.centre[1]!r}))^2)-({spot.radius!r})"
                gmsh.model.mesh.field.setString(f, "F", f"{spot.size!r}+{growth!r}*0.5*(({d})+Fabs({d}))")
                fields.append(f)
            cap = gmsh.model.mesh.field.add("MathEval")
            gmsh.model.mesh.field.setString(cap, "F", f"{h_max!r}")
            fields.append(cap)
            least = gmsh.model.mesh.field.add("Min")
            gmsh.model.mesh.field.setNumbers(least, "FieldsList", fields)
            gmsh.model.mesh.field.setAsBackgroundMesh(least)
            for key in ("MeshSizeFromPoints", "MeshSizeFromCurvature", "MeshSizeExtendFromBoundary"):
                gmsh.option.setNumber(f"Mesh.{key}", 0)
            gmsh.option.setNumber("Mesh.Algorithm", 6)
            gmsh.model.mesh.generate(2)
            node_tags, coords, _ = gmsh.model.mesh.getNodes()
            _, element_nodes = gmsh.model.mesh.getElementsByType(2)
        finally:
            gmsh.finalize()
    xyz = np.asarray(coords, dtype=float).reshape(-1, 3)
    index = np.zeros(int(np.max(node_tags)) + 1, dtype=np.int64)
    index[np.asarray(node_tags, dtype=np.int64)] = np.arange(len(node_tags))
    triangles = index[np.asarray(element_nodes, dtype=np.int64).reshape(-1, 3)]
    points = np.ascontiguousarray(xyz[:, :2])
    # orient every triangle counter-clockwise
    a, b, c = (points[triangles[:, k]] for k in range(3))
    flip = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0.0
    triangles[flip] = triangles[flip][:, [0, 2, 1]]
    # boundary nodes are the exact points given to gmsh: find them by coordinates
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    edges: list[IntArray] = []
    edge_tags: list[IntArray] = []
    edge_params: list[FloatArray] = []
    edge_mids: list[FloatArray] = []
    for xy, loop_tags, params, mids in loops:
        dist, ids = tree.query(xy)
        if float(dist.max()) > 1e-9 * max(1.0, float(np.abs(xy).max())):
            raise RuntimeError("gmsh moved a boundary node")  # pragma: no cover - transfinite edges keep them
        edges.append(np.column_stack((ids, np.roll(ids, -1))))
        edge_tags.append(loop_tags)
        edge_params.append(params)
        edge_mids.append(mids)
    out = PlateMesh(
        points=points,
        triangles=np.ascontiguousarray(triangles),
        edges=np.vstack(edges),
        edge_tags=np.concatenate(edge_tags),
        edge_params=np.vstack(edge_params),
        edge_midpoints=np.vstack(edge_mids),
        spots=tuple(spots),
    )
    readonly(out.points, out.edge_params, out.edge_midpoints)
    return out
