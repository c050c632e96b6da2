"""Laws that adapt to their boundary values: the blend polynomial and the inclined sine (VDI 2143).

Both are stated by the user without their boundary values; :mod:`camcad.motion.blend`
solves for them (match the neighbour, or meet a specified value) and returns
the resolved law, whose fields then hold everything needed to evaluate it.
An unresolved law cannot be evaluated.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.polynomial import legendre

from camcad._typing import ArrayLike
from camcad.errors import DesignError
from camcad.motion._lawbase import _PI, Derivatives, Law, _as_x, _cospi, _finish, _show, _sinpi

__all__ = ["MAX_POLYNOMIAL_DEGREE", "InclinedSine", "Polynomial"]

MAX_POLYNOMIAL_DEGREE = 15
"""Largest accepted ``degree`` of a blend polynomial (Legendre form keeps it well conditioned)."""

_ZERO_RTOL = 1e-12


def _check_poly_degree(value: object) -> int:
    allowed = f"allowed: an integer 5 ≤ degree ≤ {MAX_POLYNOMIAL_DEGREE}, or omit it for the lowest degree"
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise DesignError("degree", f"degree = {_show(value)} is not an integer; {allowed}")
    n = int(value)
    if n != 0 and not 5 <= n <= MAX_POLYNOMIAL_DEGREE:
        raise DesignError("degree", f"degree = {n} is out of range; {allowed}")
    return n


@dataclass(frozen=True, slots=True, kw_only=True)
class Polynomial(Law):
    """A polynomial that meets the segment's boundary values (a blend polynomial).

    Attributes
    ----------
    degree
        The degree asked for; 0 means the lowest degree that meets the
        conditions (Hermite interpolation: 5 for s, v, a at both ends).
    coefficients
        After resolution: the Legendre coefficients of y(x) in u = 2x − 1
        (normalised lift, y(0) = 0, y(1) = 1). Empty before resolution.

    Notes
    -----
    Where the degree leaves freedom beyond the conditions, the polynomial is
    the one of least jerk norm ∫ (d³s/dφ³)² dφ (a linear KKT solve,
    :mod:`camcad.motion.blend`). The Legendre basis keeps that solve and the
    evaluation well conditioned up to ``MAX_POLYNOMIAL_DEGREE`` (the monomial
    Gram matrix of degree 15 has condition ~1e20).
    """

    name: ClassVar[str] = "polynomial"
    degree: int = 0
    coefficients: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        """Validate ``degree``."""
        object.__setattr__(self, "degree", _check_poly_degree(self.degree))

    @property
    def resolved(self) -> bool:
        """True once the boundary values have been solved for."""
        return bool(self.coefficients)

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate y and three derivatives (see :meth:`Law.evaluate`)."""
        if not self.coefficients:
            raise ValueError("an unresolved polynomial has no values; build the program with MotionProgram")
        xa = _as_x(x)
        u = 2.0 * xa - 1.0
        c = np.asarray(self.coefficients)
        out = [legendre.legval(u, c)]
        for m in (1, 2, 3):
            out.append(2.0**m * legendre.legval(u, legendre.legder(c, m)))  # d/dx = 2 d/du
        return _finish(xa.shape, *out)

    def _end_values(self, x: float) -> list[float]:
        return [float(v) for v in self.evaluate(x)[1:]]

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """Orders among (1, 2, 3) whose derivative vanishes at x = 0 (to 1e-12 of the coefficients)."""
        scale = max(1.0, *map(abs, self.coefficients)) if self.coefficients else 1.0
        return tuple(m for m, v in enumerate(self._end_values(0.0), 1) if abs(v) <= _ZERO_RTOL * scale)

    @property
    def zero_at_end(self) -> tuple[int, ...]:
        """Orders among (1, 2, 3) whose derivative vanishes at x = 1."""
        scale = max(1.0, *map(abs, self.coefficients)) if self.coefficients else 1.0
        return tuple(m for m, v in enumerate(self._end_values(1.0), 1) if abs(v) <= _ZERO_RTOL * scale)

    def describe(self) -> str:
        """Return e.g. ``"polynomial n=5 (blend)"``."""
        n = len(self.coefficients) - 1 if self.coefficients else self.degree
        return f"polynomial n={n} (blend)" if n else "polynomial (blend)"


@dataclass(frozen=True, slots=True, kw_only=True)
class InclinedSine(Law):
    """Inclined sine (Bestehorn's "geneigte Sinuslinie", VDI 2143) between given end velocities.

    Attributes
    ----------
    start_velocity, end_velocity
        After resolution: the normalised end velocities c₀ = y′(0), c₁ = y′(1)
        (taken from the neighbours). ``None`` before resolution.

    Notes
    -----
    y″ = A sin 2πx + B (1 − cos 2πx) with B = c₁ − c₀ and
    A = 2π (1 − (c₀ + c₁)/2), so that y(0) = 0, y(1) = 1, y′ = c₀, c₁ and
    y″ = 0 at both ends: the sine acceleration of the cycloid, inclined by a
    constant-jerk ramp that carries the velocity from c₀ to c₁. Between rests
    (c₀ = c₁ = 0) it is the cycloidal law; next to a constant-velocity stretch
    it joins C2. (Our closed form of the VDI 2143 transition; its jerk at the
    ends is 2πA.)

    Examples
    --------
    Between rests it is the cycloid: at x = ¼, y = ¼ − 1/(2π).

    >>> import math
    >>> y = InclinedSine(start_velocity=0.0, end_velocity=0.0).evaluate(0.25)[0]
    >>> math.isclose(float(y), 0.25 - 1 / (2 * math.pi), rel_tol=1e-15)
    True
    """

    name: ClassVar[str] = "inclined-sine"
    start_velocity: float | None = None
    end_velocity: float | None = None

    @property
    def resolved(self) -> bool:
        """True once the end velocities are known."""
        return self.start_velocity is not None and self.end_velocity is not None

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate y and three derivatives (see :meth:`Law.evaluate`)."""
        if self.start_velocity is None or self.end_velocity is None:
            raise ValueError(
                "an unresolved inclined sine has no values; build the program with MotionProgram"
            )
        xa = _as_x(x)
        c0, c1 = self.start_velocity, self.end_velocity
        big_a = 2.0 * _PI * (1.0 - 0.5 * (c0 + c1))
        big_b = c1 - c0
        s, c = _sinpi(2.0 * xa), _cospi(2.0 * xa)
        tau = 2.0 * _PI
        y = c0 * xa + big_a * (xa - s / tau) / tau + big_b * (0.5 * xa * xa - (1.0 - c) / tau**2)
        y1 = c0 + big_a * (1.0 - c) / tau + big_b * (xa - s / tau)
        y2 = big_a * s + big_b * (1.0 - c)
        y3 = tau * (big_a * c + big_b * s)
        return _finish(xa.shape, y, y1, y2, y3)

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """y″ = 0 at the ends; y′ too where the end velocity is 0."""
        return (1, 2) if self.start_velocity == 0.0 else (2,)

    @property
    def zero_at_end(self) -> tuple[int, ...]:
        """y″ = 0 at the ends; y′ too where the end velocity is 0."""
        return (1, 2) if self.end_velocity == 0.0 else (2,)

    def describe(self) -> str:
        """Return ``"inclined sine"`` with its end velocities once resolved."""
        if self.start_velocity is None or self.end_velocity is None:
            return "inclined sine"
        if self.start_velocity == 0.0 and self.end_velocity == 0.0:
            return "inclined sine (= cycloidal)"
        return f"inclined sine y'={self.start_velocity:.4g}..{self.end_velocity:.4g}"
