"""CSV tables for inspection and rotary grinding: ``points.csv`` and ``lift.csv``.

Both tables use one uniform angle grid: n = ⌈2π / ``[tables].step``⌉ rows at
angles 2πi/n, so the grid closes the turn exactly (the step is shrunk
slightly when 2π is not a multiple of it). Angles are written in degrees and
lengths in millimetres, the unit in each column name, with fixed decimals.

``points.csv``, per cam angle φ: ``cam_angle_deg, x_mm, y_mm, normal_x,
normal_y, radius_of_curvature_mm``, the exact contact point of the profile in
the cam frame (origin on the cam axis, follower on +y at φ = 0), its outward
unit normal and signed radius of curvature (positive convex, ``inf`` where
straight).

``lift.csv``, per angle ``angle_deg``:

``lift_mm``
    Follower lift s(φ) at cam angle φ = angle.
``polar_radius_mm``
    Distance from the cam axis to the profile along the ray at polar angle
    θ = angle. θ is measured like the cam angle: it is the direction of the
    follower axis (+y of the follower frame) after the cam has turned by θ,
    u(θ) = (±sin θ, cos θ), + for a counter-clockwise cam, − for clockwise.
    So a probe or grinding wheel on a fixed radial line reads this radius
    when the table has turned by θ. It is not the radius of the contact
    point at cam angle φ = θ, which lies off the ray for a roller or offset
    follower; the crossing is solved exactly on the analytic profile.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import NotStarShapedError
from camcad.export.records import write_csv
from camcad.export.spec import TablesSpec
from camcad.geometry.spec import Rotation

if TYPE_CHECKING:
    from camcad.geometry.cam import Cam

__all__ = [
    "LIFT_HEADER",
    "POINTS_HEADER",
    "polar_radius",
    "table_angles",
    "write_lift_csv",
    "write_points_csv",
]

POINTS_HEADER = "cam_angle_deg,x_mm,y_mm,normal_x,normal_y,radius_of_curvature_mm"
LIFT_HEADER = "angle_deg,lift_mm,polar_radius_mm"
_BISECTIONS = 60  # halves a bracket of ≤ 2π/n down to round-off


def table_angles(step: float) -> FloatArray:
    """Return the table grid: n = ⌈2π/step⌉ angles 2πi/n [rad], (n,), read-only."""
    if not step > 0.0:
        raise ValueError(f"table step must be > 0 rad, got {step!r}")
    n = max(1, math.ceil(2.0 * math.pi / step - 1e-9))
    out = 2.0 * math.pi * np.arange(n) / n
    readonly(out)
    return out


def _ray_angle(points: FloatArray, sign: float) -> FloatArray:
    """θ of points: the angle of u(θ) = (sign·sin θ, cos θ) through them [rad], in (−π, π]."""
    return np.arctan2(sign * points[:, 0], points[:, 1])


def polar_radius(cam: Cam, theta: FloatArray, *, rotation: Rotation) -> FloatArray:
    """Radius of the profile along the rays at polar angles θ [mm].

    Parameters
    ----------
    cam
        The exact cam; ``cam.profile(phi)`` gives the contact point at cam
        angle φ.
    theta
        (n,) ray angles [rad], measured like the cam angle (module docstring).
    rotation
        The cam's rotation; fixes which way θ turns.

    Returns
    -------
    FloatArray
        (n,) radii [mm], read-only.

    Raises
    ------
    NotStarShapedError
        When the profile is not star-shaped about the cam axis (a ray crosses
        it more than once), so a polar radius is not defined.

    Notes
    -----
    As φ grows the contact point turns the same way as θ, so the profile's
    own ray angle θ_C(φ) increases. It is unwrapped on the fine grid
    ``cam.sample_phi()``, each θ is bracketed there, and the crossing
    θ_C(φ*) = θ is found by bisection on the analytic profile to round-off;
    the radius is |C(φ*)|.
    """
    sign = 1.0 if rotation is Rotation.CCW else -1.0
    theta = np.asarray(theta, dtype=float)
    grid = np.append(cam.sample_phi(), 2.0 * math.pi)
    angle = np.unwrap(_ray_angle(cam.profile(grid).point, sign))
    if np.any(np.diff(angle) <= 0.0):
        bad = float(grid[int(np.argmax(np.diff(angle) <= 0.0))])
        raise NotStarShapedError(
            f"cam.base_radius: the profile is not star-shaped about the cam axis near cam angle "
            f"{math.degrees(bad):.2f}°: a ray meets it twice, so lift.csv has no polar radius; "
            "use a larger cam.base_radius or a smaller follower.offset"
        )
    start = angle[0]
    target = start + np.mod(theta - start, 2.0 * math.pi)  # in [θ_C(0), θ_C(0) + 2π)
    idx = np.clip(np.searchsorted(angle, target, side="right") - 1, 0, grid.size - 2)
    lo, hi = grid[idx].copy(), grid[idx + 1].copy()
    base = angle[idx]  # unwrapped angle at lo; the bracket spans < π, so wrap relative to it
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        value = _ray_angle(cam.profile(mid).point, sign)
        value = base + np.mod(value - base + math.pi, 2.0 * math.pi) - math.pi
        below = value < target
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    point = cam.profile(0.5 * (lo + hi)).point
    out = np.hypot(point[:, 0], point[:, 1])
    readonly(out)
    return out


def write_points_csv(path: str | os.PathLike[str], cam: Cam, options: TablesSpec) -> Path:
    """Write ``points.csv``: profile points per cam angle (module docstring).

    Parameters
    ----------
    path
        Target file.
    cam
        The exact cam.
    options
        ``[tables]``: ``step`` [rad] sets the grid.

    Returns
    -------
    Path
        The written file.
    """
    phi = table_angles(options.step)
    prof = cam.profile(phi)
    columns = [
        np.degrees(phi),
        prof.point[:, 0],
        prof.point[:, 1],
        prof.normal[:, 0],
        prof.normal[:, 1],
        prof.rho,
    ]
    formats = ["{:.6f}", "{:.6f}", "{:.6f}", "{:.9f}", "{:.9f}", "{:.6f}"]
    return write_csv(path, dict(zip(POINTS_HEADER.split(","), columns, strict=True)), formats=formats)


def write_lift_csv(path: str | os.PathLike[str], cam: Cam, options: TablesSpec) -> Path:
    """Write ``lift.csv``: lift per cam angle and polar radius per ray angle (module docstring).

    Parameters
    ----------
    path
        Target file.
    cam
        The exact cam.
    options
        ``[tables]``: ``step`` [rad] sets the grid; the cam's rotation the sense of θ.

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    NotStarShapedError
        When the profile is not star-shaped about the cam axis.
    """
    angle = table_angles(options.step)
    lift = cam.motion(angle).s
    radius = polar_radius(cam, angle, rotation=cam.rotation)
    columns = dict(zip(LIFT_HEADER.split(","), [np.degrees(angle), lift, radius], strict=True))
    return write_csv(path, columns, formats=["{:.6f}"] * 3)
