"""Rotary-axis machining: the cam turned past a tool whose centre moves on a line through its axis.

The machine (``[gcode] machine = "rotary"``): the cam's axis is the machine's
Z axis and the cam turns on the rotary axis (``A`` or ``C``); the tool (an
end mill cutting with its side, or a grinding wheel), its axis parallel to
the cam's, has its centre on the machine's +X half-line through the cam
axis, X millimetres from it. Turning the cam by θ (counter-clockwise seen
from +Z) shows the tool centre at R(−θ)·(X, 0) in the cam frame, so the tool
follows the exact offset curve Q(φ) = ``cam.offset_curve(φ, r_tool)`` when

    X = |Q(φ)|,    θ = −atan2(Q_y, Q_x)   (unwrapped),

and the rotary word is θ in degrees, or −θ when ``rotary_direction = "cw"``
(a machine whose rotary word grows as the cam turns clockwise seen from +Z).
At rotary word 0 the cam frame lies on the machine frame.

Between two blocks a controller moves X and the rotary axis linearly in
time (G93: each block takes 1/F minutes), so in the cam frame the tool
centre runs along an Archimedean spiral r = X(θ), linear in θ, from one
block's point to the next. :func:`plan_rotary` chooses the blocks so that
this spiral stays within ``gcode.tolerance`` of the exact offset curve,
measured in the cam frame on the rounded X and angle words that are
written: the radial gap |Q(φ)| − X(θ(φ)) between the exact point and the
spiral at the same polar angle bounds the distance both ways (from every
exact point to the spiral and back), and its largest value over the turn
is certified on the exact curve with :func:`camcad.extremes.maximum`
(sampled, then refined between samples, both sides of every joint).

Feed: the cut runs in inverse time (G93); block i takes
T_i = L_i / feed minutes, L_i the length of the profile (the contact path)
between the block's cam angles, so the contact moves over the cam surface at
``feed`` mm/min; F_i = 1/T_i.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import DesignError, GougeError, NotStarShapedError
from camcad.extremes import maximum
from camcad.geometry.cam import Cam
from camcad.geometry.spec import Rotation
from camcad.geometry.tool import check_tool
from camcad.knobs import Knob
from camcad.motion.program import Side
from camcad.toolpath.spec import Cutter, Direction, GcodeSpec, Machine

__all__ = [
    "ANGLE_DECIMALS",
    "MIN_RATE",
    "X_DECIMALS",
    "RotaryToolpath",
    "plan_rotary",
    "rotary_levels",
]

X_DECIMALS = 4  # X words [mm], as the XY programs write coordinates
ANGLE_DECIMALS = 6  # rotary words [deg]: 5e-7° at a 1 m radius is 9 nm
_GRID_STEP = math.radians(0.02)  # the planner's sample step [rad]; certified between samples
_MAX_SPAN = math.radians(90.0)  # a block turns the cam by at most this (keeps polar angles unambiguous)
_PLAN_SHARE = 0.9  # plan to this share of the tolerance on the samples; the certificate takes the rest
_MAX_SPLITS = 200
MIN_RATE = 0.1 * 1.5  # mm/min: LinuxCNC's slowest G93 rate (0.1) with a margin for its 4-decimal rounding
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)  # contact-path length per sample interval


@dataclass(frozen=True, slots=True, kw_only=True)
class RotaryToolpath:
    """A planned rotary program: one revolution of blocks, run once per depth level.

    Attributes
    ----------
    name
        Design name for the header.
    spec
        The ``[gcode]`` options (machine, axis, direction, cutter, feeds).
    thickness
        Plate thickness [mm].
    phi
        (n + 1,) cam angles φ of the block ends in cutting order [rad]; the
        last is the first ± 2π.
    x
        (n + 1,) X words: tool-centre distance from the cam axis [mm], rounded
        to ``X_DECIMALS``.
    turn_deg
        (n + 1,) the cam's turn θ [deg] (counter-clockwise seen from +Z),
        unwrapped, rounded to ``ANGLE_DECIMALS``.
    contact_length
        (n,) length of the profile the contact runs over in each block [mm].
    inverse_feed
        (n,) the G93 F word of each block: feed / contact_length [1/min].
    levels
        Z of each revolution (the tool's lower end) [mm].
    x_clear
        X where the tool clears the cam at every angle [mm].
    max_deviation
        Certified largest radial gap between the written X–θ path and the
        exact offset curve [mm] (bounds the distance both ways).
    max_deviation_phi
        Cam angle where it occurs [rad].
    concave_radius_min
        Smallest concave radius of the profile [mm] (inf if none): the
        largest tool or wheel radius that cuts the profile exactly.
    """

    name: str
    spec: GcodeSpec
    thickness: float
    phi: FloatArray
    x: FloatArray
    turn_deg: FloatArray
    contact_length: FloatArray
    inverse_feed: FloatArray
    levels: tuple[float, ...]
    x_clear: float
    max_deviation: float
    max_deviation_phi: float
    concave_radius_min: float

    @property
    def rotary_words(self) -> FloatArray:
        """(n + 1,) the rotary axis words [deg]: θ, or −θ for ``rotary_direction = "cw"``."""
        sign = 1.0 if self.spec.rotary_direction is Rotation.CCW else -1.0
        out: FloatArray = np.round(sign * self.turn_deg, ANGLE_DECIMALS) + 0.0
        readonly(out)
        return out

    @property
    def blocks_per_revolution(self) -> int:
        """G93 blocks in one revolution."""
        return int(self.contact_length.size)

    def revolution_time(self) -> float:
        """Time of one revolution at the programmed inverse-time feeds [s]."""
        return float(np.sum(1.0 / self.inverse_feed)) * 60.0

    def cycle_time(self) -> float:
        """Cutting time of every revolution plus the radial infeeds and retracts [s]."""
        infeed = 2.0 * (self.x_clear - float(self.x[0])) / self.spec.plunge_feed * 60.0
        return len(self.levels) * (self.revolution_time() + infeed)


def rotary_levels(spec: GcodeSpec, thickness: float) -> tuple[float, ...]:
    """Z of each revolution [mm]: one at full depth for a wheel, step-downs for an end mill.

    The depth is thickness + breakthrough below Z0 (the top of the stock),
    in ⌈depth / step_down⌉ equal steps for an end mill, as the XY program cuts.
    """
    depth = thickness + spec.breakthrough
    n = 1 if spec.cutter is Cutter.WHEEL else max(1, math.ceil(depth / spec.step_down - 1e-9))
    return tuple(round(-depth * k / n, X_DECIMALS) + 0.0 for k in range(1, n + 1))


def _check_cutter(cam: Cam, spec: GcodeSpec) -> float:
    """Smallest concave radius [mm]; a tool or wheel larger than it is refused (hard limit)."""
    try:
        return check_tool(cam, spec.tool_radius)
    except GougeError as err:
        if spec.cutter is not Cutter.WHEEL:
            raise
        largest = err.max_tool_radius
        raise GougeError(
            f"a wheel of radius {spec.tool_radius:g} mm grinds the profile exactly "
            f"only where every concave radius is at least its radius, but the smallest concave radius "
            f"is {largest:.4f} mm (near φ = {math.degrees(err.phi_range[0]):.1f}°); the largest wheel "
            f"is Ø{2.0 * largest:.4f} mm (set the tool diameter to at most that)",
            phi_range=err.phi_range,
            max_tool_radius=largest,
            field=Knob.TOOL_DIAMETER,
        ) from None


def _wrap(angle: FloatArray) -> FloatArray:
    """Angles [rad] into [−π, π)."""
    out: FloatArray = np.mod(angle + math.pi, 2.0 * math.pi) - math.pi
    return out


@dataclass(frozen=True, slots=True)
class _Path:
    """The exact tool-centre path on the planner's grid, in cutting order."""

    phi0: float  # start cam angle [rad]
    sense: float  # +1: φ grows along the cut, −1: it falls
    u: FloatArray  # (N + 1,) distance along the cut in cam angle, 0 … 2π [rad]
    radius: FloatArray  # (N + 1,) |Q| [mm]
    turn: FloatArray  # (N + 1,) θ = −polar angle of Q, unwrapped, shifted [rad]

    def phi(self, u: FloatArray) -> FloatArray:
        """Cam angles [rad] at cut parameters u."""
        out: FloatArray = self.phi0 + self.sense * u
        return out


def _polar(cam: Cam, r: float, phi: FloatArray, side: Side = "right") -> tuple[FloatArray, FloatArray]:
    """|Q| [mm] and θ = −atan2(Q_y, Q_x) [rad, wrapped] of the tool centre at cam angles φ."""
    q = cam.offset_curve(phi, r, side=side).point
    return np.hypot(q[:, 0], q[:, 1]), -np.arctan2(q[:, 1], q[:, 0])


def _path(cam: Cam, spec: GcodeSpec) -> _Path:
    """Sample the offset curve from ``start_angle`` once round, in the order the cut runs."""
    phi0 = spec.start_angle % (2.0 * math.pi)
    grid = cam.sample_phi(_GRID_STEP)
    u = np.unique(np.append(np.mod(grid - phi0, 2.0 * math.pi), 0.0))  # the cut starts at start_angle
    u = np.append(u[(u < 2.0 * math.pi - 1e-12) & ((u == 0.0) | (u > 1e-12))], 2.0 * math.pi)
    want = 1.0 if spec.direction is Direction.CLIMB else -1.0  # climb: the cam turns ccw seen from +Z
    for sense in (1.0, -1.0):
        radius, turn = _polar(cam, spec.tool_radius, phi0 + sense * u)
        turn = np.unwrap(turn)
        if (turn[-1] - turn[0]) * want > 0.0:
            break
    steps = np.diff(turn) * want
    if np.any(steps <= 0.0):
        bad = float(np.mod(phi0 + sense * u[int(np.argmax(steps <= 0.0))], 2.0 * math.pi))
        raise NotStarShapedError(
            f"the tool-centre path is not star-shaped about the cam axis near cam angle "
            f"{math.degrees(bad):.2f}°: a ray from the axis meets it twice, so a tool on a line through "
            "the axis would have to turn the cam back; use machine = 'xy', a smaller tool, or a larger "
            "base radius",
            field=Knob.MACHINE,
        )
    # shift whole turns so that the first rotary word lies in [0°, 360°)
    sign = 1.0 if spec.rotary_direction is Rotation.CCW else -1.0
    turn = turn - sign * 2.0 * math.pi * math.floor(sign * turn[0] / (2.0 * math.pi))
    readonly(u, radius, turn)
    return _Path(phi0=phi0, sense=sense, u=u, radius=radius, turn=turn)


def _words(path: _Path, index: FloatArray | list[int]) -> tuple[FloatArray, FloatArray]:
    """The X and θ words of the samples at ``index``, rounded as written ([mm], [rad])."""
    idx = np.asarray(index, dtype=int)
    x = np.round(path.radius[idx], X_DECIMALS)
    turn = np.radians(np.round(np.degrees(path.turn[idx]), ANGLE_DECIMALS))
    return x, turn


def _arc_lengths(cam: Cam, path: _Path) -> FloatArray:
    """(N + 1,) profile length from the start to each sample [mm] (4-point Gauss–Legendre per step)."""
    u0, u1 = path.u[:-1], path.u[1:]
    nodes = (0.5 * (u0 + u1))[:, None] + (0.5 * (u1 - u0))[:, None] * _GAUSS_X[None, :]
    speed = np.linalg.norm(cam.profile(path.phi(nodes.ravel())).d1, axis=1).reshape(nodes.shape)
    out: FloatArray = np.concatenate(([0.0], np.cumsum(0.5 * (u1 - u0) * (speed @ _GAUSS_W))))
    return out


def _gap(path: _Path, i: int, j: int, x0: float, x1: float) -> float:
    """Largest radial gap [mm] on the samples i…j from the spiral through the words (x0, θ_i), (x1, θ_j)."""
    _, (t0, t1) = _words(path, [i, j])
    along = (path.turn[i : j + 1] - t0) / (t1 - t0)
    return float(np.max(np.abs(path.radius[i : j + 1] - (x0 + along * (x1 - x0)))))


def _greedy(path: _Path, arc: FloatArray, budget: float, feed: float) -> tuple[list[int], list[float]]:
    """Block ends (sample indices) and their written X: each block as long as the samples stay in ``budget``.

    A G93 block whose X moves by less than ``MIN_RATE`` × its time would be
    run too fast: LinuxCNC takes the block's length as its XYZ length (the
    rotary move only when X stands still) and never feeds slower than
    0.1 units/min (``Interp::inverse_time_rate_straight``). Such a block
    keeps X still instead when the path stays within ``budget`` that way.
    """
    last = path.u.size - 1

    def end_x(i: int, j: int, x0: float) -> float:
        x1 = float(np.round(path.radius[j], X_DECIMALS))
        minutes = (arc[j] - arc[i]) / feed
        return x0 if x1 != x0 and abs(x1 - x0) < MIN_RATE * minutes else x1

    def fits(i: int, j: int, x0: float) -> bool:
        return (
            abs(path.turn[j] - path.turn[i]) <= _MAX_SPAN and _gap(path, i, j, x0, end_x(i, j, x0)) <= budget
        )

    ends, xs, i = [0], [float(np.round(path.radius[0], X_DECIMALS))], 0
    while i < last:
        x0 = xs[-1]
        good, step = i + 1, 1
        while good + step <= last and fits(i, good + step, x0):
            good += step
            step *= 2
        bad = min(good + step, last + 1)
        while bad - good > 1:
            mid = (good + bad) // 2
            if fits(i, mid, x0):
                good = mid
            else:
                bad = mid
        x1 = end_x(i, good, x0)
        if good == i + 1 and not fits(i, good, x0):  # one sample step: the exact word, never a drifted one
            x1 = float(np.round(path.radius[good], X_DECIMALS))
        ends.append(good)
        xs.append(x1)
        i = good
    return ends, xs


def _certify(cam: Cam, spec: GcodeSpec, path: _Path, ends: list[int], x: FloatArray) -> tuple[float, float]:
    """The true largest radial gap [mm] of the written path over the turn, and its cam angle [rad]."""
    _, turn = _words(path, ends)
    u_end = path.u[np.asarray(ends)]

    def gap(phi: FloatArray, side: Side) -> FloatArray:
        u = np.mod((phi - path.phi0) * path.sense, 2.0 * math.pi)
        k = np.clip(np.searchsorted(u_end, u, side="right") - 1, 0, len(ends) - 2)
        radius, theta = _polar(cam, spec.tool_radius, phi, side)
        theta = turn[k] + _wrap(theta - turn[k])
        along = (theta - turn[k]) / (turn[k + 1] - turn[k])
        out: FloatArray = np.abs(radius - (x[k] + along * (x[k + 1] - x[k])))
        return out

    grid = np.mod(path.phi(path.u[:-1]), 2.0 * math.pi)
    order = np.argsort(grid)
    joints = [bp.phi for bp in cam.program.breakpoints]
    worst = maximum(gap, grid[order], joints)
    return float(worst.value), float(worst.phi)


def plan_rotary(cam: Cam, spec: GcodeSpec, *, name: str, thickness: float) -> RotaryToolpath:
    """Plan the rotary program: blocks of X and rotary-axis words round the exact offset curve.

    Parameters
    ----------
    cam
        The cam; its exact offset ``cam.offset_curve(φ, r_tool)`` is the tool-centre path.
    spec
        ``[gcode]`` with ``machine = "rotary"``: tool (end mill or wheel)
        diameter, tolerance, direction, start angle, feeds, step-down.
    name
        Design name for the header.
    thickness
        Plate thickness [mm].

    Returns
    -------
    RotaryToolpath
        One revolution of blocks, the depth levels and the certified deviation.

    Raises
    ------
    GougeError
        When the tool or wheel is larger than the smallest concave radius of
        the profile (names ``gcode.tool_diameter`` and the largest that fits).
    NotStarShapedError
        When a ray from the cam axis meets the tool-centre path twice.
    DesignError
        When ``spec.machine`` is not rotary.
    """
    if spec.machine is not Machine.ROTARY:
        raise DesignError(Knob.MACHINE, f"{spec.machine.value!r}: plan_rotary plans machine = 'rotary'")
    concave = _check_cutter(cam, spec)
    path = _path(cam, spec)
    arc = _arc_lengths(cam, path)
    ends, xs = _greedy(path, arc, _PLAN_SHARE * spec.tolerance, spec.feed)
    x = np.asarray(xs)
    deviation, where = _certify(cam, spec, path, ends, x)
    for _ in range(_MAX_SPLITS):
        if deviation <= spec.tolerance:
            break
        # split the block holding the worst point at its middle sample (exact words there), measure again
        u = float(np.mod((where - path.phi0) * path.sense, 2.0 * math.pi))
        k = int(np.clip(np.searchsorted(path.u[np.asarray(ends)], u, side="right") - 1, 0, len(ends) - 2))
        if ends[k + 1] - ends[k] < 2:
            break
        mid = (ends[k] + ends[k + 1]) // 2
        ends.insert(k + 1, mid)
        x = np.insert(x, k + 1, np.round(path.radius[mid], X_DECIMALS))
        deviation, where = _certify(cam, spec, path, ends, x)
    if deviation > spec.tolerance:  # pragma: no cover - a block of one sample step is far within
        raise DesignError(Knob.GCODE_TOLERANCE, f"{spec.tolerance:g} mm cannot be certified on a rotary path")
    _, turn = _words(path, ends)
    length = np.diff(arc[np.asarray(ends)])
    readonly(length)
    inverse = spec.feed / length
    phi = path.phi(path.u[np.asarray(ends)])
    sampled = cam.profile(path.phi(path.u)).point  # 0.02° apart: within nanometres of the true largest radius
    profile_max = float(np.max(np.hypot(sampled[:, 0], sampled[:, 1])))
    x_clear = round(profile_max + spec.tool_radius + spec.safe_height + spec.tolerance, X_DECIMALS)
    turn_deg = np.round(np.degrees(turn), ANGLE_DECIMALS)
    readonly(phi, x, turn_deg, inverse)
    return RotaryToolpath(
        name=name,
        spec=spec,
        thickness=thickness,
        phi=phi,
        x=x,
        turn_deg=turn_deg,
        contact_length=length,
        inverse_feed=inverse,
        levels=rotary_levels(spec, thickness),
        x_clear=x_clear,
        max_deviation=deviation,
        max_deviation_phi=where,
        concave_radius_min=concave,
    )
