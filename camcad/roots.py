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

import numpy as np

from camcad._typing import ArrayLike, FloatArray

__all__ = ["brent_root", "brent_roots"]

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


def brent_roots(
    f: Callable[[FloatArray], ArrayLike],
    a: ArrayLike,
    b: ArrayLike,
    *,
    fa: ArrayLike | None = None,
    fb: ArrayLike | None = None,
    xtol: float = 1e-12,
    max_iter: int = 200,
) -> FloatArray:
    """A root in each bracket [a_i, b_i] at once: :func:`brent_root` run on every bracket in lockstep.

    ``f`` maps an array of points to the values there, evaluated pointwise, so
    one call per step serves every bracket still searching (a quantity of the
    cam costs about as much at one angle as at ten). Each bracket takes
    exactly the steps :func:`brent_root` takes on it, the same floating-point
    operations in the same order, so the roots are the same to the last bit.
    ``fa`` and ``fb``, the values at the ends, save their evaluation when known.

    Raises
    ------
    ValueError
        When some f(a_i) and f(b_i) have the same sign, or a bracket does not
        converge in ``max_iter`` steps.
    """
    lo = np.array(a, dtype=float).ravel()
    hi = np.array(b, dtype=float).ravel()
    if fa is None or fb is None:
        ends = np.asarray(f(np.concatenate((lo, hi))), dtype=float)
        f_lo, f_hi = ends[: lo.size], ends[lo.size :]
    else:
        f_lo, f_hi = np.array(fa, dtype=float).ravel(), np.array(fb, dtype=float).ravel()
    return _lockstep(f, lo, hi, f_lo, f_hi, xtol=xtol, max_iter=max_iter)


def _lockstep(
    f: Callable[[FloatArray], ArrayLike],
    a: FloatArray,
    b: FloatArray,
    fa: FloatArray,
    fb: FloatArray,
    *,
    xtol: float,
    max_iter: int,
) -> FloatArray:
    """:func:`brent_roots` on arrays of bracket ends and the values there; the steps of :func:`brent_root`."""
    root = np.where(fa == 0.0, a, b)
    live = (fa != 0.0) & (fb != 0.0)
    bad = live & ((fa > 0.0) == (fb > 0.0))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"f({a[i]!r}) = {fa[i]!r} and f({b[i]!r}) = {fb[i]!r} do not bracket a root")
    c, fc = a.copy(), fa.copy()
    d = b - a
    e = d.copy()
    for _ in range(max_iter):
        if not live.any():
            return root
        flip = live & (((fb > 0.0) & (fc > 0.0)) | ((fb < 0.0) & (fc < 0.0)))  # keep the root in [b, c]
        c, fc = np.where(flip, a, c), np.where(flip, fa, fc)
        d, e = np.where(flip, b - a, d), np.where(flip, b - a, e)
        swap = live & (np.abs(fc) < np.abs(fb))  # b is the best estimate so far
        a, b, c = np.where(swap, b, a), np.where(swap, c, b), np.where(swap, b, c)
        fa, fb, fc = np.where(swap, fb, fa), np.where(swap, fc, fb), np.where(swap, fb, fc)
        tol = 2.0 * _EPS * np.abs(b) + 0.5 * xtol  # Brent 1973, §4.6
        m = 0.5 * (c - b)
        done = live & ((np.abs(m) <= tol) | (fb == 0.0))
        root = np.where(done, b, root)
        live = live & ~done
        if not live.any():
            return root
        bisect = (np.abs(e) < tol) | (np.abs(fa) <= np.abs(fb))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # lanes bisecting discard these
            s = fb / fa
            secant = a == c
            q1, r1 = fa / fc, fb / fc  # inverse quadratic interpolation
            p = np.where(secant, 2.0 * m * s, s * (2.0 * m * q1 * (q1 - r1) - (b - a) * (r1 - 1.0)))
            q = np.where(secant, 1.0 - s, (q1 - 1.0) * (r1 - 1.0) * (s - 1.0))
            q = np.where(p > 0.0, -q, q)
            p = np.abs(p)
            accept = ~bisect & (2.0 * p < np.minimum(3.0 * m * q - np.abs(tol * q), np.abs(e * q)))
            e, d = np.where(accept, d, m), np.where(accept, p / q, m)
        a, fa = np.where(live, b, a), np.where(live, fb, fa)
        step = np.where(np.abs(d) > tol, d, np.where(m > 0.0, tol, -tol))
        b = np.where(live, b + step, b)
        at = np.flatnonzero(live)
        fb = fb.copy()
        fb[at] = np.asarray(f(b[at]), dtype=float)
    if live.any():
        raise ValueError(f"Brent's method did not converge in {max_iter} steps")  # pragma: no cover
    return root
