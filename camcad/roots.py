"""A bracketed scalar root by Brent's method, without importing SciPy.

Hand-written because ``scipy.optimize`` costs about 0.3 s to import (it
pulls in ``scipy.sparse``, ``scipy.special``, ``scipy.linalg``), far more
than the few dozen function calls of the roots camcad needs per build: the
crossovers of a positive-drive cam and the ends of a broken limit's range.
The algorithm is Brent's ``zero`` (Brent 1973, *Algorithms for Minimization
without Derivatives*, ch. 4, §4.6), the one behind ``scipy.optimize.brentq``:
inverse quadratic interpolation or the secant step when they stay inside the
bracket and shrink it fast enough, bisection otherwise, so it never takes
more than about (log₂((b − a)/xtol))² evaluations.
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["brent_root"]

_EPS = 2.220446049250313e-16  # machine epsilon of float64


def brent_root(
    f: Callable[[float], float], a: float, b: float, *, xtol: float = 1e-12, max_iter: int = 200
) -> float:
    """A root of ``f`` in [a, b], where f(a) and f(b) differ in sign, to within ``xtol`` (+ 4ε|x|).

    Raises
    ------
    ValueError
        When f(a) and f(b) have the same sign (no bracket), or Brent's
        method does not converge in ``max_iter`` steps.
    """
    fa, fb = f(a), f(b)
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if (fa > 0.0) == (fb > 0.0):
        raise ValueError(f"f({a!r}) = {fa!r} and f({b!r}) = {fb!r} do not bracket a root")
    c, fc = a, fa
    d = e = b - a
    for _ in range(max_iter):
        if (fb > 0.0 and fc > 0.0) or (fb < 0.0 and fc < 0.0):  # keep the root between b and c
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):  # b is the best estimate so far
            a, b, c = b, c, b
            fa, fb, fc = fb, fc, fb
        tol = 2.0 * _EPS * abs(b) + 0.5 * xtol  # Brent 1973, §4.6
        m = 0.5 * (c - b)
        if abs(m) <= tol or fb == 0.0:
            return b
        if abs(e) < tol or abs(fa) <= abs(fb):
            d = e = m  # bisection
        else:
            s = fb / fa
            if a == c:  # secant
                p, q = 2.0 * m * s, 1.0 - s
            else:  # inverse quadratic interpolation
                q, r = fa / fc, fb / fc
                p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0))
                q = (q - 1.0) * (r - 1.0) * (s - 1.0)
            if p > 0.0:
                q = -q
            p = abs(p)
            if 2.0 * p < min(3.0 * m * q - abs(tol * q), abs(e * q)):
                e, d = d, p / q  # accept the interpolation
            else:
                d = e = m  # it falls outside or shrinks too slowly: bisect
        a, fa = b, fb
        b += d if abs(d) > tol else (tol if m > 0.0 else -tol)
        fb = f(b)
    raise ValueError(f"Brent's method did not converge in {max_iter} steps")  # pragma: no cover
