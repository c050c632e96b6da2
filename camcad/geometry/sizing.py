"""Smallest base radius that meets the pressure-angle and curvature limits."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from camcad.errors import DesignError
from camcad.geometry.cam import Cam

__all__ = ["SizingResult", "feasible_margins", "min_base_radius"]

_RADIUS_TOL_MM = 1e-7
_MAX_RADIUS_MM = 1e5


@dataclass(frozen=True, slots=True, kw_only=True)
class SizingResult:
    """The smallest base radius and what limits it.

    ``limit`` is ``"pressure angle"`` or ``"curvature"``; ``angle`` [rad] is
    the cam angle where that limit is reached at ``base_radius`` [mm].
    """

    base_radius: float
    limit: str
    angle: float
    pressure_angle_max: float  # rad, at base_radius
    curvature_radius_min: float  # mm, smallest convex profile radius at base_radius


def feasible_margins(
    cam: Cam, phi: np.ndarray, *, max_pressure_angle: float, min_curvature_radius: float
) -> tuple[float, float, int, int]:
    """Margins of both limits (≥ 0 is met) and the cam-angle index of each worst case.

    Returns ``(pressure_margin [rad], curvature_margin [mm], i_pressure, i_curvature)``.
    The curvature margin is the smallest convex profile radius minus the
    required one; a roller whose pitch curve is sharper than the roller (an
    undercut) has a negative margin.
    """
    alpha = np.abs(cam.pressure_angle(phi))
    i_alpha = int(np.argmax(alpha))
    if cam.is_roller:
        rho_pitch = cam.pitch(phi).rho
        convex = rho_pitch > 0
        rho_profile = np.where(convex, rho_pitch - cam.roller_radius, np.inf)
    else:
        rho_profile = cam.profile(phi).rho
    i_rho = int(np.argmin(rho_profile))
    margin_rho = float(rho_profile[i_rho]) - min_curvature_radius
    return max_pressure_angle - float(alpha[i_alpha]), margin_rho, i_alpha, i_rho


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
    """Search the smallest base radius [mm] meeting both limits on the sample grid.

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
    half-line: the search doubles an upper bracket, then bisects to 1e-7 mm.
    The result is verified feasible before it is returned.
    """
    phi = cam.sample_phi(step)
    lo = max(abs(cam.offset_e) - cam.roller_radius, 0.0) + _RADIUS_TOL_MM

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
    while hi - lo > _RADIUS_TOL_MM:
        mid = 0.5 * (lo + hi)
        if _ok(at(mid), phi, max_pressure_angle, min_curvature_radius):
            hi = mid
        else:
            lo = mid
    best = at(hi)
    m_alpha, m_rho, i_alpha, i_rho = feasible_margins(
        best, phi, max_pressure_angle=max_pressure_angle, min_curvature_radius=min_curvature_radius
    )
    # the binding limit is the one with the smaller relative margin
    alpha_binding = m_alpha / max(max_pressure_angle, 1e-12) < m_rho / max(min_curvature_radius, 1.0)
    limit, i = ("pressure angle", i_alpha) if alpha_binding else ("curvature", i_rho)
    return SizingResult(
        base_radius=hi,
        limit=limit,
        angle=float(phi[i]),
        pressure_angle_max=max_pressure_angle - m_alpha,
        curvature_radius_min=m_rho + min_curvature_radius,
    )
