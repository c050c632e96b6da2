"""Oscillating (swinging-arm) roller follower."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray
from camcad.geometry.envelope import Guide, PointElement
from camcad.geometry.followers._arm import arm_swing, pivot_problem, turning_centre, turning_point
from camcad.geometry.followers.base import (
    ARM_LIFT,
    PIVOT_DISTANCE,
    ROLLER_RADIUS,
    ROLLER_WORDS,
    FollowerKey,
    FollowerSketch,
    FollowerType,
    Problem,
    Words,
    circle_points,
)
from camcad.motion.program import Motion

if TYPE_CHECKING:
    from camcad.geometry.spec import FollowerSpec

__all__ = ["ARM_LENGTH", "TYPE", "OscillatingRoller"]

ARM_LENGTH = FollowerKey(name="arm_length", description="arm length l, pivot to roller centre (mm)")


@dataclass(frozen=True, slots=True, kw_only=True)
class OscillatingRoller:
    """A roller of radius r_f on an arm of length l that swings about a pivot at distance d from the cam axis.

    Convention: at φ = 0 (ψ = 0) the roller centre stands on the +y axis at
    r_b + r_f from the cam axis and the pivot lies to its right (x > 0). The
    arm angle β (at the pivot, from the line pivot → cam axis to the arm) is
    β = β0 + ψ with cos β0 = (d² + l² − (r_b + r_f)²)/(2dl) (Rothbart 2004,
    §5.3; Chen 1982, eq. 6-12): a rise (ψ growing) swings the roller away from
    the cam axis, which turns the arm clockwise in the machine frame.
    """

    base_radius: float  # r_b [mm]
    roller_radius: float  # r_f [mm]
    pivot_distance: float  # d [mm]
    arm_length: float  # l [mm]

    @property
    def prime_radius(self) -> float:
        """r_b + r_f [mm]: the roller centre's distance from the cam axis at ψ = 0."""
        return self.base_radius + self.roller_radius

    @property
    def pivot(self) -> tuple[float, float]:
        """The pivot (x > 0, y) [mm], machine frame: |pivot| = d, |pivot − (0, r_b + r_f)| = l."""
        r0, d, arm = self.prime_radius, self.pivot_distance, self.arm_length
        y = (d * d - arm * arm + r0 * r0) / (2.0 * r0)
        return (math.sqrt(max(d * d - y * y, 0.0)), y)

    @property
    def initial_arm_angle(self) -> float:
        """β0 [rad]: the arm's angle from the line pivot → cam axis at ψ = 0 (law of cosines)."""
        r0, d, arm = self.prime_radius, self.pivot_distance, self.arm_length
        return math.acos(max(-1.0, min(1.0, (d * d + arm * arm - r0 * r0) / (2.0 * d * arm))))

    @property
    def cam_direction(self) -> float:
        """γ [rad]: the direction from the pivot to the cam axis, machine frame."""
        px, py = self.pivot
        return math.atan2(-py, -px)

    @property
    def arm_direction(self) -> float:
        """The arm's direction pivot → roller centre at ψ = 0, machine frame [rad]."""
        px, py = self.pivot
        return math.atan2(self.prime_radius - py, -px)

    def arm_angle(self, motion: Motion) -> FloatArray:
        """β = β0 + ψ [rad] at the motion's angles."""
        out: FloatArray = self.initial_arm_angle + arm_swing(motion)[0]
        return out

    @property
    def guide(self) -> Guide:
        """The pivot; a growing ψ turns the arm clockwise."""
        return Guide(pivot=self.pivot, turn=-1.0)

    def element(self, motion: Motion) -> PointElement:
        """The roller centre P + l·e(θ), θ = γ − β0 − ψ with γ the direction pivot → cam axis."""
        psi, d1, d2, d3 = arm_swing(motion)
        return turning_point(self.pivot, self.arm_length, (self._theta(psi), -d1, -d2, -d3))

    def _theta(self, psi: FloatArray) -> FloatArray:
        """θ = γ − β0 − ψ [rad]: the arm's direction pivot → roller centre at arm swing ψ [rad]."""
        out: FloatArray = self.cam_direction - self.initial_arm_angle - psi
        return out

    def trace(self, motion: Motion) -> PointElement:
        """The roller centre: the element itself."""
        return self.element(motion)

    def describe(self) -> str:
        """E.g. ``"oscillating roller, r_f = 15 mm, d = 120 mm, l = 90 mm"``."""
        return (
            f"oscillating roller, r_f = {self.roller_radius:g} mm, d = {self.pivot_distance:g} mm, "
            f"l = {self.arm_length:g} mm"
        )

    def contact_position(self, contact: FloatArray, motion: Motion) -> FloatArray:
        """The contact's signed distance from the arm's line [mm] (r_f·sin α; + to the arm's left)."""
        centre = turning_centre(self.pivot, self.arm_length, self._theta(arm_swing(motion)[0]))
        arm = centre - np.asarray(self.pivot)
        unit = arm / np.hypot(arm[:, 0], arm[:, 1])[:, None]
        rel = contact - centre
        out: FloatArray = unit[:, 0] * rel[:, 1] - unit[:, 1] * rel[:, 0]
        return out

    def sketch(self, motion: Motion, *, size: float) -> list[FollowerSketch]:
        """Roller, arm from the pivot to the roller centre, and the pivot, at each angle."""
        pivot = np.asarray(self.pivot)
        out = []
        for centre in self.element(motion).m0:
            radial = centre / np.hypot(*centre)  # the label goes outward, beyond the roller
            out.append(
                FollowerSketch(
                    body=(circle_points(centre, self.roller_radius),),
                    links=(np.array([pivot, centre]),),
                    axes=(),
                    marks=np.array([centre, pivot]),
                    tip=centre + (self.roller_radius + 0.05 * size) * radial,
                    heading=radial,
                )
            )
        return out

    @property
    def contact_radius(self) -> float:
        """r_f [mm]: the roller's radius sets the contact stress."""
        return self.roller_radius

    @property
    def rolls(self) -> bool:
        """True: a roller turning on its bearing."""
        return True

    @property
    def words(self) -> Words:
        """A roller's names."""
        return ROLLER_WORDS

    def rows(self) -> tuple[tuple[str, float | None], ...]:
        """Roller radius; no offset on an arm."""
        return (("roller radius [mm]", self.roller_radius), ("follower offset [mm]", None))


def _build(spec: FollowerSpec, base_radius: float) -> OscillatingRoller:
    assert spec.pivot_distance is not None and spec.arm_length is not None  # the schema requires them
    return OscillatingRoller(
        base_radius=base_radius,
        roller_radius=spec.roller_radius,
        pivot_distance=spec.pivot_distance,
        arm_length=spec.arm_length,
    )


def _check(spec: FollowerSpec, base_radius: float, swing: float) -> Problem:
    """The arm must reach the roller's start on the base circle and not swing past the line pivot → cam axis.

    |d − l| ≤ r_b + r_f ≤ d + l, and β0 + ψ < 180° (after which the roller
    would come back towards the cam); ``swing`` is the largest ψ [degrees].
    """
    problem = pivot_problem(spec, base_radius)
    if problem is not None:
        return problem
    d, arm = spec.pivot_distance, spec.arm_length
    assert d is not None
    if arm is None:
        return ("follower.arm_length", f"is required for an {spec.kind.word} follower (mm)")
    r0 = base_radius + spec.roller_radius
    if abs(d - arm) > r0 or d + arm < r0:
        return (
            "follower.arm_length",
            f"{arm:g} mm cannot reach the roller's start on the base circle: with pivot_distance "
            f"{d:g} mm the arm must be between |d − (r_b + r_f)| = {abs(d - r0):g} mm and "
            f"d + r_b + r_f = {d + r0:g} mm",
        )
    beta0 = math.degrees(math.acos(max(-1.0, min(1.0, (d * d + arm * arm - r0 * r0) / (2.0 * d * arm)))))
    if beta0 + swing >= 180.0:
        return (
            "motion",
            f"the arm swings {swing:g}° from its start at {beta0:.2f}° off the line pivot → cam "
            f"axis, past 180°: the roller would swing back towards the cam axis; allowed: a "
            f"largest lift below {180.0 - beta0:.2f}°",
        )
    return None


TYPE = FollowerType(
    word="oscillating-roller",
    order=3,
    keys=(ROLLER_RADIUS, PIVOT_DISTANCE, ARM_LENGTH),
    required=("roller_radius", "pivot_distance", "arm_length"),
    lift=ARM_LIFT,
    face=False,
    two_sided=True,
    build=_build,
    check=_check,
)
"""``type = "oscillating-roller"``: a roller on a swinging arm; its lift is the arm's swing in degrees."""
