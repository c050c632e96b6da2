"""A barrel cam's developed walls and its limits: pressure angle, undercut, the barrel's ends, the arm.

The developed plane at station t is the plane perpendicular to the roller's
axis there, unrolled along the travel: u = tφ + (the e_θ coordinate),
w = z. In it the roller's cross-section is a circle of radius r(t) at
(tφ + y, z), and for a cylindrical roller each wall is exactly the pitch
line P(φ) = (tφ + y, z) offset by ±r along its normal: a linear cam of speed
t (:func:`camcad.geometry.envelope.translation_envelope`). For a cone
(y ≡ 0) the contact normal is that of the line (qφ, z), q = t + k·r, so the
wall is that line's offset by ±r shifted back by (q − t)φ along u.

A wall loops (undercut) where its developed point stops advancing along u:
λ = (dC_u/dφ)/t ≤ 0; for a cylinder λ = 1 ± r/ρ with ρ the developed pitch
line's signed radius (the plate cam's 1 + δ/ρ, Quintero & Vanegas 2016,
eq. 13), so the upper wall loops where the pitch line bends towards +z
with radius < r, the lower where it bends towards −z.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import DesignError
from camcad.extremes import Extreme, Kind, Side, extremes_rows
from camcad.findings import Finding, Severity
from camcad.geometry.barrel import (
    BarrelFollower,
    BarrelKind,
    BarrelOptions,
    FaceSource,
    WallSide,
    _contact,
    _pressure,
    check_barrel,
    face_rollers,
    faces_at_radius,
)
from camcad.geometry.curves import CurveSample, curve_sample
from camcad.geometry.envelope import PointElement, offset_curve, translation_envelope
from camcad.knobs import Knob
from camcad.motion.program import Motion, MotionProgram

__all__ = ["BarrelLimits", "DevelopedWalls", "barrel_limits", "developed_walls"]


@dataclass(frozen=True, slots=True, kw_only=True)
class DevelopedWalls:
    """The developed pitch line and both walls at one station t [mm], plane (u, w) [mm].

    Each a :class:`~camcad.geometry.curves.CurveSample` in φ with exact
    first and second derivatives; normals point towards +w (the upper side),
    radii are signed as for a linear cam (positive where convex seen from
    +w). ``stretch_upper``, ``stretch_lower`` (n,): λ = (dC_u/dφ)/t of each
    wall, ≤ 0 where it loops.
    """

    station: float
    pitch: CurveSample
    upper: CurveSample
    lower: CurveSample
    stretch_upper: FloatArray
    stretch_lower: FloatArray


def developed_walls(
    motion: Motion, follower: BarrelFollower, options: BarrelOptions, station: float
) -> DevelopedWalls:
    """The developed pitch line and walls at station t [mm] (module notes), exact to φ″."""
    axis = follower.centre(motion)
    phi = np.asarray(motion.phi, dtype=float)
    t = float(station)
    r = float(options.roller_at(t, clearance=True))
    pitch, drho = translation_envelope(phi, axis, t)
    k = options.taper
    if k == 0.0:
        upper = offset_curve(pitch, drho, r)
        lower = offset_curve(pitch, drho, -r)
    else:  # a cone, y ≡ 0: offset the line (qφ, z) and shift it back by (q − t)φ
        q = t + k * r
        slanted, srho = translation_envelope(phi, axis, q)
        upper, lower = (_shifted(offset_curve(slanted, srho, delta), phi, q - t) for delta in (r, -r))
    stretch_upper = upper.d1[:, 0] / t
    stretch_lower = lower.d1[:, 0] / t
    readonly(stretch_upper, stretch_lower)
    return DevelopedWalls(
        station=t,
        pitch=pitch,
        upper=upper,
        lower=lower,
        stretch_upper=stretch_upper,
        stretch_lower=stretch_lower,
    )


def _shifted(curve: CurveSample, phi: FloatArray, rate: float) -> CurveSample:
    """The curve moved by −rate·φ along u: C = O − (rate·φ, 0), C′ = O′ − (rate, 0), C″ = O″."""
    shift = np.column_stack((rate * phi, np.zeros_like(phi)))
    d1 = curve.d1 - np.array([rate, 0.0])
    return curve_sample(phi, curve.point - shift, d1, curve.d2.copy(), clockwise=True)


@dataclass(frozen=True, slots=True, kw_only=True)
class BarrelLimits:
    """A barrel cam's figures over the turn, at true extremes (one-sided at joints).

    ``pressure_angle_max``: the largest |α| [rad] at the groove's bottom, the
    pitch station and the top (stations R − depth, t_p, R), in that order
    (a rib: the larger of its two rollers'); ``stretch_min``: the smallest λ
    of the (upper, lower) face at the pitch station and at the bottom,
    ``{"pitch": (upper, lower), "bottom": (...)}`` (≤ 0: the face loops);
    ``z_range``: the lowest point of the lower face and the highest of the
    upper face [mm] (a groove's on the barrel's surface, a rib's over its
    height); ``rib_thickness_min``: a rib's least width between its
    developed faces at the bottom and the top stations [mm],
    ``{"bottom": ..., "top": ...}`` (negative where the faces cross; empty
    for a groove); ``findings``: a hard finding for a face that loops or a
    rib that vanishes.
    """

    pressure_angle_max: tuple[Extreme, Extreme, Extreme]
    stretch_min: dict[str, tuple[Extreme, Extreme]]
    z_range: tuple[Extreme, Extreme]
    findings: tuple[Finding, ...]
    rib_thickness_min: dict[str, Extreme] = field(default_factory=dict)


def _axis_rows(motion: Motion, follower: BarrelFollower, bottom: float) -> tuple[FloatArray, FloatArray]:
    """|y| of the roller's axis, and t + y′ at the bottom station (≤ 0: the groove runs backwards)."""
    axis: PointElement = follower.centre(motion)
    out_y: FloatArray = np.abs(axis.m0[:, 0])
    out_u: FloatArray = bottom + axis.m1[:, 0]
    return out_y, out_u


def _face_curve(motion: Motion, source: FaceSource, options: BarrelOptions, station: float) -> CurveSample:
    walls = developed_walls(motion, source[0], options, station)
    return walls.upper if source[1] is WallSide.UPPER else walls.lower


class _RibWidth:
    """The signed distance from the rib's upper face at φ to its lower face, in the developed plane at t.

    For each U(φ) the foot L(φ′) on the lower face is found from a k-d tree
    of the lower face sampled every 0.05° and polished by Newton's method on
    g(φ′) = (L − U)·L′ = 0, g′ = |L′|² + (L − U)·L″ (the exact developed
    derivatives); the sign is that of (U − L)·n_U, n_U the upper face's
    normal out of the rib: negative where the faces cross.
    """

    def __init__(
        self,
        program: MotionProgram,
        faces: tuple[FaceSource, FaceSource],
        options: BarrelOptions,
        station: float,
    ) -> None:
        self.program, self.faces, self.options, self.station = program, faces, options, station
        self.phi = np.linspace(0.0, math.tau, 7201)
        lower = _face_curve(program.evaluate(self.phi), faces[1], options, station).point
        self.period = math.tau * station
        shift = np.array([self.period, 0.0])
        from scipy.spatial import cKDTree  # a rib's check only: a plate's check loads no SciPy

        self.tree = cKDTree(np.vstack((lower - shift, lower, lower + shift)))

    def __call__(self, motion: Motion) -> FloatArray:
        upper = _face_curve(motion, self.faces[0], self.options, self.station)
        _, idx = self.tree.query(upper.point)
        n = self.phi.size
        shift = (idx // n - 1).astype(float)  # which copy: −1, 0, +1 periods
        foot = self.phi[idx % n] + shift * math.tau
        for _ in range(8):
            lower = _face_curve(
                self.program.evaluate(np.mod(foot, math.tau)), self.faces[1], self.options, self.station
            )
            point = lower.point + np.column_stack((np.floor(foot / math.tau) * self.period, 0.0 * foot))
            diff = point - upper.point
            g = np.sum(diff * lower.d1, axis=1)
            dg = np.sum(lower.d1 * lower.d1, axis=1) + np.sum(diff * lower.d2, axis=1)
            foot = foot - g / dg
        lower = _face_curve(
            self.program.evaluate(np.mod(foot, math.tau)), self.faces[1], self.options, self.station
        )
        point = lower.point + np.column_stack((np.floor(foot / math.tau) * self.period, 0.0 * foot))
        gap = upper.point - point
        # the upper face is its roller's lower wall: its developed normal (towards +w) points out of the rib
        sign = np.sign(np.sum(gap * upper.normal, axis=1))
        out: FloatArray = sign * np.hypot(gap[:, 0], gap[:, 1])
        return out


def barrel_limits(
    program: MotionProgram,
    follower: BarrelFollower,
    options: BarrelOptions,
    *,
    step: float = math.radians(0.5),
) -> BarrelLimits:
    """Check a barrel cam over the turn and return its limits (``step`` [rad]: the sample grid).

    Raises
    ------
    DesignError
        What :func:`~camcad.geometry.barrel.check_barrel` refuses; and, from
        the motion: the groove (or rib) crosses the barrel's end z = 0 or
        z = length (``follower.axial_position``), the arm swings a roller's
        axis out of the groove's bottom cylinder (``follower.pivot_distance``),
        or the developed groove runs backwards and crosses itself
        (``follower.arm_length``).
    """
    check_barrel(options, follower)
    bottom, tp, top = options.bottom_radius, options.pitch_station, options.barrel_radius
    stations = np.array([bottom, tp, top])
    k = options.taper
    faces = face_rollers(follower, options)
    rollers = [faces[0][0]] if faces[0][0] is faces[1][0] else [faces[0][0], faces[1][0]]
    rib = options.kind is BarrelKind.RIB
    widths = (
        {name: _RibWidth(program, faces, options, t) for name, t in (("bottom", bottom), ("top", top))}
        if rib
        else {}
    )

    def rows(phi: FloatArray, side: Side) -> FloatArray:
        m = program.evaluate(phi, side=side)
        alpha = np.zeros((phi.size, 3))
        off = np.zeros(phi.size)
        advance = np.full(phi.size, np.inf)
        for roller in rollers:
            up = _contact(roller.centre(m), stations, options, WallSide.UPPER, clearance=True)
            alpha = np.maximum(alpha, np.abs(_pressure(up, roller.driven(m), k)))
            o, a = _axis_rows(m, roller, bottom)
            off, advance = np.maximum(off, o), np.minimum(advance, a)
        stretch = [_face_curve(m, src, options, t).d1[:, 0] / t for t in (tp, bottom) for src in faces]
        # a groove's walls reach farthest from the pitch line at the barrel's surface, a rib's at its root
        radii = (top, bottom) if rib else (top,)
        z_low = np.min(
            [faces_at_radius(m, follower, options, r, WallSide.LOWER)[1].point[:, 0, 2] for r in radii],
            axis=0,
        )
        z_high = np.max(
            [faces_at_radius(m, follower, options, r, WallSide.UPPER)[1].point[:, 0, 2] for r in radii],
            axis=0,
        )
        extra = [widths["bottom"](m), widths["top"](m)] if rib else []
        return np.vstack((alpha.T, *stretch, z_low, z_high, off, advance, *extra))

    kinds: tuple[Kind, ...] = ("max", "max", "max", "min", "min", "min", "min", "min", "max", "max", "min")
    if rib:
        kinds = (*kinds, "min", "min")
    joints = [bp.phi for bp in program.breakpoints]
    found = extremes_rows(rows, program.sample_phi(step), joints, kinds)
    a_bot, a_pitch, a_top, sp_u, sp_l, sb_u, sb_l, z_low, z_high, off, advance = found[:11]
    thickness = dict(zip(("bottom", "top"), found[11:], strict=True)) if rib else {}
    if off.value >= bottom:
        raise DesignError(
            Knob.PIVOT_DISTANCE,
            f"the arm swings the roller's axis {off.value:.3f} mm off the barrel's axis {off.where()}, "
            f"beyond the groove's bottom radius {bottom:g} mm; bring the pivot nearer or shorten the swing",
        )
    if advance.value <= 0.0:
        raise DesignError(
            Knob.ARM_LENGTH,
            f"the groove crosses itself {advance.where()}: the arm moves the roller backwards along the "
            f"groove faster than the barrel turns it forward at the bottom ({advance.value:.3f} mm/rad); "
            "use a longer arm, a smaller swing or a larger barrel",
        )
    if z_low.value < 0.0 or z_high.value > options.length:
        bad = z_low if z_low.value < 0.0 else z_high
        what = "rib" if rib else "groove"
        raise DesignError(
            Knob.AXIAL_POSITION,
            f"the {what} reaches z = {bad.value:.3f} mm {bad.where()}, beyond the barrel's ends "
            f"0 … {options.length:g} mm; move axial_position or lengthen the barrel",
        )
    what = "rib's" if rib else "groove's"
    findings = [
        Finding(
            kind="groove undercut",
            severity=Severity.HARD,
            field=Knob.BARREL_RADIUS,
            field_first=True,
            message=(
                f"the {what} {name} {'face' if rib else 'wall'} loops at the {where} "
                f"(station {t:g} mm) {ext.where()}: the developed pitch line bends more sharply than the "
                "roller; use a larger barrel, a smaller roller, a shallower groove or a gentler law"
            ),
            angle=ext.phi,
            value=ext.value,
            limit=0.0,
            unit="",
        )
        for ext, name, where, t in (
            (sb_u, "upper", "groove's bottom", bottom),
            (sb_l, "lower", "groove's bottom", bottom),
        )
        if ext.value <= 0.0
    ]
    findings += [
        Finding(
            kind="rib vanishes",
            severity=Severity.HARD,
            field=Knob.RIB_WIDTH,
            field_first=True,
            message=(
                f"the rib's faces cross at its {name} (station {t:g} mm) {ext.where()}, "
                f"where its least width is {ext.value:.3f} mm: a steep flank narrows the rib; "
                "use a wider rib, a gentler law or a larger barrel"
            ),
            angle=ext.phi,
            value=ext.value,
            limit=0.0,
            unit="mm",
        )
        for name, t in (("bottom", bottom), ("top", top))
        if name in thickness and (ext := thickness[name]).value <= 0.0
    ]
    return BarrelLimits(
        pressure_angle_max=(a_bot, a_pitch, a_top),
        stretch_min={"pitch": (sp_u, sp_l), "bottom": (sb_u, sb_l)},
        z_range=(z_low, z_high),
        findings=tuple(findings),
        rib_thickness_min=thickness,
    )
