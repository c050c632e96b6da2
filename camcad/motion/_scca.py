"""The SCCA family: modified trapezoid and modified sine (Norton, Design of Machinery)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache
from typing import ClassVar

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.motion._lawbase import _PI, Derivatives, Law, _as_x, _cospi, _finish, _sinpi

__all__ = ["ModifiedSine", "ModifiedTrapezoid"]


# -------------------------------------------------------------------------- SCCA


@cache
def _scca_table(b: float, c: float, d: float) -> tuple[FloatArray, ...]:
    """Pieces of an SCCA law on [0, ½]: start, α, β, γ, w, y₀, v₀ and the scale C_a.

    On a piece starting at x₀ with t = x − x₀ and ω = π/w, the unscaled
    acceleration is α + β sin ωt + γ cos ωt: a quarter sine over b/2, a
    constant over c/2, a half cosine over d (of which [.., ½] lies here).
    """
    pieces: list[tuple[float, float, float, float, float]] = []
    x0 = 0.0
    for width, piece in (
        (0.5 * b, (0.0, 1.0, 0.0, b)),  # sine ramp up: sin(πt/b)
        (0.5 * c, (1.0, 0.0, 0.0, 1.0)),  # constant
        (0.5 * d, (0.0, 0.0, 1.0, d)),  # cosine down to 0 at x = ½: cos(πt/d)
    ):
        if width > 0.0:
            pieces.append((x0, *piece))
            x0 += width
    y0 = v0 = 0.0
    table = []
    for i, (start, al, be, ga, w) in enumerate(pieces):
        table.append((start, al, be, ga, w, y0, v0))
        t = (pieces[i + 1][0] if i + 1 < len(pieces) else 0.5) - start
        om, sn, cs = _PI / w, math.sin(_PI * t / w), math.cos(_PI * t / w)
        y0 += v0 * t + 0.5 * al * t * t + be / om * (t - sn / om) + ga / om**2 * (1.0 - cs)
        v0 += al * t + be / om * (1.0 - cs) + ga / om * sn
    cols = [np.array(col, dtype=np.float64) for col in zip(*table, strict=True)]
    cols.append(np.array(0.5 / y0))  # C_a: makes y(½) = ½, hence y(1) = 1
    readonly(*cols)
    return tuple(cols)


def _scca_evaluate(b: float, c: float, d: float, x: ArrayLike) -> Derivatives:
    """Evaluate the SCCA law with fractions b + c + d = 1 (Norton, ch. 8)."""
    xa = _as_x(x)
    start, al, be, ga, w, y0, v0, scale = _scca_table(b, c, d)
    mirror = xa > 0.5
    xm = np.where(mirror, 1.0 - xa, xa)  # y(x) = 1 − y(1 − x)
    i = np.clip(np.searchsorted(start, xm, side="right") - 1, 0, start.size - 1)
    t = xm - start[i]
    al, be, ga, w, y0, v0 = al[i], be[i], ga[i], w[i], y0[i], v0[i]
    om = _PI / w
    sn, cs = _sinpi(t / w), _cospi(t / w)
    y = y0 + v0 * t + 0.5 * al * t * t + be / om * (t - sn / om) + ga / om**2 * (1.0 - cs)
    y1 = v0 + al * t + be / om * (1.0 - cs) + ga / om * sn
    y2 = al + be * sn + ga * cs
    y3 = om * (be * cs - ga * sn)
    y, y1, y2, y3 = scale * y, scale * y1, scale * y2, scale * y3
    y = np.where(mirror, 1.0 - y, y)
    y2 = np.where(mirror, -y2, y2)
    return _finish(xa.shape, y, y1, y2, y3)


def _scca_breakpoints(b: float, c: float) -> tuple[float, ...]:
    joints = {x for x in (0.5 * b, 0.5 * (b + c)) if 0.0 < x < 0.5}
    return tuple(sorted(joints | {1.0 - x for x in joints}))


@dataclass(frozen=True, slots=True, kw_only=True)
class ModifiedTrapezoid(Law):
    """Modified trapezoid: SCCA with b = 0.25, c = 0.5, d = 0.25.

    Notes
    -----
    Acceleration: quarter sine over [0, ⅛], constant over [⅛, ⅜], half cosine
    over [⅜, ⅝], then mirrored. Peak y′ = 2, peak y″ ≈ 4.888; y‴ jumps at the
    joints ⅛, ⅜, ⅝, ⅞ and is nonzero at the ends.

    References
    ----------
    .. [1] R. L. Norton, Design of Machinery, McGraw-Hill, ch. 8 (the SCCA
       family of double-dwell cam functions).
    """

    name: ClassVar[str] = "modified-trapezoid"

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate the modified trapezoid (see :meth:`Law.evaluate`)."""
        return _scca_evaluate(0.25, 0.5, 0.25, x)  # Norton, SCCA

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """y′ = y″ = 0 at the ends."""
        return (1, 2)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """The SCCA piece joints ⅛, ⅜, ⅝, ⅞."""
        return _scca_breakpoints(0.25, 0.5)

    def describe(self) -> str:
        """Return ``"modified trapezoid"``."""
        return "modified trapezoid"


@dataclass(frozen=True, slots=True, kw_only=True)
class ModifiedSine(Law):
    """Modified sine: SCCA with b = 0.25, c = 0, d = 0.75.

    Notes
    -----
    Acceleration: quarter sine over [0, ⅛], half cosine over [⅛, ⅞], quarter
    sine back to 0. Peak y′ ≈ 1.760, peak y″ ≈ 5.528.

    References
    ----------
    .. [1] R. L. Norton, Design of Machinery, McGraw-Hill, ch. 8 (the SCCA
       family of double-dwell cam functions).
    """

    name: ClassVar[str] = "modified-sine"

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate the modified sine (see :meth:`Law.evaluate`)."""
        return _scca_evaluate(0.25, 0.0, 0.75, x)  # Norton, SCCA

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """y′ = y″ = 0 at the ends."""
        return (1, 2)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """The SCCA piece joints ⅛ and ⅞."""
        return _scca_breakpoints(0.25, 0.0)

    def describe(self) -> str:
        """Return ``"modified sine"``."""
        return "modified sine"
