"""Smallest base radius that meets the pressure-angle and curvature limits."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from camcad._typing import FloatArray
from camcad.errors import DesignError
from camcad.extremes import Extreme, Side, extremes_rows
from camcad.geometry.cam import Cam

__all__ = ["SizingResult", "feasible_margins", "min_base_radius"]

_RADIUS_TOL_MM = 1e-7
_MAX_RADIUS_MM = 1e5


@dataclass(frozen=True, slots=True, kw_only=True)
class SizingResult:
    """The smallest base radius and what limits it.

    ``limit`` is ``"pressure angle"`` or ``"curvature"``; ``angle`` [rad] is
    the cam angle where that limit is reached at ``base_radius`` [mm], with
    ``side`` when it is reached as a one-sided limit at a joint.
    """

    base_radius: float
    limit: str
    angle: float
    side: Side | None  # the limit is reached just before ("left") or after ("right") a joint
    pressure_angle_max: float  # rad, at base_radius
    curvature_radius_min: float  # mm, smallest convex profile radius at base_radius


def feasible_margins(
    cam: Cam, phi: np.ndarray, *, max_pressure_angle: float, min_curvature_radius: float
) -> tuple[float, float, Extreme, Extreme]:
    """Margins of both limits (≥ 0 is met) at their true extremes, and those extremes.

    Returns ``(pressure_margin [rad], curvature_margin [mm], worst |α|, worst ρ)``.
    The curvature margin is the smallest convex profile radius minus the
    required one; a roller whose pitch curve is sharper than the roller (an
    undercut) has a negative margin. Both extremes are true extremes over the
    turn (:func:`camcad.extremes.extremes`): refined between the samples
    ``phi`` [rad] and taken at both sides of every joint.
    """
    joints = [bp.phi for bp in cam.program.breakpoints]

    def rows(p: FloatArray, side: Side) -> FloatArray:
        """|α| and the convex profile radius (for a roller: convex pitch ρ − r_f)."""
        st = cam.state(p, side=side)
        return np.vstack((np.abs(st.pressure_angle), cam.loop_radius(st) - cam.roller_radius))

    worst_alpha, worst_rho = extremes_rows(rows, phi, joints, ("max", "min"))
    margin_rho = worst_rho.value - min_curvature_radius
    return max_pressure_angle - worst_alpha.value, margin_rho, worst_alpha, worst_rho


def _ok(cam: Cam, phi: np.ndarray, alpha_max: float, rho_min: float) -> bool:
    m_alpha, m_rho, _, _ = feasible_margins(
        cam, phi, max_pressure_angle=alpha_max, min_curvature_radius=rho_min
    )
    # a zero convex radius is a cusp: strictly positive is required
    return m_alpha >= 0.0 and (m_rho > 0.0 if rho_min == 0.0 else m_rho >= 0.0)


def min_base_radius(
    cam: Cam,
    *,
    max_pressure_angle: float = math.pi / 2,
    min_curvature_radius: float = 0.0,
    step: float | None = None,
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
    lo = max(abs(cam.eccentricity) - cam.roller_radius, 0.0) + _RADIUS_TOL_MM

    def at(radius: float) -> Cam:
        return replace(cam, base_radius=radius)

    hi = max(cam.base_radius, 1.0)
    while not _ok(at(hi), phi, max_pressure_angle, min_curvature_radius):
        lo = hi
        hi *= 2.0
        if hi > _MAX_RADIUS_MM:
            raise DesignError(
                "cam.max_pressure_angle",
                f"no base radius up to {_MAX_RADIUS_MM:g} mm meets the limits "
                f"(max pressure angle {math.degrees(max_pressure_angle):g}°, "
                f"min curvature radius {min_curvature_radius:g} mm)",
            )
    if _ok(at(lo), phi, max_pressure_angle, min_curvature_radius):
        hi = lo

    def trial(radius: float) -> tuple[bool, float]:
        """Whether ``radius`` meets both limits, and its smaller relative margin."""
        m_a, m_r, _, _ = feasible_margins(
            at(radius), phi, max_pressure_angle=max_pressure_angle, min_curvature_radius=min_curvature_radius
        )
        ok = m_a >= 0.0 and (m_r > 0.0 if min_curvature_radius == 0.0 else m_r >= 0.0)  # ρ = 0: a cusp
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
        best, phi, max_pressure_angle=max_pressure_angle, min_curvature_radius=min_curvature_radius
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
