"""The law interface shared by every displacement law, and small numeric helpers."""

from __future__ import annotations

import difflib
import math
import numbers
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly

__all__ = ["DUDLEY_MAX_DEGREE", "Derivatives", "Law", "LawInfo", "LawParameter"]

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

    @property
    def knots(self) -> tuple[float, ...]:
        """Interior x where the law switches formula but stays smooth through y‴ (a spline's knots).

        Not joints: nothing jumps there. ``MotionProgram.smooth_knots`` lists
        them in φ, for quadratures that converge fastest split there.
        """
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


def _finish(shape: tuple[int, ...], *arrays: ArrayLike) -> Derivatives:
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
