"""Derivatives of any order of the shipped laws that have them in closed form, and of a program.

The motion layer gives s, v, a, j; a polydyne cam needs the output law's
derivatives to the 5th (single mass) or 7th (two masses) order. They are
written here for the closed-form laws: constant velocity, harmonic, cycloidal
(trigonometric), 3-4-5, 4-5-6-7, Dudley and the blend polynomial. The SCCA
family, the modified sine with constant velocity, VAP, inclined sine and point
tables have none here (piecewise or spline laws whose higher derivatives jump
inside the segment); :func:`program_derivatives` refuses them.
"""

from __future__ import annotations

import math
from functools import cache
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np
from numpy.polynomial import legendre
from numpy.polynomial import polynomial as poly

from camcad._typing import FloatArray
from camcad.angles import TWO_PI
from camcad.errors import DesignError
from camcad.motion.laws import (
    ConstantVelocity,
    Cycloidal,
    Dudley,
    Harmonic,
    Law,
    Poly345,
    Poly4567,
    Polynomial,
)
from camcad.motion.segments import SegmentKind

if TYPE_CHECKING:
    from camcad.extremes import Side
    from camcad.motion.program import MotionProgram

__all__ = ["SUPPORTED_LAWS", "law_derivatives", "program_derivatives"]

SUPPORTED_LAWS = (
    "constant-velocity",
    "harmonic",
    "cycloidal",
    "poly-345",
    "poly-4567",
    "dudley",
    "polynomial",
)
"""Laws with derivatives of every order here."""

_MONOMIAL = {
    "poly-345": (0.0, 0.0, 0.0, 10.0, -15.0, 6.0),
    "poly-4567": (0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0),
}


@cache
def _bernstein(n: int, k: int) -> tuple[tuple[int, int, float], ...]:
    """Bernstein terms of y^(k) of Dudley's law I_x(p, p) (as in camcad.motion._polynomial, any k ≤ n)."""
    p = (n + 1) // 2
    diff = [0] * p + [1] * (n + 1 - p)
    for _ in range(k):
        diff = [b - a for a, b in pairwise(diff)]
    m = n - k
    scale = math.perm(n, k)
    return tuple((j, m - j, float(scale * d * math.comb(m, j))) for j, d in enumerate(diff) if d)


def law_derivatives(law: Law, x: FloatArray, orders: int) -> FloatArray | None:
    """(orders + 1, m) y, y′, …, y^(orders) of a normalised law at x (m,), or None if not available."""
    x = np.asarray(x, dtype=float)
    out = np.zeros((orders + 1, x.size))
    if isinstance(law, ConstantVelocity):
        out[0] = x
        if orders >= 1:
            out[1] = 1.0
        return out
    if isinstance(law, Harmonic):
        out[0] = 0.5 * (1.0 - np.cos(math.pi * x))
        for k in range(1, orders + 1):
            out[k] = -0.5 * math.pi**k * np.cos(math.pi * x + 0.5 * k * math.pi)
        return out
    if isinstance(law, Cycloidal):
        w = TWO_PI
        out[0] = x - np.sin(w * x) / w
        if orders >= 1:
            out[1] = 1.0 - np.cos(w * x)
        for k in range(2, orders + 1):
            out[k] = -(w ** (k - 1)) * np.sin(w * x + 0.5 * k * math.pi)
        return out
    if isinstance(law, (Poly345, Poly4567)):
        c = np.asarray(_MONOMIAL[law.name])
        for k in range(orders + 1):
            out[k] = poly.polyval(x, poly.polyder(c, k)) if k < c.size else 0.0
        return out
    if isinstance(law, Dudley):
        n = law.degree
        xp = [np.ones_like(x)]
        qp = [np.ones_like(x)]
        for _ in range(n):
            xp.append(xp[-1] * x)
            qp.append(qp[-1] * (1.0 - x))
        for k in range(min(orders, n) + 1):
            out[k] = sum((w * xp[j] * qp[m] for j, m, w in _bernstein(n, k)), np.zeros_like(x))
        return out
    if isinstance(law, Polynomial) and law.coefficients:
        c = np.asarray(law.coefficients)
        u = 2.0 * x - 1.0
        for k in range(orders + 1):
            out[k] = 2.0**k * legendre.legval(u, legendre.legder(c, k)) if k < c.size else 0.0
        return out
    return None


def program_derivatives(
    program: MotionProgram, phi: FloatArray, orders: int, *, side: Side = "right"
) -> FloatArray:
    """(orders + 1, m) s and its φ-derivatives to ``orders`` [lift unit / rad^k] at angles ``phi``.

    Raises
    ------
    DesignError
        ``motion[i].law`` for a segment whose law has no derivatives of that
        order here (see ``SUPPORTED_LAWS``).
    """
    check_supported(program)
    phi_in = np.asarray(phi, dtype=float).ravel()
    wrapped = np.mod(phi_in, TWO_PI)
    edges = np.asarray(program.starts[1:])
    if side == "left":
        wrapped = np.where(wrapped == 0.0, TWO_PI, wrapped)
        index = np.searchsorted(edges, wrapped, side="left")
    else:
        index = np.searchsorted(edges, wrapped, side="right")
    out = np.zeros((orders + 1, phi_in.size))
    for k, seg in enumerate(program.segments):
        mask = index == k
        if not mask.any():
            continue
        base = program.base_s[k]
        if seg.kind is SegmentKind.DWELL or seg.law is None:
            out[0, mask] = base
            continue
        x = np.clip((wrapped[mask] - program.starts[k]) / seg.span, 0.0, 1.0)
        y = law_derivatives(seg.law, x, orders)
        assert y is not None
        h, beta = seg.signed_lift, seg.span
        out[:, mask] = h * y / beta ** np.arange(orders + 1)[:, None]
        out[0, mask] += base
    return out


def check_supported(program: MotionProgram) -> None:
    """Refuse a program with a law that has no higher derivatives here (``motion[i].law``)."""
    for i, seg in enumerate(program.segments):
        if seg.kind is SegmentKind.DWELL or seg.law is None:
            continue
        if seg.kind is SegmentKind.TABLE or law_derivatives(seg.law, np.zeros(1), 4) is None:
            name = getattr(seg.law, "name", "table")
            raise DesignError(
                f"motion[{i}].law",
                f"{name!r} has no closed-form 4th and 5th derivatives for a compensated (polydyne) cam; "
                f"allowed: {', '.join(SUPPORTED_LAWS)} (smooth enough at every joint)",
            )
