"""What the two oscillating followers share: the arm angle ψ(φ) and points turning about a pivot."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray
from camcad.geometry.envelope import PointElement
from camcad.motion.program import Motion

if TYPE_CHECKING:
    from camcad.geometry.spec import FollowerSpec

__all__ = ["arm_swing", "per_angle", "pivot_problem", "turning_centre", "turning_point"]


def pivot_problem(spec: FollowerSpec, base_radius: float) -> tuple[str, str] | None:
    """Why an arm's pivot cannot be: missing, or inside the base circle (field path, message); or None."""
    d = spec.pivot_distance
    if d is None:
        return ("follower.pivot_distance", f"is required for a {spec.kind.word} follower (mm)")
    if d <= base_radius:
        return (
            "follower.pivot_distance",
            f"{d:g} mm puts the pivot inside the base circle; allowed: > base_radius = {base_radius:g} mm",
        )
    return None


ArmAngles = tuple[FloatArray, FloatArray, FloatArray, FloatArray]


def arm_swing(motion: Motion) -> ArmAngles:
    """ψ [rad] and ψ′, ψ″, ψ‴ [rad/radᵏ]: an oscillating follower's lift is an angle given in degrees."""
    k = math.pi / 180.0
    return (
        np.asarray(motion.s, dtype=float) * k,
        np.asarray(motion.v, dtype=float) * k,
        np.asarray(motion.a, dtype=float) * k,
        np.asarray(motion.j, dtype=float) * k,
    )


def per_angle(value: float | FloatArray) -> float | FloatArray:
    """A length as a factor of (n, 2) points: a scalar as it is, one value per angle (n,) as a column (n, 1).

    Batch analysis (:mod:`camcad.explore.batch`) hands a follower one
    parameter value per angle; each product is then the same IEEE product
    as the scalar one, row by row.
    """
    if np.ndim(value) == 0:
        return value
    column: FloatArray = np.asarray(value, dtype=float)[:, None]
    return column


def turning_point(
    pivot: tuple[float, float] | FloatArray, length: float | FloatArray, theta: ArmAngles
) -> PointElement:
    """The point P + l·e(θ) at distance l [mm] from the pivot P, at angle θ(φ), with three φ-derivatives.

    With e = (cos θ, sin θ) and J e its quarter turn: M′ = lθ′Je,
    M″ = l(θ″Je − θ′²e), M‴ = l((θ‴ − θ′³)Je − 3θ′θ″e). The pivot (2,) or
    (n, 2) and the length, a scalar or (n,), may be one per angle.
    """
    t0, t1, t2, t3 = theta
    e = np.column_stack((np.cos(t0), np.sin(t0)))
    je = np.column_stack((-e[:, 1], e[:, 0]))
    length = per_angle(length)
    return PointElement(
        m0=_turned(pivot, length, e),
        m1=length * t1[:, None] * je,
        m2=length * (t2[:, None] * je - (t1**2)[:, None] * e),
        m3=length * ((t3 - t1**3)[:, None] * je - (3.0 * t1 * t2)[:, None] * e),
    )


def turning_centre(
    pivot: tuple[float, float] | FloatArray, length: float | FloatArray, theta: FloatArray
) -> FloatArray:
    """(n, 2) the point P + l·e(θ) alone [mm]: :func:`turning_point`'s ``m0``, the same bits."""
    return _turned(pivot, per_angle(length), np.column_stack((np.cos(theta), np.sin(theta))))


def _turned(pivot: tuple[float, float] | FloatArray, length: float | FloatArray, e: FloatArray) -> FloatArray:
    out: FloatArray = np.asarray(pivot, dtype=float) + length * e
    return out
