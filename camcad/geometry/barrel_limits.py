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
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import DesignError
from camcad.extremes import Extreme, Kind, Side, extremes_rows
from camcad.findings import Finding, Severity
from camcad.geometry.barrel import (
    BarrelFollower,
    BarrelOptions,
    WallSide,
    _contact,
    _pressure,
    check_barrel,
    walls_at_radius,
)
from camcad.geometry.curves import CurveSample, curve_sample
from camcad.geometry.envelope import PointElement, offset_curve, translation_envelope
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
    pitch station and the top (stations R − depth, t_p, R), in that order;
    ``stretch_min``: the smallest λ of the (upper, lower) wall at the
    pitch station and at the bottom, ``{"pitch": (upper, lower), "bottom": (...)}``
    (≤ 0: the wall loops); ``z_range``: the lowest point of the lower wall
    and the highest of the upper wall, on the barrel's surface (radius R) [mm];
    ``findings``: a hard finding for a wall that loops.
    """

    pressure_angle_max: tuple[Extreme, Extreme, Extreme]
    stretch_min: dict[str, tuple[Extreme, Extreme]]
    z_range: tuple[Extreme, Extreme]
    findings: tuple[Finding, ...]


def _axis_rows(motion: Motion, follower: BarrelFollower, bottom: float) -> tuple[FloatArray, FloatArray]:
    """|y| of the roller's axis, and t + y′ at the bottom station (≤ 0: the groove runs backwards)."""
    axis: PointElement = follower.centre(motion)
    out_y: FloatArray = np.abs(axis.m0[:, 0])
    out_u: FloatArray = bottom + axis.m1[:, 0]
    return out_y, out_u


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
        the motion: the groove crosses the barrel's end z = 0 or z = length
        (``follower.axial_position``), the arm swings the roller's axis out of
        the groove's bottom cylinder (``follower.pivot_distance``), or the
        developed groove runs backwards and crosses itself
        (``follower.arm_length``).
    """
    check_barrel(options, follower)
    bottom, tp, top = options.bottom_radius, options.pitch_station, options.barrel_radius
    stations = np.array([bottom, tp, top])
    k = options.taper

    def rows(phi: FloatArray, side: Side) -> FloatArray:
        m = program.evaluate(phi, side=side)
        axis = follower.centre(m)
        up = _contact(axis, stations, options, WallSide.UPPER, clearance=True)
        alpha = np.abs(_pressure(up, follower.driven(m), k))
        pitch_walls = developed_walls(m, follower, options, tp)
        bottom_walls = developed_walls(m, follower, options, bottom)
        # the walls' edges on the barrel's surface (each wall reaches farthest from the pitch line there)
        z_low = walls_at_radius(m, follower, options, top, WallSide.LOWER)[1].point[:, 0, 2]
        z_high = walls_at_radius(m, follower, options, top, WallSide.UPPER)[1].point[:, 0, 2]
        off, advance = _axis_rows(m, follower, bottom)
        return np.vstack(
            (
                alpha.T,
                pitch_walls.stretch_upper,
                pitch_walls.stretch_lower,
                bottom_walls.stretch_upper,
                bottom_walls.stretch_lower,
                z_low,
                z_high,
                off,
                advance,
            )
        )

    kinds: tuple[Kind, ...] = ("max", "max", "max", "min", "min", "min", "min", "min", "max", "max", "min")
    joints = [bp.phi for bp in program.breakpoints]
    found = extremes_rows(rows, program.sample_phi(step), joints, kinds)
    a_bot, a_pitch, a_top, sp_u, sp_l, sb_u, sb_l, z_low, z_high, off, advance = found
    if off.value >= bottom:
        raise DesignError(
            "follower.pivot_distance",
            f"the arm swings the roller's axis {off.value:.3f} mm off the barrel's axis {off.where()}, "
            f"beyond the groove's bottom radius {bottom:g} mm; bring the pivot nearer or shorten the swing",
        )
    if advance.value <= 0.0:
        raise DesignError(
            "follower.arm_length",
            f"the groove crosses itself {advance.where()}: the arm moves the roller backwards along the "
            f"groove faster than the barrel turns it forward at the bottom ({advance.value:.3f} mm/rad); "
            "use a longer arm, a smaller swing or a larger barrel",
        )
    if z_low.value < 0.0 or z_high.value > options.length:
        bad = z_low if z_low.value < 0.0 else z_high
        raise DesignError(
            "follower.axial_position",
            f"the groove reaches z = {bad.value:.3f} mm {bad.where()}, beyond the barrel's ends "
            f"0 … {options.length:g} mm; move axial_position or lengthen the barrel",
        )
    findings = [
        Finding(
            kind="groove undercut",
            severity=Severity.HARD,
            field="cam.barrel_radius",
            message=(
                f"cam.barrel_radius: the groove's {name} wall loops at the {where} (station {t:g} mm) "
                f"{ext.where()}: the developed pitch line bends more sharply than the roller; use a larger "
                "barrel, a smaller roller, a shallower groove or a gentler law"
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
    return BarrelLimits(
        pressure_angle_max=(a_bot, a_pitch, a_top),
        stretch_min={"pitch": (sp_u, sp_l), "bottom": (sb_u, sb_l)},
        z_range=(z_low, z_high),
        findings=tuple(findings),
    )
