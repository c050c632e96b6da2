"""``stress.vtu``: the finite-element check's mesh and fields, for ParaView or any VTK reader.

One unstructured grid of quadratic triangles (VTK_QUADRATIC_TRIANGLE, the P2
nodes of the solution) in the cam frame, z = 0, with one set of point arrays
per load case ``n`` (1, 2, … in the order of ``summary.json``'s
``fea.cases``):

- ``case<n>_displacement_mm`` (3 components, z = 0: ParaView's "Warp By Vector"),
- ``case<n>_stress_MPa`` (6 components, VTK's symmetric-tensor order XX, YY,
  ZZ, XY, YZ, XZ; σ_zz = 0 in plane stress, ν(σ_xx + σ_yy) in plane strain),
- ``case<n>_von_mises_MPa``,
- ``case<n>_principal_stress_MPa`` (σ1 ≥ σ2 ≥ σ3).

``summary.json`` names each case (its label, cam angle, loads and peak). Nodal
stresses are the averages of the elements meeting at the node. Written by
meshio in its default binary form through :func:`camcad.export.atomic.atomic_write`;
the same result gives the same bytes.
"""

from __future__ import annotations

import os
from pathlib import Path

import meshio
import numpy as np

from camcad.export.atomic import atomic_write
from camcad.fea.results import FeaResult

__all__ = ["stress_mesh", "write_stress_vtu"]


def stress_mesh(result: FeaResult) -> meshio.Mesh:
    """The meshio mesh of :func:`write_stress_vtu` (points, quadratic triangles, the arrays)."""
    points = np.column_stack((result.nodes, np.zeros(len(result.nodes))))
    data: dict[str, np.ndarray] = {}
    for i, sc in enumerate(result.cases, start=1):
        u = sc.field.displacement
        sx, sy, txy, sz = sc.field.stress.T
        zero = np.zeros(len(u))
        data[f"case{i}_displacement_mm"] = np.column_stack((u, zero))
        data[f"case{i}_stress_MPa"] = np.column_stack((sx, sy, sz, txy, zero, zero))
        data[f"case{i}_von_mises_MPa"] = np.ascontiguousarray(sc.von_mises)
        data[f"case{i}_principal_stress_MPa"] = np.ascontiguousarray(sc.principal)
    return meshio.Mesh(
        points, [meshio.CellBlock("triangle6", np.asarray(result.cells, dtype=np.int64))], point_data=data
    )


def write_stress_vtu(path: str | os.PathLike[str], result: FeaResult) -> Path:
    """Write ``stress.vtu`` (see the module docstring) atomically; return the path."""
    mesh = stress_mesh(result)
    return atomic_write(path, lambda tmp: meshio.write(tmp, mesh, file_format="vtu"))
