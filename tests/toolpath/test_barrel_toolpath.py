"""The barrel's 4-axis passes (issue 36) against independent truths.

- the chord deviation of every pass, recomputed on a 20× finer grid of the exact path;
- a cutter smaller than the roller, offset to be exact at the pitch station, leaves stock
  (never gouges) at the groove's bottom and top; for a translating roller the amount matches
  the first-order estimate δ(1 − cos(β_t − β_p)), tan β_t = s′/t, δ = r_w − r_c (the cutter's
  axis shifted by δ along the pitch station's normal is δ·cos Δβ off the line at station t);
- bad options name their field.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad.design.paths import path_of
from camcad.errors import DesignError
from camcad.geometry.barrel_limits import developed_walls
from camcad.toolpath.barrel import BarrelToolpathOptions, plan_barrel, small_cutter_deviation
from tests.barrel_cases import CASES, INDEXER


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


def test_a_rib_is_refused_naming_the_field():
    from tests.barrel_cases import RIB

    with pytest.raises(DesignError) as err:
        plan_barrel(RIB.program, RIB.follower, RIB.options, BarrelToolpathOptions())
    assert path_of(err.value.path) == "cam.style"


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
