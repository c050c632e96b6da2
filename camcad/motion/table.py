"""Point tables: a lift measured or given point by point, smoothed into an exact motion law.

``law = "table"`` reads angle [°] → lift [mm, or ° of swing on an arm]
(optionally a velocity column ds/dφ [mm/rad]) over the whole turn. The motion
is the periodic quintic smoothing spline through the points (FITPACK's
``percur`` via :func:`scipy.interpolate.make_splrep`), so s, v, a and the
jerk j are continuous everywhere and known exactly at any angle. The
smoothing is set by the stated measurement noise σ: weights 1/σ and the
smoothing factor S = m (Dierckx 1993, §5.2.1: with w = 1/σ the residual sum
Σ (r/σ)² should be about m, the number of points).

The fit reports its residuals and flags the points where the *table's own*
acceleration or jerk (its second and third divided differences) departs from
the smooth law's by more than the stated noise can explain (4 standard
deviations of that difference under noise σ): spikes from a bad point, or a
noise stated too small.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.errors import DesignError
from camcad.motion._lawbase import Derivatives, Law, _as_x, _finish

__all__ = [
    "MAX_TABLE_POINTS",
    "MAX_TABLE_VALUE",
    "TableFit",
    "TableFlag",
    "TableLaw",
    "parse_table_text",
    "smooth_table",
    "table_scatter",
    "table_summary",
]

MAX_TABLE_POINTS = 36_000
"""Most rows a point table may have (one every 0.01°)."""
MIN_TABLE_POINTS = 12
"""Fewest rows: a periodic quintic needs a dozen points to be determined at all."""
FLAG_SIGMAS = 4.0
"""A difference beyond this many standard deviations of what the noise explains is flagged."""


class SegmentLike(Protocol):
    """Anything with a ``law`` (a :class:`~camcad.motion.segments.SegmentSpec`)."""

    @property
    def law(self) -> Law | None:
        """The segment's law."""
        ...


@dataclass(frozen=True, slots=True, kw_only=True)
class TableFlag:
    """One implausible place in a point table.

    Attributes
    ----------
    angle
        Cam angle of the table row [rad].
    quantity
        ``"lift"`` (residual), ``"acceleration"`` or ``"jerk"``.
    value
        The table's own value there, minus the smooth law's: residual [mm],
        second divided difference [mm/rad²] or third [mm/rad³].
    limit
        What the stated noise explains (``FLAG_SIGMAS`` standard deviations), same unit.
    """

    angle: float
    quantity: str
    value: float
    limit: float

    def describe(self, unit: str = "mm") -> str:
        """One line, e.g. ``'41.0°: acceleration off by +3.1 mm/rad² (noise explains 0.8)'``."""
        power = {"lift": "", "acceleration": "/rad²", "jerk": "/rad³"}[self.quantity]
        what = "lift" if self.quantity == "lift" else f"table {self.quantity}"
        shown = "°" if unit == "deg" else unit  # an arm's lift is in degrees of swing
        return (
            f"{math.degrees(self.angle):.3f}°: {what} off the smooth law by {self.value:+.4g} {shown}{power} "
            f"(the stated noise explains {self.limit:.3g})"
        )


@dataclass(frozen=True, slots=True, kw_only=True)
class TableFit:
    """What the smoothing did: residuals per point, their size, and the flagged places.

    Attributes
    ----------
    angle
        (m,) table angles [rad].
    residual
        (m,) table lift minus smooth law [mm].
    noise
        The stated noise σ [mm].
    flags
        Implausible places, in angle order.
    velocity_residual
        (m,) table velocity minus the law's [mm/rad], when the table has a velocity column.
    """

    angle: FloatArray
    residual: FloatArray
    noise: float
    flags: tuple[TableFlag, ...]
    velocity_residual: FloatArray | None = None

    @property
    def rms(self) -> float:
        """Root mean square of the residuals [mm]."""
        return float(np.sqrt(np.mean(self.residual**2)))

    @property
    def worst(self) -> tuple[float, float]:
        """(largest |residual| [mm], its angle [rad])."""
        i = int(np.argmax(np.abs(self.residual)))
        return float(abs(self.residual[i])), float(self.angle[i])


@functools.lru_cache(maxsize=16)
def _critical(
    knot_vector: tuple[float, ...], coefficients: tuple[float, ...]
) -> tuple[float, tuple[float, float]]:
    """:attr:`TableLaw.peak` and :attr:`TableLaw.trough` of one spline, kept for the spline's next designs.

    A sweep parses one table once per variant: its spline, and so these
    (a root finder's work), are the same each time.
    """
    from scipy.interpolate import BSpline, PPoly

    spline = BSpline(np.asarray(knot_vector), np.asarray(coefficients), 5, extrapolate="periodic")
    roots = PPoly.from_spline(spline.derivative()).roots(extrapolate=False)  # where v = 0
    roots = roots[np.isfinite(roots)]
    knots = np.asarray(knot_vector)
    peak = float(np.max(spline(np.concatenate([roots, knots]))))
    interior = knots[5:-5]  # the knots_phi of TableLaw
    phi = np.mod(np.concatenate([roots, interior]), TWO_PI)
    s = spline(phi)
    i = int(np.argmin(s))
    return peak, (float(s[i]), float(phi[i]))


@dataclass(frozen=True, slots=True, kw_only=True)
class TableLaw(Law):
    """The smoothing spline of a point table, as a law over the whole turn.

    Unlike the normalised laws, ``evaluate`` returns the displacement itself
    [mm] at x = φ/2π and its x-derivatives (the program scales them by
    β = 2π and h = 1).

    Attributes
    ----------
    knot_vector, coefficients
        The periodic quintic B-spline s(φ), φ in rad.
    source
        The table's name for messages and the report (the file name).
    fit
        Residuals and flags (not part of equality).
    """

    name: ClassVar[str] = "table"
    knot_vector: tuple[float, ...]
    coefficients: tuple[float, ...]
    source: str = ""
    fit: TableFit | None = field(default=None, compare=False, hash=False, repr=False)

    def _spline(self) -> Any:
        """The law as SciPy's periodic quintic BSpline (imported here: only tables need SciPy's splines)."""
        from scipy.interpolate import BSpline

        return BSpline(np.asarray(self.knot_vector), np.asarray(self.coefficients), 5, extrapolate="periodic")

    def evaluate(self, x: ArrayLike) -> Derivatives:
        """Evaluate s [mm] and its x-derivatives at x = φ/2π (see the class notes)."""
        xa = _as_x(x)
        spline = self._spline()
        phi = TWO_PI * xa
        out = [spline(phi, nu=m) * TWO_PI**m for m in range(4)]  # d/dx = 2π d/dφ
        return _finish(xa.shape, *out)

    @property
    def peak(self) -> float:
        """Largest displacement of the smooth law [mm]: the spline at the roots of its velocity."""
        return _critical(self.knot_vector, self.coefficients)[0]

    @property
    def trough(self) -> tuple[float, float]:
        """(smallest displacement [mm], its angle [rad]): the spline at its velocity's roots and its knots.

        Exact to the root finder: s is a quintic on each knot span, so its
        minimum lies at a root of the quartic v = ds/dφ or at a span's end.
        """
        return _critical(self.knot_vector, self.coefficients)[1]

    @property
    def knots(self) -> tuple[float, ...]:
        """The spline's distinct interior knots as x = φ/2π in (0, 1) (C4 there: s, v, a, j continuous)."""
        t = np.unique(np.mod(np.asarray(self.knots_phi), TWO_PI)) / TWO_PI
        return tuple(float(x) for x in t if 0.0 < x < 1.0)

    @property
    def knots_phi(self) -> tuple[float, ...]:
        """The spline's knot vector over one period [rad]."""
        k = 5
        return self.knot_vector[k:-k]

    @property
    def zero_at_start(self) -> tuple[int, ...]:
        """Nothing is forced to 0 at φ = 0; the law is periodic and smooth there."""
        return ()

    def describe(self) -> str:
        """Return e.g. ``"point table lift.csv (360 points, σ = 0.005)"``."""
        if self.fit is None:
            return f"point table {self.source}".strip()
        return f"point table {self.source} ({self.fit.angle.size} points, σ = {self.fit.noise:g})".strip()


MAX_TABLE_VALUE = 1e4
"""Largest |angle|, |lift| or |velocity| a table cell may hold (a 10 m part: the design's length bound)."""


def parse_table_text(text: str, *, where: str = "file") -> tuple[FloatArray, FloatArray, FloatArray | None]:
    """Read the rows of a point table (see :func:`_parse_table_text`); read once per text and field.

    A sweep validates many variants of one design, each reading the same
    table: the read-only arrays of the first reading are handed out again.
    """
    return _parse_kept(text, where)


@functools.lru_cache(maxsize=16)
def _parse_kept(text: str, where: str) -> tuple[FloatArray, FloatArray, FloatArray | None]:
    return _parse_table_text(text, where=where)


def _parse_table_text(text: str, *, where: str = "file") -> tuple[FloatArray, FloatArray, FloatArray | None]:
    """Read the rows of a point table: angle [°], lift, optional velocity; further columns ignored.

    Parameters
    ----------
    text
        CSV text (commas, semicolons, tabs or spaces); an optional header line
        (any first line that is not numbers); ``#`` starts a comment.
    where
        Field path for errors (``motion[0].file``).

    Returns
    -------
    tuple
        (angle [rad], lift, velocity or None), each (m,) read-only.

    Raises
    ------
    DesignError
        Naming ``where``, the line and the field (column) number and what was
        expected. The message never repeats the file's text: the file may be
        one the user did not mean to show (issue 32).
    """
    rows: list[list[float]] = []
    lines: list[int] = []  # the line number of each row
    widths: set[int] = set()
    first_data = True
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        cells = [c for c in line.replace(";", ",").replace("\t", ",").replace(" ", ",").split(",") if c]
        values: list[float] = []
        column = 0  # the first cell that is not a number (1-based), 0 if none
        for k, cell in enumerate(cells, start=1):
            try:
                values.append(float(cell))
            except ValueError:
                column = k
                break
        if column:
            if first_data and not rows:
                first_data = False
                continue  # the header
            raise DesignError(
                where, f"line {number}, field {column}: expected a number (the text is not one)"
            )
        first_data = False
        if len(values) < 2:
            raise DesignError(where, f"line {number}: needs angle and lift, got {len(values)} value")
        for column, v in enumerate(values[:3], start=1):
            if not abs(v) <= MAX_TABLE_VALUE:  # also NaN
                what = ("angle [°]", "lift", "velocity")[column - 1]
                raise DesignError(
                    where,
                    f"line {number}, field {column} ({what}): expected a finite number of magnitude at "
                    f"most {MAX_TABLE_VALUE:g}",
                )
        widths.add(min(len(values), 3))
        rows.append(values[:3])
        lines.append(number)
        if len(rows) > MAX_TABLE_POINTS:
            raise DesignError(where, f"more than {MAX_TABLE_POINTS} rows; allowed: at most one per 0.01°")
    if len(widths) > 1:
        raise DesignError(where, "rows have different numbers of columns (angle, lift[, velocity])")
    if len(rows) < MIN_TABLE_POINTS:
        raise DesignError(where, f"{len(rows)} rows; allowed: at least {MIN_TABLE_POINTS} over the turn")
    data = np.asarray(rows, dtype=float)
    angle_deg = data[:, 0]
    outside = np.flatnonzero((angle_deg < 0.0) | (angle_deg > 360.0))
    if outside.size:
        raise DesignError(where, f"line {lines[outside[0]]}, field 1 (angle): expected 0° to 360°")
    if np.any(np.diff(angle_deg) <= 0.0):
        bad = int(np.argmax(np.diff(angle_deg) <= 0.0)) + 1
        raise DesignError(
            where, f"angles must increase; line {lines[bad]}, field 1 (angle) is not above the row before"
        )
    lift, velocity = data[:, 1], data[:, 2] if data.shape[1] > 2 else None
    if angle_deg[-1] == 360.0:  # the closing row repeats the first: it must agree, then it is dropped
        if angle_deg[0] != 0.0 or abs(lift[-1] - lift[0]) > 1e-9 * max(1.0, abs(lift[0])):
            raise DesignError(where, "a row at 360° must repeat the row at 0° (the table is periodic)")
        angle_deg, lift = angle_deg[:-1], lift[:-1]
        velocity = velocity[:-1] if velocity is not None else None
    angle = np.radians(angle_deg)
    out = (np.array(angle), np.array(lift), None if velocity is None else np.array(velocity))
    readonly(*(a for a in out if a is not None))
    return out


def _divided(phi: FloatArray, y: FloatArray, order: int) -> tuple[FloatArray, FloatArray]:
    """Periodic centred divided differences of ``order`` and their weights on y, as (value·k!, weights)."""
    m = phi.size
    span = order + 1
    offsets = np.arange(span) - order // 2  # centred stencil
    idx = (np.arange(m)[:, None] + offsets[None, :]) % m
    wraps = np.floor_divide(np.arange(m)[:, None] + offsets[None, :], m)
    x = phi[idx] + TWO_PI * wraps  # unwrap the angles of the stencil
    weights = np.ones((m, span))
    for i in range(span):
        for k in range(span):
            if k != i:
                weights[:, i] /= x[:, i] - x[:, k]
    weights *= math.factorial(order)  # f[x0..xn]·n! → the order-th derivative
    return np.sum(weights * y[idx], axis=1), weights


SCATTER_MIN_POINTS = 1000
"""Rows from which :func:`table_scatter` measures the noise alone (steps under 0.36°)."""


def table_scatter(angle: FloatArray, lift: FloatArray) -> float:
    """A robust estimate of the table's scatter σ̂ [mm] from its sixth divided differences.

    Under noise σ alone the sixth divided difference at row i has the
    standard deviation σ·√Σw² (w its weights on the rows), so z = d/√Σw²
    scatters with σ; σ̂ = 1.4826·median|z| (the normal consistency factor of
    the median absolute deviation; a difference-based variance estimate in
    the manner of Gasser, Sroka & Jennen-Steinmetz 1986), robust to the few
    stencils that straddle a joint or a misread point. A smooth law's own
    sixth difference is h⁶·s⁽⁶⁾, far below any stated noise for steps under
    0.36° (:data:`SCATTER_MIN_POINTS` rows); on coarser tables σ̂ also holds
    the law's shape.
    """
    diff, w = _divided(np.asarray(angle, dtype=float), np.asarray(lift, dtype=float), 6)
    z = diff / np.sqrt(np.sum(w**2, axis=1))
    return 1.4826 * float(np.median(np.abs(z)))


def smooth_table(
    angle: FloatArray, lift: FloatArray, *, noise: float, velocity: FloatArray | None = None, source: str = ""
) -> TableLaw:
    """:func:`_smooth_table`, fitted once per table, noise and source (a sweep's variants share it)."""

    def bits(a: FloatArray | None) -> bytes | None:
        return None if a is None else np.ascontiguousarray(a, dtype=float).tobytes()

    return _smooth_kept(bits(angle), bits(lift), repr(float(noise)), bits(velocity), source)


@functools.lru_cache(maxsize=16)
def _smooth_kept(
    angle: bytes | None, lift: bytes | None, noise: str, velocity: bytes | None, source: str
) -> TableLaw:
    def array(b: bytes | None) -> FloatArray | None:
        return None if b is None else np.frombuffer(b, dtype=float)

    a, y = array(angle), array(lift)
    assert a is not None and y is not None
    return _smooth_table(a, y, noise=float(noise), velocity=array(velocity), source=source)


def _smooth_table(
    angle: FloatArray, lift: FloatArray, *, noise: float, velocity: FloatArray | None = None, source: str = ""
) -> TableLaw:
    """The periodic quintic smoothing spline of a point table, with residuals and flags.

    Parameters
    ----------
    angle
        (m,) strictly increasing cam angles in [0, 2π) [rad].
    lift
        (m,) displacement [mm] (or degrees of swing).
    noise
        Measurement noise σ [mm], > 0: the spline passes within about σ of
        the points (Σ (r/σ)² ≈ m).
    velocity
        Optional (m,) measured ds/dφ [mm/rad], compared with the law's.
    source
        A name for messages.

    Returns
    -------
    TableLaw
        The law; ``law.fit`` has the residuals and flags.
    """
    phi = np.asarray(angle, dtype=float)
    y = np.asarray(lift, dtype=float)
    m = phi.size
    x = np.append(phi, phi[0] + TWO_PI)
    yy = np.append(y, y[0])
    weights = np.full(x.size, 1.0 / noise)
    from scipy.interpolate import BSpline, make_splrep

    spline = make_splrep(x, yy, w=weights, k=5, s=float(m), bc_type="periodic")  # Dierckx: S = m for w = 1/σ
    knots, coefficients = spline.t, spline.c
    law_spline = BSpline(knots, coefficients, 5, extrapolate="periodic")
    smooth = law_spline(phi)
    residual = y - smooth
    flags: list[TableFlag] = []
    limit = FLAG_SIGMAS * noise
    for i in np.flatnonzero(np.abs(residual) > limit):
        flags.append(TableFlag(angle=float(phi[i]), quantity="lift", value=float(residual[i]), limit=limit))
    for order, quantity in ((2, "acceleration"), (3, "jerk")):
        diff, w = _divided(phi, residual, order)  # table's difference minus the law's = difference of r
        spread = FLAG_SIGMAS * noise * np.sqrt(np.sum(w**2, axis=1))  # its std under noise σ alone
        centre = (np.arange(m) + 0) % m
        for i in np.flatnonzero(np.abs(diff) > spread):
            flags.append(
                TableFlag(
                    angle=float(phi[centre[i]]),
                    quantity=quantity,
                    value=float(diff[i]),
                    limit=float(spread[i]),
                )
            )
    flags.sort(key=lambda f: (f.angle, f.quantity))
    vres = None
    if velocity is not None:
        vres = np.asarray(velocity, dtype=float) - law_spline(phi, nu=1)
        readonly(vres)
    phi_ro, res_ro = np.array(phi), np.array(residual)
    readonly(phi_ro, res_ro)
    fit = TableFit(
        angle=phi_ro, residual=res_ro, noise=float(noise), flags=tuple(flags), velocity_residual=vres
    )
    return TableLaw(
        knot_vector=tuple(float(t) for t in knots),
        coefficients=tuple(float(c) for c in coefficients),
        source=source,
        fit=fit,
    )


def table_summary(segments: Sequence[SegmentLike], unit: str = "mm") -> dict[str, Any]:
    """What ``summary.json`` (and the report) say about a point table: residuals and flags.

    Empty when no segment is a point table. ``unit`` is the lift's (``mm`` or ``deg``).
    """
    for seg in segments:
        law = seg.law
        if isinstance(law, TableLaw) and law.fit is not None:
            fit = law.fit
            worst, where = fit.worst
            out: dict[str, Any] = {
                "table_file": law.source,
                "table_points": int(fit.angle.size),
                f"table_noise_{unit}": fit.noise,
                f"table_residual_rms_{unit}": fit.rms,
                f"table_residual_max_{unit}": worst,
                "table_residual_max_angle_deg": math.degrees(where),
                "table_flags": [f.describe(unit) for f in fit.flags],
            }
            if fit.velocity_residual is not None:
                out[f"table_velocity_residual_max_{unit}_per_rad"] = float(
                    np.max(np.abs(fit.velocity_residual))
                )
            return out
    return {}
