"""Check a toolpath geometrically against the exact cam, from its moves alone.

The moves may come from the planner, from :func:`camcad.export.gcode.parse.parse_gcode`
or from LinuxCNC's canonical output (:func:`~camcad.export.gcode.parse.parse_canon`),
so the same proof runs on what a controller would execute. Nothing here
uses the planner's internals: passes are found from the motion itself.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from camcad._typing import FloatArray
from camcad.geometry.cam import Cam
from camcad.toolpath.moves import Move, MoveKind
from camcad.toolpath.spec import Direction, GcodeSpec

__all__ = ["ToolpathCheck", "check_toolpath", "densify", "distance_to_polyline"]

_STEP = 0.02  # mm between samples along moves
_EXACT_SAMPLES = 200_000  # samples of the exact curve, to measure the path against it
_COARSE = 8192  # samples seeding the projection onto the exact curve
_NEWTON = 4
_LEVEL_TOL = 1e-3  # mm: a pass is at a level when its depth is this close
_RADIUS_TOL = 1e-3  # mm: arc start and end radii must agree this well


@dataclass(frozen=True, slots=True, kw_only=True)
class ToolpathCheck:
    """What the proof measured; :attr:`problems` lists what failed.

    Attributes
    ----------
    hausdorff
        Two-way distance between the finishing contour (leads excluded) and
        the exact offset curve [mm].
    min_clearance
        Smallest distance from the tool centre to the exact profile minus
        the tool radius, over feed moves below the stock top [mm]
        (negative: the tool cuts into the part).
    bore_excess
        Largest amount by which the tool reaches beyond the bore wall [mm]
        (0 when it never does, or without a bore).
    levels
        Depths of the profile passes found [mm].
    missing_levels
        Step-down levels with no pass [mm].
    low_rapids
        Rapids that start or end below the safe height (the first move
        excepted: its start is the unknown machine position).
    max_radius_mismatch
        Largest difference between an arc's start and end radius [mm].
    direction
        Milling direction of the finishing contour, from its orientation.
    final_depth
        Depth of the finishing contour [mm].
    """

    hausdorff: float
    min_clearance: float
    bore_excess: float
    levels: tuple[float, ...]
    missing_levels: tuple[float, ...]
    low_rapids: int
    max_radius_mismatch: float
    direction: Direction
    final_depth: float
    tolerance: float
    expected_direction: Direction
    expected_depth: float

    @property
    def problems(self) -> tuple[str, ...]:
        """One line per failed check; empty when the toolpath passes."""
        out = []
        if self.hausdorff > self.tolerance:
            out.append(f"finishing contour deviates {self.hausdorff:.5f} mm > {self.tolerance:g} mm")
        if self.min_clearance < -self.tolerance:
            out.append(f"tool cuts {-self.min_clearance:.5f} mm into the profile")
        if self.bore_excess > self.tolerance:
            out.append(f"tool cuts {self.bore_excess:.5f} mm beyond the bore")
        if self.missing_levels:
            out.append(f"no pass at Z {', '.join(f'{z:.4f}' for z in self.missing_levels)}")
        if self.low_rapids:
            out.append(f"{self.low_rapids} rapid moves below the safe height")
        if self.max_radius_mismatch > _RADIUS_TOL:
            out.append(f"arc radii differ by {self.max_radius_mismatch:.5f} mm")
        if self.direction is not self.expected_direction:
            out.append(f"contour is milled {self.direction.value}, expected {self.expected_direction.value}")
        if abs(self.final_depth - self.expected_depth) > _LEVEL_TOL:
            out.append(f"finishing depth Z{self.final_depth:.4f}, expected Z{self.expected_depth:.4f}")
        return tuple(out)

    @property
    def ok(self) -> bool:
        """Whether every check passed."""
        return not self.problems


def densify(move: Move, step: float = _STEP) -> FloatArray:
    """(k, 3) points along a move from its start to its end [mm], at most ``step`` apart."""
    a, b = np.asarray(move.start, dtype=float), np.asarray(move.end, dtype=float)
    if not move.kind.is_arc:
        n = max(1, math.ceil(float(np.linalg.norm(b - a)) / step))
        u = np.linspace(0.0, 1.0, n + 1)
        return a + (b - a) * u[:, None]
    assert move.center is not None
    c = np.asarray(move.center, dtype=float)
    r0, r1 = move.radii
    sweep = move.sweep
    n = max(1, math.ceil(abs(sweep) * max(r0, r1) / step))
    u = np.linspace(0.0, 1.0, n + 1)
    ang = math.atan2(a[1] - c[1], a[0] - c[0]) + sweep * u
    rad = r0 + (r1 - r0) * u  # a controller spirals between unequal radii
    out = np.column_stack((c[0] + rad * np.cos(ang), c[1] + rad * np.sin(ang), a[2] + (b[2] - a[2]) * u))
    out[0], out[-1] = a, b
    return out


def distance_to_polyline(points: FloatArray, poly: FloatArray, *, bound: float = math.inf) -> FloatArray:
    """Distance [mm] from (n, 2) points to an (m, 2) polyline.

    The two nearest vertices are found with a k-d tree and the segments on
    both sides of each are measured, so closed polylines (last vertex equal
    to the first) work too. Points whose nearest vertex is farther than
    ``bound`` [mm] get ``inf``.
    """
    keep = np.concatenate(([True], np.linalg.norm(np.diff(poly, axis=0), axis=1) > 1e-9))
    poly = poly[keep]  # a repeated vertex would hide a segment
    gap, nearest = cKDTree(poly).query(points, k=2, distance_upper_bound=bound)
    far = ~np.isfinite(gap[:, 0])
    nearest = np.where(np.isfinite(gap), nearest, nearest[:, :1])
    nearest = np.where(far[:, None], 0, nearest)
    best = np.full(len(points), np.inf)
    for first in (nearest[:, 0] - 1, nearest[:, 0], nearest[:, 1] - 1, nearest[:, 1]):
        j = np.clip(first, 0, len(poly) - 2)
        a, w = poly[j], poly[j + 1] - poly[j]
        ww = np.maximum(np.einsum("ij,ij->i", w, w), 1e-300)
        t = np.clip(np.einsum("ij,ij->i", points - a, w) / ww, 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(points - (a + w * t[:, None]), axis=1))
    best[far] = np.inf
    return best


class _Projector:
    """Distance from points to an exact closed curve C(φ) = cam.offset_curve(φ, distance).

    A k-d tree over coarse samples gives the starting φ; Newton's method on
    (C(φ) − p)·C′(φ) = 0 then finds the foot point on the exact curve.
    """

    def __init__(self, cam: Cam, distance: float) -> None:
        self.cam, self.distance = cam, distance
        self.phi = np.linspace(0.0, 2.0 * math.pi, _COARSE, endpoint=False)
        self.points = np.asarray(cam.offset_curve(self.phi, distance).point)
        self.tree = cKDTree(self.points)

    def curve(self, phi: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        o = self.cam.offset_curve(phi, self.distance)
        return o.point, o.d1, o.d2

    def dense(self, n: int) -> FloatArray:
        """(n + 1, 2) closed polyline of the exact curve."""
        return np.asarray(self.cam.offset_curve(np.linspace(0.0, 2.0 * math.pi, n + 1), self.distance).point)

    def __call__(self, points: FloatArray, *, bound: float = math.inf) -> FloatArray:
        """Distance [mm] from (n, 2) points to the curve; ``inf`` beyond ``bound`` [mm]."""
        gap, idx = self.tree.query(points, distance_upper_bound=bound)
        near = np.isfinite(gap)
        out = np.full(len(points), np.inf)
        if not near.any():
            return out
        p = points[near]
        step = 2.0 * math.pi / _COARSE
        phi0 = self.phi[idx[near]]
        phi = phi0.copy()
        best = gap[near]
        for _ in range(_NEWTON):
            c, d1, d2 = self.curve(phi)
            diff = c - p
            best = np.minimum(best, np.linalg.norm(diff, axis=1))
            g = np.einsum("ij,ij->i", diff, d1)
            gp = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", diff, d2)
            gp = np.where(gp > 0.0, gp, np.einsum("ij,ij->i", d1, d1))
            phi = np.clip(phi - g / gp, phi0 - 2.0 * step, phi0 + 2.0 * step)
        c, _, _ = self.curve(phi)
        out[near] = np.minimum(best, np.linalg.norm(c - p, axis=1))
        return out


def _runs(moves: Sequence[Move]) -> list[list[Move]]:
    """Maximal runs of consecutive feed moves (a pass each)."""
    runs: list[list[Move]] = []
    current: list[Move] = []
    for m in moves:
        if m.kind is MoveKind.RAPID:
            if current:
                runs.append(current)
            current = []
        else:
            current.append(m)
    if current:
        runs.append(current)
    return runs


def _planar(m: Move) -> bool:
    return m.kind.is_arc or math.hypot(m.end[0] - m.start[0], m.end[1] - m.start[1]) > 0.0


def check_toolpath(
    moves: Sequence[Move], cam: Cam, spec: GcodeSpec, *, thickness: float, bore: float = 0.0
) -> ToolpathCheck:
    """Prove a toolpath against the exact cam geometry.

    Parameters
    ----------
    moves
        The program's motion, in order (from the planner or either reader).
    cam
        The cam the program should mill.
    spec
        The milling settings it was planned with.
    thickness
        Plate thickness [mm].
    bore
        Bore diameter [mm].

    Returns
    -------
    ToolpathCheck
        Hausdorff distance of the finishing contour, clearance from the
        profile, depth levels, rapids, arc radii and direction.

    Notes
    -----
    Passes are the runs of feed moves between rapids; a run staying inside
    the bore is a bore pass, any other a profile pass. The last profile pass
    is the finishing pass; its first and last planar moves are the leads.
    Distances to the exact curves are found by Newton projection onto
    ``cam.offset_curve(φ, d)``; distances from the exact curve to the path use
    200 000 samples of the curve and the path as a polyline of 0.02 mm
    chords (error below 1e-4 mm for path radii above 0.5 mm).
    """
    r = spec.tool_radius
    depth = thickness + spec.breakthrough
    runs = _runs(moves)
    bore_r = bore / 2.0
    pts_by_run = [np.vstack([densify(m) for m in run]) for run in runs]
    is_bore = [bore_r > 0.0 and bool(np.all(np.hypot(p[:, 0], p[:, 1]) < bore_r + 1e-6)) for p in pts_by_run]
    profile_runs = [run for run, b in zip(runs, is_bore, strict=True) if not b]
    levels, missing = _levels(profile_runs, depth, spec.step_down)
    finish = profile_runs[-1] if profile_runs else []
    hausdorff, direction, final_depth = _measure_finish(finish, _Projector(cam, r))
    feed_pts = np.vstack(pts_by_run) if pts_by_run else np.zeros((0, 3))
    clearance, bore_excess = _clearance(feed_pts, _Projector(cam, 0.0), r, bore_r)
    mismatch = max((abs(m.radii[0] - m.radii[1]) for m in moves if m.kind.is_arc), default=0.0)
    return ToolpathCheck(
        hausdorff=hausdorff,
        min_clearance=clearance,
        bore_excess=bore_excess,
        levels=levels,
        missing_levels=missing,
        low_rapids=_low_rapids(moves, spec.safe_height),
        max_radius_mismatch=mismatch,
        direction=direction,
        final_depth=final_depth,
        tolerance=spec.tolerance,
        expected_direction=spec.direction,
        expected_depth=-depth,
    )


def _levels(
    profile_runs: Sequence[Sequence[Move]], depth: float, step_down: float
) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Depths [mm] of the profile passes found (top down), and the step-down levels with no pass."""
    levels = tuple(sorted({round(min(m.end[2] for m in run), 4) for run in profile_runs}, reverse=True))
    n_levels = max(1, math.ceil(depth / step_down - 1e-9))
    expected = [-depth * k / n_levels for k in range(1, n_levels + 1)]
    missing = tuple(z for z in expected if not any(abs(z - lv) <= _LEVEL_TOL for lv in levels))
    return levels, missing


def _measure_finish(finish: Sequence[Move], offset: _Projector) -> tuple[float, Direction, float]:
    """Hausdorff distance, milling direction and depth of the finishing contour.

    The contour is the finishing pass without its first and last planar
    moves (the leads); the distance [mm] is two-way, to the exact offset
    curve; the depth [mm] is its lowest Z.
    """
    planar = [m for m in finish if _planar(m)]
    contour = planar[1:-1]
    if not contour:
        return math.inf, Direction.CONVENTIONAL, 0.0
    xy = np.vstack([densify(m) for m in contour])[:, :2]
    to_exact = offset(xy, bound=1.0)
    to_path = distance_to_polyline(offset.dense(_EXACT_SAMPLES), xy, bound=1.0)
    hausdorff = float(max(to_exact.max(), to_path.max()))
    x, y = xy[:, 0], xy[:, 1]
    area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    direction = Direction.CLIMB if area < 0.0 else Direction.CONVENTIONAL
    return hausdorff, direction, float(min(m.end[2] for m in contour))


def _clearance(feed_pts: FloatArray, profile: _Projector, r: float, bore_r: float) -> tuple[float, float]:
    """Smallest clearance from the profile and largest reach beyond the bore wall [mm].

    Over the feed points (n, 3) below the stock top: the clearance is the
    distance to the exact profile minus the tool radius ``r``; points inside
    the bore radius ``bore_r`` are measured against the bore wall instead.
    """
    below = feed_pts[feed_pts[:, 2] < 0.0]
    inside = np.hypot(below[:, 0], below[:, 1]) < bore_r if bore_r > 0 else np.zeros(len(below), bool)
    outer = below[~inside]
    near = profile(outer[:, :2], bound=r + 1.0)
    clearance = float((near - r).min()) if len(outer) else math.inf
    in_bore = below[inside]
    bore_excess = (
        float(max(0.0, (np.hypot(in_bore[:, 0], in_bore[:, 1]) + r - bore_r).max())) if len(in_bore) else 0.0
    )
    return clearance, bore_excess


def _low_rapids(moves: Sequence[Move], safe_height: float) -> int:
    """Rapids that start or end below the safe height [mm] (the first move's unknown start excepted)."""
    floor = safe_height - 1e-9
    return sum(
        1
        for i, m in enumerate(moves)
        if m.kind is MoveKind.RAPID and (m.end[2] < floor or (i > 0 and m.start[2] < floor))
    )
