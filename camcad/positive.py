"""Positive drive: groove cams and conjugate pairs, beside the plate analysis.

A groove cam adds the groove's flank checks (:mod:`camcad.geometry.groove`);
a conjugate pair adds its second plate, driving the tied second roller
(:class:`camcad.geometry.followers.tied.TiedRoller`), with its own geometry
limits and its own contact force, which is positive where that roller drives
(the first plate's force is positive where the first roller does).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from camcad.design import Design
from camcad.dynamics import analyse_dynamics
from camcad.dynamics.results import DynamicsResult
from camcad.findings import Finding
from camcad.fit import ProfileFit, fit_cam_profile
from camcad.geometry import Cam, GeometryAnalysis, analyse_geometry
from camcad.geometry.groove import GrooveAnalysis, analyse_groove
from camcad.geometry.spec import CamStyle

if TYPE_CHECKING:
    from camcad.export.gcode import GcodeProgram

__all__ = ["PositiveDrive", "analyse_positive_drive", "fit_positive_drive", "plan_partner"]


@dataclass(frozen=True, slots=True, kw_only=True)
class PositiveDrive:
    """What a groove or a conjugate pair adds: the groove checks, or the second plate's analyses."""

    groove: GrooveAnalysis | None = None
    partner: Cam | None = None
    partner_geometry: GeometryAnalysis | None = None
    partner_dynamics: DynamicsResult | None = None
    flank_fits: tuple[ProfileFit, ProfileFit] | None = None  # the groove's inner and outer flank
    partner_fit: ProfileFit | None = None  # the second plate (None for a constant-breadth single plate)
    partner_gcode: GcodeProgram | None = None

    @property
    def second_plate(self) -> bool:
        """Whether a conjugate pair has a second plate to make (not a constant-breadth single plate)."""
        return self.partner is not None and not (
            self.partner.conjugate is not None and self.partner.conjugate.single_plate
        )

    @property
    def findings(self) -> tuple[Finding, ...]:
        """The groove's findings, and the second plate's (their messages say so)."""
        out: list[Finding] = []
        if self.groove is not None:
            out += self.groove.findings
        for result in (self.partner_geometry, self.partner_dynamics):
            if result is not None:
                out += [replace(f, message=f"second plate: {f.message}") for f in result.findings]
        return tuple(out)

    def summary(self) -> dict[str, Any]:
        """The ``groove`` or ``second_plate`` section of ``summary.json``."""
        if self.groove is not None:
            out: dict[str, Any] = self.groove.summary()
            if self.flank_fits is not None:
                inner, outer = self.flank_fits
                out["fit"] = {"inner_flank": inner.summary(), "outer_flank": outer.summary()}
            return {"groove": out}
        if self.partner_geometry is not None and self.partner_dynamics is not None:
            plate: dict[str, Any] = {
                "single_plate": not self.second_plate,
                "geometry": self.partner_geometry.summary(),
                "dynamics": self.partner_dynamics.summary(),
            }
            if self.partner_fit is not None:
                plate["fit"] = self.partner_fit.summary()
            return {"second_plate": plate}
        return {}


def analyse_positive_drive(design: Design, cam: Cam) -> PositiveDrive:
    """The groove checks or the conjugate pair's second plate of ``design`` (empty for a plate cam)."""
    style = design.cam.style
    if style is CamStyle.GROOVE:
        bore = design.plate().bore
        groove = analyse_groove(
            cam,
            clearance=design.groove.clearance,
            outer_radius=design.cam.outer_radius,
            hole_radius=0.0 if bore is None else bore.reach,
        )
        return PositiveDrive(groove=groove)
    if style is not CamStyle.CONJUGATE:
        return PositiveDrive()
    partner = cam.partner(design.conjugate)
    geometry = analyse_geometry(
        partner,
        max_pressure_angle=design.cam.max_pressure_angle,
        min_curvature_radius=design.min_curvature_radius,
    )
    dynamics = analyse_dynamics(
        partner.motion(geometry.phi),
        pressure_angle=geometry.pressure_angle,
        profile_rho=geometry.profile.rho,
        # the second plate's own roller: its radius sets the Hertz contact (Johnson 1985, §4.3)
        setup=replace(design.dynamics_setup(), drive_sign=-1.0, roller_radius=partner.roller_radius),
        cam=partner,
    )
    return PositiveDrive(partner=partner, partner_geometry=geometry, partner_dynamics=dynamics)


def fit_positive_drive(
    drive: PositiveDrive, cam: Cam, *, tolerance: float, max_control_points: int | None
) -> PositiveDrive:
    """``drive`` with the certified fits of every further curve exported: both flanks, or the second plate."""
    if drive.groove is not None:
        inner, outer = (
            fit_cam_profile(cam, tolerance=tolerance, max_control_points=max_control_points, offset=d)
            for d in (drive.groove.inner_offset, drive.groove.outer_offset)
        )
        return replace(drive, flank_fits=(inner, outer))
    if drive.partner is not None and drive.second_plate:
        fit = fit_cam_profile(drive.partner, tolerance=tolerance, max_control_points=max_control_points)
        return replace(drive, partner_fit=fit)
    return drive


def plan_partner(drive: PositiveDrive, design: Design) -> PositiveDrive:
    """``drive`` with the G-code program of a conjugate pair's second plate (same tool and passes)."""
    if drive.partner is None or not drive.second_plate:
        return drive
    from camcad.export.gcode import render_program
    from camcad.toolpath import plan_toolpath

    planned = plan_toolpath(
        drive.partner,
        design.gcode,
        name=f"{design.cam.name} (second plate)",
        thickness=design.cam.thickness,
        bore=design.cam.bore,
    )
    return replace(drive, partner_gcode=render_program(planned, design.gcode.dialect))
