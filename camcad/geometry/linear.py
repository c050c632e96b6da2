"""Linear cams: a plate translating along x under a plate cam's roller follower.

The plate-cam core with a translation instead of a rotation. One cycle of the
motion program (φ from 0 to 2π) moves the plate by ``stroke_length`` L [mm],
so the follower sits at plate coordinate x = Lφ/2π, i.e. c = L/2π [mm/rad]
of plate per radian of motion. In the plate's frame a machine point M(φ)
of the follower is at X(φ) = M(φ) + (cφ, 0)
(:func:`camcad.geometry.envelope.translation_envelope`); the plate moves
towards −x in the machine, so the follower walks it towards +x, as it walks
a counter-clockwise disc cam's pitch curve clockwise (the disc cam's limit
r_b → ∞ with r_b·φ held).

Frames: machine frame = plate frame at φ = 0; x along the plate's travel, y
towards the follower; the follower modules are the plate cam's (their
``base_radius`` is the base line's height y = r_b above the reference line
y = 0). A translating roller at eccentricity e stands at x = e; the profile
is the pitch line offset by −r_f, towards the plate.

Pressure angle: as on a ccw disc cam (:func:`camcad.geometry.envelope.pressure_angle`);
a translating roller has tan α = s′/c = 2πs′/L exactly (the disc cam's
tan α = s′/(r_b + r_f + s) with the radius replaced by c).

Flat-faced followers are refused: a translating face does not turn relative
to a translating plate, so the family of face lines has no envelope (the face
touches only the plate's highest point under it), and an oscillating face
turns only while ψ′ ≠ 0, which fails at every dwell and every turning point
of ψ.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import DesignError
from camcad.extremes import Extreme, Kind, Side, extremes_rows
from camcad.findings import Finding, Severity
from camcad.geometry.curves import CurveSample
from camcad.geometry.envelope import PointElement, offset_curve, pressure_angle, translation_envelope
from camcad.geometry.followers import FOLLOWER_TYPES
from camcad.geometry.followers.base import Follower
from camcad.knobs import Knob
from camcad.motion.program import Motion, MotionProgram

__all__ = ["LinearLimits", "LinearOptions", "LinearState", "linear_limits", "linear_state"]


@dataclass(frozen=True, slots=True, kw_only=True)
class LinearOptions:
    """A linear cam: ``stroke_length`` L [mm] of plate travel per cycle of the motion (2π)."""

    stroke_length: float

    @property
    def speed(self) -> float:
        """Speed c = L/2π [mm/rad]: plate travel per radian of the motion."""
        return self.stroke_length / (2.0 * math.pi)


@dataclass(frozen=True, slots=True, kw_only=True)
class LinearState:
    """The linear cam at some motion angles, plate frame.

    ``travel`` (n,) [mm] is the plate coordinate x = Lφ/2π; ``pitch`` the
    roller centre's path and ``profile`` the plate's edge (pitch offset by
    −r_f), each with exact tangents, normals (towards the follower) and
    signed radii (positive convex); ``pressure_angle`` (n,) [rad], signed,
    positive where the normal leans towards +x (on a rise).
    """

    travel: FloatArray
    pitch: CurveSample
    profile: CurveSample
    pressure_angle: FloatArray


def _roller(follower: Follower, options: LinearOptions) -> float:
    if not options.stroke_length > 0.0 or not math.isfinite(options.stroke_length):
        raise DesignError(
            Knob.STROKE_LENGTH, f"{options.stroke_length!r} mm is not allowed; give a length > 0 mm"
        )
    if not follower.roller_radius > 0.0:
        raise DesignError(
            Knob.FOLLOWER_TYPE,
            "a flat face has no envelope on a linear cam (it does not turn relative to the plate); "
            f"use {' or '.join(t.word for t in FOLLOWER_TYPES.values() if t.two_sided)}",
        )
    return follower.roller_radius


def linear_state(motion: Motion, follower: Follower, options: LinearOptions) -> LinearState:
    """Pitch line, profile and pressure angle of a linear cam at the motion's angles.

    Parameters
    ----------
    motion
        s, v, a, j at the angles φ (n,) [rad].
    follower
        A roller follower module (:class:`~camcad.geometry.followers.TranslatingRoller`
        or :class:`~camcad.geometry.followers.OscillatingRoller`), whose
        ``base_radius`` is the base line's height [mm].
    options
        The stroke length.

    Raises
    ------
    DesignError
        ``cam.stroke_length`` ≤ 0, or a flat-faced follower (``follower.type``).
    """
    r_f = _roller(follower, options)
    element = follower.element(motion)
    assert isinstance(element, PointElement)  # a roller's element is its centre
    pitch, drho = translation_envelope(motion.phi, element, options.speed)
    profile = offset_curve(pitch, drho, -r_f)
    # the plate does not turn: its frame is the machine frame turned by 0 (σ = +1 as for a ccw disc)
    zero = np.zeros_like(motion.phi)
    alpha = pressure_angle(zero, profile.normal, element.m0, follower.guide, 1.0)
    travel = options.speed * np.asarray(motion.phi, dtype=float)
    readonly(travel)
    return LinearState(travel=travel, pitch=pitch, profile=profile, pressure_angle=alpha)


@dataclass(frozen=True, slots=True, kw_only=True)
class LinearLimits:
    """True extremes over the cycle (one-sided at joints).

    ``pressure_angle_max``: the largest |α| [rad]; ``pitch_convex_min``: the
    pitch line's smallest convex radius [mm] (the profile loops where it is
    ≤ r_f; +inf where never convex); ``profile_concave_min``: the profile's
    smallest concave radius [mm] (the largest cutter; +inf where never
    concave); ``findings``: a hard undercut finding.
    """

    pressure_angle_max: Extreme
    pitch_convex_min: Extreme
    profile_concave_min: Extreme
    findings: tuple[Finding, ...]


def linear_limits(
    program: MotionProgram, follower: Follower, options: LinearOptions, *, step: float = math.radians(0.5)
) -> LinearLimits:
    """Pressure angle, undercut and the largest cutter of a linear cam, at true extremes.

    ``step`` [rad] is the sample grid the extremes are refined from.
    """
    r_f = _roller(follower, options)

    def rows(phi: FloatArray, side: Side) -> FloatArray:
        st = linear_state(program.evaluate(phi, side=side), follower, options)
        rho = st.pitch.rho
        convex = np.where(rho > 0.0, rho, np.inf)
        concave = np.where(st.profile.rho < 0.0, -st.profile.rho, np.inf)
        return np.vstack((np.abs(st.pressure_angle), convex, concave))

    kinds: tuple[Kind, ...] = ("max", "min", "min")
    joints = [bp.phi for bp in program.breakpoints]
    alpha, convex, concave = extremes_rows(rows, program.sample_phi(step), joints, kinds)
    findings = []
    if convex.value <= r_f:
        findings.append(
            Finding(
                kind="undercut",
                severity=Severity.HARD,
                field=Knob.STROKE_LENGTH,
                field_first=True,
                message=(
                    f"the profile loops {convex.where()}: the pitch line's convex "
                    f"radius is {convex.value:.3f} mm, not more than the roller radius {r_f:g} mm; "
                    "lengthen the stroke, use a smaller roller or a gentler law"
                ),
                angle=convex.phi,
                value=convex.value,
                limit=r_f,
                unit="mm",
            )
        )
    return LinearLimits(
        pressure_angle_max=alpha,
        pitch_convex_min=convex,
        profile_concave_min=concave,
        findings=tuple(findings),
    )
