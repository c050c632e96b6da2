"""The results of analysing a design: one value object the report and the files are made from.

:class:`Analysis` gathers what every stage computed (motion, geometry,
dynamics, fit, toolpath) with the summary that goes to ``summary.json``. It
sits below the report and the pipeline: both read it, neither is imported here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad._typing import FloatArray, tree_copy
from camcad._version import __version__
from camcad.design import Design
from camcad.design.paths import named_findings
from camcad.dynamics import DynamicsResult
from camcad.extremes import SIDE_WORDS, Side, extremes_rows
from camcad.findings import Finding
from camcad.fit import ProfileFit
from camcad.geometry import Cam, GeometryAnalysis
from camcad.geometry.families import CamFamily, Part
from camcad.motion.program import Motion
from camcad.motion.table import table_summary

if TYPE_CHECKING:
    from camcad.dynamics.duty import DriveDuty, DutyResult
    from camcad.dynamics.vibration import VibrationResult
    from camcad.export.gcode import GcodeProgram
    from camcad.fea.results import FeaResult  # only typing: the FE package loads when the check runs
    from camcad.fit.surface import BarrelWallFit
    from camcad.toolpath import Toolpath

__all__ = ["Analysis", "PartResult", "motion_summary"]


@dataclass(frozen=True, slots=True, kw_only=True)
class PartResult:
    """What the stages computed for one part of a cam family, by the same code for every part.

    Attributes
    ----------
    part
        The part (:class:`camcad.geometry.families.Part`): its cam, its files' suffix, its shape.
    geometry
        Its pitch curve, profile, pressure angle, curvature, undercut.
    dynamics
        Its contact force, torque and Hertz stress, with its own roller and drive sign.
    fit
        The certified NURBS of its outline; None when not fitted or not made.
    flank_fits
        The certified NURBS of its further curves (``part.flanks``), in order; empty when not fitted.
    gcode
        Its program; None without a tool path, or when not made.
    duty
        Its roller's and track's life and its lubricant film (``[life]``,
        ``[lubrication]``), by the same code for every part; None without either table.
    fea
        The finite-element check of a made plate (its own roller's contact
        loads); None when not run, or for a part that is not a plate.
    wall_fit
        A barrel's certified wall surfaces (:class:`~camcad.fit.surface.BarrelWallFit`), else None.
    """

    part: Part
    geometry: GeometryAnalysis
    dynamics: DynamicsResult
    fit: ProfileFit | None = None
    flank_fits: tuple[ProfileFit, ...] = ()
    gcode: GcodeProgram | None = None
    duty: DutyResult | None = None
    fea: FeaResult | None = None
    wall_fit: BarrelWallFit | None = None

    @property
    def findings(self) -> tuple[Finding, ...]:
        """Its geometry's, family checks', dynamics', FE's and duty's findings; a later part's name theirs."""
        fea = self.fea.findings if self.fea is not None else ()
        duty = self.duty.findings if self.duty is not None else ()
        found = named_findings(
            (*self.geometry.findings, *self.part.findings, *self.dynamics.findings, *fea, *duty)
        )
        if not self.part.label:
            return found
        return tuple(replace(f, message=f"{self.part.label}: {f.message}") for f in found)


@dataclass(frozen=True, slots=True, kw_only=True)
class Analysis:
    """Everything camcad computes for a design, before any file is written.

    Attributes
    ----------
    family
        The cam family (plate, groove, conjugate) whose parts were analysed.
    parts
        What every stage computed for each part, the designed cam's first.
    motion
        s, v, a, j over ``geometry.phi`` (0.1° grid plus breakpoints).
    toolpath
        The first part's planned toolpath, or None when not requested (or rotary).
    timings
        Seconds per stage (all parts).
    stage_findings
        Hard limits the fit or the toolpath plan found (fit tolerance
        unreachable, gouge) when the analysis was not strict.

    ``cam``, ``geometry``, ``dynamics``, ``fit`` and ``gcode`` are the first part's.
    """

    design: Design
    family: CamFamily
    parts: tuple[PartResult, ...]
    motion: Motion
    toolpath: Toolpath | None
    timings: dict[str, float] = field(default_factory=dict)
    stage_findings: tuple[Finding, ...] = ()
    drive: DriveDuty | None = None  # the follower train's drive ([drive]; issue 35)
    vibration: VibrationResult | None = None  # the elastic follower train ([vibration]; issue 34)
    _memo: dict[str, Any] = field(  # the motion summary, computed once (see summary)
        default_factory=dict, init=False, repr=False, compare=False
    )

    @property
    def cam(self) -> Cam:
        """The designed cam (the first part's)."""
        return self.parts[0].part.cam

    @property
    def geometry(self) -> GeometryAnalysis:
        """The first part's pitch curve, profile, pressure angle, curvature, undercut."""
        return self.parts[0].geometry

    @property
    def dynamics(self) -> DynamicsResult:
        """The first part's contact force, torque, Hertz stress (over the same angles)."""
        return self.parts[0].dynamics

    @property
    def fea(self) -> FeaResult | None:
        """The first plate's finite-element check, when run ([fea], or asked); each plate's in ``parts``."""
        return self.parts[0].fea

    @property
    def duty(self) -> DutyResult | None:
        """The first part's life and film ([life], [lubrication]; issue 35); every part's in ``parts``."""
        return self.parts[0].duty

    @property
    def fit(self) -> ProfileFit | None:
        """The certified NURBS of the first part's profile, or None when not requested."""
        return self.parts[0].fit

    @property
    def gcode(self) -> GcodeProgram | None:
        """The first part's program (the text of ``cam.ngc`` and its figures); None without a toolpath."""
        return self.parts[0].gcode

    @property
    def findings(self) -> tuple[Finding, ...]:
        """Every finding of every stage and part: hard, soft, then notes (:mod:`camcad.findings`)."""
        first, *later = self.parts
        found = (
            *first.geometry.findings,
            *first.part.findings,
            *(f for result in later for f in result.findings),
            *first.dynamics.findings,
            *self.stage_findings,
            *(self.fea.findings if self.fea is not None else ()),
            *(self.duty.findings if self.duty is not None else ()),
            *(self.drive.findings if self.drive is not None else ()),
            *(self.vibration.findings if self.vibration is not None else ()),
        )
        return tuple(sorted(named_findings(found), key=lambda f: f.rank))

    @property
    def violations(self) -> list[str]:
        """The kinds of the broken limits, hard and soft, not notes (``camcad check`` exits 3 when any)."""
        return list(dict.fromkeys(f.kind for f in self.findings if not f.note))

    def summary(self) -> dict[str, Any]:
        """The content of ``summary.json``; a new dict on each call, the caller's to change.

        The motion's true peaks are refined once per analysis and copied from
        then on: the report, its cards and its warning banner each ask for the
        summary, and the designer draws all three after every edit.
        """
        if "motion" not in self._memo:
            self._memo["motion"] = motion_summary(self.cam, self.motion)
        out: dict[str, Any] = {
            "camcad_version": __version__,
            "design": {"name": self.design.cam.name, "source": self.design.source},
            "motion": tree_copy(self._memo["motion"]),
            "geometry": self.geometry.summary(),
            "dynamics": self.dynamics.summary(),
            **self.family.summary(self.parts),  # a groove's flanks, a pair's second plate
        }
        if self.fit is not None:
            out["fit"] = self.fit.summary()
        if self.gcode is not None:
            out["gcode"] = self.gcode.summary()
        if self.fea is not None:
            out["fea"] = self.fea.summary()
        if self.duty is not None:
            out |= self.duty.summary()  # the first part's life, lubrication (a later part's: its family's)
        if self.drive is not None:
            out |= self.drive.summary()  # the train's drive
        if self.vibration is not None:
            out["vibration"] = self.vibration.summary()
        out["violations"] = self.violations
        out["findings"] = [f.summary() for f in self.findings]
        return out


def motion_summary(cam: Cam, motion: Motion) -> dict[str, Any]:
    """True peaks of |v|, |a|, |j| with their angles (one-sided at joints), the lift and the joint report.

    ``lift_*`` is the nominal lift (the largest total the program states);
    ``stroke_*`` the true travel, max − min of s over the turn (its ends in
    ``travel_max_*`` and ``travel_min_*`` with their angles), which is larger
    where a segment overshoots.

    Where the velocity jumps (``velocity_jumps_deg``) the acceleration is an
    impulse: the peaks of |a| and |j| are infinite and reported as ``None``.
    """
    u = cam.follower_spec.kind.lift_unit  # mm on a slide, degrees of swing on an arm
    out: dict[str, Any] = {f"lift_{u}": cam.program.lift}
    joints = [bp.phi for bp in cam.program.breakpoints]
    # where v jumps, a is an impulse and j is undefined: their peaks are infinite, not the samples'
    impulses = [round(math.degrees(bp.phi), 6) for bp in cam.program.breakpoints if bp.continuity == 0]
    out["velocity_jumps_deg"] = impulses

    def rows(p: FloatArray, side: Side) -> FloatArray:
        m = cam.motion(p, side=side)
        return np.vstack((np.abs(np.vstack((m.v, m.a, m.j))), m.s, m.s))

    # |v|, |a|, |j| and the true stroke, the follower's travel max − min over the turn, refined on the
    # exact motion in one search (a segment that overshoots, as a return out of a constant-velocity rise
    # does, can exceed the lift)
    values = np.vstack((np.abs(np.vstack((motion.v, motion.a, motion.j))), motion.s, motion.s))
    found = extremes_rows(rows, motion.phi, joints, ("max", "max", "max", "max", "min"), values=values)
    peaks, (top, bottom) = found[:3], found[3:]
    out[f"stroke_{u}"] = top.value - bottom.value
    out[f"travel_max_{u}"] = top.value
    out["travel_max_angle_deg"] = top.angle_deg
    out[f"travel_min_{u}"] = bottom.value
    out["travel_min_angle_deg"] = bottom.angle_deg
    for (key, unit), peak in zip(
        (("v", f"{u}_per_rad"), ("a", f"{u}_per_rad2"), ("j", f"{u}_per_rad3")), peaks, strict=True
    ):
        if impulses and key != "v":
            out[f"{key}_max_abs_{unit}"] = None  # infinite at the velocity jumps
            out[f"{key}_max_abs_angle_deg"] = impulses[0]
            out[f"{key}_max_abs_side"] = None
            continue
        out[f"{key}_max_abs_{unit}"] = peak.value
        out[f"{key}_max_abs_angle_deg"] = peak.angle_deg
        out[f"{key}_max_abs_side"] = None if peak.side is None else SIDE_WORDS[peak.side]
    out["joints"] = [
        {
            "angle_deg": math.degrees(j.phi),
            "segment": j.index,
            f"dv_{u}_per_rad": j.dv,
            f"da_{u}_per_rad2": j.da,
            f"dj_{u}_per_rad3": j.dj,
            "continuity": j.continuity,
            "text": j.describe(u),
        }
        for j in cam.program.joints()
    ]
    if cam.program.blend_points:  # joints whose values a polynomial or inclined sine took from a neighbour
        out["blend_points_deg"] = [round(math.degrees(bp.phi), 6) for bp in cam.program.blend_points]
    out.update(table_summary(cam.program.segments, u))  # a point table's residuals and flags
    return out
