"""The VAP law (Quintero & Vanegas 2016, eqs. 1-9) mapped onto a rise."""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from camcad._typing import ArrayLike
from camcad.errors import DesignError
from camcad.motion._lawbase import Derivatives, Law, _as_x, _finish, _show

__all__ = ["Vap"]


# --------------------------------------------------------------------------- VAP


def _check_b(value: object) -> float:
    """Validate the VAP smoothness parameter: a real number, 0 < b < 1."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise DesignError("b", f"b = {_show(value)} is not a number; allowed: 0 < b < 1")
    b = float(value)
    if not 0.0 < b < 1.0:  # also rejects nan
        raise DesignError("b", f"b = {_show(value)} is outside the allowed range 0 < b < 1")
    return b


@dataclass(frozen=True, slots=True, kw_only=True)
class Vap(Law):
    """Rise by the VAP function of Quintero & Vanegas (2016), eqs. 1-9.

    Attributes
    ----------
    b
        Smoothness parameter, 0 < b < 1: near 0 the rise approaches constant
        velocity, near 1 constant acceleration (parabolic).

    Notes
    -----
    The rise is the half period of eq. 4 from its minimum to its maximum, with
    τ = 2β, y_m = y_a = h/2 and paper abscissa X = (x − ½)β (papers/README).
    With u = 2x − 1 = 4X/τ ∈ [−1, 1], s = |u|, σ = sign u, k = (1 − b)/b and
    E = exp(k(s − 1)), eq. 3 and its odd symmetry about X = 0 give

    - y   = ½ + u (1 − b E) / (2(1 − b))         (Quintero & Vanegas 2016, eq. 3)
    - y′  = (1 − (b + (1 − b)s) E) / (1 − b)      (eq. 7, times β/h)
    - y″  = −2σ (2 + k s) E
    - y‴  = −4k (3 + k s) E

    y and y′ use expm1 so that no terms cancel as b → 1. Peak
    y′ = (1 − b e^(−k)) / (1 − b) at x = ½ (eq. 9, times β/h).

    y′ = 0 at the ends but y″ = ±2(1 + b)/b and y‴ = −4k(3 + k) do not vanish:
    the acceleration jumps against a dwell. Because eq. 3 uses |X|, y″ also
    jumps at x = ½, from +4e^(−k) to −4e^(−k) (negligible for small b, large for
    b near 1); there ``evaluate`` returns the mean, 0.

    References
    ----------
    .. [1] Quintero & Vanegas (2016), Use of the VAP function in the design of
       cam-follower mechanisms, Ingeniería y Competitividad
       (../shared/papers/000_8f0d8937b22a3cde.txt).
    """

    name: ClassVar[str] = "vap"
    b: float

    def __post_init__(self) -> None:
        """Validate ``b``."""
        object.__setattr__(self, "b", _check_b(self.b))

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate the VAP rise (see :meth:`Law.evaluate`)."""
        xa = _as_x(x)
        b = self.b
        k = (1.0 - b) / b
        u = 2.0 * xa - 1.0  # u = 4X/τ
        s, sigma = np.abs(u), np.sign(u)  # 2·h2(X) and the sign of h1(X) (eqs. 5-6)
        t = k * (s - 1.0)
        e = np.exp(t)
        r = np.expm1(t) / (1.0 - b)  # (E − 1)/(1 − b), O(1) for all b
        y = 0.5 + 0.5 * u * (1.0 - b * r)  # Quintero & Vanegas 2016, eq. 3
        y1 = (1.0 - s) - (b + (1.0 - b) * s) * r  # Quintero & Vanegas 2016, eq. 7
        y2 = -2.0 * sigma * (2.0 + k * s) * e
        y3 = -4.0 * k * (3.0 + k * s) * e
        return _finish(xa.shape, y, y1, y2, y3)

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """Only y′ vanishes at the ends."""
        return (1,)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """y″ jumps at x = ½ (the |X| of eq. 3)."""
        return (0.5,)

    def describe(self) -> str:
        """Return e.g. ``"VAP b=0.1"``."""
        return f"VAP b={self.b:g}"
