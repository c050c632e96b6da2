"""4-axis passes for a barrel cam's groove: rough with a small cutter, finish each wall with the roller's.

Machine convention
------------------
The barrel lies on the rotary axis A, which turns about the machine's X;
the barrel's axis z is machine X (z = 0 at X0); the tool points down the
machine's −Z onto the barrel, its axis on the line Y = const, Z is the
distance of the tool's tip from the barrel's axis. The barrel frame maps
to the machine at A = 0 by x → Z, y → −Y, z → X (a proper rotation), and a
positive A turns the barrel right-handed about +X, so the tool (at +Z) sees
barrel angle θ = −A. The roller's axis at motion angle φ,
t·e_r(φ) + y·e_θ(φ) + z·ẑ (:mod:`camcad.geometry.barrel`), is then the tool's
axis at A = −φ [deg], Y = −y, X = z: the tool moves along the roller's own
path, and a flat end mill of the roller's diameter cuts exactly the
roller's envelope, i.e. the walls of a cylindrical roller, at every station.

Between two blocks X, Y and A move linearly together, so in the developed
plane of every station t (u = tφ + y, w = z) the tool's axis moves on a
straight line between the exact points; its distance from the exact path is
|(Δy, Δz)|, the same at every station, and the wall a disc of fixed radius
sweeps moves by no more than its centre does. Blocks are split until that
distance, checked at every eighth of a block and scaled by 64/63 (the
peak of a parabola lies within 1/16 of a node), is within ``tolerance``,
by bisection.

Passes
------
- Finish, one per wall: the cutter of the roller's diameter on the roller's
  path shifted by ±c/2 along the developed pitch line's normal at the pitch
  station (c the clearance), tip at the groove's bottom radius.
- Rough: a smaller cutter on the pitch path shifted by δ along the same
  normal, |δ| ≤ r_w − r_c − stock (r_w = r_f + c/2), in steps no wider than
  ``stepover`` × its diameter, at depth levels ``step_down`` apart down to the
  bottom plus ``stock``. The shift δ moves the cutter's axis by |δ| at every
  station, so the cutter stays at least ``stock`` inside each wall.

A cutter smaller than the roller cannot finish a wall exactly: on the path
offset by r_w − r_c along the pitch station's normal it cuts the wall at
the pitch station only; :func:`small_cutter_deviation` measures the error at
the groove's top and bottom.

A conical roller
----------------
Its wall is the envelope of the surface of revolution r(t) = k·t + c/2
about the roller's axis (:mod:`camcad.geometry.barrel`, apex on the
barrel's axis, widened by half the clearance). A tapered end mill of the
same surface, tip radius r_tip = k·b + c/2 at the groove's bottom station b
and flank taper k (half-angle atan k, the roller's), on the roller's own
path (shift 0) sweeps the same envelope: one pass cuts both walls exactly at
every station, the clearance included. Roughing plans as for a cylindrical
roller of wall radius r_tip: that cylinder lies inside the cone over the
stations b … R (k ≥ 0), so its groove lies inside the cone's and a cutter
``stock`` inside the first is at least ``stock`` inside the second.

A rib
-----
A rib (:class:`~camcad.geometry.barrel.BarrelKind`) stands on a core of
radius b = R − depth, its top the blank's surface R: everything else between
the barrel's ends 0 ≤ z ≤ ``length`` comes off down to b. Its faces are
walls of its two rollers (:func:`~camcad.geometry.barrel.face_rollers`): the
upper face the lower wall of the roller at +h, the lower face the upper wall
of the roller at −h (h: ``rib_offset``), so each face is finished as a
groove's wall is, a cutter of the roller's diameter on that roller's path
shifted by c/2 towards the rib along its pitch station's normal (its edge
then r_f + c/2 = r_w off the path, on the face).

Roughing works on each side from its roller's path outwards: near the face,
shifts δ along the normal from r_w − r_c − stock towards the rib out to the
roller's path itself (the cutter stays ``stock`` off the face: every point of
the path is r_w from it), then the path translated along the barrel's axis,
away from the rib, in steps no wider than ``stepover`` × the cutter's
diameter, until the cutter's axis lies beyond the barrel's end all round.
A translated pass cannot touch the rib: at every station the developed
roller path is a graph over u (t + y′ > 0, checked by the limits) and the rib
lies on its other side, r_w from it, so a segment from a point beyond the
path to the rib crosses the path and is at least r_w long. Between two
passes at one u the gap along w is at most the step, so no point of the band
is farther than half a step from a cutter's axis. The last level's tip is at
the root b itself (the floor between the faces' finishing passes is cut by
roughing alone); the faces keep the stock.

For a translating follower (y ≡ 0) a flat end mill whose tip is at b leaves
the cylinder of radius b exactly; on an arm (y ≠ 0) a point under the
cutter's axis line is reached at station √(ρ² − y²), so the floor far from
the rib rises where |y| > r_c (under the cutter's axis to √(b² + (|y| − r_c)²)).

The root's fillet: a face point at station t lies √(t² + a²) from the
barrel's axis, a = y + r_w·cos γ its offset across the roller's axis, so on
a flank the face's root edge (station b) stands above the root cylinder, by
up to F = max √(b² + a²) − b (a translating roller: a = r_w·sin β, tan β =
s′/b). A flat end whose tip is at station b cuts the face exactly at every
station from b up, and reaches a point of radius ρ only within acos(b/ρ) of
its own angle: between the face's root edge and the root cylinder it leaves
a fillet at most F high (``root_fillet``, in the program's header), as a
groove's bottom corners keep one. Lowering the tip to √(b² − a²) would cut
it, and gouge the floor under the cutter's axis by as much.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from camcad._typing import FloatArray, readonly
from camcad.errors import DesignError
from camcad.extremes import extremes_rows
from camcad.geometry.barrel import (
    BarrelFollower,
    BarrelKind,
    BarrelOptions,
    OscillatingBarrelRoller,
    RibRoller,
    RollerShape,
    TranslatingBarrelRoller,
    barrel_faces,
    rib_rollers,
)
from camcad.geometry.barrel_limits import developed_walls
from camcad.knobs import Knob
from camcad.motion.program import MotionProgram, Side

__all__ = [
    "BarrelPass",
    "BarrelToolpath",
    "BarrelToolpathOptions",
    "plan_barrel",
    "small_cutter_deviation",
]

_MAX_SPLITS = 30


@dataclass(frozen=True, slots=True, kw_only=True)
class BarrelToolpathOptions:
    """The 4-axis program's tools and passes [mm, mm/min].

    ``tolerance``: the tool axis's largest distance from the exact path;
    ``rough_diameter``: the roughing cutter (smaller than the roller);
    ``stepover``: roughing passes' spacing as a fraction of its diameter;
    ``step_down``: roughing depth per level; ``stock``: what roughing leaves
    on the walls and the bottom; ``clearance_height``: above the barrel's
    surface for rapids; feeds and tool numbers.
    """

    tolerance: float = 0.005
    rough_diameter: float = 10.0
    stepover: float = 0.4
    step_down: float = 4.0
    stock: float = 0.2
    clearance_height: float = 5.0
    feed: float = 300.0
    plunge_feed: float = 60.0
    spindle_rpm: float = 6000.0
    rough_tool: int = 1
    finish_tool: int = 2


@dataclass(frozen=True, slots=True, kw_only=True)
class BarrelPass:
    """One revolution of the tool: ``x``, ``y`` [mm], ``a`` [deg] (n,), tip at ``z`` [mm].

    ``kind``: "rough", "finish upper", "finish lower" or (a tapered cutter
    for a conical roller) "finish both"; ``shift`` [mm]: the path's offset
    from the pitch path along the pitch station's developed normal (towards
    the upper wall); ``tool`` its number, ``radius`` its cutter radius at the
    tip [mm] and ``taper`` its flank's dr/dt (0 for a flat end mill: radius
    + taper·(t − z) at station t ≥ z); ``deviation``: the axis's largest
    distance from the exact path between blocks [mm]. A rib's passes follow
    one of its rollers (:func:`~camcad.geometry.barrel.rib_rollers`):
    ``roller`` its offset h [mm] (0: the follower's own roller, a groove's
    pitch path), and ``slide`` [mm] moves the shifted path along the
    barrel's axis (+z); ``shift`` is then from that roller's path.
    """

    kind: str
    shift: float
    tool: int
    radius: float
    z: float
    x: FloatArray
    y: FloatArray
    a: FloatArray
    deviation: float
    taper: float = 0.0
    roller: float = 0.0
    slide: float = 0.0


@dataclass(frozen=True, slots=True, kw_only=True)
class BarrelToolpath:
    """Every pass in cutting order, with the options and the barrel they were planned for.

    ``small_cutter`` (2, 2, 2) [mm]: what finishing the walls with the roughing
    cutter instead would leave (:func:`small_cutter_deviation`) at the
    groove's bottom and top (rows), upper and lower wall, (least, greatest);
    a rib: at its root and top, its upper and lower face; NaN for a conical
    roller (its finishing cutter is tapered, not smaller). ``root_fillet``
    [mm]: a rib's faces at the root station b stand up to this far outside
    the root cylinder, the most a flat end leaves beside them there (module
    notes); ``floor_rise`` [mm]: how far above the root a rib's floor stays
    where a roughing cutter's axis runs more than its radius off the
    barrel's axis (an arm), √(b² + (|y| − r_c)²) − b at the largest |y|;
    both 0 for a groove.
    """

    passes: tuple[BarrelPass, ...]
    options: BarrelToolpathOptions
    barrel: BarrelOptions
    small_cutter: FloatArray
    root_fillet: float = 0.0
    floor_rise: float = 0.0

    @property
    def max_deviation(self) -> float:
        """The largest path deviation of any pass [mm]."""
        return max(p.deviation for p in self.passes)


def _path(
    program: MotionProgram, follower: BarrelFollower, options: BarrelOptions, phi: FloatArray, shift: float
) -> tuple[FloatArray, FloatArray]:
    """(y, z) (n,) [mm] of the pitch path shifted by ``shift`` along the pitch station's developed normal."""
    axis = follower.centre(program.evaluate(phi))
    tp = options.pitch_station
    du, dz = tp + axis.m1[:, 0], axis.m1[:, 1]
    big = np.hypot(du, dz)
    return axis.m0[:, 0] - shift * dz / big, axis.m0[:, 1] + shift * du / big


def _refined(
    program: MotionProgram, follower: BarrelFollower, options: BarrelOptions, shift: float, tolerance: float
) -> tuple[FloatArray, float]:
    """Angles φ (n + 1,) over 0 … 2π whose chords keep within ``tolerance`` of the path; the largest gap."""
    phi = np.union1d(program.sample_phi(math.radians(2.0)), [math.tau])
    for _ in range(_MAX_SPLITS):
        fractions = np.arange(1, 8) / 8.0
        mid = phi[:-1, None] + fractions[None, :] * np.diff(phi)[:, None]
        y0, z0 = _path(program, follower, options, phi, shift)
        ym, zm = _path(program, follower, options, mid.ravel(), shift)
        ylin = y0[:-1, None] + fractions * np.diff(y0)[:, None]
        zlin = z0[:-1, None] + fractions * np.diff(z0)[:, None]
        # a block's gap is nearly a parabola in the fraction; its peak is within 1/16 of a node,
        # where the parabola is at least 1 − 4/16² of it: the bound is the largest node / (1 − 1/64)
        gap = np.hypot(ym.reshape(mid.shape) - ylin, zm.reshape(mid.shape) - zlin).max(axis=1) / (
            1.0 - 1.0 / 64.0
        )
        bad = gap > tolerance
        if not bad.any():
            return phi, float(gap.max())
        phi = np.union1d(phi, mid[bad, 3])
    raise DesignError(Knob.GCODE_TOLERANCE, f"{tolerance:g} mm cannot be met by splitting blocks; loosen it")


def _pass(
    program: MotionProgram,
    follower: BarrelFollower,
    options: BarrelOptions,
    *,
    kind: str,
    tool: int,
    radius: float,
    z: float,
    shift: float,
    tolerance: float,
    taper: float = 0.0,
) -> BarrelPass:
    phi, gap = _refined(program, follower, options, shift, tolerance)
    y, zz = _path(program, follower, options, phi, shift)
    x, yy, a = zz.copy(), -y, -np.degrees(phi)
    readonly(x, yy, a)
    roller = follower.offset if isinstance(follower, RibRoller) else 0.0
    return BarrelPass(
        kind=kind,
        shift=shift,
        tool=tool,
        radius=radius,
        z=z,
        x=x,
        y=yy,
        a=a,
        deviation=gap,
        taper=taper,
        roller=roller,
    )


def _slid(base: BarrelPass, slide: float, z: float) -> BarrelPass:
    """``base`` moved by ``slide`` [mm] along the barrel's axis (machine X), its tip at ``z``.

    The same blocks: a translation keeps every chord's distance from the
    (translated) exact path, so the deviation is the base pass's.
    """
    x = base.x + slide
    readonly(x)
    return BarrelPass(
        kind=base.kind,
        shift=base.shift,
        tool=base.tool,
        radius=base.radius,
        z=z,
        x=x,
        y=base.y,
        a=base.a,
        deviation=base.deviation,
        roller=base.roller,
        slide=base.slide + slide,
    )


def plan_barrel(
    program: MotionProgram, follower: BarrelFollower, options: BarrelOptions, spec: BarrelToolpathOptions
) -> BarrelToolpath:
    """Rough and finish passes for the groove, or for the barrel round a rib (module notes).

    Raises
    ------
    DesignError
        ``gcode.rough_diameter`` not smaller than the groove is wide (a rib:
        the gap its roller runs in, 2r_f + c) less twice the stock;
        ``gcode.step_down``, ``gcode.stepover``, ``gcode.stock``,
        ``gcode.tolerance`` not positive; ``gcode.stepover`` above 1.
    """
    for path, value in (
        (Knob.GCODE_TOLERANCE, spec.tolerance),
        (Knob.STEP_DOWN, spec.step_down),
        (Knob.STEPOVER, spec.stepover),
        (Knob.ROUGH_DIAMETER, spec.rough_diameter),
    ):
        if not (math.isfinite(value) and value > 0.0):
            raise DesignError(path, f"{value!r} is not allowed; give a number > 0")
    if spec.stepover > 1.0:
        raise DesignError(
            Knob.STEPOVER,
            f"{spec.stepover!r} is not allowed: passes farther apart than the cutter's diameter leave "
            "ridges; give 0 < stepover ≤ 1",
        )
    cone = options.roller is RollerShape.CONICAL
    if not (math.isfinite(spec.stock) and spec.stock >= 0.0):
        raise DesignError(Knob.STOCK, f"{spec.stock!r} mm is not allowed; give 0 mm or more")
    if options.kind is BarrelKind.RIB:
        if isinstance(follower, RibRoller):
            raise ValueError("plan a rib with its follower, not one of its rollers")
        return _plan_rib(program, follower, options, spec)
    # a cone: rough as for the cylinder of its wall's radius at the bottom (module notes)
    r_w = (
        float(options.roller_at(options.bottom_radius, clearance=True))
        if cone
        else (options.roller_radius + 0.5 * options.clearance)
    )
    r_c = 0.5 * spec.rough_diameter
    reach = _rough_reach(
        r_w, spec, f"the groove {2 * r_w:g} mm wide with {spec.stock:g} mm stock on each wall"
    )
    count = max(1, math.ceil(2.0 * reach / (spec.stepover * spec.rough_diameter)) + 1) if reach > 0 else 1
    shifts = np.linspace(-reach, reach, count) if count > 1 else np.zeros(1)
    bottom = options.bottom_radius + spec.stock
    levels = _levels(options.barrel_radius, bottom, spec.step_down)
    passes = [
        _pass(
            program,
            follower,
            options,
            kind="rough",
            tool=spec.rough_tool,
            radius=r_c,
            z=float(level),
            shift=float(shift),
            tolerance=spec.tolerance,
        )
        for level in levels
        for shift in shifts
    ]
    half_c = 0.5 * options.clearance
    if cone:
        passes.append(
            _pass(
                program,
                follower,
                options,
                kind="finish both",
                tool=spec.finish_tool,
                radius=r_w,
                z=options.bottom_radius,
                shift=0.0,
                tolerance=spec.tolerance,
                taper=options.taper,
            )
        )
        nan = np.full((2, 2, 2), np.nan)
        readonly(nan)
        return BarrelToolpath(passes=tuple(passes), options=spec, barrel=options, small_cutter=nan)
    passes += [
        _pass(
            program,
            follower,
            options,
            kind=f"finish {name}",
            tool=spec.finish_tool,
            radius=options.roller_radius,
            z=options.bottom_radius,
            shift=sign * half_c,
            tolerance=spec.tolerance,
        )
        for name, sign in (("upper", 1.0), ("lower", -1.0))
    ]
    small = small_cutter_deviation(
        program, follower, options, r_c, np.array([options.bottom_radius, options.barrel_radius])
    )
    return BarrelToolpath(passes=tuple(passes), options=spec, barrel=options, small_cutter=small)


def _rough_reach(r_w: float, spec: BarrelToolpathOptions, room: str) -> float:
    """How far [mm] the rougher's axis may shift either way of the roller's path: r_w − r_c − stock ≥ 0.

    ``room`` names the space it must fit in, for the error.
    """
    reach = r_w - 0.5 * spec.rough_diameter - spec.stock
    if reach < 0.0:
        raise DesignError(
            Knob.ROUGH_DIAMETER,
            f"{spec.rough_diameter:g} mm does not fit {room}; "
            f"give rough_diameter ≤ {2 * (r_w - spec.stock):g} mm",
        )
    return reach


def _levels(top: float, bottom: float, step_down: float) -> FloatArray:
    """The roughing levels [mm from the axis]: from step_down below ``top`` down to ``bottom``, the last."""
    levels = np.arange(top - step_down, bottom, -step_down)
    out: FloatArray = np.r_[levels[levels > bottom], bottom]
    return out


def _plan_rib(
    program: MotionProgram,
    follower: TranslatingBarrelRoller | OscillatingBarrelRoller,
    options: BarrelOptions,
    spec: BarrelToolpathOptions,
) -> BarrelToolpath:
    """The barrel round a rib: each side roughed from its roller's path outwards, each face finished."""
    r_w = options.roller_radius + 0.5 * options.clearance
    r_c = 0.5 * spec.rough_diameter
    reach = _rough_reach(
        r_w,
        spec,
        f"the gap {2 * r_w:g} mm wide each roller runs in beside the rib "
        f"with {spec.stock:g} mm stock on its face",
    )
    step = spec.stepover * spec.rough_diameter
    bottom = options.bottom_radius
    levels = _levels(options.barrel_radius, bottom, spec.step_down)  # the floor round the rib: to the root
    up, low = rib_rollers(follower, options)
    near = np.linspace(0.0, reach, max(1, math.ceil(reach / step) + 1)) if reach > 0.0 else np.zeros(1)
    sides: list[list[BarrelPass]] = []
    for roller, away in ((up, 1.0), (low, -1.0)):  # +1: the side above the rib, away from it is +z
        # near the face: shifts towards the rib out to the roller's own path (the last, shift 0)
        base = [
            _pass(
                program,
                roller,
                options,
                kind="rough",
                tool=spec.rough_tool,
                radius=r_c,
                z=bottom,
                shift=float(-away * d) + 0.0,  # + 0.0: no −0.0
                tolerance=spec.tolerance,
            )
            for d in near[::-1]
        ]
        path = base[-1]
        # then the roller's path slid away from the rib until the cutter's axis is past the end all round
        far = (options.length - float(path.x.min())) if away > 0 else float(path.x.max())
        count = max(0, math.ceil(far / step)) if far > 0.0 else 0
        slides = [away * far * (k + 1) / count for k in range(count)]
        sides.append(base + [_slid(path, d, bottom) for d in slides])
    passes = [_slid(p, 0.0, float(level)) for level in levels for side in sides for p in side]
    half_c = 0.5 * options.clearance
    passes += [
        _pass(
            program,
            roller,
            options,
            kind=f"finish {name}",
            tool=spec.finish_tool,
            radius=options.roller_radius,
            z=bottom,
            shift=-away * half_c,  # towards the rib: the cutter's edge r_f + c/2 off the path
            tolerance=spec.tolerance,
        )
        for name, roller, away in (("upper", up, 1.0), ("lower", low, -1.0))
    ]
    # the upper face is the +h roller's lower wall, the lower face the −h roller's upper wall
    stations = np.array([bottom, options.barrel_radius])
    upper = small_cutter_deviation(program, up, options, r_c, stations, walls=(1,))
    lower = small_cutter_deviation(program, low, options, r_c, stations, walls=(0,))
    small = np.stack((upper[:, 1], lower[:, 0]), axis=1)
    readonly(small)

    # the faces' root edges: their largest radius over the turn, a true extreme (one-sided at joints)
    def edges(phi: FloatArray, side: Side) -> FloatArray:
        faces = barrel_faces(program.evaluate(phi, side=side), follower, options, stations[:1])
        out: FloatArray = np.vstack(
            [np.hypot(f.point[:, 0, 0], f.point[:, 0, 1]) for f in (faces.upper, faces.lower)]
        )
        return out

    joints = [bp.phi for bp in program.breakpoints]
    found = extremes_rows(edges, program.sample_phi(math.radians(0.5)), joints, ("max", "max"))
    edge = max(e.value for e in found)
    off = max(0.0, max(float(np.abs(p.y).max()) for p in passes if p.kind == "rough") - r_c)
    return BarrelToolpath(
        passes=tuple(passes),
        options=spec,
        barrel=options,
        small_cutter=small,
        root_fillet=edge - bottom,
        floor_rise=math.hypot(bottom, off) - bottom,
    )


def _nearest_on_path(points: FloatArray, path: FloatArray, param: FloatArray, idx: np.ndarray) -> FloatArray:
    """Distance (n,) from points to a sampled smooth path near its samples ``idx``, by a 3-point parabola.

    f(φ) = |P − C(φ)|² through the nearest sample and its neighbours (at
    their own parameters, the grid may be uneven); its vertex value where
    the parabola opens upward, else the sample's own distance.
    """
    i = np.clip(idx, 1, len(path) - 2)
    x0, x1, x2 = param[i - 1], param[i], param[i + 1]
    f0, f1, f2 = (np.sum((points - path[k]) ** 2, axis=1) for k in (i - 1, i, i + 1))
    # the parabola f1 + B·u + A·u² in u = φ − x1 through the three (centred: no cancellation)
    h0, h2 = x0 - x1, x2 - x1
    s0, s2 = (f0 - f1) / h0, (f2 - f1) / h2
    a = (s2 - s0) / (h2 - h0)
    b = s2 - a * h2
    safe = np.where(a > 0.0, a, 1.0)
    u = np.clip(-b / (2.0 * safe), h0, h2)
    best = np.where(a > 0.0, f1 + b * u + a * u * u, f1)
    out: FloatArray = np.sqrt(np.maximum(np.minimum(best, f1), 0.0))
    return out


def small_cutter_deviation(
    program: MotionProgram,
    follower: BarrelFollower,
    options: BarrelOptions,
    cutter_radius: float,
    stations: FloatArray,
    *,
    step: float = math.radians(0.05),
    walls: tuple[int, ...] = (0, 1),
) -> FloatArray:
    """How far a wall cut by a smaller cutter lies from the exact wall, at stations t [mm].

    The cutter (radius r_c < r_w) follows the pitch path shifted by
    ±(r_w − r_c) along the developed normal at the pitch station, so it is
    exact there. At station t the cut wall is the boundary of the discs of
    radius r_c round its axis in the developed plane; for each exact wall
    point the distance to the nearest axis point minus r_c is the stock left
    (> 0) or the gouge (< 0). The nearest of the axis's samples (every
    ``step``) is polished by a parabola through it and its two neighbours
    (:func:`_nearest_on_path`), so the sampling adds O(step³), not the
    (spacing/2)²/(2r_c) ≈ 5e-5 mm the nearest sample alone would.

    A translating roller on its steepest flank (s″ = 0, where the developed
    path is straight) has the closed form δ(1 − cos(β_t − β_p)), δ = r_w −
    r_c, tan β = s′/t (the cutter's axis is δ off the path along the pitch
    station's normal, δ·cos Δβ along the wall's at station t).

    ``walls``: which to measure, 0 the upper and 1 the lower (the other's
    row is NaN); a rib's face is one wall of one of its rollers.

    Returns
    -------
    FloatArray
        (m, 2, 2) [mm]: per station, (upper, lower) wall × (least, greatest)
        signed deviation.
    """
    r_w = options.roller_radius + 0.5 * options.clearance
    phi = program.sample_phi(step)
    motion = program.evaluate(phi)
    out = np.full((len(stations), 2, 2), np.nan)
    for i, t in enumerate(np.asarray(stations, dtype=float)):
        developed = developed_walls(motion, follower, options, float(t))
        for j, (sign, wall) in enumerate(((1.0, developed.upper.point), (-1.0, developed.lower.point))):
            if j not in walls:
                continue
            y, z = _path(program, follower, options, phi, sign * (r_w - cutter_radius))
            centres = np.column_stack((t * phi + y, z))
            period = np.array([t * math.tau, 0.0])
            every = np.vstack((centres - period, centres, centres + period))
            _, idx = cKDTree(every).query(wall)
            dist = _nearest_on_path(wall, every, np.r_[phi - math.tau, phi, phi + math.tau], idx)
            dev = dist - cutter_radius
            out[i, j] = (float(dev.min()), float(dev.max()))
    readonly(out)
    return out
