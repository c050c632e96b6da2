"""Modified sine with X % constant velocity: the modified sine split by a constant-velocity stretch."""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from camcad._typing import ArrayLike
from camcad.errors import DesignError
from camcad.motion._lawbase import _PI, Derivatives, Law, _as_x, _finish, _show
from camcad.motion._scca import ModifiedSine

__all__ = ["ModifiedSineCV"]

_MS_PEAK_VELOCITY = 4.0 * _PI / (4.0 + _PI)  # y′(½) of the modified sine (Rothbart 2004, ch. 2)


@dataclass(frozen=True, slots=True, kw_only=True)
class ModifiedSineCV(Law):
    """Modified sine with a share ``cv`` of the span at constant velocity, rest to rest.

    Attributes
    ----------
    cv
        Fraction of the span at constant velocity, 0 ≤ cv < 1 (``cv = 0.3``:
        "modified sine with 30 % constant velocity").

    Notes
    -----
    The modified sine's accelerating half runs over [0, w/2] (w = 1 − cv),
    the velocity then stays at its peak over [w/2, w/2 + cv], and the
    decelerating half mirrors the first: y(1 − x) = 1 − y(x). With
    y_ms the modified sine and V = y_ms′(½) = 4π/(4 + π),
    y = A·y_ms(x/w) on the first part, A = 1/(1 + cv·V/w) so that y(1) = 1.
    The acceleration is continuous; the jerk jumps where the constant
    velocity begins and ends (and at the modified sine's own joints).
    cv = 0 is the modified sine.

    Examples
    --------
    Half the span at constant velocity: the velocity there is A·V/w.

    >>> import math
    >>> law = ModifiedSineCV(cv=0.5)
    >>> v = float(law.evaluate(0.5)[1])
    >>> a = 1.0 / (1.0 + 0.5 * _MS_PEAK_VELOCITY / 0.5)
    >>> math.isclose(v, a * _MS_PEAK_VELOCITY / 0.5, rel_tol=1e-12)
    True
    """

    name: ClassVar[str] = "modified-sine-cv"
    cv: float

    def __post_init__(self) -> None:
        """Validate ``cv``."""
        value = self.cv
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not 0.0 <= float(value) < 1.0:
            raise DesignError("cv", f"cv = {_show(value)} is outside the allowed range 0 ≤ cv < 1")
        object.__setattr__(self, "cv", float(value))

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate the law and three derivatives (see :meth:`Law.evaluate`)."""
        xa = _as_x(x)
        w = 1.0 - self.cv
        amp = 1.0 / (1.0 + self.cv * _MS_PEAK_VELOCITY / w)
        mirror = xa > 0.5
        xm = np.where(mirror, 1.0 - xa, xa)
        accel = xm < 0.5 * w
        ms = ModifiedSine().evaluate(np.where(accel, xm / w, 0.5))
        peak = amp * _MS_PEAK_VELOCITY / w
        y = np.where(accel, amp * ms[0], 0.5 * amp + peak * (xm - 0.5 * w))
        y1 = np.where(accel, amp * ms[1] / w, peak)
        y2 = np.where(accel, amp * ms[2] / w**2, 0.0)
        y3 = np.where(accel, amp * ms[3] / w**3, 0.0)
        y = np.where(mirror, 1.0 - y, y)
        y2 = np.where(mirror, -y2, y2)
        return _finish(xa.shape, y, y1, y2, y3)

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """y′ = y″ = 0 at the ends."""
        return (1, 2)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """The modified sine's joints w/8, 1 − w/8 and the ends of the constant velocity."""
        w = 1.0 - self.cv
        points = {w / 8.0, 1.0 - w / 8.0}
        if self.cv > 0.0:
            points |= {w / 2.0, 1.0 - w / 2.0}
        return tuple(sorted(points))

    def describe(self) -> str:
        """Return e.g. ``"modified sine 30% c.v."``."""
        return f"modified sine {100.0 * self.cv:g}% c.v."
