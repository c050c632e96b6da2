"""CSV tables: motion, profile and dynamics; ``points.csv`` and ``lift.csv`` for inspection and grinding.

``motion.csv``: s, v, a, j per cam angle on a 0.1° grid (``MOTION_TABLE_STEP_DEG``),
in the lift's unit (mm on a slide, degrees of swing on an arm) per radian;
``profile.csv``: the pitch curve, the profile with its outward normal, the
pressure angle and both radii of curvature at the geometry's angles;
``dynamics.csv``: contact force, torque and Hertz stress at the dynamics'
angles, with any further columns the duty stages add.

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

``polar.txt`` (only with ``[tables] wheel_radius = R``), for cam grinders and
CMM software: the centre of a wheel (or probe ball, or tool) of radius R
rolling on the profile, as the distance from the cam axis along the same
rays θ as ``polar_radius_mm``, at ``polar_step_deg`` with ``polar_decimals``
decimals (R = 0 gives the profile itself). Plain text, ASCII, LF line ends:
header lines start with ``#``; then one row per angle, ``angle_deg`` and
``radius_mm`` separated by one space, angles from 0 up to 360° − step::

    # camcad polar table: my cam
    # wheel radius 12.5000 mm: distance of the wheel centre from the cam axis
    # angle a: degrees the cam has turned in its running direction ...
    # columns: angle_deg radius_mm; 360 rows, step 1 deg, radius 4 decimals
    0 52.5000
    1 52.5012
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import GougeError, NotStarShapedError
from camcad.export.records import write_csv, write_text
from camcad.export.spec import TablesSpec
from camcad.geometry.spec import Rotation
from camcad.geometry.tool import check_tool
from camcad.knobs import Knob

if TYPE_CHECKING:
    from camcad.dynamics.results import DynamicsResult
    from camcad.geometry.cam import Cam
    from camcad.geometry.limits import GeometryAnalysis

__all__ = [
    "LIFT_HEADER",
    "MOTION_TABLE_STEP_DEG",
    "POINTS_HEADER",
    "polar_radius",
    "polar_table_text",
    "table_angles",
    "write_dynamics_csv",
    "write_lift_csv",
    "write_motion_csv",
    "write_points_csv",
    "write_polar_table",
    "write_profile_csv",
]

MOTION_TABLE_STEP_DEG = 0.1
"""The angle step of ``motion.csv`` [deg]."""

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


def _curve(cam: Cam, phi: FloatArray, distance: float) -> FloatArray:
    """(n, 2) points of the profile (distance 0) or of its offset by ``distance`` [mm]."""
    out: FloatArray = (cam.profile(phi) if distance == 0.0 else cam.offset_curve(phi, distance)).point
    return out


def polar_radius(cam: Cam, theta: FloatArray, *, rotation: Rotation, distance: float = 0.0) -> FloatArray:
    """Radius of the profile (or of its offset by ``distance``) along the rays at polar angles θ [mm].

    Parameters
    ----------
    cam
        The exact cam; ``cam.offset_curve(phi, distance)`` gives the point at cam
        angle φ (the contact point for ``distance = 0``, the centre of a
        wheel of radius ``distance`` rolling on the profile otherwise).
    theta
        (n,) ray angles [rad], measured like the cam angle (module docstring).
    rotation
        The cam's rotation; fixes which way θ turns.
    distance
        Offset of the curve from the profile [mm], 0 for the profile.

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
    angle = np.unwrap(_ray_angle(_curve(cam, grid, distance), sign))
    if np.any(np.diff(angle) <= 0.0):
        bad = float(grid[int(np.argmax(np.diff(angle) <= 0.0))])
        curve, table = ("profile", "lift.csv") if distance == 0.0 else ("wheel-centre path", "polar.txt")
        raise NotStarShapedError(
            f"the {curve} is not star-shaped about the cam axis near cam angle "
            f"{math.degrees(bad):.2f}°: a ray meets it twice, so {table} has no polar radius; "
            "use a larger base radius or a smaller follower offset",
            field=Knob.BASE_RADIUS,
        )
    start = angle[0]
    target = start + np.mod(theta - start, 2.0 * math.pi)  # in [θ_C(0), θ_C(0) + 2π)
    idx = np.clip(np.searchsorted(angle, target, side="right") - 1, 0, grid.size - 2)
    lo, hi = grid[idx].copy(), grid[idx + 1].copy()
    base = angle[idx]  # unwrapped angle at lo; the bracket spans < π, so wrap relative to it
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        value = _ray_angle(_curve(cam, mid, distance), sign)
        value = base + np.mod(value - base + math.pi, 2.0 * math.pi) - math.pi
        below = value < target
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    point = _curve(cam, 0.5 * (lo + hi), distance)
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


def _angle_decimals(angle_deg: FloatArray) -> int:
    """Fewest decimals (0–6) that write every angle of the grid exactly (to 1e-9°)."""
    for d in range(7):
        if np.all(np.abs(np.round(angle_deg, d) - angle_deg) < 1e-9):
            return d
    return 6


def polar_table_text(cam: Cam, options: TablesSpec, *, name: str = "") -> str:
    """The text of ``polar.txt``: wheel-centre radius per ray angle (module docstring).

    Parameters
    ----------
    cam
        The exact cam.
    options
        ``[tables]``: ``wheel_radius`` [mm] (required here), ``polar_step``
        (or ``step``) [rad], ``polar_decimals``.
    name
        The design's name for the first line (cleaned to printable ASCII).

    Raises
    ------
    GougeError
        When the wheel is larger than the smallest concave radius of the
        profile (it cannot reach the concave stretch), naming
        ``tables.wheel_radius`` and the largest wheel that fits.
    NotStarShapedError
        When a ray from the cam axis meets the wheel-centre path twice.
    """
    radius = options.wheel_radius
    if radius is None:
        raise ValueError("polar.txt needs [tables] wheel_radius")
    try:
        check_tool(cam, radius)
    except GougeError as err:
        raise GougeError(
            f"a wheel of radius {radius:g} mm cannot follow the profile: its "
            f"smallest concave radius is {err.max_tool_radius:.4f} mm (near φ = "
            f"{math.degrees(err.phi_range[0]):.1f}°); allowed: wheel_radius ≤ {err.max_tool_radius:.4f} mm",
            phi_range=err.phi_range,
            max_tool_radius=err.max_tool_radius,
            field=Knob.WHEEL_RADIUS,
        ) from None
    step = options.step if options.polar_step is None else options.polar_step
    angle = table_angles(step)
    rows = polar_radius(cam, angle, rotation=cam.rotation, distance=radius)
    degrees = np.degrees(angle)
    a_dec, r_dec = _angle_decimals(degrees), options.polar_decimals
    sense = "counter-clockwise" if cam.rotation is Rotation.CCW else "clockwise"
    ray = "(sin a, cos a)" if cam.rotation is Rotation.CCW else "(-sin a, cos a)"
    title = " ".join("".join(c if 32 <= ord(c) < 127 else " " if ord(c) < 32 else "?" for c in name).split())
    lines = [
        f"# camcad polar table: {title}",
        f"# wheel radius {radius:.4f} mm: distance of the wheel centre from the cam axis",
        f"# angle a: degrees the cam has turned in its running direction ({sense}) from cam angle 0; "
        f"the wheel sits on the follower's line through the axis, the ray {ray} of the cam frame",
        f"# columns: angle_deg radius_mm; {angle.size} rows, step {360.0 / angle.size:.6g} deg, "
        f"radius {r_dec} decimals",
    ]
    lines += [f"{a:.{a_dec}f} {r:.{r_dec}f}" for a, r in zip(degrees, rows, strict=True)]
    return "\n".join(lines) + "\n"


def write_polar_table(path: str | os.PathLike[str], cam: Cam, options: TablesSpec, *, name: str = "") -> Path:
    """Write ``polar.txt`` (see :func:`polar_table_text`) atomically; return its path."""
    return write_text(path, polar_table_text(cam, options, name=name))


def write_motion_csv(path: str | os.PathLike[str], cam: Cam, *, unit: str) -> Path:
    """``motion.csv``: angle_deg, then s, v, a, j in ``unit`` (mm or deg) per rad^k, every 0.1°."""
    step = math.radians(MOTION_TABLE_STEP_DEG)
    grid = np.arange(round(2 * math.pi / step)) * step
    m = cam.motion(grid)
    u = unit
    columns = {
        "angle_deg": np.degrees(grid),
        f"s_{u}": m.s,
        f"v_{u}_per_rad": m.v,
        f"a_{u}_per_rad2": m.a,
        f"j_{u}_per_rad3": m.j,
    }
    return write_csv(path, columns)


def write_profile_csv(path: str | os.PathLike[str], geometry: GeometryAnalysis) -> Path:
    """``profile.csv``: pitch curve, profile, outward normal, pressure angle [deg], radii [mm] per angle."""
    geo = geometry
    columns = {
        "angle_deg": np.degrees(geo.phi),
        "pitch_x": geo.pitch.point[:, 0],
        "pitch_y": geo.pitch.point[:, 1],
        "x": geo.profile.point[:, 0],
        "y": geo.profile.point[:, 1],
        "nx": geo.profile.normal[:, 0],
        "ny": geo.profile.normal[:, 1],
        "pressure_angle_deg": np.degrees(geo.pressure_angle),
        "rho_pitch_mm": geo.pitch.rho,
        "rho_profile_mm": geo.profile.rho,
    }
    return write_csv(path, columns)


def write_dynamics_csv(
    path: str | os.PathLike[str],
    dynamics: DynamicsResult,
    *,
    extra: dict[str, FloatArray] | None = None,
    later_parts: Sequence[tuple[str, DynamicsResult, dict[str, FloatArray]]] = (),
) -> Path:
    """``dynamics.csv``: contact force [N], torque [N·mm], Hertz stress [MPa], then ``extra``'s columns.

    ``later_parts``: (files' suffix, dynamics, extra columns) of every further
    part (a pair's second plate, ``_2``): its contact force, Hertz stress and
    extra columns follow, each name ending in its suffix, the same figures as
    the first part's. A part on other angles than the first has none here.
    """
    dyn = dynamics
    columns = {
        "angle_deg": np.degrees(dyn.phi),
        "contact_force_N": dyn.contact_force,
        "torque_Nmm": dyn.torque,
        "hertz_stress_MPa": dyn.hertz_stress,
        **(extra or {}),
    }
    for sfx, part, more in later_parts:
        if part.phi.shape != dyn.phi.shape or not np.array_equal(part.phi, dyn.phi):
            continue
        columns[f"contact_force_N{sfx}"] = part.contact_force
        columns[f"hertz_stress_MPa{sfx}"] = part.hertz_stress
        columns |= {f"{key}{sfx}": column for key, column in more.items()}
    return write_csv(path, columns)
