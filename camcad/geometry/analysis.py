"""Geometry analysis of a cam: the sampled curves, limits, undercut and findings."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.angles import flagged_ranges, format_ranges
from camcad.errors import UndercutError
from camcad.geometry.cam import Cam
from camcad.geometry.curves import CurveSample
from camcad.geometry.sizing import min_base_radius

__all__ = ["GeometryAnalysis", "Undercut", "analyse_geometry", "undercut_error"]

_SUGGEST_ROUND_MM = 0.01


@dataclass(frozen=True, slots=True, kw_only=True)
class Undercut:
    """Where the profile loops (roller) or has a cusp (flat face).

    ``ranges`` are cam-angle ranges [rad]; ``worst`` is the smallest convex
    pitch radius [mm] (roller) or the most negative profile radius (flat),
    at cam angle ``worst_angle`` [rad].
    """

    ranges: tuple[tuple[float, float], ...]
    worst: float
    worst_angle: float


@dataclass(frozen=True, slots=True, kw_only=True)
class GeometryAnalysis:
    """A cam's geometry sampled over one turn, with its limits checked.

    Arrays are (n,) over ``phi`` [rad]; ``pressure_angle`` rad; radii mm.
    """

    cam: Cam
    phi: FloatArray
    s: FloatArray
    pitch: CurveSample
    profile: CurveSample
    pressure_angle: FloatArray
    max_pressure_angle: float  # rad, the design limit
    undercut: Undercut | None
    warnings: tuple[str, ...]
    face_width_min: float | None  # mm, flat follower only

    @property
    def profile_radius(self) -> FloatArray:
        """(n,) polar radius of the contact point [mm]."""
        return np.hypot(self.profile.point[:, 0], self.profile.point[:, 1])

    def summary(self) -> dict[str, Any]:
        """The ``geometry`` section of summary.json (angles in degrees, lengths mm)."""
        alpha = np.abs(self.pressure_angle)
        i = int(np.argmax(alpha))
        rho = self.profile.rho
        convex = rho > 0
        concave = rho < 0
        radius = self.profile_radius
        out: dict[str, Any] = {
            "pressure_angle_max_deg": math.degrees(float(alpha[i])),
            "pressure_angle_max_angle_deg": math.degrees(float(self.phi[i])),
            "profile_radius_min_mm": float(radius.min()),
            "profile_radius_max_mm": float(radius.max()),
            "curvature_radius_min_mm": float(rho[convex].min()) if convex.any() else None,
            "curvature_radius_min_angle_deg": (
                math.degrees(float(self.phi[convex][np.argmin(rho[convex])])) if convex.any() else None
            ),
            "concave_radius_min_mm": float(-rho[concave].max()) if concave.any() else None,
            "undercut": self.undercut is not None,
            "warnings": list(self.warnings),
        }
        if self.face_width_min is not None:
            out["face_width_min_mm"] = self.face_width_min
        return out


def analyse_geometry(
    cam: Cam, *, max_pressure_angle: float, face_width: float | None = None, step: float | None = None
) -> GeometryAnalysis:
    """Sample the cam and check its limits.

    Parameters
    ----------
    cam
        The cam.
    max_pressure_angle
        Design limit on |α| [rad]; exceeding it is a warning, not an error.
    face_width
        Flat-follower face width [mm] to check against the minimum, if given.
    step
        Sampling step [rad]; default the cam's (0.1°). Breakpoints are always samples.
    """
    phi = cam.sample_phi(step)
    motion = cam.motion(phi)
    pitch = cam.pitch(phi)
    profile = cam.profile(phi)
    alpha = cam.pressure_angle(phi)
    warnings: list[str] = []

    over = np.abs(alpha) > max_pressure_angle
    if over.any():
        worst = float(np.abs(alpha).max())
        warnings.append(
            f"pressure angle reaches {math.degrees(worst):.2f}° > limit "
            f"{math.degrees(max_pressure_angle):g}° at {format_ranges(flagged_ranges(phi, over))}"
        )

    if cam.is_roller:
        bad = (pitch.rho > 0) & (pitch.rho < cam.roller_radius)
        values = np.where(bad, pitch.rho, np.inf)
        face_min = None
    else:
        bad = profile.rho <= 0
        values = np.where(bad, profile.rho, np.inf)
        reach = np.abs(cam.contact_offset(phi))
        face_min = float(2.0 * reach.max())
        if face_width is not None and face_width < face_min:
            warnings.append(
                f"follower.face_width {face_width:g} mm is below the minimum {face_min:.3f} mm "
                f"(contact reaches {reach.max():.3f} mm off the follower axis)"
            )
    undercut = None
    if bad.any():
        k = int(np.argmin(values))
        undercut = Undercut(
            ranges=tuple(flagged_ranges(phi, bad)), worst=float(values[k]), worst_angle=float(phi[k])
        )
    s = np.asarray(motion.s)
    readonly(phi)
    return GeometryAnalysis(
        cam=cam,
        phi=phi,
        s=s,
        pitch=pitch,
        profile=profile,
        pressure_angle=alpha,
        max_pressure_angle=max_pressure_angle,
        undercut=undercut,
        warnings=tuple(warnings),
        face_width_min=face_min,
    )


def undercut_error(analysis: GeometryAnalysis, *, min_curvature_radius: float = 0.0) -> UndercutError:
    """The error for an undercut analysis, with the smallest base radius that removes it."""
    cam, uc = analysis.cam, analysis.undercut
    assert uc is not None
    sized = min_base_radius(cam, min_curvature_radius=min_curvature_radius)
    suggestion = math.ceil(sized.base_radius / _SUGGEST_ROUND_MM) * _SUGGEST_ROUND_MM
    where = format_ranges(list(uc.ranges))
    if cam.is_roller:
        what = (
            f"undercut at {where}: the pitch curve's convex radius of curvature falls to "
            f"{uc.worst:.3f} mm at {math.degrees(uc.worst_angle):.1f}°, below the roller radius "
            f"{cam.roller_radius:g} mm, so the profile loops"
        )
        way_out = "or use a smaller roller"
    else:
        what = (
            f"cusp at {where}: the profile radius of curvature r_b + s + a falls to "
            f"{uc.worst:.3f} mm at {math.degrees(uc.worst_angle):.1f}°"
        )
        way_out = "or use a gentler motion law"
    message = (
        f"cam.base_radius: {what}; use base_radius ≥ {suggestion:.2f} mm "
        f"(now {cam.base_radius:g} mm) {way_out}"
    )
    return UndercutError(
        message,
        phi_range=uc.ranges[0],
        worst=uc.worst,
        suggested_base_radius=suggestion,
    )
