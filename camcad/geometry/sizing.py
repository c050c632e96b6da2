"""Smallest base radius that meets the pressure-angle and curvature limits, and the curvature limit itself.

The curvature limit is one rule, applied here for ``camcad size``, by
:func:`camcad.geometry.limits.analyse_geometry` for ``camcad check`` (through
:func:`curvature_finding`) and by ``camcad optimize`` (through
:func:`feasible_margins`): the smallest convex profile radius ρ_min [mm] must
be at least ``cam.min_curvature_radius`` (default 0 for a roller, 1 mm for a
flat face), and above 0 when that is 0 (:func:`meets_curvature`). ρ_min ≤ 0
is an undercut or a cusp, a hard limit; 0 < ρ_min < the required radius is a
soft one (engineering judgement, like the pressure angle). A conjugate pair
is held to both limits on both plates (``conjugate``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from camcad._typing import FloatArray
from camcad.errors import DesignError
from camcad.extremes import Extreme, Side, extremes_rows
from camcad.findings import Finding, Severity
from camcad.geometry.cam import Cam
from camcad.geometry.spec import ConjugateSpec
from camcad.knobs import Knob

__all__ = [
    "SizingResult",
    "curvature_finding",
    "feasible_margins",
    "meets_curvature",
    "min_base_radius",
    "min_pivot_distance",
]

_RADIUS_TOL_MM = 1e-7
_MAX_RADIUS_MM = 1e5
_SCAN_POINTS = 96  # grid over an arm's admissible range before the bisection


@dataclass(frozen=True, slots=True, kw_only=True)
class SizingResult:
    """The smallest base radius and what limits it.

    ``limit`` is ``"pressure angle"`` or ``"curvature"``; ``angle`` [rad] is
    the cam angle where that limit is reached at ``base_radius`` [mm], with
    ``side`` when it is reached as a one-sided limit at a joint.
    """

    base_radius: float  # mm (the design's when the pivot distance was sized)
    limit: str
    angle: float
    side: Side | None  # the limit is reached just before ("left") or after ("right") a joint
    pressure_angle_max: float  # rad, at base_radius
    curvature_radius_min: float  # mm, smallest convex profile radius at base_radius
    pivot_distance: float | None = None  # mm, oscillating followers: d at the result


def meets_curvature(rho_min: float, required: float) -> bool:
    """The curvature limit of every command: ρ_min ≥ ``required`` [mm], and ρ_min > 0 when it is 0.

    ``rho_min`` is the smallest convex profile radius [mm] (negative in a
    loop or cusp); a zero radius is a cusp, so with ``required`` 0 it must be
    strictly positive.
    """
    return rho_min > 0.0 if required == 0.0 else rho_min >= required


def curvature_finding(cam: Cam, worst: Extreme, *, required: float) -> Finding | None:
    """The soft finding for a smallest convex radius ``worst`` [mm] above 0 but below ``required`` [mm].

    None when the limit holds (:func:`meets_curvature`), when ``required`` is 0
    (then only the undercut or cusp applies, a hard limit found by
    :func:`~camcad.geometry.limits.analyse_geometry`) or when ``worst`` is not
    above 0 (that hard limit). The message names the smallest base radius
    that meets the limit (rounded up to 0.01 mm), as ``camcad size`` finds it.
    """
    if required == 0.0 or worst.value <= 0.0 or meets_curvature(worst.value, required):
        return None
    try:
        sized = min_base_radius(cam, min_curvature_radius=required)
        up = math.ceil(sized.base_radius * 100.0) / 100.0  # advice errs to the safe side
        fix = f"use base_radius ≥ {up:.2f} mm (now {cam.base_radius:g} mm)"
    except DesignError:
        fix = "use a gentler motion law"
    return Finding(
        kind="curvature",
        severity=Severity.SOFT,
        field=Knob.MIN_CURVATURE_RADIUS,
        field_first=True,
        message=(
            f"the convex profile radius of curvature falls to {worst.value:.3f} mm "
            f"{worst.where()}, below the required {required:g} mm; {fix}, or lower the limit"
        ),
        angle=worst.phi,
        value=worst.value,
        limit=required,
        unit="mm",
    )


def feasible_margins(
    cam: Cam,
    phi: np.ndarray,
    *,
    max_pressure_angle: float,
    min_curvature_radius: float,
    conjugate: ConjugateSpec | None = None,
) -> tuple[float, float, Extreme, Extreme]:
    """Margins of both limits (≥ 0 is met) at their true extremes, and those extremes.

    Returns ``(pressure_margin [rad], curvature_margin [mm], worst |α|, worst ρ)``.
    The curvature margin is the smallest convex profile radius minus the
    required one; a roller whose pitch curve is sharper than the roller (an
    undercut) has a negative margin. Both extremes are true extremes over the
    turn (:func:`camcad.extremes.extremes`): refined between the samples
    ``phi`` [rad] and taken at both sides of every joint. With ``conjugate``
    (a conjugate pair's second roller) each margin is the smaller of the two
    plates', and each extreme the binding plate's.
    """
    joints = [bp.phi for bp in cam.program.breakpoints]
    plates = [cam] if conjugate is None or conjugate.single_plate else [cam, cam.partner(conjugate)]
    found: list[tuple[Extreme, Extreme]] = []
    for plate in plates:

        def rows(p: FloatArray, side: Side, plate: Cam = plate) -> FloatArray:
            """|α| and the convex profile radius (for a roller: convex pitch ρ − r_f)."""
            st = plate.state(p, side=side)
            return np.vstack((np.abs(st.pressure_angle), plate.loop_radius(st) - plate.roller_radius))

        # on a dwell both rows are constant (the follower stands still): no search there, as in limits
        worst_alpha, worst_rho = extremes_rows(rows, phi, joints, ("max", "min"), rests=plate.rests)
        found.append((worst_alpha, worst_rho))
    worst_alpha = max((a for a, _ in found), key=lambda e: e.value)
    worst_rho = min((r for _, r in found), key=lambda e: e.value)
    margin_rho = worst_rho.value - min_curvature_radius
    return max_pressure_angle - worst_alpha.value, margin_rho, worst_alpha, worst_rho


def _ok(cam: Cam, phi: np.ndarray, alpha_max: float, rho_min: float, conjugate: ConjugateSpec | None) -> bool:
    m_alpha, _, _, worst_rho = feasible_margins(
        cam, phi, max_pressure_angle=alpha_max, min_curvature_radius=rho_min, conjugate=conjugate
    )
    return m_alpha >= 0.0 and meets_curvature(worst_rho.value, rho_min)


def min_base_radius(
    cam: Cam,
    *,
    max_pressure_angle: float = math.pi / 2,
    min_curvature_radius: float = 0.0,
    step: float | None = None,
    conjugate: ConjugateSpec | None = None,
) -> SizingResult:
    """Search the smallest base radius [mm] meeting both limits at their true extremes.

    Parameters
    ----------
    cam
        The cam whose base radius is varied (follower and motion kept).
    max_pressure_angle
        Largest allowed |α| [rad]; π/2 disables the limit.
    min_curvature_radius
        Smallest allowed convex profile radius of curvature [mm]; 0 means
        only "no undercut / no cusp".
    step
        Sampling step [rad]; default the cam's.
    conjugate
        A conjugate pair's second roller: both plates must meet both limits
        (the second plate's radii follow the first's base radius).

    Notes
    -----
    Both margins grow with the base radius (|tan α| = |v − e|/(s + k) and the
    pitch radius of curvature both increase with k), so the feasible set is a
    half-line: the search doubles an upper bracket, then narrows it to 1e-7 mm
    by regula falsi (Illinois) on the relative margin.
    Each trial checks the true extremes (one-sided limits at joints
    included), so a profile that loops only in the last fraction of a degree
    before a joint is not passed. The result is verified feasible before it
    is returned.
    """
    phi = cam.sample_phi(step)
    if cam.follower.guide.pivot is not None:  # an arm
        return _arm_search(cam, phi, "base_radius", max_pressure_angle, min_curvature_radius, conjugate)
    lo = max(abs(cam.eccentricity) - cam.roller_radius, 0.0) + _RADIUS_TOL_MM

    def at(radius: float) -> Cam:
        return replace(cam, base_radius=radius)

    hi = max(cam.base_radius, 1.0)
    while not _ok(at(hi), phi, max_pressure_angle, min_curvature_radius, conjugate):
        lo = hi
        hi *= 2.0
        if hi > _MAX_RADIUS_MM:
            raise DesignError(
                Knob.MAX_PRESSURE_ANGLE,
                f"no base radius up to {_MAX_RADIUS_MM:g} mm meets the limits "
                f"(max pressure angle {math.degrees(max_pressure_angle):g}°, "
                f"min curvature radius {min_curvature_radius:g} mm)",
            )
    if _ok(at(lo), phi, max_pressure_angle, min_curvature_radius, conjugate):
        hi = lo

    def trial(radius: float) -> tuple[bool, float]:
        """Whether ``radius`` meets both limits, and its smaller relative margin."""
        m_a, m_r, _, worst = feasible_margins(
            at(radius),
            phi,
            max_pressure_angle=max_pressure_angle,
            min_curvature_radius=min_curvature_radius,
            conjugate=conjugate,
        )
        ok = m_a >= 0.0 and meets_curvature(worst.value, min_curvature_radius)
        return ok, min(m_a / max(max_pressure_angle, 1e-12), m_r / max(min_curvature_radius, 1.0))

    # Illinois regula falsi on the (continuous, increasing) relative margin, keeping the
    # bracket lo infeasible < hi feasible; a bisection step wherever the secant is unusable.
    f_lo, f_hi, kept = trial(lo)[1], trial(hi)[1], 0
    while hi - lo > _RADIUS_TOL_MM:
        x = hi - f_hi * (hi - lo) / (f_hi - f_lo) if math.isfinite(f_lo) and f_hi != f_lo else math.nan
        if abs(kept) > 2 or not lo + 0.25 * _RADIUS_TOL_MM < x < hi - 0.25 * _RADIUS_TOL_MM:
            x, kept = 0.5 * (lo + hi), 0  # the secant creeps from one side or is unusable: bisect
        ok, f_x = trial(x)
        if ok:
            hi, f_hi = x, f_x
            f_lo, kept = (0.5 * f_lo if kept < 0 else f_lo), min(kept, 0) - 1
        else:
            lo, f_lo = x, f_x
            f_hi, kept = (0.5 * f_hi if kept > 0 else f_hi), max(kept, 0) + 1
    best = at(hi)
    m_alpha, m_rho, worst_alpha, worst_rho = feasible_margins(
        best,
        phi,
        max_pressure_angle=max_pressure_angle,
        min_curvature_radius=min_curvature_radius,
        conjugate=conjugate,
    )
    # the binding limit is the one with the smaller relative margin
    alpha_binding = m_alpha / max(max_pressure_angle, 1e-12) < m_rho / max(min_curvature_radius, 1.0)
    limit, worst = ("pressure angle", worst_alpha) if alpha_binding else ("curvature", worst_rho)
    return SizingResult(
        base_radius=hi,
        limit=limit,
        angle=worst.phi,
        side=worst.side,
        pressure_angle_max=max_pressure_angle - m_alpha,
        curvature_radius_min=m_rho + min_curvature_radius,
    )


def min_pivot_distance(
    cam: Cam,
    *,
    max_pressure_angle: float = math.pi / 2,
    min_curvature_radius: float = 0.0,
    step: float | None = None,
    conjugate: ConjugateSpec | None = None,
) -> SizingResult:
    """The smallest pivot distance d [mm] of an oscillating follower meeting both limits, at the cam's r_b.

    See :func:`min_base_radius` for the limits and :func:`_arm_search` for the search.
    """
    if cam.follower.guide.pivot is None:
        raise DesignError(Knob.FOLLOWER_TYPE, "sizing the pivot distance needs an oscillating follower")
    phi = cam.sample_phi(step)
    return _arm_search(cam, phi, "pivot_distance", max_pressure_angle, min_curvature_radius, conjugate)


def _arm_search(
    cam: Cam, phi: FloatArray, knob: str, alpha_max: float, rho_min: float, conjugate: ConjugateSpec | None
) -> SizingResult:
    """Smallest r_b or d of an oscillating follower meeting both limits at their true extremes.

    For an arm neither limit is monotonic in r_b or d (the pressure angle at a
    dwell is atan((d·cos β − l)/(d·sin β)), zero at one geometry and growing on
    both sides of it), so the feasible set need not be a half-line: the search
    scans the admissible range (the arm reaches the base circle and swings
    clear, the follower kind's ``check``) on a grid of
    ``_SCAN_POINTS`` and the design's own value, and bisects to 1e-7 mm between
    the last infeasible and the first feasible grid value. Feasible sets
    narrower than the grid step are not found unless they hold the design's
    own value (the error says so); a design that meets the limits always has
    an answer, at or below its own value.
    """
    fol = cam.follower_spec
    swing = float(np.max(cam.motion(phi).s))
    r_f = cam.roller_radius
    d = fol.pivot_distance or 0.0
    arm = fol.arm_length or 0.0
    if knob == "base_radius":
        hi = d - _RADIUS_TOL_MM
        if fol.arm_length is not None:
            hi = min(hi, d + arm - r_f)
            lo = max(abs(d - arm) - r_f, 0.0)
        else:
            lo = 0.0
    else:
        r0 = cam.base_radius + r_f
        lo = max(cam.base_radius, abs(r0 - arm) if fol.arm_length is not None else abs(cam.base_radius))
        hi = r0 + arm if fol.arm_length is not None else 20.0 * (cam.base_radius + abs(fol.face_offset) + 1.0)

    def make(x: float) -> Cam | None:
        trial = (
            replace(cam, base_radius=x)
            if knob == "base_radius"
            else replace(cam, follower_spec=replace(fol, pivot_distance=x))
        )
        if trial.follower_spec.kind.check(trial.follower_spec, trial.base_radius, swing) is not None:
            return None
        return trial

    def ok(x: float) -> bool:
        trial = make(x)
        return trial is not None and _ok(trial, phi, alpha_max, rho_min, conjugate)

    # the design's own value joins the grid: a design that meets the limits (an optimum, where the
    # feasible set can be a sliver narrower than the grid step) always has an answer at or below it
    own = cam.base_radius if knob == "base_radius" else d
    grid = np.linspace(lo, hi, _SCAN_POINTS)[1:]
    if lo < own < hi:
        grid = np.unique(np.append(grid, own))
    previous = x = lo
    for x in grid:
        if ok(float(x)):
            break
        previous = float(x)
    else:
        raise DesignError(
            Knob.PIVOT_DISTANCE if knob == "pivot_distance" else Knob.MAX_PRESSURE_ANGLE,
            f"no {knob} between {lo:.3f} and {hi:.3f} mm meets the limits (max pressure angle "
            f"{math.degrees(alpha_max):g}°, min curvature radius {rho_min:g} mm) at this "
            + ("pivot and arm" if knob == "base_radius" else "base radius"),
        )
    bad, good = previous, float(x)
    while good - bad > _RADIUS_TOL_MM:
        mid = 0.5 * (bad + good)
        bad, good = (bad, mid) if ok(mid) else (mid, good)
    best = make(good)
    assert best is not None
    m_alpha, m_rho, worst_alpha, worst_rho = feasible_margins(
        best, phi, max_pressure_angle=alpha_max, min_curvature_radius=rho_min, conjugate=conjugate
    )
    alpha_binding = m_alpha / max(alpha_max, 1e-12) < m_rho / max(rho_min, 1.0)
    limit, worst = ("pressure angle", worst_alpha) if alpha_binding else ("curvature", worst_rho)
    if make(bad) is None:  # below the result the arm cannot be built at all
        limit = "arm geometry (the arm must reach the base circle and swing clear)"
    return SizingResult(
        base_radius=best.base_radius,
        limit=limit,
        angle=worst.phi,
        side=worst.side,
        pressure_angle_max=alpha_max - m_alpha,
        curvature_radius_min=m_rho + rho_min,
        pivot_distance=best.follower_spec.pivot_distance,
    )
