"""The rib barrel's 4-axis program read by LinuxCNC's ``rs274`` and measured in 3-D (issue 36).

From rs274's canonical moves alone each pass is rebuilt (X, Y, A linear within a block) and the
body its flat end mill sweeps is measured (tests/readers/test_barrel_readers.py's helpers: the
tool's axis the radial line at θ = −A, y = −Y across it, z = X; radius r at stations ≥ its tip):

- each rib face, in closed form for the sample's translating rollers (the roller at z0 ± h + s,
  its wall r_w = r_f + c/2 off its axis along the contact normal (cos γ, sin γ) = σ(−s′, t)/D,
  D = √(s′² + t²), at the root, pitch and top stations), lies on the finishing cutter's swept
  surface within the program's tolerance, and every roughing cutter stays the stock off it;
- points inside the rib (between its faces at the root, pitch and top radii, 0.02 mm in from
  them) are never inside any cutter: the rib is never cut into;
- points of the blank away from the rib (0.05 mm or more beyond a face, over the barrel's length,
  from just above the root to the rib's top) all lie inside some cutter: nothing is left above
  the root radius but the flat end's fillet beside the faces at the root, whose size the
  program's header states and which is checked here in closed form.
"""

from __future__ import annotations

import math
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from camcad.geometry.barrel import WallSide, faces_at_radius
from camcad.toolpath.barrel import BarrelToolpathOptions, plan_barrel
from tests.barrel_cases import RIB
from tests.readers.test_barrel_readers import _positions, _swept_distance, rs274_passes

pytestmark = pytest.mark.slow
SPEC = BarrelToolpathOptions(rough_diameter=9.5, tolerance=0.005)


@cache
def rib_passes(folder: Path) -> tuple[list[dict], str]:
    """rs274's canonical moves of the rib's program: the deepest roughing level's and the finishing
    passes (the others shown to lie inside them); and the program's text."""
    tp = plan_barrel(RIB.program, RIB.follower, RIB.options, SPEC)
    passes, text = rs274_passes(folder, tp, name="rib", rough_diameter=9.5)
    # every roughing level repeats the deepest one's X, Y, A: a body reaching lower holds the higher
    # one's, so the deepest level and the finishing passes are the whole cut
    levels: dict[float, list[np.ndarray]] = {}
    for p in passes:
        if p["kind"] == "rough":
            moves = np.array([end for _, end in p["moves"][1:]])  # after the plunge
            levels.setdefault(float(moves[0, 2]), []).append(moves[:, [0, 1, 3]])
    deepest = min(levels)
    assert deepest == pytest.approx(RIB.options.bottom_radius, abs=1e-4) and len(levels) >= 2
    for moves in levels.values():
        assert len(moves) == len(levels[deepest])
        assert all(np.array_equal(a, b) for a, b in zip(moves, levels[deepest], strict=True))
    return [p for p in passes if p["kind"] != "rough" or p["moves"][-1][1][2] == deepest], text


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("ribngc")


def _closed_form_face(phi: np.ndarray, station: float, upper: bool) -> np.ndarray:
    """A rib face's points (n, 3) in the barrel's frame, from s and s′ alone (module notes)."""
    o = RIB.options
    m = RIB.program.evaluate(phi)
    h = o.rib_offset if upper else -o.rib_offset
    sigma = -1.0 if upper else 1.0  # the upper face is the +h roller's lower wall
    r_w = o.roller_radius + 0.5 * o.clearance
    d = np.hypot(m.v, station)
    cos_g, sin_g = -sigma * m.v / d, sigma * station / d
    across = r_w * cos_g
    e_r = np.column_stack((np.cos(phi), np.sin(phi)))
    e_t = np.column_stack((-np.sin(phi), np.cos(phi)))
    xy = station * e_r + across[:, None] * e_t
    return np.column_stack((xy, RIB.follower.axial_position + h + m.s + r_w * sin_g))


def _swept(points: np.ndarray, passes: list[dict], kinds: tuple[str, ...], spacing: float) -> np.ndarray:
    """The least signed distance of barrel-frame points from the bodies of the passes of ``kinds``."""
    radius = {"rough": 0.5 * SPEC.rough_diameter, "finish upper": 8.0, "finish lower": 8.0}
    phi = np.mod(np.arctan2(points[:, 1], points[:, 0]), 2.0 * math.pi)
    out = np.full(len(points), np.inf)
    groups: dict[tuple[str, float], list[np.ndarray]] = {}
    for p in passes:
        if p["kind"] in kinds:
            pos, tip = _positions(p["moves"], spacing, RIB.options.barrel_radius)
            groups.setdefault((p["kind"], tip), []).append(pos)
    for (kind, tip), chunks in groups.items():
        pos = np.concatenate(chunks)
        # the turn is periodic: the positions again a turn either way, so the ±0.3 rad window wraps
        wrap = np.concatenate([pos + np.array([0.0, 0.0, k]) for k in (-360.0, 0.0, 360.0)])
        out = np.minimum(out, _swept_distance(points, phi, wrap, tip, radius[kind], 0.0))
    return out


def test_rs274_runs_the_rib_program_and_the_finish_cuts_the_exact_faces(folder):
    passes, text = rib_passes(folder)
    o = RIB.options
    assert "rib: 14 wide" in text and "at the rib's root" in text
    phi = np.linspace(0.0, 2.0 * math.pi, 181, endpoint=False) + 1e-3
    stations = (o.bottom_radius + 1e-3, o.pitch_station, o.barrel_radius)
    worst = {}
    for upper, kind in ((True, "finish upper"), (False, "finish lower")):
        face = np.concatenate([_closed_form_face(phi, t, upper) for t in stations])
        finish = [p for p in passes if p["kind"] == kind]
        assert len(finish) == 1
        d = _swept(face, passes, (kind,), 0.05)
        worst[kind] = float(np.abs(d).max())
        # 4-decimal words, 0.05 mm position spacing, the c/2 shift off the normal away from the pitch station
        assert np.all(np.abs(d) <= SPEC.tolerance + 3e-4), kind
        rough = _swept(face, passes, ("rough",), 0.2)
        worst[f"rough {kind}"] = float(rough.min())
        assert rough.min() >= SPEC.stock - SPEC.tolerance - 1e-3, kind
        # the nearest roughing pass is exact at the pitch station: it leaves the stock there, not much more
        assert rough.min() <= SPEC.stock + 0.01
    print(worst)


def _face_z(radius: float, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rib's lower and upper faces' z [mm] on the cylinder of ``radius`` at barrel angles φ."""
    grid = np.linspace(0.0, 2.0 * math.pi, 7200, endpoint=False)
    motion = RIB.program.evaluate(grid)
    out = []
    for side in (WallSide.LOWER, WallSide.UPPER):
        pts = faces_at_radius(motion, RIB.follower, RIB.options, radius, side)[1].point[:, 0]
        theta = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
        out.append(np.interp(phi, theta, pts[:, 2], period=2.0 * math.pi))
    return out[0], out[1]


def _on_cylinder(radius: float, phi: np.ndarray, z: np.ndarray) -> np.ndarray:
    return np.column_stack((radius * np.cos(phi), radius * np.sin(phi), z))


def test_the_rib_is_never_cut_into(folder):
    passes, _ = rib_passes(folder)
    o = RIB.options
    phi = np.linspace(0.0, 2.0 * math.pi, 90, endpoint=False) + 0.01
    pts = []
    for radius in (o.bottom_radius + 1e-3, o.pitch_station, o.barrel_radius):
        low, up = _face_z(radius, phi)
        assert np.all(up - low > 1.0)
        for f in np.linspace(0.0, 1.0, 7):
            pts.append(_on_cylinder(radius, phi, low + 0.02 + f * (up - low - 0.04)))
    d = _swept(np.concatenate(pts), passes, ("rough", "finish upper", "finish lower"), 0.2)
    print("inside the rib: least distance from any cutter", float(d.min()))
    assert d.min() > 0.0


def _steepest() -> tuple[float, float, float]:
    """r_w, sin β and cos β at the root's steepest point, tan β = s′max/b (s′ on a fine grid)."""
    o = RIB.options
    v = float(np.abs(RIB.program.evaluate(np.linspace(0.0, 2.0 * math.pi, 200_001)).v).max())
    d = math.hypot(v, o.bottom_radius)
    return o.roller_radius + 0.5 * o.clearance, v / d, o.bottom_radius / d


def test_nothing_is_left_above_the_root_away_from_the_rib(folder):
    """Every sampled point of the blank beyond the faces is inside some cutter, but for the root's fillet.

    The fillet, in closed form: a face point at the root station b on the steepest flank lies
    a = r_w·sin β across the roller's axis, at radius √(b² + a²) = b + F; a flat end reaches radius
    b + ε only within acos(b/(b + ε)) of its own angle, so beside the face at the root it leaves up to
    r_w(1/cos β − 1) along the axis (the developed face lies r_w/cos β from the path at the same u,
    the aligned cutter's edge r_w). So: just above the root, points farther than that from the
    faces; from b + F up, every point 0.05 mm beyond a face; and the header's F.
    """
    passes, text = rib_passes(folder)
    o = RIB.options
    r_w, sin_b, cos_b = _steepest()
    fillet = math.hypot(o.bottom_radius, r_w * sin_b) - o.bottom_radius
    assert f"fillet up to {fillet:.4f} high" in text
    beside = r_w * (1.0 / cos_b - 1.0)
    phi = np.linspace(0.0, 2.0 * math.pi, 48, endpoint=False) + 0.005
    z = np.linspace(0.0, o.length, 45)
    pts = []
    for radius, margin in (
        (o.bottom_radius + 0.01, beside + 0.05),
        (o.bottom_radius + fillet + 0.01, 0.05),
        (60.0, 0.05),
        (65.0, 0.05),
        (o.barrel_radius, 0.05),
    ):
        low, up = _face_z(radius, phi)
        zz, pp = np.meshgrid(z, phi)
        lo, hi = np.meshgrid(z, low)[1], np.meshgrid(z, up)[1]
        away = (zz <= lo - margin) | (zz >= hi + margin)
        pts.append(_on_cylinder(radius, pp[away], zz[away]))
        # and right beside each face, all round
        pts.append(_on_cylinder(radius, phi, low - margin))
        pts.append(_on_cylinder(radius, phi, up + margin))
    points = np.concatenate(pts)
    d = _swept(points, passes, ("rough", "finish upper", "finish lower"), 0.2)
    print("outside the rib:", len(points), "points, the one least deep in a cutter", float(d.max()))
    assert np.all(d < 0.0), points[d >= 0.0][:5]
