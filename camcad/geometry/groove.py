"""Groove (face) cams: a roller running in a groove, positively driven on both flanks.

The groove's centre line is the pitch curve (the roller centre's path); its
flanks are the pitch curve offset by ∓(r_f + c/2), c the radial clearance, so
the groove is 2r_f + c wide everywhere (Rothbart 2004, §8.2; Norton 2009,
§8.11). Both flanks are exact offsets of the same base curve
(:meth:`camcad.geometry.cam.Cam.offset_curve`), with exact normals and curvature.

Limits, all at true extremes (one-sided at joints included):

- the inner flank (towards the cam axis) loops where the pitch curve's convex
  radius falls below r_f + c/2 (undercut, as on a plate cam but with the half
  clearance added);
- the outer flank loops where the pitch curve's concave radius falls below
  r_f + c/2;
- a cutter of radius r_t finishes a flank only where that flank, seen from
  inside the groove, is concave with a radius ≥ r_t: the inner flank where
  the pitch curve is concave (radius |ρ| + r_f + c/2), the outer flank where
  it is convex (radius ρ + r_f + c/2); and r_t < r_f + c/2 so the cutter fits
  the groove. :attr:`GrooveAnalysis.tool_radius_max` is the largest admissible.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import ArrayLike, FloatArray
from camcad.extremes import Extreme, Kind, Side, extremes_rows
from camcad.findings import Finding, Severity
from camcad.geometry.cam import Cam
from camcad.geometry.curves import CurveSample
from camcad.knobs import Knob

__all__ = ["GrooveAnalysis", "analyse_groove", "flank_offsets", "groove_flanks", "roller_flank_offsets"]


def groove_flanks(
    cam: Cam, phi: ArrayLike, clearance: float, *, side: Side = "right"
) -> tuple[CurveSample, CurveSample]:
    """The inner and outer flank of the groove at cam angles φ [rad], exact to the second derivative.

    ``clearance`` c [mm] is the radial play between roller and groove: the
    flanks are the pitch curve offset by −(r_f + c/2) and +(r_f + c/2).
    """
    inner_at, outer_at = flank_offsets(cam, clearance)
    return cam.offset_curve(phi, inner_at, side=side), cam.offset_curve(phi, outer_at, side=side)


def flank_offsets(cam: Cam, clearance: float) -> tuple[float, float]:
    """The inner and outer flank as offsets of the profile [mm] (``cam.offset_curve(φ, d)``).

    The profile is the pitch curve offset by −r_f, so the inner flank, at
    −(r_f + c/2) from the pitch curve, is the profile offset by −c/2, and the
    outer flank, at +(r_f + c/2), is the profile offset by 2r_f + c/2.
    """
    return roller_flank_offsets(cam.roller_radius, clearance)


def roller_flank_offsets(roller_radius: float, clearance: float) -> tuple[float, float]:
    """:func:`flank_offsets` from the roller radius r_f [mm] and the clearance c [mm] alone."""
    return -0.5 * clearance, 2.0 * roller_radius + 0.5 * clearance


@dataclass(frozen=True, slots=True, kw_only=True)
class GrooveAnalysis:
    """The groove's width, flank radii and the largest cutter, at true extremes.

    ``inner_convex_min`` [mm]: the inner flank's smallest convex radius
    (ρ_pitch − r_f − c/2 where the pitch curve is convex; ≤ 0 is a loop);
    ``outer_concave_min`` [mm]: the outer flank's smallest concave radius seen
    from outside (|ρ_pitch| − r_f − c/2 where the pitch curve is concave; ≤ 0
    is a loop), None where the pitch curve is convex everywhere;
    ``tool_radius_max`` [mm]: the largest cutter that finishes both flanks;
    ``inner_offset``, ``outer_offset`` [mm]: the flanks as offsets of the
    profile (:func:`flank_offsets`); ``reach`` [mm]: the outer flank's
    farthest distance from the cam axis.
    """

    width: float
    inner_offset: float
    outer_offset: float
    reach: Extreme
    inner_convex_min: Extreme
    outer_concave_min: Extreme | None
    tool_radius_max: float
    tool_radius_at: Extreme
    findings: tuple[Finding, ...]

    @property
    def radius_margin(self) -> float:
        """The flanks' smallest radius [mm] that must stay positive (≤ 0: a flank loops, a hard limit)."""
        flanks = (self.inner_convex_min, self.outer_concave_min)
        return min(f.value for f in flanks if f is not None)

    def summary(self) -> dict[str, object]:
        """JSON-ready figures."""
        out: dict[str, object] = {
            "width_mm": self.width,
            "inner_flank_convex_radius_min_mm": self.inner_convex_min.value,
            "inner_flank_convex_radius_min_angle_deg": self.inner_convex_min.angle_deg,
            "outer_flank_concave_radius_min_mm": None
            if self.outer_concave_min is None
            else self.outer_concave_min.value,
            "tool_radius_max_mm": self.tool_radius_max,
            "outer_flank_reach_mm": self.reach.value,
        }
        return out


def analyse_groove(
    cam: Cam,
    *,
    clearance: float,
    outer_radius: float | None = None,
    hole_radius: float = 0.0,
    step: float | None = None,
) -> GrooveAnalysis:
    """Check a groove of clearance c [mm] around ``cam``'s pitch curve (a roller follower).

    Hard findings, each naming the angle: either flank loops
    (``cam.base_radius``); the outer flank reaches the blank's rim
    ``outer_radius`` [mm] (``cam.outer_radius``); the inner flank reaches
    the bore, ``hole_radius`` [mm] being the bore's (keyway included)
    farthest reach (``cam.base_radius``).
    """
    half = cam.roller_radius + 0.5 * clearance
    phi = cam.sample_phi(step)
    joints = [bp.phi for bp in cam.program.breakpoints]
    kinds: tuple[Kind, ...] = ("min", "min", "min", "min", "max", "min")
    inner_at, outer_at = flank_offsets(cam, clearance)

    def rows(p: FloatArray, side: Side) -> FloatArray:
        """Loop margins, the cutter's concave radii, the flanks' reach from the cam axis.

        Rows: inner convex ρ − half, outer |ρ| − half (concave), the concave
        radii the cutter meets on each flank, the outer flank's farthest and
        the inner flank's nearest distance from the cam axis.
        """
        st = cam.state(p, side=side)
        rho, base, normal = st.base.rho, st.base.point, st.base.normal
        convex = np.where(rho > 0.0, rho, np.inf)
        concave = np.where(rho < 0.0, -rho, np.inf)
        inner_tool = concave + half  # the inner flank is concave (from the groove) where the pitch is
        outer_tool = np.where(rho > 0.0, rho + half, np.inf)
        reach = np.hypot(*(base + half * normal).T)  # the flanks are the pitch curve ± half along n
        near = np.hypot(*(base - half * normal).T)
        return np.vstack((convex - half, concave - half, inner_tool, outer_tool, reach, near))

    inner, outer, inner_tool, outer_tool, reach, near = extremes_rows(
        rows, phi, joints, kinds, rests=cam.rests
    )
    findings: list[Finding] = []
    if outer_radius is not None and reach.value >= outer_radius:
        findings.append(
            Finding(
                kind="groove outside the blank",
                severity=Severity.HARD,
                field=Knob.OUTER_RADIUS,
                field_first=True,
                message=(
                    f"the groove's outer flank reaches {reach.value:.3f} mm from the cam "
                    f"axis {reach.where()}, beyond the blank's {outer_radius:g} mm; use outer_radius > "
                    f"{reach.value:.3f} mm (plus a wall)"
                ),
                angle=reach.phi,
                value=reach.value,
                limit=outer_radius,
                unit="mm",
            )
        )
    if near.value <= hole_radius:
        findings.append(
            Finding(
                kind="groove into the bore",
                severity=Severity.HARD,
                field=Knob.BASE_RADIUS,
                field_first=True,
                message=(
                    f"the groove's inner flank comes within {near.value:.3f} mm of the cam "
                    f"axis {near.where()}, into the bore (reaching {hole_radius:g} mm); enlarge the base "
                    "circle"
                ),
                angle=near.phi,
                value=near.value,
                limit=hole_radius,
                unit="mm",
            )
        )
    for ext, flank, what in (
        (inner, "inner", "convex"),
        (outer, "outer", "concave"),
    ):
        if math.isfinite(ext.value) and ext.value <= 0.0:
            findings.append(
                Finding(
                    kind="groove undercut",
                    severity=Severity.HARD,
                    field=Knob.BASE_RADIUS,
                    field_first=True,
                    message=(
                        f"the groove's {flank} flank loops {ext.where()}: the pitch "
                        f"curve's {what} radius is {ext.value + half:.3f} mm, not more than "
                        f"r_f + clearance/2 = {half:g} mm; enlarge the base circle or use a gentler law"
                    ),
                    angle=ext.phi,
                    value=ext.value + half,
                    limit=half,
                    unit="mm",
                )
            )
    tool_at = inner_tool if inner_tool.value <= outer_tool.value else outer_tool
    return GrooveAnalysis(
        width=2.0 * half,
        inner_offset=inner_at,
        outer_offset=outer_at,
        reach=reach,
        inner_convex_min=inner,
        outer_concave_min=outer if math.isfinite(outer.value) else None,
        tool_radius_max=min(half, tool_at.value),
        tool_radius_at=tool_at,
        findings=tuple(findings),
    )
