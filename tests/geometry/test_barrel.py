"""Barrel cams (issue 36) against independent truths.

- the issue's figures: a cycloidal 50 mm rise over 90° has s′max = 2h/β = 63.66 mm/rad,
  so tan α = s′/r gives 51.9°, 46.7°, 42.3° at r = 50, 60, 70 mm;
- a brute-force 3-D interference test: each wall point touches the roller at its own
  angle and lies outside the roller at every other angle (a dense scan plus a bounded
  search, using only the roller's shape and where its axis is);
- the developed wall at the pitch station against a second method: its distance to a
  dense polyline of the unrolled pitch line (k-d tree), which must be the roller radius;
- closed forms: walls at r from the roller's axis, the developed pitch line's radius,
  the slip of a cylindrical roller, a cone's zero slip in dwells;
- finite differences: the wall normals, the slip vector (the roller's material point
  moved by its carrier and spin), the oscillating arm's chain rule;
- an independent construction of the arm by a rotation about its pivot axis (Rodrigues).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.optimize import minimize_scalar
from scipy.spatial import cKDTree

from camcad.design.paths import path_of
from camcad.errors import EXIT_INVALID, DesignError, exit_code
from camcad.geometry.barrel import (
    BarrelKind,
    BarrelOptions,
    OscillatingBarrelRoller,
    RollerShape,
    TranslatingBarrelRoller,
    WallSide,
    barrel_faces,
    barrel_walls,
    check_barrel,
    rib_rollers,
    roller_slip,
    walls_at_radius,
)
from camcad.geometry.barrel_limits import barrel_limits, developed_walls
from camcad.motion.laws import make_law
from camcad.motion.program import MotionProgram
from camcad.motion.segments import SegmentKind, SegmentSpec


def program(lift: float = 50.0, *, law: str = "cycloidal", span_deg: float = 90.0) -> MotionProgram:
    dwell = math.radians(180.0 - span_deg)
    span = math.radians(span_deg)
    return MotionProgram.from_segments(
        [
            SegmentSpec(kind=SegmentKind.RISE, span=span, lift=lift, law=make_law(law)),
            SegmentSpec(kind=SegmentKind.DWELL, span=dwell),
            SegmentSpec(kind=SegmentKind.RETURN, span=span, lift=lift, law=make_law(law)),
            SegmentSpec(kind=SegmentKind.DWELL, span=dwell),
        ]
    )


def options(**kw: object) -> BarrelOptions:
    base: dict[str, object] = {
        "barrel_radius": 70.0,
        "length": 120.0,
        "depth": 20.0,
        "roller_radius": 8.0,
        "roller_length": 15.0,
        "clearance": 0.1,
    }
    base.update(kw)
    return BarrelOptions(**base)  # type: ignore[arg-type]


TRANSLATING = TranslatingBarrelRoller(axial_position=35.0)
ARM = OscillatingBarrelRoller(axial_position=60.0, pivot_distance=100.0, arm_length=110.0)
PHI = np.linspace(0.0, 2.0 * math.pi, 361, endpoint=False) + 0.0123
STATIONS = np.array([50.0, 57.5, 62.5, 70.0])


def arm_program() -> MotionProgram:
    return program(12.0, law="poly-345", span_deg=100.0)  # ψ in degrees


# -- the issue's figures ---------------------------------------------------------


def test_issue_pressure_angles_at_three_radii():
    prog = program()
    v_max = 2.0 * 50.0 / (math.pi / 2.0)  # cycloidal: s′max = 2h/β (Rothbart 2004, §3.4)
    assert v_max == pytest.approx(63.66, abs=5e-3)
    assert float(np.max(prog.evaluate(np.linspace(0.0, math.pi / 2, 2001)).v)) == pytest.approx(
        v_max, rel=1e-6
    )
    walls = barrel_walls(prog.evaluate(PHI), TRANSLATING, options(), np.array([50.0, 60.0, 70.0]))
    peak = np.degrees(np.abs(walls.pressure_angle).max(axis=0))
    assert_allclose(peak, [51.9, 46.7, 42.3], atol=0.05)
    # the true extremes: atan(63.662/r) exactly, at 45° (the middle of the rise)
    opt = options(depth=20.0, roller_length=15.0)  # bottom 50, pitch 62.5, top 70
    lim = barrel_limits(prog, TRANSLATING, opt)
    for ext, r in zip(lim.pressure_angle_max, (50.0, 62.5, 70.0), strict=True):
        assert ext.value == pytest.approx(math.atan(v_max / r), abs=1e-10)
        assert ext.angle_deg % 180.0 == pytest.approx(45.0, abs=1e-4)


@pytest.mark.parametrize("shape", list(RollerShape), ids=lambda s: s.value)
def test_pressure_angle_closed_form(shape: RollerShape):
    prog = program()
    m = prog.evaluate(PHI)
    opt = options(roller=shape)
    walls = barrel_walls(m, TRANSLATING, opt, STATIONS)
    t, v = STATIONS[None, :], m.v[:, None]
    if shape is RollerShape.CYLINDRICAL:
        expected = np.arctan(v / t)  # tan α = s′/t
    else:  # the 3-D angle: cos α = q/(D√(1 + k²)), q = t + k·r, D = √(s′² + q²)
        k = opt.taper
        q = t + k * opt.roller_at(t, clearance=True)
        expected = np.sign(v) * np.arccos(q / (np.hypot(v, q) * math.sqrt(1.0 + k * k)))
    assert_allclose(walls.pressure_angle, expected, atol=1e-12)


# -- the walls -------------------------------------------------------------------


def _axis_at(follower, prog, phi):
    m = prog.evaluate(np.atleast_1d(phi))
    return follower.centre(m).m0


def _outside(point, follower, prog, phis, opt):
    """δ − r(t′): a point's in-plane distance from the roller's axis at angles φ′, less the radius there."""
    axis = _axis_at(follower, prog, phis)
    e_r = np.column_stack((np.cos(phis), np.sin(phis)))
    e_t = np.column_stack((-np.sin(phis), np.cos(phis)))
    t_here = e_r @ point[:2]
    delta = np.hypot(e_t @ point[:2] - axis[:, 0], point[2] - axis[:, 1])
    return delta - opt.roller_at(t_here, clearance=True)


@pytest.mark.parametrize(
    ("follower", "shape", "prog"),
    [
        (TRANSLATING, RollerShape.CYLINDRICAL, program()),
        (TRANSLATING, RollerShape.CONICAL, program()),
        (ARM, RollerShape.CYLINDRICAL, arm_program()),
    ],
    ids=["translating-cylinder", "translating-cone", "arm-cylinder"],
)
def test_walls_touch_the_roller_and_never_cut_it(follower, shape, prog):
    """Brute force in 3-D: min over φ′ of (distance to the roller − its radius) is 0, reached at φ′ = φ."""
    opt = options(roller=shape)
    phis = PHI[::24]
    walls = barrel_walls(prog.evaluate(phis), follower, opt, STATIONS)
    scan = np.linspace(-0.4, 0.4, 1601)
    worst = 0.0
    for sheet in (walls.upper, walls.lower):
        for i, phi in enumerate(phis):
            for j in range(STATIONS.size):
                p = sheet.point[i, j]
                assert abs(_outside(p, follower, prog, np.array([phi]), opt)[0]) < 1e-9
                gap = _outside(p, follower, prog, phi + scan, opt)
                k = int(np.argmin(gap))
                lo, hi = phi + scan[max(k - 1, 0)], phi + scan[min(k + 1, scan.size - 1)]
                res = minimize_scalar(
                    lambda x, p=p: float(_outside(p, follower, prog, np.array([x]), opt)[0]),
                    bounds=(lo, hi),
                    method="bounded",
                    options={"xatol": 1e-12},
                )
                worst = min(worst, float(gap.min()), float(res.fun))
    assert worst > -1e-7  # no wall point is ever inside the roller


def test_walls_at_roller_radius_from_the_axis_and_normals_exact():
    prog = program()
    opt = options()
    m = prog.evaluate(PHI)
    walls = barrel_walls(m, TRANSLATING, opt, STATIONS)
    r_w = opt.roller_radius + 0.5 * opt.clearance
    e_r = np.stack((np.cos(PHI), np.sin(PHI), 0 * PHI), axis=-1)[:, None, :]
    e_t = np.stack((-np.sin(PHI), np.cos(PHI), 0 * PHI), axis=-1)[:, None, :]
    for sheet, sign in ((walls.upper, 1.0), (walls.lower, -1.0)):
        assert_allclose(
            np.sum(sheet.point * e_r, axis=-1), np.broadcast_to(STATIONS, (PHI.size, 4)), atol=1e-10
        )
        across = np.sum(sheet.point * e_t, axis=-1)
        up = sheet.point[..., 2] - (35.0 + m.s)[:, None]
        assert_allclose(np.hypot(across, up), r_w, atol=1e-10)
        # the contact lies along the developed pitch line's normal (−s′, t), on its own side
        assert_allclose(across * STATIONS + up * m.v[:, None], 0.0, atol=1e-8)
        assert np.all(sign * up > 0.0)
    # normals against finite differences of the sheets in φ and t
    h = 1e-5
    for side in ("upper", "lower"):
        plus = getattr(barrel_walls(prog.evaluate(PHI + h), TRANSLATING, opt, STATIONS), side).point
        minus = getattr(barrel_walls(prog.evaluate(PHI - h), TRANSLATING, opt, STATIONS), side).point
        d_phi = (plus - minus) / (2 * h)
        tp = getattr(barrel_walls(m, TRANSLATING, opt, STATIONS + h), side).point
        tm = getattr(barrel_walls(m, TRANSLATING, opt, STATIONS - h), side).point
        d_t = (tp - tm) / (2 * h)
        normal = getattr(walls, side).normal
        assert_allclose(np.linalg.norm(normal, axis=-1), 1.0, atol=1e-12)
        for tangent in (d_phi, d_t):
            cosine = np.sum(normal * tangent, axis=-1) / np.linalg.norm(tangent, axis=-1)
            assert np.abs(cosine).max() < 1e-6
        # into the groove: towards the roller's axis
        axis_pt = STATIONS[None, :, None] * e_r + (35.0 + m.s)[:, None, None] * np.array([0.0, 0.0, 1.0])
        assert np.all(np.sum(normal * (axis_pt - getattr(walls, side).point), axis=-1) > 0.0)


@pytest.mark.parametrize("radius", [50.0, 57.3, 70.0])
def test_walls_at_radius_lie_on_the_cylinder_and_the_sheet(radius: float):
    prog = program()
    opt = options()
    m = prog.evaluate(PHI)
    for side in WallSide:
        station, sheet = walls_at_radius(m, TRANSLATING, opt, radius, side)
        assert_allclose(np.hypot(sheet.point[:, 0, 0], sheet.point[:, 0, 1]), radius, atol=1e-9)
        assert np.all(station <= radius + 1e-12)
        # the same point as the sheet at that station (one station per angle)
        for i in range(0, PHI.size, 37):
            one = barrel_walls(prog.evaluate(PHI[i : i + 1]), TRANSLATING, opt, station[i : i + 1])
            want = (one.upper if side is WallSide.UPPER else one.lower).point[0, 0]
            assert_allclose(sheet.point[i, 0], want, atol=1e-12)


# -- the developed walls ---------------------------------------------------------


def test_developed_wall_at_pitch_is_the_plate_envelope_by_brute_force():
    """Second method: the wall's distance from a dense polyline of the unrolled pitch line is r."""
    prog = program()
    opt = options()
    tp = opt.pitch_station
    r_w = opt.roller_radius + 0.5 * opt.clearance
    dense = np.linspace(-0.5, 2 * math.pi + 0.5, 400_001)
    line = np.column_stack((tp * dense, 35.0 + prog.evaluate(dense).s))
    tree = cKDTree(line)
    m = prog.evaluate(PHI)
    walls = barrel_walls(m, TRANSLATING, opt, np.array([tp]))
    dev = developed_walls(m, TRANSLATING, opt, tp)
    e_t = np.column_stack((-np.sin(PHI), np.cos(PHI)))
    for sheet, flat in ((walls.upper, dev.upper), (walls.lower, dev.lower)):
        # the 3-D wall, developed: u = tφ + (W·e_θ), w = W_z
        u = tp * PHI + np.sum(sheet.point[:, 0, :2] * e_t, axis=1)
        w = sheet.point[:, 0, 2]
        assert_allclose(np.column_stack((u, w)), flat.point, atol=1e-10)
        dist, _ = tree.query(flat.point)
        assert_allclose(dist, r_w, atol=1e-6)


def test_developed_radii_closed_form():
    """ρ = −(t² + s′²)^{3/2}/(t·s″) for the pitch line; the walls ρ ± r; λ = 1 ± r/ρ."""
    prog = program()
    opt = options()
    m = prog.evaluate(PHI)
    r_w = opt.roller_radius + 0.5 * opt.clearance
    for t in (50.0, 62.5):
        dev = developed_walls(m, TRANSLATING, opt, t)
        moving = np.abs(m.a) > 1e-6
        rho = -((t * t + m.v[moving] ** 2) ** 1.5) / (t * m.a[moving])
        assert_allclose(dev.pitch.rho[moving], rho, rtol=1e-10)
        assert_allclose(dev.upper.rho[moving], rho + r_w, rtol=1e-10)
        assert_allclose(dev.lower.rho[moving], rho - r_w, rtol=1e-10)
        assert_allclose(dev.stretch_upper[moving], 1 + r_w / rho, rtol=1e-10)
        assert_allclose(dev.stretch_lower[moving], 1 - r_w / rho, rtol=1e-10)


def test_undercut_found_at_the_bottom():
    """A steep law on a thin barrel loops the walls; the stretch's extreme matches a dense scan."""
    prog = program(40.0, span_deg=40.0)
    opt = options(barrel_radius=25.0, depth=10.0, roller_length=8.0, roller_radius=10.0, length=200.0)
    f = TranslatingBarrelRoller(axial_position=60.0)
    lim = barrel_limits(prog, f, opt)
    assert any(fd.kind == "groove undercut" for fd in lim.findings)
    dense = np.linspace(0.0, 2 * math.pi, 200_001)
    dev = developed_walls(prog.evaluate(dense), f, opt, opt.bottom_radius)
    assert lim.stretch_min["bottom"][0].value <= dev.stretch_upper.min() + 1e-9
    assert lim.stretch_min["bottom"][0].value == pytest.approx(dev.stretch_upper.min(), abs=1e-6)
    assert lim.stretch_min["bottom"][0].value <= 0.0


# -- slip ------------------------------------------------------------------------


def _material_velocity(follower, prog, opt, phi, t, side, spin):
    """d/dφ of the roller's material point at the contact: carrier moved, roller turned by Ω·h (FD)."""
    walls = barrel_walls(prog.evaluate(np.array([phi])), follower, opt, np.array([t]))
    here = (walls.upper if side is WallSide.UPPER else walls.lower).point[0, 0]
    axis = _axis_at(follower, prog, phi)[0]
    e_t = np.array([-math.sin(phi), math.cos(phi)])
    gamma = math.atan2(here[2] - axis[1], e_t @ here[:2] - axis[0])
    r = float(opt.roller_at(t, clearance=False))

    def where(h: float) -> np.ndarray:
        p = phi + h
        ax = _axis_at(follower, prog, p)[0]
        er, et = np.array([math.cos(p), math.sin(p), 0.0]), np.array([-math.sin(p), math.cos(p), 0.0])
        g = gamma + spin * h
        return (
            t * er
            + ax[0] * et
            + np.array([0.0, 0.0, ax[1]])
            + r * (math.cos(g) * et + math.sin(g) * np.array([0, 0, 1.0]))
        )

    h = 1e-6
    return (where(h) - where(-h)) / (2 * h), gamma


@pytest.mark.parametrize("shape", list(RollerShape), ids=lambda s: s.value)
@pytest.mark.parametrize("side", list(WallSide), ids=lambda s: s.name.lower())
def test_slip_vector_against_the_rolling_roller(shape, side):
    prog = program()
    opt = options(roller=shape, clearance=0.0)
    phis = np.array([0.3, 0.8, 2.0, 4.0])
    slip = roller_slip(prog.evaluate(phis), TRANSLATING, opt, STATIONS, side)
    k = opt.taper
    for i, phi in enumerate(phis):
        # Ω from rolling without slip at t_p, worked out from the closed form (module notes)
        v = float(prog.evaluate(np.array([phi])).v[0])
        tp = opt.pitch_station
        q = tp + k * float(opt.roller_at(tp, clearance=False))
        big = math.hypot(v, q)
        sigma = side.value
        spin = -(-tp * sigma * q / big + v * (-sigma * v / big)) / float(opt.roller_at(tp, clearance=False))
        for j, t in enumerate(STATIONS):
            vel, gamma = _material_velocity(TRANSLATING, prog, opt, phi, t, side, spin)
            circ = np.array([0.0, 0.0, 0.0])
            er = np.array([math.cos(phi), math.sin(phi), 0.0])
            et = np.array([-math.sin(phi), math.cos(phi), 0.0])
            zh = np.array([0.0, 0.0, 1.0])
            circ = -math.sin(gamma) * et + math.cos(gamma) * zh
            gen = (er + k * (math.cos(gamma) * et + math.sin(gamma) * zh)) / math.sqrt(1 + k * k)
            assert vel @ circ == pytest.approx(slip.across[i, j], abs=1e-6)
            assert vel @ gen == pytest.approx(slip.along[i, j], abs=1e-6)


def test_cylindrical_slip_closed_form_and_cone_rolls_in_dwells():
    prog = program()
    m = prog.evaluate(PHI)
    cyl = options(clearance=0.0)
    tp, r_f = cyl.pitch_station, cyl.roller_radius
    v = m.v[:, None]
    t = STATIONS[None, :]
    for side in WallSide:
        s = side.value
        slip = roller_slip(m, TRANSLATING, cyl, STATIONS, side)
        assert_allclose(slip.across, s * (np.hypot(tp, v) - np.hypot(t, v)), atol=1e-10)
        assert_allclose(slip.along, s * r_f * v / np.hypot(t, v), atol=1e-10)
    dwell = np.abs(m.v) == 0.0
    assert dwell.sum() > 100
    # in a dwell the cylinder slips by ω(t_p − t) across its length
    slip = roller_slip(m, TRANSLATING, cyl, STATIONS, WallSide.LOWER)
    assert_allclose(
        np.abs(slip.across[dwell]), np.abs(tp - STATIONS)[None, :].repeat(dwell.sum(), 0), atol=1e-12
    )
    cone = options(clearance=0.0, roller=RollerShape.CONICAL)
    for side in WallSide:
        slip = roller_slip(m, TRANSLATING, cone, STATIONS, side)
        assert np.abs(slip.across[dwell]).max() < 1e-12
        assert np.abs(slip.along[dwell]).max() < 1e-12
        # in the rise it slides, less across its length than the cylinder at the ends
        cyl_slip = roller_slip(m, TRANSLATING, cyl, STATIONS, side)
        assert np.abs(slip.across).max() < np.abs(cyl_slip.across).max()


# -- the oscillating arm ----------------------------------------------------------


def _rodrigues_centre(follower: OscillatingBarrelRoller, psi_rad: np.ndarray) -> np.ndarray:
    """(y, z) of the roller: the ψ = 0 arm rotated about the pivot's axis (parallel to x) by −ψ."""
    d, arm, z0 = follower.pivot_distance, follower.arm_length, follower.axial_position
    pivot = np.array([0.0, d, z0 - math.sqrt(arm * arm - d * d)])
    start = np.array([0.0, 0.0, z0]) - pivot
    axis = np.array([1.0, 0.0, 0.0])
    out = []
    for ang in -psi_rad:
        rot = (
            start * math.cos(ang)
            + np.cross(axis, start) * math.sin(ang)
            + axis * (axis @ start) * (1 - math.cos(ang))
        )
        out.append(pivot + rot)
    return np.array(out)[:, 1:]


def test_arm_kinematics_position_and_chain_rule():
    prog = arm_program()
    m = prog.evaluate(PHI)
    centre = ARM.centre(m)
    assert_allclose(centre.m0, _rodrigues_centre(ARM, np.radians(m.s)), atol=1e-10)
    start = ARM.centre(prog.evaluate(np.array([0.0]))).m0[0]
    assert_allclose(start, [0.0, 60.0], atol=1e-12)  # ψ(0) = 0: the roller at (0, z0)
    h = 1e-4
    fd = [_rodrigues_centre(ARM, np.radians(prog.evaluate(PHI + k * h).s)) for k in (-2, -1, 1, 2)]
    d1 = (fd[0] - 8 * fd[1] + 8 * fd[2] - fd[3]) / (12 * h)
    d2 = (-fd[0] + 16 * fd[1] - 30 * centre.m0 + 16 * fd[2] - fd[3]) / (12 * h * h)
    assert_allclose(centre.m1, d1, atol=1e-7)
    assert_allclose(centre.m2, d2, atol=1e-4)
    # a rise moves the roller towards +z; the barrel sees it at angle φ + atan(y/t) on radius √(t² + y²)
    rising = m.v > 1.0
    assert np.all(centre.m1[rising, 1] > 0.0)


def test_arm_pressure_angle_against_the_arm_perpendicular():
    """|α| = angle between the wall's contact normal and the roller's velocity direction (FD of Rodrigues)."""
    prog = arm_program()
    m = prog.evaluate(PHI)
    opt = options()
    walls = barrel_walls(m, ARM, opt, STATIONS)
    h = 1e-6
    psi = np.radians(m.s)
    vel = (_rodrigues_centre(ARM, psi + h) - _rodrigues_centre(ARM, psi - h)) / (2 * h)
    d = vel / np.linalg.norm(vel, axis=1)[:, None]
    e_t = np.stack((-np.sin(PHI), np.cos(PHI), 0 * PHI), axis=-1)
    d3 = d[:, 0:1] * e_t + d[:, 1:2] * np.array([0.0, 0.0, 1.0])
    cosine = np.abs(np.sum(walls.upper.normal * d3[:, None, :], axis=-1))
    assert_allclose(np.abs(walls.pressure_angle), np.arccos(np.clip(cosine, -1, 1)), atol=1e-6)
    lim = barrel_limits(prog, ARM, opt)
    assert lim.pressure_angle_max[0].value >= np.abs(walls.pressure_angle[:, 0]).max() - 1e-12


# -- bad input ---------------------------------------------------------------------


@pytest.mark.parametrize(
    ("opt", "follower", "field"),
    [
        (options(bore=100.0, depth=21.0), TRANSLATING, "groove.depth"),
        (options(roller_length=20.0), TRANSLATING, "follower.roller_length"),
        (
            options(),
            OscillatingBarrelRoller(axial_position=60.0, pivot_distance=100.0, arm_length=90.0),
            "follower.arm_length",
        ),
        (options(roller=RollerShape.CONICAL), ARM, "follower.roller"),
        (options(barrel_radius=-1.0), TRANSLATING, "cam.barrel_radius"),
        (options(clearance=float("nan")), TRANSLATING, "groove.clearance"),
    ],
    ids=[
        "depth-into-bore",
        "roller-too-long",
        "arm-too-short",
        "cone-on-arm",
        "negative-radius",
        "nan-clearance",
    ],
)
def test_bad_input_names_the_field(opt, follower, field):
    with pytest.raises(DesignError) as err:
        check_barrel(opt, follower)
    assert path_of(err.value.path) == field
    assert exit_code(err.value) == EXIT_INVALID
    assert "\n" not in str(err.value)


def test_groove_beyond_the_barrels_ends():
    with pytest.raises(DesignError) as err:
        barrel_limits(program(), TranslatingBarrelRoller(axial_position=5.0), options())
    assert path_of(err.value.path) == "follower.axial_position"
    with pytest.raises(DesignError) as err:
        barrel_limits(program(), TranslatingBarrelRoller(axial_position=70.0), options())
    assert path_of(err.value.path) == "follower.axial_position"
    # the exact reach: z0 − r_w at the bottom of the stroke, z0 + h + r_w at its top
    lim = barrel_limits(program(), TRANSLATING, options())
    r_w = 8.05
    assert lim.z_range[0].value == pytest.approx(35.0 - r_w, abs=1e-12)
    assert lim.z_range[1].value == pytest.approx(85.0 + r_w, abs=1e-12)


def test_arm_that_swings_the_groove_backwards_or_off_the_barrel():
    """A short arm nearly along the barrel's axis swings the roller sideways; fast, the groove runs back."""
    follower = OscillatingBarrelRoller(axial_position=100.0, pivot_distance=10.0, arm_length=60.0)
    opt = options(length=300.0, barrel_radius=40.0, depth=10.0, roller_length=6.0)
    with pytest.raises(DesignError) as err:  # 20° in 20°: y′ = l·sin b·ψ′ reaches −118 mm/rad < −30
        barrel_limits(program(20.0, span_deg=20.0), follower, opt)
    assert path_of(err.value.path) == "follower.arm_length"
    assert "crosses itself" in str(err.value)
    with pytest.raises(DesignError) as err:  # 40°: the axis swings 40.4 mm off the barrel's axis
        barrel_limits(program(40.0, span_deg=60.0), follower, opt)
    assert path_of(err.value.path) == "follower.pivot_distance"
    # the independent figure: |y| = |d + l cos(b0 − ψ)| at ψ = 40°
    b0 = math.atan2(math.sqrt(60.0**2 - 10.0**2), -10.0)
    assert f"{abs(10.0 + 60.0 * math.cos(b0 - math.radians(40.0))):.3f} mm" in str(err.value)


# -- over laws and lifts -------------------------------------------------------------


@settings(max_examples=25, deadline=None)
@given(
    law=st.sampled_from(["cycloidal", "poly-345", "harmonic", "poly-4567"]),
    lift=st.floats(1.0, 60.0),
    span=st.floats(40.0, 170.0),
    t=st.floats(40.0, 90.0),
)
def test_laws_and_lifts(law, lift, span, t):
    prog = program(lift, law=law, span_deg=span)
    m = prog.evaluate(PHI)
    opt = options(barrel_radius=95.0, depth=60.0, roller_length=40.0)
    walls = barrel_walls(m, TRANSLATING, opt, np.array([t]))
    assert_allclose(walls.pressure_angle[:, 0], np.arctan(m.v / t), atol=1e-12)
    r_w = opt.roller_radius + 0.5 * opt.clearance
    e_t = np.column_stack((-np.sin(PHI), np.cos(PHI)))
    for sheet in (walls.upper, walls.lower):
        across = np.sum(sheet.point[:, 0, :2] * e_t, axis=1)
        assert_allclose(np.hypot(across, sheet.point[:, 0, 2] - 35.0 - m.s), r_w, atol=1e-10)
    dev = developed_walls(m, TRANSLATING, opt, t)
    assert_allclose(dev.upper.point - dev.pitch.point, r_w * dev.pitch.normal, atol=1e-10)
    assert_allclose(np.abs(walls.pressure_angle[:, 0]), np.arccos(np.abs(dev.pitch.normal[:, 1])), atol=1e-7)


# -- a rib instead of a groove ---------------------------------------------------------


def rib_options(**kw: object) -> BarrelOptions:
    base: dict[str, object] = {
        "kind": BarrelKind.RIB,
        "rib_width": 14.0,
        "depth": 15.0,
        "roller_length": 12.0,
    }
    return options(**{**base, **kw})


def _yoke_centre(follower: OscillatingBarrelRoller, offset: float, psi_rad: np.ndarray) -> np.ndarray:
    """(y, z) of a rib roller on a yoke: its ψ = 0 place, h along the arm's perpendicular, turned by −ψ."""
    d, arm, z0 = follower.pivot_distance, follower.arm_length, follower.axial_position
    pivot = np.array([d, z0 - math.sqrt(arm * arm - d * d)])
    arm0 = np.array([0.0, z0]) - pivot
    across = np.array([arm0[1], -arm0[0]]) / arm  # the arm's perpendicular, on the side a rise moves it
    start = arm0 + offset * across
    out = []
    for ang in -psi_rad:
        c, s = math.cos(ang), math.sin(ang)
        out.append(pivot + np.array([c * start[0] - s * start[1], s * start[0] + c * start[1]]))
    return np.array(out)


def test_rib_rollers_on_a_yoke_against_a_rotation():
    prog = arm_program()
    m = prog.evaluate(PHI)
    for roller, sign in zip(rib_rollers(ARM, rib_options()), (1.0, -1.0), strict=True):
        h = rib_options().rib_offset
        assert roller.offset == sign * h == sign * (7.0 + 8.0 + 0.05)
        assert_allclose(roller.centre(m).m0, _yoke_centre(ARM, roller.offset, np.radians(m.s)), atol=1e-10)
        eps = 1e-6
        moved = _yoke_centre(ARM, roller.offset, np.radians(m.s) + eps) - _yoke_centre(
            ARM, roller.offset, np.radians(m.s) - eps
        )
        assert_allclose(roller.driven(m), moved / np.linalg.norm(moved, axis=1)[:, None], atol=1e-7)


@pytest.mark.parametrize(
    ("follower", "shape", "prog"),
    [
        (TRANSLATING, RollerShape.CYLINDRICAL, program(30.0)),
        (TRANSLATING, RollerShape.CONICAL, program(30.0)),
        (ARM, RollerShape.CYLINDRICAL, arm_program()),
    ],
    ids=["translating-cylinder", "translating-cone", "arm-cylinder"],
)
def test_rib_faces_touch_their_roller_and_neither_roller_cuts_the_rib(follower, shape, prog):
    """Brute force in 3-D: each face point touches its own roller at φ and is outside both at every φ′."""
    opt = rib_options(roller=shape)
    phis = PHI[::24]
    st = np.array([55.0, 64.0, 70.0])
    faces = barrel_faces(prog.evaluate(phis), follower, opt, st)
    up_roller, low_roller = rib_rollers(follower, opt)
    scan = np.linspace(-0.4, 0.4, 801)
    for sheet, own in ((faces.upper, up_roller), (faces.lower, low_roller)):
        for i, phi in enumerate(phis):
            for j in range(st.size):
                p = sheet.point[i, j]
                assert abs(_outside(p, own, prog, np.array([phi]), opt)[0]) < 1e-9
                for roller in (up_roller, low_roller):
                    assert _outside(p, roller, prog, phi + scan, opt).min() > -1e-4
        # normals out of the rib: towards its roller's axis, away from the pitch path between the rollers
        m = prog.evaluate(phis)
        e_r = np.stack((np.cos(phis), np.sin(phis), 0 * phis), axis=-1)[:, None, :]
        e_t = np.stack((-np.sin(phis), np.cos(phis), 0 * phis), axis=-1)[:, None, :]
        yz = own.centre(m).m0
        axis_pt = (
            st[None, :, None] * e_r + yz[:, None, 0:1] * e_t + yz[:, None, 1:2] * np.array([0.0, 0.0, 1.0])
        )
        assert np.all(np.sum(sheet.normal * (axis_pt - sheet.point), axis=-1) > 0.0)


def test_rib_faces_at_pitch_are_the_plate_envelopes_of_the_shifted_pitch_lines():
    """Second method: each developed face lies r_w from a dense polyline of its roller's unrolled path.

    The roller paths are (t_p·φ, z0 ± h + s(φ)); the upper face lies below the upper path, the lower
    face above the lower one, and where the follower dwells the faces are the rib's width apart.
    """
    prog = program(30.0)
    opt = rib_options()
    tp, h = opt.pitch_station, opt.rib_offset
    r_w = opt.roller_radius + 0.5 * opt.clearance
    dense = np.linspace(-0.5, 2 * math.pi + 0.5, 400_001)
    s_dense = prog.evaluate(dense).s
    m = prog.evaluate(PHI)
    walls = barrel_faces(m, TRANSLATING, opt, np.array([tp]))
    e_t = np.column_stack((-np.sin(PHI), np.cos(PHI)))
    developed = {}
    for sheet, sign, name in ((walls.upper, 1.0, "upper"), (walls.lower, -1.0, "lower")):
        u = tp * PHI + np.sum(sheet.point[:, 0, :2] * e_t, axis=1)
        w = sheet.point[:, 0, 2]
        path = np.column_stack((tp * dense, 35.0 + sign * h + s_dense))
        dist, idx = cKDTree(path).query(np.column_stack((u, w)))
        assert_allclose(dist, r_w, atol=1e-6)
        assert np.all(sign * (w - path[idx, 1]) < 0.0)  # towards the rib
        developed[name] = np.column_stack((u, w))
    dwell = np.abs(m.v) < 1e-12
    assert dwell.sum() > 50
    width = developed["upper"][dwell, 1] - developed["lower"][dwell, 1]
    assert_allclose(width, opt.rib_width, atol=1e-12)
    assert_allclose(developed["upper"][dwell, 0], developed["lower"][dwell, 0], atol=1e-12)


def test_rib_limits_against_brute_force():
    """z reach, pressure angle and the rib's least width against dense samples and a k-d tree."""
    prog = program(30.0)
    opt = rib_options()
    lim = barrel_limits(prog, TRANSLATING, opt)
    assert not lim.findings
    h, r_w = opt.rib_offset, 8.05
    # each face reaches farthest from the pitch line where the follower dwells: z0 ± (h − r_w) = z0 ± w/2
    assert h - r_w == pytest.approx(7.0, abs=1e-12)
    assert lim.z_range[0].value == pytest.approx(35.0 - (h - r_w), abs=1e-9)
    assert lim.z_range[1].value == pytest.approx(65.0 + (h - r_w), abs=1e-9)
    v_max = 2.0 * 30.0 / (math.pi / 2.0)  # cycloidal: s′max = 2h/β (Rothbart 2004, §3.4)
    for ext, r in zip(lim.pressure_angle_max, (55.0, opt.pitch_station, 70.0), strict=True):
        assert ext.value == pytest.approx(math.atan(v_max / r), abs=1e-10)
    # the nearest vertex of a polyline 0.02 mm apart is within (0.01 mm)²/(2·10 mm) = 5e-6 mm of the curve's
    dense = np.linspace(0.0, 2 * math.pi, 20_001)
    m = prog.evaluate(dense)
    for name, t in (("bottom", 55.0), ("top", 70.0)):
        up_roller, low_roller = rib_rollers(TRANSLATING, opt)
        upper = developed_walls(m, up_roller, opt, t).lower.point
        lower = developed_walls(m, low_roller, opt, t).upper.point
        period = np.array([2 * math.pi * t, 0.0])
        d, _ = cKDTree(np.vstack((lower - period, lower, lower + period))).query(upper)
        assert lim.rib_thickness_min[name].value == pytest.approx(d.min(), abs=2e-5)
        assert lim.rib_thickness_min[name].value < opt.rib_width - 1.0  # the flank is narrower than the dwell
    assert lim.rib_thickness_min["bottom"].value < lim.rib_thickness_min["top"].value


def test_a_rib_too_narrow_for_its_flank_vanishes():
    lim = barrel_limits(program(50.0, span_deg=60.0), TRANSLATING, rib_options(rib_width=1.0, length=140.0))
    (finding,) = [f for f in lim.findings if f.kind == "rib vanishes"][:1]
    assert path_of(finding.field) == "cam.rib_width"
    assert lim.rib_thickness_min["bottom"].value < 0.0
    with pytest.raises(DesignError) as err:
        check_barrel(rib_options(rib_width=0.0), TRANSLATING)
    assert path_of(err.value.path) == "cam.rib_width"
    assert exit_code(err.value) == EXIT_INVALID


@settings(max_examples=20, deadline=None)
@given(
    law=st.sampled_from(["cycloidal", "poly-345", "harmonic", "modified-sine"]),
    lift=st.floats(2.0, 40.0),
    span=st.floats(60.0, 170.0),
    width=st.floats(4.0, 30.0),
    t=st.floats(55.0, 70.0),
)
def test_rib_faces_for_any_law(law, lift, span, width, t):
    """Any translating rib: each developed face is r_w from its roller's path, on the rib's side, and
    the faces are the rib's width apart (exactly, along z) wherever the follower dwells."""
    prog = program(lift, law=law, span_deg=span)
    m = prog.evaluate(PHI)
    opt = rib_options(rib_width=width)
    h, r_w = opt.rib_offset, opt.roller_radius + 0.5 * opt.clearance
    up_roller, low_roller = rib_rollers(TRANSLATING, opt)
    upper = developed_walls(m, up_roller, opt, t).lower
    lower = developed_walls(m, low_roller, opt, t).upper
    for face, sign in ((upper, 1.0), (lower, -1.0)):
        path = np.column_stack((t * PHI, 35.0 + sign * h + m.s))
        offset = face.point - path
        assert_allclose(np.hypot(offset[:, 0], offset[:, 1]), r_w, atol=1e-10)
        # along the path's normal (−s′, t)/D, towards the rib
        normal = np.column_stack((-m.v, np.full_like(m.v, t))) / np.hypot(m.v, t)[:, None]
        assert_allclose(np.sum(offset * normal, axis=1), -sign * r_w, atol=1e-10)
    dwell = np.abs(m.v) < 1e-12
    assert_allclose(upper.point[dwell, 1] - lower.point[dwell, 1], width, atol=1e-10)
