"""The barrel's 4-axis passes (issue 36) against independent truths.

- the chord deviation of every pass, recomputed on a 20× finer grid of the exact path;
- a cutter smaller than the roller, offset to be exact at the pitch station, leaves stock
  (never gouges) at the groove's bottom and top; for a translating roller the amount matches
  the first-order estimate δ(1 − cos(β_t − β_p)), tan β_t = s′/t, δ = r_w − r_c (the cutter's
  axis shifted by δ along the pitch station's normal is δ·cos Δβ off the line at station t);
- a rib's passes, over rib cams and roughing cutters (Hypothesis): in the developed plane at the
  root, pitch and top every roughing cutter keeps the stock off both closed-form faces and each
  finishing cutter lies on its face; its small-cutter report is the flank's closed form;
- bad options name their field.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from camcad.design.paths import path_of
from camcad.errors import DesignError
from camcad.geometry.barrel import TranslatingBarrelRoller
from camcad.geometry.barrel_limits import developed_walls
from camcad.toolpath.barrel import BarrelToolpathOptions, plan_barrel, small_cutter_deviation
from tests.barrel_cases import CASES, INDEXER, BarrelCase


@pytest.mark.parametrize("name", list(CASES))
def test_blocks_keep_the_axis_within_tolerance(name):
    c = CASES[name]
    spec = BarrelToolpathOptions(tolerance=0.01)
    tp = plan_barrel(c.program, c.follower, c.options, spec)
    assert tp.max_deviation <= spec.tolerance
    tp_station = c.options.pitch_station
    for p in tp.passes:
        phi = -np.radians(p.a)
        f = np.linspace(0.0, 1.0, 41)[1:-1]
        fine = (phi[:-1, None] + f * np.diff(phi)[:, None]).ravel()
        y_lin = -(p.y[:-1, None] + f * np.diff(p.y)[:, None]).ravel()
        z_lin = (p.x[:-1, None] + f * np.diff(p.x)[:, None]).ravel()
        # the exact path, rebuilt here: the follower's axis shifted along the developed pitch normal
        axis = c.follower.centre(c.program.evaluate(fine))
        du, dz = tp_station + axis.m1[:, 0], axis.m1[:, 1]
        norm = np.hypot(du, dz)
        y = axis.m0[:, 0] - p.shift * dz / norm
        z = axis.m0[:, 1] + p.shift * du / norm
        assert np.max(np.hypot(y - y_lin, z - z_lin)) <= spec.tolerance
        assert abs(p.shift) + p.radius <= c.options.roller_radius + 0.5 * c.options.clearance + 1e-12


def test_the_program_reports_the_small_cutters_deviation():
    from camcad.export.gcode.barrel import render_barrel_program

    c = INDEXER
    tp = plan_barrel(c.program, c.follower, c.options, BarrelToolpathOptions())
    again = small_cutter_deviation(
        c.program, c.follower, c.options, 5.0, np.array([c.options.bottom_radius, c.options.barrel_radius])
    )
    assert np.array_equal(tp.small_cutter, again)
    text = render_barrel_program(tp)
    assert f"{np.abs(again[0]).max():.4f} at the groove's bottom" in text


def test_a_smaller_cutter_leaves_stock_at_bottom_and_top_as_estimated():
    """Against a brute-force scan of the cutter's path and the closed form on the steepest flank.

    Second method: each exact developed wall point's distance from the cutter's axis path, built here
    from s and s′ alone ((t·φ − δ s′/D_p, z0 + s + δ t_p/D_p), D_p = √(s′² + t_p²)), by a dense scan of
    4001 angles within ±0.05 rad of it (the nearest sample within 4e-8 mm of the curve). Closed form:
    where s″ = 0 (s′ largest, the middle of the modified-sine rise, 50°) the path is straight and the
    stock is δ(1 − cos(β_t − β_p)), tan β = s′/t.
    """
    c = INDEXER
    o = c.options
    r_c = 5.0
    r_w = o.roller_radius + 0.5 * o.clearance
    delta, tp = r_w - r_c, o.pitch_station
    stations = np.array([o.bottom_radius, o.pitch_station, o.barrel_radius])
    dev = small_cutter_deviation(c.program, c.follower, o, r_c, stations)
    assert np.all(dev[..., 0] >= -1e-9)  # no gouge anywhere
    assert np.all(np.abs(dev[1]) <= 1e-9)  # exact at the pitch station
    steepest = math.radians(50.0)
    assert float(c.program.evaluate(np.array([steepest])).a[0]) == pytest.approx(0.0, abs=1e-9)
    near = np.linspace(steepest - 0.2, steepest + 0.2, 41)  # round the steepest flank
    scan = near[:, None] + np.linspace(-0.05, 0.05, 4001)[None, :]
    m = c.program.evaluate(scan.ravel())
    d_p = np.hypot(m.v, tp)
    v_star = float(c.program.evaluate(np.array([steepest])).v[0])
    for i, t in ((0, o.bottom_radius), (2, o.barrel_radius)):
        walls = developed_walls(c.program.evaluate(near), c.follower, o, float(t))
        estimate = delta * (1.0 - math.cos(math.atan(v_star / t) - math.atan(v_star / tp)))
        assert estimate > 0.002
        for j, (sign, wall) in enumerate(((1.0, walls.upper.point), (-1.0, walls.lower.point))):
            u = (t * scan.ravel() - sign * delta * m.v / d_p).reshape(scan.shape)
            w = (30.0 + m.s + sign * delta * tp / d_p).reshape(scan.shape)
            stock = np.min(np.hypot(u - wall[:, 0:1], w - wall[:, 1:2]), axis=1) - r_c
            assert stock[20] == pytest.approx(estimate, abs=1e-5)  # the closed form on the straight flank
            # the reported greatest stock (the turn's) is this neighbourhood's (the rise is the steepest)
            assert dev[i, j, 1] == pytest.approx(stock.max(), abs=2e-7)


@pytest.mark.parametrize(
    ("field", "change"),
    [
        ("gcode.rough_diameter", {"rough_diameter": 16.0}),
        ("gcode.step_down", {"step_down": 0.0}),
        ("gcode.stock", {"stock": -1.0}),
        ("gcode.tolerance", {"tolerance": float("nan")}),
    ],
)
def test_bad_options_name_their_field(field, change):
    """Each bad option is refused naming its field."""
    spec = replace(BarrelToolpathOptions(), **change)
    with pytest.raises(DesignError) as err:
        plan_barrel(INDEXER.program, INDEXER.follower, INDEXER.options, spec)
    assert path_of(err.value.path) == field


def _rib_case(lift: float, span_deg: float, width: float) -> BarrelCase:
    """A translating rib cam long enough for its rollers' paths (rise, dwell, return, dwell)."""
    from tests.barrel_cases import RIB, _program

    o = replace(RIB.options, rib_width=width)
    z0 = o.rib_offset + 12.0
    return replace(
        RIB,
        program=_program(lift, "modified-sine", span_deg),
        follower=TranslatingBarrelRoller(axial_position=z0),
        options=replace(o, length=z0 + lift + o.rib_offset + 12.0),
    )


def _developed_faces(case: BarrelCase, phi: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """The rib's (upper, lower) faces developed at station t from s and s′ alone: each roller's line
    (tφ, z0 ± h + s) offset by r_w along its normal (−s′, t)/D towards the rib."""
    o = case.options
    m = case.program.evaluate(phi)
    d = np.hypot(m.v, t)
    normal = np.column_stack((-m.v / d, t / d))
    r_w = o.roller_radius + 0.5 * o.clearance
    out = []
    for h, sign in ((o.rib_offset, -1.0), (-o.rib_offset, 1.0)):
        line = np.column_stack((t * phi, case.follower.axial_position + h + m.s))
        out.append(line + sign * r_w * normal)
    return out[0], out[1]


def _axis_at(p, t: float, spacing: float = 0.1) -> np.ndarray:
    """A pass's tool axis in the developed plane of station t (u = t·φ + y, w = z; φ = −A, y = −Y,
    z = X), dense along each block, one turn either side for the period."""
    phi = -np.radians(p.a)
    u, w = t * phi - p.y, p.x
    n = np.maximum(2, np.ceil(np.hypot(np.diff(u), np.diff(w)) / spacing).astype(int))
    block = np.repeat(np.arange(n.size), n)
    f = (np.arange(block.size) - np.repeat(np.cumsum(n) - n, n)) / n[block]
    pts = np.column_stack((u[block] + f * np.diff(u)[block], w[block] + f * np.diff(w)[block]))
    period = np.array([t * 2.0 * math.pi, 0.0])
    return np.vstack((pts - period, pts, pts + period))


@settings(max_examples=5, deadline=None)
@given(
    lift=st.floats(10.0, 30.0),
    span=st.floats(80.0, 140.0),
    width=st.floats(10.0, 20.0),
    rough_d=st.floats(3.0, 15.6),
)
def test_a_ribs_passes_keep_off_the_faces_and_finish_them_exactly(lift, span, width, rough_d):
    """Law over rib cams and roughing cutters, in the developed plane at the root, pitch and top:
    every roughing cutter stays at least the stock off both closed-form faces, each finishing cutter
    (the roller's radius) touches its face and no other within the tolerance, and the roughing passes
    slide out past the barrel's ends all round (the rs274 test measures the sample's cut in 3-D)."""
    from scipy.spatial import cKDTree

    case = _rib_case(lift, span, width)
    o = case.options
    spec = BarrelToolpathOptions(rough_diameter=rough_d, tolerance=0.01)
    tp = plan_barrel(case.program, case.follower, o, spec)
    assert tp.max_deviation <= spec.tolerance
    phi = np.linspace(0.0, 2.0 * math.pi, 1441)
    deepest = min(p.z for p in tp.passes)
    rough = [p for p in tp.passes if p.kind == "rough"]
    # the levels repeat the deepest one's X, Y, A: its passes are every roughing cutter's axis
    base = [p for p in rough if p.z == deepest]
    assert len(rough) % len(base) == 0
    for i, p in enumerate(rough):
        q = base[i % len(base)]
        assert np.array_equal(p.x, q.x) and np.array_equal(p.y, q.y) and np.array_equal(p.a, q.a)
    for t in (o.bottom_radius, o.pitch_station, o.barrel_radius):
        upper, lower = _developed_faces(case, phi, t)
        tree = cKDTree(np.concatenate([_axis_at(p, t) for p in base]))
        left = min(tree.query(upper)[0].min(), tree.query(lower)[0].min()) - 0.5 * rough_d
        assert left >= spec.stock - spec.tolerance - 1e-3
        for p in tp.passes[len(rough) :]:
            tree = cKDTree(_axis_at(p, t))
            d_up, d_low = tree.query(upper)[0] - p.radius, tree.query(lower)[0] - p.radius
            mine, other = (d_up, d_low) if p.kind == "finish upper" else (d_low, d_up)
            # the c/2 shift along the pitch station's normal misses another station's by (c/2)(1 − cos Δβ)
            assert np.abs(mine).max() <= spec.tolerance + 1e-3, p.kind
            assert other.min() > 1.0
    rough_x = [p.x for p in rough]
    # the outermost slides put the cutter's axis on or past each end (far·k/count sums round to an ulp)
    end_ulp = 4.0 * np.spacing(o.length)
    assert max(x.min() for x in rough_x) >= o.length - end_ulp and min(x.max() for x in rough_x) <= end_ulp


def test_an_arm_ribs_passes_keep_off_its_faces_and_finish_them():
    """A rib on the arm sample's follower (yokes ±h across the arm's end): in the developed plane at the
    root, pitch and top the finishing cutters lie on the exact faces (the lower layer's walls of each
    of its rollers), the roughing cutters keep the stock off them; its axis runs |y| > r_c off the
    barrel's axis, so the floor's rise is reported."""
    from scipy.spatial import cKDTree

    from camcad.geometry.barrel import BarrelKind, rib_rollers
    from tests.barrel_cases import ARM

    o = replace(ARM.options, kind=BarrelKind.RIB, rib_width=14.0, length=ARM.options.length + 40.0)
    follower = replace(ARM.follower, axial_position=ARM.follower.axial_position + 20.0)
    spec = BarrelToolpathOptions(rough_diameter=9.5, tolerance=0.01)
    tp = plan_barrel(ARM.program, follower, o, spec)
    assert tp.max_deviation <= spec.tolerance
    up, low = rib_rollers(follower, o)
    rough = [p for p in tp.passes if p.kind == "rough" and p.z == o.bottom_radius]
    motion = ARM.program.evaluate(np.linspace(0.0, 2.0 * math.pi, 1441))
    for t in (o.bottom_radius, o.pitch_station, o.barrel_radius):
        faces = {
            "finish upper": developed_walls(motion, up, o, t).lower.point,
            "finish lower": developed_walls(motion, low, o, t).upper.point,
        }
        tree = cKDTree(np.concatenate([_axis_at(p, t) for p in rough]))
        for face in faces.values():
            assert tree.query(face)[0].min() - 4.75 >= spec.stock - spec.tolerance - 1e-3
        for p in tp.passes[-2:]:
            d = cKDTree(_axis_at(p, t)).query(faces[p.kind])[0] - p.radius
            assert np.abs(d).max() <= spec.tolerance + 1e-3, (t, p.kind)
    y = max(float(np.abs(p.y).max()) for p in rough)
    assert y > 4.75 and tp.floor_rise == pytest.approx(
        math.hypot(o.bottom_radius, y - 4.75) - o.bottom_radius
    )


def test_a_ribs_small_cutter_report_is_the_flank_estimate():
    """Each face finished by the rougher, exact at the pitch station, leaves on the steepest flank
    δ(1 − cos(β_t − β_p)), δ = r_w − r_c, tan β = s′/t: the reported greatest stock at the root and
    the top is that (1 % for the turn's largest, just off the steepest point), and nothing gouges;
    the root's fillet in closed form."""
    from tests.barrel_cases import RIB

    o = RIB.options
    tp = plan_barrel(RIB.program, RIB.follower, o, BarrelToolpathOptions(rough_diameter=9.5))
    v_star = float(np.abs(RIB.program.evaluate(np.linspace(0.0, 2.0 * math.pi, 200_001)).v).max())
    delta = o.roller_radius + 0.5 * o.clearance - 4.75
    for i, t in enumerate((o.bottom_radius, o.barrel_radius)):
        estimate = delta * (1.0 - math.cos(math.atan(v_star / t) - math.atan(v_star / o.pitch_station)))
        for j in range(2):
            assert tp.small_cutter[i, j, 0] >= -1e-9
            assert estimate <= tp.small_cutter[i, j, 1] <= 1.01 * estimate
    # the root's fillet: the face at the root station b on the steepest flank is a = r_w·sin β across
    # the roller's axis, √(b² + a²) from the barrel's, tan β = s′/b
    a = (delta + 4.75) * v_star / math.hypot(v_star, o.bottom_radius)
    assert tp.root_fillet == pytest.approx(math.hypot(o.bottom_radius, a) - o.bottom_radius, abs=1e-8)
    assert tp.floor_rise == 0.0  # a translating follower: the tool's axis runs through the barrel's


@pytest.mark.parametrize(
    ("field", "change"),
    [("gcode.rough_diameter", {"rough_diameter": 15.7}), ("gcode.stepover", {"stepover": 1.5})],
)
def test_a_ribs_bad_options_name_their_field(field, change):
    """The rougher must fit the gap 2r_f + c = 16.05 mm beside the rib less 0.2 mm stock each side."""
    from tests.barrel_cases import RIB

    with pytest.raises(DesignError) as err:
        plan_barrel(RIB.program, RIB.follower, RIB.options, replace(BarrelToolpathOptions(), **change))
    assert path_of(err.value.path) == field


def test_a_conical_roller_is_finished_by_a_tapered_cutter_of_its_own_shape():
    """One pass, the roller's own path, tip radius k·b + c/2 and taper k = r_f/t_p (apex on the axis).

    The cutter's radius r_tip + k(t − b) equals the wall's roller radius k·t + c/2 at every station t
    (the identity that makes the one pass exact; the swept walls are measured in test_barrel_readers).
    """
    from camcad.geometry.barrel import RollerShape

    o = replace(INDEXER.options, roller=RollerShape.CONICAL)
    tp = plan_barrel(INDEXER.program, INDEXER.follower, o, BarrelToolpathOptions(tolerance=0.01))
    finish = [p for p in tp.passes if p.kind.startswith("finish")]
    assert [p.kind for p in finish] == ["finish both"]
    (f,) = finish
    k = 8.0 / (70.0 - 14.0 / 2.0)
    b = 70.0 - 18.0
    assert f.taper == pytest.approx(k, rel=1e-12)
    assert f.radius == pytest.approx(k * b + 0.025, rel=1e-12)
    assert f.z == b and f.shift == 0.0
    for t in (b, 61.0, 70.0):
        assert f.radius + f.taper * (t - f.z) == pytest.approx(
            float(o.roller_at(t, clearance=True)), abs=1e-12
        )
    # on the roller's own path: X = z0 + s, Y = 0, A = −φ
    phi = -np.radians(f.a)
    assert_allclose(f.x, 30.0 + INDEXER.program.evaluate(phi).s, atol=1e-12)
    assert np.all(f.y == 0.0)
    assert tp.max_deviation <= 0.01
    # roughing keeps the stock inside the cylinder of the tip's radius
    for p in tp.passes[:-1]:
        assert abs(p.shift) + p.radius <= f.radius - 0.2 + 1e-12
