"""The barrel (cylindrical) cam: a groove round a cylinder drives a roller along or across its axis.

One part, a :class:`~camcad.geometry.families.base.Barrel`: the cylinder of
``barrel_radius`` and ``length`` with the groove whose walls are the exact
envelope of the roller (:mod:`camcad.geometry.barrel`), checked over the
turn (:func:`~camcad.geometry.barrel_limits.barrel_limits`: the groove's
ends, the arm's reach, a groove that crosses itself, undercut). The later
stages take the walls from the part's shape: the certified wall surfaces
(:mod:`camcad.fit.surface`), the 4-axis program
(:mod:`camcad.toolpath.barrel`), the STEP, STL and developed DXF writers.

The part's :class:`~camcad.geometry.cam.Cam` is :class:`BarrelCam`: the
groove developed (unrolled) at the roller's pitch station t_p, where the
pitch line is (t_p·φ + y, z) and the walls are its offsets by ±(r_f + c/2)
(:func:`camcad.geometry.barrel_limits.developed_walls`; the plate-cam
envelope of a roller on the unrolled pitch line, a linear cam of speed
t_p). Geometry and dynamics run on it unchanged: its pressure angle is the
barrel's exact one at the pitch station (tan α = s′/t_p for a translating
cylinder), its profile's curvature sets the Hertz contact, and an arm's
lever is its length. The figures at the groove's bottom and top and the
roller's slip are this family's ``barrel`` section.

The rib (``cam.style = "barrel-rib"``, :data:`BARREL_RIB`): the same family
with :attr:`~camcad.geometry.barrel.BarrelKind.RIB`, a rib of ``rib_width``
standing ``[groove] depth`` high on the core, straddled by two rollers
±h = ±(w/2 + r_f + c/2) off the follower's pitch path
(:func:`~camcad.geometry.barrel.rib_rollers`). Each face is the 3-D envelope
of one roller, the material on the same side of its roller as a groove's
wall (the rib's upper face is the +h roller's lower wall), so for a
translating follower each roller's developed pitch line is the follower's
moved by ±h along the barrel's axis, with the same pressure angle and
curvature: the developed cam, its positive drive and its flanks are the
groove's (for an arm the pressure angle is the larger of the two rollers'
and the lever the roller's, √(l² + h²)). A rib's ``cam.ngc`` cuts the
barrel's whole surface round the rib down to its root and finishes each
face along its roller's path (:mod:`camcad.toolpath.barrel`, module notes).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.errors import DesignError
from camcad.extremes import SIDE_WORDS, Extreme, extremes_rows
from camcad.geometry.barrel import (
    BarrelFollower,
    BarrelKind,
    BarrelOptions,
    OscillatingBarrelRoller,
    TranslatingBarrelRoller,
    barrel_faces,
    face_rollers,
    roller_slip,
)
from camcad.geometry.barrel_limits import barrel_limits
from camcad.geometry.cam import Cam, CamState
from camcad.geometry.curves import CurveSample
from camcad.geometry.envelope import offset_curve, translation_envelope
from camcad.geometry.families.base import Barrel, Drive, FamilyOptions, Part, PartResults
from camcad.geometry.groove import roller_flank_offsets
from camcad.motion.program import Side

__all__ = ["BARREL", "BARREL_RIB", "BarrelCam", "BarrelFamily", "barrel_of"]


@dataclass(frozen=True, slots=True, kw_only=True)
class BarrelCam(Cam):
    """The barrel's groove developed at the roller's pitch station: a plate-cam view of its walls.

    Frame: u = t_p·φ + y along the barrel's circumference (unrolled), w = z
    along its axis [mm]; the pitch line runs towards +u, its normal points
    towards +w, its radius is positive where it is convex seen from +w (as a
    counter-clockwise plate cam's seen from its follower). The profile is
    the pitch line offset by −r_f (the lower wall less half the clearance):
    the groove's walls are its offsets −c/2 and 2r_f + c/2, as a groove
    cam's flanks (:func:`camcad.geometry.groove.roller_flank_offsets`).
    """

    barrel_follower: BarrelFollower
    barrel_options: BarrelOptions
    turns_about_axis: ClassVar[bool] = False  # the developed groove slides past; it sweeps no disc

    def _pitch_line(self, phi: ArrayLike, side: Side) -> tuple[Any, CurveSample, FloatArray]:
        m = self.motion(phi, side=side)
        axis = self.barrel_follower.centre(m)
        pitch, drho = translation_envelope(
            np.asarray(m.phi, dtype=float), axis, self.barrel_options.pitch_station
        )
        return m, pitch, drho

    def pitch(self, phi: ArrayLike, *, side: Side = "right") -> CurveSample:
        """The developed pitch line (t_p·φ + y, z) [mm] at motion angles φ [rad]."""
        return self._pitch_line(phi, side)[1]

    def _base_curve(self, phi: ArrayLike, side: Side) -> tuple[CurveSample, FloatArray, float]:
        _, pitch, drho = self._pitch_line(phi, side)
        return pitch, drho, -self.roller_radius

    def _state(self, phi: ArrayLike, side: Side) -> CamState:
        m, pitch, drho = self._pitch_line(phi, side)
        profile = offset_curve(pitch, drho, -self.roller_radius)
        alpha = self._alpha(m)
        lever = None
        if isinstance(self.barrel_follower, OscillatingBarrelRoller):  # pivot → roller axis: the arm
            # a rib's roller rides on a yoke h off the arm's end: its lever is √(l² + h²)
            arm = math.hypot(self.barrel_follower.arm_length, self.barrel_options.rib_offset)
            lever = np.full(np.shape(alpha), arm)
            readonly(lever)
        position = self.roller_radius * np.sin(alpha)  # where the contact sits on the roller, across it
        readonly(position)
        return CamState(
            motion=m,
            base=pitch,
            profile=profile,
            pressure_angle=alpha,
            contact_position=position,
            lever=lever,
        )

    def _alpha(self, motion: Any) -> FloatArray:
        """The exact pressure angle at the pitch station [rad] (3-D for a cone; a rib: the larger)."""
        station = np.array([self.barrel_options.pitch_station])
        out: FloatArray = (
            barrel_faces(motion, self.barrel_follower, self.barrel_options, station)
            .pressure_angle[:, 0]
            .copy()
        )
        readonly(out)
        return out

    def pressure_angle(self, phi: ArrayLike, *, side: Side = "right") -> FloatArray:
        """The pressure angle at the pitch station [rad] (:func:`camcad.geometry.barrel.barrel_faces`)."""
        return self._alpha(self.motion(phi, side=side))

    def contact_offset(self, phi: ArrayLike, *, side: Side = "right") -> FloatArray:
        """r_f·sin α [mm]: where the contact sits round the roller, across its axis."""
        out: FloatArray = self.roller_radius * np.sin(self.pressure_angle(phi, side=side))
        readonly(out)
        return out


def _barrel_objects(cam: Cam, options: FamilyOptions) -> tuple[BarrelFollower, BarrelOptions]:
    """The barrel follower and options a design states (its follower's kind decides slide or arm).

    A ``rib_width`` makes it a rib (:attr:`~camcad.geometry.barrel.BarrelKind.RIB`); the
    schema allows it on ``cam.style = "barrel-rib"`` only, and requires it there.
    """
    spec = options.barrel
    if spec is None:
        raise DesignError("cam.barrel_radius", "is required for a barrel cam (mm, the barrel's outer radius)")
    fol = cam.follower_spec
    follower: BarrelFollower
    if fol.kind.lift.angular:  # an arm: its pivot axis perpendicular to the barrel's
        assert fol.pivot_distance is not None and fol.arm_length is not None  # the schema requires them
        follower = OscillatingBarrelRoller(
            axial_position=spec.axial_position, pivot_distance=fol.pivot_distance, arm_length=fol.arm_length
        )
    else:
        follower = TranslatingBarrelRoller(axial_position=spec.axial_position)
    barrel = BarrelOptions(
        barrel_radius=spec.barrel_radius,
        length=spec.length,
        depth=options.groove.depth,
        roller_radius=fol.roller_radius,
        roller_length=spec.roller_length,
        bore=options.bore,
        clearance=options.groove.clearance,
        roller=spec.roller,
        kind=BarrelKind.GROOVE if spec.rib_width is None else BarrelKind.RIB,
        rib_width=0.0 if spec.rib_width is None else spec.rib_width,
    )
    return follower, barrel


def barrel_of(cam: Cam, options: FamilyOptions) -> Barrel:
    """The checked barrel of a designed cam: motion, follower, options and limits.

    Raises
    ------
    DesignError
        What :func:`~camcad.geometry.barrel_limits.barrel_limits` refuses, naming the field.
    """
    follower, barrel = _barrel_objects(cam, options)
    limits = barrel_limits(cam.program, follower, barrel)
    return Barrel(program=cam.program, follower=follower, options=barrel, limits=limits)


class BarrelFamily:
    """A barrel cam: one part, the cylinder with its groove (or, ``kind`` RIB, with its rib)."""

    table = "groove"  # the groove's depth and clearance, as a groove cam's (a rib: its height)
    needs_roller = True
    one_plate = False
    plates = False  # a cylinder: no FE check of a plate

    def __init__(self, kind: BarrelKind = BarrelKind.GROOVE) -> None:
        self.kind = kind
        self.rib = kind is BarrelKind.RIB
        self.name = "barrel-rib" if self.rib else "barrel"
        keys = {
            "cam.barrel_radius",
            "cam.length",
            "follower.axial_position",
            "follower.roller_length",
            "follower.roller",
        }
        self.own_keys = frozenset(keys | {"cam.rib_width"} if self.rib else keys)

    def check(
        self, options: FamilyOptions, *, base_radius: float, roller_radius: float, thickness: float
    ) -> None:
        """A barrel has no plate blank; its own values are checked with the cam (:meth:`check_cam`)."""
        if options.outer_radius is not None:
            raise DesignError("cam.outer_radius", "applies to groove cams (cam.style = 'groove') only")
        if options.barrel is None:
            raise DesignError(
                "cam.barrel_radius", "is required for a barrel cam (mm, the barrel's outer radius)"
            )
        if self.rib and options.barrel.rib_width is None:
            raise DesignError("cam.rib_width", "is required for cam.style = 'barrel-rib' (mm, > 0)")
        if not self.rib and options.barrel.rib_width is not None:
            raise DesignError("cam.rib_width", "applies to cam.style = 'barrel-rib' only")

    def check_cam(self, cam: Callable[[], Cam], options: FamilyOptions) -> None:
        """The barrel, groove (or rib), roller and arm can be made (:func:`barrel_of`)."""
        barrel_of(cam(), options)

    def parts(self, cam: Cam, options: FamilyOptions) -> tuple[Part, ...]:
        """The barrel with its groove or rib; its cam is the groove developed at the pitch station."""
        barrel = barrel_of(cam, options)
        developed = BarrelCam(
            program=cam.program,
            base_radius=cam.base_radius,
            follower_spec=cam.follower_spec,
            rotation=cam.rotation,
            sample_step=cam.sample_step,
            barrel_follower=barrel.follower,
            barrel_options=barrel.options,
        )
        return (Part(cam=developed, barrel=barrel, checks=(_BarrelCheck(barrel),)),)

    def drive(self, roller_radius: float, options: FamilyOptions) -> Drive:
        """The groove's two walls (a rib's two faces) drive the roller(s) both ways, with the play c."""
        clearance = options.groove.clearance
        return Drive(
            positive_drive=True,
            clearance=clearance,
            flank_offsets=roller_flank_offsets(roller_radius, clearance),
        )

    def summary(self, results: Sequence[PartResults]) -> dict[str, Any]:
        """The ``barrel`` section, the walls' ``fit`` certificate, and a ``geometry`` without plate radii.

        The common ``geometry`` section's profile radii are distances in the
        developed plane, which mean nothing on a barrel: this family's
        ``geometry`` replaces it (the same figures less those two).
        """
        (result,) = results
        barrel = result.part.barrel
        assert barrel is not None
        geometry = {k: v for k, v in result.geometry.summary().items() if not k.startswith("profile_radius")}
        out: dict[str, Any] = {"geometry": geometry, "barrel": _barrel_summary(barrel)}
        if result.wall_fit is not None:
            out["fit"] = result.wall_fit.summary()
        return out

    def caption(self, parts: Sequence[Part]) -> str:
        """The roller runs in the groove round the barrel (the two rollers straddle the rib)."""
        if self.rib:
            return " Two rollers straddle the rib round the barrel, shown developed at their pitch station."
        return " The roller runs in the groove round the barrel, shown developed at its pitch station."


@dataclass(frozen=True, slots=True)
class _BarrelCheck:
    """The barrel's own findings (a wall that loops at the groove's bottom)."""

    barrel: Barrel

    @property
    def findings(self) -> tuple[Any, ...]:
        return self.barrel.limits.findings

    @property
    def radius_margin(self) -> float:
        """No flank radius to keep positive: a wall that loops (stretch λ ≤ 0) is its own hard finding."""
        return math.inf

    def summary(self) -> dict[str, Any]:
        return _barrel_summary(self.barrel)


def _extreme(ext: Extreme, *, unit: str, scale: float = 1.0) -> dict[str, Any]:
    return {
        f"value_{unit}": ext.value * scale,
        "angle_deg": ext.angle_deg,
        "side": None if ext.side is None else SIDE_WORDS[ext.side],
    }


def _barrel_summary(barrel: Barrel) -> dict[str, Any]:
    """The barrel's figures: its size, the stations, pressure angles, wall stretch, axial reach, slip."""
    o, lim = barrel.options, barrel.limits
    bottom, pitch, top = lim.pressure_angle_max
    out: dict[str, Any] = {
        "barrel_radius_mm": o.barrel_radius,
        "length_mm": o.length,
        "bore_mm": o.bore,
        "groove_depth_mm": o.depth,  # a rib: its height
        "groove_width_mm": 2.0 * o.roller_radius + o.clearance,  # a rib: the gap each roller runs in
        "roller": o.roller.value,
        "roller_length_mm": o.roller_length,
        "stations_mm": {"bottom": o.bottom_radius, "pitch": o.pitch_station, "top": o.barrel_radius},
        "pressure_angle_max": {
            "bottom": _extreme(bottom, unit="deg", scale=180.0 / math.pi),
            "pitch": _extreme(pitch, unit="deg", scale=180.0 / math.pi),
            "top": _extreme(top, unit="deg", scale=180.0 / math.pi),
        },
        "wall_stretch_min": {
            where: {"upper": _extreme(up, unit="ratio"), "lower": _extreme(low, unit="ratio")}
            for where, (up, low) in lim.stretch_min.items()
        },
        "groove_z_mm": {"lowest": lim.z_range[0].value, "highest": lim.z_range[1].value},
        "undercut": any(f.kind == "groove undercut" for f in lim.findings),
    }
    if o.kind is BarrelKind.RIB:  # its width as designed, and its least width between the exact faces
        out["rib"] = {
            "width_mm": o.rib_width,
            "roller_offset_mm": o.rib_offset,
            "thickness_min": {
                where: _extreme(ext, unit="mm") for where, ext in lim.rib_thickness_min.items()
            },
        }
    out["slip"] = _slip_summary(barrel)
    return out


def _slip_summary(barrel: Barrel) -> dict[str, Any]:
    """The largest slip of the roller on either wall over its length [mm/rad] (× ω for mm/s).

    ``across``: along the roller's circumference (a cylinder rolls at its
    pitch station only, Rothbart 2004, §8.4); ``along``: along its axis,
    while the follower moves. True extremes over the turn
    (:func:`camcad.extremes.extremes_rows`) of the largest |slip| over nine
    stations from the roller's inner end to the barrel's surface (for a
    translating cylinder it grows with the distance from t_p, so the ends,
    which are stations, hold it).
    """
    o = barrel.options
    stations = np.linspace(o.barrel_radius - o.roller_length, o.barrel_radius, 9)

    def rows(phi: FloatArray, side: Side) -> FloatArray:
        motion = barrel.program.evaluate(phi, side=side)
        out = np.zeros((2, np.size(phi)))
        for roller, wall in face_rollers(barrel.follower, o):  # a rib: each face's own roller
            slip = roller_slip(motion, roller, o, stations, wall)
            out[0] = np.maximum(out[0], np.max(np.abs(slip.across), axis=1))
            out[1] = np.maximum(out[1], np.max(np.abs(slip.along), axis=1))
        return out

    joints = [bp.phi for bp in barrel.program.breakpoints]
    across, along = extremes_rows(rows, barrel.program.sample_phi(math.radians(0.5)), joints, ("max", "max"))
    return {
        "across_max": _extreme(across, unit="mm_per_rad"),
        "along_max": _extreme(along, unit="mm_per_rad"),
    }


BARREL = BarrelFamily()
BARREL_RIB = BarrelFamily(BarrelKind.RIB)
