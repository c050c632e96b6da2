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

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import ClassVar

from camcad._typing import ArrayLike
from camcad.errors import DesignError
from camcad.motion._blendlaws import MAX_POLYNOMIAL_DEGREE, InclinedSine, Polynomial
from camcad.motion._lawbase import (
    _PI,
    DUDLEY_MAX_DEGREE,
    Derivatives,
    Law,
    LawInfo,
    LawParameter,
    _as_x,
    _cospi,
    _finish,
    _sinpi,
    _unknown,
)
from camcad.motion._mscv import ModifiedSineCV
from camcad.motion._polynomial import Dudley, Poly345, Poly4567, dudley_coefficients, dudley_matrix
from camcad.motion._scca import ModifiedSine, ModifiedTrapezoid
from camcad.motion._vap import Vap

__all__ = [
    "DUDLEY_MAX_DEGREE",
    "LAWS",
    "MAX_POLYNOMIAL_DEGREE",
    "ConstantVelocity",
    "Cycloidal",
    "Derivatives",
    "Dudley",
    "Harmonic",
    "InclinedSine",
    "Law",
    "LawInfo",
    "LawParameter",
    "ModifiedSine",
    "ModifiedSineCV",
    "ModifiedTrapezoid",
    "Poly345",
    "Poly4567",
    "Polynomial",
    "Vap",
    "dudley_coefficients",
    "dudley_matrix",
    "make_law",
]


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

    Examples
    --------
    At mid-rise x = 1/2: y = 1/2, y′ = 1 − cos π = 2 (the peak), y″ = 2π sin π
    = 0 and y‴ = 4π² cos π = −4π².

    >>> import math
    >>> y, y1, y2, y3 = Cycloidal().evaluate(0.5)
    >>> float(y), float(y1), float(y2), math.isclose(y3, -4.0 * math.pi**2, rel_tol=1e-15)
    (0.5, 2.0, 0.0, True)
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


# ---------------------------------------------------------------------- registry

_B = LawParameter(name="b", kind=float, default=None, allowed="0 < b < 1")
_DEGREE = LawParameter(
    name="degree", kind=int, default=None, allowed=f"odd integer 3 ≤ degree ≤ {DUDLEY_MAX_DEGREE}"
)

_CV = LawParameter(name="cv", kind=float, default=None, allowed="0 ≤ cv < 1")
_POLY_DEGREE = LawParameter(
    name="degree",
    kind=int,
    default=0,
    allowed=f"5 ≤ degree ≤ {MAX_POLYNOMIAL_DEGREE}; omitted: the lowest degree (5, or 6-7 with a given jerk)",
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
    (
        ModifiedSineCV,
        "modified sine with a share cv of the span at constant velocity (VDI 2143); cv = 0: modified sine",
        (_CV,),
    ),
    (Vap, "VAP function; near-constant velocity, acceleration jumps at the ends", (_B,)),
    (
        Polynomial,
        "blend polynomial meeting the neighbours' (or the given) s, v, a; least jerk norm when degree > 5",
        (_POLY_DEGREE,),
    ),
    (InclinedSine, "inclined sine (Bestehorn, VDI 2143); takes its end velocities from the neighbours", ()),
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
