"""Linear elasticity of a plane plate with quadratic triangles (scikit-fem).

Why scikit-fem: small (pure Python on numpy/scipy, which camcad already
needs), BSD-licensed, with vector P2 elements, facet integrals for tractions
and supports, and assembly into scipy sparse matrices that
:func:`scipy.sparse.linalg.splu` factors once for several load cases.

Supports are elastic (a penalty): a layer of stiffness k [MPa/mm] on the
tagged edges, either in the edge's normal direction only (a frictionless
pin: the bore on the shaft, a keyway flank on the key) or in both directions
(a bonded edge). Its forces are the reactions; their resultant and moment
balance the applied load exactly, since rigid motions lie in the kernel of
the elastic stiffness.

Units: mm, N per mm of thickness, MPa.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.fea.mesh import IntArray, PlateMesh
from camcad.fea.spec import PlaneModel

__all__ = ["ElasticPlate", "Field", "Material", "Support", "principal_stresses", "stress_at", "von_mises"]

_INVERSE_TOL = 1e-8  # reference-coordinate tolerance of the facets' inverse map (see _facet_basis)

Traction = Callable[[FloatArray, FloatArray], FloatArray]
"""Traction on the plate [MPa]: (points (2, ...), outward normals (2, ...)) → (2, ...)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class Material:
    """An isotropic plate material: E [MPa], ν, and the 2-D hypothesis (STRESS or STRAIN)."""

    modulus: float
    poisson: float
    plane: PlaneModel

    def lame(self) -> tuple[float, float]:
        """(λ, μ) [MPa] of the 2-D constitutive law; plane stress uses λ* = 2λμ/(λ + 2μ)."""
        e, nu = self.modulus, self.poisson
        lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
        mu = e / (2.0 * (1.0 + nu))
        if self.plane is PlaneModel.STRESS:
            lam = 2.0 * lam * mu / (lam + 2.0 * mu)  # Timoshenko & Goodier 1970, §16
        return lam, mu


@dataclass(frozen=True, slots=True, kw_only=True)
class Support:
    """An elastic support on the edges tagged ``tags``: ``normal`` only, or ``fixed`` (both directions).

    ``stiffness`` k [MPa/mm]: the support pushes back with k·u [MPa] (a
    layer of modulus E and thickness E/k).
    """

    tags: tuple[int, ...]
    stiffness: float
    normal_only: bool = True


@dataclass(frozen=True, slots=True, kw_only=True)
class Field:
    """The solution of one load case on the P2 nodes (vertices, then edge midpoints).

    Attributes
    ----------
    displacement
        (N2, 2) [mm].
    stress
        (N2, 4) σ_xx, σ_yy, τ_xy, σ_zz [MPa], averaged over the elements at each node.
    element_stress
        (M, 6, 4) the same at each triangle's six nodes, unaveraged: with the
        displacement quadratic the stress is linear in a straight-sided
        triangle, so this is the whole FE field (:func:`stress_at`).
    applied, reaction
        (3,) resultant force x, y [N/mm] and moment about the origin [N·mm/mm]
        of the applied tractions and of the supports.
    """

    displacement: FloatArray
    stress: FloatArray
    element_stress: FloatArray
    applied: FloatArray
    reaction: FloatArray

    @property
    def von_mises(self) -> FloatArray:
        """(N2,) von Mises stress at the nodes [MPa] (from the averaged stress)."""
        return von_mises(self.stress)


def von_mises(stress: FloatArray) -> FloatArray:
    """Von Mises stress [MPa] of (..., 4) σ_xx, σ_yy, τ_xy, σ_zz: √(½Σ(σᵢ − σⱼ)² + 3τ²)."""
    sx, sy, txy, sz = np.moveaxis(np.asarray(stress, dtype=float), -1, 0)
    out: FloatArray = np.sqrt(0.5 * ((sx - sy) ** 2 + (sy - sz) ** 2 + (sz - sx) ** 2) + 3.0 * txy**2)
    return out


def principal_stresses(stress: FloatArray) -> FloatArray:
    """(..., 3) principal stresses σ1 ≥ σ2 ≥ σ3 [MPa] of (..., 4) σ_xx, σ_yy, τ_xy, σ_zz."""
    sx, sy, txy, sz = np.moveaxis(np.asarray(stress, dtype=float), -1, 0)
    centre, radius = 0.5 * (sx + sy), np.hypot(0.5 * (sx - sy), txy)
    out: FloatArray = -np.sort(-np.stack((centre + radius, centre - radius, sz), axis=-1), axis=-1)
    return out


class ElasticPlate:
    """The assembled elastic plate on one mesh: stiffness once, then any supports and loads.

    Parameters
    ----------
    mesh
        The triangle mesh with its tagged boundary edges.
    material
        E, ν and plane stress or strain.
    """

    def __init__(self, mesh: PlateMesh, material: Material) -> None:
        from skfem import Basis, ElementTriP2, ElementVector, MeshTri, MeshTri2, asm
        from skfem.models.elasticity import linear_elasticity

        self.mesh = mesh
        self.material = material
        linear = MeshTri(np.ascontiguousarray(mesh.points.T), np.ascontiguousarray(mesh.triangles.T))
        # skfem facet index of each boundary edge
        facets = linear.facets
        key = {(int(a), int(b)): i for i, (a, b) in enumerate(zip(facets[0], facets[1], strict=True))}
        lo, hi = (
            np.minimum(mesh.edges[:, 0], mesh.edges[:, 1]),
            np.maximum(mesh.edges[:, 0], mesh.edges[:, 1]),
        )
        self.edge_facets: IntArray = np.array([key[(int(a), int(b))] for a, b in zip(lo, hi, strict=True)])
        # quadratic geometry: the boundary edges' middle nodes on the exact curves (isoparametric P2)
        curved = MeshTri2.from_mesh(linear)
        doflocs = np.array(curved.doflocs)
        doflocs[:, linear.p.shape[1] + self.edge_facets] = mesh.edge_midpoints.T
        self._skmesh = MeshTri2(doflocs, curved.t)
        self._element = ElementVector(ElementTriP2())
        self._basis = Basis(self._skmesh, self._element, intorder=4)
        lam, mu = material.lame()
        self._lam, self._mu = lam, mu
        self._stiffness = asm(linear_elasticity(lam, mu), self._basis).tocsr()
        scalar = Basis(self._skmesh, ElementTriP2())
        self.nodes: FloatArray = np.ascontiguousarray(doflocs.T)  # (N2, 2) P2 nodes: vertices, then edges
        self.cells: IntArray = np.ascontiguousarray(scalar.element_dofs.T).astype(np.int64)  # (M, 6)
        self._doflocs = self._basis.doflocs
        self._x_dofs = np.concatenate((self._basis.nodal_dofs[0], self._basis.facet_dofs[0]))
        self._y_dofs = np.concatenate((self._basis.nodal_dofs[1], self._basis.facet_dofs[1]))
        self._factors: dict[tuple[Support, ...], Any] = {}
        self._mapping = self._skmesh._mapping()
        exact_inverse = self._mapping.invF

        def inverse(x: Any, tind: Any = None) -> Any:
            # skfem inverts the quadratic map by Newton to 1e-12 in reference coordinates; an
            # element of a few µm at 100 mm from the origin carries ~1e-11 of round-off there
            return exact_inverse(x, tind=tind, newton_tol=_INVERSE_TOL)

        self._mapping.invF = inverse

    def area(self) -> float:
        """The meshed area [mm²], on the curved (isoparametric) elements."""
        from skfem import Functional, asm

        return float(asm(Functional(lambda w: 1.0 + 0.0 * w.x[0]), self._basis))

    def _facet_basis(self, edges: IntArray, intorder: int) -> Any:
        from skfem import FacetBasis

        return FacetBasis(
            self._skmesh,
            self._element,
            mapping=self._mapping,
            facets=self.edge_facets[edges],
            intorder=intorder,
        )

    def _support_matrix(self, supports: Sequence[Support]) -> Any:
        from skfem import BilinearForm, asm
        from skfem.helpers import dot

        total = None
        for sup in supports:
            edges = np.flatnonzero(np.isin(self.mesh.edge_tags, sup.tags))
            if edges.size == 0:
                continue
            fb = self._facet_basis(edges, 4)
            k = sup.stiffness
            if sup.normal_only:

                @BilinearForm
                def form(u: Any, v: Any, w: Any, k: float = k) -> Any:
                    return k * dot(u, w.n) * dot(v, w.n)
            else:

                @BilinearForm
                def form(u: Any, v: Any, w: Any, k: float = k) -> Any:
                    return k * dot(u, v)

            part = asm(form, fb)
            total = part if total is None else total + part
        if total is None:
            raise ValueError("no support: the plate is free to move")
        return total.tocsr()

    def load(self, edges: IntArray, traction: Traction, *, intorder: int = 12) -> FloatArray:
        """The consistent load vector of a traction on some boundary edges (indices into ``mesh.edges``)."""
        from skfem import LinearForm, asm
        from skfem.helpers import dot

        fb = self._facet_basis(np.asarray(edges, dtype=np.int64), intorder)

        @LinearForm
        def form(v: Any, w: Any) -> Any:
            return dot(traction(np.asarray(w.x), np.asarray(w.n)), v)

        out: FloatArray = np.asarray(asm(form, fb), dtype=float)
        return out

    def resultant(self, vector: FloatArray) -> FloatArray:
        """(3,) force x, y and moment about the origin of a nodal force vector (P2 reproduces x and y)."""
        fx, fy = vector[self._x_dofs], vector[self._y_dofs]
        x, y = self._doflocs[0, self._x_dofs], self._doflocs[1, self._x_dofs]
        return np.array([fx.sum(), fy.sum(), float(np.sum(x * fy - y * fx))])

    def solve(self, supports: Sequence[Support], load: FloatArray) -> Field:
        """Displacement and stress under ``load`` (from :meth:`load`) with the given supports."""
        from scipy.sparse.linalg import splu

        key = tuple(supports)
        if key not in self._factors:
            support = self._support_matrix(supports)
            self._factors[key] = (splu((self._stiffness + support).tocsc()), support)
        factor, support = self._factors[key]
        u = np.asarray(factor.solve(np.asarray(load, dtype=float)), dtype=float)
        reaction = self.resultant(-(support @ u))
        applied = self.resultant(load)
        return self._field(u, applied, reaction)

    def _field(self, u: FloatArray, applied: FloatArray, reaction: FloatArray) -> Field:
        from skfem import Basis, ElementTriP2

        ref = np.asarray(ElementTriP2.doflocs, dtype=float).T  # (2, 6): corners, then edge middles
        at_nodes = Basis(self._skmesh, self._element, quadrature=(ref, np.ones(6) / 12.0))
        grad = np.asarray(at_nodes.interpolate(u).grad)  # (2, 2, M, 6): ∂u_i/∂x_j
        exx, eyy = grad[0, 0], grad[1, 1]
        exy = 0.5 * (grad[0, 1] + grad[1, 0])
        lam, mu = self._lam, self._mu
        sx = lam * (exx + eyy) + 2.0 * mu * exx
        sy = lam * (exx + eyy) + 2.0 * mu * eyy
        txy = 2.0 * mu * exy
        if self.material.plane is PlaneModel.STRAIN:
            sz = self.material.poisson * (sx + sy)  # ε_zz = 0
        else:
            sz = np.zeros_like(sx)
        element_stress = np.stack((sx, sy, txy, sz), axis=-1)  # (M, 6, 4) in skfem's P2 node order
        total = np.zeros((len(self.nodes), 4))
        count = np.zeros(len(self.nodes))
        np.add.at(total, self.cells.ravel(), element_stress.reshape(-1, 4))
        np.add.at(count, self.cells.ravel(), 1.0)
        stress = total / count[:, None]
        disp_x = np.concatenate((u[self._basis.nodal_dofs[0]], u[self._basis.facet_dofs[0]]))
        disp_y = np.concatenate((u[self._basis.nodal_dofs[1]], u[self._basis.facet_dofs[1]]))
        displacement = np.column_stack((disp_x, disp_y))
        readonly(displacement, stress, element_stress, applied, reaction)
        return Field(
            displacement=displacement,
            stress=stress,
            element_stress=element_stress,
            applied=applied,
            reaction=reaction,
        )


def stress_at(
    nodes: FloatArray, cells: IntArray, element_stress: FloatArray, points: FloatArray
) -> FloatArray:
    """(n, 4) the FE stress at points (n, 2) inside the mesh [MPa].

    Parameters
    ----------
    nodes, cells
        (N2, 2) P2 nodes and (M, 6) triangles (corners first, as :class:`ElasticPlate`).
    element_stress
        (M, 6, 4) each triangle's stress at its six nodes (:attr:`Field.element_stress`).
    points
        (n, 2) where [mm].

    Notes
    -----
    The triangle holding each point is found on the straight-sided mesh and
    the stress interpolated from its six nodes with the quadratic shape
    functions; curved boundary triangles bulge by h²/8ρ, far below their size.
    """
    from skfem import MeshTri

    xy = np.atleast_2d(np.asarray(points, dtype=float))
    corners_ids = np.ascontiguousarray(cells[:, :3])
    vertices = int(corners_ids.max()) + 1
    linear = MeshTri(np.ascontiguousarray(nodes[:vertices].T), np.ascontiguousarray(corners_ids.T))
    elements = linear.element_finder()(xy[:, 0], xy[:, 1])
    corners = nodes[corners_ids[elements]]  # (n, 3, 2), in the cells' own order
    v0, v1, v2 = corners[:, 0], corners[:, 1], corners[:, 2]
    det = (v1[:, 0] - v0[:, 0]) * (v2[:, 1] - v0[:, 1]) - (v1[:, 1] - v0[:, 1]) * (v2[:, 0] - v0[:, 0])
    d = xy - v0
    s = (d[:, 0] * (v2[:, 1] - v0[:, 1]) - d[:, 1] * (v2[:, 0] - v0[:, 0])) / det
    t = ((v1[:, 0] - v0[:, 0]) * d[:, 1] - (v1[:, 1] - v0[:, 1]) * d[:, 0]) / det
    r = 1.0 - s - t
    shape = np.column_stack(
        (r * (2 * r - 1), s * (2 * s - 1), t * (2 * t - 1), 4 * r * s, 4 * s * t, 4 * r * t)
    )  # P2 on the reference triangle, skfem's node order (corners 0, 1, 2; edges 01, 12, 02)
    out: FloatArray = np.einsum("nk,nkc->nc", shape, element_stress[elements])
    return out
