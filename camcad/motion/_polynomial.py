"""Polynomial laws: 3-4-5, 4-5-6-7 and Dudley's odd-degree family (Hren et al., eqs. 1-12)."""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from fractions import Fraction
from functools import cache
from itertools import pairwise
from typing import ClassVar

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.errors import DesignError
from camcad.motion._lawbase import DUDLEY_MAX_DEGREE, Derivatives, Law, _as_x, _finish, _show

__all__ = ["Dudley", "Poly345", "Poly4567", "dudley_coefficients", "dudley_matrix"]


# ------------------------------------------------------------------ polynomials


@dataclass(frozen=True, slots=True, kw_only=True)
class Poly345(Law):
    """3-4-5 polynomial, y = 10x³ − 15x⁴ + 6x⁵ (Dudley n = 5).

    Notes
    -----
    y′ = 30x²(1 − x)², y″ = 60x(1 − x)(1 − 2x), y‴ = 60(1 − 6x + 6x²).
    Peak y′ = 15/8; y‴ = 60 at the ends.

    Examples
    --------
    At mid-rise x = 1/2: y = 10/8 − 15/16 + 6/32 = 1/2, y′ = 30/16 = 15/8
    (the peak), y″ = 0 and y‴ = 60(1 − 3 + 3/2) = −30.

    >>> [float(d) for d in Poly345().evaluate(0.5)]
    [0.5, 1.875, 0.0, -30.0]
    """

    name: ClassVar[str] = "poly-345"

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate the 3-4-5 polynomial (see :meth:`Law.evaluate`)."""
        xa = _as_x(x)
        w = xa * (1.0 - xa)
        y = xa**3 * (10.0 + xa * (-15.0 + 6.0 * xa))
        return _finish(xa.shape, y, 30.0 * w * w, 60.0 * w * (1.0 - 2.0 * xa), 60.0 * (1.0 - 6.0 * w))

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """y′ = y″ = 0 at the ends; y‴ = 60."""
        return (1, 2)

    def describe(self) -> str:
        """Return ``"3-4-5 polynomial"``."""
        return "3-4-5 polynomial"


@dataclass(frozen=True, slots=True, kw_only=True)
class Poly4567(Law):
    """4-5-6-7 polynomial, y = 35x⁴ − 84x⁵ + 70x⁶ − 20x⁷ (Dudley n = 7).

    Notes
    -----
    y′ = 140x³(1 − x)³, y″ = 420x²(1 − x)²(1 − 2x),
    y‴ = 840x(1 − x)(1 − 5x + 5x²). Peak y′ = 35/16.
    """

    name: ClassVar[str] = "poly-4567"

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate the 4-5-6-7 polynomial (see :meth:`Law.evaluate`)."""
        xa = _as_x(x)
        w = xa * (1.0 - xa)
        y = xa**4 * (35.0 + xa * (-84.0 + xa * (70.0 - 20.0 * xa)))
        y3 = 840.0 * w * (1.0 - 5.0 * w)
        return _finish(xa.shape, y, 140.0 * w**3, 420.0 * w * w * (1.0 - 2.0 * xa), y3)

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """y′ = y″ = y‴ = 0 at the ends."""
        return (1, 2, 3)

    def describe(self) -> str:
        """Return ``"4-5-6-7 polynomial"``."""
        return "4-5-6-7 polynomial"


def _check_degree(value: object, name: str = "degree") -> int:
    """Validate a Dudley degree: an odd int (not bool), 3 ≤ n ≤ DUDLEY_MAX_DEGREE."""
    allowed = f"allowed: an odd integer 3 ≤ {name} ≤ {DUDLEY_MAX_DEGREE}"
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise DesignError(name, f"{name} = {_show(value)} is not an integer; {allowed}")
    n = int(value)
    if n % 2 == 0:
        raise DesignError(name, f"{name} = {n} is even; {allowed}")
    if not 3 <= n <= DUDLEY_MAX_DEGREE:
        raise DesignError(name, f"{name} = {n} is out of range; {allowed}")
    return n


@cache
def _dudley_exact(n: int) -> tuple[Fraction, ...]:
    """Exact normalised coefficients c_p..c_n (φ₂ = 1, z = 1) of Dudley's law.

    Solves the p×p system A·x = b of Hren et al., eqs. 7-10 with φ₂ = 1, whose
    entries a_ef = Π_{k=1}^{e-1} (p + f − k) (eq. 8) are integers, by exact
    Gauss-Jordan elimination in rationals.
    """
    p = (n + 1) // 2  # Hren et al., eq. 6
    rows = [
        [Fraction(math.perm(p + f - 1, e - 1)) for f in range(1, p + 1)]  # eq. 8, φ₂ = 1
        + [Fraction(1 if e == 1 else 0)]  # eqs. 9-10 with z = 1
        for e in range(1, p + 1)
    ]
    for col in range(p):
        pivot = next(r for r in range(col, p) if rows[r][col] != 0)
        rows[col], rows[pivot] = rows[pivot], rows[col]
        lead = rows[col][col]
        rows[col] = [v / lead for v in rows[col]]
        for r in range(p):
            if r != col and rows[r][col] != 0:
                factor = rows[r][col]
                rows[r] = [v - factor * w for v, w in zip(rows[r], rows[col], strict=True)]
    return tuple(row[p] for row in rows)  # x_e = α_{p+e-1}, eq. 11


def _check_phi2(value: float) -> float:
    phi2 = float(value)
    if not (math.isfinite(phi2) and phi2 > 0.0):
        raise DesignError("phi2", f"phi2 = {_show(value)} must be a finite angle > 0 rad")
    return phi2


def dudley_matrix(n: int, phi2: float) -> FloatArray:
    """Build the boundary-condition matrix A of Dudley's polynomial law.

    Parameters
    ----------
    n
        Odd polynomial degree, 3 ≤ n ≤ ``DUDLEY_MAX_DEGREE``.
    phi2
        Rise angle φ₂ [rad], > 0.

    Returns
    -------
    FloatArray
        (p, p) read-only matrix, p = (n + 1)/2; row e is the (e−1)-th
        derivative at φ₂, column f the coefficient α_{p+f−1}.

    Notes
    -----
    a_ef = φ₂^(p+f−e) Π_{k=1}^{e−1} (p + f − k)  (Hren et al., eq. 8)
    """
    n = _check_degree(n, "n")
    phi2 = _check_phi2(phi2)
    p = (n + 1) // 2  # Hren et al., eq. 6
    a = np.array(
        [
            [phi2 ** (p + f - e) * math.perm(p + f - 1, e - 1) for f in range(1, p + 1)]
            for e in range(1, p + 1)
        ],
        dtype=np.float64,
    )  # Hren et al., eq. 8
    readonly(a)
    return a


def dudley_coefficients(n: int, phi2: float, z: float) -> FloatArray:
    """Coefficients α_0..α_n of Dudley's polynomial lift s(φ) = Σ α_i φ^i.

    Parameters
    ----------
    n
        Odd polynomial degree, 3 ≤ n ≤ ``DUDLEY_MAX_DEGREE``.
    phi2
        Rise angle φ₂ [rad], > 0.
    z
        Stroke [mm] (any length unit; α_i carries unit/rad^i).

    Returns
    -------
    FloatArray
        (n + 1,) read-only; α_i = 0 for i < p = (n + 1)/2.

    Notes
    -----
    Solves A·x = b (Hren et al., eqs. 7-12) with A from eq. 8, b₁ = z (eq. 9),
    b_e = 0 for e > 1 (eq. 10) and x_e = α_{p+e−1} (eq. 11). Writing
    A = diag(φ₂^(1−e)) · M · diag(φ₂^(p+f−1)) with the integer matrix M of
    φ₂ = 1 gives α_i = z c_i / φ₂^i, where M c = e₁ is solved exactly in
    rationals; this avoids the inverse of eq. 12 and its ill-conditioning.
    """
    n = _check_degree(n, "n")
    phi2 = _check_phi2(phi2)
    p = (n + 1) // 2
    alpha = np.zeros(n + 1)
    for i, c in enumerate(_dudley_exact(n), start=p):
        alpha[i] = float(z) * float(c) / phi2**i  # α_i = z c_i / φ₂^i
    readonly(alpha)
    return alpha


@cache
def _dudley_bernstein(n: int) -> tuple[tuple[tuple[int, int, float], ...], ...]:
    """Bernstein terms of y^(k), k = 0..3, for Dudley's normalised law.

    y = I_x(p, p) = Σ_{j=p}^{n} C(n, j) x^j (1 − x)^(n−j) has control values
    b_j = [j ≥ p]; y^(k) = n!/(n−k)! Σ_j Δ^k b_j C(n−k, j) x^j (1 − x)^(n−k−j).
    Each entry lists (j, n − k − j, weight) for the nonzero Δ^k b_j.
    """
    p = (n + 1) // 2
    ctrl = [0] * p + [1] * (n + 1 - p)
    orders = []
    for k in range(4):
        diff = ctrl
        for _ in range(k):
            diff = [b - a for a, b in pairwise(diff)]
        m = n - k
        scale = math.perm(n, k)
        orders.append(tuple((j, m - j, float(scale * d * math.comb(m, j))) for j, d in enumerate(diff) if d))
    return tuple(orders)


@dataclass(frozen=True, slots=True, kw_only=True)
class Dudley(Law):
    """Dudley's odd-degree polynomial law (Hren et al., eqs. 1-12), normalised.

    Attributes
    ----------
    degree
        Odd polynomial degree n, 3 ≤ n ≤ ``DUDLEY_MAX_DEGREE``.

    Notes
    -----
    y = Σ_{i=p}^{n} c_i x^i, p = (n + 1)/2 (Hren et al., eqs. 3, 6), with
    derivatives 1..p−1 zero at both ends (eqs. 2, 5). The unique solution has
    y′ = x^(p−1)(1 − x)^(p−1)/B(p, p), i.e. y is the regularised incomplete beta
    function I_x(p, p). It is evaluated in Bernstein form, a sum of positive
    terms, which stays accurate for large n where the alternating monomial
    coefficients would cancel. n = 5 is 3-4-5, n = 7 is 4-5-6-7.
    """

    name: ClassVar[str] = "dudley"
    degree: int

    def __post_init__(self) -> None:
        """Validate ``degree``."""
        object.__setattr__(self, "degree", _check_degree(self.degree))

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate Dudley's law of degree n (see :meth:`Law.evaluate`)."""
        xa = _as_x(x)
        n = self.degree
        xp = [np.ones_like(xa)]
        qp = [np.ones_like(xa)]
        q = 1.0 - xa
        for _ in range(n):
            xp.append(xp[-1] * xa)
            qp.append(qp[-1] * q)
        out = [
            sum((w * xp[j] * qp[m] for j, m, w in terms), np.zeros_like(xa)) for terms in _dudley_bernstein(n)
        ]  # Bernstein form of Hren et al., eq. 3 on x = φ/φ₂
        return _finish(xa.shape, *out)

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """Orders 1..min(3, (n−1)/2) (Hren et al., eqs. 2 and 5)."""
        return tuple(range(1, min(3, (self.degree - 1) // 2) + 1))

    def describe(self) -> str:
        """Return e.g. ``"Dudley n=9"``."""
        return f"Dudley n={self.degree}"
