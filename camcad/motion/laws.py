"""Displacement laws of cam motion on the normalised rise x ∈ [0, 1].

A law maps the rise fraction x = (φ − φ₀)/β of a segment spanning β [rad] to
the normalised lift y = s/h and its x-derivatives y′, y″, y‴, all in closed
form. The motion program scales them to a rise of h [mm]:
s = h·y, v = ds/dφ = h·y′/β, a = h·y″/β², j = h·y‴/β³.

Every law here has y(0) = 0, y(1) = 1 and y′ ≥ 0, and is point-symmetric about
(½, ½): y(1 − x) = 1 − y(x). ``zero_at_start`` / ``zero_at_end`` say which of
y′, y″, y‴ vanish exactly at the ends, so the program can judge the continuity
of a joint with a dwell or a neighbouring segment without sampling.

``LAWS`` lists the registry (name, summary, parameters) in a stable order for
``camcad laws``; ``make_law`` validates a name and its parameters and raises
:class:`~camcad.errors.DesignError` naming the offending field.
"""

from __future__ import annotations

import difflib
import math
import numbers
from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from functools import cache
from itertools import pairwise
from types import MappingProxyType
from typing import ClassVar

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.errors import DesignError

__all__ = [
    "DUDLEY_MAX_DEGREE",
    "LAWS",
    "ConstantVelocity",
    "Cycloidal",
    "Derivatives",
    "Dudley",
    "Harmonic",
    "Law",
    "LawInfo",
    "LawParameter",
    "ModifiedSine",
    "ModifiedTrapezoid",
    "Poly345",
    "Poly4567",
    "Vap",
    "dudley_coefficients",
    "dudley_matrix",
    "make_law",
]

Derivatives = tuple[FloatArray, FloatArray, FloatArray, FloatArray]
"""(y, y′, y″, y‴) at the sample points, each read-only float64 of x's shape."""

DUDLEY_MAX_DEGREE = 99
"""Largest accepted Dudley degree (keeps the exact solve and the sums cheap)."""

_PI = math.pi


# --------------------------------------------------------------------------- base


class Law(ABC):
    """A normalised displacement law y(x) on the rise fraction x ∈ [0, 1].

    Concrete laws are frozen, slotted, keyword-only dataclasses whose fields are
    the law's parameters. ``name`` is the registry name used by design files.
    """

    __slots__ = ()

    name: ClassVar[str]

    @abstractmethod
    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate the law and its first three derivatives.

        Parameters
        ----------
        x
            Rise fraction, any shape, values in [0, 1]. Outside [0, 1] the
            formulas are merely continued and carry no meaning.

        Returns
        -------
        Derivatives
            ``(y, dy/dx, d²y/dx², d³y/dx³)``, read-only float64 arrays of x's
            shape: normalised lift [1] and its derivatives [1].
        """

    @property
    @abstractmethod
    def zero_at_start(self) -> tuple[int, ...]:
        """Derivative orders among (1, 2, 3) that are exactly 0 at x = 0."""

    @property
    def zero_at_end(self) -> tuple[int, ...]:
        """Derivative orders among (1, 2, 3) that are exactly 0 at x = 1.

        The laws here are point-symmetric, so this equals ``zero_at_start``
        unless a law overrides it.
        """
        return self.zero_at_start

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Interior x where the law switches formula and y″ or y‴ may jump."""
        return ()

    @abstractmethod
    def describe(self) -> str:
        """Return a short human description such as ``"VAP b=0.1"``."""


@dataclass(frozen=True, slots=True, kw_only=True)
class LawParameter:
    """One parameter of a law, as listed by ``camcad laws``.

    Attributes
    ----------
    name
        Key in the design file, e.g. ``"b"``.
    kind
        Python type of the value (``float`` or ``int``).
    default
        Default value, or ``None`` when the parameter is required.
    allowed
        Human-readable allowed range, e.g. ``"0 < b < 1"``.
    """

    name: str
    kind: type
    default: object | None
    allowed: str


@dataclass(frozen=True, slots=True, kw_only=True)
class LawInfo:
    """Registry entry of a law: its name, a one-line summary and its parameters."""

    name: str
    summary: str
    parameters: tuple[LawParameter, ...]


# ------------------------------------------------------------------ small helpers


def _as_x(x: ArrayLike) -> FloatArray:
    return np.asarray(x, dtype=np.float64)


def _finish(shape: tuple[int, ...], *arrays: object) -> Derivatives:
    """Copy to fresh float64 arrays of ``shape`` and mark them read-only."""
    y, y1, y2, y3 = (np.array(np.broadcast_to(a, shape), dtype=np.float64) for a in arrays)
    readonly(y, y1, y2, y3)
    return y, y1, y2, y3


def _sinpi(x: FloatArray) -> FloatArray:
    """sin(πx), exactly 0 at integers and ±1 at half-integers."""
    r = x - 2.0 * np.round(0.5 * x)  # r ∈ [-1, 1], same sine
    r = np.where(r > 0.5, 1.0 - r, np.where(r < -0.5, -1.0 - r, r))  # fold to [-½, ½]
    return np.sin(_PI * r)


def _cospi(x: FloatArray) -> FloatArray:
    """cos(πx) = sin(π(x + ½)), exactly 0 at half-integers."""
    return _sinpi(x + 0.5)


def _show(value: object) -> str:
    """Format a user value for an error message (``1``, ``0.5``, ``'x'``)."""
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        return str(int(value))
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return repr(float(value))
    return repr(value)


def _unknown(what: str, word: str, choices: Sequence[str], where: str = "") -> str:
    """Message for an unknown name, suggesting the closest choice."""
    close = difflib.get_close_matches(word, choices, n=1)
    hint = f"did you mean {close[0]!r}? " if close else ""
    return f"unknown {what} {word!r}{where}; {hint}allowed: {', '.join(choices)}"


# ------------------------------------------------------------ trigonometric laws


@dataclass(frozen=True, slots=True, kw_only=True)
class ConstantVelocity(Law):
    """Constant velocity, y = x.

    Notes
    -----
    y′ = 1 at both ends, so the velocity jumps against a dwell (infinite
    acceleration at the joint). y″ and y‴ are identically 0, so
    ``zero_at_start = zero_at_end = (2, 3)``; the program must check the
    lowest unmatched order first.
    """

    name: ClassVar[str] = "constant-velocity"

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate y = x and its derivatives (see :meth:`Law.evaluate`)."""
        xa = _as_x(x)
        return _finish(xa.shape, xa, 1.0, 0.0, 0.0)

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """y″ = y‴ = 0 everywhere; y′ = 1."""
        return (2, 3)

    def describe(self) -> str:
        """Return ``"constant velocity"``."""
        return "constant velocity"


@dataclass(frozen=True, slots=True, kw_only=True)
class Harmonic(Law):
    """Simple harmonic rise, y = (1 − cos πx)/2.

    Notes
    -----
    y′ = (π/2) sin πx, y″ = (π²/2) cos πx, y‴ = −(π³/2) sin πx. Peak y′ = π/2.
    y″ = ±π²/2 at the ends, so acceleration jumps against a dwell.
    """

    name: ClassVar[str] = "harmonic"

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate the harmonic law (see :meth:`Law.evaluate`)."""
        xa = _as_x(x)
        s, c = _sinpi(xa), _cospi(xa)
        h = 0.5 * _PI
        return _finish(xa.shape, 0.5 * (1.0 - c), h * s, h * _PI * c, -h * _PI**2 * s)

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """y′ = y‴ = 0 at the ends; y″ = ±π²/2."""
        return (1, 3)

    def describe(self) -> str:
        """Return ``"harmonic"``."""
        return "harmonic"


@dataclass(frozen=True, slots=True, kw_only=True)
class Cycloidal(Law):
    """Cycloidal rise, y = x − sin(2πx)/(2π).

    Notes
    -----
    y′ = 1 − cos 2πx, y″ = 2π sin 2πx, y‴ = 4π² cos 2πx. Peak y′ = 2, peak
    y″ = 2π. y‴ = 4π² at the ends.
    """

    name: ClassVar[str] = "cycloidal"

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate the cycloidal law (see :meth:`Law.evaluate`)."""
        xa = _as_x(x)
        s, c = _sinpi(2.0 * xa), _cospi(2.0 * xa)
        return _finish(xa.shape, xa - s / (2.0 * _PI), 1.0 - c, 2.0 * _PI * s, 4.0 * _PI**2 * c)

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """y′ = y″ = 0 at the ends; y‴ = 4π²."""
        return (1, 2)

    def describe(self) -> str:
        """Return ``"cycloidal"``."""
        return "cycloidal"


# ------------------------------------------------------------------ polynomials


@dataclass(frozen=True, slots=True, kw_only=True)
class Poly345(Law):
    """3-4-5 polynomial, y = 10x³ − 15x⁴ + 6x⁵ (Dudley n = 5).

    Notes
    -----
    y′ = 30x²(1 − x)², y″ = 60x(1 − x)(1 − 2x), y‴ = 60(1 − 6x + 6x²).
    Peak y′ = 15/8; y‴ = 60 at the ends.
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


# ---------------------------------------------------------------------- registry

_B = LawParameter(name="b", kind=float, default=None, allowed="0 < b < 1")
_DEGREE = LawParameter(
    name="degree", kind=int, default=None, allowed=f"odd integer 3 ≤ degree ≤ {DUDLEY_MAX_DEGREE}"
)

_ENTRIES: tuple[tuple[type[Law], str, tuple[LawParameter, ...]], ...] = (
    (ConstantVelocity, "y = x; velocity jumps at the ends", ()),
    (Harmonic, "simple harmonic; acceleration jumps at the ends, peak y' = pi/2", ()),
    (Cycloidal, "cycloidal; zero velocity and acceleration at the ends, peak y' = 2", ()),
    (Poly345, "3-4-5 polynomial; zero velocity and acceleration at the ends", ()),
    (Poly4567, "4-5-6-7 polynomial; zero velocity, acceleration and jerk at the ends", ()),
    (Dudley, "Dudley odd-degree polynomial; derivatives 1..(n-1)/2 zero at the ends", (_DEGREE,)),
    (ModifiedTrapezoid, "modified trapezoid (SCCA); peak y' = 2, low peak acceleration", ()),
    (ModifiedSine, "modified sine (SCCA); peak y' = 1.76", ()),
    (Vap, "VAP function; near-constant velocity, acceleration jumps at the ends", (_B,)),
)

_CLASSES: dict[str, type[Law]] = {cls.name: cls for cls, _, _ in _ENTRIES}

LAWS: Mapping[str, LawInfo] = MappingProxyType(
    {cls.name: LawInfo(name=cls.name, summary=text, parameters=ps) for cls, text, ps in _ENTRIES}
)
"""Registry of the laws by name, in the order ``camcad laws`` lists them."""


def make_law(name: str, **params: object) -> Law:
    """Build a law from its registry name and parameters, validating both.

    Parameters
    ----------
    name
        Registry name, a key of ``LAWS`` (e.g. ``"cycloidal"``).
    **params
        The law's parameters (e.g. ``b=0.2`` for ``"vap"``).

    Returns
    -------
    Law
        The frozen law object.

    Raises
    ------
    DesignError
        ``path == "law"`` for an unknown law; ``path`` is the parameter name
        for an unknown, missing or invalid parameter. Callers re-prefix the
        path (``motion[2].b``).

    Examples
    --------
    >>> make_law("vap", b=0.1).describe()
    'VAP b=0.1'
    """
    if not isinstance(name, str):
        raise DesignError("law", f"expected a law name, got {name!r}; allowed: {', '.join(LAWS)}")
    info = LAWS.get(name)
    if info is None:
        raise DesignError("law", _unknown("law", name, list(LAWS)))
    allowed = [p.name for p in info.parameters]
    for key in params:
        if key not in allowed:
            if not allowed:
                raise DesignError(key, f"unknown parameter {key!r}; law {name!r} takes no parameters")
            raise DesignError(key, _unknown("parameter", key, allowed, f" for law {name!r}"))
    for p in info.parameters:
        if p.name not in params and p.default is None:
            raise DesignError(p.name, f"is required for law {name!r} ({p.allowed})")
    return _CLASSES[name](**params)
