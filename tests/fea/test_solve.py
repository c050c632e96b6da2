"""The mesher and the elastic solver against Lamé's thick ring (a closed form), with mesh convergence.

Independent truth: a ring a ≤ r ≤ b held at its bore (u = 0 at r = a) under
an outer pressure q has u = A·r + B/r with B = −A·a² and
σ_r(b) = 2(λ+μ)A − 2μB/b² = −q (Timoshenko & Goodier 1970, §28: Lamé's
problem; plane stress with λ* = 2λμ/(λ+2μ)). The hoop stress at the bore is
σ_θ(a) = 2(λ+μ)A + 2μB/a². The element is quadratic, so the stress error
must fall as h² (a halving of the element size divides it by about 4).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from camcad.fea.mesh import Loop, Piece, Spot, element_size, mesh_region
from camcad.fea.solve import ElasticPlate, Material, Support, principal_stresses, von_mises
from camcad.fea.spec import PlaneModel

pytest.importorskip("gmsh")
pytest.importorskip("skfem")

A_IN, B_OUT, Q = 10.0, 20.0, 100.0  # mm, mm, MPa
E, NU = 200000.0, 0.3
BORE, OUTER = 2, 1


def _circle(r: float):
    return lambda t: np.column_stack((r * np.cos(t), r * np.sin(t)))


def _ring(h: float):
    outer = Loop(pieces=(Piece(curve=_circle(B_OUT), start=0.0, stop=2 * math.pi, tag=OUTER),))
    inner = Loop(pieces=(Piece(curve=_circle(A_IN), start=0.0, stop=2 * math.pi, tag=BORE),))
    return mesh_region(outer, [inner], [], h_max=h, growth=0.3)


def _lame(material: Material) -> tuple[float, float]:
    """A and B of u = A r + B/r for the ring held at r = a, pressed by q at r = b."""
    lam, mu = material.lame()
    a_coef = -Q / (2.0 * (lam + mu) + 2.0 * mu * A_IN**2 / B_OUT**2)
    return a_coef, -a_coef * A_IN**2


def _solve(h: float, plane: PlaneModel):
    mesh = _ring(h)
    material = Material(modulus=E, poisson=NU, plane=plane)
    plate = ElasticPlate(mesh, material)
    load = plate.load(np.flatnonzero(mesh.edge_tags == OUTER), lambda x, n: -Q * n)
    field = plate.solve([Support(tags=(BORE,), stiffness=E / (1e-7 * A_IN), normal_only=False)], load)
    return mesh, plate, material, field


def _hoop_error(plate: ElasticPlate, material: Material, field) -> float:
    """Relative error of the peak hoop stress over every element's nodes.

    σ_θ(r) = 2(λ+μ)A + 2μB/r² with B = −Aa² is compressive and largest in size at r = b.
    """
    lam, mu = material.lame()
    a_coef, b_coef = _lame(material)
    xy = plate.nodes[plate.cells]
    r = np.hypot(xy[..., 0], xy[..., 1])
    c, s = xy[..., 0] / r, xy[..., 1] / r
    sx, sy, txy, _ = np.moveaxis(field.element_stress, -1, 0)
    hoop = sx * s * s + sy * c * c - 2.0 * txy * s * c
    exact = 2.0 * (lam + mu) * a_coef + 2.0 * mu * b_coef / B_OUT**2
    return abs(float(hoop.min()) - exact) / abs(exact)


@pytest.mark.parametrize(
    "plane", [PlaneModel.STRESS, PlaneModel.STRAIN], ids=["plane-stress", "plane-strain"]
)
def test_lame_ring_converges_at_the_quadratic_rate(plane: PlaneModel):
    errors = []
    for h in (3.0, 1.5, 0.75):
        _, plate, material, field = _solve(h, plane)
        errors.append(_hoop_error(plate, material, field))
    assert errors[-1] < 1e-3
    rates = [math.log2(e0 / e1) for e0, e1 in itertools.pairwise(errors)]
    assert min(rates) > 1.6, (errors, rates)  # P2: error ∝ h²


def test_lame_ring_displacement_and_stress_field():
    _, plate, material, field = _solve(1.5, PlaneModel.STRAIN)
    a_coef, b_coef = _lame(material)
    r = np.hypot(*plate.nodes.T)
    radial = np.sum(field.displacement * plate.nodes, axis=1) / r
    exact = a_coef * r + b_coef / r
    np.testing.assert_allclose(radial, exact, atol=2e-4 * abs(a_coef * B_OUT + b_coef / B_OUT))
    tangential = (
        field.displacement[:, 1] * plate.nodes[:, 0] - field.displacement[:, 0] * plate.nodes[:, 1]
    ) / r
    np.testing.assert_allclose(tangential, 0.0, atol=1e-3 * abs(a_coef * B_OUT))
    # plane strain: σ_zz = ν(σ_r + σ_θ) = 2ν(λ+μ)·2A … checked through the invariants at mid-radius
    lam, mu = material.lame()
    mid = np.array([[15.0 * math.cos(0.3), 15.0 * math.sin(0.3)]])
    sx, sy, _, sz = plate_stress = field_stress_at(plate, field, mid)[0]
    sr = 2 * (lam + mu) * a_coef - 2 * mu * b_coef / 15.0**2
    st = 2 * (lam + mu) * a_coef + 2 * mu * b_coef / 15.0**2
    np.testing.assert_allclose(sx + sy, sr + st, rtol=2e-3)
    np.testing.assert_allclose(sz, NU * (sr + st), rtol=2e-3)
    np.testing.assert_allclose(
        von_mises(plate_stress), von_mises(np.array([sr, st, 0.0, NU * (sr + st)])), rtol=3e-3
    )
    np.testing.assert_allclose(
        principal_stresses(plate_stress), sorted([sr, st, NU * (sr + st)], reverse=True), rtol=3e-3
    )


def field_stress_at(plate: ElasticPlate, field, points: np.ndarray) -> np.ndarray:
    from camcad.fea.solve import stress_at

    return stress_at(plate.nodes, plate.cells, field.element_stress, points)


def test_supports_balance_the_load():
    """The reactions' resultant and moment equal and oppose the applied load (rigid motions are free)."""
    mesh = _ring(2.0)
    material = Material(modulus=E, poisson=NU, plane=PlaneModel.STRESS)
    plate = ElasticPlate(mesh, material)
    edges = np.flatnonzero(mesh.edge_tags == OUTER)

    def lopsided(x: np.ndarray, n: np.ndarray) -> np.ndarray:  # a uniform pull (30, 5) MPa and a shear 7 MPa
        return np.stack((30.0 - 7.0 * x[1] / B_OUT + 0.0 * n[0], 5.0 + 7.0 * x[0] / B_OUT))

    load = plate.load(edges, lopsided)
    field = plate.solve([Support(tags=(BORE,), stiffness=E / (1e-5 * A_IN), normal_only=False)], load)
    np.testing.assert_allclose(
        field.reaction, -field.applied, rtol=1e-9, atol=1e-9 * np.abs(field.applied).max()
    )
    # the applied load against the traction's integral over the circle, in closed form:
    # ∫ (30, 5) ds = 2πb·(30, 5); the shear 7 MPa along the tangent has moment 7·b·2πb
    ring = 2.0 * math.pi * B_OUT
    np.testing.assert_allclose(field.applied, [30.0 * ring, 5.0 * ring, 7.0 * B_OUT * ring], rtol=1e-6)


def test_boundary_nodes_are_exact_and_sizes_follow_the_spots():
    spot = Spot(centre=(B_OUT, 0.0), size=0.05, radius=0.1)
    outer = Loop(pieces=(Piece(curve=_circle(B_OUT), start=-math.pi, stop=math.pi, tag=OUTER, fixed=(0.0,)),))
    inner = Loop(pieces=(Piece(curve=_circle(A_IN), start=0.0, stop=2 * math.pi, tag=BORE),))
    mesh = mesh_region(outer, [inner], [spot], h_max=3.0, growth=0.3)
    ends = mesh.points[mesh.edges]
    radius = np.hypot(ends[..., 0], ends[..., 1])
    expected = np.where(mesh.edge_tags == OUTER, B_OUT, A_IN)[:, None]
    np.testing.assert_allclose(radius, np.broadcast_to(expected, radius.shape), rtol=1e-13)
    np.testing.assert_allclose(np.hypot(*mesh.edge_midpoints.T), expected[:, 0], rtol=1e-13)
    assert np.any(np.all(np.isclose(mesh.points, [B_OUT, 0.0], atol=1e-12), axis=1))  # the fixed node
    length = np.hypot(*(ends[:, 1] - ends[:, 0]).T)
    target = element_size(0.5 * (ends[:, 0] + ends[:, 1]), [spot], h_max=3.0, growth=0.3)
    assert np.all(length < 1.6 * target) and np.all(length > 0.4 * target)
    # the area of the curved (isoparametric) mesh is the ring's
    material = Material(modulus=E, poisson=NU, plane=PlaneModel.STRESS)
    plate = ElasticPlate(mesh, material)
    assert plate.area() == pytest.approx(math.pi * (B_OUT**2 - A_IN**2), rel=2e-5)


@pytest.mark.parametrize("h", [4.0, 2.0, 1.0])
def test_the_element_estimate_is_within_a_fifth_of_gmsh_on_a_ring(h):
    """estimated_triangles (area / (√3/4 h²)) against the count gmsh makes on the ring, no refinement."""
    from camcad.fea.mesh import estimated_triangles

    made = len(_ring(h).triangles)
    estimate = estimated_triangles(math.pi * (B_OUT**2 - A_IN**2), h)
    assert 0.8 * made <= estimate <= 1.2 * made, (made, estimate)
