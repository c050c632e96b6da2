"""The B-spline curve value type shared by the fit and the exporters, and its evaluation.

The evaluation is hand-written (vectorised Cox–de Boor, Piegl & Tiller 1997,
Alg. A2.1–A2.2 and §3.3) rather than :class:`scipy.interpolate.BSpline`:
importing ``scipy.interpolate`` pulls in ``scipy.special``, ``scipy.optimize``
and ``scipy.sparse`` and costs about 0.3 s, more than a whole profile fit, in
every process that only needs points of a curve (``camcad check``, a build).
On the few hundred to few thousand parameters of a call it is as fast.

References
----------
.. [1] Piegl & Tiller (1997), The NURBS Book, 2nd ed., Springer.
   doi:10.1007/978-3-642-59223-2
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from camcad._typing import FloatArray

__all__ = [
    "BSplineCurve",
    "IntArray",
    "basis_stages",
    "curve_derivatives",
    "derivative_control_points",
    "derivatives_at",
    "find_span",
]

IntArray = NDArray[np.intp]


@dataclass(frozen=True, slots=True, kw_only=True)
class BSplineCurve:
    """A non-rational B-spline plane curve (all weights 1).

    Attributes
    ----------
    degree
        Polynomial degree p (3 for the cam profile).
    knots
        (m + p + 1,) full knot vector. For ``periodic=False`` the ends are
        clamped (p + 1 equal knots); for ``periodic=True`` it is the extended
        knot vector of a periodic spline over ``[knots[p], knots[-p-1]]``.
    control_points
        (m, 2) control points [mm]. For a periodic curve the last p points
        repeat the first p; for a closed clamped curve the last point equals
        the first.
    periodic
        Whether the curve is the periodic form (C^{p-1} across the seam).
    """

    degree: int
    knots: FloatArray
    control_points: FloatArray
    periodic: bool = False

    @property
    def domain(self) -> tuple[float, float]:
        """Parameter interval ``(u_start, u_end)`` of the curve."""
        p = self.degree
        return float(self.knots[p]), float(self.knots[-p - 1])

    def evaluate(self, u: FloatArray, der: int = 0) -> FloatArray:
        """Points (or the ``der``-th derivative) at parameters ``u``; (n, 2) [mm].

        Periodic curves wrap ``u`` into the domain; clamped ones clip it.
        """
        u = np.asarray(u, dtype=float)
        if der > self.degree:
            return np.zeros((*u.shape, self.control_points.shape[1]))
        flat = u.reshape(-1)
        values: FloatArray = curve_derivatives(self, flat, der)[der]
        return values.reshape(*u.shape, self.control_points.shape[1])


def find_span(knots: FloatArray, degree: int, n_ctrl: int, u: FloatArray) -> IntArray:
    """Knot-span index i with ``knots[i] <= u < knots[i+1]`` (vectorised).

    ``u`` at the domain end maps to the last non-empty span
    (Piegl & Tiller 1997, Alg. A2.1).
    """
    span = np.searchsorted(knots, u, side="right") - 1
    return np.clip(span, degree, n_ctrl - 1)  # Piegl & Tiller 1997, Alg. A2.1


def basis_stages(
    knots: FloatArray, degree: int, u: FloatArray, span: IntArray, lowest: int = 0
) -> list[FloatArray]:
    """Non-zero B-spline basis functions of degrees ``lowest … degree``.

    Parameters
    ----------
    knots
        Full knot vector.
    degree
        Degree p.
    u
        (n,) parameters.
    span
        (n,) span indices from :func:`find_span`.
    lowest
        Lowest degree to return (``degree - d`` gives what the d-th
        derivative needs).

    Returns
    -------
    list of FloatArray
        Item ``j`` is (q + 1, n) for q = lowest + j: row r holds
        N_{span-q+r, q}(u) (rows, not columns, so each is contiguous).

    Notes
    -----
    The triangular Cox–de Boor scheme of Piegl & Tiller (1997, Alg. A2.2),
    vectorised over u; each intermediate degree is kept, so derivatives come
    from the same pass (see :func:`curve_derivatives`).
    """
    n = len(u)
    left = np.zeros((degree + 1, n))
    right = np.zeros((degree + 1, n))
    vals = np.zeros((degree + 1, n))
    vals[0] = 1.0
    stages = [vals[:1].copy()] if lowest == 0 else []
    for j in range(1, degree + 1):
        left[j] = u - np.take(knots, span + 1 - j)
        right[j] = np.take(knots, span + j) - u
        saved = np.zeros(n)
        for r in range(j):
            temp = vals[r] / (right[r + 1] + left[j - r])  # Piegl & Tiller 1997, Alg. A2.2
            vals[r] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        vals[j] = saved
        if j >= lowest:
            stages.append(vals[: j + 1].copy())
    return stages


def derivative_control_points(
    knots: FloatArray, degree: int, ctrl: FloatArray, order: int
) -> list[FloatArray]:
    """Control points of the derivative curves, indexed like the original ones.

    Item k is (m, dim): Q^(k)_i for i = k … m-1 (rows below k are zero), so
    C^(k)(u) = Σ_i N_{i, p-k}(u) Q^(k)_i on the original knot vector
    (Piegl & Tiller 1997, §3.3, Alg. A3.3).
    """
    out = [np.asarray(ctrl, dtype=float)]
    m = len(ctrl)
    for k in range(1, order + 1):
        prev = out[-1]
        q = np.zeros_like(prev)
        i = np.arange(k, m)
        du = knots[i + degree - k + 1] - knots[i]
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.where(du > 0, (degree - k + 1) / du, 0.0)  # Piegl & Tiller 1997, §3.3
        q[k:] = scale[:, None] * (prev[k:] - prev[k - 1 : -1])
        out.append(q)
    return out


def _combine(basis: FloatArray, first: IntArray, ctrl: FloatArray) -> FloatArray:
    """Σ_r basis[r] · ctrl[first + r]: (n, dim) points from (q+1, n) basis values.

    Coordinates are gathered one at a time with ``np.take`` (row fancy
    indexing of an (m, 2) array is several times slower).
    """
    out = np.zeros((len(first), ctrl.shape[1]))
    for d in range(ctrl.shape[1]):
        col = np.ascontiguousarray(ctrl[:, d])
        for r in range(basis.shape[0]):
            out[:, d] += basis[r] * np.take(col, first + r)
    return out


def derivatives_at(
    knots: FloatArray, degree: int, ctrl: FloatArray, span: IntArray, stages: list[FloatArray], order: int
) -> FloatArray:
    """C … C^(order) at the parameters behind ``span``/``stages`` (lowest stage p − order)."""
    dctrl = derivative_control_points(knots, degree, ctrl, order)
    out = np.zeros((order + 1, len(span), ctrl.shape[1]))
    for k in range(order + 1):
        q = degree - k
        out[k] = _combine(stages[-1 - k], span - q, dctrl[k])  # degree p − k basis
    return out


def curve_derivatives(curve: BSplineCurve, u: FloatArray, order: int = 0) -> FloatArray:
    """Points and derivatives of a B-spline curve at parameters ``u``.

    Parameters
    ----------
    curve
        The curve; periodic curves wrap ``u`` into the domain, clamped ones
        clip it.
    u
        (n,) parameters.
    order
        Highest derivative wanted (at most ``degree``).

    Returns
    -------
    FloatArray
        (order + 1, n, 2): C, C', …, C^(order) [mm, mm/unit u, …].
    """
    p = curve.degree
    knots = curve.knots
    ctrl = curve.control_points
    a, b = curve.domain
    u = np.asarray(u, dtype=float)
    u = a + np.mod(u - a, b - a) if curve.periodic else np.clip(u, a, b)
    span = find_span(knots, p, len(ctrl), u)
    order = min(order, p)
    stages = basis_stages(knots, p, u, span, lowest=p - order)
    return derivatives_at(knots, p, ctrl, span, stages, order)
