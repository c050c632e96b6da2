"""A barrel cam as a watertight triangle mesh (manifold3d): the blank minus the groove, or with its rib.

The groove is meshed straight from the exact walls
(:func:`camcad.geometry.barrel.barrel_walls`) as a ring: at each motion
angle φ of a grid, a cross-section polygon runs out along the upper wall
over the stations t₀ … t₁ (:func:`camcad.fit.surface.wall_station_range`:
from inside the groove's bottom cylinder to outside the barrel) and back
along the lower wall; consecutive sections are joined by quads. manifold3d
cuts it with the bottom cylinder and subtracts it from the blank (a
cylinder less the bore), all polygons with at most ``chord`` [mm] of sag. A
rib's ring (between its faces, :func:`~camcad.geometry.barrel.barrel_faces`)
is intersected with the blank and joined to the core cylinder instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import manifold3d
import numpy as np

from camcad._typing import FloatArray
from camcad.errors import ExportError
from camcad.export._triangles import TriangleMesh, stl_bytes
from camcad.fit.surface import wall_station_range
from camcad.geometry.barrel import BarrelFollower, BarrelKind, BarrelOptions, barrel_faces
from camcad.motion.program import MotionProgram

__all__ = ["BarrelMeshOptions", "barrel_mesh", "barrel_stl_bytes"]


@dataclass(frozen=True, slots=True, kw_only=True)
class BarrelMeshOptions:
    """``chord`` [mm]: the largest sag of a cylinder's polygon; ``angles``, ``stations``: the walls' grid."""

    chord: float = 0.01
    angles: int = 1440
    stations: int = 9


def _segments(radius: float, chord: float, angles: int) -> int:
    """Polygon sides so that the sag r(1 − cos(π/n)) ≤ chord, n dividing ``angles`` where it can.

    With n dividing the sections' count (and the polygon turned by half a
    section's step, :func:`barrel_mesh`) no vertical edge of a cylinder comes
    near a section of the ring: near-coincident ones leave slivers thinner
    than float32, which an STL reader welds into non-manifold edges.
    """
    need = max(16, math.ceil(math.pi / math.acos(max(1.0 - chord / radius, -1.0))))
    return next((n for n in range(need, angles + 1) if angles % n == 0), need)


def _ring(walls_upper: FloatArray, walls_lower: FloatArray) -> tuple[FloatArray, np.ndarray]:
    """Vertices and triangles of the closed ring of sections (n sections of 2m points)."""
    n, m = walls_upper.shape[:2]
    section = np.concatenate((walls_upper, walls_lower[:, ::-1]), axis=1)  # (n, 2m, 3)
    k = 2 * m
    verts = section.reshape(n * k, 3)
    i = np.arange(n)[:, None]
    j = np.arange(k)[None, :]
    a = i * k + j
    b = ((i + 1) % n) * k + j
    c = ((i + 1) % n) * k + (j + 1) % k
    d = i * k + (j + 1) % k
    tris = np.concatenate((np.stack((a, b, c), -1).reshape(-1, 3), np.stack((a, c, d), -1).reshape(-1, 3)))
    return verts, tris


def _manifold(verts: FloatArray, tris: np.ndarray) -> manifold3d.Manifold:
    mesh = manifold3d.Mesh(vert_properties=np.ascontiguousarray(verts, dtype=np.float32), tri_verts=tris)
    solid = manifold3d.Manifold(mesh)
    if solid.status() != manifold3d.Error.NoError or solid.volume() < 0.0:  # inside out: flip
        solid = manifold3d.Manifold(
            manifold3d.Mesh(
                vert_properties=np.ascontiguousarray(verts, dtype=np.float32),
                tri_verts=np.ascontiguousarray(tris[:, ::-1]),
            )
        )
    return solid


def barrel_mesh(
    program: MotionProgram,
    follower: BarrelFollower,
    options: BarrelOptions,
    mesh: BarrelMeshOptions | None = None,
    *,
    margin: float = 1.0,
) -> TriangleMesh:
    """The barrel with its groove as one watertight mesh [mm].

    Raises
    ------
    ExportError
        manifold3d reports an error or the result is not one closed solid.
    """
    mesh = mesh or BarrelMeshOptions()
    o = options
    phi = np.linspace(0.0, math.tau, mesh.angles, endpoint=False)
    phi = np.union1d(phi, np.mod([bp.phi for bp in program.breakpoints], math.tau))
    t0, t1 = wall_station_range(program, follower, options, margin)
    walls = barrel_faces(program.evaluate(phi), follower, options, np.linspace(t0, t1, mesh.stations))
    tool = _manifold(*_ring(walls.upper.point, walls.lower.point))
    if tool.volume() < 0.0 or tool.status() != manifold3d.Error.NoError:
        raise ExportError(f"the groove's ring mesh is not a solid: manifold3d reports {tool.status().name}")

    def cylinder(radius: float, z0: float, height: float) -> manifold3d.Manifold:
        sides = _segments(radius, mesh.chord, mesh.angles)
        half_step = 180.0 / mesh.angles  # [deg]: the polygon's vertices midway between the ring's sections
        return (
            manifold3d.Manifold.cylinder(height, radius, radius, sides)
            .rotate((0.0, 0.0, half_step))
            .translate((0.0, 0.0, z0))
        )

    blank = cylinder(o.barrel_radius, 0.0, o.length)
    if o.kind is BarrelKind.RIB:  # the ring is the rib: within the blank, on the core
        blank = (blank ^ tool) + cylinder(o.bottom_radius, 0.0, o.length)
    if o.bore > 0.0:
        blank = blank - cylinder(0.5 * o.bore, -1.0, o.length + 2.0)
    if o.kind is BarrelKind.RIB:
        solid = blank
    else:
        extent = 2.0 * (o.length + t1)
        groove = tool - cylinder(o.bottom_radius, -extent, 2.0 * extent + o.length)
        solid = blank - groove
    if solid.status() != manifold3d.Error.NoError or solid.is_empty():
        raise ExportError(f"the barrel's mesh failed: manifold3d reports {solid.status().name}")
    out = solid.to_mesh()
    verts = np.asarray(out.vert_properties, dtype=float)[:, :3]
    faces = np.asarray(out.tri_verts, dtype=np.int64)
    verts.flags.writeable = False
    faces.flags.writeable = False
    return TriangleMesh(vertices=verts, faces=faces)


def barrel_stl_bytes(mesh: TriangleMesh) -> bytes:
    """Binary STL of the mesh (camcad's own writer)."""
    return stl_bytes(mesh)
