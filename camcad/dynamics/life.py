"""Roller and track life: the track roller's rating life and the cam track's surface fatigue.

Pure functions over per-angle arrays from the rigid dynamics (contact force,
relative curvature) and the profile (the arc speed of the contact along it):

- the roller's basic rating life after ISO 281: L10 = (C/P)^p million
  revolutions, P the equivalent load over a cam turn weighted by the roller's
  own revolutions;
- the cam track's surface fatigue after the Cam Design Handbook (Rothbart
  2004, §9): the load-stress factor K = (F/L)·(1/R₁ + 1/R₂) against the
  material's K–N line log₁₀ K = (B − log₁₀ N)/A (eq. 9.15).

A flat or mushroom face slides on the cam: rolling life does not apply to it,
and :func:`camcad.dynamics.rolling.contact_motion` gives its sliding speed instead.

Units: N, mm, MPa, s; cam speed ω [rad/s]; lives in hours.

References
----------
.. [1] ISO 281:2007, Rolling bearings — Dynamic load ratings and rating life,
   §7 (L10 = (C/P)^p, p = 3 ball, 10/3 roller) and §7.2 (equivalent load of a
   varying load, P = (∫F^p dn / ∫dn)^(1/p)).
.. [2] H. A. Rothbart (ed.) (2004), Cam Design Handbook, McGraw-Hill, §9.6:
   load-stress factor K and eq. 9.15, log₁₀ K = (B − log₁₀ N)/A with A, B from
   its Table 9.3 (roll tests of Talbourdet and Buckingham, 10⁸ cycles).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.dynamics._cycle import cycle_weights
from camcad.errors import DesignError
from camcad.findings import Finding, Severity
from camcad.knobs import Knob

__all__ = [
    "BALL_EXPONENT",
    "PSI_PER_MPA",
    "ROLLER_EXPONENT",
    "LifeSpec",
    "LoadStressLine",
    "RollerLife",
    "TrackLife",
    "equivalent_load",
    "life_findings",
    "load_stress_factor",
    "roller_l10",
    "roller_life",
    "roller_turns_per_cam_turn",
    "summary_entry",
    "track_life",
]

ROLLER_EXPONENT = 10.0 / 3.0
"""ISO 281 §7 life exponent p of roller (and needle) bearings."""

BALL_EXPONENT = 3.0
"""ISO 281 §7 life exponent p of ball bearings."""

PSI_PER_MPA = 145.03773773020923
"""1 MPa in psi (lbf/in²): 1 / 0.00689475729316836."""

_SECONDS_PER_HOUR = 3600.0


def _positive(path: str, value: float | None, unit: str) -> None:
    if value is not None and not (math.isfinite(value) and value > 0.0):
        raise DesignError(path, f"must be a positive number [{unit}], got {value!r}")


@dataclass(frozen=True, slots=True, kw_only=True)
class LoadStressLine:
    """A material's surface-fatigue line K–N (Cam Design Handbook §9, eq. 9.15).

    Attributes
    ----------
    name
        The material pair as the source names it.
    slope
        A [1] of eq. 9.15.
    intercept
        B [1] of eq. 9.15 (log₁₀ of cycles, with K in psi as the handbook tabulates).
    source
        Where the constants come from (book, table, or "user").

    Notes
    -----
    log₁₀ K = (B − log₁₀ N)/A  (Rothbart 2004, eq. 9.15), so
    N = 10^(B − A·log₁₀ K) cycles to failure at load-stress factor K [psi].
    """

    name: str = "user"
    slope: float
    intercept: float
    source: str = "user"

    def __post_init__(self) -> None:
        """Check the constants: one-line errors naming the field."""
        _positive(Knob.TRACK_SLOPE, self.slope, "1")
        if not math.isfinite(self.intercept):
            raise DesignError(Knob.TRACK_INTERCEPT, f"must be a finite number, got {self.intercept!r}")

    def cycles(self, factor: ArrayLike) -> FloatArray:
        """Cycles to failure N at load-stress factors K [MPa]; ``inf`` where K ≤ 0 (unloaded)."""
        k_psi = np.asarray(factor, dtype=float) * PSI_PER_MPA
        with np.errstate(divide="ignore"):
            log_n = self.intercept - self.slope * np.log10(np.where(k_psi > 0.0, k_psi, 0.0))
        out: FloatArray = np.power(10.0, log_n)  # Rothbart 2004, eq. 9.15 solved for N
        return out

    def factor(self, cycles: float) -> float:
        """The load-stress factor K [MPa] the material bears for N cycles (eq. 9.15)."""
        k_psi = 10.0 ** ((self.intercept - math.log10(cycles)) / self.slope)  # Rothbart 2004, eq. 9.15
        return float(k_psi / PSI_PER_MPA)


@dataclass(frozen=True, slots=True, kw_only=True)
class LifeSpec:
    """The ``[life]`` table: the track roller's rating and the life wanted.

    Attributes
    ----------
    roller_dynamic_load_rating
        C [N], the basic dynamic load rating from the track roller's catalogue;
        ``None``: no roller life.
    roller_life_exponent
        p: 10/3 for needle and roller bearings, 3 for ball bearings (ISO 281 §7).
    hours_per_day
        Operating hours a day [h]; with it lives are also given in days.
    required_hours
        The life wanted [h] (a soft limit).
    track
        The cam material's K–N line; ``None``: no track life.
    """

    roller_dynamic_load_rating: float | None = None
    roller_life_exponent: float = ROLLER_EXPONENT
    hours_per_day: float | None = None
    required_hours: float | None = None
    track: LoadStressLine | None = None

    def __post_init__(self) -> None:
        """Check every value: one-line errors naming the field."""
        _positive(Knob.ROLLER_LOAD_RATING, self.roller_dynamic_load_rating, "N")
        p = self.roller_life_exponent
        if not (math.isclose(p, BALL_EXPONENT) or math.isclose(p, ROLLER_EXPONENT, rel_tol=1e-6)):
            raise DesignError(
                Knob.ROLLER_LIFE_EXPONENT,
                f"must be 3 (ball bearing) or 10/3 (needle or roller bearing, ISO 281), got {p!r}",
            )
        _positive(Knob.HOURS_PER_DAY, self.hours_per_day, "h")
        if self.hours_per_day is not None and self.hours_per_day > 24.0:
            raise DesignError(Knob.HOURS_PER_DAY, f"must be at most 24 h, got {self.hours_per_day!r}")
        _positive(Knob.REQUIRED_HOURS, self.required_hours, "h")


def roller_turns_per_cam_turn(phi: ArrayLike, arc_speed: ArrayLike, *, roller_radius: float) -> float:
    """Revolutions of a roller in pure rolling per cam turn.

    Parameters
    ----------
    phi
        (n,) sorted cam angles in [0, 2π) [rad].
    arc_speed
        (n,) |dS/dφ| [mm/rad]: the speed of the contact point along the cam
        profile per radian of cam turn (|``profile.d1``|).
    roller_radius
        r_f [mm].

    Returns
    -------
    float
        ∮|dS|/(2π r_f): the profile's arc length over the roller's circumference.

    Notes
    -----
    Rolling without slip, the roller turns relative to the follower by the
    arc it rolls over plus the turn of the contact normal (the pressure angle's
    change) minus the arm's swing; the last two add up to nothing over a cam
    turn, so the count is exact per turn. An eccentric circle of radius R
    gives R/r_f.
    """
    speed = np.abs(np.asarray(arc_speed, dtype=float))
    return float(np.dot(cycle_weights(phi), speed)) / (TWO_PI * roller_radius)


def equivalent_load(force: ArrayLike, weight: ArrayLike, *, exponent: float) -> float:
    """The equivalent load P of a varying load (ISO 281 §7.2).

    Parameters
    ----------
    force
        (n,) load F [N]; F < 0 (contact lost) counts as 0.
    weight
        (n,) dn: the revolutions (or any measure proportional to them) the
        bearing turns through at each sample, e.g. quadrature weight times
        arc speed.
    exponent
        p (3 or 10/3).

    Returns
    -------
    float
        P = (Σ F^p dn / Σ dn)^(1/p) [N] (ISO 281:2007, §7.2); 0 if the bearing does not turn.
    """
    f = np.clip(np.asarray(force, dtype=float), 0.0, None)
    dn = np.asarray(weight, dtype=float)
    total = float(np.sum(dn))
    if total <= 0.0:
        return 0.0
    top = float(f.max()) if f.size else 0.0
    if top <= 0.0:
        return 0.0
    # ISO 281 §7.2, scaled by the largest load so that F^p neither underflows nor overflows
    return top * float((np.dot((f / top) ** exponent, dn) / total) ** (1.0 / exponent))


def roller_l10(rating: float, load: float, *, exponent: float) -> float:
    """Basic rating life L10 = (C/P)^p [million revolutions] (ISO 281:2007, §7); ``inf`` at P = 0."""
    if load <= 0.0:
        return math.inf
    return float((rating / load) ** exponent)  # ISO 281 §7


@dataclass(frozen=True, slots=True, kw_only=True)
class RollerLife:
    """The track roller's rating life.

    Attributes
    ----------
    turns_per_cam_turn
        Roller revolutions per cam turn [1].
    equivalent_load
        P [N] (ISO 281 §7.2), weighted by the roller's revolutions.
    l10_million_revolutions
        L10 = (C/P)^p [10⁶ roller revolutions].
    hours
        L10 at the cam speed [h].
    days
        ``hours / hours_per_day`` or ``None``.
    """

    turns_per_cam_turn: float
    equivalent_load: float
    l10_million_revolutions: float
    hours: float
    days: float | None = None


def roller_life(
    phi: ArrayLike,
    force: ArrayLike,
    arc_speed: ArrayLike,
    *,
    roller_radius: float,
    omega: float,
    spec: LifeSpec,
) -> RollerLife:
    """Rating life of the track roller over the cam's load cycle.

    Parameters
    ----------
    phi
        (n,) sorted cam angles in [0, 2π) [rad].
    force
        (n,) contact force F [N] (the roller's radial load).
    arc_speed
        (n,) |dS/dφ| [mm/rad] of the contact along the profile.
    roller_radius
        r_f [mm].
    omega
        Cam speed ω [rad/s].
    spec
        The ``[life]`` table; needs ``roller_dynamic_load_rating``.

    Returns
    -------
    RollerLife

    Notes
    -----
    In pure rolling the roller turns dn = |dS|/(2π r_f) as the contact runs
    dS along the profile, so P = (∮F^p |dS| / ∮|dS|)^(1/p) (ISO 281 §7.2), and
    L10 = (C/P)^p million revolutions (ISO 281 §7) last
    L10·10⁶ / (turns per cam turn · ω/2π) seconds.
    """
    if spec.roller_dynamic_load_rating is None:
        raise DesignError(Knob.ROLLER_LOAD_RATING, "is needed for the roller's life")
    p = spec.roller_life_exponent
    dn = cycle_weights(phi) * np.abs(np.asarray(arc_speed, dtype=float))
    turns = roller_turns_per_cam_turn(phi, arc_speed, roller_radius=roller_radius)
    load = equivalent_load(force, dn, exponent=p)
    l10 = roller_l10(spec.roller_dynamic_load_rating, load, exponent=p)
    revs_per_second = turns * omega / TWO_PI
    hours = math.inf if revs_per_second <= 0.0 else l10 * 1e6 / revs_per_second / _SECONDS_PER_HOUR
    days = None if spec.hours_per_day is None else hours / spec.hours_per_day
    return RollerLife(
        turns_per_cam_turn=turns,
        equivalent_load=load,
        l10_million_revolutions=l10,
        hours=hours,
        days=days,
    )


def load_stress_factor(force: ArrayLike, *, curvature: ArrayLike, length: float) -> FloatArray:
    """The load-stress factor K = (F/L)·(1/R₁ + 1/R₂) [MPa] (Rothbart 2004, §9.6).

    Parameters
    ----------
    force
        (n,) contact force F [N]; F ≤ 0 gives 0.
    curvature
        (n,) relative curvature 1/R₁ + 1/R₂ [1/mm] (:func:`~camcad.dynamics.contact.contact_curvature`).
    length
        Contact length L [mm].

    Returns
    -------
    FloatArray
        (n,) K [MPa]. With the Hertz peak pressure p₀ = √(F·E*/(π·L·R*)) it is
        K = π·p₀²/E* (Johnson 1985, eq. 4.45).
    """
    load = np.clip(np.asarray(force, dtype=float), 0.0, None)
    out: FloatArray = (
        load / length * np.asarray(curvature, dtype=float)
    )  # Rothbart 2004, §9.6: K = P'(1/R1 + 1/R2)
    readonly(out)
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class TrackLife:
    """The cam track's surface-fatigue life.

    Attributes
    ----------
    factor
        (n,) load-stress factor K [MPa] at each cam angle.
    factor_max
        The largest K [MPa] and ``angle`` [rad] where it acts: the track point
        that fails first (each point of the track is stressed once a cam turn).
    cycles_per_cam_turn
        Stress cycles of a track point per cam turn (1; a conjugate or groove
        flank is a track of its own).
    cycles
        Cycles (cam turns) to failure at ``factor_max`` (eq. 9.15).
    hours
        The same at the cam speed [h].
    days
        ``hours / hours_per_day`` or ``None``.
    flank
        A groove's flank whose point fails first (``"inner"``/``"outer"``), else None.
    """

    factor: FloatArray
    factor_max: float
    angle: float
    cycles_per_cam_turn: float
    cycles: float
    hours: float
    days: float | None = None
    flank: str | None = None


def track_life(
    phi: ArrayLike,
    force: ArrayLike,
    *,
    curvature: ArrayLike,
    length: float,
    omega: float,
    spec: LifeSpec,
) -> TrackLife:
    """Surface-fatigue life of the cam track (Rothbart 2004, §9.6, eq. 9.15).

    Parameters
    ----------
    phi
        (n,) cam angles [rad].
    force, curvature, length
        As in :func:`load_stress_factor`.
    omega
        Cam speed ω [rad/s].
    spec
        The ``[life]`` table; needs ``track``.

    Returns
    -------
    TrackLife

    Notes
    -----
    The point of the track under the contact at φ is stressed once a cam turn
    at K(φ); it fails after N(K(φ)) turns. The first to fail is the point of
    the largest K.
    """
    if spec.track is None:
        raise DesignError(Knob.TRACK_SLOPE, "is needed for the track's life")
    p = np.asarray(phi, dtype=float).ravel()
    k = load_stress_factor(force, curvature=curvature, length=length)
    i = int(np.argmax(k))
    cycles = float(spec.track.cycles(k[i]))
    hours = math.inf if omega <= 0.0 else cycles * TWO_PI / omega / _SECONDS_PER_HOUR
    return TrackLife(
        factor=k,
        factor_max=float(k[i]),
        angle=float(p[i]),
        cycles_per_cam_turn=1.0,
        cycles=cycles,
        hours=hours,
        days=None if spec.hours_per_day is None else hours / spec.hours_per_day,
    )


def life_findings(
    spec: LifeSpec, *, roller: RollerLife | None, track: TrackLife | None
) -> tuple[Finding, ...]:
    """Soft findings where a life falls short of ``required_hours``.

    Parameters
    ----------
    spec
        The ``[life]`` table.
    roller, track
        The lives computed (either may be ``None``).

    Returns
    -------
    tuple[Finding, ...]
        One soft finding per life below ``spec.required_hours`` (none without it).
    """
    need = spec.required_hours
    if need is None:
        return ()
    out: list[Finding] = []
    if roller is not None and roller.hours < need:
        out.append(
            Finding(
                kind="roller life",
                severity=Severity.SOFT,
                field=Knob.ROLLER_LOAD_RATING,
                message=(
                    f"track roller L10 life {roller.hours:.4g} h (equivalent load "
                    f"{roller.equivalent_load:.4g} N, {roller.turns_per_cam_turn:.4g} roller turns a turn) "
                    f"is below the required {need:g} h: "
                    "choose a roller with a larger dynamic load rating, lower the spring load or the speed"
                ),
                value=roller.hours,
                limit=need,
                unit="h",
            )
        )
    if track is not None and track.hours < need:
        out.append(
            Finding(
                kind="track life",
                severity=Severity.SOFT,
                field=Knob.TRACK_SLOPE,
                message=(
                    f"cam track surface-fatigue life {track.hours:.4g} h (load-stress factor "
                    f"{track.factor_max:.4g} MPa at {math.degrees(track.angle):.1f}°) is below the required "
                    f"{need:g} h: a harder material pair, a wider contact or a larger radius of curvature "
                    "there"
                ),
                angle=track.angle,
                value=track.hours,
                limit=need,
                unit="h",
            )
        )
    return tuple(out)


def summary_entry(
    roller: RollerLife | None, track: TrackLife | None, *, sliding_max: float | None
) -> dict[str, Any]:
    """The ``life`` section of ``summary.json`` (plain JSON values; ``inf`` as ``None``).

    Parameters
    ----------
    roller, track
        The lives computed, or ``None``.
    sliding_max
        A flat or mushroom face's largest sliding speed [mm/s] (rolling life
        does not apply to it), else ``None``.
    """

    def num(x: float | None) -> float | None:
        return None if x is None or not math.isfinite(x) else x

    out: dict[str, Any] = {}
    if sliding_max is not None:
        out["rolling_life"] = "does not apply: the face slides on the cam"
        out["sliding_speed_max_mm_per_s"] = sliding_max
    if roller is not None:
        out |= {
            "roller_turns_per_cam_turn": roller.turns_per_cam_turn,
            "roller_equivalent_load_N": roller.equivalent_load,
            "roller_l10_million_revolutions": num(roller.l10_million_revolutions),
            "roller_life_h": num(roller.hours),
            "roller_life_days": num(roller.days),
        }
    if track is not None:
        out |= {
            "track_load_stress_factor_max_MPa": track.factor_max,
            "track_load_stress_factor_angle_deg": round(math.degrees(track.angle) % 360.0, 6),
            **({} if track.flank is None else {"track_load_stress_factor_flank": track.flank}),
            "track_cycles_per_cam_turn": track.cycles_per_cam_turn,
            "track_life_cycles": num(track.cycles),
            "track_life_h": num(track.hours),
            "track_life_days": num(track.days),
        }
    return out
